// Twin of select.wgsl.

inline bool key_less(uint2 a, uint2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); }

__kernel void admit(__global const Params *P, __global const Best *best, __global const uint *blocked,
                    __global uint2 *keys, __global const uint *list) {
    uint i = get_global_id(0);
    if (i >= P->list_len) return;
    uint v = list[i];
    Best b = best[v];
    uint2 key = (uint2)(NONE, NONE);
    if (blocked[v] == 0u && b.other != NONE && b.error <= P->threshold && best[b.other].other == v) {
        uint low = min(v, b.other);
        key = (uint2)(best[low].key, low);
    }
    keys[v] = key;
}

bool local_minimum(Topo t, __global const uint2 *keys, uint p, uint c, uint2 key) {
    for (uint s = 0u; s < 2u; s++) {
        uint w = s == 0u ? p : c;
        uint first = fan_first(t, w);
        uint k = first;
        for (uint i = 0; i < FAN_GUARD && k != NONE; i++) {
            uint x = cv(t, next_c(k)), y = cv(t, prev_c(k));
            if (x != p && x != c && key_less(keys[x], key)) return false;
            if (y != p && y != c && key_less(keys[y], key)) return false;
            k = fan_step(t, k, first);
        }
    }
    return true;
}

__kernel void local_min(__global const Params *P, __global const uint2 *corners,
                        __global const uint *corner_of, __global const Best *best,
                        __global const uint2 *keys, __global const uint *list,
                        __global Winner *winners, __global uint *counter) {
    uint i = get_global_id(0);
    if (i >= P->list_len) return;
    Topo t = {corners, corner_of, 0, P->metric.xyz};
    uint v = list[i];
    uint2 key = keys[v];
    Best b = best[v];
    if (key.y == NONE || v >= b.other || !local_minimum(t, keys, v, b.other, key)) return;
    uint slot = atomic_inc(counter);
    Winner w = {v, b.other, b.error, b.key, b.tx, b.ty, b.tz};
    winners[slot] = w;
}

void block_fan(Topo t, __global uint *blocked, uint w) {
    blocked[w] = 1u;
    uint first = fan_first(t, w);
    uint k = first;
    for (uint i = 0; i < FAN_GUARD && k != NONE; i++) {
        blocked[cv(t, next_c(k))] = 1u;
        blocked[cv(t, prev_c(k))] = 1u;
        k = fan_step(t, k, first);
    }
}

__kernel void block(__global const Params *P, __global const uint2 *corners,
                    __global const uint *corner_of, __global uint *blocked,
                    __global const Winner *winners) {
    uint i = get_global_id(0);
    if (i >= P->list_len) return;
    Topo t = {corners, corner_of, 0, P->metric.xyz};
    Winner w = winners[P->mode + i];
    block_fan(t, blocked, w.v);
    block_fan(t, blocked, w.other);
}

__kernel void live_errors(__global const Params *P, __global const Best *best,
                          __global const uint *list, __global uint *errors) {
    uint i = get_global_id(0);
    if (i >= P->list_len) return;
    Best b = best[list[i]];
    errors[i] = b.other != NONE ? as_uint(b.error) : NONE;
}
