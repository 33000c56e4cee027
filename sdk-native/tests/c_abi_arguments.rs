//! Every argument check of the C ABI, called from Rust: null handles,
//! null or short buffers, level indices out of range, cameras that are no
//! camera, calls out of order. Each must answer its status and leave
//! `ss_last_error_class` / `ss_last_error_message` saying why, never crash.
//! (`c_abi.rs` runs the C program on the conformance vectors; its calls go
//! through a static library that coverage tools do not see, so the checks
//! are held here, where `cargo llvm-cov` measures them.)

mod c_abi_common;
mod vectors;

use std::ptr;

use c_abi_common::{last_error, level_bytes, open, stream};
use splitstream_sdk_native::ffi::c::*;
use vectors::newest_vectors;

/// `status` is `SS_STATUS_INVALID_ARGUMENT` and the message names `what`.
fn invalid(status: SsStatus, what: &str) {
    assert_eq!(status, SsStatus::InvalidArgument, "{what}");
    let (class, message) = last_error();
    assert_eq!(class, "invalid-argument");
    assert!(message.contains(what), "{message:?} does not say {what:?}");
}

#[test]
fn opening_checks_its_pointers() {
    let s = stream();
    let mut n = 0usize;
    // SAFETY (every call below): null pointers are what is tested; the
    // others are live slices or writable locals.
    unsafe {
        invalid(
            ss_head_len(ptr::null(), 96, &mut n),
            "null data pointer with a non-zero length",
        );
        invalid(
            ss_head_len(s.as_ptr(), s.len(), ptr::null_mut()),
            "null output pointer",
        );
        // A null pointer with no bytes is an empty stream: a decoder error.
        assert_eq!(ss_head_len(ptr::null(), 0, &mut n), SsStatus::Truncated);
        assert_eq!(last_error().0, "truncated");
        assert_eq!(ss_head_len(s.as_ptr(), s.len(), &mut n), SsStatus::Ok);
        assert!(n > 96 && n <= s.len());

        invalid(
            ss_decoder_open(s.as_ptr(), s.len(), ptr::null_mut()),
            "null output pointer",
        );
        let mut d = ptr::dangling_mut::<SsDecoder>();
        invalid(
            ss_decoder_open(ptr::null(), 10, &mut d),
            "null data pointer with a non-zero length",
        );
        assert!(d.is_null(), "a failed open sets the handle to null");
        let mut d = ptr::dangling_mut::<SsDecoder>();
        assert_eq!(
            ss_decoder_open(b"nope".as_ptr(), 4, &mut d),
            SsStatus::Truncated
        );
        assert!(d.is_null());
        let mut bad = s.clone();
        bad[0] ^= 0xFF;
        assert_eq!(
            ss_decoder_open(bad.as_ptr(), bad.len(), &mut d),
            SsStatus::BadMagic
        );
        assert_eq!(last_error().0, "bad-magic");
    }
}

#[test]
fn a_null_decoder_answers_nothing_and_fails_each_call() {
    let null: *mut SsDecoder = ptr::null_mut();
    let mut level = 0u16;
    let mut decoded = false;
    let mut info = SsLevelInfo::default();
    let bytes = [0u8; 4];
    // SAFETY: every handle is null, every other pointer a writable local.
    unsafe {
        assert_eq!(ss_decoder_levels_that_fit(null), 0);
        assert_eq!(ss_decoder_level_count(null), 0);
        assert_eq!(ss_decoder_workspace_bytes(null), 0);
        assert_eq!(ss_decoder_next_level(null), -1);
        assert_eq!(ss_decoder_vertex_count(null), 0);
        assert_eq!(ss_decoder_triangle_count(null), 0);
        assert!(ss_decoder_positions(null).is_null());
        assert!(ss_decoder_triangles(null).is_null());
        assert_eq!(ss_decoder_state_hash(null), 0);
        ss_decoder_free(null);

        invalid(ss_decoder_level_info(null, 0, &mut info), "null decoder");
        invalid(
            ss_decoder_level_within_error(null, 1.0, &mut level),
            "null decoder",
        );
        invalid(
            ss_decoder_level_for_screen_error(null, 1080.0, 1.0, 10.0, 1.0, &mut level),
            "null decoder",
        );
        invalid(
            ss_decoder_decode_level(null, 0, bytes.as_ptr(), 4),
            "null decoder",
        );
        invalid(
            ss_decoder_decode_level_two_threads(null, 0, bytes.as_ptr(), 4),
            "null decoder",
        );
        invalid(
            ss_decoder_begin_level(null, 0, bytes.as_ptr(), 4),
            "null decoder",
        );
        invalid(ss_decoder_next_round(null, &mut decoded), "null decoder");
        let mut out = [0.0f64; 3];
        invalid(
            ss_decoder_positions_f64(null, out.as_mut_ptr(), 3),
            "null decoder",
        );
    }
}

