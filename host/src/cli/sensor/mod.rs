//! `tirroi sensor`: a read-out of the thermal camera model of `tirroi_core::sensor`
//! for engineers: the noise budget in volts and DN, the noise voltage density, and the
//! band radiance, emissive power, radiometry DN and radiometric temperature of a list
//! of scene temperatures.
//!
//! This command only parses and checks the options ([`report::SensorRequest`]), calls
//! the core ([`report::report`]) and formats the results ([`markdown`]); every number
//! comes from the core (the one exception is the σT⁴/π column, the hand check the flat
//! response is compared against).
//!
//! Bad input is reported as one line, `--option: what was wrong; expected what`, which
//! the CLI prints as `tirroi: error: …` with exit code 2.

use std::io::Write;
use std::process::ExitCode;

use tirroi_core::frame::DEFAULT_BIT_DEPTH;
use tirroi_core::sensor::noise::TIR_NETD_K;

use super::EXIT_BAD_INPUT;

pub mod markdown;
pub mod report;

pub use report::{SensorReport, SensorRequest, report};

/// The options of `tirroi sensor`. They are taken as text and checked by
/// [`report::report`], so that every bad value gets the same one-line error.
#[derive(Debug, clap::Args)]
pub struct SensorArgs {
    /// Noise level of the sigma in DN: netd (total sigma = NETD (K) x dDN/dT (DN/K) at
    /// --t-ref-k), paper-literal (Eq. 16: 2470 ADU/V x RMS (V)), paper-visible (Eq. 16 x
    /// (2^bits - 1)).
    #[arg(long, value_name = "LEVEL", default_value = "netd")]
    pub level: String,
    /// NETD of the `netd` level, K.
    #[arg(
        long,
        value_name = "K",
        default_value_t = TIR_NETD_K.to_string(),
        allow_hyphen_values = true
    )]
    pub netd_k: String,
    /// Reference scene temperature of the `netd` level (where dDN/dT is taken), K.
    #[arg(
        long,
        value_name = "K",
        default_value = "300",
        allow_hyphen_values = true
    )]
    pub t_ref_k: String,
    /// RMS voltages (V) of the three noise sources: table2 (the published Table 2),
    /// as-printed (Eqs. 11, 13, 14 as printed), physical (consistent bandwidths).
    #[arg(long, value_name = "READING", default_value = "table2")]
    pub reading: String,
    /// Bit depth of the DN, 1..=16.
    #[arg(
        long,
        value_name = "N",
        default_value_t = DEFAULT_BIT_DEPTH.to_string(),
        allow_hyphen_values = true
    )]
    pub bits: String,
    /// Scene temperatures, K, comma-separated (0..=10000).
    #[arg(
        long,
        value_name = "K,K,...",
        default_value = "150,200,250,300,350,400,460",
        allow_hyphen_values = true
    )]
    pub temps: String,
    /// Gray-body emissivity of the scene (and of the range), 0 < emissivity <= 1.
    #[arg(
        long,
        value_name = "E",
        default_value = "1.0",
        allow_hyphen_values = true
    )]
    pub emissivity: String,
    /// Radiometry auto range (Eq. 17), K: F(T_lo) maps to DN 0, F(T_hi) to 2^bits - 1.
    #[arg(
        long,
        value_name = "T_LO,T_HI",
        default_value = "150,460",
        allow_hyphen_values = true
    )]
    pub range_k: String,
    /// Measurement bandwidths of the noise voltage density, Hz, comma-separated (> 0).
    #[arg(
        long,
        value_name = "HZ,HZ,...",
        default_value = "1,10,100,1000,10000,83333,1000000",
        allow_hyphen_values = true
    )]
    pub bandwidths: String,
    /// Spectral response: hayabusa2 (the Hayabusa2 TIR's measured curve, the default),
    /// tir (the analytic skewed-bell model of it, 8-12 um, eta = 1) or flat (R = 1, so
    /// that i = emissivity x sigma T^4/pi (W m^-2 sr^-1)).
    #[arg(long, value_name = "RESPONSE", default_value = "hayabusa2")]
    pub response: String,
    /// Print one JSON object (shape in `tirroi sensor --help`) instead of the tables.
    #[arg(long)]
    pub json: bool,
}

/// Runs `tirroi sensor`: the report as markdown tables or one JSON object.
pub fn run(args: &SensorArgs) -> ExitCode {
    let request = SensorRequest {
        level: &args.level,
        reading: &args.reading,
        response: &args.response,
        netd_k: &args.netd_k,
        t_ref_k: &args.t_ref_k,
        bits: &args.bits,
        temps: &args.temps,
        emissivity: &args.emissivity,
        range_k: &args.range_k,
        bandwidths: &args.bandwidths,
    };
    let report = match report::report(&request) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("tirroi: error: {e}");
            return ExitCode::from(EXIT_BAD_INPUT);
        }
    };
    let text = if args.json {
        match serde_json::to_string(&report) {
            Ok(s) => s + "\n",
            Err(e) => {
                eprintln!("tirroi: error: cannot write JSON: {e}");
                return ExitCode::from(EXIT_BAD_INPUT);
            }
        }
    } else {
        report.markdown()
    };
    // A closed stdout (e.g. piped into `head`) is not an error worth a panic.
    let _ = std::io::stdout().lock().write_all(text.as_bytes());
    ExitCode::SUCCESS
}
