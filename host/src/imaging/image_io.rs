//! Reading DN frames from image files: 8/16-bit grayscale PNG, TIFF, and FITS.
//!
//! Every format's size is read from its header before any pixel is decoded (a
//! 20 000 × 20 000 PNG is refused without allocating its pixels). A multi-page TIFF is
//! read at its first page, with a warning. `--bits` below the data's depth is an error.
//!
//! **FITS → DN** ([`fits_to_dn`]): FITS frames carry physical values (BZERO + BSCALE ·
//! stored, [`crate::imaging::fits`]), for a real camera often floats and negative ones
//! (the Hayabusa2 TIR's L1 frames are shutter-differenced: space minus shutter, −434 …
//! −131 DN over the effective area of the reference dark frame). The rule is
//! `DN = clamp(round(value + offset), 0, 2^bits − 1)`, `bits` from `--bits` or the
//! project's 14, `offset` from `--fits-offset` or [`default_fits_offset_dn`]: the
//! renderer's fixed-gain pedestal of 1024 DN for float data (so deep space sits where our
//! realistic frames put it, and the reference dark frame lands on 590 … 893 DN), 0 for
//! integer data (already DN). Clamped pixels are counted in a warning; a non-finite
//! value is an error. `--crop` (any format) cuts the frame before detection, e.g. to the
//! TIR's 328 × 248 effective area (`--crop hayabusa2-tir`).

use std::fmt;
use std::path::{Path, PathBuf};

use image::{DynamicImage, ImageReader, Limits};
use tirroi_core::capacity::{Cap1024x768, FrameCapacity};
use tirroi_core::{Frame, FrameError};

use crate::imaging::fits;
use crate::imaging::signature::{FIXED_GAIN_PEDESTAL_DN, TIR_EFFECTIVE_AREA_PX};

/// A frame read from a file: owned DN and the bit depth they are read at.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameBuf {
    /// DN, row-major.
    pub pixels: Vec<u16>,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Bit depth of a DN.
    pub bits: u8,
}

impl FrameBuf {
    /// The core's view of this frame.
    ///
    /// # Errors
    /// [`FrameError`] when the dimensions do not fit the core (checked at load time
    /// for files).
    pub fn view(&self) -> Result<Frame<'_>, FrameError> {
        Frame::new(&self.pixels, self.width, self.height, self.bits)
    }

    /// The part `[x0, y0, x1, y1)` of the frame.
    ///
    /// # Errors
    /// A message when the crop is empty or reaches outside the frame.
    pub fn crop(&self, c: [usize; 4]) -> Result<FrameBuf, String> {
        check_crop(c, self.width, self.height)?;
        let [x0, y0, x1, y1] = c;
        let mut pixels = Vec::with_capacity((x1 - x0) * (y1 - y0));
        for y in y0..y1 {
            pixels.extend_from_slice(&self.pixels[y * self.width + x0..y * self.width + x1]);
        }
        Ok(FrameBuf {
            pixels,
            width: x1 - x0,
            height: y1 - y0,
            bits: self.bits,
        })
    }
}

fn check_crop(c: [usize; 4], width: usize, height: usize) -> Result<(), String> {
    let [x0, y0, x1, y1] = c;
    if x0 >= x1 || y0 >= y1 || x1 > width || y1 > height {
        return Err(format!(
            "crop {c:?} of a {width}x{height} px image: expected x0 < x1 <= {width} and y0 < y1 <= {height}"
        ));
    }
    Ok(())
}

/// The TIR's 328 × 248 effective area as a crop `[x0, y0, x1, y1)`: columns 16–343, rows
/// 6–253 of its 384 × 256 L1 frames (`/work/shared/reference/hayabusa2-tir/README.md`).
pub const HAYABUSA2_TIR_CROP: [usize; 4] = [
    TIR_EFFECTIVE_AREA_PX[0],
    TIR_EFFECTIVE_AREA_PX[1],
    TIR_EFFECTIVE_AREA_PX[0] + TIR_EFFECTIVE_AREA_PX[2],
    TIR_EFFECTIVE_AREA_PX[1] + TIR_EFFECTIVE_AREA_PX[3],
];

