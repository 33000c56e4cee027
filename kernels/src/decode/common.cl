// Shared prelude of the decoder's OpenCL C kernels (the OpenCL port of
// common.wgsl; sources.rs concatenates it before the step files). Every
// kernel takes the same arguments (DECODE_ARGS), so the host binds each
// buffer once; per-dispatch parameters are a slot of the `params` array.

#define NONE 0xffffffffu
#define LEAF 255u
#define WG 256u
#define MAX_RING 255u
#define SPLIT_WORDS 8u
#define BYTE_MAX 255u
#define SCHEDULE_EVERY_VERTEX 1u

#define COUNT_V 0
#define COUNT_T 1
#define COUNT_CANDIDATES 2
#define COUNT_ERROR 3

#define ERR_COUNT 0u
#define ERR_RING_TOO_LONG 1u
#define ERR_ADJACENT_FLAGS 2u
#define ERR_RING_OFFSET 3u
#define ERR_POSITION 4u
#define ERR_VALENCE 5u
#define ERR_TRIANGLE_LIMIT 6u

typedef struct {
    uint n, candidates, splits, sort_len, tri_limit, pos_limit;
    uint arg0, arg1, arg2, schedule, pad1, pad2;
} Params;

typedef struct {
    uint offset, distance, config, deficit_p, deficit_c;
    uint px, py, pz, cx, cy, cz, pad;
} Record;

#define DECODE_ARGS                                                        \
    __global const Params *params_all, uint slot,                         \
    volatile __global uint *counts, __global uint *positions,             \
    __global uint *corners, __global uint *opposite,                      \
    __global uint *vertex_corner, volatile __global uint *deficit,        \
    __global uint *mark, volatile __global uint *uses, __global uint *cand, \
    __global const uint *flags, __global const Record *records,           \
    __global uint *scan, __global uint *splits

#define PARAMS (params_all[slot])
// SPEC §6.2 (3.6): every vertex a candidate, the word a capped valence.
#define EVERY_VERTEX (PARAMS.schedule == SCHEDULE_EVERY_VERTEX)

inline uint next_corner(uint c) { return c % 3u == 2u ? c - 2u : c + 1u; }
inline uint prev_corner(uint c) { return c % 3u == 0u ? c + 2u : c - 1u; }

inline void report(volatile __global uint *counts, uint split_plus_one, uint code) {
    atomic_min(&counts[COUNT_ERROR], split_plus_one * 8u + code);
}
