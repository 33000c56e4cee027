//! Host tests of the wrapper logic, on the conformance vectors (read from
//! their manifest, so they follow the format version in use).

use std::path::PathBuf;

use serde_json::Value;

#[cfg(feature = "grid")]
use crate::GridSimplifier;
use crate::{SdkError, StreamDecoder};

/// The newest vector set: `conformance/vectors/<version>/`.
fn vector_dir() -> PathBuf {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../conformance/vectors");
    let mut versions: Vec<PathBuf> = std::fs::read_dir(&root)
        .expect("conformance/vectors")
        .map(|e| e.unwrap().path())
        .filter(|p| p.join("manifest.json").is_file())
        .collect();
    versions.sort_by_key(|p| {
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        name.split('.')
            .map(|n| n.parse::<u32>().unwrap_or(0))
            .collect::<Vec<_>>()
    });
    versions.pop().expect("a vector set with a manifest.json")
}

fn vectors() -> (PathBuf, Vec<Value>) {
    let dir = vector_dir();
    let manifest: Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap();
    (dir, manifest["vectors"].as_array().unwrap().clone())
}

/// Decodes `stream` the way a browser would: head first, then each level's
/// range, round by round; returns the hash after the seed and every round.
fn decode_by_rounds(stream: &[u8]) -> Result<Vec<String>, SdkError> {
    let head_len = StreamDecoder::head_length(stream)?;
    let mut d = StreamDecoder::new(&stream[..head_len.min(stream.len())])?;
    let mut hashes = Vec::new();
    while let Some(k) = d.next_level() {
        let r = d.level_range(k)?;
        let bytes = stream
            .get(r[0] as usize..r[1] as usize)
            .ok_or_else(|| SdkError::from(splitstream_decoder_core::Error::Truncated))?;
        d.begin_level(k, bytes)?;
        if k == 0 {
            hashes.push(d.state_hash_hex());
        }
        while d.next_round()? {
            hashes.push(d.state_hash_hex());
        }
    }
    assert_eq!(d.levels_done(), d.level_count());
    let n = d.vertex_count() as usize;
    assert_eq!(d.fill_f32().len(), 3 * n);
    assert_eq!(d.fill_f64().len(), 3 * n);
    Ok(hashes)
}

fn decode_by_levels(stream: &[u8]) -> Result<String, SdkError> {
    let mut d = StreamDecoder::new(stream)?;
    while let Some(k) = d.next_level() {
        let r = d.level_range(k)?;
        let bytes = stream
            .get(r[0] as usize..r[1] as usize)
            .ok_or_else(|| SdkError::from(splitstream_decoder_core::Error::Truncated))?;
        d.decode_level(k, bytes)?;
    }
    Ok(d.state_hash_hex())
}

