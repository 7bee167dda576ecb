//! `tirroi._native`: the Rust half of the Python package `tirroi` (the Python half,
//! `tirroi/__init__.py`, wraps it with dataclasses, docstrings and input checks).
//!
//! Every call goes to the host library or the core, the same code the `tirroi` binary
//! runs: the renderer and labels of `tirroi render` (`tirroi_host::dataset::FrameRenderer`),
//! the detector bank of `tirroi detect` (`tirroi_host::eval::bank::DetectorBank`), the
//! camera model of `tirroi sensor` (`tirroi_core::sensor`). Nothing is re-implemented
//! here. Bad input raises `ValueError` with the message the CLI prints after
//! `tirroi: error: `; no input panics.

use std::cell::RefCell;
use std::f64::consts::PI;
use std::path::Path;

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tirroi_core::capacity::{Cap1024x768, FrameCapacity};
use tirroi_core::roi::auto::learned::AutoV2;
use tirroi_core::roi::track::Tracker as CoreTracker;
use tirroi_core::sensor::noise::NoiseRms;
use tirroi_core::sensor::{BandRadiance, DnMapping, NoiseField, NoiseLevel, expose_frame};
use tirroi_core::{Detection, Frame, Method, Roi};
use tirroi_host::dataset::{FrameRenderer, LabelledFrame};
use tirroi_host::eval::bank::DetectorBank;
use tirroi_host::world::scene::{self, Camera, ResponseName, SceneFile};

/// A `ValueError` carrying `msg` (the CLI's one-line message).
fn bad(msg: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(msg.to_string())
}

/// The detectors' names, in registry order (`Method::ALL`).
#[pyfunction]
fn methods() -> Vec<&'static str> {
    Method::ALL.iter().map(|m| m.name()).collect()
}

/// The built-in presets: (name, one-line description), as `tirroi render --list-presets`.
#[pyfunction]
fn presets() -> Vec<(&'static str, &'static str)> {
    scene::PRESETS
        .iter()
        .map(|(name, about, _)| (*name, *about))
        .collect()
}

/// The scene file of `tirroi render --preset/--config [--seed] [--count]`, or the
/// CLI's error message.
fn scene_file(
    preset: Option<&str>,
    config: Option<&str>,
    count: Option<u64>,
    seed: Option<u64>,
) -> Result<SceneFile, String> {
    let mut file = match (preset, config) {
        (Some(_), Some(_)) => {
            return Err("give either preset or config, not both".into());
        }
        (Some(name), None) => SceneFile::preset(name),
        (None, Some(path)) => SceneFile::load(Path::new(path)),
        (None, None) => return Err("give --preset NAME or --config FILE".into()),
    }
    .map_err(|e| e.to_string())?;
    if let Some(seed) = seed {
        file.dataset.seed = seed;
    }
    if let Some(count) = count {
        if !(1..=10_000_000).contains(&count) {
            return Err(format!(
                "count {count} is out of range; expected 1..=10000000 images"
            ));
        }
        file.rescale_count(count as usize)
            .map_err(|e| e.to_string())?;
    }
    Ok(file)
}

/// A dataset's plan and library, built once; frames render on demand (`render`).
#[pyclass(module = "tirroi._native", frozen)]
struct Renderer {
    inner: FrameRenderer,
}

#[pymethods]
impl Renderer {
    /// Plans the dataset of a preset or scene file (after `seed` and `count`, as the
    /// CLI's options) and builds its shared library (thermal solutions, Earth maps).
    #[new]
    #[pyo3(signature = (preset=None, config=None, count=None, seed=None))]
    fn new(
        py: Python<'_>,
        preset: Option<&str>,
        config: Option<&str>,
        count: Option<u64>,
        seed: Option<u64>,
    ) -> PyResult<Self> {
        let file = scene_file(preset, config, count, seed).map_err(bad)?;
        let inner = py.detach(move || FrameRenderer::new(file)).map_err(bad)?;
        Ok(Renderer { inner })
    }

