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

    /// The coarsest level whose geometric error (SPEC §4.1, model units) is
    /// at most `max_error`, the last when none is: decode levels 0 ..= it
    /// (`splitstream_decoder_core::level_within_error`).
    pub fn level_within_error(&self, max_error: f32) -> u16 {
        level_within_error(self.levels.iter().copied(), max_error).unwrap_or(0)
    }

    /// The coarsest level whose geometric error covers at most
    /// `max_pixels` pixels of `view` at `distance` model units from the
    /// camera: what a viewer needs to decode for this object now.
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

    /// The level to feed next; `None` when all are decoded, while a level
    /// is being decoded round by round, or after an error.
    pub fn next_level(&self) -> Option<u16> {
        if self.level.is_some() {
            return None;
        }
        self.decoder().next_level()
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

    /// Decodes level `k` whole from its bytes.
    pub fn decode_level(&mut self, k: u16, bytes: &[u8]) -> Result<(), Error> {
        if self.level.is_some() {
            return Err(self.misuse(k));
        }
        self.decoder_mut().decode_level(k, bytes)
    }

    /// [`Session::decode_level`] on two cores: the rounds here, the split
    /// records on a second thread (see [`crate::threaded`]), to the same
    /// state. A level adding fewer splits than
    /// [`threaded::TWO_THREADS_FROM_SPLITS`] (or the number set with
    /// [`Session::set_two_threads_from`]) decodes on this thread alone. The
    /// first call allocates 12 bytes per vertex of the session's capacity
    /// and about 1.6 MB more, kept until the session is dropped.
    pub fn decode_level_two_threads(&mut self, k: u16, bytes: &[u8]) -> Result<(), Error> {
        if self.level.is_some() {
            return Err(self.misuse(k));
        }
        let capacity = self.decoder().state().vertex_capacity();
        let mut memory = self
            .two_threads
            .take()
            .unwrap_or_else(|| Box::new(TwoThreadMemory::new(capacity)));
        memory.set_two_threads_from(self.two_threads_from);
        let result = threaded::decode_level(self.decoder_mut(), k, bytes, &mut memory);
        self.two_threads = Some(memory);
        result
    }

    /// From how many splits a level decoded by
    /// [`Session::decode_level_two_threads`] uses the second thread.
    pub fn set_two_threads_from(&mut self, splits: u32) {
        self.two_threads_from = splits;
    }

    /// Starts level `k` (its bytes are copied); decode its rounds with
    /// [`Session::next_round`]. Level 0's seed mesh is decoded here.
    pub fn begin_level(&mut self, k: u16, bytes: &[u8]) -> Result<(), Error> {
        if self.level.is_some() {
            return Err(self.misuse(k));
        }
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
                Err(e)
            }
        }
    }

    /// Decodes the next round of the open level. `Ok(None)` when the level
    /// is complete (it is then closed and checked) or none is open.
    pub fn next_round(&mut self) -> Result<Option<RoundInfo>, Error> {
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
                Err(e)
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

    fn misuse(&self, got: u16) -> Error {
        Error::LevelOutOfOrder {
            expected: self.levels_done(),
            got,
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
