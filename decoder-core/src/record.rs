//! Reading split records and the base mesh from substreams (SPEC §6.3, §7.4).

use crate::Error;
use crate::context::{self, DeficitContexts, SINGLE};
use crate::header::{PositionMode, Schedule};
use crate::limits::MAX_SPLIT_VALENCE;
use crate::limits::substream::{self, SLOTS};
use crate::positions_first::{
    self, KIND_CONTEXT, KIND_ESCAPE, NewEdge, OFFSET_CONTEXT, PositionsFirst, RecordOrder, Ties,
    Z_CONTEXT, choice_context, rank_context,
};
use crate::predict::{
    Plane, PlanePolicy, SplitFan, Target, arc_means, constrained_positions, height_prediction,
    predict, wrap,
};
use crate::ring::Ring;
use crate::round::{RecordSource, all_ones_wide};
use crate::split::SplitRecord;
use crate::state::MeshState;
use crate::substream::{Substreams, zigzag};
use crate::symbols::{WingCandidates, deficit_of};
use crate::wing_order::{NearKeys, WingPolicy, near_keys, near_wings};

/// Substream slot of a refinement substream id (ids 1..=7 use slots 0..=6).
const fn slot(id: u8) -> usize {
    (id - substream::FLAGS) as usize
}

/// Substream slot of a base substream id (ids 8..=10 use slots 0..=2).
const fn base_slot(id: u8) -> usize {
    (id - substream::BASE_POSITIONS) as usize
}

const _: () = assert!(slot(substream::PLACEMENT) < SLOTS);

/// Feeds a round from a level's substreams: the stream decoder's
/// [`RecordSource`]. Public so that other drivers (a GPU decoder's host,
/// the conformance suite's deliberately broken decoder) reuse the parsing.
pub struct StreamSource<'s, 'l, 'b> {
    pub subs: &'s mut Substreams<'l, 'b>,
    pub mode: PositionMode,
    /// The level's plane policy (SPEC §5.1).
    pub plane: PlanePolicy,
    /// The level's wing policy (SPEC §5.1, 3.2).
    pub wings: WingPolicy,
    /// The level's deficit contexts (SPEC §5.1, 3.3).
    pub deficits: DeficitContexts,
    /// The stream's schedule (SPEC §3.2, 3.6).
    pub schedule: Schedule,
    /// The level's record order (SPEC §5.1, 3.7).
    pub records: RecordOrder,
    /// Its wing choices' tie-break under `positions-first` (SPEC §5.1, 3.8).
    pub ties: Ties,
    /// What reading a record needs besides the substreams.
    scratch: RecordScratch,
}

/// The working arrays of a record (kept between records: nothing is
/// cleared per split but what it uses): the current ring's near keys under
/// a near wing policy, its fan's free lattice points and wing pairs under
/// `positions-first`.
#[derive(Clone)]
pub struct RecordScratch {
    keys: NearKeys,
    pf: PositionsFirst,
}

impl Default for RecordScratch {
    fn default() -> Self {
        RecordScratch {
            keys: [0; MAX_SPLIT_VALENCE],
            pf: PositionsFirst::default(),
        }
    }
}

impl<'s, 'l, 'b> StreamSource<'s, 'l, 'b> {
    /// Reads the rounds of the level whose substreams `subs` are open, in
    /// position mode `mode`, with the plane policy of the level's header.
    pub fn new(subs: &'s mut Substreams<'l, 'b>, mode: PositionMode) -> Self {
        let plane = subs.level_header().plane_policy;
        let wings = subs.level_header().wing_policy;
        let deficits = subs.level_header().deficit_contexts;
        let schedule = subs.level_header().schedule;
        let records = subs.level_header().record_order;
        let ties = subs.level_header().ties;
        StreamSource {
            subs,
            mode,
            plane,
            wings,
            deficits,
            schedule,
            records,
            ties,
            scratch: RecordScratch::default(),
        }
    }
}

/// Reads one residual vector from `slot` (SPEC §7.4): the axes in the
/// plane's order and contexts, then the plane's offset on its axis.
#[inline]
fn read_vector(s: &mut Substreams<'_, '_>, slot: usize, plane: &Plane) -> Result<[i64; 3], Error> {
    let mut coded = [0i64; 3];
    for axis in plane.order() {
        coded[axis] = s.signed(slot, plane.context(axis))? as i64;
    }
    Ok(plane.decode(coded))
}

