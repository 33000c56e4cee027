//! Bounds-checked little-endian field access on borrowed input (SPEC §2).

use crate::Error;

pub fn u8_at(b: &[u8], at: usize) -> Result<u8, Error> {
    b.get(at).copied().ok_or(Error::Truncated)
}

pub fn u16_at(b: &[u8], at: usize) -> Result<u16, Error> {
    Ok(u16::from_le_bytes(array(b, at)?))
}

pub fn u32_at(b: &[u8], at: usize) -> Result<u32, Error> {
    Ok(u32::from_le_bytes(array(b, at)?))
}

pub fn u64_at(b: &[u8], at: usize) -> Result<u64, Error> {
    Ok(u64::from_le_bytes(array(b, at)?))
}

pub fn f32_at(b: &[u8], at: usize) -> Result<f32, Error> {
    Ok(f32::from_le_bytes(array(b, at)?))
}

pub fn f64_at(b: &[u8], at: usize) -> Result<f64, Error> {
    Ok(f64::from_le_bytes(array(b, at)?))
}

fn array<const N: usize>(b: &[u8], at: usize) -> Result<[u8; N], Error> {
    let end = at.checked_add(N).ok_or(Error::Truncated)?;
    let s = b.get(at..end).ok_or(Error::Truncated)?;
    let mut out = [0u8; N];
    out.copy_from_slice(s);
    Ok(out)
}

/// CRC-32 (ISO-HDLC, the zlib/PNG polynomial) of `data` (SPEC §2).
pub fn crc32(data: &[u8]) -> u32 {
    let mut h = crc32fast::Hasher::new();
    h.update(data);
    h.finalize()
}
