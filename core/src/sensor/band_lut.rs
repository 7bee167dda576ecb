//! The flight-friendly fast path of the band radiance: a table of ln L on temperature
//! nodes spaced 2^(1/32) apart from 2.5 K to 5120 K, and cubic Hermite interpolation of
//! ln L in T with the exact slopes (the "LUT B" method of `shared/reference/REFERENCE.md`
//! §3). f32 only, no `log` call (the node index comes from the float's exponent bits),
//! one `expf` per call.
//!
//! Error: ≤ 1e-5 relative (asserted in core/tests/sensor_radiance.rs; measured
//! figures in docs/camera-model.md) wherever L is a normal f32 (13 K and up); 0 below
//! 2.5 K, where L < 1.4e-173 is far below the f32 range anyway. Above 5120 K (to the
//! model's limit of 10 000 K) ln L is extrapolated linearly along the last slope:
//! finite and monotone, not accuracy-checked.

use super::SensorError;
use super::planck::{BandRadiance, T_MAX_K, check_emissivity, check_temperature};

/// Lowest table node, K.
pub const LUT_T_MIN_K: f32 = 2.5;
/// Nodes per doubling of the temperature.
pub const LUT_NODES_PER_OCTAVE: usize = 32;
/// Octaves covered: 2.5 K · 2¹¹ = 5120 K.
pub const LUT_OCTAVES: usize = 11;
/// Number of intervals of the table.
pub const LUT_INTERVALS: usize = LUT_NODES_PER_OCTAVE * LUT_OCTAVES;

/// One interval [T_i, T_i+1] of the table: everything the interpolation needs, in f32.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Interval {
    /// T_i, K.
    t_k: f32,
    /// 1/(T_i+1 − T_i), 1/K.
    inv_width_k: f32,
    /// ln L(T_i), ln(W m⁻² sr⁻¹).
    ln_l: f32,
    /// L(T_i) in f32 (0 or subnormal below 13 K), W m⁻² sr⁻¹.
    l: f32,
    /// L(T_i+1) in f32, W m⁻² sr⁻¹: with `l`, the clamp that keeps the result
    /// monotone across nodes despite rounding.
    l_next: f32,
    /// ln L(T_i+1) − ln L(T_i), taken in f64 before rounding.
    dln_l: f32,
    /// d ln L/du at u = 0 (u = (T − T_i)/(T_i+1 − T_i)).
    slope0: f32,
    /// d ln L/du at u = 1.
    slope1: f32,
}

/// The fast band-radiance table for one response: 352 intervals, 11 264 bytes
/// (`size_of::<BandLut>()`), built from the exact f64 path.
#[derive(Debug, Clone, PartialEq)]
pub struct BandLut {
    intervals: [Interval; LUT_INTERVALS],
}

/// Fields of one [`Interval`] in the generated tables of [`super::band_tables`]:
/// T_i, 1/width, ln L_i, L_i, L_i+1, Δln L, slope₀, slope₁ (f32 bit patterns).
pub(super) const INTERVAL_FIELDS: usize = 8;

impl BandLut {
    /// The table of the Hayabusa2 TIR camera's measured response as a `const`:
    /// `BandLut::new(&BandRadiance::hayabusa2_tir())` computed at build time (the
    /// generated [`super::band_tables`], checked against the run-time code bit for
    /// bit). Nothing to compute at start-up (on the Cortex-M7 the run-time build costs
    /// about 664 M instructions of soft f64).
    pub const HAYABUSA2_TIR: BandLut = BandLut::from_bits(&super::band_tables::TIR_LUT_BITS);

    /// A table from its intervals' f32 bit patterns (field order of [`INTERVAL_FIELDS`]).
    const fn from_bits(bits: &[[u32; INTERVAL_FIELDS]; LUT_INTERVALS]) -> Self {
        let zero = Interval {
            t_k: 0.0,
            inv_width_k: 0.0,
            ln_l: 0.0,
            l: 0.0,
            l_next: 0.0,
            dln_l: 0.0,
            slope0: 0.0,
            slope1: 0.0,
        };
        let mut intervals = [zero; LUT_INTERVALS];
        let mut i = 0;
        while i < LUT_INTERVALS {
            let b = &bits[i];
            intervals[i] = Interval {
                t_k: f32::from_bits(b[0]),
                inv_width_k: f32::from_bits(b[1]),
                ln_l: f32::from_bits(b[2]),
                l: f32::from_bits(b[3]),
                l_next: f32::from_bits(b[4]),
                dln_l: f32::from_bits(b[5]),
                slope0: f32::from_bits(b[6]),
                slope1: f32::from_bits(b[7]),
            };
            i += 1;
        }
        BandLut { intervals }
    }

