//! From a foreground mask, streamed row by row, to one box ([`BoxRule`]).
//!
//! The largest-component rule labels 8-connected components with a one-pass,
//! run-length union-find that only remembers the previous row: the runs of the
//! previous and the current row, and a table of the components they touch. A
//! component that no run of the current row continues is complete; it is compared
//! with the best so far and its table entry is freed. Memory is therefore bounded by
//! the number of runs a row can hold (`⌈W/2⌉` for a capacity `W` pixels wide: 164 on a
//! 328-pixel row), not by the frame.
//!
//! Bounds (capacity `W × H`, both below 65 535 by [`crate::capacity`]): run ends `≤ W`
//! and component labels `< 2·⌈W/2⌉` fit `u16`, and so do row stamps `< H`; a
//! component's area and its first pixel's raster index `y·width + x` are below
//! `W·H ≤ 1024 · 768`, far inside `u32`.

use super::components::{Components, Label, Stats};
use super::{BoxRule, Roi};
use crate::capacity::{ConstInit, FrameCapacity, Reference};

/// A component label of the run table (`u16`; [`FREE`] marks a free entry). A fresh
/// table holds zeros (so a builder in a `static` is all zero bytes and lands in `.bss`,
/// with no initial values in flash); [`RoiBuilder::start`] frees every entry before
/// its first frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct RunLabel(u16);

impl Label for RunLabel {
    #[inline(always)]
    fn index(self) -> usize {
        usize::from(self.0)
    }
}

impl ConstInit for RunLabel {
    /// Zero bytes: not yet a free entry ([`RoiBuilder::start`] frees it).
    const INIT: Self = RunLabel(0);
}

/// Marks a free component-table entry (as its parent, outside the table).
const FREE: RunLabel = RunLabel(u16::MAX);

/// A horizontal run of foreground pixels `[x0, x1)` and its component label.
#[derive(Debug, Clone, Copy)]
struct Run {
    x0: u16,
    x1: u16,
    label: RunLabel,
}

impl ConstInit for Run {
    /// Zero bytes: runs are only read below the row's run count, after being written.
    const INIT: Self = Run {
        x0: 0,
        x1: 0,
        label: RunLabel(0),
    };
}

/// Statistics of one (partial) component of foreground pixels.
#[derive(Debug, Clone, Copy)]
struct RunStats {
    /// Bounding box so far.
    roi: Roi,
    /// Pixels so far.
    area: u32,
    /// Raster index `y·width + x` of the first pixel (the tie-breaker).
    first: u32,
}

const NO_PIXELS: RunStats = RunStats {
    roi: Roi::EMPTY,
    area: 0,
    first: u32::MAX,
};

impl ConstInit for RunStats {
    /// Zero bytes: replaced by [`NO_PIXELS`] when [`RoiBuilder::start`] frees the entry.
    const INIT: Self = RunStats {
        roi: Roi::EMPTY,
        area: 0,
        first: 0,
    };
}

impl RunStats {
    /// True when `self` beats `other` (no component yet: `None`) as the largest
    /// component.
    fn beats(&self, other: Option<&RunStats>) -> bool {
        let other = other.unwrap_or(&NO_PIXELS);
        self.area > other.area || (self.area == other.area && self.first < other.first)
    }
}

impl Stats for RunStats {
    fn merge(&mut self, other: &RunStats) {
        self.roi = self.roi.hull(&other.roi);
        self.area += other.area;
        self.first = self.first.min(other.first);
    }
}

/// The open components of capacity `C`: `u16` labels, one entry per open component
/// (those of the previous row plus new ones of this row, at most `⌈W/2⌉` each).
type RunComponents<C> = Components<
    RunLabel,
    RunStats,
    <C as FrameCapacity>::OpenComponents<RunLabel>,
    <C as FrameCapacity>::OpenComponents<RunStats>,
>;

