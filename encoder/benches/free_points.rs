//! Criterion benchmark of `free_points` (SPEC §7.4 "Positions first"), the
//! largest single cost of decoding a level read positions first: the
//! fans of every split of the positions-first levels of a synthetic
//! terrain (`splitstream demo`'s, constrained mode) are gathered once by
//! decoding it, then `PositionsFirst::free_points` runs over all of them,
//! in decoding order, so its branches see the real mix of fan shapes,
//! each followed by `point_at` of the rank the stream names. The
//! fans are copied out of the mesh (a fan's ring entries renumbered from
//! 1, R as 0) and stay in cache far better than the mesh does: the figure
//! is the function's own work, without the cache misses of a decode.
//! The stream is encoded once and kept in target/bench-data/.
//!
//! A second function times the wing choice of the same records: with the
//! new edge known, `order_xs` and `choice` of the wing x the stream names,
//! then `order_ys` and `choice` of wing y (the splits named positions
//! first; escapes are left out).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use splitstream_decoder_core::limits::NONE;
use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_decoder_core::positions_first::{NewEdge, PositionsFirst};
use splitstream_decoder_core::{
    MeshState, RecordOrder, Ring, SplitObserver, SplitRecord, WingCandidates,
};
use splitstream_encoder::emit::EncodeOptions;

const SIDE: usize = 512;

mod common;

/// Every split's fan, flattened: R's position then its ring entries'
/// (the ghost as `None`).
#[derive(Default)]
struct Fans {
    positions: Vec<[u32; 3]>,
    /// Per fan: where its positions start, its ring (local ids) and the
    /// rank of its new vertex among its free points (0 where it has none).
    starts: Vec<usize>,
    rings: Vec<Vec<u32>>,
    ranks: Vec<usize>,
    /// Per fan named positions first: its index, new edge and the ranks
    /// `u`, `v` of its wings among the choices (SPEC §7.4).
    wings: Vec<(usize, NewEdge, usize, usize)>,
    pf: PositionsFirst,
}

/// The new edge and the wings `(x, y)` of a split read positions first
/// (SPEC §7.4; the encoder's `emit/positions_first.rs` backwards): code 0
/// when P stays on R, 1 when C does, else a midpoint.
fn new_edge(parent: [u32; 3], record: &SplitRecord) -> (NewEdge, (usize, usize)) {
    let rel = |v: [u32; 3]| [0, 1].map(|a| v[a] as i64 - parent[a] as i64);
    let (o, b) = (
        record.wing_offset as usize,
        (record.wing_offset + record.wing_distance) as usize,
    );
    let (p, c) = (rel(record.position_p), rel(record.position_c));
    if p == [0, 0] {
        let a = c;
        (
            NewEdge {
                a,
                b: p,
                midpoint: false,
            },
            (b, o),
        )
    } else if c == [0, 0] {
        (
            NewEdge {
                a: p,
                b: c,
                midpoint: false,
            },
            (o, b),
        )
    } else {
        (
            NewEdge {
                a: p,
                b: c,
                midpoint: true,
            },
            (o, b),
        )
    }
}

impl SplitObserver for Fans {
    fn record(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring, record: &SplitRecord) {
        let all = state.positions();
        self.starts.push(self.positions.len());
        self.positions.push(all[r as usize]);
        let mut local = Vec::with_capacity(ring.len());
        for &v in ring.vertices() {
            if v == NONE {
                local.push(NONE);
            } else {
                local.push((self.positions.len() - self.starts.last().unwrap()) as u32);
                self.positions.push(all[v as usize]);
            }
        }
        // The new vertex: P or C, whichever is a free point (SPEC §7.4).
        let parent = all[r as usize];
        let rank = [record.position_c, record.position_p]
            .into_iter()
            .find_map(|v| {
                self.pf.free_points(all, parent, ring)?;
                let relative = [0, 1].map(|a| v[a] as i64 - parent[a] as i64);
                self.pf.rank_of(relative)
            })
            .unwrap_or(0);
        self.ranks.push(rank);
        self.rings.push(local);
        // The wing ranks, where the split is named positions first.
        let (edge, (x, y)) = new_edge(parent, record);
        let eligible = WingCandidates::all(ring.len());
        if self.pf.free_points(all, parent, ring).is_some() {
            let xs = self.pf.order_xs(&eligible, &edge);
            if let Some(u) = self.pf.rank_of_choice(xs, x) {
                let ys = self.pf.order_ys(&edge, x);
                if let Some(v) = self.pf.rank_of_choice(ys, y) {
                    self.wings.push((self.rings.len() - 1, edge, u, v));
                }
            }
        }
    }
}

