//! Rectangles to a crack-free triangle mesh.
//!
//! The vertices are the corners of every rectangle plus the border vertices
//! pinned by [`super::border`]. A rectangle whose sides carry no other
//! vertex is drawn as two triangles split along its (col0, row0)–(col1,
//! row1) diagonal. A straightened side can still pass through a vertex that
//! a neighbouring rectangle uses as a corner; drawing the side as one
//! straight edge would leave a T-junction there (and a crack wherever that
//! vertex is off the straight line, the paper's Fig. 4). Such a rectangle is
//! instead fanned through every vertex on its perimeter, in order: from the
//! (col0, row0) or (col1, row1) corner when both sides at that corner are
//! bare (n - 2 triangles for n perimeter vertices), or else by ear clipping
//! (n - 2 triangles), whichever first keeps every sample inside within its
//! T; otherwise from a new vertex at its centre whose height is that of
//! the two-triangle surface there (n triangles). Each edge of the mesh is
//! then shared by exactly the two triangles on either side, with the same
//! two end vertices, so there is neither a crack nor a T-junction inside the
//! tile. None of this bounds the error by itself: [`super::Simplifier`]
//! checks the result and splits the rectangles around any sample off by
//! more than its T, then triangulates again.
//!
//! The tile border carries exactly the vertices the border pass pinned, so
//! that the neighbouring tile, which pins the same ones, meets it edge to
//! edge. A rectangle corner left on the border between two pinned vertices
//! (where a merge across it was refused) is removed from the mesh and the
//! hole its triangles leave is ear-clipped ([`super::earclip`]). Should that
//! fail (it needs a strictly convex ear), the corner is reported and the
//! caller splits the rectangles around it (next to the border, single cells
//! always leave a strictly convex ear).
//!
//! Triangles are counter-clockwise seen from +z (the winding flips when one
//! spacing is negative, since the axes are then mirrored).

use super::Rect;
use super::earclip::ear_clip;
use super::measure::visit_triangle;

/// Scratch buffers of the triangulation.
#[derive(Debug, Default)]
pub struct Scratch {
    pub used: Vec<bool>,
    pub vertex_of: Vec<u32>,
    pub perimeter: Vec<u32>,
    /// `(junction vertex, triangle)` pairs, sorted.
    pub incident: Vec<(u32, u32)>,
    /// Triangles created by removals.
    pub added: Vec<u32>,
    pub fan: Vec<[u32; 3]>,
    pub chain: Vec<u32>,
    pub work: Vec<u32>,
    pub new_tris: Vec<[u32; 3]>,
    pub remap: Vec<u32>,
}

const DEAD: [u32; 3] = [u32::MAX; 3];

/// Removes border vertex `v` (inside a straight stretch of the tile border)
/// by ear-clipping the polygon its triangles leave, choosing ears of least
/// error. False, with nothing changed, when no ear can be clipped.
fn remove_vertex(
    v: u32,
    layout: &Layout,
    triangles: &mut Vec<[u32; 3]>,
    positions: &[[f64; 3]],
    grid: &[[f64; 2]],
    sc: &mut Scratch,
) -> bool {
    sc.fan.clear();
    let lo = sc.incident.partition_point(|&(w, _)| w < v);
    let hi = sc.incident.partition_point(|&(w, _)| w <= v);
    let listed = sc.incident[lo..hi].iter().map(|&(_, t)| t);
    for t in listed.chain(sc.added.iter().copied()) {
        let tri = triangles[t as usize];
        if let Some(k) = tri.iter().position(|&x| x == v) {
            sc.fan.push([v, tri[(k + 1) % 3], tri[(k + 2) % 3]]);
        }
    }
    if sc.fan.len() < 2 {
        return false;
    }
    // The chain p -> q around v starts at the p that is no triangle's q.
    let Some(first) = sc
        .fan
        .iter()
        .position(|t| !sc.fan.iter().any(|u| u[2] == t[1]))
    else {
        return false;
    };
    sc.chain.clear();
    sc.chain.push(sc.fan[first][1]);
    let mut q = sc.fan[first][2];
    for _ in 0..sc.fan.len() {
        sc.chain.push(q);
        match sc.fan.iter().find(|t| t[1] == q) {
            Some(t) => q = t[2],
            None => break,
        }
    }
    if sc.chain.len() != sc.fan.len() + 1 {
        return false;
    }
    // The hole: a (the chain's end), then the chain from b.
    let a = sc.chain.pop().expect("chain");
    sc.chain.insert(0, a);
    sc.new_tris.clear();
    let cost = |t: [u32; 3]| triangle_error(layout, t, positions, grid);
    match ear_clip(
        &sc.chain,
        |x| grid[x as usize],
        cost,
        &mut sc.work,
        &mut sc.new_tris,
    ) {
        // The caller checks the error of the result (and splits rectangles
        // where it is too large); the border must match the neighbour's.
        Some(_) => {}
        None => return false,
    }
    let listed = sc.incident[lo..hi].iter().map(|&(_, t)| t);
    for t in listed.chain(sc.added.iter().copied()) {
        if triangles[t as usize].contains(&v) {
            triangles[t as usize] = DEAD;
        }
    }
    for &t in &sc.new_tris {
        sc.added.push(triangles.len() as u32);
        triangles.push(t);
    }
    true
}

