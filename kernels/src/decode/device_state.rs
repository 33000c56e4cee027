//! What the wgpu (`refine`) and OpenCL (`ocl_refine`) hosts share beside
//! the API calls: the device buffers with their sizes and first contents,
//! and each round's checks and dispatch plan. The hosts only allocate,
//! upload, dispatch and read back.

use super::adjacency::build_adjacency;
use super::host::{BaseMesh, RefineError, RoundInput, StateBuffer, check_base, check_round};
use super::host::{position_limit, round_split_capacity};
use super::layout::{COUNT_WORDS, NONE, Params, SPLIT_WORDS, Schedule, WORKGROUP};
use super::schedule::{Dispatch, round_schedule, scan_words};

/// Parameter slots one round may use (sort stages dominate: 2^24 candidates
/// need 17 + 16 * 17 / 2 < 200).
pub const PARAM_SLOTS: usize = 512;

/// A state or work buffer of the decoder kernels, in their argument order
/// after the parameters (common.wgsl bindings 1 to 13, common.cl
/// `DECODE_ARGS`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DeviceBuffer {
    Counts,
    Positions,
    Corners,
    Opposite,
    VertexCorner,
    Deficit,
    Mark,
    Uses,
    Candidates,
    Flags,
    Records,
    Scan,
    Splits,
}

impl DeviceBuffer {
    /// Every buffer, in argument order (`ALL[i] as usize == i`).
    pub const ALL: [DeviceBuffer; 13] = [
        DeviceBuffer::Counts,
        DeviceBuffer::Positions,
        DeviceBuffer::Corners,
        DeviceBuffer::Opposite,
        DeviceBuffer::VertexCorner,
        DeviceBuffer::Deficit,
        DeviceBuffer::Mark,
        DeviceBuffer::Uses,
        DeviceBuffer::Candidates,
        DeviceBuffer::Flags,
        DeviceBuffer::Records,
        DeviceBuffer::Scan,
        DeviceBuffer::Splits,
    ];

    /// The buffer as an error message names it.
    pub fn what(self) -> &'static str {
        match self {
            DeviceBuffer::Counts => "the counts buffer",
            DeviceBuffer::Positions => "the positions buffer",
            DeviceBuffer::Corners => "the corners buffer",
            DeviceBuffer::Opposite => "the opposite-corner buffer",
            DeviceBuffer::VertexCorner => "the vertex-corner buffer",
            DeviceBuffer::Deficit => "the deficit buffer",
            DeviceBuffer::Mark => "the mark buffer",
            DeviceBuffer::Uses => "the uses buffer",
            DeviceBuffer::Candidates => "the candidates buffer",
            DeviceBuffer::Flags => "the flags buffer",
            DeviceBuffer::Records => "the split records buffer",
            DeviceBuffer::Scan => "the scan buffer",
            DeviceBuffer::Splits => "the splits buffer",
        }
    }
}

impl From<StateBuffer> for DeviceBuffer {
    fn from(b: StateBuffer) -> DeviceBuffer {
        match b {
            StateBuffer::Positions => DeviceBuffer::Positions,
            StateBuffer::Deficit => DeviceBuffer::Deficit,
            StateBuffer::Corners => DeviceBuffer::Corners,
            StateBuffer::Opposite => DeviceBuffer::Opposite,
            StateBuffer::VertexCorner => DeviceBuffer::VertexCorner,
        }
    }
}

/// The buffers of one refiner: each one's size in `u32` words, and the
/// first contents of those that start from the base mesh (the others start
/// zeroed, or hold nothing read before a round writes it).
pub struct DeviceState {
    /// Words per buffer, indexed by [`DeviceBuffer`].
    pub words: [u64; 13],
    /// The base state, in argument order.
    pub uploads: Vec<(DeviceBuffer, Vec<u32>)>,
    /// The round planner, at the base mesh's vertex count.
    pub rounds: Rounds,
}

