//! Adversarial 328×248 frames for the worst-case instruction bounds (issue 18, part 2),
//! made deterministically on board (nothing is stored but this code): every detector's
//! data-dependent work (histogram bins in use, gradient strengths, runs and components
//! of the mask, DoG extrema, `auto`'s edge components and refinement) is pushed to its
//! extreme by one of them.
//!
//! | kind | cases | what it stresses |
//! |---|---|---|
//! | `checker-P`, P = 1..=64 | 64 | edges at every spatial period: gradients, runs per row, components of every size |
//! | `stripes-v-P`, `stripes-h-P`, P = 1, 2 | 4 | all-edge frames: every column (row) an edge |
//! | `dots-S`, `holes-S`, S = 2, 3 | 4 | isolated pixels on a lattice: the most 8-connected components a frame holds (164 × 124 at S = 2) |
//! | `framed-holes-S`, S = 2, 3 | 2 | `holes-S` inside an 8-px margin at a quarter of the range: a saturated blob over nearly the whole frame that passes `auto-v2`'s gate, so its refinement, body stage and shape statistics run over the whole frame (session 32: with the retrained forest `holes-3` no longer does) |
//! | `plate-holes-S`, S = 2, 3 | 2 | `holes-S` on a plate at half the range, the margin on the top and left only: `auto`'s refinement scans every row and column of its region to the end without a boundary, in the whole frame and in the tracking window at the top-left corner (session 33: that small region counted 2.3× the refinement's per-pixel charge of the time) |
//! | `weak-blob-S`, S = 2, 3 | 2 | `holes-S` on a saturated plate reaching the right and bottom edges, its top and left margin ([`WEAK_BLOB_MARGIN_PX`]) [`WEAK_BLOB_MARGIN_BELOW_TOP_DN`] under the top: `auto-v2` rates the blob over the gate but under its 800 ‰, so the region stages' whole-frame pass runs and then stage 5e's spots compete with it (session 47: the two together, which no other case reaches; the worst-case run fails when the rating leaves that range) |
//! | `noise-N` | 4 | uniform noise over the whole 14-bit range: every histogram bin, random runs |
//! | `salt-pepper-N` | 2 | each pixel 0 or saturated, at random |
//! | `spikes-N` | 2 | 45 % black, 45 % saturated, the rest uniform between: a nearly flat score over the bins between, but not flat enough (Otsu refines 2 bins) |
//! | `flat-variance-S` | 2 | Otsu's worst case (`otsu::fill_flat_variance`): S px at 0 and at saturation, the rest placed so that the between-class variance is flat over every bin where the optimal split may lie; Otsu refines 64 bins in 16 passes (proven bound 17), S = 100, 1 000 |
//! | `saturated`, `black`, `ramp` | 3 | flat frames and a smooth ramp over the full range |
//! | `tiled-L` | 4 | the fuzz target's frames (`fuzz/fuzz_targets/auto.rs`: a short run of random DN repeated to fill the frame), L = 3, 7, 31, 329 |
//! | the embedded frames | 6 | the demo's rendered scenes |
//!
//! `auto` with a prior is run with each of [`PRIORS`] (corners, the whole frame, one
//! pixel, boxes partly and wholly outside the frame).

use core::fmt;

use tirroi_core::Roi;
use tirroi_core::frame::{FRAME_HEIGHT, FRAME_PIXELS, FRAME_WIDTH};

use crate::BITS;
use crate::frames::FRAMES;

/// The largest DN at the demo's bit depth (saturation).
pub const MAX_DN: u16 = (1u16 << BITS) - 1;

/// Largest checkerboard period, px (a quarter of the frame height: beyond it the
/// board is a few big blocks, which the periods below already cover in kind).
pub const MAX_CHECKER_PERIOD_PX: usize = 64;

