//! Stages 5 and 6, refinement at full resolution: the gate (the winner's cells and
//! their neighbours), saturation counts, the outermost boundaries, and a saturated
//! target's box.

use super::super::Roi;
use super::super::plane::{BLOCK, Window};
use super::edges::{CellStats, EdgeComponents};
use super::noise::Noise;
use super::rules::{GATE_CELLS, SATURATED_TAU_FACTOR, TRIM_LINE_PX, TRIM_PASSES};
use crate::capacity::{ConstInit, FrameCapacity};
use crate::frame::Frame;

/// The refinement window: the winner's cell box grown by [`GATE_CELLS`], in frame
/// pixels (exclusive ends) and in cells of the plane (`ca..cb`, `ra..rb`).
#[derive(Debug, Clone, Copy)]
pub(super) struct Region {
    pub rx0: usize,
    pub ry0: usize,
    pub rx1: usize,
    pub ry1: usize,
    pub ca: usize,
    pub cb: usize,
    pub ra: usize,
    pub rb: usize,
}

impl Region {
    /// The region of the winner `c` of the plane of `win`.
    pub fn around(c: &CellStats, win: Window) -> Region {
        let cell_px = |cell: u8| usize::from(cell) * BLOCK;
        let rx0 = win.x0 + cell_px(c.x0.saturating_sub(GATE_CELLS));
        let ry0 = win.y0 + cell_px(c.y0.saturating_sub(GATE_CELLS));
        let end_px = |end: usize| (end + usize::from(GATE_CELLS)) * BLOCK;
        let rx1 = (win.x0 + end_px(c.x_end())).min(win.x0 + win.w);
        let ry1 = (win.y0 + end_px(c.y_end())).min(win.y0 + win.h);
        let (ca, cb) = ((rx0 - win.x0) / BLOCK, (rx1 - 1 - win.x0) / BLOCK + 1);
        let (ra, rb) = ((ry0 - win.y0) / BLOCK, (ry1 - 1 - win.y0) / BLOCK + 1);
        Region {
            rx0,
            ry0,
            rx1,
            ry1,
            ca,
            cb,
            ra,
            rb,
        }
    }
}

/// The gate, a view of the label plane once the labels are spent: per cell of the
/// window (`pw` per row), nonzero when the cell is the winner's or touches one of its
/// cells (over the region's cells only). Boundaries count only at gated pixels.
#[derive(Debug, Clone, Copy)]
pub(super) struct Gate<'a> {
    cells: &'a [u8],
    pw: usize,
    win: Window,
}

impl Gate<'_> {
    /// True when pixel `(x, y)` (frame coordinates, inside the region) is gated.
    #[inline(always)]
    pub fn contains(&self, x: usize, y: usize) -> bool {
        let i = y.wrapping_sub(self.win.y0) / BLOCK * self.pw + x.wrapping_sub(self.win.x0) / BLOCK;
        self.cells.get(i).is_some_and(|&g| g != 0)
    }

    /// Cells `ca..cb` of cell row `cy`.
    #[inline(always)]
    pub fn cells(&self, cy: usize, ca: usize, cb: usize) -> &[u8] {
        self.cells
            .get(cy * self.pw + ca..cy * self.pw + cb)
            .unwrap_or(&[])
    }
}

