//! What a tracker carries of its last box besides the box: the target's look, its
//! mean DN and the mean DN of the background just around it, side by side.
//! `auto-v2`'s fast tracking path ([`super::AutoV2::look`]) takes the prior's cells for
//! the target's and keeps the box it refines from them only when the place of the last
//! box still looks as it did ([`Look::matches`]: it departs from its strips the same
//! way by ½–2 times as much, its level moved by at most half the last departure) and
//! the new box stands out from the background on every side ([`Look::stands_out`]).
//! Under a wrong prior the last box's place holds other things now (background departs
//! by another amount or not at all), and a box on the limb or a cloud deck's edge has a
//! side that does not depart (`tirroi eval --track sequence` on family A's fixtures:
//! such boxes on 3 of 80 frames without a target before the side rule, none after); the
//! search then runs instead.
//!
//! A look is a sum over the box and four strips of [`RING_PX`] along its sides: each
//! pixel of the box and its strips read once, no scratch.

use crate::frame::Frame;
use crate::roi::Roi;

/// Width of the background ring around a box, px: wide enough for a mean over a few
/// dozen pixels around a 3-px far target, narrow enough to stay on the background the
/// target crosses (a wider ring reaches other clouds).
pub const RING_PX: u16 = 2;

/// The last look serves only when its box departed from its strips by at least this
/// many pixel noise σ (of the new frame's tracking window): a box that does not stand
/// out tells nothing, and the search decides. The departure is a mean over the box,
/// whose noise is σ over the square root of its pixels. Chosen on family A (seed 7001;
/// summed mean IoU change of `--track jitter` / `--track sequence` against tracking
/// without the fast path): 1 → +0.117 / −0.007, 2 → +0.108 / −0.007, 4 → +0.076 /
/// −0.007, no false alarm added at any.
pub const MIN_DEPARTURE_SIGMA: u32 = 1;

/// The departure under the last box must lie within this factor of the last one's
/// (either way, same sign): the target's contrast against the background it moves
/// over changes between frames, but not by more than twice. Family A (as
/// [`MIN_DEPARTURE_SIGMA`], in session 41's first form, the new box's look compared):
/// 2 → +0.057 / −0.007, 3 → +0.060 / −0.014.
pub const DEPARTURE_FACTOR: i64 = 2;

/// The mean DN under the last box may differ from the last one's by at most this
/// share of the last departure, ‰: the target's own level changes less than its
/// background. Family A (as [`DEPARTURE_FACTOR`]): 150 → +0.016 (jitter), 300 →
/// +0.054 / −0.012, 500 → +0.057 / −0.007, 1000 → +0.055 / −0.011.
pub const LEVEL_SHARE_PERMILLE: i64 = 500;

/// Mean DN (clamped to the frame's top DN) of the pixels of `r`, a box inside the
/// frame, and their count; `None` when it is empty.
fn mean_dn(frame: &Frame<'_>, r: Roi) -> Option<(u16, u64)> {
    let max_dn = frame.max_dn();
    let mut sum = 0u64;
    for y in r.y0..r.y1 {
        let row = frame.row(usize::from(y))?;
        let row = row.get(usize::from(r.x0)..usize::from(r.x1))?;
        // A row's sum in 32 bits (one add per pixel on the M7, not two): a frame is at
        // most `MAX_FRAME_SIDE` (65 534) px wide, so the sum stays under 65 535² < 2³²
        // and never wraps.
        let row_sum = row
            .iter()
            .fold(0u32, |s, &v| s.wrapping_add(u32::from(v.min(max_dn))));
        sum += u64::from(row_sum);
    }
    let n = u64::from(r.area());
    // `checked_div`: an empty box has no mean (and the flight build no panic path).
    Some((sum.checked_div(n)? as u16, n))
}

/// The look of a box: mean DN inside it and in the strips of [`RING_PX`] along each of
/// its sides (DN, the frame's pixels clamped to its top DN; a strip outside the frame
/// is absent; the corners belong to no strip).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Look {
    /// Mean DN of the box's pixels.
    pub level_dn: u16,
    /// Mean DN of all the strips' pixels (the ring).
    pub ring_dn: u16,
    /// Mean DN of the strip above, below, left of and right of the box, `None` where
    /// the box lies on the frame's border.
    pub side_dn: [Option<u16>; 4],
}

