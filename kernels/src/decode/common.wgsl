// Shared prelude of the decoder kernels (prepended to every decode/*.wgsl by
// sources.rs): constants, the per-dispatch parameters, the round counters and
// corner-table helpers. Layouts mirror decode/layout.rs.

const NONE: u32 = 0xffffffffu;
const LEAF: u32 = 255u;
const WG: u32 = 256u;
// The largest value of a per-vertex byte: under the schedule every-vertex a
// valence is kept capped at it (SPEC §6.2).
const BYTE_MAX: u32 = 255u;
// Params.schedule (layout.rs: Schedule::word; SPEC §3.2 header flag bit 1).
const SCHEDULE_EVERY_VERTEX: u32 = 1u;

// Slots of the `counts` buffer (layout.rs: Counts).
const COUNT_V: u32 = 0u;
const COUNT_T: u32 = 1u;
const COUNT_CANDIDATES: u32 = 2u;
const COUNT_ERROR: u32 = 3u;

// Error codes, in the order SPEC §7.3-§7.5 checks them within one split; the
// key atomicMin-ed into counts[COUNT_ERROR] is (split + 1) * 8 + code, so the
// smallest key is the first fault in the reference decoder's order. Split 0
// of the key (round-level faults) uses code ERR_COUNT.
const ERR_COUNT: u32 = 0u;
const ERR_RING_TOO_LONG: u32 = 1u;
const ERR_ADJACENT_FLAGS: u32 = 2u;
const ERR_RING_OFFSET: u32 = 3u;
const ERR_POSITION: u32 = 4u;
const ERR_VALENCE: u32 = 5u;
const ERR_TRIANGLE_LIMIT: u32 = 6u;

struct Params {
    // Vertex count at the start of the round.
    n: u32,
    // Candidates the host expects (the number of flags it uploaded).
    candidates: u32,
    // Splits of the round (records uploaded).
    splits: u32,
    // Padded length of the candidate array (a power of two, >= WG).
    sort_len: u32,
    // Triangle count the level may reach (SPEC §7.5), capped at the capacity.
    tri_limit: u32,
    // 2^bits, or 0 when every u32 is a valid coordinate.
    pos_limit: u32,
    // Step arguments: bitonic (k, j); scan (base, len, sums).
    arg0: u32,
    arg1: u32,
    arg2: u32,
    // 0 split-valences, 1 every-vertex (format 3.6): what `deficit` holds and
    // which vertices are candidates (SPEC §6.2, §7.3).
    schedule: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> counts: array<atomic<u32>>;

// SPEC §6.2 (3.6): every vertex is a candidate of every round, and the
// per-vertex word holds its valence capped at 255, not a deficit.
fn every_vertex() -> bool {
    return params.schedule == SCHEDULE_EVERY_VERTEX;
}

fn next_corner(c: u32) -> u32 {
    if c % 3u == 2u {
        return c - 2u;
    }
    return c + 1u;
}

fn prev_corner(c: u32) -> u32 {
    if c % 3u == 0u {
        return c + 2u;
    }
    return c - 1u;
}

fn report(split_plus_one: u32, code: u32) {
    atomicMin(&counts[COUNT_ERROR], split_plus_one * 8u + code);
}
