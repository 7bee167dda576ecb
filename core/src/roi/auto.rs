//! A scene-aware ROI detector of our own (`auto`): decides from cheap statistics of
//! the frame what the scene needs, runs only that, and can track (a prior box from
//! the last frame limits the work to a window around it).
//!
//! # Pipeline
//!
//! 1. **Noise and scene.** Horizontal differences on 16 rows give two noise
//!    estimates: first differences (which include the Earth's smooth texture) and
//!    second differences (blind to smooth shading). Runs at 0 DN or saturated are
//!    skipped (clipped noise says nothing). When most sampled pairs are both at 0 DN,
//!    deep space fills the frame and the only texture is the target's own shading:
//!    the second-difference σ is used, else the first.
//! 2. **Step plane.** One pass over every other row of the frame (or the tracking
//!    window): per 4×4 cell, the largest difference of a pixel and the pixel two to
//!    its right or two below, in units of σ/4, as an 8-bit logarithmic code (16 codes
//!    per octave; a plane of 82×62 cells). The target's outline is a step; the
//!    Earth's texture is a ramp and the noise small.
//! 3. **Candidates.** Cells with a step of at least `coarse_sigma · σ` are edge cells,
//!    labelled into 8-connected components (at most [`MAX_COMPONENTS`]; a frame with
//!    more is labelled again with a threshold half as high again), each with its cell
//!    box and summed steps (linear, so a saturated target's outline outweighs a wide
//!    patch of the Earth's texture).
//! 4. **Target decision.** Each component scores its summed steps, divided by 8 for
//!    every side of the window it touches: the Earth's limb (an arc from border to
//!    border) and Earth patches cut by the frame lose to a compact outline inside it.
//! 5. **Refinement.** At full resolution inside the winner's cell box plus one cell,
//!    only at pixels whose cell neighbours the winner: a step of at least
//!    `fine_sigma · σ` between pixels `x − 1` and `x + 1`, the largest along its direction
//!    (which drops the small step between a partly covered pixel and the background
//!    beyond it), is a boundary before `x` when `x` resembles `x + 1`, else after it.
//!    With labels of pixels at least half covered (our truth), that is the truth's
//!    boundary for any contrast and polarity. The box spans the outermost boundaries.
//!    In clean deep space (sunlit frames: 0 DN nearly everywhere, clipped noise a
//!    sparse sprinkle), a step from 0 DN below `fine_sigma · σ` also counts when the pixel
//!    beyond it and its four neighbours are above 0: a faint (cold) face.
//! 6. **Saturated target** (detection mode, recognised by pixels at the top DN with
//!    hardly any just below it, unlike a radiometry face at the top DN with noise):
//!    pixels less than half covered saturate too, so the box is that of the
//!    saturated pixels with outermost lines of at most 2 pixels trimmed (twice per
//!    side at most), joined with the boundaries of unsaturated (cold) faces.
//!
//! # Tracking
//!
//! With [`Auto::prior`] set, the pipeline runs on the prior grown by
//! `margin_px + max(width, height) / 8` on every side. If nothing is found there, or
//! the box found misses the prior or reaches the window's border (the target left the
//! window, grew out of it, or the prior was wrong), the full frame is processed
//! instead.
//!
//! # Budgets
//!
//! No heap; integer arithmetic only in every loop over pixels and cells (no floating
//! point at all); no panic on any frame (`Frame` bounds every access; proptest and a
//! fuzz target check it); memory [`SCRATCH_BYTES`] (≤ 32 KiB, checked at compile
//! time).

use super::plane::{BLOCK, PLANE_CELLS, PLANE_WIDTH, Window};
use super::{BoxRule, DetectError, Detection, Detector, Roi, RoiBuilder, Scratch};
use crate::frame::{FRAME_HEIGHT, FRAME_WIDTH, Frame};

const GRID: usize = PLANE_CELLS;
/// Most edge components labelled per frame; edge cells that would start a further
/// component are dropped (a frame that noisy has no outline worth boxing).
pub const MAX_COMPONENTS: usize = 250;
/// Bins of the noise histogram (16 exact bins, then 4 per octave up to 2^16).
const NOISE_BINS: usize = 64;
/// The extra bin of the noise histograms that takes the samples not counted (so the
/// sampling loop has no branches).
const SKIP_BIN: usize = NOISE_BINS;

/// Parameters of the `auto` detector.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Auto {
    /// Tracking prior: the last frame's box, or `None` to search the whole frame.
    /// Any box is accepted; it is cut to the frame, and an empty result means no prior.
    pub prior: Option<Roi>,
    /// Coarse edge threshold: a cell is an edge cell when its largest step reaches
    /// `coarse_sigma · σ` (σ: the pixel noise, DN): 1..=1000. Default 6.
    pub coarse_sigma: u16,
    /// Full-resolution boundary threshold: a step over two pixels counts when it
    /// reaches `fine_sigma · σ` (twice that beside a saturated target): 1..=1000. Default 8.
    pub fine_sigma: u16,
    /// Tracking window margin around the prior, in pixels: 0..=328. Default 16 (plus
    /// `max(width, height) / 8`: room for a move of several pixels and a 10 % change of
    /// size per frame).
    pub margin_px: u16,
}

impl Default for Auto {
    fn default() -> Self {
        Auto {
            prior: None,
            coarse_sigma: 6,
            fine_sigma: 8,
            margin_px: 16,
        }
    }
}

impl Auto {
    /// The same parameters with a tracking prior (the last frame's box).
    pub const fn with_prior(self, prior: Option<Roi>) -> Self {
        Auto { prior, ..self }
    }
}

