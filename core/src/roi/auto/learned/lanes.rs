//! Pixel pairs: two 16-bit lanes in a 32-bit word, for the cell plane's pass over every
//! pixel ([`super::cells`]). On a Cortex-M4/M7 (`target_feature = "dsp"`: the Armv7E-M
//! DSP extension) a lane operation is one or two instructions on both pixels at once
//! (`usub16` sets a flag per lane, `sel` picks per lane); elsewhere the same operations
//! lane by lane in plain integer code (the host, and the test of the lane form against
//! the per-pixel one).
//!
//! **The core's only `unsafe`**: `core::arch::asm!`, which has no safe form. Each block
//! is register arithmetic alone: it reads and writes no memory and no stack
//! (`nostack`), and the GE flags `usub16` sets are read by the `sel` of the same block
//! only. The blocks are deliberately not marked `pure, nomem`: as opaque operations
//! free to move, the compiler hoisted every pixel load of a cell above them and spilled
//! the words to the stack (8.32 M instructions per `auto-v2` call against 8.02 M).
//! Measured reason for the assembly: on the emulated Cortex-M7 the cell plane took 23
//! instructions per pixel, 31 % of an `auto-v2` call (`scripts/m7-profile.sh`, session
//! 48), and `auto-v2` fell from 8.62 M to 7.42 M instructions per call with it
//! (`docs/flight.md` § Session 48). The inputs and outputs are whole words.

/// The pair `(lo, hi)` as one word: `lo` in bits 0–15, `hi` in bits 16–31 (the order of
/// two neighbouring pixels of a row in little-endian memory).
#[inline(always)]
pub fn pair(lo: u16, hi: u16) -> u32 {
    u32::from(lo) | (u32::from(hi) << 16)
}

/// The lanes of `w`: `(lo, hi)`.
#[inline(always)]
pub fn split(w: u32) -> (u16, u16) {
    (w as u16, (w >> 16) as u16)
}

/// Lane by lane, the larger of `a` and `b` (unsigned 16-bit lanes).
#[inline(always)]
pub fn max(a: u32, b: u32) -> u32 {
    #[cfg(all(target_arch = "arm", target_feature = "dsp"))]
    {
        let r: u32;
        // SAFETY: register arithmetic only (see the module): `usub16` sets GE per lane
        // where a ≥ b, `sel` takes a's lane there and b's elsewhere.
        #[allow(unsafe_code)]
        unsafe {
            core::arch::asm!(
                "usub16 {r}, {a}, {b}",
                "sel {r}, {a}, {b}",
                a = in(reg) a,
                b = in(reg) b,
                r = out(reg) r,
                options(nostack),
            );
        }
        r
    }
    #[cfg(not(all(target_arch = "arm", target_feature = "dsp")))]
    {
        let ((a0, a1), (b0, b1)) = (split(a), split(b));
        pair(a0.max(b0), a1.max(b1))
    }
}

