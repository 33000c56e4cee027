//! C ABI of the progressive decoder ([`Session`]).

use std::ptr;

use super::error::{SsStatus, fail_argument, fail_decoder, fail_refusal, guard};
use crate::ffi::{Refusal, Session};
use crate::view::ScreenView;

/// A progressive decoder (opaque). Create with `ss_decoder_open`, release
/// with `ss_decoder_free`.
pub struct SsDecoder {
    session: Session,
}

/// A level-table entry (decoder-core SPEC §4.1).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SsLevelInfo {
    /// Byte offset of the level in the stream: fetch `offset .. offset + length`.
    pub offset: u64,
    pub length: u32,
    /// Vertex and triangle counts once this level is decoded.
    pub vertex_count: u32,
    pub triangle_count: u32,
    pub round_count: u32,
    /// The encoder's estimate of the level's distance to the original.
    pub geometric_error: f32,
}

/// `len` bytes at `data` as a slice; null is allowed only for `len == 0`.
///
/// # Safety
/// Unless null, `data` must point to `len` readable bytes that stay
/// unchanged for `'a`.
unsafe fn byte_slice<'a>(data: *const u8, len: usize) -> Result<&'a [u8], SsStatus> {
    if data.is_null() {
        return if len == 0 {
            Ok(&[])
        } else {
            Err(fail_argument("null data pointer with a non-zero length"))
        };
    }
    // SAFETY: non-null, and the caller promises `len` readable bytes.
    Ok(unsafe { std::slice::from_raw_parts(data, len) })
}

/// # Safety
/// `decoder` is null or a live handle from `ss_decoder_open`.
unsafe fn session<'a>(decoder: *const SsDecoder) -> Option<&'a Session> {
    // SAFETY: the caller passes null or a live handle, not used mutably
    // elsewhere meanwhile (one thread at a time uses a handle).
    unsafe { decoder.as_ref() }.map(|d| &d.session)
}

/// The session behind `decoder` for a call that writes its result to
/// `out`: the argument failure when either is null.
///
/// # Safety
/// As [`session`].
unsafe fn session_and_out<'a, T>(
    decoder: *const SsDecoder,
    out: *mut T,
) -> Result<&'a Session, SsStatus> {
    // SAFETY: per the contract.
    let Some(s) = (unsafe { session(decoder) }) else {
        return Err(fail_argument("null decoder"));
    };
    if out.is_null() {
        return Err(fail_argument("null output pointer"));
    }
    Ok(s)
}

/// # Safety
/// As [`session`], with no other reference to the handle alive.
unsafe fn session_mut<'a>(decoder: *mut SsDecoder) -> Result<&'a mut Session, SsStatus> {
    // SAFETY: null or a live handle, used by one caller at a time.
    match unsafe { decoder.as_mut() } {
        Some(d) => Ok(&mut d.session),
        None => Err(fail_argument("null decoder")),
    }
}

/// Bytes of header and level table, from the first 96 bytes of a stream
/// (`header_len >= 96`): fetch that many bytes, then `ss_decoder_open`.
///
/// # Safety
/// `header` points to `header_len` readable bytes; `out` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_head_len(
    header: *const u8,
    header_len: usize,
    out: *mut usize,
) -> SsStatus {
    guard(|| {
        // SAFETY: per this function's contract.
        let bytes = match unsafe { byte_slice(header, header_len) } {
            Ok(b) => b,
            Err(s) => return s,
        };
        if out.is_null() {
            return fail_argument("null output pointer");
        }
        match Session::head_len(bytes) {
            Ok(n) => {
                // SAFETY: checked non-null; the caller promises it writable.
                unsafe { out.write(n) };
                SsStatus::Ok
            }
            Err(e) => fail_decoder(e),
        }
    })
}

/// Opens a decoder on the stream head `head[0 .. len]` (header and level
/// table, or the whole stream; the head is copied) and allocates all the
/// working memory the stream needs (decoder-core SPEC §9). On success
/// `*out` is the new handle; on failure it is set to null.
///
/// # Safety
/// `head` points to `len` readable bytes; `out` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_open(
    head: *const u8,
    len: usize,
    out: *mut *mut SsDecoder,
) -> SsStatus {
    // SAFETY: the same contract.
    unsafe { ss_decoder_open_within(head, len, u64::MAX, out) }
}

