// OpenCL port of candidates.wgsl: deficit-0 vertices by atomic append;
// under every-vertex (3.6) every vertex below n, at its own index.

__kernel void clear_candidates(DECODE_ARGS) {
    uint i = get_global_id(0);
    if (i < PARAMS.sort_len) cand[i] = NONE;
    if (i == 0u) counts[COUNT_CANDIDATES] = 0u;
}

__kernel void append_candidates(DECODE_ARGS) {
    uint v = get_global_id(0);
    bool every = EVERY_VERTEX;
    if (v >= PARAMS.n || (!every && deficit[v] != 0u)) return;
    uint at = atomic_inc(&counts[COUNT_CANDIDATES]);
    if (every) at = v;
    if (at < PARAMS.sort_len) cand[at] = v;
}
