//! Stage 2e's model of a frame that holds both the Earth and deep space: which cells
//! are the Earth's, so that the sky beside it can be fitted alone (stage 2c fits one
//! smooth surface to the whole window, which a frame holding both cannot be).
//!
//! The cells' means are split at their Otsu level; the warm side's 8-connected
//! components of at least [`EARTH_MIN_PERMILLE`] of the cells are the Earth (the disc
//! or its limb band; most targets are smaller), grown over the cells they touch
//! above a dimmer level ([`DIM_SHARE`]: the limb-darkened band), and their holes are
//! filled (the disc's cold clouds are no sky: a hole is a region of the rest that the
//! frame's border cannot reach, 4-connected). The Earth's disc is convex across the
//! frame: its cells must cross nearly every row and column in one run
//! ([`MAX_SPLIT_LINES_PERMILLE`]), else the frame is the Earth's alone, its cold clouds
//! taken for sky. Each cell then gets its Chebyshev distance to the Earth, in cells
//! ([`earth_distance`]): the caller fits the sky on cells beyond [`EXCLUDED_CELLS`]
//! (the limb's blur and the disc's dark edge stay out of the fit) and rejects a
//! component that reaches the first cell beyond them (the limb's own cold fragments;
//! `docs/detectors.md` § Session 57: without that, 10 of famAE's 59 mixed frames
//! without a target were boxed on the limb, with it 1).
//!
//! Chosen on family A (seeds 7001–7201): the share, the exclusion and the margin by a
//! Python replay (session 57), the convexity and the dim level in the core (session
//! 58, `docs/detectors.md` § Session 58). Memory: the distances in a `u8` cell plane
//! and a work stack of one `u32` per cell, both lent by the caller (`auto-v2`'s planes,
//! free at this stage); on the stack a 64-bin histogram (256 B). Cost: a pass for the
//! levels, one for the histogram, a flood fill of each warm component, a second of
//! each large one with what it grows over, one of the sky side (each cell pushed once
//! per fill), two passes over the rows and columns for the convexity and two raster
//! passes for the distances: 0.55 M x86-64 instructions on a 41×31-cell frame where it
//! runs in full (0.6 M on the Cortex-M7, `docs/flight.md` § Session 58).

/// A warm component of at least this share of the cells, ‰, is the Earth (a limb band
/// two cells deep across the 41 columns of a 328×248 frame is 6.5 %). A close target
/// warmer than the split and this large is taken for Earth too: the stage then finds
/// no target and the classifier decides, as before the stage.
pub const EARTH_MIN_PERMILLE: usize = 80;

/// Cells within this Chebyshev distance of the Earth are left out of the sky's fit
/// (the limb's blur over 2 cells, 16 px, at the `realistic` world's optics).
pub const EXCLUDED_CELLS: u8 = 2;

/// A component of departing cells with a cell at this distance of the Earth (the first
/// cell beyond [`EXCLUDED_CELLS`]) is the limb's, not a target's.
pub const MARGIN_CELLS: u8 = EXCLUDED_CELLS + 1;

/// The sky (cells beyond [`EXCLUDED_CELLS`]) must be at least this share of the
/// cells, ‰, for the fit to mean anything (a surface of 15 terms on fewer than a fifth
/// of the frame's blocks extrapolates).
pub const MIN_SKY_PERMILLE: usize = 200;

/// At most this share of the rows and columns crossing the Earth's cells, ‰, may
/// cross them in more than one run (`convex`). Chosen on family A (session 58, a
/// Python replay on the frames where stage 2e boxed): frames holding the Earth and sky
/// split 0–8 % of their lines (the limb's clouds near the split level), but two of 15
/// at 59 and 79 % (boxes at IoU 0.54 and 0.33); Earth-filled frames split 14–89 %
/// (seven false or missed boxes of ten).
pub const MAX_SPLIT_LINES_PERMILLE: usize = 100;

/// The Earth grows over the cells it touches whose mean lies above the cold side's
/// mean by this share of the way to the split level: the disc's limb-darkened band
/// lies below the split but above the sky, and beyond it the disc's bright corner
/// departed from the sky as a target (family A's approach frames without a target,
/// `famASE/000433`, `000455`, `000456`, `000460`: four false boxes). Chosen on family
/// A (session 58): 0.5 → the four gone, but targets beside the Earth grown over
/// (summed mean IoU −0.0042, famAT −0.0034); **0.75** → the four gone, +0.0004, no
/// set lower; 0.9 → one left (`000457`).
pub const DIM_SHARE: f32 = 0.75;

