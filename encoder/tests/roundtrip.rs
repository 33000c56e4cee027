//! decode(encode(M)) gives M back exactly: the same oriented triangles after
//! mapping decoded vertices to input ids, and the quantized positions.

mod common;

use splitstream_decoder_core::PositionMode;
use splitstream_decoder_core::owned::decode_all;
use splitstream_encoder::Mesh;
use splitstream_encoder::emit::{EncodeOptions, encode};
use splitstream_encoder::quantize::quantize;

fn canonical(t: [u32; 3]) -> [u32; 3] {
    let r = (0..3).min_by_key(|&i| t[i]).unwrap();
    [t[r], t[(r + 1) % 3], t[(r + 2) % 3]]
}

/// Encodes, decodes with decoder-core from the bytes alone, and compares.
pub fn assert_roundtrip(mesh: &Mesh, options: &EncodeOptions) -> usize {
    let encoded = encode(mesh, options, |_| {}).expect("encode");
    let decoded = decode_all(&encoded.stream, false).expect("decode");
    let q = quantize(mesh, options.bits, options.units);
    assert_eq!(decoded.positions.len(), mesh.positions.len());
    for (d, &e) in encoded.permutation.iter().enumerate() {
        assert_eq!(decoded.positions[d], q.positions[e as usize], "vertex {e}");
    }
    let mut got: Vec<[u32; 3]> = decoded
        .triangles
        .iter()
        .map(|t| canonical(t.map(|v| encoded.permutation[v as usize])))
        .collect();
    let mut want: Vec<[u32; 3]> = mesh.triangles.iter().map(|&t| canonical(t)).collect();
    got.sort_unstable();
    want.sort_unstable();
    assert_eq!(got, want);
    assert_eq!(decoded.levels as usize, encoded.level_vertex_counts.len());
    encoded.stream.len()
}

#[test]
fn closed_sphere_roundtrips() {
    let mesh = common::icosphere(3);
    assert_roundtrip(&mesh, &EncodeOptions::default());
}

#[test]
fn grid_with_boundary_roundtrips() {
    let mesh = common::bumpy_grid(23, 17, 1);
    assert_roundtrip(&mesh, &EncodeOptions::default());
}

#[test]
fn constrained_mode_roundtrips() {
    let options = EncodeOptions {
        position_mode: PositionMode::Constrained,
        ..EncodeOptions::default()
    };
    assert_roundtrip(&common::icosphere(2), &options);
    assert_roundtrip(&common::bumpy_grid(15, 12, 2), &options);
}

#[test]
fn locked_boundary_and_one_level() {
    let mesh = common::bumpy_grid(12, 12, 3);
    let options = EncodeOptions {
        lock_boundary: true,
        levels: 1,
        ..EncodeOptions::default()
    };
    assert_roundtrip(&mesh, &options);
    let options = EncodeOptions {
        lock_boundary: true,
        levels: 7,
        ..EncodeOptions::default()
    };
    assert_roundtrip(&mesh, &options);
}
