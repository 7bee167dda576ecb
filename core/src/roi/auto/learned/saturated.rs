//! The box of a saturated target. A target far hotter than the top DN saturates every
//! pixel the optics' point-spread function carries any of its light to: the
//! saturated blob is the target's outline dilated by the kernel's reach (2 px for the
//! TIR's 5×5 kernel), plus the target's edge pixels that it covers less than half.
//! The truth (pixels at least half covered) lies inside, about
//! [`PSF_RADIUS_PX`] + ½ px in from each side, and no pixel value inside the blob
//! says where (they are all at the top DN). So a box that is the saturated blob (plus
//! at most its halo) is cut by a fixed number of pixels per side, chosen on our
//! family-A renders (`AutoV2::saturated_erode_px`); a side on the frame's edge is
//! kept (the target goes on beyond it).
//!
//! The cut box is the box of the pixels the target covers at all; the truth counts only
//! those it covers half. Where the target meets the box's outermost line with a
//! corner's tip (one or two covered pixels: a target turned at an angle), that line is
//! rarely half covered and is cut too ([`TIP_MAX_PX`], session 61).
//!
//! Only a target saturated *whole* is its blob: a hot face of a larger body saturates
//! too, with the body's cooler faces beyond the halo (session 47: on family A's
//! radiometry frames such a face was cut to a 1×1 … 13×17 px box of a 5×4 … 24×27 px
//! target). So the blob is cut only when the ring just beyond its halo is not
//! brighter than the ring outside that ([`continues_beyond`]); otherwise the box stays
//! the earlier stages' and the body stage grows it.
//!
//! Nor is a target *barely* above the top DN cut (session 61): its blurred edge shows
//! around the blob as a bright halo ([`HALO_SHARE_DIV`]), and the blob lies inside
//! its outline; it is taken to its half maximum as a core is.
//!
//! Nor is a target saturated only in its middle (session 60): light spread by a kernel
//! of reach r saturates at least 2r + 1 px across around any target far hotter than
//! the top DN, so a blob narrower than that on a side is the *core* of a target
//! barely above the top DN, whose outline lies beyond it (`famA/000168`: a 5×5 px
//! target saturated on 3×2 px). Cutting it would leave a pixel (then no box at all):
//! [`saturated_target`] gives its box grown instead ([`Saturated::Core`]), for the
//! caller to take to the target's half maximum.

use crate::frame::Frame;
use crate::roi::Roi;

/// Reach of the optics' point-spread function, px: the half-width of the TIR's 5×5
/// kernel (`tirroi-host` `imaging/psf.rs`, `PSF_RADIUS_PX`): light falls at most this
/// far from the pixel it came from.
pub const PSF_RADIUS_PX: u16 = 2;

/// Fewest pixels at the top DN for a box to count as a saturated blob: a 2×2 core (hot
/// pixels come alone).
pub const MIN_BLOB_PX: u32 = 4;

/// Width, px, of the two rings [`continues_beyond`] compares: the near ring, just
/// beyond the blob's halo (Chebyshev distance [`PSF_RADIUS_PX`] + 1 ..=
/// [`PSF_RADIUS_PX`] + 2 from the blob's box, where a target saturated whole has put no
/// light), and the far ring outside it (the surroundings' level and spread).
pub const RING_PX: u16 = 2;

/// A near-ring pixel departs from the surroundings when it is brighter than the far
/// ring's mean by more than this many times the far ring's mean absolute deviation
/// (at least 1 DN): 4 of them (about 3 σ of Gaussian noise) leave noise, smooth Earth
/// texture and the camera's shading across a large blob in place. Brighter only: a
/// body hot enough to saturate in part is warmer than its surroundings on most faces,
/// while a cold cloud beside a target saturated whole is darker (both ways, a blob next
/// to a cold cloud cell was left uncut: detection rows of the test split fell, 0.741 →
/// 0.385 on a target at 229 m). Means, not medians: with medians a shading gradient
/// across a large blob's rings (0 DN on one side, 150 DN on the other) departed —
/// family A's detection rows fell by 0.02–0.12. The price: a body that also fills more
/// than about 1/8 of the far ring widens the spread it is measured against and is not
/// seen; its face is cut as before.
pub const DEPART_SPREAD_FACTOR: u64 = 4;

/// The target goes on beyond its blob when more than 1/10 of the near ring departs
/// (family A, session 47, departures either way: blobs that were the whole target
/// 0–5 % — the 5 % one sprinkle of noise on 0 DN deep space — and hot faces of a
/// larger body 12–42 %).
pub const DEPART_SHARE_DIVISOR: u64 = 10;

/// Most pixels of the covered set's outermost line (see [`saturated_target`]) that make
/// it a corner's tip, cut one pixel more. A target far above the top DN saturates every
/// pixel within the kernel's reach of a pixel it covers at all, so the blob eroded by
/// the kernel's square is the set of pixels the target covers at all, and the cut box
/// is that set's box. The truth counts a pixel only when the target covers half of it:
/// along an edge square to the frame's axes the outermost line's pixels are covered by
/// the same share (in the truth half the time, the cut's coin toss), but a target turned
/// at an angle reaches the outermost line with a corner's tip, one or two pixels
/// covered by a small triangle, rarely half. A line shorter than twice this many
/// pixels has no tip to tell from an edge, and a cut never leaves a side under
/// [`super::MIN_BOX_SIDE_PX`] + 1 px (a 3-px box cut to 1 px would be no target).
/// Chosen on family A (session 61): a Python replay on famA's cut boxes, 1 / **2** / 3
/// px → mean IoU +0.012 / **+0.028** / +0.003 (3 px is the whole edge of the smallest
/// far targets), any side (one pixel more on every side) −0.014; in the detector, with
/// the short-line and 3-px rules, famA +0.0295 (detection far 0.729 → 0.823), famAF
/// −0.0004, paper A and fixtures A unchanged, famAT −0.0037 (Tango's boxes are already
/// short of its booms); held out famB +0.0338, famBW +0.0300, famBT −0.0021.
pub const TIP_MAX_PX: u32 = 2;

