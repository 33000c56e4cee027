//! Valid-stream generator shared by the fuzz targets, the seed-stream example
//! and the property tests (`#[path]`-included there; it uses only the public
//! API of `splitstream-decoder-core` with the `alloc` feature, plus `std`).
//!
//! A stream is built the way the encoder builds one: a [`MeshState`] replays
//! every round through [`MeshState::run_round`] with a [`RecordSource`] that
//! *chooses* flags and split records (from a byte string of choices) and
//! writes them into the substreams as it goes. The result is valid by
//! construction, and the state hash after the base and after every round is
//! known, so a decoder run can be compared round by round.
//!
//! With `allow_invalid`, a few choice values inject one fault per record
//! (raw wing ranks, raw split-valence symbols, a placement code above 2, a
//! flagged neighbour); the replay then stops at the error and the stream
//! ends with that round, so the decoder must report the very same error.
//!
//! Each level gets a plane policy and a wing policy from the choices (SPEC
//! §5.1); with 31
//! bits per axis the base meshes are scaled up to the top of the grid, so
//! that the predictions' wide arithmetic (SPEC §7.4) is exercised.

#![allow(dead_code)]

use splitstream_decoder_core::handmade;
use splitstream_decoder_core::limits::{LEAF, NONE};
use splitstream_decoder_core::pipe::{InPlacePipe, PendingSplit, PendingSplits};
use splitstream_decoder_core::positions_first::{
    self, KIND_CONTEXT, KIND_ESCAPE, NewEdge, OFFSET_CONTEXT, PositionsFirst, Ties, Z_CONTEXT,
    choice_context, rank_context,
};
use splitstream_decoder_core::predict::wrap;
use splitstream_decoder_core::symbols::{deficit_of, split_valence_symbol};
use splitstream_decoder_core::writer::{
    ChunkCodec, LevelPayload, SeedPayload, StreamParams, SubstreamWriter, write_stream,
    write_stream_seeded,
};
use splitstream_decoder_core::{
    Decoder, DeficitContexts, Error, FANS_AHEAD_FROM_VERTICES, Framing, Inflater, Layout,
    MeshState, Plane, PlanePolicy, PositionMode, RecordOrder, RecordSource, Ring, Schedule,
    SplitFan, SplitRecord, Target, WingPolicy, arc_means, constrained_positions, context,
    height_prediction, predict, wing_order, workspace_len,
};

/// A byte string read as a sequence of choices; zeros once exhausted.
pub struct Choices<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Choices<'a> {
    pub fn new(data: &'a [u8]) -> Self {
        Choices { data, pos: 0 }
    }

    pub fn byte(&mut self) -> u8 {
        let b = self.data.get(self.pos).copied().unwrap_or(0);
        self.pos += 1;
        b
    }

    pub fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.byte(), self.byte()])
    }

    /// A value in `0 .. n` (0 when `n <= 1`).
    pub fn below(&mut self, n: usize) -> usize {
        if n <= 1 { 0 } else { self.u16() as usize % n }
    }

    pub fn exhausted(&self) -> bool {
        self.pos >= self.data.len()
    }
}

/// A base mesh: positions in a small grid and counter-clockwise triangles.
#[derive(Clone, Debug)]
pub struct BaseMesh {
    pub name: &'static str,
    pub positions: Vec<[u32; 3]>,
    pub triangles: Vec<[u32; 3]>,
}

pub fn tetrahedron() -> BaseMesh {
    BaseMesh {
        name: "tetrahedron",
        positions: handmade::TETRA_POSITIONS.to_vec(),
        triangles: handmade::TETRA_TRIANGLES.to_vec(),
    }
}

pub fn triangle() -> BaseMesh {
    BaseMesh {
        name: "triangle",
        positions: handmade::TRIANGLE_POSITIONS.to_vec(),
        triangles: vec![[0, 1, 2]],
    }
}

pub fn octahedron() -> BaseMesh {
    // 0 = +x, 1 = -x, 2 = +y, 3 = -y, 4 = +z, 5 = -z; the triangles in
    // octant order (not handmade::OCTA_TRIANGLES' order, which would change
    // the seed streams).
    let positions = handmade::OCTA_POSITIONS.to_vec();
    let mut triangles = Vec::new();
    for sx in [1i32, -1] {
        for sy in [1i32, -1] {
            for sz in [1i32, -1] {
                let x = if sx > 0 { 0 } else { 1 };
                let y = if sy > 0 { 2 } else { 3 };
                let z = if sz > 0 { 4 } else { 5 };
                triangles.push(if sx * sy * sz > 0 {
                    [x, y, z]
                } else {
                    [x, z, y]
                });
            }
        }
    }
    BaseMesh {
        name: "octahedron",
        positions,
        triangles,
    }
}

/// A `w` x `h` vertex grid in the z = 0 plane: a disk with boundary.
pub fn grid(w: u32, h: u32) -> BaseMesh {
    let mut positions = Vec::new();
    for j in 0..h {
        for i in 0..w {
            positions.push([10 * i, 10 * j, 0]);
        }
    }
    let mut triangles = Vec::new();
    for j in 0..h - 1 {
        for i in 0..w - 1 {
            let v00 = j * w + i;
            let v10 = v00 + 1;
            let v01 = v00 + w;
            let v11 = v01 + 1;
            triangles.push([v00, v10, v11]);
            triangles.push([v00, v11, v01]);
        }
    }
    BaseMesh {
        name: if w == 2 && h == 2 { "quad" } else { "grid" },
        positions,
        triangles,
    }
}

pub fn bases() -> Vec<BaseMesh> {
    vec![
        tetrahedron(),
        octahedron(),
        grid(4, 4),
        triangle(),
        grid(2, 2),
        grid(5, 3),
    ]
}

/// The base level (substreams 8..=10) of `base` with `deficits`.
pub fn base_level(base: &BaseMesh, deficits: &[u8]) -> LevelPayload {
    SeedPayload::new(&base.positions, &base.triangles, deficits).into_level(1.0)
}

