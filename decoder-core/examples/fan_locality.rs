//! How much the memory order of a mesh costs a decoder's fan walks.
//!
//! Decodes a stream, then walks the fan of every vertex (its corners, the
//! swing table and one coordinate of every neighbour, as a split's ring
//! walk does) in vertex order, under several numberings of the same final
//! mesh:
//!
//! * `canonical`: the stream's own (SPEC §7.3: each round appends its new
//!   vertices in the order of their parents' indices, and its triangles in
//!   split order);
//! * `rounds`: within each round's block of new vertices and triangles,
//!   Morton order of the positions (what numbering each round's splits by the
//!   Morton code of the split vertex would give);
//! * `groups N`: the same with blocks of N consecutive rounds;
//! * `morton`: one Morton order for all vertices, triangles by their
//!   smallest vertex;
//! * `morton v`: the same vertex order, triangles in the stream's order;
//! * `random`: a random vertex order, triangles by their smallest vertex.
//!
//! It prints the best of five walks in nanoseconds per fan. The mesh is the
//! same in every row; only its numbering differs.
//!
//! ```text
//! cargo run --release -p splitstream-decoder-core --features alloc --example fan_locality -- FILE.sps
//! ```

use std::collections::HashMap;
use std::time::Instant;

use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_decoder_core::{next, prev};

const NONE: u32 = u32::MAX;

/// A mesh with the adjacency decoder-core keeps (a swing table and a corner
/// per vertex).
struct Mesh {
    positions: Vec<[u32; 3]>,
    corners: Vec<u32>,
    swing: Vec<u32>,
    vertex_corner: Vec<u32>,
}

impl Mesh {
    fn new(positions: Vec<[u32; 3]>, triangles: &[[u32; 3]]) -> Mesh {
        let corners: Vec<u32> = triangles.iter().flatten().copied().collect();
        let mut corner_of_edge = HashMap::with_capacity(corners.len());
        for c in 0..corners.len() as u32 {
            corner_of_edge.insert((corners[c as usize], corners[next(c) as usize]), c);
        }
        // swing[c] = next(opposite(next(c))): the corner facing next(c) lies
        // across the edge prev(c) -> c, in the triangle holding c -> prev(c).
        let swing = (0..corners.len() as u32)
            .map(|c| {
                let (from, to) = (corners[c as usize], corners[prev(c) as usize]);
                corner_of_edge.get(&(from, to)).map_or(NONE, |&e| e)
            })
            .collect();
        let mut vertex_corner = vec![NONE; positions.len()];
        for (c, &v) in corners.iter().enumerate() {
            vertex_corner[v as usize] = c as u32;
        }
        Mesh {
            positions,
            corners,
            swing,
            vertex_corner,
        }
    }

    /// Walks every vertex's fan in vertex order; seconds and a checksum.
    fn walk_all(&self) -> (f64, u64) {
        let started = Instant::now();
        let mut sum = 0u64;
        for &start in &self.vertex_corner {
            let mut c = start;
            for _ in 0..256 {
                let u = self.corners[next(c) as usize];
                sum += self.positions[u as usize][0] as u64;
                c = self.swing[c as usize];
                if c == NONE || c == start {
                    break;
                }
            }
        }
        (started.elapsed().as_secs_f64(), sum)
    }
}

/// Morton code of the top 21 bits of each coordinate.
fn morton(p: [u32; 3], bits: u32) -> u64 {
    let shift = bits.saturating_sub(21);
    let mut key = 0u64;
    for b in 0..21 {
        for (axis, &x) in p.iter().enumerate() {
            key |= (((x >> shift) as u64 >> b) & 1) << (3 * b + axis as u32);
        }
    }
    key
}

