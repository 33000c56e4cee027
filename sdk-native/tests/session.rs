//! `Session`, the owning progressive decoder: the conformance vectors'
//! round hashes, level by level and round by round, dropped half way,
//! misused, moved to other threads mid-level. Small enough to run under
//! Miri, which checks the unsafe self-borrowing in src/ffi/session.rs and
//! its `Send` (about 3 minutes; the tests read the vector files):
//! `MIRIFLAGS=-Zmiri-disable-isolation cargo +nightly miri test -p
//! splitstream-sdk-native --test session`.

mod vectors;

use serde_json::Value;
use splitstream_sdk_native::Session;
use vectors::newest_vectors;

/// The valid vectors, smallest first (Miri is slow).
fn valid_vectors(limit: usize) -> Vec<(String, Vec<u8>, Vec<String>)> {
    let dir = newest_vectors();
    let manifest: Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap();
    let mut out: Vec<(String, Vec<u8>, Vec<String>)> = manifest["vectors"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["valid"].as_bool().unwrap())
        .map(|v| {
            let hashes = v["round_hashes"]
                .as_array()
                .unwrap()
                .iter()
                .map(|h| h.as_str().unwrap().to_string())
                .collect();
            let bytes = std::fs::read(dir.join(v["file"].as_str().unwrap())).unwrap();
            (v["name"].as_str().unwrap().to_string(), bytes, hashes)
        })
        .collect();
    out.sort_by_key(|(_, b, _)| b.len());
    out.truncate(limit);
    out
}

fn level<'a>(s: &Session, stream: &'a [u8], k: u16) -> &'a [u8] {
    let r = s.level_range(k).unwrap();
    &stream[r.start as usize..r.end as usize]
}

fn limit() -> usize {
    if cfg!(miri) { 3 } else { usize::MAX }
}

#[test]
fn round_by_round_gives_the_manifest_hashes() {
    for (name, stream, expected) in valid_vectors(limit()) {
        let head = Session::head_len(&stream).unwrap();
        let mut s = Session::open(&stream[..head]).unwrap();
        let mut hashes = Vec::new();
        while let Some(k) = s.next_level() {
            s.begin_level(k, level(&s, &stream, k)).unwrap();
            assert_eq!(s.open_level(), Some(k));
            assert_eq!(s.next_level(), None);
            if k == 0 {
                hashes.push(format!("{:016x}", s.state_hash()));
            }
            while s.next_round().unwrap().is_some() {
                hashes.push(format!("{:016x}", s.state_hash()));
            }
            assert_eq!(s.open_level(), None);
            assert_eq!(s.levels_done(), k + 1);
        }
        assert_eq!(hashes, expected, "{name}");
        // Level by level: the same final state.
        let mut whole = Session::open(&stream).unwrap();
        while let Some(k) = whole.next_level() {
            whole.decode_level(k, level(&whole, &stream, k)).unwrap();
        }
        assert_eq!(whole.state_hash(), s.state_hash(), "{name}");
        assert_eq!(whole.positions(), s.positions());
        assert_eq!(whole.triangles(), s.triangles());
        assert_eq!(whole.deficits(), s.deficits());
    }
}

#[test]
fn dropped_half_way_and_misused() {
    let (_, stream, _) = valid_vectors(usize::MAX)
        .into_iter()
        .find(|(_, b, _)| Session::open(b).unwrap().level_count() >= 2)
        .expect("a vector with two levels");
    // Dropped with a level open, after 0 or 1 rounds.
    for rounds in 0..2 {
        let mut s = Session::open(&stream).unwrap();
        s.begin_level(0, level(&s, &stream, 0)).unwrap();
        for _ in 0..rounds {
            let _ = s.next_round().unwrap();
        }
        drop(s);
    }
    let mut s = Session::open(&stream).unwrap();
    assert!(s.level_range(s.level_count()).is_none());
    assert!(s.next_round().unwrap().is_none(), "no level open");
    let l1 = level(&s, &stream, 1);
    assert_eq!(s.decode_level(1, l1).unwrap_err().class(), "api-misuse");
    s.begin_level(0, level(&s, &stream, 0)).unwrap();
    // While a level is open, no other may start.
    assert_eq!(s.begin_level(1, l1).unwrap_err().class(), "api-misuse");
    while s.next_round().unwrap().is_some() {}
    // A corrupted level fails and leaves the session spent.
    let mut bad = level(&s, &stream, 1).to_vec();
    let at = bad.len() / 2;
    bad[at] ^= 0x10;
    assert!(
        s.begin_level(1, &bad)
            .and_then(|()| {
                while s.next_round()?.is_some() {}
                Ok(())
            })
            .is_err()
    );
    assert_eq!(s.next_level(), None);
    assert_eq!(s.decode_level(1, l1).unwrap_err().class(), "api-misuse");
    // Garbage heads are typed errors.
    assert_eq!(
        Session::open(&stream[..10]).unwrap_err().class(),
        "truncated"
    );
    assert_eq!(
        Session::open(b"not a stream at all").unwrap_err().class(),
        "bad-magic"
    );
}

