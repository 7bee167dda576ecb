//! A scene-aware ROI detector of our own (`auto`): decides from cheap statistics of
//! the frame what the scene needs, runs only that, and can track (a prior box from
//! the last frame limits the work to a window around it).
//!
//! # Pipeline
//!
//! `Auto::locate` runs these stages in order, one module each; every number they
//! decide with is a parameter of [`Auto`] or a named constant of [`rules`], with its
//! reason.
//!
//! 1. **Noise and scene** (`noise`). Horizontal differences on [`rules::NOISE_ROWS`]
//!    rows give two noise estimates: first differences (which include the Earth's
//!    smooth texture) and second differences (blind to smooth shading). Runs at 0 DN
//!    or saturated are skipped (clipped noise says nothing). When most sampled pairs
//!    are both at 0 DN, deep space fills the frame and the only texture is the
//!    target's own shading: the second-difference σ is used, else the first.
//! 2. **Step plane** (`steps`). One pass over every other row of the frame (or the
//!    tracking window): per 4×4 cell, the largest difference of a pixel and the pixel
//!    two to its right or two below, in units of σ/4, as an 8-bit logarithmic code
//!    (16 codes per octave; a plane of 82×62 cells). The target's outline is a step;
//!    the Earth's texture is a ramp and the noise small.
//! 3. **Candidates** (`edges`). Cells with a step of at least `coarse_sigma · σ` are
//!    edge cells, labelled into 8-connected components with the union-find shared with
//!    the mask rule (at most [`MAX_EDGE_COMPONENTS`]; a frame with more is labelled
//!    again with a threshold `relabel_codes` codes, half as high, higher), each with
//!    its cell box and summed steps (linear, so a saturated target's outline outweighs
//!    a wide patch of the Earth's texture).
//! 4. **Target decision** (`decision`). Each component scores its summed steps,
//!    divided by 2^`side_shift` (8) for every side of the window it touches: the
//!    Earth's limb (an arc from border to border) and Earth patches cut by the frame
//!    lose to a compact outline inside it.
//! 5. **Refinement** (`refine`). At full resolution inside the winner's cell box plus
//!    one cell, only at pixels whose cell neighbours the winner (the gate): a step of
//!    at least `fine_sigma · σ` between pixels `x − 1` and `x + 1`, the largest along
//!    its direction (which drops the small step between a partly covered pixel and the
//!    background beyond it), is a boundary before `x` when `x` resembles `x + 1`, else
//!    after it. With labels of pixels at least half covered (our truth), that is the
//!    truth's boundary for any contrast and polarity. The box spans the outermost
//!    boundaries. In clean deep space (sunlit frames: 0 DN nearly everywhere, clipped
//!    noise a sparse sprinkle), a step from 0 DN below `fine_sigma · σ` also counts
//!    when the pixel beyond it and its four neighbours are above 0: a faint (cold)
//!    face.
//! 6. **Saturated target** (`refine`; detection mode, recognised by pixels at the top
//!    DN with hardly any within `near_sat_sigma · σ` below it, unlike a radiometry
//!    face at the top DN with noise): pixels less than half covered saturate too, so
//!    the box is that of the saturated pixels with outermost lines of at most 2 pixels
//!    trimmed (twice per side at most), joined with the boundaries of unsaturated
//!    (cold) faces.
//!
//! # Tracking
//!
//! With [`Auto::prior`] set (`tracking`), the pipeline runs on the prior grown by
//! `margin_px + max(width, height) / margin_divisor` on every side. If nothing is
//! found there, or the box found misses the prior or reaches the window's border (the
//! target left the window, grew out of it, or the prior was wrong), the full frame is
//! processed instead.
//!
//! # Budgets
//!
//! No heap; integer arithmetic only in every loop over pixels and cells (no floating
//! point at all); no panic on any frame (`Frame` bounds every access; proptest and a
//! fuzz target check it; the flight build links without a panic path,
//! `scripts/panic-never.sh`); memory [`SCRATCH_BYTES`] (≤ 32 KiB, checked at compile
//! time). Time: [`Auto::detect_within`] takes a [`WorkBudget`] in Cortex-M7
//! instructions, charges each stage's worst case before it runs and stops with its
//! best box so far when the next stage does not fit (module `budget`), so a frame
//! never overruns its slot.