/// As `ss_decoder_open`, with at most `max_bytes` of working memory: the
/// decoder holds the longest prefix of levels that fits (a device's memory
/// budget; `ss_decoder_levels_that_fit`) and decodes those.
/// `SS_STATUS_CAPACITY_EXCEEDED` when not even the base level fits.
///
/// # Safety
/// `head` points to `len` readable bytes; `out` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_open_within(
    head: *const u8,
    len: usize,
    max_bytes: u64,
    out: *mut *mut SsDecoder,
) -> SsStatus {
    guard(|| {
        if out.is_null() {
            return fail_argument("null output pointer");
        }
        // SAFETY: checked non-null; writable per the contract.
        unsafe { out.write(ptr::null_mut()) };
        // SAFETY: per this function's contract.
        let bytes = match unsafe { byte_slice(head, len) } {
            Ok(b) => b,
            Err(s) => return s,
        };
        match Session::open_within(bytes, max_bytes) {
            Ok(session) => {
                let handle = Box::into_raw(Box::new(SsDecoder { session }));
                // SAFETY: as above.
                unsafe { out.write(handle) };
                SsStatus::Ok
            }
            Err(e) => fail_decoder(e),
        }
    })
}

/// Levels (base included) the decoder's working memory holds: all of them
/// unless opened with `ss_decoder_open_within`; 0 for a null handle.
///
/// # Safety
/// `decoder` is null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_levels_that_fit(decoder: *const SsDecoder) -> u16 {
    // SAFETY: per the contract.
    unsafe { session(decoder) }.map_or(0, Session::levels_that_fit)
}

/// Releases a decoder and all its memory; null is ignored.
///
/// # Safety
/// `decoder` is null or a handle from `ss_decoder_open` not freed yet; it
/// must not be used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_free(decoder: *mut SsDecoder) {
    if !decoder.is_null() {
        // SAFETY: from `Box::into_raw` in `ss_decoder_open`, freed once.
        drop(unsafe { Box::from_raw(decoder) });
    }
}

/// Levels in the stream (base level 0 included); 0 for a null handle.
///
/// # Safety
/// `decoder` is null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_level_count(decoder: *const SsDecoder) -> u16 {
    // SAFETY: per the contract.
    unsafe { session(decoder) }.map_or(0, Session::level_count)
}

/// Level `level`'s table entry (its byte range is `offset .. offset +
/// length`).
///
/// # Safety
/// `decoder` is null or a live handle; `out` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_level_info(
    decoder: *const SsDecoder,
    level: u16,
    out: *mut SsLevelInfo,
) -> SsStatus {
    // SAFETY: per the contract.
    let s = match unsafe { session_and_out(decoder, out) } {
        Ok(s) => s,
        Err(status) => return status,
    };
    let Some(e) = s.level_info(level) else {
        return fail_argument("level index beyond the level count");
    };
    let info = SsLevelInfo {
        offset: e.offset,
        length: e.length,
        vertex_count: e.vertex_count,
        triangle_count: e.triangle_count,
        round_count: e.round_count,
        geometric_error: e.geometric_error,
    };
    // SAFETY: checked non-null; writable per the contract.
    unsafe { out.write(info) };
    SsStatus::Ok
}

/// The coarsest level this decoder can decode (below
/// `ss_decoder_levels_that_fit`) whose geometric error (decoder-core SPEC
/// §4.1, model units) is at most `max_error`, the finest that fits when
/// none is, into `*out`: decode levels 0 ..= it. `max_error` is a number
/// of at least 0 (+infinity gives level 0); NaN or a negative bound is
/// `SS_STATUS_INVALID_ARGUMENT`.
///
/// # Safety
/// `decoder` is null or a live handle; `out` is null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_level_within_error(
    decoder: *const SsDecoder,
    max_error: f32,
    out: *mut u16,
) -> SsStatus {
    // SAFETY: per the contract.
    let s = match unsafe { session_and_out(decoder, out) } {
        Ok(s) => s,
        Err(status) => return status,
    };
    match s.checked_level_within_error(max_error) {
        Ok(k) => {
            // SAFETY: checked non-null; writable per the contract.
            unsafe { out.write(k) };
            SsStatus::Ok
        }
        Err(e) => fail_argument(&e.to_string()),
    }
}

/// The coarsest level this decoder can decode (below
/// `ss_decoder_levels_that_fit`) whose geometric error covers at most
/// `max_pixels` pixels on screen, the finest that fits when none does, for
/// a perspective camera with a viewport `viewport_height` pixels high and
/// a vertical field of view of `fov_y` radians, at `distance` model units
/// from the object, into `*out`. Parameters that describe no camera are
/// `SS_STATUS_INVALID_ARGUMENT`, with the reason in `ss_last_error_message`.
///
/// # Safety
/// `decoder` is null or a live handle; `out` is null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_level_for_screen_error(
    decoder: *const SsDecoder,
    viewport_height: f32,
    fov_y: f32,
    distance: f32,
    max_pixels: f32,
    out: *mut u16,
) -> SsStatus {
    // SAFETY: per the contract.
    let s = match unsafe { session_and_out(decoder, out) } {
        Ok(s) => s,
        Err(status) => return status,
    };
    let level = ScreenView::perspective(viewport_height, fov_y)
        .and_then(|view| s.level_for_screen_error(&view, distance, max_pixels));
    match level {
        Ok(k) => {
            // SAFETY: checked non-null; writable per the contract.
            unsafe { out.write(k) };
            SsStatus::Ok
        }
        Err(e) => fail_argument(&e.to_string()),
    }
}