/// Builds the gate of the winner `root` over the region into `labels` (the label
/// plane, `pw × ph` cells; it becomes the gate), with `row_dilated` (the step-code
/// plane, free after labelling: the winner dilated along rows) and `winner_row` (one
/// cell row of the winner, padded by a cell on each side). Labels `1..next` are in use.
#[allow(clippy::too_many_arguments)]
pub(super) fn build_gate<'a>(
    labels: &'a mut [u8],
    row_dilated: &mut [u8],
    winner_row: &mut [bool],
    comps: &mut EdgeComponents,
    root: u8,
    next: usize,
    region: &Region,
    win: Window,
    (pw, ph): (usize, usize),
) -> Gate<'a> {
    // Every label to its root first (at most 250 finds), so the gate is
    // comparisons only: the winner's cells dilated by one cell, along rows into
    // `row_dilated`, then down columns into `labels` (which becomes the gate).
    comps.flatten(1..next, |l| l as u8);
    comps.set_parent(0, 0);
    let parent = comps.parents();
    let Region { ca, cb, ra, rb, .. } = *region;
    let (cwa, cwb) = (ca.saturating_sub(1), (cb + 1).min(pw));
    // The winner's cells of one cell row, padded by a cell on each side:
    // `winner[cx + 1]` is cell cx.
    let Some(winner) = winner_row.get_mut(..pw + 2) else {
        return Gate {
            cells: labels,
            pw,
            win,
        };
    };
    winner.fill(false);
    for cy in ra.saturating_sub(1)..(rb + 1).min(ph) {
        let cells = labels.get(cy * pw + cwa..cy * pw + cwb).unwrap_or(&[]);
        let padded = winner.get_mut(cwa + 1..cwb + 1).unwrap_or(&mut []);
        for (w, &l) in padded.iter_mut().zip(cells) {
            *w = parent[usize::from(l)] == root;
        }
        // Along the row: out[cx] = w[cx − 1] | w[cx] | w[cx + 1].
        let Some(out) = row_dilated.get_mut(cy * pw + ca..cy * pw + cb) else {
            continue;
        };
        let at = |r: core::ops::RangeFrom<usize>| winner.get(r).unwrap_or(&[]);
        let (left, mid, right) = (at(ca..), at(ca + 1..), at(ca + 2..));
        for (((o, &l), &m), &r) in out.iter_mut().zip(left).zip(mid).zip(right) {
            *o = u8::from(l | m | r);
        }
    }
    for cy in ra..rb {
        let row = |gy: usize| row_dilated.get(gy * pw + ca..gy * pw + cb).unwrap_or(&[]);
        let up = row(cy.saturating_sub(1));
        let down = row((cy + 1).min(ph.saturating_sub(1)));
        let Some(gated) = labels.get_mut(cy * pw + ca..cy * pw + cb) else {
            continue;
        };
        for (((g, &u), &m), &d) in gated.iter_mut().zip(up).zip(row(cy)).zip(down) {
            *g = u | m | d;
        }
    }
    Gate {
        cells: labels,
        pw,
        win,
    }
}

/// Saturated pixels of the gated cells of the region, per column and row.
pub(super) struct SaturationCounts<'a> {
    /// Saturated pixels per column of the region (`col_sat[i]`: column `rx0 + i`).
    pub col_sat: &'a [u16],
    /// Saturated pixels per row of the region.
    pub row_sat: &'a [u16],
    /// Saturated pixels in all.
    pub sat_px: u32,
    /// Pixels within the near-saturation band below the top DN, not saturated.
    pub near_px: u32,
}

/// Counts saturated pixels (and pixels at `near_sat` DN or above) over the gated
/// cells of the region, into `col_sat` and `row_sat` (region-sized slices).
pub(super) fn count_saturation<'a, C: FrameCapacity>(
    frame: &Frame<'_>,
    gate: &Gate<'_>,
    region: &Region,
    near_sat: u16,
    col_sat: &'a mut [u16],
    row_sat: &'a mut [u16],
) -> SaturationCounts<'a> {
    let max_dn = frame.max_dn();
    let win = gate.win;
    let Region {
        rx0,
        ry0,
        rx1,
        ry1,
        ca,
        cb,
        ..
    } = *region;
    // Saturation counts, over the gated cells.
    let (mut sat_px, mut near_px) = (0u32, 0u32);
    col_sat.fill(0);
    row_sat.fill(0);
    // Runs of gated cells of a cell row as pixel ranges relative to rx0 (set for
    // each cell row): the counts touch gated pixels only, a slice per run.
    let mut runs = <C::CellRuns<(u16, u16)> as ConstInit>::INIT;
    let runs = runs.as_mut();
    let (mut n_runs, mut runs_row) = (0, usize::MAX);
    for (y, rs) in (ry0..ry1).zip(row_sat.iter_mut()) {
        let Some(row) = frame.row(y).and_then(|r| r.get(rx0..rx1)) else {
            continue;
        };
        // Most rows of a radiometry frame hold no pixel near saturation (a max is
        // cheaper than the counts).
        if row.iter().fold(0, |m, &v| m.max(v)) < near_sat {
            continue;
        }
        let cy = (y - win.y0) / BLOCK;
        if cy != runs_row {
            runs_row = cy;
            n_runs = 0;
            let cells = gate.cells(cy, ca, cb);
            let mut open = None;
            for (i, &g) in cells.iter().chain(&[0]).enumerate() {
                match (open, g != 0) {
                    (None, true) => open = Some(i),
                    (Some(start), false) => {
                        let px = |c: usize| (c * BLOCK).min(row.len()) as u16;
                        if let Some(r) = runs.get_mut(n_runs) {
                            *r = (px(start), px(i));
                            n_runs += 1;
                        }
                        open = None;
                    }
                    _ => {}
                }
            }
        }
        // (v ≥ max_dn is v saturated; near_sat ≤ max_dn: no clamp needed.)
        let (mut sat_row, mut near) = (0u16, 0u16);
        for &(a, b) in runs.get(..n_runs).unwrap_or(&[]) {
            let (a, b) = (usize::from(a), usize::from(b));
            let (Some(px), Some(counts)) = (row.get(a..b), col_sat.get_mut(a..b)) else {
                continue;
            };
            for (&v, cs) in px.iter().zip(counts) {
                let sat = u16::from(v >= max_dn);
                *cs += sat;
                sat_row += sat;
                near += u16::from(v >= near_sat) & (1 - sat);
            }
        }
        let (sat_row, near) = (u32::from(sat_row), u32::from(near));
        *rs = sat_row as u16;
        sat_px += sat_row;
        near_px += near;
    }
    SaturationCounts {
        col_sat,
        row_sat,
        sat_px,
        near_px,
    }
}