/// Bins of the cell means' histogram for the Otsu split (the split need not be exact:
/// the Earth's components are far larger than a bin's error).
const BINS: usize = 64;

/// Cell marks while the Earth is found (before they become distances).
const COLD: u8 = 0;
const WARM: u8 = 1;
const WARM_SEEN: u8 = 2;
const EARTH: u8 = 3;
const SKY_SIDE: u8 = 4;
const DIM: u8 = 5;

/// Distance of a cell beyond every reachable one (no Earth in the frame).
const FAR: u8 = u8::MAX;

/// The Otsu split of the cell means (`lo..=hi`): the last bin of the cold side, as a
/// DN (cells above it are warm), the cold side's cells and their mean, DN; `None`
/// when every mean is equal.
fn otsu_level(mean_dn: &[u16]) -> Option<(u16, usize, f32)> {
    let lo = mean_dn.iter().copied().min()?;
    let hi = mean_dn.iter().copied().max()?;
    if hi <= lo {
        return None;
    }
    let span = u32::from(hi - lo) + 1;
    let bin = |m: u16| (u32::from(m - lo) * BINS as u32 / span) as usize;
    let mut hist = [0u32; BINS];
    for &m in mean_dn {
        if let Some(h) = hist.get_mut(bin(m)) {
            *h += 1;
        }
    }
    let n = mean_dn.len() as f32;
    let total: f32 = hist
        .iter()
        .enumerate()
        .map(|(b, &c)| b as f32 * c as f32)
        .sum();
    let (mut w0, mut s0) = (0.0f32, 0.0f32);
    let mut best = (f32::MIN, 0usize, 0usize, 0.0f32);
    for (b, &c) in hist.iter().enumerate().take(BINS - 1) {
        w0 += c as f32;
        s0 += b as f32 * c as f32;
        let w1 = n - w0;
        if w0 == 0.0 || w1 == 0.0 {
            continue;
        }
        let d = s0 / w0 - (total - s0) / w1;
        let between = w0 * w1 * d * d;
        if between > best.0 {
            best = (between, b, w0 as usize, s0 / w0);
        }
    }
    // The bin's upper edge: `m` is cold when `bin(m) <= b`.
    let level = u32::from(lo) + ((best.1 as u32 + 1) * span).div_ceil(BINS as u32) - 1;
    // The cold side's mean at its bins' centres.
    let cold_mean_dn = f32::from(lo) + (best.3 + 0.5) * span as f32 / BINS as f32;
    Some((level.min(u32::from(u16::MAX)) as u16, best.2, cold_mean_dn))
}

/// Floods from `seed` over the cells whose mark `from` takes (8-connected when
/// `diagonal`, else 4-connected), marking them `to`; the cells reached, counting the
/// seed (marked by the caller). `stack` holds ≥ one entry per cell (each is pushed
/// once: it is marked `to` when pushed, which `from` must not take).
fn flood(
    marks: &mut [u8],
    (pw, ph): (usize, usize),
    seed: usize,
    (from, to): (impl Fn(u8) -> bool, u8),
    diagonal: bool,
    stack: &mut [u32],
) -> usize {
    let (mut top, mut reached) = (0usize, 1usize);
    if let Some(s) = stack.get_mut(top) {
        *s = seed as u32;
        top += 1;
    }
    while top > 0 {
        top -= 1;
        let i = stack.get(top).copied().unwrap_or(0) as usize;
        let (cx, cy) = (i % pw.max(1), i / pw.max(1));
        let (left, right, up, down) = (cx > 0, cx + 1 < pw, cy > 0, cy + 1 < ph);
        let mut visit = |inside: bool, j: usize| {
            if !inside {
                return;
            }
            if let (Some(m), Some(s)) = (marks.get_mut(j), stack.get_mut(top)) {
                if from(*m) {
                    *m = to;
                    *s = j as u32;
                    top += 1;
                    reached += 1;
                }
            }
        };
        // (`wrapping`: an index off the plane is never visited, `inside` is false.)
        visit(left, i.wrapping_sub(1));
        visit(right, i + 1);
        visit(up, i.wrapping_sub(pw));
        visit(down, i + pw);
        if diagonal {
            visit(left && up, i.wrapping_sub(pw + 1));
            visit(right && up, i.wrapping_sub(pw).wrapping_add(1));
            visit(left && down, (i + pw).wrapping_sub(1));
            visit(right && down, i + pw + 1);
        }
    }
    reached
}

