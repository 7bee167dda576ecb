//! One frame: the detected flux of Eq. 4 per pixel from whichever surface the pixel sees
//! (a target facet, the Earth, or deep space), then the core's DN conversion and noise.
//!
//! The camera is a pinhole at the origin looking along +z, x right and y down (the pixel
//! grid's axes); pixel (i, j) spans [i, i+1) × [j, j+1) in image coordinates and the
//! principal point is the frame centre.
//!
//! **Target.** Each facet's band radiance comes from the core's table
//! ([`BandLut::radiance_f32`], T and ε of the facet) and its flux from the core's Eq. 4
//! ([`facet_flux_w_m2`](tirroi_core::sensor::flux::facet_flux_w_m2)) at the facet centroid, as the paper's per-mesh-element flux.
//! Facets are rasterised (back faces culled, nearest wins by 1/z) inside the target's
//! projected bounds only. A pixel is *partial* when a facet touches its square
//! (conservative test) but its centre or one of its 8 neighbours' centres is not
//! covered; only partial pixels are supersampled (4 × 4 stratified samples) for their
//! target coverage and mixed signal. Coverage is the fraction of samples on the target
//! (1 for interior pixels).
//!
//! **Earth.** A sphere of radius R at the scene's centre position. A pixel's ray that
//! hits it takes the band radiance of the Earth mesh cell there ([`EarthMap`]) and the
//! flux of Eq. 4 with the local surface normal, the pixel's ray and |r| = the
//! camera–Earth-centre distance (the paper's 10 871 km; this reading reproduces
//! Table 5's q_max, `shared/reference/REFERENCE.md` §4). No Earth work is done for a
//! frame whose field of view cannot reach the Earth's disc, nor for pixels fully on the
//! target; pixels at the limb are supersampled like the target's edges.
//!
//! **Moon.** Optionally a background disc behind the target and the Earth ([`moon`]).
//!
//! **Readout.** Radiometry mode turns q into F = D·q (Eq. 7) with D = π|r|²/ΔA_c per
//! object (target: distance to its centre; Earth: to its centre) and auto-ranges the DN
//! map over the frame's pure (unmixed) pixels (Eq. 17); detection mode uses the fixed
//! Table 5 scale (Eq. 9). A gain factor ([`RenderInput::gain_factor`]) then multiplies
//! the map's gain a: detection, a = factor·(2ⁿ − 1)/q_max; radiometry, about the
//! frame's minimum F (kept at DN 0), so a factor above 1 clips the brightest pixels.
//! The core's [`expose_frame`] then adds the noise (Eq. 18,
//! scaled to the NETD) and quantises.
//!
//! **Sensor effects** (opt-in, [`SensorEffects`]; none by default, leaving the frames
//! bit-identical): the optics' PSF blurs the signal ([`OpticsPsf`]), then the camera's
//! own signature multiplies it by the per-pixel gain and adds its radiance offset map
//! in the readout's signal unit ([`SensorSignature`]); a fixed-gain radiometry map
//! ([`DnMapping::radiometry_fixed_gain`]) may replace the auto range.

use std::time::Instant;

use tirroi_core::Roi;
use tirroi_core::capacity::Cap1024x768;
use tirroi_core::sensor::noise::NoiseRms;
use tirroi_core::sensor::{
    BandLut, BandRadiance, DetectionScale, DnMapping, NoiseField, NoiseLevel, SENSOR_AREA_M2,
    SensorError, expose_frame,
};

use crate::imaging::psf::OpticsPsf;
use crate::imaging::signature::SensorSignature;
use crate::world::earth::EarthMap;
use crate::world::geom::{Rotation, Vec3, norm, scale};
use crate::world::scene::Camera;
use crate::world::spacecraft::Mesh;

mod clutter;
mod earth;
mod moon;
mod pure;
mod target;

pub use clutter::{
    Clutter, QUANTISATION_SIGMA_DN, RING_MIN_WIDTH_PX, clutter_statistics, ring_width_px,
    ring_window, signal_to_clutter,
};

