//! The canonical state hash (SPEC §8): 64-bit FNV-1a over a byte-exact
//! serialisation of the normative state, compared after every round by the
//! conformance suite.

use crate::state::MeshState;

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;

/// Incremental 64-bit FNV-1a.
#[derive(Clone, Copy, Debug)]
pub struct Fnv1a(u64);

impl Default for Fnv1a {
    fn default() -> Self {
        Fnv1a(FNV_OFFSET)
    }
}

impl Fnv1a {
    #[inline]
    pub fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(FNV_PRIME);
        }
    }

    #[inline]
    pub fn u32(&mut self, v: u32) {
        self.bytes(&v.to_le_bytes());
    }

    pub fn finish(&self) -> u64 {
        self.0
    }
}

impl MeshState<'_> {
    /// The state hash of SPEC §8: vertex count, triangle count, then per
    /// vertex its x, y, z and deficit, then per triangle its three corners.
    pub fn state_hash(&self) -> u64 {
        let mut h = Fnv1a::default();
        h.u32(self.vertex_count);
        h.u32(self.triangle_count);
        for (p, &d) in self.positions().iter().zip(self.deficits()) {
            h.u32(p[0]);
            h.u32(p[1]);
            h.u32(p[2]);
            h.bytes(&[d]);
        }
        for &v in self.indices() {
            h.u32(v);
        }
        h.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::Fnv1a;

    #[test]
    fn fnv1a_reference_values() {
        let mut h = Fnv1a::default();
        assert_eq!(h.finish(), 0xcbf29ce484222325);
        h.bytes(b"a");
        assert_eq!(h.finish(), 0xaf63dc4c8601ec8c);
        let mut h = Fnv1a::default();
        h.bytes(b"foobar");
        assert_eq!(h.finish(), 0x85944171f73967e8);
    }
}
