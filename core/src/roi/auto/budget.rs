//! A work budget per `auto` call, so a frame never overruns its time slot.
//!
//! Before each stage of a pass (noise, step plane, candidates, refinement) `auto`
//! charges that stage's worst-case cost, worked out from the geometry alone (the
//! window's rows and columns, the cell plane, the refinement region), in instructions
//! of the flight build on a Cortex-M7 (thumbv7em-none-eabihf, release). When the charge
//! does not fit in what is left, the stage does not run: `auto` stops there and returns
//! its best box so far, and says where it stopped ([`BudgetReport`]):
//!
//! 1. the box of the tracking window's pass, when the full-frame pass that should
//!    confirm or replace it does not fit and that box overlaps the prior (the tracked
//!    target, cut by the window);
//! 2. else, when the refinement does not fit, the winner's cell box (4-pixel
//!    resolution, cut to the frame): where the candidates stage put the target;
//! 3. else no box.
//!
//! Charges are deterministic (no clock is read), so a budgeted call gives the same
//! answer on the host and on board, and the work done never exceeds the budget by
//! more than the call's fixed cost. The coefficients below are upper bounds per element
//! of each stage's loops, measured on the adversarial frames under QEMU
//! (`scripts/worst-case.sh` runs every frame with a ladder of budgets and fails when a
//! call counts more instructions than it charged). On another processor, scale the
//! budget by that processor's instructions per M7 instruction for the same code.

use super::super::Roi;
use super::super::plane::{BLOCK, Window};
use super::edges::CellStats;
use super::refine::Region;
use super::rules::{NOISE_ROWS, RELABEL_ATTEMPTS};

/// A work budget for one `auto` call, in Cortex-M7 instructions (see the module
/// documentation for how they are charged): 0..=`u32::MAX`, [`WorkBudget::UNLIMITED`]
/// when none is given. A 100 MHz M7 runs 100 000 per millisecond at one instruction
/// per cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WorkBudget {
    /// Instructions the call may spend (worst-case charges of the stages it runs).
    pub instructions: u32,
}

impl WorkBudget {
    /// No limit: the pipeline always runs to the end (what [`crate::Detector::detect`] does).
    pub const UNLIMITED: WorkBudget = WorkBudget {
        instructions: u32::MAX,
    };

    /// A budget of `instructions` Cortex-M7 instructions.
    pub const fn instructions(instructions: u32) -> Self {
        WorkBudget { instructions }
    }

    /// The budget of a time slot: `slot_us` microseconds at `clock_hz` and one
    /// instruction per cycle (the M7's sustained rate on this code is lower, so this
    /// is the slot's most; leave room for what else runs in it).
    pub const fn slot(clock_hz: u32, slot_us: u32) -> Self {
        let n = clock_hz as u64 * slot_us as u64 / 1_000_000;
        WorkBudget {
            instructions: if n > u32::MAX as u64 {
                u32::MAX
            } else {
                n as u32
            },
        }
    }
}

/// A stage of one pass of `auto`'s pipeline, in the order they run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AutoStage {
    /// Stage 1: the noise estimate.
    Noise,
    /// Stage 2: the step plane (one pass over every other row of the window).
    StepPlane,
    /// Stages 3 and 4: edge components (with relabelling) and the target decision.
    Candidates,
    /// Stages 5 and 6: the gate, saturation counts and the outline at full resolution.
    Refinement,
}

impl AutoStage {
    /// The stage's name in reports (`noise`, `step-plane`, `candidates`, `refinement`).
    pub const fn name(self) -> &'static str {
        match self {
            AutoStage::Noise => "noise",
            AutoStage::StepPlane => "step-plane",
            AutoStage::Candidates => "candidates",
            AutoStage::Refinement => "refinement",
        }
    }
}

/// Where a budgeted call stopped because the next stage's charge did not fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Stopped {
    /// The stage that did not run.
    pub stage: AutoStage,
    /// True when it was a stage of the full-frame pass after a tracking pass (whose
    /// box, if any, is the answer).
    pub after_tracking: bool,
}

