//! Reading FITS images: the one FITS reader of the host (the Hayabusa2 TIR's L1 frames,
//! the sensor-signature fit, and any FITS frame given to the CLI).
//!
//! The file is parsed with the CDS's pure-Rust `fitsrs`; this module picks the first
//! HDU holding a two-dimensional image (the primary HDU or an IMAGE extension), checks
//! its size from the header (NAXIS1 × NAXIS2 ≤ [`MAX_FITS_SIDE`] a side) before
//! decoding any data, and returns the physical values
//! `BZERO + BSCALE · stored` (FITS 4.0 §5.3) as f64 for every BITPIX (8, 16, 32, 64,
//! −32, −64), row-major with x = NAXIS1 (columns) fastest and y = NAXIS2 (rows) in the
//! file's order (FITS row 1 first). Errors name the file and what was expected.

use std::path::Path;

use fitsrs::card::Value;
use fitsrs::hdu::header::Bitpix;
use fitsrs::{Fits, HDU, Pixels};

/// Largest accepted image side, px: far above any thermal camera frame (the core's
/// largest capacity is 1024 × 768), small enough that a corrupt header cannot ask for
/// gigabytes.
pub const MAX_FITS_SIDE: usize = 16_384;

/// Largest accepted file, bytes (64 MiB: a 4096 × 4096 f32 image is 64 MiB).
pub const MAX_FITS_FILE_BYTES: u64 = 64 << 20;

/// One header keyword's value.
#[derive(Debug, Clone, PartialEq)]
pub enum FitsValue {
    /// An integer (`NAXIS1 = 384`).
    Integer(i64),
    /// A real number (`BOL_TEMP = 40.346`).
    Float(f64),
    /// A logical (`SIMPLE = T`).
    Logical(bool),
    /// A character string, trailing blanks removed (`INSTRUME= 'TIR     '` → `TIR`).
    Text(String),
}

impl FitsValue {
    /// The value as a number (integers and reals), `None` for logicals and strings.
    pub fn as_f64(&self) -> Option<f64> {
        match *self {
            FitsValue::Integer(i) => Some(i as f64),
            FitsValue::Float(f) => Some(f),
            _ => None,
        }
    }
}

/// A two-dimensional FITS image in physical units (BSCALE and BZERO applied).
#[derive(Debug, Clone, PartialEq)]
pub struct FitsImage {
    /// NAXIS1, columns, px.
    pub width: usize,
    /// NAXIS2, rows, px.
    pub height: usize,
    /// BITPIX of the stored data (8, 16, 32, 64, −32, −64).
    pub bitpix: i32,
    /// `BZERO + BSCALE · stored`, row-major, `width × height` values.
    pub pixels: Vec<f64>,
    /// The header's value keywords in file order (COMMENT/HISTORY excluded).
    pub keywords: Vec<(String, FitsValue)>,
}

impl FitsImage {
    /// The value of a header keyword (exact, upper-case FITS name), if present.
    pub fn keyword(&self, name: &str) -> Option<&FitsValue> {
        self.keywords
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v)
    }

    /// A numeric header keyword, if present and numeric.
    pub fn keyword_f64(&self, name: &str) -> Option<f64> {
        self.keyword(name).and_then(FitsValue::as_f64)
    }

    /// The pixel at column `x`, row `y` (0-based).
    pub fn at(&self, x: usize, y: usize) -> f64 {
        self.pixels[y * self.width + x]
    }
}

/// Reads the first two-dimensional image of a FITS file.
///
/// # Errors
/// A message naming `path` and what was expected: a file that cannot be read or is
/// larger than [`MAX_FITS_FILE_BYTES`], not FITS, with no 2-D image HDU, a side of 0 or
/// above [`MAX_FITS_SIDE`], a non-numeric BSCALE/BZERO, or data shorter than the header
/// says.
pub fn read_fits(path: &Path) -> Result<FitsImage, String> {
    read_fits_within(path, MAX_FITS_SIDE, MAX_FITS_SIDE)
}

/// [`read_fits`] for an image of at most `max_width` × `max_height` px, checked from the
/// header before any data is decoded (the caller's own limit, e.g. the core's 1024 × 768).
///
/// # Errors
/// As [`read_fits`], and a side above `max_width` or `max_height`.
pub fn read_fits_within(
    path: &Path,
    max_width: usize,
    max_height: usize,
) -> Result<FitsImage, String> {
    let name = path.display();
    let meta = std::fs::metadata(path).map_err(|e| format!("{name}: cannot read: {e}"))?;
    if meta.len() > MAX_FITS_FILE_BYTES {
        return Err(format!(
            "{name}: {} bytes: expected a FITS file of at most {MAX_FITS_FILE_BYTES} bytes",
            meta.len()
        ));
    }
    let bytes = std::fs::read(path).map_err(|e| format!("{name}: cannot read: {e}"))?;
    parse_fits_within(&bytes, max_width, max_height).map_err(|e| format!("{name}: {e}"))
}

