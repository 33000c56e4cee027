// OpenCL port of candidates.wgsl: deficit-0 vertices by atomic append.

__kernel void clear_candidates(DECODE_ARGS) {
    uint i = get_global_id(0);
    if (i < PARAMS.sort_len) cand[i] = NONE;
    if (i == 0u) counts[COUNT_CANDIDATES] = 0u;
}

__kernel void append_candidates(DECODE_ARGS) {
    uint v = get_global_id(0);
    if (v >= PARAMS.n || deficit[v] != 0u) return;
    uint at = atomic_inc(&counts[COUNT_CANDIDATES]);
    if (at < PARAMS.sort_len) cand[at] = v;
}