impl StreamSource<'_, '_, '_> {
    /// How the level codes its records.
    pub(crate) fn coding(&self) -> RecordCoding {
        RecordCoding {
            mode: self.mode,
            plane: self.plane,
            wings: self.wings,
            deficits: self.deficits,
            schedule: self.schedule,
            records: self.records,
            ties: self.ties,
        }
    }
}

/// The context of `v`'s flag under `every-vertex` (SPEC §5.5.5): its
/// valence byte and, under the contexts `split-history`, its split-history
/// bit, as the state holds them (at the start of the round for every
/// vertex whose flag is still to be read, §7.3).
#[inline]
pub(crate) fn flag_context(state: &MeshState<'_>, contexts: DeficitContexts, v: u32) -> u8 {
    let byte = state.deficits().get(v as usize).copied().unwrap_or(0);
    match contexts {
        // `context::flag`'s rule, written again with the bit as a number (no
        // branch on it), and the bit read only under `split-history`:
        // calling `context::flag` with the bit read for every level cost
        // 0.7 % more instructions on a 3.9 stream and 0.2 % on a 3.10 one
        // (the 1M demo terrain under callgrind, 2026-12-06).
        DeficitContexts::SplitHistory => byte.clamp(5, 8) - 5 + 4 * state.split_bit(v),
        _ => context::flag(Schedule::EveryVertex, contexts, byte, false),
    }
}

impl RecordSource for StreamSource<'_, '_, '_> {
    /// SPEC §7.3: one context, or under `every-vertex` the vertex's
    /// valence at the start of the round, and under the contexts
    /// `split-history` its split-history bit (§5.5.5, 3.10).
    #[inline]
    fn flag(&mut self, state: &MeshState<'_>, v: u32) -> Result<bool, Error> {
        let context = match self.schedule {
            Schedule::SplitValences => SINGLE,
            Schedule::EveryVertex => flag_context(state, self.deficits, v),
        };
        self.subs.bit(slot(substream::FLAGS), context)
    }

    #[inline]
    fn likely_flags(&mut self, state: &MeshState<'_>, upcoming: &[u32]) -> u128 {
        // The next flags of the stream, as far as the loaded chunk shows
        // them; the candidates past them are all taken as likely. Under
        // `every-vertex` each is peeked in its vertex's context, as if no
        // upcoming vertex blocked a later one (a hint only).
        let (bits, known) = match self.schedule {
            Schedule::SplitValences => {
                let (bits, known) = self.subs.peek_bits(slot(substream::FLAGS), SINGLE);
                (bits as u128, known)
            }
            Schedule::EveryVertex => {
                let mut contexts = [0u8; 128];
                let n = upcoming.len().min(128);
                for (c, &v) in contexts.iter_mut().zip(&upcoming[..n]) {
                    *c = flag_context(state, self.deficits, v);
                }
                self.subs
                    .peek_bits_in(slot(substream::FLAGS), &contexts[..n])
            }
        };
        bits & all_ones_wide(known as usize)
            | !all_ones_wide(known as usize) & all_ones_wide(upcoming.len())
    }

    /// SPEC §7.4, fields in order: wing ranks (in ring order, or in the near
    /// order of the level's wing policy), split valences of P and C (in the
    /// level's deficit contexts),
    /// then (constrained) the placement code and one residual vector, or
    /// (optimal) two residual vectors.
    fn record(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring) -> Result<SplitRecord, Error> {
        let eligible = state.wing_candidates(ring);
        let coding = self.coding();
        let fan = RecordFan {
            positions: state.positions(),
            bits: state.bits(),
            r,
            ring,
            eligible: &eligible,
        };
        read_record(self.subs, &coding, &mut self.scratch, &fan)
    }
}

/// How a level codes its split records (SPEC §5.1): the position mode and
/// the level's policies.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RecordCoding {
    pub(crate) mode: PositionMode,
    pub(crate) plane: PlanePolicy,
    pub(crate) wings: WingPolicy,
    pub(crate) deficits: DeficitContexts,
    pub(crate) schedule: Schedule,
    pub(crate) records: RecordOrder,
    pub(crate) ties: Ties,
}

/// What a split record is read against (SPEC §7.4): the positions, R and
/// its ring, and the ring entries that may be wings (from the round-start
/// candidates).
pub(crate) struct RecordFan<'a> {
    pub(crate) positions: &'a [[u32; 3]],
    pub(crate) bits: u8,
    pub(crate) r: u32,
    pub(crate) ring: &'a Ring,
    pub(crate) eligible: &'a WingCandidates,
}

