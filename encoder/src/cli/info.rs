//! `splitstream info`: what a stream holds and where its bits go.

use std::path::Path;

use splitstream_decoder_core::limits::substream::{self, NAMES};
use splitstream_decoder_core::{Header, LevelHeader, LevelTable, PositionMode};

use super::{CliResult, read_file};

/// Bytes per substream id, stored (compressed) and raw.
#[derive(Default)]
pub struct FieldSizes {
    pub stored: [u64; 12],
    pub raw: [u64; 12],
    pub framing: u64,
}

/// Sums chunk sizes per substream over every level of `stream`.
pub fn field_sizes(
    stream: &[u8],
    header: &Header,
    table: &LevelTable<'_>,
) -> Result<FieldSizes, String> {
    let mut sizes = FieldSizes {
        framing: splitstream_decoder_core::head_len(header.level_count) as u64,
        ..FieldSizes::default()
    };
    for k in 0..table.len() {
        let e = table.get(k);
        let bytes = stream
            .get(e.offset as usize..(e.offset + e.length as u64) as usize)
            .ok_or("stream truncated")?;
        let lh =
            LevelHeader::parse(bytes, k == 0, header.max_chunk_len).map_err(|e| e.to_string())?;
        sizes.framing += lh.payload_start as u64;
        for c in 0..lh.chunk_count {
            let chunk = lh.chunk(c).map_err(|e| e.to_string())?;
            sizes.stored[chunk.substream as usize] += chunk.stored_len as u64;
            sizes.raw[chunk.substream as usize] += chunk.raw_len as u64;
        }
    }
    Ok(sizes)
}

/// Whether a substream carries positions (the rest is connectivity).
pub fn is_geometry(id: usize) -> bool {
    id == substream::EDGE as usize
        || id == substream::PLACEMENT as usize
        || id == substream::BASE_POSITIONS as usize
}

pub fn run(input: &Path, json: bool) -> CliResult {
    let stream = read_file(input)?;
    let fail = |e: splitstream_decoder_core::Error| format!("{}: {e}", input.display());
    let header = Header::parse(&stream).map_err(fail)?;
    let table = LevelTable::parse(&stream, &header).map_err(fail)?;
    let sizes = field_sizes(&stream, &header, &table)?;
    let n = header.vertex_capacity as f64;
    let bpv = |bytes: u64| 8.0 * bytes as f64 / n;
    let connectivity: u64 = (1..12)
        .filter(|&i| !is_geometry(i))
        .map(|i| sizes.stored[i])
        .sum();
    let geometry: u64 = (1..12)
        .filter(|&i| is_geometry(i))
        .map(|i| sizes.stored[i])
        .sum();
    let mode = match header.position_mode {
        PositionMode::Optimal => "optimal",
        PositionMode::Constrained => "constrained",
    };
    if json {
        let levels: Vec<_> = (0..table.len())
            .map(|k| {
                let e = table.get(k);
                serde_json::json!({
                    "level": k, "offset": e.offset, "length": e.length,
                    "vertices": e.vertex_count, "triangles": e.triangle_count,
                    "rounds": e.round_count, "geometric_error": e.geometric_error,
                })
            })
            .collect();
        let fields: serde_json::Map<String, serde_json::Value> = (1..12)
            .map(|i| {
                (
                    NAMES[i].to_string(),
                    serde_json::json!({"bytes": sizes.stored[i], "raw_bytes": sizes.raw[i], "bits_per_vertex": bpv(sizes.stored[i])}),
                )
            })
            .collect();
        let doc = serde_json::json!({
            "version": format!("1.{}", header.version_minor),
            "position_mode": mode,
            "bits": header.bits,
            "origin": header.origin,
            "scale": header.scale,
            "vertices": header.vertex_capacity,
            "triangles": header.triangle_capacity,
            "bytes": stream.len(),
            "bits_per_vertex": bpv(stream.len() as u64),
            "connectivity_bits_per_vertex": bpv(connectivity),
            "geometry_bits_per_vertex": bpv(geometry),
            "framing_bytes": sizes.framing,
            "workspace_bytes": header.workspace_bytes,
            "workspace_bytes_per_vertex": header.workspace_bytes as f64 / n,
            "max_chunk_len": header.max_chunk_len,
            "levels": levels,
            "fields": fields,
        });
        println!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| e.to_string())?
        );
        return Ok(());
    }
    println!(
        "{}: splitstream format 1.{}",
        input.display(),
        header.version_minor
    );
    println!(
        "  {} vertices, {} triangles, {} bytes ({:.2} bits/vertex: connectivity {:.2}, geometry {:.2}, framing {:.2})",
        header.vertex_capacity,
        header.triangle_capacity,
        stream.len(),
        bpv(stream.len() as u64),
        bpv(connectivity),
        bpv(geometry),
        bpv(sizes.framing)
    );
    println!(
        "  positions: {} bits/axis, {mode} placement, origin {:?}, step {:?}",
        header.bits, header.origin, header.scale
    );
    println!(
        "  decoder memory: {} bytes ({:.1} bytes/vertex), chunks up to {} bytes",
        header.workspace_bytes,
        header.workspace_bytes as f64 / n,
        header.max_chunk_len
    );
    println!("  level    offset     bytes   vertices  triangles rounds  geometric error");
    for k in 0..table.len() {
        let e = table.get(k);
        println!(
            "  {:>5} {:>9} {:>9} {:>10} {:>10} {:>6}  {:.6}",
            k,
            e.offset,
            e.length,
            e.vertex_count,
            e.triangle_count,
            e.round_count,
            e.geometric_error
        );
    }
    println!("  field            bytes   raw bytes  bits/vertex");
    for (i, name) in NAMES.iter().enumerate().skip(1) {
        println!(
            "  {:<14} {:>9} {:>11} {:>10.3}",
            name,
            sizes.stored[i],
            sizes.raw[i],
            bpv(sizes.stored[i])
        );
    }
    Ok(())
}
