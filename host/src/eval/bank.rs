//! Running the core's detectors from the host, one reusable scratch per method.

use std::time::Instant;

use tirroi_core::capacity::{Cap640x512, Cap1024x768};
use tirroi_core::roi::adaptive::{Adaptive, AdaptiveScratch};
use tirroi_core::roi::auto::{Auto, AutoScratch};
use tirroi_core::roi::dog::{Dog, DogScratch};
use tirroi_core::roi::otsu::{Otsu, OtsuScratch};
use tirroi_core::roi::wge::{Wge, WgeScratch};
use tirroi_core::roi::{Detectors, Params};
use tirroi_core::{BoxRule, DetectError, Detection, Detector, Frame, FrameCapacity, Method};

/// The five detectors with their parameters and their scratch memory (boxed: DoG's
/// is 70 KiB), ready to run frame after frame.
#[derive(Default)]
pub struct DetectorBank {
    /// Otsu parameters.
    pub otsu: Otsu,
    /// Adaptive-threshold parameters.
    pub adaptive: Adaptive,
    /// WGE parameters.
    pub wge: Wge,
    /// DoG parameters.
    pub dog: Dog,
    /// `auto` parameters (its `prior` is used as given: set it for tracking).
    pub auto: Auto,
    otsu_scratch: Box<OtsuScratch>,
    adaptive_scratch: Box<AdaptiveScratch>,
    wge_scratch: Box<WgeScratch>,
    dog_scratch: Box<DogScratch>,
    auto_scratch: Box<AutoScratch>,
    /// Scratch of the larger capacities, made on the first frame that needs them.
    larger: LargerBanks,
}

/// The core's registry banks of the capacities above the reference 328×248: the
/// smallest that holds a frame runs it.
#[derive(Default)]
struct LargerBanks {
    c640x512: Option<Box<Detectors<Cap640x512>>>,
    c1024x768: Option<Box<Detectors<Cap1024x768>>>,
}

/// True when `frame` fits capacity `C`.
fn fits<C: FrameCapacity>(frame: &Frame<'_>) -> bool {
    frame.width() <= C::WIDTH && frame.height() <= C::HEIGHT
}

impl DetectorBank {
    /// Sets the mask-to-box rule of every detector (`auto` has none).
    pub fn set_box_rule(&mut self, rule: BoxRule) {
        self.otsu.box_rule = rule;
        self.adaptive.box_rule = rule;
        self.wge.box_rule = rule;
        self.dog.box_rule = rule;
    }

    /// Runs `method` on `frame`.
    ///
    /// # Errors
    /// The core's [`DetectError`] for parameters out of bounds or a frame above the
    /// largest capacity (1024×768).
    pub fn detect(&mut self, method: Method, frame: &Frame<'_>) -> Result<Detection, DetectError> {
        if !fits::<tirroi_core::Reference>(frame) {
            let params = match method {
                Method::Otsu => Params::Otsu(self.otsu),
                Method::Adaptive => Params::Adaptive(self.adaptive),
                Method::Wge => Params::Wge(self.wge),
                Method::Dog => Params::Dog(self.dog),
                Method::Auto => Params::Auto(self.auto),
            };
            let larger = &mut self.larger;
            return if fits::<Cap640x512>(frame) {
                larger
                    .c640x512
                    .get_or_insert_with(Box::default)
                    .detect(&params, frame)
            } else {
                larger
                    .c1024x768
                    .get_or_insert_with(Box::default)
                    .detect(&params, frame)
            };
        }
        match method {
            Method::Otsu => self.otsu.detect(frame, &mut self.otsu_scratch),
            Method::Adaptive => self.adaptive.detect(frame, &mut self.adaptive_scratch),
            Method::Wge => self.wge.detect(frame, &mut self.wge_scratch),
            Method::Dog => self.dog.detect(frame, &mut self.dog_scratch),
            Method::Auto => self.auto.detect(frame, &mut self.auto_scratch),
        }
    }

    /// Runs `method` `repeat` times (at least once) and returns the detection with the
    /// median wall time of the core call alone, in microseconds.
    ///
    /// # Errors
    /// As [`DetectorBank::detect`].
    pub fn detect_timed(
        &mut self,
        method: Method,
        frame: &Frame<'_>,
        repeat: usize,
    ) -> Result<(Detection, f64), DetectError> {
        let mut times = Vec::with_capacity(repeat.max(1));
        let mut timed = || -> Result<Detection, DetectError> {
            let start = Instant::now();
            let d = self.detect(method, frame)?;
            times.push(start.elapsed().as_secs_f64() * 1e6);
            Ok(d)
        };
        let detection = timed()?;
        for _ in 1..repeat {
            timed()?;
        }
        Ok((detection, median(&mut times)))
    }
}

/// Median of `values` (mean of the two middle ones for an even count; 0 when empty).
pub fn median(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}
