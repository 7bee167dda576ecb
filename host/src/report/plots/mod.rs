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
//! Colours: truth [`TRUTH_COLOUR`](crate::imaging::overlay::TRUTH_COLOUR); the registry's
//! methods (`tirroi_core::Method::ALL`, names compared without case) take
//! [`method_colour`](crate::imaging::overlay::method_colour), the same as in the box
//! pictures, and any other method name takes the next of [`EXTRA_METHOD_COLOURS`] in
//! order of first appearance in the input. Legends list the registry's methods first,
//! in registry order, then the others by first appearance.
//!
//! Empty input (no point, no frame, or only non-finite values) is an error
//! ([`PlotError`] saying "no data") and no file is written: a figure without data is
//! the caller's decision, not a silent placeholder.

use std::error::Error;
use std::fmt;

use tirroi_core::Roi;

mod draw;
mod examples;
mod histograms;
mod iou;
mod tradeoff;

pub use examples::example_grid;
pub use histograms::{gradient_distribution, intensity_histogram};
pub use iou::iou_against_distance;
pub use tradeoff::{pareto_front, runtime_against_iou};

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
const FONT_BYTES: &[u8] = include_bytes!("../../../assets/DejaVuSans.ttf");
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
