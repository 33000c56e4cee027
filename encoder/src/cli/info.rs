//! `splitstream info`: what a stream holds and where its bits go.

use std::path::Path;

use splitstream_decoder_core::limits::VERSION_MAJOR;
use splitstream_decoder_core::limits::codec;
use splitstream_decoder_core::limits::substream::{self, NAMES};
use splitstream_decoder_core::table_kinds;
use splitstream_decoder_core::writer::ChunkCodec;
use splitstream_decoder_core::{
    DeficitContexts, Header, LevelHeader, LevelTable, PositionMode, Schedule, layout_for,
};
use splitstream_encoder::emit::{TranscodeOptions, transcode};

use super::{CliResult, read_file};

const FIELDS: usize = NAMES.len();

/// Bytes per substream id, stored (compressed) and raw, and which codecs
/// its chunks use.
#[derive(Default)]
pub struct FieldSizes {
    pub stored: [u64; FIELDS],
    /// Raw bytes (stored and deflate chunks) plus values (rANS chunks).
    pub raw: [u64; FIELDS],
    /// Per id, a bit per codec id seen (1 stored, 2 deflate, 4 rANS).
    pub codecs: [u8; FIELDS],
    /// Chunks per id, over every level (rANS substreams are cut where
    /// their tables pay, so their counts vary).
    pub chunks: [u64; FIELDS],
    pub framing: u64,
    /// Values of the longest rANS chunk (0 if none).
    pub largest_rans_chunk: u32,
    /// rANS tables per id, over every chunk: how many are adaptive (format
    /// 3.9) and how many are in use (SPEC §5.5.2).
    pub adaptive_tables: [u32; FIELDS],
    pub tables: [u32; FIELDS],
    /// Stored bytes per substream id in each level counted (`stored` is
    /// their sum).
    pub per_level: Vec<[u64; FIELDS]>,
}

impl FieldSizes {
    /// The codecs of substream `id`, by name.
    pub fn codec_names(&self, id: usize) -> String {
        let names: Vec<&str> = ["stored", "deflate", "rans"]
            .iter()
            .enumerate()
            .filter(|(bit, _)| self.codecs[id] & (1 << bit) != 0)
            .map(|(_, n)| *n)
            .collect();
        if names.is_empty() {
            "-".to_string()
        } else {
            names.join("+")
        }
    }
}

/// Sums chunk sizes per substream over every level of `stream`.
pub fn field_sizes(
    stream: &[u8],
    header: &Header,
    table: &LevelTable<'_>,
) -> Result<FieldSizes, String> {
    field_sizes_of(stream, header, table, table.len())
}

/// How many levels, from level 0, have all their bytes in `stream` (a
/// prefix of a stream holds its first levels whole, SPEC §4.1).
pub fn levels_in(stream: &[u8], table: &LevelTable<'_>) -> u16 {
    (0..table.len())
        .take_while(|&k| {
            let e = table.get(k);
            e.offset + e.length as u64 <= stream.len() as u64
        })
        .count() as u16
}

/// Sums chunk sizes per substream over levels `0..levels` of `stream`.
fn field_sizes_of(
    stream: &[u8],
    header: &Header,
    table: &LevelTable<'_>,
    levels: u16,
) -> Result<FieldSizes, String> {
    let mut sizes = FieldSizes {
        framing: header.head_len() as u64,
        ..FieldSizes::default()
    };
    for k in 0..levels {
        let e = table.get(k);
        let end = e.offset + e.length as u64;
        let bytes = stream.get(e.offset as usize..end as usize).ok_or_else(|| {
            format!(
                "stream truncated: level {k} ends at byte {end}, the stream has {} bytes",
                stream.len()
            )
        })?;
        let lh = table
            .level_header(k, bytes, header.level_rules())
            .map_err(|e| format!("level {k}: {e}"))?;
        sizes.framing += lh.payload_start as u64;
        let mut level = [0u64; FIELDS];
        let mut payload_at = lh.payload_start;
        for c in 0..lh.chunk_count {
            let chunk = lh.chunk(c).map_err(|e| e.to_string())?;
            let payload = bytes
                .get(payload_at..payload_at + chunk.stored_len as usize)
                .ok_or_else(|| format!("level {k}: chunk {c} runs past the level"))?;
            payload_at += chunk.stored_len as usize;
            if chunk.codec == codec::RANS {
                let contexts = splitstream_decoder_core::context::count(
                    chunk.substream,
                    lh.deficit_contexts,
                    lh.record_order,
                    header.schedule,
                );
                let (adaptive, in_use) = table_kinds(payload, contexts)
                    .map_err(|e| format!("level {k}: chunk {c}: {e}"))?;
                sizes.adaptive_tables[chunk.substream as usize] += adaptive;
                sizes.tables[chunk.substream as usize] += in_use;
            }
            level[chunk.substream as usize] += chunk.stored_len as u64;
            sizes.stored[chunk.substream as usize] += chunk.stored_len as u64;
            sizes.raw[chunk.substream as usize] += chunk.raw_len as u64;
            sizes.codecs[chunk.substream as usize] |= 1 << chunk.codec.min(7);
            sizes.chunks[chunk.substream as usize] += 1;
            if chunk.codec == codec::RANS {
                sizes.largest_rans_chunk = sizes.largest_rans_chunk.max(chunk.raw_len);
            }
        }
        sizes.per_level.push(level);
    }
    Ok(sizes)
}

