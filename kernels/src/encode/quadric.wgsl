// Quadrics in vertex-local frames (see quadric_init.wgsl): load, move to
// another frame, add, evaluate, minimise.

@group(0) @binding(4) var<storage, read> quadric: array<f32>;

// Symmetric 4x4 upper triangle: a2 ab ac ad b2 bc bd c2 cd d2.
struct Quad {
    a: mat3x3<f32>,
    b: vec3<f32>,
    c: f32,
}

fn quad_load(v: u32) -> Quad {
    let o = v * 10u;
    let a = mat3x3<f32>(
        vec3<f32>(quadric[o], quadric[o + 1u], quadric[o + 2u]),
        vec3<f32>(quadric[o + 1u], quadric[o + 4u], quadric[o + 5u]),
        vec3<f32>(quadric[o + 2u], quadric[o + 5u], quadric[o + 7u]),
    );
    return Quad(a, vec3<f32>(quadric[o + 3u], quadric[o + 6u], quadric[o + 8u]), quadric[o + 9u]);
}

// q expressed in a frame whose origin sits at -d in q's frame, i.e. the
// quadric x -> q(x - d), for x measured from the new origin.
fn quad_shift(q: Quad, d: vec3<f32>) -> Quad {
    let ad = q.a * d;
    return Quad(q.a, q.b - ad, dot(d, ad) - 2.0 * dot(q.b, d) + q.c);
}

fn quad_add(x: Quad, y: Quad) -> Quad {
    return Quad(x.a + y.a, x.b + y.b, x.c + y.c);
}

fn quad_error(q: Quad, p: vec3<f32>) -> f32 {
    return max(dot(p, q.a * p) + 2.0 * dot(q.b, p) + q.c, 0.0);
}

// The minimiser (w = 1), or w = 0 when the 3x3 system is nearly singular.
// The singularity bound is far looser than the CPU's 1e-10: f32 determinants
// carry ~1e-7 relative noise.
fn quad_minimizer(q: Quad) -> vec4<f32> {
    let m = q.a;
    let det = determinant(m);
    let s = max(max(abs(m[0][0]), abs(m[1][1])), abs(m[2][2]));
    if s == 0.0 || abs(det) <= 1e-6 * s * s * s {
        return vec4<f32>(0.0);
    }
    // Symmetric: the adjugate over the determinant is the inverse.
    let c0 = cross(m[1], m[2]);
    let c1 = cross(m[2], m[0]);
    let c2 = cross(m[0], m[1]);
    let inv = transpose(mat3x3<f32>(c0, c1, c2)) * (1.0 / det);
    let x = inv * (-q.b);
    if any(x != x) || any(abs(x) > vec3<f32>(3.0e38)) {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(x, 1.0);
}