/// Statistics of one component of edge cells.
#[derive(Debug, Clone, Copy)]
struct Component {
    /// Cell box, exclusive ends.
    x0: u8,
    y0: u8,
    x1: u8,
    y1: u8,
    /// Edge cells.
    area: u16,
    /// Sum of the cells' coarse gradients.
    energy: u32,
    /// Largest coarse gradient.
    gmax: u32,
}

impl Component {
    fn add(&mut self, x: u8, y: u8, q: u32) {
        self.x0 = self.x0.min(x);
        self.y0 = self.y0.min(y);
        self.x1 = self.x1.max(x.saturating_add(1));
        self.y1 = self.y1.max(y.saturating_add(1));
        self.area = self.area.saturating_add(1);
        self.energy = self.energy.saturating_add(q);
        self.gmax = self.gmax.max(q);
    }

    fn merge(&mut self, o: &Component) {
        self.x0 = self.x0.min(o.x0);
        self.y0 = self.y0.min(o.y0);
        self.x1 = self.x1.max(o.x1);
        self.y1 = self.y1.max(o.y1);
        self.area = self.area.saturating_add(o.area);
        self.energy = self.energy.saturating_add(o.energy);
        self.gmax = self.gmax.max(o.gmax);
    }
}

const NO_COMPONENT: Component = Component {
    x0: u8::MAX,
    y0: u8::MAX,
    x1: 0,
    y1: 0,
    area: 0,
    energy: 0,
    gmax: 0,
};

/// `auto`'s buffers: the cell plane (steps, then labels), the component table, and
/// rows of the refinement.
#[derive(Debug, Clone)]
pub struct AutoWork {
    /// Per cell of the window: the largest step in σ/4, as a [`step_code`].
    step: [u8; GRID],
    /// Per cell of the window: its component label (0: not an edge cell).
    label: [u8; GRID],
    /// Union-find parents of the labels (256 entries: any `u8` label indexes it).
    parent: [u8; 256],
    comps: [Component; MAX_COMPONENTS + 1],
    /// Largest steps of one band of rows per pixel, DN (first one clamped row of the
    /// noise estimate).
    steps: [u16; FRAME_WIDTH],
    /// Saturated pixels per column and per row of the refinement window.
    col_sat: [u16; FRAME_WIDTH],
    row_sat: [u16; FRAME_HEIGHT],
    /// Histogram of one noise estimate.
    hist: [u32; NOISE_BINS + 1],
    /// The winner's cells of one cell row, padded by a cell on each side (building the
    /// gate), or a mask row of [`Detector::foreground`].
    mask: [bool; FRAME_WIDTH],
}

/// The `auto` detector's scratch memory.
pub type AutoScratch = Scratch<AutoWork>;

/// Bytes of [`AutoScratch`] (budget: 32 KiB, checked at compile time).
pub const SCRATCH_BYTES: usize = core::mem::size_of::<AutoScratch>();
const _: () = assert!(SCRATCH_BYTES <= 32 * 1024, "auto's scratch exceeds 32 KiB");

impl AutoScratch {
    /// Fresh scratch memory (a `const fn`, so it can be a `static`).
    pub const fn new() -> Self {
        Scratch {
            work: AutoWork {
                step: [0; GRID],
                label: [0; GRID],
                parent: [0; 256],
                comps: [NO_COMPONENT; MAX_COMPONENTS + 1],
                steps: [0; FRAME_WIDTH],
                col_sat: [0; FRAME_WIDTH],
                row_sat: [0; FRAME_HEIGHT],
                hist: [0; NOISE_BINS + 1],
                mask: [false; FRAME_WIDTH],
            },
            roi: RoiBuilder::new(),
        }
    }
}

impl Default for AutoScratch {
    fn default() -> Self {
        Self::new()
    }
}

/// What one pass of the pipeline found in a window.
#[derive(Debug, Clone, Copy)]
struct Found {
    roi: Option<Roi>,
    /// Coarse edge threshold (Prewitt L1 of block means, DN).
    threshold: u32,
    /// Full-resolution edge pixels inside the gate.
    edge_px: u32,
}

/// Noise histogram bin of an absolute difference: exact below 16, then 4 per octave.
fn noise_bin(d: u32) -> usize {
    if d < 16 {
        return d as usize;
    }
    let l = 31 - d.leading_zeros(); // 4..=16
    let sub = (d >> (l - 2)) & 3;
    (16 + (l - 4) * 4 + sub).min(NOISE_BINS as u32 - 1) as usize
}

/// The middle of the values of bin `b` (inverse of [`noise_bin`]).
fn bin_value(b: usize) -> u32 {
    if b < 16 {
        return b as u32;
    }
    let l = (b as u32 - 16) / 4 + 4;
    let sub = (b as u32 - 16) % 4;
    let lo = (4 + sub) << (l - 2);
    lo + (1 << (l - 2)) / 2
}

/// Median of the values counted in `hist` (`None` below 16 counts): the middle of
/// its bin.
fn hist_median(hist: &[u32]) -> Option<u32> {
    let n: u32 = hist.iter().sum();
    if n < 16 {
        return None;
    }
    let mut seen = 0;
    hist.iter()
        .position(|&c| {
            seen += c;
            2 * seen > n
        })
        .map(bin_value)
}

/// Calls `f(a, b, c)` with the clamped pixels at `x, x + 1, x + 2` for every other `x`
/// of at most 16 evenly spaced rows of `win` (about 2 600 samples on a full frame:
/// plenty for a median). `buf` holds one clamped row.
fn for_each_noise_sample(
    frame: &Frame<'_>,
    win: Window,
    buf: &mut [u16; FRAME_WIDTH],
    mut f: impl FnMut(u16, u16, u16),
) {
    let max_dn = frame.max_dn();
    let stride = (win.h / 16).max(1);
    for y in (win.y0 + stride / 2..win.y0 + win.h).step_by(stride) {
        let row = win.row(frame, y);
        let clamped = &mut buf[..row.len()];
        for (c, &v) in clamped.iter_mut().zip(row) {
            *c = v.min(max_dn);
        }
        for abc in clamped.windows(3).step_by(2) {
            f(abc[0], abc[1], abc[2]);
        }
    }
}

