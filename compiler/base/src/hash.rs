//! FNV-1a (Fowler, Noll, Vo), 64 bits: stable across runs, versions and platforms, unlike
//! `std`'s `DefaultHasher`. Not for untrusted keys in a hash table, only for seeds and
//! names.

const OFFSET_BASIS: u64 = 0xcbf2_9ce4_8422_2325;
const PRIME: u64 = 0x0100_0000_01b3;

/// The FNV-1a hash of `bytes`.
pub fn fnv1a(bytes: impl IntoIterator<Item = u8>) -> u64 {
    fnv1a_seeded(0, bytes)
}

/// FNV-1a of `bytes` started from the offset basis mixed with `seed` (XOR), so one name
/// gives a different, stable value under each seed.
pub fn fnv1a_seeded(seed: u64, bytes: impl IntoIterator<Item = u8>) -> u64 {
    bytes.into_iter().fold(OFFSET_BASIS ^ seed, |h, b| (h ^ u64::from(b)).wrapping_mul(PRIME))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn published_test_vectors() {
        // from the FNV reference test suite
        assert_eq!(fnv1a(*b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(*b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a(*b"foobar"), 0x8594_4171_f739_67e8);
        assert_eq!(fnv1a_seeded(0, "a".bytes()), fnv1a(*b"a"));
        assert_ne!(fnv1a_seeded(1, "a".bytes()), fnv1a(*b"a"));
    }
}
