//! The Earth's limb at the frame's border (session 45). Over deep space the Earth's
//! disc, cut by the frame, shows as a bright triangle in a corner or a sliver along a
//! side; the classifier's winner there was most of family A's no-target false alarms
//! (11 of 17 of famAE's). Its in-frame boundary is one arc of the disc (at the
//! camera's ~10 900 km from the Earth's centre its angular radius is ~36°, ~700 px, so
//! the arc is nearly straight over a frame), while a spacecraft cut by the frame shows
//! corners. A spacecraft's single straight edge at the border would look the same, so
//! the test stays narrow: a box on the frame's border, at most a quarter of the frame,
//! hardly saturated (a saturated target's face cut by the frame is straight too,
//! family A's detection frames), whose boundary between its two levels (Otsu inside
//! the box) follows a parabola within [`MAX_ARC_RMS2_PX2`]. A boundary pixel counts
//! only with 3 px of its level behind it and of the other level beyond (session 50), so
//! hot pixels and cold specks off the arc do not break the fit.
//!
//! The converse, [`Outline::Bends`] (session 53): a boundary far from every parabola is a
//! target's corner or bend, never the disc's arc; stage 2c boxes a piece in a corner of
//! deep space only when its outline bends, since the disc cut by a corner shows there
//! too.
//!
//! The disc saturated by the camera (session 54, [`is_saturated_disc`]): in a corner,
//! with deep space beyond it, the envelope of its bright level is one convex arc that
//! sags visibly and bends no more than the limb can.

use crate::frame::Frame;
use crate::roi::Roi;

/// Histogram bins of the box's Otsu threshold (between its lowest and highest DN).
const OTSU_BINS: usize = 256;

/// Largest box tested, as a share of the frame (1/4): the limb pieces that won on
/// family A were slivers of 30–100 px; a larger box is left to the confidence (and the
/// test's cost, about 8 reads of each of its pixels, stays under a quarter frame).
const MAX_FRAME_SHARE_DIVISOR: usize = 4;

/// A box with at least 1/10 of its pixels at the top DN is a saturated target's face
/// (family A: saturated detection targets cut by the frame have straight edges too,
/// their boxes 39–97 % saturated; the limb's were 0–1 %).
const SATURATED_SHARE_DIVISOR: u32 = 10;

/// Largest saturated box [`is_saturated_disc`] tests, as a share of the frame (1/2): the
/// Earth's disc saturated and cut by a corner (famAE, session 54: the saturated blob's
/// boxes 20 % and 28 % of the frame); its cost, at most 8 reads of each pixel of the
/// box, stays under 4 frames' worth.
const SATURATED_CORNER_SHARE_DIVISOR: usize = 2;

/// How far, px, the region must go on behind a boundary pixel and the other level
/// beyond it, within the box, for the pixel to count (3): a hot pixel in the deep sky
/// or a cluster of cold pixels on the Earth's side (the real camera's hot pixels, the
/// renderer's small cold elements, 1–3 px across) is no boundary of the limb. Without
/// it a few such specks 30–60 px off the arc broke the fit (session 50: the deep sky
/// in a corner of an Earth-filled frame, `famAS/000080`, boxed by a retrained forest:
/// 11 px rms with them, 0.2 px without); the boundary of a half-plane or of a disc of
/// 700 px radius passes whatever the slant (bar its pixels within 2 px of the box's
/// sides), a U-shaped outline's sides and corners too, so a target's still fails.
const BOUNDARY_DEPTH_PX: usize = 3;

/// Fewest boundary pixels for a fit: fewer is a speck, not an arc.
const MIN_BOUNDARY_PX: u32 = 8;

/// Largest mean squared distance, px², of the boundary pixels from the fitted
/// parabola for an arc: 1.7² (family A, session 45: the limb's boundaries 1.2–1.6 px
/// rms, as a 4-connected staircase of a slanted line is about 1 px thick; two edges
/// meeting at a corner depart further).
pub const MAX_ARC_RMS2_PX2: f64 = 2.89;

/// Smallest mean squared distance, px², of the boundary pixels from the fitted
/// parabola for an outline that bends ([`Outline::Bends`]): 6 × [`MAX_ARC_RMS2_PX2`] (4.2 px
/// rms). Between the largest non-target outline of family A (session 53, stage 2c's
/// corner pieces of seeds 7001–7201: the paper world's limb in a corner, ragged by its
/// noise, `paperA/000078`, 8.6 px², 3.0 ×) and the smallest target's corner piece that
/// decides a frame (`famA/000039`, a rectangle's corner, 31.4 px², 10.9 ×), about
/// twice the one and half the other; every factor from 3.3 to 10.8 gives family A the
/// same answers (`famAT/000105`'s corner piece, 9.4 px², is boxed under 3.3 ×).
pub const MIN_BEND_RMS2_PX2: f64 = 6.0 * MAX_ARC_RMS2_PX2;

