//! The C ABI's answers to calls that cannot be right and to calls after a
//! failure (audit M1–M3, L1): a failed decoder answers only
//! `SS_STATUS_API_MISUSE`, never `SS_STATUS_OK` with `decoded = false`; the
//! level pickers stay within the levels that fit; a level beyond them is
//! `SS_STATUS_CAPACITY_EXCEEDED`; a level begun twice says so; a level's
//! bytes of the wrong length (or a level index out of range) are
//! `SS_STATUS_INVALID_ARGUMENT`, refused before anything is decoded, and
//! the right bytes then decode to the same state as a clean decode.

mod c_abi_common;
mod vectors;

use std::ptr;

use c_abi_common::{last_error, level_bytes, open, open_within, stream};
use splitstream_sdk_native::ffi::c::*;

/// `status` is `want`, the last error of `class`, its message saying `what`.
#[track_caller]
fn refused(status: SsStatus, want: SsStatus, class: &str, what: &str) {
    assert_eq!(status, want, "{what}: {:?}", last_error());
    let (got_class, message) = last_error();
    assert_eq!(got_class, class, "{message}");
    assert!(message.contains(what), "{message:?} does not say {what:?}");
}

/// Level `k`'s bytes with one byte in its last chunk flipped (the chunk's
/// CRC then fails when the round that loads it runs).
fn corrupt_level_bytes(d: *const SsDecoder, stream: &[u8], k: u16) -> Vec<u8> {
    let mut bytes = level_bytes(d, stream, k);
    let last = bytes.len() - 1;
    bytes[last] ^= 0x5A;
    bytes
}

