//! Fig. 12 (DN histograms) and Fig. 17 (gradient distributions inside and outside the
//! truth box).

use std::path::Path;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::draw::{
    LegendEntry, LegendKind, check_frame, fail, fmt_tick, header, legend_strip, legible, no_data,
    render, rgb, step_outline, text,
};
use super::{FRAME_COLOURS, GradientFrame, HEIGHT, PlotError, WIDTH, grid, panel_figure_size};
use crate::eval::bank::median;
use crate::imaging::overlay;

/// Fig. 12: histogram of the DN of one or more frames, overlaid, each filled in its
/// colour with its outline, legend `label (N px)`.
///
/// The x axis spans the whole DN range of the bit depth, `0..2^bits`, in
/// `min(2^bits, 256)` equal bins (64 DN per bin at 14 bits), so saturation shows at the
/// right edge; the y axis is the pixel count on a log scale (empty bins drop to the
/// axis), so a small target's mode stays visible next to the background's. 800×500.
///
/// # Errors
/// [`PlotError`] when there is no pixel at all ("no data"), `bits` is not 1..=16, a DN
/// exceeds `2^bits − 1` (the message names the frame), or the file cannot be drawn or
/// written.
pub fn intensity_histogram(
    frames: &[(&str, &[u16])],
    bits: u8,
    title: &str,
    path: &Path,
) -> Result<(), PlotError> {
    if !(1..=16).contains(&bits) {
        return Err(fail(path, format!("bit depth {bits} is not 1..=16")));
    }
    if frames.iter().all(|(_, dn)| dn.is_empty()) {
        return Err(no_data(path, "no pixel to histogram"));
    }
    let levels = 1u32 << bits;
    let nbins = levels.min(256) as usize;
    let per_bin = levels / nbins as u32;
    let max_dn = levels - 1;
    let mut hists = Vec::with_capacity(frames.len());
    for (label, dn) in frames {
        let mut h = vec![0u64; nbins];
        for &v in *dn {
            if u32::from(v) > max_dn {
                return Err(fail(
                    path,
                    format!("frame '{label}' has DN {v} above the {bits}-bit maximum {max_dn}"),
                ));
            }
            h[(u32::from(v) / per_bin) as usize] += 1;
        }
        hists.push(h);
    }
    let top = hists.iter().flatten().copied().max().unwrap_or(1).max(1) as f64;
    const BASE: f64 = 0.5;
    render(path, WIDTH, HEIGHT, None, |root| {
        let body = header(root, title)?;
        let entries: Vec<LegendEntry> = frames
            .iter()
            .enumerate()
            .map(|(i, (label, dn))| LegendEntry {
                label: format!("{label} ({} px)", dn.len()),
                colour: rgb(FRAME_COLOURS[i % FRAME_COLOURS.len()]),
                kind: LegendKind::Fill,
            })
            .collect();
        let body = legend_strip(root, &body, &entries)?;
        let mut chart = ChartBuilder::on(&body)
            .margin(8)
            .margin_right(24)
            .x_label_area_size(40)
            .y_label_area_size(64)
            .build_cartesian_2d(0.0..f64::from(levels), (BASE..top * 2.0).log_scale())?;
        chart
            .configure_mesh()
            .x_desc(format!("DN ({bits}-bit, {per_bin} DN per bin)"))
            .y_desc("pixels per bin")
            .label_style(text(13))
            .axis_desc_style(text(14))
            .x_label_formatter(&|v| fmt_tick(*v))
            .y_label_formatter(&|v| fmt_tick(*v))
            .light_line_style(RGBColor(240, 240, 240))
            .bold_line_style(RGBColor(215, 215, 215))
            .draw()?;
        for (i, h) in hists.iter().enumerate() {
            let colour = rgb(FRAME_COLOURS[i % FRAME_COLOURS.len()]);
            let step = step_outline(h.iter().enumerate().map(|(b, &c)| {
                let x0 = f64::from(b as u32 * per_bin);
                (
                    x0,
                    x0 + f64::from(per_bin),
                    if c == 0 { BASE } else { c as f64 },
                )
            }));
            let mut poly = step.clone();
            poly.push((f64::from(levels), BASE));
            poly.insert(0, (0.0, BASE));
            chart.draw_series(std::iter::once(Polygon::new(
                poly,
                colour.mix(0.25).filled(),
            )))?;
            chart.draw_series(LineSeries::new(step, colour.stroke_width(1)))?;
        }
        Ok(())
    })
}