/// Turns a foreground mask, pushed one row at a time, into a box and a pixel count,
/// for frames up to capacity `C` (default: the reference 328×248).
///
/// Memory: about 8.5 KiB at 328×248, linear in the capacity's width; part of every
/// detector's [`super::Scratch`].
#[derive(Debug, Clone)]
pub struct RoiBuilder<C: FrameCapacity = Reference> {
    rule: BoxRule,
    width: usize,
    /// Row expected next; rows must come in order.
    next_row: usize,
    foreground_px: u32,
    /// [`BoxRule::AllForeground`]: the hull of all foreground pixels.
    hull: Roi,
    /// The runs of the previous and of the current row, alternately (`cur_side`
    /// says which is current, so finishing a row swaps an index, not the arrays).
    runs: [C::Runs<Run>; 2],
    cur_side: usize,
    prev_len: usize,
    cur_len: usize,
    /// The open components (union-find; a free entry's parent is [`FREE`]).
    table: RunComponents<C>,
    /// Per table entry: the last row in which a run of the component was seen.
    seen_row: C::OpenComponents<u16>,
    /// One past the highest table entry in use.
    table_high: usize,
    /// The largest complete component so far.
    best: Option<RunStats>,
    /// False until the first [`RoiBuilder::start`] has freed the whole table (a fresh
    /// builder is all zeros, see [`RunLabel`]).
    cleared: bool,
}

impl<C: FrameCapacity> Default for RoiBuilder<C> {
    fn default() -> Self {
        Self::for_capacity()
    }
}

impl RoiBuilder {
    /// An idle builder of the reference capacity, 328×248 (call
    /// [`RoiBuilder::start`] before pushing rows).
    pub const fn new() -> Self {
        Self::for_capacity()
    }
}

impl<C: FrameCapacity> RoiBuilder<C> {
    /// An idle builder of capacity `C` (call [`RoiBuilder::start`] before pushing rows).
    pub const fn for_capacity() -> Self {
        RoiBuilder {
            rule: BoxRule::AllForeground,
            width: 0,
            next_row: 0,
            foreground_px: 0,
            hull: Roi::EMPTY,
            runs: [ConstInit::INIT; 2],
            cur_side: 0,
            prev_len: 0,
            cur_len: 0,
            table: ConstInit::INIT,
            seen_row: ConstInit::INIT,
            table_high: 0,
            best: None,
            cleared: false,
        }
    }

    /// Starts a frame `width` pixels wide (at most the capacity's width; wider rows
    /// are cut: the detectors refuse such frames before).
    pub fn start(&mut self, rule: BoxRule, width: usize) {
        self.rule = rule;
        self.width = width.min(C::WIDTH);
        self.next_row = 0;
        self.foreground_px = 0;
        self.hull = Roi::EMPTY;
        self.prev_len = 0;
        self.cur_len = 0;
        // Entries at and above `table_high` are free once the table has been cleared.
        let used = if self.cleared {
            self.table_high
        } else {
            self.table.parents().as_ref().len()
        };
        for k in 0..used {
            self.free(k);
        }
        self.cleared = true;
        self.table_high = 0;
        self.best = None;
    }

    /// Adds mask row `y` (`true` = foreground). Rows must come in order 0, 1, 2, ...;
    /// a skipped row counts as background, a repeated or earlier row is ignored.
    pub fn push_row(&mut self, y: usize, mask: &[bool]) {
        if y < self.next_row || y >= usize::from(u16::MAX) {
            return;
        }
        while self.next_row < y {
            self.close_row(self.next_row, 0, &[]);
        }
        let mask = &mask[..mask.len().min(self.width)];
        // Written so the count vectorises; first/last look at 16 pixels at a time.
        let count = mask.iter().map(|&m| u32::from(m)).sum::<u32>();
        self.foreground_px += count;
        let (Some(first), Some(last)) = (first_set(mask), last_set(mask)) else {
            self.close_row(y, 0, &[]);
            return;
        };
        match self.rule {
            BoxRule::AllForeground => {
                let row = Roi::new(first as u16, y as u16, last as u16 + 1, y as u16 + 1);
                self.hull = self.hull.hull(&row);
                self.next_row = y + 1;
            }
            BoxRule::LargestComponent => {
                // `first ≤ last < mask.len()` by construction; `get` keeps a panic
                // branch out of the flight build.
                let runs = mask.get(first..=last).unwrap_or(&[]);
                self.close_row(y, first, runs);
            }
        }
    }