#[test]
fn the_level_for_a_screen_error_is_the_coarsest_within_it() {
    use splitstream_sdk_native::ScreenView;
    let view = ScreenView::perspective(1080.0, 60f32.to_radians()).unwrap();
    for (name, stream, _) in valid_vectors(12) {
        let s = Session::open(&stream).unwrap();
        let errors: Vec<f32> = (0..s.level_count())
            .map(|k| s.level_info(k).unwrap().geometric_error)
            .collect();
        let mut previous = s.level_count() - 1;
        for distance in [0.0, 1e-3, 0.1, 1.0, 10.0, 1e3, 1e6, 1e12] {
            let k = s.level_for_screen_error(&view, distance, 2.0).unwrap();
            let bound = view.error_for_pixels(2.0, distance).unwrap();
            assert_eq!(k, s.level_within_error(bound), "{name}");
            // Coarser levels are all beyond the bound; this one is within
            // it unless it is the finest.
            assert!(errors[..k as usize].iter().all(|&e| e > bound), "{name}");
            assert!(
                errors[k as usize] <= bound || k + 1 == s.level_count(),
                "{name}"
            );
            // Farther away never needs more levels.
            assert!(k <= previous, "{name} at {distance}");
            previous = k;
        }
    }
}

#[test]
fn sessions_move_to_other_threads_mid_level() {
    // Opened here, half decoded, finished on worker threads (one per
    // vector, several at once): the same hashes as on one thread.
    let vectors = valid_vectors(if cfg!(miri) { 2 } else { 16 });
    let mut sessions = Vec::new();
    for (name, stream, expected) in &vectors {
        let mut s = Session::open(stream).unwrap();
        let k = s.next_level().unwrap();
        s.begin_level(k, level(&s, stream, k)).unwrap();
        sessions.push((name, stream, expected, s));
    }
    std::thread::scope(|scope| {
        let workers: Vec<_> = sessions
            .into_iter()
            .map(|(name, stream, expected, mut s)| {
                scope.spawn(move || {
                    while s.next_round().unwrap().is_some() {}
                    while let Some(k) = s.next_level() {
                        s.decode_level(k, level(&s, stream, k)).unwrap();
                    }
                    let last = expected.last().unwrap();
                    assert_eq!(&format!("{:016x}", s.state_hash()), last, "{name}");
                    // Back to the spawning thread, to be dropped there.
                    s
                })
            })
            .collect();
        for w in workers {
            drop(w.join().unwrap());
        }
    });
}

#[test]
fn a_budget_opens_the_levels_that_fit_and_decodes_them_exactly() {
    use splitstream_decoder_core::{Error, Header, LevelTable, layout_for};
    for (name, stream, _) in valid_vectors(if cfg!(miri) { 2 } else { 8 }) {
        let header = Header::parse(&stream).unwrap();
        let table = LevelTable::parse(&stream, &header).unwrap();
        for k in 0..header.level_count {
            // Exactly the memory of levels 0 ..= k (the session's workspace
            // is 8-aligned: no slack).
            let layout = layout_for(&header, &table, k);
            let mut s = Session::open_within(&stream, layout.total).unwrap();
            assert_eq!(s.levels_that_fit(), k + 1, "{name}");
            assert_eq!(s.workspace_bytes(), layout.total, "{name}");
            while let Some(level) = s.next_level() {
                s.decode_level(level, self::level(&s, &stream, level))
                    .unwrap();
            }
            assert_eq!(s.levels_done(), k + 1, "{name}");
            // The same state as a full session stopped after level k.
            let mut full = Session::open(&stream).unwrap();
            for level in 0..=k {
                full.decode_level(level, self::level(&full, &stream, level))
                    .unwrap();
            }
            assert_eq!(s.state_hash(), full.state_hash(), "{name} level {k}");
        }
        let base = layout_for(&header, &table, 0).total;
        let err = Session::open_within(&stream, base - 1).unwrap_err();
        assert!(
            matches!(err, Error::WorkspaceTooSmall { .. }),
            "{name}: {err}"
        );
        assert_eq!(err.class(), "capacity-exceeded");
    }
}