/// Fig. 17: distribution of the gradient magnitude inside the truth box against outside
/// it, one panel per frame (size [`panel_figure_size`]).
///
/// The gradient is the Prewitt operator on the DN (unnormalised kernels, as the WGE
/// detector uses), its magnitude the L2 norm `√(g_x² + g_y²)` in DN, on interior pixels
/// (the one-pixel border has no 3×3 neighbourhood). WGE thresholds the L1 norm
/// `|g_x| + |g_y|`, which lies between this and √2 times it. Each class is a histogram
/// normalised to fractions of its pixels, 50 bins spaced logarithmically from 1 to the
/// frame's largest magnitude (zero gradients count in the first bin), drawn on a log x
/// axis; the legend gives each class's pixel count and median.
///
/// # Errors
/// [`PlotError`] when there is no frame ("no data"), a frame's `dn` does not hold
/// `width * height` values, a frame is smaller than 3×3, or the file cannot be drawn or
/// written.
pub fn gradient_distribution(frames: &[GradientFrame], path: &Path) -> Result<(), PlotError> {
    if frames.is_empty() {
        return Err(no_data(path, "no frame"));
    }
    const NBINS: usize = 50;
    let mut panels = Vec::with_capacity(frames.len());
    for f in frames {
        check_frame(path, &f.label, f.dn, f.width, f.height)?;
        if f.width < 3 || f.height < 3 {
            return Err(fail(
                path,
                format!(
                    "frame '{}' is {}×{}, smaller than 3×3",
                    f.label, f.width, f.height
                ),
            ));
        }
        let (mut inside, mut outside) = prewitt_l2(f);
        let hi = inside
            .iter()
            .chain(&outside)
            .copied()
            .fold(0.0f64, f64::max)
            .max(10.0);
        let span = hi.ln();
        let hist = |values: &[f64]| {
            let mut h = vec![0.0f64; NBINS];
            for &v in values {
                let b = if v <= 1.0 {
                    0
                } else {
                    ((v.ln() / span * NBINS as f64) as usize).min(NBINS - 1)
                };
                h[b] += 1.0;
            }
            let n = values.len().max(1) as f64;
            h.iter_mut().for_each(|c| *c /= n);
            h
        };
        let (hi_in, hi_out) = (hist(&inside), hist(&outside));
        let (med_in, med_out) = (median(&mut inside), median(&mut outside));
        panels.push((
            hi,
            hi_in,
            hi_out,
            inside.len(),
            outside.len(),
            med_in,
            med_out,
        ));
    }
    let (w, h) = panel_figure_size(frames.len());
    render(path, w, h, None, |root| {
        let body = header(
            root,
            "Gradient magnitude (Prewitt, L2) inside and outside the truth box",
        )?;
        let inside_colour = rgb(overlay::TRUTH_COLOUR);
        let outside_colour = RGBColor(90, 90, 90);
        let entries = [
            LegendEntry {
                label: "inside the truth box".into(),
                colour: inside_colour,
                kind: LegendKind::Fill,
            },
            LegendEntry {
                label: "outside".into(),
                colour: outside_colour,
                kind: LegendKind::Fill,
            },
        ];
        let body = legend_strip(root, &body, &entries)?;
        let (cols, rows) = grid(frames.len());
        let areas = body.split_evenly((rows, cols));
        for (i, (f, p)) in frames.iter().zip(&panels).enumerate() {
            let (hi, h_in, h_out, n_in, n_out, med_in, med_out) = p;
            let ymax = h_in
                .iter()
                .chain(h_out)
                .copied()
                .fold(0.0f64, f64::max)
                .max(1e-3)
                * 1.1;
            let mut chart = ChartBuilder::on(&areas[i])
                .caption(&f.label, text(16))
                .margin(8)
                .margin_right(16)
                .x_label_area_size(40)
                .y_label_area_size(56)
                .build_cartesian_2d((1.0..*hi).log_scale(), 0.0..ymax)?;
            chart
                .configure_mesh()
                .x_desc("gradient magnitude (DN)")
                .x_labels(12)
                .y_desc("fraction of pixels")
                .label_style(text(13))
                .axis_desc_style(text(14))
                .x_label_formatter(&|v| fmt_tick(*v))
                .y_label_formatter(&|v| fmt_tick(*v))
                .light_line_style(RGBColor(240, 240, 240))
                .bold_line_style(RGBColor(215, 215, 215))
                .draw()?;
            let edge = |b: usize| hi.powf(b as f64 / NBINS as f64);
            for (hist, colour) in [(h_out, outside_colour), (h_in, inside_colour)] {
                let step = step_outline(
                    hist.iter()
                        .enumerate()
                        .map(|(b, &v)| (edge(b), edge(b + 1), v)),
                );
                let mut poly = step.clone();
                poly.push((*hi, 0.0));
                poly.insert(0, (1.0, 0.0));
                chart.draw_series(std::iter::once(Polygon::new(
                    poly,
                    colour.mix(0.25).filled(),
                )))?;
                chart.draw_series(LineSeries::new(step, colour.stroke_width(2)))?;
            }
            let (xs, ys) = chart.plotting_area().get_pixel_range();
            let notes = [
                (
                    format!("inside: {n_in} px, median {}", fmt_tick(*med_in)),
                    inside_colour,
                ),
                (
                    format!("outside: {n_out} px, median {}", fmt_tick(*med_out)),
                    outside_colour,
                ),
            ];
            let right = xs.end - 6;
            for (k, (note, colour)) in notes.iter().enumerate() {
                root.draw_text(
                    note,
                    &text(12)
                        .color(&legible(*colour))
                        .pos(Pos::new(HPos::Right, VPos::Top)),
                    (right, ys.start + 4 + 15 * k as i32),
                )?;
            }
        }
        Ok(())
    })
}

