//! What the fuzz targets share: reading their parameters from the input.

/// The fuzz input, read a value at a time; zeros once it runs out, so
/// every input is a complete case.
pub struct Bytes<'a>(pub &'a [u8]);

impl Bytes<'_> {
    pub fn u8(&mut self) -> u8 {
        match self.0.split_first() {
            Some((&b, rest)) => {
                self.0 = rest;
                b
            }
            None => 0,
        }
    }

    pub fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.u8(), self.u8()])
    }

    pub fn i16(&mut self) -> i16 {
        i16::from_le_bytes([self.u8(), self.u8()])
    }

    /// A float that is ordinary most of the time and anything at all
    /// (NaN, infinities, subnormals, zeros of either sign) otherwise.
    pub fn f64(&mut self, ordinary: f64) -> f64 {
        match self.u8() % 8 {
            0 => f64::from_le_bytes(std::array::from_fn(|_| self.u8())),
            1 => [
                0.0,
                -0.0,
                f64::NAN,
                f64::INFINITY,
                -1.0,
                1e-310,
                1e300,
                1e-12,
            ][self.u8() as usize % 8],
            _ => ordinary * (1 + self.u8() as u32 % 16) as f64,
        }
    }

    /// Whether the input is used up.
    pub fn done(&self) -> bool {
        self.0.is_empty()
    }
}
