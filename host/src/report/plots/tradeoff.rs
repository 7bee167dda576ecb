//! Run time against IoU, one point per (method, parameter set), with the Pareto front.

use std::path::Path;

use plotters::prelude::*;

use super::draw::{
    LegendEntry, LegendKind, Palette, fmt_tick, header, legend_strip, marker, no_data, render, text,
};
use super::{HEIGHT, PlotError, TradeoffPoint, WIDTH};

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