/// A generated stream with what a decoder must see.
#[derive(Clone, Debug)]
pub struct Generated {
    pub base: &'static str,
    pub params: StreamParams,
    /// Levels before framing (base first), for structured mutation.
    pub levels: Vec<LevelPayload>,
    /// Whether level 0 carries the rounds of `levels[1]` after its seed mesh
    /// (SPEC §5.1, §6.3): framed by [`frame`].
    pub seeded: bool,
    pub stream: Vec<u8>,
    /// State hash after the base and after every round that succeeded.
    pub hashes: Vec<u64>,
    /// The error the replay hit (only with `allow_invalid`).
    pub error: Option<Error>,
    pub base_vertices: u32,
    pub splits: u32,
    pub triangles: Vec<[u32; 3]>,
    pub positions: Vec<[u32; 3]>,
}

/// Largest number of splits a generated stream holds.
pub const MAX_SPLITS: u32 = 120;

struct GenSource<'g, 'c> {
    choices: &'g mut Choices<'c>,
    flags: Vec<bool>,
    next_flag: usize,
    subs: &'g mut [SubstreamWriter],
    mode: PositionMode,
    plane: PlanePolicy,
    wings: WingPolicy,
    deficits: DeficitContexts,
    /// The level's record order (3.7), its tie rule (3.8) and the
    /// positions-first scratch.
    records: RecordOrder,
    ties: Ties,
    pf: PositionsFirst,
    bits: u8,
    allow_invalid: bool,
}

/// Whether `x` may still be a wing now: under split valences, with a
/// deficit left; under `every-vertex` (3.6) always.
fn wing_ok(state: &MeshState<'_>, x: u32) -> bool {
    x == NONE || state.schedule() == Schedule::EveryVertex || state.deficits()[x as usize] != 0
}

/// Wing pairs `(o, d)` that a valid record may name for this ring: both
/// eligible at round start (SPEC §7.4) and with a deficit left now.
fn wing_pairs(state: &MeshState<'_>, ring: &Ring) -> Vec<(usize, usize)> {
    let k = ring.len();
    let v = ring.vertices();
    let eligible = state.wing_candidates(ring);
    let ok = |i: usize| eligible.contains(i) && wing_ok(state, v[i]);
    let mut pairs = Vec::new();
    for o in 0..k {
        if !ok(o) {
            continue;
        }
        for d in 1..k - o {
            if ok(o + d) && !(v[o] == NONE && v[o + d] == NONE) {
                pairs.push((o, d));
            }
        }
    }
    pairs
}

/// Whether the ring has a wing pair that stays valid after `earlier`
/// splits of the same round (each decrements a wing deficit at most once).
fn has_robust_pair(state: &MeshState<'_>, ring: &Ring, earlier: usize) -> bool {
    let robust = |x: u32| {
        x == NONE || state.schedule() == Schedule::EveryVertex || {
            let d = state.deficits()[x as usize];
            d == LEAF || d as usize > earlier
        }
    };
    let v = ring.vertices();
    let k = v.len();
    (0..k).any(|o| {
        robust(v[o]) && (o + 1..k).any(|j| robust(v[j]) && !(v[o] == NONE && v[j] == NONE))
    })
}

fn pick_deficit(b: u8, valence: usize) -> u8 {
    let d = match b % 4 {
        0 => 0,
        1 => 1,
        2 => 2 + b / 64,
        _ => LEAF,
    };
    if d != LEAF && valence + d as usize > 255 {
        LEAF
    } else {
        d
    }
}

fn small(b: u8) -> i64 {
    ((b as i8) >> 2) as i64
}

impl GenSource<'_, '_> {
    /// The split valences of P and C for a ring of `k` entries whose wings
    /// are `d` apart (SPEC §7.4 step 2), chosen and written.
    fn split_valences(
        &mut self,
        state: &MeshState<'_>,
        k: usize,
        d: usize,
    ) -> Result<(u8, u8), Error> {
        let c = &mut *self.choices;
        let (valence_p, valence_c) = (d + 2, k - d + 2);
        Ok(if state.schedule() == Schedule::EveryVertex {
            // 3.6: no split valences coded; the bytes are the valences.
            (valence_p.min(255) as u8, valence_c.min(255) as u8)
        } else {
            let (deficit_p, deficit_c) = (
                pick_deficit(c.byte(), valence_p),
                pick_deficit(c.byte(), valence_c),
            );
            let (mut sp, mut sc) = (
                split_valence_symbol(deficit_p, valence_p),
                split_valence_symbol(deficit_c, valence_c),
            );
            if self.allow_invalid && c.byte() == 0xFE {
                sp = c.byte();
                sc = c.byte();
            }
            self.subs[3].byte_in(context::deficit_p(self.deficits, valence_p), sp);
            let deficit_p = deficit_of(sp, valence_p)?;
            self.subs[4].byte_in(context::deficit_c(self.deficits, deficit_p, valence_c), sc);
            let deficit_c = deficit_of(sc, valence_c)?;
            (deficit_p, deficit_c)
        })
    }

