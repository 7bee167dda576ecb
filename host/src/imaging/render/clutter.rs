//! Signal-to-clutter ratio of a rendered frame: how far the target stands out of the
//! background it sits on, before noise.
//!
//! - **Background twin**: the frame rendered without the target, noise-free, over the
//!   truth box and its ring only (the Earth pass on a window of the camera; deep space
//!   is 0 signal). Outside the target's coverage it equals the frame's own noise-free
//!   signal; under the target it is the Earth (or space) the target hides.
//! - **Target contrast**, DN: |mean over the target mask (coverage ≥ [`MASK_COVERAGE`])
//!   of (frame DN − twin DN *as the camera sees it*)|, both noise-free and unquantised
//!   but **clipped to the camera's range** 0..=2ⁿ − 1 (session 35: a target below
//!   DN 0 over deep space at DN 0, or saturated over a saturated Earth, is in no pixel
//!   of the frame, and the unclipped difference had given such frames SCR up to 10¹⁰
//!   and a visible share of 1). The frame's signal went through the optics PSF and the
//!   sensor signature, so the twin does too ([`super::through_the_optics`]): their
//!   difference is the target's own signal, blurred, with the signature's offsets
//!   (shading, hot pixels) cancelled. (Before session 26 the raw twin was subtracted,
//!   which left those offsets in the contrast: on `realistic` seed 9001, 77 of 540
//!   frames were in another SCR bin; without optics and signature, e.g. the `paper`
//!   world, nothing changes.)
//! - **Clutter σ**, DN: the standard deviation of the twin over the ring: the pixels
//!   within [`ring_width_px`] of the truth box (Chebyshev distance, outside the box,
//!   cut to the frame), in DN clipped to the range likewise (a saturated deck shows no
//!   clutter).
//! - **SCR** = contrast / max(clutter σ, noise σ, [`QUANTISATION_SIGMA_DN`]). The floor:
//!   a background flatter than the camera's own noise (deep space, a uniform cloud
//!   deck) is not what hides the target, and the floor keeps deep space finite; the
//!   quantisation σ is the floor of a noise-free render.
//! - **Visible box**: the tight box of the target's pixels (coverage ≥
//!   [`MASK_COVERAGE`]) whose noise-free, clipped DN differs from the background twin's
//!   *as the camera sees it* (twin through the optics PSF and the signature,
//!   [`super::through_the_optics`]) by at least [`VISIBLE_K_SIGMA`] × max(noise σ,
//!   [`QUANTISATION_SIGMA_DN`]). A part of the target at its background's level (a cold
//!   face over deep space, a face at the clouds' temperature) is in the truth box but
//!   in no pixel of the frame, so `visible_share` = visible box area / truth box area
//!   (the visible box lies inside the truth box) is the IoU a detector gets that boxes
//!   every pixel the target changes beyond the noise and nothing else: an optimistic
//!   ceiling (the clutter, which the detector must also tell apart, is not counted).
//!
//! The window's Earth pass supersamples the limb where neighbours *inside the window*
//! differ, so a limb pixel on the window's edge may get its centre ray only (a small
//! difference in a statistic over hundreds of pixels). Cost: one Earth ray per pixel
//! of the window (plus its limb), measured in `docs/scenes.md`.

use tirroi_core::Roi;
use tirroi_core::sensor::DnMapping;

use super::earth::render_earth;
use super::pure::PurePixels;
use super::{MASK_COVERAGE, Pinhole, RenderError, RenderInput, RenderStats, Rendered};

/// Narrowest ring around the truth box, px: enough pixels for a standard deviation of
/// a small target's surroundings.
pub const RING_MIN_WIDTH_PX: usize = 4;

/// The σ of uniform quantisation to whole DN, 1/√12 DN: the clutter floor of a
/// noise-free frame.
pub const QUANTISATION_SIGMA_DN: f64 = 0.288_675_134_594_812_9;

/// Noise σ from which a target pixel's noise-free contrast against its background counts
/// as visible (the visible box, [module docs](self)): the usual single-pixel detection
/// threshold, at which Gaussian noise alone crosses it on 0.13 % of pixels per sign.
pub const VISIBLE_K_SIGMA: f64 = 3.0;

