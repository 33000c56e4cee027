// Twin of best_edge.wgsl.

typedef struct {
    bool ok;
    uint3 target;
    float error;
} Eval;

uint3 grid_point(uint3 origin, float3 x, float3 metric, uint top) {
    int3 g = convert_int3(origin) + convert_int3_rte(x / metric);
    return convert_uint3(clamp(g, (int3)(0), (int3)((int)top)));
}

Eval evaluate(Topo t, __global const float *quadric, __global const Params *P, uint v, uint u) {
    uint p = min(v, u), c = max(v, u);
    uint4 pp = t.vpos[p], pc = t.vpos[c];
    float3 d = offset(t, pc.xyz, pp.xyz);
    Quad q = quad_add(quad_load(quadric, p), quad_shift(quad_load(quadric, c), d));
    uint3 target = pp.xyz;
    bool bp = (pp.w & BOUNDARY) != 0u, bc = (pc.w & BOUNDARY) != 0u;
    Eval out;
    out.ok = false;
    out.target = target;
    out.error = HUGE_ERROR;
    if ((P->flags & LOCKED) != 0u && (bp || bc)) {
        if (bp && bc) return out;
        if (!bp) target = pc.xyz;
    } else if ((P->flags & CONSTRAINED) != 0u) {
        int3 ip = convert_int3(pp.xyz);
        uint3 mid = convert_uint3(ip + ((convert_int3(pc.xyz) - ip) >> 1));
        float e = quad_error(q, (float3)(0.0f));
        float ec = quad_error(q, d);
        if (ec < e) {
            target = pc.xyz;
            e = ec;
        }
        if (quad_error(q, offset(t, mid, pp.xyz)) < e) target = mid;
    } else {
        float3 x = (float3)(0.0f);
        float e = quad_error(q, x);
        float ec = quad_error(q, d);
        if (ec < e) {
            x = d;
            e = ec;
        }
        float3 mid = 0.5f * d;
        float em = quad_error(q, mid);
        if (em < e) {
            x = mid;
            e = em;
        }
        float4 m = quad_minimizer(q);
        if (m.w != 0.0f && length(m.xyz - mid) <= 2.0f * length(d) && quad_error(q, m.xyz) < e) x = m.xyz;
        target = grid_point(pp.xyz, x, t.metric, P->top);
    }
    float error = quad_error(q, offset(t, target, pp.xyz));
    if (isnan(error) || error >= HUGE_ERROR) return out;
    out.ok = true;
    out.target = target;
    out.error = error;
    return out;
}

/* The WGSL kernel's test, stricter than the CPU's: a triangle without a
 * normal (zero area) may stay so, as on the CPU, but refuses to gain one,
 * where the CPU holds the normal it gains to the fan's normal. */
bool keeps_orientation(Topo t, uint v, uint other, float3 target, uint3 origin) {
    float3 pv = rel(t, v, origin);
    uint first = fan_first(t, v);
    uint k = first;
    for (uint i = 0; i < FAN_GUARD && k != NONE; i++) {
        uint n1 = cv(t, next_c(k)), n2 = cv(t, prev_c(k));
        if (n1 != other && n2 != other) {
            float3 q1 = rel(t, n1, origin), q2 = rel(t, n2, origin);
            float3 d1 = q1 - pv, d2 = q2 - pv;
            float3 old = cross(d1, d2);
            float os = dot(d1, d1) + dot(d2, d2);
            float3 e1 = q1 - target, e2 = q2 - target;
            float3 nw = cross(e1, e2);
            float s = dot(e1, e1) + dot(e2, e2);
            float nn = dot(nw, nw);
            bool stays_flat = dot(old, old) <= 1e-10f * os * os && nn <= 1e-10f * s * s;
            if (!stays_flat
                && (dot(old, nw) <= 1e-5f * sqrt(dot(old, old) * nn) || nn <= 1e-10f * s * s))
                return false;
        }
        k = fan_step(t, k, first);
    }
    return true;
}

