//! The report of `tirroi sensor`: the options checked ([`SensorRequest`]) and every
//! number taken from the core ([`report`] → [`SensorReport`]); the tables are in
//! [`markdown`](super::markdown).

use std::f64::consts::PI;

use serde::Serialize;
use tirroi_core::frame::MAX_BIT_DEPTH;
use tirroi_core::sensor::noise::NoiseRms;
use tirroi_core::sensor::planck::STEFAN_BOLTZMANN_W_M2_K4;
use tirroi_core::sensor::{
    BandRadiance, BolometerParams, CameraResponse, DnMapping, NoiseLevel, NoiseSigmas, RmsReading,
    SensorError,
};

use crate::world::scene::ResponseName;

/// Which noise level sets the σ in DN (`tirroi_core::sensor::NoiseLevel`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum LevelChoice {
    /// Total σ = NETD (K) × ∂DN/∂T at the reference temperature (the default).
    Netd,
    /// Eq. 16 as printed: σ = 2470 ADU/V × v (V), in DN.
    PaperLiteral,
    /// Eq. 16 as a fraction of full scale: σ = 2470 ADU/V × v (V) × (2^bits − 1) DN.
    PaperVisible,
}

impl LevelChoice {
    /// All levels, in the order they are printed.
    pub const ALL: [LevelChoice; 3] = [Self::Netd, Self::PaperLiteral, Self::PaperVisible];

    /// The name used on the command line and in the JSON.
    pub fn name(self) -> &'static str {
        match self {
            Self::Netd => "netd",
            Self::PaperLiteral => "paper-literal",
            Self::PaperVisible => "paper-visible",
        }
    }

    /// The core's noise level, with the NETD (K) and ∂DN/∂T (DN K⁻¹) for `Netd`.
    pub fn to_core(self, netd_k: f64, dn_per_k: f64) -> NoiseLevel {
        match self {
            Self::Netd => NoiseLevel::Netd { netd_k, dn_per_k },
            Self::PaperLiteral => NoiseLevel::PaperLiteral,
            Self::PaperVisible => NoiseLevel::PaperVisible,
        }
    }
}

/// Which set of RMS voltages feeds the noise (`tirroi_core::sensor::RmsReading`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ReadingChoice {
    /// The published Table 2 values (the default).
    Table2,
    /// Eqs. 11, 13, 14 exactly as printed.
    AsPrinted,
    /// Physically consistent bandwidths and thermal formula.
    Physical,
}

impl ReadingChoice {
    /// The name used on the command line and in the JSON.
    pub fn name(self) -> &'static str {
        match self {
            Self::Table2 => "table2",
            Self::AsPrinted => "as-printed",
            Self::Physical => "physical",
        }
    }

    /// The core's reading.
    pub fn to_core(self) -> RmsReading {
        match self {
            Self::Table2 => RmsReading::Table2,
            Self::AsPrinted => RmsReading::AsPrinted,
            Self::Physical => RmsReading::Physical,
        }
    }
}

/// Which spectral response the band radiance integrates over.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ResponseChoice {
    /// The Hayabusa2 TIR's measured response (`CameraResponse::default()`; JAXA's TIR
    /// team, 0.01 µm samples, linear between them).
    #[value(name = "hayabusa2")]
    #[serde(rename = "hayabusa2")]
    Hayabusa2,
    /// The analytic skewed-bell model of the TIR, 8–12 µm, η = 1
    /// (`SkewedBell::HAYABUSA2_TIR`).
    Tir,
    /// R = 1 at every wavelength: i = ε·σT⁴/π, checkable by hand.
    Flat,
}

impl ResponseChoice {
    /// The name used on the command line and in the JSON.
    pub fn name(self) -> &'static str {
        self.scene_name().name()
    }

    /// The same choice as a scene file's `[camera] response`.
    pub fn scene_name(self) -> ResponseName {
        match self {
            Self::Hayabusa2 => ResponseName::Hayabusa2,
            Self::Tir => ResponseName::Tir,
            Self::Flat => ResponseName::Flat,
        }
    }

    /// The core's response.
    pub fn to_core(self) -> CameraResponse {
        self.scene_name().to_core()
    }
}

