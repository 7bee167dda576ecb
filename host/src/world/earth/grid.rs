//! The 1° OLR grid ([`OlrGrid`]): construction, checks, scaling, and the bicubic
//! (Catmull-Rom) interpolation of its Eq. 10 temperatures.

use super::{EarthError, OLR_MAX_W_M2, OLR_MIN_W_M2, OlrGrid};
use crate::world::earth::flux_to_temperature_k;

impl OlrGrid {
    /// Number of latitude rows.
    pub const ROWS: usize = 180;
    /// Number of longitude columns.
    pub const COLS: usize = 360;

    /// Latitude of the centre of row `row`, degrees (−89.5 + row).
    pub fn node_lat_deg(row: usize) -> f64 {
        row as f64 - 89.5
    }

    /// Longitude of the centre of column `col`, degrees east (0.5 + col).
    pub fn node_lon_deg(col: usize) -> f64 {
        col as f64 + 0.5
    }

    /// A grid from 64 800 row-major values, W m⁻² (row 0 = latitude −89.5°, column 0 =
    /// longitude 0.5° E).
    ///
    /// # Errors
    /// [`EarthError::WrongLength`] unless there are 180 × 360 values;
    /// [`EarthError::BadFlux`] for the first NaN, infinite or out-of-range value.
    pub fn from_values(values: Vec<f32>) -> Result<OlrGrid, EarthError> {
        if values.len() != Self::ROWS * Self::COLS {
            return Err(EarthError::WrongLength {
                actual: values.len(),
            });
        }
        if let Some(i) = values
            .iter()
            .position(|v| !(OLR_MIN_W_M2..=OLR_MAX_W_M2).contains(v))
        {
            return Err(EarthError::BadFlux {
                row: i / Self::COLS,
                col: i % Self::COLS,
                value: values[i],
            });
        }
        Ok(OlrGrid { values })
    }

    /// The 64 800 fluxes, W m⁻², row-major (south → north, 0.5° E eastwards).
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// Flux at node (`row`, `col`), W m⁻². Never panics: `row` beyond 179 is clamped to
    /// the northernmost row, `col` is taken modulo 360 (longitude is periodic).
    pub fn at_node(&self, row: usize, col: usize) -> f32 {
        self.values[row.min(Self::ROWS - 1) * Self::COLS + col % Self::COLS]
    }

    /// Every flux times `factor` (the eclipse scaling of Section 3.2.2, e.g.
    /// [`ECLIPSE_FLUX_FACTOR`](super::ECLIPSE_FLUX_FACTOR)). The result stays a valid grid: products above 500 W m⁻²
    /// are clamped to 500, and a negative or NaN factor counts as 0.
    pub fn scaled(&self, factor: f32) -> OlrGrid {
        let factor = if factor >= 0.0 { factor } else { 0.0 };
        OlrGrid {
            values: self
                .values
                .iter()
                .map(|v| (v * factor).min(OLR_MAX_W_M2))
                .collect(),
        }
    }

    /// Area-weighted global mean flux, W m⁻². The area of a 1° cell is proportional
    /// to sin(φ + ½°) − sin(φ − ½°) = 2 sin ½° · cos φ, so cos φ weights are exact.
    pub fn area_weighted_mean_w_m2(&self) -> f64 {
        let (mut sum, mut weight) = (0.0, 0.0);
        for (row, values) in self.values.chunks_exact(Self::COLS).enumerate() {
            let w = libm::cos(Self::node_lat_deg(row).to_radians());
            sum += w * values.iter().map(|&v| f64::from(v)).sum::<f64>();
            weight += w * Self::COLS as f64;
        }
        sum / weight
    }

    /// The area-weighted zonal mean of row `row` (clamped to 0..=179), W m⁻²: the plain
    /// mean of its 360 values (all cells of a row have the same area).
    pub fn zonal_mean_w_m2(&self, row: usize) -> f64 {
        let row = row.min(Self::ROWS - 1);
        let values = &self.values[row * Self::COLS..(row + 1) * Self::COLS];
        values.iter().map(|&v| f64::from(v)).sum::<f64>() / Self::COLS as f64
    }

    /// Eq. 10 temperature of every node, K, row-major like [`OlrGrid::values`].
    pub fn temperatures_k(&self) -> Vec<f32> {
        self.values
            .iter()
            .map(|&v| flux_to_temperature_k(f64::from(v)) as f32)
            .collect()
    }
}

