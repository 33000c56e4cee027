//! `LevelDecoder::next_round_observed` shows every split record the decoder
//! applies, once, in decoding order, and decodes exactly as `next_round`.

#[path = "../fuzz/src/streams.rs"]
mod streams;

use splitstream_decoder_core::{
    Decoder, Inflater, MeshState, Ring, SplitObserver, SplitRecord, workspace_len,
};

/// Records what it is shown, and the vertex count it was shown it at.
#[derive(Default)]
struct Seen {
    records: Vec<(u32, u32, SplitRecord)>,
}

impl SplitObserver for Seen {
    fn record(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring, record: &SplitRecord) {
        assert!(ring.len() >= 2, "a split's ring");
        self.records.push((r, state.vertex_count(), *record));
    }
}

#[test]
fn the_observer_sees_every_applied_split_and_decoding_is_unchanged() {
    for g in streams::seed_generated() {
        let stream = &g.stream;
        let mut ws = vec![0u8; workspace_len(stream).unwrap()];
        let mut inflater = Box::new(Inflater::new());
        let mut d = Decoder::new(stream, &mut ws, &mut inflater).unwrap();
        let mut seen = Seen::default();
        let mut splits = 0;
        while let Some(k) = d.next_level() {
            let bytes = d.level_bytes(k, stream).unwrap();
            let mut level = d.begin_level(k, bytes).unwrap();
            while let Some(info) = level.next_round_observed(&mut seen).unwrap() {
                splits += info.stats.splits as usize;
                assert_eq!(seen.records.len(), splits, "{}", g.base);
            }
        }
        // The C of the j-th split overall is vertex (base vertices + j), and
        // the records' positions are where P and C ended up, unless a later
        // split moved them (R keeps P's index and gets P's position).
        let positions = d.positions();
        for (j, &(r, n, record)) in seen.records.iter().enumerate() {
            assert_eq!(n, g.base_vertices + j as u32, "{}", g.base);
            let later = |v: u32| seen.records[j + 1..].iter().any(|&(r2, _, _)| r2 == v);
            if !later(n) {
                assert_eq!(positions[n as usize], record.position_c, "{}", g.base);
            }
            if !later(r) {
                assert_eq!(positions[r as usize], record.position_p, "{}", g.base);
            }
        }
        assert_eq!(d.state_hash(), *g.hashes.last().unwrap(), "{}", g.base);
    }
}

/// The candidates, scanned (SPEC §6.2): the deficit-0 vertices, or under
/// the schedule `every-vertex` every vertex.
fn scanned(state: &MeshState<'_>) -> Vec<u32> {
    let every = state.schedule() == splitstream_decoder_core::Schedule::EveryVertex;
    (0..state.vertex_count())
        .filter(|&v| every || state.deficits()[v as usize] == 0)
        .collect()
}

#[test]
fn the_candidates_are_the_scheduled_vertices_before_every_round() {
    for g in streams::seed_generated() {
        let stream = &g.stream;
        let mut ws = vec![0u8; workspace_len(stream).unwrap()];
        let mut inflater = Box::new(Inflater::new());
        let mut d = Decoder::new(stream, &mut ws, &mut inflater).unwrap();
        let mut rounds = 0;
        while let Some(k) = d.next_level() {
            let bytes = d.level_bytes(k, stream).unwrap();
            let mut level = d.begin_level(k, bytes).unwrap();
            loop {
                let state = level.state();
                assert_eq!(state.candidates().collect::<Vec<_>>(), scanned(state));
                if level.next_round().unwrap().is_none() {
                    break;
                }
                rounds += 1;
            }
        }
        assert!(rounds > 0, "{}", g.base);
    }
}

/// Records the flags it is shown, and the splits.
#[derive(Default)]
struct Flags {
    /// (vertex, flag, vertex count when read) of the current round.
    round: Vec<(u32, bool, u32)>,
    splits: Vec<u32>,
}

impl SplitObserver for Flags {
    fn flag(&mut self, state: &MeshState<'_>, v: u32, flag: bool) {
        self.round.push((v, flag, state.vertex_count()));
    }

    fn record(&mut self, _: &MeshState<'_>, r: u32, _: &Ring, _: &SplitRecord) {
        self.splits.push(r);
    }
}

#[test]
fn the_observer_sees_each_coded_flag_in_candidate_order() {
    for g in streams::seed_generated() {
        let stream = &g.stream;
        let mut ws = vec![0u8; workspace_len(stream).unwrap()];
        let mut inflater = Box::new(Inflater::new());
        let mut d = Decoder::new(stream, &mut ws, &mut inflater).unwrap();
        let mut seen = Flags::default();
        while let Some(k) = d.next_level() {
            let bytes = d.level_bytes(k, stream).unwrap();
            let mut level = d.begin_level(k, bytes).unwrap();
            loop {
                let start = level.state().vertex_count();
                let candidates: Vec<u32> = scanned(level.state());
                let Some(info) = level.next_round_observed(&mut seen).unwrap() else {
                    break;
                };
                // Ascending candidates of the round's start, each once; the
                // flagged ones are the round's splits, in order.
                let shown: Vec<u32> = seen.round.iter().map(|&(v, _, _)| v).collect();
                assert!(shown.windows(2).all(|w| w[0] < w[1]), "{}", g.base);
                assert!(shown.iter().all(|v| candidates.contains(v)), "{}", g.base);
                let flagged: Vec<u32> = seen
                    .round
                    .iter()
                    .filter(|&&(_, f, _)| f)
                    .map(|&(v, _, _)| v)
                    .collect();
                assert_eq!(flagged, seen.splits, "{}", g.base);
                assert_eq!(flagged.len(), info.stats.splits as usize, "{}", g.base);
                // A flag is read before its own split (the state it sees
                // has the vertices of the splits before it only).
                for &(v, _, n) in &seen.round {
                    let before = seen.splits.iter().take_while(|&&r| r < v).count() as u32;
                    assert_eq!(n, start + before, "{}", g.base);
                }
                seen.round.clear();
                seen.splits.clear();
            }
        }
        assert_eq!(d.state_hash(), *g.hashes.last().unwrap(), "{}", g.base);
    }
}
