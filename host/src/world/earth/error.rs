//! [`EarthError`]: why an Earth source was refused, and its one-paragraph message.

use crate::world::earth::EarthMap;
use crate::world::earth::OlrGrid;
use std::fmt;
use std::path::PathBuf;

use tirroi_core::sensor::SensorError;

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
