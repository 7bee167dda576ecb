//! Adaptive thresholding (paper ref. \[48\]): a pixel is foreground when it exceeds the
//! mean of the square block around it by an offset.
//!
//! The block mean is exact: the block is `block × block` pixels centred on the pixel
//! and clipped to the frame (fewer pixels near the edges), and the test
//! `v > mean + offset` is evaluated as `(v − offset)·count > sum` in integers, so no
//! division and no rounding enter the mask. Block sums come from column sums over the
//! `block` rows around the current row, updated by one row in and one row out, and
//! their prefix sums along the row: scratch memory is O(width), never O(pixels).

use super::{BoxRule, DetectError, Detector, Scratch};
use crate::capacity::{ConstInit, FrameCapacity, Reference};
use crate::frame::Frame;

/// Largest block side accepted, in pixels (the whole height of a reference frame),
/// at every capacity: a window sum is at most `249² · 65 535 < 2^32`, so the wrapping
/// `u32` prefix differences are exact (a side above 255 could overflow them).
pub const MAX_BLOCK: u16 = 2 * (crate::frame::FRAME_HEIGHT as u16 / 2) + 1;

/// Parameters of the adaptive-threshold detector.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Adaptive {
    /// Side of the square block, in pixels: odd, 3..=[`MAX_BLOCK`]. Default 41
    /// (≈ 2° of the 16° field of view; a 15–50 m target spans 30–150 px).
    pub block: u16,
    /// How far above the local mean a pixel must be, in DN (may be negative).
    /// Default 64 DN (0.4 % of the 14-bit range).
    pub offset_dn: i32,
    /// Mask-to-box rule (default [`BoxRule::AllForeground`]).
    pub box_rule: BoxRule,
}

impl Default for Adaptive {
    fn default() -> Self {
        Adaptive {
            block: 41,
            offset_dn: 64,
            box_rule: BoxRule::AllForeground,
        }
    }
}

/// Adaptive thresholding's buffers at capacity `C`: one column sum per column and a
/// mask row.
#[derive(Debug, Clone)]
pub struct AdaptiveWork<C: FrameCapacity = Reference> {
    /// Sum of each column over the rows of the current block (≤ min(block, H) ·
    /// 65 535 ≤ 249 · 65 535 < 2^32).
    column_sum: C::Row<u32>,
    /// Prefix sums of `column_sum` along the row (`prefix[x]` = sum of columns < x),
    /// modulo 2^32: any window's sum (≤ 249² · 65 535 < 2^32, [`MAX_BLOCK`]) is the
    /// exact wrapping difference of two of them.
    prefix: C::RowPlus1<u32>,
    mask: C::Row<bool>,
}

impl<C: FrameCapacity> ConstInit for AdaptiveWork<C> {
    const INIT: Self = AdaptiveWork {
        column_sum: ConstInit::INIT,
        prefix: ConstInit::INIT,
        mask: ConstInit::INIT,
    };
}

/// The adaptive detector's scratch memory at capacity `C` (default 328×248).
pub type AdaptiveScratch<C = Reference> = Scratch<AdaptiveWork<C>, C>;

/// Bytes of [`AdaptiveScratch`] at 328×248 (budget: 16 KiB).
pub const SCRATCH_BYTES: usize = core::mem::size_of::<AdaptiveScratch>();

/// The parameters as `name=value` pairs separated by spaces (as in tuning reports
/// and tuned sets).
impl core::fmt::Display for Adaptive {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "block={} offset_dn={} box={}",
            self.block, self.offset_dn, self.box_rule
        )
    }
}

impl Detector for Adaptive {
    type Work<C: FrameCapacity> = AdaptiveWork<C>;
    const NAME: &'static str = "adaptive";

    fn validate(&self) -> Result<(), DetectError> {
        if self.block < 3 || self.block > MAX_BLOCK || self.block % 2 == 0 {
            return Err(DetectError::InvalidParameter {
                name: "block",
                expected: "an odd block side in 3..=249 pixels",
            });
        }
        Ok(())
    }

    fn box_rule(&self) -> BoxRule {
        self.box_rule
    }

    fn set_box_rule(&mut self, rule: BoxRule) {
        self.box_rule = rule;
    }

