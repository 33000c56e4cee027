// Step 3 of a round (SPEC §7.1, §7.4, §7.5): the splits, all in parallel.
// The independence rule (§7.2) makes every split touch a disjoint part of
// the corner table (R's wedges, the opposite entries facing them) and of the
// vertex arrays (R, C); only a wing's deficit can be shared by two splits,
// hence the atomics on `deficit` and `uses`. Under the schedule every-vertex
// (3.6) `deficit` holds valences capped at 255: a wing's grows by one, P's
// and C's are the record's, and none of the deficit checks apply (§7.5).
//
// ring_check  (per split) canonical ring walk exactly as decoder-core's
//             ring.rs, the checks of §7.2-§7.5 in the reference's order,
//             triangles added -> scan (prefix_number.wgsl numbers them);
// wing_check  (per split) wings shared by several splits of the round
//             (split-valences), and the level's triangle limit, once the
//             triangle numbers are known;
// apply       (per split) corner rewrites and new triangles with their
//             opposite links exactly as decoder-core's split.rs, positions,
//             deficits or valences; skipped entirely when any check failed;
// finish      clears the marks and advances the vertex and triangle counts.

@group(0) @binding(2) var<storage, read_write> positions: array<u32>;
@group(0) @binding(3) var<storage, read_write> corners: array<u32>;
@group(0) @binding(4) var<storage, read_write> opposite: array<u32>;
@group(0) @binding(5) var<storage, read_write> vertex_corner: array<u32>;
@group(0) @binding(6) var<storage, read_write> deficit: array<atomic<u32>>;
@group(0) @binding(7) var<storage, read_write> mark: array<u32>;
@group(0) @binding(8) var<storage, read_write> uses: array<atomic<u32>>;
@group(0) @binding(11) var<storage, read_write> records: array<Record>;
@group(0) @binding(12) var<storage, read_write> scan: array<u32>;
@group(0) @binding(13) var<storage, read_write> splits: array<u32>;

// layout.rs: GpuRecord. Positions are final (SPEC §7.4 resolved on the host
// in phase 1).
struct Record {
    offset: u32,
    distance: u32,
    config: u32,
    deficit_p: u32,
    deficit_c: u32,
    px: u32,
    py: u32,
    pz: u32,
    cx: u32,
    cy: u32,
    cz: u32,
    _pad: u32,
}

// Words per split in `splits` (layout.rs: SPLIT_WORDS):
// 0 R, 1 canonical start corner, 2 ring length | boundary << 16,
// 3 wing a, 4 wing b, 5 triangles added, 6 checks passed.
const SPLIT_WORDS: u32 = 8u;
const MAX_RING: u32 = 255u;

// The next wedge counter-clockwise around the same centre, or NONE at a
// boundary gap.
fn wedge_step(c: u32) -> u32 {
    let o = opposite[next_corner(c)];
    if o == NONE {
        return NONE;
    }
    return next_corner(o);
}

// Iterates the canonical ring: wedge i's corner of R (NONE when virtual) and
// r_i (NONE for the ghost). A boundary ring is [ghost, u_1 .. u_{m+1}] with
// wedge 0 and wedge k-1 virtual; `start` is the corner of the first real
// wedge (boundary) or of W_0 (interior).
struct RingCursor {
    boundary: bool,
    k: u32,
    c: u32,
    last_real: u32,
}

fn wedge_at(cur: ptr<function, RingCursor>, i: u32) -> vec2<u32> {
    let first_real = select(0u, 1u, (*cur).boundary);
    let last_real = select((*cur).k - 1u, (*cur).k - 2u, (*cur).boundary);
    if i >= first_real && i <= last_real {
        let wc = (*cur).c;
        (*cur).last_real = wc;
        if i < last_real {
            (*cur).c = wedge_step(wc);
        }
        return vec2<u32>(wc, corners[next_corner(wc)]);
    }
    if (*cur).boundary && i == (*cur).k - 1u {
        return vec2<u32>(NONE, corners[prev_corner((*cur).last_real)]);
    }
    return vec2<u32>(NONE, NONE);
}

fn load_deficit(v: u32) -> u32 {
    return atomicLoad(&deficit[v]);
}