/// What a budgeted `auto` call spent, and whether the budget stopped it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BudgetReport {
    /// Instructions charged (worst-case cost of the stages that ran, plus the call's
    /// fixed cost): at most the budget, except for a budget below [`CALL_INSTR`]
    /// (then only the fixed cost, and nothing ran).
    pub charged: u32,
    /// `None` when the pipeline ran to its end; else where it stopped.
    pub stopped: Option<Stopped>,
}

/// Fixed cost of a call (parameter checks, the detection's assembly, tracking
/// arithmetic), charged up front even when nothing else fits. Measured ~1 000 on
/// the M7 for a call that stops at once; doubled.
pub const CALL_INSTR: u32 = 2_000;
/// Fixed cost of one pass (window set-up, decision over at most 250 labels of ~8
/// instructions, the found box).
const PASS_INSTR: u32 = 4_000;
/// Noise: per pixel of a sampled row, per pass over the samples (the scene count and
/// at most two difference histograms: [`NOISE_PASSES`]): clamp copy, a difference, a
/// histogram bin (a log2) per pair of pixels. Measured at most 16.9 (with the pass's
/// fixed cost) on the adversarial frames.
const NOISE_INSTR_PER_PX: u32 = 20;
/// The noise stage goes over its sampled rows at most this often.
const NOISE_PASSES: u32 = 3;
/// Step plane: per pixel of a processed row (every other row): three loads, three
/// clamps, two absolute differences and two maxima, and the band's reset and maximum.
/// The whole stage measured 1.66–1.78 M on the full frame (40 672 pixels processed,
/// 41–44 per pixel with the cells' share).
const STEP_INSTR_PER_PX: u32 = 48;
/// Step plane: per cell (the maximum over 4 pixels and its log code).
const STEP_INSTR_PER_CELL: u32 = 40;
/// Candidates: per cell per labelling attempt (a code compare, and for an edge cell
/// up to four neighbour unions with statistics merged). Frames of thousands of small
/// components (`holes-3`: four attempts) measured about 54.
const LABEL_INSTR_PER_CELL: u32 = 64;
/// Refinement: per cell of the region grown by a cell (gate: two dilation passes).
const GATE_INSTR_PER_CELL: u32 = 24;
/// Refinement: per pixel of the region: the saturation count (one pass over gated
/// cells) and the outline's worst case: every row scanned to its end without a
/// boundary (each pixel tested once from the left or the right, a row per cell band
/// twice) and every row tested for vertical boundaries, with the row set-ups. A small
/// region does that when nothing but its first boundary lies in it: `plate-holes-2`'s
/// corner window (34 × 34 px) measured 71.6 (session 33, after the outline's scans
/// were made to test each pixel once and on raw steps first; before, 91.5, which 40,
/// from `holes-3`'s whole-frame region at 33.5, undercharged by 13 %), its whole frame
/// 41.7 (the row set-ups weigh less in long rows); whole-frame regions whose scans stop
/// at boundaries 13–34. The measured worst × 1.2.
const REFINE_INSTR_PER_PX: u32 = 86;

/// The charges of one call: what is left, what was charged.
#[derive(Debug, Clone, Copy)]
pub(super) struct Ledger {
    left: u32,
    charged: u32,
    stopped: Option<Stopped>,
    /// Set once a tracking pass has run: a stop from now on is "after tracking".
    after_tracking: bool,
}

impl Ledger {
    /// A ledger for one call under `budget`, the call's fixed cost charged.
    pub fn new(budget: WorkBudget) -> Ledger {
        let fixed = CALL_INSTR.min(budget.instructions);
        Ledger {
            left: budget.instructions - fixed,
            charged: CALL_INSTR,
            stopped: None,
            after_tracking: false,
        }
    }

    /// Charges `cost` for `stage` if it fits; else records the stop and returns false.
    fn take(&mut self, stage: AutoStage, cost: u32) -> bool {
        if self.stopped.is_some() {
            return false;
        }
        if cost <= self.left {
            self.left -= cost;
            self.charged = self.charged.saturating_add(cost);
            true
        } else {
            self.stopped = Some(Stopped {
                stage,
                after_tracking: self.after_tracking,
            });
            false
        }
    }

    /// Marks the end of the tracking pass.
    pub fn tracking_done(&mut self) {
        self.after_tracking = true;
    }

    /// True once a stage did not fit.
    pub fn is_stopped(&self) -> bool {
        self.stopped.is_some()
    }

