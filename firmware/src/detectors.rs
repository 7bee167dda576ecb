//! Every detector of the core with its scratch memory, behind one call per method.

use tirroi_core::roi::adaptive::{Adaptive, AdaptiveScratch};
use tirroi_core::roi::auto::{Auto, AutoScratch};
use tirroi_core::roi::dog::{Dog, DogScratch};
use tirroi_core::roi::otsu::{Otsu, OtsuScratch};
use tirroi_core::roi::wge::{Wge, WgeScratch};
use tirroi_core::{DetectError, Detection, Detector, Frame, Method, Roi};

/// The methods the demo runs on every frame, in the core's order.
pub const DEMO_METHODS: &[Method] = &Method::ALL;

/// The detectors with their default parameters (what `tirroi detect` runs on the host,
/// so the boxes can be compared bit for bit) and each one's scratch memory.
pub struct Detectors {
    otsu: OtsuScratch,
    adaptive: AdaptiveScratch,
    wge: WgeScratch,
    dog: DogScratch,
    auto: AutoScratch,
}

impl Detectors {
    /// Fresh scratch for every detector (a `const fn`: the whole struct can be a
    /// `static`, in `.bss`).
    pub const fn new() -> Self {
        Detectors {
            otsu: OtsuScratch::new(),
            adaptive: AdaptiveScratch::new(),
            wge: WgeScratch::new(),
            dog: DogScratch::new(),
            auto: AutoScratch::new(),
        }
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
        match method {
            Method::Otsu => Otsu::default().detect(frame, &mut self.otsu),
            Method::Adaptive => Adaptive::default().detect(frame, &mut self.adaptive),
            Method::Wge => Wge::default().detect(frame, &mut self.wge),
            Method::Dog => Dog::default().detect(frame, &mut self.dog),
            Method::Auto => Auto::default().detect(frame, &mut self.auto),
        }
    }
}

impl Detectors {
    /// Runs `auto` in tracking mode: only a window around `prior` (the last frame's
    /// box) is processed, the whole frame only when the target is lost there.
    ///
    /// Never inlined, for the same reason as [`Detectors::run`].
    ///
    /// # Errors
    /// [`DetectError`] when the default parameters are refused (never).
    #[inline(never)]
    pub fn track(&mut self, prior: Roi, frame: &Frame<'_>) -> Result<Detection, DetectError> {
        Auto::default()
            .with_prior(Some(prior))
            .detect(frame, &mut self.auto)
    }
}

impl Default for Detectors {
    fn default() -> Self {
        Self::new()
    }
}
