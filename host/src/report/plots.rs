//! PNG figures of the evaluation, after the paper's Figs. 10–17: IoU against distance
//! (Figs. 10, 14), DN histograms (Fig. 12), gradient distributions inside and outside
//! the truth box (Fig. 17), example frames with boxes (Figs. 11, 13, 16), and run time
//! against IoU with its Pareto front.
//!
//! Drawing: plotters' bitmap backend renders into an RGB buffer, which the `image`
//! crate writes as PNG (plotters' own encoder would pull a second copy of `image`).
//! Text uses DejaVu Sans, embedded in the binary (`host/assets/DejaVuSans.ttf`, Bitstream
//! Vera licence beside it) through plotters' `ab_glyph` feature, so no system font is
//! read and the same input gives the same bytes on every machine.
//!
//! Sizes: single-panel figures are [`WIDTH`]×[`HEIGHT`] (800×500); figures with one
//! panel per group or frame are [`panel_figure_size`]; the example grid's size follows
//! its frames (see [`example_grid`]).
//!
//! Colours: truth [`overlay::TRUTH_COLOUR`]; the methods `otsu`, `adaptive`, `wge`, `dog`
//! (names compared without case) take [`overlay::METHOD_COLOURS`] in that order, and any
//! other method name takes the next of [`EXTRA_METHOD_COLOURS`] in order of first
//! appearance in the input. Legends list the four known methods first, in that order,
//! then the others by first appearance.
//!
//! Empty input (no point, no frame, or only non-finite values) is an error
//! ([`PlotError`] saying "no data") and no file is written: a figure without data is
//! the caller's decision, not a silent placeholder.

use std::error::Error;
use std::fmt;
use std::path::Path;
use std::sync::OnceLock;

use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{ExtendedColorType, ImageEncoder, RgbImage};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::register_font;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use tirroi_core::Roi;

use crate::eval::bank::median;
use crate::imaging::image_io::FrameBuf;
use crate::imaging::overlay;

/// Width of single-panel figures, px.
pub const WIDTH: u32 = 800;
/// Height of single-panel figures, px.
pub const HEIGHT: u32 = 500;

/// Colours of method names other than the four detectors, by first appearance (cycled).
pub const EXTRA_METHOD_COLOURS: [[u8; 3]; 4] =
    [[0, 170, 170], [120, 75, 30], [110, 110, 110], [0, 110, 0]];

/// Colours of the frames of [`intensity_histogram`], in order (cycled).
const FRAME_COLOURS: [[u8; 3]; 6] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
];

/// The embedded font: DejaVu Sans 2.37 (Bitstream Vera licence, see
/// `host/assets/DejaVuSans-LICENSE.txt`).
const FONT_BYTES: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");
const FONT_FAMILY: &str = "sans-serif";

/// Why a figure could not be drawn or written; the message names the file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlotError(pub String);

impl fmt::Display for PlotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl Error for PlotError {}

/// One point of IoU against distance: one frame scored by one method.
#[derive(Debug, Clone, PartialEq)]
pub struct IouPoint {
    /// Method name (`otsu`, `adaptive`, `wge`, `dog`, or any other).
    pub method: String,
    /// Panel the point belongs to, e.g. `mono`, `scale 1`.
    pub group: String,
    /// Camera–target distance, m.
    pub range_m: f64,
    /// IoU of the method's box with the truth box, 0..=1.
    pub iou: f64,
}

/// One frame of [`gradient_distribution`].
#[derive(Debug, Clone, PartialEq)]
pub struct GradientFrame<'a> {
    /// Panel title.
    pub label: String,
    /// DN, row-major, `width * height` values.
    pub dn: &'a [u16],
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// The truth box: its pixels are "inside", all others "outside".
    pub truth: Roi,
}

/// One frame of [`example_grid`].
#[derive(Debug, Clone, PartialEq)]
pub struct ExampleFrame<'a> {
    /// Caption under the frame, e.g. `(a) multi-material 1, 23 m`.
    pub caption: String,
    /// DN, row-major, `width * height` values.
    pub dn: &'a [u16],
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// The truth box.
    pub truth: Roi,
    /// Each method's box (`None`: the method found nothing), drawn in the method's colour.
    pub boxes: Vec<(String, Option<Roi>)>,
}

