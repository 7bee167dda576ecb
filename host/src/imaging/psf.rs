//! The optics' point-spread function: diffraction at the aperture (an Airy pattern,
//! band-averaged over the camera's response) integrated over the square pixel
//! footprint, as a small normalised kernel applied to the signal frame before the DN
//! map.
//!
//! **f-number.** The TIR's f-number is not published in any source reachable here
//! (Okada et al. 2017, Space Sci. Rev. 208:255, give the 8–12 µm band, the 0.05°/px
//! IFOV and the NETD but, in the parts we could read, no aperture).
//! [`TIR_F_NUMBER`] = 1.4 is an assumption: the slower end of the F/1–F/1.4 bracket
//! `shared/reference/REFERENCE.md` §4 uses for the same camera, and the usual speed of
//! uncooled-microbolometer optics (their NETD needs a fast lens). The slower lens gives
//! the wider (more conservative) blur; the aperture is then 42.2 mm / 1.4 = 30.1 mm.
//!
//! **Kernel.** A point source on the centre of pixel (0, 0) puts the fraction
//! K[m, n] = ∫∫ over pixel (m, n) of I(r) dA into pixel (m, n), with
//! I(r) = Σ_λ w_λ · π/(4(λN)²) · [2 J₁(v)/v]², v = πr/(λN), the Airy irradiance of unit
//! energy, and w_λ ∝ R(λ)·B(λ, 300 K) the band weights (the core's TIR response). The
//! 5 × 5 kernel holds [`OpticsPsf::captured_energy`] of the energy (97 % at F/1.4); the
//! wings beyond it are returned to the kernel by normalising it to sum 1 (energy
//! conserving: a uniform scene stays uniform).

use tirroi_core::sensor::CameraResponse;
use tirroi_core::sensor::planck::spectral_radiance_w_m2_sr_um;

/// The assumed f-number of the Hayabusa2 TIR (see the module docs for its source).
pub const TIR_F_NUMBER: f64 = 1.4;

/// Kernel half-width, px: a 5 × 5 kernel.
pub const PSF_RADIUS_PX: usize = 2;

/// Kernel side, px.
pub const PSF_SIDE_PX: usize = 2 * PSF_RADIUS_PX + 1;

/// Temperature whose Planck spectrum weights the band average, K (the scenes' 300 K).
pub const BAND_WEIGHT_TEMPERATURE_K: f64 = 300.0;

/// Band of the average, µm: where the TIR's response is above 0.1 % of its peak.
const BAND_UM: (f64, f64) = (7.5, 13.0);

/// Wavelength step of the band average, µm.
const BAND_STEP_UM: f64 = 0.05;

/// Sub-samples per pixel side of the footprint integral (midpoint rule).
const FOOTPRINT_SAMPLES: usize = 64;

/// Radial step of the band-averaged profile table, µm.
const PROFILE_STEP_UM: f64 = 0.02;

/// The optics PSF as a normalised kernel.
#[derive(Debug, Clone, PartialEq)]
pub struct OpticsPsf {
    /// K[dy + R][dx + R], sums to 1.
    pub kernel: [[f32; PSF_SIDE_PX]; PSF_SIDE_PX],
    /// f-number N.
    pub f_number: f64,
    /// Pixel pitch, µm.
    pub pixel_pitch_um: f64,
    /// Fraction of the PSF's energy inside the kernel before normalising.
    pub captured_energy: f64,
}

/// Band weights (λ in µm, weight), summing to 1: R(λ)·B(λ, T) of the TIR model.
pub fn band_weights() -> Vec<(f64, f64)> {
    let r = CameraResponse::default();
    let n = ((BAND_UM.1 - BAND_UM.0) / BAND_STEP_UM).round() as usize;
    let mut w: Vec<(f64, f64)> = (0..=n)
        .map(|k| {
            let l = BAND_UM.0 + k as f64 * BAND_STEP_UM;
            (
                l,
                r.at(l) * spectral_radiance_w_m2_sr_um(l, BAND_WEIGHT_TEMPERATURE_K),
            )
        })
        .collect();
    let s: f64 = w.iter().map(|x| x.1).sum();
    w.iter_mut().for_each(|x| x.1 /= s);
    w
}

/// Airy irradiance of unit total energy at radius `r_um` for wavelength `lambda_um` and
/// f-number `n`, µm⁻².
pub fn airy_irradiance_per_um2(r_um: f64, lambda_um: f64, n: f64) -> f64 {
    let ln = lambda_um * n;
    let v = std::f64::consts::PI * r_um / ln;
    let a = if v < 1e-8 { 1.0 } else { 2.0 * libm::j1(v) / v };
    std::f64::consts::PI / (4.0 * ln * ln) * a * a
}

