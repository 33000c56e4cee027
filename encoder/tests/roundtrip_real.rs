//! decode(encode(M)) == M on every real mesh of encoder/data/fetch.sh, in
//! both position modes (the files are fetched by .ci/run; without them this
//! test says so and passes).

mod roundtrip_check;

use std::path::Path;

use splitstream_decoder_core::PositionMode;
use splitstream_decoder_core::writer::ChunkCodec;
use splitstream_encoder::emit::EncodeOptions;
use splitstream_encoder::input::{ReadOptions, check_mesh, read_mesh};
use splitstream_encoder::quantize::Units;

#[test]
fn real_meshes_roundtrip_exactly() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/real");
    let files = [
        ("bunny.ply", Units::Linear),
        ("armadillo.off", Units::Linear),
        ("bunny00.off", Units::Linear),
        ("refined_elephant.off", Units::Linear),
        ("jacksboro_fault_dem.npz", Units::Geographic),
        ("bunny.glb", Units::Linear),
        ("armadillo.gltf", Units::Linear),
        ("refined_elephant.stl", Units::Linear),
    ];
    for (file, units) in files {
        let path = dir.join(file);
        if !path.exists() {
            eprintln!("skipped {file}: run encoder/data/fetch.sh");
            continue;
        }
        let mesh = read_mesh(&path, &ReadOptions::default()).unwrap();
        check_mesh(&mesh).unwrap();
        // The default codec (rANS, deflate where smaller) in optimal mode;
        // rANS on every substream in 7 lanes in constrained mode.
        for (mode, codec) in [
            (PositionMode::Optimal, ChunkCodec::Rans { lanes: 4 }),
            (
                PositionMode::Constrained,
                ChunkCodec::RansAlways { lanes: 7 },
            ),
        ] {
            let options = EncodeOptions {
                position_mode: mode,
                codec,
                units,
                ..EncodeOptions::default()
            };
            let bytes = roundtrip_check::assert_roundtrip(&mesh, &options);
            eprintln!("{file} {mode:?}: {bytes} bytes, exact");
        }
    }
}