/// One adversarial frame: its kind and its parameter (period, spacing, seed, length or
/// index of the embedded frame).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Case {
    /// Square checkerboard of period `P` px (cells of P×P, 0 and saturated DN).
    Checker(usize),
    /// Vertical stripes `P` px wide, alternately 0 and saturated.
    StripesV(usize),
    /// Horizontal stripes `P` px high.
    StripesH(usize),
    /// Saturated single pixels every `S` px in x and y on black.
    Dots(usize),
    /// Black single pixels every `S` px in x and y on saturated.
    Holes(usize),
    /// [`Case::Holes`] inside a [`FRAME_MARGIN_PX`] margin at a quarter of the range.
    FramedHoles(usize),
    /// [`Case::FramedHoles`] with the lattice's plate at half the range instead of
    /// saturated, and the margin on the top and left sides only: no boundary ends a
    /// row's scan from the right or a column's from the bottom.
    PlateHoles(usize),
    /// [`Case::Holes`] on a saturated plate reaching the right and bottom edges, its
    /// top and left margin ([`WEAK_BLOB_MARGIN_PX`]) [`WEAK_BLOB_MARGIN_BELOW_TOP_DN`]
    /// under the top DN: a blob whose confidence passes the gate but not the spots' 800 ‰.
    WeakBlob(usize),
    /// Uniform noise over 0..=MAX_DN from seed `N`.
    Noise(u64),
    /// Each pixel 0 or MAX_DN at random, from seed `N`.
    SaltPepper(u64),
    /// Two spikes (0 and MAX_DN, [`SPIKE_PERMILLE`] each) with the rest spread
    /// uniformly between them, from seed `N`: Otsu's between-class variance is nearly
    /// flat over every bin between the spikes, so its branch and bound prunes least.
    Spikes(u64),
    /// Otsu's worst case: a histogram of flat between-class variance with spikes of
    /// `S` px at 0 and at saturation ([`tirroi_core::roi::otsu::fill_flat_variance`]).
    FlatVariance(usize),
    /// Every pixel saturated.
    Saturated,
    /// Every pixel 0.
    Black,
    /// A ramp over the whole range along x + y.
    Ramp,
    /// `L` random DN (seed `L`) repeated in raster order to fill the frame.
    Tiled(usize),
    /// The embedded frame of this index ([`FRAMES`]).
    Embedded(usize),
}

/// The all-edge stripe widths, px.
const STRIPE_PERIODS_PX: [usize; 2] = [1, 2];
/// The lattice spacings of isolated pixels, px (2: the densest 8-isolated lattice).
const DOT_SPACINGS_PX: [usize; 2] = [2, 3];
/// Margin around the plate of the framed lattices, px (one cell: the winner does not
/// touch the frame's sides).
pub const FRAME_MARGIN_PX: usize = 8;
/// How far under the top DN the margin of [`Case::WeakBlob`] lies: surroundings this
/// close to the top lower the blob model's ring depth, so the blob is rated between
/// the gate (550 ‰) and the 800 ‰ under which the spots compete (session 47: 0.735 for
/// S = 3, 0.67 for S = 2 on the host; 512 DN under the top rated it 0.812, no
/// competition). The worst-case run checks the rating (`worst_case.rs`).
pub const WEAK_BLOB_MARGIN_BELOW_TOP_DN: u16 = 256;
/// Width of [`Case::WeakBlob`]'s top and left margin, px, for hole spacings S = 2
/// and 3 ([`DOT_SPACINGS_PX`]). Session 52's cell forest rates `weak-blob-3` with
/// [`FRAME_MARGIN_PX`]'s 8 px at 0.872 (over 800 ‰: the spots no longer compete,
/// 19.16 M instead of the double path), with 7 px at 0.599; `weak-blob-2` stays in
/// range with 8 px (0.557) and has no box with 7 px.
pub const WEAK_BLOB_MARGIN_PX: [usize; 2] = [8, 7];

