//! Stable content hashes that key cached and resumed work: a result may be reused only when
//! every input that made it hashes the same.

/// 64-bit FNV-1a: a stable hash (std's hasher may change between releases).
pub fn fnv1a(bytes: &[u8]) -> u64 {
    fnv1a_on(FNV1A_BASIS, bytes)
}

/// FNV-1a's offset basis: the hash of nothing.
pub const FNV1A_BASIS: u64 = 0xcbf2_9ce4_8422_2325;

/// FNV-1a of `earlier`'s bytes followed by `bytes`, given `hash`, the hash of `earlier`: a file
/// that only grows is hashed one append at a time.
pub fn fnv1a_on(hash: u64, bytes: &[u8]) -> u64 {
    bytes
        .iter()
        .fold(hash, |h, &b| (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3))
}

/// A hash of the running executable: any change to the renderer's or the metrics' code
/// invalidates cached ground truths and journaled runs, whichever file the change is in.
pub fn build_id() -> u64 {
    static ID: std::sync::OnceLock<u64> = std::sync::OnceLock::new();
    *ID.get_or_init(|| {
        std::env::current_exe()
            .and_then(std::fs::read)
            .map_or(0, |bytes| fnv1a(&bytes))
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn published_test_vectors() {
        // From the FNV reference test suite.
        assert_eq!(super::fnv1a(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(super::fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(super::fnv1a(b"foobar"), 0x8594_4171_f739_67e8);
        assert_eq!(super::fnv1a_on(super::fnv1a(b"foo"), b"bar"), super::fnv1a(b"foobar"));
    }
}