/// Pixels of the line `fixed` (a column when `vertical`, else a row) from `from` to
/// `to` (exclusive) whose (2 `erode_px` + 1)² square lies wholly at the top DN (off the
/// frame counting as at it): the pixels the target covers at all, in that line of the
/// cut box. Counts at most `limit` + 1.
fn covered_in_line(
    frame: &Frame<'_>,
    fixed: u16,
    (from, to): (u16, u16),
    vertical: bool,
    erode_px: u16,
    limit: u32,
) -> u32 {
    let top = frame.max_dn();
    let (fw, fh) = (frame.width() as i32, frame.height() as i32);
    let e = i32::from(erode_px);
    let saturated = |x: i32, y: i32| {
        if x < 0 || y < 0 || x >= fw || y >= fh {
            return true;
        }
        frame
            .row(y as usize)
            .and_then(|r| r.get(x as usize))
            .is_some_and(|&v| v >= top)
    };
    // Along the line, each position's cross-section (2e + 1 px across it) saturated;
    // a pixel is covered when 2e + 1 consecutive cross-sections are.
    let fixed = i32::from(fixed);
    let (mut run, mut count) = (0i32, 0u32);
    for p in i32::from(from) - e..i32::from(to) + e {
        let whole = (-e..=e).all(|d| {
            if vertical {
                saturated(fixed + d, p)
            } else {
                saturated(p, fixed + d)
            }
        });
        run = if whole { run + 1 } else { 0 };
        if p >= i32::from(from) + e && run > 2 * e {
            count += 1;
            if count > limit {
                break;
            }
        }
    }
    count
}

/// Calls `f` with every pixel value at Chebyshev distance `from..=to` px (`from` ≥ 1)
/// from `hull`, inside the frame and at least `margin` px from its edges.
fn for_each_ring_px(
    frame: &Frame<'_>,
    hull: Roi,
    from: u16,
    to: u16,
    margin: usize,
    mut f: impl FnMut(u16),
) {
    let (fw, fh) = (frame.width(), frame.height());
    let (from, to) = (usize::from(from), usize::from(to));
    let (hx0, hy0) = (usize::from(hull.x0), usize::from(hull.y0));
    let (hx1, hy1) = (usize::from(hull.x1), usize::from(hull.y1));
    let (x0, x1) = (
        hx0.saturating_sub(to).max(margin),
        (hx1 + to).min(fw.saturating_sub(margin)),
    );
    // The columns at distance `from..=to` left and right of the hull.
    let left = x0..(hx0 + 1).saturating_sub(from).max(x0);
    let right = (hx1 + from - 1).min(x1)..x1;
    for y in hy0.saturating_sub(to).max(margin)..(hy1 + to).min(fh.saturating_sub(margin)) {
        let Some(row) = frame.row(y) else {
            continue;
        };
        let dy = if y < hy0 {
            hy0 - y
        } else {
            (y + 1).saturating_sub(hy1)
        };
        if dy >= from {
            row.get(x0..x1)
                .unwrap_or_default()
                .iter()
                .for_each(|&v| f(v));
        } else {
            row.get(left.clone())
                .unwrap_or_default()
                .iter()
                .for_each(|&v| f(v));
            row.get(right.clone())
                .unwrap_or_default()
                .iter()
                .for_each(|&v| f(v));
        }
    }
}

/// The mean DN of the far ring around the blob's box `hull` (Chebyshev distance
/// [`PSF_RADIUS_PX`] + [`RING_PX`] + 1 ..= [`PSF_RADIUS_PX`] + 2 [`RING_PX`]: the
/// surroundings' level) and its pixel count; `None` when it lies wholly outside the
/// frame.
fn far_ring_level(frame: &Frame<'_>, hull: Roi) -> Option<(u64, u64)> {
    let from = PSF_RADIUS_PX + RING_PX + 1;
    let (mut sum, mut n) = (0u64, 0u64);
    for_each_ring_px(frame, hull, from, from + RING_PX - 1, 0, |v| {
        sum += u64::from(v);
        n += 1;
    });
    sum.checked_div(n).map(|level| (level, n))
}