/// Whether the Earth's cells (0 in `marks`, the sky's [`FAR`]) cross every row and
/// column in one run, but for [`MAX_SPLIT_LINES_PERMILLE`] of the lines that cross them:
/// the disc seen through the frame is convex, while an Earth-filled frame's cold
/// clouds, taken for sky, cut its warm side into runs.
fn convex(marks: &[u8], (pw, ph): (usize, usize)) -> bool {
    // Per line: whether it crosses the Earth, and whether in more than one run.
    let line = |cells: &mut dyn Iterator<Item = u8>| {
        let (mut runs, mut inside) = (0u32, false);
        for m in cells {
            let earth = m == 0;
            runs += u32::from(earth && !inside);
            inside = earth;
        }
        (runs > 0, runs > 1)
    };
    let (mut crossing, mut split) = (0usize, 0usize);
    for cy in 0..ph {
        let (c, s) = line(&mut marks.iter().skip(cy * pw).take(pw).copied());
        crossing += usize::from(c);
        split += usize::from(s);
    }
    for cx in 0..pw {
        let (c, s) = line(&mut marks.iter().skip(cx).step_by(pw.max(1)).take(ph).copied());
        crossing += usize::from(c);
        split += usize::from(s);
    }
    split * 1000 <= MAX_SPLIT_LINES_PERMILLE * crossing
}