/// Whether `roi` is a piece of the Earth's limb at the frame's border (see the module
/// docs): `false` for a box not on the border, over a quarter of the frame, under
/// 3 px on a side, at least a tenth saturated, with fewer than [`MIN_BOUNDARY_PX`]
/// boundary pixels, or whose boundary is not an arc. Four passes over the box (about
/// 8 pixel reads per pixel: range, histogram, region, and each region pixel's four
/// neighbours, 2·`BOUNDARY_DEPTH_PX` more where one is of the other level); 1 KiB
/// of stack (the histogram).
pub fn is_limb(frame: &Frame<'_>, roi: Roi) -> bool {
    outline(frame, roi) == Outline::Arc
}

/// What the boundary in a box at the frame's border is ([`outline`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outline {
    /// One arc: within [`MAX_ARC_RMS2_PX2`] of a parabola (the Earth's limb, or a single
    /// straight edge).
    Arc,
    /// At least [`MIN_BEND_RMS2_PX2`] from every parabola: a corner or a bend inside the
    /// box, which a piece of the Earth's disc cut by the frame (one nearly straight arc)
    /// never shows.
    Bends,
    /// Between the two, or nothing to measure (a box off the border, too large,
    /// saturated, with too few boundary pixels: see [`is_limb`]).
    Unclear,
}

/// The boundary in `roi` read as [`is_limb`] reads it, classed by its mean squared
/// distance from the best parabola ([`Outline`]). Same cost as [`is_limb`].
pub fn outline(frame: &Frame<'_>, roi: Roi) -> Outline {
    match arc_rms2_px2(frame, roi) {
        Some(rms2) if rms2 <= MAX_ARC_RMS2_PX2 => Outline::Arc,
        Some(rms2) if rms2 >= MIN_BEND_RMS2_PX2 => Outline::Bends,
        _ => Outline::Unclear,
    }
}

/// `roi`'s ends `(x0, y0, x1, y1)`, px, when it lies in the frame and spans at least
/// 3 px each way (a boundary with a pixel on either side); `None` otherwise.
fn measurable(frame: &Frame<'_>, roi: Roi) -> Option<(usize, usize, usize, usize)> {
    let (x0, y0, x1, y1) = (
        usize::from(roi.x0),
        usize::from(roi.y0),
        usize::from(roi.x1),
        usize::from(roi.y1),
    );
    let inside = x1 <= frame.width() && y1 <= frame.height();
    (inside && x1 >= x0 + 3 && y1 >= y0 + 3).then_some((x0, y0, x1, y1))
}

