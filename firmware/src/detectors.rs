//! Every detector of the core behind one call per method, with default parameters, in
//! ONE scratch area shared by all of them ([`SharedScratch`]): only one detector runs at
//! a time, so the demo needs the largest scratch (DoG's, 74 KB), not the sum of all
//! six (190 KB, the core's registry bank [`tirroi_core::roi::Detectors`]).

use tirroi_core::roi::adaptive::{Adaptive, AdaptiveScratch};
use tirroi_core::roi::auto::learned::look::Look;
use tirroi_core::roi::auto::learned::{AutoV2, AutoV2Scratch};
use tirroi_core::roi::auto::{Auto, AutoScratch, BudgetReport, WorkBudget};
use tirroi_core::roi::dog::{Dog, DogScratch};
use tirroi_core::roi::otsu::{Otsu, OtsuScratch};
use tirroi_core::roi::track::Tracker;
use tirroi_core::roi::wge::{Wge, WgeScratch};
use tirroi_core::roi::{Detector, Scratch};
use tirroi_core::{DetectError, Detection, Frame, Method, Roi};

/// The methods the demo runs on every frame, in the core's order.
pub const DEMO_METHODS: &[Method] = &Method::ALL;

/// The one scratch area of the demo: idle, or the scratch of the detector that ran
/// last. A fresh one is [`SharedScratch::Idle`], discriminant 0 and nothing else, so a
/// `static` of it is zero bytes in `.bss` (no initial values in flash). Switching to
/// another detector writes that detector's fresh scratch over the area (a memset:
/// every fresh scratch is all zero bytes, `auto`'s too since session 24, so no image of
/// one sits in flash). Detectors keep no state between calls, so a
/// fresh scratch gives the same box as a reused one (the flight report compares every
/// box with the host's `tirroi detect`).
// repr(u8): an explicit tag byte, 0 for `Idle`, so the idle area is all zero bytes
// (without it rustc may encode `Idle` in a niche of a scratch field, a non-zero byte
// that moves the whole 74 KB to `.data`).
#[allow(clippy::large_enum_variant)] // one area the size of the largest, on purpose
#[repr(u8)]
pub enum SharedScratch {
    /// No detector has run yet.
    Idle,
    /// [`Otsu`]'s scratch.
    Otsu(OtsuScratch),
    /// [`Adaptive`]'s scratch.
    Adaptive(AdaptiveScratch),
    /// [`Wge`]'s scratch.
    Wge(WgeScratch),
    /// [`Dog`]'s scratch.
    Dog(DogScratch),
    /// [`Auto`]'s scratch.
    Auto(AutoScratch),
    /// [`AutoV2`]'s scratch (48 792 B on x86-64: below DoG's, so the area, and the
    /// demo's RAM, keep DoG's size).
    AutoV2(AutoV2Scratch),
}

// `auto-v2` fits in the area DoG already needs: adding it costs no RAM.
const _: () = assert!(
    core::mem::size_of::<AutoV2Scratch>() <= core::mem::size_of::<DogScratch>(),
    "auto-v2's scratch would grow the shared area beyond DoG's"
);

/// The area switched to a fresh `auto-v2` scratch (see [`Detectors::run`]).
const FRESH_AUTO_V2: SharedScratch = SharedScratch::AutoV2(Scratch::new());

/// The `$Variant` scratch of a [`SharedScratch`] (`Some`), switching the area over to it
/// first when another detector used it last.
macro_rules! scratch_in {
    ($shared:expr, $Variant:ident) => {{
        let shared: &mut SharedScratch = $shared;
        if !matches!(shared, SharedScratch::$Variant(_)) {
            *shared = SharedScratch::$Variant(Scratch::new());
        }
        match shared {
            SharedScratch::$Variant(scratch) => Some(scratch),
            _ => None,
        }
    }};
}

/// The error of a scratch area that did not switch (never: [`scratch_in`] just did).
const NOT_SWITCHED: DetectError = DetectError::InvalidParameter {
    name: "scratch",
    expected: "the shared area switched to the detector",
};

/// The error of [`Detectors::track`] for a method that does not track.
const NOT_A_TRACKER: DetectError = DetectError::InvalidParameter {
    name: "method",
    expected: "a tracker: auto or auto-v2",
};

