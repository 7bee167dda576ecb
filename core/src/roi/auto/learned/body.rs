//! The whole body from its winning part. In radiometry mode the scale spans the
//! scene's minimum to maximum and a multi-material target has faces both hotter and
//! colder than the Earth behind it (low-emissivity parts); the region stage's winner is
//! then often only the body's brightest face (issue 16, "where v2 loses": boxes too
//! small on 39 % of realistic radiometry-close frames). This stage grows the winner's
//! 8×8 cells over the cells that depart from a local background model, either sign:
//!
//! 1. background: the median of the cell means on a ring of cells around the winner's
//!    cell box ([`BodyParams::ring_from_cells`]..=[`BodyParams::ring_to_cells`] cells
//!    out, Chebyshev distance), its spread the larger of the pixel noise σ and the
//!    ring's median absolute deviation (× 1.4826: σ of a normal law), so cloud texture
//!    raises the bar;
//! 2. growth: 8-connected cells whose mean departs from the background by at least
//!    [`BodyParams::k_sigma`] spreads, from the winner's cells;
//! 3. bounds: a growth that covers more than [`BodyParams::max_share_permille`] of the
//!    frame's cells or runs from one side of the frame to the opposite one (a cloud
//!    deck or the limb running across the frame, a border that does not close) is
//!    dropped;
//! 4. full resolution: the grown cells' box, one cell wider per side, is trimmed from
//!    each side to the first pixel column or row where at least
//!    [`BodyParams::trim_permille`] of the box's pixels across it depart from the
//!    background by the same threshold; the result is joined with the box it got.
//!
//! No buffer of its own: the marks live in a cell plane the caller owns (reused after
//! the refinement), the medians are found by binned counting passes over the value
//! range ([`super::order::select_binned`]: 3 passes over the ring, no sort, no copy;
//! 17 by bisection until session 50).

use super::cells::{CELL_PX, cell_plane};
use super::order::select_binned;
use crate::frame::Frame;
use crate::roi::Roi;
use crate::roi::plane::Window;

/// Mark of a winner cell in the plane given to [`body_box`].
pub const WINNER: u8 = 1;
/// Mark of a cell the growth added.
pub const GROWN: u8 = 2;

/// Bound on the growth's sweeps over the cell plane (alternately forward and
/// backward; a compact body is reached in 2–4): a snake that needs more is left
/// partly grown, deterministically.
pub const MAX_PASSES: usize = 32;

/// A growth ends at a step, not in a fade: the median departure of the cells just
/// outside the grown body (8-adjacent to a grown cell, not marked) must stay under
/// this share of a spread, %. A target's faces end at their outline, beyond which the
/// cells sit at the background's level (median departure 0–0.8 spread on 7 of the 8
/// paper A frames stage 6 helps most, 1.4 on the eighth); a growth through the Earth's
/// ramp stops where the ramp falls just under the bar (1.1–1.8 spreads on 4 of 5
/// overgrown real-Earth boxes looked at), the
/// "step vs ramp" rule of `auto` applied to the body. Chosen on family A (seeds
/// 7001–7201, ½ convention; docs/detectors.md § Session 69): 75 / 100 / 150 % →
/// summed mean IoU +0.0000 / +0.0013 / +0.0012 against no such test.
pub const MAX_FADE_PERCENT: u32 = 100;

/// 1.4826 (σ of a normal law per median absolute deviation), ‰.
const MAD_TO_SIGMA_PERMILLE: u32 = 1483;

