//! [`Session`]: a progressive decoder that owns everything it borrows, for
//! callers that cannot hold Rust borrows across calls (C, JavaScript).
//!
//! decoder-core's [`Decoder`] borrows the stream head and its workspace, and
//! a [`LevelDecoder`] borrows the decoder and the level's bytes. A C or JS
//! handle must own all of that at once, which safe Rust cannot express (it
//! is self-referential). This is the one place that does it, with raw
//! pointers obtained from `Box::leak`: the pointees never move, are reached
//! only through the borrows handed to decoder-core (never through the
//! pointers while a borrow derived from them is in use), and are freed in
//! `Drop`, borrowers first. Every borrower lives behind such a pointer too,
//! so no reference is stored in the `Session` value itself: moving it
//! (into `drop`, say) retags nothing that is freed while it is protected
//! (`cargo +nightly miri test -p splitstream-sdk-native --test session`
//! checks this under Stacked Borrows).
//!
//! Before it hands a level to decoder-core, a session checks what it can
//! check without decoding (no failure yet, no level open, the index, the
//! memory, the order, the length): a call refused there leaves the session
//! as it was ([`Refusal`]). A failure in decoding itself spends the
//! session (SPEC §10): every decoding call then answers `Poisoned`.

use core::fmt;
use core::ops::Range;
use core::ptr::NonNull;

use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_decoder_core::{
    Decoder, Error, Header, LevelDecoder, LevelInfo, MeshState, RoundInfo, layout_for,
    level_within_error,
};

use crate::threaded::{self, TwoThreadMemory};
use crate::view::{ScreenView, ViewError};

/// A progressive decoding session: created from the stream head (header and
/// level table), fed level by level, decoded level by level or round by
/// round. All memory is allocated once, at [`Session::open`], from the
/// sizes the header declares. A session is `Send`: decode it on a worker
/// thread, or many sessions (tiles, objects) on as many cores.
///
/// Failures come in two kinds. A call that cannot be right (a level
/// already decoded or not yet due, one beyond the stream or beyond the
/// memory, bytes of another length than the level's, a level given while
/// another is open) is refused before anything is decoded and changes
/// nothing: [`Session::check_level`] names the reason, and the same call
/// with the right arguments may follow (a client whose range request came
/// back short fetches the level again). A level whose bytes fail to decode
/// spends the session (SPEC §10): [`Session::failure`] is then that error,
/// and [`Session::decode_level`], [`Session::decode_level_two_threads`],
/// [`Session::begin_level`] and [`Session::next_round`] answer
/// `Error::Poisoned` (class `api-misuse`); the mesh getters still answer,
/// but the state they show means nothing. Open a new session.
pub struct Session {
    /// `Box<LevelDecoder>` of the level being decoded round by round;
    /// borrows `*decoder` mutably and `*level_bytes`. Dropped before either.
    level: Option<NonNull<LevelDecoder<'static, 'static, 'static>>>,
    /// The bytes of the open level (`Box<[u8]>::into_raw`), if any.
    level_bytes: Option<NonNull<[u8]>>,
    /// `Box<Decoder>::into_raw`; borrows `*head` and `*workspace`.
    decoder: NonNull<Decoder<'static, 'static>>,
    /// `Box<OwnedWorkspace>::into_raw`.
    workspace: NonNull<OwnedWorkspace>,
    /// `Box<[u8]>::into_raw`: header and level table.
    head: NonNull<[u8]>,
    header: Header,
    levels: Vec<LevelInfo>,
    /// Levels the workspace holds (all, unless opened within a budget).
    levels_that_fit: u16,
    /// SPEC §9's workspace size for those levels.
    workspace_bytes: u64,
    /// Levels done when the open level began (the decoder's own count is
    /// out of reach while a level borrows it).
    done_while_open: u16,
    /// What [`Session::decode_level_two_threads`] needs besides the
    /// workspace, made at its first call.
    two_threads: Option<Box<TwoThreadMemory>>,
    /// [`TwoThreadMemory::set_two_threads_from`] for it.
    two_threads_from: u32,
    /// The error that spent the session, if a decoding call failed.
    failed: Option<Error>,
}

