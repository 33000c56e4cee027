//! A [`SplitObserver`] that keeps what the GPU needs to replay a round:
//! the candidate count, one flag bit per candidate (in ascending candidate
//! order) and the flagged splits' records with their final positions.

use splitstream_decoder_core::{MeshState, Ring, Schedule, SplitObserver, SplitRecord};
use splitstream_kernels::decode::GpuRecord;

/// One round as the stream gave it, in the GPU's terms.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CapturedRound {
    /// Vertices with deficit 0 at round start; under the schedule
    /// `every-vertex` (SPEC §7.3, 3.6), all of them.
    pub candidates: u32,
    /// Bit i (LSB first) is candidate i's flag; candidates whose flag the
    /// format infers (a neighbour flagged before them) read 0.
    pub flags: Vec<u32>,
    /// The flagged splits' records, in split order.
    pub records: Vec<GpuRecord>,
}

/// Watches a round's flags and records (decoder-core's
/// `LevelDecoder::next_round_observed`).
#[derive(Default)]
pub struct Capture {
    round: CapturedRound,
    /// The round's candidates, ascending, once the first flag is asked.
    candidates: Vec<u32>,
    cursor: usize,
    started: bool,
    /// A flag was asked for a vertex that is not a candidate (a change in
    /// decoder-core's round procedure this capture does not follow).
    pub out_of_order: bool,
}

impl Capture {
    /// The round captured since the last call; starts a new one.
    pub fn take_round(&mut self) -> CapturedRound {
        self.started = false;
        self.cursor = 0;
        self.candidates.clear();
        core::mem::take(&mut self.round)
    }

    fn start(&mut self, state: &MeshState<'_>) {
        // Flags are read before any split of the round: the state is the
        // round's starting state, whose candidates are the deficit-0
        // vertices, or under every-vertex every vertex (SPEC §7.3; scanned
        // here; the two-thread capture reads them from decoder-core's
        // bitmap, and the tests compare the two).
        self.candidates.clear();
        let every_vertex = state.schedule() == Schedule::EveryVertex;
        self.candidates.extend(
            state
                .deficits()
                .iter()
                .enumerate()
                .filter(|&(_, &d)| every_vertex || d == 0)
                .map(|(v, _)| v as u32),
        );
        let count = self.candidates.len();
        self.round = CapturedRound {
            candidates: count as u32,
            flags: vec![0; count.div_ceil(32)],
            records: Vec::new(),
        };
        self.started = true;
    }
}

/// The GPU's form of a record (positions already resolved on the CPU).
pub fn gpu_record(rec: &SplitRecord) -> GpuRecord {
    GpuRecord {
        offset: rec.wing_offset as u32,
        distance: rec.wing_distance as u32,
        // Format 2.0: arc 1 always goes to P (no configuration bit).
        config: 0,
        deficit_p: rec.deficit_p as u32,
        deficit_c: rec.deficit_c as u32,
        position_p: rec.position_p,
        position_c: rec.position_c,
        _pad: 0,
    }
}

impl SplitObserver for Capture {
    fn flag(&mut self, state: &MeshState<'_>, v: u32, flag: bool) {
        if !self.started {
            self.start(state);
        }
        while self.candidates.get(self.cursor).is_some_and(|&c| c < v) {
            self.cursor += 1;
        }
        if self.candidates.get(self.cursor) != Some(&v) {
            self.out_of_order = true;
        } else if flag {
            self.round.flags[self.cursor / 32] |= 1 << (self.cursor % 32);
        }
    }

    fn record(&mut self, _: &MeshState<'_>, _: u32, _: &Ring, record: &SplitRecord) {
        self.round.records.push(gpu_record(record));
    }
}