/// One (method, parameter set) of [`runtime_against_iou`].
#[derive(Debug, Clone, PartialEq)]
pub struct TradeoffPoint {
    /// Method name.
    pub method: String,
    /// The parameter set, as a short label (drawn next to Pareto-optimal points).
    pub params: String,
    /// Mean run time, ms.
    pub mean_time_ms: f64,
    /// Mean IoU, 0..=1.
    pub mean_iou: f64,
}

/// Size of a figure with `panels` panels (one per group or frame): up to three panels
/// per row; 800 px wide for one or two columns, 960 for three; 500 px high for one row
/// and 436 px more per further row.
pub fn panel_figure_size(panels: usize) -> (u32, u32) {
    let (cols, rows) = grid(panels);
    let width = if cols <= 2 { WIDTH } else { 320 * cols as u32 };
    (width, HEIGHT + 436 * (rows as u32 - 1))
}

fn grid(panels: usize) -> (usize, usize) {
    let panels = panels.max(1);
    let cols = panels.min(3);
    (cols, panels.div_ceil(cols))
}

/// Figs. 10 and 14: mean IoU against camera–target distance, one panel per group (in
/// order of first appearance), one line per method with markers; y from 0 to 1.
///
/// Distances are binned: 5 m bins for a data span from 15 m to 100 m, otherwise the
/// 1-2-5 step giving at most 10 (narrower spans) or 20 (wider spans) bins; bin edges are
/// multiples of the step, all panels share them, and each bin's mean is drawn at its
/// centre. Lines break across empty bins. Points with a non-finite distance or IoU are
/// left out. The figure's size is [`panel_figure_size`] of the number of groups.
///
/// # Errors
/// [`PlotError`] when no point is left ("no data") or the file cannot be drawn or
/// written.
pub fn iou_against_distance(
    points: &[IouPoint],
    title: &str,
    path: &Path,
) -> Result<(), PlotError> {
    let points: Vec<&IouPoint> = points
        .iter()
        .filter(|p| p.range_m.is_finite() && p.iou.is_finite())
        .collect();
    if points.is_empty() {
        return Err(no_data(path, "no IoU point with a finite distance and IoU"));
    }
    let palette = Palette::new(points.iter().map(|p| p.method.as_str()));
    let mut groups: Vec<&str> = Vec::new();
    for p in &points {
        if !groups.contains(&p.group.as_str()) {
            groups.push(&p.group);
        }
    }
    let (lo_r, hi_r) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
            (a.0.min(p.range_m), a.1.max(p.range_m))
        });
    let bins = Bins::new(lo_r, hi_r);
    // sums[group][method][bin] = (sum of IoU, count)
    let mut sums = vec![vec![vec![(0.0f64, 0u32); bins.n]; palette.len()]; groups.len()];
    for p in &points {
        let g = groups.iter().position(|g| *g == p.group).unwrap_or(0);
        let m = palette.index(&p.method);
        let cell = &mut sums[g][m][bins.index(p.range_m)];
        cell.0 += p.iou;
        cell.1 += 1;
    }
    let (w, h) = panel_figure_size(groups.len());
    render(path, w, h, None, |root| {
        let body = header(root, title)?;
        let entries: Vec<LegendEntry> = palette
            .names
            .iter()
            .enumerate()
            .map(|(i, name)| LegendEntry {
                label: name.clone(),
                colour: palette.colours[i],
                kind: LegendKind::LineMarker(i),
            })
            .collect();
        let body = legend_strip(root, &body, &entries)?;
        let (cols, rows) = grid(groups.len());
        let panels = body.split_evenly((rows, cols));
        for (g, name) in groups.iter().enumerate() {
            let mut chart = ChartBuilder::on(&panels[g])
                .caption(*name, text(16))
                .margin(8)
                .margin_right(16)
                .x_label_area_size(40)
                .y_label_area_size(48)
                .build_cartesian_2d(bins.lo..bins.hi(), 0.0..1.0)?;
            chart
                .configure_mesh()
                .x_desc("camera–target distance (m)")
                .x_labels(if cols >= 3 { 6 } else { 10 })
                .y_desc("mean IoU")
                .label_style(text(13))
                .axis_desc_style(text(14))
                .x_label_formatter(&|v| fmt_tick(*v))
                .y_label_formatter(&|v| format!("{v:.1}"))
                .light_line_style(RGBColor(240, 240, 240))
                .bold_line_style(RGBColor(215, 215, 215))
                .draw()?;
            for (m, per_bin) in sums[g].iter().enumerate() {
                let colour = palette.colours[m];
                let mut run: Vec<(f64, f64)> = Vec::new();
                let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
                for (b, &(sum, n)) in per_bin.iter().enumerate() {
                    if n == 0 {
                        if !run.is_empty() {
                            runs.push(std::mem::take(&mut run));
                        }
                    } else {
                        run.push((bins.centre(b), sum / f64::from(n)));
                    }
                }
                if !run.is_empty() {
                    runs.push(run);
                }
                for run in &runs {
                    chart.draw_series(LineSeries::new(
                        run.iter().copied(),
                        colour.stroke_width(2),
                    ))?;
                    for p in run {
                        marker(root, chart.backend_coord(p), m, colour)?;
                    }
                }
            }
        }
        Ok(())
    })
}

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