/// Whether a substream carries positions (the rest is connectivity).
pub fn is_geometry(id: usize) -> bool {
    id == substream::EDGE as usize
        || id == substream::PLACEMENT as usize
        || id == substream::BASE_POSITIONS as usize
}

/// The stream coded again with one codec (`transcode`, nothing written):
/// its field sizes and total bytes.
struct Recoded {
    codec: &'static str,
    sizes: FieldSizes,
    bytes: u64,
}

/// The stream re-coded with rANS and with deflate, at its own chunk sizes
/// and lane count (its longest rANS chunk as the limit; 4 lanes and the
/// encoder's default limit for a stream without rANS chunks), each level's
/// plane, wing and deficit coding chosen again for that codec.
fn recode(stream: &[u8], header: &Header, sizes: &FieldSizes) -> Result<Vec<Recoded>, String> {
    let has_rans = sizes.largest_rans_chunk > 0;
    let lanes = if has_rans { header.lane_count } else { 4 };
    let rans_chunk_limit = if has_rans {
        sizes.largest_rans_chunk
    } else {
        TranscodeOptions::default().rans_chunk_limit
    };
    let codecs = [
        ("rans", ChunkCodec::Rans { lanes }),
        ("deflate", ChunkCodec::Deflate(9)),
    ];
    codecs
        .into_iter()
        .map(|(codec, chunk_codec)| {
            let options = TranscodeOptions {
                codec: chunk_codec,
                chunk_limit: header.max_chunk_len,
                rans_chunk_limit,
                ..TranscodeOptions::default()
            };
            let done = transcode(stream, &options).map_err(|e| e.to_string())?;
            let header = Header::parse(&done.stream).map_err(|e| e.to_string())?;
            let table = LevelTable::parse(&done.stream, &header).map_err(|e| e.to_string())?;
            Ok(Recoded {
                codec,
                sizes: field_sizes(&done.stream, &header, &table)?,
                bytes: done.stream.len() as u64,
            })
        })
        .collect()
}

/// What `splitstream info` prints besides the header and level table.
pub struct InfoOptions {
    /// One JSON document instead of text.
    pub json: bool,
    /// Every field coded again with rANS and with deflate.
    pub codecs: bool,
    /// Each field's bytes in each level (text; JSON always has them).
    pub by_level: bool,
}

