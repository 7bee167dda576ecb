//! The CERES SYN1deg NetCDF reader, `OlrGrid::load_netcdf` (cargo feature `netcdf`).

use std::path::Path;

use netcdf::{AttributeValue, Extent};

use super::{EarthError, OLR_MAX_W_M2, OLR_MIN_W_M2, OlrGrid};

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
        load(path, variable, time_index)
    }
}

/// Names a latitude / longitude dimension and coordinate variable may have.
const LAT_NAMES: [&str; 2] = ["lat", "latitude"];
const LON_NAMES: [&str; 2] = ["lon", "longitude"];
/// Tolerance on coordinate values, degrees.
const COORD_TOL_DEG: f64 = 1e-3;

fn load(path: &Path, variable: &str, time_index: usize) -> Result<OlrGrid, EarthError> {
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
    let cols =
        node_indices(&lon, OlrGrid::COLS, |v| v.rem_euclid(360.0) - 0.5).map_err(|problem| {
            EarthError::BadCoordinate {
                path: path_buf.clone(),
                coordinate: dims[lon_axis].0.clone(),
                problem,
            }
        })?;

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
