// OpenCL port of bitonic_sort.wgsl: the candidates sorted ascending.

inline void exchange_local(__local uint *tile, uint lid, uint i, uint k, uint j) {
    uint l = lid ^ j;
    if (l > lid) {
        bool ascending = (i & k) == 0u;
        uint a = tile[lid], b = tile[l];
        if ((a > b) == ascending && a != b) {
            tile[lid] = b;
            tile[l] = a;
        }
    }
}

__kernel __attribute__((reqd_work_group_size(256, 1, 1)))
void sort_blocks(DECODE_ARGS) {
    __local uint tile[256];
    uint i = get_global_id(0), lid = get_local_id(0);
    tile[lid] = cand[i];
    barrier(CLK_LOCAL_MEM_FENCE);
    for (uint k = 2u; k <= WG; k <<= 1) {
        for (uint j = k >> 1; j > 0u; j >>= 1) {
            exchange_local(tile, lid, i, k, j);
            barrier(CLK_LOCAL_MEM_FENCE);
        }
    }
    cand[i] = tile[lid];
}

__kernel void merge_global(DECODE_ARGS) {
    uint i = get_global_id(0), k = PARAMS.arg0, j = PARAMS.arg1;
    uint l = i ^ j;
    if (l <= i || l >= PARAMS.sort_len) return;
    uint a = cand[i], b = cand[l];
    bool ascending = (i & k) == 0u;
    if ((a > b) == ascending && a != b) {
        cand[i] = b;
        cand[l] = a;
    }
}

__kernel __attribute__((reqd_work_group_size(256, 1, 1)))
void merge_local(DECODE_ARGS) {
    __local uint tile[256];
    uint i = get_global_id(0), lid = get_local_id(0), k = PARAMS.arg0;
    tile[lid] = cand[i];
    barrier(CLK_LOCAL_MEM_FENCE);
    for (uint j = WG >> 1; j > 0u; j >>= 1) {
        exchange_local(tile, lid, i, k, j);
        barrier(CLK_LOCAL_MEM_FENCE);
    }
    cand[i] = tile[lid];
}
