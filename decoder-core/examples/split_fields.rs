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
//! 3 elsewhere: optimal mode) and that code's context (SPEC §5.5.5). Deficits are the live ones, as the record sees
//! them (earlier splits of the round may have decremented a wing's).

use std::io::Write;

use splitstream_decoder_core::limits::{LEAF, NONE, substream};
use splitstream_decoder_core::record::{StreamSource, read_base};
use splitstream_decoder_core::substream::Substreams;
use splitstream_decoder_core::{
    Error, Header, Inflater, LevelTable, MeshState, RecordSource, Ring, SplitRecord, arc_means,
    context, layout_for,
};

const COLUMNS: &str = "level\tround\tk\tm\to\td\tvalence_p\tvalence_c\tsymbol_p\tsymbol_c\t\
leaves_p\tdeficits_p\tghost_p\tleaves_c\tdeficits_c\tghost_c\tedge2\tnew\tplacement\t\
placement_context";

/// Passes the stream's records through and writes one line per split.
struct Fields<'a, S> {
    inner: S,
    out: &'a mut dyn Write,
    level: u16,
    round: u32,
    /// Vertices below this index existed when the level started.
    level_start: u32,
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

impl<S: RecordSource> RecordSource for Fields<'_, S> {
    fn flag(&mut self, state: &MeshState<'_>, v: u32) -> Result<bool, Error> {
        self.inner.flag(state, v)
    }

    fn likely_flags(&mut self, state: &MeshState<'_>, upcoming: &[u32]) -> u64 {
        self.inner.likely_flags(state, upcoming)
    }

    fn record(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring) -> Result<SplitRecord, Error> {
        let rec = self.inner.record(state, r, ring)?;
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
        let edge2: i64 = (0..3)
            .map(|a| (rec.position_c[a] as i64 - rec.position_p[a] as i64).pow(2))
            .sum();
        writeln!(
            self.out,
            "{}\t{}\t{k}\t{}\t{o}\t{d}\t{valence_p}\t{valence_c}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{edge2}\t{}\t{placement}\t{}",
            self.level,
            self.round,
            state.wing_candidates(ring).count(),
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
        )
        .map_err(|_| Error::CapacityExceeded)?;
        Ok(rec)
    }

    fn applied(&mut self, r: u32, c: u32, outcome: &splitstream_decoder_core::SplitOutcome) {
        self.inner.applied(r, c, outcome);
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, input, output] = &args[..] else {
        eprintln!("usage: split_fields IN.sps OUT.tsv");
        std::process::exit(2);
    };
    let stream = std::fs::read(input).unwrap_or_else(|e| {
        eprintln!("split_fields: {input}: {e}");
        std::process::exit(1)
    });
    let file = std::fs::File::create(output).unwrap_or_else(|e| {
        eprintln!("split_fields: {output}: {e}");
        std::process::exit(1)
    });
    let mut out = std::io::BufWriter::new(file);
    if let Err(e) = write_fields(&stream, &mut out).and_then(|n| {
        out.flush().map_err(|_| Error::CapacityExceeded)?;
        Ok(n)
    }) {
        eprintln!("split_fields: {input}: {e}");
        std::process::exit(1);
    }
}

/// Decodes `stream` level by level (the order of SPEC §10.3) and writes its
/// splits; returns how many.
fn write_fields(stream: &[u8], out: &mut dyn Write) -> Result<u64, Error> {
    writeln!(out, "{COLUMNS}").map_err(|_| Error::CapacityExceeded)?;
    let header = Header::parse(stream)?;
    let table = LevelTable::parse(stream, &header)?;
    let layout = layout_for(&header, &table, header.level_count - 1);
    let len = usize::try_from(layout.bytes_unaligned()).map_err(|_| Error::CapacityExceeded)?;
    let mut workspace = vec![0u8; len];
    let (memory, mut buffers) = layout.carve(&mut workspace)?;
    let mut state = MeshState::new(memory, header.bits);
    let mut inflater = Box::new(Inflater::new());
    let mut ring = Box::new(Ring::default());
    let mut splits = 0u64;
    for k in 0..header.level_count {
        let info = table.get(k);
        let bytes = usize::try_from(info.offset)
            .ok()
            .and_then(|s| stream.get(s..s.checked_add(info.length as usize)?))
            .ok_or(Error::Truncated)?;
        let level_header = table.level_header(k, bytes, header.max_chunk_len)?;
        state.set_triangle_limit(info.triangle_count);
        if k == 0 {
            let slots = buffers.each_mut().map(|b| &mut **b);
            let mut seed = Substreams::open(
                bytes,
                level_header,
                substream::BASE_POSITIONS,
                slots,
                &mut inflater,
                header.lane_count,
            );
            let (v, t) = (level_header.seed_vertices, level_header.seed_triangles);
            read_base(&mut state, &mut seed, v, t)?;
        }
        let level_start = state.vertex_count();
        let slots = buffers.each_mut().map(|b| &mut **b);
        let mut subs = Substreams::open(
            bytes,
            level_header,
            substream::FLAGS,
            slots,
            &mut inflater,
            header.lane_count,
        );
        for round in 0..level_header.round_count {
            let declared = level_header.split_count(round);
            let mut fields = Fields {
                inner: StreamSource::new(&mut subs, header.position_mode),
                out: &mut *out,
                level: k,
                round,
                level_start,
            };
            splits += state.run_round(declared, &mut fields, &mut ring)?.splits as u64;
        }
        subs.finish()?;
    }
    Ok(splits)
}