/// Parses FITS bytes held in memory (see [`read_fits`]); errors do not name a file.
///
/// # Errors
/// As [`read_fits`].
pub fn parse_fits(bytes: &[u8]) -> Result<FitsImage, String> {
    parse_fits_within(bytes, MAX_FITS_SIDE, MAX_FITS_SIDE)
}

/// [`parse_fits`] for an image of at most `max_width` × `max_height` px (and
/// [`MAX_FITS_SIDE`]), checked from the header before the data.
///
/// # Errors
/// As [`read_fits_within`].
pub fn parse_fits_within(
    bytes: &[u8],
    max_width: usize,
    max_height: usize,
) -> Result<FitsImage, String> {
    let (max_w, max_h) = (max_width.min(MAX_FITS_SIDE), max_height.min(MAX_FITS_SIDE));
    if bytes.len() < 2880 || !bytes.starts_with(b"SIMPLE  =") {
        return Err(
            "not a FITS file: expected a 2880-byte header block starting with `SIMPLE  =`"
                .to_string(),
        );
    }
    let mut cursor = std::io::Cursor::new(bytes);
    let mut hdus = Fits::from_reader(&mut cursor);
    let mut index = 0usize;
    loop {
        let hdu = match hdus.next() {
            None => {
                return Err(
                    "no image HDU with NAXIS = 2: expected a two-dimensional image".to_string(),
                );
            }
            Some(Err(e)) => return Err(format!("HDU {index}: not valid FITS: {e}")),
            Some(Ok(h)) => h,
        };
        let image_hdu = match hdu {
            HDU::Primary(h) | HDU::XImage(h) => h,
            _ => {
                index += 1;
                continue;
            }
        };
        let header = image_hdu.get_header();
        let xt = header.get_xtension();
        let naxis = xt.get_naxis().to_vec();
        if naxis.len() != 2 {
            index += 1;
            continue;
        }
        let (w, h) = (naxis[0] as usize, naxis[1] as usize);
        if !(1..=MAX_FITS_SIDE).contains(&w) || !(1..=MAX_FITS_SIDE).contains(&h) {
            return Err(format!(
                "HDU {index}: NAXIS1 × NAXIS2 = {w} × {h}: expected 1..={MAX_FITS_SIDE} a side"
            ));
        }
        if w > max_w || h > max_h {
            return Err(format!(
                "image is {w}x{h} px (HDU {index}, from the header); at most {max_w}x{max_h} px are read"
            ));
        }
        let bitpix = xt.get_bitpix();
        let mut keywords = Vec::new();
        for (k, v) in header.iter() {
            let v = match v {
                Value::Integer { value, .. } => FitsValue::Integer(*value),
                Value::Float { value, .. } => FitsValue::Float(*value),
                Value::Logical { value, .. } => FitsValue::Logical(*value),
                Value::String { value, .. } => FitsValue::Text(value.trim_end().to_string()),
                _ => continue,
            };
            keywords.push((k.to_string(), v));
        }
        let numeric = |key: &str, default: f64| -> Result<f64, String> {
            match keywords.iter().find(|(k, _)| k == key) {
                None => Ok(default),
                Some((_, v)) => v
                    .as_f64()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| format!("HDU {index}: {key} = {v:?}: expected a finite number")),
            }
        };
        let bscale = numeric("BSCALE", 1.0)?;
        let bzero = numeric("BZERO", 0.0)?;
        let n = w * h;
        let data = hdus.get_data(&image_hdu);
        let phys = |x: f64| bzero + bscale * x;
        let pixels: Vec<f64> = match data.pixels() {
            Pixels::U8(it) => it.take(n).map(|v| phys(f64::from(v))).collect(),
            Pixels::I16(it) => it.take(n).map(|v| phys(f64::from(v))).collect(),
            Pixels::I32(it) => it.take(n).map(|v| phys(f64::from(v))).collect(),
            Pixels::I64(it) => it.take(n).map(|v| phys(v as f64)).collect(),
            Pixels::F32(it) => it.take(n).map(|v| phys(f64::from(v))).collect(),
            Pixels::F64(it) => it.take(n).map(phys).collect(),
        };
        if pixels.len() != n {
            return Err(format!(
                "HDU {index}: the data hold {} of the {w} × {h} = {n} pixels the header gives (truncated file?)",
                pixels.len()
            ));
        }
        return Ok(FitsImage {
            width: w,
            height: h,
            bitpix: bitpix_code(bitpix),
            pixels,
            keywords,
        });
    }
}