/// Closed-form encircled energy of the Airy pattern within radius `r_um` (Rayleigh):
/// 1 − J₀²(v) − J₁²(v), v = πr/(λN).
pub fn airy_encircled_energy(r_um: f64, lambda_um: f64, n: f64) -> f64 {
    let v = std::f64::consts::PI * r_um / (lambda_um * n);
    1.0 - libm::j0(v).powi(2) - libm::j1(v).powi(2)
}

impl OpticsPsf {
    /// The kernel for f-number `f_number` and pixel pitch `pixel_pitch_um`.
    ///
    /// # Errors
    /// A message unless both are finite and > 0.
    pub fn new(f_number: f64, pixel_pitch_um: f64) -> Result<Self, String> {
        if !(f_number.is_finite()
            && f_number > 0.0
            && pixel_pitch_um.is_finite()
            && pixel_pitch_um > 0.0)
        {
            return Err(format!(
                "optics PSF: f-number {f_number}, pitch {pixel_pitch_um} µm: expected finite numbers > 0"
            ));
        }
        let weights = band_weights();
        // The band-averaged profile on a radial table up to the kernel's corner.
        let r_max = (PSF_RADIUS_PX as f64 + 0.5) * pixel_pitch_um * std::f64::consts::SQRT_2 + 1.0;
        let steps = (r_max / PROFILE_STEP_UM).ceil() as usize + 1;
        let profile: Vec<f64> = (0..=steps)
            .map(|k| {
                let r = k as f64 * PROFILE_STEP_UM;
                weights
                    .iter()
                    .map(|&(l, w)| w * airy_irradiance_per_um2(r, l, f_number))
                    .sum()
            })
            .collect();
        let at = |r: f64| {
            let t = r / PROFILE_STEP_UM;
            let i = (t as usize).min(steps - 1);
            let f = t - i as f64;
            profile[i] * (1.0 - f) + profile[i + 1] * f
        };
        let sub = pixel_pitch_um / FOOTPRINT_SAMPLES as f64;
        let mut k = [[0.0f64; PSF_SIDE_PX]; PSF_SIDE_PX];
        for (my, row) in k.iter_mut().enumerate() {
            for (mx, cell) in row.iter_mut().enumerate() {
                let cx = (mx as f64 - PSF_RADIUS_PX as f64 - 0.5) * pixel_pitch_um;
                let cy = (my as f64 - PSF_RADIUS_PX as f64 - 0.5) * pixel_pitch_um;
                let mut s = 0.0;
                for j in 0..FOOTPRINT_SAMPLES {
                    let y = cy + (j as f64 + 0.5) * sub;
                    for i in 0..FOOTPRINT_SAMPLES {
                        let x = cx + (i as f64 + 0.5) * sub;
                        s += at(x.hypot(y));
                    }
                }
                *cell = s * sub * sub;
            }
        }
        let captured: f64 = k.iter().flatten().sum();
        let mut kernel = [[0.0f32; PSF_SIDE_PX]; PSF_SIDE_PX];
        for (ko, ki) in kernel.iter_mut().zip(&k) {
            for (o, i) in ko.iter_mut().zip(ki) {
                *o = (i / captured) as f32;
            }
        }
        Ok(OpticsPsf {
            kernel,
            f_number,
            pixel_pitch_um,
            captured_energy: captured,
        })
    }

    /// The TIR's kernel: [`TIR_F_NUMBER`] at the camera's pixel pitch.
    ///
    /// # Errors
    /// As [`OpticsPsf::new`].
    pub fn hayabusa2_tir(pixel_pitch_um: f64) -> Result<Self, String> {
        Self::new(TIR_F_NUMBER, pixel_pitch_um)
    }