/// The box of the outermost boundaries in the region (the saturated pixels' box,
/// joined with boundaries of unsaturated faces beyond it, for a `saturated` target)
/// and the boundary pixels found. `tau`: the boundary threshold, DN.
pub(super) fn outline(
    frame: &Frame<'_>,
    gate: &Gate<'_>,
    region: &Region,
    noise: Noise,
    tau: u16,
    saturated: bool,
    sat_counts: &SaturationCounts<'_>,
) -> (Option<Roi>, u32) {
    let max_dn = frame.max_dn();
    let fw = frame.width();
    let clean = noise.clean;
    let Region {
        rx0, ry0, rx1, ry1, ..
    } = *region;
    let (tau, keep_saturated) = if saturated {
        (tau.saturating_mul(SATURATED_TAU_FACTOR), false)
    } else {
        (tau, true)
    };
    let gated = |x: usize, y: usize| gate.contains(x, y);
    let clamp = |v: u16| v.min(max_dn);
    let rows = |y: usize| frame.row(y).and_then(|r| r.get(..fw));
    // A boundary at pixel x of row y from a horizontal step: `Some(b)` (a boundary
    // before column b) when |v(x+1) − v(x−1)| ≥ τ, no neighbouring step along the
    // row is larger, and the pixels are gated (and unsaturated, unless kept).
    // In clean deep space a faint face (a few hundred DN, below τ) still shows as a
    // solid patch above 0 DN, where the clipped noise is a sparse sprinkle: a step
    // from 0 DN counts when the pixel beyond it and its four neighbours are above 0.
    let solid = |x: usize, y: usize| {
        let at = |x: usize, y: usize| rows(y).and_then(|r| r.get(x)).is_some_and(|&v| v > 0);
        x > 0 && y > 0 && at(x, y) && at(x - 1, y) && at(x + 1, y) && at(x, y - 1) && at(x, y + 1)
    };
    let faint = |a: u16, b: u16, beyond: Option<(usize, usize)>| {
        clean && a.min(b) == 0 && a.max(b) > 0 && beyond.is_some_and(|(x, y)| solid(x, y))
    };
    let h_boundary = |row: &[u16], x: usize, y: usize| -> Option<usize> {
        if x == 0 || x + 1 >= fw {
            return None;
        }
        let (Some(&l), Some(&v), Some(&r)) = (row.get(x - 1), row.get(x), row.get(x + 1)) else {
            return None;
        };
        let (l, v, r) = (clamp(l), clamp(v), clamp(r));
        let step = l.abs_diff(r);
        let beyond = if l == 0 {
            Some((x + 1, y))
        } else {
            Some((x - 1, y))
        };
        if (step < tau && !faint(l, r, beyond))
            || !(keep_saturated || l.max(r) < max_dn)
            || !gated(x, y)
        {
            return None;
        }
        let before = x
            .checked_sub(2)
            .and_then(|i| row.get(i))
            .map_or(0, |&w| clamp(w).abs_diff(v));
        let after = row.get(x + 2).map_or(0, |&w| clamp(w).abs_diff(v));
        (step >= before && step >= after).then_some(if v.abs_diff(l) >= v.abs_diff(r) {
            x
        } else {
            x + 1
        })
    };
    // The same down a column: a boundary before row b.
    let v_boundary = |x: usize, y: usize| -> Option<usize> {
        let (Some(a), Some(v), Some(d)) = (y.checked_sub(1).and_then(rows), rows(y), rows(y + 1))
        else {
            return None;
        };
        let (Some(&u), Some(&v), Some(&d)) = (a.get(x), v.get(x), d.get(x)) else {
            return None;
        };
        let (u, v, d) = (clamp(u), clamp(v), clamp(d));
        let step = u.abs_diff(d);
        let beyond = if u == 0 {
            Some((x, y + 1))
        } else {
            Some((x, y - 1))
        };
        if (step < tau && !faint(u, d, beyond))
            || !(keep_saturated || u.max(d) < max_dn)
            || !gated(x, y)
        {
            return None;
        }
        let before = y
            .checked_sub(2)
            .and_then(rows)
            .map_or(0, |r| clamp(r[x]).abs_diff(v));
        let after = rows(y + 2).map_or(0, |r| clamp(r[x]).abs_diff(v));
        (step >= before && step >= after).then_some(if v.abs_diff(u) >= v.abs_diff(d) {
            y
        } else {
            y + 1
        })
    };
    // Outside in: the box needs only the outermost boundaries, so each row is
    // scanned from the left until its first boundary (or until it cannot beat the
    // leftmost one so far) and from the right alike; rows are scanned from the top
    // until one holds a boundary from a vertical step, and from the bottom alike.
    // A saturated target's box comes from its saturated pixels; boundaries of cold
    // faces matter only beyond it.
    let sat = if saturated {
        saturated_box(sat_counts.col_sat, rx0, sat_counts.row_sat, ry0)
    } else {
        None
    };
    let (lim_x0, lim_y0, lim_x1, lim_y1) = sat.map_or((rx1, ry1, rx0, ry0), |s| {
        (
            usize::from(s.x0),
            usize::from(s.y0),
            usize::from(s.x1),
            usize::from(s.y1),
        )
    });
    let mut found = Boundaries::NONE;
    // The cheap test of a pixel pair before the boundary tests: a step of τ between
    // the clamped values, or (clean deep space) 0 DN beside a pixel above it. Raw
    // values first: clamping never widens a step, and most pairs fail on it alone.
    let candidate = |l: u16, r: u16| {
        (l.abs_diff(r) >= tau && clamp(l).abs_diff(clamp(r)) >= tau)
            || (clean && l.min(r) == 0 && l.max(r) > 0)
    };
    // One row per cell band first (cheap bounds for the rest), then every row.
    let sparse = (ry0 + BLOCK / 2..ry1).step_by(BLOCK);
    for y in sparse.chain(ry0..ry1) {
        let Some(row) = rows(y) else { continue };
        // Pixels x of [xa, xb) with both neighbours in the frame, first to last (or
        // last to first): the first boundary found.
        let scan = |xa: usize, xb: usize, backwards: bool| {
            let (xa, xb) = (xa.max(1), xb.min(fw - 1));
            let triples = row.get(xa.wrapping_sub(1)..xb + 1).filter(|_| xa < xb)?;
            let mut hits = (xa..xb)
                .zip(triples.windows(3))
                .filter(|(_, t)| candidate(t[0], t[2]));
            if backwards {
                hits.rev().find_map(|(x, _)| h_boundary(row, x, y))
            } else {
                hits.find_map(|(x, _)| h_boundary(row, x, y))
            }
        };
        let left_end = lim_x0.min(rx1).min(found.bx.0.saturating_add(1));
        let left = scan(rx0, left_end, false);
        if let Some(b) = left {
            found.add_x(b, y);
        }
        let right_start = rx0.max(lim_x1).max(found.bx.1.saturating_sub(1));
        // The left scan tested the pixels before its end (or before its boundary b,
        // found at pixel b − 1 or b) without a boundary, so the right scan stops
        // there: each pixel of a row is tested once (the worst case the budget
        // charges), and the answer is the full backward scan's (which ends at the
        // left scan's pixel when nothing lies beyond it).
        let tested = left.map_or(left_end, |b| b.saturating_sub(1));
        if let Some(b) = scan(right_start.max(tested), rx1, true) {
            found.add_x(b, y);
        }
    }
    let vertical = |y: usize, found: &mut Boundaries| {
        let (Some(a), Some(d)) = (y.checked_sub(1).and_then(rows), rows(y + 1)) else {
            return false;
        };
        // Most rows hold no candidate: one pass that vectorises says so.
        let (Some(a), Some(d)) = (a.get(rx0..rx1), d.get(rx0..rx1)) else {
            return false;
        };
        // (Raw steps: clamping never widens one, so a row below τ raw is below τ.)
        let largest = a.iter().zip(d).fold(0, |m, (&u, &w)| m.max(u.abs_diff(w)));
        if largest < tau && !(clean && a.iter().zip(d).any(|(&u, &w)| (u == 0) != (w == 0))) {
            return false;
        }
        let mut hit = false;
        for (x, (&u, &w)) in (rx0..rx1).zip(a.iter().zip(d)) {
            if !candidate(u, w) {
                continue;
            }
            if let Some(b) = v_boundary(x, y) {
                found.add_y(x, b);
                hit = true;
            }
        }
        hit
    };
    // Rows the downward pass tested without a hit are not tested again upward.
    let mut untested = ry0;
    for y in ry0..ry1.min(lim_y0) {
        if vertical(y, &mut found) {
            break;
        }
        untested = y + 1;
    }
    for y in (ry0.max(lim_y1).max(untested)..ry1).rev() {
        if y < found.by.1 || vertical(y, &mut found) {
            break;
        }
    }
    let edge_px = found.count;
    let roi = match sat {
        Some(s) => Some(found.roi().map_or(s, |u| s.hull(&u))),
        None if saturated => None,
        None => found.roi(),
    };
    (roi, edge_px)
}

