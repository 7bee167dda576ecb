//! Stage 3's cascade: the cell's 4×4-pixel windows, its features and the forest run
//! only where a target cell can be, and every other cell scores as background (code 0).
//!
//! Two steps ([`cascade`]):
//! 1. **Seeds**, a cheap look at each 8×8 cell from the cell planes alone (no pixel
//!    read, [`SeedRule::is_seed`]): a cell is a seed when it has an outline or a level
//!    of its own: its largest two-pixel step reaches [`SEED_STEP_CODE_MIN`], its mean
//!    differs from the mean of one of its nearest [`SEED_CONTRAST_RADII`] context
//!    boxes (radii 1 and 2 cells of [`super::features::RADII_CELLS`]) by at least
//!    [`SEED_CONTRAST_CODE_MIN`], or its mean lies far out in the frame's range of cell
//!    means ([`SEED_LEVEL_MIN`]). All three are the classifier's own features (feature
//!    3, the magnitudes of features 5 and 9, and of feature 0 of [`super::features`],
//!    computed here the same way, bit for bit), so the rule can be checked on any
//!    feature dump ([`is_seed_features`]). Every seed is classified.
//! 2. **Growth**: every 8-neighbour of a target cell is classified too, until no new
//!    target cell appears (a worklist, each cell classified at most once).
//!
//! So every 8-connected component of target cells that holds at least one seed comes
//! out exactly as the full pass gives it (the same cells, the same codes: the interior
//! of a large target, flat and at the level of its surroundings' box, is reached from
//! its outline); only a component without any seed is lost. Stage 4 works on the
//! components, so the winner and its box are unchanged unless its component has no
//! seed. `host/examples/auto_v2_prescreen.rs` checks that on a dataset (re-run it after
//! the forest is retrained).

use super::features::{FEATURES, FrameLevels, RADII_CELLS, log_code};

/// A cell whose largest two-pixel step reaches this [`log_code`] (of 4 · step / σ;
/// feature 3) is a seed. 90: a step of about 13 σ (`log_code(52) = 90`); a noise
/// cell's largest step of 128 two-pixel differences is about 4 σ (code ≈ 64). On
/// family A (seed 7001: realistic, paper, fixtures; `auto_v2_prescreen check`), see
/// the module's figures in `docs/detectors.md` § auto-v2.
pub const SEED_STEP_CODE_MIN: i32 = 90;

/// A cell whose mean differs from one of its nearest [`SEED_CONTRAST_RADII`] context
/// boxes' means by at least this [`log_code`] (of 4 · |difference| / σ; the magnitude
/// of features 5 and 9) is a seed. 70: a contrast of about 5 σ (`log_code(21) = 70`).
pub const SEED_CONTRAST_CODE_MIN: i32 = 70;

/// Context boxes the contrast test looks at: the first 2 of
/// [`super::features::RADII_CELLS`] (1 and 2 cells: 24 and 40 px across). Chosen in
/// session 49 for the M7 budget: until then the 4- and 8-cell boxes seeded too, and on
/// textured Earth a cloud field's cells differ from a 72- or 136-px box's mean by 5 σ
/// (those radii alone seeded 10 % of famA's cells and 15 % of paper A's, with under
/// 1 % of their target cells, which a target's outline or a near contrast seeds as
/// well). Family A (½; the sum of famA, paper A, fixtures A and famAF) 2.4261 →
/// 2.4261, false alarms unchanged, held out +0.0001; M7 `auto-v2` mean 6.54 → 4.94 M.
/// Without the level test too: 4.39 M but family A 2.4256, held out −0.003 — not
/// taken (`docs/detectors.md` § Session 49).
pub const SEED_CONTRAST_RADII: usize = 2;
const _: () = assert!(SEED_CONTRAST_RADII <= RADII_CELLS.len());

/// A cell whose mean lies at least this far from the median of the frame's cell means,
/// in 1/256 of the frame's range (p98 − p2, at least σ; the magnitude of feature 0), is
/// a seed: 128, half the range (a target near the dark or the bright end of the
/// frame, whatever its surroundings). Session 50, for the M7 budget: at 96 (three
/// eighths, until then) a textured Earth's cold and warm cloud cells seeded by their
/// level alone — 13.7 % of famA's cells, 6.3 % at 128 (all seeds 24.4 → 17.1 %;
/// paper A 16.0 → 10.8 %), while a target's cells are reached from its outline.
/// Family A (½; famA + paper A + fixtures A + famAF) 2.4261 → 2.4260 (one famAF frame
/// at IoU 0.06 lost), false alarms unchanged, famAS tracked 0.5649 → 0.5646; held
/// out −0.0030 (one paper B frame boxed in part); M7 `auto-v2` mean 4.94 → 4.71 M.
/// 160 and 192 lose famA −0.0004 (as no level seed at all).
pub const SEED_LEVEL_MIN: i32 = 128;