/// Reads the record of the split of `fan.r` (SPEC §7.4): under the record
/// order `positions-first` (3.7) positions first where the fan allows it,
/// and otherwise wings first.
#[inline]
pub(crate) fn read_record(
    s: &mut Substreams<'_, '_>,
    coding: &RecordCoding,
    scratch: &mut RecordScratch,
    fan: &RecordFan<'_>,
) -> Result<SplitRecord, Error> {
    if coding.records == RecordOrder::PositionsFirst {
        let parent = *fan
            .positions
            .get(fan.r as usize)
            .ok_or(Error::CapacityExceeded)?;
        if let Some(free) = scratch.pf.free_points(fan.positions, parent, fan.ring) {
            let kind = byte_out_of_line(s, slot(substream::PLACEMENT), KIND_CONTEXT)?;
            match kind {
                0 | 1 => {
                    return read_positions_first(
                        s,
                        coding,
                        &mut scratch.pf,
                        fan,
                        parent,
                        free,
                        kind == 1,
                    );
                }
                KIND_ESCAPE => {}
                _ => return Err(Error::InvalidPlacement),
            }
        }
    }
    read_wings_first(s, coding, &mut scratch.keys, fan)
}

/// `read_record_pf` of SPEC §7.4 ("Positions first") after its kind, for
/// the split of the vertex at `parent`: the
/// new vertex's rank among the fan's `free` lattice points (a midpoint's
/// offset after it), the wings among the pairs that keep the new
/// triangles counter-clockwise in xy, the split valences, then z.
fn read_positions_first(
    s: &mut Substreams<'_, '_>,
    coding: &RecordCoding,
    pf: &mut PositionsFirst,
    fan: &RecordFan<'_>,
    parent: [u32; 3],
    free: usize,
    midpoint: bool,
) -> Result<SplitRecord, Error> {
    let RecordFan {
        positions,
        bits,
        ring,
        eligible,
        ..
    } = *fan;
    let j = varint_out_of_line(s, slot(substream::EDGE), rank_context(free))?;
    let n = pf.point_at(j as usize).ok_or(Error::PositionOutOfRange)?;
    let (edge, offset) = if midpoint {
        let t = byte_out_of_line(s, slot(substream::PLACEMENT), OFFSET_CONTEXT)?;
        if t > 3 {
            return Err(Error::InvalidPlacement);
        }
        let offset = [(t & 1) as i64, (t >> 1) as i64];
        let p = [offset[0] - n[0], offset[1] - n[1]];
        (
            NewEdge {
                a: p,
                b: n,
                midpoint,
            },
            offset,
        )
    } else {
        (
            NewEdge {
                a: n,
                b: [0, 0],
                midpoint,
            },
            [0, 0],
        )
    };
    pf.set_ties(coding.ties);
    let xs = pf.order_xs(eligible, &edge);
    let u = byte_out_of_line(s, slot(substream::WING_OFFSET), choice_context(xs))?;
    let x = pf
        .choice(xs, u as usize)
        .ok_or(Error::RingOffsetOutOfRange)?;
    let ys = pf.order_ys(&edge, x);
    let v = byte_out_of_line(s, slot(substream::WING_DISTANCE), choice_context(ys))?;
    let y = pf
        .choice(ys, v as usize)
        .ok_or(Error::RingOffsetOutOfRange)?;
    let (o, d, code) = positions_first::wings_and_code(x, y, midpoint);
    let (deficit_p, deficit_c) = read_deficits(s, coding, ring.len(), d)?;
    let r_z = signed_out_of_line(s, slot(substream::EDGE), Z_CONTEXT)? as i64;
    let target = Target::of_code(code).ok_or(Error::InvalidPlacement)?;
    let xy = if midpoint {
        [2 * n[0] - offset[0], 2 * n[1] - offset[1]]
    } else {
        n
    };
    let h = height_prediction(positions, parent, ring, target, [xy[0], xy[1], 0]).unwrap_or(0);
    let (p, c) = constrained_positions(parent, code, [xy[0], xy[1], wrap(h + r_z)]);
    Ok(SplitRecord {
        wing_offset: o as u8,
        wing_distance: d as u8,
        deficit_p,
        deficit_c,
        position_p: to_grid(p, bits)?,
        position_c: to_grid(c, bits)?,
    })
}

/// The value readers of a positions-first record, out of line: the
/// wings-first record inlines its readers for speed, and inlining these
/// too would add kilobytes to a microcontroller's decoder for reads that
/// are not its bottleneck (the fan's free points are).
#[inline(never)]
fn byte_out_of_line(s: &mut Substreams<'_, '_>, slot: usize, context: u8) -> Result<u8, Error> {
    s.byte(slot, context)
}

