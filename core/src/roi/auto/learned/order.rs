//! Order statistics without a sort or a copy: the element of index `k` of values
//! that can be read again (a closure giving a fresh iterator), by bisection over the
//! value range. Core's sort keeps a panic path (its order-violation check) that the
//! panic-never check flags, and the stages that need a median (the body stage's
//! ring of cells, the half-maximum cut's ring of pixels) hold no buffer to sort.

/// The smallest `v` in `0..=hi` with more than `k` of `values()` at most `v` (the
/// element of index `k` of the sorted values), by bisection: no sort, no copy.
pub fn select<I: Iterator<Item = u32>>(values: impl Fn() -> I, k: usize, hi: u32) -> u32 {
    let (mut lo, mut hi) = (0u32, hi);
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if values().filter(|&v| v <= mid).count() > k {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    lo
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate std;
    use std::vec::Vec;

    /// xorshift32, a fixed sequence.
    fn rng(seed: u32) -> impl FnMut() -> u32 {
        let mut s = seed.wrapping_mul(2_654_435_761) | 1;
        move || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            s
        }
    }

    #[test]
    fn select_equals_a_sort() {
        let mut r = rng(3);
        for n in [1usize, 2, 7, 100, 257] {
            let vals: Vec<u32> = (0..n).map(|_| r() % 70_000 % 65_536).collect();
            let mut sorted = vals.clone();
            sorted.sort_unstable();
            for k in [0, n / 2, n - 1] {
                assert_eq!(select(|| vals.iter().copied(), k, 65_535), sorted[k]);
            }
        }
    }
}