    /// Convolves a row-major `width`-column signal frame with the kernel into `out`
    /// (same size), replicating the edge pixels beyond the frame.
    ///
    /// # Errors
    /// A message when the sizes do not match or `width` is 0.
    pub fn apply(&self, signal: &[f32], width: usize, out: &mut [f32]) -> Result<(), String> {
        if width == 0 || signal.len() % width != 0 || out.len() != signal.len() {
            return Err(format!(
                "optics PSF: {} values of width {width} into {}: expected whole rows of the same size",
                signal.len(),
                out.len()
            ));
        }
        let h = signal.len() / width;
        let r = PSF_RADIUS_PX as isize;
        // Padded copy (edge replicated) so the inner loop has no bounds logic.
        let pw = width + 2 * PSF_RADIUS_PX;
        let ph = h + 2 * PSF_RADIUS_PX;
        let mut pad = vec![0.0f32; pw * ph];
        for py in 0..ph {
            let sy = (py as isize - r).clamp(0, h as isize - 1) as usize;
            let src = &signal[sy * width..(sy + 1) * width];
            let dst = &mut pad[py * pw..(py + 1) * pw];
            dst[PSF_RADIUS_PX..PSF_RADIUS_PX + width].copy_from_slice(src);
            let (first, last) = (src[0], src[width - 1]);
            dst[..PSF_RADIUS_PX].fill(first);
            dst[PSF_RADIUS_PX + width..].fill(last);
        }
        for (y, orow) in out.chunks_exact_mut(width).enumerate() {
            orow.fill(0.0);
            for (ky, krow) in self.kernel.iter().enumerate() {
                let prow = &pad[(y + ky) * pw..(y + ky) * pw + pw];
                for (kx, &k) in krow.iter().enumerate() {
                    let src = &prow[kx..kx + width];
                    for (o, &s) in orow.iter_mut().zip(src) {
                        *o += k * s;
                    }
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `auto-v2` cuts saturated blobs back by the optics' reach, a core constant (the
    /// core cannot read the host's): both must name the same kernel.
    #[test]
    fn the_detectors_psf_reach_is_this_kernels() {
        use tirroi_core::roi::auto::learned::saturated;
        assert_eq!(usize::from(saturated::PSF_RADIUS_PX), PSF_RADIUS_PX);
    }

    #[test]
    fn profile_integrates_to_the_closed_form_encircled_energy() {
        // Brute-force radial integral of the irradiance against 1 − J0² − J1².
        for &(l, n) in &[(10.0, 1.4), (8.5, 1.0), (12.0, 2.0)] {
            for &r_max in &[5.0, 14.0, 40.0, 90.0] {
                let steps = 20_000;
                let dr = r_max / steps as f64;
                let e: f64 = (0..steps)
                    .map(|k| {
                        let r = (k as f64 + 0.5) * dr;
                        airy_irradiance_per_um2(r, l, n) * 2.0 * std::f64::consts::PI * r * dr
                    })
                    .sum();
                let want = airy_encircled_energy(r_max, l, n);
                assert!(
                    (e - want).abs() < 1e-5,
                    "λ {l} N {n} r {r_max}: {e} vs {want}"
                );
            }
        }
        // First dark ring at 1.22 λN holds 83.8 % (Born & Wolf 8.5).
        assert!((airy_encircled_energy(1.2197 * 14.0, 10.0, 1.4) - 0.8378).abs() < 1e-3);
    }

    #[test]
    fn kernel_sums_to_one_is_symmetric_and_captures_the_encircled_energy() {
        let psf = OpticsPsf::hayabusa2_tir(37.0).unwrap();
        eprintln!(
            "F/{} kernel (captured {:.4}): {:?}",
            psf.f_number, psf.captured_energy, psf.kernel
        );
        let s: f64 = psf.kernel.iter().flatten().map(|&k| f64::from(k)).sum();
        assert!((s - 1.0).abs() < 1e-6, "{s}");
        let k = &psf.kernel;
        for (i, j) in (0..PSF_SIDE_PX).flat_map(|i| (0..PSF_SIDE_PX).map(move |j| (i, j))) {
            assert!((k[i][j] - k[j][i]).abs() < 1e-6);
            assert!((k[i][j] - k[PSF_SIDE_PX - 1 - i][j]).abs() < 1e-6);
        }
        // The 5 × 5 square (half side 92.5 µm) lies between the inscribed and the
        // circumscribed discs: its energy between their band-averaged encircled energies.
        let half = 2.5 * 37.0;
        let ee = |r: f64| -> f64 {
            band_weights()
                .iter()
                .map(|&(l, w)| w * airy_encircled_energy(r, l, TIR_F_NUMBER))
                .sum()
        };
        let (lo, hi) = (ee(half), ee(half * std::f64::consts::SQRT_2));
        assert!(
            psf.captured_energy > lo && psf.captured_energy < hi,
            "{lo} < {} < {hi}",
            psf.captured_energy
        );
        // The central pixel alone (half side 18.5 µm) lies between discs of 18.5 and 26.2 µm.
        let c = f64::from(k[2][2]) * psf.captured_energy;
        assert!(
            c > ee(18.5) && c < ee(18.5 * std::f64::consts::SQRT_2),
            "{c}"
        );
    }

    #[test]
    fn convolution_conserves_energy_and_keeps_a_uniform_frame() {
        let psf = OpticsPsf::hayabusa2_tir(37.0).unwrap();
        let (w, h) = (20, 15);
        let mut s = vec![0.0f32; w * h];
        s[7 * w + 9] = 1000.0;
        let mut o = vec![0.0f32; w * h];
        psf.apply(&s, w, &mut o).unwrap();
        let total: f32 = o.iter().sum();
        assert!((total - 1000.0).abs() < 1e-2, "{total}");
        assert!((o[7 * w + 9] - 1000.0 * psf.kernel[2][2]).abs() < 1e-3);
        assert!((o[6 * w + 11] - 1000.0 * psf.kernel[1][4]).abs() < 1e-3);
        let u = vec![3.5f32; w * h];
        psf.apply(&u, w, &mut o).unwrap();
        assert!(o.iter().all(|&v| (v - 3.5).abs() < 1e-5));
        assert!(psf.apply(&u, 7, &mut o).is_err());
    }
}