/// Stage 2e's Earth: writes into `distance` (one per cell of the `(pw, ph)` plane of
/// `mean_dn`) each cell's Chebyshev distance to the Earth in cells (0: the Earth,
/// saturating at 255), and returns the cells beyond [`EXCLUDED_CELLS`] (the sky to
/// fit); `None` when the frame holds no Earth component, or too little sky
/// ([`MIN_SKY_PERMILLE`]), or a slice is shorter than the plane (`stack`: ≥ one
/// entry per cell).
pub fn earth_distance(
    mean_dn: &[u16],
    (pw, ph): (usize, usize),
    distance: &mut [u8],
    stack: &mut [u32],
) -> Option<usize> {
    let n = pw * ph;
    let mean_dn = mean_dn.get(..n)?;
    let marks = distance.get_mut(..n)?;
    let stack = stack.get_mut(..n)?;
    let (level, cold, cold_mean_dn) = otsu_level(mean_dn)?;
    // The sky lies on the cold side: too few cold cells, no sky to fit.
    if cold * 1000 < MIN_SKY_PERMILLE * n {
        return None;
    }
    // The Earth grows over the cells it touches above the dim level (its limb-darkened
    // band, and the warm pieces beyond it).
    let dim_dn = cold_mean_dn + (f32::from(level) - cold_mean_dn) * DIM_SHARE;
    for (m, &v) in marks.iter_mut().zip(mean_dn) {
        *m = if v > level {
            WARM
        } else if f32::from(v) > dim_dn {
            DIM
        } else {
            COLD
        };
    }
    // The warm side's large components are the Earth.
    let min_cells = (EARTH_MIN_PERMILLE * n).div_ceil(1000).max(1);
    let mut earth = false;
    for i in 0..n {
        if marks.get(i) != Some(&WARM) {
            continue;
        }
        if let Some(m) = marks.get_mut(i) {
            *m = WARM_SEEN;
        }
        let warm = (|m| m == WARM, WARM_SEEN);
        if flood(marks, (pw, ph), i, warm, true, stack) >= min_cells {
            if let Some(m) = marks.get_mut(i) {
                *m = EARTH;
            }
            let grown = (|m| m == WARM_SEEN || m == WARM || m == DIM, EARTH);
            flood(marks, (pw, ph), i, grown, true, stack);
            earth = true;
        }
    }
    if !earth {
        return None;
    }
    // The sky side: what the border reaches without crossing the Earth (4-connected,
    // as the Earth is 8-connected); the rest are the Earth's holes.
    for m in marks.iter_mut() {
        if *m != EARTH {
            *m = COLD;
        }
    }
    // (Rows and columns, not `i % pw`: no division, and no panic path for `pw` 0.)
    for cy in 0..ph {
        for cx in 0..pw {
            let i = cy * pw + cx;
            let on_border = cx == 0 || cy == 0 || cx + 1 == pw || cy + 1 == ph;
            if on_border && marks.get(i) == Some(&COLD) {
                if let Some(m) = marks.get_mut(i) {
                    *m = SKY_SIDE;
                }
                flood(marks, (pw, ph), i, (|m| m == COLD, SKY_SIDE), false, stack);
            }
        }
    }
    for m in marks.iter_mut() {
        *m = if *m == SKY_SIDE { FAR } else { 0 };
    }
    if !convex(marks, (pw, ph)) {
        return None;
    }
    // Chebyshev distances by two raster passes (every step costs 1): from the
    // neighbours before a cell (left, up-left, up, up-right), then after it.
    let step = |marks: &[u8], inside: bool, j: usize| {
        if inside {
            marks.get(j).copied().unwrap_or(FAR).saturating_add(1)
        } else {
            FAR
        }
    };
    for cy in 0..ph {
        for cx in 0..pw {
            let i = cy * pw + cx;
            let (left, right, up) = (cx > 0, cx + 1 < pw, cy > 0);
            let d = step(marks, left, i.wrapping_sub(1))
                .min(step(marks, up, i.wrapping_sub(pw)))
                .min(step(marks, left && up, i.wrapping_sub(pw + 1)))
                .min(step(marks, right && up, i.wrapping_sub(pw).wrapping_add(1)));
            if let Some(m) = marks.get_mut(i) {
                *m = (*m).min(d);
            }
        }
    }
    for cy in (0..ph).rev() {
        for cx in (0..pw).rev() {
            let i = cy * pw + cx;
            let (left, right, down) = (cx > 0, cx + 1 < pw, cy + 1 < ph);
            let d = step(marks, right, i + 1)
                .min(step(marks, down, i + pw))
                .min(step(marks, right && down, i + pw + 1))
                .min(step(marks, left && down, (i + pw).wrapping_sub(1)));
            if let Some(m) = marks.get_mut(i) {
                *m = (*m).min(d);
            }
        }
    }
    let sky = marks.iter().filter(|&&d| d > EXCLUDED_CELLS).count();
    (sky * 1000 >= MIN_SKY_PERMILLE * n).then_some(sky)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    const PW: usize = 40;
    const PH: usize = 32;

    /// Whether cell `(x, y)` lies in the disc of radius 60 cells centred at
    /// (75, 60): the Earth in the plane's lower right.
    fn in_disc(x: usize, y: usize) -> bool {
        let (dx, dy) = (x as f32 + 0.5 - 75.0, y as f32 + 0.5 - 60.0);
        dx * dx + dy * dy <= 60.0 * 60.0
    }

    /// A cell plane: sky at 1 000 DN with a ±1 DN ripple; the disc at 1 400 DN with a
    /// cold cloud (1 010 DN, a hole inside it) at cells 33..37 × 25..28; optionally a
    /// small warm target (1 200 DN) at 5..8 × 5..7.
    fn plane(target: bool) -> Vec<u16> {
        (0..PW * PH)
            .map(|i| {
                let (x, y) = (i % PW, i / PW);
                if (33..37).contains(&x) && (25..28).contains(&y) {
                    1010
                } else if in_disc(x, y) {
                    1400
                } else if target && (5..8).contains(&x) && (5..7).contains(&y) {
                    1200
                } else {
                    1000 + (x + y) as u16 % 2
                }
            })
            .collect()
    }

    /// The distances are the Chebyshev distances to the disc with its hole filled,
    /// by brute force; the target is no Earth (too small) and keeps its distance.
    #[test]
    fn distances_to_the_filled_disc() {
        for target in [false, true] {
            let mean = plane(target);
            let mut dist = std::vec![7u8; PW * PH];
            let mut stack = std::vec![0u32; PW * PH];
            let sky = earth_distance(&mean, (PW, PH), &mut dist, &mut stack).expect("earth");
            let mut want_sky = 0;
            for y in 0..PH {
                for x in 0..PW {
                    let hole = (33..37).contains(&x) && (25..28).contains(&y);
                    let want = if in_disc(x, y) || hole {
                        0
                    } else {
                        (0..PH)
                            .flat_map(|v| (0..PW).map(move |u| (u, v)))
                            .filter(|&(u, v)| in_disc(u, v))
                            .map(|(u, v)| x.abs_diff(u).max(y.abs_diff(v)))
                            .min()
                            .map_or(255, |d| d.min(255) as u8)
                    };
                    assert_eq!(dist[y * PW + x], want, "cell ({x}, {y}), target {target}");
                    want_sky += usize::from(want > EXCLUDED_CELLS);
                }
            }
            assert_eq!(sky, want_sky);
        }
    }

    /// No Earth (a sky with a small target), an Earth-filled plane whose cold clouds
    /// cross it (no convex disc), too little sky, and short slices: no answer.
    #[test]
    fn no_earth_beside_sky_is_no_answer() {
        let mut dist = std::vec![0u8; PW * PH];
        let mut stack = std::vec![0u32; PW * PH];
        let sky_only: Vec<u16> = (0..PW * PH)
            .map(|i| {
                if (5..8).contains(&(i % PW)) && i / PW < 4 {
                    1200
                } else {
                    1000
                }
            })
            .collect();
        assert_eq!(
            earth_distance(&sky_only, (PW, PH), &mut dist, &mut stack),
            None
        );
        // Warm Earth with cold cloud bands every 8 columns and across the middle rows.
        let clouds: Vec<u16> = (0..PW * PH)
            .map(|i| {
                let (x, y) = (i % PW, i / PW);
                if x % 8 < 3 || (14..18).contains(&y) {
                    1000
                } else {
                    1400
                }
            })
            .collect();
        assert_eq!(
            earth_distance(&clouds, (PW, PH), &mut dist, &mut stack),
            None
        );
        // The Earth over all but a 4-column band of sky.
        let little_sky: Vec<u16> = (0..PW * PH)
            .map(|i| if i % PW < 4 { 1000 } else { 1400 })
            .collect();
        assert_eq!(
            earth_distance(&little_sky, (PW, PH), &mut dist, &mut stack),
            None
        );
        let mean = plane(false);
        assert!(earth_distance(&mean, (PW, PH), &mut dist, &mut stack).is_some());
        assert_eq!(
            earth_distance(&mean[..10], (PW, PH), &mut dist, &mut stack),
            None
        );
        assert_eq!(
            earth_distance(&mean, (PW, PH), &mut dist[..10], &mut stack),
            None
        );
        assert_eq!(
            earth_distance(&mean, (PW, PH), &mut dist, &mut stack[..10]),
            None
        );
        let flat = std::vec![1000u16; PW * PH];
        assert_eq!(earth_distance(&flat, (PW, PH), &mut dist, &mut stack), None);
    }

    /// The disc's limb-darkened band (its outer 3 cells, 150 DN above the sky where
    /// the disc is 2 000 DN above it) is the Earth's, and so is a bright piece of the
    /// disc beyond the band (a 2×2-cell corner at full level): both at distance 0.
    #[test]
    fn the_limb_darkened_band_and_the_disc_beyond_it_are_the_earths() {
        let inner = |x: usize, y: usize| {
            let (dx, dy) = (x as f32 + 0.5 - 75.0, y as f32 + 0.5 - 60.0);
            dx * dx + dy * dy <= 57.0 * 57.0
        };
        let piece = |x: usize, y: usize| (38..40).contains(&x) && (12..14).contains(&y);
        let mean: Vec<u16> = (0..PW * PH)
            .map(|i| {
                let (x, y) = (i % PW, i / PW);
                if piece(x, y) || inner(x, y) {
                    3000
                } else if in_disc(x, y) {
                    1150
                } else {
                    1000
                }
            })
            .collect();
        let mut dist = std::vec![7u8; PW * PH];
        let mut stack = std::vec![0u32; PW * PH];
        earth_distance(&mean, (PW, PH), &mut dist, &mut stack).expect("earth");
        for y in 0..PH {
            for x in 0..PW {
                if in_disc(x, y) {
                    assert_eq!(dist[y * PW + x], 0, "cell ({x}, {y})");
                }
            }
        }
    }

    /// The Otsu level against a brute-force search of the between-class variance over
    /// every split of a two-level plane with noise.
    #[test]
    fn otsu_level_splits_two_levels() {
        let mean: Vec<u16> = (0..400u16)
            .map(|i| {
                if i % 3 == 0 {
                    2000 + i % 17
                } else {
                    1000 + i % 13
                }
            })
            .collect();
        let (level, cold, cold_mean_dn) = otsu_level(&mean).expect("two levels");
        let want: f32 = mean
            .iter()
            .filter(|&&m| m < 1500)
            .map(|&m| f32::from(m))
            .sum::<f32>()
            / cold as f32;
        // Within a bin (1 019 DN / 64) of the cold cells' mean.
        assert!((cold_mean_dn - want).abs() < 16.0, "{cold_mean_dn} {want}");
        assert!((1012..2000).contains(&level), "{level}");
        assert_eq!(cold, mean.iter().filter(|&&m| m <= level).count());
        assert_eq!(cold, mean.iter().filter(|&&m| m < 1500).count());
    }
}