/// σ in DN from the median of the first differences `|b − a|` (σ = median / 0.954;
/// pairs both at 0 DN or both saturated skipped) or, with `SECOND`, of the second
/// differences `|a − 2b + c|` (σ = median / 1.652; triples all at 0 DN or all
/// saturated skipped); `None` below 16 samples.
fn difference_sigma<const SECOND: bool>(
    frame: &Frame<'_>,
    win: Window,
    hist: &mut [u32; NOISE_BINS + 1],
    buf: &mut [u16; FRAME_WIDTH],
) -> Option<u32> {
    let max_dn = frame.max_dn();
    hist.fill(0);
    for_each_noise_sample(frame, win, buf, |a, b, c| {
        let (skip, d) = if SECOND {
            let d2 = (i32::from(a) + i32::from(c) - 2 * i32::from(b)).unsigned_abs();
            (((a | b | c) == 0) | ((a & b & c) == max_dn), d2)
        } else {
            let d1 = u32::from(a.abs_diff(b));
            (((a | b) == 0) | ((a & b) == max_dn), d1)
        };
        hist[if skip { SKIP_BIN } else { noise_bin(d) }] += 1;
    });
    let m = hist_median(&hist[..NOISE_BINS])?;
    Some(if SECOND {
        (m * 20 + 16) / 33
    } else {
        (m * 21 + 10) / 20
    })
}

/// Pixel noise σ in DN (≥ 1) of `win`, from horizontal differences (see
/// [`for_each_noise_sample`]; runs at 0 DN or saturated are skipped: clipped noise
/// says nothing), and whether deep space is clean (see below).
///
/// Two estimates: first differences, which also see the Earth's smooth texture, so
/// that texture stays below the edge thresholds; and second differences, blind to
/// smooth shading. The scene decides: when most sampled pairs are both at 0 DN (deep
/// space fills the frame), the only texture is the target's own shading, which must
/// not raise the thresholds, and the second-difference estimate is used; otherwise the
/// first. A first pass counts the pairs at 0 DN; only the histogram the scene needs
/// is built (the other one too when that one has too few samples).
fn noise_sigma(
    frame: &Frame<'_>,
    win: Window,
    hist: &mut [u32; NOISE_BINS + 1],
    buf: &mut [u16; FRAME_WIDTH],
) -> (u32, bool) {
    let (mut pairs, mut zero_pairs, mut one_zero) = (0u32, 0u32, 0u32);
    for_each_noise_sample(frame, win, buf, |a, b, _| {
        let both_zero = (a | b) == 0;
        pairs += 1;
        zero_pairs += u32::from(both_zero);
        one_zero += u32::from((a.min(b) == 0) & !both_zero);
    });
    let space = 2 * zero_pairs > pairs;
    let sigma = if space {
        difference_sigma::<true>(frame, win, hist, buf)
            .or_else(|| difference_sigma::<false>(frame, win, hist, buf))
    } else {
        difference_sigma::<false>(frame, win, hist, buf)
            .or_else(|| difference_sigma::<true>(frame, win, hist, buf))
    };
    // Clean deep space: at 0 DN nearly everywhere (sunlit frames), with at most a
    // sparse sprinkle of clipped-noise pixels (noise clipped at 0 around a level at 0
    // makes two pairs touching 0 with one side above it for every pair both at 0).
    let clean = space && zero_pairs >= 4 * one_zero;
    (sigma.unwrap_or(1).max(1), clean)
}

/// The outermost boundaries seen by the refinement, and the hull of their pixels.
#[derive(Debug, Clone, Copy)]
struct Boundaries {
    /// Boundaries between columns (from horizontal steps): smallest and largest.
    bx: (usize, usize),
    /// Boundaries between rows (from vertical steps): smallest and largest.
    by: (usize, usize),
    /// Hull of the step pixels: x range, y range (exclusive ends).
    hx: (usize, usize),
    hy: (usize, usize),
    count: u32,
}

impl Boundaries {
    const NONE: Boundaries = Boundaries {
        bx: (usize::MAX, 0),
        by: (usize::MAX, 0),
        hx: (usize::MAX, 0),
        hy: (usize::MAX, 0),
        count: 0,
    };

    fn pixel(&mut self, x: usize, y: usize) {
        self.hx = (self.hx.0.min(x), self.hx.1.max(x + 1));
        self.hy = (self.hy.0.min(y), self.hy.1.max(y + 1));
        self.count += 1;
    }

    /// A boundary before column `b`, seen on row `y`.
    fn add_x(&mut self, b: usize, y: usize) {
        self.bx = (self.bx.0.min(b), self.bx.1.max(b));
        self.pixel(b.saturating_sub(1), y);
    }

    /// A boundary before row `b`, seen in column `x`.
    fn add_y(&mut self, x: usize, b: usize) {
        self.by = (self.by.0.min(b), self.by.1.max(b));
        self.pixel(x, b.saturating_sub(1));
    }

    /// The box between the outermost boundaries (the step pixels' hull along an axis
    /// without two boundaries).
    fn roi(&self) -> Option<Roi> {
        if self.count == 0 {
            return None;
        }
        let (x0, x1) = if self.bx.0 < self.bx.1 {
            self.bx
        } else {
            self.hx
        };
        let (y0, y1) = if self.by.0 < self.by.1 {
            self.by
        } else {
            self.hy
        };
        Some(Roi::new(x0 as u16, y0 as u16, x1 as u16, y1 as u16))
    }
}