/// Parameters of the stage (see the module). Chosen on family A (seed 7001:
/// realistic, paper, fixtures), docs/detectors.md § auto-v2 "the whole body".
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BodyParams {
    /// Departure from the background that marks a body cell or pixel, in spreads (σ):
    /// 0 turns the stage off, else 1..=100.
    pub k_sigma: u16,
    /// Inner edge of the background ring, cells out from the winner's cell box: 1..=8.
    pub ring_from_cells: u8,
    /// Outer edge of the background ring, cells: `ring_from_cells..=16`.
    pub ring_to_cells: u8,
    /// Largest grown body, ‰ of the frame's cells: 1..=1000.
    pub max_share_permille: u16,
    /// A pixel column (row) ends the trim when at least this share of the box's
    /// rows (columns) depart, ‰: 0..=1000 (at least 2 pixels in any case).
    pub trim_permille: u16,
}

impl BodyParams {
    /// The default (family A's choice).
    pub const DEFAULT: BodyParams = BodyParams {
        k_sigma: 3,
        ring_from_cells: 2,
        ring_to_cells: 5,
        max_share_permille: 250,
        trim_permille: 100,
    };

    /// The stage switched off.
    pub const OFF: BodyParams = BodyParams {
        k_sigma: 0,
        ..BodyParams::DEFAULT
    };

    /// True when every field is within its documented bounds.
    pub fn is_valid(&self) -> bool {
        self.k_sigma <= 100
            && (1..=8).contains(&self.ring_from_cells)
            && (self.ring_from_cells..=16).contains(&self.ring_to_cells)
            && (1..=1000).contains(&self.max_share_permille)
            && self.trim_permille <= 1000
    }
}

impl Default for BodyParams {
    fn default() -> Self {
        BodyParams::DEFAULT
    }
}

/// A cell box, inclusive ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct CellBox {
    x0: usize,
    y0: usize,
    x1: usize,
    y1: usize,
}

/// The box of the cells marked non-zero, `None` without any.
fn marked_box(marks: &[u8], pw: usize) -> Option<CellBox> {
    box_where(marks, pw, |m| m != 0)
}

/// The box of the cells whose mark passes `keep`, `None` without any.
fn box_where(marks: &[u8], pw: usize, keep: impl Fn(u8) -> bool) -> Option<CellBox> {
    let mut b: Option<CellBox> = None;
    for (i, _) in marks.iter().enumerate().filter(|(_, m)| keep(**m)) {
        let (x, y) = (i % pw.max(1), i / pw.max(1));
        b = Some(match b {
            None => CellBox {
                x0: x,
                y0: y,
                x1: x,
                y1: y,
            },
            Some(c) => CellBox {
                x0: c.x0.min(x),
                y0: c.y0.min(y),
                x1: c.x1.max(x),
                y1: c.y1.max(y),
            },
        });
    }
    b
}

/// Chebyshev distance of cell `(x, y)` from the box (0 inside).
fn distance(b: CellBox, x: usize, y: usize) -> usize {
    let dx = b.x0.saturating_sub(x).max(x.saturating_sub(b.x1));
    let dy = b.y0.saturating_sub(y).max(y.saturating_sub(b.y1));
    dx.max(dy)
}

/// The background model: the median cell mean of the ring and its spread (the larger
/// of `sigma_dn` and 1.4826 × the median absolute deviation), DN; `None` for an
/// empty ring (the winner covers the frame).
fn background(
    mean_dn: &[u16],
    (pw, ph): (usize, usize),
    b: CellBox,
    p: BodyParams,
    sigma_dn: u32,
) -> Option<(u32, u32)> {
    let (from, to) = (usize::from(p.ring_from_cells), usize::from(p.ring_to_cells));
    let ring = || {
        (b.y0.saturating_sub(to)..(b.y1 + to + 1).min(ph)).flat_map(move |y| {
            (b.x0.saturating_sub(to)..(b.x1 + to + 1).min(pw)).filter_map(move |x| {
                let d = distance(b, x, y);
                if (from..=to).contains(&d) {
                    mean_dn.get(y * pw + x).map(|&m| u32::from(m))
                } else {
                    None
                }
            })
        })
    };
    let n = ring().count();
    if n == 0 {
        return None;
    }
    let level = select_binned(ring, n / 2, u32::from(u16::MAX));
    let mad = select_binned(
        || ring().map(|v| v.abs_diff(level)),
        n / 2,
        u32::from(u16::MAX),
    );
    let spread = (mad * MAD_TO_SIGMA_PERMILLE / 1000).max(sigma_dn).max(1);
    Some((level, spread))
}