    /// Frames in the dataset.
    fn __len__(&self) -> usize {
        self.inner.len()
    }

    /// The dataset's resolved scene file as TOML (`tirroi render --print-config`).
    fn scene_toml(&self) -> PyResult<String> {
        toml_text(self.inner.file())
    }

    /// The dataset seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.inner.file().dataset.seed
    }

    /// The dataset name.
    #[getter]
    fn name(&self) -> String {
        self.inner.file().dataset.name.clone()
    }

    /// Renders frames `start..end` (clipped to the dataset) in parallel, without the
    /// GIL; one dict per frame: `dn` (uint16, H×W), `signal` (float32, H×W, W m⁻²),
    /// `coverage` (float32, H×W, 0–1), `record` (the frame's `metadata.jsonl` line).
    fn render<'py>(
        &self,
        py: Python<'py>,
        start: usize,
        end: usize,
    ) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let frames = py.detach(|| self.inner.render(start..end)).map_err(bad)?;
        frames.into_iter().map(|f| frame_dict(py, f)).collect()
    }
}

/// `tirroi render --print-config`'s TOML of a scene file.
fn toml_text(file: &SceneFile) -> PyResult<String> {
    toml::to_string(file).map_err(bad)
}

/// One rendered frame as the dict `Renderer.render` returns.
fn frame_dict(py: Python<'_>, f: LabelledFrame) -> PyResult<Bound<'_, PyDict>> {
    let (w, h) = (f.frame.width, f.frame.height);
    let d = PyDict::new(py);
    d.set_item("dn", PyArray1::from_vec(py, f.frame.dn).reshape([h, w])?)?;
    d.set_item(
        "signal",
        PyArray1::from_vec(py, f.frame.signal).reshape([h, w])?,
    )?;
    d.set_item(
        "coverage",
        PyArray1::from_vec(py, f.frame.coverage).reshape([h, w])?,
    )?;
    let record = serde_json::to_string(&f.record).map_err(bad)?;
    d.set_item("record", record)?;
    Ok(d)
}

thread_local! {
    /// One detector bank per thread (its scratch is ~141 KB, made once).
    static BANK: RefCell<DetectorBank> = RefCell::new(DetectorBank::default());
}

/// The row-major pixels of a 2-D uint16 frame of `bits`-bit DN, with its width and
/// height, or the CLI's message (not 2-D, DN above the bit depth, a bad size).
fn frame_pixels(dn: &PyReadonlyArrayDyn<'_, u16>, bits: u8) -> PyResult<(Vec<u16>, usize, usize)> {
    let shape = dn.shape().to_vec();
    let [height, width] = shape[..] else {
        return Err(bad(format!(
            "dn has {} dimension(s); expected a 2-D frame (height, width)",
            shape.len()
        )));
    };
    // Row-major (C) order whatever the array's layout (`as_slice` would give a
    // Fortran-ordered array's memory order).
    let pixels: Vec<u16> = match dn.as_slice() {
        Ok(s) if dn.is_c_contiguous() => s.to_vec(),
        _ => dn.as_array().iter().copied().collect(),
    };
    let frame = Frame::new(&pixels, width, height, bits).map_err(bad)?;
    let max = frame.max_dn();
    if let Some(v) = pixels.iter().copied().find(|&v| v > max) {
        return Err(bad(format!(
            "DN {v} is above 2^{bits} - 1 = {max}; expected bits >= {} for this frame",
            16 - v.leading_zeros()
        )));
    }
    Ok((pixels, width, height))
}

/// A detection as the Python half takes it: (box [x0, y0, x1, y1) or None, score 0–1,
/// threshold, foreground px, `auto-v2`'s stage that gave the box or None).
type DetectionTuple = (Option<[u16; 4]>, f32, u32, u32, Option<&'static str>);

/// `d` as the Python half takes it, with the stage of `auto-v2`'s box on `frame`
/// (`learned::Stage::name`, what `tirroi detect` prints; None for the other methods).
fn detection_tuple(d: Detection, method: Method, frame: &Frame<'_>) -> DetectionTuple {
    let stage = BANK
        .with(|b| b.borrow_mut().stage(method, frame, d.roi))
        .map(|s| s.name());
    (
        d.roi.map(|r: Roi| r.to_array()),
        d.score(),
        d.threshold,
        d.foreground_px,
        stage,
    )
}

/// Runs detector `method` on a 2-D uint16 frame of `bits`-bit DN; returns
/// (box [x0, y0, x1, y1) or None, score 0–1, threshold, foreground px).
#[pyfunction]
#[pyo3(signature = (dn, method, bits))]
fn detect(dn: PyReadonlyArrayDyn<'_, u16>, method: &str, bits: u8) -> PyResult<DetectionTuple> {
    let m = Method::from_name(method).ok_or_else(|| {
        let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
        bad(format!(
            "unknown method `{method}`; expected {}",
            names.join(", ")
        ))
    })?;
    let (pixels, width, height) = frame_pixels(&dn, bits)?;
    let frame = Frame::new(&pixels, width, height, bits).map_err(bad)?;
    let d = BANK
        .with(|b| b.borrow_mut().detect(m, &frame))
        .map_err(|e| bad(format!("{method}: {e}")))?;
    Ok(detection_tuple(d, m, &frame))
}

/// `auto-v2` over a sequence of frames: the core's tracker (`tirroi detect --method
/// auto-v2 --track`), its state kept between calls.
#[pyclass(module = "tirroi._native")]
struct Tracker {
    inner: CoreTracker,
}

#[pymethods]
impl Tracker {
    /// A tracker without history, `auto-v2`'s default parameters.
    #[new]
    fn new() -> Self {
        Tracker {
            inner: CoreTracker::new(AutoV2::DEFAULT),
        }
    }

    /// The next frame of the sequence (2-D uint16, `bits`-bit DN): as [`detect`].
    fn step(&mut self, dn: PyReadonlyArrayDyn<'_, u16>, bits: u8) -> PyResult<DetectionTuple> {
        let (pixels, width, height) = frame_pixels(&dn, bits)?;
        let frame = Frame::new(&pixels, width, height, bits).map_err(bad)?;
        let (d, _) = BANK
            .with(|b| b.borrow_mut().track_timed(&mut self.inner, &frame, 1))
            .map_err(|e| bad(format!("auto-v2: {e}")))?;
        Ok(detection_tuple(d, Method::AutoV2, &frame))
    }

    /// Forgets the history (a new sequence).
    fn reset(&mut self) {
        self.inner.reset();
    }

    /// The last frame's box [x0, y0, x1, y1) (the next frame's prior), or None.
    #[getter]
    fn prior(&self) -> Option<[u16; 4]> {
        self.inner.prior().map(|r| r.to_array())
    }
}

/// The core's band radiance of `response` (`tirroi sensor --response`), or the CLI's
/// message.
fn band(response: &str) -> PyResult<BandRadiance> {
    let name = match response {
        "hayabusa2" => ResponseName::Hayabusa2,
        "tir" => ResponseName::Tir,
        "flat" => ResponseName::Flat,
        other => {
            return Err(bad(format!(
                "--response: unknown value `{other}`; expected one of hayabusa2, tir, flat"
            )));
        }
    };
    BandRadiance::new(&name.to_core()).map_err(|e| bad(format!("--response: {e}")))
}

/// An f64 array as a flat vector in row-major (C) order, whatever its layout.
fn flat(a: &PyReadonlyArrayDyn<'_, f64>) -> Vec<f64> {
    match a.as_slice() {
        Ok(s) if a.is_c_contiguous() => s.to_vec(),
        _ => a.as_array().iter().copied().collect(),
    }
}

/// Band radiance i(T, ε) = ∫ ε B(λ, T) R(λ) dλ, W m⁻² sr⁻¹, element by element of two
/// arrays of the same shape (temperature K, emissivity).
#[pyfunction]
fn band_radiance<'py>(
    py: Python<'py>,
    temperature_k: PyReadonlyArrayDyn<'py, f64>,
    emissivity: PyReadonlyArrayDyn<'py, f64>,
    response: &str,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let b = band(response)?;
    let (t, e) = (flat(&temperature_k), flat(&emissivity));
    if t.len() != e.len() {
        return Err(bad("temperature_k and emissivity differ in size"));
    }
    let out = py.detach(|| {
        t.iter()
            .zip(&e)
            .map(|(&t, &e)| {
                b.radiance_w_m2_sr(t, e)
                    .map_err(|err| format!("temperature {t} K, emissivity {e}: {err}"))
            })
            .collect::<Result<Vec<f64>, String>>()
    });
    Ok(PyArray1::from_vec(py, out.map_err(bad)?))
}

/// The radiometry DN map of Eq. 17 over `range_k` (what `tirroi sensor --range-k`
/// uses): F(T_lo) ↦ DN 0, F(T_hi) ↦ 2^bits − 1.
fn auto_map(
    b: &BandRadiance,
    range_k: (f64, f64),
    emissivity: f64,
    bits: u8,
) -> PyResult<DnMapping> {
    let (lo, hi) = range_k;
    if lo >= hi {
        return Err(bad(format!(
            "--range-k: T_lo = {lo} K is not below T_hi = {hi} K; expected two temperatures T_lo,T_hi in K with T_lo < T_hi, e.g. 150,460"
        )));
    }
    let f_lo = b
        .emissive_power_w_m2(lo, emissivity)
        .map_err(|e| bad(format!("--range-k: {e}")))?;
    let f_hi = b
        .emissive_power_w_m2(hi, emissivity)
        .map_err(|e| bad(format!("--range-k: {e}")))?;
    DnMapping::radiometry_auto(f_lo, f_hi, bits).map_err(|e| bad(format!("--range-k: {e}")))
}

/// Radiometry-mode DN of a (height, width) array of temperatures, K (the camera model
/// of `tirroi sensor` and the renderer: F = π·i(T, ε), Eq. 17 map over `range_k`,
/// quantised with saturation); with `seed`, plus the renderer's seeded noise field
/// (NETD level: σ = `netd_k` × ∂DN/∂T at `t_ref_k`, Table 2 voltages, 1/f correlation
/// `flicker_correlation_px`). Returns (DN, gain DN per W m⁻², offset DN, total σ DN).
#[pyfunction]
#[pyo3(signature = (temperature_k, emissivity, response, range_k, bits, netd_k, t_ref_k, flicker_correlation_px, seed))]
#[allow(clippy::too_many_arguments)]
fn to_dn<'py>(
    py: Python<'py>,
    temperature_k: PyReadonlyArrayDyn<'py, f64>,
    emissivity: f64,
    response: &str,
    range_k: (f64, f64),
    bits: u8,
    netd_k: f64,
    t_ref_k: f64,
    flicker_correlation_px: f32,
    seed: Option<u64>,
) -> PyResult<(Bound<'py, PyArray1<u16>>, f64, f64, f32)> {
    if !(1..=16).contains(&bits) {
        return Err(bad(format!(
            "--bits: {bits} is out of range; expected an integer bit depth 1..=16"
        )));
    }
    if !(emissivity > 0.0 && emissivity <= 1.0) {
        return Err(bad(format!(
            "--emissivity: {emissivity} is out of range; expected 0 < emissivity <= 1"
        )));
    }
    let b = band(response)?;
    let mapping = auto_map(&b, range_k, emissivity, bits)?;
    let shape = temperature_k.shape().to_vec();
    let width = match shape[..] {
        [_, w] => w,
        [w] => w,
        _ => {
            return Err(bad(format!(
                "temperature_k has {} dimensions; expected 1 (one row) or 2 (height, width)",
                shape.len()
            )));
        }
    };
    let t = flat(&temperature_k);
    let mut signal = Vec::with_capacity(t.len());
    for &t_k in &t {
        let f = b
            .emissive_power_w_m2(t_k, emissivity)
            .map_err(|e| bad(format!("temperature_k: {e}")))?;
        signal.push(f as f32);
    }
    let mut sigma_dn = 0.0f32;
    let mut field = match seed {
        None => None,
        Some(seed) => {
            let dn_per_k = mapping
                .dn_per_kelvin(&b, t_ref_k, PI)
                .map_err(|e| bad(format!("--t-ref-k: {e}")))?;
            let sigmas = NoiseLevel::Netd { netd_k, dn_per_k }
                .sigmas(&NoiseRms::TABLE2, &mapping)
                .map_err(|e| bad(format!("--netd-k: {e}")))?;
            sigma_dn = sigmas.total_dn();
            if width > Cap1024x768::WIDTH {
                return Err(bad(format!(
                    "temperature_k is {width} px wide; the noise field takes rows of at most {} px",
                    Cap1024x768::WIDTH
                )));
            }
            Some(
                NoiseField::<Cap1024x768>::for_capacity(
                    sigmas,
                    flicker_correlation_px,
                    width,
                    seed,
                )
                .map_err(bad)?,
            )
        }
    };
    let mut dn = vec![0u16; signal.len()];
    if !signal.is_empty() {
        expose_frame(&signal, width, &mapping, field.as_mut(), &mut dn).map_err(bad)?;
    }
    Ok((
        PyArray1::from_vec(py, dn),
        mapping.gain_dn(),
        mapping.offset_dn(),
        sigma_dn,
    ))
}

