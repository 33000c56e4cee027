//! `Session` (a self-referential owner built on `unsafe`) driven by
//! arbitrary sequences of calls over the conformance suite's valid streams:
//! levels begun, decoded whole or round by round, in order or not, with
//! their bytes right, cut short or with a byte changed; the mesh read
//! between any two calls; the session dropped half way through a level;
//! levels decoded on two threads (`decode_level_two_threads`, from as few
//! as 0 splits, so that every level of these small streams takes the
//! second thread), each compared with the same call on a twin session
//! decoding on one thread: the same result and the same state.
//! cargo-fuzz builds with AddressSanitizer, so a use after free or a stray
//! read of the session's pointers is a finding, as is a panic. While the
//! calls are right, the session must end where decoder-core's own decode
//! of the stream ends (the same state hash).
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use splitstream_decoder_core::owned::decode_all;
use splitstream_sdk_native::{ScreenView, Session};
use splitstream_sdk_native_fuzz::Bytes;

/// A valid stream and the state hash of its complete decode.
struct Stream {
    bytes: Vec<u8>,
    final_hash: u64,
}

/// The valid vectors of the newest format version in the conformance
/// suite, read once.
fn streams() -> &'static [Stream] {
    static STREAMS: OnceLock<Vec<Stream>> = OnceLock::new();
    STREAMS.get_or_init(|| {
        let root = PathBuf::from(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../conformance/vectors"
        ));
        let newest = std::fs::read_dir(&root)
            .expect("conformance/vectors")
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_dir())
            .max()
            .expect("a version folder");
        let mut paths: Vec<PathBuf> = std::fs::read_dir(newest.join("valid"))
            .expect("valid vectors")
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "sps"))
            .collect();
        paths.sort();
        paths
            .into_iter()
            .filter_map(|p| {
                let bytes = std::fs::read(&p).ok()?;
                let decoded = decode_all(&bytes, true).ok()?;
                let final_hash = *decoded.round_hashes.last()?;
                Some(Stream { bytes, final_hash })
            })
            .collect()
    })
}

/// Decodes level `k` from `level` on two threads, from `from` splits
/// (mostly 0: every level takes the second thread), and checks it against
/// the same call on one thread: a twin session opened on `bytes` and
/// brought to the same point. Only where `session` is `clean` (no call of
/// it failed) and at the start of a level whose predecessors decoded
/// right: otherwise the twin cannot be rebuilt cheaply, and only the
/// absence of panics and hangs is checked.
fn two_threads(
    session: &mut Session,
    bytes: &[u8],
    k: u16,
    level: &[u8],
    from: u8,
    clean: bool,
) -> Result<(), splitstream_decoder_core::Error> {
    session.set_two_threads_from(if from < 192 { 0 } else { u32::from(from) * 64 });
    let twin = if clean { twin_at(session, bytes) } else { None };
    let result = session.decode_level_two_threads(k, level);
    if let Some(mut twin) = twin {
        let expected = twin.decode_level(k, level);
        assert_eq!(
            result.map_err(|e| e.class()),
            expected.map_err(|e| e.class()),
            "level {k}: two threads and one disagree"
        );
        if result.is_ok() {
            assert_eq!(
                session.state_hash(),
                twin.state_hash(),
                "level {k}: states differ"
            );
        }
        assert_eq!(session.levels_done(), twin.levels_done());
    }
    result
}

/// A session on one thread at the point `session` is at, where that point
/// is the end of its levels done, each of them decoded from the stream's
/// right bytes (checked by the state hash); `None` otherwise.
fn twin_at(session: &Session, bytes: &[u8]) -> Option<Session> {
    if session.open_level().is_some() {
        return None;
    }
    let mut twin = Session::open(bytes).ok()?;
    for k in 0..session.levels_done() {
        let range = twin.level_range(k)?;
        twin.decode_level(k, &bytes[range.start as usize..range.end as usize])
            .ok()?;
    }
    let same = twin.state_hash() == session.state_hash()
        && twin.workspace_bytes() == session.workspace_bytes()
        && twin.levels_that_fit() == session.levels_that_fit();
    same.then_some(twin)
}

