// Twin of quadric_init.wgsl.

inline void add_plane(float *acc, float3 n, float w) {
    acc[0] += w * n.x * n.x;
    acc[1] += w * n.x * n.y;
    acc[2] += w * n.x * n.z;
    acc[4] += w * n.y * n.y;
    acc[5] += w * n.y * n.z;
    acc[7] += w * n.z * n.z;
}

inline void add_boundary(float *acc, float3 e, float3 n, float weight) {
    float3 m = cross(e, n);
    float len = length(m);
    if (len > 0.0f) add_plane(acc, m / len, weight * dot(e, e));
}

__kernel void quadric_init(__global const Params *P, __global const uint2 *corners,
                           __global const uint *corner_of, __global const uint4 *vpos,
                           __global float *quadric) {
    uint v = get_global_id(0);
    if (v >= P->vertex_count) return;
    Topo t = {corners, corner_of, vpos, P->metric.xyz};
    float acc[10] = {0.0f};
    uint3 origin = vpos[v].xyz;
    uint first = fan_first(t, v);
    uint k = first;
    for (uint i = 0; i < FAN_GUARD && k != NONE; i++) {
        float3 a = rel(t, cv(t, next_c(k)), origin);
        float3 b = rel(t, cv(t, prev_c(k)), origin);
        float3 n = cross(a, b);
        float len = length(n);
        if (len > 0.0f) add_plane(acc, n / len, 0.5f * len);
        if (P->boundary_weight != 0.0f) {
            if (co(t, prev_c(k)) == NONE) add_boundary(acc, a, n, P->boundary_weight);
            if (co(t, next_c(k)) == NONE) add_boundary(acc, -b, cross(-b, a - b), P->boundary_weight);
        }
        k = fan_step(t, k, first);
    }
    for (uint j = 0; j < 10u; j++) quadric[10u * v + j] = acc[j];
}
