// Twin of update.wgsl.

__kernel void update_triangles(__global const Params *P, __global uint2 *corners,
                               __global const uint *updates) {
    uint i = get_global_id(0);
    if (i >= P->list_len) return;
    uint r = P->mode + i * 7u;
    uint tri = updates[r];
    for (uint k = 0u; k < 3u; k++) corners[3u * tri + k] = (uint2)(updates[r + 1u + k], updates[r + 4u + k]);
}

__kernel void update_vertices(__global const Params *P, __global uint *corner_of, __global uint4 *vpos,
                              __global float *quadric, __global const uint *updates) {
    uint i = get_global_id(0);
    if (i >= P->list_len) return;
    uint r = P->mode + i * 16u;
    uint v = updates[r];
    vpos[v] = (uint4)(updates[r + 1u], updates[r + 2u], updates[r + 3u], updates[r + 4u]);
    corner_of[v] = updates[r + 5u];
    for (uint k = 0u; k < 10u; k++) quadric[10u * v + k] = as_float(updates[r + 6u + k]);
}