/// The box of the saturated pixels from their column and row counts (`col_sat[i]` is
/// column `x0 + i`), with outermost lines of at most 2 pixels trimmed (twice per
/// side at most): pixels less than half covered by a saturating target saturate
/// too, and stick out of the truth box one at a time.
fn saturated_box(col_sat: &[u16], x0: usize, row_sat: &[u16], y0: usize) -> Option<Roi> {
    let span = |counts: &[u16]| {
        let first = counts.iter().position(|&c| c > 0)?;
        let last = counts.iter().rposition(|&c| c > 0)?;
        let (mut a, mut b) = (first, last + 1);
        for _ in 0..2 {
            if b - a > 2 && counts[a] <= 2 {
                a += 1;
            }
            if b - a > 2 && counts[b - 1] <= 2 {
                b -= 1;
            }
        }
        Some((a, b))
    };
    let (xa, xb) = span(col_sat)?;
    let (ya, yb) = span(row_sat)?;
    Some(Roi::new(
        (x0 + xa) as u16,
        (y0 + ya) as u16,
        (x0 + xb) as u16,
        (y0 + yb) as u16,
    ))
}

/// The step plane of `win` into `plane` (`pw` cells per row): per cell, the largest
/// absolute difference of a pixel and the pixel two to its right or two below, on
/// every other row (so every boundary between two pixels is spanned once per column
/// and per pair of rows, at half the cost of neighbour differences on every row), in
/// units of σ/4, as a [`step_code`]; steps below `floor` (σ/4) as 0, which no edge
/// threshold reaches (the code is computed only for cells that may be edge cells).
/// `band` holds the per-pixel maxima of one band of rows.
fn step_plane(
    frame: &Frame<'_>,
    win: Window,
    sigma: u32,
    floor: u32,
    pw: usize,
    band: &mut [u16; FRAME_WIDTH],
    plane: &mut [u8],
) {
    let max_dn = frame.max_dn();
    let n = win.w;
    let band = &mut band[..n];
    // q = cm · 4/σ, as a 16.16 reciprocal.
    let inv = (4u64 << 16) / u64::from(sigma.max(1));
    // The smallest step in DN whose σ/4 units reach `floor`: cm · inv ≥ floor · 2^16.
    let cm_floor = (u64::from(floor) << 16).div_ceil(inv.max(1));
    let code = |cm: u16| {
        let v = ((u64::from(cm) * inv) >> 16).min(u64::from(u32::MAX)) as u32;
        if u64::from(cm) < cm_floor {
            0
        } else {
            step_code(v)
        }
    };
    let c = |v: u16| v.min(max_dn);
    let last = win.y0 + win.h - 1;
    for (cy, plane_row) in plane.chunks_exact_mut(pw).enumerate() {
        band.fill(0);
        let y_end = (win.y0 + (cy + 1) * BLOCK).min(win.y0 + win.h);
        for y in (win.y0 + cy * BLOCK..y_end).step_by(2) {
            let row = win.row(frame, y);
            // Two rows down, or the last row of the window (a step there still shows).
            let below = win.row(frame, (y + 2).min(last).max(y));
            if row.len() != n || below.len() != n {
                continue;
            }
            let span = 2.min(n - 1);
            for (((m, &v), &r), &b) in band.iter_mut().zip(row).zip(&row[span..]).zip(below) {
                let (v, r, b) = (c(v), c(r), c(b));
                *m = (*m).max(v.abs_diff(r)).max(v.abs_diff(b));
            }
            for x in n.saturating_sub(span)..n {
                band[x] = band[x].max(c(row[x]).abs_diff(c(below[x])));
            }
        }
        // Most bands hold no step that may make an edge cell: one pass that
        // vectorises says so.
        if u64::from(band.iter().fold(0, |m, &v| m.max(v))) < cm_floor {
            plane_row.fill(0);
            continue;
        }
        let mut cells = band.chunks_exact(BLOCK);
        for (q, chunk) in plane_row.iter_mut().zip(&mut cells) {
            let cm = chunk[0].max(chunk[1]).max(chunk[2]).max(chunk[3]);
            *q = code(cm);
        }
        // A partial cell at the right edge.
        if let (Some(q), false) = (plane_row.get_mut(n / BLOCK), cells.remainder().is_empty()) {
            let cm = cells.remainder().iter().fold(0u16, |m, &v| m.max(v));
            *q = code(cm);
        }
    }
}

/// Labels the cells whose `step` is at least `threshold` into 8-connected components
/// in `plane` (raster order, union-find with statistics merged on union); other cells
/// get 0. Returns one past the last label used, or `None` when some edge cell found no
/// free label (it is left unlabelled).
fn label_edges(
    step: &[u8],
    plane: &mut [u8],
    pw: usize,
    threshold: u8,
    parent: &mut [u8; 256],
    comps: &mut [Component; MAX_COMPONENTS + 1],
) -> Option<usize> {
    let mut next = 1usize;
    let mut overflow = false;
    for (cy, steps) in step.chunks_exact(pw).enumerate() {
        let (before, rest) = plane.split_at_mut(cy * pw);
        let cur = &mut rest[..pw];
        cur.fill(0);
        if steps.iter().all(|&q| q < threshold) {
            continue;
        }
        let prev = before.get(before.len().saturating_sub(pw)..).unwrap_or(&[]);
        let up = |cx: usize| prev.get(cx).copied().unwrap_or(0);
        for (cx, &q) in steps.iter().enumerate() {
            if q < threshold {
                continue;
            }
            let left = if cx > 0 { cur[cx - 1] } else { 0 };
            let up_left = if cx > 0 { up(cx - 1) } else { 0 };
            let mut l = 0u8;
            for m in [left, up_left, up(cx), up(cx + 1)] {
                if m == 0 {
                    continue;
                }
                let r = find(parent, m);
                if l == 0 {
                    l = r;
                } else if r != l {
                    let (keep, gone) = if r < l { (r, l) } else { (l, r) };
                    parent[usize::from(gone)] = keep;
                    let g = comps[usize::from(gone)];
                    comps[usize::from(keep)].merge(&g);
                    l = keep;
                }
            }
            if l == 0 {
                if next > MAX_COMPONENTS {
                    overflow = true;
                    continue;
                }
                l = next as u8;
                parent[next] = l;
                comps[next] = NO_COMPONENT;
                next += 1;
            }
            cur[cx] = l;
            comps[usize::from(l)].add(cx as u8, cy as u8, step_value(q));
        }
    }
    (!overflow).then_some(next)
}