/// The mean squared distance, px², of the boundary pixels in `roi` from the best
/// parabola (the lesser of `y` on `x` and `x` on `y`); `None` where [`is_limb`] says
/// `false` before fitting (see there).
fn arc_rms2_px2(frame: &Frame<'_>, roi: Roi) -> Option<f64> {
    let (w, h) = (frame.width(), frame.height());
    let (x0, y0, x1, y1) = measurable(frame, roi)?;
    let on_border = [x0 == 0, y0 == 0, x1 == w, y1 == h];
    let area = (x1 - x0) * (y1 - y0);
    if !on_border.contains(&true) || area * MAX_FRAME_SHARE_DIVISOR > w * h {
        return None;
    }
    let rows = || (y0..y1).filter_map(|y| frame.row(y).and_then(|r| r.get(x0..x1)));
    // Pass 1: the box's range and its saturated pixels.
    let (lo, hi, saturated) = range_and_saturated(rows(), frame.max_dn());
    if hi <= lo || saturated * SATURATED_SHARE_DIVISOR >= area as u32 {
        return None;
    }
    // Pass 2: Otsu's threshold on a histogram of the box.
    let above_dn = otsu_dn(rows, (lo, hi))?;
    let above = |v: u16| u32::from(v) >= above_dn;
    // The region is the level the border sides of the box mostly show.
    let mut border = [0u32; 2];
    let mut count = |v: u16| border[usize::from(above(v))] += 1;
    for (y, row) in (y0..y1).zip(rows()) {
        if let (true, Some(&v)) = (on_border[0], row.first()) {
            count(v);
        }
        if let (true, Some(&v)) = (on_border[2], row.last()) {
            count(v);
        }
        if (on_border[1] && y == y0) || (on_border[3] && y == y1 - 1) {
            row.iter().copied().for_each(&mut count);
        }
    }
    let region_above = border[1] >= border[0];
    // Whether the box's pixel (x, y) is in the region; `None` outside the box.
    let pixels = frame.pixels();
    let inside = |x: isize, y: isize| -> Option<bool> {
        let (x, y) = (usize::try_from(x).ok()?, usize::try_from(y).ok()?);
        if !(x0..x1).contains(&x) || !(y0..y1).contains(&y) {
            return None;
        }
        pixels.get(y * w + x).map(|&v| above(v) == region_above)
    };
    // Pass 3: the boundary pixels (in the region, a 4-neighbour in the box not, with
    // the region behind it and the other level beyond for [`BOUNDARY_DEPTH_PX`] each
    // way, all in the box) and the sums of two parabola fits, y on x and x on y
    // (pixel centres from the box's centre, px; exact in f64).
    let depth = BOUNDARY_DEPTH_PX as isize;
    let crosses = |x: isize, y: isize, dx: isize, dy: isize| {
        inside(x + dx, y + dy) == Some(false)
            && (1..depth).all(|k| {
                inside(x - k * dx, y - k * dy) == Some(true)
                    && inside(x + (k + 1) * dx, y + (k + 1) * dy) == Some(false)
            })
    };
    let from_centre = |a: usize, lo: usize, hi: usize| a as f64 + 0.5 - (lo + hi) as f64 / 2.0;
    let mut fit_x = ParabolaSums::default();
    let mut fit_y = ParabolaSums::default();
    for y in y0..y1 {
        for x in x0..x1 {
            let (xi, yi) = (x as isize, y as isize);
            if inside(xi, yi) != Some(true) {
                continue;
            }
            let boundary = crosses(xi, yi, -1, 0)
                || crosses(xi, yi, 1, 0)
                || crosses(xi, yi, 0, -1)
                || crosses(xi, yi, 0, 1);
            if boundary {
                let (u, v) = (from_centre(x, x0, x1), from_centre(y, y0, y1));
                fit_x.add(u, v);
                fit_y.add(v, u);
            }
        }
    }
    if fit_x.n < f64::from(MIN_BOUNDARY_PX) {
        return None;
    }
    Some(fit_x.residual2().min(fit_y.residual2()))
}

/// The lowest and the highest DN of `rows` and how many of their pixels are at `top`
/// (the frame's top DN): `(u16::MAX, 0, 0)` without a pixel.
fn range_and_saturated<'a>(rows: impl Iterator<Item = &'a [u16]>, top: u16) -> (u16, u16, u32) {
    rows.flatten().fold((u16::MAX, 0, 0), |(lo, hi, n), &v| {
        (lo.min(v), hi.max(v), n + u32::from(v >= top))
    })
}

/// The lowest DN of the upper class of Otsu's threshold over the rows `rows` (DN
/// range `lo..=hi`, `lo < hi`), from a histogram of [`OTSU_BINS`] bins; `None` with one
/// occupied bin.
fn otsu_dn<'a, I: Iterator<Item = &'a [u16]>>(
    rows: impl Fn() -> I,
    (lo, hi): (u16, u16),
) -> Option<u32> {
    let span = u32::from(hi.saturating_sub(lo)) + 1;
    let bin = |v: u16| (u32::from(v.saturating_sub(lo)) * OTSU_BINS as u32 / span) as usize;
    let mut hist = [0u32; OTSU_BINS];
    for row in rows() {
        for &v in row {
            if let Some(c) = hist.get_mut(bin(v)) {
                *c += 1;
            }
        }
    }
    let t_bin = otsu_bin(&hist)?;
    // `bin(v) > t_bin` as one comparison: (v − lo)·256 / span ≥ t_bin + 1.
    Some(u32::from(lo) + ((t_bin as u32 + 1) * span).div_ceil(OTSU_BINS as u32))
}

