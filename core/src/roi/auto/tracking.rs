//! Tracking: with a prior box, the pipeline runs first on a window around it (the
//! prior grown by `margin_px + max(width, height) / margin_divisor`); if nothing is
//! found there, or the box found misses the prior or reaches the window's border, on
//! the full frame.

use super::super::Detection;
use super::super::plane::Window;
use super::budget::Ledger;
use super::{Auto, AutoWork, Found};
use crate::capacity::FrameCapacity;
use crate::frame::Frame;

impl Auto {
    /// The detection (box, coarse threshold, edge pixels), tracking window first, each
    /// stage charged to `ledger` (a stop returns the best box so far: the tracking
    /// pass's box, else the full pass's coarse box, else none).
    pub(super) fn run<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoWork<C>,
        ledger: &mut Ledger,
    ) -> Detection {
        let full = Window::full(frame);
        let mut tracked = None;
        let around = self.prior.and_then(|prior| {
            Window::around(frame, prior, |p| {
                usize::from(self.margin_px)
                    + usize::from(p.width().max(p.height()))
                        / usize::from(self.margin_divisor.max(1))
            })
        });
        if let Some((p, win)) = around.filter(|(_, w)| !w.is_full(frame)) {
            let found = self.locate(frame, work, win, ledger);
            if ledger.is_stopped() {
                return found.map_or(NO_DETECTION, detection);
            }
            if let Some(f) = found {
                if f.roi.is_some_and(|r| win.keeps(frame, &p, &r)) {
                    return detection(f);
                }
                // The best box so far should the full pass not fit: the tracked
                // target cut by the window (not a box beside it).
                if f.roi.is_some_and(|r| !r.intersection(&p).is_empty()) {
                    tracked = Some(f);
                }
            }
            ledger.tracking_done();
        }
        let found = self.locate(frame, work, full, ledger);
        match (ledger.is_stopped(), tracked) {
            (true, Some(t)) => detection(t),
            _ => found.map_or(NO_DETECTION, detection),
        }
    }
}

/// No box.
const NO_DETECTION: Detection = Detection {
    roi: None,
    threshold: 0,
    foreground_px: 0,
    score_permille: 0,
};

fn detection(f: Found) -> Detection {
    Detection {
        roi: f.roi,
        threshold: f.threshold,
        foreground_px: f.edge_px,
        score_permille: Detection::certain_if_found(&f.roi),
    }
}
