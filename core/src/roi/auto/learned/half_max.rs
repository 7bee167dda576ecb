//! The half-maximum box of a small target. A far target (3–12 px in the `realistic`
//! preset) is blurred by the optics over 2–3 px on each side, and `auto`'s boundary
//! rule (steps above `fine_sigma` σ) finds the outer end of that blur: boxes come out
//! 2–3 px too wide per side, which halves a 5-px target's IoU. The truth marks the
//! pixels at least half covered by the target; across a blurred edge of a uniform
//! face that is where the signal crosses half its height above the background. So a
//! small box is cut to the pixels whose departure from the local background reaches
//! half the peak departure (same sign as the peak).
//!
//! **Weaker faces** (session 35). A far target is often a hot face beside cooler
//! ones: half the *peak* cuts the cooler faces away (paper B's far radiometry: a
//! 6 × 5 target boxed 3 × 2 around its saturated face). A pixel is kept too when it
//! is a face of its own: it departs, either way, at least [`FACE_SHARE_DIV`]⁻¹ of the
//! peak's magnitude and [`FACE_MIN_SIGMA`] σ, and more than half the strongest
//! departure of its sign among its 8 neighbours (inside the box) — the half maximum
//! of its own face (a face colder than the background beside a hot one counts).
//! Across a blurred edge of the optics' 5×5 kernel the pixel just outside holds under
//! half of its inward neighbour, so the faces' outline is cut where a uniform face's
//! half height is, as before.
//!
//! **Over deep space** (session 57, [`Background::DeepSpace`]): stage 2c's boxes lie on
//! a fitted smooth sky with no clutter to keep out, so a face counts from
//! [`DEEP_SPACE_FACE_MIN_SIGMA`] σ whatever the peak, when one of its neighbours
//! departs as far (no lone hot pixel): a close target's faces in shadow (under ⅓ of
//! its sunlit face) are no longer cut away. So too for any other stage's box whose ring
//! is a sky clipped at DN 0 (its median 0 DN: nothing around the box but clipped noise)
//! and that holds no saturated pixel (whose optics' halo and a limb beside it would
//! pass for faces) — or holds some, through optics that do not blur
//! ([`Background::ClutteredSharp`], session 59: the `paper` world, whose Tango's sunlit
//! face saturates beside faces in shadow, `paperAT/000282`).

use super::order::select_binned;
use crate::frame::Frame;
use crate::roi::Roi;

/// Boxes with both sides at most this many pixels are cut to their half maximum. 24
/// until session 35 (the largest far target, 12 px, plus the blur on both sides and
/// margin); with the weaker faces kept, mid-range targets gain too. Chosen on family A
/// (summed gated mean IoU of famA4, paper A, fixtures A and famAF): 24 / 32 / 40 /
/// **48** / 56 / 64 / 96 px: 2.451 / 2.458 / 2.460 / **2.472** / 2.469 / 2.461 / 2.424
/// (the fixtures 0.857 → 0.879; radiometry close −0.007 on famA4 and −0.011 on paper
/// A: a close multi-face target's faces under ⅓ of its peak are cut; docs/detectors.md
/// § Session 35).
pub const MAX_SIDE_PX: u16 = 48;

/// The peak departure must reach this many noise σ, else the box is kept: below it
/// half the peak is within 4 σ of the background and noise would pick the pixels.
pub const MIN_PEAK_SIGMA: u32 = 8;

/// A weaker face counts from this share of the peak departure (1/3): clutter and the
/// blur's tail below it stay out. Chosen on family A (famA4, paper A, fixtures A,
/// famAF; summed gated mean IoU 2.430 without the faces): 1/2 2.436, **1/3 2.451**,
/// 1/4 2.449, 1/8 2.442 (docs/detectors.md § Session 35).
pub const FACE_SHARE_DIV: u32 = 3;

/// … and from this many noise σ (a face of a faint target must stand out of the
/// noise on its own): 3, 4 and 6 σ gave 2.449 alike at 1/4 on family A.
pub const FACE_MIN_SIGMA: u32 = 4;