pub mod budget;
mod decision;
mod edges;
pub mod learned;
mod noise;
mod refine;
pub mod rules;
mod steps;
mod tracking;

pub use budget::{AutoStage, BudgetReport, CALL_INSTR, Stopped, WorkBudget, largest_charge};
pub use edges::MAX_EDGE_COMPONENTS;

use super::plane::{BLOCK, Window};
use super::{BoxRule, DetectError, Detection, Detector, Roi, Scratch};
use crate::capacity::{ConstInit, FrameCapacity, Reference};
use crate::frame::{FRAME_WIDTH, Frame};
use budget::{Ledger, coarse_box};
use decision::choose_target;
use edges::{EdgeComponents, label_edge_cells};
use noise::{NOISE_BINS, noise_sigma};
use refine::{Region, build_gate, count_saturation, outline};
use rules::{MIN_SATURATED_PX, STEP_UNITS_PER_SIGMA};
use steps::{step_code, step_plane, step_value};

/// Parameters of the `auto` detector.
///
/// The thresholds are multiples of the pixel noise σ (DN), estimated per frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Auto {
    /// Tracking prior: the last frame's box, or `None` to search the whole frame.
    /// Any box is accepted; it is cut to the frame, and an empty result means no prior.
    pub prior: Option<Roi>,
    /// Coarse edge threshold: a cell is an edge cell when its largest step reaches
    /// `coarse_sigma · σ`: 1..=1000. Default 6.
    pub coarse_sigma: u16,
    /// Full-resolution boundary threshold: a step over two pixels counts when it
    /// reaches `fine_sigma · σ` (twice that beside a saturated target): 1..=1000.
    /// Default 8.
    pub fine_sigma: u16,
    /// Tracking window margin around the prior, in pixels: 0..=328. Default 16 (plus
    /// `max(width, height) / margin_divisor`: room for a move of several pixels and a
    /// 10 % change of size per frame).
    pub margin_px: u16,
    /// The tracking margin grows by `max(width, height) / margin_divisor` of the prior:
    /// 1..=64. Default 8 (12.5 %: a 10 % change of size per frame fits).
    pub margin_divisor: u16,
    /// A component's summed steps are shifted right by this for every side of the
    /// window it touches (the Earth's limb and patches cut by the frame touch one or
    /// more): 0..=15. Default 3 (÷ 8 per side: a limb arc touching two sides needs 64
    /// times a compact outline's steps to win).
    pub side_shift: u8,
    /// When a frame has more edge components than labels, the edge threshold rises by
    /// this many step codes per relabelling (16 per octave): 1..=64. Default 9
    /// (16 · log2 1.5 ≈ 9.4: half as high again).
    pub relabel_codes: u8,
    /// Near-saturation band, multiples of σ below the top DN: a saturated target has
    /// hardly any pixel in it, a radiometry face at the top DN has its noise there:
    /// 1..=64. Default 4 (4 σ holds nearly all of a noisy face's pixels below the top).
    pub near_sat_sigma: u16,
    /// A target is saturated (at least 4 pixels at the top DN) when
    /// `sat_ratio · near < saturated` pixels: 1..=1000. Default 8 (fewer than one pixel
    /// in the band per 8 saturated: flat, not a noisy face).
    pub sat_ratio: u16,
}

impl Default for Auto {
    fn default() -> Self {
        Auto {
            prior: None,
            coarse_sigma: 6,
            fine_sigma: 8,
            margin_px: 16,
            margin_divisor: 8,
            side_shift: 3,
            relabel_codes: 9,
            near_sat_sigma: 4,
            sat_ratio: 8,
        }
    }
}

impl Auto {
    /// The same parameters with a tracking prior (the last frame's box).
    pub const fn with_prior(self, prior: Option<Roi>) -> Self {
        Auto { prior, ..self }
    }
}

