//! Criterion benchmarks of the camera model: run time of the three band-radiance paths
//! (exact f64 quadrature, f32 quadrature, f32 table) and of a full-frame DN + noise
//! pass. Their errors are measured by core/tests/sensor_radiance.rs (`cargo test -p
//! tirroi-core --test sensor_radiance -- --nocapture` prints the worst relative error of
//! each path).
//! `cargo bench --bench sensor`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use tirroi::core::sensor::noise::{DEFAULT_FLICKER_CORRELATION_PX, NoiseRms};
use tirroi::core::sensor::{
    BandLut, BandRadiance, DnMapping, NoiseField, NoiseLevel, expose_frame,
};

/// 64 temperatures spread geometrically over 20–2000 K: one call each per iteration.
fn temps() -> Vec<f64> {
    (0..64)
        .map(|i| 20.0 * 100f64.powf(f64::from(i) / 63.0))
        .collect()
}

fn band_radiance(c: &mut Criterion) {
    let band = BandRadiance::hayabusa2_tir();
    let lut = BandLut::new(&band);
    let t64 = temps();
    let t32: Vec<f32> = t64.iter().map(|&t| t as f32).collect();
    let mut g = c.benchmark_group("band_radiance");
    g.throughput(Throughput::Elements(t64.len() as u64));
    g.bench_function("exact_f64", |b| {
        b.iter(|| {
            for &t in &t64 {
                black_box(band.radiance_w_m2_sr(black_box(t), 1.0).unwrap_or(0.0));
            }
        })
    });
    g.bench_function("quadrature_f32", |b| {
        b.iter(|| {
            for &t in &t32 {
                black_box(band.radiance_f32(black_box(t), 1.0).unwrap_or(0.0));
            }
        })
    });
    g.bench_function("table_f32", |b| {
        b.iter(|| {
            for &t in &t32 {
                black_box(lut.radiance_f32(black_box(t), 1.0).unwrap_or(0.0));
            }
        })
    });
    g.finish();
    c.bench_function("band_lut_build", |b| {
        b.iter(|| BandLut::new(black_box(&band)))
    });
}

fn frame_pass(c: &mut Criterion) {
    const W: usize = 328;
    const H: usize = 248;
    let band = BandRadiance::hayabusa2_tir();
    let f = |t: f64| band.emissive_power_w_m2(t, 1.0).unwrap_or(0.0);
    let mapping = DnMapping::radiometry_auto(f(150.0), f(460.0), 14).expect("valid range");
    // A radiometry-mode frame: a 150–400 K ramp of emissive power.
    let signal: Vec<f32> = (0..W * H)
        .map(|i| f(150.0 + 250.0 * (i % W) as f64 / W as f64) as f32)
        .collect();
    let dn_per_k = mapping
        .dn_per_kelvin(&band, 300.0, std::f64::consts::PI)
        .expect("valid temperature");
    let sigmas = NoiseLevel::Netd {
        netd_k: 0.4,
        dn_per_k,
    }
    .sigmas(&NoiseRms::TABLE2, &mapping)
    .expect("valid level");
    let mut out = vec![0u16; W * H];
    let mut g = c.benchmark_group("frame_pass");
    g.throughput(Throughput::Elements((W * H) as u64));
    g.bench_function("dn_only", |b| {
        b.iter(|| {
            expose_frame(
                black_box(&signal),
                W,
                &mapping,
                None::<&mut NoiseField>,
                &mut out,
            )
        })
    });
    g.bench_function("dn_plus_noise", |b| {
        b.iter(|| {
            let mut field =
                NoiseField::new(sigmas, DEFAULT_FLICKER_CORRELATION_PX, W, 1).expect("valid");
            expose_frame(black_box(&signal), W, &mapping, Some(&mut field), &mut out)
        })
    });
    g.finish();
}

criterion_group!(sensor, band_radiance, frame_pass);
criterion_main!(sensor);
