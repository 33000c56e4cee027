//! Writes every split record of a stream, with what a decoder knows when it
//! reads it, as tab-separated text: the raw material for measuring a new
//! context or transform before building it (SPEC §5.5.5, §7.4).
//!
//! ```text
//! cargo run --release -p splitstream-decoder-core --features alloc --example split_fields -- IN.sps OUT.tsv
//! ```
//!
//! One line per split, in decoding order, after a header line naming the
//! columns: the level and round; the ring length `k` and the number `m` of
//! entries that may be wings; the wings' ring offset `o` and distance `d`;
//! P's and C's valences right after the split and their split-valence
//! symbols (0 for a leaf, otherwise the split valence − 2); per arc (P's
//! closed arc from wing a to wing b, C's from b round to a) how many of its
//! vertices are leaves, the sum of the others' deficits, and whether it
//! holds the ghost; the squared length of the edge PC; whether R was
//! created in this level; where R lay (0 at P, 1 at C, 2 at their midpoint,
//! 3 elsewhere: optimal mode) and that code's context (SPEC §5.5.5); the
//! two wing ranks the stream coded (SPEC §7.4: in ring order, or in the
//! near order of the level's wing policy).
//! Deficits are the live ones, as the record sees them (earlier splits of
//! the round may have decremented a wing's).
//!
//! It decodes with decoder-core's own `Decoder`, whose
//! `LevelDecoder::next_round_observed` shows it each record before the
//! split is applied.

use std::io::Write;

use splitstream_decoder_core::limits::{LEAF, MAX_SPLIT_VALENCE, NONE};
use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_decoder_core::wing_order::{NearKeys, WingPolicy, near_keys, near_ranks};
use splitstream_decoder_core::{
    Error, MeshState, Ring, SplitObserver, SplitRecord, arc_means, context,
};

const COLUMNS: &str = "level\tround\tk\tm\to\td\tvalence_p\tvalence_c\tsymbol_p\tsymbol_c\t\
leaves_p\tdeficits_p\tghost_p\tleaves_c\tdeficits_c\tghost_c\tedge2\tnew\tplacement\t\
placement_context\trank_o\trank_d";

/// Writes one line per split record the decoder shows it.
struct Fields<'a> {
    out: &'a mut dyn Write,
    level: u16,
    round: u32,
    /// Vertices below this index existed when the level started.
    level_start: u32,
    /// The level's wing policy (SPEC §5.1), which names the wings' ranks.
    wings: WingPolicy,
    /// The first write error, reported after the round.
    failed: Option<std::io::Error>,
}

/// What P's or C's arc holds: leaves, the sum of the other deficits, the ghost.
fn arc(state: &MeshState<'_>, vertices: impl Iterator<Item = u32>) -> (u32, u32, u8) {
    let (mut leaves, mut deficits, mut ghost) = (0, 0, 0);
    for v in vertices {
        match state.deficits().get(v as usize) {
            _ if v == NONE => ghost = 1,
            Some(&LEAF) => leaves += 1,
            Some(&d) => deficits += d as u32,
            None => {}
        }
    }
    (leaves, deficits, ghost)
}

impl SplitObserver for Fields<'_> {
    fn record(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring, rec: &SplitRecord) {
        let (k, o, d) = (
            ring.len(),
            rec.wing_offset as usize,
            rec.wing_distance as usize,
        );
        let (valence_p, valence_c) = (d + 2, k - d + 2);
        let symbol = |deficit: u8, valence: usize| {
            if deficit == LEAF {
                0
            } else {
                deficit as usize + valence - 2
            }
        };
        let v = ring.vertices();
        let arc_p = arc(state, v[o..=o + d].iter().copied());
        let arc_c = arc(state, v[o + d..].iter().chain(&v[..=o]).copied());
        let parent = state.positions()[r as usize];
        let (p, c) = (rec.position_p, rec.position_c);
        let mid: [u32; 3] =
            core::array::from_fn(|a| (p[a] as i64 + ((c[a] as i64 - p[a] as i64) >> 1)) as u32);
        let placement = if parent == p {
            0
        } else if parent == c {
            1
        } else if parent == mid {
            2
        } else {
            3
        };
        let means = arc_means(state.positions(), parent, ring, o, d);
        let eligible = state.wing_candidates(ring);
        let (rank_o, rank_d) = match self.wings {
            WingPolicy::Ranks => eligible.ranks(o, d),
            near => {
                let mut keys: NearKeys = [0; MAX_SPLIT_VALENCE];
                let m = near_keys(state.positions(), ring, &eligible, near, &mut keys);
                near_ranks(&keys[..m], k, o, d)
            }
        }
        .unwrap_or((u8::MAX, u8::MAX));
        let edge2: i64 = (0..3).map(|a| (c[a] as i64 - p[a] as i64).pow(2)).sum();
        let written = writeln!(
            self.out,
            "{}\t{}\t{k}\t{}\t{o}\t{d}\t{valence_p}\t{valence_c}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{edge2}\t{}\t{placement}\t{}\t{rank_o}\t{rank_d}",
            self.level,
            self.round,
            eligible.count(),
            symbol(rec.deficit_p, valence_p),
            symbol(rec.deficit_c, valence_c),
            arc_p.0,
            arc_p.1,
            arc_p.2,
            arc_c.0,
            arc_c.1,
            arc_c.2,
            (r >= self.level_start) as u8,
            context::placement(&means),
        );
        if let Err(e) = written {
            self.failed.get_or_insert(e);
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, input, output] = &args[..] else {
        eprintln!("usage: split_fields IN.sps OUT.tsv");
        std::process::exit(2);
    };
    let fail = |what: &str, why: &dyn std::fmt::Display| -> ! {
        eprintln!("split_fields: {what}: {why}");
        std::process::exit(1)
    };
    let stream = std::fs::read(input).unwrap_or_else(|e| fail(input, &e));
    let file = std::fs::File::create(output).unwrap_or_else(|e| fail(output, &e));
    let mut out = std::io::BufWriter::new(file);
    match write_fields(&stream, &mut out) {
        Ok(Ok(())) => {}
        Ok(Err(e)) => fail(output, &e),
        Err(e) => fail(input, &e),
    }
    out.flush().unwrap_or_else(|e| fail(output, &e));
}

/// Decodes `stream` with decoder-core's `Decoder`, level by level and round
/// by round, writing every split record; the outer error is the stream's,
/// the inner one the output's.
fn write_fields(stream: &[u8], out: &mut dyn Write) -> Result<std::io::Result<()>, Error> {
    if let Err(e) = writeln!(out, "{COLUMNS}") {
        return Ok(Err(e));
    }
    let mut workspace = OwnedWorkspace::for_stream(stream)?;
    let mut decoder = workspace.decoder(stream)?;
    let mut fields = Fields {
        out,
        level: 0,
        round: 0,
        level_start: 0,
        wings: WingPolicy::Ranks,
        failed: None,
    };
    while let Some(k) = decoder.next_level() {
        let bytes = decoder.level_bytes(k, stream)?;
        fields.wings = decoder
            .level_table()
            .level_header(k, bytes, decoder.header().level_rules())?
            .wing_policy;
        let mut level = decoder.begin_level(k, bytes)?;
        // Level 0's seed is decoded by now: its vertices are old too.
        fields.level = k;
        fields.level_start = level.state().vertex_count();
        fields.round = 0;
        while level.next_round_observed(&mut fields)?.is_some() {
            if let Some(e) = fields.failed.take() {
                return Ok(Err(e));
            }
            fields.round += 1;
        }
    }
    Ok(Ok(()))
}
