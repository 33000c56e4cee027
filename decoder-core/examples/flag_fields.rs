//! Writes every coded flag of a stream (SPEC §7.3), with what a decoder
//! knows when it reads it, as tab-separated text: the raw material for
//! measuring a context for the flags before building it (SPEC §5.5.5).
//!
//! ```text
//! cargo run --release -p splitstream-decoder-core --features alloc --example flag_fields -- IN.sps OUT.tsv
//! ```
//!
//! One line per coded flag (inferred flags, SPEC §7.2, are left out), in
//! decoding order, after a header line naming the columns: the level and
//! the round within it; the candidate's index; the flag; whether the
//! candidate was created in this level (`new`) or in the round before
//! (`fresh`); for how many rounds of this level just before this one it was
//! already a candidate (`waited`; 0 for a vertex that was not), how many
//! of those flags were coded rather than inferred (`coded_before`), and its
//! deficit at the start of the round (`deficit`; under the schedule
//! `every-vertex` its valence, which gives the flag's context).

use std::io::Write;

use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_decoder_core::{Error, MeshState, Ring, SplitObserver, SplitRecord};

const COLUMNS: &str = "level\tround\tv\tflag\tnew\tfresh\twaited\tcoded_before\tdeficit";

/// The splits of one round, as the decoder shows them: the split vertex and
/// its ring at round start.
#[derive(Default)]
struct Splits {
    rings: Vec<(u32, Vec<u32>)>,
}

impl SplitObserver for Splits {
    fn record(&mut self, _: &MeshState<'_>, r: u32, ring: &Ring, _: &SplitRecord) {
        self.rings.push((r, ring.vertices().to_vec()));
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, input, output] = &args[..] else {
        eprintln!("usage: flag_fields IN.sps OUT.tsv");
        std::process::exit(2);
    };
    let fail = |what: &str, why: &dyn std::fmt::Display| -> ! {
        eprintln!("flag_fields: {what}: {why}");
        std::process::exit(1)
    };
    let stream = std::fs::read(input).unwrap_or_else(|e| fail(input, &e));
    let file = std::fs::File::create(output).unwrap_or_else(|e| fail(output, &e));
    let mut out = std::io::BufWriter::new(file);
    match write_flags(&stream, &mut out) {
        Ok(Ok(())) => {}
        Ok(Err(e)) => fail(output, &e),
        Err(e) => fail(input, &e),
    }
    out.flush().unwrap_or_else(|e| fail(output, &e));
}

/// The candidates of the coming round (SPEC §7.3): vertices with deficit
/// 0, or every vertex under the schedule `every-vertex`.
fn candidates(state: &MeshState<'_>) -> Vec<u32> {
    state.candidates().collect()
}

/// Decodes `stream`, writing every coded flag; the outer error is the
/// stream's, the inner one the output's.
fn write_flags(stream: &[u8], out: &mut dyn Write) -> Result<std::io::Result<()>, Error> {
    if let Err(e) = writeln!(out, "{COLUMNS}") {
        return Ok(Err(e));
    }
    let mut workspace = OwnedWorkspace::for_stream(stream)?;
    let mut decoder = workspace.decoder(stream)?;
    let mut splits = Splits::default();
    // Per vertex: consecutive rounds of this level as a candidate, and how
    // many of their flags were coded.
    let mut waited: Vec<(u32, u32)> = Vec::new();
    let mut inferred: Vec<bool> = Vec::new();
    let mut flagged: Vec<bool> = Vec::new();
    while let Some(k) = decoder.next_level() {
        let bytes = decoder.level_bytes(k, stream)?;
        let mut level = decoder.begin_level(k, bytes)?;
        let level_start = level.state().vertex_count();
        waited.clear();
        let mut round = 0u32;
        let mut previous_start = level_start;
        loop {
            let before = level.state().vertex_count();
            let cands = candidates(level.state());
            // Round-start deficits (under `every-vertex`, the valences:
            // the flags' context, SPEC §5.5.5).
            let deficits = level.state().deficits().to_vec();
            splits.rings.clear();
            if level.next_round_observed(&mut splits)?.is_none() {
                break;
            }
            let grown = level.state().vertex_count() as usize;
            waited.resize(grown, (0, 0));
            inferred.clear();
            inferred.resize(grown, false);
            flagged.clear();
            flagged.resize(grown, false);
            for (r, ring) in &splits.rings {
                flagged[*r as usize] = true;
                for &u in ring {
                    // A ring entry after r in the candidates' order has its
                    // flag inferred (SPEC §7.2).
                    if u > *r && (u as usize) < grown {
                        inferred[u as usize] = true;
                    }
                }
            }
            let mut next = vec![(0u32, 0u32); grown];
            // Vertices at or above this were created by the round before
            // (none, in the level's first round).
            let fresh_from = previous_start;
            for &v in &cands {
                let (w, coded) = waited.get(v as usize).copied().unwrap_or((0, 0));
                let is_inferred = inferred[v as usize] && !flagged[v as usize];
                if !is_inferred {
                    let line = writeln!(
                        out,
                        "{k}\t{round}\t{v}\t{}\t{}\t{}\t{w}\t{coded}\t{}",
                        flagged[v as usize] as u8,
                        (v >= level_start) as u8,
                        (v >= fresh_from) as u8,
                        deficits[v as usize],
                    );
                    if let Err(e) = line {
                        return Ok(Err(e));
                    }
                }
                if !flagged[v as usize] {
                    next[v as usize] = (w + 1, coded + !is_inferred as u32);
                }
            }
            waited = next;
            round += 1;
            previous_start = before;
        }
    }
    Ok(Ok(()))
}
