// OpenCL C twin of params.wgsl, topology.wgsl and quadric.wgsl: the same
// layouts and helpers, so both backends choose the same collapses up to
// floating-point rounding. Kernel arguments follow `Kernel::slots`.

#define NONE 0xffffffffu
#define FAN_GUARD 1024u
#define ALIVE 1u
#define BOUNDARY 2u
#define CONSTRAINED 1u
#define LOCKED 2u
#define MAX_CANDIDATES 32u
#define HUGE_ERROR 3.4e38f

typedef struct {
    uint vertex_count;
    uint corner_count;
    uint list_len;
    uint mode;
    uint top;
    uint flags;
    uint max_valence;
    uint pad0;
    float4 metric;
    float cell;
    float flat_error;
    float threshold;
    float boundary_weight;
} Params;

typedef struct {
    uint other;
    float error;
    uint key;
    uint tx, ty, tz;
} Best;

typedef struct {
    uint v;
    uint other;
    float error;
    uint key;
    uint tx, ty, tz;
} Winner;

// The corner table and vertices a kernel reads, passed to helpers as one value.
typedef struct {
    __global const uint2 *corners;
    __global const uint *corner_of;
    __global const uint4 *vpos;
    float3 metric;
} Topo;

inline uint next_c(uint c) { return c % 3u == 2u ? c - 2u : c + 1u; }
inline uint prev_c(uint c) { return c % 3u == 0u ? c + 2u : c - 1u; }
inline uint cv(Topo t, uint c) { return t.corners[c].x; }
inline uint co(Topo t, uint c) { return t.corners[c].y; }

uint fan_first(Topo t, uint v) {
    uint start = t.corner_of[v];
    if (start == NONE) return NONE;
    uint c = start;
    for (uint i = 0; i < FAN_GUARD; i++) {
        uint o = co(t, next_c(c));
        if (o == NONE) return c;
        uint back = next_c(o);
        if (back == start) return start;
        c = back;
    }
    return start;
}

inline bool fan_open(Topo t, uint first) { return co(t, next_c(first)) == NONE; }

inline uint fan_step(Topo t, uint c, uint first) {
    uint o = co(t, prev_c(c));
    if (o == NONE) return NONE;
    uint c2 = prev_c(o);
    return c2 == first ? NONE : c2;
}

uint valence(Topo t, uint w) {
    uint first = fan_first(t, w);
    if (first == NONE) return 0u;
    uint count = 0u;
    uint k = first;
    for (uint i = 0; i < FAN_GUARD && k != NONE; i++) {
        count++;
        k = fan_step(t, k, first);
    }
    return fan_open(t, first) ? count + 2u : count;
}

bool is_neighbour(Topo t, uint w, uint x) {
    uint first = fan_first(t, w);
    if (first == NONE) return false;
    bool open = fan_open(t, first);
    if (x == NONE) return open;
    if (open && cv(t, prev_c(first)) == x) return true;
    uint k = first;
    for (uint i = 0; i < FAN_GUARD && k != NONE; i++) {
        if (cv(t, next_c(k)) == x) return true;
        k = fan_step(t, k, first);
    }
    return false;
}

inline float3 offset(Topo t, uint3 g, uint3 origin) {
    int3 d = convert_int3(g) - convert_int3(origin);
    return convert_float3(d) * t.metric;
}

inline float3 rel(Topo t, uint v, uint3 origin) { return offset(t, t.vpos[v].xyz, origin); }

// Quadric: symmetric 3x3 part (rows r0..r2), linear part b, constant c.
typedef struct {
    float3 r0, r1, r2;
    float3 b;
    float c;
} Quad;

Quad quad_load(__global const float *q, uint v) {
    __global const float *p = q + 10u * v;
    Quad out;
    out.r0 = (float3)(p[0], p[1], p[2]);
    out.r1 = (float3)(p[1], p[4], p[5]);
    out.r2 = (float3)(p[2], p[5], p[7]);
    out.b = (float3)(p[3], p[6], p[8]);
    out.c = p[9];
    return out;
}

inline float3 quad_mul(Quad q, float3 x) {
    return (float3)(dot(q.r0, x), dot(q.r1, x), dot(q.r2, x));
}

// x -> q(x - d): q seen from a frame whose origin sits at -d in q's frame.
Quad quad_shift(Quad q, float3 d) {
    float3 ad = quad_mul(q, d);
    Quad out = q;
    out.b = q.b - ad;
    out.c = dot(d, ad) - 2.0f * dot(q.b, d) + q.c;
    return out;
}

Quad quad_add(Quad x, Quad y) {
    Quad out;
    out.r0 = x.r0 + y.r0;
    out.r1 = x.r1 + y.r1;
    out.r2 = x.r2 + y.r2;
    out.b = x.b + y.b;
    out.c = x.c + y.c;
    return out;
}

inline float quad_error(Quad q, float3 p) {
    return fmax(dot(p, quad_mul(q, p)) + 2.0f * dot(q.b, p) + q.c, 0.0f);
}

// Minimiser in xyz, w = 1; w = 0 when nearly singular (bound as in WGSL).
float4 quad_minimizer(Quad q) {
    float3 c0 = cross(q.r1, q.r2);
    float3 c1 = cross(q.r2, q.r0);
    float3 c2 = cross(q.r0, q.r1);
    float det = dot(q.r0, c0);
    float s = fmax(fmax(fabs(q.r0.x), fabs(q.r1.y)), fabs(q.r2.z));
    if (s == 0.0f || fabs(det) <= 1e-6f * s * s * s) return (float4)(0.0f);
    float3 rhs = -q.b;
    // Symmetric: the inverse's rows are the cross products over det.
    float3 x = (float3)(dot(c0, rhs), dot(c1, rhs), dot(c2, rhs)) / det;
    if (any(isnan(x)) || any(isinf(x))) return (float4)(0.0f);
    return (float4)(x, 1.0f);
}