impl Look {
    /// The look of `roi` on `frame`; `None` when the box, cut to the frame, is empty
    /// or no strip lies inside the frame (a box of the whole frame).
    pub fn measure(frame: &Frame<'_>, roi: Roi) -> Option<Look> {
        let (fw, fh) = (frame.width() as u16, frame.height() as u16);
        let inner = roi.clip(fw, fh);
        if inner.is_empty() {
            return None;
        }
        let (level, _) = mean_dn(frame, inner)?;
        let strips = [
            Roi::new(
                inner.x0,
                inner.y0.saturating_sub(RING_PX),
                inner.x1,
                inner.y0,
            ),
            Roi::new(
                inner.x0,
                inner.y1,
                inner.x1,
                inner.y1.saturating_add(RING_PX),
            ),
            Roi::new(
                inner.x0.saturating_sub(RING_PX),
                inner.y0,
                inner.x0,
                inner.y1,
            ),
            Roi::new(
                inner.x1,
                inner.y0,
                inner.x1.saturating_add(RING_PX),
                inner.y1,
            ),
        ];
        let mut side_dn = [None; 4];
        let (mut sum, mut px) = (0u64, 0u64);
        for (side, strip) in side_dn.iter_mut().zip(strips) {
            if let Some((mean, n)) = mean_dn(frame, strip.clip(fw, fh)) {
                *side = Some(mean);
                sum += u64::from(mean) * n;
                px += n;
            }
        }
        // No strip inside the frame: no ring.
        Some(Look {
            level_dn: level,
            ring_dn: sum.checked_div(px)? as u16,
            side_dn,
        })
    }

    /// Mean DN of the box minus that of its ring (DN; negative for a target colder
    /// than its background).
    pub const fn departure_dn(&self) -> i32 {
        self.level_dn as i32 - self.ring_dn as i32
    }

    /// Whether this look (the last frame's) tells a target at all under pixel noise
    /// `sigma` (DN): the box departs by [`MIN_DEPARTURE_SIGMA`] σ or more.
    pub fn is_distinct(&self, sigma: u32) -> bool {
        i64::from(self.departure_dn()).unsigned_abs()
            >= u64::from(MIN_DEPARTURE_SIGMA) * u64::from(sigma.max(1))
    }

    /// Whether `under` (the look of the same box on this frame) is still the target
    /// this look (the last frame's) was taken of, under pixel noise `sigma` (DN): the
    /// last look is distinct, the box departs from its strips in the same direction by
    /// ½–2 times as much, and its level moved by at most [`LEVEL_SHARE_PERMILLE`] of
    /// the last departure. A target moves a few pixels between frames and stays under
    /// its last box; a wrong prior's box holds other things now.
    pub fn matches(&self, under: &Look, sigma: u32) -> bool {
        if !self.is_distinct(sigma) {
            return false;
        }
        let (last, new) = (
            i64::from(self.departure_dn()),
            i64::from(under.departure_dn()),
        );
        let same_sign = (last > 0) == (new > 0) && new != 0;
        let (a_last, a_new) = (last.abs(), new.abs());
        let level_moved = (i64::from(under.level_dn) - i64::from(self.level_dn)).abs();
        same_sign
            && a_new * DEPARTURE_FACTOR >= a_last
            && a_new <= a_last * DEPARTURE_FACTOR
            && level_moved * 1000 <= a_last * LEVEL_SHARE_PERMILLE
    }