/// Runs detector `$params` in the `$Variant` of a [`SharedScratch`].
macro_rules! run_in {
    ($shared:expr, $Variant:ident, $params:expr, $frame:expr) => {{
        match scratch_in!($shared, $Variant) {
            Some(scratch) => Detector::detect(&$params, $frame, scratch),
            None => Err(NOT_SWITCHED),
        }
    }};
}

/// `auto-v2`'s scratch in the shared area, switched to a fresh `auto-v2` scratch first
/// when another detector used it last (`None` never: it just switched).
fn auto_v2_scratch(shared: &mut SharedScratch) -> Option<&mut AutoV2Scratch> {
    if !matches!(shared, SharedScratch::AutoV2(_)) {
        // From a constant (copied from flash), not built on the stack and moved as
        // `scratch_in!` does: LLVM turns the other detectors' fresh scratch into a
        // memset of the area, but built that way `auto-v2`'s put a 33 KB temporary in
        // this function's frame, on every detector's call (stack peak 9.3 -> 43 KB).
        // The constant is the whole area, 74 KB of flash, for 33 KB of RAM (peak 9.5 KB).
        *shared = FRESH_AUTO_V2;
    }
    match shared {
        SharedScratch::AutoV2(scratch) => Some(scratch),
        _ => None,
    }
}

/// Runs `auto-v2` with `params` in the shared area ([`auto_v2_scratch`]).
fn auto_v2_in(
    shared: &mut SharedScratch,
    params: AutoV2,
    frame: &Frame<'_>,
) -> Result<Detection, DetectError> {
    match auto_v2_scratch(shared) {
        Some(scratch) => Detector::detect(&params, frame, scratch),
        None => Err(NOT_SWITCHED),
    }
}

/// `auto-v2`'s sequence tracker ([`Detectors::sequence_step`]): idle until its first
/// step (tag 0 and nothing else, so the idle slot is zero bytes in `.bss`, as
/// [`SharedScratch`]), then the tracker's state (8 KiB: the ground's patches).
#[allow(clippy::large_enum_variant)] // one slot the size of the tracker, on purpose
#[repr(u8)]
pub enum TrackerSlot {
    /// No step yet.
    Idle,
    /// The tracker after its last step.
    Tracking(Tracker),
}

/// A fresh tracker with the default parameters, copied from flash on the first step
/// (not built on the stack: an 8 KiB temporary there).
const FRESH_TRACKER: TrackerSlot = TrackerSlot::Tracking(Tracker::new(AutoV2::DEFAULT));

impl TrackerSlot {
    /// The tracker, made fresh on first use (`None` never: it just did).
    fn tracker(&mut self) -> Option<&mut Tracker> {
        if matches!(self, TrackerSlot::Idle) {
            *self = FRESH_TRACKER;
        }
        match self {
            TrackerSlot::Tracking(tracker) => Some(tracker),
            TrackerSlot::Idle => None,
        }
    }
}

/// The detectors with their default parameters (what `tirroi detect` runs on the host,
/// so the boxes can be compared bit for bit), the one scratch area they share, and
/// `auto-v2`'s sequence tracker.
pub struct Detectors {
    shared: SharedScratch,
    tracker: TrackerSlot,
}

impl Detectors {
    /// An idle scratch area (a `const fn` of zero bytes: the whole struct can be a
    /// `static` in `.bss`).
    pub const fn new() -> Self {
        Detectors {
            shared: SharedScratch::Idle,
            tracker: TrackerSlot::Idle,
        }
    }

    /// Bytes of the shared scratch area (the largest detector's scratch and the tag).
    pub const fn scratch_bytes() -> usize {
        core::mem::size_of::<SharedScratch>()
    }

    /// Bytes of the sequence tracker's slot ([`TrackerSlot`]: its state and the tag).
    pub const fn tracker_bytes() -> usize {
        core::mem::size_of::<TrackerSlot>()
    }

    /// Runs `method` with its default parameters on `frame`.
    ///
    /// Never inlined: it is the unit the firmware counts instructions and stack in,
    /// and the function callgrind's `--toggle-collect` selects on the host.
    ///
    /// # Errors
    /// [`DetectError`] when the default parameters are refused (never, by the core's
    /// tests).
    #[inline(never)]
    pub fn run(&mut self, method: Method, frame: &Frame<'_>) -> Result<Detection, DetectError> {
        let shared = &mut self.shared;
        match method {
            Method::Otsu => run_in!(shared, Otsu, Otsu::default(), frame),
            Method::Adaptive => run_in!(shared, Adaptive, Adaptive::default(), frame),
            Method::Wge => run_in!(shared, Wge, Wge::default(), frame),
            Method::Dog => run_in!(shared, Dog, Dog::default(), frame),
            Method::Auto => run_in!(shared, Auto, Auto::default(), frame),
            Method::AutoV2 => auto_v2_in(shared, AutoV2::default(), frame),
        }
    }