/// Figs. 11, 13, 16: example frames side by side (one column per frame), each
/// contrast-stretched to gray ([`overlay::frame_with_boxes`]) with the truth box and each
/// method's box in its colour, the caption under it, then one line per method with its
/// IoU against the truth (or "no box"), and a legend strip at the bottom.
///
/// Frames are magnified by the largest integer factor (1 to 8) that keeps each column
/// within `max(900 / frames, 260)` px and 600 px high. The figure is the columns side by
/// side with 12 px gaps (at least 400 px and the legend's width wide); its height is the
/// tallest frame plus 46 px of caption, 18 px per method line of the frame with most
/// boxes, and 44 px of legend. Text too wide for its column is set smaller (down to
/// 11 px), then cut with "…".
///
/// # Errors
/// [`PlotError`] when there is no frame ("no data"), a frame's `dn` does not hold
/// `width * height` values or is empty, or the file cannot be drawn or written.
pub fn example_grid(frames: &[ExampleFrame], path: &Path) -> Result<(), PlotError> {
    if frames.is_empty() {
        return Err(no_data(path, "no frame"));
    }
    for f in frames {
        check_frame(path, &f.caption, f.dn, f.width, f.height)?;
        if f.dn.is_empty() {
            return Err(fail(path, format!("frame '{}' is empty", f.caption)));
        }
    }
    let palette = Palette::new(
        frames
            .iter()
            .flat_map(|f| f.boxes.iter().map(|(m, _)| m.as_str())),
    );
    let cell_w = (900 / frames.len()).max(260);
    let images: Vec<RgbImage> = frames
        .iter()
        .map(|f| {
            let scale = (cell_w / f.width).min(600 / f.height).clamp(1, 8) as u32;
            let frame = FrameBuf {
                pixels: f.dn.to_vec(),
                width: f.width,
                height: f.height,
                bits: 16,
            };
            let mut boxes = vec![(f.truth, overlay::TRUTH_COLOUR)];
            for (m, roi) in &f.boxes {
                if let Some(roi) = roi {
                    boxes.push((*roi, palette.rgb(m)));
                }
            }
            overlay::frame_with_boxes(&frame, &boxes, scale)
        })
        .collect();
    const GAP: u32 = 12;
    const LINE: u32 = 18;
    let lines = frames.iter().map(|f| f.boxes.len()).max().unwrap_or(0) as u32;
    let frame_h = images.iter().map(|i| i.height()).max().unwrap_or(0);
    let cols_w: u32 =
        images.iter().map(|i| i.width().max(180)).sum::<u32>() + GAP * (images.len() as u32 + 1);
    let mut entries = vec![LegendEntry {
        label: "truth".into(),
        colour: rgb(overlay::TRUTH_COLOUR),
        kind: LegendKind::Box,
    }];
    entries.extend(palette.names.iter().enumerate().map(|(i, n)| LegendEntry {
        label: n.clone(),
        colour: palette.colours[i],
        kind: LegendKind::Box,
    }));
    ensure_font().map_err(|e| fail(path, e))?;
    let legend_w = legend_width(&entries);
    let width = cols_w.max(400).max(legend_w + 2 * GAP);
    let height = GAP + frame_h + 46 + LINE * lines + 44;
    let mut canvas = RgbImage::from_pixel(width, height, image::Rgb([255, 255, 255]));
    let mut lefts = Vec::with_capacity(images.len());
    let mut x = GAP;
    for img in &images {
        let col_w = img.width().max(180);
        let left = x + (col_w - img.width()) / 2;
        image::imageops::replace(&mut canvas, img, i64::from(left), i64::from(GAP));
        lefts.push((x, col_w));
        x += col_w + GAP;
    }
    render(path, width, height, Some(canvas.into_raw()), |root| {
        for ((f, &(left, col_w)), img) in frames.iter().zip(&lefts).zip(&images) {
            let cx = (left + col_w / 2) as i32;
            let y = (GAP + img.height() + 8) as i32;
            let (caption, size) = fit_text(&f.caption, 15, col_w.saturating_sub(4));
            root.draw_text(
                &caption,
                &text(size).pos(Pos::new(HPos::Center, VPos::Top)),
                (cx, y),
            )?;
            for (k, (m, roi)) in f.boxes.iter().enumerate() {
                let colour = palette.colour(m);
                let y = (GAP + frame_h + 38 + LINE * k as u32) as i32;
                let x0 = left as i32 + 4;
                root.draw(&Rectangle::new(
                    [(x0, y + 2), (x0 + 11, y + 13)],
                    colour.stroke_width(2),
                ))?;
                let line = match roi {
                    Some(r) => format!("{m}: IoU {:.2}", r.iou(&f.truth)),
                    None => format!("{m}: no box"),
                };
                let (line, size) = fit_text(&line, 13, col_w.saturating_sub(26));
                root.draw_text(&line, &text(size), (x0 + 18, y))?;
            }
        }
        let top = (height - 36) as i32;
        root.draw(&PathElement::new(
            vec![(GAP as i32, top), ((width - GAP) as i32, top)],
            RGBColor(200, 200, 200),
        ))?;
        let x0 = ((width - legend_w) / 2) as i32;
        draw_legend(root, x0, top + 10, &entries)?;
        Ok(())
    })
}