/// Why a [`Session`] refused a call before decoding anything: the session
/// is as it was before the call (after [`Refusal::Failed`], spent).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refusal {
    /// An earlier call failed with `error`: the session is spent (SPEC
    /// §10); open a new one.
    Failed { error: Error },
    /// Level `open` is being decoded round by round; `got` was given.
    LevelOpen { open: u16, got: u16 },
    /// `level` is beyond the stream's `count` levels.
    NoSuchLevel { level: u16, count: u16 },
    /// `level` is beyond the `levels_that_fit` levels the session's memory
    /// holds ([`Session::open_within`]): `needed` bytes of workspace would
    /// hold it, the session has `available`.
    DoesNotFit {
        level: u16,
        levels_that_fit: u16,
        needed: u64,
        available: u64,
    },
    /// Levels are decoded in order, once each: `expected` is next (or, when
    /// it equals `levels_that_fit`, every level that fits is done).
    OutOfOrder {
        expected: u16,
        got: u16,
        levels_that_fit: u16,
    },
    /// The bytes given for `level` are not its level-table length.
    WrongLength {
        level: u16,
        expected: u32,
        given: usize,
    },
}

impl Refusal {
    /// The conformance class (SPEC §10) or argument class of the refusal:
    /// `api-misuse` for calls out of sequence, `capacity-exceeded` for a
    /// level beyond the memory, `invalid-argument` for a level index or a
    /// length that is wrong in itself.
    pub fn class(&self) -> &'static str {
        match self {
            Refusal::Failed { .. } | Refusal::LevelOpen { .. } | Refusal::OutOfOrder { .. } => {
                "api-misuse"
            }
            Refusal::DoesNotFit { .. } => "capacity-exceeded",
            Refusal::NoSuchLevel { .. } | Refusal::WrongLength { .. } => "invalid-argument",
        }
    }
}

/// `n` with its thousands grouped by commas ("8,215").
fn grouped(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Refusal::Failed { error } => {
                write!(f, "the decoder already failed ({error}); open a new one")
            }
            Refusal::LevelOpen { open, got } if open == got => write!(
                f,
                "level {open} is already open: run its rounds (next_round) until it completes"
            ),
            Refusal::LevelOpen { open, got } => write!(
                f,
                "level {got} given while level {open} is open: run level {open}'s rounds \
                 (next_round) until it completes"
            ),
            Refusal::NoSuchLevel { level, count } => write!(
                f,
                "level {level} does not exist: the stream has levels 0..={}",
                count.saturating_sub(1)
            ),
            Refusal::DoesNotFit {
                level,
                levels_that_fit,
                ..
            } => write!(
                f,
                "level {level} does not fit the memory this decoder was opened with \
                 (levels 0..={} fit)",
                levels_that_fit.saturating_sub(1)
            ),
            Refusal::OutOfOrder {
                expected,
                got,
                levels_that_fit,
            } if got < expected => {
                write!(
                    f,
                    "level {got} is already decoded (levels 0..={} are)",
                    expected - 1
                )?;
                if expected < levels_that_fit {
                    write!(f, "; level {expected} is next")?;
                }
                Ok(())
            }
            Refusal::OutOfOrder { expected, got, .. } => write!(
                f,
                "level {got} given before level {expected}: levels are decoded in order"
            ),
            Refusal::WrongLength {
                level,
                expected,
                given,
            } => write!(
                f,
                "level {level} is {} bytes; {} {} given",
                grouped(expected.into()),
                grouped(given as u64),
                if given == 1 { "was" } else { "were" }
            ),
        }
    }
}

impl std::error::Error for Refusal {}

impl Refusal {
    /// The decoder-core error a refused call of [`Session`]'s decoding
    /// methods returns, of the refusal's class where decoder-core has one:
    /// a failed session is `Poisoned`, calls out of sequence
    /// `LevelOutOfOrder`, a level beyond the stream `NoSuchLevel`, beyond
    /// the memory `WorkspaceTooSmall`, and bytes of the wrong length
    /// `Truncated` (decoder-core's answer to a level whose bytes are not
    /// its range, SPEC §10.3). (A method, not `From`: an impl of `From` for
    /// decoder-core's `Error` would make `?` ambiguous in crates that use
    /// both.)
    pub fn core_error(self) -> Error {
        match self {
            Refusal::Failed { .. } => Error::Poisoned,
            // The level after the open one is due once it completes.
            Refusal::LevelOpen { open, got } => Error::LevelOutOfOrder {
                expected: if got == open {
                    open.saturating_add(1)
                } else {
                    open
                },
                got,
            },
            Refusal::NoSuchLevel { level, count } => Error::NoSuchLevel { level, count },
            Refusal::DoesNotFit {
                needed, available, ..
            } => Error::WorkspaceTooSmall {
                needed: usize::try_from(needed).unwrap_or(usize::MAX),
                available: usize::try_from(available).unwrap_or(usize::MAX),
            },
            Refusal::OutOfOrder { expected, got, .. } => Error::LevelOutOfOrder { expected, got },
            Refusal::WrongLength { .. } => Error::Truncated,
        }
    }
}

