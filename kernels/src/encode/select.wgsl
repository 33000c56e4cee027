// Steps b and c of §2: reciprocal best pairs under the threshold S that are
// local minima of the (error, lower id) key among the requests of their
// 1-rings (index priority), appended to the winners list; then the block
// pass that takes the winners' 1-rings out of the following passes.

struct Best {
    other: u32,
    error: f32,
    key: u32,
    tx: u32,
    ty: u32,
    tz: u32,
}

struct Winner {
    v: u32,
    other: u32,
    error: f32,
    key: u32,
    tx: u32,
    ty: u32,
    tz: u32,
}

@group(0) @binding(5) var<storage, read> best: array<Best>;
@group(0) @binding(6) var<storage, read_write> blocked: array<u32>;
// Per vertex (error key, lower id) of its admitted pair; (NONE, NONE) if none.
@group(0) @binding(7) var<storage, read_write> keys: array<vec2<u32>>;
@group(0) @binding(8) var<storage, read> list: array<u32>;
@group(0) @binding(9) var<storage, read_write> winners: array<Winner>;
@group(0) @binding(10) var<storage, read_write> counter: array<atomic<u32>>;
// Per listed vertex, its request's error (f32 bits), NONE if it has none.
@group(0) @binding(12) var<storage, read_write> errors: array<u32>;

fn key_less(a: vec2<u32>, b: vec2<u32>) -> bool {
    return a.x < b.x || (a.x == b.x && a.y < b.y);
}

// Step b: reciprocal, under S, not blocked. One key per pair, taken from its
// lower endpoint, so that both endpoints compare alike.
@compute @workgroup_size(256)
fn admit(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = flat_index(id, groups);
    if i >= params.list_len {
        return;
    }
    let v = list[i];
    let b = best[v];
    var key = vec2<u32>(NONE, NONE);
    if blocked[v] == 0u && b.other != NONE && b.error <= params.threshold && best[b.other].other == v {
        let low = min(v, b.other);
        key = vec2<u32>(best[low].key, low);
    }
    keys[v] = key;
}

// No neighbour of p or c (other than p and c) requests a smaller key.
fn local_minimum(p: u32, c: u32, key: vec2<u32>) -> bool {
    for (var s = 0u; s < 2u; s++) {
        var w = p;
        if s == 1u {
            w = c;
        }
        let first = fan_first(w);
        var k = first;
        for (var i = 0u; i < FAN_GUARD && k != NONE; i++) {
            let x = cv(next_c(k));
            let y = cv(prev_c(k));
            if x != p && x != c && key_less(keys[x], key) {
                return false;
            }
            if y != p && y != c && key_less(keys[y], key) {
                return false;
            }
            k = fan_step(k, first);
        }
    }
    return true;
}

// Step c: the lower endpoint of each local-minimum pair appends the pair.
@compute @workgroup_size(256)
fn local_min(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = flat_index(id, groups);
    if i >= params.list_len {
        return;
    }
    let v = list[i];
    let key = keys[v];
    let b = best[v];
    if key.y == NONE || v >= b.other || !local_minimum(v, b.other, key) {
        return;
    }
    let slot = atomicAdd(&counter[0], 1u);
    winners[slot] = Winner(v, b.other, b.error, b.key, b.tx, b.ty, b.tz);
}

fn block_fan(w: u32) {
    blocked[w] = 1u;
    let first = fan_first(w);
    var k = first;
    for (var i = 0u; i < FAN_GUARD && k != NONE; i++) {
        blocked[cv(next_c(k))] = 1u;
        blocked[cv(prev_c(k))] = 1u;
        k = fan_step(k, first);
    }
}

// The winners[mode .. mode + list_len] of the last pass and their 1-rings
// leave the game (plain stores of 1: races are harmless).
@compute @workgroup_size(256)
fn block(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = flat_index(id, groups);
    if i >= params.list_len {
        return;
    }
    let w = winners[params.mode + i];
    block_fan(w.v);
    block_fan(w.other);
}

// The errors of the listed (live) vertices' requests, for the host's
// threshold S: the host reads these 4 bytes a live vertex instead of every
// vertex's 24-byte `Best`.
@compute @workgroup_size(256)
fn live_errors(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = flat_index(id, groups);
    if i >= params.list_len {
        return;
    }
    let b = best[list[i]];
    var error = NONE;
    if b.other != NONE {
        error = bitcast<u32>(b.error);
    }
    errors[i] = error;
}