/// The least `q` whose [`log_code`] reaches [`SEED_CONTRAST_CODE_MIN`] (21: a contrast
/// of 5.25 σ): the contrast test as `4 · |m − mean| / σ ≥ q`, without the log.
const SEED_CONTRAST_Q_MIN: u64 = {
    let mut q = 0u32;
    while log_code(q) < SEED_CONTRAST_CODE_MIN {
        q += 1;
    }
    q as u64
};

/// The seed rule for one frame (see the module): the thresholds of the level
/// and contrast tests turned into DN once per frame, so that a cell's look multiplies
/// and compares but never divides (with four box means and a level divided per cell
/// the cascade cost the M7 0.72 M instructions per frame, now 0.60 M; the decisions
/// are the same, bit for bit: tested against the divisions and against
/// [`is_seed_features`]).
#[derive(Debug, Clone, Copy)]
pub struct SeedRule {
    /// The frame's median cell mean, DN (feature 0's origin).
    p50: u64,
    /// `SEED_LEVEL_MIN · max(p98 − p2, σ)`: a cell is a level seed when `256 · |m − p50|`
    /// reaches it (feature 0 rounds toward zero, so `|level| ≥ SEED_LEVEL_MIN` exactly
    /// then).
    level_x256: u64,
    /// `⌈SEED_CONTRAST_Q_MIN · σ / 4⌉`, DN: a cell is a contrast seed when its mean and a
    /// context box's (rounded down, as feature 5 + 4k takes it) differ by at least this
    /// (`⌊4 d / σ⌋ ≥ q` exactly when `4 d ≥ q σ`).
    contrast_dn: u32,
}

/// A contrast bound no cell mean reaches (means are u16): [`SeedRule::is_seed`]'s clamp.
const ABOVE_ANY_MEAN: u32 = 1 << 16;

// `SeedRule::is_seed` multiplies a bound of at most `ABOVE_ANY_MEAN` by the cells of
// the largest context box in 32 bits: exact while that product fits.
const _: () = {
    let (mut k, mut radius) = (0, 0);
    while k < RADII_CELLS.len() {
        if RADII_CELLS[k] > radius {
            radius = RADII_CELLS[k];
        }
        k += 1;
    }
    let side = 2 * radius as u64 + 1;
    assert!(ABOVE_ANY_MEAN as u64 * side * side <= u32::MAX as u64);
};

impl SeedRule {
    /// The rule for a frame of levels `lv`.
    pub fn new(lv: &FrameLevels) -> Self {
        let sigma = u64::from(lv.sigma.max(1));
        let range = u64::from(lv.p98.saturating_sub(lv.p2)).max(sigma);
        Self {
            p50: u64::from(lv.p50),
            level_x256: SEED_LEVEL_MIN as u64 * range,
            contrast_dn: (SEED_CONTRAST_Q_MIN * sigma)
                .div_ceil(4)
                .min(u64::from(ABOVE_ANY_MEAN)) as u32,
        }
    }

    /// Whether cell `(cx, cy)` of a `pw × ph` plane is a seed (see the module).
    /// `mean_dn`, `step_code`: the cell planes ([`super::cells::fill_cells`]); `sum`:
    /// the integral plane of `mean_dn` ([`super::features::integrate`]). A cell outside
    /// the plane reads as 0 (no panic path).
    pub fn is_seed(
        &self,
        mean_dn: &[u16],
        step_code: &[u8],
        sum: &[u32],
        (pw, ph): (usize, usize),
        (cx, cy): (usize, usize),
    ) -> bool {
        let i = cy * pw + cx;
        if i32::from(step_code.get(i).copied().unwrap_or(0)) >= SEED_STEP_CODE_MIN {
            return true;
        }
        let m = u64::from(mean_dn.get(i).copied().unwrap_or(0));
        if 256 * m.abs_diff(self.p50) >= self.level_x256 {
            return true;
        }
        // In 32 bits, exactly: a box sum of n cell means is at most n · 65 535, so a
        // bound above 65 535 cannot be reached and is clamped to 65 536 (n ≤ 17² cells:
        // 65 536 · n fits).
        let m = m as u32;
        let at = |x: Option<usize>, y: Option<usize>| match (x, y) {
            (Some(x), Some(y)) => sum.get(y * pw + x).copied().unwrap_or(0),
            _ => 0,
        };
        // ⌊s/n⌋ ≥ m + t ⇔ s ≥ (m + t)·n; ⌊s/n⌋ ≤ m − t ⇔ s < (m − t + 1)·n.
        let above = (m + self.contrast_dn).min(ABOVE_ANY_MEAN);
        let below = m.checked_sub(self.contrast_dn);
        for &r in RADII_CELLS.iter().take(SEED_CONTRAST_RADII) {
            let (x0, y0) = (cx.saturating_sub(r), cy.saturating_sub(r));
            let (x1, y1) = (
                (cx + r).min(pw.saturating_sub(1)),
                (cy + r).min(ph.saturating_sub(1)),
            );
            let n = ((x1 + 1).saturating_sub(x0) * (y1 + 1).saturating_sub(y0)).max(1) as u32;
            let (xa, ya) = (x0.checked_sub(1), y0.checked_sub(1));
            // Modulo 2³², exact: the box sum itself is under 2³².
            let s = (at(Some(x1), Some(y1)).wrapping_add(at(xa, ya)))
                .wrapping_sub(at(xa, Some(y1)).wrapping_add(at(Some(x1), ya)));
            if s >= above.wrapping_mul(n) || below.is_some_and(|b| s < (b + 1).wrapping_mul(n)) {
                return true;
            }
        }
        false
    }
}

