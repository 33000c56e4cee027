//! What the criterion benches share: their encoded terrains, kept in
//! target/bench-data/ because encoding takes a while.

use std::path::PathBuf;

use splitstream_decoder_core::limits::{VERSION_MAJOR, VERSION_MINOR};
use splitstream_encoder::emit::{EncodeOptions, encode};
use splitstream_encoder::input::fractal_terrain;

/// The stream of the `side` × `side` fractal terrain (seed 2012) under
/// `options`, from target/bench-data/ when an earlier run cached it: the
/// file name carries the side, the format version and `name`, which must
/// tell the options apart.
pub fn terrain_stream(side: usize, name: &str, options: &EncodeOptions) -> Vec<u8> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/bench-data");
    let path = dir.join(format!(
        "terrain-{side}-v{VERSION_MAJOR}.{VERSION_MINOR}-{name}.sps"
    ));
    if let Ok(bytes) = std::fs::read(&path) {
        return bytes;
    }
    let mesh = fractal_terrain(side, 2012);
    let encoded = encode(&mesh, options, |_| {}).expect("encode the terrain");
    std::fs::create_dir_all(&dir).expect("create target/bench-data");
    std::fs::write(&path, &encoded.stream).expect("cache the stream");
    encoded.stream
}