/// Run time against IoU: one point per (method, parameter set), x the mean time in ms
/// on a log axis, y the mean IoU (0 to 1), colour and marker per method; the Pareto
/// front ([`pareto_front`]) is a black step line through its points, each circled and
/// labelled `method params` where the label overlaps no other front point or label.
/// Points with a non-finite time or IoU are left out; times ≤ 0 are drawn at the axis'
/// left end. 800×500.
///
/// # Errors
/// [`PlotError`] when no point is left ("no data") or the file cannot be drawn or
/// written.
pub fn runtime_against_iou(
    points: &[TradeoffPoint],
    title: &str,
    path: &Path,
) -> Result<(), PlotError> {
    let kept: Vec<&TradeoffPoint> = points
        .iter()
        .filter(|p| p.mean_time_ms.is_finite() && p.mean_iou.is_finite())
        .collect();
    if kept.is_empty() {
        return Err(no_data(path, "no point with a finite time and IoU"));
    }
    let palette = Palette::new(kept.iter().map(|p| p.method.as_str()));
    let front = pareto_front(points);
    let positive = kept
        .iter()
        .map(|p| p.mean_time_ms)
        .filter(|&t| t > 0.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, t| {
            (a.0.min(t), a.1.max(t))
        });
    let (t_lo, t_hi) = if positive.0.is_finite() {
        (positive.0 / 1.6, positive.1 * 1.6)
    } else {
        (1e-3, 1.0)
    };
    let (t_lo, t_hi) = if t_hi / t_lo < 10.0 {
        let mid = (t_lo * t_hi).sqrt();
        (mid / 10f64.sqrt(), mid * 10f64.sqrt())
    } else {
        (t_lo, t_hi)
    };
    let x_of = |t: f64| t.max(t_lo);
    render(path, WIDTH, HEIGHT, None, |root| {
        let body = header(root, title)?;
        let mut entries: Vec<LegendEntry> = palette
            .names
            .iter()
            .enumerate()
            .map(|(i, name)| LegendEntry {
                label: name.clone(),
                colour: palette.colours[i],
                kind: LegendKind::Marker(i),
            })
            .collect();
        entries.push(LegendEntry {
            label: "Pareto front".into(),
            colour: BLACK,
            kind: LegendKind::Front,
        });
        let body = legend_strip(root, &body, &entries)?;
        let mut chart = ChartBuilder::on(&body)
            .margin(8)
            .margin_right(24)
            .x_label_area_size(40)
            .y_label_area_size(52)
            .build_cartesian_2d((t_lo..t_hi).log_scale(), 0.0..1.0)?;
        chart
            .configure_mesh()
            .x_desc("mean run time (ms, log scale)")
            .x_labels(12)
            .y_desc("mean IoU")
            .label_style(text(13))
            .axis_desc_style(text(14))
            .x_label_formatter(&|v| fmt_tick(*v))
            .y_label_formatter(&|v| format!("{v:.1}"))
            .light_line_style(RGBColor(240, 240, 240))
            .bold_line_style(RGBColor(215, 215, 215))
            .draw()?;
        let mut step: Vec<(f64, f64)> = Vec::new();
        for &i in &front {
            let p = &points[i];
            if let Some(&(_, last_y)) = step.last() {
                step.push((x_of(p.mean_time_ms), last_y));
            }
            step.push((x_of(p.mean_time_ms), p.mean_iou));
        }
        chart.draw_series(LineSeries::new(step, BLACK.stroke_width(2)))?;
        for p in &kept {
            let m = palette.index(&p.method);
            let at = chart.backend_coord(&(x_of(p.mean_time_ms), p.mean_iou));
            marker(root, at, m, palette.colours[m])?;
        }
        let (xs, ys) = chart.plotting_area().get_pixel_range();
        let mut placed: Vec<[i32; 4]> = Vec::new();
        for &i in &front {
            let p = &points[i];
            let at = chart.backend_coord(&(x_of(p.mean_time_ms), p.mean_iou));
            root.draw(&Circle::new(at, 8, BLACK.stroke_width(2)))?;
            placed.push([at.0 - 9, at.1 - 9, at.0 + 9, at.1 + 9]);
        }
        // Labels where they overlap neither a front point nor another label, else none.
        for &i in &front {
            let p = &points[i];
            let at = chart.backend_coord(&(x_of(p.mean_time_ms), p.mean_iou));
            let label = format!("{} {}", p.method, p.params);
            let label = label.trim();
            let (tw, th) = text(12).font.box_size(label).unwrap_or((0, 12));
            let (tw, th) = (tw as i32, th as i32);
            let spots = [
                (at.0 + 10, at.1 - 8 - th),
                (at.0 + 10, at.1 + 8),
                (at.0 - 10 - tw, at.1 - 8 - th),
                (at.0 - 10 - tw, at.1 + 8),
            ];
            let free = spots
                .into_iter()
                .map(|(x, y)| [x, y, x + tw, y + th])
                .find(|r| {
                    r[0] >= xs.start
                        && r[2] <= xs.end
                        && r[1] >= ys.start
                        && r[3] <= ys.end
                        && placed
                            .iter()
                            .all(|q| r[2] <= q[0] || q[2] <= r[0] || r[3] <= q[1] || q[3] <= r[1])
                });
            if let Some(r) = free {
                root.draw_text(label, &text(12), (r[0], r[1]))?;
                placed.push(r);
            }
        }
        Ok(())
    })
}