    /// Finishes the frame: the box (if any foreground) and the foreground pixel count.
    pub fn finish(&mut self) -> (Option<Roi>, u32) {
        let roi = match self.rule {
            BoxRule::AllForeground => self.hull,
            BoxRule::LargestComponent => {
                // Everything still open is complete.
                let y = self.next_row;
                self.close_row(y, 0, &[]);
                self.best.map_or(Roi::EMPTY, |b| b.roi)
            }
        };
        (
            if roi.is_empty() { None } else { Some(roi) },
            self.foreground_px,
        )
    }

    /// Labels the runs of row `y` (`mask` holds pixels `x0..x0 + mask.len()`; empty for
    /// a background row) and retires the components the row does not continue.
    // Out of line, as it was before the shared union-find: inlined into `push_row` it
    // changes how the detectors' own pixel loops are compiled (callgrind: otsu +3 %).
    #[inline(never)]
    fn close_row(&mut self, y: usize, x0: usize, mask: &[bool]) {
        self.next_row = y + 1;
        if self.rule != BoxRule::LargestComponent || (mask.is_empty() && self.prev_len == 0) {
            return;
        }
        self.collect_runs(x0, mask);
        self.link_runs(y);
        self.retire(y);
        self.cur_side = 1 - self.cur_side;
        self.prev_len = self.cur_len;
        self.cur_len = 0;
    }

    /// Splits the mask row into runs (at most `⌈W/2⌉` fit any row of the width).
    fn collect_runs(&mut self, x0: usize, mask: &[bool]) {
        self.cur_len = 0;
        let mut x = 0;
        while x < mask.len() {
            if !mask[x] {
                x += 1;
                continue;
            }
            let start = x;
            while x < mask.len() && mask[x] {
                x += 1;
            }
            if let Some(run) = self.runs[self.cur_side & 1].as_mut().get_mut(self.cur_len) {
                *run = Run {
                    x0: (x0 + start) as u16,
                    x1: (x0 + x) as u16,
                    label: FREE,
                };
                self.cur_len += 1;
            }
        }
    }

    /// Gives every run of the current row a component: the union of the components of
    /// the 8-connected runs above it, or a new one.
    fn link_runs(&mut self, y: usize) {
        let (cur, prev) = sides::<C>(&mut self.runs, self.cur_side);
        let cur_len = self.cur_len;
        // The previous row's runs (`prev_len` never exceeds the array: collect_runs
        // stops at its end).
        let prev = prev.as_ref().get(..self.prev_len).unwrap_or(&[]);
        let mut j0 = 0;
        for run in cur.as_mut().iter_mut().take(cur_len) {
            let (x0, x1) = (run.x0, run.x1);
            // Runs above that end left of this run's left neighbour can no longer touch
            // this or any later run.
            while prev.get(j0).is_some_and(|above| above.x1 < x0) {
                j0 += 1;
            }
            let mut label = FREE;
            for above in prev.get(j0..).unwrap_or(&[]) {
                if above.x0 > x1 {
                    break;
                }
                let root = self.table.find(above.label);
                label = if label == FREE {
                    root
                } else {
                    self.table.union(label, root)
                };
            }
            if label == FREE {
                match alloc::<C>(&mut self.table, &mut self.seen_row, &mut self.table_high) {
                    Some(l) => label = l,
                    // Unreachable by the capacity argument (at most MAX_RUNS components
                    // survive a row, at most MAX_RUNS are born in one); drop the run
                    // rather than panic.
                    None => continue,
                }
            }
            let width = self.width as u32;
            if let Some(comp) = self.table.stats_mut(label.index()) {
                let run_roi = Roi::new(x0, y as u16, x1, y as u16 + 1);
                comp.roi = comp.roi.hull(&run_roi);
                comp.area += u32::from(x1 - x0);
                comp.first = comp.first.min(y as u32 * width + u32::from(x0));
            }
            run.label = label;
        }
    }