    /// A record read positions first (SPEC §7.4, format 3.7), chosen the
    /// way a decoder reads it: a kind, a lattice rank, an offset, wing
    /// ranks among the pairs, a z residual, each picked among the values
    /// the decoder accepts (the wings also among those with a deficit left
    /// now). `None` after writing an escape (or nothing, for a fan without
    /// free points): the caller writes the wings-first record.
    fn positions_first_record(
        &mut self,
        state: &MeshState<'_>,
        r: u32,
        ring: &Ring,
    ) -> Result<Option<SplitRecord>, Error> {
        let positions = state.positions();
        let parent = positions[r as usize];
        let Some(free) = self.pf.free_points(positions, parent, ring) else {
            return Ok(None);
        };
        let c = &mut *self.choices;
        let escape = |subs: &mut [SubstreamWriter]| {
            subs[6].byte_in(KIND_CONTEXT, KIND_ESCAPE);
            Ok(None)
        };
        if self.allow_invalid && c.byte() == 0xFB {
            // A kind above 2, or a lattice rank past the free points.
            if c.byte() & 1 == 0 {
                self.subs[6].byte_in(KIND_CONTEXT, 3 + c.byte() % 253);
                return Err(Error::InvalidPlacement);
            }
            self.subs[6].byte_in(KIND_CONTEXT, 0);
            self.subs[5].varint_in(rank_context(free), (free + c.below(4)) as u32);
            return Err(Error::PositionOutOfRange);
        }
        let kind = c.byte() % 3;
        if kind == KIND_ESCAPE {
            return escape(self.subs);
        }
        let midpoint = kind == 1;
        let j = c.below(free);
        let n = self.pf.point_at(j).expect("a rank below the free points");
        let t = if midpoint { c.byte() % 4 } else { 0 };
        let offset = [(t & 1) as i64, (t >> 1) as i64];
        let edge = if midpoint {
            NewEdge {
                a: [offset[0] - n[0], offset[1] - n[1]],
                b: n,
                midpoint,
            }
        } else {
            NewEdge {
                a: n,
                b: [0, 0],
                midpoint,
            }
        };
        // Every pair, as ranks, whose wings still have a deficit left.
        let eligible = state.wing_candidates(ring);
        let v = ring.vertices();
        self.pf.set_ties(self.ties);
        let nx = self.pf.order_xs(&eligible, &edge);
        let xs: Vec<usize> = (0..nx).filter_map(|u| self.pf.choice(nx, u)).collect();
        let mut pairs = Vec::new();
        for (u, &x) in xs.iter().enumerate() {
            let ny = self.pf.order_ys(&edge, x);
            for w in 0..ny {
                let y = self.pf.choice(ny, w).expect("a rank below the count");
                if wing_ok(state, v[x]) && wing_ok(state, v[y]) {
                    pairs.push((u, w, x, y, ny));
                }
            }
        }
        // The positions must stay on the grid.
        let limit = 1i64 << self.bits;
        let base = parent.map(|x| x as i64);
        let on_grid = |p: [i64; 2]| (0..2).all(|i| (0..limit).contains(&(base[i] + p[i])));
        if pairs.is_empty() || !on_grid(n) || !on_grid(edge.a) {
            return escape(self.subs);
        }
        let (u, w, x, y, ny) = pairs[c.below(pairs.len())];
        let dz = small(c.byte());
        self.subs[6].byte_in(KIND_CONTEXT, kind);
        self.subs[5].varint_in(rank_context(free), j as u32);
        if midpoint {
            self.subs[6].byte_in(OFFSET_CONTEXT, t);
        }
        self.subs[1].byte_in(choice_context(nx), u as u8);
        self.subs[2].byte_in(choice_context(ny), w as u8);
        let (o, d, code) = positions_first::wings_and_code(x, y, midpoint);
        let (deficit_p, deficit_c) = self.split_valences(state, ring.len(), d)?;
        let target = Target::of_code(code).expect("codes 0..=2");
        let xy = if midpoint {
            [2 * n[0] - offset[0], 2 * n[1] - offset[1]]
        } else {
            n
        };
        let h = height_prediction(positions, parent, ring, target, [xy[0], xy[1], 0]).unwrap_or(0);
        // z: a small step from R (or between P and C), or none when that
        // leaves the grid.
        let pick = |vz: i64| constrained_positions(parent, code, [xy[0], xy[1], vz]);
        let in_grid = |v: &[i64; 3]| v.iter().all(|&x| (0..limit).contains(&x));
        let vz = if let (p, q) = pick(dz)
            && in_grid(&p)
            && in_grid(&q)
        {
            dz
        } else {
            0
        };
        self.subs[5].signed_in(Z_CONTEXT, wrap(vz - h) as i32);
        let (p, q) = pick(wrap(h + wrap(vz - h)));
        if !in_grid(&p) || !in_grid(&q) {
            return Err(Error::PositionOutOfRange);
        }
        Ok(Some(SplitRecord {
            wing_offset: o as u8,
            wing_distance: d as u8,
            deficit_p,
            deficit_c,
            position_p: [p[0] as u32, p[1] as u32, p[2] as u32],
            position_c: [q[0] as u32, q[1] as u32, q[2] as u32],
        }))
    }
}

impl RecordSource for GenSource<'_, '_> {
    fn flag(&mut self, _state: &MeshState<'_>, _v: u32) -> Result<bool, Error> {
        let f = self.flags.get(self.next_flag).copied().unwrap_or(false);
        self.next_flag += 1;
        Ok(f)
    }