/// Whether `roi`, a box in a corner of the frame, is the Earth's disc saturated by the
/// camera (session 54: two of famAE's last eight no-target false alarms, boxed by the
/// saturated blob at 553 and 770 ‰): `false` unless the box lies in a corner (one
/// vertical and one horizontal side of the frame), covers at most half the frame
/// ([`SATURATED_CORNER_SHARE_DIVISOR`]) and is at least a tenth saturated. The disc's
/// saturated part ends inside it where the limb darkens and its clouds cut holes, so
/// the boundary [`is_limb`] fits is ragged; the disc's own edge is the envelope of the
/// bright level (Otsu's in the box): per row, from the box's far side towards the
/// frame's vertical side, the first bright pixel, and per column the same towards the
/// horizontal side. The disc when, along rows or columns, deep space lies beyond that
/// edge (the pixels [`SKY_BEYOND_PX`] past it average at most `sky_max_dn`, DN) and the
/// edge is one convex arc of the disc ([`disc_edge`]: a parabola within
/// [`MAX_ARC_RMS2_PX2`] bar isolated specks, bulging away from the corner, sagging at
/// least [`DISC_MIN_SAG_PX`] and bending no more than the limb can). A saturated
/// target in the corner shows corners, a straight edge or a tight round face; over
/// the Earth, the Earth lies beyond it. Cost, on a box in a corner only: two passes over
/// the box (range, histogram), then each row's and column's edge scan three times (the
/// sky beyond, the first fit, the refit without strays; a scan stops at the first bright
/// pixel from the far side): at most 8 reads per pixel of the box; 1 KiB of stack (the
/// histogram). Stage 4d calls [`is_limb`] first, whose range pass this repeats.
pub fn is_saturated_disc(frame: &Frame<'_>, roi: Roi, sky_max_dn: u32) -> bool {
    let (w, h) = (frame.width(), frame.height());
    let Some((x0, y0, x1, y1)) = measurable(frame, roi) else {
        return false;
    };
    let (left, right, top_side, bottom) = (x0 == 0, x1 == w, y0 == 0, y1 == h);
    if !((left || right) && (top_side || bottom)) {
        return false;
    }
    let area = (x1 - x0) * (y1 - y0);
    if area * SATURATED_CORNER_SHARE_DIVISOR > w * h {
        return false;
    }
    let rows = || (y0..y1).filter_map(|y| frame.row(y).and_then(|r| r.get(x0..x1)));
    let (lo, hi, saturated) = range_and_saturated(rows(), frame.max_dn());
    if hi <= lo || saturated * SATURATED_SHARE_DIVISOR < area as u32 {
        return false;
    }
    let Some(bright_dn) = otsu_dn(rows, (lo, hi)) else {
        return false;
    };
    let pixels = frame.pixels();
    let at = |x: usize, y: usize| pixels.get(y * w + x).map(|&v| u32::from(v));
    let bright = |x: usize, y: usize| at(x, y).is_some_and(|v| v >= bright_dn);
    let centre = |a: usize, lo: usize, hi: usize| a as f64 + 0.5 - (lo + hi) as f64 / 2.0;
    // Per row, the edge's column: from the box's far side towards the frame's vertical
    // side, the first bright pixel; a row bright to the far side (the disc goes on
    // beyond the box) or without one is left out. Per column the same towards the
    // horizontal side. `beyond`: the pixel `SKY_BEYOND_PX` past the edge, if in the box.
    let row_edge = |y: usize| edge(x0..x1, left, |x| bright(x, y));
    let column_edge = |x: usize| edge(y0..y1, top_side, |y| bright(x, y));
    let beyond = |e: usize, (lo, hi): (usize, usize), from_low: bool| {
        if from_low {
            Some(e + SKY_BEYOND_PX)
        } else {
            e.checked_sub(SKY_BEYOND_PX)
        }
        .filter(|b| (lo..hi).contains(b))
    };
    // Beyond the disc's edge is deep space: the pixels past each edge point average no
    // warmer than `sky_max_dn` (a saturated target's piece over the Earth has the
    // Earth beyond it).
    let sky_rows = (y0..y1).filter_map(|y| {
        row_edge(y)
            .and_then(|e| beyond(e, (x0, x1), left))
            .and_then(|x| at(x, y))
    });
    let sky_columns = (x0..x1).filter_map(|x| {
        column_edge(x)
            .and_then(|e| beyond(e, (y0, y1), top_side))
            .and_then(|y| at(x, y))
    });
    let (sky_sum, sky_n) = sky_rows
        .chain(sky_columns)
        .fold((0u64, 0u64), |(s, n), v| (s + u64::from(v), n + 1));
    if sky_sum
        .checked_div(sky_n)
        .is_none_or(|m| m > u64::from(sky_max_dn))
    {
        return false;
    }
    let rows_fit =
        (y0..y1).filter_map(|y| row_edge(y).map(|x| (centre(y, y0, y1), centre(x, x0, x1))));
    let columns_fit =
        (x0..x1).filter_map(|x| column_edge(x).map(|y| (centre(x, x0, x1), centre(y, y0, y1))));
    // The disc's bright region is convex: its edge bulges away from the corner.
    let away = |towards_high: bool| if towards_high { 1.0 } else { -1.0 };
    disc_edge(rows_fit, away(left)) || disc_edge(columns_fit, away(top_side))
}

