//! Figs. 11, 13, 16: example frames side by side with their boxes.

use std::path::Path;

use image::RgbImage;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::draw::{
    LegendEntry, LegendKind, Palette, check_frame, draw_legend, ensure_font, fail, fit_text,
    legend_width, no_data, render, rgb, text,
};
use super::{ExampleFrame, PlotError};
use crate::imaging::image_io::FrameBuf;
use crate::imaging::overlay;

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