/// The 8-bit code of a step of `v` (units of σ/4): 16 codes per octave,
/// `16·⌊log2 v⌋ + ` the next 4 bits of `v`, 0 for 0, at most 255 (`v` ≥ 2^15.9).
/// Integer only; [`step_value`] inverts it to within 1/16 of an octave.
fn step_code(v: u32) -> u8 {
    if v == 0 {
        return 0;
    }
    let l = 31 - v.leading_zeros();
    let frac = if l >= 4 {
        (v >> (l - 4)) & 15
    } else {
        (v << (4 - l)) & 15
    };
    (16 * l + frac).min(255) as u8
}

/// The step (units of σ/4) a [`step_code`] stands for: the bottom of its sixteenth
/// of an octave.
fn step_value(code: u8) -> u32 {
    let (l, frac) = (u32::from(code) / 16, u32::from(code) % 16);
    ((16 + frac) << l) >> 4
}

/// Root of component `l`, halving the path.
fn find(parent: &mut [u8; 256], mut l: u8) -> u8 {
    loop {
        let p = parent[usize::from(l)];
        if p == l {
            return l;
        }
        let g = parent[usize::from(p)];
        parent[usize::from(l)] = g;
        l = p;
    }
}

impl Auto {
    /// Runs the pipeline on `win`; `None` when no component is found.
    fn locate(&self, frame: &Frame<'_>, work: &mut AutoWork, win: Window) -> Option<Found> {
        let max_dn = frame.max_dn();
        let fw = frame.width();
        let (pw, ph) = (win.w.div_ceil(BLOCK), win.h.div_ceil(BLOCK));
        let (sigma, clean) = noise_sigma(frame, win, &mut work.hist, &mut work.steps);
        let AutoWork {
            step,
            label,
            parent,
            comps,
            steps,
            col_sat,
            row_sat,
            mask,
            ..
        } = work;
        let label = &mut label[..pw * ph];
        let step = &mut step[..pw * ph];
        // Edge cells (step ≥ coarse_sigma·σ), labelled in raster order (8-connected,
        // union-find on u8 labels, statistics merged on union). A frame with more
        // components than labels (noise, texture) is labelled again with a threshold
        // half as high again, up to four times; so no cell below the first threshold's
        // code is ever an edge cell.
        let mut threshold = step_code(u32::from(self.coarse_sigma) * 4);
        step_plane(frame, win, sigma, step_value(threshold), pw, steps, step);

        let mut next = None;
        for _ in 0..4 {
            next = label_edges(step, label, pw, threshold, parent, comps);
            if next.is_some() || threshold == u8::MAX {
                break;
            }
            // Half as high again: 16·log2(1.5) ≈ 9 codes.
            threshold = threshold.saturating_add(9);
        }
        let next = next.unwrap_or(MAX_COMPONENTS + 1);
        // The target decision: summed steps, / 8 per window side touched.
        let (pw8, ph8) = (pw as u8, ph as u8);
        let sides = |c: &Component| {
            u32::from(c.x0 == 0)
                + u32::from(c.y0 == 0)
                + u32::from(c.x1 >= pw8)
                + u32::from(c.y1 >= ph8)
        };
        let mut best: Option<(u8, u64)> = None;
        for l in 1..next {
            if parent[l] != l as u8 {
                continue;
            }
            let c = &comps[l];
            let score = u64::from(c.energy) >> (3 * sides(c));
            if best.is_none_or(|(_, s)| score > s) {
                best = Some((l as u8, score));
            }
        }
        let (root, _) = best?;
        let c = comps[usize::from(root)];

        // Refinement at full resolution inside the winner's box plus one cell: a step
        // of at least τ between pixels x − 1 and x + 1 puts a boundary before x when x
        // is closer to x + 1, else after it (x goes with the side it resembles: with
        // half-coverage labels, exactly the truth's boundary). The box spans the
        // outermost boundaries.
        let cell_px = |cell: u8| usize::from(cell) * BLOCK;
        let rx0 = win.x0 + cell_px(c.x0.saturating_sub(1));
        let ry0 = win.y0 + cell_px(c.y0.saturating_sub(1));
        let rx1 = (win.x0 + cell_px(c.x1.saturating_add(1))).min(win.x0 + win.w);
        let ry1 = (win.y0 + cell_px(c.y1.saturating_add(1))).min(win.y0 + win.h);
        // The gate: cells that are the winner's or touch one of its cells (in `step`,
        // free after labelling), over the refinement window's cells.
        let (ca, cb) = ((rx0 - win.x0) / BLOCK, (rx1 - 1 - win.x0) / BLOCK + 1);
        let (ra, rb) = ((ry0 - win.y0) / BLOCK, (ry1 - 1 - win.y0) / BLOCK + 1);
        // Every label to its root first (at most 250 finds), so the gate is
        // comparisons only: the winner's cells dilated by one cell, along rows into
        // `step`, then down columns into `label`.
        for l in 1..next {
            parent[l] = find(parent, l as u8);
        }
        parent[0] = 0;
        let (cwa, cwb) = (ca.saturating_sub(1), (cb + 1).min(pw));
        // The winner's cells of one cell row, padded by a cell on each side:
        // `winner[cx + 1]` is cell cx.
        let winner = &mut mask[..pw + 2];
        winner.fill(false);
        for cy in ra.saturating_sub(1)..(rb + 1).min(ph) {
            let labels = &label[cy * pw + cwa..cy * pw + cwb];
            for (w, &l) in winner[cwa + 1..cwb + 1].iter_mut().zip(labels) {
                *w = parent[usize::from(l)] == root;
            }
            // Along the row: out[cx] = w[cx − 1] | w[cx] | w[cx + 1].
            let out = &mut step[cy * pw + ca..cy * pw + cb];
            let (left, mid, right) = (&winner[ca..cb], &winner[ca + 1..], &winner[ca + 2..]);
            for (((o, &l), &m), &r) in out.iter_mut().zip(left).zip(mid).zip(right) {
                *o = u8::from(l | m | r);
            }
        }
        for cy in ra..rb {
            let row = |gy: usize| &step[gy * pw + ca..gy * pw + cb];
            let up = row(cy.saturating_sub(1));
            let down = row((cy + 1).min(ph - 1));
            for (((g, &u), &m), &d) in label[cy * pw + ca..cy * pw + cb]
                .iter_mut()
                .zip(up)
                .zip(row(cy))
                .zip(down)
            {
                *g = u | m | d;
            }
        }
        let gate = &*label;
        let gated =
            |x: usize, y: usize| gate[(y - win.y0) / BLOCK * pw + (x - win.x0) / BLOCK] != 0;
        let tau = (u32::from(self.fine_sigma) * sigma).min(u32::from(u16::MAX)) as u16;
        // Beside a saturated target the frame is nearly noise-free and the boundaries
        // that matter are of cold, unsaturated faces: twice the threshold.
        let tau_unsat = tau.saturating_mul(2);
        let near_sat = max_dn.saturating_sub((4 * sigma).min(u32::from(u16::MAX)) as u16);

        // Saturation counts, over the gated cells.
        let (mut sat_px, mut near_px) = (0u32, 0u32);
        let col_sat = &mut col_sat[rx0..rx1];
        let row_sat = &mut row_sat[ry0..ry1];
        col_sat.fill(0);
        row_sat.fill(0);
        // Runs of gated cells of a cell row as pixel ranges relative to rx0 (set for
        // each cell row): the counts touch gated pixels only, a slice per run.
        let mut runs = [(0u16, 0u16); PLANE_WIDTH / 2 + 1];
        let (mut n_runs, mut runs_row) = (0, usize::MAX);
        for (y, rs) in (ry0..ry1).zip(row_sat.iter_mut()) {
            let Some(row) = frame.row(y) else { continue };
            let row = &row[rx0..rx1];
            // Most rows of a radiometry frame hold no pixel near saturation (a max is
            // cheaper than the counts).
            if row.iter().fold(0, |m, &v| m.max(v)) < near_sat {
                continue;
            }
            let cy = (y - win.y0) / BLOCK;
            if cy != runs_row {
                runs_row = cy;
                n_runs = 0;
                let cells = &gate[cy * pw + ca..cy * pw + cb];
                let mut open = None;
                for (i, &g) in cells.iter().chain(&[0]).enumerate() {
                    match (open, g != 0) {
                        (None, true) => open = Some(i),
                        (Some(start), false) => {
                            let px = |c: usize| (c * BLOCK).min(row.len()) as u16;
                            if let Some(r) = runs.get_mut(n_runs) {
                                *r = (px(start), px(i));
                                n_runs += 1;
                            }
                            open = None;
                        }
                        _ => {}
                    }
                }
            }
            // (v ≥ max_dn is v saturated; near_sat ≤ max_dn: no clamp needed.)
            let (mut sat_row, mut near) = (0u16, 0u16);
            for &(a, b) in &runs[..n_runs] {
                let (a, b) = (usize::from(a), usize::from(b));
                for (&v, cs) in row[a..b].iter().zip(&mut col_sat[a..b]) {
                    let sat = u16::from(v >= max_dn);
                    *cs += sat;
                    sat_row += sat;
                    near += u16::from(v >= near_sat) & (1 - sat);
                }
            }
            let (sat_row, near) = (u32::from(sat_row), u32::from(near));
            *rs = sat_row as u16;
            sat_px += sat_row;
            near_px += near;
        }
        // A saturated target (detection mode) is flat at max_dn: hardly any pixel just
        // below it, unlike a radiometry face at max_dn with noise. Then the boundaries
        // sought are those of unsaturated faces (twice the threshold).
        let saturated = sat_px >= 4 && 8 * near_px < sat_px;
        let (tau, keep_saturated) = if saturated {
            (tau_unsat, false)
        } else {
            (tau, true)
        };
        let clamp = |v: u16| v.min(max_dn);
        let rows = |y: usize| frame.row(y).map(|r| &r[..fw]);
        // A boundary at pixel x of row y from a horizontal step: `Some(b)` (a boundary
        // before column b) when |v(x+1) − v(x−1)| ≥ τ, no neighbouring step along the
        // row is larger, and the pixels are gated (and unsaturated, unless kept).
        // In clean deep space a faint face (a few hundred DN, below τ) still shows as a
        // solid patch above 0 DN, where the clipped noise is a sparse sprinkle: a step
        // from 0 DN counts when the pixel beyond it and its four neighbours are above 0.
        let solid = |x: usize, y: usize| {
            let at = |x: usize, y: usize| rows(y).and_then(|r| r.get(x)).is_some_and(|&v| v > 0);
            x > 0
                && y > 0
                && at(x, y)
                && at(x - 1, y)
                && at(x + 1, y)
                && at(x, y - 1)
                && at(x, y + 1)
        };
        let faint = |a: u16, b: u16, beyond: Option<(usize, usize)>| {
            clean && a.min(b) == 0 && a.max(b) > 0 && beyond.is_some_and(|(x, y)| solid(x, y))
        };
        let h_boundary = |row: &[u16], x: usize, y: usize| -> Option<usize> {
            if x == 0 || x + 1 >= fw {
                return None;
            }
            let (l, v, r) = (clamp(row[x - 1]), clamp(row[x]), clamp(row[x + 1]));
            let step = l.abs_diff(r);
            let beyond = if l == 0 {
                Some((x + 1, y))
            } else {
                Some((x - 1, y))
            };
            if (step < tau && !faint(l, r, beyond))
                || !(keep_saturated || l.max(r) < max_dn)
                || !gated(x, y)
            {
                return None;
            }
            let before = x.checked_sub(2).map_or(0, |i| clamp(row[i]).abs_diff(v));
            let after = row.get(x + 2).map_or(0, |&w| clamp(w).abs_diff(v));
            (step >= before && step >= after).then_some(if v.abs_diff(l) >= v.abs_diff(r) {
                x
            } else {
                x + 1
            })
        };
        // The same down a column: a boundary before row b.
        let v_boundary = |x: usize, y: usize| -> Option<usize> {
            let (Some(a), Some(v), Some(d)) =
                (y.checked_sub(1).and_then(rows), rows(y), rows(y + 1))
            else {
                return None;
            };
            let (u, v, d) = (clamp(a[x]), clamp(v[x]), clamp(d[x]));
            let step = u.abs_diff(d);
            let beyond = if u == 0 {
                Some((x, y + 1))
            } else {
                Some((x, y - 1))
            };
            if (step < tau && !faint(u, d, beyond))
                || !(keep_saturated || u.max(d) < max_dn)
                || !gated(x, y)
            {
                return None;
            }
            let before = y
                .checked_sub(2)
                .and_then(rows)
                .map_or(0, |r| clamp(r[x]).abs_diff(v));
            let after = rows(y + 2).map_or(0, |r| clamp(r[x]).abs_diff(v));
            (step >= before && step >= after).then_some(if v.abs_diff(u) >= v.abs_diff(d) {
                y
            } else {
                y + 1
            })
        };
        // Outside in: the box needs only the outermost boundaries, so each row is
        // scanned from the left until its first boundary (or until it cannot beat the
        // leftmost one so far) and from the right alike; rows are scanned from the top
        // until one holds a boundary from a vertical step, and from the bottom alike.
        // A saturated target's box comes from its saturated pixels; boundaries of cold
        // faces matter only beyond it.
        let sat = if saturated {
            saturated_box(col_sat, rx0, row_sat, ry0)
        } else {
            None
        };
        let (lim_x0, lim_y0, lim_x1, lim_y1) = sat.map_or((rx1, ry1, rx0, ry0), |s| {
            (
                usize::from(s.x0),
                usize::from(s.y0),
                usize::from(s.x1),
                usize::from(s.y1),
            )
        });
        let mut found = Boundaries::NONE;
        // The cheap test of a pixel pair (clamped) before the boundary tests: a step of
        // τ, or (clean deep space) 0 DN beside a pixel above it.
        let candidate =
            |l: u16, r: u16| l.abs_diff(r) >= tau || (clean && l.min(r) == 0 && l.max(r) > 0);
        // One row per cell band first (cheap bounds for the rest), then every row.
        let sparse = (ry0 + BLOCK / 2..ry1).step_by(BLOCK);
        for y in sparse.chain(ry0..ry1) {
            let Some(row) = rows(y) else { continue };
            // Pixels x of [xa, xb) with both neighbours in the frame, first to last (or
            // last to first): the first boundary found.
            let scan = |xa: usize, xb: usize, backwards: bool| {
                let (xa, xb) = (xa.max(1), xb.min(fw - 1));
                let triples = row.get(xa.wrapping_sub(1)..xb + 1).filter(|_| xa < xb)?;
                let mut hits = (xa..xb)
                    .zip(triples.windows(3))
                    .filter(|(_, t)| candidate(clamp(t[0]), clamp(t[2])));
                if backwards {
                    hits.rev().find_map(|(x, _)| h_boundary(row, x, y))
                } else {
                    hits.find_map(|(x, _)| h_boundary(row, x, y))
                }
            };
            let left_end = lim_x0.min(rx1).min(found.bx.0.saturating_add(1));
            if let Some(b) = scan(rx0, left_end, false) {
                found.add_x(b, y);
            }
            let right_start = rx0.max(lim_x1).max(found.bx.1.saturating_sub(1));
            if let Some(b) = scan(right_start, rx1, true) {
                found.add_x(b, y);
            }
        }
        let vertical = |y: usize, found: &mut Boundaries| {
            let (Some(a), Some(d)) = (y.checked_sub(1).and_then(rows), rows(y + 1)) else {
                return false;
            };
            // Most rows hold no candidate: one pass that vectorises says so.
            let (a, d) = (&a[rx0..rx1], &d[rx0..rx1]);
            let largest = a
                .iter()
                .zip(d)
                .fold(0, |m, (&u, &w)| m.max(clamp(u).abs_diff(clamp(w))));
            if largest < tau && !(clean && a.iter().zip(d).any(|(&u, &w)| (u == 0) != (w == 0))) {
                return false;
            }
            let mut hit = false;
            for (x, (&u, &w)) in (rx0..rx1).zip(a.iter().zip(d)) {
                if !candidate(clamp(u), clamp(w)) {
                    continue;
                }
                if let Some(b) = v_boundary(x, y) {
                    found.add_y(x, b);
                    hit = true;
                }
            }
            hit
        };
        for y in ry0..ry1.min(lim_y0) {
            if vertical(y, &mut found) {
                break;
            }
        }
        for y in (ry0.max(lim_y1)..ry1).rev() {
            if y < found.by.1 || vertical(y, &mut found) {
                break;
            }
        }
        let edge_px = found.count;
        let roi = match sat {
            Some(s) => Some(found.roi().map_or(s, |u| s.hull(&u))),
            None if saturated => None,
            None => found.roi(),
        };
        roi.map(|roi| Found {
            roi: Some(roi),
            threshold: u32::from(self.coarse_sigma) * sigma,
            edge_px,
        })
    }