    /// The intervals' f32 bit patterns (for the generator of [`super::band_tables`]).
    #[cfg(test)]
    pub(super) fn interval_bits(&self) -> impl Iterator<Item = [u32; INTERVAL_FIELDS]> + '_ {
        self.intervals.iter().map(|iv| {
            [
                iv.t_k.to_bits(),
                iv.inv_width_k.to_bits(),
                iv.ln_l.to_bits(),
                iv.l.to_bits(),
                iv.l_next.to_bits(),
                iv.dln_l.to_bits(),
                iv.slope0.to_bits(),
                iv.slope1.to_bits(),
            ]
        })
    }

    /// Tabulates `band` (about 700 exact evaluations: 2 ms on the host, done once).
    pub fn new(band: &BandRadiance) -> Self {
        let mut intervals = [Interval::default(); LUT_INTERVALS];
        let node_t =
            |i: usize| f64::from(LUT_T_MIN_K) * libm::exp2(i as f64 / LUT_NODES_PER_OCTAVE as f64);
        // ε = 1 and T within (0, T_MAX_K]: the exact path cannot fail here.
        let eval = |t: f64| {
            let l = band.radiance_w_m2_sr(t.min(T_MAX_K), 1.0).unwrap_or(0.0);
            let dl = band
                .radiance_derivative_w_m2_sr_k(t.min(T_MAX_K), 1.0)
                .unwrap_or(0.0);
            (l, dl)
        };
        let mut t0 = node_t(0);
        let (mut l0, mut d0) = eval(t0);
        for (i, iv) in intervals.iter_mut().enumerate() {
            let t1 = node_t(i + 1);
            let (l1, d1) = eval(t1);
            let h = t1 - t0;
            *iv = Interval {
                t_k: t0 as f32,
                inv_width_k: (1.0 / h) as f32,
                ln_l: libm::log(l0) as f32,
                l: l0 as f32,
                l_next: l1 as f32,
                dln_l: (libm::log(l1) - libm::log(l0)) as f32,
                slope0: (d0 / l0 * h) as f32,
                slope1: (d1 / l1 * h) as f32,
            };
            (t0, l0, d0) = (t1, l1, d1);
        }
        BandLut { intervals }
    }

    /// Index of the interval holding `t` (≥ [`LUT_T_MIN_K`]): a first guess from the
    /// exponent and mantissa bits of t/T_min (log₂ to within 0.09), then at most a few
    /// steps to the right interval.
    fn index(&self, t_k: f32) -> usize {
        let r = t_k / LUT_T_MIN_K;
        let bits = r.to_bits();
        let exponent = ((bits >> 23) & 0xff) as i32 - 127;
        let mantissa = (bits & 0x007f_ffff) as f32 * (1.0 / 8_388_608.0);
        let guess = (exponent as f32 + mantissa) * LUT_NODES_PER_OCTAVE as f32;
        let mut i = (guess.max(0.0) as usize).min(LUT_INTERVALS - 1);
        // Checked reads (no panic path in the flight build); `i` stays in the table.
        let start_k = |j: usize| self.intervals.get(j).map_or(f32::INFINITY, |iv| iv.t_k);
        for _ in 0..8 {
            if i > 0 && t_k < start_k(i) {
                i -= 1;
            } else if i + 1 < LUT_INTERVALS && t_k >= start_k(i + 1) {
                i += 1;
            } else {
                break;
            }
        }
        i
    }

    /// Band radiance ε·L(T), W m⁻² sr⁻¹, from the table. `t_k` in [0, 10 000] K,
    /// `emissivity` in [0, 1]; 0 below 2.5 K.
    ///
    /// # Errors
    /// [`SensorError`] for NaN, infinite, negative or too large T, or ε outside [0, 1].
    pub fn radiance_f32(&self, t_k: f32, emissivity: f32) -> Result<f32, SensorError> {
        check_temperature(t_k as f64)?;
        let e = check_emissivity(emissivity as f64)? as f32;
        if t_k < LUT_T_MIN_K {
            return Ok(0.0);
        }
        // `index` is below LUT_INTERVALS; the `min` lets the compiler see it.
        let iv = &self.intervals[self.index(t_k).min(LUT_INTERVALS - 1)];
        let u = (t_k - iv.t_k) * iv.inv_width_k;
        let u2 = u * u;
        let u3 = u2 * u;
        // Cubic Hermite basis: h01 = 3u² − 2u³, h10 = u³ − 2u² + u, h11 = u³ − u².
        let dy = if u <= 1.0 {
            (3.0 * u2 - 2.0 * u3) * iv.dln_l
                + (u3 - 2.0 * u2 + u) * iv.slope0
                + (u3 - u2) * iv.slope1
        } else {
            // Above the last node: straight on along the end slope.
            iv.dln_l + (u - 1.0) * iv.slope1
        };
        let l = if iv.l >= f32::MIN_POSITIVE {
            iv.l * libm::expf(dy)
        } else {
            libm::expf(iv.ln_l + dy)
        };
        // The true L lies between the two correctly rounded node values; clamping to
        // them only removes error, and makes the end of one interval meet the start
        // of the next without a one-ulp step down.
        // (max then min: `clamp`'s result for node values in order, without its
        // panic branch for unordered bounds.)
        let l = if u <= 1.0 {
            l.max(iv.l).min(iv.l_next)
        } else {
            l.max(iv.l_next)
        };
        Ok(e * l)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_size_is_as_documented() {
        assert_eq!(core::mem::size_of::<BandLut>(), 11_264);
        assert_eq!(LUT_INTERVALS, 352);
    }
}