/// Parses a `--crop` value: `x0,y0,x1,y1` (px, x1 and y1 exclusive) or `hayabusa2-tir`
/// ([`HAYABUSA2_TIR_CROP`]).
///
/// # Errors
/// A message naming the expected forms.
pub fn parse_crop(s: &str) -> Result<[usize; 4], String> {
    if s == "hayabusa2-tir" {
        return Ok(HAYABUSA2_TIR_CROP);
    }
    parse_box_px::<usize>(s).map_err(|e| format!("{e} (or hayabusa2-tir)"))
}

/// Parses a box `x0,y0,x1,y1` (px, x1 and y1 exclusive) of integers of type `T` with
/// x0 < x1 and y0 < y1 (`--crop`, `detect --prior`); the error says what was expected.
pub fn parse_box_px<T: std::str::FromStr + PartialOrd + Copy>(s: &str) -> Result<[T; 4], String> {
    let v: Vec<T> = s
        .split(',')
        .map(|p| p.trim().parse::<T>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("`{s}`: expected four integers x0,y0,x1,y1 (px)"))?;
    match v[..] {
        [x0, y0, x1, y1] if x0 < x1 && y0 < y1 => Ok([x0, y0, x1, y1]),
        _ => Err(format!(
            "`{s}`: expected four integers x0,y0,x1,y1 with x0 < x1, y0 < y1"
        )),
    }
}

/// How to read a frame file ([`read_frame_with`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ReadOptions {
    /// Bit depth of the DN (`--bits`); `None`: 8 for 8-bit files; for 16-bit PNG the
    /// depth its `sBIT` chunk states (tirroi's renders write it, [`encode_dn_png`]) when
    /// every DN fits it; otherwise 14 for 16-bit files whose DN fit (else 16), and 14
    /// for FITS.
    pub bits: Option<u8>,
    /// FITS only: DN added to the physical value before rounding (`--fits-offset`);
    /// `None`: [`default_fits_offset_dn`].
    pub fits_offset_dn: Option<f64>,
    /// Part of the image to keep, `[x0, y0, x1, y1)` px (`--crop`).
    pub crop: Option<[usize; 4]>,
}

/// Largest image side decoded when a crop is given, px: 4096 (a 4096 × 4096 16-bit
/// image is 32 MiB); without a crop the frame itself must fit the core (1024 × 768).
pub const MAX_DECODE_SIDE_PX: usize = 4096;

/// The default FITS offset, DN: [`FIXED_GAIN_PEDESTAL_DN`] (1024) for float data (BITPIX
/// −32/−64: differenced or calibrated frames that go negative), 0 for integer data.
pub fn default_fits_offset_dn(bitpix: i32) -> f64 {
    if bitpix < 0 {
        FIXED_GAIN_PEDESTAL_DN
    } else {
        0.0
    }
}

/// The module's FITS rule: `clamp(round(v + offset), 0, 2^bits − 1)` per value; also
/// returns how many values were clamped.
///
/// # Errors
/// A message naming the first non-finite value's position (x, y).
pub fn fits_to_dn(
    values: &[f64],
    width: usize,
    offset_dn: f64,
    bits: u8,
) -> Result<(Vec<u16>, usize), String> {
    let max = f64::from((1u32 << bits) - 1);
    let mut clamped = 0;
    let mut out = Vec::with_capacity(values.len());
    for (i, &v) in values.iter().enumerate() {
        if !v.is_finite() {
            return Err(format!(
                "value {v} at (x {}, y {}): expected finite values",
                i % width,
                i / width
            ));
        }
        let dn = (v + offset_dn).round();
        clamped += usize::from(!(0.0..=max).contains(&dn));
        out.push(dn.clamp(0.0, max) as u16);
    }
    Ok((out, clamped))
}