/// [`WEAK_BLOB_MARGIN_PX`] of hole spacing `s` ([`FRAME_MARGIN_PX`] for another).
fn weak_blob_margin_px(s: usize) -> usize {
    DOT_SPACINGS_PX
        .iter()
        .position(|&d| d == s)
        .and_then(|k| WEAK_BLOB_MARGIN_PX.get(k).copied())
        .unwrap_or(FRAME_MARGIN_PX)
}
/// Seeds of the noise frames.
const NOISE_SEEDS: [u64; 4] = [1, 2, 3, 4];
/// Seeds of the salt-and-pepper frames.
const SALT_PEPPER_SEEDS: [u64; 2] = [1, 2];
/// Seeds of the two-spike frames.
const SPIKE_SEEDS: [u64; 2] = [1, 2];
/// Spike sizes of the flat-variance frames, px (both make Otsu refine 64 bins; the
/// larger spike moves the optimum and the pixels between).
const FLAT_VARIANCE_SPIKES_PX: [usize; 2] = [100, 1000];
/// Share of the pixels in each spike of [`Case::Spikes`], per mille.
pub const SPIKE_PERMILLE: u64 = 450;
/// Lengths of the fuzz-style tiled frames (329: one more than a row, a diagonal drift).
const TILE_LENGTHS: [usize; 4] = [3, 7, 31, 329];

/// Number of cases ([`case`] is `Some` for `0..COUNT`).
pub const COUNT: usize = MAX_CHECKER_PERIOD_PX
    + 2 * STRIPE_PERIODS_PX.len()
    + 5 * DOT_SPACINGS_PX.len()
    + NOISE_SEEDS.len()
    + SALT_PEPPER_SEEDS.len()
    + SPIKE_SEEDS.len()
    + FLAT_VARIANCE_SPIKES_PX.len()
    + 3
    + TILE_LENGTHS.len()
    + FRAMES.len();

/// The `index`-th case, `None` from [`COUNT`] on.
pub fn case(index: usize) -> Option<Case> {
    /// Takes the next group of `len` cases: `Some(k)` when `i` falls in it (k-th of
    /// the group), else moves `i` past it.
    fn group(i: &mut usize, len: usize) -> Option<usize> {
        if *i < len {
            Some(*i)
        } else {
            *i -= len;
            None
        }
    }
    let mut i = index;
    if let Some(k) = group(&mut i, MAX_CHECKER_PERIOD_PX) {
        return Some(Case::Checker(k + 1));
    }
    if let Some(k) = group(&mut i, STRIPE_PERIODS_PX.len()) {
        return STRIPE_PERIODS_PX.get(k).map(|&p| Case::StripesV(p));
    }
    if let Some(k) = group(&mut i, STRIPE_PERIODS_PX.len()) {
        return STRIPE_PERIODS_PX.get(k).map(|&p| Case::StripesH(p));
    }
    if let Some(k) = group(&mut i, DOT_SPACINGS_PX.len()) {
        return DOT_SPACINGS_PX.get(k).map(|&s| Case::Dots(s));
    }
    if let Some(k) = group(&mut i, DOT_SPACINGS_PX.len()) {
        return DOT_SPACINGS_PX.get(k).map(|&s| Case::Holes(s));
    }
    if let Some(k) = group(&mut i, DOT_SPACINGS_PX.len()) {
        return DOT_SPACINGS_PX.get(k).map(|&s| Case::FramedHoles(s));
    }
    if let Some(k) = group(&mut i, DOT_SPACINGS_PX.len()) {
        return DOT_SPACINGS_PX.get(k).map(|&s| Case::PlateHoles(s));
    }
    if let Some(k) = group(&mut i, DOT_SPACINGS_PX.len()) {
        return DOT_SPACINGS_PX.get(k).map(|&s| Case::WeakBlob(s));
    }
    if let Some(k) = group(&mut i, NOISE_SEEDS.len()) {
        return NOISE_SEEDS.get(k).map(|&s| Case::Noise(s));
    }
    if let Some(k) = group(&mut i, SALT_PEPPER_SEEDS.len()) {
        return SALT_PEPPER_SEEDS.get(k).map(|&s| Case::SaltPepper(s));
    }
    if let Some(k) = group(&mut i, SPIKE_SEEDS.len()) {
        return SPIKE_SEEDS.get(k).map(|&s| Case::Spikes(s));
    }
    if let Some(k) = group(&mut i, FLAT_VARIANCE_SPIKES_PX.len()) {
        return FLAT_VARIANCE_SPIKES_PX
            .get(k)
            .map(|&s| Case::FlatVariance(s));
    }
    if let Some(k) = group(&mut i, 3) {
        return [Case::Saturated, Case::Black, Case::Ramp].get(k).copied();
    }
    if let Some(k) = group(&mut i, TILE_LENGTHS.len()) {
        return TILE_LENGTHS.get(k).map(|&l| Case::Tiled(l));
    }
    group(&mut i, FRAMES.len()).map(Case::Embedded)
}

