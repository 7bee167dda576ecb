//! The CERES NetCDF reader, `OlrGrid::load_netcdf` (feature `netcdf`, needs the C
//! libnetcdf): the tests write small NetCDF-4 files with the `netcdf` crate in the
//! layouts CERES subsets and other tools use (latitude north → south, longitude
//! −179.5…179.5, a time dimension, packed shorts, fill values) and check that every
//! value lands on the right 1° node, and that each malformed file gets its own error.
//!
//! Run with `cargo test --features netcdf --test earth_netcdf`. With libnetcdf 4.9.0
//! (Debian bookworm) opening a NetCDF-4 file from a second thread prints harmless
//! `HDF5-DIAG ... can't locate attribute: '_Quantize...'` lines on stderr: a known
//! libnetcdf bug (Unidata/netcdf-c#2674), not a test failure.
#![cfg(feature = "netcdf")]

use std::path::{Path, PathBuf};

use tirroi::host::world::earth::{EarthError, OlrGrid};

const VAR: &str = "toa_lw_all_daily";

/// The flux the tests store at node (row, col) of time step `t`: distinct per node and
/// exact in f32 (multiples of 1/4), 100…379.25 W m⁻².
fn expected(row: usize, col: usize, t: usize) -> f32 {
    100.0 + row as f32 * 0.5 + col as f32 * 0.25 + t as f32 * 100.0
}

/// Latitudes north → south (89.5 … −89.5), as some tools write them.
fn lat_north_to_south() -> Vec<f64> {
    (0..180).map(|i| 89.5 - i as f64).collect()
}

/// Longitudes −179.5 … 179.5.
fn lon_signed() -> Vec<f32> {
    (0..360).map(|j| -179.5 + j as f32).collect()
}

/// Our row of a latitude and column of a longitude.
fn row_of(lat: f64) -> usize {
    (lat + 89.5).round() as usize
}
fn col_of(lon: f64) -> usize {
    (lon.rem_euclid(360.0) - 0.5).round() as usize
}

fn dir() -> tempfile::TempDir {
    tempfile::tempdir().expect("temp dir")
}

/// A SYN1deg-like file: `toa_lw_all_daily(time=2, lat=180, lon=360)` as f32 with
/// `_FillValue` −999, lat north → south (f64), lon −179.5…179.5 (f32).
fn write_syn1deg(path: &Path, edit: impl Fn(&mut Vec<f32>)) {
    let (lat, lon) = (lat_north_to_south(), lon_signed());
    let mut file = netcdf::create(path).expect("create");
    file.add_dimension("time", 2).unwrap();
    file.add_dimension("lat", 180).unwrap();
    file.add_dimension("lon", 360).unwrap();
    file.add_variable::<f64>("lat", &["lat"])
        .unwrap()
        .put_values(&lat, ..)
        .unwrap();
    file.add_variable::<f32>("lon", &["lon"])
        .unwrap()
        .put_values(&lon, ..)
        .unwrap();
    let mut data = Vec::with_capacity(2 * 180 * 360);
    for t in 0..2 {
        for &la in &lat {
            for &lo in &lon {
                data.push(expected(row_of(la), col_of(f64::from(lo)), t));
            }
        }
    }
    edit(&mut data);
    let mut var = file
        .add_variable::<f32>(VAR, &["time", "lat", "lon"])
        .unwrap();
    var.set_fill_value(-999.0f32).unwrap();
    var.put_attribute("units", "W m-2").unwrap();
    var.put_values(&data, ..).unwrap();
}

fn syn1deg(dir: &tempfile::TempDir) -> PathBuf {
    let path = dir.path().join("CERES_SYN1deg-Day_Subset.nc");
    write_syn1deg(&path, |_| {});
    path
}

#[test]
fn reorders_north_south_and_signed_longitudes_at_each_time_step() {
    let d = dir();
    let path = syn1deg(&d);
    for t in 0..2 {
        let g = OlrGrid::load_netcdf(&path, VAR, t).expect("load");
        for row in 0..180 {
            for col in 0..360 {
                assert_eq!(
                    g.at_node(row, col),
                    expected(row, col, t),
                    "t {t} ({row}, {col})"
                );
            }
        }
    }
    // Spot checks by hand: our row 0 is lat −89.5 (the file's last latitude), our
    // column 0 is lon 0.5 (the file's index 180).
    let g = OlrGrid::load_netcdf(&path, VAR, 0).unwrap();
    assert_eq!(g.values()[0], 100.0);
    assert_eq!(g.values()[179 * 360 + 359], 100.0 + 89.5 + 89.75);
}

