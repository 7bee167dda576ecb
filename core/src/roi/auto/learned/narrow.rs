//! 64-bit divisions and square roots done in 32 bits when the operands fit: the
//! Cortex-M7 divides 32-bit integers in hardware, while a 64-bit division or square
//! root is a library routine of tens of instructions. The answers are the 64-bit
//! operations' own, bit for bit (tested against them on both sides of 2³²).

/// `a / b` (`b` > 0; `b` = 0 gives 0, no panic path).
#[inline(always)]
pub fn div_u64(a: u64, b: u64) -> u64 {
    match (u32::try_from(a), u32::try_from(b)) {
        (Ok(a), Ok(b)) => u64::from(a.checked_div(b).unwrap_or(0)),
        _ => a.checked_div(b).unwrap_or(0),
    }
}

/// `a / b`, rounded toward zero like Rust's `/` (`b` = 0 gives 0, and `i64::MIN / −1`
/// saturates: no panic path).
#[inline(always)]
pub fn div_i64(a: i64, b: i64) -> i64 {
    match (i32::try_from(a), i32::try_from(b)) {
        // `i32::MIN / −1` overflows i32 but not i64: the 64-bit path below.
        (Ok(a32), Ok(b32)) if !(a32 == i32::MIN && b32 == -1) => {
            i64::from(a32.checked_div(b32).unwrap_or(0))
        }
        _ => a
            .checked_div(b)
            .unwrap_or(if b == 0 { 0 } else { i64::MAX }),
    }
}

/// `⌊√v⌋`.
#[inline(always)]
pub fn isqrt_u64(v: u64) -> u64 {
    u32::try_from(v).map_or_else(|_| v.isqrt(), |v| u64::from(v.isqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the 64-bit operations on values around every power of two (both sides
    /// of 2³¹ and 2³²), signs, and pseudo-random pairs.
    #[test]
    fn narrow_operations_equal_the_64_bit_ones() {
        let mut values = [0u64; 3 * 64 + 2];
        for k in 0..64 {
            values[3 * k] = (1u64 << k) - 1;
            values[3 * k + 1] = 1u64 << k;
            values[3 * k + 2] = (1u64 << k) + 1;
        }
        values[192] = u64::MAX;
        values[193] = 12_345;
        let mut s = 0x2545_F491_4F6C_DD1Du64;
        let mut rand = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        let mut pairs = 0u32;
        for &a in values.iter() {
            assert_eq!(isqrt_u64(a), a.isqrt(), "√{a}");
            for &b in values.iter().filter(|&&b| b > 0) {
                assert_eq!(div_u64(a, b), a / b, "{a} / {b}");
                for (sa, sb) in [(1i64, 1i64), (-1, 1), (1, -1), (-1, -1)] {
                    let (x, y) = ((a >> 1) as i64 * sa, (b >> 1) as i64 * sb);
                    if y != 0 {
                        assert_eq!(div_i64(x, y), x / y, "{x} / {y}");
                    }
                }
                pairs += 1;
            }
        }
        for _ in 0..100_000 {
            let (a, b) = (rand() >> (rand() % 64), (rand() >> (rand() % 64)).max(1));
            assert_eq!(div_u64(a, b), a / b);
            let (x, y) = (a as i64, (b as i64).max(1));
            assert_eq!(div_i64(x, y), x / y);
            assert_eq!(div_i64(-x.max(-i64::MAX), y), -x.max(-i64::MAX) / y);
            assert_eq!(isqrt_u64(a), a.isqrt());
        }
        assert_eq!(div_i64(i64::from(i32::MIN), -1), -i64::from(i32::MIN));
        assert_eq!(div_u64(5, 0), 0);
        assert_eq!(div_i64(5, 0), 0);
        assert!(pairs > 30_000);
    }
}
