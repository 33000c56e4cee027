// Shared by every encoder kernel: the per-dispatch parameters (layout of
// `layout::Params` on the host) and the flat-index helper.

const NONE: u32 = 0xffffffffu;
// Threads per workgroup; the host sizes dispatches with the same number.
const GROUP: u32 = 256u;

struct Params {
    vertex_count: u32,
    corner_count: u32,
    // Items of the list this dispatch walks.
    list_len: u32,
    // best_edge: 0 = evaluate every listed vertex, 1 = re-pick avoiding
    // blocked partners; block/update: offset into their input.
    mode: u32,
    // Largest grid coordinate, 2^bits - 1.
    top: u32,
    // Bit 0: constrained placement; bit 1: locked boundary.
    flags: u32,
    max_valence: u32,
    pad0: u32,
    // Grid units to metric units per axis (w unused).
    metric: vec4<f32>,
    // Sub-grid cell size (0: no sub-grid tie-break).
    cell: f32,
    // Errors at or below this count as flat (key 0).
    flat_error: f32,
    // The step's threshold S.
    threshold: f32,
    boundary_weight: f32,
}

@group(0) @binding(0) var<uniform> params: Params;

// Dispatches wider than 65535 groups use y as well (4M-vertex terrains).
fn flat_index(id: vec3<u32>, groups: vec3<u32>) -> u32 {
    return id.x + id.y * groups.x * GROUP;
}
