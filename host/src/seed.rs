//! Hashing and seeding for the whole host: one home for the bit-level functions that
//! seeds, splits and priors are derived from, below every stage that uses them
//! (`dataset` seeds each image's generator, `eval` splits frames and jitters priors).
//!
//! Every output of the host (dataset bytes, the tune/test split, the jittered priors)
//! depends on these exact bits: change them and every rendered dataset and table moves.
//! The flight core has its own generator (`tirroi_core::sensor::rng`), left alone.

/// The SplitMix64 increment (the 64-bit golden-ratio constant).
const GOLDEN_GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// 64-bit FNV-1a hash of `bytes` (offset basis 0xcbf29ce484222325, prime 0x100000001b3).
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// The SplitMix64 finaliser: a bijection that spreads every input bit over the output.
pub fn splitmix64_finalise(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// One full SplitMix64 step of state `z`: the golden-ratio increment, then
/// [`splitmix64_finalise`]. Decorrelates seeds derived from (seed, index) pairs.
pub fn splitmix64(z: u64) -> u64 {
    splitmix64_finalise(z.wrapping_add(GOLDEN_GAMMA))
}

/// One step of the short hash stream behind the jittered tracking priors
/// (`eval::scoring::jittered_prior`): `h ^= h >> 29`, then a multiply by SplitMix64's
/// first finaliser constant. Returns the new state, which is also the output.
pub fn stir(h: u64) -> u64 {
    let h = h ^ (h >> 29);
    h.wrapping_mul(0xBF58_476D_1CE4_E5B9)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a64_matches_published_vectors() {
        assert_eq!(fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x8594_4171_f739_67e8);
    }

    #[test]
    fn splitmix64_matches_the_reference_stream() {
        // Reference SplitMix64 from state 0: the first output is mix(0 + gamma).
        assert_eq!(splitmix64(0), 0xE220_A839_7B1D_CDAF);
        assert_eq!(splitmix64_finalise(0), 0);
    }
}
