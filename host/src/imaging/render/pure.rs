//! The pure (unmixed) pixels of a frame, which bound the radiometry auto range
//! (Eq. 17): where they lie and their scene signal. A camera ranges on what it
//! measures, so with optics or a sensor signature the range is taken over the same
//! pixels after them ([`PurePixels::measured_bounds`]): the camera's own shading and
//! offset are part of the signal its auto range sees. Without them the measured signal
//! is the scene's and the range is Eq. 17's exactly.

/// Share of the pure pixels trimmed at each end of the measured range, ‰: a camera's
/// auto range ignores its histogram's last bins, so the sensor's hot and dead pixels
/// (about 0.04 % of the frame for the Hayabusa2 TIR: 34 of 81 344) do not set it.
/// 1 ‰ is more than twice their share and keeps the range the faces' (a target's
/// coldest and hottest faces cover far more than 1 ‰ of its pixels).
pub const MEASURED_TAIL_PERMILLE: usize = 1;

/// The pure pixels of a frame: their indices (row-major) and the (min, max) of their
/// scene signal (the signal's unit: F in W m⁻² in radiometry).
#[derive(Debug, Default, Clone, PartialEq)]
pub struct PurePixels {
    px: Vec<u32>,
    lo: f32,
    hi: f32,
}

impl PurePixels {
    /// Adds pixel `index` (row-major) whose scene signal is `signal`.
    pub fn add(&mut self, index: usize, signal: f32) {
        if self.px.is_empty() {
            (self.lo, self.hi) = (signal, signal);
        } else {
            self.lo = self.lo.min(signal);
            self.hi = self.hi.max(signal);
        }
        // Frames are far below 2³² pixels (the camera's size is checked by the core).
        self.px.push(index as u32);
    }

    /// (min, max) of their scene signal (Eq. 17), `None` without a pure pixel.
    pub fn bounds(&self) -> Option<(f64, f64)> {
        (!self.px.is_empty()).then_some((f64::from(self.lo), f64::from(self.hi)))
    }

    /// (low, high) of the `measured` signal (the frame after the optics and the sensor
    /// signature, row-major) at the pure pixels, each end trimmed by
    /// [`MEASURED_TAIL_PERMILLE`]; `None` without a pure pixel inside `measured`.
    pub fn measured_bounds(&self, measured: &[f32]) -> Option<(f64, f64)> {
        let mut v: Vec<f32> = self
            .px
            .iter()
            .filter_map(|&i| measured.get(i as usize).copied())
            .filter(|s| s.is_finite())
            .collect();
        if v.is_empty() {
            return None;
        }
        let tail = v.len() * MEASURED_TAIL_PERMILLE / 1000;
        let last = v.len() - 1 - tail;
        let (_, &mut hi, _) = v.select_nth_unstable_by(last, f32::total_cmp);
        let (_, &mut lo, _) = v.select_nth_unstable_by(tail, f32::total_cmp);
        Some((f64::from(lo), f64::from(hi)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_bounds_are_the_min_and_max() {
        let mut p = PurePixels::default();
        assert_eq!(p.bounds(), None);
        for (i, s) in [3.0, -1.0, 7.5, 2.0].into_iter().enumerate() {
            p.add(i * 2, s);
        }
        assert_eq!(p.bounds(), Some((-1.0, 7.5)));
        // Read at the added pixels only (0, 2, 4, 6): the odd ones are not looked at.
        let measured = [1.0, -50.0, 2.0, 50.0, 3.0, 50.0, 4.0];
        assert_eq!(p.measured_bounds(&measured), Some((1.0, 4.0)));
    }

    #[test]
    fn measured_bounds_read_the_measured_frame_at_the_pure_pixels() {
        let mut p = PurePixels::default();
        p.add(1, 10.0);
        p.add(3, 20.0);
        // The measured frame: an offset of +5 at pixel 1, a gain of 2 at pixel 3; the
        // other pixels (mixed or not pure) are not looked at.
        let measured = [-100.0, 15.0, 1e9, 40.0];
        assert_eq!(p.measured_bounds(&measured), Some((15.0, 40.0)));
        // Without a signature the measured frame is the scene: Eq. 17's bounds.
        assert_eq!(p.measured_bounds(&[0.0, 10.0, 0.0, 20.0]), p.bounds());
        // An index past the frame is skipped, no panic.
        assert_eq!(p.measured_bounds(&[0.0, 10.0]), Some((10.0, 10.0)));
        assert_eq!(PurePixels::default().measured_bounds(&measured), None);
    }

    #[test]
    fn a_hot_pixel_among_many_pure_pixels_does_not_set_the_range() {
        // 4 000 pure pixels at 1.0..=2.0, one of them hot at 1 000: with 1 ‰ trimmed
        // per end (4 values) the hot pixel is dropped, against a brute-force sort.
        let mut p = PurePixels::default();
        let mut measured = Vec::new();
        for i in 0..4000 {
            let s = 1.0 + (i % 101) as f32 / 100.0;
            p.add(i, s);
            measured.push(if i == 1234 { 1000.0 } else { s });
        }
        let (lo, hi) = p.measured_bounds(&measured).expect("pure pixels");
        let mut sorted = measured.clone();
        sorted.sort_by(f32::total_cmp);
        assert_eq!((lo as f32, hi as f32), (sorted[4], sorted[4000 - 1 - 4]));
        assert!(hi <= 2.0 && lo >= 1.0);
    }
}
