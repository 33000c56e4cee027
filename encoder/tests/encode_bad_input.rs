//! The library's encode functions check their mesh themselves: a mesh that
//! `input::check_mesh` refuses gets that typed error from `encode` and
//! `encode_quantized`, never a panic, a hang or
//! a stream of garbage. Before the check, a triangle naming a missing
//! vertex panicked in the corner table, a non-manifold or flipped
//! icosphere panicked in the simplifier's checks, and a NaN coordinate was
//! quantized into a stream.

mod common;

use splitstream_decoder_core::PositionMode;
use splitstream_encoder::Mesh;
use splitstream_encoder::emit::{
    EncodeError, EncodeOptions, encode, encode_quantized, quantize_for,
};
use splitstream_encoder::input::MeshError;

/// Every entry point refuses `mesh` with the error `matches` accepts.
fn refused(name: &str, mesh: &Mesh, matches: fn(&MeshError) -> bool) {
    for mode in [PositionMode::Constrained, PositionMode::Optimal] {
        let options = EncodeOptions {
            position_mode: mode,
            ..EncodeOptions::default()
        };
        let result = encode(mesh, &options, |_| {}).map(|_| ());
        match result {
            Err(EncodeError::Input(e)) => assert!(matches(&e), "{name}: {e}"),
            Err(e) => panic!("{name}: another error: {e}"),
            Ok(()) => panic!("{name}: encoded"),
        }
    }
}

fn icosphere_with(edit: impl FnOnce(&mut Mesh)) -> Mesh {
    let mut mesh = common::icosphere(3);
    edit(&mut mesh);
    mesh
}

#[test]
fn a_triangle_naming_a_missing_vertex_is_refused() {
    let mesh = icosphere_with(|m| m.triangles[0][2] = m.positions.len() as u32 + 5);
    refused("index", &mesh, |e| {
        matches!(e, MeshError::IndexOutOfRange { .. })
    });
}

#[test]
fn non_manifold_and_flipped_meshes_are_refused() {
    let fin = icosphere_with(|m| {
        let t = m.triangles[10];
        m.positions.push([9.0, 9.0, 9.0]);
        let n = m.positions.len() as u32 - 1;
        m.triangles.push([t[0], t[1], n]);
    });
    refused("fin", &fin, |e| {
        matches!(e, MeshError::NonManifoldEdge { .. })
    });
    let flipped = icosphere_with(|m| {
        let t = m.triangles[10];
        m.triangles[10] = [t[0], t[2], t[1]];
    });
    refused("flipped", &flipped, |e| {
        matches!(e, MeshError::InconsistentOrientation { .. })
    });
    // Two icospheres sharing one vertex: its triangles form two fans.
    let ico = common::icosphere(3);
    let shared = ico.triangles[0][0];
    let bowtie = icosphere_with(|m| {
        let nv = m.positions.len() as u32;
        let copy = |v: u32| match v.cmp(&shared) {
            std::cmp::Ordering::Equal => shared,
            std::cmp::Ordering::Less => v + nv,
            std::cmp::Ordering::Greater => v + nv - 1,
        };
        m.positions.extend(
            ico.positions
                .iter()
                .enumerate()
                .filter(|&(v, _)| v as u32 != shared)
                .map(|(_, p)| [p[0] + 2.0, p[1], p[2]]),
        );
        m.triangles
            .extend(ico.triangles.iter().map(|t| t.map(copy)));
    });
    refused("bowtie", &bowtie, |e| {
        matches!(e, MeshError::NonManifoldVertex { .. })
    });
}

#[test]
fn non_finite_coordinates_and_empty_meshes_are_refused() {
    let nan = icosphere_with(|m| m.positions[3][1] = f64::NAN);
    refused("nan", &nan, |e| {
        matches!(e, MeshError::NonFiniteCoordinate { vertex: 3, .. })
    });
    refused("empty", &Mesh::default(), |e| {
        matches!(e, MeshError::Empty { .. })
    });
}