    /// Noise estimate of a pass over `win` (and the pass's fixed cost).
    pub fn noise(&mut self, win: Window) -> bool {
        self.take(AutoStage::Noise, saturated(noise_charge(win.w, win.h)))
    }

    /// Step plane of `win` (`cells` cells).
    pub fn step_plane(&mut self, win: Window, cells: usize) -> bool {
        self.take(
            AutoStage::StepPlane,
            saturated(step_plane_charge(win.w, win.h, cells)),
        )
    }

    /// Labelling of `cells` cells (every attempt) and the decision.
    pub fn candidates(&mut self, cells: usize) -> bool {
        self.take(AutoStage::Candidates, saturated(candidates_charge(cells)))
    }

    /// Gate, saturation counts and outline over `region`.
    pub fn refinement(&mut self, region: &Region) -> bool {
        let cells = (region.cb - region.ca + 2) * (region.rb - region.ra + 2);
        let px = (region.rx1 - region.rx0) * (region.ry1 - region.ry0);
        self.take(
            AutoStage::Refinement,
            saturated(refinement_charge(cells, px)),
        )
    }

    /// The report of the call.
    pub fn report(&self) -> BudgetReport {
        BudgetReport {
            charged: self.charged,
            stopped: self.stopped,
        }
    }
}

/// The winner's cell box in frame pixels (4-pixel resolution, cut to the window): the
/// best box so far when the refinement does not fit.
pub(super) fn coarse_box(win: Window, c: &CellStats) -> Roi {
    let px = |v: usize| v.min(usize::from(u16::MAX)) as u16;
    Roi::new(
        px(win.x0 + usize::from(c.x0) * BLOCK),
        px(win.y0 + usize::from(c.y0) * BLOCK),
        px((win.x0 + c.x_end() * BLOCK).min(win.x0 + win.w)),
        px((win.y0 + c.y_end() * BLOCK).min(win.y0 + win.h)),
    )
}

/// The charge of the noise stage of a pass over a `w × h` window, with the pass's
/// fixed cost.
const fn noise_charge(w: usize, h: usize) -> u64 {
    let rows = if h < NOISE_ROWS + 1 {
        h
    } else {
        NOISE_ROWS + 1
    };
    (rows * w) as u64 * (NOISE_INSTR_PER_PX * NOISE_PASSES) as u64 + PASS_INSTR as u64
}

/// The charge of the step plane of a `w × h` window of `cells` cells.
const fn step_plane_charge(w: usize, h: usize, cells: usize) -> u64 {
    (h.div_ceil(2) * w) as u64 * STEP_INSTR_PER_PX as u64
        + cells as u64 * STEP_INSTR_PER_CELL as u64
}

/// The charge of labelling `cells` cells (every attempt) and the decision.
const fn candidates_charge(cells: usize) -> u64 {
    cells as u64 * LABEL_INSTR_PER_CELL as u64 * RELABEL_ATTEMPTS as u64
}

/// The charge of the refinement over a region of `px` pixels and `cells` cells (with
/// a cell around it).
const fn refinement_charge(cells: usize, px: usize) -> u64 {
    cells as u64 * GATE_INSTR_PER_CELL as u64 + px as u64 * REFINE_INSTR_PER_PX as u64
}

/// The largest charge of an `auto` call on a `width × height` frame (pixels; the
/// capacity's at most): a budget of at least this never stops the call. With
/// `tracking`, two passes (the window around the prior, then the full frame); the
/// refinement as if its region were the whole frame. 10 922 288 instructions at
/// 328 × 248 without a prior, 21 842 576 with one.
pub const fn largest_charge(width: usize, height: usize, tracking: bool) -> u32 {
    let (pw, ph) = (width.div_ceil(BLOCK), height.div_ceil(BLOCK));
    let cells = pw * ph;
    let pass = noise_charge(width, height)
        + step_plane_charge(width, height, cells)
        + candidates_charge(cells)
        + refinement_charge((pw + 2) * (ph + 2), width * height);
    let passes = if tracking { 2 * pass } else { pass };
    saturated(passes + CALL_INSTR as u64)
}

/// `v` saturated to `u32`.
const fn saturated(v: u64) -> u32 {
    if v > u32::MAX as u64 {
        u32::MAX
    } else {
        v as u32
    }
}