/// The options of `tirroi sensor` as given on the command line, as text: parsed and
/// checked by [`report`], so that every bad value gets the same one-line error.
#[derive(Debug, Clone, Copy)]
pub struct SensorRequest<'a> {
    /// `--level`: `netd`, `paper-literal` or `paper-visible`.
    pub level: &'a str,
    /// `--reading`: `table2`, `as-printed` or `physical`.
    pub reading: &'a str,
    /// `--response`: `hayabusa2`, `tir` or `flat`.
    pub response: &'a str,
    /// `--netd-k`: NETD, K.
    pub netd_k: &'a str,
    /// `--t-ref-k`: reference scene temperature of the NETD level, K.
    pub t_ref_k: &'a str,
    /// `--bits`: bit depth, 1..=16.
    pub bits: &'a str,
    /// `--temps`: comma-separated scene temperatures, K.
    pub temps: &'a str,
    /// `--emissivity`: gray-body emissivity, (0, 1].
    pub emissivity: &'a str,
    /// `--range-k`: `T_lo,T_hi` of the radiometry auto range, K.
    pub range_k: &'a str,
    /// `--bandwidths`: comma-separated measurement bandwidths of the NVD, Hz.
    pub bandwidths: &'a str,
}

/// Everything `tirroi sensor` prints; serialised as the `--json` object.
#[derive(Debug, Clone, Serialize)]
pub struct SensorReport {
    /// `"tir"` or `"flat"`.
    pub response: ResponseChoice,
    /// `"netd"`, `"paper-literal"` or `"paper-visible"`.
    pub level: LevelChoice,
    /// NETD of the `netd` level, K.
    pub netd_k: f64,
    /// Reference scene temperature of the `netd` level, K.
    pub t_ref_k: f64,
    /// Bit depth.
    pub bits: u8,
    /// Emissivity of every temperature (and of the range).
    pub emissivity: f64,
    /// The radiometry DN map.
    pub mapping: MappingView,
    /// The noise budget.
    pub noise: NoiseView,
    /// Noise voltage density per bandwidth.
    pub nvd: Vec<NvdRow>,
    /// One row per scene temperature.
    pub temperatures: Vec<TemperatureRow>,
}

/// The radiometry-mode DN map of Eq. 17.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct MappingView {
    /// Low end of the auto range, K.
    pub t_lo_k: f64,
    /// High end of the auto range, K.
    pub t_hi_k: f64,
    /// F(T_lo), W m⁻²: mapped to DN 0.
    pub f_min_w_m2: f64,
    /// F(T_hi), W m⁻²: mapped to DN 2ⁿ − 1.
    pub f_max_w_m2: f64,
    /// Camera gain a, DN per W m⁻².
    pub gain_dn_per_w_m2: f64,
    /// Camera offset b, DN.
    pub offset_dn: f64,
    /// Largest DN, 2ⁿ − 1.
    pub max_dn: u16,
}

/// RMS voltages and σ in DN of the three noise sources and their total.
#[derive(Debug, Clone, Serialize)]
pub struct NoiseView {
    /// `"table2"`, `"as-printed"` or `"physical"`.
    pub reading: ReadingChoice,
    /// Johnson noise, V.
    pub johnson_v: f64,
    /// 1/f noise, V.
    pub flicker_v: f64,
    /// Temperature-fluctuation noise, V.
    pub thermal_v: f64,
    /// √(v_J² + v_1/f² + v_th²), V.
    pub total_v: f64,
    /// Johnson σ at the chosen level, DN.
    pub johnson_dn: f64,
    /// 1/f σ at the chosen level, DN.
    pub flicker_dn: f64,
    /// Thermal σ at the chosen level, DN.
    pub thermal_dn: f64,
    /// Total σ at the chosen level, DN.
    pub total_dn: f64,
    /// ∂DN/∂T of the radiometry map at `t_ref_k` (ε = 1), DN K⁻¹.
    pub dn_per_k: f64,
    /// `total_dn / dn_per_k`, K.
    pub netd_equivalent_k: f64,
    /// The total σ and its NETD equivalent at every level, for comparison.
    pub levels: Vec<LevelRow>,
}

/// The total noise of one level.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct LevelRow {
    /// The level.
    pub level: LevelChoice,
    /// Total σ, DN.
    pub total_dn: f64,
    /// `total_dn / dn_per_k`, K.
    pub netd_equivalent_k: f64,
}

/// The noise voltage density over one measurement bandwidth.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct NvdRow {
    /// Bandwidth Δf, Hz.
    pub bandwidth_hz: f64,
    /// NVD, V Hz^-½.
    pub nvd_v_per_sqrt_hz: f64,
}

/// The camera model at one scene temperature.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct TemperatureRow {
    /// Scene temperature, K.
    pub t_k: f64,
    /// Band radiance i(T, ε), W m⁻² sr⁻¹.
    pub radiance_w_m2_sr: f64,
    /// Emissive power F(T) = π·i, W m⁻².
    pub emissive_power_w_m2: f64,
    /// σT⁴/π, W m⁻² sr⁻¹: the hand check (i = ε·σT⁴/π for the flat response).
    pub sigma_t4_over_pi_w_m2_sr: f64,
    /// Radiometry DN of F(T), quantised.
    pub dn: u16,
    /// Whether the DN was clipped at 0 or 2ⁿ − 1 (T outside the range).
    pub saturated: bool,
    /// Radiometric temperature of that DN, K.
    pub t_rad_k: f64,
}

