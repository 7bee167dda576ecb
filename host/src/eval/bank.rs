//! Running the core's detectors from the host, one reusable scratch per method.

use std::path::Path;
use std::time::Instant;

use tirroi_core::capacity::{Cap640x512, Cap1024x768};
use tirroi_core::roi::auto::learned::look::Look;
use tirroi_core::roi::auto::learned::{AutoV2, Stage};
use tirroi_core::roi::auto::{Auto, AutoScratch, BudgetReport, WorkBudget};
use tirroi_core::roi::track::Tracker;
use tirroi_core::roi::{Detectors, Params};
use tirroi_core::{BoxRule, DetectError, Detection, Frame, FrameCapacity, Method, Roi};

use crate::dataset::{MANIFEST_FILE, Manifest};
use crate::world::scene::SceneFile;

/// The methods that take a tracking prior (the last frame's box): `auto` and `auto-v2`
/// ([`DetectorBank::set_prior_of`]; `auto-v2` also a look, [`DetectorBank::set_look`]).
pub const TRACKERS: [Method; 2] = [Method::Auto, Method::AutoV2];

/// Every registered detector (the core's registry, [`Method::ALL`]) with its
/// parameters and its scratch memory, ready to run frame after frame: the 328×248
/// bank (boxed: about 190 KB) and, made on the first frame that needs them, the
/// 640×512 and 1024×768 banks; the smallest that holds a frame runs it.
pub struct DetectorBank {
    /// The parameters of each method at [`Method::index`]; `auto`'s slot is unused
    /// (its parameters are [`Self::auto`]).
    others: [Params; Method::ALL.len()],
    /// `auto`'s parameters, typed: budgeted calls need an [`Auto`] (no other variant of
    /// [`Params`] can stand in its place).
    auto: Auto,
    scratch: Box<Detectors>,
    scratch_640x512: Option<Box<Detectors<Cap640x512>>>,
    scratch_1024x768: Option<Box<Detectors<Cap1024x768>>>,
    /// `auto`'s scratch for budgeted calls (328×248), made on the first one.
    auto_budgeted: Option<Box<AutoScratch>>,
}

/// A fresh bank of capacity `C` on the heap. Never inlined, and called only when a
/// frame needs the bank: the by-value bank it builds before boxing (about 0.57 MB at
/// 640×512, 1.25 MB at 1024×768) then lives in this function's stack frame, once,
/// instead of in the frame of every [`DetectorBank::detect`] call, where both together
/// overflowed the 2 MiB stack of a rayon worker even for 328×248 frames.
#[inline(never)]
#[cold]
fn new_bank<C: FrameCapacity>() -> Box<Detectors<C>> {
    Box::new(Detectors::for_capacity())
}

/// True when `frame` fits capacity `C`.
fn fits<C: FrameCapacity>(frame: &Frame<'_>) -> bool {
    frame.width() <= C::WIDTH && frame.height() <= C::HEIGHT
}

