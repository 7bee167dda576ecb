//! Stage 3, candidates: edge cells (a step code at least the edge threshold)
//! labelled into 8-connected components with the shared union-find
//! ([`super::super::components`]), each with its cell box and summed steps; a frame
//! with more components than labels is labelled again with a higher threshold.

use super::super::components::{Components, Stats};
use super::rules::RELABEL_ATTEMPTS;
use super::steps::step_value;

/// Most edge components labelled per frame (labels 1..=250 of a `u8` plane); edge
/// cells that would start a further component are dropped (a frame that noisy has no
/// outline worth boxing; it is labelled again with a higher threshold). Unlike the
/// mask's table (components open at once, reused), this is a whole frame's count; it
/// does not grow with the capacity (a larger frame of that many components is as
/// noisy, and is labelled again the same way).
pub const MAX_EDGE_COMPONENTS: usize = 250;

/// Statistics of one component of edge cells (`auto`'s use of the shared labelling).
#[derive(Debug, Clone, Copy)]
pub(super) struct CellStats {
    /// Cell box, inclusive ends (the last cell, so `u8` holds planes of up to 256
    /// cells a side: 1024 pixels; every capacity meets it, [`crate::capacity`]).
    pub x0: u8,
    pub y0: u8,
    pub x_last: u8,
    pub y_last: u8,
    /// Edge cells (saturating: 49 152 cells at 1024×768 fit).
    pub area: u16,
    /// Sum of the cells' coarse gradients.
    pub energy: u32,
    /// Largest coarse gradient.
    pub gmax: u32,
}

impl crate::capacity::ConstInit for CellStats {
    /// All zero bytes, so a fresh `auto` scratch is all zeros (a `static` of it lands in
    /// `.bss`, and switching a shared scratch area to `auto` is a memset, with no image of
    /// it in flash). Never read as statistics: a label's entry is only read after
    /// `make_set(l, NO_CELLS)` handed it out in the current labelling.
    const INIT: Self = CellStats {
        x0: 0,
        y0: 0,
        x_last: 0,
        y_last: 0,
        area: 0,
        energy: 0,
        gmax: 0,
    };
}

impl CellStats {
    /// One past the last cell column.
    pub fn x_end(&self) -> usize {
        usize::from(self.x_last) + 1
    }

    /// One past the last cell row.
    pub fn y_end(&self) -> usize {
        usize::from(self.y_last) + 1
    }

    /// Sides of a `(pw, ph)` cell plane the cells' box touches, 0..=4.
    pub fn sides_touched(&self, (pw, ph): (usize, usize)) -> u8 {
        u8::from(self.x0 == 0)
            + u8::from(self.y0 == 0)
            + u8::from(self.x_end() >= pw)
            + u8::from(self.y_end() >= ph)
    }

    fn add(&mut self, x: u8, y: u8, q: u32) {
        self.x0 = self.x0.min(x);
        self.y0 = self.y0.min(y);
        self.x_last = self.x_last.max(x);
        self.y_last = self.y_last.max(y);
        self.area = self.area.saturating_add(1);
        self.energy = self.energy.saturating_add(q);
        self.gmax = self.gmax.max(q);
    }
}

impl Stats for CellStats {
    fn merge(&mut self, o: &CellStats) {
        self.x0 = self.x0.min(o.x0);
        self.y0 = self.y0.min(o.y0);
        self.x_last = self.x_last.max(o.x_last);
        self.y_last = self.y_last.max(o.y_last);
        self.area = self.area.saturating_add(o.area);
        self.energy = self.energy.saturating_add(o.energy);
        self.gmax = self.gmax.max(o.gmax);
    }
}

pub(super) const NO_CELLS: CellStats = CellStats {
    x0: u8::MAX,
    y0: u8::MAX,
    x_last: 0,
    y_last: 0,
    area: 0,
    energy: 0,
    gmax: 0,
};

/// The edge components of a frame: `u8` labels (0: not an edge cell); the parent table
/// spans all 256 `u8` values (no bounds checks), statistics only the labels handed out.
pub(super) type EdgeComponents =
    Components<u8, CellStats, [u8; 256], [CellStats; MAX_EDGE_COMPONENTS + 1]>;

/// Labels the edge cells of `step` (the step codes, `pw` per row) into `labels`,
/// first at `threshold`, then, while some edge cell finds no free label, at a
/// threshold `relabel_codes` codes higher, [`RELABEL_ATTEMPTS`] passes at most (no
/// cell below the first threshold's code is ever an edge cell). Returns one past the
/// last label used.
pub(super) fn label_edge_cells(
    step: &[u8],
    labels: &mut [u8],
    pw: usize,
    mut threshold: u8,
    relabel_codes: u8,
    comps: &mut EdgeComponents,
) -> usize {
    let mut next = None;
    for _ in 0..RELABEL_ATTEMPTS {
        next = label_edges(step, labels, pw, threshold, comps);
        if next.is_some() || threshold == u8::MAX {
            break;
        }
        threshold = threshold.saturating_add(relabel_codes);
    }
    next.unwrap_or(MAX_EDGE_COMPONENTS + 1)
}

/// Labels the cells whose `step` is at least `threshold` into 8-connected components
/// in `plane` (raster order, the shared union-find with statistics merged on union); other cells
/// get 0. Returns one past the last label used, or `None` when some edge cell found no
/// free label (it is left unlabelled).
fn label_edges(
    step: &[u8],
    plane: &mut [u8],
    pw: usize,
    threshold: u8,
    comps: &mut EdgeComponents,
) -> Option<usize> {
    let mut next = 1usize;
    let mut overflow = false;
    for (cy, steps) in step.chunks_exact(pw.max(1)).enumerate() {
        let Some((before, rest)) = plane.split_at_mut_checked(cy * pw) else {
            break;
        };
        let Some(cur) = rest.get_mut(..pw) else {
            break;
        };
        cur.fill(0);
        if steps.iter().all(|&q| q < threshold) {
            continue;
        }
        let prev = before.get(before.len().saturating_sub(pw)..).unwrap_or(&[]);
        let up = |cx: usize| prev.get(cx).copied().unwrap_or(0);
        for (cx, &q) in steps.iter().enumerate() {
            if q < threshold {
                continue;
            }
            let left = cx
                .checked_sub(1)
                .and_then(|i| cur.get(i))
                .copied()
                .unwrap_or(0);
            let up_left = if cx > 0 { up(cx - 1) } else { 0 };
            let mut l = 0u8;
            for m in [left, up_left, up(cx), up(cx + 1)] {
                if m == 0 {
                    continue;
                }
                let r = comps.find(m);
                if l == 0 {
                    l = r;
                } else if r != l {
                    l = comps.union(l, r);
                }
            }
            if l == 0 {
                if next > MAX_EDGE_COMPONENTS {
                    overflow = true;
                    continue;
                }
                l = next as u8;
                comps.make_set(l, NO_CELLS);
                next += 1;
            }
            if let Some(c) = cur.get_mut(cx) {
                *c = l;
            }
            if let Some(c) = comps.stats_mut(usize::from(l)) {
                c.add(cx as u8, cy as u8, step_value(q));
            }
        }
    }
    (!overflow).then_some(next)
}
