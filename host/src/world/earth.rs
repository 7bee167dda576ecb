//! The Earth seen from orbit: TOA longwave flux grids (built-in and CERES SYN1deg),
//! Eq. 10 temperatures, mesh refinement and eclipse scaling (paper Section 3.2).
//!
//! Data flow, as in the paper:
//!
//! 1. an [`OlrGrid`]: daily all-sky top-of-atmosphere (TOA) longwave flux on the 1°
//!    CERES SYN1deg grid, either read from a CERES NetCDF subset
//!    (`OlrGrid::load_netcdf`, cargo feature `netcdf`) or the synthetic
//!    [`OlrGrid::builtin`] field;
//! 2. optionally [`OlrGrid::scaled`] by [`ECLIPSE_FLUX_FACTOR`] for eclipse scenes
//!    (Section 3.2.2);
//! 3. Eq. 10, [`flux_to_temperature_k`], at every 1° node, then interpolation to a finer
//!    latitude/longitude mesh and the band radiance of every mesh cell: an [`EarthMap`],
//!    built once and then looked up per pixel by the renderer.

use std::fmt;
use std::path::PathBuf;

use rayon::prelude::*;
use tirroi_core::sensor::BandLut;
use tirroi_core::sensor::SensorError;
use tirroi_core::sensor::planck::STEFAN_BOLTZMANN_W_M2_K4;

/// Lowest flux an [`OlrGrid`] accepts, W m⁻² (the CERES `valid_range` lower bound).
pub const OLR_MIN_W_M2: f32 = 0.0;
/// Highest flux an [`OlrGrid`] accepts, W m⁻² (the CERES `valid_range` upper bound).
pub const OLR_MAX_W_M2: f32 = 500.0;

/// Default eclipse scaling of the TOA flux (paper Section 3.2.2): the night-time OLR as
/// a fraction of the daily mean, applied uniformly with [`OlrGrid::scaled`].
///
/// The paper takes "the daily average variation in TOA fluxes" from 24 hourly CERES
/// maps; we have no hourly data here, so the value comes from the measured diurnal
/// cycle of OLR. ERBE found the longwave diurnal range (maximum − minimum) to be
/// smallest over clear oceans (under 5 W m⁻², i.e. a night minimum about 1 % below
/// the daily mean) and largest over clear deserts (up to about 70 W m⁻², a minimum
/// about 35 W m⁻² or 12 % below a ~300 W m⁻² mean), with vegetated land in between
/// (Harrison et al., "First estimates of the diurnal variation of longwave radiation
/// from the multiple-satellite Earth Radiation Budget Experiment (ERBE)", Bull. Amer.
/// Meteor. Soc. 69(10):1144, 1988; Smith and Rutan, J. Atmos. Sci. 60:1529, 2003).
/// 0.95 is the night minimum of a land-weighted view (a ~25 W m⁻² half-range on a
/// ~250 W m⁻² mean): colder than an ocean night (~0.99), warmer than a desert night
/// (~0.88), so eclipse scenes test the detectors on a noticeably dimmer Earth without
/// the extreme of a desert-only disc. In temperature it is a factor 0.95^¼ = 0.987,
/// −3.3 K at 255 K.
pub const ECLIPSE_FLUX_FACTOR: f32 = 0.95;

/// Eq. 10 of the paper: the equivalent blackbody temperature T = (F/σ)^¼ of a TOA flux
/// F, in K, with σ = [`STEFAN_BOLTZMANN_W_M2_K4`]. `flux_w_m2` ≥ 0 (W m⁻²): 240 W m⁻²
/// gives 255.1 K. Negative or NaN flux gives NaN; +∞ gives +∞.
pub fn flux_to_temperature_k(flux_w_m2: f64) -> f64 {
    // Two square roots: exact rounding, the same bits on every platform.
    (flux_w_m2 / STEFAN_BOLTZMANN_W_M2_K4).sqrt().sqrt()
}

/// Why an Earth source was refused. Every variant names what was read (file,
/// variable, node) and what was expected, so its [`Display`](fmt::Display) text tells a
/// person what to fix.
#[derive(Debug, Clone, PartialEq)]
pub enum EarthError {
    /// A flux vector for [`OlrGrid::from_values`] has the wrong length.
    WrongLength {
        /// Number of values given.
        actual: usize,
    },
    /// A flux value is NaN, infinite or outside the CERES `valid_range` 0..=500 W m⁻².
    BadFlux {
        /// Row of the node (0 = latitude −89.5°, south → north).
        row: usize,
        /// Column of the node (0 = longitude 0.5° E).
        col: usize,
        /// The value found, W m⁻².
        value: f32,
    },
    /// A mesh size for [`EarthMap::refine`] is not 1/k degree for an integer k in
    /// 1..=[`EarthMap::MAX_CELLS_PER_DEG`].
    BadMesh {
        /// The mesh size given, degrees.
        mesh_deg: f64,
    },
    /// The band radiance table refused a temperature (cannot happen for a valid grid;
    /// kept so that no path panics).
    Radiance {
        /// The temperature, K.
        t_k: f32,
        /// The camera model's reason.
        source: SensorError,
    },
    /// A NetCDF file could not be opened (missing, unreadable, not NetCDF).
    Open {
        /// The file.
        path: PathBuf,
        /// The NetCDF library's message.
        message: String,
    },
    /// The NetCDF file has no variable of that name.
    MissingVariable {
        /// The file.
        path: PathBuf,
        /// The variable asked for.
        variable: String,
        /// The variables the file does have.
        available: Vec<String>,
    },
    /// The variable's dimensions are not (lat, lon) or (time, lat, lon) with a 180-long
    /// latitude and a 360-long longitude dimension.
    BadShape {
        /// The file.
        path: PathBuf,
        /// The variable.
        variable: String,
        /// The dimensions found, as `name=len` pairs.
        found: String,
    },
    /// The time index is beyond the variable's time dimension.
    TimeIndex {
        /// The file.
        path: PathBuf,
        /// The variable.
        variable: String,
        /// The index asked for.
        index: usize,
        /// The length of the time dimension (0 when the variable has none).
        len: usize,
    },
    /// A latitude or longitude coordinate variable is missing or is not the 1° grid of
    /// cell centres (lat ±0.5…±89.5 in either order, lon 0.5…359.5 or −179.5…179.5).
    BadCoordinate {
        /// The file.
        path: PathBuf,
        /// The coordinate (dimension) name.
        coordinate: String,
        /// What is wrong with it.
        problem: String,
    },
    /// The slice holds fill (missing) values: CERES daily maps have none, so a fill
    /// value means a wrong product or time index.
    FillValues {
        /// The file.
        path: PathBuf,
        /// The variable.
        variable: String,
        /// How many nodes are fill values.
        count: usize,
        /// Latitude of the first one, degrees.
        lat_deg: f64,
        /// Longitude of the first one, degrees east (as in the file).
        lon_deg: f64,
    },
    /// A decoded value is NaN or outside 0..=500 W m⁻².
    OutOfRange {
        /// The file.
        path: PathBuf,
        /// The variable.
        variable: String,
        /// Latitude of the node, degrees.
        lat_deg: f64,
        /// Longitude of the node, degrees east (as in the file).
        lon_deg: f64,
        /// The decoded value, W m⁻².
        value: f64,
    },
    /// The NetCDF library failed while reading a variable or attribute.
    Read {
        /// The file.
        path: PathBuf,
        /// The variable or attribute.
        variable: String,
        /// The NetCDF library's message.
        message: String,
    },
}

