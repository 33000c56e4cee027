// Step 1 of a round (SPEC §7.3): the candidates are the vertices below n
// with deficit 0. Each is appended with an atomic counter, in no particular
// order; bitonic_sort.wgsl then restores the ascending order the flags
// refer to (Cellier et al. 2012, §3: atomic append + sort). Under the
// schedule every-vertex (3.6) every vertex below n is a candidate: v is its
// own rank, so it is written at index v, already sorted (schedule.rs skips
// the sort); the counter still counts, for number_splits' check.

@group(0) @binding(6) var<storage, read_write> deficit: array<u32>;
@group(0) @binding(9) var<storage, read_write> cand: array<u32>;

// Fills the whole padded candidate array with NONE (sorts last) and resets
// the round counters.
@compute @workgroup_size(256)
fn clear_candidates(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i < params.sort_len {
        cand[i] = NONE;
    }
    if i == 0u {
        atomicStore(&counts[COUNT_CANDIDATES], 0u);
    }
}

@compute @workgroup_size(256)
fn append_candidates(@builtin(global_invocation_id) gid: vec3<u32>) {
    let v = gid.x;
    let every = every_vertex();
    if v >= params.n || (!every && deficit[v] != 0u) {
        return;
    }
    var slot = atomicAdd(&counts[COUNT_CANDIDATES], 1u);
    if every {
        slot = v;
    }
    if slot < params.sort_len {
        cand[slot] = v;
    }
}