/// The edge of the bright level along one line of a box (`span`, px): scanning from
/// the box's far side towards the frame's side the box touches (the low end when
/// `from_low`), the first pixel `bright` says is bright; `None` without one or when
/// the line is bright to the far side (the bright level goes on beyond the box).
fn edge(
    span: core::ops::Range<usize>,
    from_low: bool,
    bright: impl Fn(usize) -> bool,
) -> Option<usize> {
    let (lo, hi) = (span.start, span.end);
    if from_low {
        span.rev().find(|&i| bright(i)).filter(|&i| i + 1 < hi)
    } else {
        span.into_iter().find(|&i| bright(i)).filter(|&i| i > lo)
    }
}

/// How far past the disc's edge [`is_saturated_disc`] reads the sky, px: beyond the
/// blur of the edge (the optics' spread, 1–2 px).
const SKY_BEYOND_PX: usize = 4;

/// Points farther than this from the first parabola, px, are strays (a hot pixel in
/// the sky beyond the disc, a bright speck): 3 px, the reach [`BOUNDARY_DEPTH_PX`]
/// gives the other fit.
const STRAY_PX: f64 = 3.0;

/// At most one point in this many may be a stray ([`STRAY_PX`]): a few hot pixels,
/// not a target's outline.
const MAX_STRAY_DIVISOR: f64 = 10.0;