const EXPECTED_FORM: &str = "a 1° CERES SYN1deg map: dimensions (lat=180, lon=360) or \
     (time, lat=180, lon=360), with coordinate variables lat/latitude and lon/longitude";

impl fmt::Display for EarthError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EarthError::WrongLength { actual } => write!(
                f,
                "OLR grid has {actual} values, expected {} (180 latitude rows × 360 \
                 longitude columns, row-major, south → north)",
                OlrGrid::ROWS * OlrGrid::COLS
            ),
            EarthError::BadFlux { row, col, value } => write!(
                f,
                "OLR value {value} W/m² at row {row} (lat {:.1}°), column {col} (lon \
                 {:.1}° E) is not a finite flux in the CERES valid_range 0..=500 W/m²",
                OlrGrid::node_lat_deg(*row),
                OlrGrid::node_lon_deg(*col)
            ),
            EarthError::BadMesh { mesh_deg } => write!(
                f,
                "Earth mesh size {mesh_deg}° is not 1/k degree for an integer k from 1 to \
                 {}: use 1.0, 0.5, 0.25, 0.2, 0.1 or 0.05",
                EarthMap::MAX_CELLS_PER_DEG
            ),
            EarthError::Radiance { t_k, source } => {
                write!(f, "band radiance of the Earth at {t_k} K failed: {source}")
            }
            EarthError::Open { path, message } => write!(
                f,
                "cannot open CERES NetCDF file {}: {message}",
                path.display()
            ),
            EarthError::MissingVariable {
                path,
                variable,
                available,
            } => write!(
                f,
                "{}: no variable `{variable}` (the file has: {}); for SYN1deg daily \
                 all-sky OLR use `toa_lw_all_daily`",
                path.display(),
                available.join(", ")
            ),
            EarthError::BadShape {
                path,
                variable,
                found,
            } => write!(
                f,
                "{}: variable `{variable}` has dimensions ({found}), expected {EXPECTED_FORM}",
                path.display()
            ),
            EarthError::TimeIndex {
                path,
                variable,
                index,
                len,
            } => write!(
                f,
                "{}: variable `{variable}` has {len} time steps, time index {index} is out \
                 of range (0-based)",
                path.display()
            ),
            EarthError::BadCoordinate {
                path,
                coordinate,
                problem,
            } => write!(
                f,
                "{}: coordinate `{coordinate}`: {problem}; expected {EXPECTED_FORM}",
                path.display()
            ),
            EarthError::FillValues {
                path,
                variable,
                count,
                lat_deg,
                lon_deg,
            } => write!(
                f,
                "{}: variable `{variable}` has {count} fill (missing) values in this time \
                 step, the first at lat {lat_deg}°, lon {lon_deg}°; a daily SYN1deg map \
                 has none: check the product and the time index",
                path.display()
            ),
            EarthError::OutOfRange {
                path,
                variable,
                lat_deg,
                lon_deg,
                value,
            } => write!(
                f,
                "{}: variable `{variable}` = {value} W/m² at lat {lat_deg}°, lon \
                 {lon_deg}° is outside the CERES valid_range 0..=500 W/m² (is it a TOA \
                 longwave flux?)",
                path.display()
            ),
            EarthError::Read {
                path,
                variable,
                message,
            } => write!(
                f,
                "{}: reading `{variable}` failed: {message}",
                path.display()
            ),
        }
    }
}

impl std::error::Error for EarthError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        None
    }
}

