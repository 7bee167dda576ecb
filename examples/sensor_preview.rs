//! The real TIR dark frame beside a rendered deep-space frame with the fitted sensor
//! signature, optics PSF, fixed-gain readout and noise, on the same DN stretch about
//! each frame's mean: `docs/sensor/dark-real-vs-synthetic.png`. Also times the PSF and
//! the signature per frame.
//!
//! `cargo run --release --example sensor_preview -- <dark.fit> [out.png]`

use std::path::PathBuf;
use std::time::Instant;

use tirroi::core::sensor::{BandLut, BandRadiance};
use tirroi::host::imaging::fits::read_fits;
use tirroi::host::imaging::psf::OpticsPsf;
use tirroi::host::imaging::render::{Readout, RenderInput, SensorEffects, render};
use tirroi::host::imaging::signature::{Calibration, TIR_EFFECTIVE_AREA_PX};
use tirroi::host::world::scene::Camera;

/// The stretch: DN below and above each frame's mean mapped to black and white.
const STRETCH_DN: (f64, f64) = (-80.0, 120.0);

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().collect();
    let fits = PathBuf::from(
        args.get(1)
            .ok_or("usage: sensor_preview <dark.fit> [out.png]")?,
    );
    let out = PathBuf::from(
        args.get(2)
            .cloned()
            .unwrap_or_else(|| "docs/sensor/dark-real-vs-synthetic.png".into()),
    );
    let img = read_fits(&fits)?;
    let [x0, y0, w, h] = TIR_EFFECTIVE_AREA_PX;
    let real: Vec<f64> = (y0..y0 + h)
        .flat_map(|y| (x0..x0 + w).map(move |x| (x, y)))
        .map(|(x, y)| img.at(x, y))
        .collect();

    let camera = Camera::default();
    let band = BandRadiance::hayabusa2_tir();
    let lut = BandLut::new(&band);
    let cal = Calibration::hayabusa2_tir()?;
    let psf = OpticsPsf::hayabusa2_tir(camera.pixel_pitch_um)?;
    let fixed = cal.fixed_gain();
    let sig = cal.realise(w, h, 2026);
    let input = RenderInput {
        camera: &camera,
        readout: Readout::Radiometry,
        target: None,
        earth: None,
        earth_distance_m: 10_871e3,
        noise_seed: Some(7),
        band: &band,
        lut: &lut,
        gain_factor: 1.0,
        moon: None,
        sensor: SensorEffects {
            psf: Some(&psf),
            signature: Some(&sig),
            fixed_gain: Some(fixed),
        },
    };
    let frame = render(&input).map_err(|e| e.to_string())?;
    let synth: Vec<f64> = frame.dn.iter().map(|&d| f64::from(d)).collect();

    // Timing: the PSF and the signature (apply) per frame, and a new realisation.
    let reps = 200;
    let mut s = frame.signal.clone();
    let mut o = vec![0f32; s.len()];
    let t = Instant::now();
    for _ in 0..reps {
        psf.apply(&s, w, &mut o)?;
        std::mem::swap(&mut s, &mut o);
    }
    let psf_us = t.elapsed().as_secs_f64() * 1e6 / f64::from(reps);
    let t = Instant::now();
    for _ in 0..reps {
        sig.apply(&mut s, std::f64::consts::PI)?;
    }
    let apply_us = t.elapsed().as_secs_f64() * 1e6 / f64::from(reps);
    let t = Instant::now();
    for k in 0..20u64 {
        std::hint::black_box(cal.realise(w, h, k));
    }
    let realise_us = t.elapsed().as_secs_f64() * 1e6 / 20.0;
    let t = Instant::now();
    for _ in 0..20 {
        std::hint::black_box(render(&input).map_err(|e| e.to_string())?);
    }
    let render_us = t.elapsed().as_secs_f64() * 1e6 / 20.0;
    println!(
        "per 328x248 frame: PSF {psf_us:.0} us, signature apply {apply_us:.0} us, new realisation {realise_us:.0} us; \
         whole deep-space render with them {render_us:.0} us (sensor stage {} us)",
        frame.stats.sensor_ns / 1000
    );
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    println!(
        "real: mean {:.1} DN; synthetic: mean {:.1} DN, min {} DN, noise sigma {:.2} DN",
        mean(&real),
        mean(&synth),
        frame.dn.iter().min().unwrap(),
        frame.noise_sigma_dn
    );

    // Side by side, 2x enlarged, a 16 px gap.
    let scale = 2;
    let gap = 16;
    let (cw, ch) = (2 * w * scale + gap, h * scale);
    let mut canvas = image::GrayImage::from_pixel(cw as u32, ch as u32, image::Luma([255]));
    for (k, data) in [&real, &synth].iter().enumerate() {
        let m = mean(data);
        for y in 0..h {
            for x in 0..w {
                let t = (data[y * w + x] - m - STRETCH_DN.0) / (STRETCH_DN.1 - STRETCH_DN.0);
                let v = (t.clamp(0.0, 1.0) * 255.0).round() as u8;
                for dy in 0..scale {
                    for dx in 0..scale {
                        let px = k * (w * scale + gap) + x * scale + dx;
                        canvas.put_pixel(px as u32, (y * scale + dy) as u32, image::Luma([v]));
                    }
                }
            }
        }
    }
    if let Some(d) = out.parent() {
        std::fs::create_dir_all(d).map_err(|e| e.to_string())?;
    }
    canvas
        .save(&out)
        .map_err(|e| format!("{}: {e}", out.display()))?;
    println!("wrote {}", out.display());
    Ok(())
}
