//! The camera model on board: a 328×248 frame of DN made from a temperature field by
//! the core's sensor chain (band-radiance table → emissive power F = π·ε·L → Eq. 17
//! radiometry DN map → Johnson + 1/f + temperature-fluctuation noise at the TIR's NETD),
//! one row at a time into the frame buffer, with no buffer beyond one row of signal.
//!
//! The scene, in kelvin: an Earth-like background warming from 250 K at the top to
//! 290 K at the bottom (ε = 0.95), a 60×60 px target body at 300 K (ε = 0.85) with a
//! 20×60 px panel at 330 K (ε = 0.90). Only f32/f64 arithmetic that IEEE 754 fixes bit
//! for bit and libm's software functions are used, so every target (with or without an
//! FPU) and the host must give the same frame: [`checksum`] proves it.

use tirroi_core::frame::{FRAME_HEIGHT, FRAME_WIDTH};
use tirroi_core::sensor::noise::NoiseRms;
use tirroi_core::sensor::noise::{DEFAULT_FLICKER_CORRELATION_PX, TIR_NETD_K};
use tirroi_core::sensor::{
    BandLut, BandRadiance, DnMapping, NoiseField, NoiseLevel, SensorError, expose_frame,
};

use crate::{BITS, Workspace};

/// The camera model's tables: band radiance (160-node quadrature, 5.9 KB) and its fast
/// table (11.3 KB). Both are `const`s computed at build time
/// ([`BandRadiance::HAYABUSA2_TIR`], [`BandLut::HAYABUSA2_TIR`], in flash); [`setup`]
/// only points at them, so start-up computes nothing (it built them on board before:
/// 710 M instructions and 30 KB of stack on the Cortex-M7).
#[derive(Default)]
pub struct Tables {
    band: Option<&'static BandRadiance>,
    lut: Option<&'static BandLut>,
}

impl Tables {
    /// No tables yet (a `const fn`: a `static`).
    pub const fn new() -> Self {
        Tables {
            band: None,
            lut: None,
        }
    }
}

/// The name the synthetic frame is reported under.
pub const NAME: &str = "on-board-sensor";

/// Noise seed of the synthetic frame.
pub const SEED: u64 = 2026;

/// NETD of the camera, K (the TIR's, from the core's noise model).
pub const NETD_K: f64 = TIR_NETD_K;

/// Correlation length of the 1/f noise map, px (the core's default).
pub const FLICKER_CORRELATION_PX: f32 = DEFAULT_FLICKER_CORRELATION_PX;

/// Coldest and warmest (T, ε) of the scene: they set the Eq. 17 range.
const COLDEST: (f32, f32) = (250.0, 0.95);
const WARMEST: (f32, f32) = (330.0, 0.90);

/// Temperature (K) and emissivity of pixel (x, y).
fn scene(x: usize, y: usize) -> (f32, f32) {
    let in_target = (140..200).contains(&x) && (90..150).contains(&y);
    if in_target && (150..170).contains(&x) {
        WARMEST
    } else if in_target {
        (300.0, 0.85)
    } else {
        (250.0 + 40.0 * y as f32 / (FRAME_HEIGHT - 1) as f32, 0.95)
    }
}

/// Points the workspace at the camera's band radiance (160-node quadrature of
/// ε·B(λ,T)·R(λ) over the measured Hayabusa2 TIR response) and its fast table, both
/// computed at build time. Never inlined, so that its cost is measured as its own.
#[inline(never)]
pub fn setup(ws: &mut Workspace<'_>) {
    ws.tables.band = Some(&BandRadiance::HAYABUSA2_TIR);
    ws.tables.lut = Some(&BandLut::HAYABUSA2_TIR);
}

/// The tables, or the error of a missing [`setup`].
fn tables(tables: &Tables) -> Result<(&'static BandRadiance, &'static BandLut), SensorError> {
    match (tables.band, tables.lut) {
        (Some(band), Some(lut)) => Ok((band, lut)),
        _ => Err(SensorError::NotFinite {
            name: "band tables (run synth::setup)",
        }),
    }
}