impl Session {
    /// Parses the header and level table at the start of `head` (the whole
    /// stream or just its first [`Session::head_len`] bytes, which are
    /// copied) and allocates the workspace the whole stream needs.
    pub fn open(head: &[u8]) -> Result<Session, Error> {
        Session::open_within(head, u64::MAX)
    }

    /// As [`Session::open`], with a workspace of at most `max_bytes`: sized
    /// for the longest prefix of levels that fits (SPEC §9), which is all
    /// the session decodes ([`Session::levels_that_fit`]); a device's
    /// memory budget. `WorkspaceTooSmall` (class `capacity-exceeded`) when
    /// not even the base level fits.
    pub fn open_within(head: &[u8], max_bytes: u64) -> Result<Session, Error> {
        let header = Header::parse(head)?;
        let len = header.head_len();
        let head: Box<[u8]> = head.get(..len).ok_or(Error::Truncated)?.into();
        // Checks the level table and the declared size, refuses absurd ones.
        let workspace = Box::new(OwnedWorkspace::within(&head, max_bytes)?);
        let head = NonNull::from(Box::leak(head));
        let workspace = NonNull::from(Box::leak(workspace));
        // SAFETY: both pointers come from `Box::leak` just above, so they
        // are valid, unique and never move; they are freed only in `Drop`,
        // after the decoder built from them (and on the error path below).
        // Nothing else reads or writes them while the decoder lives.
        let built = unsafe { (*workspace.as_ptr()).decoder(&*head.as_ptr()) };
        let decoder = match built {
            Ok(d) => d,
            Err(e) => {
                // SAFETY: from `Box::leak` above; the failed decoder borrowed
                // nothing beyond this point.
                unsafe {
                    drop(Box::from_raw(workspace.as_ptr()));
                    drop(Box::from_raw(head.as_ptr()));
                }
                return Err(e);
            }
        };
        let levels = decoder.level_table().iter().collect();
        let levels_that_fit = decoder.levels_that_fit();
        // SPEC §9's size for the levels that fit (the header's for all).
        let workspace_bytes = layout_for(&header, decoder.level_table(), levels_that_fit - 1).total;
        let decoder = NonNull::from(Box::leak(Box::new(decoder)));
        Ok(Session {
            level: None,
            level_bytes: None,
            decoder,
            workspace,
            head,
            header,
            levels,
            levels_that_fit,
            workspace_bytes,
            done_while_open: 0,
            two_threads: None,
            two_threads_from: threaded::TWO_THREADS_FROM_SPLITS,
            failed: None,
        })
    }

    /// Bytes of header and level table, from the 96-byte header alone (so a
    /// client knows how much to fetch before [`Session::open`]).
    pub fn head_len(header: &[u8]) -> Result<usize, Error> {
        Ok(Header::parse(header)?.head_len())
    }

    /// The decoder, while no level borrows it (callers check; the assert
    /// turns a forgotten check into a panic rather than aliasing).
    fn decoder(&self) -> &Decoder<'static, 'static> {
        assert!(self.level.is_none(), "decoder borrowed by an open level");
        // SAFETY: `decoder` is valid until `Drop`, and no level decoder
        // holds its mutable borrow (checked above).
        unsafe { self.decoder.as_ref() }
    }

    fn decoder_mut(&mut self) -> &mut Decoder<'static, 'static> {
        assert!(self.level.is_none(), "decoder borrowed by an open level");
        // SAFETY: as in `decoder`; `&mut self` makes this the only access.
        unsafe { self.decoder.as_mut() }
    }

    pub fn header(&self) -> &Header {
        &self.header
    }

    pub fn level_count(&self) -> u16 {
        self.header.level_count
    }

