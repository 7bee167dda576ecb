//! Every detector of the core with its scratch memory, behind one call per method: the
//! core's registry bank ([`tirroi_core::roi::Detectors`]) with default parameters.

use tirroi_core::roi::auto::Auto;
use tirroi_core::roi::{self, Params};
use tirroi_core::{DetectError, Detection, Frame, Method, Roi};

/// The methods the demo runs on every frame, in the core's order.
pub const DEMO_METHODS: &[Method] = &Method::ALL;

/// The detectors with their default parameters (what `tirroi detect` runs on the host,
/// so the boxes can be compared bit for bit) and each one's scratch memory.
pub struct Detectors {
    bank: roi::Detectors,
}

impl Detectors {
    /// Fresh scratch for every detector (a `const fn`: the whole struct can be a
    /// `static`).
    pub const fn new() -> Self {
        Detectors {
            bank: roi::Detectors::new(),
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
        self.bank.detect_default(method, frame)
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
        let params = Params::Auto(Auto::default().with_prior(Some(prior)));
        self.bank.detect(&params, frame)
    }
}

impl Default for Detectors {
    fn default() -> Self {
        Self::new()
    }
}