#[test]
fn every_vector_decodes_or_fails_as_the_manifest_says() {
    let (dir, vectors) = vectors();
    let mut valid = 0;
    for v in &vectors {
        let name = v["name"].as_str().unwrap();
        let stream = std::fs::read(dir.join(v["file"].as_str().unwrap())).unwrap();
        let expected: Vec<String> = v["round_hashes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|h| h.as_str().unwrap().to_string())
            .collect();
        if v["valid"].as_bool().unwrap() {
            let hashes = decode_by_rounds(&stream).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(hashes, expected, "{name}");
            let last = decode_by_levels(&stream).unwrap();
            assert_eq!(last, v["result"]["state_hash"].as_str().unwrap(), "{name}");
            valid += 1;
        } else {
            let class = v["error_class"].as_str().unwrap();
            let e = decode_by_rounds(&stream).expect_err(name);
            assert_eq!(e.class, class, "{name}: {e}");
            assert!(!e.message.is_empty() && !e.message.contains('\n'));
        }
    }
    assert!(valid >= 5, "too few valid vectors in {}", dir.display());
}

fn first_valid_multilevel() -> Vec<u8> {
    let (dir, vectors) = vectors();
    let v = vectors
        .iter()
        .find(|v| v["valid"].as_bool().unwrap() && v["result"]["levels"].as_u64().unwrap() >= 3)
        .expect("a valid vector with 3 levels");
    std::fs::read(dir.join(v["file"].as_str().unwrap())).unwrap()
}

#[test]
fn misuse_gives_api_misuse_errors() {
    let stream = first_valid_multilevel();
    let mut d = StreamDecoder::new(&stream).unwrap();
    // Level 1 before level 0.
    let r1 = d.level_range(1).unwrap();
    let e = d
        .decode_level(1, &stream[r1[0] as usize..r1[1] as usize])
        .unwrap_err();
    assert_eq!(e.class, "api-misuse", "{e}");
    // Out-of-range level index.
    let e = d.level_range(d.level_count()).unwrap_err();
    assert_eq!(e.class, "invalid-argument");
    // A level begun: no other level may start until it completes.
    let r0 = d.level_range(0).unwrap();
    let level0 = &stream[r0[0] as usize..r0[1] as usize];
    d.begin_level(0, level0).unwrap();
    assert_eq!(d.next_level(), None);
    let e = d.decode_level(0, level0).unwrap_err();
    assert_eq!(e.class, "api-misuse");
    while d.next_round().unwrap() {}
    assert_eq!(d.levels_done(), 1);
    assert_eq!(d.next_level(), Some(1));
    assert!(!d.next_round().unwrap(), "no level begun");
    // Wrong bytes poison the decoder; it stays failed.
    let r1 = d.level_range(1).unwrap();
    let mut bad = stream[r1[0] as usize..r1[1] as usize].to_vec();
    let mid = bad.len() / 2;
    bad[mid] ^= 0x40;
    assert!(d.decode_level(1, &bad).is_err());
    assert_eq!(d.next_level(), None);
    let e = d
        .decode_level(1, &stream[r1[0] as usize..r1[1] as usize])
        .unwrap_err();
    assert_eq!(e.class, "api-misuse");
}

#[test]
fn the_level_for_a_screen_error_follows_the_distance() {
    let stream = first_valid_multilevel();
    let d = StreamDecoder::new(&stream).unwrap();
    let fov = std::f32::consts::FRAC_PI_3;
    let last = d.level_count() - 1;
    // Close up, the level within error 0; very far, the base level.
    assert_eq!(
        d.level_for_screen_error(1080.0, fov, 0.0, 2.0),
        Ok(d.level_within_error(0.0).unwrap())
    );
    assert!(d.level_within_error(0.0).unwrap() <= last);
    // A bound that is no bound is refused, as the camera's parameters are.
    for bad in [f32::NAN, -1.0] {
        assert_eq!(
            d.level_within_error(bad).unwrap_err().class,
            "invalid-argument"
        );
    }
    assert_eq!(d.level_for_screen_error(1080.0, fov, 1e30, 2.0), Ok(0));
    let err = d
        .level_for_screen_error(1080.0, 4.0, 10.0, 2.0)
        .unwrap_err();
    assert_eq!(err.class, "invalid-argument");
    assert!(err.message.contains("field of view"), "{}", err.message);
}

#[test]
fn a_budget_holds_the_levels_that_fit() {
    let stream = first_valid_multilevel();
    let full = StreamDecoder::new(&stream).unwrap();
    assert_eq!(full.levels_that_fit(), full.level_count());
    // The base level's budget: one level.
    let err = StreamDecoder::within_budget(&stream, 1.0).err().unwrap();
    assert_eq!(err.class, "capacity-exceeded");
    let err = StreamDecoder::within_budget(&stream, f64::NAN)
        .err()
        .unwrap();
    assert_eq!(err.class, "invalid-argument");
    let whole = StreamDecoder::within_budget(&stream, f64::INFINITY).unwrap();
    assert_eq!(whole.levels_that_fit(), full.level_count());
    let mut budget = full.workspace_bytes();
    let smaller = loop {
        budget = (budget * 0.75).floor();
        match StreamDecoder::within_budget(&stream, budget) {
            Ok(d) if d.levels_that_fit() < full.level_count() => break d,
            Ok(_) => continue,
            Err(e) => panic!("no budget between the base level and all: {e}"),
        }
    };
    assert!(smaller.workspace_bytes() <= budget);
    assert!(smaller.levels_that_fit() >= 1);
}

#[test]
fn dropping_mid_level_frees_cleanly() {
    let stream = first_valid_multilevel();
    for rounds in 0..3 {
        let mut d = StreamDecoder::new(&stream).unwrap();
        let r = d.level_range(0).unwrap();
        d.begin_level(0, &stream[r[0] as usize..r[1] as usize])
            .unwrap();
        for _ in 0..rounds {
            d.next_round().unwrap();
        }
        // Freed with the level open (Miri checks this for Session itself).
        drop(d);
    }
}

#[test]
fn head_length_needs_the_header() {
    let stream = first_valid_multilevel();
    let n = StreamDecoder::head_length(&stream[..96]).unwrap();
    assert!(n > 96 && n < stream.len());
    let e = StreamDecoder::head_length(&stream[..50]).unwrap_err();
    assert_eq!(e.class, "truncated");
    // The head alone opens the decoder; a byte less does not.
    assert!(StreamDecoder::new(&stream[..n]).is_ok());
    let e = StreamDecoder::new(&stream[..n - 1]).err().unwrap();
    assert_eq!(e.class, "truncated");
}

#[cfg(feature = "grid")]
#[test]
fn grid_simplifier_wraps_the_tile_simplifier() {
    let (rows, cols) = (33, 17);
    let plane: Vec<f64> = (0..rows * cols)
        .map(|i| 2.0 + 0.5 * (i % cols) as f64 - 0.25 * (i / cols) as f64)
        .collect();
    let mut g = GridSimplifier::new(rows, cols);
    let s = g
        .simplify(
            &plane,
            rows,
            cols,
            &[10.0, 10.0],
            &[5.0, 7.0],
            700.0,
            &[],
            &[],
        )
        .unwrap();
    assert_eq!((s.cells, s.rectangles, s.triangles_after), (512, 1, 2));
    assert!(s.max_vertical_error < 1e-9);
    assert_eq!(g.simplifier().result().positions[0], [5.0, 7.0, 2.0]);
    assert_eq!(g.fill_f32().len(), 3 * s.vertices_after);

    // Float32 heights give the same result on a rough tile.
    let rough: Vec<f64> = (0..rows * cols)
        .map(|i| ((i % cols) as f64 * 0.7).sin() * 9.0 + ((i / cols) as f64 * 0.3).cos() * 5.0)
        .map(|h| (h as f32) as f64)
        .collect();
    let narrow: Vec<f32> = rough.iter().map(|&h| h as f32).collect();
    let res = [0.0, 20.0, f64::NAN, 0.0];
    let a = g
        .simplify(
            &rough,
            rows,
            cols,
            &[10.0, 10.0],
            &[0.0, 0.0],
            5000.0,
            &res,
            &[1, 1, 1, 1],
        )
        .unwrap();
    let tris = g.simplifier().result().triangles.clone();
    let b = g
        .simplify_f32(
            &narrow,
            rows,
            cols,
            &[10.0, 10.0],
            &[0.0, 0.0],
            5000.0,
            &res,
            &[],
        )
        .unwrap();
    assert_eq!(a, b);
    assert_eq!(tris, g.simplifier().result().triangles);
    assert!(a.rectangles < a.cells && a.max_error_ratio <= 1.0 + 1e-9);

    // Bad input: typed classes.
    let e = g
        .simplify(&plane, rows, cols, &[10.0], &[0.0, 0.0], 700.0, &[], &[])
        .unwrap_err();
    assert_eq!(e.class, "invalid-argument");
    let e = g
        .simplify(
            &plane,
            rows,
            cols,
            &[10.0, 10.0],
            &[0.0, 0.0],
            700.0,
            &[1.0],
            &[],
        )
        .unwrap_err();
    assert_eq!(e.class, "invalid-argument");
    let e = g
        .simplify(
            &plane[1..],
            rows,
            cols,
            &[10.0, 10.0],
            &[0.0, 0.0],
            700.0,
            &[],
            &[],
        )
        .unwrap_err();
    assert_eq!(e.class, "grid-tile");
    assert!(e.message.contains("heights"), "{e}");
}