#[test]
fn packed_two_dimensional_lon_lat_variable_is_decoded() {
    // (lon, lat) order, no time, i16 packed with scale_factor/add_offset, lat south →
    // north and lon 0.5…359.5, one fill value.
    let d = dir();
    let path = d.path().join("packed.nc");
    let lat: Vec<f64> = (0..180).map(|i| -89.5 + i as f64).collect();
    let lon: Vec<f64> = (0..360).map(|j| 0.5 + j as f64).collect();
    let (scale, offset) = (0.25f64, 200.0f64);
    let write = |fill_at: Option<(usize, usize)>| {
        let mut file = netcdf::create(&path).expect("create");
        file.add_dimension("longitude", 360).unwrap();
        file.add_dimension("latitude", 180).unwrap();
        file.add_variable::<f64>("latitude", &["latitude"])
            .unwrap()
            .put_values(&lat, ..)
            .unwrap();
        file.add_variable::<f64>("longitude", &["longitude"])
            .unwrap()
            .put_values(&lon, ..)
            .unwrap();
        let mut data = Vec::with_capacity(180 * 360);
        for col in 0..360 {
            for row in 0..180 {
                let v = f64::from(expected(row, col, 0));
                let mut packed = ((v - offset) / scale).round() as i16;
                if fill_at == Some((row, col)) {
                    packed = -32768;
                }
                data.push(packed);
            }
        }
        let mut var = file
            .add_variable::<i16>("olr", &["longitude", "latitude"])
            .unwrap();
        var.set_fill_value(-32768i16).unwrap();
        var.put_attribute("scale_factor", scale).unwrap();
        var.put_attribute("add_offset", offset).unwrap();
        var.put_values(&data, ..).unwrap();
    };
    write(None);
    let g = OlrGrid::load_netcdf(&path, "olr", 0).expect("load");
    for row in 0..180 {
        for col in 0..360 {
            assert_eq!(g.at_node(row, col), expected(row, col, 0), "({row}, {col})");
        }
    }
    // A 2-D variable is one time step.
    assert_eq!(
        OlrGrid::load_netcdf(&path, "olr", 1),
        Err(EarthError::TimeIndex {
            path: path.clone(),
            variable: "olr".into(),
            index: 1,
            len: 1
        })
    );
    // One fill value (raw −32768) is found and located.
    write(Some((100, 20)));
    match OlrGrid::load_netcdf(&path, "olr", 0) {
        Err(EarthError::FillValues {
            count,
            lat_deg,
            lon_deg,
            ..
        }) => {
            assert_eq!(count, 1);
            assert_eq!((lat_deg, lon_deg), (10.5, 20.5));
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn fill_values_missing_values_and_nan_are_refused() {
    let d = dir();
    let path = d.path().join("fill.nc");
    // File index (lat 0 = 89.5°, lon 0 = −179.5°) is a −999 fill at time 1 only.
    write_syn1deg(&path, |data| data[180 * 360] = -999.0);
    assert!(OlrGrid::load_netcdf(&path, VAR, 0).is_ok());
    let err = OlrGrid::load_netcdf(&path, VAR, 1).unwrap_err();
    assert_eq!(
        err,
        EarthError::FillValues {
            path: path.clone(),
            variable: VAR.into(),
            count: 1,
            lat_deg: 89.5,
            lon_deg: -179.5
        }
    );
    let msg = err.to_string();
    assert!(
        msg.contains("fill") && msg.contains(VAR) && msg.contains("fill.nc"),
        "{msg}"
    );
    // NaN (a common fill of Python tools) and the NetCDF default fill are fill values.
    write_syn1deg(&path, |data| {
        data[5] = f32::NAN;
        data[6] = 9.969_21e36;
    });
    assert!(matches!(
        OlrGrid::load_netcdf(&path, VAR, 0),
        Err(EarthError::FillValues { count: 2, .. })
    ));
}

#[test]
fn values_outside_the_valid_range_are_refused() {
    let d = dir();
    let path = d.path().join("range.nc");
    write_syn1deg(&path, |data| data[1] = 612.0);
    match OlrGrid::load_netcdf(&path, VAR, 0) {
        Err(EarthError::OutOfRange {
            value,
            lat_deg,
            lon_deg,
            ..
        }) => {
            assert_eq!(value, 612.0);
            assert_eq!((lat_deg, lon_deg), (89.5, -178.5));
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn missing_file_and_variable_name_what_is_wrong() {
    let d = dir();
    let missing = d.path().join("nope.nc");
    match OlrGrid::load_netcdf(&missing, VAR, 0) {
        Err(e @ EarthError::Open { .. }) => {
            assert!(e.to_string().contains("nope.nc"), "{e}");
        }
        other => panic!("{other:?}"),
    }
    // Not a NetCDF file.
    let text = d.path().join("notes.nc");
    std::fs::write(&text, "not netcdf").unwrap();
    assert!(matches!(
        OlrGrid::load_netcdf(&text, VAR, 0),
        Err(EarthError::Open { .. })
    ));
    // A directory.
    assert!(matches!(
        OlrGrid::load_netcdf(d.path(), VAR, 0),
        Err(EarthError::Open { .. })
    ));

    let path = syn1deg(&d);
    match OlrGrid::load_netcdf(&path, "toa_sw_all_daily", 0) {
        Err(e @ EarthError::MissingVariable { .. }) => {
            let EarthError::MissingVariable { available, .. } = &e else {
                unreachable!()
            };
            assert!(available.iter().any(|v| v == VAR), "{available:?}");
            let msg = e.to_string();
            assert!(
                msg.contains("toa_sw_all_daily") && msg.contains(VAR),
                "{msg}"
            );
        }
        other => panic!("{other:?}"),
    }
    match OlrGrid::load_netcdf(&path, VAR, 2) {
        Err(
            e @ EarthError::TimeIndex {
                index: 2, len: 2, ..
            },
        ) => {
            assert!(e.to_string().contains("2 time steps"), "{e}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn wrong_grids_and_coordinates_are_refused() {
    let d = dir();
    // A 2° grid (90 × 180).
    let path = d.path().join("two_degree.nc");
    {
        let mut file = netcdf::create(&path).unwrap();
        file.add_dimension("lat", 90).unwrap();
        file.add_dimension("lon", 180).unwrap();
        file.add_variable::<f32>(VAR, &["lat", "lon"])
            .unwrap()
            .put_values(&vec![240.0f32; 90 * 180], ..)
            .unwrap();
    }
    match OlrGrid::load_netcdf(&path, VAR, 0) {
        Err(e @ EarthError::BadShape { .. }) => {
            let msg = e.to_string();
            assert!(
                msg.contains("lat=90") && msg.contains("lon=180") && msg.contains("180"),
                "{msg}"
            );
        }
        other => panic!("{other:?}"),
    }
    // Dimensions without lat/lon names.
    let path = d.path().join("xy.nc");
    {
        let mut file = netcdf::create(&path).unwrap();
        file.add_dimension("y", 180).unwrap();
        file.add_dimension("x", 360).unwrap();
        file.add_variable::<f32>(VAR, &["y", "x"])
            .unwrap()
            .put_values(&vec![240.0f32; 180 * 360], ..)
            .unwrap();
    }
    assert!(matches!(
        OlrGrid::load_netcdf(&path, VAR, 0),
        Err(EarthError::BadShape { .. })
    ));
    // Right sizes, but the latitudes are edges (−90…89), not centres; and a file with
    // no latitude coordinate variable at all.
    for (name, lat) in [
        (
            "edges.nc",
            Some((0..180).map(|i| -90.0 + i as f64).collect::<Vec<_>>()),
        ),
        ("nolat.nc", None),
    ] {
        let path = d.path().join(name);
        {
            let mut file = netcdf::create(&path).unwrap();
            file.add_dimension("lat", 180).unwrap();
            file.add_dimension("lon", 360).unwrap();
            if let Some(lat) = &lat {
                file.add_variable::<f64>("lat", &["lat"])
                    .unwrap()
                    .put_values(lat, ..)
                    .unwrap();
            }
            let lon: Vec<f64> = (0..360).map(|j| 0.5 + j as f64).collect();
            file.add_variable::<f64>("lon", &["lon"])
                .unwrap()
                .put_values(&lon, ..)
                .unwrap();
            file.add_variable::<f32>(VAR, &["lat", "lon"])
                .unwrap()
                .put_values(&vec![240.0f32; 180 * 360], ..)
                .unwrap();
        }
        match OlrGrid::load_netcdf(&path, VAR, 0) {
            Err(e @ EarthError::BadCoordinate { .. }) => {
                let msg = e.to_string();
                assert!(msg.contains("`lat`") && msg.contains(name), "{msg}");
            }
            other => panic!("{name}: {other:?}"),
        }
    }
}
