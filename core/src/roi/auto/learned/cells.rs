//! The plane of 8×8-pixel cells the classifier works on: per cell the mean DN, the
//! largest step over two pixels (as a log code of σ units), in one pass over the frame.

use super::super::super::plane::Window;
use crate::frame::Frame;

/// Cell side, pixels: two of the 4×4 cells of `auto`'s other planes, so a cell of this
/// plane maps onto 2×2 cells of the gate.
pub const CELL_PX: usize = 8;

/// Size of the cell plane of a window: `(⌈w/8⌉, ⌈h/8⌉)`.
pub fn cell_plane(win: Window) -> (usize, usize) {
    (win.w.div_ceil(CELL_PX), win.h.div_ceil(CELL_PX))
}

/// Per-cell sums filled by [`fill_cells`] (planes of `pw × ph` cells, row-major).
pub struct CellPlanes<'a> {
    /// Mean DN of the cell's pixels inside the window (clamped to the frame's top DN).
    pub mean_dn: &'a mut [u16],
    /// Largest |v(x+1) − v(x−1)| or |v(y+1) − v(y−1)| of the cell's pixels, as
    /// [`super::features::log_code`] of 4 · step / σ.
    pub step_code: &'a mut [u8],
}

/// Fills the cell planes of `win`. `sums` holds one cell row of running sums
/// (`pw` entries).
pub fn fill_cells(
    frame: &Frame<'_>,
    win: Window,
    sigma: u32,
    planes: CellPlanes<'_>,
    sums: &mut [u32],
    steps: &mut [u16],
) {
    let max_dn = frame.max_dn();
    let (pw, ph) = cell_plane(win);
    let sums = &mut sums[..pw];
    let steps = &mut steps[..pw];
    let (x0, w) = (win.x0, win.w);
    let fw = frame.width();
    let fh = frame.height();
    for cy in 0..ph {
        let ya = win.y0 + cy * CELL_PX;
        let yb = (ya + CELL_PX).min(win.y0 + win.h);
        sums.fill(0);
        let step_row = &mut *steps;
        step_row.fill(0);
        for y in ya..yb {
            let Some(row) = frame.row(y) else { continue };
            let row = &row[..fw];
            let up = frame.row(y.saturating_sub(1)).map(|r| &r[..fw]);
            let down = frame.row((y + 1).min(fh - 1)).map(|r| &r[..fw]);
            for (cx, (s, st)) in sums.iter_mut().zip(step_row.iter_mut()).enumerate() {
                let xa = x0 + cx * CELL_PX;
                let xb = (xa + CELL_PX).min(x0 + w);
                let mut acc = 0u32;
                let mut best = *st;
                for x in xa..xb {
                    let v = row[x].min(max_dn);
                    acc += u32::from(v);
                    let l = row[x.saturating_sub(1)].min(max_dn);
                    let r = row[(x + 1).min(fw - 1)].min(max_dn);
                    let h = l.abs_diff(r);
                    let vert = match (up, down) {
                        (Some(u), Some(d)) => u[x].min(max_dn).abs_diff(d[x].min(max_dn)),
                        _ => 0,
                    };
                    best = best.max(h).max(vert);
                }
                *s += acc;
                *st = best;
            }
        }
        for (code, &st) in planes.step_code[cy * pw..(cy + 1) * pw]
            .iter_mut()
            .zip(step_row.iter())
        {
            let q = u32::from(st) * 4 / sigma.max(1);
            *code = super::features::log_code(q).clamp(0, 255) as u8;
        }
        let rows = (yb - ya) as u32;
        for (cx, (m, &s)) in planes.mean_dn[cy * pw..(cy + 1) * pw]
            .iter_mut()
            .zip(sums.iter())
            .enumerate()
        {
            let xa = x0 + cx * CELL_PX;
            let cols = ((xa + CELL_PX).min(x0 + w) - xa) as u32;
            *m = (s / (rows * cols).max(1)) as u16;
        }
    }
}