/// What lies around the box, which decides from where a weaker face counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Background {
    /// The Earth, or not known: a face counts from [`FACE_SHARE_DIV`]⁻¹ of the peak and
    /// [`FACE_MIN_SIGMA`] σ (clutter and the blur's tail stay out). Unless the ring
    /// around the box is deep space clipped at DN 0 (its median is 0) and the box holds
    /// no saturated pixel: then as [`Background::DeepSpace`].
    Cluttered,
    /// As [`Background::Cluttered`], through optics without blur (no halo around a
    /// saturated pixel): a ring at DN 0 makes the box's background deep space even when
    /// it holds saturated pixels (`auto-v2` with `saturated_erode_px` 0). Family A
    /// (seeds 7001–7201, ½ convention): paperAT 0.7593 → 0.7813, paper A +0.0027, no
    /// set lower; held out paperBT +0.0121, paperB +0.0036.
    ClutteredSharp,
    /// Deep space, as stage 2c fitted it (a smooth surface under white noise): there is
    /// no clutter to keep out, so a face counts from [`DEEP_SPACE_FACE_MIN_SIGMA`] σ
    /// (with a neighbour as far: no lone hot pixel) whatever the peak (a close target's
    /// faces in shadow, under ⅓ of its sunlit face's departure).
    DeepSpace,
}

/// Over deep space ([`Background::DeepSpace`]) a face counts from this many noise σ
/// alone, when a neighbour departs as far (a face is more than one pixel: two hot
/// pixels are no target; session 57). Chosen on family A (seeds 7001–7201, ½
/// convention; change of the summed mean IoU of famA, paper A, fixtures A and famAF
/// against the ⅓-of-peak rule, without the neighbour): 3 σ +0.0121, **4 σ +0.0124**,
/// 6 σ +0.0091 (famAT: +0.0068 / **+0.0067** / +0.0042); with the neighbour +0.0122
/// (famAT +0.0067), and `famBSE/000420`'s two hot pixels no longer boxed. The same
/// 4 σ as [`FACE_MIN_SIGMA`]: a pixel of the sky departs that far by chance about 3
/// times in 10⁵.
pub const DEEP_SPACE_FACE_MIN_SIGMA: u32 = 4;

/// Background samples: the one-pixel ring around a box of up to [`MAX_SIDE_PX`] per
/// side, at most `4 · (48 + 1)` = 196 pixels (400 B of stack).
const RING_PX: usize = 4 * (MAX_SIDE_PX as usize + 2);

/// Median DN of the one-pixel ring around `roi` (cut to the frame), or `None` when the
/// ring is empty (a box covering the frame).
fn ring_median(frame: &Frame<'_>, roi: Roi) -> Option<u16> {
    let mut buf = [0u16; RING_PX];
    let mut n = 0usize;
    let (w, h) = (frame.width(), frame.height());
    let (x0, y0) = (usize::from(roi.x0), usize::from(roi.y0));
    let (x1, y1) = (usize::from(roi.x1), usize::from(roi.y1));
    let mut push = |v: u16| {
        if let Some(slot) = buf.get_mut(n) {
            *slot = v;
            n += 1;
        }
    };
    let xa = x0.saturating_sub(1);
    let xb = (x1 + 1).min(w);
    for y in [y0.checked_sub(1), Some(y1).filter(|&y| y < h)]
        .into_iter()
        .flatten()
    {
        if let Some(row) = frame.row(y) {
            for &v in row.get(xa..xb).unwrap_or(&[]) {
                push(v);
            }
        }
    }
    for y in y0..y1.min(h) {
        if let Some(row) = frame.row(y) {
            for x in [x0.checked_sub(1), Some(x1).filter(|&x| x < w)]
                .into_iter()
                .flatten()
            {
                if let Some(&v) = row.get(x) {
                    push(v);
                }
            }
        }
    }
    let ring = buf.get(..n).filter(|r| !r.is_empty())?;
    // The element at index n/2 of the sorted ring.
    let median = select_binned(
        || ring.iter().map(|&v| u32::from(v)),
        n / 2,
        u32::from(u16::MAX),
    );
    u16::try_from(median).ok()
}

/// The strongest departure from `bg` of the sign of `d` among pixel (x, y)'s 3 × 3
/// inside `roi` (its own included): the level of the face it lies on; and how many of
/// its neighbours depart that way by at least `face_min` (a face's other pixels).
fn face_level(
    frame: &Frame<'_>,
    roi: Roi,
    (x, y): (usize, usize),
    d: i32,
    bg: i32,
    face_min: u32,
) -> (u32, u32) {
    let x_end = (x + 2).min(usize::from(roi.x1)).min(frame.width());
    let x_start = x.saturating_sub(1).max(usize::from(roi.x0));
    let ys = y.saturating_sub(1).max(usize::from(roi.y0))..(y + 2).min(usize::from(roi.y1));
    let (mut face, mut others) = (0u32, 0u32);
    for yy in ys {
        let row = frame.row(yy).and_then(|r| r.get(x_start..x_end));
        for (xx, &v) in (x_start..).zip(row.unwrap_or(&[])) {
            let e = i32::from(v) - bg;
            if e.signum() == d.signum() {
                face = face.max(e.unsigned_abs());
                others += u32::from((xx, yy) != (x, y) && e.unsigned_abs() >= face_min);
            }
        }
    }
    (face, others)
}

