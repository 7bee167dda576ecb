//! `tirroi sensor-fit`: fits the camera's own signature on a real frame (FITS) and
//! writes the numbers the renderer's [`Calibration`] loads.

use std::path::PathBuf;

use crate::imaging::fits::read_fits;
use crate::imaging::signature::{Calibration, TIR_EFFECTIVE_AREA_PX};

/// The options of `tirroi sensor-fit`.
#[derive(Debug, clap::Args)]
pub struct SensorFitArgs {
    /// The FITS frame: a Hayabusa2 TIR L1 dark frame (space minus shutter), e.g.
    /// shared/reference/hayabusa2-tir/dark_20180629_083003.fit.
    #[arg(long)]
    pub fits: PathBuf,
    /// The area to fit, x0,y0,width,height in px, 0-based (default: the TIR's effective
    /// area 16,6,328,248).
    #[arg(long, value_delimiter = ',', num_args = 4)]
    pub area: Option<Vec<usize>>,
    /// Write the calibration TOML here (the committed one is
    /// host/assets/sensor/hayabusa2-tir-dark.toml); without it, print it.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Runs `tirroi sensor-fit`.
///
/// # Errors
/// A message naming the file and what was expected.
pub fn run(args: &SensorFitArgs) -> Result<(), String> {
    let area = match &args.area {
        None => TIR_EFFECTIVE_AREA_PX,
        Some(v) => [v[0], v[1], v[2], v[3]],
    };
    let image = read_fits(&args.fits)?;
    let name = args
        .fits
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| args.fits.display().to_string());
    let cal = Calibration::from_fits(&image, &name, area)?;
    let text = cal.to_toml()?;
    let f = &cal.fit;
    eprintln!(
        "{name}: {}x{} area at ({}, {}); mean {:.2} DN; shading amplitude (p99-p1) {:.2} DN, \
         range {:.2} DN (min {:.2} at {:?}, max {:.2} at {:?}); columns sigma {:.3} DN rho {:.3}; \
         rows sigma {:.3} DN rho {:.3}; field sigma {:.3} DN length {:.1} px (process {:.1} px); \
         pixel sigma {:.3} DN; hot {} dead {} (> {} sigma); \
         gain {:.4} DN per W m-2 sr-1 (shutter {:.2} K, L {:.4} W m-2 sr-1)",
        area[2],
        area[3],
        area[0],
        area[1],
        f.shading.mean_dn,
        f.shading.amplitude_dn,
        f.shading.range_dn,
        f.shading.min_dn,
        f.shading.min_at_px,
        f.shading.max_dn,
        f.shading.max_at_px,
        f.columns.sigma_dn,
        f.columns.lag1_correlation,
        f.rows.sigma_dn,
        f.rows.lag1_correlation,
        f.field.sigma_dn,
        f.field.correlation_length_px,
        cal.field_process.length_px,
        f.pixels.sigma_dn,
        f.pixels.hot_count,
        f.pixels.dead_count,
        f.pixels.outlier_k_sigma,
        cal.gain.dn_per_w_m2_sr,
        cal.source.shutter_temperature_k,
        cal.gain.shutter_radiance_w_m2_sr,
    );
    match &args.out {
        None => print!("{text}"),
        Some(p) => {
            if let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(dir)
                    .map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
            }
            std::fs::write(p, text).map_err(|e| format!("{}: cannot write: {e}", p.display()))?;
        }
    }
    Ok(())
}
