//! A stable hash that identifies input files and settings in fingerprints and model files.

/// FNV-1a 64-bit hash (stable across platforms and versions; identifies inputs, not security).
///
/// ```
/// use hpge_foundation::hash::fnv1a;
/// // The published offset basis and a published test vector (Fowler, Noll, Vo).
/// assert_eq!(fnv1a(b""), 0xcbf2_9ce4_8422_2325);
/// assert_eq!(fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
/// assert_ne!(fnv1a(b"detector a"), fnv1a(b"detector b"));
/// ```
pub fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}
