// OpenCL port of split_apply.wgsl: ring walk and checks, wing check,
// parallel split apply (under every-vertex, 3.6: wing valences grow, no
// deficit checks), round finish. See the WGSL file for the reasoning.

inline uint wedge_step(__global const uint *opposite, uint c) {
    uint o = opposite[next_corner(c)];
    return o == NONE ? NONE : next_corner(o);
}

typedef struct {
    bool boundary;
    uint k, c, last_real;
} RingCursor;

// Wedge i's corner of R (NONE when virtual) in .x, r_i (NONE: ghost) in .y.
inline uint2 wedge_at(RingCursor *cur, __global const uint *corners,
                      __global const uint *opposite, uint i) {
    uint first_real = cur->boundary ? 1u : 0u;
    uint last_real = cur->boundary ? cur->k - 2u : cur->k - 1u;
    if (i >= first_real && i <= last_real) {
        uint wc = cur->c;
        cur->last_real = wc;
        if (i < last_real) cur->c = wedge_step(opposite, wc);
        return (uint2)(wc, corners[next_corner(wc)]);
    }
    if (cur->boundary && i == cur->k - 1u)
        return (uint2)(NONE, corners[prev_corner(cur->last_real)]);
    return (uint2)(NONE, NONE);
}

__kernel void ring_check(DECODE_ARGS) {
    uint j = get_global_id(0);
    if (j >= PARAMS.splits) return;
    uint base = j * SPLIT_WORDS, key = j + 1u;
    scan[j] = 0u;
    splits[base + 6u] = 0u;
    if (counts[COUNT_ERROR] < 8u) return;
    uint r = splits[base];

    uint any_corner = vertex_corner[r], c = any_corner, k = 0u, start = c, smallest = NONE;
    bool boundary = false;
    for (;;) {
        if (k == MAX_RING) { report(counts, key, ERR_RING_TOO_LONG); return; }
        uint v = corners[next_corner(c)];
        if (v < smallest) { smallest = v; start = c; }
        k++;
        uint s = wedge_step(opposite, c);
        if (s == NONE) { boundary = true; break; }
        c = s;
        if (c == any_corner) break;
    }
    if (boundary) {
        uint first = any_corner, steps = 0u;
        for (;;) {
            uint o = opposite[prev_corner(first)];
            if (o == NONE) break;
            first = prev_corner(o);
            if (++steps == MAX_RING) { report(counts, key, ERR_RING_TOO_LONG); return; }
        }
        uint m = 1u, w = first;
        for (;;) {
            if (m + 1u >= MAX_RING) { report(counts, key, ERR_RING_TOO_LONG); return; }
            uint s = wedge_step(opposite, w);
            if (s == NONE) break;
            w = s;
            m++;
        }
        start = first;
        k = m + 2u;
    }

    Record rec = records[j];
    uint o = rec.offset, d = rec.distance;
    RingCursor cur = { boundary, k, start, NONE };
    bool dependent = false;
    uint a = NONE, b = NONE;
    for (uint i = 0u; i < k; i++) {
        uint v = wedge_at(&cur, corners, opposite, i).y;
        if (v != NONE && mark[v] != 0u) dependent = true;
        if (i == o) a = v;
        if (i == o + d) b = v;
    }
    if (dependent) { report(counts, key, ERR_ADJACENT_FLAGS); return; }
    if (d == 0u || o + d >= k) { report(counts, key, ERR_RING_OFFSET); return; }
    if (PARAMS.pos_limit != 0u) {
        uint hi = max(max(max(rec.px, rec.py), max(rec.pz, rec.cx)), max(rec.cy, rec.cz));
        if (hi >= PARAMS.pos_limit) { report(counts, key, ERR_POSITION); return; }
    }
    uint len_p = rec.config != 0u ? k - d : d;
    uint len_c = k - len_p;
    bool every = EVERY_VERTEX;
    if (!every && ((rec.deficit_p != LEAF && len_p + 2u + rec.deficit_p > MAX_RING)
        || (rec.deficit_c != LEAF && len_c + 2u + rec.deficit_c > MAX_RING))) {
        report(counts, key, ERR_VALENCE);
        return;
    }
    if (!every && ((a != NONE && deficit[a] == 0u) || (b != NONE && deficit[b] == 0u))) {
        report(counts, key, ERR_VALENCE);
        return;
    }
    uint added = (a != NONE ? 1u : 0u) + (b != NONE ? 1u : 0u);
    if (added == 0u) { report(counts, key, ERR_RING_OFFSET); return; }
    splits[base + 1u] = start;
    splits[base + 2u] = k | ((boundary ? 1u : 0u) << 16);
    splits[base + 3u] = a;
    splits[base + 4u] = b;
    splits[base + 5u] = added;
    splits[base + 6u] = 1u;
    scan[j] = added;
    if (every) return;
    if (a != NONE && deficit[a] != LEAF) atomic_inc(&uses[a]);
    if (b != NONE && deficit[b] != LEAF) atomic_inc(&uses[b]);
}