/// [`SeedRule::is_seed`] on a cell's feature vector ([`super::features::cell_features`]):
/// feature 3 against [`SEED_STEP_CODE_MIN`], the magnitudes of features 5 and 9 (the
/// first [`SEED_CONTRAST_RADII`] context boxes) against [`SEED_CONTRAST_CODE_MIN`] and
/// of feature 0 against [`SEED_LEVEL_MIN`]. The same decision as [`SeedRule::is_seed`]
/// on the planes (tested), for checks on feature dumps.
pub fn is_seed_features(f: &[i32; FEATURES]) -> bool {
    f[3] >= SEED_STEP_CODE_MIN
        || f[0].abs() >= SEED_LEVEL_MIN
        || (0..SEED_CONTRAST_RADII).any(|k| f[5 + 4 * k].abs() >= SEED_CONTRAST_CODE_MIN)
}

/// The cascade over a `pw × ph` plane (see the module): `codes[i]` ends as
/// `classify(cx, cy)` for every classified cell and 0 for the others; `marks` (one
/// byte per cell) records which were classified (1) and `stack` (two bytes per cell)
/// holds the worklist. `seed(cx, cy)`: [`SeedRule::is_seed`] in the detector, `|_, _| true` to
/// classify every cell. Returns the number of cells classified. With buffers shorter
/// than the plane (never, by the caller's sizes) every cell is classified: the full
/// pass, no panic path.
pub fn cascade(
    (pw, ph): (usize, usize),
    codes: &mut [u8],
    marks: &mut [u8],
    stack: &mut [u8],
    mut seed: impl FnMut(usize, usize) -> bool,
    mut classify: impl FnMut(usize, usize) -> u8,
) -> usize {
    let n = pw * ph;
    let buffers = (
        codes.get_mut(..n),
        marks.get_mut(..n),
        stack.get_mut(..2 * n),
    );
    let (Some(codes), Some(marks), Some(stack), true) = (
        buffers.0,
        buffers.1,
        buffers.2,
        n <= usize::from(u16::MAX) + 1,
    ) else {
        // Too small a buffer: classify every cell in order, into what there is.
        for cy in 0..ph {
            for cx in 0..pw {
                let c = classify(cx, cy);
                if let Some(slot) = codes.get_mut(cy * pw + cx) {
                    *slot = c;
                }
            }
        }
        return n;
    };
    marks.fill(0);
    codes.fill(0);
    let mut top = 0usize;
    let mut classified = 0usize;
    for i in 0..n {
        if seed(i % pw.max(1), i / pw.max(1)) {
            classified += visit(i, pw, codes, marks, stack, &mut top, &mut classify);
        }
    }
    while top > 0 {
        top -= 1;
        let i = stack
            .get(2 * top..2 * top + 2)
            .and_then(|p| <[u8; 2]>::try_from(p).ok())
            .map_or(0, |p| usize::from(u16::from_le_bytes(p)));
        let (cx, cy) = (i % pw.max(1), i / pw.max(1));
        for ny in cy.saturating_sub(1)..=(cy + 1).min(ph.saturating_sub(1)) {
            for nx in cx.saturating_sub(1)..=(cx + 1).min(pw.saturating_sub(1)) {
                classified += visit(
                    ny * pw + nx,
                    pw,
                    codes,
                    marks,
                    stack,
                    &mut top,
                    &mut classify,
                );
            }
        }
    }
    classified
}

