// Step a of §2: every listed vertex picks its best valid incident edge:
// lowest quadric error at the merged position (optimal with the singular
// fallback, or constrained to P, C, midpoint), ties broken by the sub-grid
// rule of Fig. 2, then the other end's coordinates, then its id; validity as
// the CPU's `check_collapse` (link condition with the ghost, valences,
// wings, no folded triangle). Edges are evaluated in the frame of their lower
// endpoint, so both endpoints compute identical results.

struct Best {
    other: u32,
    error: f32,
    key: u32,
    tx: u32,
    ty: u32,
    tz: u32,
}

@group(0) @binding(5) var<storage, read_write> best: array<Best>;
@group(0) @binding(6) var<storage, read> blocked: array<u32>;
@group(0) @binding(8) var<storage, read> list: array<u32>;

// Candidates kept per vertex; neighbours past this are not considered (the
// choice stays valid, only possibly not the cheapest).
const MAX_CANDIDATES: u32 = 32u;
const CONSTRAINED: u32 = 1u;
const LOCKED: u32 = 2u;
const HUGE: f32 = 3.4e38;

struct Eval {
    ok: bool,
    dest: vec3<u32>,
    error: f32,
}

fn grid_point(origin: vec3<u32>, x: vec3<f32>) -> vec3<u32> {
    let g = vec3<i32>(origin) + vec3<i32>(round(x / params.metric.xyz));
    return vec3<u32>(clamp(g, vec3<i32>(0), vec3<i32>(i32(params.top))));
}

// Where the collapse of edge (v, u) puts the merged vertex and its error,
// as the CPU's `evaluate` and `collapse_target`.
fn evaluate(v: u32, u: u32) -> Eval {
    let p = min(v, u);
    let c = max(v, u);
    let pp = vpos[p];
    let pc = vpos[c];
    let d = offset(pc.xyz, pp.xyz);
    let q = quad_add(quad_load(p), quad_shift(quad_load(c), d));
    var t = pp.xyz;
    let bp = (pp.w & BOUNDARY) != 0u;
    let bc = (pc.w & BOUNDARY) != 0u;
    if (params.flags & LOCKED) != 0u && (bp || bc) {
        if bp && bc {
            return Eval(false, t, HUGE);
        }
        if !bp {
            t = pc.xyz;
        }
    } else if (params.flags & CONSTRAINED) != 0u {
        let mid = vec3<u32>(vec3<i32>(pp.xyz) + ((vec3<i32>(pc.xyz) - vec3<i32>(pp.xyz)) >> vec3<u32>(1u)));
        var e = quad_error(q, vec3<f32>(0.0));
        let ec = quad_error(q, d);
        if ec < e {
            t = pc.xyz;
            e = ec;
        }
        if quad_error(q, offset(mid, pp.xyz)) < e {
            t = mid;
        }
    } else {
        var x = vec3<f32>(0.0);
        var e = quad_error(q, x);
        let ec = quad_error(q, d);
        if ec < e {
            x = d;
            e = ec;
        }
        let mid = 0.5 * d;
        let em = quad_error(q, mid);
        if em < e {
            x = mid;
            e = em;
        }
        let m = quad_minimizer(q);
        if m.w != 0.0 && length(m.xyz - mid) <= 2.0 * length(d) && quad_error(q, m.xyz) < e {
            x = m.xyz;
        }
        t = grid_point(pp.xyz, x);
    }
    let error = quad_error(q, offset(t, pp.xyz));
    if error != error || error >= HUGE {
        return Eval(false, t, HUGE);
    }
    return Eval(true, t, error);
}

// Every triangle around v not holding `other` keeps a non-degenerate normal
// within 90 degrees of its old one when v moves to t (all in p's frame).
// Slightly stricter than the CPU (f32), so the CPU's own check at apply
// time rarely disagrees. A triangle that had no normal (zero area) may stay
// so, as on the CPU (coarsely quantized scans have thousands: refusing them
// stalled the steps), but refuses to gain one, where the CPU holds the
// normal it gains to the fan's normal: on such input the GPU backends offer
// somewhat fewer collapses than the CPU makes.
fn keeps_orientation(v: u32, other: u32, t: vec3<f32>, origin: vec3<u32>) -> bool {
    let pv = rel(v, origin);
    let first = fan_first(v);
    var k = first;
    for (var i = 0u; i < FAN_GUARD && k != NONE; i++) {
        let n1 = cv(next_c(k));
        let n2 = cv(prev_c(k));
        if n1 != other && n2 != other {
            let q1 = rel(n1, origin);
            let q2 = rel(n2, origin);
            let d1 = q1 - pv;
            let d2 = q2 - pv;
            let old = cross(d1, d2);
            let os = dot(d1, d1) + dot(d2, d2);
            let e1 = q1 - t;
            let e2 = q2 - t;
            let moved = cross(e1, e2);
            let s = dot(e1, e1) + dot(e2, e2);
            let nn = dot(moved, moved);
            let stays_flat = dot(old, old) <= 1e-10 * os * os && nn <= 1e-10 * s * s;
            if !stays_flat
                && (dot(old, moved) <= 1e-5 * sqrt(dot(old, old) * nn) || nn <= 1e-10 * s * s) {
                return false;
            }
        }
        k = fan_step(k, first);
    }
    return true;
}