/// Whether the points (`u`, `v`, in order along `u`) are the disc's edge: they follow
/// one parabola of `v` on `u` (at least [`MIN_BOUNDARY_PX`] of them, at most a tenth
/// farther than [`STRAY_PX`] from the first fit and no two of those in a row: specks,
/// not a run of the outline; the others refitted within [`MAX_ARC_RMS2_PX2`]), which
/// bulges towards increasing `v` when `bulge` is positive (the bright region convex,
/// as a disc is) and decreasing `v` when it is negative, visibly
/// ([`DISC_MIN_SAG_PX`] over its chord: a target's straight edge does not bend) and no
/// more than the disc's limb can ([`DISC_CURVATURE_SLACK`]).
fn disc_edge(points: impl Iterator<Item = (f64, f64)> + Clone, bulge: f64) -> bool {
    let mut all = ParabolaSums::default();
    points.clone().for_each(|(u, v)| all.add(u, v));
    let Some((a, b, c)) = all.coefficients() else {
        return false;
    };
    // Squared distance across the curve, as `residual2` measures it.
    let off2 = |u: f64, v: f64| {
        let d = v - (a + b * u + c * u * u);
        d * d / (1.0 + b * b)
    };
    let mut kept = ParabolaSums::default();
    let (mut u_lo, mut u_hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut last_stray = false;
    for (u, v) in points {
        let stray = off2(u, v) > STRAY_PX * STRAY_PX;
        // Two strays in a row are a run of the outline off the arc (a corner), not
        // a speck.
        if stray && last_stray {
            return false;
        }
        if !stray {
            kept.add(u, v);
            u_lo = u_lo.min(u);
            u_hi = u_hi.max(u);
        }
        last_stray = stray;
    }
    let follows = kept.n >= f64::from(MIN_BOUNDARY_PX)
        && (all.n - kept.n) * MAX_STRAY_DIVISOR <= all.n
        && kept.residual2() <= MAX_ARC_RMS2_PX2;
    let Some((_, b, c)) = kept.coefficients().filter(|_| follows) else {
        return false;
    };
    // At the box's centre: curvature 2|c| / (1 + b²)^(3/2); the sag across the chord
    // of length L along `u`, |c| · L² / (4 √(1 + b²)). Both compared squared.
    let slope2 = 1.0 + b * b;
    let chord = u_hi - u_lo;
    let max_curvature = DISC_CURVATURE_SLACK / f64::from(super::EARTH_MIN_LIMB_RADIUS_PX);
    c * bulge < 0.0
        && 4.0 * c * c <= max_curvature * max_curvature * slope2 * slope2 * slope2
        && c * c * chord * chord * chord * chord
            >= 16.0 * DISC_MIN_SAG_PX * DISC_MIN_SAG_PX * slope2
}

/// How much more the fitted edge may bend than the disc's tightest limb
/// ([`super::EARTH_MIN_LIMB_RADIUS_PX`]): 2, for the fit's own noise; a target's
/// rounded vertex in a corner (famAT/000204, a Tango face's tip 31 px across, radius
/// 11–15 px) bends far more, and a parabola follows it within [`MAX_ARC_RMS2_PX2`].
const DISC_CURVATURE_SLACK: f64 = 2.0;

/// Least sag of the disc's edge across its chord, px: 1. A saturated panel's straight
/// edge in a corner over deep space (famBW/000725, held out) fits a parabola too, with
/// none; the saturated disc's pieces of famAE (session 54) sag 2.7 and 5.6 px (radii
/// 1 190 and 914 px over chords of 160 and 200 px).
const DISC_MIN_SAG_PX: f64 = 1.0;

/// The bin of Otsu's threshold (the last bin of the lower class) over `hist`; `None`
/// with one occupied bin.
fn otsu_bin(hist: &[u32; OTSU_BINS]) -> Option<usize> {
    let total: f64 = hist.iter().map(|&c| f64::from(c)).sum();
    let sum: f64 = hist
        .iter()
        .enumerate()
        .map(|(i, &c)| i as f64 * f64::from(c))
        .sum();
    let (mut w0, mut m0) = (0.0f64, 0.0f64);
    let mut best: Option<(usize, f64)> = None;
    for (i, &c) in hist.iter().enumerate() {
        w0 += f64::from(c);
        m0 += i as f64 * f64::from(c);
        let w1 = total - w0;
        if w0 == 0.0 || w1 == 0.0 {
            continue;
        }
        let d = sum * w0 - m0 * total;
        let between = d * d / (w0 * w1);
        if best.is_none_or(|(_, b)| between > b) {
            best = Some((i, between));
        }
    }
    best.map(|(i, _)| i)
}

/// Sums of the least-squares parabola `v = a + b·u + c·u²` over points `(u, v)`.
#[derive(Default, Clone, Copy)]
struct ParabolaSums {
    n: f64,
    u: f64,
    u2: f64,
    u3: f64,
    u4: f64,
    v: f64,
    uv: f64,
    u2v: f64,
    v2: f64,
}

impl ParabolaSums {
    fn add(&mut self, u: f64, v: f64) {
        let u2 = u * u;
        self.n += 1.0;
        self.u += u;
        self.u2 += u2;
        self.u3 += u2 * u;
        self.u4 += u2 * u2;
        self.v += v;
        self.uv += u * v;
        self.u2v += u2 * v;
        self.v2 += v * v;
    }

    /// The best parabola's `(a, b, c)`; `None` when `u` takes fewer than three values
    /// (no parabola of `v` on `u`).
    fn coefficients(&self) -> Option<(f64, f64, f64)> {
        let m = [
            [self.n, self.u, self.u2],
            [self.u, self.u2, self.u3],
            [self.u2, self.u3, self.u4],
        ];
        let b = [self.v, self.uv, self.u2v];
        let det = det3(&m);
        if det.is_nan() || det.abs() <= 1e-9 * self.n.max(1.0) {
            return None;
        }
        // Cramer's rule: each coefficient from `m` with one column replaced by `b`.
        let coef = |k: usize| {
            let mut mk = m;
            for (row, &bi) in mk.iter_mut().zip(b.iter()) {
                if let Some(c) = row.get_mut(k) {
                    *c = bi;
                }
            }
            det3(&mk) / det
        };
        Some((coef(0), coef(1), coef(2)))
    }

    /// The mean squared distance of the points from the best parabola, px², across
    /// it (∞ when `u` takes fewer than three values: no parabola of `v` on `u`).
    fn residual2(&self) -> f64 {
        let Some((a, b1, c)) = self.coefficients() else {
            return f64::INFINITY;
        };
        let rss = self.v2 - (a * self.v + b1 * self.uv + c * self.u2v);
        // From distances along `v` to distances across the curve (its slope at the
        // box's centre): a slanted line's points lie √(1 + b²) farther along `v`.
        rss.max(0.0) / self.n / (1.0 + b1 * b1)
    }
}

fn det3(m: &[[f64; 3]; 3]) -> f64 {
    let [[a, b, c], [d, e, f], [g, h, i]] = *m;
    a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
}

#[cfg(test)]
mod tests {
    use super::*;

    const W: usize = 160;
    const H: usize = 120;

    /// A 14-bit frame: 1 000 DN deep space, 6 000 DN where `bright(x, y)`.
    fn frame_of(bright: impl Fn(f64, f64) -> bool) -> [u16; W * H] {
        let mut px = [1000u16; W * H];
        for y in 0..H {
            for x in 0..W {
                if bright(x as f64 + 0.5, y as f64 + 0.5) {
                    px[y * W + x] = 6000;
                }
            }
        }
        px
    }

    fn roi(x0: u16, y0: u16, x1: u16, y1: u16) -> Roi {
        Roi { x0, y0, x1, y1 }
    }

    #[test]
    fn a_disc_in_the_corner_is_the_limb() {
        // A disc of 700 px radius whose edge cuts the top-right corner.
        let (cx, cy, r) = (160.0 + 480.0, -480.0, 700.0);
        let px = frame_of(|x, y| (x - cx).hypot(y - cy) < r);
        let f = Frame::new(&px, W, H, 14).unwrap();
        assert!(is_limb(&f, roi(100, 0, 160, 50)));
    }

    #[test]
    fn a_limb_along_one_side_is_the_limb() {
        // The disc's edge runs down the left side, 5–25 px in.
        let (cx, cy, r) = (-700.0 + 15.0, 60.0, 700.0);
        let px = frame_of(|x, y| (x - cx).hypot(y - cy) < r);
        let f = Frame::new(&px, W, H, 14).unwrap();
        assert!(is_limb(&f, roi(0, 0, 30, 120)));
    }

    #[test]
    fn specks_off_the_arc_do_not_break_it() {
        // The deep sky in the top-right corner of an Earth-filled frame (the region is
        // the darker level), with the real camera's specks: hot pixels in the sky and
        // clusters of cold pixels on the Earth 20–60 px off the arc. Each of them alone
        // would put boundary pixels far from the parabola.
        let (cx, cy, r) = (160.0 - 480.0, 120.0 + 480.0, 700.0);
        let mut px = frame_of(|x, y| (x - cx).hypot(y - cy) < r);
        let mut set = |x: usize, y: usize, v: u16| px[y * W + x] = v;
        for &(x, y) in &[(150, 3), (140, 10), (155, 20)] {
            set(x, y, 6000); // hot pixels in the deep sky
        }
        for &(x, y) in &[(104, 45), (120, 48), (130, 46), (108, 30)] {
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                set(x + dx, y + dy, 1000); // 2 × 2 cold specks on the Earth
            }
        }
        let f = Frame::new(&px, W, H, 14).unwrap();
        let b = roi(100, 0, 160, 50);
        assert!(is_limb(&f, b));
        // The same box without the arc (a square of sky in the corner, specks and all)
        // still fails: its outline has a corner.
        let mut sq = frame_of(|x, y| !(x > 125.0 && y < 25.0));
        sq[3 * W + 150] = 6000;
        let g = Frame::new(&sq, W, H, 14).unwrap();
        assert!(!is_limb(&g, roi(100, 0, 160, 50)));
    }

    #[test]
    fn a_square_at_the_border_is_not_but_one_straight_edge_is() {
        // A square hanging from the top edge: in its box the boundary is a U (two
        // corners), no parabola.
        let sq = frame_of(|x, y| (100.0..140.0).contains(&x) && y < 40.0);
        let f = Frame::new(&sq, W, H, 14).unwrap();
        assert!(!is_limb(&f, roi(90, 0, 150, 50)));
        // A block in the top-right corner seen in a box whose only boundary is its one
        // straight edge: an arc (why the stage keeps away from saturated boxes).
        let corner = frame_of(|x, y| x > 110.0 && y < 40.0);
        let g = Frame::new(&corner, W, H, 14).unwrap();
        assert!(is_limb(&g, roi(100, 0, 160, 40)));
    }

    #[test]
    fn a_corner_bends_an_arc_does_not_a_ragged_arc_is_neither() {
        // A rectangle cut by the top-left corner: an L inside its box.
        let corner = frame_of(|x, y| x < 30.0 && y < 40.0);
        let f = Frame::new(&corner, W, H, 14).unwrap();
        let b = roi(0, 0, 50, 60);
        assert_eq!(outline(&f, b), Outline::Bends);
        // The disc across the top-right corner: one arc.
        let (cx, cy, r) = (160.0 + 480.0, -480.0, 700.0);
        let disc = frame_of(|x, y| (x - cx).hypot(y - cy) < r);
        let f = Frame::new(&disc, W, H, 14).unwrap();
        assert_eq!(outline(&f, roi(100, 0, 160, 50)), Outline::Arc);
        // The same arc ragged by ±3 px every 8 px along it (a noisy limb, the paper
        // world's, 8.6 px² on family A): not an arc within 1.7 px, no bend either.
        let ragged = frame_of(|x, y| {
            let step = if (x as usize / 8) % 2 == 0 { 3.0 } else { -3.0 };
            (x - cx).hypot(y - cy) < r + step
        });
        let f = Frame::new(&ragged, W, H, 14).unwrap();
        let b = roi(100, 0, 160, 50);
        assert_eq!(
            outline(&f, b),
            Outline::Unclear,
            "{:?}",
            arc_rms2_px2(&f, b)
        );
        // No boundary to measure: no bend.
        let flat = [1000u16; W * H];
        let g = Frame::new(&flat, W, H, 14).unwrap();
        assert_eq!(outline(&g, b), Outline::Unclear);
    }

    #[test]
    fn boxes_off_the_border_too_large_or_saturated_are_not() {
        let (cx, cy, r) = (160.0 + 480.0, -480.0, 700.0);
        let px = frame_of(|x, y| (x - cx).hypot(y - cy) < r);
        let f = Frame::new(&px, W, H, 14).unwrap();
        assert!(!is_limb(&f, roi(100, 1, 159, 50)), "off the border");
        assert!(!is_limb(&f, roi(0, 0, 160, 120)), "the whole frame");
        let mut sat = px;
        for v in sat.iter_mut().filter(|v| **v == 6000) {
            *v = 16383;
        }
        let s = Frame::new(&sat, W, H, 14).unwrap();
        assert!(!is_limb(&s, roi(100, 0, 160, 50)), "saturated");
        // Flat: one level, no threshold.
        let flat = [1000u16; W * H];
        let g = Frame::new(&flat, W, H, 14).unwrap();
        assert!(!is_limb(&g, roi(100, 0, 160, 50)));
    }

    /// A 14-bit frame: deep space at `sky` DN, saturated (16 383) where `bright(x, y)`.
    fn saturated_of(bright: impl Fn(f64, f64) -> bool, sky: u16) -> [u16; W * H] {
        let mut px = frame_of(bright);
        for v in px.iter_mut() {
            *v = if *v == 6000 { 16383 } else { sky };
        }
        px
    }

    /// The disc of 700 px radius across the top-left corner: its edge runs from (0, 77)
    /// to (77, 0), a chord of 109 px that sags 2.1 px.
    fn disc(x: f64, y: f64) -> bool {
        (x + 455.0).hypot(y + 455.0) < 700.0
    }

    /// Deep space beyond the disc's edge: 1 000 DN plus a margin.
    const SKY_MAX_DN: u32 = 1500;

    #[test]
    fn a_saturated_disc_in_a_corner_is_the_earth() {
        let mut px = saturated_of(disc, 1000);
        // Clouds below saturation inside the disc (holes in the saturated region, some
        // at its edge) and a hot pixel in the sky beyond it.
        for &(x, y) in &[(10, 10), (30, 20), (50, 8), (20, 50), (40, 30), (60, 10)] {
            for dy in 0..4 {
                for dx in 0..4 {
                    px[(y + dy) * W + x + dx] = 12_000;
                }
            }
        }
        px[40 * W + 85] = 16383;
        let f = Frame::new(&px, W, H, 14).unwrap();
        let b = roi(0, 0, 90, 90);
        assert!(is_saturated_disc(&f, b, SKY_MAX_DN));
        // The saturated region's own boundary is ragged: the limb test does not see it.
        assert!(!is_limb(&f, b));
        // The same disc with a warm level beyond it (the Earth around a target's piece).
        let warm = saturated_of(disc, 9000);
        let g = Frame::new(&warm, W, H, 14).unwrap();
        assert!(!is_saturated_disc(&g, b, SKY_MAX_DN));
        // Along one side only (not a corner), or larger than half the frame: not tested.
        assert!(!is_saturated_disc(&f, roi(0, 5, 90, 95), SKY_MAX_DN));
        assert!(!is_saturated_disc(&f, roi(0, 0, 130, 90), SKY_MAX_DN));
    }

    #[test]
    fn a_saturated_target_in_a_corner_is_not_the_disc() {
        let b = roi(0, 0, 90, 90);
        let not_disc = |bright: &dyn Fn(f64, f64) -> bool, what: &str| {
            let px = saturated_of(bright, 1000);
            let f = Frame::new(&px, W, H, 14).unwrap();
            assert!(!is_saturated_disc(&f, b, SKY_MAX_DN), "{what}");
        };
        not_disc(&|x, y| x < 40.0 && y < 50.0, "a rectangle's corner");
        // A nearly straight edge (a radius of 20 000 px, as a panel's: it sags 0.07 px
        // across the same chord as the disc's).
        not_disc(
            &|x, y| (x + 14_103.6).hypot(y + 14_103.6) < 20_000.0,
            "a straight edge (no sag)",
        );
        not_disc(
            &|x, y| (x - 5.0).hypot(y - 5.0) < 30.0,
            "a tight round face",
        );
        // Bulging towards the corner (the bright region concave): no disc.
        not_disc(&|x, y| (x - 532.0).hypot(y - 532.0) > 700.0, "concave");
    }
}