/// Classifies cell `i` of a plane `pw` cells wide unless `marks` says it was, and pushes
/// it on the worklist (`stack`, two bytes per entry, `top` entries) when it is a
/// target cell (code ≠ 0). Returns 1 when it classified the cell, else 0.
#[inline(always)]
fn visit<F: FnMut(usize, usize) -> u8>(
    i: usize,
    pw: usize,
    codes: &mut [u8],
    marks: &mut [u8],
    stack: &mut [u8],
    top: &mut usize,
    classify: &mut F,
) -> usize {
    match marks.get_mut(i) {
        Some(m) if *m == 0 => *m = 1,
        _ => return 0,
    }
    let c = classify(i % pw.max(1), i / pw.max(1));
    if let Some(slot) = codes.get_mut(i) {
        *slot = c;
    }
    if c != 0 {
        // A cell is pushed only when first classified: at most one entry per cell.
        if let Some(pair) = stack.get_mut(2 * *top..2 * *top + 2) {
            for (d, b) in pair.iter_mut().zip((i as u16).to_le_bytes()) {
                *d = b;
            }
            *top += 1;
        }
    }
    1
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    fn xorshift(s: &mut u32) -> u32 {
        *s ^= *s << 13;
        *s ^= *s >> 17;
        *s ^= *s << 5;
        *s
    }

    /// The cascade against a brute force: the 8-connected components of the full
    /// pass's target cells (flood fill) that hold a seed keep every cell and code, and
    /// nothing else is a target cell; random planes of random sizes, sparse seeds.
    #[test]
    fn cascade_keeps_exactly_the_seeded_components() {
        let mut s = 0x1234_5677u32;
        for _ in 0..300 {
            let pw = 1 + (xorshift(&mut s) % 45) as usize;
            let ph = 1 + (xorshift(&mut s) % 33) as usize;
            let n = pw * ph;
            let density = xorshift(&mut s) % 60;
            let full: Vec<u8> = (0..n)
                .map(|_| {
                    if xorshift(&mut s) % 100 < density {
                        1 + (xorshift(&mut s) % 255) as u8
                    } else {
                        0
                    }
                })
                .collect();
            let seeds: Vec<bool> = (0..n).map(|_| xorshift(&mut s) % 10 == 0).collect();
            // Brute force: label components, keep those holding a seed.
            let mut label = std::vec![0usize; n];
            let mut keep = std::vec![false; n + 1];
            let mut next = 0;
            for start in 0..n {
                if full[start] == 0 || label[start] != 0 {
                    continue;
                }
                next += 1;
                label[start] = next;
                let mut todo = std::vec![start];
                while let Some(i) = todo.pop() {
                    keep[next] |= seeds[i];
                    let (x, y) = ((i % pw) as i64, (i / pw) as i64);
                    for dy in -1..=1 {
                        for dx in -1..=1 {
                            let (nx, ny) = (x + dx, y + dy);
                            if nx < 0 || ny < 0 || nx >= pw as i64 || ny >= ph as i64 {
                                continue;
                            }
                            let j = ny as usize * pw + nx as usize;
                            if full[j] != 0 && label[j] == 0 {
                                label[j] = next;
                                todo.push(j);
                            }
                        }
                    }
                }
            }
            let (mut codes, mut marks, mut stack) =
                (std::vec![7u8; n], std::vec![9u8; n], std::vec![0u8; 2 * n]);
            let mut calls = std::vec![0u32; n];
            let classified = cascade(
                (pw, ph),
                &mut codes,
                &mut marks,
                &mut stack,
                |x, y| seeds[y * pw + x],
                |x, y| {
                    calls[y * pw + x] += 1;
                    full[y * pw + x]
                },
            );
            for i in 0..n {
                let want = if full[i] != 0 && keep[label[i]] {
                    full[i]
                } else {
                    0
                };
                assert_eq!(codes[i], want, "{pw}x{ph} cell {i}");
                assert!(calls[i] <= 1, "classified twice");
                assert_eq!(calls[i] == 1, marks[i] == 1);
                // A seed is always classified.
                assert!(!seeds[i] || calls[i] == 1);
            }
            assert_eq!(classified as u32, calls.iter().sum::<u32>());
            // Seeding every cell classifies every cell once: the full pass.
            let mut calls = 0usize;
            let all = cascade(
                (pw, ph),
                &mut codes,
                &mut marks,
                &mut stack,
                |_, _| true,
                |x, y| {
                    calls += 1;
                    full[y * pw + x]
                },
            );
            assert_eq!((all, calls), (n, n));
            assert_eq!(codes, full);
        }
    }

    /// [`SeedRule::is_seed`] (no division) against the rule as the features state it,
    /// by brute force: box means summed cell by cell and divided, the contrast's and the
    /// level's codes through [`log_code`] and a division rounded toward zero. Random
    /// planes whose means sit near the thresholds (a few σ of spread, σ 1–30 000 DN,
    /// means up to 65 535), steps under the step threshold.
    #[test]
    fn seed_rule_without_division_equals_the_features_rule() {
        let mut s = 0x0bad_5eedu32;
        let (mut seeds, mut cells) = (0usize, 0usize);
        for _ in 0..400 {
            let pw = 1 + (xorshift(&mut s) % 24) as usize;
            let ph = 1 + (xorshift(&mut s) % 20) as usize;
            // One plane in eight with a σ of thousands of DN and means up to the top
            // of u16 (the 32-bit clamps), the others σ 1–40 DN.
            let sigma = 1 + xorshift(&mut s)
                % if xorshift(&mut s) % 8 == 0 {
                    30_000
                } else {
                    40
                };
            let spread = 1 + xorshift(&mut s) % (12 * sigma).min(60_000);
            let base = xorshift(&mut s) % (65_536 - spread);
            let mean_dn: Vec<u16> = (0..pw * ph)
                .map(|_| (base + xorshift(&mut s) % spread) as u16)
                .collect();
            let step_code: Vec<u8> = (0..pw * ph)
                .map(|_| (xorshift(&mut s) % SEED_STEP_CODE_MIN as u32) as u8)
                .collect();
            let mut sum = std::vec![0u32; pw * ph];
            for cy in 0..ph {
                for cx in 0..pw {
                    sum[cy * pw + cx] = (0..=cy)
                        .flat_map(|y| (0..=cx).map(move |x| (x, y)))
                        .map(|(x, y)| u32::from(mean_dn[y * pw + x]))
                        .sum();
                }
            }
            let mut sorted = mean_dn.clone();
            sorted.sort_unstable();
            let p50 = sorted[xorshift(&mut s) as usize % sorted.len()];
            let (p2, p98) = (sorted[0], sorted[sorted.len() - 1]);
            let lv = FrameLevels {
                p2,
                p50,
                p98,
                sigma,
                sd_shift: 0,
                max_dn: u16::MAX,
                step_rank_code: 0,
            };
            let rule = SeedRule::new(&lv);
            let range = i64::from(p98 - p2).max(i64::from(sigma));
            for cy in 0..ph {
                for cx in 0..pw {
                    let m = i64::from(mean_dn[cy * pw + cx]);
                    let level = ((m - i64::from(p50)) * 256 / range).clamp(-4096, 4096);
                    let mut want = level.abs() >= i64::from(SEED_LEVEL_MIN);
                    for &r in RADII_CELLS.iter().take(SEED_CONTRAST_RADII) {
                        let (mut total, mut n) = (0i64, 0i64);
                        for y in cy.saturating_sub(r)..=(cy + r).min(ph - 1) {
                            for x in cx.saturating_sub(r)..=(cx + r).min(pw - 1) {
                                total += i64::from(mean_dn[y * pw + x]);
                                n += 1;
                            }
                        }
                        let d = (m - total / n).unsigned_abs();
                        let q = (d * 4 / u64::from(sigma)).min(u64::from(u32::MAX)) as u32;
                        want |= log_code(q) >= SEED_CONTRAST_CODE_MIN;
                    }
                    let got = rule.is_seed(&mean_dn, &step_code, &sum, (pw, ph), (cx, cy));
                    assert_eq!(got, want, "{pw}x{ph} ({cx}, {cy}) sigma {sigma}");
                    seeds += usize::from(got);
                    cells += 1;
                }
            }
        }
        // Both answers are common: the thresholds are crossed, not avoided.
        assert!(
            seeds > cells / 10 && seeds < cells * 9 / 10,
            "{seeds} of {cells}"
        );
    }

    /// Buffers shorter than the plane: every cell classified (the full pass), no panic.
    #[test]
    fn short_buffers_classify_every_cell() {
        let (mut codes, mut marks, mut stack) = ([0u8; 12], [0u8; 12], [0u8; 5]);
        let n = cascade(
            (4, 3),
            &mut codes,
            &mut marks,
            &mut stack,
            |_, _| false,
            |x, y| (x + y) as u8,
        );
        assert_eq!(n, 12);
        assert_eq!(codes[11], 5);
    }
}