    fn record(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring) -> Result<SplitRecord, Error> {
        if self.records == RecordOrder::PositionsFirst
            && let Some(record) = self.positions_first_record(state, r, ring)?
        {
            return Ok(record);
        }
        let c = &mut *self.choices;
        let k = ring.len();
        let pairs = wing_pairs(state, ring);
        let eligible = state.wing_candidates(ring);
        let wing_context = context::wing(eligible.count());
        // The wings as ranks among the entries that may be wings (SPEC
        // §7.4); raw ranks name whatever pair they name, or none.
        // Under a near wing policy (3.2) the ranks count in the near order.
        let mut keys: wing_order::NearKeys = [0; 255];
        let m = wing_order::near_keys(state.positions(), ring, &eligible, self.wings, &mut keys);
        let keys = &keys[..m];
        let (o_rank, d_rank) = if self.allow_invalid && c.byte() == 0xFF {
            (c.byte(), c.byte())
        } else if pairs.is_empty() {
            (0, 0)
        } else {
            let (o, d) = pairs[c.below(pairs.len())];
            match self.wings {
                WingPolicy::Ranks => eligible.ranks(o, d),
                _ => wing_order::near_ranks(keys, k, o, d),
            }
            .expect("pairs are eligible")
        };
        self.subs[1].byte_in(wing_context, o_rank);
        self.subs[2].byte_in(wing_context, d_rank);
        let (o, d) = match self.wings {
            WingPolicy::Ranks => eligible.wings(o_rank, d_rank)?,
            _ => wing_order::near_wings(keys, k, o_rank, d_rank)?,
        };
        let (deficit_p, deficit_c) = self.split_valences(state, k, d)?;
        let c = &mut *self.choices;
        let limit = 1i64 << self.bits;
        let in_grid = |v: &[i64; 3]| v.iter().all(|&x| (0..limit).contains(&x));
        let clamp = |v: i64| v.clamp(0, limit - 1);
        let parent = state.positions()[r as usize];
        let parent64 = parent.map(|x| x as i64);
        let means = arc_means(state.positions(), parent, ring, o, d);
        let plane = Plane::new(self.plane, &means);
        let write = |w: &mut SubstreamWriter, coded: [i64; 3]| {
            for axis in plane.order() {
                w.signed_in(plane.context(axis), coded[axis] as i32);
            }
        };
        let sub = |a: [i64; 3], b: [i64; 3]| -> [i64; 3] { core::array::from_fn(|k| a[k] - b[k]) };
        let add = |a: [i64; 3], b: [i64; 3]| -> [i64; 3] { core::array::from_fn(|k| a[k] + b[k]) };
        // The positions are what the decoder computes from the values
        // written (SPEC §7.4); residuals wrap modulo 2^32, so every chosen
        // position of the grid can be coded.
        let (p, q) = match self.mode {
            PositionMode::Optimal => {
                let mut p = [0i64; 3];
                let mut q = [0i64; 3];
                for k in 0..3 {
                    p[k] = clamp(parent64[k] + small(c.byte()));
                    q[k] = clamp(p[k] + small(c.byte()));
                }
                let p_hat = predict(&means, self.mode, Target::P);
                let c_hat = predict(&means, self.mode, Target::C);
                let fan = SplitFan {
                    positions: state.positions(),
                    parent,
                    ring,
                };
                let policy = self.plane;
                let code = |target, hat, x| plane.encode(fan.residual(policy, target, hat, x));
                let cs = code(Target::P, p_hat, sub(p, parent64));
                let ct = code(Target::C, c_hat, sub(q, parent64));
                write(&mut self.subs[5], cs);
                write(&mut self.subs[6], ct);
                let decode =
                    |target, hat, coded| fan.vector(policy, target, hat, plane.decode(coded));
                (
                    add(parent64, decode(Target::P, p_hat, cs)),
                    add(parent64, decode(Target::C, c_hat, ct)),
                )
            }
            PositionMode::Constrained => {
                let mut code = c.byte() % 3;
                if self.allow_invalid && c.byte() == 0xFC {
                    code = 3 + c.byte() % 253;
                }
                self.subs[6].byte_in(context::placement(&means), code);
                let target = Target::of_code(code).ok_or(Error::InvalidPlacement)?;
                let mut edge = [0i64; 3];
                for e in &mut edge {
                    *e = small(c.byte());
                }
                let vector = |code: u8, e: &[i64; 3]| -> [i64; 3] {
                    match code {
                        // R sits on P: the vector is C - R.
                        0 => *e,
                        // R sits on C: the vector is P - R.
                        1 => e.map(|x| -x),
                        // R is the midpoint: the vector is the edge C - P.
                        _ => *e,
                    }
                };
                let (p, q) = constrained_positions(parent, code, vector(code, &edge));
                if !in_grid(&p) || !in_grid(&q) {
                    edge = [0; 3];
                }
                let prediction = predict(&means, self.mode, target);
                let fan = SplitFan {
                    positions: state.positions(),
                    parent,
                    ring,
                };
                let policy = self.plane;
                let coded =
                    plane.encode(fan.residual(policy, target, prediction, vector(code, &edge)));
                write(&mut self.subs[5], coded);
                let x = fan.vector(policy, target, prediction, plane.decode(coded));
                constrained_positions(parent, code, x)
            }
        };
        if !in_grid(&p) || !in_grid(&q) {
            return Err(Error::PositionOutOfRange);
        }
        Ok(SplitRecord {
            wing_offset: o as u8,
            wing_distance: d as u8,
            deficit_p,
            deficit_c,
            position_p: [p[0] as u32, p[1] as u32, p[2] as u32],
            position_c: [q[0] as u32, q[1] as u32, q[2] as u32],
        })
    }
}