    /// Level `k`'s table entry, `None` past the last level.
    pub fn level_info(&self, k: u16) -> Option<LevelInfo> {
        self.levels.get(k as usize).copied()
    }

    /// Level `k`'s byte range within the stream (an HTTP range request).
    pub fn level_range(&self, k: u16) -> Option<Range<u64>> {
        self.level_info(k)
            .map(|e| e.offset..e.offset + e.length as u64)
    }

    /// The coarsest level the session can decode (one of the
    /// [`Session::levels_that_fit`]) whose geometric error (SPEC §4.1, model
    /// units) is at most `max_error`, the finest that fits when none is:
    /// decode levels 0 ..= it (`splitstream_decoder_core::level_within_error`
    /// over those levels). A bound that is NaN or below 0 is within no
    /// level's error, so it gives the finest level that fits;
    /// [`Session::checked_level_within_error`] refuses it instead.
    pub fn level_within_error(&self, max_error: f32) -> u16 {
        let fit = &self.levels[..(self.levels_that_fit as usize).min(self.levels.len())];
        level_within_error(fit.iter().copied(), max_error).unwrap_or(0)
    }

    /// [`Session::level_within_error`] for a bound that is a number of model
    /// units of at least 0 (+∞ included, which gives level 0);
    /// `ViewError::MaxError` for NaN or a negative bound, as
    /// [`Session::level_for_screen_error`] refuses parameters that describe
    /// no camera.
    pub fn checked_level_within_error(&self, max_error: f32) -> Result<u16, ViewError> {
        if max_error.is_nan() || max_error < 0.0 {
            return Err(ViewError::MaxError(max_error));
        }
        Ok(self.level_within_error(max_error))
    }

    /// The coarsest level the session can decode (one of the
    /// [`Session::levels_that_fit`]) whose geometric error covers at most
    /// `max_pixels` pixels of `view` at `distance` model units from the
    /// camera, the finest that fits when none does: what a viewer needs to
    /// decode for this object now.
    pub fn level_for_screen_error(
        &self,
        view: &ScreenView,
        distance: f32,
        max_pixels: f32,
    ) -> Result<u16, ViewError> {
        Ok(self.level_within_error(view.error_for_pixels(max_pixels, distance)?))
    }

    /// Bytes of working memory the session holds (SPEC §9): the whole
    /// stream's, or under [`Session::open_within`] the levels' that fit.
    pub fn workspace_bytes(&self) -> u64 {
        self.workspace_bytes
    }

    /// Levels (base included) the session's workspace holds: all of them
    /// unless opened with [`Session::open_within`].
    pub fn levels_that_fit(&self) -> u16 {
        self.levels_that_fit
    }

    /// The level to feed next; `None` when all that fit are decoded, while a
    /// level is being decoded round by round, or after a failure.
    pub fn next_level(&self) -> Option<u16> {
        if self.level.is_some() || self.failed.is_some() {
            return None;
        }
        self.decoder().next_level()
    }

    /// The error that spent the session, if a decoding call failed (see
    /// [`Session`]); refusals ([`Refusal`]) are not failures.
    pub fn failure(&self) -> Option<Error> {
        self.failed
    }

    /// Whether level `k`, given as `len` bytes, would be taken by
    /// [`Session::decode_level`], [`Session::decode_level_two_threads`] or
    /// [`Session::begin_level`] now; the reason if not. In this order: the
    /// session failed, a level is open, `k` is beyond the stream, beyond
    /// the memory, not the next level, `len` is not the level's length.
    /// Those calls check this first: a refusal changes nothing.
    pub fn check_level(&self, k: u16, len: usize) -> Result<(), Refusal> {
        if let Some(error) = self.failed {
            return Err(Refusal::Failed { error });
        }
        if self.level.is_some() {
            return Err(Refusal::LevelOpen {
                open: self.done_while_open,
                got: k,
            });
        }
        let Some(info) = self.level_info(k) else {
            return Err(Refusal::NoSuchLevel {
                level: k,
                count: self.level_count(),
            });
        };
        if k >= self.levels_that_fit {
            return Err(Refusal::DoesNotFit {
                level: k,
                levels_that_fit: self.levels_that_fit,
                needed: layout_for(&self.header, self.decoder().level_table(), k).total,
                available: self.workspace_bytes,
            });
        }
        let expected = self.decoder().levels_done();
        if k != expected {
            return Err(Refusal::OutOfOrder {
                expected,
                got: k,
                levels_that_fit: self.levels_that_fit,
            });
        }
        if len as u64 != u64::from(info.length) {
            return Err(Refusal::WrongLength {
                level: k,
                expected: info.length,
                given: len,
            });
        }
        Ok(())
    }