impl DeviceState {
    /// Checks `base` against the capacities and lays out the buffers for a
    /// stream of `schedule` (SPEC §3.2): `base`'s deficits are what
    /// decoder-core's state holds under it (§6.2).
    pub fn new(
        base: BaseMesh<'_>,
        schedule: Schedule,
        vertex_capacity: u32,
        triangle_capacity: u32,
    ) -> Result<DeviceState, RefineError> {
        check_base(&base, vertex_capacity, triangle_capacity)?;
        let v0 = base.positions.len() as u32;
        let t0 = base.triangles.len() as u32;
        let (opposite, vertex_corner) =
            build_adjacency(base.triangles, v0).map_err(RefineError::Base)?;
        let split_capacity = round_split_capacity(vertex_capacity, v0);
        let sort_capacity = vertex_capacity.max(WORKGROUP).next_power_of_two();
        let scan_len = vertex_capacity.max(1);
        let (v, t, s) = (
            vertex_capacity as u64,
            triangle_capacity as u64,
            split_capacity as u64,
        );
        let words = [
            COUNT_WORDS as u64,
            3 * v,
            3 * t,
            3 * t,
            v,
            v,
            v,
            v,
            sort_capacity as u64,
            v.div_ceil(32),
            (core::mem::size_of::<super::layout::GpuRecord>() as u64 / 4) * s,
            scan_words(scan_len),
            SPLIT_WORDS as u64 * s,
        ];
        let uploads = vec![
            (DeviceBuffer::Counts, vec![v0, t0, 0, NONE]),
            (
                DeviceBuffer::Positions,
                base.positions.iter().flatten().copied().collect(),
            ),
            (
                DeviceBuffer::Corners,
                base.triangles.iter().flatten().copied().collect(),
            ),
            (DeviceBuffer::Opposite, opposite),
            (DeviceBuffer::VertexCorner, vertex_corner),
            (
                DeviceBuffer::Deficit,
                base.deficits.iter().map(|&d| d as u32).collect(),
            ),
        ];
        Ok(DeviceState {
            words,
            uploads,
            rounds: Rounds {
                vertex_capacity,
                triangle_capacity,
                split_capacity,
                scan_scratch: scan_len,
                pos_limit: position_limit(base.bits),
                vertex_count: v0,
                schedule: schedule.word(),
            },
        })
    }
}

/// The host's side of the rounds: the capacities, and the vertex count as
/// the host tracks it (the device keeps its own).
pub struct Rounds {
    vertex_capacity: u32,
    triangle_capacity: u32,
    split_capacity: u32,
    /// First scan word after the values (block sums live there).
    scan_scratch: u32,
    pos_limit: u32,
    vertex_count: u32,
    /// `Params::schedule` of every dispatch.
    schedule: u32,
}

impl Rounds {
    /// Vertex count after the rounds submitted so far (assuming they passed).
    pub fn vertex_count(&self) -> u32 {
        self.vertex_count
    }

    /// The dispatches of the round `input`, after its checks; at most
    /// [`PARAM_SLOTS`].
    pub fn plan(&self, input: &RoundInput<'_>) -> Result<Vec<Dispatch>, RefineError> {
        let n = self.vertex_count;
        check_round(input, n, self.vertex_capacity, self.split_capacity)?;
        let common = Params {
            n,
            candidates: input.candidates,
            splits: input.records.len() as u32,
            sort_len: input.candidates.max(WORKGROUP).next_power_of_two(),
            tri_limit: input.triangle_limit.min(self.triangle_capacity),
            pos_limit: self.pos_limit,
            schedule: self.schedule,
            ..Params::default()
        };
        let plan = round_schedule(common, self.scan_scratch);
        if plan.len() > PARAM_SLOTS {
            return Err(RefineError::Capacity {
                what: "dispatches per round",
                needed: plan.len() as u64,
                capacity: PARAM_SLOTS as u64,
            });
        }
        Ok(plan)
    }

    /// Counts the round `input` as submitted.
    pub fn submitted(&mut self, input: &RoundInput<'_>) {
        self.vertex_count += input.records.len() as u32;
    }

    /// Takes the device's vertex count, read back with a snapshot.
    pub fn read_back(&mut self, vertex_count: u32) {
        self.vertex_count = vertex_count;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_buffers_are_listed_in_argument_order() {
        for (i, b) in DeviceBuffer::ALL.iter().enumerate() {
            assert_eq!(*b as usize, i);
        }
    }

    #[test]
    fn a_round_is_checked_and_counted() {
        let positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]];
        let triangles = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        let base = BaseMesh {
            positions: &positions,
            triangles: &triangles,
            deficits: &[0, 0, 0, 0],
            bits: 8,
        };
        let mut state = DeviceState::new(base, Schedule::SplitValences, 16, 32).expect("lays out");
        assert_eq!(state.words[DeviceBuffer::Positions as usize], 48);
        assert_eq!(state.uploads[0].1, vec![4, 4, 0, NONE]);
        let record = super::super::layout::GpuRecord::default();
        let input = RoundInput {
            candidates: 4,
            flags: &[1],
            records: &[record],
            triangle_limit: 32,
        };
        assert!(state.rounds.plan(&input).is_ok());
        state.rounds.submitted(&input);
        assert_eq!(state.rounds.vertex_count(), 5);
        let too_many = RoundInput {
            candidates: 6,
            ..input
        };
        assert!(matches!(
            state.rounds.plan(&too_many),
            Err(RefineError::Input(_))
        ));
    }
}