use earth::render_earth;
pub use moon::MoonView;
use moon::render_moon;
pub use pure::{MEASURED_TAIL_PERMILLE, PurePixels};
use target::render_target;

/// Sub-samples per axis on a partial pixel (4 × 4 = 16 per pixel).
pub const SUPERSAMPLES_PER_AXIS: usize = 4;
const SAMPLES: usize = SUPERSAMPLES_PER_AXIS * SUPERSAMPLES_PER_AXIS;
const NO_FACET: u32 = u32::MAX;
/// Narrowest radiometry range (Eq. 17), in NETDs of F at the reference temperature
/// (10 × 0.4 K: 4 K at 300 K): a scene of (nearly) one temperature keeps a usable DN map.
pub const MIN_RANGE_NETD: f64 = 10.0;
/// Coverage at or above which a pixel belongs to the target's mask and truth box.
pub const MASK_COVERAGE: f32 = 0.5;
/// Coverage *above* which a pixel belongs to the second truth box,
/// [`Rendered::truth_quarter`] (the looser convention scored beside the ½ box).
pub const QUARTER_COVERAGE: f32 = 0.25;

/// The target as the camera sees it.
#[derive(Debug, Clone, Copy)]
pub struct TargetView<'a> {
    /// The mesh in the body frame, m.
    pub mesh: &'a Mesh,
    /// Temperature per facet, K (the thermal solution).
    pub temperature_k: &'a [f64],
    /// Body frame → camera frame.
    pub body_to_camera: Rotation,
    /// The body origin (the target's centre) in the camera frame, m.
    pub centre_m: Vec3,
}

/// The Earth as the camera sees it.
#[derive(Debug, Clone, Copy)]
pub struct EarthView<'a> {
    /// Band radiance per mesh cell.
    pub map: &'a EarthMap,
    /// The Earth's centre in the camera frame, m.
    pub centre_m: Vec3,
    /// Radius, m.
    pub radius_m: f64,
    /// Camera-frame directions → Earth-fixed frame (z north, x at longitude 0).
    pub camera_to_earth: Rotation,
}

/// The camera mode and its DN map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Readout {
    /// Radiometry, auto-ranged per frame (Eq. 17).
    Radiometry,
    /// Detection on a Table 5 scale.
    Detection(DetectionScale),
}

/// The camera's optional sensor effects (all off in [`SensorEffects::NONE`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct SensorEffects<'a> {
    /// The optics' PSF applied to the signal before the DN map.
    pub psf: Option<&'a OpticsPsf>,
    /// A realisation of the camera's signature (the frame's size).
    pub signature: Option<&'a SensorSignature>,
    /// Radiometry mode only: this fixed gain and pedestal instead of the auto range of
    /// Eq. 17 (made into the frame's DN map at its bit depth).
    pub fixed_gain: Option<FixedGain>,
}

/// A fixed-gain radiometry readout, DN = a·F + b at the reference 14 bits
/// ([`DnMapping::radiometry_fixed_gain`] scales both by 2^(bits − 14)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixedGain {
    /// Camera gain, DN per W m⁻² sr⁻¹ of scene radiance (> 0).
    pub dn_per_w_m2_sr: f64,
    /// Pedestal, DN: what deep space reads.
    pub pedestal_dn: f64,
}

impl SensorEffects<'_> {
    /// No sensor effects: the paper's renderer.
    pub const NONE: SensorEffects<'static> = SensorEffects {
        psf: None,
        signature: None,
        fixed_gain: None,
    };
}

