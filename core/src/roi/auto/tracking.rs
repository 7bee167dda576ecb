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
        if let Some(p) = self.prior {
            let p = p.clip(frame.width() as u16, frame.height() as u16);
            if !p.is_empty() {
                let m = usize::from(self.margin_px)
                    + usize::from(p.width().max(p.height()))
                        / usize::from(self.margin_divisor.max(1));
                let win = Window::clipped(
                    frame,
                    usize::from(p.x0).saturating_sub(m),
                    usize::from(p.y0).saturating_sub(m),
                    usize::from(p.x1) + m,
                    usize::from(p.y1) + m,
                );
                if let Some(win) = win.filter(|w| !w.is_full(frame)) {
                    let found = self.locate(frame, work, win, ledger);
                    if ledger.is_stopped() {
                        return found.map_or(NO_DETECTION, detection);
                    }
                    if let Some(f) = found {
                        // Still the tracked target: the box overlaps the prior and is
                        // not cut by the window (a side on the window's border is one
                        // the frame's border, or the target left the window).
                        let (fw, fh) = (frame.width(), frame.height());
                        let kept = f.roi.is_some_and(|r| {
                            let (x0, y0) = (usize::from(r.x0), usize::from(r.y0));
                            let (x1, y1) = (usize::from(r.x1), usize::from(r.y1));
                            !r.intersection(&p).is_empty()
                                && (x0 > win.x0 || win.x0 == 0)
                                && (y0 > win.y0 || win.y0 == 0)
                                && (x1 < win.x0 + win.w || x1 == fw)
                                && (y1 < win.y0 + win.h || y1 == fh)
                        });
                        if kept {
                            return detection(f);
                        }
                        // The best box so far should the full pass not fit: the
                        // tracked target cut by the window (not a box beside it).
                        if f.roi.is_some_and(|r| !r.intersection(&p).is_empty()) {
                            tracked = Some(f);
                        }
                    }
                    ledger.tracking_done();
                }
            }
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