@compute @workgroup_size(256)
fn ring_check(@builtin(global_invocation_id) gid: vec3<u32>) {
    let j = gid.x;
    if j >= params.splits {
        return;
    }
    let base = j * SPLIT_WORDS;
    let key = j + 1u;
    scan[j] = 0u;
    splits[base + 6u] = 0u;
    if atomicLoad(&counts[COUNT_ERROR]) < 8u {
        return; // the round's counts are already wrong
    }
    let r = splits[base];

    // Counter-clockwise walk from any corner of R (ring.rs: MeshState::ring);
    // an interior ring starts at its smallest neighbour.
    let any_corner = vertex_corner[r];
    var c = any_corner;
    var k = 0u;
    var start = c;
    var smallest = NONE;
    var boundary = false;
    loop {
        if k == MAX_RING {
            report(key, ERR_RING_TOO_LONG);
            return;
        }
        let v = corners[next_corner(c)];
        if v < smallest {
            smallest = v;
            start = c;
        }
        k = k + 1u;
        let s = wedge_step(c);
        if s == NONE {
            boundary = true;
            break;
        }
        c = s;
        if c == any_corner {
            break;
        }
    }
    if boundary {
        // ring.rs: boundary_ring. Clockwise to the first wedge after the gap,
        // then count the open fan's m wedges: k = m + 2 (ghost first).
        var first = any_corner;
        var steps = 0u;
        loop {
            let o = opposite[prev_corner(first)];
            if o == NONE {
                break;
            }
            first = prev_corner(o);
            steps = steps + 1u;
            if steps == MAX_RING {
                report(key, ERR_RING_TOO_LONG);
                return;
            }
        }
        var m = 1u;
        var w = first;
        loop {
            if m + 1u >= MAX_RING {
                report(key, ERR_RING_TOO_LONG);
                return;
            }
            let s = wedge_step(w);
            if s == NONE {
                break;
            }
            w = s;
            m = m + 1u;
        }
        start = first;
        k = m + 2u;
    }

    let rec = records[j];
    let o = rec.offset;
    let d = rec.distance;
    // One pass over the ring: the independence rule (§7.2; at round start
    // "created in this round" cannot occur, a flagged neighbour is marked)
    // and the wings a = r_o, b = r_{o+d}.
    var cur = RingCursor(boundary, k, start, NONE);
    var dependent = false;
    var a = NONE;
    var b = NONE;
    for (var i = 0u; i < k; i = i + 1u) {
        let v = wedge_at(&cur, i).y;
        if v != NONE && mark[v] != 0u {
            dependent = true;
        }
        if i == o {
            a = v;
        }
        if i == o + d {
            b = v;
        }
    }
    if dependent {
        report(key, ERR_ADJACENT_FLAGS);
        return;
    }
    if d == 0u || o + d >= k {
        report(key, ERR_RING_OFFSET);
        return;
    }
    if params.pos_limit != 0u {
        let hi = max(max(max(rec.px, rec.py), max(rec.pz, rec.cx)), max(rec.cy, rec.cz));
        if hi >= params.pos_limit {
            report(key, ERR_POSITION);
            return;
        }
    }
    var len_p = d;
    if rec.config != 0u {
        len_p = k - d;
    }
    let len_c = k - len_p;
    // §7.5: deficits only; every-vertex (3.6) has no valence to overflow.
    let every = every_vertex();
    if !every && ((rec.deficit_p != LEAF && len_p + 2u + rec.deficit_p > MAX_RING)
        || (rec.deficit_c != LEAF && len_c + 2u + rec.deficit_c > MAX_RING)) {
        report(key, ERR_VALENCE);
        return;
    }
    if !every && ((a != NONE && load_deficit(a) == 0u) || (b != NONE && load_deficit(b) == 0u)) {
        report(key, ERR_VALENCE);
        return;
    }
    let added = u32(a != NONE) + u32(b != NONE);
    if added == 0u {
        report(key, ERR_RING_OFFSET); // unreachable: a ring holds one ghost at most
        return;
    }
    splits[base + 1u] = start;
    splits[base + 2u] = k | (u32(boundary) << 16u);
    splits[base + 3u] = a;
    splits[base + 4u] = b;
    splits[base + 5u] = added;
    splits[base + 6u] = 1u;
    scan[j] = added;
    if every {
        return; // no wing deficit to share out (wing_check)
    }
    for (var w = 0u; w < 2u; w = w + 1u) {
        let x = select(a, b, w == 1u);
        if x != NONE && load_deficit(x) != LEAF {
            atomicAdd(&uses[x], 1u);
        }
    }
}

// After the triangle scan: a wing used by more splits than its deficit
// allows (decoder-core fails at the split that takes it below 0; here every
// sharer reports and the smallest index wins; split-valences only), and the
// triangle limit.
@compute @workgroup_size(256)
fn wing_check(@builtin(global_invocation_id) gid: vec3<u32>) {
    let j = gid.x;
    let base = j * SPLIT_WORDS;
    if j >= params.splits || splits[base + 6u] == 0u {
        return;
    }
    let key = j + 1u;
    // every-vertex (3.6): no deficit to exhaust, nothing counted in `uses`.
    for (var w = 0u; w < 2u && !every_vertex(); w = w + 1u) {
        let x = splits[base + 3u + w];
        if x != NONE {
            let dx = load_deficit(x);
            if dx != LEAF && atomicLoad(&uses[x]) > dx {
                report(key, ERR_VALENCE);
                return;
            }
        }
    }
    let t = atomicLoad(&counts[COUNT_T]);
    if t + scan[j] + splits[base + 5u] > params.tri_limit {
        report(key, ERR_TRIANGLE_LIMIT);
    }
}

fn link(x: u32, y: u32) {
    opposite[x] = y;
    if y != NONE {
        opposite[y] = x;
    }
}

fn facing_next(c: u32) -> u32 {
    if c == NONE {
        return NONE;
    }
    return next_corner(c);
}

