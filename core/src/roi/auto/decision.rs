//! Stage 4, the target decision: each component scores its summed steps, divided by
//! 2^`side_shift` (8 by default) for every side of the window it touches; the best
//! score wins (ties: the lowest label, the first in raster order).

use super::edges::{CellStats, EdgeComponents};

/// The winning component among labels `1..next` of the plane of `pw × ph` cells: its
/// root label and statistics; `None` without any component.
pub(super) fn choose_target(
    comps: &EdgeComponents,
    next: usize,
    (pw, ph): (usize, usize),
    side_shift: u8,
) -> Option<(u8, CellStats)> {
    // The Earth's limb (an arc from border to border) and Earth patches cut by the
    // frame lose to a compact outline inside it.
    let sides = |c: &CellStats| {
        u32::from(c.x0 == 0)
            + u32::from(c.y0 == 0)
            + u32::from(c.x_end() >= pw)
            + u32::from(c.y_end() >= ph)
    };
    let parent = comps.parents();
    let shift = u32::from(side_shift);
    let mut best: Option<(u8, u64)> = None;
    #[allow(clippy::needless_range_loop)] // `l` is the label: parent and statistics
    for l in 1..next {
        if parent.get(l) != Some(&(l as u8)) {
            continue;
        }
        let Some(c) = comps.stats(l) else { continue };
        let score = u64::from(c.energy) >> (shift * sides(c));
        if best.is_none_or(|(_, s)| score > s) {
            best = Some((l as u8, score));
        }
    }
    let (root, _) = best?;
    comps.stats(usize::from(root)).map(|c| (root, *c))
}
