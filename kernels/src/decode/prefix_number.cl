// OpenCL port of prefix_number.wgsl: block scans and split numbering.

inline uint flag_bit(__global const uint *flags, uint i) {
    return (flags[i / 32u] >> (i % 32u)) & 1u;
}

__kernel void flags_to_values(DECODE_ARGS) {
    uint i = get_global_id(0);
    if (i < PARAMS.candidates) scan[i] = flag_bit(flags, i);
}

__kernel __attribute__((reqd_work_group_size(256, 1, 1)))
void scan_local(DECODE_ARGS) {
    __local uint partial[256];
    uint i = get_global_id(0), lid = get_local_id(0);
    uint base = PARAMS.arg0, len = PARAMS.arg1;
    uint x = i < len ? scan[base + i] : 0u;
    partial[lid] = x;
    barrier(CLK_LOCAL_MEM_FENCE);
    for (uint off = 1u; off < WG; off <<= 1) {
        uint add = lid >= off ? partial[lid - off] : 0u;
        barrier(CLK_LOCAL_MEM_FENCE);
        partial[lid] += add;
        barrier(CLK_LOCAL_MEM_FENCE);
    }
    if (i < len) scan[base + i] = partial[lid] - x;
    if (lid == WG - 1u) scan[PARAMS.arg2 + get_group_id(0)] = partial[lid];
}

__kernel void scan_add(DECODE_ARGS) {
    uint i = get_global_id(0);
    if (i < PARAMS.arg1) scan[PARAMS.arg0 + i] += scan[PARAMS.arg2 + i / WG];
}

__kernel void number_splits(DECODE_ARGS) {
    uint i = get_global_id(0);
    if (i == 0u) {
        if (counts[COUNT_CANDIDATES] != PARAMS.candidates || scan[PARAMS.arg0] != PARAMS.splits)
            report(counts, 0u, ERR_COUNT);
    }
    if (i >= PARAMS.candidates || flag_bit(flags, i) == 0u) return;
    uint j = scan[i], v = cand[i];
    // NONE when the host flags more candidates than the device found (the
    // count fault above): OpenCL has no bounds checks.
    if (j < PARAMS.splits && v < PARAMS.n) {
        splits[j * SPLIT_WORDS] = v;
        mark[v] = 1u;
    }
}
