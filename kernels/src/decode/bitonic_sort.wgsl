// Step 1b of a round: sorts the appended candidates ascending (NONE pads the
// array to a power of two and sorts last). Bitonic network with the usual
// split: strides below the workgroup size run in workgroup memory
// (sort_blocks for k <= 256, merge_local for the tail of each larger k), only
// strides of 256 and more (merge_global) need a dispatch of their own.
// Host schedule: decode/refine.rs, `sort_schedule`.

@group(0) @binding(9) var<storage, read_write> cand: array<u32>;

var<workgroup> tile: array<u32, 256>;

// One compare-exchange of the network on the workgroup tile; `i` is the
// element's global index, which decides the direction of its k-block.
fn exchange_local(lid: u32, i: u32, k: u32, j: u32) {
    let l = lid ^ j;
    if l > lid {
        let ascending = (i & k) == 0u;
        let a = tile[lid];
        let b = tile[l];
        if (a > b) == ascending && a != b {
            tile[lid] = b;
            tile[l] = a;
        }
    }
}

// Every block of 256 sorted (alternating directions): stages k = 2 .. 256.
@compute @workgroup_size(256)
fn sort_blocks(@builtin(global_invocation_id) gid: vec3<u32>,
               @builtin(local_invocation_id) lid: vec3<u32>) {
    let i = gid.x;
    tile[lid.x] = cand[i];
    workgroupBarrier();
    for (var k = 2u; k <= WG; k = k << 1u) {
        for (var j = k >> 1u; j > 0u; j = j >> 1u) {
            exchange_local(lid.x, i, k, j);
            workgroupBarrier();
        }
    }
    cand[i] = tile[lid.x];
}

// One stride j >= 256 of stage k (arg0 = k, arg1 = j).
@compute @workgroup_size(256)
fn merge_global(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    let k = params.arg0;
    let j = params.arg1;
    let l = i ^ j;
    if l <= i || l >= params.sort_len {
        return;
    }
    let a = cand[i];
    let b = cand[l];
    let ascending = (i & k) == 0u;
    if (a > b) == ascending && a != b {
        cand[i] = b;
        cand[l] = a;
    }
}

// Strides 128 .. 1 of stage k (arg0 = k > 256), in workgroup memory.
@compute @workgroup_size(256)
fn merge_local(@builtin(global_invocation_id) gid: vec3<u32>,
               @builtin(local_invocation_id) lid: vec3<u32>) {
    let i = gid.x;
    let k = params.arg0;
    tile[lid.x] = cand[i];
    workgroupBarrier();
    for (var j = WG >> 1u; j > 0u; j = j >> 1u) {
        exchange_local(lid.x, i, k, j);
        workgroupBarrier();
    }
    cand[i] = tile[lid.x];
}
