//! Every input reader on arbitrary bytes: the first byte picks the format
//! (by extension, as `splitstream encode` does), the rest is the file. A
//! mesh that reads is then checked and repaired, as the CLI would. Any
//! panic, abort or unbounded allocation is a finding; errors are fine.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use splitstream_encoder::input::{
    ReadOptions, SUPPORTED_EXTENSIONS, check_mesh, read_mesh, repair_mesh,
};

/// A scratch folder of this process (files must have the format's
/// extension, and readers take paths).
fn scratch() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let base =
            std::env::var_os("SPLITSTREAM_FUZZ_DIR").map_or_else(std::env::temp_dir, PathBuf::from);
        let dir = base.join(format!("splitstream-read-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("scratch folder");
        dir
    })
}

fuzz_target!(|data: &[u8]| {
    let Some((&pick, contents)) = data.split_first() else {
        return;
    };
    let extension = SUPPORTED_EXTENSIONS[pick as usize % SUPPORTED_EXTENSIONS.len()];
    let path = scratch().join(format!("input.{extension}"));
    std::fs::write(&path, contents).expect("scratch file");
    if let Ok(mesh) = read_mesh(&path, &ReadOptions::default()) {
        let _ = check_mesh(&mesh);
        let (repaired, _) = repair_mesh(&mesh);
        let _ = check_mesh(&repaired);
    }
});
