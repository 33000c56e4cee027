// Step 2 of a round (SPEC §7.3): numbering. The j-th flagged candidate
// (ascending) splits into P (its own index) and C = n + j, and its 1 or 2 new
// triangles follow those of splits 0 .. j-1. Both numberings are exclusive
// prefix sums: over the flag bits of the sorted candidates, and over the
// triangles each split adds (written by split_apply.wgsl's ring_check).
//
// The scan is the classic two-level block scan, applied recursively by the
// host (decode/refine.rs, `ScanPlan`): scan_local scans blocks of 256 in
// workgroup memory and writes each block's total to a sums array; the sums
// are scanned the same way; scan_add adds the scanned block sums back.

@group(0) @binding(7) var<storage, read_write> mark: array<u32>;
@group(0) @binding(9) var<storage, read_write> cand: array<u32>;
@group(0) @binding(10) var<storage, read_write> flags: array<u32>;
@group(0) @binding(12) var<storage, read_write> scan: array<u32>;
@group(0) @binding(13) var<storage, read_write> splits: array<u32>;

// Words per split in `splits` (layout.rs: SPLIT_WORDS).
const SPLIT_WORDS: u32 = 8u;

var<workgroup> partial: array<u32, 256>;

fn flag_bit(i: u32) -> u32 {
    return (flags[i / 32u] >> (i % 32u)) & 1u;
}

// scan[i] = flag of sorted candidate i.
@compute @workgroup_size(256)
fn flags_to_values(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i < params.candidates {
        scan[i] = flag_bit(i);
    }
}

// Exclusive scan of scan[arg0 .. arg0 + arg1] per block of 256; block totals
// to scan[arg2 + block].
@compute @workgroup_size(256)
fn scan_local(@builtin(global_invocation_id) gid: vec3<u32>,
              @builtin(local_invocation_id) lid: vec3<u32>,
              @builtin(workgroup_id) wid: vec3<u32>) {
    let i = gid.x;
    let base = params.arg0;
    let len = params.arg1;
    var x = 0u;
    if i < len {
        x = scan[base + i];
    }
    partial[lid.x] = x;
    workgroupBarrier();
    // Hillis-Steele inclusive scan of the block.
    for (var off = 1u; off < WG; off = off << 1u) {
        var add = 0u;
        if lid.x >= off {
            add = partial[lid.x - off];
        }
        workgroupBarrier();
        partial[lid.x] = partial[lid.x] + add;
        workgroupBarrier();
    }
    if i < len {
        scan[base + i] = partial[lid.x] - x;
    }
    if lid.x == WG - 1u {
        scan[params.arg2 + wid.x] = partial[lid.x];
    }
}

// scan[arg0 + i] += scan[arg2 + i / 256] for i < arg1.
@compute @workgroup_size(256)
fn scan_add(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i < params.arg1 {
        scan[params.arg0 + i] = scan[params.arg0 + i] + scan[params.arg2 + i / WG];
    }
}

// Lists the flagged candidates in split order and marks them (the
// independence check of split_apply.wgsl reads the marks). Checks the
// candidate count and the flag count against the host's (arg0: the slot of
// the flag total).
@compute @workgroup_size(256)
fn number_splits(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i == 0u {
        if atomicLoad(&counts[COUNT_CANDIDATES]) != params.candidates
            || scan[params.arg0] != params.splits {
            report(0u, ERR_COUNT);
        }
    }
    if i >= params.candidates || flag_bit(i) == 0u {
        return;
    }
    let j = scan[i];
    let v = cand[i];
    // A host that flags more candidates than the device found (the count
    // fault above) leaves NONE here: no mark out of bounds.
    if j < params.splits && v < params.n {
        splits[j * SPLIT_WORDS] = v;
        mark[v] = 1u;
    }
}
