//! Stage 2b, **the saturated blob first**: before the cell classifier, the frame is
//! searched whole for pixels at the top DN. A target far above the camera's range
//! (the detection gain) saturates as one solid blob with a sharp drop to the
//! background around it; the Earth clipped at the top DN (the radiometry gain over
//! warm clear sky) saturates as ragged plateaus with holes, bright surroundings and
//! more clipped pixels elsewhere. The largest blob (8-connected 8×8 cells holding
//! pixels at the top DN, [`saturated_counts`]) is rated by a logistic model of P(hit)
//! over five statistics of it ([`BlobStats`], weights `blob_weights.rs`, fitted on our
//! renders by `scripts/train-auto.py --blob`), a calibrated P(hit) like the
//! classifier winner's confidence; under [`super::BlobRule::Compete`] (the default) it
//! is the winner when that confidence passes the gate and is above the classifier
//! winner's, so a target that saturates only in part keeps the classifier's box with
//! its unsaturated faces, and a saturated target is not joined to unrelated
//! boundaries the classifier's component runs into.
//!
//! On family A (the development renders, seed 7001: 695 frames with a blob, 491 of
//! them a hit when taken alone) the hits are solid and sit in the background (median
//! solidity 1.000, ring depth 1.000: the cells around at the frame's median; 27 % touch
//! a side), the misses are ragged Earth plateaus and clipped hot spots of a larger
//! target (median solidity 0.667, ring depth 0.579, 78 % touch a side). Held out
//! (realistic seed 9001) the detection-close row rises 0.888 → 0.921 (½ convention),
//! detection-far 0.604 → 0.644; `docs/detectors.md` § session 27 has every set.

use super::blob_weights;
use super::cells::{CELL_PX, cell_plane};
use super::features::log_code;
use crate::frame::Frame;
use crate::roi::plane::Window;

/// Fewest pixels at the top DN in the frame for the stage to run: a 2×2 core (hot
/// pixels come alone), as [`super::saturated::MIN_BLOB_PX`].
pub const MIN_FRAME_SATURATED_PX: u32 = super::saturated::MIN_BLOB_PX;

/// Number of the blob model's features ([`BlobStats::features`]).
pub const BLOB_FEATURES: usize = 6;

// The generated weights match the features (a retrain with another count fails here).
const _: () = assert!(blob_weights::WEIGHTS.len() == BLOB_FEATURES);

/// From this many sides touched a blob is rated as its own class
/// ([`BlobStats::features`]): on family A no realistic blob touching 3 or 4 sides was a
/// hit (0 of 65: the Earth's disc clipped at the top DN), but the sides' linear weight
/// alone let a large enough one pass (its size's weight outgrew it).
pub const MANY_SIDES: u8 = 3;

/// Statistics of the largest saturated blob of a frame (the blob model's inputs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct BlobStats {
    /// Pixels at the top DN in the blob's cells.
    pub saturated_px: u32,
    /// Solidity, ‰: those pixels over the pixels between the first and the last of
    /// them on each row of the blob's cell box (1000: no gap on any row).
    pub solid_permille: u16,
    /// How far below the top DN the cells around the blob lie, ‰ of the frame's
    /// median cell below the top DN (1000: at the median; 0: at the top), capped at
    /// 2000: the mean DN of the 8-neighbour cells of the blob that hold no pixel at the
    /// top DN (the blob's whole surroundings when it touches others).
    pub ring_depth_permille: u16,
    /// Pixels at the top DN elsewhere in the frame, ‰ of the blob's (saturating).
    pub other_permille: u32,
    /// Sides of the frame the blob's cell box touches (0..=4).
    pub sides: u8,
}

impl BlobStats {
    /// The blob model's integer features: log code of the saturated pixels − 1, the
    /// solidity ‰, the ring's depth ‰, log code of the other saturated pixels ‰, the
    /// sides touched, and 1 from [`MANY_SIDES`] sides (else 0).
    pub fn features(&self) -> [i32; BLOB_FEATURES] {
        [
            log_code(self.saturated_px.saturating_sub(1)),
            i32::from(self.solid_permille),
            i32::from(self.ring_depth_permille),
            log_code(self.other_permille),
            i32::from(self.sides),
            i32::from(self.sides >= MANY_SIDES),
        ]
    }