fn is_fits(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 9];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok_and(|()| &head == b"SIMPLE  =")
}

/// Why a file could not be read as a frame; its `Display` is one line naming the file.
#[derive(Debug)]
pub struct FrameFileError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong with it.
    pub problem: String,
}

impl fmt::Display for FrameFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.path.display(), self.problem)
    }
}

impl std::error::Error for FrameFileError {}

/// Reads an 8- or 16-bit grayscale PNG (or TIFF, or FITS) as DN.
///
/// The bit depth is `bits` when given; otherwise 8 for 8-bit files, a 16-bit PNG's
/// `sBIT` depth when every DN fits it, and for other 16-bit files the project's default
/// of 14 bits when every DN fits, else 16 ([`ReadOptions::bits`]). Warnings
/// ([`read_frame_with`]) are dropped.
///
/// # Errors
/// As [`read_frame_with`].
pub fn read_frame(path: &Path, bits: Option<u8>) -> Result<FrameBuf, FrameFileError> {
    read_frame_with(
        path,
        &ReadOptions {
            bits,
            ..ReadOptions::default()
        },
    )
    .map(|(f, _)| f)
}

/// The size of the frame `path` gives under `options` (after the crop), from the
/// file's header alone for PNG and TIFF.
///
/// # Errors
/// A [`FrameFileError`] naming the file when its header cannot be read or the crop does
/// not fit.
pub fn frame_dimensions(
    path: &Path,
    options: &ReadOptions,
) -> Result<(usize, usize), FrameFileError> {
    let fail = |problem: String| FrameFileError {
        path: path.to_path_buf(),
        problem,
    };
    let (w, h) = if is_fits(path) {
        let img = fits::read_fits(path).map_err(|e| FrameFileError {
            path: path.to_path_buf(),
            problem: e
                .strip_prefix(&format!("{}: ", path.display()))
                .unwrap_or(&e)
                .to_string(),
        })?;
        (img.width, img.height)
    } else {
        ImageReader::open(path)
            .map_err(|e| fail(format!("cannot open: {e}")))?
            .with_guessed_format()
            .map_err(|e| fail(format!("cannot read: {e}")))?
            .into_dimensions()
            .map(|(w, h)| (w as usize, h as usize))
            .map_err(|e| fail(format!("cannot read the header: {e}")))?
    };
    match options.crop {
        Some(c) => {
            check_crop(c, w, h).map_err(fail)?;
            Ok((c[2] - c[0], c[3] - c[1]))
        }
        None => Ok((w, h)),
    }
}

