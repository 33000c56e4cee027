//! Property tests of the memory model (SPEC §9): decoding with a workspace
//! of every size from 0 up to the needed size, at every alignment, never
//! panics; a workspace too small for the base level gives
//! `WorkspaceTooSmall`, a larger one decodes the levels that fit, to the same
//! states as a full decode; an owned workspace within a budget holds exactly
//! the levels whose layout fits the budget.

#[path = "../fuzz/src/streams.rs"]
mod streams;

use proptest::prelude::*;
use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_decoder_core::{
    Decoder, Error, Header, Inflater, LevelTable, layout_for, workspace_len,
};
use streams::Choices;

/// Decodes `stream` into `ws` and checks it against the full decode.
fn check_size(stream: &[u8], ws: &mut [u8], inflater: &mut Inflater, full: &streams::Decoded) {
    let size = ws.len();
    let d = streams::decode_rounds(stream, ws, inflater);
    match d.error {
        Some(Error::WorkspaceTooSmall { available, .. }) => {
            assert_eq!(available, size);
            assert_eq!(d.levels, 0);
        }
        Some(e) => panic!("size {size}: unexpected {e:?}"),
        None => {
            assert!(d.levels_that_fit >= 1);
            assert_eq!(d.levels, d.levels_that_fit);
            assert_eq!(
                d.level_hashes[..],
                full.level_hashes[..d.levels as usize],
                "size {size}"
            );
            assert_eq!(d.hashes[..], full.hashes[..d.hashes.len()]);
        }
    }
}

fn every_size(stream: &[u8]) {
    let needed = workspace_len(stream).unwrap();
    let full = streams::decode_full(stream);
    assert_eq!(full.error, None);
    let mut inflater = Box::new(Inflater::new());
    let mut bytes = vec![0u8; needed + 16];
    let mut last_fit = 0;
    for size in 0..=needed {
        for skew in [0usize, 1, 3, 7] {
            let ws = &mut bytes[skew..skew + size];
            check_size(stream, ws, &mut inflater, &full);
        }
        // The number of levels that fit never shrinks as the workspace grows.
        let fit = Decoder::new(stream, &mut bytes[..size], &mut inflater)
            .map(|d| d.levels_that_fit())
            .unwrap_or(0);
        assert!(
            fit >= last_fit,
            "size {size}: {fit} levels fit, {last_fit} before"
        );
        last_fit = fit;
    }
    // The advertised size always suffices, at any alignment.
    for skew in 0..8 {
        let ws = &mut bytes[skew..skew + needed];
        let d = streams::decode_rounds(stream, ws, &mut inflater);
        assert_eq!(d.error, None);
        assert_eq!(d.levels as usize, full.level_hashes.len());
    }
}

/// `OwnedWorkspace::within(stream, budget)` for every budget around each
/// prefix's size (its layout in whole 8-byte words: the owned workspace is
/// aligned): too small for the base level is `WorkspaceTooSmall`,
/// otherwise a workspace of at most `budget` bytes whose decoder holds
/// exactly the levels whose layout fits it.
fn every_budget(stream: &[u8]) {
    let header = Header::parse(stream).unwrap();
    let table = LevelTable::parse(stream, &header).unwrap();
    let sizes: Vec<u64> = (0..header.level_count)
        .map(|k| layout_for(&header, &table, k).total.div_ceil(8) * 8)
        .collect();
    let budgets = sizes
        .iter()
        .flat_map(|&b| [b.saturating_sub(1), b, b + 1])
        .chain([0, u64::MAX]);
    for budget in budgets {
        let fit = sizes.iter().filter(|&&b| b <= budget).count() as u16;
        match OwnedWorkspace::within(stream, budget) {
            Err(Error::WorkspaceTooSmall { .. }) => assert_eq!(fit, 0, "budget {budget}"),
            Err(e) => panic!("budget {budget}: {e:?}"),
            Ok(mut ws) => {
                assert!(ws.len() as u64 <= budget, "budget {budget}");
                let decoder = ws.decoder(stream).unwrap();
                assert_eq!(decoder.levels_that_fit(), fit, "budget {budget}");
            }
        }
    }
}

#[test]
fn every_budget_of_the_seed_streams() {
    for g in streams::seed_generated().iter().take(5) {
        every_budget(&g.stream);
    }
}

#[test]
fn every_workspace_size_of_the_seed_streams() {
    for g in streams::seed_generated().iter().take(5) {
        every_size(&g.stream);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 8, ..ProptestConfig::default() })]

    #[test]
    fn every_workspace_size_of_generated_streams(choices in proptest::collection::vec(any::<u8>(), 0..1024)) {
        let g = streams::generate(&mut Choices::new(&choices), false);
        every_size(&g.stream);
        every_budget(&g.stream);
    }
}
