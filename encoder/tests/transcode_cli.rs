//! `splitstream transcode` and `info --codecs` from the command line.

mod cli;

use std::path::PathBuf;

use cli::{one_line_error, splitstream, succeeded};

fn temp(name: &str, contents: &str) -> PathBuf {
    cli::temp("transcode-cli", name, contents)
}

/// A stream of a 16 x 14 ESRI ASCII raster (30 m cells, whole metres),
/// written by `encode` under `name`.
fn stream(name: &str) -> PathBuf {
    let mut s = String::from(
        "ncols 16\nnrows 14\nxllcorner 500000\nyllcorner 4100000\ncellsize 30\nNODATA_value -9999\n",
    );
    for r in 0..14 {
        let row: Vec<String> = (0..16)
            .map(|c| format!("{}", 200 + (r * 7 + c * 13) % 23 + r * c / 4))
            .collect();
        s.push_str(&row.join(" "));
        s.push('\n');
    }
    let raster = temp(&format!("{name}.asc"), &s);
    let out = raster.with_file_name(name);
    succeeded(&splitstream(&[
        "encode",
        raster.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]));
    out
}

/// `verify`'s state hash line.
fn state_hash(path: &str) -> String {
    succeeded(&splitstream(&["verify", path]))
        .lines()
        .find(|l| l.starts_with("state hash"))
        .unwrap()
        .to_string()
}

#[test]
fn a_transcoded_stream_reaches_the_same_state() {
    let input = stream("in.sps");
    let s = input.to_str().unwrap();
    let output = input.with_file_name("deflated.sps");
    let o = output.to_str().unwrap();
    let report = succeeded(&splitstream(&[
        "transcode",
        s,
        "-o",
        o,
        "--codec",
        "deflate",
        "--chunk-size",
        "100",
    ]));
    assert!(report.contains("deflated.sps: "), "{report}");
    assert!(report.contains("decoder memory: "), "{report}");
    assert_eq!(state_hash(o), state_hash(s));
    // The stream's own options give it back byte for byte.
    let again = input.with_file_name("again.sps");
    succeeded(&splitstream(&[
        "transcode",
        o,
        "-o",
        again.to_str().unwrap(),
    ]));
    assert_eq!(
        std::fs::read(&again).unwrap(),
        std::fs::read(&input).unwrap()
    );
}

#[test]
fn bad_streams_and_arguments_get_one_line() {
    let garbage = temp("garbage.sps", "not a stream at all");
    let out = garbage.with_file_name("out.sps");
    let o = out.to_str().unwrap();
    let err = one_line_error(&splitstream(&[
        "transcode",
        garbage.to_str().unwrap(),
        "-o",
        o,
    ]));
    assert!(err.contains("garbage.sps: "), "{err}");
    let input = stream("for-errors.sps");
    let s = input.to_str().unwrap();
    for flag in ["--chunk-size", "--rans-chunk"] {
        let err = one_line_error(&splitstream(&["transcode", s, "-o", o, flag, "0"]));
        assert!(err.contains(flag), "{err}");
    }
    let bytes = std::fs::read(&input).unwrap();
    let cut = input.with_file_name("cut.sps");
    std::fs::write(&cut, &bytes[..bytes.len() - 3]).unwrap();
    let err = one_line_error(&splitstream(&["transcode", cut.to_str().unwrap(), "-o", o]));
    assert!(err.contains("cut.sps: the stream does not decode"), "{err}");
}

#[test]
fn info_gives_every_field_under_both_codecs() {
    let input = stream("for-info.sps");
    let s = input.to_str().unwrap();
    let doc: serde_json::Value =
        serde_json::from_str(&succeeded(&splitstream(&["info", s, "--json", "--codecs"]))).unwrap();
    // The encoder's own stream is what rANS gives again.
    assert_eq!(doc["recoded"]["rans"]["bytes"], doc["bytes"]);
    assert!(doc["recoded"]["deflate"]["bytes"].as_u64().unwrap() > 0);
    let fields = doc["fields"].as_object().unwrap();
    for (name, field) in fields {
        assert_eq!(field["recoded_bytes"]["rans"], field["bytes"], "{name}");
        assert!(field["recoded_bytes"]["deflate"].is_u64(), "{name}");
    }
    let text = succeeded(&splitstream(&["info", s, "--codecs"]));
    assert!(text.contains("as deflate"), "{text}");
}