/// The Pareto-optimal points, as indices into `points`, sorted by time (then by index).
///
/// A point is Pareto-optimal when no other point is at least as fast and at least as
/// accurate and strictly better in one of the two (lower `mean_time_ms` or higher
/// `mean_iou`); exact duplicates of an optimal point are all optimal. Points with a
/// non-finite time or IoU are never optimal and never dominate. O(n log n).
pub fn pareto_front(points: &[TradeoffPoint]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len())
        .filter(|&i| points[i].mean_time_ms.is_finite() && points[i].mean_iou.is_finite())
        .collect();
    order.sort_by(|&a, &b| {
        let (pa, pb) = (&points[a], &points[b]);
        pa.mean_time_ms
            .total_cmp(&pb.mean_time_ms)
            .then(pb.mean_iou.total_cmp(&pa.mean_iou))
            .then(a.cmp(&b))
    });
    let mut front = Vec::new();
    let mut best = f64::NEG_INFINITY;
    let mut k = 0;
    while k < order.len() {
        // One run of equal times: its first point has the run's best IoU.
        let t = points[order[k]].mean_time_ms;
        let top = points[order[k]].mean_iou;
        let mut end = k;
        while end < order.len() && points[order[end]].mean_time_ms == t {
            end += 1;
        }
        if top > best {
            front.extend(
                order[k..end]
                    .iter()
                    .copied()
                    .filter(|&i| points[i].mean_iou == top),
            );
            best = top;
        }
        k = end;
    }
    front
}