    /// The detection (box, coarse threshold, edge pixels), tracking window first.
    fn run(&self, frame: &Frame<'_>, work: &mut AutoWork) -> Detection {
        let full = Window::full(frame);
        if let Some(p) = self.prior {
            let p = p.clip(frame.width() as u16, frame.height() as u16);
            if !p.is_empty() {
                let m = usize::from(self.margin_px) + usize::from(p.width().max(p.height())) / 8;
                let win = Window::clipped(
                    frame,
                    usize::from(p.x0).saturating_sub(m),
                    usize::from(p.y0).saturating_sub(m),
                    usize::from(p.x1) + m,
                    usize::from(p.y1) + m,
                );
                if let Some(win) = win.filter(|w| !w.is_full(frame)) {
                    if let Some(f) = self.locate(frame, work, win) {
                        // Still the tracked target: the box overlaps the prior and is
                        // not cut by the window (a side on the window's border is one
                        // the frame's border, or the target left the window).
                        let (fw, fh) = (frame.width(), frame.height());
                        let kept = f.roi.is_some_and(|r| {
                            let (x0, y0) = (usize::from(r.x0), usize::from(r.y0));
                            let (x1, y1) = (usize::from(r.x1), usize::from(r.y1));
                            !r.intersection(&p).is_empty()
                                && (x0 > win.x0 || win.x0 == 0)
                                && (y0 > win.y0 || win.y0 == 0)
                                && (x1 < win.x0 + win.w || x1 == fw)
                                && (y1 < win.y0 + win.h || y1 == fh)
                        });
                        if kept {
                            return detection(f);
                        }
                    }
                }
            }
        }
        match self.locate(frame, work, full) {
            Some(f) => detection(f),
            None => Detection {
                roi: None,
                threshold: 0,
                foreground_px: 0,
            },
        }
    }
}