/// `auto`'s buffers. Two cell planes and two rows change meaning between stages; the
/// field docs say what each holds when, and the stages take them under the role names.
///
/// At capacity `C` (`W × H` pixels, `PW × PH` cells): saturation counts per row and
/// column are at most `W`, `H` ≤ 1024 (`u16`); cell coordinates are `u8` (inclusive,
/// ≤ 255 cells); labels `u8` ([`MAX_EDGE_COMPONENTS`], independent of the capacity).
#[derive(Debug, Clone)]
pub struct AutoWork<C: FrameCapacity = Reference> {
    /// Cell plane (window cells, row-major): the step codes (stage 2, read by stage 3);
    /// then, free, the winner dilated along rows (`row_dilated`, building the gate).
    step_codes: C::Cells<u8>,
    /// Cell plane: the component labels (stage 3; 0: not an edge cell); then the gate
    /// (stage 5: the winner's cells and their neighbours, a `refine::Gate`).
    labels: C::Cells<u8>,
    /// The edge components (the shared union-find): parents of all 256 `u8` labels,
    /// statistics of the labels handed out.
    comps: EdgeComponents,
    /// One pixel row: the clamped noise row (stage 1), then the largest steps per pixel
    /// of one band of rows (`band`, stage 2).
    pixel_row: C::Row<u16>,
    /// Saturated pixels per column and per row of the refinement window.
    col_sat: C::Row<u16>,
    row_sat: C::Column<u16>,
    /// Histogram of one noise estimate.
    hist: [u32; NOISE_BINS + 1],
    /// One row of flags: the winner's cells of one cell row, padded by a cell on each
    /// side (`winner_row`, building the gate), or a mask row of
    /// [`Detector::foreground`] (`mask_row`).
    flag_row: C::Row<bool>,
}

impl<C: FrameCapacity> ConstInit for AutoWork<C> {
    const INIT: Self = AutoWork {
        step_codes: ConstInit::INIT,
        labels: ConstInit::INIT,
        comps: ConstInit::INIT,
        pixel_row: ConstInit::INIT,
        col_sat: ConstInit::INIT,
        row_sat: ConstInit::INIT,
        hist: [0; NOISE_BINS + 1],
        flag_row: ConstInit::INIT,
    };
}

/// The `auto` detector's scratch memory at capacity `C` (default 328×248).
pub type AutoScratch<C = Reference> = Scratch<AutoWork<C>, C>;

/// Bytes of [`AutoScratch`] at 328×248 (budget: 32 KiB, checked at compile time).
pub const SCRATCH_BYTES: usize = core::mem::size_of::<AutoScratch>();
const _: () = assert!(SCRATCH_BYTES <= 32 * 1024, "auto's scratch exceeds 32 KiB");

/// What one pass of the pipeline found in a window.
#[derive(Debug, Clone, Copy)]
struct Found {
    roi: Option<Roi>,
    /// Coarse edge threshold, DN: `coarse_sigma · σ`.
    threshold: u32,
    /// Full-resolution boundary pixels inside the gate.
    edge_px: u32,
}