/// Bytes of working memory the decoder holds (decoder-core SPEC §9).
///
/// # Safety
/// `decoder` is null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_workspace_bytes(decoder: *const SsDecoder) -> u64 {
    // SAFETY: per the contract.
    unsafe { session(decoder) }.map_or(0, Session::workspace_bytes)
}

/// The level to feed next, or -1 when every level that fits is decoded, a
/// level is being decoded round by round, the decoder failed, or it is
/// null.
///
/// # Safety
/// `decoder` is null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_next_level(decoder: *const SsDecoder) -> i32 {
    // SAFETY: per the contract.
    unsafe { session(decoder) }
        .and_then(Session::next_level)
        .map_or(-1, i32::from)
}

/// Decodes level `level` whole from its bytes `bytes[0 .. len]` (exactly
/// the level's range, `SsLevelInfo::length` bytes).
///
/// Refused before anything is decoded, the decoder unchanged (the call may
/// be repeated with the right arguments): `SS_STATUS_INVALID_ARGUMENT` for
/// a null pointer, a level beyond the stream, or `len` other than the
/// level's length (a short range response: fetch the level again);
/// `SS_STATUS_CAPACITY_EXCEEDED` for a level beyond
/// `ss_decoder_levels_that_fit`; `SS_STATUS_API_MISUSE` for a level out of
/// order or given while a level begun with `ss_decoder_begin_level` is
/// open. Any other status is a failure of the level's bytes: the decoder
/// is then spent, and `ss_decoder_decode_level`,
/// `ss_decoder_decode_level_two_threads`, `ss_decoder_begin_level`,
/// `ss_decoder_next_round` and `ss_decoder_positions_f64` answer only
/// `SS_STATUS_API_MISUSE` (`ss_decoder_next_level` -1): open a new one.
///
/// # Safety
/// `decoder` is a live handle; `bytes` points to `len` readable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_decode_level(
    decoder: *mut SsDecoder,
    level: u16,
    bytes: *const u8,
    len: usize,
) -> SsStatus {
    // SAFETY: the caller's contract is this function's.
    unsafe { with_level_bytes(decoder, level, bytes, len, Session::decode_level) }
}

/// `ss_decoder_decode_level` on two cores: the rounds on the calling
/// thread, the split records on a second thread that lives as long as the
/// call; the same state, the same statuses. The first call allocates 12
/// bytes per vertex of the decoder's capacity and about 1.6 MB more, kept
/// until `ss_decoder_free`.
///
/// # Safety
/// `decoder` is a live handle; `bytes` points to `len` readable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_decode_level_two_threads(
    decoder: *mut SsDecoder,
    level: u16,
    bytes: *const u8,
    len: usize,
) -> SsStatus {
    // SAFETY: the caller's contract is this function's.
    unsafe {
        with_level_bytes(
            decoder,
            level,
            bytes,
            len,
            Session::decode_level_two_threads,
        )
    }
}

/// Starts level `level` from its bytes (copied) for round-by-round
/// decoding with `ss_decoder_next_round`; level 0's seed mesh is decoded
/// here. Refusals and failures as `ss_decoder_decode_level`'s; a level
/// given while this one is open is refused with `SS_STATUS_API_MISUSE`.
///
/// # Safety
/// `decoder` is a live handle; `bytes` points to `len` readable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_begin_level(
    decoder: *mut SsDecoder,
    level: u16,
    bytes: *const u8,
    len: usize,
) -> SsStatus {
    // SAFETY: the caller's contract is this function's.
    unsafe { with_level_bytes(decoder, level, bytes, len, Session::begin_level) }
}

/// Runs `f` on the session behind `decoder`, level `level` and its bytes
/// `bytes[0 .. len]`, turning bad arguments, refusals (checked first, with
/// their own messages: `Session::check_level`) and decoder errors into
/// statuses.
///
/// # Safety
/// `decoder` is a live handle; `bytes` points to `len` readable bytes.
unsafe fn with_level_bytes(
    decoder: *mut SsDecoder,
    level: u16,
    bytes: *const u8,
    len: usize,
    f: impl FnOnce(&mut Session, u16, &[u8]) -> Result<(), splitstream_decoder_core::Error>,
) -> SsStatus {
    guard(|| {
        // SAFETY: per the contract.
        let (s, b) = match unsafe { (session_mut(decoder), byte_slice(bytes, len)) } {
            (Ok(s), Ok(b)) => (s, b),
            (Err(e), _) | (_, Err(e)) => return e,
        };
        if let Err(r) = s.check_level(level, b.len()) {
            return fail_refusal(r);
        }
        match f(s, level, b) {
            Ok(()) => SsStatus::Ok,
            Err(e) => fail_decoder(e),
        }
    })
}