// The CPU's `check_collapse` for p < c, merged vertex at grid point t.
fn collapse_ok(p: u32, c: u32, t: vec3<u32>) -> bool {
    let fp = fan_first(p);
    if fp == NONE {
        return false;
    }
    var left = NONE;
    var right = NONE;
    var p_side = 0u;
    var both_sides = 0u;
    var k = fp;
    for (var i = 0u; i < FAN_GUARD && k != NONE; i++) {
        let x = cv(next_c(k));
        if x == c {
            left = k;
        } else {
            p_side += 1u;
            if is_neighbour(c, x) {
                both_sides += 1u;
            }
        }
        if cv(prev_c(k)) == c {
            right = k;
        }
        k = fan_step(k, fp);
    }
    if left == NONE && right == NONE {
        return false;
    }
    if fan_open(fp) {
        // The open fan's far end and the ghost.
        let x = cv(prev_c(fp));
        if x != c {
            p_side += 1u;
            if is_neighbour(c, x) {
                both_sides += 1u;
            }
        }
        p_side += 1u;
        if is_neighbour(c, NONE) {
            both_sides += 1u;
        }
    }
    if both_sides != 2u {
        return false;
    }
    // c's neighbours other than p.
    let c_side = valence(c) - 1u;
    let union_count = p_side + c_side - both_sides;
    if union_count < 3u || union_count > params.max_valence {
        return false;
    }
    if left != NONE && valence(cv(prev_c(left))) < 4u {
        return false;
    }
    if right != NONE && valence(cv(next_c(right))) < 4u {
        return false;
    }
    let origin = vpos[p].xyz;
    let tm = offset(t, origin);
    return keeps_orientation(p, c, tm, origin) && keeps_orientation(c, p, tm, origin);
}

struct Cand {
    u: u32,
    key: u32,
    other_cell: u32,
    pos: vec3<u32>,
    error: f32,
    dest: vec3<u32>,
}

// Rank of Fig. 2: error key, same cell first, other end's coordinates, id.
fn ranks_before(a: Cand, b: Cand) -> bool {
    if a.key != b.key {
        return a.key < b.key;
    }
    if a.other_cell != b.other_cell {
        return a.other_cell < b.other_cell;
    }
    if a.pos.x != b.pos.x {
        return a.pos.x < b.pos.x;
    }
    if a.pos.y != b.pos.y {
        return a.pos.y < b.pos.y;
    }
    if a.pos.z != b.pos.z {
        return a.pos.z < b.pos.z;
    }
    return a.u < b.u;
}

fn cell_of(g: vec3<u32>) -> vec3<f32> {
    return floor(vec3<f32>(g) * params.metric.xyz / params.cell);
}

@compute @workgroup_size(256)
fn best_edge(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = flat_index(id, groups);
    if i >= params.list_len {
        return;
    }
    let v = list[i];
    let repick = params.mode == 1u;
    let own = vpos[v];
    if repick {
        // Pass > 0: only free vertices whose partner was taken choose again.
        let b = best[v];
        if (own.w & ALIVE) == 0u || blocked[v] != 0u || b.other == NONE || blocked[b.other] == 0u {
            return;
        }
    }
    var none = Best(NONE, HUGE, NONE, 0u, 0u, 0u);
    let first = fan_first(v);
    if (own.w & ALIVE) == 0u || first == NONE {
        best[v] = none;
        return;
    }
    var cands: array<Cand, MAX_CANDIDATES>;
    var count = 0u;
    var k = first;
    for (var j = 0u; j < FAN_GUARD && k != NONE; j++) {
        for (var side = 0u; side < 2u; side++) {
            var u = cv(next_c(k));
            if side == 1u {
                u = cv(prev_c(k));
            }
            var seen = repick && blocked[u] != 0u;
            for (var m = 0u; m < count; m++) {
                seen = seen || cands[m].u == u;
            }
            if seen || count == MAX_CANDIDATES {
                continue;
            }
            let e = evaluate(v, u);
            if !e.ok {
                continue;
            }
            var key = bitcast<u32>(e.error);
            if e.error <= params.flat_error {
                key = 0u;
            }
            var other_cell = 0u;
            if params.cell > 0.0 && any(cell_of(own.xyz) != cell_of(vpos[u].xyz)) {
                other_cell = 1u;
            }
            cands[count] = Cand(u, key, other_cell, vpos[u].xyz, e.error, e.dest);
            count += 1u;
        }
        k = fan_step(k, first);
    }
    // Cheapest first; the first valid one wins.
    var tried = 0u;
    for (var attempt = 0u; attempt < count; attempt++) {
        var pick = NONE;
        for (var m = 0u; m < count; m++) {
            if (tried & (1u << m)) == 0u && (pick == NONE || ranks_before(cands[m], cands[pick])) {
                pick = m;
            }
        }
        tried |= 1u << pick;
        let cand = cands[pick];
        if collapse_ok(min(v, cand.u), max(v, cand.u), cand.dest) {
            best[v] = Best(cand.u, cand.error, cand.key, cand.dest.x, cand.dest.y, cand.dest.z);
            return;
        }
    }
    best[v] = none;
}