/// Grows the cells marked [`WINNER`] in `marks` (a `pw × ph` plane, others 0) over
/// 8-connected cells whose mean departs from `level` by at least `thr` DN, marking
/// them [`GROWN`]; at most [`MAX_PASSES`] sweeps. Returns the marked cells' count.
fn grow(
    marks: &mut [u8],
    mean_dn: &[u16],
    (pw, ph): (usize, usize),
    level: u32,
    thr: u32,
) -> usize {
    let n = (pw * ph).min(marks.len()).min(mean_dn.len());
    let body = |i: usize| {
        mean_dn
            .get(i)
            .is_some_and(|&m| u32::from(m).abs_diff(level) >= thr)
    };
    for pass in 0..MAX_PASSES {
        let mut changed = false;
        for k in 0..n {
            let i = if pass % 2 == 0 { k } else { n - 1 - k };
            if marks.get(i) != Some(&0) || !body(i) {
                continue;
            }
            let (x, y) = (i % pw.max(1), i / pw.max(1));
            let touches = (y.saturating_sub(1)..(y + 2).min(ph)).any(|ny| {
                (x.saturating_sub(1)..(x + 2).min(pw))
                    .any(|nx| marks.get(ny * pw + nx).is_some_and(|&m| m != 0))
            });
            if touches {
                if let Some(m) = marks.get_mut(i) {
                    *m = GROWN;
                }
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    marks.iter().take(n).filter(|&&m| m != 0).count()
}

/// Whether the grown body (cells marked [`GROWN`] in `marks`, a `pw × ph` plane)
/// ends in a fade: the median departure from `level` of the unmarked cells 8-adjacent
/// to a grown cell is at least [`MAX_FADE_PERCENT`] of `spread` (see there). False
/// without such cells. One pass over the plane for the grown cells' box, then over that
/// box one pass to count the neighbours and two binned passes for their median
/// ([`select_binned`]), each re-testing a cell's 3×3 neighbourhood: no buffer (the
/// marks plane is the caller's and read again after this).
fn fades(marks: &[u8], mean_dn: &[u16], (pw, ph): (usize, usize), level: u32, spread: u32) -> bool {
    let n = (pw * ph).min(marks.len()).min(mean_dn.len());
    let Some(marks) = marks.get(..n) else {
        return false;
    };
    // The grown cells' box one cell wider: the cells beside them lie in it (a scan of
    // the body's box, not of the plane: the M7's `deep-space` frame took 0.7 M
    // instructions more with whole-plane scans).
    let grown = box_where(marks, pw, |m| m == GROWN);
    let Some(g) = grown else {
        return false;
    };
    let (x0, y0) = (g.x0.saturating_sub(1), g.y0.saturating_sub(1));
    let (x1, y1) = (
        (g.x1 + 1).min(pw.saturating_sub(1)),
        (g.y1 + 1).min(ph.saturating_sub(1)),
    );
    let outside = |x: usize, y: usize| {
        marks.get(y * pw + x) == Some(&0)
            && (y.saturating_sub(1)..(y + 2).min(ph)).any(|ny| {
                (x.saturating_sub(1)..(x + 2).min(pw))
                    .any(|nx| marks.get(ny * pw + nx) == Some(&GROWN))
            })
    };
    // Departures in hundredths of a spread, capped (a cell far off counts as far; the
    // cap keeps the median to two binned passes).
    const CAP: u32 = 4095;
    let departures = || {
        (y0..=y1)
            .flat_map(move |y| (x0..=x1).map(move |x| (x, y)))
            .filter(move |&(x, y)| outside(x, y))
            .map(move |(x, y)| {
                let d = mean_dn
                    .get(y * pw + x)
                    .map_or(0, |&m| u32::from(m).abs_diff(level));
                (d.saturating_mul(100) / spread.max(1)).min(CAP)
            })
    };
    let k = departures().count();
    k > 0 && select_binned(departures, k / 2, CAP) >= MAX_FADE_PERCENT
}

/// Pixels of column `x` (or row, `vertical` false) over `span` departing from
/// `level` by at least `thr` DN.
fn departing(
    frame: &Frame<'_>,
    line: usize,
    span: (usize, usize),
    vertical: bool,
    level: u32,
    thr: u32,
) -> u32 {
    let off = |v: u16| u32::from(u32::from(v).abs_diff(level) >= thr);
    if vertical {
        (span.0..span.1)
            .filter_map(|y| frame.row(y).and_then(|r| r.get(line)))
            .map(|&v| off(v))
            .sum()
    } else {
        frame
            .row(line)
            .and_then(|r| r.get(span.0..span.1))
            .unwrap_or_default()
            .iter()
            .map(|&v| off(v))
            .sum()
    }
}

/// The whole body's box (see the module): `marks` holds the winner's cells of the
/// plane of 8×8 cells of the frame's window `win` ([`cell_plane`]; `mean_dn`: their
/// mean DN) marked [`WINNER`], others 0 (the grown cells are marked [`GROWN`] on
/// return); `roi` is the box found so far, kept (and returned unchanged) when the
/// stage is off, the ring is empty, nothing grows or the growth breaks a bound. The
/// result holds `roi`; what it adds lies inside the window.
pub(crate) fn body_box(
    frame: &Frame<'_>,
    win: Window,
    mean_dn: &[u16],
    marks: &mut [u8],
    sigma_dn: u32,
    roi: Roi,
    p: BodyParams,
) -> Roi {
    let plane = cell_plane(win);
    let (pw, ph) = plane;
    let n = pw * ph;
    if p.k_sigma == 0 || n == 0 || roi.x1 <= roi.x0 || roi.y1 <= roi.y0 {
        return roi;
    }
    let (Some(marks), Some(mean_dn)) = (marks.get_mut(..n), mean_dn.get(..n)) else {
        return roi;
    };
    let Some(wb) = marked_box(marks, pw) else {
        return roi;
    };
    let Some((level, spread)) = background(mean_dn, plane, wb, p, sigma_dn) else {
        return roi;
    };
    let thr = spread.saturating_mul(u32::from(p.k_sigma));
    let before = marks.iter().filter(|&&m| m != 0).count();
    let after = grow(marks, mean_dn, plane, level, thr);
    if after == before
        || after * 1000 > n * usize::from(p.max_share_permille)
        || fades(marks, mean_dn, plane, level, spread)
    {
        return roi;
    }
    let Some(gb) = marked_box(marks, pw) else {
        return roi;
    };
    // A growth from one side of the frame to the opposite one runs across it (a
    // cloud deck, the limb): not a compact body.
    let across = (gb.x0 == 0 && gb.x1 + 1 >= pw) || (gb.y0 == 0 && gb.y1 + 1 >= ph);
    if across {
        return roi;
    }
    // The grown box one cell wider per side, in frame pixels (cut to the window).
    let mut x0 = win.x0 + gb.x0.saturating_sub(1) * CELL_PX;
    let mut y0 = win.y0 + gb.y0.saturating_sub(1) * CELL_PX;
    let mut x1 = win.x0 + ((gb.x1 + 2) * CELL_PX).min(win.w);
    let mut y1 = win.y0 + ((gb.y1 + 2) * CELL_PX).min(win.h);
    let need = |len: usize| (len as u32 * u32::from(p.trim_permille) / 1000).max(2);
    // Trim each side to its first line with enough departing pixels.
    while x0 + 1 < x1 && departing(frame, x0, (y0, y1), true, level, thr) < need(y1 - y0) {
        x0 += 1;
    }
    while x1 > x0 + 1 && departing(frame, x1 - 1, (y0, y1), true, level, thr) < need(y1 - y0) {
        x1 -= 1;
    }
    while y0 + 1 < y1 && departing(frame, y0, (x0, x1), false, level, thr) < need(x1 - x0) {
        y0 += 1;
    }
    while y1 > y0 + 1 && departing(frame, y1 - 1, (x0, x1), false, level, thr) < need(x1 - x0) {
        y1 -= 1;
    }
    let px = |v: usize| v.min(usize::from(u16::MAX)) as u16;
    Roi {
        x0: roi.x0.min(px(x0)),
        y0: roi.y0.min(px(y0)),
        x1: roi.x1.max(px(x1)),
        y1: roi.y1.max(px(y1)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{FRAME_HEIGHT, FRAME_WIDTH};
    extern crate std;
    use std::vec::Vec;

    /// xorshift32: deterministic test values.
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
    fn background_equals_the_sorted_ring() {
        let (pw, ph) = (41usize, 31usize);
        let mut r = rng(5);
        let mean: Vec<u16> = (0..pw * ph).map(|_| (r() % 5000) as u16).collect();
        let p = BodyParams::DEFAULT;
        for b in [
            CellBox {
                x0: 10,
                y0: 10,
                x1: 14,
                y1: 12,
            },
            CellBox {
                x0: 0,
                y0: 0,
                x1: 2,
                y1: 1,
            },
            CellBox {
                x0: 38,
                y0: 25,
                x1: 40,
                y1: 30,
            },
        ] {
            let mut ring = Vec::new();
            for y in 0..ph {
                for x in 0..pw {
                    // Chebyshev distance from the box, brute force.
                    let dx = if x < b.x0 {
                        b.x0 - x
                    } else {
                        x.saturating_sub(b.x1)
                    };
                    let dy = if y < b.y0 {
                        b.y0 - y
                    } else {
                        y.saturating_sub(b.y1)
                    };
                    let d = dx.max(dy);
                    if d >= usize::from(p.ring_from_cells) && d <= usize::from(p.ring_to_cells) {
                        ring.push(u32::from(mean[y * pw + x]));
                    }
                }
            }
            ring.sort_unstable();
            let level = ring[ring.len() / 2];
            let mut dev: Vec<u32> = ring.iter().map(|v| v.abs_diff(level)).collect();
            dev.sort_unstable();
            let spread = (dev[dev.len() / 2] * 1483 / 1000).max(7);
            assert_eq!(
                background(&mean, (pw, ph), b, p, 7),
                Some((level, spread)),
                "{b:?}"
            );
        }
    }

    /// Growth against a breadth-first flood fill (brute force) from the same seeds.
    #[test]
    fn growth_equals_a_flood_fill() {
        let (pw, ph) = (41usize, 31usize);
        for seed in 1..20u32 {
            let mut r = rng(seed);
            // Blobs of departing cells (about a third) on a flat level.
            let mean: Vec<u16> = (0..pw * ph)
                .map(|_| if r() % 3 == 0 { 3000 } else { 1000 })
                .collect();
            let mut marks = std::vec![0u8; pw * ph];
            let s = (r() as usize) % (pw * ph);
            marks[s] = WINNER;
            let mut want = marks.clone();
            let mut queue = std::collections::VecDeque::from([s]);
            while let Some(i) = queue.pop_front() {
                let (x, y) = ((i % pw) as i64, (i / pw) as i64);
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let (nx, ny) = (x + dx, y + dy);
                        if nx < 0 || ny < 0 || nx >= pw as i64 || ny >= ph as i64 {
                            continue;
                        }
                        let j = ny as usize * pw + nx as usize;
                        if want[j] == 0 && mean[j].abs_diff(1000) >= 1500 {
                            want[j] = GROWN;
                            queue.push_back(j);
                        }
                    }
                }
            }
            let n = grow(&mut marks, &mean, (pw, ph), 1000, 1500);
            assert_eq!(marks, want, "seed {seed}");
            assert_eq!(n, want.iter().filter(|&&m| m != 0).count());
        }
    }

    /// The fade test against a brute force: the sorted departures of the unmarked
    /// cells 8-adjacent to a grown cell, their element `k / 2` against the bar.
    #[test]
    fn fades_equals_the_sorted_neighbours() {
        let (pw, ph) = (41usize, 31usize);
        for seed in 1..40u32 {
            let mut r = rng(seed);
            let mean: Vec<u16> = (0..pw * ph).map(|_| 900 + (r() % 200) as u16).collect();
            let marks: Vec<u8> = (0..pw * ph)
                .map(|_| match r() % 7 {
                    0 => GROWN,
                    1 => WINNER,
                    _ => 0,
                })
                .collect();
            let spread = 1 + r() % 60;
            let mut deps = Vec::new();
            for y in 0..ph {
                for x in 0..pw {
                    if marks[y * pw + x] != 0 {
                        continue;
                    }
                    let mut near = false;
                    for ny in y.saturating_sub(1)..(y + 2).min(ph) {
                        for nx in x.saturating_sub(1)..(x + 2).min(pw) {
                            near |= marks[ny * pw + nx] == GROWN;
                        }
                    }
                    if near {
                        let d = u32::from(mean[y * pw + x]).abs_diff(1000);
                        deps.push((d * 100 / spread).min(4095));
                    }
                }
            }
            deps.sort_unstable();
            let want = !deps.is_empty() && deps[deps.len() / 2] >= MAX_FADE_PERCENT;
            assert_eq!(
                fades(&marks, &mean, (pw, ph), 1000, spread),
                want,
                "seed {seed}"
            );
        }
        // No grown cell, or empty planes: no fade.
        assert!(!fades(&[WINNER; 4], &[5000; 4], (2, 2), 0, 1));
        assert!(!fades(&[], &[], (41, 31), 0, 1));
    }

    /// A body ends at a step; a growth through a ramp (falling a quarter spread per
    /// cell away from the winner) ends in a fade.
    #[test]
    fn a_growth_through_a_ramp_fades() {
        let (pw, ph) = (41usize, 31usize);
        let (level, spread) = (1000u32, 20u32);
        // Chebyshev distance of a cell from the winner cell (20, 15).
        let dist = |i: usize| {
            let (x, y) = ((i % pw) as i64, (i / pw) as i64);
            (x - 20).abs().max((y - 15).abs()) as u32
        };
        let grown = |mean: &[u16]| -> Vec<u8> {
            let mut marks = std::vec![0u8; pw * ph];
            marks[15 * pw + 20] = WINNER;
            grow(&mut marks, mean, (pw, ph), level, 3 * spread);
            marks
        };
        // A step: a body of radius 2 at 5 spreads, the background at the level.
        let step: Vec<u16> = (0..pw * ph)
            .map(|i| if dist(i) <= 2 { level + 5 * spread } else { level } as u16)
            .collect();
        let marks = grown(&step);
        assert_eq!(marks.iter().filter(|&&m| m == GROWN).count(), 24);
        assert!(!fades(&marks, &step, (pw, ph), level, spread));
        // A ramp: 4 spreads at the winner, a quarter less per cell, 1.5 at the least;
        // the growth (bar 3 spreads) stops at 4 cells, its neighbours at 2.75 spreads.
        let ramp: Vec<u16> = (0..pw * ph)
            .map(|i| (level + 4 * spread - (spread * dist(i) / 4).min(spread * 5 / 2)) as u16)
            .collect();
        let marks = grown(&ramp);
        assert_eq!(marks.iter().filter(|&&m| m == GROWN).count(), 80);
        assert!(fades(&marks, &ramp, (pw, ph), level, spread));
    }

    /// A frame: textured background (noise of ±`tex` DN), a body of two faces, one
    /// hotter and one colder than the background, a cloud band across the frame.
    fn scene(tex: u32, band: bool) -> Vec<u16> {
        let mut r = rng(11);
        let mut px = std::vec![0u16; FRAME_WIDTH * FRAME_HEIGHT];
        for y in 0..FRAME_HEIGHT {
            for x in 0..FRAME_WIDTH {
                let mut v = 2000 + (r() % (2 * tex + 1)) as i32 - tex as i32;
                if band && (150..180).contains(&y) {
                    v = 600;
                }
                if (100..140).contains(&x) && (60..90).contains(&y) {
                    v = 3500; // hot face
                }
                if (140..181).contains(&x) && (60..90).contains(&y) {
                    v = 800; // cold face
                }
                px[y * FRAME_WIDTH + x] = v as u16;
            }
        }
        px
    }

    fn cell_means(px: &[u16]) -> Vec<u16> {
        let (pw, ph) = (41, 31);
        (0..pw * ph)
            .map(|i| {
                let (cx, cy) = (i % pw, i / pw);
                let mut s = 0u32;
                for y in cy * 8..cy * 8 + 8 {
                    for x in cx * 8..cx * 8 + 8 {
                        s += u32::from(px[y * FRAME_WIDTH + x]);
                    }
                }
                (s / 64) as u16
            })
            .collect()
    }

    #[test]
    fn the_body_grows_over_hot_and_cold_faces() {
        let (pw, ph) = (41usize, 31usize);
        for band in [false, true] {
            let px = scene(50, band);
            let frame = Frame::reference(&px).unwrap();
            let mean = cell_means(&px);
            // The winner: the hot face's whole cells (x 104..136, y 64..88).
            let mut marks = std::vec![0u8; pw * ph];
            for cy in 8..11 {
                for cx in 13..17 {
                    marks[cy * pw + cx] = WINNER;
                }
            }
            let hot = Roi::new(100, 60, 140, 90);
            let got = body_box(
                &frame,
                Window::full(&frame),
                &mean,
                &mut marks,
                20,
                hot,
                BodyParams::DEFAULT,
            );
            assert_eq!(got, Roi::new(100, 60, 181, 90), "band {band}");
            // Off: unchanged.
            let mut marks2 = std::vec![0u8; pw * ph];
            marks2[9 * pw + 14] = WINNER;
            assert_eq!(
                body_box(
                    &frame,
                    Window::full(&frame),
                    &mean,
                    &mut marks2,
                    20,
                    hot,
                    BodyParams::OFF
                ),
                hot
            );
        }
    }

    /// A winner on a band that runs across the frame: the growth is dropped.
    #[test]
    fn a_band_across_the_frame_is_not_a_body() {
        let (pw, ph) = (41usize, 31usize);
        let px = scene(50, true);
        let frame = Frame::reference(&px).unwrap();
        let mean = cell_means(&px);
        let mut marks = std::vec![0u8; pw * ph];
        // Cells of the band (y 152..176) near the middle.
        marks[20 * pw + 20] = WINNER;
        let roi = Roi::new(160, 152, 168, 160);
        let got = body_box(
            &frame,
            Window::full(&frame),
            &mean,
            &mut marks,
            20,
            roi,
            BodyParams::DEFAULT,
        );
        assert_eq!(got, roi);
        // Bad input: empty planes and boxes are safe.
        assert_eq!(
            body_box(
                &frame,
                Window::full(&frame),
                &[],
                &mut [],
                20,
                roi,
                BodyParams::DEFAULT
            ),
            roi
        );
        assert_eq!(
            body_box(
                &frame,
                Window::full(&frame),
                &mean,
                &mut marks,
                20,
                Roi::EMPTY,
                BodyParams::DEFAULT
            ),
            Roi::EMPTY
        );
    }
}
