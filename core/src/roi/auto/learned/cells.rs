//! The plane of 8×8-pixel cells the classifier works on: per cell the mean DN, the
//! largest step over two pixels (as a log code of σ units), in one pass over the frame;
//! and, per cell on demand, the hottest and coldest 4×4-pixel window inside it
//! ([`sub_window_extremes`]: the finer look that keeps a 3–12 px target's contrast).

use super::super::super::plane::Window;
use super::lanes;
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
    /// Pixels of the cell at or above the frame's top DN (0..=64): the saturated blob's
    /// counts ([`super::blob`]), counted in the same pass (a separate pass cost
    /// 1.2 M instructions per frame on the M7, 15 per pixel).
    pub saturated_px: &'a mut [u8],
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
    let (pw, ph) = cell_plane(win);
    // The caller's rows hold a plane row of any window of the frame (`get_mut`: no
    // panic path, nothing filled if they were short).
    let (Some(sums), Some(steps)) = (sums.get_mut(..pw), steps.get_mut(..pw)) else {
        return;
    };
    let (x0, w) = (win.x0, win.w);
    let fw = frame.width();
    for cy in 0..ph {
        let ya = win.y0 + cy * CELL_PX;
        let yb = (ya + CELL_PX).min(win.y0 + win.h);
        sums.fill(0);
        let step_row = &mut *steps;
        step_row.fill(0);
        // This cell row's saturated counts (`get_mut`: an empty row, never a panic
        // path, if the plane were short).
        let sat_row = planes
            .saturated_px
            .get_mut(cy * pw..(cy + 1) * pw)
            .unwrap_or_default();
        sat_row.fill(0);
        // Cell by cell: a whole cell as a block (those at the frame's left and right
        // edges from a copy); a cell cut by the window's right side or bottom row by
        // row.
        for (cx, ((s, st), sat)) in sums
            .iter_mut()
            .zip(step_row.iter_mut())
            .zip(sat_row.iter_mut())
            .enumerate()
        {
            let xa = x0 + cx * CELL_PX;
            let xb = (xa + CELL_PX).min(x0 + w);
            if yb == ya + CELL_PX && xb == xa + CELL_PX {
                (*s, *st, *sat) = if xa >= 1 && xb < fw {
                    full_block(frame, xa, ya)
                } else {
                    edge_block(frame, xa, ya)
                };
            } else {
                for y in ya..yb {
                    let acc = cell_row(frame, y, xa, xb, *st);
                    (*s, *st, *sat) = (*s + acc.0, acc.1, sat.saturating_add(acc.2));
                }
            }
        }
        // `get_mut`: the planes hold pw·ph cells (the caller's slices), so the row is
        // always there; an empty row instead of a panic path if not.
        for (code, &st) in planes
            .step_code
            .get_mut(cy * pw..(cy + 1) * pw)
            .unwrap_or_default()
            .iter_mut()
            .zip(step_row.iter())
        {
            let q = u32::from(st) * 4 / sigma.max(1);
            *code = super::features::log_code(q).clamp(0, 255) as u8;
        }
        let rows = (yb - ya) as u32;
        for (cx, (m, &s)) in planes
            .mean_dn
            .get_mut(cy * pw..(cy + 1) * pw)
            .unwrap_or_default()
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

/// Columns `xa..xb` of frame row `y` (inside the frame): the sum of the pixels clamped
/// to the top DN, the largest of `best` and their two-pixel steps across and down
/// (neighbours clamped at the frame's edges), and how many are at or above the top DN.
/// `(0, best, 0)` for a row outside the frame.
#[inline(always)]
fn cell_row(frame: &Frame<'_>, y: usize, xa: usize, xb: usize, best: u16) -> (u32, u16, u8) {
    let max_dn = frame.max_dn();
    let (fw, fh) = (frame.width(), frame.height());
    let Some(row) = frame.row(y) else {
        return (0, best, 0);
    };
    let row = &row[..fw];
    let up = frame.row(y.saturating_sub(1)).map(|r| &r[..fw]);
    let down = frame.row((y + 1).min(fh - 1)).map(|r| &r[..fw]);
    // An inner cell (a pixel on each side, both neighbouring rows): the same sums and
    // steps from slices, without a bounds check per read.
    if let (Some(u), Some(d), true) = (up, down, xa >= 1 && xb < fw) {
        return if xb - xa == CELL_PX {
            full_inner_cell(row, u, d, xa, max_dn, best)
        } else {
            inner_cell(row, u, d, xa, xb, max_dn, best)
        };
    }
    let mut acc = 0u32;
    let mut best = best;
    let mut n_sat = 0u8;
    // Inside the frame (a window always is; `min(fw)` says so to the compiler: no
    // bounds check per read below).
    for x in xa..xb.min(fw) {
        n_sat += u8::from(row[x] >= max_dn);
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
    (acc, best, n_sat)
}

/// The sum of pixels `xa..xb` of `row` (clamped to `max_dn`), the largest of `best`
/// and their two-pixel steps, across (`row[x − 1]` to `row[x + 1]`) and down (`up[x]` to
/// `down[x]`), and how many are at or above `max_dn`, for `1 ≤ xa` and `xb < row.len()`
/// (an inner cell: every neighbour in the row; `xb − xa` ≤ 8); `fill_cells`'s per-pixel
/// loop without its edge clamps. Slices out of range (never, by the caller's test) give
/// `(0, best, 0)`.
#[inline(always)]
fn inner_cell(
    row: &[u16],
    up: &[u16],
    down: &[u16],
    xa: usize,
    xb: usize,
    max_dn: u16,
    best: u16,
) -> (u32, u16, u8) {
    let (Some(left), Some(mid), Some(right), Some(up), Some(down)) = (
        row.get(xa.wrapping_sub(1)..xb.wrapping_sub(1)),
        row.get(xa..xb),
        row.get(xa + 1..xb + 1),
        up.get(xa..xb),
        down.get(xa..xb),
    ) else {
        return (0, best, 0);
    };
    let mut acc = 0u32;
    let mut best = best;
    let mut n_sat = 0u8;
    for ((((&l, &v), &r), &u), &d) in left.iter().zip(mid).zip(right).zip(up).zip(down) {
        n_sat += u8::from(v >= max_dn);
        acc += u32::from(v.min(max_dn));
        let h = l.min(max_dn).abs_diff(r.min(max_dn));
        let vert = u.min(max_dn).abs_diff(d.min(max_dn));
        best = best.max(h).max(vert);
    }
    (acc, best, n_sat)
}

/// [`inner_cell`] of a whole cell row (`xb = xa + CELL_PX`) on fixed-size arrays: each
/// pixel of the row clamped once (it is the left, centre and right neighbour of three),
/// the loop unrolled. The same sums and steps; `(0, best, 0)` for slices out of range.
#[inline(always)]
fn full_inner_cell(
    row: &[u16],
    up: &[u16],
    down: &[u16],
    xa: usize,
    max_dn: u16,
    best: u16,
) -> (u32, u16, u8) {
    let (Some(around), Some(up), Some(down)) = (
        row.get(xa.wrapping_sub(1)..xa + CELL_PX + 1)
            .and_then(|r| <&[u16; CELL_PX + 2]>::try_from(r).ok()),
        up.get(xa..xa + CELL_PX)
            .and_then(|r| <&[u16; CELL_PX]>::try_from(r).ok()),
        down.get(xa..xa + CELL_PX)
            .and_then(|r| <&[u16; CELL_PX]>::try_from(r).ok()),
    ) else {
        return (0, best, 0);
    };
    let clamped = around.map(|v| v.min(max_dn));
    let mut acc = 0u32;
    let mut best = best;
    let mut n_sat = 0u8;
    for i in 0..CELL_PX {
        n_sat += u8::from(around[i + 1] >= max_dn);
        acc += u32::from(clamped[i + 1]);
        let h = clamped[i].abs_diff(clamped[i + 2]);
        let vert = up[i].min(max_dn).abs_diff(down[i].min(max_dn));
        best = best.max(h).max(vert);
    }
    (acc, best, n_sat)
}

/// The sum, largest two-pixel step and saturated count of the whole 8×8 cell at
/// `(xa, ya)` with a frame pixel on its left and right (`xa ≥ 1`, `xa + 8 < width`,
/// `ya + 8 ≤ height`; the frame's first and last rows are their own neighbours above
/// and below, as in [`cell_row`]): [`full_inner_cell`] on its 8 rows, but first without the clamps
/// to the top DN, which change nothing when no pixel read is above it (the bitwise or
/// of them all at most the top DN, `2^bits − 1`): a pixel above it sends the cell
/// through the clamped rows (never in a camera's frame; tested). `(0, 0, 0)` for a
/// cell without its rows (never, by the caller's test).
#[inline(always)]
fn full_block(frame: &Frame<'_>, xa: usize, ya: usize) -> (u32, u16, u8) {
    const EMPTY: &[u16; CELL_PX + 2] = &[0; CELL_PX + 2];
    let mut rows = [EMPTY; CELL_PX + 2];
    // Rows ya − 1 ..= ya + 8, columns xa − 1 ..= xa + 8 (views of the frame).
    let last = frame.height().saturating_sub(1);
    for (k, out) in rows.iter_mut().enumerate() {
        // The frame's first and last rows are their own neighbours (as in `cell_row`).
        let Some(r) = frame
            .row((ya + k).saturating_sub(1).min(last))
            .and_then(|r| r.get(xa - 1..xa + CELL_PX + 1))
            .and_then(|r| <&[u16; CELL_PX + 2]>::try_from(r).ok())
        else {
            return (0, 0, 0);
        };
        *out = r;
    }
    block_of(rows, frame.max_dn())
}

/// [`full_block`] of a whole cell on the frame's left or right edge (`xa + 8 ≤ width`),
/// whose outer column is its own neighbour (as in [`cell_row`]): the 10 × 10 pixels
/// copied with the edge column repeated.
#[inline(never)]
fn edge_block(frame: &Frame<'_>, xa: usize, ya: usize) -> (u32, u16, u8) {
    let (last_x, last_y) = (
        frame.width().saturating_sub(1),
        frame.height().saturating_sub(1),
    );
    let mut copies = [[0u16; CELL_PX + 2]; CELL_PX + 2];
    for (k, out) in copies.iter_mut().enumerate() {
        let Some(r) = frame.row((ya + k).saturating_sub(1).min(last_y)) else {
            return (0, 0, 0);
        };
        for (j, v) in out.iter_mut().enumerate() {
            *v = r
                .get((xa + j).saturating_sub(1).min(last_x))
                .copied()
                .unwrap_or(0);
        }
    }
    block_of(copies.each_ref(), frame.max_dn())
}

/// The sum, largest two-pixel step and saturated count of the 8 × 8 pixels inside
/// `rows` (10 rows of 10: the cell and a neighbour on every side), first without the
/// clamps to the top DN `max_dn`, which change nothing when no pixel is above it (the
/// bitwise or of them all at most `2^bits − 1`), else through the clamped rows
/// ([`block_clamped`]). A Cortex-M4/M7 build takes the pixel-pair form instead
/// ([`block_lanes`]), which checks the same condition by its lane maxima.
#[inline(always)]
fn block_of(rows: [&[u16; CELL_PX + 2]; CELL_PX + 2], max_dn: u16) -> (u32, u16, u8) {
    if lanes::DSP {
        return block_lanes(rows, max_dn).unwrap_or_else(|| block_clamped(rows, max_dn));
    }
    let mut any = 0u16;
    for r in rows {
        for &v in r {
            any |= v;
        }
    }
    if any > max_dn {
        return block_clamped(rows, max_dn);
    }
    if VECTOR_HOST {
        block_columns(rows, max_dn)
    } else {
        block_scalar(rows, max_dn)
    }
}

/// [`block_of`]'s sums without the clamps, pixel by pixel with one running maximum
/// (the targets without 16-bit vector lanes: see [`VECTOR_HOST`]).
#[inline(always)]
fn block_scalar(rows: [&[u16; CELL_PX + 2]; CELL_PX + 2], max_dn: u16) -> (u32, u16, u8) {
    let mut acc = 0u32;
    let mut best = 0u16;
    let mut n_sat = 0u8;
    for k in 1..=CELL_PX {
        // Unrolled: every index is a constant in range (no panic path).
        let (up, mid, down) = (rows[k - 1], rows[k], rows[k + 1]);
        for i in 1..=CELL_PX {
            let v = mid[i];
            n_sat += u8::from(v >= max_dn);
            acc += u32::from(v);
            best = best
                .max(mid[i - 1].abs_diff(mid[i + 1]))
                .max(up[i].abs_diff(down[i]));
        }
    }
    (acc, best, n_sat)
}

/// Whether [`block_of`] runs as [`block_columns`]: on hosts whose vector units take
/// 16-bit lanes (x86-64 with SSE4.1, AArch64). Targets without them keep the running
/// maximum over all 64 pixels (`thumbv7m-none-eabi`: `auto-v2` 100 → 108 instructions
/// per pixel in the column form, `scripts/flight.sh`).
const VECTOR_HOST: bool = cfg!(any(target_arch = "x86_64", target_arch = "aarch64"));

/// [`block_of`]'s sums without the clamps, per column of the cell (a lane each) down
/// its 8 rows — the sums, the largest step and the saturated count — folded over the
/// columns at the end: eight independent lanes of `u16`/`u32` arithmetic, which the
/// compiler turns into vector instructions (x86-64, callgrind on 40 frames of family A:
/// `fill_cells` 28 → 10 instructions per pixel). The same sums, step and count.
#[inline(always)]
fn block_columns(rows: [&[u16; CELL_PX + 2]; CELL_PX + 2], max_dn: u16) -> (u32, u16, u8) {
    let mut sums = [0u32; CELL_PX];
    let mut steps = [0u16; CELL_PX];
    let mut sats = [0u8; CELL_PX];
    for k in 1..=CELL_PX {
        // Unrolled: every index is a constant in range (no panic path).
        let (up, mid, down) = (rows[k - 1], rows[k], rows[k + 1]);
        for i in 0..CELL_PX {
            let v = mid[i + 1];
            sats[i] += u8::from(v >= max_dn);
            sums[i] += u32::from(v);
            steps[i] = steps[i]
                .max(mid[i].abs_diff(mid[i + 2]))
                .max(up[i + 1].abs_diff(down[i + 1]));
        }
    }
    let acc = sums.iter().sum();
    let best = steps.iter().copied().max().unwrap_or(0);
    let n_sat = sats.iter().sum();
    (acc, best, n_sat)
}

/// [`block_of`] through the clamped rows ([`full_inner_cell`] on each of the 8): for a
/// cell with a pixel above the top DN, never in a camera's frame.
#[inline(always)]
fn block_clamped(rows: [&[u16; CELL_PX + 2]; CELL_PX + 2], max_dn: u16) -> (u32, u16, u8) {
    let (mut acc, mut best, mut n_sat) = (0u32, 0u16, 0u8);
    for w in rows.windows(3) {
        let &[up, mid, down] = w else { continue };
        let (a, b, n) = full_inner_cell(mid, &up[..], &down[..], 1, max_dn, best);
        acc += a;
        best = b;
        n_sat += n;
    }
    (acc, best, n_sat)
}

/// [`block_of`] without the clamps (no pixel of `rows` above `max_dn`) on pixel pairs
/// ([`lanes`]): per pair of a cell row its two steps across and down folded into a
/// running maximum per lane, its sum, and its larger pixel; the saturated pixels (at
/// `max_dn`) are counted only when the cell's largest pixel reaches it. The same
/// sum, step and count as the per-pixel loop (tested against it).
#[inline(always)]
fn block_lanes(rows: [&[u16; CELL_PX + 2]; CELL_PX + 2], max_dn: u16) -> Option<(u32, u16, u8)> {
    const PAIRS: usize = CELL_PX / 2;
    let (mut acc, mut steps, mut top) = (0u32, 0u32, 0u32);
    for j in 0..PAIRS {
        (acc, steps, top) = pair_column(&rows, 1 + 2 * j, (acc, steps, top));
    }
    // The pixels read around the cell: the rows above and below, the columns left and
    // right (not the corners).
    let (first, last) = (rows[0], rows[CELL_PX + 1]);
    for j in 0..PAIRS {
        let i = 1 + 2 * j;
        top = lanes::max(
            top,
            lanes::max(
                lanes::pair(first[i], first[i + 1]),
                lanes::pair(last[i], last[i + 1]),
            ),
        );
    }
    for mid in &rows[1..=CELL_PX] {
        top = lanes::max(top, lanes::pair(mid[0], mid[CELL_PX + 1]));
    }
    let (s0, s1) = lanes::split(steps);
    let (t0, t1) = lanes::split(top);
    let read_max = t0.max(t1);
    if read_max > max_dn {
        return None;
    }
    let mut n_sat = 0u8;
    if read_max == max_dn {
        for mid in &rows[1..=CELL_PX] {
            for &v in &mid[1..=CELL_PX] {
                n_sat += u8::from(v >= max_dn);
            }
        }
    }
    Some((acc, s0.max(s1), n_sat))
}

/// One column of pairs of [`block_lanes`] (pixels `i`, `i + 1` of the cell's 8 rows):
/// `(sum, steps, top)` with its pairs added. Down the column the pair above and the pair
/// itself are carried over from the row before (three words read per step, not five).
#[inline(always)]
fn pair_column(
    rows: &[&[u16; CELL_PX + 2]; CELL_PX + 2],
    i: usize,
    (mut acc, mut steps, mut top): (u32, u32, u32),
) -> (u32, u32, u32) {
    // `i` is odd and at most 7 (the caller's): every index below is then in range (the
    // guard says so to the compiler: no panic path, `scripts/panic-never.sh`); any other
    // `i` leaves the sums as they are.
    if !(1..CELL_PX).contains(&i) {
        return (acc, steps, top);
    }
    let at = |row: &[u16; CELL_PX + 2]| lanes::pair(row[i], row[i + 1]);
    let (mut up, mut mid) = (at(rows[0]), at(rows[1]));
    for k in 1..=CELL_PX {
        let down = at(rows[k + 1]);
        let row = rows[k];
        (steps, acc, top) = lanes::pair_step(
            (steps, acc, top),
            (
                lanes::pair(row[i - 1], row[i]),
                lanes::pair(row[i + 1], row[i + 2]),
            ),
            (up, mid, down),
        );
        (up, mid) = (mid, down);
    }
    (acc, steps, top)
}

/// Side of the finer windows the classifier also looks through, pixels: a 3–12 px far
/// target covers at most a quarter to a half of an 8×8 cell, so its cell mean keeps a
/// quarter of its contrast or less; a 4×4 window it fills keeps all of it.
pub const SUB_PX: usize = 4;

/// Stride of the finer windows inside a cell, pixels: half a window, so a target of
/// 4 px or more (truth side) fills at least a 2×2-pixel quarter of some window
/// wherever it falls inside the cell (3×3 windows per full 8×8 cell).
pub const SUB_STRIDE_PX: usize = 2;

/// Blocks of `SUB_STRIDE_PX` pixels per cell side.
const BLOCKS: usize = CELL_PX / SUB_STRIDE_PX;

/// Windows per cell side.
const SUB_WINDOWS: usize = (CELL_PX - SUB_PX) / SUB_STRIDE_PX + 1;

/// The hottest and the coldest mean DN over the 4×4-pixel windows at a 2-px stride
/// inside cell `(cx, cy)` of `win` (3×3 windows for a full 8×8 cell; pixels clamped
/// to the frame's top DN), read from the frame: 64 pixel reads per cell. A cell cut by
/// the window's edge uses only the windows wholly inside it; without one (a cell less
/// than 4 px on a side), both are its mean. `(0, 0)` for a cell outside the window.
pub fn sub_window_extremes(frame: &Frame<'_>, win: Window, (cx, cy): (usize, usize)) -> (u16, u16) {
    let max_dn = frame.max_dn();
    let (xa, ya) = (win.x0 + cx * CELL_PX, win.y0 + cy * CELL_PX);
    let xb = (xa + CELL_PX).min(win.x0 + win.w);
    let yb = (ya + CELL_PX).min(win.y0 + win.h);
    if xa >= xb || ya >= yb {
        return (0, 0);
    }
    if xb - xa == CELL_PX && yb - ya == CELL_PX {
        if let Some(extremes) = full_cell_extremes(frame, xa, ya) {
            return extremes;
        }
    }
    // Sums and pixel counts of the 2×2-pixel blocks of the cell.
    let mut sums = [[0u32; BLOCKS]; BLOCKS];
    let mut counts = [[0u32; BLOCKS]; BLOCKS];
    let (mut all, mut n_all) = (0u32, 0u32);
    for y in ya..yb {
        let Some(row) = frame.row(y).and_then(|r| r.get(xa..xb)) else {
            continue;
        };
        let by = (y - ya) / SUB_STRIDE_PX;
        let (Some(srow), Some(crow)) = (sums.get_mut(by), counts.get_mut(by)) else {
            continue;
        };
        for (i, &v) in row.iter().enumerate() {
            let bx = i / SUB_STRIDE_PX;
            let v = u32::from(v.min(max_dn));
            if let (Some(s), Some(c)) = (srow.get_mut(bx), crow.get_mut(bx)) {
                *s += v;
                *c += 1;
            }
            all += v;
            n_all += 1;
        }
    }
    let per = SUB_PX / SUB_STRIDE_PX;
    let full = (SUB_PX * SUB_PX) as u32;
    let (mut hot, mut cold) = (None::<u32>, None::<u32>);
    for wy in 0..SUB_WINDOWS {
        for wx in 0..SUB_WINDOWS {
            let (mut s, mut c) = (0u32, 0u32);
            for (srow, crow) in sums.iter().zip(&counts).skip(wy).take(per) {
                for (&bs, &bc) in srow.iter().zip(crow).skip(wx).take(per) {
                    s += bs;
                    c += bc;
                }
            }
            if c == full {
                let m = s / full;
                hot = Some(hot.map_or(m, |h| h.max(m)));
                cold = Some(cold.map_or(m, |h| h.min(m)));
            }
        }
    }
    let mean = all / n_all.max(1);
    (
        hot.unwrap_or(mean).min(u32::from(max_dn)) as u16,
        cold.unwrap_or(mean).min(u32::from(max_dn)) as u16,
    )
}

/// [`sub_window_extremes`] of a whole 8×8 cell at `(xa, ya)` on fixed-size arrays (every
/// window full: no counts; 2 × 2 blocks of 2 × 2 pixels per window); `None` if a row
/// were out of the frame (never for a cell of a window).
#[inline(always)]
fn full_cell_extremes(frame: &Frame<'_>, xa: usize, ya: usize) -> Option<(u16, u16)> {
    let max_dn = frame.max_dn();
    // Sums of the 2×2-pixel blocks.
    const { assert!(SUB_STRIDE_PX == 2 && SUB_PX == 2 * SUB_STRIDE_PX) };
    let mut blocks = [[0u32; BLOCKS]; BLOCKS];
    for dy in 0..CELL_PX {
        let row = frame.row(ya + dy)?.get(xa..xa + CELL_PX)?;
        let row = <&[u16; CELL_PX]>::try_from(row).ok()?;
        let sums = blocks.get_mut(dy / SUB_STRIDE_PX)?;
        for (bx, s) in sums.iter_mut().enumerate() {
            *s += u32::from(row[2 * bx].min(max_dn)) + u32::from(row[2 * bx + 1].min(max_dn));
        }
    }
    let full = (SUB_PX * SUB_PX) as u32;
    let (mut hot, mut cold) = (0u32, u32::MAX);
    for wy in 0..SUB_WINDOWS {
        for wx in 0..SUB_WINDOWS {
            let s =
                blocks[wy][wx] + blocks[wy][wx + 1] + blocks[wy + 1][wx] + blocks[wy + 1][wx + 1];
            let m = s / full;
            hot = hot.max(m);
            cold = cold.min(m);
        }
    }
    Some((hot as u16, cold as u16))
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    /// The hottest and coldest 4×4 windows against a brute force over every window at
    /// a 2-px stride wholly inside the cell and the window (pixels clamped to the top
    /// DN; the cell's mean without one), on odd frame sizes, an offset window (partial
    /// cells on every side) and values above the top DN.
    #[test]
    fn sub_window_extremes_equal_brute_force() {
        let mut rand = super::super::xorshift32(0x9E37_79B9);
        let mut windows = 0u32;
        for (w, h, bits, win) in [
            (37usize, 29usize, 12u8, None),
            (328, 248, 14, None),
            (61, 45, 14, Some((5usize, 3usize, 50usize, 39usize))),
            (9, 3, 8, None),
        ] {
            let px: Vec<u16> = (0..w * h).map(|_| (rand() % 20_000) as u16).collect();
            let frame = Frame::new(&px, w, h, bits).unwrap();
            let win = match win {
                None => Window::full(&frame),
                Some((x0, y0, x1, y1)) => Window::clipped(&frame, x0, y0, x1, y1).unwrap(),
            };
            let top = u64::from(frame.max_dn());
            let at = |x: usize, y: usize| u64::from(px[y * w + x]).min(top);
            let (pw, ph) = cell_plane(win);
            for cy in 0..ph {
                for cx in 0..pw {
                    let (xa, ya) = (win.x0 + cx * CELL_PX, win.y0 + cy * CELL_PX);
                    let xb = (xa + CELL_PX).min(win.x0 + win.w);
                    let yb = (ya + CELL_PX).min(win.y0 + win.h);
                    let (mut hot, mut cold) = (None::<u64>, None::<u64>);
                    for y in (ya..yb).step_by(SUB_STRIDE_PX).filter(|y| y + SUB_PX <= yb) {
                        for x in (xa..xb).step_by(SUB_STRIDE_PX).filter(|x| x + SUB_PX <= xb) {
                            let mut s = 0u64;
                            for yy in y..y + SUB_PX {
                                for xx in x..x + SUB_PX {
                                    s += at(xx, yy);
                                }
                            }
                            let m = s / (SUB_PX * SUB_PX) as u64;
                            hot = Some(hot.map_or(m, |v| v.max(m)));
                            cold = Some(cold.map_or(m, |v| v.min(m)));
                            windows += 1;
                        }
                    }
                    let (mut s, mut n) = (0u64, 0u64);
                    for y in ya..yb {
                        for x in xa..xb {
                            s += at(x, y);
                            n += 1;
                        }
                    }
                    let want = (hot.unwrap_or(s / n) as u16, cold.unwrap_or(s / n) as u16);
                    assert_eq!(
                        sub_window_extremes(&frame, win, (cx, cy)),
                        want,
                        "{w}x{h} cell ({cx}, {cy})"
                    );
                }
            }
        }
        assert!(windows > 10_000, "{windows}");
    }

    /// The cell plane against a brute force over the pixels (sum, the largest clamped
    /// two-pixel step across and down, neighbours clamped at the frame's edges, and the
    /// pixels at or above the top DN)
    /// on frames of odd sizes (partial cells on the right and bottom), values above the
    /// bit depth's top DN, and the full reference size.
    #[test]
    fn cell_plane_equals_brute_force() {
        let mut rand = super::super::xorshift32(0x2545_F491);
        // (width, height, bits, one pixel in `sparse` above the top DN; 0: values
        // anywhere in 0..20 000): whole cells without a pixel above the top DN take
        // the unclamped block path, the others the clamped rows.
        for (w, h, bits, sparse) in [
            (37usize, 29usize, 12u8, 0u32),
            (328, 248, 14, 0),
            (328, 248, 14, 700),
            (328, 248, 16, 0),
            (9, 1, 14, 0),
            (1, 9, 8, 0),
        ] {
            let top = (1u32 << bits) - 1;
            let px: Vec<u16> = (0..w * h)
                .map(|_| {
                    let seed = rand();
                    if sparse == 0 {
                        (seed % 20_000) as u16
                    } else if seed % sparse == 0 {
                        (top + 1 + seed % 100) as u16
                    } else {
                        // Near the top too: saturated pixels counted on both paths.
                        (top - seed % 2_000) as u16
                    }
                })
                .collect();
            let frame = Frame::new(&px, w, h, bits).unwrap();
            // The whole frame, and a tracking window inside it (neighbours still read
            // from the frame: only its own edges clamp).
            let inner = Window::clipped(&frame, w / 5, h / 7, w - w / 6, h - h / 9);
            for win in [Some(Window::full(&frame)), inner].into_iter().flatten() {
                check_cell_plane(&frame, &px, win);
            }
        }
    }

    /// The pair form of a whole cell ([`block_lanes`], what a Cortex-M4/M7 build runs;
    /// here on the lane-by-lane operations) against a brute force over its 10 × 10
    /// pixels: the sum of the inner 8 × 8, the largest two-pixel step across and down
    /// and the pixels at the top DN, at 8, 14 and 16 bits, with and without saturated
    /// pixels and with only small steps.
    #[test]
    fn cell_pairs_equal_brute_force() {
        let mut rand = super::super::xorshift32(0x0DD_B10C);
        let mut saturated_cells = 0u32;
        for k in 0..30_000u32 {
            let bits = [8u8, 14, 16][(k % 3) as usize];
            let top = ((1u32 << bits) - 1) as u16;
            let (base, spread) = match k % 4 {
                // Anywhere in range, near the top (saturated pixels), small steps.
                0 | 1 => (0u32, u32::from(top) + 1),
                2 => (u32::from(top) - 40, 41),
                _ => (u32::from(top) / 2, 5),
            };
            let px: [[u16; CELL_PX + 2]; CELL_PX + 2] =
                core::array::from_fn(|_| core::array::from_fn(|_| (base + rand() % spread) as u16));
            let rows = px.each_ref();
            let (mut sum, mut best, mut n_sat) = (0u32, 0u16, 0u8);
            for y in 1..=CELL_PX {
                for x in 1..=CELL_PX {
                    sum += u32::from(px[y][x]);
                    n_sat += u8::from(px[y][x] >= top);
                    best = best
                        .max(px[y][x - 1].abs_diff(px[y][x + 1]))
                        .max(px[y - 1][x].abs_diff(px[y + 1][x]));
                }
            }
            saturated_cells += u32::from(n_sat > 0);
            assert_eq!(
                block_lanes(rows, top),
                Some((sum, best, n_sat)),
                "block {k}"
            );
            assert_eq!(block_of(rows, top), (sum, best, n_sat), "block {k}");
            // Both forms of the unclamped sums, whichever this build runs.
            assert_eq!(block_columns(rows, top), (sum, best, n_sat), "block {k}");
            assert_eq!(block_scalar(rows, top), (sum, best, n_sat), "block {k}");
            // One pixel above the top DN (never in a camera's frame): the pair form
            // declines when it is read (the clamped rows decide), not in a corner.
            if bits < 16 {
                let (y, x) = ((rand() % 10) as usize, (rand() % 10) as usize);
                let mut over = px;
                over[y][x] = top + 1;
                let corner = (y == 0 || y == CELL_PX + 1) && (x == 0 || x == CELL_PX + 1);
                let got = block_lanes(over.each_ref(), top);
                assert_eq!(got.is_none(), !corner, "block {k} ({x}, {y})");
                if corner {
                    assert_eq!(got, Some((sum, best, n_sat)), "block {k} corner");
                }
            }
        }
        assert!(saturated_cells > 5_000, "{saturated_cells}");
    }

    /// [`fill_cells`] of `win` against the brute force over `px` (the frame's pixels).
    fn check_cell_plane(frame: &Frame<'_>, px: &[u16], win: Window) {
        let (w, h) = (frame.width(), frame.height());
        let (pw, ph) = cell_plane(win);
        let sigma = 7u32;
        let (mut mean, mut code) = (std::vec![0u16; pw * ph], std::vec![0u8; pw * ph]);
        let mut sat = std::vec![0xAAu8; pw * ph];
        let (mut sums, mut steps) = (std::vec![0u32; pw], std::vec![0u16; pw]);
        fill_cells(
            frame,
            win,
            sigma,
            CellPlanes {
                mean_dn: &mut mean,
                step_code: &mut code,
                saturated_px: &mut sat,
            },
            &mut sums,
            &mut steps,
        );
        let top = frame.max_dn();
        let at = |x: usize, y: usize| px[y * w + x].min(top);
        for cy in 0..ph {
            for cx in 0..pw {
                let (mut s, mut n, mut best, mut n_sat) = (0u64, 0u64, 0u16, 0u8);
                let (xa, ya) = (win.x0 + cx * 8, win.y0 + cy * 8);
                for y in ya..(ya + 8).min(win.y0 + win.h) {
                    for x in xa..(xa + 8).min(win.x0 + win.w) {
                        s += u64::from(at(x, y));
                        n += 1;
                        n_sat += u8::from(px[y * w + x] >= top);
                        let across = at(x.saturating_sub(1), y).abs_diff(at((x + 1).min(w - 1), y));
                        let down = at(x, y.saturating_sub(1)).abs_diff(at(x, (y + 1).min(h - 1)));
                        best = best.max(across).max(down);
                    }
                }
                let i = cy * pw + cx;
                assert_eq!(
                    u64::from(mean[i]),
                    s / n,
                    "{w}x{h} {win:?} cell ({cx}, {cy})"
                );
                assert_eq!(sat[i], n_sat, "{w}x{h} {win:?} saturated ({cx}, {cy})");
                let want = super::super::features::log_code(u32::from(best) * 4 / sigma);
                assert_eq!(
                    i32::from(code[i]),
                    want.clamp(0, 255),
                    "{w}x{h} {win:?} ({cx}, {cy})"
                );
            }
        }
    }
}