#[test]
fn a_live_decoder_checks_its_other_arguments() {
    let s = stream();
    let d = open(&s);
    let mut level = 0u16;
    // SAFETY: `d` is live until freed at the end; null pointers and short
    // lengths are what is tested.
    unsafe {
        let levels = ss_decoder_level_count(d);
        assert!(levels >= 2);
        let mut info = SsLevelInfo::default();
        invalid(
            ss_decoder_level_info(d, levels, &mut info),
            "level index beyond the level count",
        );
        invalid(
            ss_decoder_level_info(d, 0, ptr::null_mut()),
            "null output pointer",
        );
        invalid(
            ss_decoder_level_within_error(d, 1.0, ptr::null_mut()),
            "null output pointer",
        );
        invalid(
            ss_decoder_level_for_screen_error(d, 1080.0, 1.0, 10.0, 1.0, ptr::null_mut()),
            "null output pointer",
        );
        // Parameters that describe no camera: the reason in the message.
        for (height, fov, distance, pixels) in [
            (0.0, 1.0, 10.0, 1.0),
            (1080.0, 4.0, 10.0, 1.0),
            (1080.0, f32::NAN, 10.0, 1.0),
            (1080.0, 1.0, -1.0, 1.0),
            (1080.0, 1.0, 10.0, 0.0),
        ] {
            let status =
                ss_decoder_level_for_screen_error(d, height, fov, distance, pixels, &mut level);
            assert_eq!(
                status,
                SsStatus::InvalidArgument,
                "{height} {fov} {distance} {pixels}"
            );
            assert_eq!(last_error().0, "invalid-argument");
            assert!(!last_error().1.is_empty());
        }
        assert_eq!(
            ss_decoder_level_for_screen_error(
                d,
                1080.0,
                std::f32::consts::FRAC_PI_3,
                500.0,
                2.0,
                &mut level
            ),
            SsStatus::Ok
        );
        assert!(level < levels);
        assert_eq!(
            ss_decoder_level_within_error(d, f32::INFINITY, &mut level),
            SsStatus::Ok
        );
        assert_eq!(level, 0, "an unbounded error needs only level 0");

        // Level bytes: null with a length, then levels out of order.
        let l0 = level_bytes(d, &s, 0);
        let l1 = level_bytes(d, &s, 1);
        invalid(
            ss_decoder_decode_level(d, 0, ptr::null(), l0.len()),
            "null data pointer with a non-zero length",
        );
        invalid(
            ss_decoder_begin_level(d, 0, ptr::null(), 1),
            "null data pointer with a non-zero length",
        );
        invalid(
            ss_decoder_next_round(d, ptr::null_mut()),
            "null output pointer",
        );
        // Before any level: no mesh, and positions need no buffer.
        assert_eq!(ss_decoder_vertex_count(d), 0);
        assert_eq!(
            ss_decoder_positions_f64(d, ptr::null_mut(), 0),
            SsStatus::Ok
        );
        assert_eq!(
            ss_decoder_decode_level(d, 1, l1.as_ptr(), l1.len()),
            SsStatus::ApiMisuse,
            "level 1 before level 0"
        );
        assert_eq!(last_error().0, "api-misuse");
        ss_decoder_free(d);
    }
    // A fresh decoder, since a failed one answers only api-misuse.
    let d = open(&s);
    // SAFETY: as above.
    unsafe {
        let l0 = level_bytes(d, &s, 0);
        assert_eq!(
            ss_decoder_decode_level(d, 0, l0.as_ptr(), l0.len()),
            SsStatus::Ok
        );
        let n = 3 * ss_decoder_vertex_count(d) as usize;
        assert!(n > 0);
        let mut out = vec![0.0f64; n];
        invalid(
            ss_decoder_positions_f64(d, out.as_mut_ptr(), n - 1),
            "output buffer shorter than 3 * vertex_count",
        );
        invalid(
            ss_decoder_positions_f64(d, ptr::null_mut(), n),
            "null output pointer",
        );
        assert_eq!(
            ss_decoder_positions_f64(d, out.as_mut_ptr(), n),
            SsStatus::Ok
        );
        assert!(out.iter().all(|x| x.is_finite()));
        // Round by round: the next level begun, then its rounds to the end.
        let l1 = level_bytes(d, &s, 1);
        assert_eq!(
            ss_decoder_begin_level(d, 1, l1.as_ptr(), l1.len()),
            SsStatus::Ok
        );
        assert_eq!(ss_decoder_next_level(d), -1, "a level is open");
        let mut decoded = true;
        let mut rounds = 0;
        while decoded {
            assert_eq!(ss_decoder_next_round(d, &mut decoded), SsStatus::Ok);
            rounds += u32::from(decoded);
        }
        assert!(rounds > 0);
        assert_eq!(ss_decoder_next_level(d), 2);
        // A level fed twice is out of order.
        assert_eq!(
            ss_decoder_decode_level_two_threads(d, 1, l1.as_ptr(), l1.len()),
            SsStatus::ApiMisuse
        );
        assert_eq!(last_error().0, "api-misuse");
        ss_decoder_free(d);
    }
}

