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

use tirroi_core::sensor::planck::STEFAN_BOLTZMANN_W_M2_K4;

mod builtin;
#[cfg(feature = "netcdf")]
mod ceres;
pub mod clouds;
mod error;
mod grid;
mod refine;
#[cfg(test)]
mod tests;
pub mod texture_stats;

pub use builtin::BUILTIN_ZONAL_OLR_W_M2;
pub use clouds::CloudField;
pub use error::EarthError;
pub use grid::interpolate_temperature_k;

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

/// TOA longwave flux on the 1° CERES SYN1deg grid: 180 rows (latitude centres
/// −89.5…89.5°, south → north), 360 columns (longitude centres 0.5…359.5° east),
/// W m⁻², row-major. Every value is finite and within the CERES `valid_range`
/// 0..=500 W m⁻² (checked once on construction).
#[derive(Debug, Clone, PartialEq)]
pub struct OlrGrid {
    values: Vec<f32>,
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
    /// The sub-grid cloud texture (`earth_model.texture = "clouds"`), if any (shared
    /// between the sunlit and the eclipse map of a day).
    clouds: Option<std::sync::Arc<clouds::CloudField>>,
    /// Factor on the texture's temperatures (1 sunlit; (eclipse factor)^¼ in eclipse,
    /// so every cell's σT⁴ scales by the eclipse factor exactly).
    cloud_t_scale: f64,
}
