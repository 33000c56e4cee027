// Quadric init (paper §2, "Vertex" array): each vertex gathers the
// area-weighted plane quadrics of its triangles and the penalty planes of
// its boundary edges. A gather per vertex, so no float atomics. Quadrics are
// stored in the vertex's own frame (origin at its position): every plane
// passes through the vertex, so only the 3x3 part is non-zero and f32 keeps
// its precision however far the mesh is from the origin.

@group(0) @binding(4) var<storage, read_write> quadric: array<f32>;

fn add_plane(acc: ptr<function, array<f32, 10>>, n: vec3<f32>, w: f32) {
    (*acc)[0] += w * n.x * n.x;
    (*acc)[1] += w * n.x * n.y;
    (*acc)[2] += w * n.x * n.z;
    (*acc)[4] += w * n.y * n.y;
    (*acc)[5] += w * n.y * n.z;
    (*acc)[7] += w * n.z * n.z;
}

// Penalty plane of boundary edge e (from the vertex) in the triangle with
// normal n: the plane holding the edge and the normal, weight w |e|^2.
fn add_boundary(acc: ptr<function, array<f32, 10>>, e: vec3<f32>, n: vec3<f32>) {
    let m = cross(e, n);
    let len = length(m);
    if len > 0.0 {
        add_plane(acc, m / len, params.boundary_weight * dot(e, e));
    }
}

@compute @workgroup_size(256)
fn quadric_init(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let v = flat_index(id, groups);
    if v >= params.vertex_count {
        return;
    }
    var acc: array<f32, 10>;
    let origin = vpos[v].xyz;
    let first = fan_first(v);
    var k = first;
    for (var i = 0u; i < FAN_GUARD && k != NONE; i++) {
        // Triangle (v, a, b) counter-clockwise, in v's frame.
        let a = rel(cv(next_c(k)), origin);
        let b = rel(cv(prev_c(k)), origin);
        let n = cross(a, b);
        let len = length(n);
        if len > 0.0 {
            // len is twice the area.
            add_plane(&acc, n / len, 0.5 * len);
        }
        if params.boundary_weight != 0.0 {
            // Edge (v, a) faces prev(k); edge (b, v) faces next(k).
            if co(prev_c(k)) == NONE {
                add_boundary(&acc, a, n);
            }
            if co(next_c(k)) == NONE {
                add_boundary(&acc, -b, cross(-b, a - b));
            }
        }
        k = fan_step(k, first);
    }
    for (var j = 0u; j < 10u; j++) {
        quadric[v * 10u + j] = acc[j];
    }
}