/// Reads a frame file under `options`; returns the frame and warnings for the user (one
/// line each, not naming the file: a multi-page TIFF read at page 1, clamped FITS values).
///
/// # Errors
/// A [`FrameFileError`] naming the file when it cannot be opened or decoded, is a colour
/// image, is larger than the largest capacity of the core's detectors (1024×768, checked
/// from the header before decoding; with a crop, the file up to
/// [`MAX_DECODE_SIDE_PX`] a side and the cropped part), holds a DN above `2^bits − 1`
/// for an explicit `bits` (PNG/TIFF), or (FITS) a non-finite value.
pub fn read_frame_with(
    path: &Path,
    options: &ReadOptions,
) -> Result<(FrameBuf, Vec<String>), FrameFileError> {
    let fail = |problem: String| FrameFileError {
        path: path.to_path_buf(),
        problem,
    };
    let (max_w, max_h) = (Cap1024x768::WIDTH, Cap1024x768::HEIGHT);
    let (limit_w, limit_h) = if options.crop.is_some() {
        (MAX_DECODE_SIDE_PX, MAX_DECODE_SIDE_PX)
    } else {
        (max_w, max_h)
    };
    let too_large = |w: usize, h: usize| {
        fail(if options.crop.is_some() {
            format!("image is {w}x{h} px; at most {limit_w}x{limit_h} px are decoded")
        } else {
            format!("image is {w}x{h} px; the core takes frames of at most {max_w}x{max_h} px")
        })
    };
    let mut warnings = Vec::new();
    let (frame, cropped) = if is_fits(path) {
        let img = fits::read_fits_within(path, limit_w, limit_h).map_err(|e| FrameFileError {
            path: path.to_path_buf(),
            problem: e
                .strip_prefix(&format!("{}: ", path.display()))
                .unwrap_or(&e)
                .to_string(),
        })?;
        if img.width > limit_w || img.height > limit_h {
            return Err(too_large(img.width, img.height));
        }
        let bits = options
            .bits
            .unwrap_or(tirroi_core::frame::DEFAULT_BIT_DEPTH);
        let offset = options
            .fits_offset_dn
            .unwrap_or_else(|| default_fits_offset_dn(img.bitpix));
        // Crop first: only the kept values are mapped (and counted when clamped).
        let (values, width, height) = match options.crop {
            Some(c) => {
                check_crop(c, img.width, img.height).map_err(fail)?;
                let [x0, y0, x1, y1] = c;
                let mut v = Vec::with_capacity((x1 - x0) * (y1 - y0));
                for y in y0..y1 {
                    v.extend_from_slice(&img.pixels[y * img.width + x0..y * img.width + x1]);
                }
                (v, x1 - x0, y1 - y0)
            }
            None => (img.pixels, img.width, img.height),
        };
        let (pixels, clamped) = fits_to_dn(&values, width, offset, bits).map_err(fail)?;
        if clamped > 0 {
            warnings.push(format!(
                "{clamped} of {} values clamped to 0..={} DN (FITS rule: round(value + {offset}) at {bits} bits; see --fits-offset, --bits)",
                pixels.len(),
                (1u32 << bits) - 1
            ));
        }
        let frame = FrameBuf {
            pixels,
            width,
            height,
            bits,
        };
        (frame, true)
    } else {
        let open = || -> Result<ImageReader<std::io::BufReader<std::fs::File>>, FrameFileError> {
            let reader = ImageReader::open(path)
                .map_err(|e| fail(format!("cannot open: {e}")))?
                .with_guessed_format()
                .map_err(|e| fail(format!("cannot read: {e}")))?;
            if reader.format().is_none() {
                return Err(fail(
                    "not an image file (expected 8- or 16-bit grayscale PNG, TIFF or FITS)".into(),
                ));
            }
            Ok(reader)
        };
        let (w, h) = open()?
            .into_dimensions()
            .map_err(|e| fail(format!("cannot decode: {e}")))?;
        let (w, h) = (w as usize, h as usize);
        if w > limit_w || h > limit_h {
            return Err(too_large(w, h));
        }
        let mut reader = open()?;
        if reader.format() == Some(image::ImageFormat::Tiff) && tiff_has_more_pages(path) {
            warnings.push("multi-page TIFF: reading page 1 only".to_string());
        }
        let mut limits = Limits::default();
        limits.max_image_width = Some(limit_w as u32);
        limits.max_image_height = Some(limit_h as u32);
        reader.limits(limits);
        let is_png = reader.format() == Some(image::ImageFormat::Png);
        let image = reader
            .decode()
            .map_err(|e| fail(format!("cannot decode: {e}")))?;
        let (width, height) = (image.width() as usize, image.height() as usize);
        let (pixels, file_bits): (Vec<u16>, u8) = match image {
            DynamicImage::ImageLuma8(img) => {
                (img.into_raw().into_iter().map(u16::from).collect(), 8)
            }
            DynamicImage::ImageLuma16(img) => (img.into_raw(), 16),
            other => {
                return Err(fail(format!(
                    "colour or alpha image ({:?}); expected 8- or 16-bit grayscale",
                    other.color()
                )));
            }
        };
        let max = pixels.iter().copied().max().unwrap_or(0);
        let bits = match options.bits {
            Some(b) => {
                if b < 16 && u32::from(max) >= 1u32 << b {
                    let need = 16 - max.leading_zeros();
                    return Err(fail(format!(
                        "--bits {b} is below the data's depth: a DN of {max} needs {need} bits (at most {} at {b} bits)",
                        (1u32 << b) - 1
                    )));
                }
                b
            }
            None if file_bits == 8 => 8,
            None => {
                let guess = if max < 1 << tirroi_core::frame::DEFAULT_BIT_DEPTH {
                    tirroi_core::frame::DEFAULT_BIT_DEPTH
                } else {
                    16
                };
                match is_png.then(|| png_significant_bits(path)).flatten() {
                    Some(s) if s >= 16 || u32::from(max) < 1u32 << s => s,
                    Some(s) => {
                        warnings.push(format!(
                            "the PNG's sBIT chunk says {s} bits, but a DN of {max} needs more: read at {guess} bits (see --bits)"
                        ));
                        guess
                    }
                    None => guess,
                }
            }
        };
        let frame = FrameBuf {
            pixels,
            width,
            height,
            bits,
        };
        (frame, false)
    };
    let frame = match options.crop {
        Some(c) if !cropped => frame.crop(c).map_err(fail)?,
        _ => frame,
    };
    if frame.width > max_w || frame.height > max_h {
        return Err(too_large(frame.width, frame.height));
    }
    frame.view().map_err(|e| fail(e.to_string()))?;
    Ok((frame, warnings))
}

