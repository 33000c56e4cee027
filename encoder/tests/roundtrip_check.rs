//! The exactness check shared by the round-trip tests.
#![allow(dead_code)]

use splitstream_decoder_core::owned::decode_all;
use splitstream_encoder::Mesh;
use splitstream_encoder::emit::{EncodeOptions, Encoded, encode, quantize_for};
use splitstream_encoder::mesh::sorted_canonical;

/// Encodes, decodes with decoder-core from the bytes alone, and compares;
/// returns the stream's length.
pub fn assert_roundtrip(mesh: &Mesh, options: &EncodeOptions) -> usize {
    roundtrip(mesh, options).stream.len()
}

/// [`assert_roundtrip`], returning what the encoder wrote.
pub fn roundtrip(mesh: &Mesh, options: &EncodeOptions) -> Encoded {
    let encoded = encode(mesh, options, |_| {}).expect("encode");
    let decoded = decode_all(&encoded.stream, false).expect("decode");
    let q = quantize_for(mesh, options);
    assert_eq!(encoded.on_lattice, q.on_lattice);
    assert_eq!(decoded.positions.len(), mesh.positions.len());
    for (d, &e) in encoded.permutation.iter().enumerate() {
        assert_eq!(decoded.positions[d], q.positions[e as usize], "vertex {e}");
        // An axis on its own lattice comes back exactly (up to the f64
        // rounding of origin + i * step).
        let real = q.dequantize(decoded.positions[d]);
        let input = mesh.positions[e as usize];
        for k in (0..3).filter(|&k| q.on_lattice[k]) {
            let tolerance = 1e-9 * (q.scale[k] * (1u64 << q.bits) as f64);
            assert!(
                (real[k] - input[k]).abs() <= tolerance,
                "vertex {e} axis {k}"
            );
        }
    }
    let got = sorted_canonical(&decoded.triangles, Some(&encoded.permutation));
    let want = sorted_canonical(&mesh.triangles, None);
    assert_eq!(got, want);
    assert_eq!(decoded.levels as usize, encoded.level_vertex_counts.len());
    encoded
}
