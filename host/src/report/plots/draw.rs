//! Drawing helpers shared by every figure: the font, titles, legends, markers, ticks,
//! the method palette and the PNG writer.

use std::error::Error;
use std::fmt;
use std::path::Path;
use std::sync::OnceLock;

use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{ExtendedColorType, ImageEncoder};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::register_font;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use tirroi_core::Method;

use super::{EXTRA_METHOD_COLOURS, FONT_BYTES, FONT_FAMILY, PlotError};
use crate::imaging::overlay;

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
type DrawResult = Result<(), Box<dyn Error>>;

pub(super) fn fail(path: &Path, what: impl fmt::Display) -> PlotError {
    PlotError(format!("{}: {what}", path.display()))
}

pub(super) fn no_data(path: &Path, what: &str) -> PlotError {
    fail(path, format!("no data ({what})"))
}

pub(super) fn check_frame(
    path: &Path,
    label: &str,
    dn: &[u16],
    w: usize,
    h: usize,
) -> Result<(), PlotError> {
    if w.checked_mul(h) != Some(dn.len()) {
        return Err(fail(
            path,
            format!("frame '{label}' holds {} DN, not {w}×{h}", dn.len()),
        ));
    }
    Ok(())
}

pub(super) fn ensure_font() -> Result<(), String> {
    static FONT: OnceLock<Result<(), String>> = OnceLock::new();
    FONT.get_or_init(|| {
        register_font(FONT_FAMILY, FontStyle::Normal, FONT_BYTES)
            .map_err(|_| "the embedded font is not a valid TrueType font".to_string())
    })
    .clone()
}

/// Draws a `w`×`h` figure over `background` (RGB, or white), then writes it as PNG.
pub(super) fn render(
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

pub(super) fn text(size: u32) -> TextStyle<'static> {
    TextStyle::from((FONT_FAMILY, size).into_font()).color(&BLACK)
}

/// `s` in the largest font size from `size` down to 11 px that fits `max_w` px, else
/// cut and ended with "…" at 11 px.
pub(super) fn fit_text(s: &str, size: u32, max_w: u32) -> (String, u32) {
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
pub(super) fn legible(c: RGBColor) -> RGBColor {
    let RGBColor(r, g, b) = c;
    let luma = (299 * u32::from(r) + 587 * u32::from(g) + 114 * u32::from(b)) / 1000;
    if luma <= 90 {
        return c;
    }
    let k = |v: u8| (u32::from(v) * 90 / luma) as u8;
    RGBColor(k(r), k(g), k(b))
}

pub(super) fn rgb(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

/// Draws the title and returns the area below it.
pub(super) fn header<'a>(root: &Area<'a>, title: &str) -> Result<Area<'a>, Box<dyn Error>> {
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
pub(super) enum LegendKind {
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

pub(super) struct LegendEntry {
    pub(super) label: String,
    pub(super) colour: RGBColor,
    pub(super) kind: LegendKind,
}

const SWATCH: i32 = 26;
const ENTRY_GAP: i32 = 22;

pub(super) fn legend_width(entries: &[LegendEntry]) -> u32 {
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
pub(super) fn legend_strip<'a>(
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

pub(super) fn draw_legend(root: &Area, x0: i32, y: i32, entries: &[LegendEntry]) -> DrawResult {
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
pub(super) fn marker(root: &Area, at: (i32, i32), k: usize, c: RGBColor) -> DrawResult {
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
pub(super) fn step_outline(bins: impl Iterator<Item = (f64, f64, f64)>) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for (x0, x1, v) in bins {
        out.push((x0, v));
        out.push((x1, v));
    }
    out
}

/// Tick label: up to four significant digits, no trailing zeros, no exponent.
pub(super) fn fmt_tick(v: f64) -> String {
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

/// Method names → colours: the four detectors first in their fixed order, then other
/// names by first appearance.
pub(super) struct Palette {
    pub(super) names: Vec<String>,
    pub(super) colours: Vec<RGBColor>,
}

impl Palette {
    pub(super) fn new<'a>(names: impl Iterator<Item = &'a str>) -> Palette {
        let mut known = [false; Method::ALL.len()];
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
        for (k, method) in Method::ALL.into_iter().enumerate() {
            if known[k] {
                p.names.push(method.name().to_string());
                p.colours.push(rgb(overlay::method_colour(method)));
            }
        }
        for (i, name) in extra.into_iter().enumerate() {
            p.names.push(name);
            p.colours
                .push(rgb(EXTRA_METHOD_COLOURS[i % EXTRA_METHOD_COLOURS.len()]));
        }
        p
    }

    pub(super) fn len(&self) -> usize {
        self.names.len()
    }

    /// Index of a method name (known names matched without case).
    pub(super) fn index(&self, name: &str) -> usize {
        let key = match known_index(name) {
            Some(k) => Method::ALL[k].name(),
            None => name,
        };
        self.names.iter().position(|n| n == key).unwrap_or(0)
    }

    pub(super) fn colour(&self, name: &str) -> RGBColor {
        self.colours.get(self.index(name)).copied().unwrap_or(BLACK)
    }

    pub(super) fn rgb(&self, name: &str) -> [u8; 3] {
        let RGBColor(r, g, b) = self.colour(name);
        [r, g, b]
    }
}

/// Registry position of a method name (compared without case).
fn known_index(name: &str) -> Option<usize> {
    Method::ALL
        .iter()
        .position(|m| m.name().eq_ignore_ascii_case(name.trim()))
}

/// Smallest step of the form {1, 2, 5}·10^k that is at least `raw`.
pub(super) fn nice_step(raw: f64) -> f64 {
    let mag = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * mag)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * mag)
}