    /// Keeps the first error of a decoding call: the session is spent.
    fn spent_by<T>(&mut self, result: Result<T, Error>) -> Result<T, Error> {
        if let Err(e) = &result {
            self.failed.get_or_insert(*e);
        }
        result
    }

    /// The level being decoded round by round, if any.
    pub fn open_level(&self) -> Option<u16> {
        self.level.as_ref().map(|_| self.levels_done())
    }

    /// Levels completely decoded (base included).
    pub fn levels_done(&self) -> u16 {
        match &self.level {
            // The level decoder holds the count; the open one is not done.
            Some(_) => self.done_while_open,
            None => self.decoder().levels_done(),
        }
    }

    /// Decodes level `k` whole from exactly its bytes. A call
    /// [`Session::check_level`] refuses returns the refusal's decoder-core
    /// error ([`Refusal::core_error`]) and changes nothing; a failure in decoding
    /// spends the session.
    pub fn decode_level(&mut self, k: u16, bytes: &[u8]) -> Result<(), Error> {
        self.check_level(k, bytes.len())
            .map_err(Refusal::core_error)?;
        let result = self.decoder_mut().decode_level(k, bytes);
        self.spent_by(result)
    }

    /// [`Session::decode_level`] on two cores: the rounds here, the split
    /// records on a second thread (see [`crate::threaded`]), to the same
    /// state. A level adding fewer splits than
    /// [`threaded::TWO_THREADS_FROM_SPLITS`] (or the number set with
    /// [`Session::set_two_threads_from`]) decodes on this thread alone. The
    /// first call allocates 12 bytes per vertex of the session's capacity
    /// and about 1.6 MB more, kept until the session is dropped. Refusals and
    /// failures as [`Session::decode_level`]'s.
    pub fn decode_level_two_threads(&mut self, k: u16, bytes: &[u8]) -> Result<(), Error> {
        self.check_level(k, bytes.len())
            .map_err(Refusal::core_error)?;
        let capacity = self.decoder().state().vertex_capacity();
        let mut memory = self
            .two_threads
            .take()
            .unwrap_or_else(|| Box::new(TwoThreadMemory::new(capacity)));
        memory.set_two_threads_from(self.two_threads_from);
        let result = threaded::decode_level(self.decoder_mut(), k, bytes, &mut memory);
        self.two_threads = Some(memory);
        self.spent_by(result)
    }

    /// From how many splits a level decoded by
    /// [`Session::decode_level_two_threads`] uses the second thread.
    pub fn set_two_threads_from(&mut self, splits: u32) {
        self.two_threads_from = splits;
    }

    /// Starts level `k` (its bytes are copied); decode its rounds with
    /// [`Session::next_round`]. Level 0's seed mesh is decoded here.
    /// Refusals and failures as [`Session::decode_level`]'s.
    pub fn begin_level(&mut self, k: u16, bytes: &[u8]) -> Result<(), Error> {
        self.check_level(k, bytes.len())
            .map_err(Refusal::core_error)?;
        let done = self.decoder().levels_done();
        let bytes = NonNull::from(Box::leak(Box::<[u8]>::from(bytes)));
        // SAFETY: `decoder` and `bytes` are valid and do not move until
        // `Drop` / `close_level`, which drop the level decoder first; while
        // it lives, the session reaches the decoder only through it (every
        // method checks `self.level`).
        let begun = unsafe { (*self.decoder.as_ptr()).begin_level(k, &*bytes.as_ptr()) };
        match begun {
            Ok(level) => {
                self.level = Some(NonNull::from(Box::leak(Box::new(level))));
                self.level_bytes = Some(bytes);
                self.done_while_open = done;
                Ok(())
            }
            Err(e) => {
                // SAFETY: from `Box::leak` above and borrowed by nothing now.
                unsafe { drop(Box::from_raw(bytes.as_ptr())) };
                self.spent_by(Err(e))
            }
        }
    }

