//! Checksum rewriting for byte-level fuzzing (shared with the tests).

/// The header's length (SPEC §3.1).
const HEADER_LEN: usize = 96;
/// A fixed level table's entry (SPEC §4.1).
const ENTRY: usize = 32;

/// Rewrites every checksum of `stream` that can be located (header, level
/// table, level headers, chunks) to match its bytes, so that byte-level
/// mutations reach the parsers and the split logic behind the CRCs.
/// Best effort: stops where the structure cannot be followed.
pub fn fix_checksums(stream: &mut [u8]) {
    use splitstream_decoder_core::crc32;
    let rd32 = |b: &[u8], at: usize| -> Option<u32> {
        Some(u32::from_le_bytes(
            b.get(at..at.checked_add(4)?)?.try_into().ok()?,
        ))
    };
    let Some(table_end) = fix_head_checksums(stream) else {
        return;
    };
    let level_count = u16::from_le_bytes([stream[14], stream[15]]) as usize;
    // Header flag bit 2: the compact level framing (SPEC §5.1.1, 3.11);
    // bit 3: the compact level table (§4.3, 3.12).
    let compact = stream[10] & 4 != 0;
    let compact_table = stream[10] & 8 != 0;
    let ranges: Vec<(u64, u64)> = if compact_table {
        compact_ranges(
            &stream[HEADER_LEN..table_end],
            level_count,
            table_end as u64 + 4,
        )
    } else {
        (0..level_count)
            .map(|k| {
                let at = HEADER_LEN + ENTRY * k;
                let offset = u64::from_le_bytes(stream[at..at + 8].try_into().unwrap());
                (offset, rd32(stream, at + 8).unwrap_or(0) as u64)
            })
            .collect()
    };
    for (k, (offset, length)) in ranges.into_iter().enumerate() {
        let Some(end) = offset.checked_add(length) else {
            return;
        };
        if end > stream.len() as u64 {
            return;
        }
        let level = &mut stream[offset as usize..end as usize];
        let layout = if compact {
            compact_layout(level, k == 0)
        } else {
            fixed_layout(level, k == 0)
        };
        let Some((entries, crc_at)) = layout else {
            return;
        };
        let mut payload = crc_at + 4;
        for (entry_crc_at, stored) in entries {
            let Some(p_end) = payload.checked_add(stored) else {
                break;
            };
            if p_end > level.len() {
                break;
            }
            let crc = crc32(&level[payload..p_end]);
            level[entry_crc_at..entry_crc_at + 4].copy_from_slice(&crc.to_le_bytes());
            payload = p_end;
        }
        let crc = crc32(&level[..crc_at]);
        level[crc_at..crc_at + 4].copy_from_slice(&crc.to_le_bytes());
    }
}

/// Rewrites the header's checksum and the level table's (SPEC §3.3, §4.2),
/// wherever the header's flags and `table_len` put the table (fixed or
/// compact, §4.3), and answers where the table's CRC lies; `None`, with
/// the table's CRC untouched, where the stream is too short for it.
pub fn fix_head_checksums(stream: &mut [u8]) -> Option<usize> {
    use splitstream_decoder_core::crc32;
    if stream.len() < HEADER_LEN {
        return None;
    }
    let crc = crc32(&stream[..HEADER_LEN - 4]);
    stream[HEADER_LEN - 4..HEADER_LEN].copy_from_slice(&crc.to_le_bytes());
    let level_count = u16::from_le_bytes([stream[14], stream[15]]) as usize;
    let table_end = if stream[10] & 8 != 0 {
        let table_len = u32::from_le_bytes(stream[28..32].try_into().ok()?);
        (HEADER_LEN + table_len as usize).saturating_sub(4)
    } else {
        HEADER_LEN + ENTRY * level_count
    };
    if stream.len() < table_end + 4 || table_end < HEADER_LEN {
        return None;
    }
    let crc = crc32(&stream[HEADER_LEN..table_end]);
    stream[table_end..table_end + 4].copy_from_slice(&crc.to_le_bytes());
    Some(table_end)
}

/// Each level's offset and length from a compact table's entries (SPEC
/// §4.3), as far as they can be read; level 0 starts at `head_len`.
fn compact_ranges(entries: &[u8], level_count: usize, head_len: u64) -> Vec<(u64, u64)> {
    let varint = |at: &mut usize| -> Option<u32> {
        let mut v = 0u32;
        for i in 0..5 {
            let b = *entries.get(*at)?;
            *at += 1;
            v |= u32::from(b & 0x7F).checked_shl(7 * i)?;
            if b & 0x80 == 0 {
                return Some(v);
            }
        }
        None
    };
    let mut at = 0;
    let mut ranges = Vec::new();
    let mut offset = head_len;
    for _ in 0..level_count {
        let Some(length) = varint(&mut at) else { break };
        if (0..3).any(|_| varint(&mut at).is_none()) {
            break;
        }
        ranges.push((offset, length as u64));
        offset += length as u64;
        // The entry's geometric error.
        at += 4;
    }
    ranges
}

/// Where each directory entry's CRC lies and its `stored_len`, and where
/// the level header's CRC lies, in a fixed-framing level (SPEC §5.1);
/// `None` where the header runs past the level.
fn fixed_layout(level: &[u8], is_base: bool) -> Option<(Vec<(usize, usize)>, usize)> {
    const CHUNK: usize = 16;
    let rd32 = |at: usize| -> Option<u32> {
        Some(u32::from_le_bytes(
            level.get(at..at.checked_add(4)?)?.try_into().ok()?,
        ))
    };
    let (rounds, chunks) = (rd32(0)?, rd32(4)?);
    // Split counts start at H = 20 in level 0 (after the policy bytes and
    // seed counts), 12 elsewhere (SPEC §5.1).
    let h = if is_base { 20 } else { 12 };
    let dir = (rounds as usize).checked_mul(4)?.checked_add(h)?;
    let crc_at = (chunks as usize).checked_mul(CHUNK)?.checked_add(dir)?;
    if level.len() < crc_at.checked_add(4)? {
        return None;
    }
    let entries = (0..chunks as usize)
        .map(|c| {
            let e = dir + CHUNK * c;
            (e + 12, rd32(e + 8).unwrap_or(0) as usize)
        })
        .collect();
    Some((entries, crc_at))
}

/// [`fixed_layout`] for a compact-framing level (SPEC §5.1.1): its
/// varints read leniently (any 1 to 5 bytes), since only the CRCs'
/// places matter here.
fn compact_layout(level: &[u8], is_base: bool) -> Option<(Vec<(usize, usize)>, usize)> {
    let mut at = 0usize;
    let varint = |at: &mut usize| -> Option<u32> {
        let mut v = 0u32;
        for i in 0..5 {
            let b = *level.get(*at)?;
            *at += 1;
            v |= u32::from(b & 0x7F).checked_shl(7 * i).unwrap_or(0);
            if b & 0x80 == 0 {
                break;
            }
        }
        Some(v)
    };
    let rounds = varint(&mut at)?;
    let chunks = varint(&mut at)?;
    at += 4;
    if is_base {
        varint(&mut at)?;
        varint(&mut at)?;
    }
    for _ in 0..rounds {
        varint(&mut at)?;
    }
    let mut entries = Vec::new();
    for _ in 0..chunks {
        at += 1;
        varint(&mut at)?;
        let stored = varint(&mut at)? as usize;
        entries.push((at, stored));
        at += 4;
    }
    if level.len() < at.checked_add(4)? {
        return None;
    }
    Some((entries, at))
}
