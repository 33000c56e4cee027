//! include/splitstream.h is what cbindgen generates from src/ffi/c today
//! (like the conformance vectors: regenerate, compare byte for byte).
//! After changing the C ABI: `SPLITSTREAM_BLESS=1 cargo test -p
//! splitstream-sdk-native --test c_header`, then commit the header.

use std::path::Path;

#[test]
fn committed_header_is_up_to_date() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(root.join("cbindgen.toml")).expect("cbindgen.toml");
    // From the C module's source files alone: no `cargo metadata` (which
    // could touch the workspace's Cargo.lock), nothing from other modules.
    let bindings = cbindgen::Builder::new()
        .with_config(config)
        .with_src(root.join("src/ffi/c/mod.rs"))
        .generate()
        .expect("cbindgen generates the header");
    let mut fresh = Vec::new();
    bindings.write(&mut fresh);
    let path = root.join("include/splitstream.h");
    if std::env::var_os("SPLITSTREAM_BLESS").is_some() {
        std::fs::write(&path, &fresh).expect("write include/splitstream.h");
        return;
    }
    let committed = std::fs::read(&path).unwrap_or_default();
    assert!(
        committed == fresh,
        "include/splitstream.h differs from what cbindgen generates now; regenerate it with \
         SPLITSTREAM_BLESS=1 cargo test -p splitstream-sdk-native --test c_header"
    );
    let text = String::from_utf8(fresh).unwrap();
    for f in [
        "ss_decoder_open",
        "ss_decoder_next_round",
        "ss_grid_simplify",
    ] {
        assert!(text.contains(f), "{f} missing from the header");
    }
}