/// The mesh with vertices sorted by `vertex_key` and triangles by
/// `triangle_key` (both given old ids).
fn renumbered(
    positions: &[[u32; 3]],
    triangles: &[[u32; 3]],
    vertex_key: impl Fn(usize) -> (u64, u64),
    triangle_key: impl Fn(usize, &[u32]) -> (u64, u64),
) -> Mesh {
    let mut order: Vec<u32> = (0..positions.len() as u32).collect();
    order.sort_by_key(|&v| vertex_key(v as usize));
    let mut new_id = vec![0u32; positions.len()];
    for (n, &v) in order.iter().enumerate() {
        new_id[v as usize] = n as u32;
    }
    let mut tri_order: Vec<u32> = (0..triangles.len() as u32).collect();
    tri_order.sort_by_key(|&t| triangle_key(t as usize, &new_id));
    let new_triangles: Vec<[u32; 3]> = tri_order
        .iter()
        .map(|&t| triangles[t as usize].map(|v| new_id[v as usize]))
        .collect();
    let new_positions = order.iter().map(|&v| positions[v as usize]).collect();
    Mesh::new(new_positions, &new_triangles)
}

fn main() {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: fan_locality FILE.sps");
        std::process::exit(2);
    };
    let stream = std::fs::read(&path).unwrap_or_else(|e| {
        eprintln!("error: {path}: {e}");
        std::process::exit(1)
    });
    let mut ws = OwnedWorkspace::for_stream(&stream).expect("valid stream");
    let mut decoder = ws.decoder(&stream).expect("valid stream");
    // Vertex and triangle counts after the seed and after every round.
    let (mut vertex_ends, mut triangle_ends) = (Vec::new(), Vec::new());
    while let Some(k) = decoder.next_level() {
        let range = decoder.level_range(k);
        let bytes = &stream[range.start as usize..range.end as usize];
        let mut level = decoder.begin_level(k, bytes).expect("valid level");
        if k == 0 {
            vertex_ends.push(level.state().vertex_count());
            triangle_ends.push(level.state().triangle_count());
        }
        while let Some(round) = level.next_round().expect("valid round") {
            vertex_ends.push(round.vertex_count);
            triangle_ends.push(round.triangle_count);
        }
    }
    let positions = decoder.positions().to_vec();
    let triangles = decoder.triangles().to_vec();
    let bits = decoder.header().bits as u32;
    let n = positions.len();
    println!(
        "{path}: {n} vertices, {} triangles, {} rounds",
        triangles.len(),
        vertex_ends.len() - 1
    );
    let block = |i: usize, ends: &[u32], group: usize| {
        (ends.partition_point(|&e| e as usize <= i) / group) as u64
    };
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let random: Vec<u64> = (0..n)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        })
        .collect();
    let smallest = |t: usize, new_id: &[u32]| {
        let m = triangles[t].iter().map(|&v| new_id[v as usize]).min();
        (m.unwrap_or(0) as u64, t as u64)
    };
    let by_groups = |group: usize| {
        renumbered(
            &positions,
            &triangles,
            |v| (block(v, &vertex_ends, group), morton(positions[v], bits)),
            |t, _| {
                let first = triangles[t][0] as usize;
                (
                    block(t, &triangle_ends, group),
                    morton(positions[first], bits),
                )
            },
        )
    };
    let layouts: Vec<(String, Mesh)> = vec![
        ("canonical".into(), Mesh::new(positions.clone(), &triangles)),
        ("rounds".into(), by_groups(1)),
        ("groups 8".into(), by_groups(8)),
        ("groups 30".into(), by_groups(30)),
        (
            "morton".into(),
            renumbered(
                &positions,
                &triangles,
                |v| (morton(positions[v], bits), v as u64),
                smallest,
            ),
        ),
        (
            "morton v".into(),
            renumbered(
                &positions,
                &triangles,
                |v| (morton(positions[v], bits), v as u64),
                |t, _| (0, t as u64),
            ),
        ),
        (
            "random".into(),
            renumbered(&positions, &triangles, |v| (random[v], v as u64), smallest),
        ),
    ];
    for (name, mesh) in &layouts {
        let mut best = f64::MAX;
        let mut checksum = 0;
        for _ in 0..5 {
            let (seconds, sum) = mesh.walk_all();
            best = best.min(seconds);
            checksum = sum;
        }
        println!(
            "{name:10} {:7.1} ns per fan (best of 5; checksum {checksum})",
            best * 1e9 / n as f64
        );
    }
}