#[test]
fn a_corrupt_level_fails_with_its_class_and_the_decoder_stays_failed() {
    let s = stream();
    let d = open(&s);
    // SAFETY: `d` is live until freed; the slices are live.
    unsafe {
        let mut l0 = level_bytes(d, &s, 0);
        let last = l0.len() - 1;
        l0[last] ^= 0x5A;
        let status = ss_decoder_decode_level(d, 0, l0.as_ptr(), l0.len());
        assert_eq!(status, SsStatus::ChecksumMismatch);
        assert_eq!(last_error().0, "checksum-mismatch");
        l0[last] ^= 0x5A;
        assert_eq!(
            ss_decoder_decode_level(d, 0, l0.as_ptr(), l0.len()),
            SsStatus::ApiMisuse,
            "a failed decoder refuses further levels"
        );
        assert_eq!(ss_decoder_next_level(d), -1);
        ss_decoder_free(d);
    }
}

/// A level corrupted past its header fails in the round that loads the
/// chunk, through `ss_decoder_next_round`.
#[test]
fn a_corrupt_chunk_fails_in_its_round() {
    let s = stream();
    let d = open(&s);
    // SAFETY: `d` is live until freed; the slices are live.
    unsafe {
        let l0 = level_bytes(d, &s, 0);
        assert_eq!(
            ss_decoder_decode_level(d, 0, l0.as_ptr(), l0.len()),
            SsStatus::Ok
        );
        let mut l1 = level_bytes(d, &s, 1);
        let last = l1.len() - 1;
        l1[last] ^= 0x5A;
        assert_eq!(
            ss_decoder_begin_level(d, 1, l1.as_ptr(), l1.len()),
            SsStatus::Ok,
            "the level header and the seed do not reach the last chunk"
        );
        let mut decoded = true;
        let mut status = SsStatus::Ok;
        while decoded && status == SsStatus::Ok {
            status = ss_decoder_next_round(d, &mut decoded);
        }
        assert_eq!(status, SsStatus::ChecksumMismatch);
        assert_eq!(last_error().0, "checksum-mismatch");
        ss_decoder_free(d);
    }
}