    /// Whether this box stands out from the background on every side in the direction
    /// of `departure_dn` (its sign: hotter or colder): each strip present lies on the
    /// other side of the box's level. A target does; a box on the limb or a cloud
    /// deck's edge has a side that does not.
    pub fn stands_out(&self, departure_dn: i32) -> bool {
        departure_dn != 0
            && self.side_dn.iter().flatten().all(|&side| {
                let d = i32::from(self.level_dn) - i32::from(side);
                d != 0 && (d > 0) == (departure_dn > 0)
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 32×24 frame at `bg` with a `value` block at (10..16, 8..12).
    fn frame_with_block(bg: u16, value: u16, px: &mut [u16]) -> Frame<'_> {
        for (i, p) in px.iter_mut().enumerate() {
            let (x, y) = (i % 32, i / 32);
            *p = if (10..16).contains(&x) && (8..12).contains(&y) {
                value
            } else {
                bg
            };
        }
        Frame::new(px, 32, 24, 14).expect("a valid frame")
    }

    /// A look with every side at the ring's level.
    fn look(level_dn: u16, ring_dn: u16) -> Look {
        Look {
            level_dn,
            ring_dn,
            side_dn: [Some(ring_dn); 4],
        }
    }

    /// The look of a block's own box is its level and the background's, by hand.
    #[test]
    fn measures_the_box_and_its_strips() {
        let mut px = [0u16; 32 * 24];
        let f = frame_with_block(1000, 1400, &mut px);
        let own = Look::measure(&f, Roi::new(10, 8, 16, 12)).expect("a look");
        assert_eq!(own, look(1400, 1000));
        assert_eq!(own.departure_dn(), 400);
        // One column of background inside the box: (6·4·1400 + 4·1000) / 28; its
        // top and bottom strips hold one background and six block pixels, 2 rows.
        let wider = Look::measure(&f, Roi::new(9, 8, 16, 12)).expect("a look");
        assert_eq!(wider.level_dn, ((24 * 1400 + 4 * 1000) / 28) as u16);
        assert_eq!(wider.side_dn[0], Some(1000));
        assert_eq!(wider.side_dn[2], Some(1000));
        // A box reaching into the block from above: its bottom strip is the block's.
        let above = Look::measure(&f, Roi::new(10, 4, 16, 8)).expect("a look");
        assert_eq!(above.side_dn[1], Some(1400));
        // In the corner the strips above and left lie outside the frame.
        let corner = Look::measure(&f, Roi::new(0, 0, 3, 3)).expect("a look");
        assert_eq!(corner.side_dn[0], None);
        assert_eq!(corner.side_dn[2], None);
        assert_eq!(corner.side_dn[1], Some(1000));
        // No strip (the whole frame) and nothing inside: no look.
        assert_eq!(Look::measure(&f, Roi::new(0, 0, 32, 24)), None);
        assert_eq!(Look::measure(&f, Roi::new(40, 40, 50, 50)), None);
    }

    /// The widest frame's full-width box, every pixel at the top DN: its rows' 32-bit
    /// sums (65 534 × 65 535) do not wrap, so its level is the top DN; the strip below,
    /// at half the level, gives its own.
    #[test]
    fn the_widest_box_at_the_top_dn_keeps_its_level() {
        extern crate std;
        const W: usize = crate::frame::MAX_FRAME_SIDE;
        let mut px = std::vec![u16::MAX; W * 3];
        px[2 * W..].fill(u16::MAX / 2);
        let f = Frame::new(&px, W, 3, 16).expect("a valid frame");
        let wide = Look::measure(&f, Roi::new(0, 0, W as u16, 2)).expect("a look");
        assert_eq!(wide.level_dn, u16::MAX);
        assert_eq!(wide.side_dn[1], Some(u16::MAX / 2));
        assert_eq!(wide.ring_dn, u16::MAX / 2);
    }

    /// The same place matches itself; background, the other sign, a halved or
    /// doubled-and-more departure or a moved level do not; an indistinct look matches
    /// nothing.
    #[test]
    fn matches_only_the_same_target() {
        let last = look(1400, 1000);
        let sigma = 10;
        assert!(last.matches(&last, sigma));
        // The background moved under the target: the departure 400 → 250 and 700
        // match (within twice), 900 does not.
        assert!(last.matches(&look(1400, 1150), sigma));
        assert!(last.matches(&look(1400, 700), sigma));
        assert!(!last.matches(&look(1400, 500), sigma));
        // A patch of background: no departure; a cold target: the other sign.
        assert!(!last.matches(&look(1005, 1000), sigma));
        assert!(!last.matches(&look(600, 1000), sigma));
        // Half the departure (the boundary) matches; less does not.
        assert!(last.matches(&look(1400, 1200), sigma));
        assert!(!last.matches(&look(1400, 1201), sigma));
        // Level moved by half the last departure (200 DN) matches; by more does not.
        assert!(last.matches(&look(1600, 1200), sigma));
        assert!(!last.matches(&look(1601, 1201), sigma));
        // A look within 1 σ of its strips tells nothing.
        let faint = look(1009, 1000);
        assert!(!faint.matches(&faint, sigma));
        assert!(faint.matches(&faint, 9));
    }

    /// A box stands out when every strip present lies on the other side of its level
    /// from the departure's sign: not on an edge, not the other way, not with no sign.
    #[test]
    fn stands_out_on_every_side() {
        let hot = look(1400, 1000);
        assert!(hot.stands_out(400));
        assert!(!hot.stands_out(-400));
        assert!(!hot.stands_out(0));
        // A box on an edge: the ring departs on average, one side does not.
        let edge = Look {
            side_dn: [Some(700), Some(1400), Some(1000), Some(1000)],
            ..look(1400, 1025)
        };
        assert!(!edge.stands_out(400));
        // A side off the frame is no objection.
        let cut = Look {
            side_dn: [None, Some(1000), Some(1000), None],
            ..hot
        };
        assert!(cut.stands_out(400));
        // A cold target against warmer strips.
        assert!(look(600, 1000).stands_out(-400));
    }
}