/// Builds a stream from `choices` (any bytes; all zeros gives a deep stream).
pub fn generate(choices: &mut Choices<'_>, allow_invalid: bool) -> Generated {
    let bases = bases();
    let base_index = choices.below(bases.len());
    let base = bases[base_index].clone();
    // The schedule (SPEC §3.2) by the base's index, no choice of its own,
    // so that existing corpora keep their meaning: both schedules on every
    // kind of base over the corpus.
    let schedule = if base_index % 2 == 1 {
        Schedule::EveryVertex
    } else {
        Schedule::SplitValences
    };
    let position_mode = if choices.byte() & 1 == 0 {
        PositionMode::Optimal
    } else {
        PositionMode::Constrained
    };
    let bits = [8u8, 10, 16, 24, 31][choices.below(5)];
    // Deflate is rare: miniz_oxide's compressor state is large and is set
    // up per chunk, which would dominate the fuzzers' time.
    let codec = match choices.byte() % 8 {
        4 => ChunkCodec::RansAlways { lanes: 1 },
        5 => ChunkCodec::RansAlways {
            lanes: 1 + choices.byte() % 32,
        },
        6 => ChunkCodec::Deflate(1),
        7 => ChunkCodec::Deflate(6),
        _ => ChunkCodec::Stored,
    };
    let mut chunk_limit = [64u32, 1, 3, 7, 16, 255][choices.below(6)];
    if codec != ChunkCodec::Stored {
        // Deflating thousands of one-byte chunks only slows the fuzzer down.
        chunk_limit = chunk_limit.max(64);
    }
    let params = StreamParams {
        position_mode,
        bits,
        origin: [0.0; 3],
        scale: [1.0; 3],
        codec,
        chunk_limit,
        // rANS chunks as short as the byte-codec ones, or as long as the
        // reference encoder's (format 3.4), by the bit count's parity (no
        // choice of its own, so that existing corpora keep their meaning).
        rans_chunk_limit: if bits.is_multiple_of(2) {
            chunk_limit
        } else {
            1 << 14
        },
        schedule,
        // Adaptive tables where the writer finds them smaller (format 3.9).
        adaptive_tables: true,
        // The three framings (formats 3.11 and 3.12), by the bit count
        // again (no choice of its own, as above).
        framing: match (bits / 2) % 3 {
            0 => Framing::Compact,
            1 => Framing::Fixed,
            _ => Framing::CompactLevels,
        },
    };
    let refinement_levels = 4 - choices.below(4);
    // With 31 bits, the base mesh is scaled towards the top of the grid.
    let mut base = base;
    if bits == 31 {
        for p in &mut base.positions {
            *p = p.map(|x| (x << 25) + 1);
        }
    }
    let bv = base.positions.len() as u32;
    let bt = base.triangles.len() as u32;
    let deficits: Vec<u8> = (0..bv as usize)
        .map(|i| match (choices.byte() as usize + i) % 5 {
            0 | 3 => 0,
            1 => LEAF,
            2 => 2,
            _ => 1,
        })
        .collect();

    let vcap = bv + MAX_SPLITS;
    let tcap = bt + 2 * MAX_SPLITS;
    let layout = Layout::new(vcap, tcap, bv, bt, 1);
    let mut memory = vec![0u8; layout.bytes_unaligned() as usize];
    let (mem, _) = layout.carve(&mut memory).expect("layout fits");
    let mut state = MeshState::new(mem, bits, schedule);
    {
        let (positions, corners, defs) = state.base_arrays();
        positions[..bv as usize].copy_from_slice(&base.positions);
        for (i, t) in base.triangles.iter().enumerate() {
            corners[3 * i..3 * i + 3].copy_from_slice(t);
        }
        defs[..bv as usize].copy_from_slice(&deficits);
    }
    state
        .finish_base(bv, bt)
        .expect("seed base meshes are manifold");
    let mut hashes = vec![state.state_hash()];
    // Under `every-vertex` the seed codes no deficits (SPEC §6.3).
    let coded_deficits: &[u8] = match schedule {
        Schedule::SplitValences => &deficits,
        Schedule::EveryVertex => &[],
    };
    let mut levels = vec![base_level(&base, coded_deficits)];
    let mut ring = Ring::default();
    let mut error = None;

    'levels: for _ in 0..refinement_levels {
        let mut subs = vec![SubstreamWriter::default(); 7];
        let mut round_splits = Vec::new();
        let level_start_v = state.vertex_count();
        let plane = PlanePolicy::ALL[choices.below(PlanePolicy::ALL.len())];
        let wings = WingPolicy::ALL[choices.below(WingPolicy::ALL.len())];
        // `plain` or `valence` (the two choices of `split-valences`: the
        // corpora's bytes keep their meaning).
        let mut deficits = DeficitContexts::ALL[choices.below(2)];
        if schedule == Schedule::EveryVertex {
            // No split valences: byte 10 names the flags' contexts (SPEC
            // §5.1), `split-history` (3.10) on every other level, without a
            // choice of its own.
            deficits = if (levels.len() + base_index).is_multiple_of(2) {
                DeficitContexts::SplitHistory
            } else {
                DeficitContexts::Plain
            };
        }
        // SPEC §6.1 (3.10): the split-history bits start the level at 0.
        state.start_level(u32::MAX);
        // Positions first (3.7) on every other constrained level under
        // `height` (no choice of its own, so that existing corpora keep
        // their meaning); its escapes use the level's wing policy.
        let records = if position_mode == PositionMode::Constrained
            && plane == PlanePolicy::Height
            && (levels.len() + base_index) % 2 == 1
        {
            RecordOrder::PositionsFirst
        } else {
            RecordOrder::WingsFirst
        };
        // Its tie rule (3.8) by the level's index, again without a choice.
        let ties = if records == RecordOrder::PositionsFirst {
            Ties::ALL[levels.len() % Ties::ALL.len()]
        } else {
            Ties::Ring
        };
        let rounds = 3 - choices.below(3);
        for _ in 0..rounds {
            let n = state.vertex_count();
            let room = (vcap - n) as usize;
            // One flag per candidate not next to a vertex flagged before it
            // (those are inferred 0, SPEC §7.2).
            let mut decide = |force: Option<u32>, choices: &mut Choices<'_>| {
                let mut flags = Vec::new();
                let mut flagged: Vec<u32> = Vec::new();
                let mut first_eligible = None;
                for v in 0..n {
                    if schedule == Schedule::SplitValences && state.deficits()[v as usize] != 0 {
                        continue;
                    }
                    let ring_ok = state.ring(v, &mut ring).is_ok();
                    if ring_ok && ring.vertices().iter().any(|x| flagged.contains(x)) {
                        continue;
                    }
                    // Earlier splits of this round decrement each wing at most
                    // once: a pair of wings whose deficits exceed the number of
                    // splits flagged so far is still valid when `v` splits.
                    let eligible = flagged.len() < room
                        && ring_ok
                        && has_robust_pair(&state, &ring, flagged.len());
                    if eligible && first_eligible.is_none() {
                        first_eligible = Some(v);
                    }
                    let f = match force {
                        Some(forced) => v == forced,
                        None => {
                            let b = choices.byte();
                            if eligible {
                                b < 200
                            } else {
                                allow_invalid && b == 0xFD && flagged.len() < room
                            }
                        }
                    };
                    if f {
                        flagged.push(v);
                    }
                    let byte = state.deficits()[v as usize];
                    let split = state.split_in_level(v);
                    flags.push((f, context::flag(schedule, deficits, byte, split)));
                }
                (flags, flagged, first_eligible)
            };
            let (mut flags, mut flagged, first_eligible) = decide(None, choices);
            if flagged.is_empty() {
                match first_eligible {
                    Some(v) => (flags, flagged, _) = decide(Some(v), choices),
                    None => break,
                }
            }
            for &(f, context) in &flags {
                subs[0].bit_in(context, f);
            }
            let declared = flagged.len() as u32;
            round_splits.push(declared);
            let mut source = GenSource {
                choices: &mut *choices,
                flags: flags.iter().map(|&(f, _)| f).collect(),
                next_flag: 0,
                subs: &mut subs,
                mode: position_mode,
                plane,
                wings,
                deficits,
                records,
                ties,
                pf: PositionsFirst::default(),
                bits,
                allow_invalid,
            };
            match state.run_round(declared, &mut source, &mut ring) {
                Ok(_) => hashes.push(state.state_hash()),
                Err(e) => {
                    let done = state.vertex_count() - n;
                    let remaining = declared - done;
                    levels.push(LevelPayload {
                        round_splits,
                        plane,
                        wings,
                        deficits,
                        records,
                        ties,
                        substreams: subs,
                        vertex_count: n + declared,
                        triangle_count: state.triangle_count() + remaining,
                        geometric_error: 0.0,
                    });
                    error = Some(e);
                    break 'levels;
                }
            }
        }
        if round_splits.is_empty() {
            break;
        }
        debug_assert!(state.vertex_count() > level_start_v);
        levels.push(LevelPayload {
            round_splits,
            plane,
            wings,
            deficits,
            records,
            ties,
            substreams: subs,
            vertex_count: state.vertex_count(),
            triangle_count: state.triangle_count(),
            geometric_error: 0.0,
        });
    }
    // Level 0 may carry the first refinement level's rounds itself.
    let seeded = levels.len() >= 2 && choices.byte() & 1 == 1;
    let stream = frame(&params, &levels, seeded);
    Generated {
        base: base.name,
        params,
        levels,
        seeded,
        stream,
        hashes,
        error,
        base_vertices: bv,
        splits: state.vertex_count() - bv,
        triangles: state.triangles().to_vec(),
        positions: state.positions().to_vec(),
    }
}