/// The target's standing against its background ([module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clutter {
    /// |Mean target − background| over the mask, DN (noise-free).
    pub target_contrast_dn: f64,
    /// Standard deviation of the background twin over the ring, DN (noise-free).
    pub clutter_sigma_dn: f64,
    /// Contrast over max(clutter σ, noise σ, [`QUANTISATION_SIGMA_DN`]).
    pub signal_to_clutter: f64,
    /// Tight box of the target pixels visible beyond the noise ([module docs](self);
    /// inside the truth box, empty when none is).
    pub visible: Roi,
}

impl Clutter {
    /// Visible box area / truth box area, 0..=1 (0 for an empty truth box): the IoU of
    /// the visible box with the truth box, the ceiling of a detector that sees only the
    /// pixels the target changes ([module docs](self)).
    pub fn visible_share(&self, truth: Roi) -> f64 {
        let area = |r: Roi| usize::from(r.width()) * usize::from(r.height());
        if truth.is_empty() {
            return 0.0;
        }
        area(self.visible) as f64 / area(truth) as f64
    }
}

/// Width of the ring around a truth box, px: max([`RING_MIN_WIDTH_PX`], half the box's
/// longer side, rounded up).
pub fn ring_width_px(truth: Roi) -> usize {
    let side = usize::from(truth.width().max(truth.height()));
    RING_MIN_WIDTH_PX.max(side.div_ceil(2))
}

/// The truth box grown by the ring width on every side, cut to the frame.
pub fn ring_window(truth: Roi, width: usize, height: usize) -> Roi {
    let b = ring_width_px(truth);
    let grow = |v: u16, d: usize| usize::from(v).saturating_sub(d);
    let x0 = grow(truth.x0, b);
    let y0 = grow(truth.y0, b);
    let x1 = (usize::from(truth.x1) + b).min(width);
    let y1 = (usize::from(truth.y1) + b).min(height);
    Roi::new(x0 as u16, y0 as u16, x1 as u16, y1 as u16)
}

/// The statistics of [`Clutter`] from full-frame arrays: `signal` (with the target,
/// noise-free, as the camera sees it), `background` (the twin: its ring gives the
/// clutter σ, the scene's own variation), `seen_background` (the twin as the camera
/// sees it, through the optics and signature like `signal`: the contrast and the
/// visible box are against it),
/// `coverage`, all `width` wide; `truth` the ½ box; `mapping` the frame's signal-to-DN
/// map (every signal is compared as the DN it maps to, clipped to 0..=2ⁿ − 1, not
/// rounded); `noise_sigma_dn` the frame's noise σ. `None` when the truth box is empty.
#[allow(clippy::too_many_arguments)]
pub fn clutter_statistics(
    signal: &[f32],
    background: &[f32],
    seen_background: &[f32],
    coverage: &[f32],
    width: usize,
    truth: Roi,
    mapping: &DnMapping,
    noise_sigma_dn: f64,
) -> Option<Clutter> {
    if truth.is_empty() || width == 0 {
        return None;
    }
    let height = signal.len() / width;
    let window = ring_window(truth, width, height);
    // The DN the camera can show: noise-free, unquantised, within its range.
    let max_dn = f64::from(mapping.max_dn());
    let dn = |v: f32| mapping.dn(f64::from(v)).clamp(0.0, max_dn);
    let (mut diff, mut n_mask) = (0f64, 0usize);
    let (mut sum, mut sum2, mut n_ring) = (0f64, 0f64, 0usize);
    let visible_dn = VISIBLE_K_SIGMA * noise_sigma_dn.max(QUANTISATION_SIGMA_DN);
    let (mut vx0, mut vy0, mut vx1, mut vy1) = (usize::MAX, usize::MAX, 0usize, 0usize);
    for y in usize::from(window.y0)..usize::from(window.y1) {
        for x in usize::from(window.x0)..usize::from(window.x1) {
            let i = y * width + x;
            let b = dn(background[i]);
            if coverage[i] >= MASK_COVERAGE {
                let d = dn(signal[i]) - dn(seen_background[i]);
                diff += d;
                n_mask += 1;
                if d.abs() >= visible_dn {
                    (vx0, vy0) = (vx0.min(x), vy0.min(y));
                    (vx1, vy1) = (vx1.max(x + 1), vy1.max(y + 1));
                }
            }
            let inside = x >= usize::from(truth.x0)
                && x < usize::from(truth.x1)
                && y >= usize::from(truth.y0)
                && y < usize::from(truth.y1);
            if !inside {
                sum += b;
                sum2 += b * b;
                n_ring += 1;
            }
        }
    }
    if n_mask == 0 {
        return None;
    }
    let contrast = (diff / n_mask as f64).abs();
    let sigma = if n_ring == 0 {
        0.0
    } else {
        let m = sum / n_ring as f64;
        (sum2 / n_ring as f64 - m * m).max(0.0).sqrt()
    };
    let floor = sigma.max(noise_sigma_dn).max(QUANTISATION_SIGMA_DN);
    // Inside the window, which is at most 1024 px wide (`u16` boxes).
    let visible = if vx1 == 0 {
        Roi::EMPTY
    } else {
        Roi::new(vx0 as u16, vy0 as u16, vx1 as u16, vy1 as u16)
    };
    Some(Clutter {
        target_contrast_dn: contrast,
        clutter_sigma_dn: sigma,
        signal_to_clutter: contrast / floor,
        visible,
    })
}

