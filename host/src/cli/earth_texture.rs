//! `tirroi earth-texture`: statistics of the Earth's cloud texture at 4 km per pixel
//! beside those of real longwave imagery, and side-by-side previews.

use std::path::{Path, PathBuf};

use clap::Args;
use image::{GrayImage, Luma};

use crate::imaging::image_io::{FrameBuf, read_frame, write_png16};
use crate::seed::splitmix64;
use crate::world::earth::clouds::MAX_REGIONAL_RADIUS_CELLS;
use crate::world::earth::texture_stats::{PATCH_PX_KM, REAL_QUANTUM_K, TextureStats, sample_patch};
use crate::world::earth::{CloudField, OlrGrid};
use crate::world::scene::MAX_CLOUD_TOP_TEXTURE_K;

/// Arguments of `tirroi earth-texture`.
#[derive(Debug, Args)]
pub struct EarthTextureArgs {
    /// Print the statistics table (2-px steps, shares, spectral slope, BT percentiles).
    #[arg(long)]
    pub stats: bool,
    /// A real 16-bit PNG (value = BT × 50, 0 = no data) to measure the same way, on its
    /// largest all-valid rectangle.
    #[arg(long)]
    pub real: Option<PathBuf>,
    /// Write a side-by-side preview (ours | real, 220–300 K greyscale) to this PNG.
    #[arg(long)]
    pub preview: Option<PathBuf>,
    /// Also write each patch the statistics sample as a 16-bit PNG in the real image's
    /// encoding (value = BT × 50, 0.02 K per count) into this directory, for one's own
    /// measurements beside the real scene; an existing file is never overwritten.
    #[arg(long, requires = "stats")]
    pub export: Option<PathBuf>,
    /// Dataset seed (the built-in OLR grid and the texture derive from it).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Days (built-in OLR grid and texture) to sample.
    #[arg(long, default_value_t = 2)]
    pub days: u64,
    /// Patch size, pixels (square).
    #[arg(long, default_value_t = 512)]
    pub size: usize,
    /// Texture of the cloud tops outside deep convection, K per σ of the finer octaves
    /// (a scene file's `earth_model.cloud_top_texture_k`; the `realistic` presets render
    /// 5), 0..=10.
    #[arg(long, default_value_t = 0.0)]
    pub cloud_top_texture_k: f64,
    /// Radius of the regional cloud balance, cells (a scene file's
    /// `earth_model.regional_balance_cells`; 0: each 1° cell balanced on its own),
    /// 0..=4.
    #[arg(long, default_value_t = 0)]
    pub regional_balance_cells: usize,
    /// Cold fragments bound to the clouds (a scene file's `earth_model.cloud_fragments`;
    /// the `realistic` presets render them): more of them among clouds, fewer in clear
    /// air, their tops below the cloud under them.
    #[arg(long)]
    pub cloud_fragments: bool,
}

/// Patch centres (latitude°, longitude° E) the statistics sample: the Hawaii sector of
/// the real scene, the subtropical Atlantic, the warm pool and a mid-latitude storm track.
pub const PATCH_CENTRES: [(f64, f64); 4] =
    [(20.0, 202.0), (25.0, 320.0), (2.0, 140.0), (45.0, 330.0)];

/// Greyscale of the previews: 220 K black, 300 K white.
const GREY_K: (f64, f64) = (220.0, 300.0);

fn grey(t: f64) -> u8 {
    ((t - GREY_K.0) / (GREY_K.1 - GREY_K.0) * 255.0).clamp(0.0, 255.0) as u8
}

/// The texture of the built-in grid of (seed, day), as the dataset library makes it.
pub fn builtin_field(seed: u64, day: u64) -> CloudField {
    let grid = OlrGrid::builtin(splitmix64(seed ^ 0xEA27) ^ day);
    CloudField::new(&grid, day, seed)
}

fn row(name: &str, s: &TextureStats) -> String {
    format!(
        "| {name} | {:.1} / {:.1} / {:.1} / {:.1} | {:.1} / {:.1} | {:.2} / {:.2} / {:.2} | {:.2} | {:.1} / {:.1} / {:.1} | {:.1} / {:.1} | {:.0} % | {:.1} / {:.1} | {:.1} / {:.1} | {:.1} | {:.2}, {:.0} |",
        s.step2_k[0],
        s.step2_k[1],
        s.step2_k[2],
        s.step2_k[3],
        100.0 * s.step2_share_over[0],
        100.0 * s.step2_share_over[1],
        100.0 * s.step2_share_over[2],
        100.0 * s.step2_share_over[3],
        100.0 * s.step2_share_over[4],
        s.spectral_slope,
        s.bt_k[0],
        s.bt_k[1],
        s.bt_k[2],
        s.cold_features_per_10k_px[0],
        s.cold_features_per_10k_px[1],
        100.0 * s.cold_feature_cloudy_share,
        s.cold_feature_depth_k[0],
        s.cold_feature_depth_k[1],
        s.cloud_top_sd_k[0],
        s.cloud_top_sd_k[1],
        100.0 * s.intermediate_share,
        s.cold_structures[0],
        100.0 * s.cold_structures[1],
    )
}

/// The real image: (w, h, BT or NaN per pixel).
fn read_real(path: &Path) -> Result<(usize, usize, Vec<f64>), String> {
    let f = read_frame(path, Some(16)).map_err(|e| e.to_string())?;
    let t = f
        .pixels
        .iter()
        .map(|&v| {
            if v == 0 {
                f64::NAN
            } else {
                f64::from(v) / 50.0
            }
        })
        .collect();
    Ok((f.width, f.height, t))
}

