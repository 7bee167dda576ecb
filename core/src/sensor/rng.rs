//! The noise generator: xoshiro128++ (D. Blackman and S. Vigna, "Scrambled linear
//! pseudorandom number generators", ACM TOMS 47(4), 2021; reference code at
//! prng.di.unimi.it), seeded by SplitMix64 as its authors recommend. 16 bytes of state,
//! 32-bit operations only (native on a Cortex-M), the same stream on every target for a
//! seed. The noise field draws its Gaussians from it with the table-driven ziggurat of
//! [`super::gaussian`] (one 32-bit draw and no libm for 97 % of deviates);
//! [`Xoshiro128pp::gaussian_pair`] (Box–Muller, two libm calls per pair) is kept as a
//! simple reference generator.
//!
//! It is also the one generator of the core's tests: `core/tests/common` draws its
//! random test frames and masks from [`Xoshiro128pp::seed_from_u64`] and
//! [`Xoshiro128pp::next_u32`] (no private copy of a generator there).

/// xoshiro128++: period 2¹²⁸ − 1, passes BigCrush; 16 bytes.
#[derive(Debug, Clone)]
pub struct Xoshiro128pp {
    s: [u32; 4],
}

impl Xoshiro128pp {
    /// A generator whose state is two SplitMix64 outputs of `seed` (never all zero).
    pub fn seed_from_u64(seed: u64) -> Self {
        let mut sm = seed;
        let a = splitmix64(&mut sm);
        let b = splitmix64(&mut sm);
        let s = [a as u32, (a >> 32) as u32, b as u32, (b >> 32) as u32];
        if s == [0; 4] {
            // SplitMix64 is a bijection of its counter, so two zero outputs in a row
            // cannot happen; keep the generator valid regardless.
            return Xoshiro128pp { s: [1, 2, 3, 4] };
        }
        Xoshiro128pp { s }
    }

    /// A generator with this exact state (for known-answer tests); `None` if all zero.
    pub fn from_state(s: [u32; 4]) -> Option<Self> {
        (s != [0; 4]).then_some(Xoshiro128pp { s })
    }

    /// The next 32 random bits.
    pub fn next_u32(&mut self) -> u32 {
        let s = &mut self.s;
        let result = s[0].wrapping_add(s[3]).rotate_left(7).wrapping_add(s[0]);
        let t = s[1] << 9;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(11);
        result
    }

    /// Two independent standard normal deviates (Box–Muller, f32). u₁ ∈ (0, 1] has 24
    /// bits, so |z| ≤ √(−2 ln 2⁻²⁴) = 5.77: the tails beyond 5.77 σ (probability 8e-9)
    /// are cut.
    pub fn gaussian_pair(&mut self) -> (f32, f32) {
        const TWO_POW_M24: f32 = 1.0 / 16_777_216.0;
        let u1 = ((self.next_u32() >> 8) + 1) as f32 * TWO_POW_M24;
        let u2 = (self.next_u32() >> 8) as f32 * TWO_POW_M24;
        let radius = libm::sqrtf(-2.0 * libm::logf(u1));
        let (s, c) = libm::sincosf(core::f32::consts::TAU * u2);
        (radius * c, radius * s)
    }
}

/// SplitMix64 (G. Steele, D. Lea, C. Flood, OOPSLA 2014): one output, advancing `state`.
fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn xoshiro128pp_known_answers() {
        // The reference implementation's first outputs from state {1, 2, 3, 4}.
        let mut r = Xoshiro128pp::from_state([1, 2, 3, 4]).unwrap();
        let want = [
            641,
            1_573_767,
            3_222_811_527,
            3_517_856_514,
            836_907_274,
            4_247_214_768,
        ];
        for w in want {
            assert_eq!(r.next_u32(), w);
        }
        assert!(Xoshiro128pp::from_state([0; 4]).is_none());
    }

    #[test]
    fn splitmix64_known_answer() {
        let mut s = 0;
        assert_eq!(splitmix64(&mut s), 0xe220_a839_7b1d_cdaf);
    }

    #[test]
    fn gaussians_are_bounded_and_seeded() {
        let mut a = Xoshiro128pp::seed_from_u64(7);
        let mut b = Xoshiro128pp::seed_from_u64(7);
        for _ in 0..10_000 {
            let (x, y) = a.gaussian_pair();
            assert_eq!((x, y), b.gaussian_pair());
            assert!(x.abs() <= 5.8 && y.abs() <= 5.8);
        }
    }
}
