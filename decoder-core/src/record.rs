//! Reading split records and the base mesh from substreams (SPEC §6.3, §7.4, §7.5).

use crate::Error;
use crate::context::{self, SINGLE};
use crate::header::PositionMode;
use crate::limits::substream::{self, SLOTS};
use crate::predict::{predict_split, refine_c};
use crate::ring::Ring;
use crate::round::{RecordSource, all_ones};
use crate::split::SplitRecord;
use crate::state::MeshState;
use crate::substream::Substreams;

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
}

impl RecordSource for StreamSource<'_, '_, '_> {
    #[inline]
    fn flag(&mut self, _state: &MeshState<'_>, _v: u32) -> Result<bool, Error> {
        self.subs.bit(slot(substream::FLAGS), SINGLE)
    }

    #[inline]
    fn likely_flags(&mut self, _state: &MeshState<'_>, upcoming: &[u32]) -> u64 {
        // The next flags of the stream, as far as the loaded chunk shows
        // them; the candidates past them are all taken as likely.
        let (bits, known) = self.subs.peek_bits(slot(substream::FLAGS), SINGLE);
        bits & all_ones(known as usize) | !all_ones(known as usize) & all_ones(upcoming.len())
    }

    fn record(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring) -> Result<SplitRecord, Error> {
        let s = &mut *self.subs;
        let wing_offset = s.byte(slot(substream::WING_OFFSET), SINGLE)?;
        let wing_distance = s.byte(
            slot(substream::WING_DISTANCE),
            context::wing_distance(ring.len()),
        )?;
        let (o, d) = (wing_offset as usize, wing_distance as usize);
        if d == 0 || o + d >= ring.len() {
            return Err(Error::RingOffsetOutOfRange);
        }
        let deficit_p = s.byte(slot(substream::DEFICIT_P), SINGLE)?;
        let deficit_c = s.byte(slot(substream::DEFICIT_C), context::deficit_c(deficit_p))?;
        let parent = state.positions()[r as usize];
        let (p_hat, c_hat) = predict_split(state.positions(), parent, ring, o, d);
        let mut first = [0i64; 3];
        for (k, x) in first.iter_mut().enumerate() {
            *x = s.signed(slot(substream::EDGE), context::axis(k))? as i64;
        }
        let (p, c) = match self.mode {
            PositionMode::Optimal => {
                let p: [i64; 3] = core::array::from_fn(|k| p_hat[k] + first[k]);
                let c_hat = refine_c(c_hat, parent, p);
                let mut c = [0i64; 3];
                for k in 0..3 {
                    c[k] =
                        c_hat[k] + s.signed(slot(substream::PLACEMENT), context::axis(k))? as i64;
                }
                (p, c)
            }
            PositionMode::Constrained => {
                let parent = parent.map(|x| x as i64);
                match s.byte(slot(substream::PLACEMENT), SINGLE)? {
                    // R sits on P: C is coded.
                    0 => (parent, core::array::from_fn(|k| c_hat[k] + first[k])),
                    // R sits on C: P is coded.
                    1 => (core::array::from_fn(|k| p_hat[k] + first[k]), parent),
                    // R is the midpoint P + (e >> 1): the edge e is coded.
                    2 => {
                        let e: [i64; 3] = core::array::from_fn(|k| c_hat[k] - p_hat[k] + first[k]);
                        let p: [i64; 3] = core::array::from_fn(|k| parent[k] - (e[k] >> 1));
                        (p, core::array::from_fn(|k| p[k] + e[k]))
                    }
                    _ => return Err(Error::InvalidPlacement),
                }
            }
        };
        let bits = state.bits();
        Ok(SplitRecord {
            wing_offset,
            wing_distance,
            deficit_p,
            deficit_c,
            position_p: to_grid(p, bits)?,
            position_c: to_grid(c, bits)?,
        })
    }
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
    let (positions, corners, deficits) = state.base_arrays();
    let mut previous = [0i64; 3];
    for p in &mut positions[..vertices as usize] {
        for (k, axis) in previous.iter_mut().enumerate() {
            *axis += subs.signed(base_slot(substream::BASE_POSITIONS), context::axis(k))? as i64;
        }
        *p = to_grid(previous, bits)?;
    }
    for c in &mut corners[..3 * triangles as usize] {
        *c = subs.varint(base_slot(substream::BASE_TRIANGLES), SINGLE)?;
    }
    for d in &mut deficits[..vertices as usize] {
        *d = subs.byte(base_slot(substream::BASE_DEFICITS), SINGLE)?;
    }
    subs.finish()?;
    state.finish_base(vertices, triangles)
}
