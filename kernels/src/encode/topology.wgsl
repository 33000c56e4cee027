// Read access to the corner table and the vertices, and fan walks without
// local arrays (a kernel keeps no per-vertex lists).

// Per corner: (vertex, opposite corner), NONE for dead corners / boundaries.
@group(0) @binding(1) var<storage, read> corners: array<vec2<u32>>;
// One live corner per vertex, NONE for removed vertices.
@group(0) @binding(2) var<storage, read> corner_of: array<u32>;
// Quantized position (xyz) and flags (w: bit 0 alive, bit 1 boundary).
@group(0) @binding(3) var<storage, read> vpos: array<vec4<u32>>;

// Bounds every fan walk so corrupted topology can never hang a kernel.
const FAN_GUARD: u32 = 1024u;
const ALIVE: u32 = 1u;
const BOUNDARY: u32 = 2u;

fn next_c(c: u32) -> u32 {
    if c % 3u == 2u {
        return c - 2u;
    }
    return c + 1u;
}

fn prev_c(c: u32) -> u32 {
    if c % 3u == 0u {
        return c + 2u;
    }
    return c - 1u;
}

fn cv(c: u32) -> u32 {
    return corners[c].x;
}

fn co(c: u32) -> u32 {
    return corners[c].y;
}

// First corner of v's fan: on an open fan the corner whose edge (prev, v) is
// a boundary edge, so walking forward from it visits the whole fan.
fn fan_first(v: u32) -> u32 {
    let start = corner_of[v];
    if start == NONE {
        return NONE;
    }
    var c = start;
    for (var i = 0u; i < FAN_GUARD; i++) {
        let o = co(next_c(c));
        if o == NONE {
            return c;
        }
        let back = next_c(o);
        if back == start {
            return start;
        }
        c = back;
    }
    return start;
}

fn fan_open(first: u32) -> bool {
    return co(next_c(first)) == NONE;
}

// The corner after c around the same vertex, NONE past the end of the fan.
fn fan_step(c: u32, first: u32) -> u32 {
    let o = co(prev_c(c));
    if o == NONE {
        return NONE;
    }
    let c2 = prev_c(o);
    if c2 == first {
        return NONE;
    }
    return c2;
}

// Neighbour count with the boundary ghost, as the CPU's `neighbours`.
fn valence(w: u32) -> u32 {
    let first = fan_first(w);
    if first == NONE {
        return 0u;
    }
    var count = 0u;
    var k = first;
    for (var i = 0u; i < FAN_GUARD && k != NONE; i++) {
        count += 1u;
        k = fan_step(k, first);
    }
    if fan_open(first) {
        count += 2u;
    }
    return count;
}

// Whether x (NONE: the ghost) is a neighbour of w.
fn is_neighbour(w: u32, x: u32) -> bool {
    let first = fan_first(w);
    if first == NONE {
        return false;
    }
    let open = fan_open(first);
    if x == NONE {
        return open;
    }
    if open && cv(prev_c(first)) == x {
        return true;
    }
    var k = first;
    for (var i = 0u; i < FAN_GUARD && k != NONE; i++) {
        if cv(next_c(k)) == x {
            return true;
        }
        k = fan_step(k, first);
    }
    return false;
}

// Metric offset of grid point g from grid point origin: integer difference
// first, so frames local to a vertex keep f32 precision on large meshes.
fn offset(g: vec3<u32>, origin: vec3<u32>) -> vec3<f32> {
    return vec3<f32>(vec3<i32>(g) - vec3<i32>(origin)) * params.metric.xyz;
}

fn rel(v: u32, origin: vec3<u32>) -> vec3<f32> {
    return offset(vpos[v].xyz, origin);
}