/// Largest ratio |h - surface| / T(sample) over the samples in triangle `t`.
fn triangle_error(layout: &Layout, t: [u32; 3], positions: &[[f64; 3]], grid: &[[f64; 2]]) -> f64 {
    let mut worst: f64 = 0.0;
    visit_triangle(layout.rows, layout.cols, t, positions, grid, |i, z| {
        worst = worst.max((layout.reference[i] - z).abs() / layout.thresholds[i]);
    });
    worst
}

/// Triangulates a rectangle whose perimeter `poly` has more than four
/// vertices by ear clipping (shortest new edge first), keeping the result
/// only if every sample inside stays within its T; false leaves `mesh` as
/// it was.
fn clip_rectangle(layout: &Layout, poly: &[u32], work: &mut Vec<u32>, mesh: &mut Mesh) -> bool {
    let start = mesh.triangles.len();
    let grid = &*mesh.grid;
    let at = |v: u32| grid[v as usize];
    let cost = |t: [u32; 3]| {
        let (a, c) = (at(t[0]), at(t[2]));
        (a[0] - c[0]).powi(2) + (a[1] - c[1]).powi(2)
    };
    if ear_clip(poly, at, cost, work, mesh.triangles).is_none() {
        return false;
    }
    let ok = mesh.triangles[start..]
        .iter()
        .all(|&t| triangle_error(layout, t, mesh.positions, grid) <= 1.0);
    if !ok {
        mesh.triangles.truncate(start);
    }
    ok
}

/// Fans a rectangle from a corner on its diagonal whose two sides are bare
/// (`corner` holds the perimeter indices of its corners p00, p10, p11,
/// p01): n - 2 triangles, kept only if every sample inside stays within
/// its T; false leaves `mesh` as it was.
fn corner_fan(layout: &Layout, perimeter: &[u32], corner: [usize; 4], mesh: &mut Mesh) -> bool {
    let n = perimeter.len();
    // South and west bare: p00 sees every other perimeter vertex.
    let apex = if corner[1] == 1 && corner[3] == n - 1 {
        0
    } else {
        corner[2]
    };
    let start = mesh.triangles.len();
    for k in 1..n - 1 {
        mesh.triangles.push([
            perimeter[apex],
            perimeter[(apex + k) % n],
            perimeter[(apex + k + 1) % n],
        ]);
    }
    let ok = mesh.triangles[start..]
        .iter()
        .all(|&t| triangle_error(layout, t, mesh.positions, mesh.grid) <= 1.0);
    if !ok {
        mesh.triangles.truncate(start);
    }
    ok
}

/// Output buffers, reused between tiles.
pub struct Mesh<'a> {
    pub positions: &'a mut Vec<[f64; 3]>,
    pub triangles: &'a mut Vec<[u32; 3]>,
    /// Grid coordinates `(col, row)` of each vertex, for the error measure.
    pub grid: &'a mut Vec<[f64; 2]>,
}

/// Geometry of the tile.
pub struct Layout<'a> {
    pub rows: usize,
    pub cols: usize,
    /// Heights after the border pass.
    pub heights: &'a [f64],
    /// The heights the error is measured against (`super::reference`).
    pub reference: &'a [f64],
    /// T(V) of every sample.
    pub thresholds: &'a [f64],
    pub origin: [f64; 2],
    pub spacing: [f64; 2],
}