impl Auto {
    /// Runs the pipeline's stages on `win`; `None` when no component is found. Each
    /// stage is charged to `ledger` first; when one does not fit, the pass stops: no
    /// box before the candidates, the winner's cell box ([`coarse_box`]) when the
    /// refinement does not fit.
    fn locate<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoWork<C>,
        win: Window,
        ledger: &mut Ledger,
    ) -> Option<Found> {
        let AutoWork {
            step_codes,
            labels,
            comps,
            pixel_row,
            col_sat,
            row_sat,
            hist,
            flag_row,
        } = work;
        let plane = (win.w.div_ceil(BLOCK), win.h.div_ceil(BLOCK));
        let cells = plane.0 * plane.1;
        let (Some(step_codes), Some(labels)) = (
            step_codes.as_mut().get_mut(..cells),
            labels.as_mut().get_mut(..cells),
        ) else {
            return None;
        };
        let (pixel_row, flag_row) = (pixel_row.as_mut(), flag_row.as_mut());
        // 1. Noise and scene.
        if !ledger.noise(win) {
            return None;
        }
        let noise = noise_sigma(frame, win, hist, pixel_row);
        // 2. Step plane (codes below the edge threshold's are not worked out).
        let edge_code = step_code(u32::from(self.coarse_sigma) * STEP_UNITS_PER_SIGMA);
        let floor = step_value(edge_code);
        if !ledger.step_plane(win, cells) {
            return None;
        }
        step_plane(
            frame,
            win,
            noise.sigma,
            floor,
            plane.0,
            pixel_row,
            step_codes,
        );
        // 3. Candidates: edge components.
        if !ledger.candidates(cells) {
            return None;
        }
        let next = label_edge_cells(
            step_codes,
            labels,
            plane.0,
            edge_code,
            self.relabel_codes,
            comps,
        );
        // 4. Target decision.
        let (root, winner) = choose_target(comps, next, plane, self.side_shift)?;
        // 5. Refinement: the gate (the labels become it), saturation counts.
        let region = Region::around(&winner, win);
        let threshold = u32::from(self.coarse_sigma) * noise.sigma;
        if !ledger.refinement(&region) {
            return Some(Found {
                roi: Some(coarse_box(win, &winner)),
                threshold,
                edge_px: 0,
            });
        }
        let (row_dilated, winner_row) = (step_codes, flag_row);
        let gate = build_gate(
            labels,
            row_dilated,
            winner_row,
            comps,
            root,
            next,
            &region,
            win,
            plane,
        );
        let (Some(col_sat), Some(row_sat)) = (
            col_sat.as_mut().get_mut(region.rx0..region.rx1),
            row_sat.as_mut().get_mut(region.ry0..region.ry1),
        ) else {
            return None;
        };
        let counts = count_saturation::<C>(
            frame,
            &gate,
            &region,
            self.near_saturation(frame, noise.sigma),
            col_sat,
            row_sat,
        );
        // 6. Saturated target, then the outermost boundaries.
        let saturated = self.is_saturated(counts.sat_px, counts.near_px);
        let tau = (u32::from(self.fine_sigma) * noise.sigma).min(u32::from(u16::MAX)) as u16;
        let (roi, edge_px) = outline(frame, &gate, &region, noise, tau, saturated, &counts);
        roi.map(|roi| Found {
            roi: Some(roi),
            threshold,
            edge_px,
        })
    }

    /// The lowest DN of the near-saturation band: `near_sat_sigma · σ` below the top.
    fn near_saturation(&self, frame: &Frame<'_>, sigma: u32) -> u16 {
        let band = u32::from(self.near_sat_sigma).saturating_mul(sigma);
        frame
            .max_dn()
            .saturating_sub(band.min(u32::from(u16::MAX)) as u16)
    }

    /// A saturated target (detection mode) is flat at the top DN: hardly any pixel just
    /// below it, unlike a radiometry face at the top DN with noise. Then the boundaries
    /// sought are those of unsaturated faces (at a higher threshold).
    fn is_saturated(&self, sat_px: u32, near_px: u32) -> bool {
        sat_px >= MIN_SATURATED_PX && u32::from(self.sat_ratio).saturating_mul(near_px) < sat_px
    }
}

/// The parameters as `name=value` pairs separated by spaces (as in tuning reports
/// and tuned sets): the thresholds and the margin, then each further tunable number
/// only when it differs from its default.
impl core::fmt::Display for Auto {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "coarse_sigma={} fine_sigma={} margin_px={}",
            self.coarse_sigma, self.fine_sigma, self.margin_px
        )?;
        let d = Auto::default();
        let extra: [(&str, u16, u16); 5] = [
            ("margin_divisor", self.margin_divisor, d.margin_divisor),
            ("side_shift", self.side_shift.into(), d.side_shift.into()),
            (
                "relabel_codes",
                self.relabel_codes.into(),
                d.relabel_codes.into(),
            ),
            ("near_sat_sigma", self.near_sat_sigma, d.near_sat_sigma),
            ("sat_ratio", self.sat_ratio, d.sat_ratio),
        ];
        for (name, value, default) in extra {
            if value != default {
                write!(f, " {name}={value}")?;
            }
        }
        Ok(())
    }
}

impl Detector for Auto {
    type Work<C: FrameCapacity> = AutoWork<C>;
    const NAME: &'static str = "auto";

    fn validate(&self) -> Result<(), DetectError> {
        let checks: [(bool, &'static str, &'static str); 8] = [
            (
                (1..=1000).contains(&self.coarse_sigma),
                "coarse_sigma",
                "1..=1000 (multiples of the pixel noise σ)",
            ),
            (
                (1..=1000).contains(&self.fine_sigma),
                "fine_sigma",
                "1..=1000 (multiples of the pixel noise σ)",
            ),
            (
                usize::from(self.margin_px) <= FRAME_WIDTH,
                "margin_px",
                "0..=328 pixels",
            ),
            (
                (1..=64).contains(&self.margin_divisor),
                "margin_divisor",
                "1..=64",
            ),
            (
                self.side_shift <= 15,
                "side_shift",
                "0..=15 (bits per window side touched)",
            ),
            (
                (1..=64).contains(&self.relabel_codes),
                "relabel_codes",
                "1..=64 (step codes, 16 per octave)",
            ),
            (
                (1..=64).contains(&self.near_sat_sigma),
                "near_sat_sigma",
                "1..=64 (multiples of the pixel noise σ)",
            ),
            (
                (1..=1000).contains(&self.sat_ratio),
                "sat_ratio",
                "1..=1000",
            ),
        ];
        match checks.iter().find(|(ok, _, _)| !ok) {
            Some(&(_, name, expected)) => Err(DetectError::InvalidParameter { name, expected }),
            None => Ok(()),
        }
    }