pub fn run(input: &Path, options: InfoOptions) -> CliResult {
    let InfoOptions {
        json,
        codecs,
        by_level,
    } = options;
    let stream = read_file(input)?;
    let fail = |e: splitstream_decoder_core::Error| format!("{}: {e}", input.display());
    let header = Header::parse(&stream).map_err(fail)?;
    let table = LevelTable::parse(&stream, &header).map_err(fail)?;
    // A prefix of the stream (its first levels, as a client fetches them)
    // is described as far as it goes.
    let in_file = levels_in(&stream, &table);
    let last = table.get(table.len() - 1);
    let declared_bytes = last.offset + last.length as u64;
    let truncated = (in_file < table.len()).then(|| {
        let counted = match in_file {
            0 => "no level is whole, so no field is counted".to_owned(),
            1 => "the fields count level 0 only".to_owned(),
            n => format!("the fields count levels 0..={} only", n - 1),
        };
        format!(
            "truncated: levels {in_file}..={} are not in the file (it has {} of {declared_bytes} bytes); {counted}",
            table.len() - 1,
            stream.len(),
        )
    });
    if codecs && truncated.is_some() {
        return Err(format!(
            "{}: --codecs re-codes the whole stream, and the file holds {in_file} of its {} levels",
            input.display(),
            table.len()
        ));
    }
    let sizes = field_sizes_of(&stream, &header, &table, in_file)
        .map_err(|e| format!("{}: {e}", input.display()))?;
    let recoded = if codecs {
        recode(&stream, &header, &sizes).map_err(|e| format!("{}: {e}", input.display()))?
    } else {
        Vec::new()
    };
    // Each level's plane and wing policies, deficit contexts and record
    // order (SPEC §5.1, §5.5.5, §7.4).
    let policies: Vec<(&str, &str, &str, &str)> = (0..table.len())
        .map(|k| {
            let e = table.get(k);
            stream
                .get(e.offset as usize..(e.offset + e.length as u64) as usize)
                .and_then(|b| LevelHeader::parse(b, k == 0, header.level_rules()).ok())
                .map_or(("?", "?", "?", "?"), |lh| {
                    // Byte 10 (SPEC §5.1): the deficit contexts, or under
                    // `every-vertex`, which codes no split valences, the
                    // flags' contexts (`valence`, or 3.10 `split-history`).
                    let deficits = match (header.schedule, lh.deficit_contexts) {
                        (Schedule::SplitValences, contexts) => contexts.name(),
                        (Schedule::EveryVertex, DeficitContexts::SplitHistory) => "split-history",
                        (Schedule::EveryVertex, _) => "valence",
                    };
                    (
                        lh.plane_policy.name(),
                        lh.wing_policy.name(),
                        deficits,
                        lh.record_order.name_with(lh.ties),
                    )
                })
        })
        .collect();
    // Per vertex of what the file holds: the whole stream, or for a prefix
    // the levels before the first one cut off (their bytes and the finest
    // one's vertices).
    let (vertices_held, bytes_held) = match in_file {
        k if k == table.len() => (header.vertex_capacity, stream.len() as u64),
        0 => (0, header.head_len() as u64),
        k => {
            let e = table.get(k - 1);
            (e.vertex_count, e.offset + e.length as u64)
        }
    };
    // With no whole level there is nothing to divide by (`null` in JSON).
    let bpv = |bytes: u64| match vertices_held {
        0 => f64::NAN,
        n => 8.0 * bytes as f64 / n as f64,
    };
    let connectivity: u64 = (1..FIELDS)
        .filter(|&i| !is_geometry(i))
        .map(|i| sizes.stored[i])
        .sum();
    let geometry: u64 = (1..FIELDS)
        .filter(|&i| is_geometry(i))
        .map(|i| sizes.stored[i])
        .sum();
    let mode = match header.position_mode {
        PositionMode::Optimal => "optimal",
        PositionMode::Constrained => "constrained",
    };
    // The workspace a decoder needs to decode levels 0 ..= k (SPEC §9): what
    // a device with a fixed buffer can hold.
    let memory: Vec<u64> = (0..table.len())
        .map(|k| layout_for(&header, &table, k).total)
        .collect();
    if json {
        let levels: Vec<_> = (0..table.len())
            .map(|k| {
                let e = table.get(k);
                serde_json::json!({
                    "level": k, "offset": e.offset, "length": e.length,
                    "vertices": e.vertex_count, "triangles": e.triangle_count,
                    "rounds": e.round_count, "geometric_error": e.geometric_error,
                    "plane_policy": policies[k as usize].0,
                    "wing_policy": policies[k as usize].1,
                    // Byte 10 (SPEC §5.1): one of the two, the other null.
                    "deficit_contexts": (header.schedule == Schedule::SplitValences).then_some(policies[k as usize].2),
                    "flag_contexts": (header.schedule == Schedule::EveryVertex).then_some(policies[k as usize].2),
                    "record_order": policies[k as usize].3,
                    "workspace_bytes": memory[k as usize],
                    // null for a level that is not in the file.
                    "field_bytes": sizes.per_level.get(k as usize).map(|level| {
                        (1..FIELDS)
                            .map(|i| (NAMES[i].to_string(), level[i].into()))
                            .collect::<serde_json::Map<_, _>>()
                    }),
                })
            })
            .collect();
        let fields: serde_json::Map<String, serde_json::Value> = (1..FIELDS)
            .map(|i| {
                let mut field = serde_json::json!({"bytes": sizes.stored[i], "raw_bytes_or_values": sizes.raw[i], "chunks": sizes.chunks[i], "codecs": sizes.codec_names(i), "bits_per_vertex": bpv(sizes.stored[i])});
                if !recoded.is_empty() {
                    field["recoded_bytes"] = recoded
                        .iter()
                        .map(|r| (r.codec.to_string(), r.sizes.stored[i].into()))
                        .collect::<serde_json::Map<_, _>>()
                        .into();
                }
                (NAMES[i].to_string(), field)
            })
            .collect();
        let doc = serde_json::json!({
            "version": format!("{VERSION_MAJOR}.{}", header.version_minor),
            "lane_count": header.lane_count,
            "position_mode": mode,
            "schedule": header.schedule.name(),
            "framing": header.framing.name(),
            "bits": header.bits,
            "origin": header.origin,
            "scale": header.scale,
            "vertices": header.vertex_capacity,
            "triangles": header.triangle_capacity,
            "bytes": stream.len(),
            "vertices_in_file": vertices_held,
            "bits_per_vertex": bpv(bytes_held),
            "connectivity_bits_per_vertex": bpv(connectivity),
            "geometry_bits_per_vertex": bpv(geometry),
            "framing_bytes": sizes.framing,
            "head_len": header.head_len(),
            "rans_tables": sizes.tables.iter().sum::<u32>(),
            "rans_tables_adaptive": sizes.adaptive_tables.iter().sum::<u32>(),
            "workspace_bytes": header.workspace_bytes,
            "workspace_bytes_per_vertex": header.workspace_bytes as f64 / header.vertex_capacity as f64,
            "max_chunk_len": header.max_chunk_len,
            "declared_bytes": declared_bytes,
            "levels_in_file": in_file,
            "levels": levels,
            "fields": fields,
        });
        let mut doc = doc;
        if !recoded.is_empty() {
            doc["recoded"] = recoded
                .iter()
                .map(|r| {
                    (
                        r.codec.to_string(),
                        serde_json::json!({"bytes": r.bytes, "bits_per_vertex": bpv(r.bytes)}),
                    )
                })
                .collect::<serde_json::Map<_, _>>()
                .into();
        }
        println!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| e.to_string())?
        );
        return Ok(());
    }
    println!(
        "{}: splitstream format {VERSION_MAJOR}.{}, {} rANS lane(s)",
        input.display(),
        header.version_minor,
        header.lane_count
    );
    let held = match in_file {
        k if k == table.len() => format!("{} bytes", stream.len()),
        0 => String::new(),
        k => format!(
            "{declared_bytes} bytes declared; levels 0..={} in the file: {vertices_held} vertices in {bytes_held} bytes",
            k - 1
        ),
    };
    if in_file == 0 {
        println!(
            "  {} vertices, {} triangles, {declared_bytes} bytes declared; no whole level in the file ({} bytes)",
            header.vertex_capacity,
            header.triangle_capacity,
            stream.len()
        );
    } else {
        println!(
            "  {} vertices, {} triangles, {held} ({:.2} bits/vertex: connectivity {:.2}, geometry {:.2}, framing {:.2})",
            header.vertex_capacity,
            header.triangle_capacity,
            bpv(bytes_held),
            bpv(connectivity),
            bpv(geometry),
            bpv(sizes.framing)
        );
    }
    println!(
        "  positions: {} bits/axis, {mode} placement, origin {:?}, step {:?}",
        header.bits, header.origin, header.scale
    );
    println!(
        "  schedule: {}; framing: {} (level table {} bytes, SPEC §3.2, §4, §5.1)",
        header.schedule.name(),
        header.framing.name(),
        header.table_len
    );
    println!(
        "  decoder memory: {} bytes ({:.1} bytes/vertex), stored and deflate chunks up to {} bytes",
        header.workspace_bytes,
        header.workspace_bytes as f64 / header.vertex_capacity as f64,
        header.max_chunk_len
    );
    println!(
        "  level    offset     bytes   vertices  triangles rounds  plane     wings    contexts       records                  decoder memory  geometric error"
    );
    for k in 0..table.len() {
        let e = table.get(k);
        println!(
            "  {:>5} {:>9} {:>9} {:>10} {:>10} {:>6}  {:<9} {:<8} {:<14} {:<23} {:>15}  {:.6}",
            k,
            e.offset,
            e.length,
            e.vertex_count,
            e.triangle_count,
            e.round_count,
            policies[k as usize].0,
            policies[k as usize].1,
            policies[k as usize].2,
            policies[k as usize].3,
            memory[k as usize],
            e.geometric_error
        );
    }
    if let Some(truncated) = &truncated {
        println!("  {truncated}");
    }
    let recoded_header: String = recoded
        .iter()
        .map(|r| format!(" {:>10}", format!("as {}", r.codec)))
        .collect();
    if in_file == 0 {
        // No vertex to count bits per: the table would say NaN.
        return Ok(());
    }
    println!(
        "  field            bytes  raw bytes/values  chunks  codecs          bits/vertex{recoded_header}"
    );
    for (i, name) in NAMES.iter().enumerate().skip(1) {
        let recoded_bits: String = recoded
            .iter()
            .map(|r| format!(" {:>10.3}", bpv(r.sizes.stored[i])))
            .collect();
        println!(
            "  {:<14} {:>9} {:>17} {:>7}  {:<14} {:>10.3}{recoded_bits}",
            name,
            sizes.stored[i],
            sizes.raw[i],
            sizes.chunks[i],
            sizes.codec_names(i),
            bpv(sizes.stored[i])
        );
    }
    if !recoded.is_empty() {
        let totals: String = recoded
            .iter()
            .map(|r| format!(" {:>10.3}", bpv(r.bytes)))
            .collect();
        println!(
            "  {:<14} {:>9} {:>17} {:>7}  {:<14} {:>10.3}{totals}",
            "all",
            stream.len(),
            "",
            "",
            "",
            bpv(stream.len() as u64)
        );
        println!(
            "  (as rans, as deflate: the same refinement coded again with that codec by `splitstream transcode`, \
             each level's coding chosen again)"
        );
    }
    let tables: u32 = sizes.tables.iter().sum();
    if tables > 0 {
        let adaptive: u32 = sizes.adaptive_tables.iter().sum();
        println!(
            "  rANS tables: {adaptive} of {tables} adaptive (format 3.9, SPEC §5.5.2: no counts sent, \
             probabilities that follow the values)"
        );
    }
    if by_level {
        print_by_level(&sizes, &table);
    }
    Ok(())
}

