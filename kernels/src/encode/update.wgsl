// Upload of what the CPU changed when it applied a step's collapses: whole
// triangles (three corners: vertex and opposite) and whole vertices
// (position, flags, corner, quadric in the vertex's frame). Records are
// packed u32 words (layout::TriangleUpdate, layout::VertexUpdate).

@group(0) @binding(1) var<storage, read_write> corners: array<vec2<u32>>;
@group(0) @binding(2) var<storage, read_write> corner_of: array<u32>;
@group(0) @binding(3) var<storage, read_write> vpos: array<vec4<u32>>;
@group(0) @binding(4) var<storage, read_write> quadric: array<f32>;
@group(0) @binding(11) var<storage, read> updates: array<u32>;

const TRIANGLE_WORDS: u32 = 7u;
const VERTEX_WORDS: u32 = 16u;

// Triangle records start at word params.mode.
@compute @workgroup_size(256)
fn update_triangles(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = flat_index(id, groups);
    if i >= params.list_len {
        return;
    }
    let r = params.mode + i * TRIANGLE_WORDS;
    let t = updates[r];
    for (var k = 0u; k < 3u; k++) {
        corners[3u * t + k] = vec2<u32>(updates[r + 1u + k], updates[r + 4u + k]);
    }
}

// Vertex records start at word params.mode.
@compute @workgroup_size(256)
fn update_vertices(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = flat_index(id, groups);
    if i >= params.list_len {
        return;
    }
    let r = params.mode + i * VERTEX_WORDS;
    let v = updates[r];
    vpos[v] = vec4<u32>(updates[r + 1u], updates[r + 2u], updates[r + 3u], updates[r + 4u]);
    corner_of[v] = updates[r + 5u];
    for (var k = 0u; k < 10u; k++) {
        quadric[v * 10u + k] = bitcast<f32>(updates[r + 6u + k]);
    }
}