    /// `auto` always boxes its chosen outline; the rule does not apply.
    fn box_rule(&self) -> BoxRule {
        BoxRule::LargestComponent
    }

    /// Foreground: the detected box, filled. Threshold: the coarse edge threshold
    /// (`coarse_sigma · σ`, DN).
    fn foreground<C: FrameCapacity, F: FnMut(usize, &[bool])>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoWork<C>,
        mut sink: F,
    ) -> u32 {
        let d = self.run(frame, work, &mut Ledger::new(WorkBudget::UNLIMITED));
        let roi = d.roi.unwrap_or(Roi::EMPTY);
        let mask_row = &mut work.flag_row.as_mut()[..frame.width()];
        for y in 0..frame.height() {
            roi.fill_mask_row(y, mask_row);
            sink(y, mask_row);
        }
        d.threshold
    }

    /// Runs `auto` (without the mask pass of the default: the box comes straight from
    /// the refinement). `foreground_px` counts the edge pixels that made the box.
    fn detect<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        scratch: &mut Scratch<AutoWork<C>, C>,
    ) -> Result<Detection, DetectError> {
        self.validate()?;
        DetectError::check_capacity::<C>(frame)?;
        Ok(self.run(
            frame,
            &mut scratch.work,
            &mut Ledger::new(WorkBudget::UNLIMITED),
        ))
    }
}

impl Auto {
    /// Runs `auto` within a work budget (module `budget` explains the charges):
    /// the same answer as [`Detector::detect`] when the budget covers every stage's
    /// charge, else the best box so far (the tracking pass's box, else the winner's
    /// cell box when only the refinement did not fit, else none) with
    /// [`BudgetReport::stopped`] saying where it stopped. The work done stays within
    /// the charges ([`BudgetReport::charged`] ≤ the budget, or [`CALL_INSTR`] for a
    /// budget below it).
    ///
    /// # Errors
    /// As [`Detector::detect`]: invalid parameters, a frame over the capacity.
    pub fn detect_within<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        scratch: &mut Scratch<AutoWork<C>, C>,
        budget: WorkBudget,
    ) -> Result<(Detection, BudgetReport), DetectError> {
        self.validate()?;
        DetectError::check_capacity::<C>(frame)?;
        let mut ledger = Ledger::new(budget);
        let d = self.run(frame, &mut scratch.work, &mut ledger);
        Ok((d, ledger.report()))
    }
}

#[cfg(test)]
mod tests {
    use super::noise::{NOISE_BINS, bin_value, noise_bin};
    use super::steps::{step_code, step_value};

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
    fn tunable_numbers_default_to_the_rule_and_are_bounded() {
        use super::{Auto, Detector};
        let d = Auto::default();
        assert_eq!((d.margin_divisor, d.side_shift, d.relabel_codes), (8, 3, 9));
        assert_eq!((d.near_sat_sigma, d.sat_ratio), (4, 8));
        assert!(d.validate().is_ok());
        let bad = [
            Auto {
                margin_divisor: 0,
                ..d
            },
            Auto {
                side_shift: 16,
                ..d
            },
            Auto {
                relabel_codes: 0,
                ..d
            },
            Auto {
                near_sat_sigma: 65,
                ..d
            },
            Auto { sat_ratio: 0, ..d },
        ];
        let names = [
            "margin_divisor",
            "side_shift",
            "relabel_codes",
            "near_sat_sigma",
            "sat_ratio",
        ];
        for (a, name) in bad.iter().zip(names) {
            match a.validate() {
                Err(super::DetectError::InvalidParameter { name: n, .. }) => assert_eq!(n, name),
                Ok(()) => panic!("{name} accepted"),
                Err(e) => panic!("{name}: {e}"),
            }
        }
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