/// Whether a TIFF file holds more than one image (a second IFD), from its headers.
fn tiff_has_more_pages(path: &Path) -> bool {
    std::fs::File::open(path)
        .ok()
        .and_then(|f| tiff::decoder::Decoder::new(std::io::BufReader::new(f)).ok())
        .is_some_and(|d| d.more_images())
}

/// Room reserved for a PNG's bytes beyond its raw samples: signature, IHDR, IEND, the
/// per-row filter bytes and zlib/deflate block overhead (stored blocks add 5 bytes per
/// 64 KiB), so that the output buffer is allocated once, not grown by doubling.
const PNG_OVERHEAD_BYTES: usize = 4096;

/// PNG bytes of `width` × `height` pixels of `colour` (masks, previews; DN frames go
/// through [`encode_dn_png`]), with fast deflate and the Sub filter: on 200 rendered
/// 328×248 16-bit frames, 0.32 ms and 111 kB per frame against 8.5 ms and 101 kB for
/// the encoder's default (measured on this 2-core machine).
///
/// # Errors
/// The encoder's error when the buffer does not match the dimensions.
pub fn encode_png(
    bytes: &[u8],
    width: u32,
    height: u32,
    colour: image::ExtendedColorType,
) -> Result<Vec<u8>, image::ImageError> {
    use image::ImageEncoder;
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    let mut out = Vec::with_capacity(bytes.len() + height as usize + PNG_OVERHEAD_BYTES);
    PngEncoder::new_with_quality(&mut out, CompressionType::Fast, FilterType::Sub)
        .write_image(bytes, width, height, colour)?;
    Ok(out)
}

/// PNG bytes of DN as 16-bit grayscale samples with their bit depth `bits` (1..=16) in
/// the PNG's `sBIT` chunk (significant bits, PNG 1.2 § 4.2.6), so that a reader knows
/// the top DN (`2^bits − 1`, where a target saturates) from the file alone
/// ([`read_frame_with`] reads it back); fast deflate and the Sub filter as
/// [`encode_png`].
///
/// # Errors
/// What is wrong, when `bits` is not in 1..=16, `pixels` does not hold `width ×
/// height` samples, or the encoder fails.
pub fn encode_dn_png(pixels: &[u16], width: u32, height: u32, bits: u8) -> Result<Vec<u8>, String> {
    if !(1..=16).contains(&bits) {
        return Err(format!("a bit depth of {bits}; expected 1..=16"));
    }
    if pixels.len() as u64 != u64::from(width) * u64::from(height) {
        return Err(format!(
            "{} samples for a {width}x{height} frame",
            pixels.len()
        ));
    }
    encode_dn_png_checked(pixels, width, height, bits).map_err(|e| e.to_string())
}

