//! Figs. 10 and 14: mean IoU against camera–target distance.

use std::path::Path;

use plotters::prelude::*;

use super::draw::{
    LegendEntry, LegendKind, Palette, fmt_tick, header, legend_strip, marker, nice_step, no_data,
    render, text,
};
use super::{IouPoint, PlotError, grid, panel_figure_size};

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
