//! Shared helpers for detectors that work on a downsampled plane of 4×4 cells
//! ([`super::dog`]: block means; [`super::auto`]: step codes): the plane's size, a
//! rectangular window of a frame and the `BLOCK × BLOCK` means of the window's
//! pixels.

use crate::frame::{FRAME_HEIGHT, FRAME_WIDTH, Frame};
use crate::roi::Roi;

/// Block side of the downsampled planes, in pixels.
pub const BLOCK: usize = 4;
/// Width of a full reference frame's plane of `BLOCK × BLOCK` cells (82 for 328 pixels): `dog`'s
/// block means and `auto`'s step codes.
pub const PLANE_WIDTH: usize = FRAME_WIDTH.div_ceil(BLOCK);
/// Height of a full reference frame's plane of cells (62 for 248 pixels).
pub const PLANE_HEIGHT: usize = FRAME_HEIGHT.div_ceil(BLOCK);

/// A rectangle of a frame in pixels: columns `x0..x0 + w`, rows `y0..y0 + h`.
///
/// Built with [`Window::full`] or [`Window::clipped`], so it always lies inside its
/// frame and is at least 1×1 pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Window {
    pub x0: usize,
    pub y0: usize,
    pub w: usize,
    pub h: usize,
}

impl Window {
    /// The whole frame.
    pub fn full(frame: &Frame<'_>) -> Window {
        Window {
            x0: 0,
            y0: 0,
            w: frame.width(),
            h: frame.height(),
        }
    }

    /// `[x0, x1) × [y0, y1)` cut to the frame; `None` when nothing is left.
    pub fn clipped(
        frame: &Frame<'_>,
        x0: usize,
        y0: usize,
        x1: usize,
        y1: usize,
    ) -> Option<Window> {
        let (x1, y1) = (x1.min(frame.width()), y1.min(frame.height()));
        (x0 < x1 && y0 < y1).then_some(Window {
            x0,
            y0,
            w: x1 - x0,
            h: y1 - y0,
        })
    }

    /// The window's part of frame row `y` (a frame row index; empty when outside).
    pub fn row<'a>(&self, frame: &Frame<'a>, y: usize) -> &'a [u16] {
        frame
            .row(y)
            .and_then(|r| r.get(self.x0..self.x0 + self.w))
            .unwrap_or(&[])
    }

    /// True when the window is the whole frame.
    pub fn is_full(&self, frame: &Frame<'_>) -> bool {
        self.x0 == 0 && self.y0 == 0 && self.w == frame.width() && self.h == frame.height()
    }

    /// A tracker's window: `prior` cut to the frame (`None` when nothing is left),
    /// grown by `margin(prior)` px on every side and cut to the frame again. Returns the
    /// cut prior and the window.
    pub fn around(
        frame: &Frame<'_>,
        prior: Roi,
        margin: impl FnOnce(Roi) -> usize,
    ) -> Option<(Roi, Window)> {
        let p = prior.clip(frame.width() as u16, frame.height() as u16);
        if p.is_empty() {
            return None;
        }
        let m = margin(p);
        let win = Window::clipped(
            frame,
            usize::from(p.x0).saturating_sub(m),
            usize::from(p.y0).saturating_sub(m),
            usize::from(p.x1) + m,
            usize::from(p.y1) + m,
        )?;
        Some((p, win))
    }

    /// Whether `r`, found in this tracking window, is still the tracked target: it
    /// overlaps `prior` and is not cut by the window (a side on the window's border is
    /// one on the frame's border, else the target left the window).
    pub fn keeps(&self, frame: &Frame<'_>, prior: &Roi, r: &Roi) -> bool {
        let (x0, y0) = (usize::from(r.x0), usize::from(r.y0));
        let (x1, y1) = (usize::from(r.x1), usize::from(r.y1));
        !r.intersection(prior).is_empty()
            && (x0 > self.x0 || self.x0 == 0)
            && (y0 > self.y0 || self.y0 == 0)
            && (x1 < self.x0 + self.w || x1 == frame.width())
            && (y1 < self.y0 + self.h || y1 == frame.height())
    }
}