    /// Points every current run at its root, then frees every entry that is not the
    /// root of a current run; roots no current run reaches are complete components.
    fn retire(&mut self, y: usize) {
        let stamp = y as u16;
        let cur_len = self.cur_len;
        let cur = &mut self.runs[self.cur_side & 1];
        for run in cur.as_mut().iter_mut().take(cur_len) {
            let root = self.table.find(run.label);
            run.label = root;
            if let Some(seen) = self.seen_row.as_mut().get_mut(root.index()) {
                *seen = stamp;
            }
        }
        let mut high = 0;
        for k in 0..self.table_high {
            let Some(parent) = self.table.parent(k).filter(|&p| p != FREE) else {
                continue;
            };
            let c = *self.table.stats(k).unwrap_or(&NO_PIXELS);
            let is_root = parent.index() == k;
            if is_root && self.seen_row.as_ref().get(k) == Some(&stamp) && c.area > 0 {
                high = k + 1;
                continue;
            }
            if is_root && c.beats(self.best.as_ref()) {
                self.best = Some(c);
            }
            self.free(k);
        }
        self.table_high = high;
    }

    /// Frees table entry `k`.
    fn free(&mut self, k: usize) {
        self.table.set_parent(k, FREE);
        if let Some(s) = self.table.stats_mut(k) {
            *s = NO_PIXELS;
        }
        if let Some(seen) = self.seen_row.as_mut().get_mut(k) {
            *seen = 0;
        }
    }
}

/// The run arrays of the current and of the previous row (`cur_side` 0 or 1), borrowed
/// apart from the rest of the builder.
fn sides<C: FrameCapacity>(
    runs: &mut [C::Runs<Run>; 2],
    cur_side: usize,
) -> (&mut C::Runs<Run>, &C::Runs<Run>) {
    let [r0, r1] = runs;
    if cur_side & 1 == 0 {
        (r0, r1)
    } else {
        (r1, r0)
    }
}

/// A free entry of `table`, as a new root with no pixels yet.
fn alloc<C: FrameCapacity>(
    table: &mut RunComponents<C>,
    seen_row: &mut C::OpenComponents<u16>,
    table_high: &mut usize,
) -> Option<RunLabel> {
    let k = table.parents().as_ref().iter().position(|&p| p == FREE)?;
    let label = RunLabel(k as u16);
    table.make_set(label, NO_PIXELS);
    if let Some(seen) = seen_row.as_mut().get_mut(k) {
        *seen = 0;
    }
    *table_high = (*table_high).max(k + 1);
    Some(label)
}

/// Bits of 16 mask pixels, pixel `i` in bit `i` (compiles to one `pmovmskb` on x86).
fn bits16(chunk: &[bool]) -> u32 {
    chunk
        .iter()
        .enumerate()
        .fold(0u32, |bits, (i, &m)| bits | (u32::from(m) << i))
}

/// Index of the first `true` in `mask`.
fn first_set(mask: &[bool]) -> Option<usize> {
    let mut chunks = mask.chunks_exact(16);
    for (c, chunk) in (&mut chunks).enumerate() {
        let bits = bits16(chunk);
        if bits != 0 {
            return Some(c * 16 + bits.trailing_zeros() as usize);
        }
    }
    let tail = mask.len() - chunks.remainder().len();
    chunks.remainder().iter().position(|&m| m).map(|i| tail + i)
}