#[inline(never)]
fn varint_out_of_line(s: &mut Substreams<'_, '_>, slot: usize, context: u8) -> Result<u32, Error> {
    s.varint(slot, context)
}

/// On 32-bit Arm, [`Substreams::signed`] through [`varint_out_of_line`]
/// (SPEC §5.4): only the zigzag step is inlined, so that the varint reader
/// has one out-of-line copy, not two (about 750 bytes of thumbv7em
/// `.text`). Elsewhere a copy of its own, compiled for its one caller's
/// constant slot and context: through `varint_out_of_line` it cost 0.13 %
/// more instructions on a positions-first terrain (t300 under callgrind).
#[cfg_attr(target_arch = "arm", inline(always))]
#[cfg_attr(not(target_arch = "arm"), inline(never))]
fn signed_out_of_line(s: &mut Substreams<'_, '_>, slot: usize, context: u8) -> Result<i32, Error> {
    if cfg!(target_arch = "arm") {
        Ok(zigzag(varint_out_of_line(s, slot, context)?))
    } else {
        s.signed(slot, context)
    }
}

/// The value readers of the base mesh (SPEC §6.3), read once per stream.
/// On 32-bit Arm they are the positions-first record's out-of-line
/// readers: the three readers inlined here were about 1.9 KB of a
/// thumbv7em decoder's `.text`. Elsewhere they stay inlined: a second
/// caller with other slots would cost the out-of-line readers the
/// constant slot they are compiled for (14 more instructions a call,
/// +0.2 % on a positions-first terrain under callgrind).
#[inline(always)]
fn base_byte(s: &mut Substreams<'_, '_>, slot: usize, context: u8) -> Result<u8, Error> {
    if cfg!(target_arch = "arm") {
        byte_out_of_line(s, slot, context)
    } else {
        s.byte(slot, context)
    }
}

/// [`base_byte`] for varints (SPEC §5.4, §6.3).
#[inline(always)]
fn base_varint(s: &mut Substreams<'_, '_>, slot: usize, context: u8) -> Result<u32, Error> {
    if cfg!(target_arch = "arm") {
        varint_out_of_line(s, slot, context)
    } else {
        s.varint(slot, context)
    }
}

/// [`base_byte`] for signed varints (SPEC §5.4, §6.3).
#[inline(always)]
fn base_signed(s: &mut Substreams<'_, '_>, slot: usize, context: u8) -> Result<i32, Error> {
    if cfg!(target_arch = "arm") {
        signed_out_of_line(s, slot, context)
    } else {
        s.signed(slot, context)
    }
}

/// The split valences of P and C (SPEC §7.4 step 2) of a split of a ring
/// of `k` entries whose wings are `d` apart, in the level's deficit
/// contexts; under `every-vertex` the valences themselves, read from
/// nothing.
#[inline]
fn read_deficits(
    s: &mut Substreams<'_, '_>,
    coding: &RecordCoding,
    k: usize,
    d: usize,
) -> Result<(u8, u8), Error> {
    let (valence_p, valence_c) = (d + 2, k - d + 2);
    match coding.schedule {
        // 3.6: no split valences; the bytes are the valences (SPEC §7.4).
        Schedule::EveryVertex => Ok((
            valence_p.min(MAX_SPLIT_VALENCE) as u8,
            valence_c.min(MAX_SPLIT_VALENCE) as u8,
        )),
        Schedule::SplitValences => {
            let contexts = coding.deficits;
            let deficit_p = deficit_of(
                s.byte(
                    slot(substream::DEFICIT_P),
                    context::deficit_p(contexts, valence_p),
                )?,
                valence_p,
            )?;
            let deficit_c = deficit_of(
                s.byte(
                    slot(substream::DEFICIT_C),
                    context::deficit_c(contexts, deficit_p, valence_c),
                )?,
                valence_c,
            )?;
            Ok((deficit_p, deficit_c))
        }
    }
}