fn gather(stream: &[u8]) -> Fans {
    let mut ws = OwnedWorkspace::for_stream(stream).expect("valid stream");
    let mut decoder = ws.decoder(stream).expect("valid stream");
    let mut fans = Fans::default();
    while let Some(k) = decoder.next_level() {
        let bytes = decoder.level_bytes(k, stream).expect("level");
        let order = decoder
            .level_table()
            .level_header(k, bytes, decoder.header().level_rules())
            .expect("level header")
            .record_order;
        let mut level = decoder.begin_level(k, bytes).expect("level");
        if order == RecordOrder::PositionsFirst {
            while level
                .next_round_observed(&mut fans)
                .expect("decodes")
                .is_some()
            {}
        } else {
            while level.next_round().expect("decodes").is_some() {}
        }
    }
    fans
}

fn free_points(c: &mut Criterion) {
    let stream = common::terrain_stream(SIDE, "constrained", &EncodeOptions::default());
    let fans = gather(&stream);
    assert!(
        !fans.rings.is_empty(),
        "the terrain has positions-first levels"
    );
    let mut ranks = [0usize; 6];
    for &r in &fans.ranks {
        ranks[r.min(5)] += 1;
    }
    eprintln!(
        "{} fans; by rank 0, 1, 2, 3, 4, 5 or more: {ranks:?}",
        fans.rings.len()
    );
    let (mut u0, mut v0) = (0, 0);
    for &(_, _, u, v) in &fans.wings {
        u0 += usize::from(u == 0);
        v0 += usize::from(v == 0);
    }
    eprintln!(
        "{} fans named positions first; wing x first choice {u0}, wing y first choice {v0}",
        fans.wings.len()
    );
    let mut group = c.benchmark_group("positions-first");
    group.throughput(Throughput::Elements(fans.rings.len() as u64));
    let mut pf = PositionsFirst::default();
    let mut ring = Ring::default();
    let name = format!("free_points and point_at, fans of terrain {SIDE}x{SIDE}");
    group.bench_function(name, |b| {
        b.iter(|| {
            let mut total = 0i64;
            for (i, local) in fans.rings.iter().enumerate() {
                let start = fans.starts[i];
                let positions = &fans.positions[start..start + local.len() + 1];
                ring.set_vertices(local);
                if pf.free_points(positions, positions[0], &ring).is_some() {
                    total += pf.point_at(fans.ranks[i]).map_or(0, |p| p[0]);
                }
            }
            total
        })
    });
    let name = format!(
        "wing choice, {} fans of terrain {SIDE}x{SIDE}",
        fans.wings.len()
    );
    group.throughput(Throughput::Elements(fans.wings.len() as u64));
    group.bench_function(name, |b| {
        b.iter(|| {
            let mut total = 0usize;
            for &(i, edge, u, v) in &fans.wings {
                let local = &fans.rings[i];
                let start = fans.starts[i];
                let positions = &fans.positions[start..start + local.len() + 1];
                ring.set_vertices(local);
                // Sets the ring's entries (the part of `free_points` that
                // the wings read) in one pass: the count stays out of it.
                pf.set_ring(positions, positions[0], &ring);
                let eligible = WingCandidates::all(local.len());
                let xs = pf.order_xs(&eligible, &edge);
                let x = pf.choice(xs, u).unwrap_or(0);
                let ys = pf.order_ys(&edge, x);
                total += pf.choice(ys, v).unwrap_or(0);
            }
            total
        })
    });
    group.finish();
}

criterion_group!(benches, free_points);
criterion_main!(benches);