/// Everything one frame needs.
#[derive(Debug, Clone, Copy)]
pub struct RenderInput<'a> {
    /// Camera geometry and read-out.
    pub camera: &'a Camera,
    /// Mode.
    pub readout: Readout,
    /// The target, if any.
    pub target: Option<TargetView<'a>>,
    /// The Earth, if rendered.
    pub earth: Option<EarthView<'a>>,
    /// Camera–Earth-centre distance, m: the detection-mode noise is scaled to the NETD
    /// of a face-on blackbody at this distance (the scene the Table 5 scales are built on).
    pub earth_distance_m: f64,
    /// Noise seed; `None` renders without noise (and skips the noise stage).
    pub noise_seed: Option<u64>,
    /// Band radiance (f64, for ∂L/∂T of the noise scale).
    pub band: &'a BandRadiance,
    /// Band radiance table (per facet and Earth cell radiances).
    pub lut: &'a BandLut,
    /// Factor on the DN map's gain a (module docs; 1: the map of the mode as is).
    pub gain_factor: f64,
    /// The Moon, if in the field of view.
    pub moon: Option<MoonView>,
    /// PSF, signature and fixed-gain readout ([`SensorEffects::NONE`] for none).
    pub sensor: SensorEffects<'a>,
}

/// Time spent and work done per stage of one frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RenderStats {
    /// Facet fluxes, rasterisation and supersampling, ns.
    pub target_ns: u64,
    /// Earth rays, lookups and limb supersampling, ns.
    pub earth_ns: u64,
    /// DN map, noise and quantisation (the core's `expose_frame`), ns.
    pub expose_ns: u64,
    /// The signal-to-clutter twin ([`signal_to_clutter`]; 0 when not computed), ns.
    pub clutter_ns: u64,
    /// Optics PSF and sensor signature, ns (0 without them).
    pub sensor_ns: u64,
    /// Pixels inside the target's projected bounds.
    pub target_region_px: usize,
    /// Pixels supersampled at the target's edges.
    pub target_partial_px: usize,
    /// Earth rays cast (centre rays plus limb sub-samples); 0 when the Earth is out of view.
    pub earth_rays: usize,
}

/// One rendered frame with its labels.
#[derive(Debug, Clone, PartialEq)]
pub struct Rendered {
    /// Width, px.
    pub width: usize,
    /// Height, px.
    pub height: usize,
    /// DN, row-major.
    pub dn: Vec<u16>,
    /// Signal before the DN map: F (W m⁻², radiometry) or q_fc (W m⁻², detection),
    /// after the optics PSF and the sensor signature when they are on.
    pub signal: Vec<f32>,
    /// Target coverage per pixel, 0..=1.
    pub coverage: Vec<f32>,
    /// Tight box of the pixels with coverage ≥ [`MASK_COVERAGE`] (empty when none).
    pub truth: Roi,
    /// Tight box of the pixels with coverage > [`QUARTER_COVERAGE`] (⊇ `truth`; empty
    /// when none).
    pub truth_quarter: Roi,
    /// Fraction of the frame's pixels whose centre sees the Earth (not the target).
    pub earth_fraction: f64,
    /// Pixels whose centre sees the Moon (not the target, not the Earth).
    pub moon_px: usize,
    /// The DN map used.
    pub mapping: DnMapping,
    /// Total noise σ, DN (0 without noise).
    pub noise_sigma_dn: f32,
    /// Stage times and counts.
    pub stats: RenderStats,
    /// Signal-to-clutter statistics; [`render`] leaves `None`, [`signal_to_clutter`]
    /// computes them (an extra, windowed Earth pass) for callers that want them.
    pub clutter: Option<Clutter>,
}

/// Why a frame could not be rendered.
#[derive(Debug, Clone, PartialEq)]
pub enum RenderError {
    /// The core refused a value (message names it).
    Sensor(SensorError),
    /// The target reaches the camera plane (too close for its size).
    TargetTooClose {
        /// The nearest vertex depth, m.
        nearest_z_m: f64,
    },
    /// Inconsistent input (message says what).
    Input(String),
}

