//! Setup shared by the C ABI test files: a stream from the conformance
//! vectors, decoders over it, its levels' bytes, the last error.
// Each test file uses part of this module.
#![allow(dead_code)]

use std::ffi::CStr;
use std::ptr;

use splitstream_sdk_native::ffi::c::*;

use super::vectors::newest_vectors;

/// The last error on this thread, as (class, message).
pub fn last_error() -> (String, String) {
    let text = |p: *const std::ffi::c_char| {
        assert!(!p.is_null(), "the last error's strings are never null");
        // SAFETY: ss_last_error_* return NUL-terminated strings valid until
        // the next failing call on this thread.
        unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
    };
    (text(ss_last_error_class()), text(ss_last_error_message()))
}

/// A small valid stream of several levels from the conformance vectors.
pub fn stream() -> Vec<u8> {
    std::fs::read(newest_vectors().join("valid/bunny-npm.sps")).expect("bunny-npm vector")
}

/// A decoder over the whole of `stream` with at most `budget` bytes of
/// working memory.
pub fn open_within(stream: &[u8], budget: u64) -> *mut SsDecoder {
    let mut d = ptr::null_mut();
    // SAFETY: a live slice and a writable out pointer.
    let status = unsafe { ss_decoder_open_within(stream.as_ptr(), stream.len(), budget, &mut d) };
    assert_eq!(status, SsStatus::Ok, "{:?}", last_error());
    assert!(!d.is_null());
    d
}

/// A decoder over the whole of `stream`.
pub fn open(stream: &[u8]) -> *mut SsDecoder {
    open_within(stream, u64::MAX)
}

/// The bytes of level `k` (offset and length from its table entry).
pub fn level_bytes(d: *const SsDecoder, stream: &[u8], k: u16) -> Vec<u8> {
    let mut info = SsLevelInfo::default();
    // SAFETY: a live handle and a writable struct.
    assert_eq!(
        unsafe { ss_decoder_level_info(d, k, &mut info) },
        SsStatus::Ok
    );
    let start = info.offset as usize;
    stream[start..start + info.length as usize].to_vec()
}
