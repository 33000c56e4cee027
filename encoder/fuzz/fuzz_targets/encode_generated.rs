//! The whole encoder on meshes built from fuzz bytes: valid connectivity
//! (rasters with holes, noisy spheres, tori, sheets with every vertex moved)
//! with whatever geometry the bytes give, coincident and collinear points,
//! flat patches, folds and all; and options picked by the fuzzer (bits
//! 1..=24, 1 to 7 levels, both position modes, both quantizations, the
//! lattice rule, every codec and chunk size, boundary locking, the
//! admission quantile, a maximum error, a base size).
//!
//! A mesh that `check_mesh` refuses is skipped. Every other mesh must
//! encode, and decoder-core, reading the stream alone, must give back its
//! triangles exactly (through the written permutation) and its quantized
//! positions. A panic, an encode error or a mismatch is a finding.
#![no_main]

use libfuzzer_sys::fuzz_target;
use splitstream_decoder_core::owned::decode_all;
use splitstream_decoder_core::writer::ChunkCodec;
use splitstream_decoder_core::{PositionMode, RecordOrder, Schedule};
use splitstream_encoder::Mesh;
use splitstream_encoder::emit::{EncodeOptions, encode, quantize_for};
use splitstream_encoder::input::{Grid, check_mesh, grid_to_mesh, icosphere};
use splitstream_encoder::mesh::sorted_canonical;
use splitstream_encoder::quantize::{Lattice, Quantization};

/// Fuzz bytes read front to back; zeros once they run out.
struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn byte(&mut self) -> u8 {
        let Some((&b, rest)) = self.0.split_first() else {
            return 0;
        };
        self.0 = rest;
        b
    }

    /// A value in `lo..=hi`.
    fn range(&mut self, lo: usize, hi: usize) -> usize {
        lo + self.byte() as usize % (hi - lo + 1)
    }

    fn flag(&mut self) -> bool {
        self.byte() & 1 == 1
    }
}

/// A raster of `rows` x `cols` samples on 0..8 (flats everywhere), some of
/// them missing (holes, cut corners, split sheets).
fn raster(b: &mut Bytes<'_>) -> Mesh {
    let (rows, cols) = (b.range(2, 24), b.range(2, 24));
    let mut elevations: Vec<f64> = (0..rows * cols).map(|_| (b.byte() % 8) as f64).collect();
    for _ in 0..b.range(0, 6) {
        let at = (b.byte() as usize * 7 + b.byte() as usize) % elevations.len();
        elevations[at] = f64::NAN;
    }
    grid_to_mesh(&Grid {
        rows,
        cols,
        elevations,
        origin: [0.0, 0.0],
        spacing: [1.0, if b.flag() { 1.0 } else { -2.5 }],
        nodata: None,
        coordinates: None,
    })
}

/// A torus of `n` x `m` quads split along either diagonal.
fn torus(b: &mut Bytes<'_>) -> Mesh {
    let (n, m) = (b.range(3, 14), b.range(3, 10));
    let mut positions = Vec::with_capacity(n * m);
    for i in 0..n {
        for j in 0..m {
            let (u, v) = (
                std::f64::consts::TAU * i as f64 / n as f64,
                std::f64::consts::TAU * j as f64 / m as f64,
            );
            positions.push([
                (3.0 + v.cos()) * u.cos(),
                (3.0 + v.cos()) * u.sin(),
                v.sin(),
            ]);
        }
    }
    let mut triangles = Vec::with_capacity(2 * n * m);
    for i in 0..n {
        for j in 0..m {
            let id = |i: usize, j: usize| ((i % n) * m + j % m) as u32;
            let (a, bb, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if b.flag() {
                triangles.extend([[a, bb, c], [a, c, d]]);
            } else {
                triangles.extend([[a, bb, d], [bb, c, d]]);
            }
        }
    }
    Mesh {
        positions,
        triangles,
    }
}

/// Moves every vertex by the bytes, on a lattice of `1 / scale` (a scale
/// of 1 puts many vertices on the same point).
fn jitter(mesh: &mut Mesh, b: &mut Bytes<'_>) {
    let scale = [1.0, 4.0, 64.0][b.range(0, 2)];
    let amount = b.range(0, 3) as f64;
    for p in &mut mesh.positions {
        for x in p.iter_mut() {
            let d = (b.byte() as i8) as f64 / 128.0 * amount;
            *x = ((*x + d) * scale).round() / scale;
        }
    }
}

fn mesh(b: &mut Bytes<'_>) -> Mesh {
    let mut mesh = match b.range(0, 2) {
        0 => raster(b),
        1 => icosphere(b.range(0, 2)),
        _ => torus(b),
    };
    if b.flag() {
        jitter(&mut mesh, b);
    }
    mesh
}

fn options(b: &mut Bytes<'_>, vertices: usize) -> EncodeOptions {
    let codec = match b.range(0, 4) {
        0 => ChunkCodec::Stored,
        1 => ChunkCodec::Deflate(b.range(1, 10) as u8),
        2 => ChunkCodec::Rans {
            lanes: b.range(1, 32) as u8,
        },
        _ => ChunkCodec::RansAlways {
            lanes: b.range(1, 32) as u8,
        },
    };
    let mut options = EncodeOptions {
        bits: b.range(1, 24) as u8,
        levels: b.range(1, 7),
        base_vertices: b.flag().then(|| b.range(0, vertices)),
        position_mode: if b.flag() {
            PositionMode::Constrained
        } else {
            PositionMode::Optimal
        },
        max_error: b.flag().then(|| [0.0, 1e-6, 0.01, 1.0][b.range(0, 3)]),
        codec,
        chunk_limit: [1, 7, 61, 4096][b.range(0, 3)],
        rans_chunk_limit: [1, 5, 61, 1 << 14][b.range(0, 3)],
        lock_boundary: b.flag(),
        admit_quantile: [1.0, 0.3, 0.05][b.range(0, 2)],
        quantization: if b.flag() {
            Quantization::Uniform
        } else {
            Quantization::PerAxis
        },
        lattice: [None, Some(Lattice::Keep), Some(Lattice::Ignore)][b.range(0, 2)],
        schedule: if b.flag() {
            Schedule::SplitValences
        } else {
            Schedule::EveryVertex
        },
        ..EncodeOptions::default()
    };
    // The record order (3.7): chosen per level (the default), or forced;
    // positions first only where a level can declare it (constrained).
    options.records = match b.range(0, 2) {
        1 => Some(RecordOrder::WingsFirst),
        2 if options.position_mode == PositionMode::Constrained => {
            Some(RecordOrder::PositionsFirst)
        }
        _ => None,
    };
    options
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let mesh = mesh(&mut b);
    if check_mesh(&mesh).is_err() {
        return;
    }
    let options = options(&mut b, mesh.positions.len());
    let encoded = match encode(&mesh, &options, |_| {}) {
        Ok(e) => e,
        Err(e) => panic!("a checked mesh did not encode: {e}"),
    };
    let decoded = decode_all(&encoded.stream, false).expect("the stream decodes");
    let q = quantize_for(&mesh, &options);
    assert_eq!(decoded.positions.len(), mesh.positions.len());
    for (d, &e) in encoded.permutation.iter().enumerate() {
        assert_eq!(decoded.positions[d], q.positions[e as usize], "vertex {e}");
    }
    let got = sorted_canonical(&decoded.triangles, Some(&encoded.permutation));
    let want = sorted_canonical(&mesh.triangles, None);
    assert_eq!(got, want, "the triangles come back");
});
