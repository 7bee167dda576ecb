//! Stage 2, the step plane: per 4×4 cell, the largest step over two pixels in units
//! of σ/4, as an 8-bit logarithmic code.

use super::super::plane::{BLOCK, Window};
use super::rules::{STEP_CODE_FRACTION_BITS, STEP_CODES_PER_OCTAVE, STEP_UNITS_PER_SIGMA};
use crate::frame::Frame;

/// The step plane of `win` into `plane` (`pw` cells per row): per cell, the largest
/// absolute difference of a pixel and the pixel two to its right or two below, on
/// every other row (so every boundary between two pixels is spanned once per column
/// and per pair of rows, at half the cost of neighbour differences on every row), in
/// units of σ/4, as a [`step_code`]; steps below `floor` (σ/4) as 0, which no edge
/// threshold reaches (the code is computed only for cells that may be edge cells).
/// `band` holds the per-pixel maxima of one band of rows.
pub(super) fn step_plane(
    frame: &Frame<'_>,
    win: Window,
    sigma: u32,
    floor: u32,
    pw: usize,
    band: &mut [u16],
    plane: &mut [u8],
) {
    let max_dn = frame.max_dn();
    let n = win.w;
    let Some(band) = band.get_mut(..n) else {
        return;
    };
    // q = cm · 4/σ, as a 16.16 reciprocal.
    let inv = (u64::from(STEP_UNITS_PER_SIGMA) << 16) / u64::from(sigma.max(1));
    // The smallest step in DN whose σ/4 units reach `floor`: cm · inv ≥ floor · 2^16.
    let cm_floor = (u64::from(floor) << 16).div_ceil(inv.max(1));
    let code = |cm: u16| {
        let v = ((u64::from(cm) * inv) >> 16).min(u64::from(u32::MAX)) as u32;
        if u64::from(cm) < cm_floor {
            0
        } else {
            step_code(v)
        }
    };
    let c = |v: u16| v.min(max_dn);
    let last = win.y0 + win.h - 1;
    for (cy, plane_row) in plane.chunks_exact_mut(pw.max(1)).enumerate() {
        band.fill(0);
        let y_end = (win.y0 + (cy + 1) * BLOCK).min(win.y0 + win.h);
        for y in (win.y0 + cy * BLOCK..y_end).step_by(2) {
            let row = win.row(frame, y);
            // Two rows down, or the last row of the window (a step there still shows).
            let below = win.row(frame, (y + 2).min(last).max(y));
            if row.len() != n || below.len() != n {
                continue;
            }
            let span = 2.min(n - 1);
            let right = row.get(span..).unwrap_or(&[]);
            for (((m, &v), &r), &b) in band.iter_mut().zip(row).zip(right).zip(below) {
                let (v, r, b) = (c(v), c(r), c(b));
                *m = (*m).max(v.abs_diff(r)).max(v.abs_diff(b));
            }
            let tail = n.saturating_sub(span);
            for ((m, &v), &b) in band.iter_mut().zip(row).zip(below).skip(tail) {
                *m = (*m).max(c(v).abs_diff(c(b)));
            }
        }
        // Most bands hold no step that may make an edge cell: one pass that
        // vectorises says so.
        if u64::from(band.iter().fold(0, |m, &v| m.max(v))) < cm_floor {
            plane_row.fill(0);
            continue;
        }
        let mut cells = band.chunks_exact(BLOCK);
        for (q, chunk) in plane_row.iter_mut().zip(&mut cells) {
            let cm = chunk[0].max(chunk[1]).max(chunk[2]).max(chunk[3]);
            *q = code(cm);
        }
        // A partial cell at the right edge.
        if let (Some(q), false) = (plane_row.get_mut(n / BLOCK), cells.remainder().is_empty()) {
            let cm = cells.remainder().iter().fold(0u16, |m, &v| m.max(v));
            *q = code(cm);
        }
    }
}

/// The 8-bit code of a step of `v` (units of σ/4): 16 codes per octave,
/// `16·⌊log2 v⌋ + ` the next 4 bits of `v`, 0 for 0, at most 255 (`v` ≥ 2^15.9).
/// Integer only; [`step_value`] inverts it to within 1/16 of an octave.
pub(super) fn step_code(v: u32) -> u8 {
    const F: u32 = STEP_CODE_FRACTION_BITS;
    const MASK: u32 = STEP_CODES_PER_OCTAVE - 1;
    if v == 0 {
        return 0;
    }
    let l = 31 - v.leading_zeros();
    let frac = if l >= F {
        (v >> (l - F)) & MASK
    } else {
        (v << (F - l)) & MASK
    };
    (STEP_CODES_PER_OCTAVE * l + frac).min(255) as u8
}

/// The step (units of σ/4) a [`step_code`] stands for: the bottom of its sixteenth
/// of an octave.
pub(super) fn step_value(code: u8) -> u32 {
    let (l, frac) = (
        u32::from(code) / STEP_CODES_PER_OCTAVE,
        u32::from(code) % STEP_CODES_PER_OCTAVE,
    );
    ((STEP_CODES_PER_OCTAVE + frac) << l) >> STEP_CODE_FRACTION_BITS
}