impl std::fmt::Display for RenderError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RenderError::Sensor(e) => write!(f, "camera model: {e}"),
            RenderError::TargetTooClose { nearest_z_m } => write!(
                f,
                "the target reaches {nearest_z_m:.3} m in front of the camera: expected the whole target > 0.1 m ahead (increase range_m)"
            ),
            RenderError::Input(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for RenderError {}

impl From<SensorError> for RenderError {
    fn from(e: SensorError) -> Self {
        RenderError::Sensor(e)
    }
}

/// Pinhole projection of the camera.
#[derive(Debug, Clone, Copy)]
pub(super) struct Pinhole {
    f: f64,
    cx: f64,
    cy: f64,
    w: usize,
    h: usize,
}

impl Pinhole {
    fn new(c: &Camera) -> Self {
        Pinhole {
            f: c.focal_px(),
            cx: c.width as f64 / 2.0,
            cy: c.height as f64 / 2.0,
            w: c.width,
            h: c.height,
        }
    }

    /// Unit ray through image point (u, v).
    fn ray(&self, u: f64, v: f64) -> Vec3 {
        let d = [(u - self.cx) / self.f, (v - self.cy) / self.f, 1.0];
        scale(d, 1.0 / norm(d))
    }

    /// The largest angle between the boresight and a frame corner, rad (half the
    /// diagonal field of view when the principal point is the frame centre; also right
    /// for a window of the frame, whose principal point is off centre).
    fn half_diagonal_rad(&self) -> f64 {
        let dx = self.cx.abs().max((self.w as f64 - self.cx).abs());
        let dy = self.cy.abs().max((self.h as f64 - self.cy).abs());
        (dx.hypot(dy) / self.f).atan()
    }
}

/// Renders one frame.
///
/// # Errors
/// [`RenderError`] for a target too close to the camera, temperatures that do not match
/// the mesh, or values the core's camera model refuses.
pub fn render(input: &RenderInput<'_>) -> Result<Rendered, RenderError> {
    let cam = Pinhole::new(input.camera);
    let n = cam.w * cam.h;
    let mut stats = RenderStats::default();
    // Per pixel: target coverage and the target's share of the signal.
    let mut coverage = vec![0f32; n];
    let mut signal = vec![0f32; n];
    // Pure pixels (all target or all Earth) bound the radiometry range (Eq. 17).
    let mut pure = PurePixels::default();

    let t0 = Instant::now();
    if let Some(target) = &input.target {
        render_target(
            &cam,
            target,
            input,
            &mut coverage,
            &mut signal,
            &mut pure,
            &mut stats,
        )?;
    }
    stats.target_ns = t0.elapsed().as_nanos() as u64;

    let t1 = Instant::now();
    let mut moon_px = 0usize;
    if let Some(moon) = &input.moon {
        moon_px = render_moon(
            &cam,
            moon,
            input.earth.as_ref(),
            input.readout,
            input.lut,
            &coverage,
            &mut signal,
            &mut pure,
        )?;
    }
    let mut earth_px = 0usize;
    if let Some(earth) = &input.earth {
        earth_px = render_earth(
            &cam,
            earth,
            input.lut,
            input.readout,
            &coverage,
            &mut signal,
            &mut pure,
            &mut stats,
        )?;
    }
    stats.earth_ns = t1.elapsed().as_nanos() as u64;

    let out = read_out(input, signal, &pure, &mut stats)?;

    let truth = mask_box(&coverage, cam.w);
    let truth_quarter = coverage_box(&coverage, cam.w, |c| c > QUARTER_COVERAGE);
    Ok(Rendered {
        width: cam.w,
        height: cam.h,
        dn: out.dn,
        signal: out.signal,
        coverage,
        truth,
        truth_quarter,
        earth_fraction: earth_px as f64 / n as f64,
        moon_px,
        mapping: out.mapping,
        noise_sigma_dn: out.noise_sigma_dn,
        stats,
        clutter: None,
    })
}

/// Radiance → `input.readout`'s signal unit, sr: F = π·L in radiometry, q_fc =
/// L·ΔA_c/r² (face-on) in detection.
fn signal_per_radiance_sr(input: &RenderInput<'_>) -> f64 {
    match input.readout {
        Readout::Radiometry => std::f64::consts::PI,
        Readout::Detection(_) => SENSOR_AREA_M2 / input.earth_distance_m / input.earth_distance_m,
    }
}

/// A scene signal frame of `input.camera`'s size as the detector array receives it: the
/// optics PSF of `input.sensor`, then its signature (each only when it is on). Linear
/// per pixel, so the difference of two frames through it is the difference blurred and
/// scaled by the pixel gains (the signature's offsets cancel).
///
/// # Errors
/// [`RenderError::Input`] for a signal or signature of another size than the camera's.
pub fn through_the_optics(
    input: &RenderInput<'_>,
    mut signal: Vec<f32>,
) -> Result<Vec<f32>, RenderError> {
    let (w, h) = (input.camera.width, input.camera.height);
    if let Some(psf) = input.sensor.psf {
        let mut blurred = vec![0f32; signal.len()];
        psf.apply(&signal, w, &mut blurred)
            .map_err(RenderError::Input)?;
        signal = blurred;
    }
    if let Some(sig) = input.sensor.signature {
        if sig.width != w || sig.height != h {
            return Err(RenderError::Input(format!(
                "sensor signature of {} × {} px for a {} × {} camera: expected the camera's size",
                sig.width, sig.height, w, h
            )));
        }
        sig.apply(&mut signal, signal_per_radiance_sr(input))
            .map_err(RenderError::Input)?;
    }
    Ok(signal)
}

/// A signal frame read out: what [`read_out`] returns.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadOut {
    /// DN, row-major.
    pub dn: Vec<u16>,
    /// The signal after the optics PSF and the sensor signature (as given without them).
    pub signal: Vec<f32>,
    /// The DN map used.
    pub mapping: DnMapping,
    /// Total noise σ, DN (0 without noise).
    pub noise_sigma_dn: f32,
}