/// Catmull-Rom weights of the four nodes around a point a fraction `t` ∈ [0, 1] of the
/// way from node 1 to node 2. At t = 0 they are exactly (0, 1, 0, 0) and at t = 1
/// exactly (0, 0, 1, 0), so the interpolant reproduces the nodes bit for bit.
pub(super) fn catmull_rom_weights(t: f64) -> [f64; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    [
        0.5 * (-t3 + 2.0 * t2 - t),
        0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t),
        0.5 * (t3 - t2),
    ]
}

/// Σ wᵢ vᵢ in a fixed order (the point evaluator and the mesh builder share it, so they
/// agree to the bit).
pub(super) fn dot4(w: &[f64; 4], v: [f64; 4]) -> f64 {
    w[0] * v[0] + w[1] * v[1] + w[2] * v[2] + w[3] * v[3]
}

/// The four 1° rows around latitude `lat_deg` and their weights: rows clamped at the
/// poles (beyond ±89.5° the value is that of the edge row).
pub(super) fn lat_stencil(lat_deg: f64) -> ([usize; 4], [f64; 4]) {
    let y = (lat_deg + 89.5).clamp(0.0, (OlrGrid::ROWS - 1) as f64);
    // y = 179 falls in the last interval at t = 1.
    let j0 = (y as usize).min(OlrGrid::ROWS - 2);
    let t = y - j0 as f64;
    let last = OlrGrid::ROWS - 1;
    let rows = [j0.saturating_sub(1), j0, j0 + 1, (j0 + 2).min(last)];
    (rows, catmull_rom_weights(t))
}

/// The four 1° columns around longitude `lon_deg` (any value, wrapped) and their
/// weights: periodic in longitude.
pub(super) fn lon_stencil(lon_deg: f64) -> ([usize; 4], [f64; 4]) {
    let x = lon_deg.rem_euclid(360.0) - 0.5;
    let fx = x.floor();
    let t = x - fx;
    // fx ∈ [−1, 359]; NaN becomes column 0 through the saturating cast.
    let i0 = (fx as i64).rem_euclid(OlrGrid::COLS as i64) as usize;
    let n = OlrGrid::COLS;
    let cols = [(i0 + n - 1) % n, i0, (i0 + 1) % n, (i0 + 2) % n];
    (cols, catmull_rom_weights(t))
}

/// Vertical pass for one 1° column: the interpolated value and the min/max of the four
/// nodes (the overshoot clamp).
pub(super) fn column_pass(
    temps: &[f32],
    rows: &[usize; 4],
    w: &[f64; 4],
    col: usize,
) -> (f64, f64, f64) {
    let v = rows.map(|r| f64::from(temps[r * OlrGrid::COLS + col]));
    let lo = v[0].min(v[1]).min(v[2]).min(v[3]);
    let hi = v[0].max(v[1]).max(v[2]).max(v[3]);
    (dot4(w, v), lo, hi)
}

/// Horizontal pass over the results of four column passes, clamped to the min/max of
/// the 4 × 4 nodes so that Catmull-Rom overshoot never leaves the data range.
pub(super) fn row_pass(w: &[f64; 4], cols: [(f64, f64, f64); 4]) -> f32 {
    let v = dot4(w, cols.map(|c| c.0));
    let lo = cols[0].1.min(cols[1].1).min(cols[2].1).min(cols[3].1);
    let hi = cols[0].2.max(cols[1].2).max(cols[2].2).max(cols[3].2);
    v.clamp(lo, hi) as f32
}

/// Bicubic Catmull-Rom interpolation of 1° node temperatures `temps_k` (row-major,
/// 180 × 360, as [`OlrGrid::temperatures_k`]) at (`lat_deg`, `lon_deg`), K:
/// periodic in longitude, clamped at the poles (beyond ±89.5° the edge row is used),
/// clamped to the min/max of the 4 × 4 nodes around the point (no overshoot).
///
/// Exact at the nodes: at (−89.5 + r, 0.5 + c) it returns `temps_k[r * 360 + c]` bit
/// for bit. NaN coordinates give NaN.
///
/// # Errors
/// [`EarthError::WrongLength`] unless `temps_k` has 64 800 values.
pub fn interpolate_temperature_k(
    temps_k: &[f32],
    lat_deg: f64,
    lon_deg: f64,
) -> Result<f32, EarthError> {
    if temps_k.len() != OlrGrid::ROWS * OlrGrid::COLS {
        return Err(EarthError::WrongLength {
            actual: temps_k.len(),
        });
    }
    if lat_deg.is_nan() || !lon_deg.is_finite() {
        return Ok(f32::NAN);
    }
    let (rows, wy) = lat_stencil(lat_deg);
    let (cols, wx) = lon_stencil(lon_deg);
    Ok(row_pass(
        &wx,
        cols.map(|c| column_pass(temps_k, &rows, &wy, c)),
    ))
}