/// The priors `auto` tracks with on every case: the four corners (16 px boxes), the
/// whole frame, the last pixel, a box half outside the right edge, one wholly outside.
pub const PRIORS: [Roi; 8] = [
    Roi::new(0, 0, 16, 16),
    Roi::new(FRAME_WIDTH as u16 - 16, 0, FRAME_WIDTH as u16, 16),
    Roi::new(0, FRAME_HEIGHT as u16 - 16, 16, FRAME_HEIGHT as u16),
    Roi::new(
        FRAME_WIDTH as u16 - 16,
        FRAME_HEIGHT as u16 - 16,
        FRAME_WIDTH as u16,
        FRAME_HEIGHT as u16,
    ),
    Roi::new(0, 0, FRAME_WIDTH as u16, FRAME_HEIGHT as u16),
    Roi::new(
        FRAME_WIDTH as u16 - 1,
        FRAME_HEIGHT as u16 - 1,
        FRAME_WIDTH as u16,
        FRAME_HEIGHT as u16,
    ),
    Roi::new(FRAME_WIDTH as u16 - 8, 100, FRAME_WIDTH as u16 + 8, 140),
    Roi::new(
        FRAME_WIDTH as u16 + 10,
        FRAME_HEIGHT as u16 + 10,
        FRAME_WIDTH as u16 + 40,
        FRAME_HEIGHT as u16 + 40,
    ),
];

/// Priors whose tracking windows are the largest `auto-v2` still searches before the
/// whole frame (`TRACK_MAX_WINDOW_PERMILLE`: half the frame; the window is the prior
/// grown by 16 px + its longer side on every side): a 92 px box in a corner (window
/// 200 × 200 px, 49 % of the frame) and a 56 px box in the middle (200 × 200 px): a
/// target lost in such a window costs the window and the whole frame, its worst case.
pub const LARGE_WINDOW_PRIORS: [Roi; 2] = [Roi::new(0, 0, 92, 92), Roi::new(136, 96, 192, 152)];

/// What `auto-v2` tracks with on every case: [`PRIORS`], then
/// [`LARGE_WINDOW_PRIORS`].
pub const AUTO_V2_PRIORS: [Roi; PRIORS.len() + LARGE_WINDOW_PRIORS.len()] = {
    let mut all = [Roi::EMPTY; PRIORS.len() + LARGE_WINDOW_PRIORS.len()];
    let mut i = 0;
    while i < all.len() {
        all[i] = if i < PRIORS.len() {
            PRIORS[i]
        } else {
            LARGE_WINDOW_PRIORS[i - PRIORS.len()]
        };
        i += 1;
    }
    all
};

/// xorshift64* (Vigna 2016): a fixed, tiny generator, so every target makes the same
/// frames.
struct XorShift(u64);