/// A blob has a halo when the pixels just outside its outline (see [`has_halo`])
/// depart from the surroundings' level by at least this share (1/4) of the way to the
/// top DN. A target far above the top DN saturates every pixel its light
/// reaches through the kernel, so the pixels beside its blob hold no light (famA's
/// and famB's saturated targets: a median share of 0.00, 90th percentile 0.03); one
/// barely above it shows its blurred edge there, bright but unsaturated (famAT's
/// Tango: median 0.25, famBT 0.45), and its blob lies *inside* its outline, not
/// around it: cut by the reach it loses 2–6 px a side (`famAT/000214`: 0.54 → 1.00).
/// Such a blob is taken to its half maximum instead, as a core is (session 61), when
/// its cut leaves a box ([`super::MIN_BOX_SIDE_PX`] a side). Chosen on family A (seeds
/// 7001–7201, ½ convention; a Python replay put the share's split at ⅛–⅖ alike): famA
/// +0.0004, famAT +0.0155, no false alarm added; held out famBT +0.0117, famBW +0.0032,
/// famB +0.0013. (Read from every pixel beside a saturated one, holes included, famA
/// +0.0007, but the pass over the blob's whole box cost the flight demo's detection
/// frame, a large saturated plate, 0.2 M instructions.) Without the "cut leaves a box"
/// condition famA and famAF gain +0.0036 more, but the Moon's disc (a few pixels just above the top DN, which
/// the cut reduced to a pixel and dropped) is boxed on two of family A's frames without
/// a target (`famA/000084`, `famAT/000138`): the Moon is then a false alarm as any
/// saturated blob is, a limit left to a rule that knows it (its direction).
pub const HALO_SHARE_DIV: u64 = 4;

/// True when the saturated blob of box `hull` has a halo (see [`HALO_SHARE_DIV`]): the
/// pixels just outside its outline, met from each side of its box — on every row the
/// pixel before its first and after its last pixel at the top DN, on every column the
/// pixel above and below — their mean against the surroundings' level. Each scan stops
/// at the blob, so a solid blob costs about its box's perimeter, not its area (a large
/// saturated plate: the flight demo's detection frame).
fn has_halo(frame: &Frame<'_>, hull: Roi) -> bool {
    let Some((level, _)) = far_ring_level(frame, hull) else {
        return false;
    };
    let top = frame.max_dn();
    if level >= u64::from(top) {
        return false;
    }
    let (x0, x1) = (usize::from(hull.x0), usize::from(hull.x1));
    let (y0, y1) = (usize::from(hull.y0), usize::from(hull.y1));
    let at = |x: usize, y: usize| frame.row(y).and_then(|r| r.get(x)).copied();
    let (mut sum, mut n) = (0u64, 0u64);
    let mut add = |v: Option<u16>| {
        if let Some(v) = v {
            sum += u64::from(v);
            n += 1;
        }
    };
    for y in y0..y1 {
        let Some(row) = frame.row(y).and_then(|r| r.get(x0..x1)) else {
            continue;
        };
        let Some(first) = row.iter().position(|&v| v >= top) else {
            continue;
        };
        let last = row.iter().rposition(|&v| v >= top).unwrap_or(first);
        add((x0 + first).checked_sub(1).and_then(|x| at(x, y)));
        add(at(x0 + last + 1, y));
    }
    for x in x0..x1 {
        let Some(first) = (y0..y1).find(|&y| at(x, y).is_some_and(|v| v >= top)) else {
            continue;
        };
        let last = (y0..y1)
            .rev()
            .find(|&y| at(x, y).is_some_and(|v| v >= top))
            .unwrap_or(first);
        add(first.checked_sub(1).and_then(|y| at(x, y)));
        add(at(x, last + 1));
    }
    sum.checked_div(n).is_some_and(|mean| {
        mean.saturating_sub(level) * HALO_SHARE_DIV >= u64::from(top).saturating_sub(level)
    })
}

/// True when the target goes on beyond the saturated blob `hull` (the blob's box):
/// more than 1/[`DEPART_SHARE_DIVISOR`] of the near ring is brighter than the far
/// ring's level (see [`RING_PX`], [`DEPART_SPREAD_FACTOR`]). Near-ring pixels within
/// [`RING_PX`] of the frame's edge are left out: the far ring beyond them lies outside
/// the frame, so the level they are judged by would be the other sides' (a blob at the
/// edge beside the Earth on that side only). False when the far ring lies wholly
/// outside the frame. Three passes over the rings, each 2 px wide: 4 × (w + h) + 48
/// pixels (near) and + 80 (far) for a w × h hull, run only on a box that is otherwise
/// a saturated blob.
pub fn continues_beyond(frame: &Frame<'_>, hull: Roi) -> bool {
    let near = (PSF_RADIUS_PX + 1, PSF_RADIUS_PX + RING_PX);
    let far = (near.1 + 1, near.1 + RING_PX);
    let Some((level, n)) = far_ring_level(frame, hull) else {
        return false;
    };
    let mut deviation = 0u64;
    for_each_ring_px(frame, hull, far.0, far.1, 0, |v| {
        deviation += u64::from(v).abs_diff(level);
    });
    // (`checked_div`: `n` > 0, but not provably so here: no panic path.)
    let limit = DEPART_SPREAD_FACTOR * deviation.checked_div(n).unwrap_or(0).max(1);
    let (mut near_px, mut departing) = (0u64, 0u64);
    for_each_ring_px(frame, hull, near.0, near.1, usize::from(RING_PX), |v| {
        near_px += 1;
        departing += u64::from(u64::from(v) > level + limit);
    });
    departing * DEPART_SHARE_DIVISOR > near_px
}

