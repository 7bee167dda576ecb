//! Running the core's detectors from the host, one reusable scratch per method.

use std::time::Instant;

use tirroi_core::capacity::{Cap640x512, Cap1024x768};
use tirroi_core::roi::auto::{Auto, AutoScratch, BudgetReport, WorkBudget};
use tirroi_core::roi::{Detectors, Params};
use tirroi_core::{BoxRule, DetectError, Detection, Frame, FrameCapacity, Method, Roi};

/// Every registered detector (the core's registry, [`Method::ALL`]) with its
/// parameters and its scratch memory, ready to run frame after frame: the 328×248
/// bank (boxed: about 141 KB) and, made on the first frame that needs them, the
/// 640×512 and 1024×768 banks; the smallest that holds a frame runs it.
pub struct DetectorBank {
    /// The parameters of each method but `auto`, at [`Method::index`].
    others: [Params; OTHERS],
    /// `auto`'s parameters, typed: budgeted calls need an [`Auto`] (no other variant of
    /// [`Params`] can stand in its place).
    auto: Auto,
    scratch: Box<Detectors>,
    scratch_640x512: Option<Box<Detectors<Cap640x512>>>,
    scratch_1024x768: Option<Box<Detectors<Cap1024x768>>>,
    /// `auto`'s scratch for budgeted calls (328×248), made on the first one.
    auto_budgeted: Option<Box<AutoScratch>>,
}

/// Methods other than `auto`: the registry puts `auto` last, so they are
/// `Method::ALL[..OTHERS]` at their own [`Method::index`].
const OTHERS: usize = Method::ALL.len() - 1;
const _: () = assert!(
    Method::Auto.index() == OTHERS,
    "auto is the registry's last method"
);

/// True when `frame` fits capacity `C`.
fn fits<C: FrameCapacity>(frame: &Frame<'_>) -> bool {
    frame.width() <= C::WIDTH && frame.height() <= C::HEIGHT
}

impl Default for DetectorBank {
    /// Every detector with its default parameters.
    fn default() -> Self {
        DetectorBank {
            others: core::array::from_fn(|i| Method::ALL[i].default_params()),
            auto: Auto::default(),
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
        // Only `auto`'s index (OTHERS) is past the end of `others`.
        self.others
            .get(method.index())
            .copied()
            .unwrap_or(Params::Auto(self.auto))
    }

    /// Sets the parameters of their method (the other methods keep theirs).
    pub fn set_params(&mut self, params: Params) {
        match params {
            Params::Auto(auto) => self.auto = auto,
            other => {
                if let Some(slot) = self.others.get_mut(other.method().index()) {
                    *slot = other;
                }
            }
        }
    }

    /// Sets `auto`'s tracking prior (the last frame's box; `None`: search the whole
    /// frame).
    pub fn set_prior(&mut self, prior: Option<Roi>) {
        self.auto.prior = prior;
    }

    /// Sets the mask-to-box rule of every detector (`auto` has none).
    pub fn set_box_rule(&mut self, rule: BoxRule) {
        for p in &mut self.others {
            p.set_box_rule(rule);
        }
    }

    /// Runs `method` on `frame`.
    ///
    /// # Errors
    /// The core's [`DetectError`] for parameters out of bounds or a frame above the
    /// largest capacity (1024×768).
    pub fn detect(&mut self, method: Method, frame: &Frame<'_>) -> Result<Detection, DetectError> {
        let params = &self.params(method);
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
        timed_median(repeat, || self.detect(method, frame))
    }
}

/// Runs `call` `repeat` times (at least once): its first result and the median wall
/// time of one call, in microseconds. Stops at the first error.
fn timed_median<T, E>(
    repeat: usize,
    mut call: impl FnMut() -> Result<T, E>,
) -> Result<(T, f64), E> {
    let mut times = Vec::with_capacity(repeat.max(1));
    let mut timed = || -> Result<T, E> {
        let start = Instant::now();
        let r = call()?;
        times.push(start.elapsed().as_secs_f64() * 1e6);
        Ok(r)
    };
    let first = timed()?;
    for _ in 1..repeat {
        timed()?;
    }
    Ok((first, median(&mut times)))
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
        let auto = self.auto;
        let scratch = self.auto_budgeted.get_or_insert_with(Box::default);
        let ((d, report), time_us) =
            timed_median(repeat, || auto.detect_within(frame, scratch, budget))?;
        Ok((d, report, time_us))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn params_round_trip_for_every_method_and_budgeted_auto_uses_the_prior() {
        let mut bank = DetectorBank::default();
        for method in Method::ALL {
            assert_eq!(bank.params(method), method.default_params(), "{method}");
            assert_eq!(bank.params(method).method(), method);
        }
        let prior = Roi::new(100, 80, 140, 120);
        bank.set_prior(Some(prior));
        let want = Auto::default().with_prior(Some(prior));
        assert_eq!(bank.params(Method::Auto), Params::Auto(want));
        // The other methods keep their defaults.
        for method in &Method::ALL[..OTHERS] {
            assert_eq!(bank.params(*method), method.default_params(), "{method}");
        }
        // A budgeted call runs the bank's `auto` (prior included): same answer as the
        // core called directly with those parameters.
        let px: Vec<u16> = (0..328 * 248)
            .map(|i| {
                if (i % 328) / 40 == 3 && (i / 328) / 40 == 2 {
                    9000
                } else {
                    3000
                }
            })
            .collect();
        let frame = Frame::new(&px, 328, 248, 14).expect("valid frame");
        let (got, report, _) = bank
            .auto_within_timed(&frame, WorkBudget::UNLIMITED, 1)
            .expect("default parameters");
        let (want_d, want_report) = want
            .detect_within(&frame, &mut AutoScratch::new(), WorkBudget::UNLIMITED)
            .expect("default parameters");
        assert_eq!(got, want_d);
        assert_eq!(report, want_report);
        bank.set_params(Params::Auto(Auto::default()));
        assert_eq!(bank.params(Method::Auto), Method::Auto.default_params());
    }
}