impl XorShift {
    fn new(seed: u64) -> Self {
        // Any non-zero state; the odd constant spreads small seeds.
        XorShift(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// A DN uniform on 0..=MAX_DN (the top bits of the output).
    fn dn(&mut self) -> u16 {
        (self.next() >> (64 - u32::from(BITS))) as u16
    }
}

/// Writes `case` into `frame` (row-major DN).
pub fn fill(case: Case, frame: &mut [u16; FRAME_PIXELS]) {
    let on = |b: bool| if b { MAX_DN } else { 0 };
    let mut rng = XorShift::new(match case {
        Case::Noise(s) | Case::SaltPepper(s) | Case::Spikes(s) => s,
        Case::Tiled(l) => l as u64,
        _ => 0,
    });
    if let Case::Embedded(k) = case {
        if let Some(embedded) = FRAMES.get(k) {
            for (dn, be) in frame.iter_mut().zip(embedded.be_bytes.chunks_exact(2)) {
                *dn = u16::from_be_bytes([be[0], be[1]]);
            }
        }
        return;
    }
    if let Case::FlatVariance(spike_px) = case {
        tirroi_core::roi::otsu::fill_flat_variance(frame, MAX_DN, spike_px);
        return;
    }
    let mut tile = [0u16; TILE_LENGTHS[TILE_LENGTHS.len() - 1]];
    if let Case::Tiled(len) = case {
        for t in tile.iter_mut().take(len) {
            *t = rng.dn();
        }
    }
    for (i, dn) in frame.iter_mut().enumerate() {
        let (x, y) = (i % FRAME_WIDTH, i / FRAME_WIDTH);
        *dn = match case {
            Case::Checker(p) => on((x / p + y / p) % 2 == 1),
            Case::StripesV(p) => on((x / p) % 2 == 1),
            Case::StripesH(p) => on((y / p) % 2 == 1),
            Case::Dots(s) => on(x % s == 0 && y % s == 0),
            Case::Holes(s) => on(!(x % s == 0 && y % s == 0)),
            Case::FramedHoles(s) | Case::PlateHoles(s) | Case::WeakBlob(s) => {
                let (plate, margin, left_px, right_px) = match case {
                    Case::PlateHoles(_) => (MAX_DN / 2, MAX_DN / 4, FRAME_MARGIN_PX, 0),
                    Case::WeakBlob(_) => (
                        MAX_DN,
                        MAX_DN - WEAK_BLOB_MARGIN_BELOW_TOP_DN,
                        weak_blob_margin_px(s),
                        0,
                    ),
                    _ => (MAX_DN, MAX_DN / 4, FRAME_MARGIN_PX, FRAME_MARGIN_PX),
                };
                // Top and left margins `left_px`, right and bottom `right_px`.
                let inside = (left_px..FRAME_WIDTH - right_px).contains(&x)
                    && (left_px..FRAME_HEIGHT - right_px).contains(&y);
                match (inside, x % s == 0 && y % s == 0) {
                    (false, _) => margin,
                    (true, true) => 0,
                    (true, false) => plate,
                }
            }
            Case::Noise(_) => rng.dn(),
            Case::SaltPepper(_) => on(rng.next() >> 63 == 1),
            Case::Spikes(_) => match rng.next() % 1000 {
                p if p < SPIKE_PERMILLE => 0,
                p if p < 2 * SPIKE_PERMILLE => MAX_DN,
                _ => rng.dn(),
            },
            Case::Saturated => MAX_DN,
            Case::Black => 0,
            Case::Ramp => ((x + y) * usize::from(MAX_DN) / (FRAME_WIDTH + FRAME_HEIGHT - 2)) as u16,
            Case::Tiled(len) => tile.get(i % len.max(1)).copied().unwrap_or(0),
            Case::Embedded(_) | Case::FlatVariance(_) => 0,
        };
    }
}

impl fmt::Display for Case {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Case::Checker(p) => write!(f, "checker-{p}"),
            Case::StripesV(p) => write!(f, "stripes-v-{p}"),
            Case::StripesH(p) => write!(f, "stripes-h-{p}"),
            Case::Dots(s) => write!(f, "dots-{s}"),
            Case::Holes(s) => write!(f, "holes-{s}"),
            Case::FramedHoles(s) => write!(f, "framed-holes-{s}"),
            Case::PlateHoles(s) => write!(f, "plate-holes-{s}"),
            Case::WeakBlob(s) => write!(f, "weak-blob-{s}"),
            Case::Noise(n) => write!(f, "noise-{n}"),
            Case::SaltPepper(n) => write!(f, "salt-pepper-{n}"),
            Case::Spikes(n) => write!(f, "spikes-{n}"),
            Case::FlatVariance(s) => write!(f, "flat-variance-{s}"),
            Case::Saturated => f.write_str("saturated"),
            Case::Black => f.write_str("black"),
            Case::Ramp => f.write_str("ramp"),
            Case::Tiled(l) => write!(f, "tiled-{l}"),
            Case::Embedded(k) => f.write_str(FRAMES.get(k).map_or("embedded-?", |e| e.name)),
        }
    }
}