/// The box of the pixels of `roi` at the frame's top DN and how many there are.
fn saturated_hull(frame: &Frame<'_>, roi: Roi) -> (Roi, u32) {
    let top = frame.max_dn();
    let mut hull = Roi::EMPTY;
    let mut n = 0u32;
    let (x0, x1) = (usize::from(roi.x0), usize::from(roi.x1));
    for y in usize::from(roi.y0)..usize::from(roi.y1) {
        let Some(row) = frame.row(y).and_then(|r| r.get(x0..x1)) else {
            continue;
        };
        for (i, &v) in row.iter().enumerate() {
            if v < top {
                continue;
            }
            let (x, y) = ((x0 + i) as u16, y as u16);
            hull = if n == 0 {
                Roi {
                    x0: x,
                    y0: y,
                    x1: x + 1,
                    y1: y + 1,
                }
            } else {
                Roi {
                    x0: hull.x0.min(x),
                    y0: hull.y0.min(y),
                    x1: hull.x1.max(x + 1),
                    y1: hull.y1.max(y + 1),
                }
            };
            n += 1;
        }
    }
    (hull, n)
}

/// Cuts `[a, b)` by `e` px at each end that is not on the frame's edge (`a == 0`,
/// `b == limit`), keeping at least 1 px (the middle one).
fn cut_span(a: u16, b: u16, e: u16, limit: u16) -> (u16, u16) {
    let ea = if a == 0 { 0 } else { e };
    let eb = if b >= limit { 0 } else { e };
    let w = b - a;
    if ea + eb < w {
        (a + ea, b - eb)
    } else {
        // Nothing would be left: the pixel at the kept end, else the middle one.
        let mid = if ea == 0 {
            a
        } else if eb == 0 {
            b - 1
        } else {
            a + (w - 1) / 2
        };
        (mid, mid + 1)
    }
}

/// The box of the saturated pixels of `roi` when `roi` is a saturated blob: at least
/// [`MIN_BLOB_PX`] pixels at the top DN, `roi` reaching at most [`PSF_RADIUS_PX`] + 1
/// px beyond their box on every side (the blob and its halo, not a larger body with a
/// saturated face) and no brighter ring just beyond the halo (the target does not go
/// on beyond it, [`continues_beyond`]); `None` otherwise.
fn blob_hull(frame: &Frame<'_>, roi: Roi) -> Option<Roi> {
    if roi.x1 <= roi.x0 || roi.y1 <= roi.y0 {
        return None;
    }
    let (hull, n) = saturated_hull(frame, roi);
    if n < MIN_BLOB_PX {
        return None;
    }
    let reach = PSF_RADIUS_PX + 1;
    // The hull lies inside `roi` (it holds ≥ 4 of its pixels): no underflow.
    let halo_only = hull.x0 - roi.x0 <= reach
        && hull.y0 - roi.y0 <= reach
        && roi.x1 - hull.x1 <= reach
        && roi.y1 - hull.y1 <= reach;
    (halo_only && !continues_beyond(frame, hull)).then_some(hull)
}

/// True when the saturated blob's box `hull` is narrower on a side than the light of
/// a target far above the top DN saturates through a kernel of reach `erode_px`
/// (2 · `erode_px` + 1 px): the blob is the core of a target barely above the top DN
/// (see the module). Never with `erode_px` 0 (optics that do not blur).
fn is_core(hull: Roi, erode_px: u16) -> bool {
    let across = 2 * erode_px + 1;
    hull.width() < across || hull.height() < across
}

/// What stage 8 makes of a box ([`saturated_target`]): a saturated blob's box cut
/// back, a saturated core's box grown, or neither.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Saturated {
    /// The blob's box cut by the optics' reach per side (off the frame's edges); it
    /// lies inside the box looked at.
    Cut(Roi),
    /// The core's box grown by the reach and a pixel (the pixel the halo may hold),
    /// cut to the frame: the target's outline lies in it.
    Core(Roi),
    /// No saturated blob (or a larger body with a saturated face): the box stands.
    Neither,
}

/// What stage 8 makes of `roi` (see the module), from one look at the blob (its hull
/// and rings read once). When `roi` holds at least [`MIN_BLOB_PX`] pixels at the top
/// DN, reaches at most [`PSF_RADIUS_PX`] + 1 px beyond their box on every side (it is
/// that blob and its halo, not a larger body with a saturated face) and the target does
/// not go on beyond the halo ([`continues_beyond`]): [`Saturated::Core`] when the blob
/// is narrower on a side than 2 · `erode_px` + 1 px, or has a bright halo
/// ([`HALO_SHARE_DIV`]) and its cut would leave a box, else [`Saturated::Cut`] (one
/// pixel more off a side that is a corner's tip, [`TIP_MAX_PX`]); otherwise
/// [`Saturated::Neither`]. Cost: besides the hull and rings, a scan in from each side
/// of the hull to the blob (the halo), and at most four lines of the cut box, 5 reads
/// a pixel (the tips).
pub fn saturated_target(frame: &Frame<'_>, roi: Roi, erode_px: u16) -> Saturated {
    let Some(hull) = blob_hull(frame, roi) else {
        return Saturated::Neither;
    };
    let (fw, fh) = (frame.width() as u16, frame.height() as u16);
    let (cut_x, cut_y) = (
        cut_span(hull.x0, hull.x1, erode_px, fw),
        cut_span(hull.y0, hull.y1, erode_px, fh),
    );
    let cut_stands =
        cut_x.1 - cut_x.0 >= super::MIN_BOX_SIDE_PX && cut_y.1 - cut_y.0 >= super::MIN_BOX_SIDE_PX;
    if is_core(hull, erode_px) || (erode_px > 0 && cut_stands && has_halo(frame, hull)) {
        let grow = erode_px + 1;
        return Saturated::Core(
            Roi::new(
                hull.x0.saturating_sub(grow),
                hull.y0.saturating_sub(grow),
                hull.x1.saturating_add(grow),
                hull.y1.saturating_add(grow),
            )
            .clip(fw, fh),
        );
    }
    let ((mut x0, mut x1), (mut y0, mut y1)) = (cut_x, cut_y);
    // A side whose outermost covered line is a corner's tip: one pixel more (keeping
    // at least MIN_BOX_SIDE_PX + 1 px, and every side on the frame's edge).
    if erode_px > 0 {
        let tip = |fixed: u16, span: (u16, u16), vertical: bool| {
            u32::from(span.1 - span.0) >= 2 * TIP_MAX_PX
                && covered_in_line(frame, fixed, span, vertical, erode_px, TIP_MAX_PX) <= TIP_MAX_PX
        };
        let (left, right) = (
            hull.x0 > 0 && tip(x0, (y0, y1), true),
            hull.x1 < fw && tip(x1.saturating_sub(1), (y0, y1), true),
        );
        let (upper, lower) = (
            hull.y0 > 0 && tip(y0, (x0, x1), false),
            hull.y1 < fh && tip(y1.saturating_sub(1), (x0, x1), false),
        );
        let keep = super::MIN_BOX_SIDE_PX + 1;
        if x1 - x0 >= keep + u16::from(left) + u16::from(right) {
            x0 += u16::from(left);
            x1 -= u16::from(right);
        }
        if y1 - y0 >= keep + u16::from(upper) + u16::from(lower) {
            y0 += u16::from(upper);
            y1 -= u16::from(lower);
        }
    }
    Saturated::Cut(Roi { x0, y0, x1, y1 })
}