fn detection(f: Found) -> Detection {
    Detection {
        roi: f.roi,
        threshold: f.threshold,
        foreground_px: f.edge_px,
    }
}

impl Detector for Auto {
    type Work = AutoWork;
    const NAME: &'static str = "auto";

    fn validate(&self) -> Result<(), DetectError> {
        if !(1..=1000).contains(&self.coarse_sigma) {
            return Err(DetectError::InvalidParameter {
                name: "coarse_sigma",
                expected: "1..=1000 (units of the block-mean noise)",
            });
        }
        if !(1..=1000).contains(&self.fine_sigma) {
            return Err(DetectError::InvalidParameter {
                name: "fine_sigma",
                expected: "1..=1000 (units of the pixel noise)",
            });
        }
        if usize::from(self.margin_px) > FRAME_WIDTH {
            return Err(DetectError::InvalidParameter {
                name: "margin_px",
                expected: "0..=328 pixels",
            });
        }
        Ok(())
    }

    /// `auto` always boxes its chosen outline; the rule does not apply.
    fn box_rule(&self) -> BoxRule {
        BoxRule::LargestComponent
    }

    /// Foreground: the detected box, filled. Threshold: the coarse edge threshold
    /// (Prewitt L1 of 4×4 block means, DN).
    fn foreground<F: FnMut(usize, &[bool])>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoWork,
        mut sink: F,
    ) -> u32 {
        let d = self.run(frame, work);
        let roi = d.roi.unwrap_or(Roi::EMPTY);
        let mask = &mut work.mask[..frame.width()];
        for y in 0..frame.height() {
            mask.fill(false);
            if roi.contains(roi.x0, y as u16) {
                mask[usize::from(roi.x0)..usize::from(roi.x1)].fill(true);
            }
            sink(y, mask);
        }
        d.threshold
    }

    /// Runs `auto` (without the mask pass of the default: the box comes straight from
    /// the refinement). `foreground_px` counts the edge pixels that made the box.
    fn detect(
        &self,
        frame: &Frame<'_>,
        scratch: &mut Scratch<AutoWork>,
    ) -> Result<Detection, DetectError> {
        self.validate()?;
        Ok(self.run(frame, &mut scratch.work))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_codes_are_monotone_and_invert() {
        let mut last = 0;
        for v in 0..70_000u32 {
            let c = step_code(v);
            assert!(c >= last, "{v}");
            last = c;
            if (1..60_000).contains(&v) {
                let back = step_value(c);
                assert!(
                    back <= v && 17 * u64::from(back) >= 16 * u64::from(v) - 16,
                    "{v} {c} {back}"
                );
                // `back` is the bottom of the code: the floor of `step_plane`.
                if c > 0 {
                    assert_eq!(step_code(back), c, "{v}");
                    assert!(step_code(back - 1) < c, "{v}");
                }
            }
        }
        assert_eq!(step_code(1), 0);
        assert_eq!(step_code(24), 16 * 4 + 8);
    }

    #[test]
    fn noise_bins_round_trip() {
        for d in [0u32, 1, 15, 16, 17, 31, 32, 100, 1000, 16383, 65535] {
            let b = noise_bin(d);
            assert!(b < NOISE_BINS);
            let v = bin_value(b);
            assert_eq!(noise_bin(v), b, "d {d} bin {b} value {v}");
        }
    }
}