/// Fills `mesh` from the live rectangles; `pinned` marks the border
/// vertices to keep. Unpinned border corners that could not be removed are
/// pushed (as sample indices) to `kept`.
pub fn triangulate(
    layout: &Layout,
    rects: &[Rect],
    pinned: &[bool],
    sc: &mut Scratch,
    mut mesh: Mesh,
    kept: &mut Vec<u32>,
) {
    let Layout {
        rows,
        cols,
        heights,
        origin,
        spacing,
        ..
    } = *layout;
    sc.used.clear();
    sc.used.extend_from_slice(pinned);
    for r in rects.iter().filter(|r| r.alive) {
        for (x, y) in [
            (r.col0, r.row0),
            (r.col1, r.row0),
            (r.col0, r.row1),
            (r.col1, r.row1),
        ] {
            sc.used[y as usize * cols + x as usize] = true;
        }
    }
    let Scratch {
        used,
        vertex_of,
        perimeter,
        incident,
        added,
        work,
        remap,
        ..
    } = sc;
    mesh.positions.clear();
    mesh.triangles.clear();
    mesh.grid.clear();
    vertex_of.clear();
    vertex_of.resize(rows * cols, u32::MAX);
    incident.clear();
    added.clear();
    for y in 0..rows {
        for x in 0..cols {
            let i = y * cols + x;
            if used[i] {
                vertex_of[i] = mesh.positions.len() as u32;
                mesh.positions.push([
                    origin[0] + x as f64 * spacing[0],
                    origin[1] + y as f64 * spacing[1],
                    heights[i],
                ]);
                mesh.grid.push([x as f64, y as f64]);
            }
        }
    }
    for r in rects.iter().filter(|r| r.alive) {
        let (x0, y0, x1, y1) = (
            r.col0 as usize,
            r.row0 as usize,
            r.col1 as usize,
            r.row1 as usize,
        );
        // Perimeter, counter-clockwise in (col, row): south, east, north, west.
        perimeter.clear();
        let visit = |x: usize, y: usize, perimeter: &mut Vec<u32>| {
            let v = vertex_of[y * cols + x];
            if v != u32::MAX {
                perimeter.push(v);
            }
        };
        let mut corner = [0usize; 4]; // perimeter index of p00, p10, p11, p01
        for x in x0..x1 {
            visit(x, y0, perimeter);
        }
        corner[1] = perimeter.len();
        for y in y0..y1 {
            visit(x1, y, perimeter);
        }
        corner[2] = perimeter.len();
        for x in (x0 + 1..=x1).rev() {
            visit(x, y1, perimeter);
        }
        corner[3] = perimeter.len();
        for y in (y0 + 1..=y1).rev() {
            visit(x0, y, perimeter);
        }
        let n = perimeter.len();
        let v = |x: usize, y: usize| vertex_of[y * cols + x];
        // Intermediate vertices on the south, east, north and west sides.
        let south = corner[1] - 1;
        let east = corner[2] - corner[1] - 1;
        let north = corner[3] - corner[2] - 1;
        let west = n - corner[3] - 1;
        if n == 4 {
            mesh.triangles.push([v(x0, y0), v(x1, y0), v(x1, y1)]);
            mesh.triangles.push([v(x0, y0), v(x1, y1), v(x0, y1)]);
        } else if !((south == 0 && west == 0 || east == 0 && north == 0)
            && corner_fan(layout, perimeter, corner, &mut mesh))
            && !clip_rectangle(layout, perimeter, work, &mut mesh)
        {
            // Neither fits within T: from the centre (n triangles); the
            // caller's check splits the rectangle if this does not fit.
            let centre = mesh.positions.len() as u32;
            let (cx, cy) = (0.5 * (x0 + x1) as f64, 0.5 * (y0 + y1) as f64);
            let hc = 0.5 * (heights[y0 * cols + x0] + heights[y1 * cols + x1]);
            mesh.positions
                .push([origin[0] + cx * spacing[0], origin[1] + cy * spacing[1], hc]);
            mesh.grid.push([cx, cy]);
            for k in 0..n {
                mesh.triangles
                    .push([centre, perimeter[k], perimeter[(k + 1) % n]]);
            }
        }
    }

    // Border corners the border pass did not pin: remove them. `remap`
    // marks them (by vertex) for the scan over the triangles.
    remap.clear();
    remap.resize(mesh.positions.len(), 0);
    let mut any = false;
    let border = (1..cols - 1)
        .flat_map(|x| [x, (rows - 1) * cols + x])
        .chain((1..rows - 1).flat_map(|y| [y * cols, y * cols + cols - 1]));
    for i in border {
        if used[i] && !pinned[i] {
            remap[vertex_of[i] as usize] = 1;
            any = true;
        }
    }
    if any {
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for &v in tri {
                if remap[v as usize] == 1 {
                    incident.push((v, t as u32));
                }
            }
        }
    }
    incident.sort_unstable();
    let mut k = 0;
    while k < sc.incident.len() {
        let v = sc.incident[k].0;
        if !remove_vertex(v, layout, mesh.triangles, mesh.positions, mesh.grid, sc) {
            let [x, y] = mesh.grid[v as usize];
            kept.push(y as u32 * cols as u32 + x as u32);
        }
        k = sc.incident.partition_point(|&(w, _)| w <= v);
    }

    // Drop dead triangles and unreferenced vertices; orient.
    let remap = &mut sc.remap;
    remap.clear();
    remap.resize(mesh.positions.len(), u32::MAX);
    for t in mesh.triangles.iter().filter(|&&t| t != DEAD) {
        for &v in t {
            remap[v as usize] = 0;
        }
    }
    let mut next = 0;
    for (v, slot) in remap.iter_mut().enumerate() {
        if *slot == 0 {
            *slot = next;
            mesh.positions[next as usize] = mesh.positions[v];
            mesh.grid[next as usize] = mesh.grid[v];
            next += 1;
        }
    }
    mesh.positions.truncate(next as usize);
    mesh.grid.truncate(next as usize);
    let mirrored = (spacing[0] < 0.0) != (spacing[1] < 0.0);
    mesh.triangles.retain(|&t| t != DEAD);
    for t in mesh.triangles.iter_mut() {
        let m = t.map(|v| remap[v as usize]);
        *t = if mirrored { [m[0], m[2], m[1]] } else { m };
    }
}