/// TOA longwave flux on the 1° CERES SYN1deg grid: 180 rows (latitude centres
/// −89.5…89.5°, south → north), 360 columns (longitude centres 0.5…359.5° east),
/// W m⁻², row-major. Every value is finite and within the CERES `valid_range`
/// 0..=500 W m⁻² (checked once on construction).
#[derive(Debug, Clone, PartialEq)]
pub struct OlrGrid {
    values: Vec<f32>,
}

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
    /// [`ECLIPSE_FLUX_FACTOR`]). The result stays a valid grid: products above 500 W m⁻²
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
fn catmull_rom_weights(t: f64) -> [f64; 4] {
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
fn dot4(w: &[f64; 4], v: [f64; 4]) -> f64 {
    w[0] * v[0] + w[1] * v[1] + w[2] * v[2] + w[3] * v[3]
}

/// The four 1° rows around latitude `lat_deg` and their weights: rows clamped at the
/// poles (beyond ±89.5° the value is that of the edge row).
fn lat_stencil(lat_deg: f64) -> ([usize; 4], [f64; 4]) {
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
fn lon_stencil(lon_deg: f64) -> ([usize; 4], [f64; 4]) {
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
fn column_pass(temps: &[f32], rows: &[usize; 4], w: &[f64; 4], col: usize) -> (f64, f64, f64) {
    let v = rows.map(|r| f64::from(temps[r * OlrGrid::COLS + col]));
    let lo = v[0].min(v[1]).min(v[2]).min(v[3]);
    let hi = v[0].max(v[1]).max(v[2]).max(v[3]);
    (dot4(w, v), lo, hi)
}

/// Horizontal pass over the results of four column passes, clamped to the min/max of
/// the 4 × 4 nodes so that Catmull-Rom overshoot never leaves the data range.
fn row_pass(w: &[f64; 4], cols: [(f64, f64, f64); 4]) -> f32 {
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

/// The Earth's temperature and band radiance on a refined latitude/longitude mesh
/// (paper Section 3.2.2 and Fig. 3), built once by [`EarthMap::refine`].
///
/// The mesh has k = 1/`mesh_deg` cells per degree: 180k rows (south → north) by 360k
/// columns (eastwards from 0°); cell (r, c) spans latitudes −90 + r/k … −90 + (r+1)/k
/// and longitudes c/k … (c+1)/k. Each cell holds the Eq. 10 temperature interpolated
/// (bicubic Catmull-Rom, [`interpolate_temperature_k`]) at its centre and the band
/// radiance of a blackbody (ε = 1, as the paper assumes) at that temperature.
///
/// With `mesh_deg` = 1 the cell centres are the 1° nodes and the map reproduces the grid
/// exactly (Fig. 3a); with an odd k (0.2°) the cell centred on each node also holds the
/// node's own temperature; with an even k (0.1°) node centres fall on cell corners, and
/// the exactness at nodes holds for the interpolant, [`EarthMap::interpolated_temperature_k`].
///
/// Memory: 8 bytes per cell (f32 radiance + f32 temperature) plus 259 kB of 1° node
/// temperatures: 52.1 MB at 0.1° (6.48 M cells), 2.3 MB at 0.5°.
#[derive(Debug, Clone)]
pub struct EarthMap {
    /// Cells per degree, k.
    k: usize,
    /// Mesh rows, 180k.
    rows: usize,
    /// Mesh columns, 360k.
    cols: usize,
    /// Band radiance per cell, W m⁻² sr⁻¹, row-major.
    radiance: Vec<f32>,
    /// Temperature per cell, K, row-major.
    temperature: Vec<f32>,
    /// 1° node temperatures, K.
    node_temps: Vec<f32>,
    /// Smallest and largest cell radiance.
    min_max: (f32, f32),
}

impl EarthMap {
    /// The paper's refined mesh, degrees (Fig. 3b).
    pub const DEFAULT_MESH_DEG: f64 = 0.1;
    /// The finest mesh accepted, cells per degree (0.05°: 25.9 M cells, 207 MB).
    pub const MAX_CELLS_PER_DEG: usize = 20;

    /// Builds the map of `grid` at `mesh_deg` degrees per cell for the camera band
    /// `band`: Eq. 10 at the nodes, Catmull-Rom interpolation to every cell centre, band
    /// radiance per cell. Rows are built in parallel (rayon); the result does not depend
    /// on the thread count.
    ///
    /// # Errors
    /// [`EarthError::BadMesh`] unless `mesh_deg` is 1/k° for an integer k in
    /// 1..=[`EarthMap::MAX_CELLS_PER_DEG`] (1.0, 0.5, 0.25, 0.2, 0.1, 0.05, …).
    pub fn refine(grid: &OlrGrid, mesh_deg: f64, band: &BandLut) -> Result<EarthMap, EarthError> {
        let k = cells_per_degree(mesh_deg).ok_or(EarthError::BadMesh { mesh_deg })?;
        let (rows, cols) = (OlrGrid::ROWS * k, OlrGrid::COLS * k);
        let node_temps = grid.temperatures_k();
        let inv_k = 1.0 / k as f64;
        // The horizontal stencil depends on the column only.
        let lon_stencils: Vec<([usize; 4], [f64; 4])> = (0..cols)
            .map(|c| lon_stencil((c as f64 + 0.5) * inv_k))
            .collect();
        let mut radiance = vec![0.0f32; rows * cols];
        let mut temperature = vec![0.0f32; rows * cols];
        let per_row = |(r, (rad, temp)): (usize, (&mut [f32], &mut [f32]))| {
            let (lat_rows, wy) = lat_stencil((r as f64 + 0.5) * inv_k - 90.0);
            let passes: Vec<(f64, f64, f64)> = (0..OlrGrid::COLS)
                .map(|c| column_pass(&node_temps, &lat_rows, &wy, c))
                .collect();
            let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
            for ((rad, temp), (lon_cols, wx)) in
                rad.iter_mut().zip(temp.iter_mut()).zip(&lon_stencils)
            {
                let t = row_pass(wx, lon_cols.map(|c| passes[c]));
                let l = band
                    .radiance_f32(t, 1.0)
                    .map_err(|source| EarthError::Radiance { t_k: t, source })?;
                *temp = t;
                *rad = l;
                lo = lo.min(l);
                hi = hi.max(l);
            }
            Ok((lo, hi))
        };
        let min_max = radiance
            .par_chunks_mut(cols)
            .zip(temperature.par_chunks_mut(cols))
            .enumerate()
            .map(per_row)
            .try_reduce(
                || (f32::INFINITY, f32::NEG_INFINITY),
                |a, b| Ok((a.0.min(b.0), a.1.max(b.1))),
            )?;
        Ok(EarthMap {
            k,
            rows,
            cols,
            radiance,
            temperature,
            node_temps,
            min_max,
        })
    }

    /// The mesh size, degrees per cell (1/k).
    pub fn mesh_deg(&self) -> f64 {
        1.0 / self.k as f64
    }

    /// (rows, columns) of the mesh: (180k, 360k).
    pub fn shape(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    /// Index of the cell containing (lat, lon): clamped at the poles, wrapped in
    /// longitude; NaN or infinite coordinates give cell row/column 0.
    #[inline]
    fn cell(&self, lat_deg: f64, lon_deg: f64) -> usize {
        let k = self.k as f64;
        // `as usize` saturates: negative and NaN → 0.
        let r = (((lat_deg + 90.0) * k) as usize).min(self.rows - 1);
        // fmod only when the longitude is not already in [0, 360).
        let lon = if (0.0..360.0).contains(&lon_deg) {
            lon_deg
        } else {
            lon_deg.rem_euclid(360.0)
        };
        let c = ((lon * k) as usize).min(self.cols - 1);
        r * self.cols + c
    }

    /// Band radiance of the mesh cell containing (`lat_deg`, `lon_deg`), W m⁻² sr⁻¹.
    /// Latitude −90…90° (clamped beyond), any longitude (wrapped). Nearest cell: a mesh
    /// element is flat, as in the paper's rendered mesh. No allocation, a few flops.
    #[inline]
    pub fn radiance_w_m2_sr(&self, lat_deg: f64, lon_deg: f64) -> f32 {
        self.radiance[self.cell(lat_deg, lon_deg)]
    }

    /// Temperature of the mesh cell containing (`lat_deg`, `lon_deg`), K (same lookup
    /// as [`EarthMap::radiance_w_m2_sr`]).
    #[inline]
    pub fn temperature_k(&self, lat_deg: f64, lon_deg: f64) -> f32 {
        self.temperature[self.cell(lat_deg, lon_deg)]
    }

    /// The continuous interpolant the cells are sampled from, K: exact at the 1° nodes
    /// (see [`interpolate_temperature_k`]); NaN for NaN coordinates.
    pub fn interpolated_temperature_k(&self, lat_deg: f64, lon_deg: f64) -> f32 {
        interpolate_temperature_k(&self.node_temps, lat_deg, lon_deg).unwrap_or(f32::NAN)
    }

    /// Smallest and largest cell radiance, W m⁻² sr⁻¹ (for an auto-span display scale,
    /// as the paper's Fig. 3).
    pub fn min_max_radiance_w_m2_sr(&self) -> (f32, f32) {
        self.min_max
    }

    /// Cell temperatures, K, row-major (south → north, eastwards from 0°).
    pub fn temperatures_k(&self) -> &[f32] {
        &self.temperature
    }

    /// Cell radiances, W m⁻² sr⁻¹, row-major (south → north, eastwards from 0°).
    pub fn radiances_w_m2_sr(&self) -> &[f32] {
        &self.radiance
    }

    /// Heap memory held by the map, bytes.
    pub fn memory_bytes(&self) -> usize {
        (self.radiance.capacity() + self.temperature.capacity() + self.node_temps.capacity())
            * size_of::<f32>()
    }
}

/// k if `mesh_deg` = 1/k for an integer k in 1..=MAX (to 1e-9 relative).
fn cells_per_degree(mesh_deg: f64) -> Option<usize> {
    if !(mesh_deg.is_finite() && mesh_deg > 0.0) {
        return None;
    }
    let k = (1.0 / mesh_deg).round();
    ((1.0..=EarthMap::MAX_CELLS_PER_DEG as f64).contains(&k) && (k * mesh_deg - 1.0).abs() < 1e-9)
        .then_some(k as usize)
}

// ---------------------------------------------------------------------------------
// The built-in synthetic field.
// ---------------------------------------------------------------------------------

/// Piecewise-linear interpolation in a table of (latitude°, value) anchors sorted by
/// latitude; flat beyond the ends.
fn profile(table: &[(f64, f64)], lat_deg: f64) -> f64 {
    let (first, last) = (table[0], table[table.len() - 1]);
    if lat_deg <= first.0 {
        return first.1;
    }
    for pair in table.windows(2) {
        let ((la, va), (lb, vb)) = (pair[0], pair[1]);
        if lat_deg <= lb {
            return va + (vb - va) * (lat_deg - la) / (lb - la);
        }
    }
    last.1
}

/// All-sky zonal-mean OLR anchors (latitude°, W m⁻²) the built-in field reproduces row
/// by row: the shape of the annual-mean zonal all-sky OLR of CERES EBAF-TOA Ed4
/// (Loeb et al., J. Climate 31:895, 2018) and ERBE (Harrison et al., J. Geophys. Res.
/// 95:18687, 1990): the ITCZ dip at 5° N, subtropical maxima at 20–25°, the
/// mid-latitude decline and a colder Antarctic than Arctic. Approximate values (about
/// ±10 W m⁻²), written from those published profiles, not digitised from the data.
/// Area-weighted mean 239.6 W m⁻² (asserted in the tests).
pub const BUILTIN_ZONAL_OLR_W_M2: [(f64, f64); 25] = [
    (-90.0, 158.0),
    (-80.0, 165.0),
    (-70.0, 185.0),
    (-60.0, 200.0),
    (-50.0, 213.0),
    (-45.0, 222.0),
    (-40.0, 234.0),
    (-30.0, 258.0),
    (-20.0, 272.0),
    (-15.0, 268.0),
    (-10.0, 258.0),
    (-5.0, 250.0),
    (0.0, 250.0),
    (5.0, 238.0),
    (10.0, 245.0),
    (15.0, 262.0),
    (22.0, 278.0),
    (30.0, 268.0),
    (40.0, 244.0),
    (45.0, 232.0),
    (50.0, 220.0),
    (60.0, 200.0),
    (70.0, 187.0),
    (80.0, 178.0),
    (90.0, 176.0),
];

/// Clear-sky zonal OLR anchors (latitude°, W m⁻²) from the same CERES EBAF clear-sky
/// climatology: the flux of the cloud-free parts of the built-in field before the
/// surface anomalies (deserts, plateaus) are added.
const CLEAR_SKY_OLR_W_M2: [(f64, f64); 19] = [
    (-90.0, 166.0),
    (-80.0, 172.0),
    (-70.0, 197.0),
    (-60.0, 220.0),
    (-50.0, 238.0),
    (-40.0, 257.0),
    (-30.0, 279.0),
    (-20.0, 290.0),
    (-10.0, 290.0),
    (0.0, 289.0),
    (10.0, 290.0),
    (20.0, 296.0),
    (30.0, 289.0),
    (40.0, 266.0),
    (50.0, 246.0),
    (60.0, 226.0),
    (70.0, 205.0),
    (80.0, 190.0),
    (90.0, 186.0),
];

/// OLR lost under the thickest, highest cloud of each latitude (latitude°, W m⁻²):
/// clear-sky OLR minus the emission of cloud tops at about 200 K (≈105 W m⁻²) in deep
/// tropical convection, about 230 K (≈140 W m⁻²) in mid-latitude fronts, and small over
/// the polar ice, where cloud tops are barely colder than the surface.
const CLOUD_DEPTH_W_M2: [(f64, f64); 15] = [
    (-90.0, 18.0),
    (-75.0, 30.0),
    (-60.0, 70.0),
    (-45.0, 112.0),
    (-30.0, 120.0),
    (-20.0, 150.0),
    (-10.0, 180.0),
    (0.0, 185.0),
    (10.0, 185.0),
    (20.0, 150.0),
    (30.0, 120.0),
    (45.0, 112.0),
    (60.0, 70.0),
    (75.0, 40.0),
    (90.0, 25.0),
];

/// A surface feature of the built-in field: a Gaussian patch (centre latitude° and
/// longitude° E, half-widths in degrees) that adds `clear_w_m2` to the clear-sky flux
/// and `convection` to the cloud propensity (negative: suppresses cloud).
struct Patch {
    lat: f64,
    lon: f64,
    sigma_lat: f64,
    sigma_lon: f64,
    clear_w_m2: f64,
    convection: f64,
}

/// Hot deserts (warm, cloud-free), high cold plateaus and ice sheets, and the three
/// tropical convection centres (maritime continent/warm pool, Amazon, Congo), placed
/// at their real positions so the disc looks like the Earth's.
const PATCHES: [Patch; 13] = [
    // Sahara, Arabia, Thar; Australian and southern African deserts; Sonoran.
    patch(23.0, 10.0, 7.0, 22.0, 26.0, -1.2),
    patch(22.0, 47.0, 6.0, 9.0, 24.0, -1.0),
    patch(27.0, 70.0, 4.0, 5.0, 12.0, -0.4),
    patch(-25.0, 132.0, 6.0, 12.0, 18.0, -0.8),
    patch(-24.0, 20.0, 5.0, 6.0, 12.0, -0.6),
    patch(30.0, 248.0, 5.0, 7.0, 12.0, -0.5),
    // Tibetan plateau, Greenland, East Antarctic plateau, Andes altiplano.
    patch(33.0, 88.0, 4.0, 10.0, -18.0, 0.0),
    patch(73.0, 318.0, 7.0, 12.0, -14.0, 0.0),
    patch(-82.0, 90.0, 6.0, 60.0, -10.0, 0.0),
    patch(-17.0, 292.0, 4.0, 3.0, -10.0, 0.0),
    // Convection centres: warm pool, Amazon, Congo.
    patch(0.0, 130.0, 12.0, 35.0, 0.0, 0.9),
    patch(-5.0, 298.0, 10.0, 14.0, 0.0, 0.7),
    patch(0.0, 22.0, 8.0, 10.0, 0.0, 0.6),
];

const fn patch(
    lat: f64,
    lon: f64,
    sigma_lat: f64,
    sigma_lon: f64,
    clear_w_m2: f64,
    convection: f64,
) -> Patch {
    Patch {
        lat,
        lon,
        sigma_lat,
        sigma_lon,
        clear_w_m2,
        convection,
    }
}

impl Patch {
    /// Gaussian weight of the patch at (lat, lon), longitude distance wrapped.
    fn weight(&self, lat: f64, lon: f64) -> f64 {
        let dlon = (lon - self.lon + 540.0).rem_euclid(360.0) - 180.0;
        let u = (lat - self.lat) / self.sigma_lat;
        let v = dlon / self.sigma_lon;
        libm::exp(-0.5 * (u * u + v * v))
    }
}

/// Integer hash (the 32-bit finaliser of MurmurHash3 over a mixed key): the gradient
/// index of a lattice point, the same on every platform.
fn hash3(seed: u32, x: i32, y: i32, z: i32) -> u32 {
    let mut h = seed
        ^ (x as u32).wrapping_mul(0x8da6_b343)
        ^ (y as u32).wrapping_mul(0xd816_3841)
        ^ (z as u32).wrapping_mul(0xcb1a_b31f);
    h ^= h >> 16;
    h = h.wrapping_mul(0x85eb_ca6b);
    h ^= h >> 13;
    h = h.wrapping_mul(0xc2b2_ae35);
    h ^ (h >> 16)
}

/// Gradient of a lattice point: one of the 12 cube-edge directions of improved Perlin
/// noise, dotted with the offset (dx, dy, dz).
fn grad(h: u32, dx: f64, dy: f64, dz: f64) -> f64 {
    match h % 12 {
        0 => dx + dy,
        1 => -dx + dy,
        2 => dx - dy,
        3 => -dx - dy,
        4 => dx + dz,
        5 => -dx + dz,
        6 => dx - dz,
        7 => -dx - dz,
        8 => dy + dz,
        9 => -dy + dz,
        10 => dy - dz,
        _ => -dy - dz,
    }
}

/// Perlin's quintic fade 6t⁵ − 15t⁴ + 10t³.
fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// 3-D gradient noise (K. Perlin, "Improving noise", SIGGRAPH 2002) with hashed
/// gradients; about −1…1, 0 at lattice points.
fn gradient_noise(seed: u32, p: [f64; 3]) -> f64 {
    let f = p.map(f64::floor);
    let [ix, iy, iz] = f.map(|v| v as i32);
    let [dx, dy, dz] = [p[0] - f[0], p[1] - f[1], p[2] - f[2]];
    let [u, v, w] = [fade(dx), fade(dy), fade(dz)];
    let corner = |a: i32, b: i32, c: i32| {
        grad(
            hash3(seed, ix + a, iy + b, iz + c),
            dx - f64::from(a),
            dy - f64::from(b),
            dz - f64::from(c),
        )
    };
    let lerp = |t: f64, a: f64, b: f64| a + t * (b - a);
    let x00 = lerp(u, corner(0, 0, 0), corner(1, 0, 0));
    let x10 = lerp(u, corner(0, 1, 0), corner(1, 1, 0));
    let x01 = lerp(u, corner(0, 0, 1), corner(1, 0, 1));
    let x11 = lerp(u, corner(0, 1, 1), corner(1, 1, 1));
    lerp(w, lerp(v, x00, x10), lerp(v, x01, x11))
}

/// Fractal sum of `seeds.len()` octaves (frequency ×2, amplitude ×0.5 per octave),
/// each octave with its own lattice (seed) and offset.
fn fractal_noise(seeds: &[(u32, [f64; 3])], p: [f64; 3], first_freq: f64) -> f64 {
    let (mut sum, mut amp, mut norm, mut freq) = (0.0, 1.0, 0.0, first_freq);
    for (seed, offset) in seeds {
        let q = [
            p[0] * freq + offset[0],
            p[1] * freq + offset[1],
            p[2] * freq + offset[2],
        ];
        sum += amp * gradient_noise(*seed, q);
        norm += amp;
        amp *= 0.62;
        freq *= 2.0;
    }
    sum / norm
}

/// Octaves of the cloud texture: lattice cells of 30°, 15°, … 0.94° of latitude, so
/// the last one gives 1° detail.
const CLOUD_OCTAVES: usize = 6;
/// Amplitude of the domain warp, radians of great circle (~1000 km).
const WARP: f64 = 0.15;
/// Octaves of the domain warp (swirls, tilted frontal bands).
const WARP_OCTAVES: usize = 3;
/// Degrees of latitude per lattice cell of the first cloud octave (~3300 km).
const CLOUD_SCALE_DEG: f64 = 30.0;
/// Width of the cloud ramp, in standard deviations of the cloud texture: from clear
/// (texture below the row threshold) to full cloud depth over this much texture.
const CLOUD_RAMP: f64 = 1.6;

impl OlrGrid {
    /// A synthetic daily all-sky OLR map, deterministic for `seed` (the same bytes on
    /// every platform and thread count). **Not real data**: it is built to have the
    /// statistics of a CERES SYN1deg daily field, for scenes and tests without a CERES
    /// file.
    ///
    /// Construction, per 1° node:
    /// - clear-sky flux: the zonal clear-sky profile of the CERES EBAF climatology plus
    ///   warm deserts (Sahara, Arabia, Australia, …) and cold plateaus and ice sheets
    ///   (Tibet, Greenland, East Antarctica) at their real places, plus a ±5 W m⁻²
    ///   seeded texture;
    /// - cloud: a seeded fractal gradient noise (6 octaves, 3300 km down to 100 km)
    ///   on the sphere, domain-warped (swirls) and stretched 2.6× zonally at 50° of
    ///   latitude (frontal bands), biased up over the tropical convection centres
    ///   and down over the deserts; cloud depth c ∈ [0, 1] is a ramp of that texture,
    ///   and OLR = clear − c·D(φ) with D the loss under the highest cloud of that
    ///   latitude (≈185 W m⁻² in deep tropical convection, so cores reach ~105 W m⁻²);
    /// - per latitude row the cloud threshold is solved (bisection) so that the zonal
    ///   mean matches [`BUILTIN_ZONAL_OLR_W_M2`] (then smoothed over ±3 rows), so the
    ///   global mean is about 240 W m⁻²; values are clamped to 100–330 W m⁻².
    pub fn builtin(seed: u64) -> OlrGrid {
        let mut rng = tirroi_core::sensor::rng::Xoshiro128pp::seed_from_u64(seed);
        let octaves = |n: usize, rng: &mut tirroi_core::sensor::rng::Xoshiro128pp| {
            (0..n)
                .map(|_| {
                    let s = rng.next_u32();
                    // Offsets in [0, 256) lattice cells, so no two octaves share a lattice.
                    let o = [0; 3].map(|_: i32| f64::from(rng.next_u32() >> 8) / 65_536.0);
                    (s, o)
                })
                .collect::<Vec<_>>()
        };
        let cloud = octaves(CLOUD_OCTAVES, &mut rng);
        let warp: Vec<Vec<(u32, [f64; 3])>> =
            (0..3).map(|_| octaves(WARP_OCTAVES, &mut rng)).collect();
        let clear_tex = octaves(3, &mut rng);

        let n = Self::ROWS * Self::COLS;
        let deg = std::f64::consts::PI / 180.0;
        // Per node: (cloud texture, clear-sky flux, convective propensity). Every node
        // is computed on its own, so the parallel, order-preserving collect gives the
        // same bytes for any thread count.
        let node = |i: usize| {
            let (lat, lon) = (
                Self::node_lat_deg(i / Self::COLS),
                Self::node_lon_deg(i % Self::COLS),
            );
            let (s_lat, c_lat) = (libm::sin(lat * deg), libm::cos(lat * deg));
            let (s_lon, c_lon) = (libm::sin(lon * deg), libm::cos(lon * deg));
            // Zonal stretch: 2.6 at 50° of latitude, 1 in the tropics and at the poles.
            let z = (lat.abs() - 50.0) / 18.0;
            let stretch = 1.0 + 1.6 * libm::exp(-z * z);
            // The unit sphere (distances in radians of great circle) for isotropic
            // fields.
            let unit = [c_lat * c_lon, c_lat * s_lon, s_lat];
            let w = [0, 1, 2].map(|a| fractal_noise(&warp[a], unit, 1.2));
            // A cylinder around the polar axis: height = latitude (radians), radius
            // = cos φ / stretch, so a step east covers 1/stretch of the texture
            // distance of the same step north (zonal stretching); then warped.
            let r = c_lat / stretch;
            let p = [
                r * c_lon + WARP * w[0],
                r * s_lon + WARP * w[1],
                lat * deg + WARP * w[2],
            ];
            let texture = fractal_noise(&cloud, p, 180.0 / CLOUD_SCALE_DEG / std::f64::consts::PI);
            let mut surface = 5.0 * fractal_noise(&clear_tex, unit, 3.0);
            let mut convect = 0.0;
            for patch in &PATCHES {
                let wgt = patch.weight(lat, lon);
                surface += wgt * patch.clear_w_m2;
                convect += wgt * patch.convection;
            }
            (
                texture,
                profile(&CLEAR_SKY_OLR_W_M2, lat) + surface,
                convect,
            )
        };
        let nodes: Vec<(f64, f64, f64)> = (0..n).into_par_iter().map(node).collect();
        let mut texture: Vec<f64> = nodes.iter().map(|v| v.0).collect();
        let clear: Vec<f64> = nodes.iter().map(|v| v.1).collect();
        let propensity: Vec<f64> = nodes.iter().map(|v| v.2).collect();
        // Standardise the texture (mean 0, sd 1) in a fixed summation order.
        let mean = texture.iter().sum::<f64>() / n as f64;
        let var = texture.iter().map(|t| (t - mean) * (t - mean)).sum::<f64>() / n as f64;
        let sd = var.sqrt().max(1e-12);
        for (t, p) in texture.iter_mut().zip(&propensity) {
            *t = (*t - mean) / sd + p;
        }

        // Per row: the threshold that gives the target zonal mean.
        let olr_at = |i: usize, depth: f64, thr: f64| {
            let c = ((texture[i] - thr) / CLOUD_RAMP).clamp(0.0, 1.0);
            clear[i] - depth * c
        };
        let thresholds: Vec<f64> = (0..Self::ROWS)
            .into_par_iter()
            .map(|row| {
                let lat = Self::node_lat_deg(row);
                let target = profile(&BUILTIN_ZONAL_OLR_W_M2, lat);
                let depth = profile(&CLOUD_DEPTH_W_M2, lat);
                let row_mean = |thr: f64| {
                    (0..Self::COLS)
                        .map(|col| olr_at(row * Self::COLS + col, depth, thr))
                        .sum::<f64>()
                        / Self::COLS as f64
                };
                let (mut lo, mut hi) = (-8.0, 8.0);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    if row_mean(mid) < target {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                0.5 * (lo + hi)
            })
            .collect();
        let values = (0..n)
            .map(|i| {
                let row = i / Self::COLS;
                let lat = Self::node_lat_deg(row);
                // Triangle-smoothed threshold over ±3 rows (clamped at the poles).
                let (mut sum, mut wsum) = (0.0, 0.0);
                for d in -3i32..=3 {
                    let r = (row as i32 + d).clamp(0, Self::ROWS as i32 - 1) as usize;
                    let w = f64::from(4 - d.abs());
                    sum += w * thresholds[r];
                    wsum += w;
                }
                let v = olr_at(i, profile(&CLOUD_DEPTH_W_M2, lat), sum / wsum);
                v.clamp(100.0, 330.0) as f32
            })
            .collect();
        OlrGrid { values }
    }
}

// ---------------------------------------------------------------------------------
// CERES NetCDF reader (cargo feature `netcdf`).
// ---------------------------------------------------------------------------------

#[cfg(feature = "netcdf")]
impl OlrGrid {
    /// Reads one daily map of `variable` (e.g. `toa_lw_all_daily` of a CERES SYN1deg
    /// ordering-tool subset) at `time_index` (0-based) from the NetCDF file `path`.
    ///
    /// Accepted form: dimensions (lat, lon) or (lon, lat), or three dimensions of which
    /// two are lat/latitude (180 long) and lon/longitude (360 long) and the third is
    /// time (any name); a 2-D variable counts as one time step. The coordinate variables
    /// of the same names give the order: latitudes ±89.5…∓89.5 in either direction and
    /// longitudes 0.5…359.5 or −179.5…179.5 (any rotation) are reordered to this type's
    /// south → north, 0.5° E eastwards convention. Packed data are decoded as
    /// `raw · scale_factor + add_offset`; raw values equal to `_FillValue` or
    /// `missing_value`, NaN, or the NetCDF default fill (|v| ≥ 9.9e36) are fill values.
    ///
    /// # Errors
    /// [`EarthError::Open`] (missing or unreadable file), [`EarthError::MissingVariable`],
    /// [`EarthError::BadShape`] (not a 180 × 360 1° map), [`EarthError::TimeIndex`],
    /// [`EarthError::BadCoordinate`] (a coordinate missing or not on the 1° centres),
    /// [`EarthError::FillValues`] (any fill value in the slice),
    /// [`EarthError::OutOfRange`] (a decoded value outside 0..=500 W m⁻²),
    /// [`EarthError::Read`] (the library failed to read).
    pub fn load_netcdf(
        path: &std::path::Path,
        variable: &str,
        time_index: usize,
    ) -> Result<OlrGrid, EarthError> {
        netcdf_io::load(path, variable, time_index)
    }
}

#[cfg(feature = "netcdf")]
mod netcdf_io {
    use std::path::Path;

    use netcdf::{AttributeValue, Extent};

    use super::{EarthError, OLR_MAX_W_M2, OLR_MIN_W_M2, OlrGrid};

    /// Names a latitude / longitude dimension and coordinate variable may have.
    const LAT_NAMES: [&str; 2] = ["lat", "latitude"];
    const LON_NAMES: [&str; 2] = ["lon", "longitude"];
    /// Tolerance on coordinate values, degrees.
    const COORD_TOL_DEG: f64 = 1e-3;

    pub(super) fn load(
        path: &Path,
        variable: &str,
        time_index: usize,
    ) -> Result<OlrGrid, EarthError> {
        let path_buf = path.to_path_buf();
        if !path.is_file() {
            return Err(EarthError::Open {
                path: path_buf,
                message: if path.exists() {
                    "not a regular file".into()
                } else {
                    "no such file".into()
                },
            });
        }
        let file = netcdf::open(path).map_err(|e| EarthError::Open {
            path: path_buf.clone(),
            message: e.to_string(),
        })?;
        let var = file
            .variable(variable)
            .ok_or_else(|| EarthError::MissingVariable {
                path: path_buf.clone(),
                variable: variable.into(),
                available: file.variables().map(|v| v.name()).collect(),
            })?;
        let read_err = |what: &str, e: netcdf::Error| EarthError::Read {
            path: path_buf.clone(),
            variable: what.into(),
            message: e.to_string(),
        };

        // Dimensions: find lat, lon and (optionally) time.
        let dims: Vec<(String, usize)> = var
            .dimensions()
            .iter()
            .map(|d| (d.name(), d.len()))
            .collect();
        let bad_shape = || EarthError::BadShape {
            path: path_buf.clone(),
            variable: variable.into(),
            found: dims
                .iter()
                .map(|(n, l)| format!("{n}={l}"))
                .collect::<Vec<_>>()
                .join(", "),
        };
        let find = |names: &[&str]| {
            dims.iter()
                .position(|(n, _)| names.iter().any(|m| n.eq_ignore_ascii_case(m)))
        };
        let (Some(lat_axis), Some(lon_axis)) = (find(&LAT_NAMES), find(&LON_NAMES)) else {
            return Err(bad_shape());
        };
        if !(2..=3).contains(&dims.len())
            || dims[lat_axis].1 != OlrGrid::ROWS
            || dims[lon_axis].1 != OlrGrid::COLS
        {
            return Err(bad_shape());
        }
        let time_axis = (0..dims.len()).find(|&a| a != lat_axis && a != lon_axis);
        let time_len = time_axis.map_or(1, |a| dims[a].1);
        if time_index >= time_len {
            return Err(EarthError::TimeIndex {
                path: path_buf.clone(),
                variable: variable.into(),
                index: time_index,
                len: time_len,
            });
        }

        // Coordinates → destination row / column of every file index.
        let coord = |axis: usize| -> Result<Vec<f64>, EarthError> {
            let name = &dims[axis].0;
            let cvar = file
                .variable(name)
                .ok_or_else(|| EarthError::BadCoordinate {
                    path: path_buf.clone(),
                    coordinate: name.clone(),
                    problem: "the file has no coordinate variable of that name".into(),
                })?;
            cvar.get_values::<f64, _>(..).map_err(|e| read_err(name, e))
        };
        let lat = coord(lat_axis)?;
        let lon = coord(lon_axis)?;
        let rows = node_indices(&lat, OlrGrid::ROWS, |v| v + 89.5).map_err(|problem| {
            EarthError::BadCoordinate {
                path: path_buf.clone(),
                coordinate: dims[lat_axis].0.clone(),
                problem,
            }
        })?;
        let cols = node_indices(&lon, OlrGrid::COLS, |v| v.rem_euclid(360.0) - 0.5).map_err(
            |problem| EarthError::BadCoordinate {
                path: path_buf.clone(),
                coordinate: dims[lon_axis].0.clone(),
                problem,
            },
        )?;

        // Packing and fill attributes.
        let attr = |name: &str| -> Result<Vec<f64>, EarthError> {
            match var.attribute_value(name) {
                None => Ok(Vec::new()),
                Some(v) => attribute_numbers(v.map_err(|e| read_err(name, e))?).ok_or_else(|| {
                    EarthError::Read {
                        path: path_buf.clone(),
                        variable: format!("{variable}:{name}"),
                        message: "the attribute is not numeric".into(),
                    }
                }),
            }
        };
        let scale = attr("scale_factor")?.first().copied().unwrap_or(1.0);
        let offset = attr("add_offset")?.first().copied().unwrap_or(0.0);
        let mut fills = attr("_FillValue")?;
        fills.extend(attr("missing_value")?);

        // The slice at `time_index`, in the file's (lat, lon) or (lon, lat) order.
        let extents: Vec<Extent> = (0..dims.len())
            .map(|a| {
                if Some(a) == time_axis {
                    Extent::from(time_index)
                } else {
                    Extent::from(..)
                }
            })
            .collect();
        let raw = var
            .get_values::<f64, _>(extents)
            .map_err(|e| read_err(variable, e))?;
        let lat_first = lat_axis < lon_axis;

        let mut values = vec![0.0f32; OlrGrid::ROWS * OlrGrid::COLS];
        if raw.len() != values.len() {
            return Err(bad_shape());
        }
        let mut fill_count = 0usize;
        let mut first_fill = None;
        for (k, &r) in raw.iter().enumerate() {
            let (i_lat, i_lon) = if lat_first {
                (k / OlrGrid::COLS, k % OlrGrid::COLS)
            } else {
                (k % OlrGrid::ROWS, k / OlrGrid::ROWS)
            };
            if r.is_nan() || r.abs() >= 9.9e36 || fills.contains(&r) {
                fill_count += 1;
                first_fill.get_or_insert((lat[i_lat], lon[i_lon]));
                continue;
            }
            let v = r * scale + offset;
            if !(f64::from(OLR_MIN_W_M2)..=f64::from(OLR_MAX_W_M2)).contains(&v) {
                return Err(EarthError::OutOfRange {
                    path: path_buf,
                    variable: variable.into(),
                    lat_deg: lat[i_lat],
                    lon_deg: lon[i_lon],
                    value: v,
                });
            }
            values[rows[i_lat] * OlrGrid::COLS + cols[i_lon]] = v as f32;
        }
        if let Some((lat_deg, lon_deg)) = first_fill {
            return Err(EarthError::FillValues {
                path: path_buf,
                variable: variable.into(),
                count: fill_count,
                lat_deg,
                lon_deg,
            });
        }
        OlrGrid::from_values(values)
    }

    /// Maps `n` coordinate values to node indices 0..n with `to_index` (value → index
    /// as a float): every value must lie within [`COORD_TOL_DEG`] of an integer index
    /// and every index must occur once.
    fn node_indices(
        values: &[f64],
        n: usize,
        to_index: impl Fn(f64) -> f64,
    ) -> Result<Vec<usize>, String> {
        if values.len() != n {
            return Err(format!("{} values, expected {n}", values.len()));
        }
        let mut seen = vec![false; n];
        let mut out = Vec::with_capacity(n);
        for &v in values {
            let x = to_index(v);
            let i = x.round();
            if !(x - i).abs().le(&COORD_TOL_DEG) || !(0.0..n as f64).contains(&i) {
                return Err(format!(
                    "value {v} is not a cell centre of the 1° grid (x.5 degrees)"
                ));
            }
            let i = i as usize;
            if seen[i] {
                return Err(format!("value {v} occurs twice"));
            }
            seen[i] = true;
            out.push(i);
        }
        Ok(out)
    }

    /// The numbers of a numeric attribute (scalar or list); `None` for text.
    fn attribute_numbers(value: AttributeValue) -> Option<Vec<f64>> {
        use AttributeValue as A;
        Some(match value {
            A::Uchar(x) => vec![f64::from(x)],
            A::Uchars(x) => x.into_iter().map(f64::from).collect(),
            A::Schar(x) => vec![f64::from(x)],
            A::Schars(x) => x.into_iter().map(f64::from).collect(),
            A::Ushort(x) => vec![f64::from(x)],
            A::Ushorts(x) => x.into_iter().map(f64::from).collect(),
            A::Short(x) => vec![f64::from(x)],
            A::Shorts(x) => x.into_iter().map(f64::from).collect(),
            A::Uint(x) => vec![f64::from(x)],
            A::Uints(x) => x.into_iter().map(f64::from).collect(),
            A::Int(x) => vec![f64::from(x)],
            A::Ints(x) => x.into_iter().map(f64::from).collect(),
            A::Ulonglong(x) => vec![x as f64],
            A::Ulonglongs(x) => x.into_iter().map(|v| v as f64).collect(),
            A::Longlong(x) => vec![x as f64],
            A::Longlongs(x) => x.into_iter().map(|v| v as f64).collect(),
            A::Float(x) => vec![f64::from(x)],
            A::Floats(x) => x.into_iter().map(f64::from).collect(),
            A::Double(x) => vec![x],
            A::Doubles(x) => x,
            A::Str(_) | A::Strs(_) => return None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catmull_rom_weights_sum_to_one_and_hit_the_nodes() {
        assert_eq!(catmull_rom_weights(0.0), [0.0, 1.0, 0.0, 0.0]);
        assert_eq!(catmull_rom_weights(1.0), [0.0, 0.0, 1.0, 0.0]);
        for i in 0..=100 {
            let w = catmull_rom_weights(f64::from(i) / 100.0);
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        }
        // Linear data are reproduced exactly (Catmull-Rom is exact for degree 1).
        let w = catmull_rom_weights(0.3);
        assert!((dot4(&w, [-1.0, 0.0, 1.0, 2.0]) - 0.3).abs() < 1e-15);
    }

    #[test]
    fn stencils_wrap_in_longitude_and_clamp_at_the_poles() {
        assert_eq!(lon_stencil(0.5).0, [359, 0, 1, 2]);
        assert_eq!(lon_stencil(0.0).0, [358, 359, 0, 1]);
        assert_eq!(lon_stencil(359.9).0, [358, 359, 0, 1]);
        assert_eq!(lon_stencil(-0.1).0, lon_stencil(359.9).0);
        assert_eq!(lat_stencil(-90.0).0, [0, 0, 1, 2]);
        assert_eq!(lat_stencil(90.0).0, [177, 178, 179, 179]);
        assert_eq!(lat_stencil(90.0).1, [0.0, 0.0, 1.0, 0.0]);
    }

    #[test]
    fn mesh_sizes_must_be_a_degree_over_an_integer() {
        assert_eq!(cells_per_degree(1.0), Some(1));
        assert_eq!(cells_per_degree(0.1), Some(10));
        assert_eq!(cells_per_degree(1.0 / 3.0), Some(3));
        assert_eq!(cells_per_degree(0.05), Some(20));
        for bad in [0.0, -1.0, 0.3, 0.04, 2.0, f64::NAN, f64::INFINITY] {
            assert_eq!(cells_per_degree(bad), None, "{bad}");
        }
    }

    #[test]
    fn profiles_interpolate_their_anchors() {
        assert_eq!(profile(&BUILTIN_ZONAL_OLR_W_M2, -90.0), 158.0);
        assert_eq!(profile(&BUILTIN_ZONAL_OLR_W_M2, 22.0), 278.0);
        assert_eq!(profile(&BUILTIN_ZONAL_OLR_W_M2, 26.0), 273.0);
        assert_eq!(profile(&BUILTIN_ZONAL_OLR_W_M2, 95.0), 176.0);
        // Every cloud can only lower the flux, and the thickest tropical cloud reaches
        // deep-convective cloud-top values (~105 W m⁻²).
        for lat in -90..=90 {
            let lat = f64::from(lat);
            assert!(profile(&CLOUD_DEPTH_W_M2, lat) > 0.0);
            assert!(profile(&CLEAR_SKY_OLR_W_M2, lat) > profile(&BUILTIN_ZONAL_OLR_W_M2, lat));
        }
        let core = profile(&CLEAR_SKY_OLR_W_M2, 5.0) - profile(&CLOUD_DEPTH_W_M2, 5.0);
        assert!((100.0..=110.0).contains(&core), "{core}");
    }

    #[test]
    fn errors_say_what_to_do() {
        let e = EarthError::BadMesh { mesh_deg: 0.3 };
        assert!(e.to_string().contains("0.1"));
        let e = EarthError::MissingVariable {
            path: "a.nc".into(),
            variable: "olr".into(),
            available: vec!["lat".into(), "lon".into()],
        };
        let msg = e.to_string();
        assert!(msg.contains("a.nc") && msg.contains("`olr`") && msg.contains("toa_lw_all_daily"));
    }
}