impl Default for DetectorBank {
    /// Every detector with its default parameters.
    fn default() -> Self {
        DetectorBank {
            others: Method::ALL.map(Method::default_params),
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
        match method {
            Method::Auto => Params::Auto(self.auto),
            // `others` has a slot per method (`Method::index` < `Method::ALL.len()`).
            other => self
                .others
                .get(other.index())
                .copied()
                .unwrap_or_else(|| other.default_params()),
        }
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

    /// Sets the tracking prior of both trackers ([`TRACKERS`]: the last frame's box;
    /// `None`: search the whole frame).
    pub fn set_prior(&mut self, prior: Option<Roi>) {
        for m in TRACKERS {
            self.set_prior_of(m, prior);
        }
    }

    /// Sets the tracking prior of `method` when it tracks (`auto`, `auto-v2`); the
    /// other methods have none and are left as they are.
    pub fn set_prior_of(&mut self, method: Method, prior: Option<Roi>) {
        match method {
            Method::Auto => self.auto.prior = prior,
            Method::AutoV2 => {
                if let Some(Params::AutoV2(v2)) = self.others.get_mut(Method::AutoV2.index()) {
                    v2.prior = prior;
                }
            }
            _ => {}
        }
    }

    /// Sets the look of the tracked target on the last frame
    /// ([`tirroi_core::roi::auto::learned::look::Look`]), which only `auto-v2` carries
    /// ([`AutoV2::look`]: its fast tracking path).
    pub fn set_look(&mut self, look: Option<Look>) {
        if let Some(Params::AutoV2(v2)) = self.others.get_mut(Method::AutoV2.index()) {
            v2.look = look;
        }
    }

    /// Sets `auto-v2`'s saturated cut (`AutoV2::saturated_erode_px`, px per side): a
    /// property of the camera, the reach of its optics' blur (2 for a camera with the
    /// optics PSF, 0 without; [`saturated_erode_px_for_optics`]).
    pub fn set_saturated_erode_px(&mut self, px: u8) {
        if let Some(Params::AutoV2(v2)) = self.others.get_mut(Method::AutoV2.index()) {
            v2.saturated_erode_px = px;
        }
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
                .get_or_insert_with(new_bank)
                .detect(params, frame)
        } else {
            // Above 1024×768 the core answers `DetectError::FrameTooLarge`.
            self.scratch_1024x768
                .get_or_insert_with(new_bank)
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
            self.scratch_640x512.get_or_insert_with(new_bank);
        } else {
            self.scratch_1024x768.get_or_insert_with(new_bank);
        }
    }

    /// The next frame of `tracker`'s sequence ([`Tracker::step`]) with this bank's
    /// `auto-v2` parameters (the prior, look and candidate floor are the tracker's) in
    /// the bank's `auto-v2` scratch, `repeat` times (at least once) from the same
    /// tracker state: the detection, the median wall time of the step alone in
    /// microseconds; the tracker is left as after one step. A repeated step starts
    /// from a copy of the state (8 KiB: well under a microsecond, inside the timed
    /// call).
    ///
    /// # Errors
    /// As [`DetectorBank::detect`].
    pub fn track_timed(
        &mut self,
        tracker: &mut Tracker,
        frame: &Frame<'_>,
        repeat: usize,
    ) -> Result<(Detection, f64), DetectError> {
        if let Params::AutoV2(v2) = self.params(Method::AutoV2) {
            tracker.detector = v2;
        }
        self.make_room(frame);
        let start = tracker.clone();
        let mut after: Option<Tracker> = None;
        let timed = timed_median(repeat, || {
            let mut t = start.clone();
            let d = if fits::<tirroi_core::Reference>(frame) {
                t.step(frame, self.scratch.auto_v2())
            } else if fits::<Cap640x512>(frame) {
                t.step(
                    frame,
                    self.scratch_640x512.get_or_insert_with(new_bank).auto_v2(),
                )
            } else {
                t.step(
                    frame,
                    self.scratch_1024x768.get_or_insert_with(new_bank).auto_v2(),
                )
            }?;
            after.get_or_insert(t);
            Ok(d)
        })?;
        if let Some(t) = after {
            *tracker = t;
        }
        Ok(timed)
    }

    /// The stage of `auto-v2` that gave `answer`, the box of `method`'s last call on
    /// `frame` (`AutoV2Work::stage`, read from the scratch of the capacity that ran
    /// `frame`); `None` for the other methods, no box, or a capacity whose scratch was
    /// never used.
    pub fn stage(
        &mut self,
        method: Method,
        frame: &Frame<'_>,
        answer: Option<Roi>,
    ) -> Option<Stage> {
        if method != Method::AutoV2 {
            None
        } else if fits::<tirroi_core::Reference>(frame) {
            self.scratch.auto_v2().work().stage(answer)
        } else if fits::<Cap640x512>(frame) {
            self.scratch_640x512
                .as_mut()?
                .auto_v2()
                .work()
                .stage(answer)
        } else {
            self.scratch_1024x768
                .as_mut()?
                .auto_v2()
                .work()
                .stage(answer)
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

/// `auto-v2`'s saturated cut for a camera with (`true`) or without the optics PSF
/// (`[camera] optics_psf` of a scene file), px per side: the default
/// ([`AutoV2::default`], chosen for the flight camera with its optics' blur) with
/// optics, 0 without (no blur to cut back: the `paper` world, the fixtures).
pub fn saturated_erode_px_for_optics(optics_psf: bool) -> u8 {
    if optics_psf {
        AutoV2::default().saturated_erode_px
    } else {
        0
    }
}

/// `auto-v2`'s saturated cut for the frames of the dataset directory `dir`, px per
/// side: [`saturated_erode_px_for_optics`] of its run manifest's (`tirroi-run.json`)
/// scene `[camera] optics_psf`; 0 when `dir` has no manifest (frames not rendered by
/// `tirroi render`: the fixtures, the test sets' composites, files from elsewhere).
///
/// # Errors
/// One line naming the manifest when it exists but cannot be read, or its scene
/// cannot be parsed.
pub fn saturated_erode_px_of_dataset(dir: &Path) -> Result<u8, String> {
    let Some(manifest) = Manifest::read(dir).map_err(|e| e.to_string())? else {
        return Ok(saturated_erode_px_for_optics(false));
    };
    let source = dir.join(MANIFEST_FILE).display().to_string();
    let scene = SceneFile::parse(&manifest.scene, &source).map_err(|e| e.to_string())?;
    Ok(saturated_erode_px_for_optics(scene.camera.optics_psf))
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

    /// Every method runs on a 328×248 frame, and the 640×512 bank is made, inside the
    /// 2 MiB stack of a rayon worker (rayon's default; `tirroi eval` scores on them).
    /// With the larger banks built inline, `detect`'s own frame outgrew it in release
    /// builds once `auto-v2` joined the registry: every `tirroi eval` aborted with a
    /// stack overflow (a debug build calls `Box::default` out of line, so this test
    /// guards the contract there; the release binary was checked by hand).
    #[test]
    fn detect_runs_in_a_rayon_workers_stack() {
        const RAYON_DEFAULT_STACK_BYTES: usize = 2 << 20;
        let worker = std::thread::Builder::new()
            .stack_size(RAYON_DEFAULT_STACK_BYTES)
            .spawn(|| {
                let mut bank = DetectorBank::default();
                let px: Vec<u16> = (0..328 * 248).map(|i| (i % 97) as u16 * 40).collect();
                let frame = Frame::new(&px, 328, 248, 14).expect("valid frame");
                for method in Method::ALL {
                    bank.detect_timed(method, &frame, 1).expect("runs");
                }
                let px: Vec<u16> = vec![100; 640 * 512];
                let frame = Frame::new(&px, 640, 512, 14).expect("valid frame");
                bank.detect(Method::Otsu, &frame).expect("runs");
            })
            .expect("thread starts");
        assert!(worker.join().is_ok(), "a detector call overflowed 2 MiB");
    }

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
        assert_eq!(
            bank.params(Method::AutoV2),
            Params::AutoV2(AutoV2::default().with_prior(Some(prior)))
        );
        // The other methods keep their defaults.
        for method in Method::ALL.iter().filter(|m| !TRACKERS.contains(m)) {
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

    /// `eval`'s saturated cut comes from the dataset's camera: the `realistic` preset
    /// (optics PSF on) gives the flight default, `paper` (off) and a directory without a
    /// manifest 0, a broken manifest an error naming it; the bank then runs `auto-v2`
    /// with it and leaves every other method as it was.
    #[test]
    fn saturated_cut_follows_the_manifest_camera() {
        use crate::dataset::{Outputs, RunSource};
        let tmp = std::env::temp_dir().join(format!("tirroi-bank-erode-{}", std::process::id()));
        std::fs::create_dir_all(&tmp).expect("temp dir");
        let dir = tmp.as_path();
        assert_eq!(saturated_erode_px_of_dataset(dir), Ok(0));
        for (preset, optics) in [("realistic", true), ("paper", false)] {
            let file = SceneFile::preset(preset).expect("built-in preset");
            assert_eq!(file.camera.optics_psf, optics, "{preset}");
            let outputs = Outputs {
                masks: false,
                preview: false,
            };
            Manifest::new(RunSource::Preset(preset.into()), &file, outputs, None)
                .expect("manifest")
                .write(dir)
                .expect("written");
            let want = if optics {
                AutoV2::default().saturated_erode_px
            } else {
                0
            };
            assert_eq!(saturated_erode_px_of_dataset(dir), Ok(want), "{preset}");
        }
        assert_eq!(AutoV2::default().saturated_erode_px, 2);
        std::fs::write(dir.join(MANIFEST_FILE), "{").expect("written");
        let err = saturated_erode_px_of_dataset(dir).expect_err("broken manifest");
        assert!(err.contains(MANIFEST_FILE), "{err}");
        std::fs::remove_dir_all(dir).expect("temp dir removed");
        let mut bank = DetectorBank::default();
        bank.set_saturated_erode_px(0);
        let want = AutoV2 {
            saturated_erode_px: 0,
            ..AutoV2::default()
        };
        assert_eq!(bank.params(Method::AutoV2), Params::AutoV2(want));
        for method in Method::ALL.into_iter().filter(|m| *m != Method::AutoV2) {
            assert_eq!(bank.params(method), method.default_params(), "{method}");
        }
    }
}