/// `roi` cut to its half maximum and its weaker faces' (see the module): boxes larger than
/// [`MAX_SIDE_PX`], or whose peak departs less than [`MIN_PEAK_SIGMA`] · `sigma_dn`
/// from the ring's median, come back unchanged. The result lies inside `roi` and
/// holds the peak pixel.
pub fn half_max_box(frame: &Frame<'_>, roi: Roi, sigma_dn: u32, background: Background) -> Roi {
    if roi.x1 <= roi.x0
        || roi.y1 <= roi.y0
        || roi.x1 - roi.x0 > MAX_SIDE_PX
        || roi.y1 - roi.y0 > MAX_SIDE_PX
    {
        return roi;
    }
    let Some(bg) = ring_median(frame, roi) else {
        return roi;
    };
    let bg = i32::from(bg);
    let (x0, x1) = (usize::from(roi.x0), usize::from(roi.x1));
    let rows = usize::from(roi.y0)..usize::from(roi.y1).min(frame.height());
    // The peak departure, signed, and whether a pixel is at the top DN (saturated).
    let (mut peak, mut saturated) = (0i32, false);
    let max_dn = frame.max_dn();
    for y in rows.clone() {
        let Some(row) = frame.row(y).and_then(|r| r.get(x0..x1)) else {
            continue;
        };
        for &v in row {
            let d = i32::from(v) - bg;
            if d.abs() > peak.abs() {
                peak = d;
            }
            saturated |= v >= max_dn;
        }
    }
    if peak.unsigned_abs() < MIN_PEAK_SIGMA.saturating_mul(sigma_dn.max(1)) {
        return roi;
    }
    // A ring at DN 0 is deep space clipped by the camera (see [`Background::Cluttered`]).
    let deep_space = match background {
        Background::DeepSpace => true,
        Background::Cluttered => bg == 0 && !saturated,
        Background::ClutteredSharp => bg == 0,
    };
    let face_min = if deep_space {
        DEEP_SPACE_FACE_MIN_SIGMA.saturating_mul(sigma_dn.max(1))
    } else {
        FACE_MIN_SIGMA
            .saturating_mul(sigma_dn.max(1))
            .max(peak.unsigned_abs() / FACE_SHARE_DIV)
    };
    let mut cut = Roi::EMPTY;
    let mut found = false;
    for y in rows.clone() {
        let Some(row) = frame.row(y).and_then(|r| r.get(x0..x1)) else {
            continue;
        };
        for (i, &v) in row.iter().enumerate() {
            let d = i32::from(v) - bg;
            // Above half the peak (its sign), or at its own face's half maximum
            // (either sign: a cold face beside a hot one; module docs).
            let kept = d.signum() == peak.signum() && 2 * d.abs() > peak.abs()
                || d.unsigned_abs() >= face_min && {
                    let (level, others) = face_level(frame, roi, (x0 + i, y), d, bg, face_min);
                    2 * d.unsigned_abs() > level && (!deep_space || others > 0)
                };
            if kept {
                let (x, y) = ((x0 + i) as u16, y as u16);
                if found {
                    cut.x0 = cut.x0.min(x);
                    cut.y0 = cut.y0.min(y);
                    cut.x1 = cut.x1.max(x + 1);
                    cut.y1 = cut.y1.max(y + 1);
                } else {
                    cut = Roi {
                        x0: x,
                        y0: y,
                        x1: x + 1,
                        y1: y + 1,
                    };
                    found = true;
                }
            }
        }
    }
    if found { cut } else { roi }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{FRAME_HEIGHT, FRAME_WIDTH};
    extern crate std;

    /// The flight camera's optics PSF (`tirroi_host::imaging::psf::OpticsPsf::
    /// hayabusa2_tir(37.0)`, the Airy pattern at F/1.4 over 37 µm pixels; its corner
    /// quadrant, rounded to 1e-4): 88 % of a point's light stays in its pixel.
    const AIRY: [[f64; 3]; 3] = [
        [0.8808, 0.0195, 0.0018],
        [0.0195, 0.0055, 0.0012],
        [0.0018, 0.0012, 0.0006],
    ];

    /// A 6 × 4 rectangle of 5000 DN over 1000 DN at (100, 50), blurred by the 5×5
    /// kernel `k(|dx|, |dy|)`, as a frame.
    fn blurred_rectangle(k: impl Fn(usize, usize) -> f64) -> std::vec::Vec<u16> {
        let (bg, top) = (1000f64, 5000f64);
        let (rx0, ry0, rx1, ry1) = (100usize, 50usize, 106usize, 54usize);
        let sharp = |x: usize, y: usize| {
            if (rx0..rx1).contains(&x) && (ry0..ry1).contains(&y) {
                top
            } else {
                bg
            }
        };
        let mut px = std::vec![0u16; FRAME_WIDTH * FRAME_HEIGHT];
        for y in 2..FRAME_HEIGHT - 2 {
            for x in 2..FRAME_WIDTH - 2 {
                let mut s = 0.0;
                for dy in 0..5usize {
                    for dx in 0..5usize {
                        s += k(dx.abs_diff(2), dy.abs_diff(2)) * sharp(x + dx - 2, y + dy - 2);
                    }
                }
                px[y * FRAME_WIDTH + x] = s.round() as u16;
            }
        }
        px
    }

    /// A uniform rectangle blurred by the flight optics over a flat background: the
    /// half-maximum box is the rectangle itself (a blurred step crosses half its height
    /// at the edge), from a box 3 px wider per side; the same for a cold one.
    #[test]
    fn a_blurred_rectangle_is_cut_to_its_edges() {
        let rect = Roi::new(100, 50, 106, 54);
        let wide = Roi::new(97, 47, 109, 57);
        let px = blurred_rectangle(|dx, dy| AIRY[dy][dx]);
        let frame = Frame::reference(&px).unwrap();
        assert_eq!(half_max_box(&frame, wide, 10, Background::Cluttered), rect);
        let inv: std::vec::Vec<u16> = px.iter().map(|&v| 6000 - v).collect();
        let frame = Frame::reference(&inv).unwrap();
        assert_eq!(half_max_box(&frame, wide, 10, Background::Cluttered), rect);
        // A large box left alone, and a peak under the threshold: unchanged.
        let big = Roi::new(60, 20, 130, 80);
        assert_eq!(half_max_box(&frame, big, 10, Background::Cluttered), big);
        assert_eq!(
            half_max_box(&frame, wide, 4000, Background::Cluttered),
            wide
        );
    }

    /// Under a blur as wide as a 5 × 5 box (every weight 1/25; far wider than the
    /// optics') the half *peak* still finds the rectangle, but across each edge the
    /// pixel outside holds 2/5 of the step against 3/5 inside, more than half: the
    /// weaker-face rule keeps one pixel more per side. Pinned here as the rule's limit
    /// (session 35 chose it on family A, whose optics are [`AIRY`]).
    #[test]
    fn a_box_blur_keeps_one_pixel_more_per_side() {
        let px = blurred_rectangle(|_, _| 1.0 / 25.0);
        let frame = Frame::reference(&px).unwrap();
        let wide = Roi::new(97, 47, 109, 57);
        assert_eq!(
            half_max_box(&frame, wide, 10, Background::Cluttered),
            Roi::new(99, 49, 107, 55)
        );
    }

    /// A sharp target of three 4 × 5 faces side by side over a flat background of
    /// 2000 DN: hot (+4000), a face of `second` (DN departure) and a third of
    /// `third`, in a box 2 px wider per side.
    fn three_faces(second: i32, third: i32) -> (std::vec::Vec<u16>, Roi) {
        let mut px = std::vec![2000u16; FRAME_WIDTH * FRAME_HEIGHT];
        for y in 60..65 {
            for (x0, d) in [(100usize, 4000i32), (104, second), (108, third)] {
                for x in x0..x0 + 4 {
                    px[y * FRAME_WIDTH + x] = (2000 + d) as u16;
                }
            }
        }
        (px, Roi::new(98, 58, 114, 67))
    }

    #[test]
    fn weaker_faces_are_kept_at_their_own_half_maximum() {
        let sigma = 10;
        let faces = |second, third| {
            let (px, wide) = three_faces(second, third);
            let frame = Frame::reference(&px).unwrap();
            half_max_box(&frame, wide, sigma, Background::Cluttered)
        };
        // A face at 0.4 of the peak (≥ ⅓ and ≥ 4 σ) is kept, beside it a cold face
        // at −0.35 of the peak too: all three faces.
        assert_eq!(faces(1600, -1400), Roi::new(100, 60, 112, 65));
        // At 0.3 and 0.2 of the peak (under ⅓): the hot face alone, as before.
        assert_eq!(faces(1200, 800), Roi::new(100, 60, 104, 65));
        // A face above half the peak is kept by the old rule already; the third at
        // 0.25 of the peak is not.
        assert_eq!(faces(2400, 1000), Roi::new(100, 60, 108, 65));
        // A faint target: ⅓ of a 100 DN peak is under 4 σ = 40 DN only for σ ≥ 9:
        // at σ = 10 its 35 DN face is noise, at σ = 2 (8 σ peak threshold 16 DN) it
        // counts.
        let mut px = std::vec![1000u16; FRAME_WIDTH * FRAME_HEIGHT];
        for y in 60..65 {
            for x in 100..104 {
                px[y * FRAME_WIDTH + x] = 1100;
            }
            for x in 104..108 {
                px[y * FRAME_WIDTH + x] = 1035;
            }
        }
        let frame = Frame::reference(&px).unwrap();
        let wide = Roi::new(98, 58, 110, 67);
        assert_eq!(
            half_max_box(&frame, wide, 10, Background::Cluttered),
            Roi::new(100, 60, 104, 65)
        );
        assert_eq!(
            half_max_box(&frame, wide, 2, Background::Cluttered),
            Roi::new(100, 60, 108, 65)
        );
    }

    /// Over deep space a close target's faces in shadow count whatever the sunlit
    /// face's peak (`famA/000073`, `000115`: faces at 0.1–0.3 of the peak), from
    /// [`DEEP_SPACE_FACE_MIN_SIGMA`] σ; a face under it stays out, as noise would.
    #[test]
    fn over_deep_space_faces_count_from_the_noise_alone() {
        let sigma = 10;
        let faces = |second, third, background| {
            let (px, wide) = three_faces(second, third);
            let frame = Frame::reference(&px).unwrap();
            half_max_box(&frame, wide, sigma, background)
        };
        // Faces at 0.3 and 0.2 of the peak: over the Earth the hot face alone (clutter
        // could be as strong), over deep space all three faces.
        assert_eq!(
            faces(1200, 800, Background::Cluttered),
            Roi::new(100, 60, 104, 65)
        );
        assert_eq!(
            faces(1200, 800, Background::DeepSpace),
            Roi::new(100, 60, 112, 65)
        );
        // A face at 0.05 of the peak (200 DN, 20 σ) counts; the third at 3.5 σ does
        // not (under 4 σ).
        assert_eq!(
            faces(200, 35, Background::DeepSpace),
            Roi::new(100, 60, 108, 65)
        );
        // A face below the ring's level counts the same (either sign, as over the
        // Earth).
        assert_eq!(
            faces(-200, 0, Background::DeepSpace),
            Roi::new(100, 60, 108, 65)
        );
    }

    /// A box of any stage whose ring is a sky clipped at DN 0 (the `paper` world's deep
    /// space, `paperAT/000186`: a Tango's faces in shadow beside its sunlit face) is cut
    /// as over deep space; one holding a saturated pixel (a halo, a limb beside it)
    /// as over the Earth, unless the optics do not blur (no halo: session 59).
    #[test]
    fn a_ring_at_dn_0_is_deep_space_unless_the_box_saturates() {
        let mut px = std::vec![0u16; FRAME_WIDTH * FRAME_HEIGHT];
        for y in 60..65 {
            for (x0, dn) in [(100usize, 4000u16), (104, 600), (108, 300)] {
                for x in x0..x0 + 4 {
                    px[y * FRAME_WIDTH + x] = dn;
                }
            }
        }
        let wide = Roi::new(98, 58, 114, 67);
        let frame = Frame::reference(&px).unwrap();
        let all = Roi::new(100, 60, 112, 65);
        assert_eq!(half_max_box(&frame, wide, 10, Background::Cluttered), all);
        assert_eq!(half_max_box(&frame, wide, 10, Background::DeepSpace), all);
        // The hot face saturated: over the Earth's rule, the hot face alone.
        let top = frame.max_dn();
        for y in 60..65 {
            for x in 100..104 {
                px[y * FRAME_WIDTH + x] = top;
            }
        }
        let frame = Frame::reference(&px).unwrap();
        assert_eq!(
            half_max_box(&frame, wide, 10, Background::Cluttered),
            Roi::new(100, 60, 104, 65)
        );
        // Through optics without blur a saturated face leaves no halo: the ring at DN 0
        // is deep space and the faces in shadow stay.
        assert_eq!(
            half_max_box(&frame, wide, 10, Background::ClutteredSharp),
            all
        );
    }

    /// Over deep space a face is more than one pixel: two hot pixels (the real
    /// camera's signature, `famBSE/000420`: +909 and +198 DN at σ 3 DN over a sky at
    /// DN 0) are no target and its face; the box is cut to the stronger one (which
    /// stage 2c then rejects as under 2 px).
    #[test]
    fn over_deep_space_a_lone_pixel_is_no_face() {
        let mut px = std::vec![0u16; FRAME_WIDTH * FRAME_HEIGHT];
        px[106 * FRAME_WIDTH + 167] = 909;
        px[100 * FRAME_WIDTH + 174] = 198;
        let frame = Frame::reference(&px).unwrap();
        let wide = Roi::new(166, 99, 176, 108);
        assert_eq!(
            half_max_box(&frame, wide, 3, Background::DeepSpace),
            Roi::new(167, 106, 168, 107)
        );
        // With a neighbour at 4 σ the weaker pixel is a face's (the neighbour itself,
        // under half of it, is the face's blur and stays out).
        px[100 * FRAME_WIDTH + 175] = 12;
        let frame = Frame::reference(&px).unwrap();
        assert_eq!(
            half_max_box(&frame, wide, 3, Background::DeepSpace),
            Roi::new(167, 100, 175, 107)
        );
    }

    #[test]
    fn ring_median_equals_the_sorted_ring() {
        // A pseudo-random frame (ties included: values 0..64) and boxes everywhere,
        // also at the frame's edges; reference: the ring collected by brute force and
        // sorted.
        let mut s = 0x9e37_79b9u32;
        let px: std::vec::Vec<u16> = (0..FRAME_WIDTH * FRAME_HEIGHT)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 17;
                s ^= s << 5;
                (s % 64) as u16
            })
            .collect();
        let frame = Frame::reference(&px).unwrap();
        for (x0, y0, x1, y1) in [
            (0u16, 0u16, 5u16, 3u16),
            (10, 10, 30, 20),
            (300, 200, 328, 248),
            (0, 100, 24, 124),
            (163, 0, 164, 1),
            // The largest box cut: a 48 × 48 px ring of 196 pixels.
            (40, 40, 88, 88),
        ] {
            let roi = Roi::new(x0, y0, x1, y1);
            let mut ring = std::vec::Vec::new();
            for y in i32::from(y0) - 1..=i32::from(y1) {
                for x in i32::from(x0) - 1..=i32::from(x1) {
                    let inside = x >= i32::from(x0)
                        && x < i32::from(x1)
                        && y >= i32::from(y0)
                        && y < i32::from(y1);
                    let in_frame = x >= 0
                        && y >= 0
                        && (x as usize) < FRAME_WIDTH
                        && (y as usize) < FRAME_HEIGHT;
                    if !inside && in_frame {
                        ring.push(px[y as usize * FRAME_WIDTH + x as usize]);
                    }
                }
            }
            ring.sort_unstable();
            assert_eq!(
                ring_median(&frame, roi),
                Some(ring[ring.len() / 2]),
                "{roi:?}"
            );
        }
    }

    #[test]
    fn boxes_at_the_frame_edge_and_degenerate_boxes_are_safe() {
        let px = std::vec![7u16; FRAME_WIDTH * FRAME_HEIGHT];
        let frame = Frame::reference(&px).unwrap();
        for roi in [
            Roi::EMPTY,
            Roi {
                x0: 0,
                y0: 0,
                x1: 5,
                y1: 5,
            },
            Roi {
                x0: 320,
                y0: 240,
                x1: 328,
                y1: 248,
            },
        ] {
            // A flat frame has no peak: the box comes back unchanged.
            assert_eq!(half_max_box(&frame, roi, 1, Background::Cluttered), roi);
        }
    }
}
