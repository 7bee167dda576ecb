//! Running the core's detectors from the host, one reusable scratch per method.

use std::time::Instant;

use tirroi_core::capacity::{Cap640x512, Cap1024x768};
use tirroi_core::roi::auto::{AutoScratch, BudgetReport, WorkBudget};
use tirroi_core::roi::{Detectors, Params};
use tirroi_core::{BoxRule, DetectError, Detection, Frame, FrameCapacity, Method, Roi};

/// Every registered detector (the core's registry, [`Method::ALL`]) with its
/// parameters and its scratch memory, ready to run frame after frame: the 328×248
/// bank (boxed: about 141 KB) and, made on the first frame that needs them, the
/// 640×512 and 1024×768 banks; the smallest that holds a frame runs it.
pub struct DetectorBank {
    /// The parameters of each method, at [`Method::index`].
    params: [Params; Method::ALL.len()],
    scratch: Box<Detectors>,
    scratch_640x512: Option<Box<Detectors<Cap640x512>>>,
    scratch_1024x768: Option<Box<Detectors<Cap1024x768>>>,
    /// `auto`'s scratch for budgeted calls (328×248), made on the first one.
    auto_budgeted: Option<Box<AutoScratch>>,
}

/// True when `frame` fits capacity `C`.
fn fits<C: FrameCapacity>(frame: &Frame<'_>) -> bool {
    frame.width() <= C::WIDTH && frame.height() <= C::HEIGHT
}

impl Default for DetectorBank {
    /// Every detector with its default parameters.
    fn default() -> Self {
        DetectorBank {
            params: Method::ALL.map(Method::default_params),
            scratch: Box::new(Detectors::new()),
            scratch_640x512: None,
            scratch_1024x768: None,
            auto_budgeted: None,
        }
    }
}

impl DetectorBank {
    /// The parameters `method` runs with.
    pub fn params(&self, method: Method) -> Params {
        self.params[method.index()]
    }

    /// Sets the parameters of their method (the other methods keep theirs).
    pub fn set_params(&mut self, params: Params) {
        self.params[params.method().index()] = params;
    }

    /// Sets `auto`'s tracking prior (the last frame's box; `None`: search the whole
    /// frame).
    pub fn set_prior(&mut self, prior: Option<Roi>) {
        if let Params::Auto(auto) = &mut self.params[Method::Auto.index()] {
            auto.prior = prior;
        }
    }

    /// Sets the mask-to-box rule of every detector (`auto` has none).
    pub fn set_box_rule(&mut self, rule: BoxRule) {
        for p in &mut self.params {
            p.set_box_rule(rule);
        }
    }

    /// Runs `method` on `frame`.
    ///
    /// # Errors
    /// The core's [`DetectError`] for parameters out of bounds or a frame above the
    /// largest capacity (1024×768).
    pub fn detect(&mut self, method: Method, frame: &Frame<'_>) -> Result<Detection, DetectError> {
        let params = &self.params[method.index()];
        if fits::<tirroi_core::Reference>(frame) {
            self.scratch.detect(params, frame)
        } else if fits::<Cap640x512>(frame) {
            self.scratch_640x512
                .get_or_insert_with(Box::default)
                .detect(params, frame)
        } else {
            // Above 1024×768 the core answers `DetectError::FrameTooLarge`.
            self.scratch_1024x768
                .get_or_insert_with(Box::default)
                .detect(params, frame)
        }
    }

    /// Makes the scratch of the smallest capacity holding `frame`, if it is not there
    /// yet (outside the timed call: a 1024×768 bank is about 0.9 MB to clear).
    fn make_room(&mut self, frame: &Frame<'_>) {
        if fits::<tirroi_core::Reference>(frame) {
            return;
        }
        if fits::<Cap640x512>(frame) {
            self.scratch_640x512.get_or_insert_with(Box::default);
        } else {
            self.scratch_1024x768.get_or_insert_with(Box::default);
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
        self.make_room(frame);
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

impl DetectorBank {
    /// Runs `auto` (its parameters here, prior included) within `budget` Cortex-M7
    /// instructions (`Auto::detect_within`) `repeat` times (at least once): the
    /// detection, what it charged and where it stopped, and the median wall time of the
    /// core call alone, in microseconds.
    ///
    /// # Errors
    /// The core's [`DetectError`]: parameters out of bounds, or a frame above 328×248
    /// (budgeted calls run at the flight capacity only).
    pub fn auto_within_timed(
        &mut self,
        frame: &Frame<'_>,
        budget: WorkBudget,
        repeat: usize,
    ) -> Result<(Detection, BudgetReport, f64), DetectError> {
        let auto = match self.params[Method::Auto.index()] {
            Params::Auto(auto) => auto,
            _ => Default::default(),
        };
        let scratch = self.auto_budgeted.get_or_insert_with(Box::default);
        let mut times = Vec::with_capacity(repeat.max(1));
        let mut timed = || -> Result<(Detection, BudgetReport), DetectError> {
            let start = Instant::now();
            let r = auto.detect_within(frame, scratch, budget)?;
            times.push(start.elapsed().as_secs_f64() * 1e6);
            Ok(r)
        };
        let (d, report) = timed()?;
        for _ in 1..repeat {
            timed()?;
        }
        Ok((d, report, median(&mut times)))
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
