//! Status codes and the per-thread last error.

use std::cell::RefCell;
use std::ffi::{CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

use splitstream_decoder_core::Error;

use crate::ffi::Refusal;
use crate::grid_tile::GridTileError;

/// Result of a C ABI call. The decoder's codes are its conformance error
/// classes (decoder-core SPEC §10).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SsStatus {
    Ok = 0,
    BadMagic = 1,
    UnsupportedVersion = 2,
    Malformed = 3,
    ChecksumMismatch = 4,
    Truncated = 5,
    /// A count beyond the capacity the header declares; a memory budget
    /// (`ss_decoder_open_within`) too small for the base level; a level
    /// beyond those that fit the decoder's memory
    /// (`ss_decoder_levels_that_fit`), refused without failing the decoder.
    CapacityExceeded = 6,
    CountMismatch = 7,
    RingOffsetOutOfRange = 8,
    ValenceOverflow = 9,
    // 10 is unused: format 1.0's dependent-splits, gone in 2.0.
    NonManifold = 11,
    PositionOutOfRange = 12,
    /// Levels fed out of order or while another is open (refused, the
    /// decoder unchanged); any decoding call after a failure.
    ApiMisuse = 13,
    /// A null pointer, a level's bytes of another length than its
    /// level-table entry's, an output buffer too short, a level index out of
    /// range, a value that is not a number the call takes. Refused before
    /// anything is decoded: the decoder is unchanged.
    InvalidArgument = 14,
    /// The grid-tile simplifier refused its input (see the message).
    GridTile = 15,
    /// A bug: a panic was caught at the boundary.
    Panic = 16,
}

struct LastError {
    class: CString,
    message: CString,
}

thread_local! {
    static LAST: RefCell<LastError> = RefCell::new(LastError {
        class: CString::default(),
        message: CString::default(),
    });
}

fn set_last(class: &str, message: String) {
    // Messages are ours and hold no NUL; strip any just in case.
    let clean = |s: String| CString::new(s.replace('\0', " ")).unwrap_or_default();
    LAST.with(|l| {
        *l.borrow_mut() = LastError {
            class: clean(class.to_string()),
            message: clean(message),
        }
    });
}

/// Records `e` as the last error and gives its status.
pub(crate) fn fail_decoder(e: Error) -> SsStatus {
    set_last(e.class(), e.to_string());
    match e.class() {
        "bad-magic" => SsStatus::BadMagic,
        "unsupported-version" => SsStatus::UnsupportedVersion,
        "checksum-mismatch" => SsStatus::ChecksumMismatch,
        "truncated" => SsStatus::Truncated,
        "capacity-exceeded" => SsStatus::CapacityExceeded,
        "count-mismatch" => SsStatus::CountMismatch,
        "ring-offset-out-of-range" => SsStatus::RingOffsetOutOfRange,
        "valence-overflow" => SsStatus::ValenceOverflow,
        "non-manifold" => SsStatus::NonManifold,
        "position-out-of-range" => SsStatus::PositionOutOfRange,
        "api-misuse" => SsStatus::ApiMisuse,
        _ => SsStatus::Malformed,
    }
}

pub(crate) fn fail_grid(e: GridTileError) -> SsStatus {
    set_last("grid-tile", e.to_string());
    SsStatus::GridTile
}

/// Records a call the session refused (it is unchanged) and gives its
/// status: `api-misuse`, `capacity-exceeded` or `invalid-argument`.
pub(crate) fn fail_refusal(r: Refusal) -> SsStatus {
    set_last(r.class(), r.to_string());
    match r.class() {
        "capacity-exceeded" => SsStatus::CapacityExceeded,
        "invalid-argument" => SsStatus::InvalidArgument,
        _ => SsStatus::ApiMisuse,
    }
}

pub(crate) fn fail_argument(what: &str) -> SsStatus {
    set_last("invalid-argument", what.to_string());
    SsStatus::InvalidArgument
}

/// Runs `f`, turning a panic into [`SsStatus::Panic`].
pub(crate) fn guard(f: impl FnOnce() -> SsStatus) -> SsStatus {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(s) => s,
        Err(p) => {
            let what = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            set_last("panic", format!("internal error (please report): {what}"));
            SsStatus::Panic
        }
    }
}

/// The last failure's message on this thread (empty if none), valid until
/// the next failing call on this thread.
#[unsafe(no_mangle)]
pub extern "C" fn ss_last_error_message() -> *const c_char {
    LAST.with(|l| l.borrow().message.as_ptr())
}

/// The last failure's class on this thread: a decoder conformance class
/// ("truncated", "checksum-mismatch", …), "invalid-argument", "grid-tile"
/// or "panic"; empty if none. Valid until the next failing call.
#[unsafe(no_mangle)]
pub extern "C" fn ss_last_error_class() -> *const c_char {
    LAST.with(|l| l.borrow().class.as_ptr())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::CStr;

    fn last() -> (String, String) {
        // SAFETY: NUL-terminated strings, valid until the next failure.
        let text = |p| unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned();
        (text(ss_last_error_class()), text(ss_last_error_message()))
    }

    /// A panic (a bug) stops at the boundary as `SS_STATUS_PANIC`, its
    /// message kept whatever its payload.
    #[test]
    fn a_panic_becomes_a_status_and_its_message() {
        assert_eq!(guard(|| panic!("a static message")), SsStatus::Panic);
        assert_eq!(last().0, "panic");
        assert!(last().1.ends_with("a static message"), "{:?}", last().1);
        let n = 7;
        assert_eq!(guard(|| panic!("a formatted message {n}")), SsStatus::Panic);
        assert!(last().1.ends_with("a formatted message 7"));
        assert_eq!(guard(|| std::panic::panic_any(42u8)), SsStatus::Panic);
        assert!(last().1.ends_with("unknown panic"));
        assert_eq!(guard(|| SsStatus::Ok), SsStatus::Ok);
    }
}