/// Rounded means of the `BLOCK × BLOCK` blocks of `win` (partial blocks at the right
/// and bottom edges average the pixels they have), row-major into `out` with
/// `win.w.div_ceil(BLOCK)` means per row; DN above `max_dn` count as `max_dn`.
/// `row_sum` needs `win.w.div_ceil(BLOCK)` entries and `out` that times
/// `win.h.div_ceil(BLOCK)`; shorter buffers leave the means they cannot hold out.
/// Returns the plane's width and height.
pub(crate) fn block_means(
    frame: &Frame<'_>,
    win: Window,
    row_sum: &mut [u32],
    out: &mut [u16],
) -> (usize, usize) {
    let max_dn = frame.max_dn();
    let (w, h) = (win.w, win.h);
    let (pw, ph) = (w.div_ceil(BLOCK), h.div_ceil(BLOCK));
    let n = pw.min(row_sum.len());
    let row_sum = &mut row_sum[..n];
    for py in 0..ph {
        row_sum.fill(0);
        let rows = (h - py * BLOCK).min(BLOCK);
        for y in win.y0 + py * BLOCK..win.y0 + py * BLOCK + rows {
            let row = win.row(frame, y);
            let blocks = row.chunks_exact(BLOCK);
            let tail = blocks.remainder();
            for (acc, block) in row_sum.iter_mut().zip(blocks) {
                *acc += block.iter().map(|&v| u32::from(v.min(max_dn))).sum::<u32>();
            }
            if let Some(acc) = row_sum.get_mut(w / BLOCK) {
                *acc += tail.iter().map(|&v| u32::from(v.min(max_dn))).sum::<u32>();
            }
        }
        if let Some(out_row) = out.get_mut(py * pw..(py + 1) * pw) {
            for (px, (o, &s)) in out_row.iter_mut().zip(row_sum.iter()).enumerate() {
                let cols = (w - px * BLOCK).min(BLOCK);
                // ≥ 1 pixel per block (rows, cols ≥ 1); `max(1)` says so, so the
                // flight build has no division-by-zero branch.
                let n = ((rows * cols) as u32).max(1);
                *o = ((s + n / 2) / n) as u16;
            }
        }
    }
    (pw, ph)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The window around a prior against the rectangle worked out by hand, at the
    /// frame's edges too; `keeps` against each of its conditions.
    #[test]
    fn tracking_window_and_kept_box_by_hand() {
        let px = [0u16; FRAME_WIDTH * FRAME_HEIGHT];
        let frame = Frame::reference(&px).unwrap();
        // 20 px margin around (100, 80)-(140, 100): (80, 60)-(160, 120).
        let (p, w) = Window::around(&frame, Roi::new(100, 80, 140, 100), |_| 20).unwrap();
        assert_eq!(p, Roi::new(100, 80, 140, 100));
        assert_eq!((w.x0, w.y0, w.w, w.h), (80, 60, 80, 60));
        // The margin gets the prior cut to the frame; the window is cut too.
        let (p, w) = Window::around(&frame, Roi::new(320, 240, 400, 300), |p| {
            usize::from(p.width())
        })
        .unwrap();
        assert_eq!(p, Roi::new(320, 240, 328, 248));
        assert_eq!((w.x0, w.y0, w.w, w.h), (312, 232, 16, 16));
        // Nothing of the prior inside the frame: no window.
        assert!(Window::around(&frame, Roi::new(400, 300, 420, 320), |_| 20).is_none());
        assert!(Window::around(&frame, Roi::EMPTY, |_| 20).is_none());
        // Kept: overlaps the prior, no side on the window's border inside the frame.
        let (p, w) = Window::around(&frame, Roi::new(100, 80, 140, 100), |_| 20).unwrap();
        assert!(w.keeps(&frame, &p, &Roi::new(95, 75, 145, 105)));
        assert!(
            !w.keeps(&frame, &p, &Roi::new(150, 110, 155, 115)),
            "misses the prior"
        );
        assert!(
            !w.keeps(&frame, &p, &Roi::new(80, 75, 145, 105)),
            "on the left border"
        );
        assert!(
            !w.keeps(&frame, &p, &Roi::new(95, 75, 160, 105)),
            "on the right border"
        );
        assert!(
            !w.keeps(&frame, &p, &Roi::new(95, 60, 145, 105)),
            "on the top border"
        );
        assert!(
            !w.keeps(&frame, &p, &Roi::new(95, 75, 145, 120)),
            "on the bottom border"
        );
        // A window on the frame's edge: a side there is the frame's, kept.
        let (p, w) = Window::around(&frame, Roi::new(0, 0, 20, 20), |_| 10).unwrap();
        assert!(w.keeps(&frame, &p, &Roi::new(0, 0, 25, 25)));
    }
}