/// [`encode_dn_png`] once its arguments are checked.
fn encode_dn_png_checked(
    pixels: &[u16],
    width: u32,
    height: u32,
    bits: u8,
) -> Result<Vec<u8>, png::EncodingError> {
    let mut out = Vec::with_capacity(2 * pixels.len() + height as usize + PNG_OVERHEAD_BYTES);
    let mut encoder = png::Encoder::new(&mut out, width, height);
    encoder.set_color(png::ColorType::Grayscale);
    encoder.set_depth(png::BitDepth::Sixteen);
    encoder.set_compression(png::Compression::Fast);
    encoder.set_filter(png::Filter::Sub);
    let mut writer = encoder.write_header()?;
    writer.write_chunk(png::chunk::sBIT, &[bits])?;
    let big_endian: Vec<u8> = pixels.iter().flat_map(|v| v.to_be_bytes()).collect();
    writer.write_image_data(&big_endian)?;
    writer.finish()?;
    Ok(out)
}

/// The `sBIT` depth of a grayscale PNG file (its significant bits, 1..=16), or `None`
/// when the file is not a PNG, cannot be read or has no such chunk. Reads the chunks
/// before the image data only.
pub fn png_significant_bits(path: &Path) -> Option<u8> {
    let file = std::fs::File::open(path).ok()?;
    let reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .ok()?;
    let info = reader.info();
    match (info.color_type, info.sbit.as_deref()) {
        (png::ColorType::Grayscale, Some(&[s])) => Some(s),
        _ => None,
    }
}