/// The readout stage of [`render`] on a signal frame of `input.camera`'s size (F in
/// W m⁻² in radiometry, q_fc in detection): the optics PSF and sensor signature of
/// `input.sensor`, the DN map of `input.readout` (auto range over `pure`, the frame's
/// unmixed pixels: the (min, max) of their signal, measured after the optics and the
/// signature when the camera has them, [`PurePixels::measured_bounds`]; or the fixed
/// gain), the noise of
/// `input.noise_seed` and quantisation. The scene part of `input` (target, Earth,
/// Moon) is not used: callers that make the signal another way (test frames over real
/// backgrounds) read it out exactly as a rendered frame is.
///
/// # Errors
/// [`RenderError`] for a signal of another size than the camera's, a bad gain factor
/// or values the core's camera model refuses.
pub fn read_out(
    input: &RenderInput<'_>,
    mut signal: Vec<f32>,
    pure: &PurePixels,
    stats: &mut RenderStats,
) -> Result<ReadOut, RenderError> {
    let (w, h) = (input.camera.width, input.camera.height);
    let n = w * h;
    if signal.len() != n {
        return Err(RenderError::Input(format!(
            "signal of {} px for a {w} × {h} camera: expected {n}",
            signal.len()
        )));
    }
    let ts = Instant::now();
    signal = through_the_optics(input, signal)?;
    let sensed = input.sensor.psf.is_some() || input.sensor.signature.is_some();
    if sensed {
        stats.sensor_ns = ts.elapsed().as_nanos() as u64;
    }

    let t2 = Instant::now();
    let bits = input.camera.bits;
    let mapping = match (input.readout, input.sensor.fixed_gain) {
        (Readout::Detection(scale), _) => DnMapping::detection(scale, bits)?,
        // The frame's gain factor multiplies the camera gain; the pedestal stays.
        (Readout::Radiometry, Some(fixed)) => DnMapping::radiometry_fixed_gain(
            fixed.dn_per_w_m2_sr * input.gain_factor,
            fixed.pedestal_dn,
            bits,
        )?,
        (Readout::Radiometry, None) => {
            // Eq. 17 over the pure pixels, with the span kept at least
            // MIN_RANGE_NETD NETDs wide (in F at the reference temperature), so a
            // near-uniform scene is not stretched until its noise fills the frame.
            // The camera ranges on what it measures: with optics or a signature, the
            // pure pixels' signal after them (its shading and offset included).
            let bounds = if sensed {
                pure.measured_bounds(&signal)
            } else {
                pure.bounds()
            };
            let (lo, hi) = bounds.unwrap_or((0.0, 0.0));
            let min_span = MIN_RANGE_NETD
                * input.camera.netd_k
                * std::f64::consts::PI
                * input
                    .band
                    .radiance_derivative_w_m2_sr_k(input.camera.netd_reference_k, 1.0)?;
            let (lo, hi) = if hi - lo >= min_span && hi > lo {
                (lo, hi)
            } else {
                // The scene's F is ≥ 0; a measured signal may be below (the offset).
                let floor = if sensed { f64::MIN } else { 0.0 };
                let lo = (0.5 * (lo + hi) - 0.5 * min_span).max(floor);
                (lo, lo + min_span.max(f64::MIN_POSITIVE))
            };
            if sensed {
                DnMapping::radiometry_auto_measured(lo, hi, bits)?
            } else {
                DnMapping::radiometry_auto(lo, hi, bits)?
            }
        }
    };
    let g = input.gain_factor;
    if !(g.is_finite() && g > 0.0) {
        return Err(RenderError::Input(format!(
            "gain factor {g}: expected a finite number > 0"
        )));
    }
    let fixed = matches!(
        (input.readout, input.sensor.fixed_gain),
        (Readout::Radiometry, Some(_))
    );
    let mapping = if g == 1.0 || fixed {
        mapping
    } else {
        // About the signal that maps to DN 0 (radiometry: the frame's minimum F).
        let zero_signal = mapping.signal(0.0);
        let gain = mapping.gain_dn() * g;
        DnMapping::new(gain, 0.0 - gain * zero_signal, bits)?
    };
    let mut noise_sigma_dn = 0.0;
    let mut field = match input.noise_seed {
        None => None,
        Some(seed) => {
            let dn_per_k = mapping.dn_per_kelvin(
                input.band,
                input.camera.netd_reference_k,
                signal_per_radiance_sr(input),
            )?;
            let level = NoiseLevel::Netd {
                netd_k: input.camera.netd_k,
                dn_per_k,
            };
            let sigmas = level.sigmas(&NoiseRms::TABLE2, &mapping)?;
            noise_sigma_dn = sigmas.total_dn();
            // The largest capacity: the same noise at any size (the capacity only
            // sizes the filter's row of state).
            Some(NoiseField::<Cap1024x768>::for_capacity(
                sigmas,
                input.camera.flicker_correlation_px,
                w,
                seed,
            )?)
        }
    };
    let mut dn = vec![0u16; n];
    expose_frame(&signal, w, &mapping, field.as_mut(), &mut dn)?;
    stats.expose_ns = t2.elapsed().as_nanos() as u64;

    Ok(ReadOut {
        dn,
        signal,
        mapping,
        noise_sigma_dn,
    })
}