/// Prewitt L2 gradient magnitudes of the interior pixels, split into (inside the truth
/// box, outside it).
fn prewitt_l2(f: &GradientFrame) -> (Vec<f64>, Vec<f64>) {
    let (w, h) = (f.width, f.height);
    let mut inside = Vec::with_capacity(f.truth.area() as usize);
    let mut outside = Vec::with_capacity(w * h);
    let rows: Vec<&[u16]> = f.dn.chunks_exact(w).collect();
    for y in 1..h - 1 {
        let (r0, r1, r2) = (rows[y - 1], rows[y], rows[y + 1]);
        for x in 1..w - 1 {
            let v = |r: &[u16], i: usize| i32::from(r[i]);
            let gx = v(r0, x + 1) + v(r1, x + 1) + v(r2, x + 1)
                - v(r0, x - 1)
                - v(r1, x - 1)
                - v(r2, x - 1);
            let gy =
                v(r2, x - 1) + v(r2, x) + v(r2, x + 1) - v(r0, x - 1) - v(r0, x) - v(r0, x + 1);
            let m = (f64::from(gx) * f64::from(gx) + f64::from(gy) * f64::from(gy)).sqrt();
            let is_in = x <= usize::from(u16::MAX)
                && y <= usize::from(u16::MAX)
                && f.truth.contains(x as u16, y as u16);
            if is_in {
                inside.push(m);
            } else {
                outside.push(m);
            }
        }
    }
    (inside, outside)
}