fn facing_prev(c: u32) -> u32 {
    if c == NONE {
        return NONE;
    }
    return prev_corner(c);
}

@compute @workgroup_size(256)
fn apply(@builtin(global_invocation_id) gid: vec3<u32>) {
    let j = gid.x;
    if j >= params.splits || atomicLoad(&counts[COUNT_ERROR]) != NONE {
        return;
    }
    let base = j * SPLIT_WORDS;
    let r = splits[base];
    let start = splits[base + 1u];
    let k = splits[base + 2u] & 0xffffu;
    let boundary = (splits[base + 2u] >> 16u) != 0u;
    let a = splits[base + 3u];
    let b = splits[base + 4u];
    let rec = records[j];
    let o = rec.offset;
    let d = rec.distance;
    let cv = params.n + j;
    let config = rec.config != 0u;
    // X owns arc 1 (from a to b), Y arc 2 (split.rs).
    let x = select(r, cv, config);
    let y = select(cv, r, config);
    let c_arc_start = select(o + d, o, config);
    let len_c = select(k - d, d, config);

    // Rewrite R to C in C's arc, and keep the wedges around the wings; the
    // opposite links change only after the walk, which reads them.
    var cur = RingCursor(boundary, k, start, NONE);
    var before_a = NONE;
    var after_a = NONE;
    var before_b = NONE;
    var after_b = NONE;
    let i_before_a = (o + k - 1u) % k;
    for (var i = 0u; i < k; i = i + 1u) {
        let wc = wedge_at(&cur, i).x;
        if wc != NONE && (i + k - c_arc_start) % k < len_c {
            corners[wc] = cv;
        }
        if i == i_before_a {
            before_a = wc;
        }
        if i == o {
            after_a = wc;
        }
        if i == o + d - 1u {
            before_b = wc;
        }
        if i == o + d {
            after_b = wc;
        }
    }

    var t = atomicLoad(&counts[COUNT_T]) + scan[j];
    var ta = NONE;
    var tb = NONE;
    if a != NONE {
        ta = t;
        t = t + 1u;
    }
    if b != NONE {
        tb = t;
    }
    if ta != NONE {
        corners[3u * ta] = x;
        corners[3u * ta + 1u] = y;
        corners[3u * ta + 2u] = a;
        link(3u * ta, facing_next(before_a));
        link(3u * ta + 1u, facing_prev(after_a));
    }
    if tb != NONE {
        corners[3u * tb] = y;
        corners[3u * tb + 1u] = x;
        corners[3u * tb + 2u] = b;
        link(3u * tb, facing_next(before_b));
        link(3u * tb + 1u, facing_prev(after_b));
    }
    if ta != NONE && tb != NONE {
        link(3u * ta + 2u, 3u * tb + 2u);
    } else if ta != NONE {
        opposite[3u * ta + 2u] = NONE;
    } else {
        opposite[3u * tb + 2u] = NONE;
    }
    if ta != NONE {
        vertex_corner[x] = 3u * ta;
        vertex_corner[y] = 3u * ta + 1u;
    } else {
        vertex_corner[x] = 3u * tb + 1u;
        vertex_corner[y] = 3u * tb;
    }
    for (var w = 0u; w < 2u; w = w + 1u) {
        let wing = select(a, b, w == 1u);
        if wing == NONE {
            continue;
        }
        if every_vertex() {
            // §7.5 (3.6): the wing gains a neighbour, its valence saturates
            // at 255. Splits sharing the wing each add, then clamp: the last
            // operation on the word is a clamp, after every add.
            atomicAdd(&deficit[wing], 1u);
            atomicMin(&deficit[wing], BYTE_MAX);
        } else if load_deficit(wing) != LEAF {
            atomicSub(&deficit[wing], 1u);
        }
    }
    positions[3u * r] = rec.px;
    positions[3u * r + 1u] = rec.py;
    positions[3u * r + 2u] = rec.pz;
    positions[3u * cv] = rec.cx;
    positions[3u * cv + 1u] = rec.cy;
    positions[3u * cv + 2u] = rec.cz;
    // every-vertex: the record holds P's and C's valences, capped (§7.4).
    atomicStore(&deficit[r], rec.deficit_p);
    atomicStore(&deficit[cv], rec.deficit_c);
}

// Clears the round's marks; one thread advances the counts (arg0: the slot
// of the triangle total in `scan`).
@compute @workgroup_size(256)
fn finish(@builtin(global_invocation_id) gid: vec3<u32>) {
    let j = gid.x;
    if j == 0u && atomicLoad(&counts[COUNT_ERROR]) == NONE {
        atomicAdd(&counts[COUNT_V], params.splits);
        atomicAdd(&counts[COUNT_T], scan[params.arg0]);
    }
    if j >= params.splits {
        return;
    }
    let base = j * SPLIT_WORDS;
    mark[splits[base]] = 0u;
    if splits[base + 6u] != 0u {
        for (var w = 0u; w < 2u; w = w + 1u) {
            let x = splits[base + 3u + w];
            if x != NONE {
                atomicStore(&uses[x], 0u);
            }
        }
    }
}