/// Reads the record of the split of `fan.r` wings first (SPEC §7.4
/// `read_record`), fields in order:
/// wing ranks (in ring order, or in the near order of the level's wing
/// policy), split valences of P and C (in the level's deficit contexts),
/// then (constrained) the placement code and one residual vector, or
/// (optimal) two residual vectors.
#[inline]
fn read_wings_first(
    s: &mut Substreams<'_, '_>,
    coding: &RecordCoding,
    keys: &mut NearKeys,
    fan: &RecordFan<'_>,
) -> Result<SplitRecord, Error> {
    let RecordFan {
        positions,
        bits,
        r,
        ring,
        eligible,
    } = *fan;
    let k = ring.len();
    let wing_context = context::wing(eligible.count());
    let o_rank = s.byte(slot(substream::WING_OFFSET), wing_context)?;
    let d_rank = s.byte(slot(substream::WING_DISTANCE), wing_context)?;
    let (o, d) = match coding.wings {
        WingPolicy::Ranks => eligible.wings(o_rank, d_rank)?,
        near => {
            let m = near_keys(positions, ring, eligible, near, keys);
            near_wings(&keys[..m], k, o_rank, d_rank)?
        }
    };
    let (deficit_p, deficit_c) = read_deficits(s, coding, k, d)?;
    let parent = *positions.get(r as usize).ok_or(Error::CapacityExceeded)?;
    let means = arc_means(positions, parent, ring, o, d);
    let plane = Plane::new(coding.plane, &means);
    let origin = parent.map(|x| x as i64);
    let add = |a: [i64; 3], b: [i64; 3]| -> [i64; 3] { core::array::from_fn(|i| a[i] + b[i]) };
    let fan = SplitFan {
        positions,
        parent,
        ring,
    };
    let (p, c) = match coding.mode {
        PositionMode::Constrained => {
            let code = s.byte(slot(substream::PLACEMENT), context::placement(&means))?;
            let target = Target::of_code(code).ok_or(Error::InvalidPlacement)?;
            let prediction = predict(&means, coding.mode, target);
            let r = read_vector(s, slot(substream::EDGE), &plane)?;
            let x = fan.vector(coding.plane, target, prediction, r);
            constrained_positions(parent, code, x)
        }
        PositionMode::Optimal => {
            let p_hat = predict(&means, coding.mode, Target::P);
            let c_hat = predict(&means, coding.mode, Target::C);
            let s_vec = read_vector(s, slot(substream::EDGE), &plane)?;
            let t_vec = read_vector(s, slot(substream::PLACEMENT), &plane)?;
            let p = fan.vector(coding.plane, Target::P, p_hat, s_vec);
            let c = fan.vector(coding.plane, Target::C, c_hat, t_vec);
            (add(origin, p), add(origin, c))
        }
    };
    Ok(SplitRecord {
        wing_offset: o as u8,
        wing_distance: d as u8,
        deficit_p,
        deficit_c,
        position_p: to_grid(p, bits)?,
        position_c: to_grid(c, bits)?,
    })
}

fn to_grid(p: [i64; 3], bits: u8) -> Result<[u32; 3], Error> {
    let limit = 1i64 << bits;
    let mut out = [0u32; 3];
    for k in 0..3 {
        if !(0..limit).contains(&p[k]) {
            return Err(Error::PositionOutOfRange);
        }
        out[k] = p[k] as u32;
    }
    Ok(out)
}

/// Reads the base mesh of `vertices` and `triangles` into `state` and builds
/// its adjacency (SPEC §6.3).
pub fn read_base(
    state: &mut MeshState<'_>,
    subs: &mut Substreams<'_, '_>,
    vertices: u32,
    triangles: u32,
) -> Result<(), Error> {
    if vertices > state.vertex_capacity() || triangles > state.triangle_capacity() {
        return Err(Error::CapacityExceeded);
    }
    let bits = state.bits();
    // Under `every-vertex` base-deficits holds nothing: `finish_base` sets
    // each byte to the vertex's valence (SPEC §6.3, 3.6).
    let schedule = state.schedule();
    let (positions, corners, deficits) = state.base_arrays();
    let mut previous = [0i64; 3];
    for p in &mut positions[..vertices as usize] {
        for (k, axis) in previous.iter_mut().enumerate() {
            *axis +=
                base_signed(subs, base_slot(substream::BASE_POSITIONS), context::axis(k))? as i64;
        }
        *p = to_grid(previous, bits)?;
    }
    for c in &mut corners[..3 * triangles as usize] {
        *c = base_varint(subs, base_slot(substream::BASE_TRIANGLES), SINGLE)?;
    }
    if schedule == Schedule::SplitValences {
        for d in &mut deficits[..vertices as usize] {
            *d = base_byte(subs, base_slot(substream::BASE_DEFICITS), SINGLE)?;
        }
    }
    subs.finish()?;
    state.finish_base(vertices, triangles)
}