/// True when `roi` is a saturated blob and its halo (stage 8 cuts or grows its box,
/// [`saturated_target`]).
pub fn is_saturated_blob(frame: &Frame<'_>, roi: Roi) -> bool {
    blob_hull(frame, roi).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{FRAME_HEIGHT, FRAME_WIDTH};
    extern crate std;

    /// The box stage 8 keeps unless it cuts it: `roi` cut, or unchanged.
    fn saturated_box(frame: &Frame<'_>, roi: Roi, erode_px: u16) -> Roi {
        match saturated_target(frame, roi, erode_px) {
            Saturated::Cut(cut) => cut,
            _ => roi,
        }
    }

    /// The grown box of a saturated core, or `None`.
    fn saturated_core(frame: &Frame<'_>, roi: Roi, erode_px: u16) -> Option<Roi> {
        match saturated_target(frame, roi, erode_px) {
            Saturated::Core(around) => Some(around),
            _ => None,
        }
    }

    /// A brute-force reference of the blob: a sharp rectangle far above the top DN,
    /// blurred by a 5×5 box (every pixel within 2 px of a covered one saturates), is
    /// cut back to the rectangle by 2 px per side, and not on the frame's edge.
    #[test]
    fn a_saturated_blob_is_cut_back_by_the_psf_reach() {
        let top = 4095u32;
        let rect = (100usize, 50usize, 108usize, 56usize);
        let mut px = std::vec![700u16; FRAME_WIDTH * FRAME_HEIGHT];
        let put = |px: &mut [u16], (rx0, ry0, rx1, ry1): (usize, usize, usize, usize)| {
            for y in 0..FRAME_HEIGHT {
                for x in 0..FRAME_WIDTH {
                    let mut covered = 0u32;
                    for dy in 0..5 {
                        for dx in 0..5 {
                            let (sx, sy) = ((x + dx).wrapping_sub(2), (y + dy).wrapping_sub(2));
                            covered +=
                                u32::from((rx0..rx1).contains(&sx) && (ry0..ry1).contains(&sy));
                        }
                    }
                    if covered > 0 {
                        // Face 100× the top DN: any light saturates.
                        px[y * FRAME_WIDTH + x] = (700 + covered * top * 100 / 25).min(top) as u16;
                    }
                }
            }
        };
        put(&mut px, rect);
        let frame = Frame::new(&px, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
        // The blob plus one pixel of halo, as the boundary rule finds it.
        let found = Roi::new(97, 47, 111, 59);
        let got = saturated_box(&frame, found, PSF_RADIUS_PX);
        assert_eq!(got, Roi::new(100, 50, 108, 56));
        // No cut: the blob's box.
        assert_eq!(saturated_box(&frame, found, 0), Roi::new(98, 48, 110, 58));
        // Far hotter than the top DN: no core (the blob is the face dilated).
        assert_eq!(saturated_core(&frame, found, PSF_RADIUS_PX), None);
        // A larger body with a saturated face: unchanged.
        let body = Roi::new(60, 20, 140, 90);
        assert_eq!(saturated_box(&frame, body, 2), body);
        // On the frame's corner: the sides on the edge stay.
        let mut px2 = std::vec![700u16; FRAME_WIDTH * FRAME_HEIGHT];
        put(&mut px2, (0, 0, 6, 5));
        let frame = Frame::new(&px2, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
        assert_eq!(
            saturated_box(&frame, Roi::new(0, 0, 10, 9), 2),
            Roi::new(0, 0, 6, 5)
        );
        // Unsaturated: unchanged.
        let flat = std::vec![700u16; FRAME_WIDTH * FRAME_HEIGHT];
        let frame = Frame::new(&flat, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
        assert_eq!(saturated_box(&frame, found, 2), found);
    }

    /// A square face far above the top DN, turned by `deg`, centred at (`cx`, `cy`) px
    /// with sides of `side_px`: each pixel's covered share (16 × 16 samples), the frame
    /// of the blob (every pixel within 2 px of one covered at all is at the top DN) and
    /// the truth box (pixels at least half covered).
    fn turned_square(cx: f64, cy: f64, side_px: f64, deg: f64) -> (std::vec::Vec<u16>, Roi) {
        let (s, c) = (deg.to_radians().sin(), deg.to_radians().cos());
        let inside = |x: f64, y: f64| {
            let (dx, dy) = (x - cx, y - cy);
            (dx * c + dy * s).abs() <= side_px / 2.0 && (-dx * s + dy * c).abs() <= side_px / 2.0
        };
        let (w, h) = (FRAME_WIDTH, FRAME_HEIGHT);
        let mut share = std::vec![0u32; w * h];
        for y in 0..h {
            for x in 0..w {
                if ((x as f64 + 0.5) - cx).abs() > side_px
                    || ((y as f64 + 0.5) - cy).abs() > side_px
                {
                    continue;
                }
                share[y * w + x] = (0..256)
                    .filter(|k| {
                        let (sx, sy) = ((k % 16) as f64 + 0.5, (k / 16) as f64 + 0.5);
                        inside(x as f64 + sx / 16.0, y as f64 + sy / 16.0)
                    })
                    .count() as u32;
            }
        }
        let mut px = std::vec![700u16; w * h];
        let mut truth = Roi::EMPTY;
        for y in 0..h {
            for x in 0..w {
                if share[y * w + x] >= 128 {
                    let p = Roi::pixel(x as u16, y as u16);
                    truth = truth.hull(&p);
                }
                let near = (y.saturating_sub(2)..(y + 3).min(h)).any(|yy| {
                    (x.saturating_sub(2)..(x + 3).min(w)).any(|xx| share[yy * w + xx] > 0)
                });
                if near {
                    px[y * w + x] = 4095;
                }
            }
        }
        (px, truth)
    }

    /// A face turned at an angle reaches the outermost line of the pixels it covers
    /// with a corner's tip, under half covered: that side is cut one pixel more, and
    /// the box is the truth's at 30° and 45° (brute force: the face's exact pixel
    /// shares), nearer it at 20°. Square to the axes, with its edges on pixel
    /// boundaries, it is cut by the reach alone.
    #[test]
    fn a_turned_face_is_cut_past_its_corners_tips() {
        for (deg, cx, cy) in [
            (30.0, 150.3, 100.6),
            (45.0, 150.5, 100.5),
            (20.0, 80.2, 60.7),
        ] {
            let (px, truth) = turned_square(cx, cy, 7.0, deg);
            let frame = Frame::new(&px, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
            let found = Roi::new(truth.x0 - 5, truth.y0 - 5, truth.x1 + 5, truth.y1 + 5);
            let (hull, _) = saturated_hull(&frame, found);
            let plain = Roi {
                x0: hull.x0 + 2,
                y0: hull.y0 + 2,
                x1: hull.x1 - 2,
                y1: hull.y1 - 2,
            };
            let got = saturated_box(&frame, hull, PSF_RADIUS_PX);
            assert_ne!(plain, truth, "{deg}°: the plain cut should miss");
            if deg >= 30.0 {
                assert_eq!(got, truth, "{deg}°: plain cut {plain:?}");
            } else {
                // At 20° a tip spans three pixels of the line on one side: that side
                // keeps the plain cut, the others are the truth's.
                assert!(
                    got.iou(&truth) > plain.iou(&truth),
                    "{deg}°: {got:?} {truth:?}"
                );
            }
        }
        // Square to the axes on pixel boundaries: the outermost lines are whole edges.
        let (px, truth) = turned_square(150.0, 100.0, 8.0, 0.0);
        let frame = Frame::new(&px, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
        let found = Roi::new(truth.x0 - 3, truth.y0 - 3, truth.x1 + 3, truth.y1 + 3);
        assert_eq!(saturated_box(&frame, found, PSF_RADIUS_PX), truth);
    }

    /// A square face of 16 px turned by 45° at 1.25 times the top DN over a background
    /// of 700 ± 100 DN, blurred by the 5×5 binomial kernel (the optics' Airy core, light
    /// tails): the pixels the kernel fills at ⅘ saturate, a blob inside the face, and
    /// the blurred edge around it is bright (the halo). Cut by the reach its box would
    /// lie inside the face's truth; it is taken as a core (its box grown, for the half
    /// maximum). The same face far above the top DN has no halo and is cut.
    #[test]
    fn a_blob_with_a_halo_is_not_cut() {
        let top = 4095.0f64;
        let (cx, cy, side, deg) = (150.5f64, 100.5f64, 16.0f64, 45.0f64);
        let (s, c) = (deg.to_radians().sin(), deg.to_radians().cos());
        // Each pixel's covered share (8 × 8 samples) around the face.
        let share = |x: i64, y: i64| -> f64 {
            (0..64)
                .filter(|k| {
                    let (px, py) = (
                        x as f64 + ((k % 8) as f64 + 0.5) / 8.0,
                        y as f64 + ((k / 8) as f64 + 0.5) / 8.0,
                    );
                    let (dx, dy) = (px - cx, py - cy);
                    (dx * c + dy * s).abs() <= side / 2.0 && (-dx * s + dy * c).abs() <= side / 2.0
                })
                .count() as f64
                / 64.0
        };
        let weights = [1.0, 4.0, 6.0, 4.0, 1.0];
        let render = |gain: f64| {
            let mut px = std::vec![0u16; FRAME_WIDTH * FRAME_HEIGHT];
            let mut seed = 12345u64;
            for y in 0..FRAME_HEIGHT {
                for x in 0..FRAME_WIDTH {
                    seed = seed
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    let noise = ((seed >> 33) % 201) as f64 - 100.0;
                    let mut blurred = 0.0;
                    if (x as f64 - cx).abs() < 20.0 && (y as f64 - cy).abs() < 20.0 {
                        for (ky, wy) in weights.iter().enumerate() {
                            for (kx, wx) in weights.iter().enumerate() {
                                let (sx, sy) = (x as i64 + kx as i64 - 2, y as i64 + ky as i64 - 2);
                                blurred += wx * wy / 256.0 * share(sx, sy);
                            }
                        }
                    }
                    let v = 700.0 + noise + blurred * gain * (top - 700.0);
                    px[y * FRAME_WIDTH + x] = v.min(top) as u16;
                }
            }
            px
        };
        // The truth: pixels at least half covered.
        let mut truth = Roi::EMPTY;
        for y in 80..121u16 {
            for x in 130..171u16 {
                if share(i64::from(x), i64::from(y)) >= 0.5 {
                    truth = truth.hull(&Roi::pixel(x, y));
                }
            }
        }
        let search = Roi::new(125, 75, 176, 126);
        let px = render(1.25);
        let frame = Frame::new(&px, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
        let (hull, _) = saturated_hull(&frame, search);
        assert!(
            truth.contains_roi(&hull) && hull != truth,
            "{hull:?} {truth:?}"
        );
        assert!(has_halo(&frame, hull));
        let found = Roi::new(hull.x0 - 3, hull.y0 - 3, hull.x1 + 3, hull.y1 + 3);
        let around = saturated_core(&frame, found, 2).expect("taken as a core");
        assert!(around.contains_roi(&truth), "{around:?} {truth:?}");
        // Far above the top DN: no halo, cut back to within a pixel a side of the truth
        // (this face's tips are half covered: the tip rule's coin toss falls short).
        let px = render(400.0);
        let frame = Frame::new(&px, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
        let (hull, _) = saturated_hull(&frame, search);
        assert!(!has_halo(&frame, hull));
        let found = Roi::new(hull.x0 - 1, hull.y0 - 1, hull.x1 + 1, hull.y1 + 1);
        assert_eq!(saturated_core(&frame, found, 2), None);
        let cut = saturated_box(&frame, found, 2);
        let near = |a: u16, b: u16| a.abs_diff(b) <= 1;
        assert!(
            near(cut.x0, truth.x0)
                && near(cut.y0, truth.y0)
                && near(cut.x1, truth.x1)
                && near(cut.y1, truth.y1),
            "{cut:?} {truth:?}"
        );
    }

    /// A target barely above the top DN (a 4×4 px face at twice the top DN over the
    /// background, blurred by the 5×5 box): only the pixels whose kernel holds at least
    /// 11 of its 16 saturate, the face less its corners, a core 4 px across, narrower
    /// than the 8 px the kernel spreads a far hotter target to. Its box is not cut; it
    /// is the core grown by the kernel's reach and a pixel, which holds the face. Without blur (`erode_px` 0) no blob is a core; the far hotter
    /// blob of the test above is none either.
    #[test]
    fn a_saturated_core_is_not_cut() {
        let top = 4095u32;
        let (rx0, ry0) = (120usize, 90usize);
        let mut px = std::vec![700u16; FRAME_WIDTH * FRAME_HEIGHT];
        for y in ry0 - 4..ry0 + 8 {
            for x in rx0 - 4..rx0 + 8 {
                let covered = (0..25)
                    .filter(|k| {
                        let (sx, sy) = ((x + k % 5).wrapping_sub(2), (y + k / 5).wrapping_sub(2));
                        (rx0..rx0 + 4).contains(&sx) && (ry0..ry0 + 4).contains(&sy)
                    })
                    .count() as u32;
                px[y * FRAME_WIDTH + x] = (700 + covered * top * 2 / 25).min(top) as u16;
            }
        }
        let frame = Frame::new(&px, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
        let saturated: std::vec::Vec<(usize, usize)> = (0..FRAME_WIDTH * FRAME_HEIGHT)
            .filter(|&i| u32::from(px[i]) >= top)
            .map(|i| (i % FRAME_WIDTH, i / FRAME_WIDTH))
            .collect();
        let face: std::vec::Vec<(usize, usize)> = (ry0..ry0 + 4)
            .flat_map(|y| (rx0..rx0 + 4).map(move |x| (x, y)))
            .filter(|&(x, y)| !((x == rx0 || x == rx0 + 3) && (y == ry0 || y == ry0 + 3)))
            .collect();
        assert_eq!(saturated, face, "the face less its corners");
        // The core and a pixel of halo, as the boundary rule finds it.
        let found = Roi::new(119, 89, 125, 95);
        assert_eq!(saturated_box(&frame, found, 2), found);
        let around = saturated_core(&frame, found, 2).expect("a core");
        assert_eq!(around, Roi::new(117, 87, 127, 97));
        assert!(around.contains_roi(&Roi::new(120, 90, 124, 94)), "the face");
        assert_eq!(saturated_core(&frame, found, 0), None);
        // A core at the frame's corner: the grown box is cut to the frame.
        let mut corner = std::vec![700u16; FRAME_WIDTH * FRAME_HEIGHT];
        for (x, y) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            corner[y * FRAME_WIDTH + x] = top as u16;
        }
        let frame = Frame::new(&corner, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
        assert_eq!(
            saturated_core(&frame, Roi::new(0, 0, 3, 3), 2),
            Some(Roi::new(0, 0, 5, 5))
        );
    }

    /// The rings against a brute-force walk of the frame (Chebyshev distance of every
    /// pixel from the hull), hulls in the middle, on the edges and in a corner.
    #[test]
    fn rings_hold_exactly_the_pixels_at_their_distance() {
        let (w, h) = (40usize, 30usize);
        let px: std::vec::Vec<u16> = (0..w * h).map(|i| i as u16).collect();
        let frame = Frame::new(&px, w, h, 12).unwrap();
        let hulls = [
            Roi::new(10, 10, 14, 13),
            Roi::new(0, 0, 3, 2),
            Roi::new(37, 5, 40, 30),
            Roi::new(18, 0, 19, 1),
        ];
        for hull in hulls {
            for (from, to, margin) in [
                (1u16, 2u16, 0usize),
                (3, 4, 2),
                (5, 6, 0),
                (1, 1, 1),
                (2, 7, 3),
            ] {
                let mut got = std::vec::Vec::new();
                for_each_ring_px(&frame, hull, from, to, margin, |v| got.push(v));
                got.sort_unstable();
                let dist = |a: usize, lo: u16, hi: u16| {
                    let (lo, hi) = (usize::from(lo), usize::from(hi));
                    if a < lo {
                        lo - a
                    } else {
                        (a + 1).saturating_sub(hi)
                    }
                };
                let want: std::vec::Vec<u16> = (0..w * h)
                    .filter(|&i| {
                        let (x, y) = (i % w, i / w);
                        let d = dist(x, hull.x0, hull.x1).max(dist(y, hull.y0, hull.y1));
                        let inside =
                            (margin..w - margin).contains(&x) && (margin..h - margin).contains(&y);
                        inside && (usize::from(from)..=usize::from(to)).contains(&d)
                    })
                    .map(|i| i as u16)
                    .collect();
                assert_eq!(got, want, "{hull:?} {from}..={to} margin {margin}");
            }
        }
    }

    /// A hot face of a larger body (a saturated 8×6 face on a 2 000 DN body whose
    /// cooler part goes on 4 px beyond the halo on two sides, over 700 DN) is no blob:
    /// its box is left to the body stage; the same face alone is cut, with a few noise
    /// spikes around it or without.
    #[test]
    fn a_saturated_face_of_a_larger_body_is_not_cut() {
        let (w, h) = (120usize, 80usize);
        let top = 4095u16;
        let face = (50usize, 30usize, 58usize, 36usize);
        let draw = |body: bool, spikes: bool| {
            let mut px = std::vec![700u16; w * h];
            for y in 0..h {
                for x in 0..w {
                    let near_face = (face.0 - 2..face.2 + 2).contains(&x)
                        && (face.1 - 2..face.3 + 2).contains(&y);
                    let in_body = (face.0 - 2..face.2 + 6).contains(&x)
                        && (face.1 - 2..face.3 + 6).contains(&y);
                    if near_face {
                        px[y * w + x] = top;
                    } else if body && in_body {
                        px[y * w + x] = 2000;
                    }
                }
            }
            if spikes {
                // Two hot pixels in the near ring (1 of 10 would be 9 of its 88).
                px[(face.1 - 5) * w + face.0] = 1900;
                px[(face.3 + 3) * w + face.2 + 2] = 1900;
            }
            px
        };
        let found = Roi::new(47, 27, 61, 39);
        let with_body = draw(true, false);
        let frame = Frame::new(&with_body, w, h, 12).unwrap();
        assert!(!is_saturated_blob(&frame, found));
        assert_eq!(saturated_box(&frame, found, 2), found);
        // A cold cloud cell (300 DN) beside the face, across the near ring on one side,
        // is the surroundings' texture, not the body: the blob is cut.
        let mut cloud = draw(false, false);
        for y in face.1 - 8..face.3 + 8 {
            for x in face.2 + 3..face.2 + 5 {
                cloud[y * w + x] = 300;
            }
        }
        let frame = Frame::new(&cloud, w, h, 12).unwrap();
        assert_eq!(saturated_box(&frame, found, 2), Roi::new(50, 30, 58, 36));
        for spikes in [false, true] {
            let alone = draw(false, spikes);
            let frame = Frame::new(&alone, w, h, 12).unwrap();
            assert!(is_saturated_blob(&frame, found), "spikes {spikes}");
            assert_eq!(saturated_box(&frame, found, 2), Roi::new(50, 30, 58, 36));
        }
    }

    #[test]
    fn spans_keep_a_pixel_and_stay_inside() {
        for a in 0u16..12 {
            for b in a + 1..20 {
                for e in 0..6 {
                    let (c, d) = cut_span(a, b, e, 20);
                    assert!(a <= c && c < d && d <= b, "{a} {b} {e}: {c} {d}");
                    if a > 0 && b < 20 && 2 * e < b - a {
                        assert_eq!((c, d), (a + e, b - e));
                    }
                }
            }
        }
    }
}
