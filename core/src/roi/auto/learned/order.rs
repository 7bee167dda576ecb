//! Order statistics without a sort or a copy: the element of index `k` of values
//! that can be read again (a closure giving a fresh iterator), by counting passes over
//! the value range ([`select_binned`], 64 bins a pass). Core's sort keeps a panic path
//! (its order-violation check) that the panic-never check flags, and the stages that
//! need a median (the body stage's ring of cells, the half-maximum cut's ring of
//! pixels, the frame's percentiles) hold no buffer to sort.

/// Bins of [`select_binned`]'s histogram passes.
const SELECT_BINS: usize = 64;

/// The element of index `k` of the sorted `values()` (all in `0..=hi`; `hi` when
/// there are fewer than `k + 1`), by histogram passes: each pass counts the values of
/// the current range into [`SELECT_BINS`] bins and keeps the bin holding the element,
/// so a range of `hi` values takes ⌈log64 hi⌉ passes (4 for a million) where bisection
/// takes ⌈log2 hi⌉ (20); a 256-byte histogram on the stack, no sort, no copy.
pub fn select_binned<I: Iterator<Item = u32>>(values: impl Fn() -> I, k: usize, hi: u32) -> u32 {
    let (mut lo, mut hi, mut k) = (0u32, hi, k);
    while lo < hi {
        let width = (u64::from(hi - lo) + 1).div_ceil(SELECT_BINS as u64).max(1);
        let mut counts = [0u32; SELECT_BINS];
        for v in values() {
            if (lo..=hi).contains(&v) {
                // In u32 (a hardware divide on the M7; u64 is a library call): both fit,
                // `v − lo` ≤ `hi − lo` and `width` ≤ 2³² / SELECT_BINS.
                let bin = ((v - lo) / width as u32) as usize;
                if let Some(c) = counts.get_mut(bin.min(SELECT_BINS - 1)) {
                    *c += 1;
                }
            }
        }
        let mut below = 0usize;
        let mut found = false;
        for (bin, &c) in counts.iter().enumerate() {
            let c = c as usize;
            if below + c > k {
                let start = u64::from(lo) + bin as u64 * width;
                lo = start as u32;
                hi = (start + width - 1).min(u64::from(hi)) as u32;
                k -= below;
                found = true;
                break;
            }
            below += c;
        }
        if !found {
            return hi;
        }
        if width == 1 {
            return lo;
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

    /// Against a sort (and `hi` past the last value), over value ranges from one value
    /// to the whole u32 range, on both sides of a bin width.
    #[test]
    fn select_binned_equals_a_sort() {
        let mut r = rng(5);
        for n in [1usize, 2, 7, 100, 257, 1271] {
            for hi in [0u32, 1, 63, 64, 65, 1000, 65_535, 1 << 20, u32::MAX] {
                let vals: Vec<u32> = (0..n).map(|_| r() % hi.saturating_add(1).max(1)).collect();
                let mut sorted = vals.clone();
                sorted.sort_unstable();
                for k in [0, n / 2, n - 1, n, n + 3] {
                    let want = sorted.get(k).copied().unwrap_or(hi);
                    assert_eq!(
                        select_binned(|| vals.iter().copied(), k, hi),
                        want,
                        "n {n} hi {hi} k {k}"
                    );
                }
            }
        }
    }
}