/// Index of the last `true` in `mask`.
fn last_set(mask: &[bool]) -> Option<usize> {
    let mut chunks = mask.rchunks_exact(16);
    for (c, chunk) in (&mut chunks).enumerate() {
        let bits = bits16(chunk);
        if bits != 0 {
            return Some(mask.len() - (c + 1) * 16 + 31 - bits.leading_zeros() as usize);
        }
    }
    chunks.remainder().iter().rposition(|&m| m)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs `rows` (ASCII art, `#` = foreground) through a builder.
    fn boxes(rows: &[&str], rule: BoxRule) -> (Option<Roi>, u32) {
        let mut b = RoiBuilder::new();
        b.start(rule, rows[0].len());
        for (y, row) in rows.iter().enumerate() {
            let mask: [bool; 64] = core::array::from_fn(|x| row.as_bytes().get(x) == Some(&b'#'));
            b.push_row(y, &mask[..row.len()]);
        }
        b.finish()
    }

    #[test]
    fn a_fresh_all_zero_builder_and_a_reused_one_agree() {
        // A fresh builder holds zeros, not free entries: its first `start` frees the
        // whole table. A frame with many components (every other pixel of every other
        // row) fills the table; the next frame must come out as from a fresh builder.
        let rows = ["#...#..##", "#...#..##", "#...#....", "#####...."];
        let dots: [bool; 64] = core::array::from_fn(|x| x % 2 == 0);
        for rule in [BoxRule::LargestComponent, BoxRule::AllForeground] {
            let fresh = boxes(&rows, rule);
            let mut b = RoiBuilder::new();
            b.start(BoxRule::LargestComponent, 64);
            for y in (0..40).step_by(2) {
                b.push_row(y, &dots);
            }
            assert_eq!(b.finish(), (Some(Roi::new(0, 0, 1, 1)), 640));
            b.start(rule, rows[0].len());
            for (y, row) in rows.iter().enumerate() {
                let mask: [bool; 64] =
                    core::array::from_fn(|x| row.as_bytes().get(x) == Some(&b'#'));
                b.push_row(y, &mask[..row.len()]);
            }
            assert_eq!(b.finish(), fresh, "{rule:?}");
        }
    }

    #[test]
    fn u_shape_merges_late_into_one_component() {
        let rows = ["#...#..##", "#...#..##", "#...#....", "#####...."];
        assert_eq!(
            boxes(&rows, BoxRule::LargestComponent),
            (Some(Roi::new(0, 0, 5, 4)), 15)
        );
        assert_eq!(
            boxes(&rows, BoxRule::AllForeground),
            (Some(Roi::new(0, 0, 9, 4)), 15)
        );
    }

    #[test]
    fn diagonal_pixels_are_connected() {
        let rows = ["#....", ".#...", "..#..", "....#"];
        assert_eq!(
            boxes(&rows, BoxRule::LargestComponent),
            (Some(Roi::new(0, 0, 3, 3)), 4)
        );
    }

    #[test]
    fn ties_go_to_the_first_component_in_raster_order() {
        let rows = ["...##", "##...", "....."];
        assert_eq!(
            boxes(&rows, BoxRule::LargestComponent).0,
            Some(Roi::new(3, 0, 5, 1))
        );
    }

    #[test]
    fn empty_mask_and_checkerboard() {
        assert_eq!(boxes(&["...", "..."], BoxRule::LargestComponent), (None, 0));
        // A full-width checkerboard is one 8-connected component.
        let even: [u8; 328] = core::array::from_fn(|x| if x % 2 == 0 { b'#' } else { b'.' });
        let odd: [u8; 328] = core::array::from_fn(|x| if x % 2 == 1 { b'#' } else { b'.' });
        let (even, odd) = (
            core::str::from_utf8(&even).unwrap(),
            core::str::from_utf8(&odd).unwrap(),
        );
        let mut b = RoiBuilder::new();
        b.start(BoxRule::LargestComponent, 328);
        for y in 0..248 {
            let row = if y % 2 == 0 { even } else { odd };
            let mask: [bool; 328] = core::array::from_fn(|x| row.as_bytes()[x] == b'#');
            b.push_row(y, &mask);
        }
        assert_eq!(b.finish(), (Some(Roi::new(0, 0, 328, 248)), 164 * 248));
    }

    #[test]
    fn capacity_holds_164_stripes_alive_at_once() {
        // 164 one-pixel stripes stay open for the whole frame; then one row joins all.
        let mut b = RoiBuilder::new();
        b.start(BoxRule::LargestComponent, 328);
        let stripes: [bool; 328] = core::array::from_fn(|x| x % 2 == 0);
        for y in 0..247 {
            b.push_row(y, &stripes);
        }
        assert_eq!(b.clone().finish().0, Some(Roi::new(0, 0, 1, 247)));
        b.push_row(247, &[true; 328]);
        assert_eq!(
            b.finish(),
            (Some(Roi::new(0, 0, 328, 248)), 164 * 247 + 328)
        );
    }
}