/// Frames `levels` (`levels[0]` the seed mesh, substreams 8..=10): with
/// `seeded`, level 0 is the seed followed by the rounds of `levels[1]`.
pub fn frame(params: &StreamParams, levels: &[LevelPayload], seeded: bool) -> Vec<u8> {
    if seeded && levels.len() >= 2 {
        let seed = SeedPayload {
            vertices: levels[0].vertex_count,
            triangles: levels[0].triangle_count,
            substreams: levels[0].substreams.clone(),
        };
        write_stream_seeded(params, &seed, &levels[1..])
    } else {
        write_stream(params, levels)
    }
}

/// What a round-by-round decode of a stream saw.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Decoded {
    /// State hash after the base and after every round.
    pub hashes: Vec<u64>,
    /// Hash after each complete level.
    pub level_hashes: Vec<u64>,
    pub error: Option<Error>,
    pub levels: u16,
    pub levels_that_fit: u16,
    pub triangles: Vec<[u32; 3]>,
    pub positions: Vec<[u32; 3]>,
    pub deficits: Vec<u8>,
}

impl Decoded {
    /// Whether this decode, made another way (`how`), matches `d`: the
    /// same hashes after every round, the same error, and with `mesh` the
    /// same final mesh.
    fn same_as(&self, d: &Decoded, mesh: bool, how: &str) -> Result<(), String> {
        let same_mesh = !mesh
            || (self.triangles == d.triangles
                && self.positions == d.positions
                && self.deficits == d.deficits);
        if self.hashes != d.hashes || self.error != d.error || !same_mesh {
            return Err(format!(
                "{how} changed the decode: {} hashes and error {:?}, against {} and {:?}",
                self.hashes.len(),
                self.error,
                d.hashes.len(),
                d.error
            ));
        }
        Ok(())
    }

    /// The outcome and the decoder's final mesh.
    fn end(&mut self, result: Result<(), Error>, decoder: &Decoder<'_, '_>) {
        self.error = result.err();
        self.levels = decoder.levels_done();
        self.triangles = decoder.triangles().to_vec();
        self.positions = decoder.positions().to_vec();
        self.deficits = decoder.state().deficits().to_vec();
    }
}

/// Decodes `stream` round by round with the no-alloc API into `workspace`.
pub fn decode_rounds(stream: &[u8], workspace: &mut [u8], inflater: &mut Inflater) -> Decoded {
    decode_rounds_with(stream, workspace, inflater, FANS_AHEAD_FROM_VERTICES)
}

/// [`decode_rounds`] with fans walked ahead from `fans_ahead_from` vertices
/// on (a speed setting that must not change any result).
pub fn decode_rounds_with(
    stream: &[u8],
    workspace: &mut [u8],
    inflater: &mut Inflater,
    fans_ahead_from: u32,
) -> Decoded {
    let mut out = Decoded::default();
    let mut decoder = match Decoder::new(stream, workspace, inflater) {
        Ok(d) => d,
        Err(e) => {
            out.error = Some(e);
            return out;
        }
    };
    out.levels_that_fit = decoder.levels_that_fit();
    decoder.set_fans_ahead_from(fans_ahead_from);
    let result = (|| -> Result<(), Error> {
        while let Some(k) = decoder.next_level() {
            let range = decoder.level_range(k);
            let bytes = stream
                .get(range.start as usize..range.end as usize)
                .ok_or(Error::Truncated)?;
            let mut level = decoder.begin_level(k, bytes)?;
            if k == 0 {
                out.hashes.push(level.state().state_hash());
            }
            while level.next_round()?.is_some() {
                out.hashes.push(level.state().state_hash());
            }
            out.level_hashes.push(decoder.state_hash());
        }
        Ok(())
    })();
    out.end(result, &decoder);
    out
}

/// Decodes with a workspace of exactly the needed size.
pub fn decode_full(stream: &[u8]) -> Decoded {
    decode_full_with(stream, FANS_AHEAD_FROM_VERTICES)
}