// ---------------------------------------------------------------------------------------
// Shared drawing helpers.

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
type DrawResult = Result<(), Box<dyn Error>>;

fn fail(path: &Path, what: impl fmt::Display) -> PlotError {
    PlotError(format!("{}: {what}", path.display()))
}

fn no_data(path: &Path, what: &str) -> PlotError {
    fail(path, format!("no data ({what})"))
}

fn check_frame(path: &Path, label: &str, dn: &[u16], w: usize, h: usize) -> Result<(), PlotError> {
    if w.checked_mul(h) != Some(dn.len()) {
        return Err(fail(
            path,
            format!("frame '{label}' holds {} DN, not {w}×{h}", dn.len()),
        ));
    }
    Ok(())
}

fn ensure_font() -> Result<(), String> {
    static FONT: OnceLock<Result<(), String>> = OnceLock::new();
    FONT.get_or_init(|| {
        register_font(FONT_FAMILY, FontStyle::Normal, FONT_BYTES)
            .map_err(|_| "the embedded font is not a valid TrueType font".to_string())
    })
    .clone()
}

/// Draws a `w`×`h` figure over `background` (RGB, or white), then writes it as PNG.
fn render(
    path: &Path,
    w: u32,
    h: u32,
    background: Option<Vec<u8>>,
    draw: impl FnOnce(&Area) -> DrawResult,
) -> Result<(), PlotError> {
    ensure_font().map_err(|e| fail(path, e))?;
    let filled = background.is_some();
    let mut buf = background.unwrap_or_else(|| vec![255u8; w as usize * h as usize * 3]);
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        if !filled {
            root.fill(&WHITE).map_err(|e| fail(path, e))?;
        }
        draw(&root).map_err(|e| fail(path, format!("cannot draw: {e}")))?;
        root.present().map_err(|e| fail(path, e))?;
    }
    // Flat colours and thin lines compress several times better with full zlib than
    // with `image`'s default (fast) setting, at a few milliseconds per figure.
    let mut png = Vec::new();
    PngEncoder::new_with_quality(&mut png, CompressionType::Default, FilterType::Adaptive)
        .write_image(&buf, w, h, ExtendedColorType::Rgb8)
        .map_err(|e| fail(path, format!("cannot encode: {e}")))?;
    std::fs::write(path, png).map_err(|e| fail(path, format!("cannot write: {e}")))
}

fn text(size: u32) -> TextStyle<'static> {
    TextStyle::from((FONT_FAMILY, size).into_font()).color(&BLACK)
}

/// `s` in the largest font size from `size` down to 11 px that fits `max_w` px, else
/// cut and ended with "…" at 11 px.
fn fit_text(s: &str, size: u32, max_w: u32) -> (String, u32) {
    let width = |t: &str, z: u32| text(z).font.box_size(t).map_or(u32::MAX, |b| b.0);
    for z in (11..=size.max(11)).rev() {
        if width(s, z) <= max_w {
            return (s.to_string(), z);
        }
    }
    let mut cut: String = s.to_string();
    while cut.pop().is_some() {
        let t = format!("{}…", cut.trim_end());
        if width(&t, 11) <= max_w {
            return (t, 11);
        }
    }
    (String::new(), 11)
}

/// `c` darkened, when light, to read as text on white.
fn legible(c: RGBColor) -> RGBColor {
    let RGBColor(r, g, b) = c;
    let luma = (299 * u32::from(r) + 587 * u32::from(g) + 114 * u32::from(b)) / 1000;
    if luma <= 90 {
        return c;
    }
    let k = |v: u8| (u32::from(v) * 90 / luma) as u8;
    RGBColor(k(r), k(g), k(b))
}