/// Counts per kelvin of the real image's encoding (value = BT × 50).
const REAL_COUNTS_PER_K: f64 = 50.0;

/// Writes a patch into the existing directory `dir` in the real image's encoding;
/// refuses to replace an existing file.
fn export_patch(dir: &Path, name: &str, t_k: &[f64], size: usize) -> Result<(), String> {
    let path = dir.join(name);
    if path.exists() {
        return Err(format!(
            "{}: already exists; choose another --export directory or remove the file",
            path.display()
        ));
    }
    let frame = FrameBuf {
        pixels: t_k
            .iter()
            .map(|&t| {
                (t * REAL_COUNTS_PER_K)
                    .round()
                    .clamp(1.0, f64::from(u16::MAX)) as u16
            })
            .collect(),
        width: size,
        height: size,
        bits: 16,
    };
    write_png16(&path, &frame).map_err(|e| e.to_string())
}

/// Runs the command.
///
/// # Errors
/// A message naming the file that could not be read or written.
pub fn run(args: &EarthTextureArgs) -> Result<(), String> {
    if args.size < 64 {
        return Err(format!("--size {}: expected at least 64 px", args.size));
    }
    if !(0.0..=MAX_CLOUD_TOP_TEXTURE_K).contains(&args.cloud_top_texture_k) {
        return Err(format!(
            "--cloud-top-texture-k {}: expected 0..={MAX_CLOUD_TOP_TEXTURE_K} K",
            args.cloud_top_texture_k
        ));
    }
    if args.regional_balance_cells > MAX_REGIONAL_RADIUS_CELLS {
        return Err(format!(
            "--regional-balance-cells {}: expected 0..={MAX_REGIONAL_RADIUS_CELLS} cells",
            args.regional_balance_cells
        ));
    }
    let texture = |day| {
        builtin_field(args.seed, day)
            .with_cloud_top_texture(args.cloud_top_texture_k)
            .with_regional_balance(args.regional_balance_cells)
            .with_cloud_fragments(args.cloud_fragments)
    };
    let real = args.real.as_deref().map(read_real).transpose()?;
    if let Some(dir) = &args.export {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
    }
    if args.stats {
        println!(
            "| patch | 2-px step p50 / p90 / p99 / max, K | share > 1 / 2 K, % | share > 5 / 10 / 20 K, % | slope 8–200 km | BT p1 / p50 / p99, K | cold features small / mid per 10⁴ px | cold features among clouds | their depth p50 / p90, K | cloud-top 5×5 σ p50 / p90, K | 2–15 K below the warm p90, % | cold structures ≥ 200 px per 10⁴ px, bands % |"
        );
        println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
        for day in 0..args.days {
            let field = texture(day);
            for &(lat, lon) in &PATCH_CENTRES {
                let t = sample_patch(
                    &field,
                    lat,
                    lon,
                    args.size,
                    args.size,
                    PATCH_PX_KM,
                    REAL_QUANTUM_K,
                );
                if let Some(dir) = &args.export {
                    let name = format!("ours-seed{}-day{day}-{lat}N-{lon}E.png", args.seed);
                    export_patch(dir, &name, &t, args.size)?;
                }
                if let Some(s) = TextureStats::of(&t, args.size, args.size, PATCH_PX_KM) {
                    println!("{}", row(&format!("ours day {day} ({lat}°, {lon}°)"), &s));
                }
            }
        }
        // Per-point cost with the patch's cells already built (a rendered frame's
        // steady state), single thread.
        let field = texture(0);
        let (lat, lon) = PATCH_CENTRES[0];
        let n = args.size * args.size;
        let cold = std::time::Instant::now();
        let _ = sample_patch(&field, lat, lon, args.size, args.size, PATCH_PX_KM, 0.0);
        let cold_ns = cold.elapsed().as_nanos() as f64 / n as f64;
        let warm = std::time::Instant::now();
        let _ = sample_patch(&field, lat, lon, args.size, args.size, PATCH_PX_KM, 0.0);
        let warm_ns = warm.elapsed().as_nanos() as f64 / n as f64;
        eprintln!("texture cost: {cold_ns:.0} ns per point with cell set-up, {warm_ns:.0} ns warm");
        if let Some((w, h, t)) = &real {
            if let Some(s) = TextureStats::of(t, *w, *h, PATCH_PX_KM) {
                println!("{}", row("real (valid pixels)", &s));
            }
        }
    }
    if let Some(out) = &args.preview {
        let (w, h) = real.as_ref().map_or((args.size, args.size), |r| (r.0, r.1));
        let field = texture(0);
        let (lat, lon) = PATCH_CENTRES[0];
        let ours = sample_patch(&field, lat, lon, w, h, PATCH_PX_KM, REAL_QUANTUM_K);
        let gap = 8;
        let total_w = if real.is_some() { 2 * w + gap } else { w };
        let mut img = GrayImage::from_pixel(total_w as u32, h as u32, Luma([0]));
        for y in 0..h {
            for x in 0..w {
                img.put_pixel(x as u32, y as u32, Luma([grey(ours[y * w + x])]));
                if let Some((_, _, t)) = &real {
                    let v = t[y * w + x];
                    let g = if v.is_finite() { grey(v) } else { 0 };
                    img.put_pixel((w + gap + x) as u32, y as u32, Luma([g]));
                }
            }
        }
        img.save(out)
            .map_err(|e| format!("{}: cannot write: {e}", out.display()))?;
    }
    Ok(())
}