/// Reads the whole mesh the session shows, as a viewer would between two
/// calls, and checks that it is a mesh.
fn look(session: &Session) {
    let positions = session.positions();
    let count = positions.len();
    for t in session.triangles() {
        assert!(
            t.iter().all(|&v| (v as usize) < count),
            "triangle {t:?} of {count} vertices"
        );
    }
    assert_eq!(session.deficits().len(), count);
    if let Some(p) = positions.first() {
        let _ = session.dequantize(*p);
    }
    let _ = session.state_hash();
}

fuzz_target!(|data: &[u8]| {
    let streams = streams();
    let mut b = Bytes(data);
    let Some(stream) = streams.get(b.u8() as usize % streams.len().max(1)) else {
        return;
    };
    let bytes = &stream.bytes[..];
    let open = |b: &mut Bytes| match b.u8() % 4 {
        0 => Session::open_within(bytes, (b.u16() as u64) << (b.u8() % 12)),
        1 => Session::open(&bytes[..bytes.len().min(b.u16() as usize)]),
        _ => Session::open(bytes),
    };
    let Ok(mut session) = open(&mut b) else {
        return;
    };
    // Whether every call so far was a right one, in order.
    let mut faithful = session.levels_that_fit() == session.level_count();
    // Whether no call has failed since the session was opened (a failed
    // call may poison the decoder, SPEC §10.3).
    let mut clean = true;
    while !b.done() {
        match b.u8() % 8 {
            // Begin or decode the next level (or another one), with its
            // bytes right, cut short, or with one byte changed.
            op @ (0 | 1 | 2) => {
                let next = session.next_level();
                let k = match b.u8() % 8 {
                    0 => b.u16() % (session.level_count() + 2),
                    _ => next.unwrap_or(0),
                };
                let Some(range) = session.level_range(k) else {
                    let _ = session.begin_level(k, &[]);
                    faithful = false;
                    continue;
                };
                let mut level = bytes[range.start as usize..range.end as usize].to_vec();
                match b.u8() % 8 {
                    0 if !level.is_empty() => {
                        let at = b.u16() as usize % level.len();
                        level[at] ^= b.u8() | 1;
                        faithful = false;
                    }
                    1 => {
                        level.truncate(b.u16() as usize % (level.len() + 1));
                        faithful = false;
                    }
                    _ => {}
                }
                faithful &= Some(k) == next;
                let result = match op {
                    0 => session.decode_level(k, &level),
                    1 => session.begin_level(k, &level),
                    _ => two_threads(&mut session, bytes, k, &level, b.u8(), clean),
                };
                faithful &= result.is_ok();
                clean &= result.is_ok();
            }
            // One round, or the rest of the open level.
            3 => {
                let ok = session.next_round().is_ok();
                faithful &= ok;
                clean &= ok;
            }
            4 => loop {
                match session.next_round() {
                    Ok(Some(_)) => {}
                    Ok(None) => break,
                    Err(_) => {
                        clean = false;
                        break;
                    }
                }
            },
            // Read everything, as a viewer drawing a frame.
            5 => look(&session),
            // The questions a viewer asks.
            6 => {
                let _ = session.level_within_error(f32::from_bits(b.u16() as u32 * 65_537));
                if let Ok(view) = ScreenView::perspective(1080.0, 0.8) {
                    let _ = session.level_for_screen_error(&view, b.u16() as f32, 1.0);
                }
                let _ = (
                    session.open_level(),
                    session.levels_done(),
                    session.next_level(),
                );
                let _ = (session.workspace_bytes(), session.level_info(b.u16() % 8));
            }
            // Drop it, wherever it is, and start again.
            _ => {
                drop(session);
                let Ok(again) = open(&mut b) else {
                    return;
                };
                session = again;
                faithful = session.levels_that_fit() == session.level_count();
                clean = true;
            }
        }
    }
    look(&session);
    // Right calls all the way: finish, and compare with decoder-core.
    if faithful {
        while session.open_level().is_some() {
            session.next_round().expect("a right stream decodes");
        }
        while let Some(k) = session.next_level() {
            let range = session.level_range(k).expect("a level of the table");
            session
                .decode_level(k, &bytes[range.start as usize..range.end as usize])
                .expect("a right stream decodes");
        }
        assert_eq!(session.state_hash(), stream.final_hash);
    }
});
