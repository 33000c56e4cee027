//! A stream of more levels than a compact level table holds (SPEC §3.3:
//! at most 255 under flag bit 3). The encoder's `--levels` stops at 64,
//! but the writer takes any plan: above 255 levels it writes the 3.11
//! framing (`compact-levels`, a fixed table) instead of a table no decoder
//! would accept, and the stream decodes to the same state either way.

use splitstream_decoder_core::limits::MAX_COMPACT_LEVELS;
use splitstream_decoder_core::owned::decode_all;
use splitstream_decoder_core::writer::assemble_stream;
use splitstream_decoder_core::{Framing, Header, LevelTable};
use splitstream_encoder::emit::{EncodeOptions, LevelPlan, ReplayOptions, quantize_for, replay};
use splitstream_encoder::input::fractal_terrain;
use splitstream_encoder::simplify::{Backend, Checked, SimplifyOptions, simplify_on};

/// `plan`'s stream framed as `framing` asks.
fn written(
    mesh: &splitstream_encoder::quantize::QuantizedMesh,
    s: &splitstream_encoder::simplify::Simplification,
    plan: &LevelPlan,
    framing: Framing,
) -> Vec<u8> {
    let options = EncodeOptions {
        framing,
        ..EncodeOptions::default()
    };
    let params = options.stream_params(mesh);
    let replayed = replay(mesh, s, plan, &params, ReplayOptions::default()).expect("replay");
    assemble_stream(&params, &replayed.levels, replayed.framed)
}

/// A plan of one simplification step per level, `levels` levels: level 0
/// undoes the steps the others leave.
fn one_step_per_level(
    s: &splitstream_encoder::simplify::Simplification,
    levels: usize,
) -> LevelPlan {
    let steps = s.steps.len();
    assert!(steps >= levels, "{steps} steps for {levels} levels");
    // Decoding order: the latest step first.
    let order: Vec<usize> = (0..steps).rev().collect();
    let base = steps - (levels - 1);
    let mut rounds = vec![order[..base].to_vec()];
    rounds.extend(order[base..].iter().map(|&k| vec![k]));
    let errors = (0..levels).map(|l| (levels - 1 - l) as f32).collect();
    LevelPlan { rounds, errors }
}

#[test]
fn more_levels_than_a_compact_table_holds_fall_back_to_a_fixed_table() {
    let mesh = quantize_for(&fractal_terrain(40, 7), &EncodeOptions::default());
    let checked = Checked::new(&mesh).expect("a grid is a manifold");
    // Few collapses a step, so that the grid takes hundreds of steps.
    let options = SimplifyOptions {
        target_vertices: 16,
        admit_quantile: 0.02,
        constrained: true,
        ..SimplifyOptions::default()
    };
    let s = simplify_on(Backend::Cpu, &checked, &options, |_| {}).expect("simplify");
    let most = usize::from(MAX_COMPACT_LEVELS);
    let mut hashes = Vec::new();
    for (levels, framing) in [(most, Framing::Compact), (most + 1, Framing::CompactLevels)] {
        let stream = written(&mesh, &s, &one_step_per_level(&s, levels), Framing::Compact);
        let header = Header::parse(&stream).expect("header");
        assert_eq!(usize::from(header.level_count), levels);
        assert_eq!(header.framing, framing, "{levels} levels");
        let table = LevelTable::parse(&stream, &header).expect("table");
        assert_eq!(table.iter().count(), levels);
        let decoded = decode_all(&stream, true).expect("the stream decodes");
        assert_eq!(decoded.triangles.len(), mesh.triangles.len());
        hashes.push(*decoded.round_hashes.last().expect("rounds"));
        // Asked for outright, the 3.11 framing gives the same state.
        let plain = written(
            &mesh,
            &s,
            &one_step_per_level(&s, levels),
            Framing::CompactLevels,
        );
        let again = decode_all(&plain, true).expect("the 3.11 stream decodes");
        assert_eq!(again.round_hashes, decoded.round_hashes);
        if framing == Framing::CompactLevels {
            assert_eq!(
                plain, stream,
                "the fallback is the 3.11 framing, byte for byte"
            );
        }
    }
    assert_eq!(hashes[0], hashes[1], "the same mesh, whatever the levels");
}