fn rgb(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

/// Draws the title and returns the area below it.
fn header<'a>(root: &Area<'a>, title: &str) -> Result<Area<'a>, Box<dyn Error>> {
    let (w, _) = root.dim_in_pixel();
    root.draw_text(
        title,
        &text(20).pos(Pos::new(HPos::Center, VPos::Top)),
        (w as i32 / 2, 8),
    )?;
    Ok(root.split_vertically(36).1)
}

/// How a legend entry is drawn.
#[derive(Clone, Copy)]
enum LegendKind {
    /// A line through a marker of this kind.
    LineMarker(usize),
    /// A marker of this kind.
    Marker(usize),
    /// A filled square.
    Fill,
    /// A square outline (a box).
    Box,
    /// A line through a circled point.
    Front,
}

struct LegendEntry {
    label: String,
    colour: RGBColor,
    kind: LegendKind,
}

const SWATCH: i32 = 26;
const ENTRY_GAP: i32 = 22;

fn legend_width(entries: &[LegendEntry]) -> u32 {
    entries
        .iter()
        .map(|e| (SWATCH + 6 + ENTRY_GAP) as u32 + text_size(&e.label).0)
        .sum::<u32>()
        .saturating_sub(ENTRY_GAP as u32)
}

/// Text width and height, px, in the legend font.
fn text_size(s: &str) -> (u32, u32) {
    text(14)
        .font
        .box_size(s)
        .unwrap_or((8 * s.len() as u32, 14))
}

/// Draws the legend centred in a 28 px strip at the top of `body`; returns the rest.
fn legend_strip<'a>(
    root: &Area<'a>,
    body: &Area<'a>,
    entries: &[LegendEntry],
) -> Result<Area<'a>, Box<dyn Error>> {
    let (x_range, y_range) = body.get_pixel_range();
    let width = legend_width(entries) as i32;
    let x0 = (x_range.start + x_range.end - width) / 2;
    draw_legend(root, x0.max(x_range.start + 4), y_range.start + 4, entries)?;
    Ok(body.split_vertically(28).1)
}

fn draw_legend(root: &Area, x0: i32, y: i32, entries: &[LegendEntry]) -> DrawResult {
    let mut x = x0;
    let mid = y + 9;
    for e in entries {
        let c = e.colour;
        match e.kind {
            LegendKind::LineMarker(k) => {
                root.draw(&PathElement::new(
                    vec![(x, mid), (x + SWATCH, mid)],
                    c.stroke_width(2),
                ))?;
                marker(root, (x + SWATCH / 2, mid), k, c)?;
            }
            LegendKind::Marker(k) => marker(root, (x + SWATCH / 2, mid), k, c)?,
            LegendKind::Fill => {
                root.draw(&Rectangle::new(
                    [(x + 4, mid - 8), (x + SWATCH - 4, mid + 8)],
                    c.mix(0.35).filled(),
                ))?;
                root.draw(&Rectangle::new(
                    [(x + 4, mid - 8), (x + SWATCH - 4, mid + 8)],
                    c.stroke_width(2),
                ))?;
            }
            LegendKind::Box => {
                root.draw(&Rectangle::new(
                    [(x + 5, mid - 7), (x + SWATCH - 5, mid + 7)],
                    c.stroke_width(2),
                ))?;
            }
            LegendKind::Front => {
                root.draw(&PathElement::new(
                    vec![(x, mid), (x + SWATCH, mid)],
                    c.stroke_width(2),
                ))?;
                root.draw(&Circle::new((x + SWATCH / 2, mid), 7, c.stroke_width(2)))?;
            }
        }
        root.draw_text(
            &e.label,
            &text(14).pos(Pos::new(HPos::Left, VPos::Center)),
            (x + SWATCH + 6, mid),
        )?;
        x += SWATCH + 6 + text_size(&e.label).0 as i32 + ENTRY_GAP;
    }
    Ok(())
}