/// The bytes of each field in each level held, and each level's bits per
/// vertex it adds (its bytes over the vertices it adds; level 0 over its
/// own).
fn print_by_level(sizes: &FieldSizes, table: &LevelTable<'_>) {
    let held = sizes.per_level.len();
    if held == 0 {
        return; // no whole level in the file (said above)
    }
    let columns: String = (0..held)
        .map(|k| format!(" {:>10}", format!("level {k}")))
        .collect();
    println!("  bytes by level:{columns}");
    for (i, name) in NAMES.iter().enumerate().skip(1) {
        if sizes.stored[i] == 0 {
            continue;
        }
        let cells: String = sizes
            .per_level
            .iter()
            .map(|level| format!(" {:>10}", level[i]))
            .collect();
        println!("  {name:<14} {cells}");
    }
    let added = |k: usize| {
        let before = if k == 0 {
            0
        } else {
            table.get(k as u16 - 1).vertex_count
        };
        table.get(k as u16).vertex_count.saturating_sub(before)
    };
    let cells: String = (0..held)
        .map(|k| match added(k) {
            0 => format!(" {:>10}", "-"),
            n => format!(
                " {:>10.2}",
                8.0 * table.get(k as u16).length as f64 / n as f64
            ),
        })
        .collect();
    println!("  {:<14} {cells}", "bits/new v");
}