fn bitpix_code(b: Bitpix) -> i32 {
    match b {
        Bitpix::U8 => 8,
        Bitpix::I16 => 16,
        Bitpix::I32 => 32,
        Bitpix::I64 => 64,
        Bitpix::F32 => -32,
        Bitpix::F64 => -64,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A FITS file made by hand: 80-character cards padded to 2880 bytes, then the
    /// big-endian data padded to 2880 bytes (FITS 4.0 §3).
    fn fits_bytes(cards: &[String], data: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        for c in cards.iter().map(String::as_str).chain(["END"]) {
            out.extend_from_slice(format!("{c:<80}").as_bytes());
        }
        out.resize(out.len().div_ceil(2880) * 2880, b' ');
        out.extend_from_slice(data);
        out.resize(out.len().div_ceil(2880) * 2880, 0);
        out
    }

    fn card(k: &str, v: &str) -> String {
        format!("{k:<8}= {v:>20}")
    }

    fn header(bitpix: i32, w: usize, h: usize, extra: &[String]) -> Vec<String> {
        let mut c = vec![
            card("SIMPLE", "T"),
            card("BITPIX", &bitpix.to_string()),
            card("NAXIS", "2"),
            card("NAXIS1", &w.to_string()),
            card("NAXIS2", &h.to_string()),
        ];
        c.extend_from_slice(extra);
        c
    }

    #[test]
    fn int16_with_bscale_bzero_gives_physical_values_row_major() {
        // Stored i16 s at (x, y) = 10·y + x − 3; physical = 32768 + 0.5·s.
        let (w, h) = (3, 2);
        let stored: Vec<i16> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (10 * y + x) as i16 - 3))
            .collect();
        let data: Vec<u8> = stored.iter().flat_map(|v| v.to_be_bytes()).collect();
        let extra = [
            card("BSCALE", "0.5"),
            card("BZERO", "32768."),
            card("BOL_TEMP", "40.346"),
            card("INSTRUME", "'TIR     '"),
        ];
        let img = parse_fits(&fits_bytes(&header(16, w, h, &extra), &data)).unwrap();
        assert_eq!((img.width, img.height, img.bitpix), (3, 2, 16));
        for y in 0..h {
            for x in 0..w {
                let s = f64::from(stored[y * w + x]);
                assert_eq!(img.at(x, y), 32768.0 + 0.5 * s);
            }
        }
        assert_eq!(img.keyword_f64("BOL_TEMP"), Some(40.346));
        assert_eq!(
            img.keyword("INSTRUME"),
            Some(&FitsValue::Text("TIR".into()))
        );
    }

    #[test]
    fn float32_and_float64_round_trip() {
        let vals = [-373.125f32, 0.0, 1.5e-3, -434.0];
        let data: Vec<u8> = vals.iter().flat_map(|v| v.to_be_bytes()).collect();
        let img = parse_fits(&fits_bytes(&header(-32, 2, 2, &[]), &data)).unwrap();
        let want: Vec<f64> = vals.iter().map(|&v| f64::from(v)).collect();
        assert_eq!(img.pixels, want);
        let vals64 = [1.0f64 / 3.0, -2.5e10];
        let data: Vec<u8> = vals64.iter().flat_map(|v| v.to_be_bytes()).collect();
        let img = parse_fits(&fits_bytes(&header(-64, 1, 2, &[]), &data)).unwrap();
        assert_eq!(img.pixels, vals64.to_vec());
        let data: Vec<u8> = vec![7, 200];
        let img = parse_fits(&fits_bytes(&header(8, 2, 1, &[]), &data)).unwrap();
        assert_eq!(img.pixels, vec![7.0, 200.0]);
    }

    #[test]
    fn oversize_header_is_refused_before_the_data() {
        // NAXIS1 far above the limit, and no data at all: the size check must come first.
        let bytes = fits_bytes(&header(-32, 100_000, 2, &[]), &[]);
        let e = parse_fits(&bytes).unwrap_err();
        assert!(e.contains("100000 × 2") && e.contains("16384"), "{e}");
    }

    #[test]
    fn a_callers_limit_is_checked_from_the_header() {
        // 2000 × 3 and no data: a check after decoding would report the truncation.
        let bytes = fits_bytes(&header(-32, 2000, 3, &[]), &[]);
        let e = parse_fits_within(&bytes, 1024, 768).unwrap_err();
        assert!(e.contains("2000x3") && e.contains("1024x768"), "{e}");
    }

    #[test]
    fn truncated_data_and_non_fits_are_errors() {
        let data: Vec<u8> = [1.0f32; 2].iter().flat_map(|v| v.to_be_bytes()).collect();
        let mut bytes = fits_bytes(&header(-32, 30, 30, &[]), &data);
        bytes.truncate(2880 + 8);
        let e = parse_fits(&bytes).unwrap_err();
        assert!(e.contains("900"), "{e}");
        let e = parse_fits(b"not a fits file at all").unwrap_err();
        assert!(e.contains("SIMPLE"), "{e}");
        let e = read_fits(Path::new("/nonexistent/dark.fit")).unwrap_err();
        assert!(e.contains("/nonexistent/dark.fit"), "{e}");
    }
}