    /// Runs a tracker, `auto` or `auto-v2` (default parameters), in tracking mode: a
    /// window around `prior` (the last frame's box) first, the whole frame only when
    /// the target is lost there. `look` (the last box's [`Look`] on the last frame;
    /// `auto-v2` only, `auto` ignores it) lets `auto-v2` take the fast path first
    /// ([`AutoV2::look`]).
    ///
    /// Never inlined, for the same reason as [`Detectors::run`].
    ///
    /// # Errors
    /// [`DetectError::InvalidParameter`] for a method that does not track (`method`).
    #[inline(never)]
    pub fn track(
        &mut self,
        method: Method,
        prior: Roi,
        look: Option<Look>,
        frame: &Frame<'_>,
    ) -> Result<Detection, DetectError> {
        match method {
            Method::Auto => {
                let params = Auto::default().with_prior(Some(prior));
                run_in!(&mut self.shared, Auto, params, frame)
            }
            Method::AutoV2 => auto_v2_in(
                &mut self.shared,
                AutoV2::default().with_prior(Some(prior)).with_look(look),
                frame,
            ),
            _ => Err(NOT_A_TRACKER),
        }
    }

    /// The next frame of the sequence for `auto-v2`'s tracker ([`Tracker::step`]:
    /// `auto-v2` with the last box and look, the ground's registration and the
    /// confirmation of a candidate under the gate; default parameters), in the shared
    /// area switched to `auto-v2`'s scratch. The tracker's own state, [`TrackerSlot`]
    /// ([`tirroi_core::roi::track::TRACKER_BYTES`]), is kept here between calls.
    ///
    /// Never inlined, for the same reason as [`Detectors::run`].
    ///
    /// # Errors
    /// [`Tracker::step`]'s (never with the default parameters).
    #[inline(never)]
    pub fn sequence_step(&mut self, frame: &Frame<'_>) -> Result<Detection, DetectError> {
        match (auto_v2_scratch(&mut self.shared), self.tracker.tracker()) {
            (Some(scratch), Some(tracker)) => tracker.step(frame, scratch),
            _ => Err(NOT_SWITCHED),
        }
    }

    /// Hands `auto-v2`'s sequence tracker a last box and its look, as if the last
    /// frame had given them (the worst-case run: a prior the next step refuses).
    pub fn set_sequence_prior(&mut self, prior: Option<Roi>, look: Option<Look>) {
        if let Some(tracker) = self.tracker.tracker() {
            tracker.set_prior(prior, look);
        }
    }

    /// Runs `auto` (tracking `prior` if given) within a work budget in Cortex-M7
    /// instructions ([`Auto::detect_within`]): its best box so far and where it stopped
    /// when the budget does not cover every stage.
    ///
    /// Never inlined, for the same reason as [`Detectors::run`].
    ///
    /// # Errors
    /// [`DetectError`] when the default parameters are refused (never).
    #[inline(never)]
    pub fn auto_within(
        &mut self,
        prior: Option<Roi>,
        frame: &Frame<'_>,
        budget: WorkBudget,
    ) -> Result<(Detection, BudgetReport), DetectError> {
        let params = Auto::default().with_prior(prior);
        match scratch_in!(&mut self.shared, Auto) {
            Some(scratch) => params.detect_within(frame, scratch, budget),
            None => Err(NOT_SWITCHED),
        }
    }
}

impl Detectors {
    /// Otsu's refinement passes (frame reads between its histogram and mask passes) in
    /// the last call, when Otsu ran last (`None` otherwise): what the worst-case run
    /// prints against the proven bound
    /// ([`tirroi_core::roi::otsu::max_refinement_passes`]).
    pub fn otsu_passes(&self) -> Option<u8> {
        match &self.shared {
            SharedScratch::Otsu(scratch) => Some(scratch.work().refinement_passes()),
            _ => None,
        }
    }
}

impl Default for Detectors {
    fn default() -> Self {
        Self::new()
    }
}