/// The [`Clutter`] of `frame`, rendered from `input` (the same input, target included);
/// `None` when the frame has no target pixel at coverage ≥ ½.
///
/// # Errors
/// [`RenderError`] as the Earth pass of [`super::render`].
pub fn signal_to_clutter(
    input: &RenderInput<'_>,
    frame: &Rendered,
) -> Result<Option<Clutter>, RenderError> {
    if input.target.is_none() || frame.truth.is_empty() {
        return Ok(None);
    }
    let (w, h) = (frame.width, frame.height);
    let window = ring_window(frame.truth, w, h);
    let mut background = vec![0f32; w * h];
    if let Some(earth) = &input.earth {
        let full = Pinhole::new(input.camera);
        let (wx, wy) = (usize::from(window.x0), usize::from(window.y0));
        let (ww, wh) = (usize::from(window.width()), usize::from(window.height()));
        let crop = Pinhole {
            f: full.f,
            cx: full.cx - wx as f64,
            cy: full.cy - wy as f64,
            w: ww,
            h: wh,
        };
        let none = vec![0f32; ww * wh];
        let mut twin = vec![0f32; ww * wh];
        render_earth(
            &crop,
            earth,
            input.lut,
            input.readout,
            &none,
            &mut twin,
            &mut PurePixels::default(),
            &mut RenderStats::default(),
        )?;
        for (row, line) in twin.chunks_exact(ww).enumerate() {
            let at = (wy + row) * w + wx;
            background[at..at + ww].copy_from_slice(line);
        }
    }
    // The twin as the camera sees it, for the visible box: the frame's signal went
    // through the optics and signature; outside the window the twin is 0, which the
    // PSF's 2-px reach carries no farther than the ring (≥ 4 px) into the window.
    let seen = super::through_the_optics(input, background.clone())?;
    Ok(clutter_statistics(
        &frame.signal,
        &background,
        &seen,
        &frame.coverage,
        w,
        frame.truth,
        &frame.mapping,
        f64::from(frame.noise_sigma_dn),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 16-bit map of gain `g` DN per unit and no offset: far from the range's ends
    /// for the backgrounds below.
    fn gain(g: f64) -> DnMapping {
        DnMapping::new(g, 0.0, 16).unwrap()
    }

    /// A uniform disc of contrast `c` (coverage 1 inside radius `r`, 0 outside) over a
    /// checkerboard background `b0 ± a`.
    fn disc_on_checkerboard(
        w: usize,
        h: usize,
        centre: (f64, f64),
        r: f64,
        c: f32,
        b0: f32,
        a: f32,
    ) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
        let (mut sig, mut bg, mut cov) = (vec![0f32; w * h], vec![0f32; w * h], vec![0f32; w * h]);
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                bg[i] = if (x + y) % 2 == 0 { b0 + a } else { b0 - a };
                let inside = (x as f64 + 0.5 - centre.0).hypot(y as f64 + 0.5 - centre.1) < r;
                cov[i] = if inside { 1.0 } else { 0.0 };
                sig[i] = if inside { bg[i] + c } else { bg[i] };
            }
        }
        (sig, bg, cov)
    }

    #[test]
    fn uniform_disc_on_a_checkerboard_by_hand() {
        // Disc of radius 5 px at (20, 20) in a 40 × 40 frame: its ≥ ½ box is the 10 × 10
        // square [15, 25)², the ring 5 px wide (half the side): the 20 × 20 square
        // [10, 30)² less the box, 300 pixels, 150 of each checkerboard colour, so the
        // ring's σ is exactly a. Contrast c; gain g scales both.
        let (w, h) = (40, 40);
        let (c, b0, a, g) = (6.0f32, 100.0f32, 2.0f32, 3.0f64);
        let (sig, bg, cov) = disc_on_checkerboard(w, h, (20.0, 20.0), 5.0, c, b0, a);
        let truth = super::super::mask_box(&cov, w);
        assert_eq!(truth, Roi::new(15, 15, 25, 25));
        assert_eq!(ring_width_px(truth), 5);
        assert_eq!(ring_window(truth, w, h), Roi::new(10, 10, 30, 30));
        let got = clutter_statistics(&sig, &bg, &bg, &cov, w, truth, &gain(g), 0.5).unwrap();
        let close = |x: f64, y: f64| (x - y).abs() < 1e-9 * y.abs().max(1.0);
        assert!(close(got.target_contrast_dn, f64::from(c) * g), "{got:?}");
        assert!(close(got.clutter_sigma_dn, f64::from(a) * g), "{got:?}");
        assert!(close(got.signal_to_clutter, f64::from(c / a)), "{got:?}");
        // A noise σ above the clutter becomes the denominator.
        let noisy = clutter_statistics(&sig, &bg, &bg, &cov, w, truth, &gain(g), 60.0).unwrap();
        assert!(close(noisy.signal_to_clutter, f64::from(c) * g / 60.0));
        // A flat background, no noise: the quantisation floor 1/√12 DN.
        let (sig, bg, cov) = disc_on_checkerboard(w, h, (20.0, 20.0), 5.0, c, b0, 0.0);
        let flat = clutter_statistics(&sig, &bg, &bg, &cov, w, truth, &gain(g), 0.0).unwrap();
        assert_eq!(flat.clutter_sigma_dn, 0.0);
        assert!(close(
            flat.signal_to_clutter,
            f64::from(c) * g * 12f64.sqrt()
        ));
        // A darker target: the contrast's magnitude.
        let (sig, bg, cov) = disc_on_checkerboard(w, h, (20.0, 20.0), 5.0, -c, b0, a);
        let dark = clutter_statistics(&sig, &bg, &bg, &cov, w, truth, &gain(g), 0.5).unwrap();
        assert!(close(dark.target_contrast_dn, f64::from(c) * g));
    }

    #[test]
    fn visible_box_holds_the_pixels_beyond_the_noise_only() {
        // A 10 × 6 target at [10, 20) × [12, 18) in a 40 × 30 frame over a flat
        // background: its left 4 columns at contrast 10, the other 6 at 2.9 (below
        // 3 σ of σ = 1 DN at unit gain), so the visible box is [10, 14) × [12, 18),
        // share 24 / 60. Every target pixel at contrast 3.0 (≥ 3σ): the whole truth box.
        let (w, h) = (40, 30);
        let bg = vec![50f32; w * h];
        let mut cov = vec![0f32; w * h];
        let mut sig = bg.clone();
        for y in 12..18 {
            for x in 10..20 {
                cov[y * w + x] = 1.0;
                sig[y * w + x] += if x < 14 { 10.0 } else { 2.9 };
            }
        }
        let truth = super::super::mask_box(&cov, w);
        assert_eq!(truth, Roi::new(10, 12, 20, 18));
        let got = clutter_statistics(&sig, &bg, &bg, &cov, w, truth, &gain(1.0), 1.0).unwrap();
        assert_eq!(got.visible, Roi::new(10, 12, 14, 18));
        assert!((got.visible_share(truth) - 0.4).abs() < 1e-12);
        // Darker pixels count by their magnitude; a gain of 2 DN per unit doubles the
        // contrast in DN: 2.9 → 5.8 DN ≥ 3 DN, so everything is visible.
        let dark: Vec<f32> = sig.iter().zip(&bg).map(|(s, b)| 2.0 * b - s).collect();
        let got = clutter_statistics(&dark, &bg, &bg, &cov, w, truth, &gain(2.0), 1.0).unwrap();
        assert_eq!(got.visible, truth);
        assert_eq!(got.visible_share(truth), 1.0);
        // The camera's offsets: a seen background 10 units above the twin (a
        // signature offset the frame's signal carries too) is what the target is
        // compared with, so a target at exactly that offset is invisible.
        let seen: Vec<f32> = bg.iter().map(|b| b + 10.0).collect();
        let got = clutter_statistics(&sig, &bg, &seen, &cov, w, truth, &gain(1.0), 1.0).unwrap();
        assert_eq!(
            got.visible,
            Roi::new(14, 12, 20, 18),
            "7.1 below the offset only"
        );
        // The contrast is against the seen twin too: (24 × 0 + 36 × (2.9 − 10)) / 60.
        assert!(
            (got.target_contrast_dn - 36.0 * 7.1 / 60.0).abs() < 1e-5,
            "{got:?}"
        );
        let flat: Vec<f32> = bg.iter().map(|b| b + 10.0).collect();
        let got = clutter_statistics(&flat, &bg, &seen, &cov, w, truth, &gain(1.0), 1.0).unwrap();
        assert!(got.visible.is_empty());
        assert_eq!(got.visible_share(truth), 0.0);
    }

    #[test]
    fn pixels_clipped_to_the_background_level_are_not_seen() {
        // A 12-bit map DN = 10·s − 500 (s = 50 ↦ DN 0, s = 459.5 ↦ 4095). Over a
        // background at s = 40 (DN −100, shown as 0) a target at s = 45 (DN −50, also
        // 0) is in no pixel: contrast 0, nothing visible, SCR 0. At s = 60 (DN 100)
        // it stands 100 DN above the shown 0, not the unclipped 200.
        let map = DnMapping::new(10.0, -500.0, 12).unwrap();
        let (w, h) = (40, 40);
        let disc = |t: f32, b: f32| disc_on_checkerboard(w, h, (20.0, 20.0), 5.0, t - b, b, 0.0);
        let (sig, bg, cov) = disc(45.0, 40.0);
        let truth = super::super::mask_box(&cov, w);
        let got = clutter_statistics(&sig, &bg, &bg, &cov, w, truth, &map, 1.0).unwrap();
        assert_eq!(got.target_contrast_dn, 0.0, "{got:?}");
        assert_eq!(got.signal_to_clutter, 0.0);
        assert!(got.visible.is_empty());
        let (sig, bg, cov) = disc(60.0, 40.0);
        let got = clutter_statistics(&sig, &bg, &bg, &cov, w, truth, &map, 1.0).unwrap();
        assert!((got.target_contrast_dn - 100.0).abs() < 1e-9, "{got:?}");
        assert_eq!(got.visible, truth);
        // Saturation alike: a target at s = 600 over a background at s = 500 (DN 4500
        // and 4095 → both 4095) is invisible; over s = 450 (DN 4000) it stands 95 DN.
        let (sig, bg, cov) = disc(600.0, 500.0);
        let got = clutter_statistics(&sig, &bg, &bg, &cov, w, truth, &map, 1.0).unwrap();
        assert_eq!(got.target_contrast_dn, 0.0, "{got:?}");
        assert!(got.visible.is_empty());
        let (sig, bg, cov) = disc(600.0, 450.0);
        let got = clutter_statistics(&sig, &bg, &bg, &cov, w, truth, &map, 1.0).unwrap();
        assert!((got.target_contrast_dn - 95.0).abs() < 1e-9, "{got:?}");
        // The clutter is the shown background's: a checkerboard 440 ± 20 (DN 3900 ±
        // 200) is cut at 4095 on its bright squares, so its σ is (3700 … 4095)'s half
        // difference, 197.5 DN, not 200.
        let (sig, bg, cov) = disc_on_checkerboard(w, h, (20.0, 20.0), 5.0, 10.0, 440.0, 20.0);
        let got = clutter_statistics(&sig, &bg, &bg, &cov, w, truth, &map, 1.0).unwrap();
        assert!((got.clutter_sigma_dn - 197.5).abs() < 1e-9, "{got:?}");
    }

    #[test]
    fn ring_is_cut_to_the_frame_and_empty_truth_gives_none() {
        let truth = Roi::new(0, 0, 3, 2);
        assert_eq!(ring_width_px(truth), RING_MIN_WIDTH_PX);
        assert_eq!(ring_window(truth, 5, 50), Roi::new(0, 0, 5, 6));
        let z = vec![0f32; 16];
        assert_eq!(
            clutter_statistics(&z, &z, &z, &z, 4, Roi::EMPTY, &gain(1.0), 0.0),
            None
        );
        assert_eq!(QUANTISATION_SIGMA_DN, 1.0 / 12f64.sqrt());
        // The scene file's default truth box is the renderer's mask.
        assert_eq!(
            crate::world::scene::DEFAULT_TRUTH_COVERAGE,
            f64::from(MASK_COVERAGE)
        );
    }
}