/// `--option: message` for a core error.
fn core_err(option: &'static str) -> impl Fn(SensorError) -> String {
    move |e| format!("{option}: {e}")
}

/// One finite number.
fn parse_number(option: &str, text: &str, expected: &str) -> Result<f64, String> {
    let t = text.trim();
    if t.is_empty() {
        return Err(format!("{option}: empty value; expected {expected}"));
    }
    match t.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(format!(
            "{option}: `{t}` is not a finite number; expected {expected}"
        )),
        Err(_) => Err(format!(
            "{option}: `{t}` is not a number; expected {expected}"
        )),
    }
}

/// A comma-separated list of finite numbers, at least one.
fn parse_list(option: &str, text: &str, expected: &str) -> Result<Vec<f64>, String> {
    if text.trim().is_empty() {
        return Err(format!("{option}: empty list; expected {expected}"));
    }
    text.split(',')
        .map(|item| parse_number(option, item, expected))
        .collect()
}

/// One of the names of a [`clap::ValueEnum`] (exact, lower case).
fn parse_choice<T: clap::ValueEnum>(option: &str, text: &str) -> Result<T, String> {
    let t = text.trim();
    T::from_str(t, false).map_err(|_| {
        let names: Vec<String> = T::value_variants()
            .iter()
            .filter_map(|v| v.to_possible_value())
            .map(|p| p.get_name().to_owned())
            .collect();
        format!(
            "{option}: unknown value `{t}`; expected one of {}",
            names.join(", ")
        )
    })
}

fn parse_bits(text: &str) -> Result<u8, String> {
    let t = text.trim();
    let expected = format!("an integer bit depth 1..={MAX_BIT_DEPTH}");
    match t.parse::<u8>() {
        Ok(b) if (1..=MAX_BIT_DEPTH).contains(&b) => Ok(b),
        Ok(_) => Err(format!("--bits: {t} is out of range; expected {expected}")),
        Err(_) => Err(format!("--bits: `{t}` is not {expected}")),
    }
}

fn sigma_row(level: LevelChoice, s: &NoiseSigmas, dn_per_k: f64) -> LevelRow {
    let total_dn = f64::from(s.total_dn());
    LevelRow {
        level,
        total_dn,
        netd_equivalent_k: total_dn / dn_per_k,
    }
}

