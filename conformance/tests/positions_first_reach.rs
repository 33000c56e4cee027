//! The valid vectors reach the rules of SPEC §7.4 ("Positions first") that
//! few fans meet, so a decoder that gets one of them wrong fails a vector:
//!
//! * the point cap: a fan whose bounding box holds more than 1,024
//!   lattice points escapes before any kind is read;
//! * `pair` under the schedule `split-valences`: ring entries that are
//!   candidates of the round are not eligible as wings;
//! * a kind-1 record whose P falls on R in x and y: R sat on the floor
//!   midpoint of an edge one lattice step long in +x or +y, so
//!   `P = 2R − C + t` is R itself. A SPEC note once said no pair could
//!   exist then; these records are common (1,453 of the Jacksboro DEM's
//!   120,549 records read positions first).
//! * a kind-1 record whose P falls on a ring entry in x and y, with that
//!   entry's wedges in C's arc: the reference encoder has never written
//!   one, so a hand-made vector holds it (`positions-first-p-on-ring-entry`).
//!
//! A generator change that drops one of them fails this test.

use splitstream_conformance::manifest::{Manifest, default_vector_dir};
use splitstream_decoder_core::limits::NONE;
use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_decoder_core::positions_first::{NewEdge, PositionsFirst};
use splitstream_decoder_core::{MeshState, RecordOrder, Ring, SplitObserver, SplitRecord};

/// How many records of the levels read positions first reach each rule.
#[derive(Default)]
struct Reached {
    positions_first: bool,
    capped: usize,
    not_eligible: usize,
    kind1_p_on_r: usize,
    kind1_p_on_entry: usize,
    pf: PositionsFirst,
}

impl Reached {
    /// Whether the reference encoder can name the split as a kind-1 record
    /// (SPEC §7.4 `read_record_pf`, backwards): C among the free points, P
    /// at `2R − C + t`, and the wings among `pair`'s choices. It writes
    /// kind 1 exactly when it can, and an escape otherwise.
    fn names_midpoint(
        &mut self,
        state: &MeshState<'_>,
        parent: [u32; 3],
        ring: &Ring,
        rec: &SplitRecord,
    ) -> bool {
        let rel = |v: [u32; 3]| [0, 1].map(|a| v[a] as i64 - parent[a] as i64);
        let (a, b) = (rel(rec.position_p), rel(rec.position_c));
        let t = [a[0] + b[0], a[1] + b[1]];
        if !t.iter().all(|t| (0..=1).contains(t)) || self.pf.rank_of(b).is_none() {
            return false;
        }
        let edge = NewEdge {
            a,
            b,
            midpoint: true,
        };
        let (x, y) = (
            rec.wing_offset as usize,
            (rec.wing_offset + rec.wing_distance) as usize,
        );
        let xs = self.pf.order_xs(&state.wing_candidates(ring), &edge);
        if self.pf.rank_of_choice(xs, x).is_none() {
            return false;
        }
        let ys = self.pf.order_ys(&edge, x);
        self.pf.rank_of_choice(ys, y).is_some()
    }
}

impl SplitObserver for Reached {
    fn record(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring, rec: &SplitRecord) {
        if !self.positions_first {
            return;
        }
        let positions = state.positions();
        let parent = positions[r as usize];
        if !self.pf.set_ring(positions, parent, ring) {
            self.capped += 1;
            return;
        }
        if self.pf.free_points(positions, parent, ring).is_none() {
            return;
        }
        if state.wing_candidates(ring).count() < ring.len() {
            self.not_eligible += 1;
        }
        let (p, c) = (rec.position_p, rec.position_c);
        let midpoint: [u32; 3] =
            core::array::from_fn(|a| (p[a] as i64 + ((c[a] as i64 - p[a] as i64) >> 1)) as u32);
        let on_r = p[..2] == parent[..2] && p != parent && c != parent && midpoint == parent;
        let on_entry = ring
            .vertices()
            .iter()
            .any(|&e| e != NONE && positions[e as usize][..2] == p[..2]);
        if (on_r || on_entry) && midpoint == parent && self.names_midpoint(state, parent, ring, rec)
        {
            if on_r {
                self.kind1_p_on_r += 1;
            } else {
                self.kind1_p_on_entry += 1;
            }
        }
    }
}

/// Decodes `stream` with `reached` watching the levels read positions first.
fn watch(stream: &[u8], reached: &mut Reached) {
    let mut workspace = OwnedWorkspace::for_stream(stream).expect("valid vector");
    let mut decoder = workspace.decoder(stream).expect("valid vector");
    while let Some(k) = decoder.next_level() {
        let bytes = decoder.level_bytes(k, stream).expect("level");
        let header = decoder
            .level_table()
            .level_header(k, bytes, decoder.header().level_rules())
            .expect("level header");
        reached.positions_first = header.record_order == RecordOrder::PositionsFirst;
        let mut level = decoder.begin_level(k, bytes).expect("level");
        while level.next_round_observed(reached).expect("round").is_some() {}
    }
}

#[test]
fn positions_first_vectors_reach_the_rare_rules() {
    let manifest = Manifest::load(&default_vector_dir().join("manifest.json")).expect("manifest");
    let mut reached = Reached::default();
    let mut watched = 0;
    for v in manifest.vectors.iter().filter(|v| v.valid) {
        if !v.features.iter().any(|f| f == "positions-first") {
            continue;
        }
        let stream = std::fs::read(default_vector_dir().join(&v.file)).expect("vector");
        watch(&stream, &mut reached);
        watched += 1;
    }
    assert!(watched > 0, "no valid positions-first vector");
    assert!(reached.capped > 0, "no fan over the point cap");
    assert!(
        reached.not_eligible > 0,
        "no fan with an entry `pair` may not take"
    );
    assert!(reached.kind1_p_on_r > 0, "no kind-1 record with P on R");
    assert!(
        reached.kind1_p_on_entry > 0,
        "no kind-1 record with P on a ring entry"
    );
}