/// [`decode_full`] with fans walked ahead from `fans_ahead_from` vertices on.
pub fn decode_full_with(stream: &[u8], fans_ahead_from: u32) -> Decoded {
    let len = workspace_len(stream).unwrap_or(0).min(64 << 20);
    let mut ws = vec![0u8; len];
    let mut inflater = Box::new(Inflater::new());
    decode_rounds_with(stream, &mut ws, &mut inflater, fans_ahead_from)
}

/// Checks that walking fans ahead in every round (`set_fans_ahead_from(0)`)
/// decodes `stream` exactly as `d`, the default decode, did: the same
/// hashes after every round, the same error, the same final mesh.
pub fn check_fans_ahead(stream: &[u8], d: &Decoded) -> Result<(), String> {
    decode_full_with(stream, 0).same_as(d, true, "walking fans ahead")
}

/// Checks that decoding with the records read through a pipe
/// (`MeshState::run_round_piped`, the two-thread decoder's rounds run on
/// one thread) decodes `stream` as `d`, the default decode, did: the same
/// hashes after every round, the same error, and without an error the same
/// final mesh; with records coming back at once or only when waited for,
/// and as few as one split pending.
pub fn check_piped(stream: &[u8], d: &Decoded) -> Result<(), String> {
    for (lag, pending) in [(false, 96), (true, 1), (true, 5)] {
        // After an error only the hashes reported and the error count
        // (SPEC §10.2): the failing round's splits still pending are not
        // applied, where the one-thread rounds applied them.
        let what = format!("piped records (lag {lag}, {pending} pending)");
        decode_piped(stream, lag, pending).same_as(d, d.error.is_none(), &what)?;
    }
    Ok(())
}

/// Decodes `stream` round by round with each level's records split off and
/// read through an [`InPlacePipe`].
pub fn decode_piped(stream: &[u8], lag: bool, pending: usize) -> Decoded {
    let mut out = Decoded::default();
    let len = workspace_len(stream).unwrap_or(0).min(64 << 20);
    let mut ws = vec![0u8; len];
    let mut inflater = Box::new(Inflater::new());
    let mut records_inflater = Box::new(Inflater::new());
    let mut slots = vec![PendingSplit::default(); pending];
    let mut decoder = match Decoder::new(stream, &mut ws, &mut inflater) {
        Ok(d) => d,
        Err(e) => {
            out.error = Some(e);
            return out;
        }
    };
    out.levels_that_fit = decoder.levels_that_fit();
    let mut mirror = vec![[0u32; 3]; decoder.state().vertex_capacity() as usize];
    let result = (|| -> Result<(), Error> {
        while let Some(k) = decoder.next_level() {
            let range = decoder.level_range(k);
            let bytes = stream
                .get(range.start as usize..range.end as usize)
                .ok_or(Error::Truncated)?;
            let mut level = decoder.begin_level(k, bytes)?;
            if k == 0 {
                out.hashes.push(level.state().state_hash());
            }
            let mut half = level.split_records(&mut records_inflater, &mut mirror)?;
            let mut pipe = InPlacePipe::new(&mut half, lag);
            let mut queue = PendingSplits::new(&mut slots).ok_or(Error::CapacityExceeded)?;
            let rounds = (|| {
                while level.next_round_piped(&mut pipe, &mut queue)?.is_some() {
                    out.hashes.push(level.state().state_hash());
                }
                Ok(())
            })();
            drop(pipe);
            level.join_records(half);
            rounds?;
            // The rounds are done: this ends the level; a round left over
            // would be a bug of the piped path.
            if level.next_round()?.is_some() {
                return Err(Error::Poisoned);
            }
            out.level_hashes.push(decoder.state_hash());
        }
        Ok(())
    })();
    out.end(result, &decoder);
    out
}

/// Checks a decode against the replay that generated the stream.
pub fn check_against(g: &Generated, d: &Decoded) -> Result<(), String> {
    if d.hashes != g.hashes {
        return Err(format!(
            "hashes differ: decoder {} rounds, generator {} (error {:?} vs {:?})",
            d.hashes.len(),
            g.hashes.len(),
            d.error,
            g.error
        ));
    }
    match (g.error, d.error) {
        (None, None) => {
            if d.triangles != g.triangles || d.positions != g.positions {
                return Err("final mesh differs".into());
            }
            Ok(())
        }
        (Some(a), Some(b)) if a == b => Ok(()),
        (a, b) => Err(format!("generator error {a:?}, decoder error {b:?}")),
    }
}