/// A filled marker of kind `k` (circle, triangle, square, diamond, cross; cycled) at a
/// pixel of `root`.
fn marker(root: &Area, at: (i32, i32), k: usize, c: RGBColor) -> DrawResult {
    let (x, y) = at;
    let fill = c.filled();
    match k % 5 {
        0 => root.draw(&Circle::new(at, 4, fill))?,
        1 => root.draw(&TriangleMarker::new(at, 6, fill))?,
        2 => root.draw(&Rectangle::new([(x - 4, y - 4), (x + 4, y + 4)], fill))?,
        3 => root.draw(&Polygon::new(
            vec![(x, y - 5), (x + 5, y), (x, y + 5), (x - 5, y)],
            fill,
        ))?,
        _ => root.draw(&Cross::new(at, 4, c.stroke_width(2)))?,
    }
    Ok(())
}

/// The outline of a step histogram: for each bin `(from, to, value)`, a flat segment.
fn step_outline(bins: impl Iterator<Item = (f64, f64, f64)>) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for (x0, x1, v) in bins {
        out.push((x0, v));
        out.push((x1, v));
    }
    out
}

/// Tick label: up to four significant digits, no trailing zeros, no exponent.
fn fmt_tick(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return "0".into();
    }
    let digits = (3 - v.abs().log10().floor() as i32).clamp(0, 6) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
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

/// Method names → colours: the four detectors first in their fixed order, then other
/// names by first appearance.
struct Palette {
    names: Vec<String>,
    colours: Vec<RGBColor>,
}

const KNOWN_METHODS: [&str; 4] = ["otsu", "adaptive", "wge", "dog"];

impl Palette {
    fn new<'a>(names: impl Iterator<Item = &'a str>) -> Palette {
        let mut known = [false; 4];
        let mut extra: Vec<String> = Vec::new();
        for n in names {
            match known_index(n) {
                Some(k) => known[k] = true,
                None => {
                    if !extra.iter().any(|e| e == n) {
                        extra.push(n.to_string());
                    }
                }
            }
        }
        let mut p = Palette {
            names: Vec::new(),
            colours: Vec::new(),
        };
        for (k, name) in KNOWN_METHODS.iter().enumerate() {
            if known[k] {
                p.names.push((*name).to_string());
                p.colours.push(rgb(overlay::METHOD_COLOURS[k]));
            }
        }
        for (i, name) in extra.into_iter().enumerate() {
            p.names.push(name);
            p.colours
                .push(rgb(EXTRA_METHOD_COLOURS[i % EXTRA_METHOD_COLOURS.len()]));
        }
        p
    }

    fn len(&self) -> usize {
        self.names.len()
    }

    /// Index of a method name (known names matched without case).
    fn index(&self, name: &str) -> usize {
        let key = match known_index(name) {
            Some(k) => KNOWN_METHODS[k],
            None => name,
        };
        self.names.iter().position(|n| n == key).unwrap_or(0)
    }

    fn colour(&self, name: &str) -> RGBColor {
        self.colours.get(self.index(name)).copied().unwrap_or(BLACK)
    }

    fn rgb(&self, name: &str) -> [u8; 3] {
        let RGBColor(r, g, b) = self.colour(name);
        [r, g, b]
    }
}

fn known_index(name: &str) -> Option<usize> {
    KNOWN_METHODS
        .iter()
        .position(|k| k.eq_ignore_ascii_case(name.trim()))
}

/// Distance bins: edges `lo + k·step`, `n` bins.
struct Bins {
    lo: f64,
    step: f64,
    n: usize,
}

impl Bins {
    fn new(min: f64, max: f64) -> Bins {
        let span = max - min;
        let step = if (15.0..=100.0).contains(&span) {
            5.0
        } else if span > 100.0 {
            nice_step(span / 20.0)
        } else if span > 0.0 {
            nice_step(span / 10.0)
        } else {
            5.0
        };
        let lo = (min / step).floor() * step;
        let n = (((max - lo) / step).ceil() as usize).max(1);
        Bins { lo, step, n }
    }

    fn hi(&self) -> f64 {
        self.lo + self.step * self.n as f64
    }

    fn index(&self, r: f64) -> usize {
        (((r - self.lo) / self.step).floor().max(0.0) as usize).min(self.n - 1)
    }

    fn centre(&self, b: usize) -> f64 {
        self.lo + self.step * (b as f64 + 0.5)
    }
}

/// Smallest step of the form {1, 2, 5}·10^k that is at least `raw`.
fn nice_step(raw: f64) -> f64 {
    let mag = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * mag)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * mag)
}