/// Every invalid conformance vector, fed level by level through the C
/// ABI, fails with the status of its error class.
#[test]
fn every_invalid_vector_gets_the_status_of_its_class() {
    let dir = newest_vectors();
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap();
    let status_of = |class: &str| match class {
        "bad-magic" => SsStatus::BadMagic,
        "unsupported-version" => SsStatus::UnsupportedVersion,
        "malformed" => SsStatus::Malformed,
        "checksum-mismatch" => SsStatus::ChecksumMismatch,
        "truncated" => SsStatus::Truncated,
        "capacity-exceeded" => SsStatus::CapacityExceeded,
        "count-mismatch" => SsStatus::CountMismatch,
        "ring-offset-out-of-range" => SsStatus::RingOffsetOutOfRange,
        "valence-overflow" => SsStatus::ValenceOverflow,
        "non-manifold" => SsStatus::NonManifold,
        "position-out-of-range" => SsStatus::PositionOutOfRange,
        other => panic!("unknown class {other}"),
    };
    let mut checked = 0;
    for v in manifest["vectors"].as_array().unwrap() {
        if v["valid"].as_bool().unwrap() {
            continue;
        }
        let name = v["name"].as_str().unwrap();
        let want = status_of(v["error_class"].as_str().unwrap());
        let bytes = std::fs::read(dir.join(v["file"].as_str().unwrap())).unwrap();
        let mut d = ptr::null_mut();
        // SAFETY: live slices and a writable handle; `d` is freed below.
        let got = unsafe {
            let mut status = ss_decoder_open(bytes.as_ptr(), bytes.len(), &mut d);
            while status == SsStatus::Ok {
                let Ok(k) = u16::try_from(ss_decoder_next_level(d)) else {
                    break;
                };
                let mut info = SsLevelInfo::default();
                assert_eq!(ss_decoder_level_info(d, k, &mut info), SsStatus::Ok);
                // A range past the stream's end: the bytes there are, which
                // the decoder refuses, unchanged; the stream is truncated.
                let start = (info.offset as usize).min(bytes.len());
                let end = (start + info.length as usize).min(bytes.len());
                status = ss_decoder_decode_level(d, k, bytes[start..end].as_ptr(), end - start);
                if end - start < info.length as usize {
                    assert_eq!(status, SsStatus::InvalidArgument, "{name}");
                    assert!(last_error().1.contains("bytes; "), "{name}");
                    assert_eq!(ss_decoder_next_level(d), i32::from(k), "{name}");
                    status = SsStatus::Truncated;
                }
            }
            ss_decoder_free(d);
            status
        };
        assert_eq!(got, want, "{name}");
        checked += 1;
    }
    assert!(checked > 100, "{checked} invalid vectors");
}

#[test]
fn the_grid_simplifier_checks_its_arguments() {
    let heights = [0.0f64, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 9.0];
    let tile = SsGridTile {
        rows: 3,
        cols: 3,
        heights: heights.as_ptr(),
        spacing: [1.0, 1.0],
        origin: [0.0, 0.0],
    };
    let params = SsGridParams {
        viewing_height: 100.0,
        neighbour_res: [0.0; 4],
        neighbour_tiles: [0; 4],
    };
    let mut count = 7usize;
    // SAFETY: `g` is live until freed; null pointers are what is tested.
    unsafe {
        ss_grid_free(ptr::null_mut());
        assert!(ss_grid_positions(ptr::null(), &mut count).is_null());
        assert_eq!(count, 0);
        assert!(ss_grid_triangles(ptr::null(), ptr::null_mut()).is_null());
        // Sizes past any allocation give a simplifier sized for nothing.
        let huge = ss_grid_new(usize::MAX, usize::MAX);
        assert!(!huge.is_null());
        ss_grid_free(huge);

        let g = ss_grid_new(3, 3);
        assert!(ss_grid_positions(g, &mut count).is_null(), "no result yet");
        for (s, t, p) in [
            (ptr::null_mut(), &tile as *const _, &params as *const _),
            (g, ptr::null(), &params),
            (g, &tile, ptr::null()),
        ] {
            invalid(
                ss_grid_simplify(s, t, p, ptr::null_mut()),
                "null simplifier, tile or params",
            );
        }
        let overflow = SsGridTile {
            rows: usize::MAX,
            cols: 2,
            ..tile
        };
        invalid(
            ss_grid_simplify(g, &overflow, &params, ptr::null_mut()),
            "rows * cols overflows",
        );
        let no_heights = SsGridTile {
            heights: ptr::null(),
            ..tile
        };
        invalid(
            ss_grid_simplify(g, &no_heights, &params, ptr::null_mut()),
            "null heights",
        );
        // The simplifier's own refusal (a tile too small to triangulate):
        // its class, and no result left to read.
        let empty = SsGridTile {
            rows: 0,
            cols: 0,
            heights: ptr::null(),
            ..tile
        };
        assert_eq!(
            ss_grid_simplify(g, &empty, &params, ptr::null_mut()),
            SsStatus::GridTile
        );
        assert_eq!(last_error().0, "grid-tile");
        assert!(ss_grid_triangles(g, &mut count).is_null());
        assert_eq!(count, 0);
        // A good tile, then its mesh, with and without the counts.
        let mut stats = SsGridStats::default();
        assert_eq!(
            ss_grid_simplify(g, &tile, &params, &mut stats),
            SsStatus::Ok
        );
        assert_eq!(stats.cells, 4);
        assert!(!ss_grid_positions(g, &mut count).is_null());
        assert!(count >= 3);
        assert!(!ss_grid_triangles(g, ptr::null_mut()).is_null());
        assert!(!ss_grid_positions(g, ptr::null_mut()).is_null());
        ss_grid_free(g);
    }
}