/// Structured mutation of a generated stream's content *before* framing,
/// so that every checksum stays valid: substream bytes, bits, split counts,
/// level counts and stream parameters. `ops` is read as a list of
/// operations until exhausted (at most 32).
pub fn mutate_levels(g: &Generated, ops: &mut Choices<'_>) -> (StreamParams, Vec<LevelPayload>) {
    let mut params = g.params;
    // Framing is redone per input: stored chunks keep it cheap (an op below
    // can still select deflate).
    params.codec = ChunkCodec::Stored;
    let mut subs: Vec<Vec<Vec<u8>>> = g
        .levels
        .iter()
        .map(|l| l.substreams.iter().map(|s| s.as_bytes().to_vec()).collect())
        .collect();
    let mut meta: Vec<(Vec<u32>, u32, u32, PlanePolicy, WingPolicy, DeficitContexts)> = g
        .levels
        .iter()
        .map(|l| {
            (
                l.round_splits.clone(),
                l.vertex_count,
                l.triangle_count,
                l.plane,
                l.wings,
                l.deficits,
            )
        })
        .collect();
    let mut records: Vec<(RecordOrder, Ties)> =
        g.levels.iter().map(|l| (l.records, l.ties)).collect();
    let mut n_ops = 0;
    while !ops.exhausted() && n_ops < 32 {
        n_ops += 1;
        let op = ops.byte() % 13;
        let l = ops.below(subs.len());
        let s = ops.below(subs[l].len());
        let bytes = &mut subs[l][s];
        match op {
            0 => {
                // Flip one bit (flags, config bits, varint continuation bits).
                let at = ops.below(bytes.len());
                let bit = ops.byte() % 8;
                if let Some(b) = bytes.get_mut(at) {
                    *b ^= 1 << bit;
                }
            }
            1 => {
                let at = ops.below(bytes.len());
                let v = ops.byte();
                if let Some(b) = bytes.get_mut(at) {
                    *b = v;
                }
            }
            2 => {
                let at = ops.below(bytes.len() + 1);
                let v = ops.byte();
                bytes.insert(at.min(bytes.len()), v);
            }
            3 => {
                let at = ops.below(bytes.len());
                if at < bytes.len() {
                    bytes.remove(at);
                }
            }
            4 => {
                let at = ops.below(bytes.len() + 1);
                bytes.truncate(at);
            }
            5 => {
                // Add a small delta to a byte (offsets, distances, deficits).
                let at = ops.below(bytes.len());
                let delta = ops.byte() as i8 % 4;
                if let Some(b) = bytes.get_mut(at) {
                    *b = b.wrapping_add(delta as u8);
                }
            }
            6 => {
                let (splits, _, _, _, _, _) = &mut meta[l];
                let r = ops.below(splits.len());
                let delta = (ops.byte() as i8 % 3) as i32;
                if let Some(x) = splits.get_mut(r) {
                    *x = (*x as i32 + delta).max(0) as u32;
                }
            }
            7 => {
                let (_, v, t, _, _, _) = &mut meta[l];
                let dv = (ops.byte() as i8 % 3) as i64;
                let dt = (ops.byte() as i8 % 3) as i64;
                *v = (*v as i64 + dv).clamp(0, u32::MAX as i64) as u32;
                *t = (*t as i64 + dt).clamp(0, u32::MAX as i64) as u32;
            }
            8 => {
                let (splits, _, _, _, _, _) = &mut meta[l];
                if ops.byte() & 1 == 0 {
                    splits.pop();
                } else {
                    splits.push(1);
                }
            }
            9 => match ops.byte() % 4 {
                0 => {
                    params.position_mode = match params.position_mode {
                        PositionMode::Optimal => PositionMode::Constrained,
                        PositionMode::Constrained => PositionMode::Optimal,
                    }
                }
                1 => params.bits = 1 + ops.byte() % 31,
                2 => {
                    params.chunk_limit = 1 + ops.byte() as u32;
                    params.rans_chunk_limit = 1 + ops.byte() as u32 * 64;
                }
                _ => {
                    params.codec = match ops.byte() % 3 {
                        0 => ChunkCodec::Stored,
                        1 => ChunkCodec::Deflate(1),
                        _ => ChunkCodec::Deflate(9),
                    };
                    if params.codec != ChunkCodec::Stored {
                        params.chunk_limit = params.chunk_limit.max(16);
                    }
                }
            },
            10 => {
                // Append a run of one byte (a long varint, a run of flags).
                let v = ops.byte();
                let n = ops.byte() % 16;
                bytes.extend(core::iter::repeat_n(v, n as usize));
            }
            11 => {
                // Another plane or wing policy, other deficit contexts or
                // the other record order, for the level (SPEC §5.1,
                // §5.5.5, §7.4).
                match ops.byte() % 4 {
                    0 => meta[l].3 = PlanePolicy::ALL[ops.below(PlanePolicy::ALL.len())],
                    1 => meta[l].4 = WingPolicy::ALL[ops.below(WingPolicy::ALL.len())],
                    2 => meta[l].5 = DeficitContexts::ALL[ops.below(DeficitContexts::ALL.len())],
                    _ => {
                        // The next of wings first and positions first
                        // under each tie rule.
                        records[l] = match records[l] {
                            (RecordOrder::WingsFirst, _) => {
                                (RecordOrder::PositionsFirst, Ties::Ring)
                            }
                            (RecordOrder::PositionsFirst, Ties::Ring) => {
                                (RecordOrder::PositionsFirst, Ties::Rising)
                            }
                            (RecordOrder::PositionsFirst, Ties::Rising) => {
                                (RecordOrder::PositionsFirst, Ties::Falling)
                            }
                            (RecordOrder::PositionsFirst, Ties::Falling) => {
                                (RecordOrder::WingsFirst, Ties::Ring)
                            }
                        }
                    }
                }
            }
            _ => {
                // Drop the last level (never the base).
                if subs.len() > 1 && ops.byte() & 1 == 0 {
                    subs.pop();
                    meta.pop();
                    records.pop();
                }
            }
        }
    }
    let levels = subs
        .into_iter()
        .zip(meta)
        .zip(records)
        .map(
            |(
                (s, (round_splits, vertex_count, triangle_count, plane, wings, deficits)),
                (records, ties),
            )| {
                LevelPayload {
                    round_splits,
                    plane,
                    wings,
                    deficits,
                    records,
                    ties,
                    substreams: s
                        .into_iter()
                        .map(|b| {
                            let mut w = SubstreamWriter::default();
                            for x in b {
                                w.byte(x);
                            }
                            w
                        })
                        .collect(),
                    vertex_count,
                    triangle_count,
                    geometric_error: 0.0,
                }
            },
        )
        .collect();
    (params, levels)
}

/// Deterministic pseudo-random bytes (xorshift64*), for seed streams.
pub fn pseudo_random_bytes(seed: u64, len: usize) -> Vec<u8> {
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..len)
        .map(|_| {
            x ^= x >> 12;
            x ^= x << 25;
            x ^= x >> 27;
            (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 56) as u8
        })
        .collect()
}

/// The fixed seed streams of `decode_mutated`: every base mesh with all-zero
/// choices (deep, valid) and a few pseudo-random choice strings.
pub fn seed_generated() -> Vec<Generated> {
    let mut out = Vec::new();
    for b in 0..bases().len() as u8 {
        // below(n) reads a little-endian u16: base index b.
        let choices = [b, 0];
        out.push(generate(&mut Choices::new(&choices), false));
    }
    for seed in 1..=10u64 {
        let bytes = pseudo_random_bytes(seed, 4096);
        out.push(generate(&mut Choices::new(&bytes), false));
    }
    out
}