/// `n` as the messages write it, thousands grouped by commas.
fn grouped(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// Decodes every remaining level that fits, whole.
///
/// # Safety
/// `d` is a live handle.
unsafe fn decode_rest(d: *mut SsDecoder, stream: &[u8]) {
    // SAFETY: per the contract; the level bytes are live.
    unsafe {
        while let Ok(k) = u16::try_from(ss_decoder_next_level(d)) {
            let bytes = level_bytes(d, stream, k);
            assert_eq!(
                ss_decoder_decode_level(d, k, bytes.as_ptr(), bytes.len()),
                SsStatus::Ok,
                "level {k}: {:?}",
                last_error()
            );
        }
    }
}

/// The state hash after decoding the first `levels` levels, cleanly.
fn clean_hash(stream: &[u8], levels: u16) -> u64 {
    let d = open(stream);
    // SAFETY: `d` is live until freed; the level bytes are live.
    unsafe {
        for k in 0..levels {
            let bytes = level_bytes(d, stream, k);
            assert_eq!(
                ss_decoder_decode_level(d, k, bytes.as_ptr(), bytes.len()),
                SsStatus::Ok
            );
        }
        let hash = ss_decoder_state_hash(d);
        ss_decoder_free(d);
        hash
    }
}

/// After a failure, every call that decodes or reads the decoded positions
/// answers `SS_STATUS_API_MISUSE`, naming the failure; the level table is
/// still there to be read.
///
/// # Safety
/// `d` is a live handle that has just failed with `failure`.
unsafe fn assert_spent(d: *mut SsDecoder, stream: &[u8], failure: &str) {
    // SAFETY: per the contract; every pointer is live or a writable local.
    unsafe {
        for _ in 0..3 {
            let mut decoded = true;
            refused(
                ss_decoder_next_round(d, &mut decoded),
                SsStatus::ApiMisuse,
                "api-misuse",
                failure,
            );
            assert!(decoded, "*decoded is not written on a failure");
            assert!(last_error().1.contains("already failed"));
        }
        assert_eq!(ss_decoder_next_level(d), -1);
        let l0 = level_bytes(d, stream, 0);
        let l1 = level_bytes(d, stream, 1);
        for (k, bytes) in [(0, &l0), (1, &l1)] {
            refused(
                ss_decoder_decode_level(d, k, bytes.as_ptr(), bytes.len()),
                SsStatus::ApiMisuse,
                "api-misuse",
                "already failed",
            );
            refused(
                ss_decoder_decode_level_two_threads(d, k, bytes.as_ptr(), bytes.len()),
                SsStatus::ApiMisuse,
                "api-misuse",
                "already failed",
            );
            refused(
                ss_decoder_begin_level(d, k, bytes.as_ptr(), bytes.len()),
                SsStatus::ApiMisuse,
                "api-misuse",
                "already failed",
            );
        }
        let mut out = vec![0.0f64; 3 * ss_decoder_vertex_count(d) as usize + 3];
        refused(
            ss_decoder_positions_f64(d, out.as_mut_ptr(), out.len()),
            SsStatus::ApiMisuse,
            "api-misuse",
            "already failed",
        );
        let mut info = SsLevelInfo::default();
        assert_eq!(ss_decoder_level_info(d, 1, &mut info), SsStatus::Ok);
        let mut decoded = true;
        assert_eq!(
            ss_decoder_next_round(d, &mut decoded),
            SsStatus::ApiMisuse,
            "still spent after the other calls"
        );
    }
}

/// M1: begin_level on a level whose last chunk is corrupt, its rounds up to
/// CHECKSUM_MISMATCH; the next `ss_decoder_next_round` is API_MISUSE, not
/// OK with `decoded = false` ("level complete").
#[test]
fn next_round_after_a_failed_round_answers_api_misuse() {
    let s = stream();
    let d = open(&s);
    // SAFETY: `d` is live until freed; the slices are live.
    unsafe {
        let l0 = level_bytes(d, &s, 0);
        assert_eq!(
            ss_decoder_decode_level(d, 0, l0.as_ptr(), l0.len()),
            SsStatus::Ok
        );
        let bad = corrupt_level_bytes(d, &s, 1);
        assert_eq!(
            ss_decoder_begin_level(d, 1, bad.as_ptr(), bad.len()),
            SsStatus::Ok
        );
        let mut decoded = true;
        let mut status = SsStatus::Ok;
        while status == SsStatus::Ok && decoded {
            status = ss_decoder_next_round(d, &mut decoded);
        }
        assert_eq!(status, SsStatus::ChecksumMismatch, "{:?}", last_error());
        assert_spent(d, &s, "checksum mismatch");
        ss_decoder_free(d);
    }
    // The same with level 0 begun from corrupt bytes.
    let d = open(&s);
    // SAFETY: as above.
    unsafe {
        let bad = corrupt_level_bytes(d, &s, 0);
        let mut status = ss_decoder_begin_level(d, 0, bad.as_ptr(), bad.len());
        let mut decoded = true;
        while status == SsStatus::Ok && decoded {
            status = ss_decoder_next_round(d, &mut decoded);
        }
        assert_eq!(status, SsStatus::ChecksumMismatch, "{:?}", last_error());
        assert_spent(d, &s, "checksum mismatch");
        ss_decoder_free(d);
    }
}

/// M1, the two-thread call: after its failure, next_round is API_MISUSE.
#[test]
fn next_round_after_a_failed_two_thread_decode_answers_api_misuse() {
    let s = stream();
    for k in [0u16, 1] {
        let d = open(&s);
        // SAFETY: `d` is live until freed; the slices are live.
        unsafe {
            for j in 0..k {
                let bytes = level_bytes(d, &s, j);
                assert_eq!(
                    ss_decoder_decode_level_two_threads(d, j, bytes.as_ptr(), bytes.len()),
                    SsStatus::Ok
                );
            }
            let bad = corrupt_level_bytes(d, &s, k);
            assert_eq!(
                ss_decoder_decode_level_two_threads(d, k, bad.as_ptr(), bad.len()),
                SsStatus::ChecksumMismatch,
                "level {k}: {:?}",
                last_error()
            );
            assert_spent(d, &s, "checksum mismatch");
            ss_decoder_free(d);
        }
    }
}

/// M2: under a budget that holds all levels but the last, the level
/// pickers answer a level the decoder can decode, and the last level is
/// CAPACITY_EXCEEDED with a message that says why, the decoder unchanged.
#[test]
fn level_pickers_and_levels_stay_within_the_levels_that_fit() {
    let s = stream();
    let full = open(&s);
    // SAFETY: the handles are live until freed; the slices are live.
    unsafe {
        let count = ss_decoder_level_count(full);
        assert!(count >= 3, "{count} levels");
        let budget = ss_decoder_workspace_bytes(full) - 1;
        ss_decoder_free(full);

        let d = open_within(&s, budget);
        let fit = ss_decoder_levels_that_fit(d);
        assert_eq!(fit, count - 1, "all levels but the last fit");
        let mut level = u16::MAX;
        assert_eq!(
            ss_decoder_level_within_error(d, 0.0, &mut level),
            SsStatus::Ok
        );
        assert_eq!(level, fit - 1, "the finest level that fits");
        level = u16::MAX;
        assert_eq!(
            ss_decoder_level_for_screen_error(d, 1080.0, 1.0, 0.0, 1.0, &mut level),
            SsStatus::Ok
        );
        assert_eq!(level, fit - 1, "a camera at distance 0");

        let last = level_bytes(d, &s, fit);
        let says = format!(
            "level {fit} does not fit the memory this decoder was opened with (levels 0..={} fit)",
            fit - 1
        );
        // Before any level, and once the levels that fit are decoded.
        refused(
            ss_decoder_decode_level(d, fit, last.as_ptr(), last.len()),
            SsStatus::CapacityExceeded,
            "capacity-exceeded",
            &says,
        );
        assert_eq!(ss_decoder_next_level(d), 0, "refused, not failed");
        decode_rest(d, &s);
        assert_eq!(ss_decoder_next_level(d), -1);
        let bytes_of = |k: u16| level_bytes(d, &s, k);
        for k in [fit, count - 1] {
            let b = bytes_of(k);
            refused(
                ss_decoder_decode_level(d, k, b.as_ptr(), b.len()),
                SsStatus::CapacityExceeded,
                "capacity-exceeded",
                &says,
            );
            refused(
                ss_decoder_decode_level_two_threads(d, k, b.as_ptr(), b.len()),
                SsStatus::CapacityExceeded,
                "capacity-exceeded",
                &says,
            );
            refused(
                ss_decoder_begin_level(d, k, b.as_ptr(), b.len()),
                SsStatus::CapacityExceeded,
                "capacity-exceeded",
                &says,
            );
        }
        assert!(!last_error().1.contains("was expected"));
        // Unchanged: the state of a full decoder after the levels that fit.
        let mut decoded = true;
        assert_eq!(ss_decoder_next_round(d, &mut decoded), SsStatus::Ok);
        assert!(!decoded, "no level open");
        let n = 3 * ss_decoder_vertex_count(d) as usize;
        let mut out = vec![0.0f64; n];
        assert_eq!(
            ss_decoder_positions_f64(d, out.as_mut_ptr(), n),
            SsStatus::Ok
        );
        assert_eq!(ss_decoder_state_hash(d), clean_hash(&s, fit));
        ss_decoder_free(d);
    }
}

/// M2: a level begun while it is open says it is open (no "level 0 given
/// where level 0 was expected"); the open level then completes as if
/// nothing had happened.
#[test]
fn a_level_begun_twice_says_it_is_open() {
    let s = stream();
    let d = open(&s);
    // SAFETY: `d` is live until freed; the slices are live.
    unsafe {
        let count = ss_decoder_level_count(d);
        let l0 = level_bytes(d, &s, 0);
        let l1 = level_bytes(d, &s, 1);
        assert_eq!(
            ss_decoder_begin_level(d, 0, l0.as_ptr(), l0.len()),
            SsStatus::Ok
        );
        for _ in 0..2 {
            refused(
                ss_decoder_begin_level(d, 0, l0.as_ptr(), l0.len()),
                SsStatus::ApiMisuse,
                "api-misuse",
                "level 0 is already open",
            );
            assert!(!last_error().1.contains("where level 0 was expected"));
            refused(
                ss_decoder_decode_level(d, 0, l0.as_ptr(), l0.len()),
                SsStatus::ApiMisuse,
                "api-misuse",
                "level 0 is already open",
            );
            refused(
                ss_decoder_decode_level_two_threads(d, 1, l1.as_ptr(), l1.len()),
                SsStatus::ApiMisuse,
                "api-misuse",
                "level 1 given while level 0 is open",
            );
        }
        let mut decoded = true;
        while decoded {
            assert_eq!(ss_decoder_next_round(d, &mut decoded), SsStatus::Ok);
        }
        assert_eq!(ss_decoder_next_level(d), 1);
        // Level 0 again, now decoded: said so, not a contradiction.
        refused(
            ss_decoder_begin_level(d, 0, l0.as_ptr(), l0.len()),
            SsStatus::ApiMisuse,
            "api-misuse",
            "level 0 is already decoded",
        );
        decode_rest(d, &s);
        assert_eq!(ss_decoder_state_hash(d), clean_hash(&s, count));
        ss_decoder_free(d);
    }
}

/// L1: `ss_decoder_level_within_error` refuses NaN and negative bounds, as
/// `ss_decoder_level_for_screen_error` refuses parameters that describe no
/// camera; positions into a null buffer name the null pointer.
#[test]
fn bounds_that_are_no_bound_and_null_buffers_are_named() {
    let s = stream();
    let d = open(&s);
    // SAFETY: `d` is live until freed; the other pointers are writable
    // locals or the null pointers tested.
    unsafe {
        let count = ss_decoder_level_count(d);
        let mut level = 7u16;
        for bad in [f32::NAN, -1.0, f32::NEG_INFINITY, -f32::MIN_POSITIVE] {
            refused(
                ss_decoder_level_within_error(d, bad, &mut level),
                SsStatus::InvalidArgument,
                "invalid-argument",
                "error bound",
            );
            assert_eq!(level, 7, "nothing written");
        }
        assert_eq!(
            ss_decoder_level_within_error(d, f32::INFINITY, &mut level),
            SsStatus::Ok
        );
        assert_eq!(level, 0);
        assert_eq!(
            ss_decoder_level_within_error(d, 0.0, &mut level),
            SsStatus::Ok
        );
        assert!(level < count);
        assert_eq!(
            ss_decoder_level_within_error(d, -0.0, &mut level),
            SsStatus::Ok
        );

        decode_rest(d, &s);
        let n = 3 * ss_decoder_vertex_count(d) as usize;
        refused(
            ss_decoder_positions_f64(d, ptr::null_mut(), usize::MAX),
            SsStatus::InvalidArgument,
            "invalid-argument",
            "null output pointer",
        );
        let mut out = vec![0.0f64; n];
        refused(
            ss_decoder_positions_f64(d, out.as_mut_ptr(), n - 1),
            SsStatus::InvalidArgument,
            "invalid-argument",
            &format!("{n} doubles needed, {} given", n - 1),
        );
        ss_decoder_free(d);
    }
}

/// M3: a level's bytes one too many, one too few, the whole stream, or
/// none at all, through each of the three level calls, and level indices
/// out of range: INVALID_ARGUMENT naming both lengths (or the level), the
/// decoder unchanged; the right bytes then decode, to a clean decode's
/// final state hash.
#[test]
fn a_level_of_the_wrong_length_is_refused_and_can_be_retried() {
    let s = stream();
    type Call = unsafe extern "C" fn(*mut SsDecoder, u16, *const u8, usize) -> SsStatus;
    let calls: [(&str, Call); 3] = [
        ("decode_level", ss_decoder_decode_level),
        (
            "decode_level_two_threads",
            ss_decoder_decode_level_two_threads,
        ),
        ("begin_level", ss_decoder_begin_level),
    ];
    let mut count = 0;
    for (name, call) in calls {
        let d = open(&s);
        // SAFETY: `d` is live until freed; every slice is live, and the
        // null pointer goes with a length of 0.
        unsafe {
            count = ss_decoder_level_count(d);
            for k in 0..count {
                let right = level_bytes(d, &s, k);
                let mut long = right.clone();
                long.push(0);
                let wrong: [(*const u8, usize); 5] = [
                    (long.as_ptr(), long.len()),
                    (right.as_ptr(), right.len() - 1),
                    (s.as_ptr(), s.len()),
                    (ptr::null(), 0),
                    (right.as_ptr(), 0),
                ];
                for (bytes, len) in wrong {
                    let says = format!(
                        "level {k} is {} bytes; {} {} given",
                        grouped(right.len()),
                        grouped(len),
                        if len == 1 { "was" } else { "were" }
                    );
                    refused(
                        call(d, k, bytes, len),
                        SsStatus::InvalidArgument,
                        "invalid-argument",
                        &says,
                    );
                    assert_eq!(ss_decoder_next_level(d), i32::from(k), "{name}: unchanged");
                }
                for bad in [count, count + 1, u16::MAX] {
                    refused(
                        call(d, bad, right.as_ptr(), right.len()),
                        SsStatus::InvalidArgument,
                        "invalid-argument",
                        &format!("level {bad} does not exist"),
                    );
                }
                // The retry with the right bytes.
                assert_eq!(
                    call(d, k, right.as_ptr(), right.len()),
                    SsStatus::Ok,
                    "{name} level {k}: {:?}",
                    last_error()
                );
                let mut decoded = true;
                while decoded {
                    assert_eq!(ss_decoder_next_round(d, &mut decoded), SsStatus::Ok);
                }
            }
            assert_eq!(ss_decoder_next_level(d), -1);
            assert_eq!(
                ss_decoder_state_hash(d),
                clean_hash(&s, count),
                "{name}: the same state as a clean decode"
            );
            ss_decoder_free(d);
        }
    }
    assert!(count >= 2);
    assert_eq!(grouped(8215), "8,215");
    assert_eq!(grouped(1_234_567), "1,234,567");
}