/// Parses and checks `req`, and evaluates the camera model.
///
/// # Errors
/// One line naming the option, what was wrong and what was expected.
pub fn report(req: &SensorRequest<'_>) -> Result<SensorReport, String> {
    let level: LevelChoice = parse_choice("--level", req.level)?;
    let reading: ReadingChoice = parse_choice("--reading", req.reading)?;
    let response: ResponseChoice = parse_choice("--response", req.response)?;
    let netd_k = parse_number("--netd-k", req.netd_k, "a NETD in K, e.g. 0.4")?;
    let t_ref_k = parse_number(
        "--t-ref-k",
        req.t_ref_k,
        "a reference temperature in K, e.g. 300",
    )?;
    let bits = parse_bits(req.bits)?;
    let temps = parse_list(
        "--temps",
        req.temps,
        "comma-separated temperatures in K, e.g. 150,200,300",
    )?;
    let emissivity = parse_number("--emissivity", req.emissivity, "0 < emissivity <= 1")?;
    if !(emissivity > 0.0 && emissivity <= 1.0) {
        return Err(format!(
            "--emissivity: {emissivity} is out of range; expected 0 < emissivity <= 1 \
             (0 gives no signal and no radiometric temperature)"
        ));
    }
    let range_expected = "two temperatures T_lo,T_hi in K with T_lo < T_hi, e.g. 150,460";
    let range = parse_list("--range-k", req.range_k, range_expected)?;
    let &[t_lo_k, t_hi_k] = range.as_slice() else {
        return Err(format!(
            "--range-k: {} value(s) given; expected {range_expected}",
            range.len()
        ));
    };
    if t_lo_k >= t_hi_k {
        return Err(format!(
            "--range-k: T_lo = {t_lo_k} K is not below T_hi = {t_hi_k} K; expected {range_expected}"
        ));
    }
    let bw_expected = "comma-separated bandwidths in Hz > 0, e.g. 1,10,100";
    let bandwidths = parse_list("--bandwidths", req.bandwidths, bw_expected)?;
    if let Some(bad) = bandwidths.iter().find(|&&b| b <= 0.0) {
        return Err(format!(
            "--bandwidths: {bad} Hz is not positive; expected {bw_expected}"
        ));
    }

    let band = BandRadiance::new(&response.to_core()).map_err(core_err("--response"))?;

    // Eq. 17: the scene's smallest and largest emissive power span the DN range.
    let f_min_w_m2 = band
        .emissive_power_w_m2(t_lo_k, emissivity)
        .map_err(core_err("--range-k"))?;
    let f_max_w_m2 = band
        .emissive_power_w_m2(t_hi_k, emissivity)
        .map_err(core_err("--range-k"))?;
    let mapping =
        DnMapping::radiometry_auto(f_min_w_m2, f_max_w_m2, bits).map_err(core_err("--range-k"))?;

    // Noise.
    let dn_per_k = mapping
        .dn_per_kelvin(&band, t_ref_k, PI)
        .map_err(core_err("--t-ref-k"))?;
    if !(dn_per_k > 0.0 && dn_per_k.is_finite()) {
        return Err(format!(
            "--t-ref-k: dDN/dT at {t_ref_k} K is {dn_per_k} DN/K for this band and range; \
             expected a temperature where the band has signal, e.g. 300"
        ));
    }
    let rms: NoiseRms = BolometerParams::TABLE1.rms(reading.to_core());
    let chosen_level = level;
    let mut chosen = NoiseSigmas::default();
    let mut levels = Vec::with_capacity(LevelChoice::ALL.len());
    for level in LevelChoice::ALL {
        let sigmas = level
            .to_core(netd_k, dn_per_k)
            .sigmas(&rms, &mapping)
            .map_err(|e| match e {
                SensorError::OutOfRange { name: "netd_k", .. }
                | SensorError::NotFinite { name: "netd_k" } => format!("--netd-k: {e}"),
                SensorError::OutOfRange {
                    name: "dn_per_k", ..
                }
                | SensorError::NotFinite { name: "dn_per_k" } => {
                    format!("--t-ref-k/--range-k: {e}")
                }
                _ => format!("--reading: {e}"),
            })?;
        if level == chosen_level {
            chosen = sigmas;
        }
        levels.push(sigma_row(level, &sigmas, dn_per_k));
    }
    let total_dn = f64::from(chosen.total_dn());
    let noise = NoiseView {
        reading,
        johnson_v: rms.johnson_v,
        flicker_v: rms.flicker_v,
        thermal_v: rms.thermal_v,
        total_v: rms.total_v(),
        johnson_dn: f64::from(chosen.johnson_dn),
        flicker_dn: f64::from(chosen.flicker_dn),
        thermal_dn: f64::from(chosen.thermal_dn),
        total_dn,
        dn_per_k,
        netd_equivalent_k: total_dn / dn_per_k,
        levels,
    };

    let nvd = bandwidths
        .iter()
        .map(|&bandwidth_hz| NvdRow {
            bandwidth_hz,
            nvd_v_per_sqrt_hz: BolometerParams::TABLE1.nvd_v_per_sqrt_hz(bandwidth_hz),
        })
        .collect();

    let mut temperatures = Vec::with_capacity(temps.len());
    for &t_k in &temps {
        let radiance_w_m2_sr = band
            .radiance_w_m2_sr(t_k, emissivity)
            .map_err(core_err("--temps"))?;
        let emissive_power_w_m2 = band
            .emissive_power_w_m2(t_k, emissivity)
            .map_err(core_err("--temps"))?;
        let raw_dn = mapping.dn(emissive_power_w_m2);
        let dn = mapping.quantise(raw_dn);
        let rounded = (raw_dn + 0.5).floor();
        let saturated = rounded < 0.0 || rounded > f64::from(mapping.max_dn());
        let t_rad_k = mapping
            .radiometric_temperature_k(f64::from(dn), &band, emissivity)
            .map_err(|e| format!("--temps: radiometric temperature of DN {dn} at {t_k} K: {e}"))?;
        let t2 = t_k * t_k;
        temperatures.push(TemperatureRow {
            t_k,
            radiance_w_m2_sr,
            emissive_power_w_m2,
            sigma_t4_over_pi_w_m2_sr: STEFAN_BOLTZMANN_W_M2_K4 * t2 * t2 / PI,
            dn,
            saturated,
            t_rad_k,
        });
    }

    Ok(SensorReport {
        response,
        level,
        netd_k,
        t_ref_k,
        bits,
        emissivity,
        mapping: MappingView {
            t_lo_k,
            t_hi_k,
            f_min_w_m2,
            f_max_w_m2,
            gain_dn_per_w_m2: mapping.gain_dn(),
            offset_dn: mapping.offset_dn(),
            max_dn: mapping.max_dn(),
        },
        noise,
        nvd,
        temperatures,
    })
}