/// One pair of the cell plane's pass, lane by lane (unsigned 16-bit lanes): `steps`
/// becomes the largest of itself, `|l − r|` and `|u − d|` (the two-pixel steps across,
/// `l` and `r` the pixels left and right of the pair, and down, `u` and `d` above and
/// below), `top` the larger of itself and the pair `m` ([`max`]), and `sum` adds both of
/// `m`'s pixels (modulo 2³², as the instructions add; a cell's sum never comes near it).
/// One block of instructions on a Cortex-M4/M7 (so the compiler keeps the
/// pair in a register instead of its two pixels for the sum).
#[inline(always)]
pub fn pair_step(
    (steps, sum, top): (u32, u32, u32),
    (l, r): (u32, u32),
    (u, m, d): (u32, u32, u32),
) -> (u32, u32, u32) {
    #[cfg(all(target_arch = "arm", target_feature = "dsp"))]
    {
        let (mut steps, mut sum, mut top) = (steps, sum, top);
        // SAFETY: register arithmetic only (see the module). Per lane: `usub16 x, a, b`
        // gives a − b and sets GE where a ≥ b, so after `usub16 y, b, a`, `sel x, y, x`
        // takes b − a where b ≥ a and a − b elsewhere: |a − b|. The larger of two lanes
        // by `usub16` + `sel` again; `uxtah` adds the low lane zero-extended, `add …,
        // lsr #16` the high one.
        #[allow(unsafe_code)]
        unsafe {
            core::arch::asm!(
                "usub16 {h}, {l}, {r}",
                "usub16 {t}, {r}, {l}",
                "sel {h}, {t}, {h}",
                "usub16 {v}, {u}, {d}",
                "usub16 {t}, {d}, {u}",
                "sel {v}, {t}, {v}",
                "usub16 {t}, {h}, {v}",
                "sel {h}, {h}, {v}",
                "usub16 {t}, {h}, {steps}",
                "sel {steps}, {h}, {steps}",
                "uxtah {sum}, {sum}, {m}",
                "add {sum}, {sum}, {m}, lsr #16",
                "usub16 {t}, {m}, {top}",
                "sel {top}, {m}, {top}",
                l = in(reg) l,
                r = in(reg) r,
                u = in(reg) u,
                m = in(reg) m,
                d = in(reg) d,
                steps = inout(reg) steps,
                sum = inout(reg) sum,
                top = inout(reg) top,
                h = out(reg) _,
                v = out(reg) _,
                t = out(reg) _,
                options(nostack),
            );
        }
        (steps, sum, top)
    }
    #[cfg(not(all(target_arch = "arm", target_feature = "dsp")))]
    {
        let ((b0, b1), (l0, l1), (r0, r1)) = (split(steps), split(l), split(r));
        let ((u0, u1), (d0, d1)) = (split(u), split(d));
        (
            pair(
                b0.max(l0.abs_diff(r0)).max(u0.abs_diff(d0)),
                b1.max(l1.abs_diff(r1)).max(u1.abs_diff(d1)),
            ),
            sum.wrapping_add(m & 0xffff).wrapping_add(m >> 16),
            max(top, m),
        )
    }
}

/// Whether [`max`] and [`pair_step`] run as the DSP extension's instructions on this
/// build (`true` on a Cortex-M4/M7 build), else lane by lane.
pub const DSP: bool = cfg!(all(target_arch = "arm", target_feature = "dsp"));

/// Checks [`max`] and [`pair_step`] as this build runs them (the DSP
/// instructions on a Cortex-M4/M7) against the same arithmetic on each lane alone
/// (`u16::abs_diff`, `u16::max`, the two pixels added), on `words` pseudo-random pairs
/// (a fixed xorshift32 stream, 16-bit values over the whole range, every fourth word
/// from edge values: 0, 1, 2^14 − 1, 2^15 − 1, 2^15, 2^16 − 1). True when every result
/// is equal. The flight demo runs it first on every target (`firmware`), where no unit
/// test runs.
pub fn self_check(words: u32) -> bool {
    const EDGES: [u16; 6] = [0, 1, 0x3fff, 0x7fff, 0x8000, 0xffff];
    let mut state = 0x1a4e_5eedu32;
    let mut draw = |k: u32| -> u32 {
        let mut lane = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            if k % 4 == 0 {
                EDGES[(state % EDGES.len() as u32) as usize]
            } else {
                state as u16
            }
        };
        pair(lane(), lane())
    };
    let mut ok = true;
    for k in 0..words {
        let [best, l, r, u, m, d, sum] = [0u32; 7].map(|_| draw(k));
        // Each lane alone: its step (the largest of best, |l − r|, |u − d|) and top.
        let lane = |shift: u32| {
            let at = |w: u32| (w >> shift) as u16;
            (
                at(best)
                    .max(at(l).abs_diff(at(r)))
                    .max(at(u).abs_diff(at(d))),
                at(best).max(at(m)),
            )
        };
        let ((s0, t0), (s1, t1)) = (lane(0), lane(16));
        let (m0, m1) = split(m);
        let want_sum = sum.wrapping_add(u32::from(m0)).wrapping_add(u32::from(m1));
        ok &= max(best, m) == pair(t0, t1);
        ok &= pair_step((best, sum, best), (l, r), (u, m, d))
            == (pair(s0, s1), want_sum, pair(t0, t1));
    }
    ok
}

#[cfg(test)]
mod tests {
    /// On the host the lane operations are the lane-by-lane code: the check's own
    /// reference agrees with it, so a failing check on a Cortex-M build (the flight
    /// demo's first step) points at the DSP instructions, not at the reference.
    #[test]
    fn lane_operations_pass_their_self_check() {
        assert!(super::self_check(50_000));
    }
}