#[test]
fn a_quantized_mesh_is_checked_too() {
    let options = EncodeOptions::default();
    let good = quantize_for(&common::icosphere(3), &options);
    encode_quantized(&good, &options, |_| {}).expect("the icosphere encodes");

    let mut index = good.clone();
    index.triangles[0][1] = index.positions.len() as u32;
    assert!(matches!(
        encode_quantized(&index, &options, |_| {}),
        Err(EncodeError::Input(MeshError::IndexOutOfRange { .. }))
    ));

    let mut flipped = good.clone();
    let t = flipped.triangles[10];
    flipped.triangles[10] = [t[0], t[2], t[1]];
    assert!(matches!(
        encode_quantized(&flipped, &options, |_| {}),
        Err(EncodeError::Input(
            MeshError::InconsistentOrientation { .. }
        ))
    ));

    let mut outside = good.clone();
    outside.positions[0][2] = 1 << outside.bits;
    match encode_quantized(&outside, &options, |_| {}) {
        Err(EncodeError::BadOption(message)) => {
            assert!(message.contains("outside its 14-bit grid"), "{message}")
        }
        other => panic!("{:?}", other.map(|e| e.stream.len())),
    }
}

/// The simplifier's public entry points take a `Checked` mesh, which only
/// `Checked::new` makes: the same checks, as a `GridError`. (Before, a
/// triangle naming a missing vertex panicked in `simplify`, and a flipped
/// triangle was simplified into a wrong mesh without a word.)
#[test]
fn the_simplifier_takes_only_a_checked_mesh() {
    use splitstream_encoder::quantize::GridError;
    use splitstream_encoder::simplify::{Backend, Checked, SimplifyOptions, simplify, simplify_on};

    let good = quantize_for(&common::icosphere(3), &EncodeOptions::default());
    let checked = Checked::new(&good).expect("the icosphere is a closed manifold");
    assert_eq!(checked.stats().vertices, good.positions.len());
    assert_eq!(checked.stats().genus, 0);
    let options = SimplifyOptions {
        target_vertices: 12,
        ..SimplifyOptions::default()
    };
    let s = simplify(&checked, &options, |_| {});
    assert_eq!(s.alive_count, 12);
    let again = simplify_on(Backend::Cpu, &checked, &options, |_| {}).expect("the CPU backend");
    assert_eq!(again.steps, s.steps);

    let refused = |name: &str,
                   mesh: &splitstream_encoder::quantize::QuantizedMesh,
                   matches: fn(&GridError) -> bool| {
        match Checked::new(mesh) {
            Err(e) => assert!(matches(&e), "{name}: {e}"),
            Ok(_) => panic!("{name}: accepted"),
        }
    };
    let mut index = good.clone();
    index.triangles[0][1] = index.positions.len() as u32;
    refused("index", &index, |e| {
        matches!(e, GridError::Mesh(MeshError::IndexOutOfRange { .. }))
    });
    let mut flipped = good.clone();
    let t = flipped.triangles[10];
    flipped.triangles[10] = [t[0], t[2], t[1]];
    refused("flipped", &flipped, |e| {
        matches!(
            e,
            GridError::Mesh(MeshError::InconsistentOrientation { .. })
        )
    });
    let mut outside = good.clone();
    outside.positions[7][0] = 1 << outside.bits;
    refused("outside", &outside, |e| {
        matches!(e, GridError::OffGrid { vertex: 7, .. })
    });
    let mut bits = good.clone();
    bits.bits = 0;
    refused("bits", &bits, |e| matches!(e, GridError::Bits(0)));
    let mut empty = good.clone();
    empty.positions.clear();
    empty.triangles.clear();
    refused("empty", &empty, |e| {
        matches!(e, GridError::Mesh(MeshError::Empty { .. }))
    });
}
