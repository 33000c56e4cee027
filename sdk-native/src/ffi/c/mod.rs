//! The C ABI. Conventions (also in the generated header):
//!
//! * Functions return an [`SsStatus`]; on anything but `SS_STATUS_OK`,
//!   `ss_last_error_message()` and `ss_last_error_class()` describe the
//!   failure (per thread, until the next failing call on that thread).
//! * Handles (`SsDecoder`, `SsGridSimplifier`) are created by `*_open` /
//!   `*_new` and released by `*_free`; a handle is not thread-safe: one
//!   thread at a time may use it, and it may move from thread to thread
//!   (decode on a worker thread, or several handles on several cores).
//! * Pointers returned into a handle's memory (positions, triangles) stay
//!   valid until the next call that changes that handle.
//! * A panic (a bug) never unwinds into C: it is caught and reported as
//!   `SS_STATUS_PANIC`.

mod decoder;
mod error;
mod grid;

pub use decoder::*;
pub use error::*;
pub use grid::*;

// What the conventions above promise: a handle may move between threads.
const _: () = {
    const fn send<T: Send>() {}
    send::<SsDecoder>();
    send::<SsGridSimplifier>();
};
