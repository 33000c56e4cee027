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

/// A reading position in bytes read field by field: a compact level
/// header (SPEC §5.1.1) or a compact level table (§4.3). Reading past the
/// end is `Truncated`; the caller says what a broken varint is.
#[derive(Clone, Copy, Debug)]
pub struct Cursor<'b> {
    pub bytes: &'b [u8],
    pub at: usize,
}

impl<'b> Cursor<'b> {
    pub fn new(bytes: &'b [u8]) -> Self {
        Cursor { bytes, at: 0 }
    }

    pub fn byte(&mut self) -> Result<u8, Error> {
        let b = u8_at(self.bytes, self.at)?;
        self.at += 1;
        Ok(b)
    }

    pub fn u32(&mut self) -> Result<u32, Error> {
        let v = u32_at(self.bytes, self.at)?;
        self.at += 4;
        Ok(v)
    }

    pub fn f32(&mut self) -> Result<f32, Error> {
        let v = f32_at(self.bytes, self.at)?;
        self.at += 4;
        Ok(v)
    }

    /// A varint by §5.4's rules (at most 5 bytes, 32 bits, minimal); a
    /// varint breaking them is `invalid(why)`.
    pub fn varint(&mut self, invalid: fn(&'static str) -> Error) -> Result<u32, Error> {
        let mut v = 0u32;
        for i in 0..5 {
            let b = self.byte()?;
            if i == 4 && b > 0x0F {
                return Err(invalid("varint over 32 bits"));
            }
            v |= u32::from(b & 0x7F) << (7 * i);
            if b & 0x80 == 0 {
                if b == 0 && i > 0 {
                    return Err(invalid("varint not minimal"));
                }
                return Ok(v);
            }
        }
        // Unreachable: the fifth byte is at most 0x0F, so it ends the value.
        Err(invalid("varint over 32 bits"))
    }
}

/// CRC-32 (ISO-HDLC, the zlib/PNG polynomial) of `data` (SPEC §2).
pub fn crc32(data: &[u8]) -> u32 {
    let mut h = crc32fast::Hasher::new();
    h.update(data);
    h.finalize()
}