/// The first stage of [`expose_scene`] alone: the emissive power of every pixel from
/// the table, one row at a time, discarded (to count its cost apart).
///
/// # Errors
/// [`SensorError`] when the tables are missing or the model refuses its input.
#[inline(never)]
pub fn radiance_only(ws: &mut Workspace<'_>) -> Result<(), SensorError> {
    let (_, lut) = tables(ws.tables)?;
    let mut signal = [0.0f32; FRAME_WIDTH];
    for y in 0..FRAME_HEIGHT {
        for (x, s) in signal.iter_mut().enumerate() {
            *s = emissive_power(lut, scene(x, y))?;
        }
        core::hint::black_box(&signal);
    }
    Ok(())
}

/// The DN map + noise pass alone ([`expose_frame`] with the noise field, as in
/// [`expose_scene`]) over a whole frame, on one row of signal computed once (the
/// scene's middle row; the pass costs the same for any finite signal), into
/// `ws.frame`: the cost of DN + noise per pixel, measured directly. [`setup`] must have
/// run. Never inlined, so that its cost is measured as its own.
///
/// # Errors
/// [`SensorError`] when the tables are missing or the model refuses its input.
#[inline(never)]
pub fn dn_noise_only(ws: &mut Workspace<'_>) -> Result<(), SensorError> {
    let (band, lut) = tables(ws.tables)?;
    let (mapping, mut noise) = dn_map_and_noise(band, lut)?;
    let mut signal = [0.0f32; FRAME_WIDTH];
    for (x, s) in signal.iter_mut().enumerate() {
        *s = emissive_power(lut, scene(x, FRAME_HEIGHT / 2))?;
    }
    for out in ws.frame.chunks_exact_mut(FRAME_WIDTH) {
        expose_frame(&signal, FRAME_WIDTH, &mapping, Some(&mut noise), out)?;
    }
    Ok(())
}

/// The Eq. 17 DN map of the scene's range and the seeded noise field at the TIR's NETD.
fn dn_map_and_noise(
    band: &BandRadiance,
    lut: &BandLut,
) -> Result<(DnMapping, NoiseField), SensorError> {
    let f_min = emissive_power(lut, COLDEST)?;
    let f_max = emissive_power(lut, WARMEST)?;
    let mapping = DnMapping::radiometry_auto(f64::from(f_min), f64::from(f_max), BITS)?;
    let dn_per_k = mapping.dn_per_kelvin(band, 300.0, core::f64::consts::PI)?;
    let sigmas = NoiseLevel::Netd {
        netd_k: NETD_K,
        dn_per_k,
    }
    .sigmas(&NoiseRms::TABLE2, &mapping)?;
    let noise = NoiseField::new(sigmas, FLICKER_CORRELATION_PX, FRAME_WIDTH, SEED)?;
    Ok((mapping, noise))
}

/// Emissive power F = π·ε·L(T), W m⁻², from the table.
fn emissive_power(lut: &BandLut, (t_k, emissivity): (f32, f32)) -> Result<f32, SensorError> {
    Ok(core::f32::consts::PI * lut.radiance_f32(t_k, emissivity)?)
}

/// Exposes the scene into `ws.frame`, row by row. [`setup`] must have run. Never
/// inlined, so that its stack is measured as its own.
///
/// # Errors
/// [`SensorError`] when the tables are missing or the model refuses its input.
#[inline(never)]
pub fn expose_scene(ws: &mut Workspace<'_>) -> Result<(), SensorError> {
    let (band, lut) = tables(ws.tables)?;
    let (mapping, mut noise) = dn_map_and_noise(band, lut)?;
    let mut signal = [0.0f32; FRAME_WIDTH];
    for (y, out) in ws.frame.chunks_exact_mut(FRAME_WIDTH).enumerate() {
        for (x, s) in signal.iter_mut().enumerate() {
            *s = emissive_power(lut, scene(x, y))?;
        }
        expose_frame(&signal, FRAME_WIDTH, &mapping, Some(&mut noise), out)?;
    }
    Ok(())
}

/// FNV-1a (64 bit) of the frame's DN, each as two little-endian bytes.
pub fn checksum(frame: &[u16]) -> u64 {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for &dn in frame {
        for byte in dn.to_le_bytes() {
            hash ^= u64::from(byte);
            hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    hash
}