    /// P(hit) of the blob as the winner, ‰: the logistic of the fitted weights
    /// (`blob_weights.rs`, 4096 per unit of log-odds) over [`Self::features`].
    pub fn score_permille(&self) -> u16 {
        super::weighted_logistic_permille(
            &self.features(),
            &blob_weights::WEIGHTS,
            blob_weights::BIAS,
        )
    }
}

/// Writes the number of pixels at the frame's top DN of every 8×8 cell of `win` into
/// `counts` (row-major, `pw × ph` cells; 0..=64) and returns the frame's total. Cells
/// beyond `counts` are not counted (no panic path).
pub(crate) fn saturated_counts(frame: &Frame<'_>, win: Window, counts: &mut [u8]) -> u32 {
    let top = frame.max_dn();
    let (pw, ph) = cell_plane(win);
    let n = pw * ph;
    let counts = match counts.get_mut(..n) {
        Some(c) => c,
        None => return 0,
    };
    counts.fill(0);
    let mut total = 0u32;
    for dy in 0..win.h {
        let Some(row) = frame
            .row(win.y0 + dy)
            .and_then(|r| r.get(win.x0..win.x0 + win.w))
        else {
            continue;
        };
        let Some(cell_row) = counts.get_mut((dy / CELL_PX) * pw..(dy / CELL_PX + 1) * pw) else {
            continue;
        };
        for (chunk, c) in row.chunks(CELL_PX).zip(cell_row.iter_mut()) {
            let k = chunk.iter().filter(|&&v| v >= top).count() as u8;
            *c += k;
            total += u32::from(k);
        }
    }
    total
}

