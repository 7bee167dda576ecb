//! The camera of a scene (Table 4, Hayabusa2 TIR) and its read-out.

use serde::{Deserialize, Serialize};
use tirroi_core::capacity::{Cap1024x768, FrameCapacity};
use tirroi_core::frame::{FRAME_HEIGHT, FRAME_WIDTH};
use tirroi_core::sensor::noise::{DEFAULT_FLICKER_CORRELATION_PX, TIR_NETD_K};
use tirroi_core::sensor::{CameraResponse, SkewedBell};

/// The spectral response R(λ) the camera integrates the scene's radiance over
/// (`[camera] response = "hayabusa2" | "tir" | "flat"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ResponseName {
    /// The Hayabusa2 TIR's measured response (JAXA's Hayabusa2 TIR team; the default):
    /// `CameraResponse::default()`.
    #[default]
    Hayabusa2,
    /// The analytic skewed-bell model of the same camera, η = 1
    /// (`SkewedBell::HAYABUSA2_TIR`): about 13 % more radiance than the real curve.
    Tir,
    /// R = 1 at every wavelength: the radiance is ε·σT⁴/π.
    Flat,
}

impl ResponseName {
    /// The name in a scene file and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Hayabusa2 => "hayabusa2",
            Self::Tir => "tir",
            Self::Flat => "flat",
        }
    }

    /// The core's response.
    pub fn to_core(self) -> CameraResponse {
        match self {
            Self::Hayabusa2 => CameraResponse::default(),
            Self::Tir => CameraResponse::Band(SkewedBell::HAYABUSA2_TIR),
            Self::Flat => CameraResponse::Flat,
        }
    }
}

/// The camera of Table 4 (Hayabusa2 TIR) and its read-out.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Camera {
    /// Focal length, mm (Table 4: 42.2).
    pub focal_length_mm: f64,
    /// Pixel pitch, µm (Table 4: 37).
    pub pixel_pitch_um: f64,
    /// Columns, 1..=1024 (Table 4: 328; up to the core's largest capacity, 1024×768,
    /// at the same pixel pitch and IFOV: a larger array sees a wider field).
    pub width: usize,
    /// Rows, 1..=768 (Table 4: 248).
    pub height: usize,
    /// Bits per DN, 1..=16 (default 14).
    pub bits: u8,
    /// Noise-equivalent temperature difference the noise is scaled to, K (0.4, the TIR's).
    pub netd_k: f64,
    /// Scene temperature at which the NETD holds, K (300).
    pub netd_reference_k: f64,
    /// Correlation length of the 1/f noise map, pixels (4).
    pub flicker_correlation_px: f32,
    /// Spectral response: "hayabusa2" (the measured curve, default), "tir" (the
    /// analytic bell) or "flat".
    pub response: ResponseName,
    /// The camera's own signature added to every frame (`"none"`, the default, or
    /// `"hayabusa2-dark"`: shading, column/row pattern, hot and dead pixels and gain
    /// residual fitted on a real TIR deep-space frame, a new realisation per image).
    #[serde(skip_serializing_if = "SignatureKind::is_none")]
    pub signature: SignatureKind,
    /// Blur the signal with the optics' PSF (Airy at F/1.4 over the pixel footprint)
    /// before the DN map (default false).
    #[serde(skip_serializing_if = "is_false")]
    pub optics_psf: bool,
    /// Radiometry-mode DN map: `"auto"` (the default, the paper's Eq. 17 per frame) or
    /// `"fixed-gain"` (the real camera's gain and a pedestal, DN = a·F + b).
    #[serde(skip_serializing_if = "RadiometryReadout::is_auto")]
    pub readout: RadiometryReadout,
}

/// Which sensor signature a camera adds (`[camera] signature`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SignatureKind {
    /// No signature: today's frames.
    #[default]
    None,
    /// The Hayabusa2 TIR's, fitted on `dark_20180629_083003.fit`.
    Hayabusa2Dark,
}

impl SignatureKind {
    fn is_none(&self) -> bool {
        *self == SignatureKind::None
    }
}

/// The radiometry-mode DN map (`[camera] readout`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RadiometryReadout {
    /// Auto-ranged per frame over the scene (Eq. 17).
    #[default]
    Auto,
    /// A fixed gain (the real camera's, at 14 bits) and a pedestal.
    FixedGain,
}

impl RadiometryReadout {
    fn is_auto(&self) -> bool {
        *self == RadiometryReadout::Auto
    }
}

/// Serde's skip test of a flag that is off by default (shared by the scene sections).
pub(super) fn is_false(b: &bool) -> bool {
    !*b
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            focal_length_mm: 42.2,
            pixel_pitch_um: 37.0,
            width: FRAME_WIDTH,
            height: FRAME_HEIGHT,
            bits: 14,
            netd_k: TIR_NETD_K,
            netd_reference_k: 300.0,
            flicker_correlation_px: DEFAULT_FLICKER_CORRELATION_PX,
            response: ResponseName::Hayabusa2,
            signature: SignatureKind::None,
            optics_psf: false,
            readout: RadiometryReadout::Auto,
        }
    }
}

impl Camera {
    /// Focal length in pixels (42.2 mm / 37 µm = 1 140.5 px).
    pub fn focal_px(&self) -> f64 {
        self.focal_length_mm * 1e3 / self.pixel_pitch_um
    }

    /// Full field of view (horizontal, vertical), degrees (16.4 × 12.4 for Table 4, which
    /// rounds them to 16 × 12).
    pub fn fov_deg(&self) -> (f64, f64) {
        let f = self.focal_px();
        let full = |n: usize| 2.0 * (n as f64 / 2.0 / f).atan().to_degrees();
        (full(self.width), full(self.height))
    }

    /// Instantaneous field of view of one pixel, rad (0.877 mrad).
    pub fn ifov_rad(&self) -> f64 {
        1.0 / self.focal_px()
    }

    pub(super) fn validate(&self) -> Result<(), String> {
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!("camera.{name} = {v}: expected a finite number > 0"))
            }
        };
        positive("focal_length_mm", self.focal_length_mm)?;
        positive("pixel_pitch_um", self.pixel_pitch_um)?;
        positive("netd_reference_k", self.netd_reference_k)?;
        if !(self.netd_k.is_finite() && self.netd_k >= 0.0) {
            return Err(format!(
                "camera.netd_k = {}: expected a number >= 0",
                self.netd_k
            ));
        }
        if !(self.flicker_correlation_px.is_finite() && self.flicker_correlation_px >= 0.0) {
            return Err(format!(
                "camera.flicker_correlation_px = {}: expected a number >= 0",
                self.flicker_correlation_px
            ));
        }
        let (max_w, max_h) = (Cap1024x768::WIDTH, Cap1024x768::HEIGHT);
        if !(1..=max_w).contains(&self.width) || !(1..=max_h).contains(&self.height) {
            return Err(format!(
                "camera.width × height = {} × {}: expected at most {max_w} × {max_h} (the core's largest capacity)",
                self.width, self.height
            ));
        }
        if !(1..=16).contains(&self.bits) {
            return Err(format!("camera.bits = {}: expected 1..=16", self.bits));
        }
        Ok(())
    }
}