    /// Decodes the next round of the open level. `Ok(None)` when the level
    /// is complete (it is then closed and checked) or none is open and the
    /// session has not failed; after a failure (this level's or an earlier
    /// call's) `Error::Poisoned`, so that a caller polling until `None`
    /// never takes a failed session for a finished level.
    pub fn next_round(&mut self) -> Result<Option<RoundInfo>, Error> {
        if self.failed.is_some() {
            return Err(Error::Poisoned);
        }
        let Some(mut level) = self.level else {
            return Ok(None);
        };
        // SAFETY: from `Box::leak` in `begin_level`, alive until
        // `close_level`; `&mut self` makes this the only access.
        match unsafe { level.as_mut() }.next_round() {
            Ok(Some(info)) => Ok(Some(info)),
            Ok(None) => {
                self.close_level();
                Ok(None)
            }
            Err(e) => {
                self.close_level();
                self.spent_by(Err(e))
            }
        }
    }

    /// Drops the level decoder, then the bytes it borrowed.
    fn close_level(&mut self) {
        if let Some(level) = self.level.take() {
            // SAFETY: from `Box::leak` in `begin_level`, freed once; no
            // reference derived from it outlives this call.
            drop(unsafe { Box::from_raw(level.as_ptr()) });
        }
        if let Some(bytes) = self.level_bytes.take() {
            // SAFETY: from `Box::leak` in `begin_level`; its only borrower,
            // the level decoder, was dropped on the line above.
            unsafe { drop(Box::from_raw(bytes.as_ptr())) };
        }
    }

    /// The mesh as of the last level or round decoded.
    fn state(&self) -> &MeshState<'static> {
        match self.level {
            // SAFETY: from `Box::leak` in `begin_level`, alive until
            // `close_level`, which needs `&mut self`.
            Some(level) => unsafe { level.as_ref() }.state(),
            None => self.decoder().state(),
        }
    }

    /// Quantized positions, one `[x, y, z]` per vertex.
    pub fn positions(&self) -> &[[u32; 3]] {
        self.state().positions()
    }

    /// Triangles, counter-clockwise vertex indices.
    pub fn triangles(&self) -> &[[u32; 3]] {
        self.state().triangles()
    }

    /// The byte SPEC §6.2 keeps per vertex: its deficit, or under the
    /// schedule `every-vertex` (format 3.6) its valence, capped at 255.
    pub fn deficits(&self) -> &[u8] {
        self.state().deficits()
    }

    /// The state hash of SPEC §8.
    pub fn state_hash(&self) -> u64 {
        self.state().state_hash()
    }

    /// Real coordinates of a quantized position.
    pub fn dequantize(&self, q: [u32; 3]) -> [f64; 3] {
        self.header.dequantize(q)
    }
}

// Every type a `Session` owns through its pointers is `Send`: checked here,
// so that a change in decoder-core that made one of them `!Send` fails to
// compile instead of making the `impl` below unsound.
const _: () = {
    const fn send<T: Send + ?Sized>() {}
    send::<Decoder<'static, 'static>>();
    send::<LevelDecoder<'static, 'static, 'static>>();
    send::<OwnedWorkspace>();
    send::<[u8]>();
};

// SAFETY: a `Session` is the only owner of every allocation its pointers
// name (all from `Box::leak` in `open` and `begin_level`, freed in `Drop`
// or `close_level`), and no reference into them outlives a call: what the
// methods return borrows `self`. Moving a `Session` to another thread is
// therefore moving those `Box`es, and every pointee is `Send` (checked
// above). It is not `Sync`: one thread at a time uses it.
unsafe impl Send for Session {}

impl Drop for Session {
    fn drop(&mut self) {
        self.close_level();
        // SAFETY: all from `Box::leak` in `open`; freed once, borrowers
        // first: the decoder borrows the workspace and the head.
        unsafe {
            drop(Box::from_raw(self.decoder.as_ptr()));
            drop(Box::from_raw(self.workspace.as_ptr()));
            drop(Box::from_raw(self.head.as_ptr()));
        }
    }
}

impl core::fmt::Debug for Session {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Session")
            .field("levels", &self.level_count())
            .field("levels_done", &self.levels_done())
            .field("open_level", &self.open_level())
            .finish_non_exhaustive()
    }
}