bool collapse_ok(Topo t, __global const Params *P, uint p, uint c, uint3 target) {
    uint fp = fan_first(t, p);
    if (fp == NONE) return false;
    uint left = NONE, right = NONE, p_side = 0u, common = 0u;
    uint k = fp;
    for (uint i = 0; i < FAN_GUARD && k != NONE; i++) {
        uint x = cv(t, next_c(k));
        if (x == c) {
            left = k;
        } else {
            p_side++;
            if (is_neighbour(t, c, x)) common++;
        }
        if (cv(t, prev_c(k)) == c) right = k;
        k = fan_step(t, k, fp);
    }
    if (left == NONE && right == NONE) return false;
    if (fan_open(t, fp)) {
        uint x = cv(t, prev_c(fp));
        if (x != c) {
            p_side++;
            if (is_neighbour(t, c, x)) common++;
        }
        p_side++;
        if (is_neighbour(t, c, NONE)) common++;
    }
    if (common != 2u) return false;
    uint union_count = p_side + valence(t, c) - 1u - common;
    if (union_count < 3u || union_count > P->max_valence) return false;
    if (left != NONE && valence(t, cv(t, prev_c(left))) < 4u) return false;
    if (right != NONE && valence(t, cv(t, next_c(right))) < 4u) return false;
    uint3 origin = t.vpos[p].xyz;
    float3 tm = offset(t, target, origin);
    return keeps_orientation(t, p, c, tm, origin) && keeps_orientation(t, c, p, tm, origin);
}

typedef struct {
    uint u, key, other_cell;
    uint3 pos;
    float error;
    uint3 target;
} Cand;

bool ranks_before(Cand a, Cand b) {
    if (a.key != b.key) return a.key < b.key;
    if (a.other_cell != b.other_cell) return a.other_cell < b.other_cell;
    if (a.pos.x != b.pos.x) return a.pos.x < b.pos.x;
    if (a.pos.y != b.pos.y) return a.pos.y < b.pos.y;
    if (a.pos.z != b.pos.z) return a.pos.z < b.pos.z;
    return a.u < b.u;
}

inline float3 cell_of(uint3 g, float3 metric, float cell) {
    return floor(convert_float3(g) * metric / cell);
}

__kernel void best_edge(__global const Params *P, __global const uint2 *corners,
                        __global const uint *corner_of, __global const uint4 *vpos,
                        __global const float *quadric, __global Best *best,
                        __global const uint *blocked, __global const uint *list) {
    uint i = get_global_id(0);
    if (i >= P->list_len) return;
    Topo t = {corners, corner_of, vpos, P->metric.xyz};
    uint v = list[i];
    bool repick = P->mode == 1u;
    uint4 own = vpos[v];
    if (repick) {
        Best b = best[v];
        if ((own.w & ALIVE) == 0u || blocked[v] != 0u || b.other == NONE || blocked[b.other] == 0u) return;
    }
    Best none = {NONE, HUGE_ERROR, NONE, 0u, 0u, 0u};
    uint first = fan_first(t, v);
    if ((own.w & ALIVE) == 0u || first == NONE) {
        best[v] = none;
        return;
    }
    Cand cands[MAX_CANDIDATES];
    uint count = 0u;
    uint k = first;
    for (uint j = 0; j < FAN_GUARD && k != NONE; j++) {
        for (uint side = 0u; side < 2u; side++) {
            uint u = side == 0u ? cv(t, next_c(k)) : cv(t, prev_c(k));
            bool seen = repick && blocked[u] != 0u;
            for (uint m = 0u; m < count; m++) seen = seen || cands[m].u == u;
            if (seen || count == MAX_CANDIDATES) continue;
            Eval e = evaluate(t, quadric, P, v, u);
            if (!e.ok) continue;
            Cand cand;
            cand.u = u;
            cand.key = e.error <= P->flat_error ? 0u : as_uint(e.error);
            cand.other_cell = (P->cell > 0.0f &&
                               any(cell_of(own.xyz, t.metric, P->cell) != cell_of(vpos[u].xyz, t.metric, P->cell)))
                                  ? 1u
                                  : 0u;
            cand.pos = vpos[u].xyz;
            cand.error = e.error;
            cand.target = e.target;
            cands[count++] = cand;
        }
        k = fan_step(t, k, first);
    }
    uint tried = 0u;
    for (uint round = 0u; round < count; round++) {
        uint pick = NONE;
        for (uint m = 0u; m < count; m++) {
            if ((tried & (1u << m)) == 0u && (pick == NONE || ranks_before(cands[m], cands[pick]))) pick = m;
        }
        tried |= 1u << pick;
        Cand cand = cands[pick];
        if (collapse_ok(t, P, min(v, cand.u), max(v, cand.u), cand.target)) {
            Best b = {cand.u, cand.error, cand.key, cand.target.x, cand.target.y, cand.target.z};
            best[v] = b;
            return;
        }
    }
    best[v] = none;
}