/// Writes DN as a 16-bit grayscale PNG with the frame's bit depth ([`encode_dn_png`]).
///
/// # Errors
/// An I/O or encoding error, naming the file.
pub fn write_png16(path: &Path, frame: &FrameBuf) -> Result<(), FrameFileError> {
    let fail = |problem: String| FrameFileError {
        path: path.to_path_buf(),
        problem,
    };
    let png = encode_dn_png(
        &frame.pixels,
        frame.width as u32,
        frame.height as u32,
        frame.bits,
    )
    .map_err(|e| fail(format!("cannot encode: {e}")))?;
    std::fs::write(path, png).map_err(|e| fail(format!("cannot write: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file of this test's own in the system's temporary directory, removed on drop.
    struct TempFile(PathBuf);

    impl TempFile {
        fn new(name: &str, bytes: &[u8]) -> Self {
            let path =
                std::env::temp_dir().join(format!("tirroi-image-io-{}-{name}", std::process::id()));
            std::fs::write(&path, bytes).unwrap();
            TempFile(path)
        }
    }

    impl Drop for TempFile {
        fn drop(&mut self) {
            let _ = std::fs::remove_file(&self.0);
        }
    }

    /// The chunks of a PNG file as (type, data), parsed by hand from the format (PNG 1.2
    /// § 3.2: signature, then length, type, data, CRC per chunk), independent of the
    /// `png` crate that wrote them.
    fn chunks(bytes: &[u8]) -> Vec<([u8; 4], Vec<u8>)> {
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        let mut out = Vec::new();
        let mut at = 8;
        while at < bytes.len() {
            let len = u32::from_be_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
            let kind: [u8; 4] = bytes[at + 4..at + 8].try_into().unwrap();
            out.push((kind, bytes[at + 8..at + 8 + len].to_vec()));
            at += 12 + len;
        }
        out
    }

    /// A 12-bit frame with its top DN (4095) in it: 16 × 8 px.
    fn frame_12_bit() -> Vec<u16> {
        (0..128u16)
            .map(|i| if i == 77 { 4095 } else { 100 + 7 * i })
            .collect()
    }

    #[test]
    fn the_bit_depth_goes_into_sbit_right_after_the_header() {
        let png = encode_dn_png(&frame_12_bit(), 16, 8, 12).unwrap();
        let chunks = chunks(&png);
        let kinds: Vec<&[u8; 4]> = chunks.iter().map(|(k, _)| k).collect();
        assert_eq!(kinds[..2], [b"IHDR", b"sBIT"]);
        assert_eq!(chunks[1].1, [12]);
        // IHDR: 16 × 8, 16-bit grayscale.
        assert_eq!(chunks[0].1[..10], [0, 0, 0, 16, 0, 0, 0, 8, 16, 0]);
    }

    #[test]
    fn a_rendered_frame_is_read_back_at_its_own_depth() {
        let pixels = frame_12_bit();
        let file = TempFile::new("12.png", &encode_dn_png(&pixels, 16, 8, 12).unwrap());
        assert_eq!(png_significant_bits(&file.0), Some(12));
        let (frame, warnings) = read_frame_with(&file.0, &ReadOptions::default()).unwrap();
        // Without sBIT, a 16-bit file whose DN fit 14 bits was read at 14: 4095 would not
        // be the top DN, and a saturated target would not look saturated.
        assert_eq!(
            (frame.bits, frame.pixels, warnings),
            (12, pixels, Vec::<String>::new())
        );
        // `--bits` still decides when given.
        assert_eq!(read_frame(&file.0, Some(16)).unwrap().bits, 16);
        for bits in [1, 8, 14, 16] {
            let pixels = vec![((1u32 << bits) - 1) as u16; 4];
            let file = TempFile::new("any.png", &encode_dn_png(&pixels, 2, 2, bits).unwrap());
            assert_eq!(read_frame(&file.0, None).unwrap().bits, bits, "{bits} bits");
        }
    }

    #[test]
    fn without_sbit_or_against_the_data_the_depth_is_guessed() {
        let pixels = frame_12_bit();
        // A 16-bit PNG as other tools write it: through `image`, no sBIT.
        let mut plain = Vec::new();
        image::ImageBuffer::<image::Luma<u16>, _>::from_raw(16, 8, pixels.clone())
            .unwrap()
            .write_to(
                &mut std::io::Cursor::new(&mut plain),
                image::ImageFormat::Png,
            )
            .unwrap();
        assert!(chunks(&plain).iter().all(|(k, _)| k != b"sBIT"));
        let file = TempFile::new("plain.png", &plain);
        assert_eq!(png_significant_bits(&file.0), None);
        assert_eq!(read_frame(&file.0, None).unwrap().bits, 14);
        // An sBIT of 10 with a DN of 4095: the data win, with a warning.
        let file = TempFile::new("lying.png", &encode_dn_png(&pixels, 16, 8, 10).unwrap());
        let (frame, warnings) = read_frame_with(&file.0, &ReadOptions::default()).unwrap();
        assert_eq!(frame.bits, 14);
        assert_eq!(warnings.len(), 1);
        assert!(
            warnings[0].contains("sBIT chunk says 10 bits"),
            "{warnings:?}"
        );
    }

    #[test]
    fn bad_depths_and_sizes_are_errors_not_files() {
        let pixels = frame_12_bit();
        assert!(
            encode_dn_png(&pixels, 16, 8, 0)
                .unwrap_err()
                .contains("expected 1..=16")
        );
        assert!(
            encode_dn_png(&pixels, 16, 8, 17)
                .unwrap_err()
                .contains("expected 1..=16")
        );
        assert!(
            encode_dn_png(&pixels, 16, 9, 12)
                .unwrap_err()
                .contains("16x9")
        );
    }
}