/// The outermost boundaries seen by the refinement, and the hull of their pixels.
#[derive(Debug, Clone, Copy)]
struct Boundaries {
    /// Boundaries between columns (from horizontal steps): smallest and largest.
    bx: (usize, usize),
    /// Boundaries between rows (from vertical steps): smallest and largest.
    by: (usize, usize),
    /// Hull of the step pixels: x range, y range (exclusive ends).
    hx: (usize, usize),
    hy: (usize, usize),
    count: u32,
}

impl Boundaries {
    const NONE: Boundaries = Boundaries {
        bx: (usize::MAX, 0),
        by: (usize::MAX, 0),
        hx: (usize::MAX, 0),
        hy: (usize::MAX, 0),
        count: 0,
    };

    fn pixel(&mut self, x: usize, y: usize) {
        self.hx = (self.hx.0.min(x), self.hx.1.max(x + 1));
        self.hy = (self.hy.0.min(y), self.hy.1.max(y + 1));
        self.count += 1;
    }

    /// A boundary before column `b`, seen on row `y`.
    fn add_x(&mut self, b: usize, y: usize) {
        self.bx = (self.bx.0.min(b), self.bx.1.max(b));
        self.pixel(b.saturating_sub(1), y);
    }

    /// A boundary before row `b`, seen in column `x`.
    fn add_y(&mut self, x: usize, b: usize) {
        self.by = (self.by.0.min(b), self.by.1.max(b));
        self.pixel(x, b.saturating_sub(1));
    }

