//! Pictures of frames with boxes drawn on them (PNG), for the README and reports.

use std::path::Path;

use image::{Rgb, RgbImage};
use tirroi_core::{Method, Roi};

use crate::imaging::image_io::{FrameBuf, FrameFileError};

/// Colour of the truth box.
pub const TRUTH_COLOUR: [u8; 3] = [0, 220, 0];
/// Colours of the detectors' boxes, in registry order (`Method::ALL`: otsu, adaptive,
/// WGE, DoG, auto, auto-v2); a detector beyond them takes them again from the start
/// ([`method_colour`]).
pub const METHOD_COLOURS: [[u8; 3]; 6] = [
    [255, 60, 60],
    [60, 140, 255],
    [255, 200, 0],
    [220, 0, 220],
    [0, 230, 230],
    [255, 130, 0],
];

/// The box colour of `method` ([`METHOD_COLOURS`] at its registry position).
pub fn method_colour(method: Method) -> [u8; 3] {
    METHOD_COLOURS[method.index() % METHOD_COLOURS.len()]
}

/// The frame as an RGB image, DN stretched linearly from the frame's minimum (black)
/// to its maximum (white), magnified `scale` times, with each box's outline drawn
/// (one output pixel thick, just outside the box's pixels).
pub fn frame_with_boxes(frame: &FrameBuf, boxes: &[(Roi, [u8; 3])], scale: u32) -> RgbImage {
    let scale = scale.max(1);
    let lo = frame.pixels.iter().copied().min().unwrap_or(0);
    let hi = frame.pixels.iter().copied().max().unwrap_or(0);
    let span = f64::from(hi.saturating_sub(lo).max(1));
    let (w, h) = (frame.width as u32, frame.height as u32);
    let mut img = RgbImage::from_fn(w * scale, h * scale, |x, y| {
        let v = frame.pixels[(y / scale * w + x / scale) as usize];
        let g = (f64::from(v - lo) / span * 255.0).round() as u8;
        Rgb([g, g, g])
    });
    for &(roi, colour) in boxes {
        outline(&mut img, roi, scale, Rgb(colour));
    }
    img
}

fn outline(img: &mut RgbImage, roi: Roi, scale: u32, colour: Rgb<u8>) {
    if roi.is_empty() {
        return;
    }
    let (w, h) = (img.width() as i64, img.height() as i64);
    let s = i64::from(scale);
    let (x0, y0) = (i64::from(roi.x0) * s - 1, i64::from(roi.y0) * s - 1);
    let (x1, y1) = (i64::from(roi.x1) * s, i64::from(roi.y1) * s);
    let mut put = |x: i64, y: i64| {
        if (0..w).contains(&x) && (0..h).contains(&y) {
            img.put_pixel(x as u32, y as u32, colour);
        }
    };
    for x in x0..=x1 {
        put(x, y0);
        put(x, y1);
    }
    for y in y0..=y1 {
        put(x0, y);
        put(x1, y);
    }
}

/// Writes `img` as PNG.
///
/// # Errors
/// A [`FrameFileError`] naming the file.
pub fn save(img: &RgbImage, path: &Path) -> Result<(), FrameFileError> {
    img.save(path).map_err(|e| FrameFileError {
        path: path.to_path_buf(),
        problem: format!("cannot write: {e}"),
    })
}