/// The statistics of the blob whose cells `labels[i] != 0 && find(labels[i]) == root`
/// picks (`is_member(i)`), given the cells' saturated `counts`, their `mean_dn`, the
/// frame's median cell mean `p50` and total saturated pixels `total`. `cell_box` is the
/// blob's cell box (x0, y0, x_last, y_last).
#[allow(clippy::too_many_arguments)] // the planes of one stage, each named
pub(crate) fn blob_stats(
    frame: &Frame<'_>,
    win: Window,
    counts: &[u8],
    mean_dn: &[u16],
    p50: u16,
    total: u32,
    cell_box: (usize, usize, usize, usize),
    is_member: impl Fn(usize) -> bool,
) -> BlobStats {
    let (pw, ph) = cell_plane(win);
    let top = frame.max_dn();
    let (bx0, by0, bx1, by1) = cell_box;
    let mut saturated_px = 0u32;
    let (mut ring_sum, mut ring_n) = (0u64, 0u64);
    // The blob's cells lie in its box and its ring in the box grown by one cell: only
    // those cells are visited (a hot pixel's blob costs a few cells, not the plane).
    for cy in by0.saturating_sub(1)..=(by1 + 1).min(ph.saturating_sub(1)) {
        for cx in bx0.saturating_sub(1)..=(bx1 + 1).min(pw.saturating_sub(1)) {
            let i = cy * pw + cx;
            if is_member(i) {
                saturated_px += u32::from(counts.get(i).copied().unwrap_or(0));
                continue;
            }
            if counts.get(i).copied().unwrap_or(0) != 0 {
                continue;
            }
            // A cell with no pixel at the top DN next to the blob: its ring.
            let near = (cy.saturating_sub(1)..=(cy + 1).min(ph - 1)).any(|ny| {
                (cx.saturating_sub(1)..=(cx + 1).min(pw - 1)).any(|nx| is_member(ny * pw + nx))
            });
            if near {
                ring_sum += u64::from(mean_dn.get(i).copied().unwrap_or(top));
                ring_n += 1;
            }
        }
    }
    // Solidity: per row of the blob's cell box, the saturated pixels over the span
    // from the first to the last of them.
    let (x_from, x_to) = (
        win.x0 + bx0 * CELL_PX,
        (win.x0 + (bx1 + 1) * CELL_PX).min(win.x0 + win.w),
    );
    let (y_from, y_to) = (
        win.y0 + by0 * CELL_PX,
        (win.y0 + (by1 + 1) * CELL_PX).min(win.y0 + win.h),
    );
    let (mut inside, mut span) = (0u64, 0u64);
    for y in y_from..y_to {
        let Some(row) = frame.row(y).and_then(|r| r.get(x_from..x_to)) else {
            continue;
        };
        // The first and the last saturated pixel from either end (each scan stops
        // there), then the count between them, where all of the row's lie: on the
        // M7 this is cheaper than one scan that updates all three per pixel
        // (`holes-3`, a whole-frame blob: 34.14 M against 35.22 M per call).
        let first = row.iter().position(|&v| v >= top);
        let last = row.iter().rposition(|&v| v >= top);
        if let (Some(a), Some(b)) = (first, last) {
            span += (b - a + 1) as u64;
            inside +=
                row.get(a..=b)
                    .map_or(0, |r| r.iter().filter(|&&v| v >= top).count()) as u64;
        }
    }
    let solid_permille = (inside * 1000 / span.max(1)).min(1000) as u16;
    // Without a ring (the blob fills the frame), the ring is at the top: depth 0.
    let ring_mean = ring_sum.checked_div(ring_n).unwrap_or(u64::from(top));
    let depth = u64::from(top).saturating_sub(ring_mean);
    let median_depth = u64::from(top.saturating_sub(p50)).max(1);
    let ring_depth_permille = (depth * 1000 / median_depth).min(2000) as u16;
    let other = total.saturating_sub(saturated_px);
    let other_permille =
        (u64::from(other) * 1000 / u64::from(saturated_px.max(1))).min(u64::from(u32::MAX)) as u32;
    let sides =
        u8::from(bx0 == 0) + u8::from(by0 == 0) + u8::from(bx1 + 1 >= pw) + u8::from(by1 + 1 >= ph);
    BlobStats {
        saturated_px,
        solid_permille,
        ring_depth_permille,
        other_permille,
        sides,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate std;
    use std::vec::Vec;

    const W: usize = 80;
    const H: usize = 56;
    const TOP: u16 = 4095;
    const BACKGROUND: u16 = 900;

    /// A 12-bit frame at `BACKGROUND` with the pixels `sat(x, y)` at the top DN.
    fn frame_with(sat: impl Fn(usize, usize) -> bool) -> Vec<u16> {
        (0..W * H)
            .map(|i| if sat(i % W, i / W) { TOP } else { BACKGROUND })
            .collect()
    }

    /// Counts per 8×8 cell against a brute-force count of every pixel at the top DN.
    #[test]
    fn counts_match_a_brute_force_count() {
        let sat = |x: usize, y: usize| (x * 7 + y * 13) % 11 == 0 || (30..41).contains(&x);
        let px = frame_with(sat);
        let frame = Frame::new(&px, W, H, 12).unwrap();
        let (pw, ph) = (W.div_ceil(CELL_PX), H.div_ceil(CELL_PX));
        let mut counts = std::vec![0u8; pw * ph];
        let total = saturated_counts(&frame, Window::full(&frame), &mut counts);
        let mut brute = 0u32;
        for cy in 0..ph {
            for cx in 0..pw {
                let mut n = 0u8;
                for y in cy * 8..(cy * 8 + 8).min(H) {
                    for x in cx * 8..(cx * 8 + 8).min(W) {
                        n += u8::from(sat(x, y));
                    }
                }
                assert_eq!(counts[cy * pw + cx], n, "cell ({cx}, {cy})");
                brute += u32::from(n);
            }
        }
        assert_eq!(total, brute);
        // A plane too small: nothing counted, no panic.
        assert_eq!(
            saturated_counts(&frame, Window::full(&frame), &mut counts[..3]),
            0
        );
    }

    /// The statistics of a blob against their definitions, worked by hand: a solid
    /// 12×10 block inside the frame, then the same block with a 2-px gap in each row
    /// and a lone saturated pixel elsewhere, then a block on the frame's corner.
    #[test]
    fn blob_statistics_follow_their_definitions() {
        let (pw, ph) = (W.div_ceil(CELL_PX), H.div_ceil(CELL_PX));
        let stats = |sat: &dyn Fn(usize, usize) -> bool, cells: &[(usize, usize)]| {
            let px = frame_with(sat);
            let frame = Frame::new(&px, W, H, 12).unwrap();
            let win = Window::full(&frame);
            let mut counts = std::vec![0u8; pw * ph];
            let total = saturated_counts(&frame, win, &mut counts);
            let member = |i: usize| cells.contains(&(i % pw, i / pw));
            let bx0 = cells.iter().map(|c| c.0).min().unwrap();
            let by0 = cells.iter().map(|c| c.1).min().unwrap();
            let bx1 = cells.iter().map(|c| c.0).max().unwrap();
            let by1 = cells.iter().map(|c| c.1).max().unwrap();
            // Every cell at the background but the saturated ones (their mean is not
            // read: only cells without a pixel at the top DN make the ring).
            let mean_dn = std::vec![BACKGROUND; pw * ph];
            blob_stats(
                &frame,
                win,
                &counts,
                &mean_dn,
                BACKGROUND,
                total,
                (bx0, by0, bx1, by1),
                member,
            )
        };
        // Block x 20..32, y 18..28: cells x 2..=3, y 2..=3.
        let block = |x: usize, y: usize| (20..32).contains(&x) && (18..28).contains(&y);
        let cells = [(2, 2), (3, 2), (2, 3), (3, 3)];
        let s = stats(&block, &cells);
        assert_eq!(s.saturated_px, 120);
        assert_eq!(s.solid_permille, 1000);
        // The ring at the median: depth (top − ring) / (top − median) = 1.
        assert_eq!(s.ring_depth_permille, 1000);
        assert_eq!((s.other_permille, s.sides), (0, 0));
        // A 2-px gap (x 25, 26) in every row and one pixel elsewhere: per row 10 of
        // a 12-px span saturated; the other pixel is 1 of 100.
        let gapped =
            |x: usize, y: usize| (block(x, y) && !(25..27).contains(&x)) || (x, y) == (70, 50);
        let s = stats(&gapped, &cells);
        assert_eq!(s.saturated_px, 100);
        assert_eq!(s.solid_permille, 10 * 1000 / 12);
        assert_eq!(s.other_permille, 1000 / 100);
        // On the frame's corner: two sides; the ring is the three cells around.
        let corner = |x: usize, y: usize| x < 8 && y < 8;
        let s = stats(&corner, &[(0, 0)]);
        assert_eq!(
            (s.saturated_px, s.sides, s.ring_depth_permille),
            (64, 2, 1000)
        );
    }

    /// The model's features are the statistics as documented, and its confidence is
    /// a logistic: a solid blob in the background rates above even odds, a ragged one on
    /// two sides (family A's median miss) and the Earth's disc on three below.
    #[test]
    fn the_confidence_ranks_a_solid_blob_above_a_ragged_plateau() {
        let solid = BlobStats {
            saturated_px: 300,
            solid_permille: 1000,
            ring_depth_permille: 1000,
            other_permille: 0,
            sides: 0,
        };
        let ragged = BlobStats {
            saturated_px: 800,
            solid_permille: 667,
            ring_depth_permille: 579,
            other_permille: 2,
            sides: 2,
        };
        assert_eq!(solid.features()[1..], [1000, 1000, log_code(0), 0, 0]);
        // Three sides: the many-sides term as well; a large solid blob touching three
        // sides (the Earth's disc clipped) is rated below even odds.
        let disc = BlobStats {
            saturated_px: 44_707,
            solid_permille: 931,
            ring_depth_permille: 2000,
            other_permille: 1,
            sides: 3,
        };
        assert_eq!(disc.features()[4..], [3, 1]);
        assert!(disc.score_permille() < 500, "{}", disc.score_permille());
        assert!(solid.score_permille() > 800, "{}", solid.score_permille());
        assert!(ragged.score_permille() < 500, "{}", ragged.score_permille());
        assert!(solid.score_permille() <= 1000);
    }
}