/// Decodes the next round of the level begun with `ss_decoder_begin_level`.
/// With `SS_STATUS_OK`, `*decoded` is true when a round was decoded, false
/// when the level is complete (and verified) or none is open. A round that
/// fails spends the decoder; from then on this call answers
/// `SS_STATUS_API_MISUSE` (never `SS_STATUS_OK` with false), as after any
/// failure (`ss_decoder_decode_level`).
///
/// # Safety
/// `decoder` is a live handle; `decoded` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_next_round(
    decoder: *mut SsDecoder,
    decoded: *mut bool,
) -> SsStatus {
    guard(|| {
        if decoded.is_null() {
            return fail_argument("null output pointer");
        }
        // SAFETY: per the contract.
        let s = match unsafe { session_mut(decoder) } {
            Ok(s) => s,
            Err(e) => return e,
        };
        if let Some(error) = s.failure() {
            return fail_refusal(Refusal::Failed { error });
        }
        match s.next_round() {
            Ok(r) => {
                // SAFETY: checked non-null; writable per the contract.
                unsafe { decoded.write(r.is_some()) };
                SsStatus::Ok
            }
            Err(e) => fail_decoder(e),
        }
    })
}

/// Vertices of the current mesh (0 for null).
///
/// # Safety
/// `decoder` is null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_vertex_count(decoder: *const SsDecoder) -> u32 {
    // SAFETY: per the contract.
    unsafe { session(decoder) }.map_or(0, |s| s.positions().len() as u32)
}

/// Triangles of the current mesh (0 for null).
///
/// # Safety
/// `decoder` is null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_triangle_count(decoder: *const SsDecoder) -> u32 {
    // SAFETY: per the contract.
    unsafe { session(decoder) }.map_or(0, |s| s.triangles().len() as u32)
}

/// Quantized positions, `x, y, z` per vertex (`3 * vertex_count` values),
/// valid until the decoder next changes; null for a null handle. These
/// getters (counts, positions, triangles, state hash) answer after a
/// failure too, but the mesh they then show means nothing.
///
/// # Safety
/// `decoder` is null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_positions(decoder: *const SsDecoder) -> *const u32 {
    // SAFETY: per the contract.
    unsafe { session(decoder) }.map_or(ptr::null(), |s| s.positions().as_ptr().cast())
}

/// Triangle corners, three vertex indices per triangle, counter-clockwise
/// (`3 * triangle_count` values); valid until the decoder next changes.
///
/// # Safety
/// `decoder` is null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_triangles(decoder: *const SsDecoder) -> *const u32 {
    // SAFETY: per the contract.
    unsafe { session(decoder) }.map_or(ptr::null(), |s| s.triangles().as_ptr().cast())
}

/// Writes the real (dequantized) positions, `x, y, z` per vertex, into
/// `out[0 .. 3 * vertex_count]`; `out_len` is the buffer's length in
/// doubles. `SS_STATUS_INVALID_ARGUMENT` for a null `out` (unless the mesh
/// is empty) or a buffer too short; `SS_STATUS_API_MISUSE` after a failure
/// (the mesh then means nothing).
///
/// # Safety
/// `decoder` is a live handle; `out` points to `out_len` writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_positions_f64(
    decoder: *const SsDecoder,
    out: *mut f64,
    out_len: usize,
) -> SsStatus {
    // SAFETY: per the contract.
    let Some(s) = (unsafe { session(decoder) }) else {
        return fail_argument("null decoder");
    };
    if let Some(error) = s.failure() {
        return fail_refusal(Refusal::Failed { error });
    }
    let n = 3 * s.positions().len();
    if out.is_null() && n > 0 {
        return fail_argument("null output pointer");
    }
    if out_len < n {
        return fail_argument(&format!(
            "output buffer shorter than 3 * vertex_count: {n} doubles needed, {out_len} given"
        ));
    }
    if n == 0 {
        return SsStatus::Ok;
    }
    // SAFETY: non-null, `out_len >= n` writable doubles per the contract.
    let out = unsafe { std::slice::from_raw_parts_mut(out, n) };
    for (o, &q) in out.chunks_exact_mut(3).zip(s.positions()) {
        o.copy_from_slice(&s.dequantize(q));
    }
    SsStatus::Ok
}

/// The state hash of the current mesh (decoder-core SPEC §8); 0 for null.
///
/// # Safety
/// `decoder` is null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_decoder_state_hash(decoder: *const SsDecoder) -> u64 {
    // SAFETY: per the contract.
    unsafe { session(decoder) }.map_or(0, Session::state_hash)
}