__kernel void wing_check(DECODE_ARGS) {
    uint j = get_global_id(0);
    uint base = j * SPLIT_WORDS;
    if (j >= PARAMS.splits || splits[base + 6u] == 0u) return;
    uint key = j + 1u;
    for (uint w = 0u; w < 2u && !EVERY_VERTEX; w++) {
        uint x = splits[base + 3u + w];
        if (x != NONE) {
            uint dx = deficit[x];
            if (dx != LEAF && uses[x] > dx) { report(counts, key, ERR_VALENCE); return; }
        }
    }
    if (counts[COUNT_T] + scan[j] + splits[base + 5u] > PARAMS.tri_limit)
        report(counts, key, ERR_TRIANGLE_LIMIT);
}

inline void link(__global uint *opposite, uint x, uint y) {
    opposite[x] = y;
    if (y != NONE) opposite[y] = x;
}

__kernel void apply(DECODE_ARGS) {
    uint j = get_global_id(0);
    if (j >= PARAMS.splits || counts[COUNT_ERROR] != NONE) return;
    uint base = j * SPLIT_WORDS;
    uint r = splits[base], start = splits[base + 1u];
    uint k = splits[base + 2u] & 0xffffu;
    bool boundary = (splits[base + 2u] >> 16) != 0u;
    uint a = splits[base + 3u], b = splits[base + 4u];
    Record rec = records[j];
    uint o = rec.offset, d = rec.distance, cv = PARAMS.n + j;
    bool config = rec.config != 0u;
    uint x = config ? cv : r, y = config ? r : cv;
    uint c_arc_start = config ? o : o + d;
    uint len_c = config ? d : k - d;

    RingCursor cur = { boundary, k, start, NONE };
    uint before_a = NONE, after_a = NONE, before_b = NONE, after_b = NONE;
    uint i_before_a = (o + k - 1u) % k;
    for (uint i = 0u; i < k; i++) {
        uint wc = wedge_at(&cur, corners, opposite, i).x;
        if (wc != NONE && (i + k - c_arc_start) % k < len_c) corners[wc] = cv;
        if (i == i_before_a) before_a = wc;
        if (i == o) after_a = wc;
        if (i == o + d - 1u) before_b = wc;
        if (i == o + d) after_b = wc;
    }

    uint t = counts[COUNT_T] + scan[j];
    uint ta = NONE, tb = NONE;
    if (a != NONE) ta = t++;
    if (b != NONE) tb = t;
    if (ta != NONE) {
        corners[3u * ta] = x;
        corners[3u * ta + 1u] = y;
        corners[3u * ta + 2u] = a;
        link(opposite, 3u * ta, before_a == NONE ? NONE : next_corner(before_a));
        link(opposite, 3u * ta + 1u, after_a == NONE ? NONE : prev_corner(after_a));
    }
    if (tb != NONE) {
        corners[3u * tb] = y;
        corners[3u * tb + 1u] = x;
        corners[3u * tb + 2u] = b;
        link(opposite, 3u * tb, before_b == NONE ? NONE : next_corner(before_b));
        link(opposite, 3u * tb + 1u, after_b == NONE ? NONE : prev_corner(after_b));
    }
    if (ta != NONE && tb != NONE) link(opposite, 3u * ta + 2u, 3u * tb + 2u);
    else if (ta != NONE) opposite[3u * ta + 2u] = NONE;
    else opposite[3u * tb + 2u] = NONE;
    if (ta != NONE) {
        vertex_corner[x] = 3u * ta;
        vertex_corner[y] = 3u * ta + 1u;
    } else {
        vertex_corner[x] = 3u * tb + 1u;
        vertex_corner[y] = 3u * tb;
    }
    if (EVERY_VERTEX) {
        // Add, then clamp at 255: wings shared by splits end capped.
        if (a != NONE) { atomic_inc(&deficit[a]); atomic_min(&deficit[a], BYTE_MAX); }
        if (b != NONE) { atomic_inc(&deficit[b]); atomic_min(&deficit[b], BYTE_MAX); }
    } else {
        if (a != NONE && deficit[a] != LEAF) atomic_dec(&deficit[a]);
        if (b != NONE && deficit[b] != LEAF) atomic_dec(&deficit[b]);
    }
    positions[3u * r] = rec.px;
    positions[3u * r + 1u] = rec.py;
    positions[3u * r + 2u] = rec.pz;
    positions[3u * cv] = rec.cx;
    positions[3u * cv + 1u] = rec.cy;
    positions[3u * cv + 2u] = rec.cz;
    deficit[r] = rec.deficit_p;
    deficit[cv] = rec.deficit_c;
}

__kernel void finish(DECODE_ARGS) {
    uint j = get_global_id(0);
    if (j == 0u && counts[COUNT_ERROR] == NONE) {
        atomic_add(&counts[COUNT_V], PARAMS.splits);
        atomic_add(&counts[COUNT_T], scan[PARAMS.arg0]);
    }
    if (j >= PARAMS.splits) return;
    uint base = j * SPLIT_WORDS;
    mark[splits[base]] = 0u;
    if (splits[base + 6u] != 0u) {
        uint a = splits[base + 3u], b = splits[base + 4u];
        if (a != NONE) uses[a] = 0u;
        if (b != NONE) uses[b] = 0u;
    }
}