/// The Rust face of the C ABI's refusals: calls that cannot be right are
/// refused before anything is decoded (`check_level` names why) and leave
/// the session as it was; a failure spends it, and `next_round` then says
/// so instead of `Ok(None)`.
#[test]
fn refusals_leave_the_session_as_it_was_and_failures_spend_it() {
    use splitstream_decoder_core::Error;
    use splitstream_sdk_native::{Refusal, ViewError};
    let (name, stream, expected) = valid_vectors(usize::MAX)
        .into_iter()
        .find(|(_, b, _)| Session::open(b).unwrap().level_count() >= 3)
        .expect("a vector with three levels");
    let final_hash = expected.last().unwrap().clone();
    let full = Session::open(&stream).unwrap();
    let count = full.level_count();

    // Wrong lengths, levels beyond the stream, out of order: refused, and
    // the right bytes then decode, on one thread, two, or round by round.
    let mut s = Session::open(&stream).unwrap();
    for k in 0..count {
        let right = level(&s, &stream, k);
        let mut long = right.to_vec();
        long.push(0);
        for wrong in [&long[..], &right[..right.len() - 1], &stream[..], &[]] {
            assert_eq!(
                s.check_level(k, wrong.len()),
                Err(Refusal::WrongLength {
                    level: k,
                    expected: right.len() as u32,
                    given: wrong.len()
                })
            );
            assert_eq!(s.decode_level(k, wrong), Err(Error::Truncated), "{name}");
            assert_eq!(s.decode_level_two_threads(k, wrong), Err(Error::Truncated));
            assert_eq!(s.begin_level(k, wrong), Err(Error::Truncated));
            assert_eq!(s.failure(), None);
            assert_eq!(s.next_level(), Some(k), "{name}: unchanged");
        }
        let e = s.decode_level(count, right).unwrap_err();
        assert_eq!(
            e,
            Error::NoSuchLevel {
                level: count,
                count
            }
        );
        if k > 0 {
            assert_eq!(
                s.begin_level(k - 1, level(&s, &stream, k - 1))
                    .unwrap_err()
                    .class(),
                "api-misuse"
            );
        }
        match k % 3 {
            0 => s.decode_level(k, right).unwrap(),
            1 => s.decode_level_two_threads(k, right).unwrap(),
            _ => {
                s.begin_level(k, right).unwrap();
                let again = s.check_level(k, right.len()).unwrap_err();
                assert_eq!(again, Refusal::LevelOpen { open: k, got: k });
                assert!(again.to_string().contains("is already open"), "{again}");
                while s.next_round().unwrap().is_some() {}
            }
        }
    }
    assert_eq!(format!("{:016x}", s.state_hash()), final_hash, "{name}");
    let done = s.check_level(0, 0).unwrap_err();
    assert!(done.to_string().contains("already decoded"), "{done}");

    // A level beyond the memory: capacity-exceeded, nothing changed.
    let budget = full.workspace_bytes() - 1;
    let mut s = Session::open_within(&stream, budget).unwrap();
    let fit = s.levels_that_fit();
    assert_eq!(fit, count - 1);
    assert_eq!(s.level_within_error(0.0), fit - 1);
    assert_eq!(s.level_within_error(f32::NAN), fit - 1);
    // NaN and negative bounds: the picker that says so refuses them.
    assert!(matches!(
        s.checked_level_within_error(f32::NAN),
        Err(ViewError::MaxError(v)) if v.is_nan()
    ));
    assert_eq!(
        s.checked_level_within_error(-1.0),
        Err(ViewError::MaxError(-1.0))
    );
    assert_eq!(s.checked_level_within_error(f32::INFINITY), Ok(0));
    let view = splitstream_sdk_native::ScreenView::perspective(1080.0, 1.0).unwrap();
    assert_eq!(s.level_for_screen_error(&view, 0.0, 1.0), Ok(fit - 1));
    let last = level(&s, &stream, fit);
    let e = s.decode_level(fit, last).unwrap_err();
    assert!(matches!(e, Error::WorkspaceTooSmall { .. }), "{e}");
    assert_eq!(e.class(), "capacity-exceeded");
    let r = s.check_level(fit, last.len()).unwrap_err();
    assert_eq!(r.class(), "capacity-exceeded");
    assert!(
        r.to_string().contains(&format!(
            "level {fit} does not fit the memory this decoder was opened with (levels 0..={} fit)",
            fit - 1
        )),
        "{r}"
    );
    assert_eq!(s.next_level(), Some(0));

    // A failure spends the session: every decoding call, next_round
    // included, answers Poisoned.
    let mut bad = level(&s, &stream, 0).to_vec();
    let at = bad.len() - 1;
    bad[at] ^= 0x5A;
    let failed = s
        .begin_level(0, &bad)
        .and_then(|()| {
            while s.next_round()?.is_some() {}
            Ok(())
        })
        .unwrap_err();
    assert_eq!(s.failure(), Some(failed));
    for _ in 0..2 {
        assert_eq!(s.next_round(), Err(Error::Poisoned));
    }
    assert_eq!(s.next_level(), None);
    let l0 = level(&s, &stream, 0);
    assert_eq!(s.decode_level(0, l0), Err(Error::Poisoned));
    assert_eq!(s.decode_level_two_threads(0, l0), Err(Error::Poisoned));
    assert_eq!(s.begin_level(0, l0), Err(Error::Poisoned));
    assert_eq!(
        s.check_level(0, l0.len()),
        Err(Refusal::Failed { error: failed })
    );
}
