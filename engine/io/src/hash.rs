//! The one stable hash of weft: XXH3 with 128-bit output, the same on every
//! build and platform (std's hasher is neither). Cache entry names, cache
//! keys and payload checksums all use it.

use xxhash_rust::xxh3::Xxh3;

/// A hash over fields, each prefixed with its length so `("ab", "c")` and
/// `("a", "bc")` differ.
#[derive(Clone)]
pub struct Hasher(Xxh3);

impl Default for Hasher {
    fn default() -> Self {
        Self::new()
    }
}

impl Hasher {
    pub fn new() -> Self {
        Self(Xxh3::new())
    }

    /// Adds one field.
    pub fn field(&mut self, bytes: &[u8]) -> &mut Self {
        self.0.update(&(bytes.len() as u64).to_le_bytes());
        self.0.update(bytes);
        self
    }

    /// Adds raw bytes with no length prefix (for streams of fixed-size items).
    pub fn bytes(&mut self, bytes: &[u8]) -> &mut Self {
        self.0.update(bytes);
        self
    }

    /// The 128-bit digest.
    pub fn finish(&self) -> u128 {
        self.0.digest128()
    }
}

/// The 128-bit hash of a byte string.
pub fn hash(bytes: &[u8]) -> u128 {
    xxhash_rust::xxh3::xxh3_128(bytes)
}

/// A digest as 32 lowercase hex digits, for file names.
pub fn hex(digest: u128) -> String {
    format!("{digest:032x}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_length_prefixed_and_the_hash_is_stable() {
        let a = Hasher::new().field(b"ab").field(b"c").finish();
        let b = Hasher::new().field(b"a").field(b"bc").finish();
        assert_ne!(a, b);
        // XXH3-128 of the empty string, from the reference implementation.
        assert_eq!(hash(b""), 0x99aa06d3014798d86001c324468d497f);
        assert_eq!(hex(1).len(), 32);
    }
}