    /// The box between the outermost boundaries (the step pixels' hull along an axis
    /// without two boundaries).
    fn roi(&self) -> Option<Roi> {
        if self.count == 0 {
            return None;
        }
        let (x0, x1) = if self.bx.0 < self.bx.1 {
            self.bx
        } else {
            self.hx
        };
        let (y0, y1) = if self.by.0 < self.by.1 {
            self.by
        } else {
            self.hy
        };
        Some(Roi::new(x0 as u16, y0 as u16, x1 as u16, y1 as u16))
    }
}

/// The box of the saturated pixels from their column and row counts (`col_sat[i]` is
/// column `x0 + i`), with outermost lines of at most [`TRIM_LINE_PX`] pixels trimmed
/// ([`TRIM_PASSES`] times per side at most): pixels less than half covered by a saturating target saturate
/// too, and stick out of the truth box one at a time.
pub(super) fn saturated_box(col_sat: &[u16], x0: usize, row_sat: &[u16], y0: usize) -> Option<Roi> {
    let span = |counts: &[u16]| {
        let first = counts.iter().position(|&c| c > 0)?;
        let last = counts.iter().rposition(|&c| c > 0)?;
        let (mut a, mut b) = (first, last + 1);
        let line = usize::from(TRIM_LINE_PX);
        for _ in 0..TRIM_PASSES {
            if b - a > line && counts.get(a).is_some_and(|&c| c <= TRIM_LINE_PX) {
                a += 1;
            }
            if b - a > line && counts.get(b - 1).is_some_and(|&c| c <= TRIM_LINE_PX) {
                b -= 1;
            }
        }
        Some((a, b))
    };
    let (xa, xb) = span(col_sat)?;
    let (ya, yb) = span(row_sat)?;
    Some(Roi::new(
        (x0 + xa) as u16,
        (y0 + ya) as u16,
        (x0 + xb) as u16,
        (y0 + yb) as u16,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sensor::rng::Xoshiro128pp;

    /// The outline as it was before session 33: the right scan over its whole range,
    /// the upward pass over every row, every step clamped before it is tested; the
    /// reference the faster scans must equal (box and boundary pixels).
    #[allow(clippy::too_many_arguments)]
    fn outline_scanning_twice(
        frame: &Frame<'_>,
        gate: &Gate<'_>,
        region: &Region,
        noise: Noise,
        tau: u16,
        saturated: bool,
        sat_counts: &SaturationCounts<'_>,
    ) -> (Option<Roi>, u32) {
        let max_dn = frame.max_dn();
        let fw = frame.width();
        let clean = noise.clean;
        let Region {
            rx0, ry0, rx1, ry1, ..
        } = *region;
        let (tau, keep_saturated) = if saturated {
            (tau.saturating_mul(SATURATED_TAU_FACTOR), false)
        } else {
            (tau, true)
        };
        let gated = |x: usize, y: usize| gate.contains(x, y);
        let clamp = |v: u16| v.min(max_dn);
        let rows = |y: usize| frame.row(y).and_then(|r| r.get(..fw));
        // A boundary at pixel x of row y from a horizontal step: `Some(b)` (a boundary
        // before column b) when |v(x+1) − v(x−1)| ≥ τ, no neighbouring step along the
        // row is larger, and the pixels are gated (and unsaturated, unless kept).
        // In clean deep space a faint face (a few hundred DN, below τ) still shows as a
        // solid patch above 0 DN, where the clipped noise is a sparse sprinkle: a step
        // from 0 DN counts when the pixel beyond it and its four neighbours are above 0.
        let solid = |x: usize, y: usize| {
            let at = |x: usize, y: usize| rows(y).and_then(|r| r.get(x)).is_some_and(|&v| v > 0);
            x > 0
                && y > 0
                && at(x, y)
                && at(x - 1, y)
                && at(x + 1, y)
                && at(x, y - 1)
                && at(x, y + 1)
        };
        let faint = |a: u16, b: u16, beyond: Option<(usize, usize)>| {
            clean && a.min(b) == 0 && a.max(b) > 0 && beyond.is_some_and(|(x, y)| solid(x, y))
        };
        let h_boundary = |row: &[u16], x: usize, y: usize| -> Option<usize> {
            if x == 0 || x + 1 >= fw {
                return None;
            }
            let (Some(&l), Some(&v), Some(&r)) = (row.get(x - 1), row.get(x), row.get(x + 1))
            else {
                return None;
            };
            let (l, v, r) = (clamp(l), clamp(v), clamp(r));
            let step = l.abs_diff(r);
            let beyond = if l == 0 {
                Some((x + 1, y))
            } else {
                Some((x - 1, y))
            };
            if (step < tau && !faint(l, r, beyond))
                || !(keep_saturated || l.max(r) < max_dn)
                || !gated(x, y)
            {
                return None;
            }
            let before = x
                .checked_sub(2)
                .and_then(|i| row.get(i))
                .map_or(0, |&w| clamp(w).abs_diff(v));
            let after = row.get(x + 2).map_or(0, |&w| clamp(w).abs_diff(v));
            (step >= before && step >= after).then_some(if v.abs_diff(l) >= v.abs_diff(r) {
                x
            } else {
                x + 1
            })
        };
        // The same down a column: a boundary before row b.
        let v_boundary = |x: usize, y: usize| -> Option<usize> {
            let (Some(a), Some(v), Some(d)) =
                (y.checked_sub(1).and_then(rows), rows(y), rows(y + 1))
            else {
                return None;
            };
            let (Some(&u), Some(&v), Some(&d)) = (a.get(x), v.get(x), d.get(x)) else {
                return None;
            };
            let (u, v, d) = (clamp(u), clamp(v), clamp(d));
            let step = u.abs_diff(d);
            let beyond = if u == 0 {
                Some((x, y + 1))
            } else {
                Some((x, y - 1))
            };
            if (step < tau && !faint(u, d, beyond))
                || !(keep_saturated || u.max(d) < max_dn)
                || !gated(x, y)
            {
                return None;
            }
            let before = y
                .checked_sub(2)
                .and_then(rows)
                .map_or(0, |r| clamp(r[x]).abs_diff(v));
            let after = rows(y + 2).map_or(0, |r| clamp(r[x]).abs_diff(v));
            (step >= before && step >= after).then_some(if v.abs_diff(u) >= v.abs_diff(d) {
                y
            } else {
                y + 1
            })
        };
        // Outside in: the box needs only the outermost boundaries, so each row is
        // scanned from the left until its first boundary (or until it cannot beat the
        // leftmost one so far) and from the right alike; rows are scanned from the top
        // until one holds a boundary from a vertical step, and from the bottom alike.
        // A saturated target's box comes from its saturated pixels; boundaries of cold
        // faces matter only beyond it.
        let sat = if saturated {
            saturated_box(sat_counts.col_sat, rx0, sat_counts.row_sat, ry0)
        } else {
            None
        };
        let (lim_x0, lim_y0, lim_x1, lim_y1) = sat.map_or((rx1, ry1, rx0, ry0), |s| {
            (
                usize::from(s.x0),
                usize::from(s.y0),
                usize::from(s.x1),
                usize::from(s.y1),
            )
        });
        let mut found = Boundaries::NONE;
        // The cheap test of a pixel pair (clamped) before the boundary tests: a step of
        // τ, or (clean deep space) 0 DN beside a pixel above it.
        let candidate =
            |l: u16, r: u16| l.abs_diff(r) >= tau || (clean && l.min(r) == 0 && l.max(r) > 0);
        // One row per cell band first (cheap bounds for the rest), then every row.
        let sparse = (ry0 + BLOCK / 2..ry1).step_by(BLOCK);
        for y in sparse.chain(ry0..ry1) {
            let Some(row) = rows(y) else { continue };
            // Pixels x of [xa, xb) with both neighbours in the frame, first to last (or
            // last to first): the first boundary found.
            let scan = |xa: usize, xb: usize, backwards: bool| {
                let (xa, xb) = (xa.max(1), xb.min(fw - 1));
                let triples = row.get(xa.wrapping_sub(1)..xb + 1).filter(|_| xa < xb)?;
                let mut hits = (xa..xb)
                    .zip(triples.windows(3))
                    .filter(|(_, t)| candidate(clamp(t[0]), clamp(t[2])));
                if backwards {
                    hits.rev().find_map(|(x, _)| h_boundary(row, x, y))
                } else {
                    hits.find_map(|(x, _)| h_boundary(row, x, y))
                }
            };
            let left_end = lim_x0.min(rx1).min(found.bx.0.saturating_add(1));
            if let Some(b) = scan(rx0, left_end, false) {
                found.add_x(b, y);
            }
            let right_start = rx0.max(lim_x1).max(found.bx.1.saturating_sub(1));
            if let Some(b) = scan(right_start, rx1, true) {
                found.add_x(b, y);
            }
        }
        let vertical = |y: usize, found: &mut Boundaries| {
            let (Some(a), Some(d)) = (y.checked_sub(1).and_then(rows), rows(y + 1)) else {
                return false;
            };
            // Most rows hold no candidate: one pass that vectorises says so.
            let (Some(a), Some(d)) = (a.get(rx0..rx1), d.get(rx0..rx1)) else {
                return false;
            };
            let largest = a
                .iter()
                .zip(d)
                .fold(0, |m, (&u, &w)| m.max(clamp(u).abs_diff(clamp(w))));
            if largest < tau && !(clean && a.iter().zip(d).any(|(&u, &w)| (u == 0) != (w == 0))) {
                return false;
            }
            let mut hit = false;
            for (x, (&u, &w)) in (rx0..rx1).zip(a.iter().zip(d)) {
                if !candidate(clamp(u), clamp(w)) {
                    continue;
                }
                if let Some(b) = v_boundary(x, y) {
                    found.add_y(x, b);
                    hit = true;
                }
            }
            hit
        };
        for y in ry0..ry1.min(lim_y0) {
            if vertical(y, &mut found) {
                break;
            }
        }
        for y in (ry0.max(lim_y1)..ry1).rev() {
            if y < found.by.1 || vertical(y, &mut found) {
                break;
            }
        }
        let edge_px = found.count;
        let roi = match sat {
            Some(s) => Some(found.roi().map_or(s, |u| s.hull(&u))),
            None if saturated => None,
            None => found.roi(),
        };
        (roi, edge_px)
    }

    /// Random frames of a few DN levels (0, mid, saturated, noise), random windows,
    /// gates, regions and thresholds, saturated or not, clean or not: the outline
    /// equals the reference that scans every pixel twice.
    #[test]
    fn outline_equals_scanning_twice() {
        let mut rng = Xoshiro128pp::seed_from_u64(33);
        let below = |n: u32, rng: &mut Xoshiro128pp| (rng.next_u32() % n) as usize;
        let (mut hits, mut boxes) = (0, 0);
        for _ in 0..3000 {
            let (w, h) = (8 + below(40, &mut rng), 8 + below(32, &mut rng));
            let max_dn = (1u16 << 14) - 1;
            let levels = [0, 0, 300, max_dn / 2, max_dn, max_dn];
            let blob = 1 + below(6, &mut rng);
            let mut pixels = [0u16; 48 * 40];
            let pixels = &mut pixels[..w * h];
            let base: [u16; 16] = core::array::from_fn(|_| levels[below(6, &mut rng)]);
            let noise_dn = [0, 0, 3, 400][below(4, &mut rng)] as u32;
            for (i, p) in pixels.iter_mut().enumerate() {
                let (x, y) = (i % w, i / w);
                let v = base[(x / blob + 4 * (y / blob)) % 16];
                let n = if noise_dn > 0 {
                    rng.next_u32() % noise_dn
                } else {
                    0
                };
                *p = (u32::from(v) + n).min(u32::from(max_dn)) as u16;
            }
            let frame = Frame::new(pixels, w, h, 14).unwrap();
            let win = Window {
                x0: below(3, &mut rng).min(w - 1),
                y0: below(3, &mut rng).min(h - 1),
                w: 0,
                h: 0,
            };
            let win = Window {
                w: w - win.x0 - below(3, &mut rng).min(w - win.x0 - 1),
                h: h - win.y0 - below(3, &mut rng).min(h - win.y0 - 1),
                ..win
            };
            let (pw, ph) = (win.w.div_ceil(BLOCK), win.h.div_ceil(BLOCK));
            let (ca, ra) = (below(pw as u32, &mut rng), below(ph as u32, &mut rng));
            let cb = ca + 1 + below((pw - ca) as u32, &mut rng);
            let rb = ra + 1 + below((ph - ra) as u32, &mut rng);
            let region = Region {
                rx0: win.x0 + ca * BLOCK,
                ry0: win.y0 + ra * BLOCK,
                rx1: (win.x0 + cb * BLOCK).min(win.x0 + win.w),
                ry1: (win.y0 + rb * BLOCK).min(win.y0 + win.h),
                ca,
                cb,
                ra,
                rb,
            };
            let mut cells = [0u8; 12 * 10];
            let share = below(4, &mut rng) as u32;
            for g in cells[..pw * ph].iter_mut() {
                *g = u8::from(rng.next_u32() % 4 <= share);
            }
            let gate = Gate {
                cells: &cells[..pw * ph],
                pw,
                win,
            };
            let (mut col_sat, mut row_sat) = ([0u16; 48], [0u16; 40]);
            let (rw, rh) = (region.rx1 - region.rx0, region.ry1 - region.ry0);
            for c in col_sat[..rw].iter_mut().chain(row_sat[..rh].iter_mut()) {
                *c = [0, 0, 1, 5][below(4, &mut rng)];
            }
            let counts = SaturationCounts {
                col_sat: &col_sat[..rw],
                row_sat: &row_sat[..rh],
                sat_px: 0,
                near_px: 0,
            };
            let noise = Noise {
                sigma: 1,
                clean: below(2, &mut rng) == 0,
            };
            let tau = [1, 50, 300, 5000][below(4, &mut rng)];
            let saturated = below(3, &mut rng) == 0;
            let got = outline(&frame, &gate, &region, noise, tau, saturated, &counts);
            let want =
                outline_scanning_twice(&frame, &gate, &region, noise, tau, saturated, &counts);
            assert_eq!(
                got, want,
                "{w}x{h} {region:?} tau {tau} saturated {saturated}"
            );
            hits += usize::from(got.1 > 0);
            boxes += usize::from(got.0.is_some());
        }
        // The draws reach both answers often.
        assert!(hits > 600 && boxes > 600 && boxes < 2900, "{hits} {boxes}");
    }
}