/// Radiometric temperature of radiometry-mode DN under the Eq. 17 map over `range_k`,
/// K (the inverse of `to_dn` without noise, `tirroi sensor`'s `t_rad_k`; 0 at or below
/// DN 0's signal).
#[pyfunction]
fn radiometric_temperature<'py>(
    py: Python<'py>,
    dn: PyReadonlyArrayDyn<'py, f64>,
    emissivity: f64,
    response: &str,
    range_k: (f64, f64),
    bits: u8,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    if !(emissivity > 0.0 && emissivity <= 1.0) {
        return Err(bad(format!(
            "--emissivity: {emissivity} is out of range; expected 0 < emissivity <= 1"
        )));
    }
    let b = band(response)?;
    let mapping = auto_map(&b, range_k, emissivity, bits)?;
    let out = flat(&dn)
        .into_iter()
        .map(|v| {
            mapping
                .radiometric_temperature_k(v, &b, emissivity)
                .map_err(|e| bad(format!("dn {v}: {e}")))
        })
        .collect::<PyResult<Vec<f64>>>()?;
    Ok(PyArray1::from_vec(py, out))
}

/// The camera's defaults the Python wrapper shows in its signatures: (NETD K, NETD
/// reference temperature K, 1/f correlation px, bits).
#[pyfunction]
fn camera_defaults() -> (f64, f64, f32, u8) {
    let c = Camera::default();
    (
        c.netd_k,
        c.netd_reference_k,
        c.flicker_correlation_px,
        c.bits,
    )
}

/// The native module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Renderer>()?;
    m.add_class::<Tracker>()?;
    m.add_function(wrap_pyfunction!(methods, m)?)?;
    m.add_function(wrap_pyfunction!(presets, m)?)?;
    m.add_function(wrap_pyfunction!(detect, m)?)?;
    m.add_function(wrap_pyfunction!(band_radiance, m)?)?;
    m.add_function(wrap_pyfunction!(to_dn, m)?)?;
    m.add_function(wrap_pyfunction!(radiometric_temperature, m)?)?;
    m.add_function(wrap_pyfunction!(camera_defaults, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