    /// Foreground: `DN > block mean + offset_dn`. Threshold: `offset_dn` (as `u32`,
    /// 0 when negative).
    fn foreground<C: FrameCapacity, F: FnMut(usize, &[bool])>(
        &self,
        frame: &Frame<'_>,
        work: &mut AdaptiveWork<C>,
        mut sink: F,
    ) -> u32 {
        let (w, h) = (frame.width(), frame.height());
        let r = usize::from(self.block / 2);
        let max_dn = frame.max_dn();
        let offset = i64::from(self.offset_dn);
        let col = &mut work.column_sum.as_mut()[..w];
        let mask = &mut work.mask.as_mut()[..w];
        let prefix = &mut work.prefix.as_mut()[..=w];
        prefix[0] = 0;
        // With |v − offset| ≤ max_dn + |offset| and count ≤ block², i32 suffices when
        // their product does (sums are at most count · max_dn, smaller still).
        let block_px = u64::from(self.block) * u64::from(self.block);
        let narrow = (u64::from(max_dn) + u64::from(self.offset_dn.unsigned_abs())) * block_px
            <= i32::MAX as u64;
        let row_at = |y: usize| frame.row(y).unwrap_or(&[]);

        col.fill(0);
        for y in 0..=r.min(h - 1) {
            add_row(col, row_at(y), max_dn);
        }
        for (y, row) in frame.rows().enumerate() {
            if y > 0 {
                if y + r < h {
                    add_row(col, row_at(y + r), max_dn);
                }
                if y > r {
                    sub_row(col, row_at(y - r - 1), max_dn);
                }
            }
            let rows = (y + r).min(h - 1) + 1 - y.saturating_sub(r);
            // Prefix sums of the column sums: the block sum of any clipped window is
            // one subtraction.
            let mut acc = 0u32;
            for (p, &c) in prefix[1..].iter_mut().zip(col.iter()) {
                acc = acc.wrapping_add(c);
                *p = acc;
            }
            // v > mean + offset  ⇔  (v − offset)·count > sum, exactly, in integers.
            // Columns r..w−r see the whole window: a branch-free loop over shifted
            // prefix slices. The clipped columns near the edges take the general path.
            let test = |v: u16, count: usize, sum: u32| {
                (i64::from(v.min(max_dn)) - offset) * count as i64 > sum as i64
            };
            let full = 2 * r + 1;
            let (left, interior) = if w >= full { (r, w - full + 1) } else { (w, 0) };
            let count = rows * full;
            let hi = prefix.get(full..full + interior).unwrap_or(&[]);
            // All in range (interior ≤ w − left, prefix holds w + 1); `get` keeps the
            // flight build free of panic branches, an empty slice is never taken.
            let lo = prefix.get(..interior).unwrap_or_default();
            let (mask_in, row_in) = (
                mask.get_mut(left..left + interior).unwrap_or_default(),
                row.get(left..left + interior).unwrap_or_default(),
            );
            let pixels = mask_in.iter_mut().zip(row_in).zip(hi).zip(lo);
            if narrow {
                // Every product and sum fits an i32: twice the SIMD lanes of i64.
                let (count, offset) = (count as i32, offset as i32);
                let max_dn = i32::from(max_dn);
                for (((m, &v), &p_hi), &p_lo) in pixels {
                    let sum = p_hi.wrapping_sub(p_lo) as i32;
                    *m = (i32::from(v).min(max_dn) - offset) * count > sum;
                }
            } else {
                for (((m, &v), &p_hi), &p_lo) in pixels {
                    *m = test(v, count, p_hi.wrapping_sub(p_lo));
                }
            }
            for x in (0..left).chain(left + interior..w) {
                let (lo, hi) = (x.saturating_sub(r), (x + r + 1).min(w));
                let at = |i: usize| prefix.get(i).copied().unwrap_or(0);
                let sum = at(hi).wrapping_sub(at(lo));
                if let (Some(m), Some(&v)) = (mask.get_mut(x), row.get(x)) {
                    *m = test(v, rows * (hi - lo), sum);
                }
            }
            sink(y, mask);
        }
        self.offset_dn.max(0) as u32
    }
}

/// Adds `row` (each DN clipped to `max_dn`) to the column sums `col` (shared with
/// `auto-v2`'s stage 2d, `learned::small`).
pub(crate) fn add_row(col: &mut [u32], row: &[u16], max_dn: u16) {
    for (c, &v) in col.iter_mut().zip(row) {
        *c += u32::from(v.min(max_dn));
    }
}

/// Takes `row` (each DN clipped to `max_dn`) out of the column sums `col`.
pub(crate) fn sub_row(col: &mut [u32], row: &[u16], max_dn: u16) {
    for (c, &v) in col.iter_mut().zip(row) {
        *c -= u32::from(v.min(max_dn));
    }
}
