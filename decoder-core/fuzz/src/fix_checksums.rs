//! Checksum rewriting for byte-level fuzzing (shared with the tests).
/// Rewrites every checksum of `stream` that can be located (header, level
/// table, level headers, chunks) to match its bytes, so that byte-level
/// mutations reach the parsers and the split logic behind the CRCs.
/// Best effort: stops where the structure cannot be followed.
pub fn fix_checksums(stream: &mut [u8]) {
    use splitstream_decoder_core::crc32;
    const HEADER_LEN: usize = 96;
    const ENTRY: usize = 32;
    const CHUNK: usize = 16;
    let rd32 = |b: &[u8], at: usize| -> Option<u32> {
        Some(u32::from_le_bytes(
            b.get(at..at.checked_add(4)?)?.try_into().ok()?,
        ))
    };
    if stream.len() < HEADER_LEN {
        return;
    }
    let crc = crc32(&stream[..HEADER_LEN - 4]);
    stream[HEADER_LEN - 4..HEADER_LEN].copy_from_slice(&crc.to_le_bytes());
    let level_count = u16::from_le_bytes([stream[14], stream[15]]) as usize;
    let table_end = HEADER_LEN + ENTRY * level_count;
    if stream.len() < table_end + 4 {
        return;
    }
    let crc = crc32(&stream[HEADER_LEN..table_end]);
    stream[table_end..table_end + 4].copy_from_slice(&crc.to_le_bytes());
    for k in 0..level_count {
        let at = HEADER_LEN + ENTRY * k;
        let offset = u64::from_le_bytes(stream[at..at + 8].try_into().unwrap());
        let length = rd32(stream, at + 8).unwrap_or(0) as u64;
        let Some(end) = offset.checked_add(length) else {
            return;
        };
        if end > stream.len() as u64 {
            return;
        }
        let level = &mut stream[offset as usize..end as usize];
        let (Some(rounds), Some(chunks)) = (rd32(level, 0), rd32(level, 4)) else {
            return;
        };
        // Split counts start at H = 20 in level 0 (after the plane policy,
        // reserved bytes and seed counts), 12 elsewhere (SPEC §5.1).
        let h = if k == 0 { 20 } else { 12 };
        let Some(dir) = (rounds as usize)
            .checked_mul(4)
            .and_then(|s| s.checked_add(h))
        else {
            return;
        };
        let Some(crc_at) = (chunks as usize)
            .checked_mul(CHUNK)
            .and_then(|d| d.checked_add(dir))
        else {
            return;
        };
        if level.len() < crc_at + 4 {
            return;
        }
        let mut payload = crc_at + 4;
        for c in 0..chunks as usize {
            let e = dir + CHUNK * c;
            let stored = rd32(level, e + 8).unwrap_or(0) as usize;
            let Some(p_end) = payload.checked_add(stored) else {
                break;
            };
            if p_end > level.len() {
                break;
            }
            let crc = crc32(&level[payload..p_end]);
            level[e + 12..e + 16].copy_from_slice(&crc.to_le_bytes());
            payload = p_end;
        }
        let crc = crc32(&level[..crc_at]);
        level[crc_at..crc_at + 4].copy_from_slice(&crc.to_le_bytes());
    }
}