/// Image point of sub-sample `s` (0..16, row-major) of pixel (x, y): the centres of a
/// 4 × 4 grid of equal cells.
fn sample_point(x: usize, y: usize, s: usize) -> (f64, f64) {
    let step = 1.0 / SUPERSAMPLES_PER_AXIS as f64;
    (
        x as f64 + ((s % SUPERSAMPLES_PER_AXIS) as f64 + 0.5) * step,
        y as f64 + ((s / SUPERSAMPLES_PER_AXIS) as f64 + 0.5) * step,
    )
}

/// Tight box of the pixels whose coverage is at least [`MASK_COVERAGE`].
pub fn mask_box(coverage: &[f32], width: usize) -> Roi {
    coverage_box(coverage, width, |c| c >= MASK_COVERAGE)
}

/// Tight box of the pixels whose coverage `keep` accepts ([`Roi::EMPTY`] when none).
pub fn coverage_box(coverage: &[f32], width: usize, keep: impl Fn(f32) -> bool) -> Roi {
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for (y, row) in coverage.chunks_exact(width).enumerate() {
        for (x, &c) in row.iter().enumerate() {
            if keep(c) {
                x0 = x0.min(x);
                y0 = y0.min(y);
                x1 = x1.max(x + 1);
                y1 = y1.max(y + 1);
            }
        }
    }
    if x0 == usize::MAX {
        Roi::EMPTY
    } else {
        Roi::new(x0 as u16, y0 as u16, x1 as u16, y1 as u16)
    }
}
