//! Band-integrated Planck radiance i(T, ε) = ∫ ε B(λ,T) R(λ) dλ (paper Eqs. 1, 4, 6) and
//! the emissive power F(T) = π·i, for a gray body (ε independent of λ, as in Table 3).
//!
//! # Method
//!
//! [`BandRadiance`] precomputes, once per response, a composite 10-point Gauss–Legendre
//! rule over the band (17 panels, 170 nodes for the TIR model): the panels are split at
//! the response's logistic edges (within a few widths, where R changes fastest), are at
//! most 1 µm wide elsewhere, and the last 0.3 µm before λ_max is a panel of its own,
//! because below 10 K the integrand is an exponential that piles up against the long-
//! wavelength cut. A tabulated response (the measured Hayabusa2 TIR curve, the default)
//! gets a product rule instead (16 panels, 160 nodes: equal panels ≤ 1 µm, the last
//! 2 µm in 0.6 … 0.2 µm panels for the same pile-up): B is interpolated at 10
//! Gauss–Legendre nodes per panel and the weights W_j = ∫R·ℓ_j dλ are integrated
//! exactly over every 0.01 µm sample interval, so the kinks of the piecewise-linear R
//! cost no accuracy. Each node stores c₂/λ and the weight w·R(λ)·c₁/λ⁵, so one radiance
//! costs one `expm1` per node and no cancellation: B = c₁λ⁻⁵/expm1(c₂/λT).
//!
//! # Accuracy (core/tests/sensor_radiance.rs against the 30-digit table)
//!
//! | path | domain | worst relative error |
//! |---|---|---|
//! | [`BandRadiance::radiance_w_m2_sr`] (f64) | 1.5–5000 K | ≤ 1e-9 asserted (measured 1.3e-11 in the quadrature prototype) |
//! | [`BandRadiance::radiance_f32`] (f32) | 13–5000 K | ≤ 1e-5 asserted |
//! | [`BandLut::radiance_f32`](super::BandLut::radiance_f32) (table) | 13–5000 K | ≤ 1e-5 asserted |
//!
//! For the measured response (`core/tests/data/band_radiance_hayabusa2_reference.csv`):
//! f64 ≤ 1e-6 asserted over 50–2000 K (measured 2.0e-15) and ≤ 1e-9 over 3–5000 K
//! (measured 9.1e-10, at 3 K); f32 quadrature 4.4e-6 and table 4.0e-6 (≤ 1e-5 asserted)
//! wherever L is a normal f32 (11 K and up).
//!
//! Below those bounds the radiance itself leaves the number format: L < 2.2e-308 (f64
//! normal minimum) below 1.34 K and L < 1.2e-38 (f32 normal minimum) below 13.0 K, so
//! the f64 path returns subnormals or 0 with an absolute error under 2.3e-308, and the
//! f32 paths return subnormals or 0 with an absolute error under 1.2e-38;
//! [`BandRadiance::ln_radiance_f32`] carries ln L instead, with an absolute error in
//! ln L below 1e-4 down to 3 K (asserted). No signal that small ever reaches a DN.
//! Results are finite, exactly 0 at 0 K, and non-decreasing in T: for the bell every
//! node's term is, and they are summed in a fixed order. The measured table has noise
//! below zero in its tail (down to −2.6e-5), so a few of its weights are negative; its f64
//! path and table are monotone on a dense sweep of 2–5000 K, its f32 quadrature from
//! 13 K (below, where L < 1e-34, it can fall by 2 ulp; tested in sensor_stability.rs).

use super::response::{CameraResponse, SkewedBell, TabulatedResponse};
use super::{SensorError, check_range};

/// First radiation constant for spectral radiance per µm, 2hc² = 1.191 042 972 397 e8
/// W µm⁴ m⁻² sr⁻¹ (SI 2019 exact h, c).
pub const C1_W_UM4_M2_SR: f64 = 1.191_042_972_397_188_4e8;
/// Second radiation constant hc/k_B = 14 387.768 775 039 34 µm K (SI 2019 exact).
pub const C2_UM_K: f64 = 14_387.768_775_039_338;
/// Stefan–Boltzmann constant σ = 5.670 374 419 184 429 e-8 W m⁻² K⁻⁴ (SI 2019 exact).
pub const STEFAN_BOLTZMANN_W_M2_K4: f64 = 5.670_374_419_184_429e-8;
/// Highest temperature the camera model accepts, K. The accuracy is proven up to
/// 5000 K; above that only finiteness and monotonicity are.
pub const T_MAX_K: f64 = 10_000.0;

/// Below this temperature the f32 paths return 0 (L < 1e-408, and 1/T overflows f32
/// for subnormal T), K.
const F32_ZERO_BELOW_K: f32 = 1.0;

/// Gauss–Legendre nodes (positive half, on [−1, 1]) and weights, 10 points, to 20
/// digits (mpmath; Abramowitz & Stegun Table 25.4). The digits beyond f64 are kept so
/// the table can be checked against its sources.
#[allow(clippy::excessive_precision)]
const GAUSS_LEGENDRE_10: [(f64, f64); 5] = [
    (0.148_874_338_981_631_210_88, 0.295_524_224_714_752_870_17),
    (0.433_395_394_129_247_190_8, 0.269_266_719_309_996_355_09),
    (0.679_409_568_299_024_406_23, 0.219_086_362_515_982_044),
    (0.865_063_366_688_984_510_73, 0.149_451_349_150_580_593_15),
    (0.973_906_528_517_171_720_08, 0.066_671_344_308_688_137_594),
];
const NODES_PER_PANEL: usize = 10;
/// Most panels a response may need (the TIR model uses 17).
pub const MAX_PANELS: usize = 24;
const MAX_NODES: usize = MAX_PANELS * NODES_PER_PANEL;
/// Widest panel away from the edges, µm.
const MAX_PANEL_UM: f64 = 1.0;
/// Width of the last panel before λ_max, µm (the low-temperature pile-up).
const TAIL_PANEL_UM: f64 = 0.3;

/// Spectral radiance of a blackbody, Planck's law B(λ, T), W m⁻² sr⁻¹ µm⁻¹, for λ in µm
/// and T in K. Returns 0 for T ≤ 0, λ ≤ 0 or NaN, never overflows (expm1 of a huge
/// exponent is +∞, whose reciprocal is 0).
pub fn spectral_radiance_w_m2_sr_um(lambda_um: f64, t_k: f64) -> f64 {
    if !(lambda_um > 0.0 && t_k > 0.0) {
        return 0.0;
    }
    let l5 = lambda_um * lambda_um * lambda_um * lambda_um * lambda_um;
    C1_W_UM4_M2_SR / l5 / libm::expm1(C2_UM_K / (lambda_um * t_k))
}

/// The node tables of a [`BandRadiance`] (see `BandRadiance::node_bits`).
#[cfg(test)]
pub(super) type NodeBits<'a> = (&'a [f64], &'a [f64], f32, &'a [f32], &'a [f32]);

/// The band radiance of one camera response, ready to evaluate at any temperature.
///
/// Build once ([`BandRadiance::new`], about 200 `exp` calls), then call as often as
/// needed; 5 872 bytes on x86-64 (`size_of::<BandRadiance>()`), no heap.
#[derive(Debug, Clone)]
pub struct BandRadiance {
    response: CameraResponse,
    /// `Some(k)` for the flat response: L = k·T⁴ W m⁻² sr⁻¹.
    flat_w_m2_sr_k4: Option<f64>,
    nodes: usize,
    /// c₂/λ at each node, µm K / µm = K.
    x_t_k: [f64; MAX_NODES],
    /// Quadrature weight × R(λ) × c₁/λ⁵ at each node, W m⁻² sr⁻¹.
    weight: [f64; MAX_NODES],
    /// f32 path: c₂/λ_max (smallest of `x_t_k`), K.
    x_min_t_k32: f32,
    /// f32 path: `x_t_k − x_min`, K, so that exp(−(x − x_min)) ≤ 1 never underflows
    /// where it matters.
    dx_t_k32: [f32; MAX_NODES],
    /// f32 path: `weight` in f32 (all normal: the smallest is about 1e-18).
    weight32: [f32; MAX_NODES],
}

impl BandRadiance {
    /// Prepares the quadrature for `response`.
    ///
    /// # Errors
    /// [`SensorError`] for a band model whose parameters do not validate, or whose band
    /// needs more than [`MAX_PANELS`] panels (wider than about 20 µm).
    pub fn new(response: &CameraResponse) -> Result<Self, SensorError> {
        let mut me = Self::empty(*response);
        match response {
            CameraResponse::Flat => {
                me.flat_w_m2_sr_k4 = Some(flat_integral() * C1_W_UM4_M2_SR / c2_pow4());
            }
            CameraResponse::Band(bell) => me.fill_band(bell)?,
            CameraResponse::Tabulated(table) => me.fill_tabulated(table)?,
        }
        Ok(me)
    }

    /// A model with no nodes yet (radiance 0 until filled).
    fn empty(response: CameraResponse) -> Self {
        BandRadiance {
            response,
            flat_w_m2_sr_k4: None,
            nodes: 0,
            x_t_k: [0.0; MAX_NODES],
            weight: [0.0; MAX_NODES],
            x_min_t_k32: 0.0,
            dx_t_k32: [0.0; MAX_NODES],
            weight32: [0.0; MAX_NODES],
        }
    }

    /// The Hayabusa2 TIR camera: its measured response
    /// ([`TabulatedResponse::HAYABUSA2_TIR`], the default), 160 nodes.
    pub fn hayabusa2_tir() -> Self {
        match Self::new(&CameraResponse::default()) {
            Ok(b) => b,
            // The built-in table validates and needs 16 panels (unit-tested).
            Err(_) => unreachable_band(),
        }
    }

    /// The analytic skewed-bell model of the Hayabusa2 TIR with η = 1
    /// ([`SkewedBell::HAYABUSA2_TIR`]), 170 nodes.
    pub fn hayabusa2_tir_bell() -> Self {
        match Self::new(&CameraResponse::Band(SkewedBell::HAYABUSA2_TIR)) {
            Ok(b) => b,
            // The built-in model validates and needs 17 panels (unit-tested).
            Err(_) => unreachable_band(),
        }
    }

    fn fill_band(&mut self, bell: &SkewedBell) -> Result<(), SensorError> {
        bell.validate()?;
        let mut breaks = [0.0f64; MAX_PANELS + 1];
        let count = panel_breaks(bell, &mut breaks)?;
        let s_max = bell.peak().1;
        let mut k = 0;
        for p in breaks[..=count].windows(2) {
            let (mid, half) = (0.5 * (p[0] + p[1]), 0.5 * (p[1] - p[0]));
            for &(node, w) in &GAUSS_LEGENDRE_10 {
                for lambda in [mid - half * node, mid + half * node] {
                    let r = bell.eta * bell.shape(lambda) / s_max;
                    let l5 = lambda * lambda * lambda * lambda * lambda;
                    self.x_t_k[k] = C2_UM_K / lambda;
                    self.weight[k] = w * half * r * C1_W_UM4_M2_SR / l5;
                    k += 1;
                }
            }
        }
        self.finish_nodes(k);
        Ok(())
    }

    /// Product Gauss–Legendre quadrature of a piecewise-linear table: the band (first
    /// to last sample) is cut into panels of whole sample intervals ([`table_breaks`]);
    /// on each panel B(λ, T) is replaced by its degree-9
    /// interpolant at the 10 Gauss–Legendre nodes λ_j, so ∫R·B dλ ≈ Σ_j W_j·B(λ_j)
    /// with W_j = ∫R(λ)·ℓ_j(λ) dλ (ℓ_j the Lagrange basis). R·ℓ_j is a polynomial of
    /// degree 10 on each sample interval, which the 10-point rule integrates exactly,
    /// so the kinks of R cost nothing; only B's smoothness over a panel sets the error.
    fn fill_tabulated(&mut self, table: &TabulatedResponse) -> Result<(), SensorError> {
        table.validate()?;
        let mut breaks = [0usize; MAX_PANELS + 1];
        let panels = table_breaks(table, &mut breaks)?;
        let mut k = 0;
        for p in breaks[..=panels].windows(2) {
            let (s0, s1) = (p[0], p[1]);
            let (a, b) = (table.wavelength_um(s0), table.wavelength_um(s1));
            let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
            let mut lambda = [0.0f64; NODES_PER_PANEL];
            for (j, &(node, _)) in GAUSS_LEGENDRE_10.iter().enumerate() {
                lambda[2 * j] = mid - half * node;
                lambda[2 * j + 1] = mid + half * node;
            }
            // Barycentric weights 1/Π_{k≠j}(λ_j − λ_k) of the panel's nodes.
            let mut inv_denominator = [0.0f64; NODES_PER_PANEL];
            for (j, d) in inv_denominator.iter_mut().enumerate() {
                let mut prod = 1.0;
                for (m, &l) in lambda.iter().enumerate() {
                    if m != j {
                        prod *= lambda[j] - l;
                    }
                }
                *d = 1.0 / prod;
            }
            let mut w_panel = [0.0f64; NODES_PER_PANEL];
            for s in s0..s1 {
                let (r0, r1) = (table.sample(s), table.sample(s + 1));
                if r0 == 0.0 && r1 == 0.0 {
                    continue;
                }
                let (sa, sb) = (table.wavelength_um(s), table.wavelength_um(s + 1));
                let (smid, shalf) = (0.5 * (sa + sb), 0.5 * (sb - sa));
                for &(node, w) in &GAUSS_LEGENDRE_10 {
                    for sign in [-1.0, 1.0] {
                        let x = smid + sign * shalf * node;
                        let t = (x - sa) / (sb - sa);
                        let r_w = (r0 * (1.0 - t) + r1 * t) * w * shalf;
                        // ℓ_j(x) = Π_{k≠j}(x − λ_k) / Π_{k≠j}(λ_j − λ_k), from prefix
                        // and suffix products (no division by x − λ_j).
                        let mut prefix = [1.0f64; NODES_PER_PANEL];
                        for m in 1..NODES_PER_PANEL {
                            prefix[m] = prefix[m - 1] * (x - lambda[m - 1]);
                        }
                        let mut suffix = 1.0;
                        for m in (0..NODES_PER_PANEL).rev() {
                            w_panel[m] += r_w * prefix[m] * suffix * inv_denominator[m];
                            suffix *= x - lambda[m];
                        }
                    }
                }
            }
            for (&l, &w) in lambda.iter().zip(&w_panel) {
                let l5 = l * l * l * l * l;
                self.x_t_k[k] = C2_UM_K / l;
                self.weight[k] = w * C1_W_UM4_M2_SR / l5;
                k += 1;
            }
        }
        self.finish_nodes(k);
        Ok(())
    }

    /// Records `k` filled nodes and derives the f32 path's arrays from them.
    fn finish_nodes(&mut self, k: usize) {
        self.nodes = k;
        let x_min = self.x_t_k[..k]
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        self.x_min_t_k32 = x_min as f32;
        for i in 0..k {
            self.dx_t_k32[i] = (self.x_t_k[i] - x_min) as f32;
            self.weight32[i] = self.weight[i] as f32;
        }
    }

    /// The Hayabusa2 TIR camera's band radiance as a `const` ([`BandRadiance::hayabusa2_tir`]
    /// computed at build time: the node tables of [`super::band_tables`], generated by the
    /// run-time code and checked against it bit for bit). Nothing to compute at start-up.
    pub const HAYABUSA2_TIR: BandRadiance = BandRadiance::from_node_bits(
        &super::band_tables::TIR_X_T_K_BITS,
        &super::band_tables::TIR_WEIGHT_BITS,
        super::band_tables::TIR_X_MIN_T_K32_BITS,
        &super::band_tables::TIR_DX_T_K32_BITS,
        &super::band_tables::TIR_WEIGHT32_BITS,
    );

    /// A measured-response (default) radiance from its node tables as IEEE bit patterns,
    /// `N` ≤ [`MAX_PANELS`]·10 nodes (longer tables are cut), in a `const` context.
    const fn from_node_bits<const N: usize>(
        x_t_k: &[u64; N],
        weight: &[u64; N],
        x_min_t_k32: u32,
        dx_t_k32: &[u32; N],
        weight32: &[u32; N],
    ) -> Self {
        let mut me = BandRadiance {
            response: CameraResponse::Tabulated(TabulatedResponse::HAYABUSA2_TIR),
            flat_w_m2_sr_k4: None,
            nodes: 0,
            x_t_k: [0.0; MAX_NODES],
            weight: [0.0; MAX_NODES],
            x_min_t_k32: f32::from_bits(x_min_t_k32),
            dx_t_k32: [0.0; MAX_NODES],
            weight32: [0.0; MAX_NODES],
        };
        let mut i = 0;
        while i < N && i < MAX_NODES {
            me.x_t_k[i] = f64::from_bits(x_t_k[i]);
            me.weight[i] = f64::from_bits(weight[i]);
            me.dx_t_k32[i] = f32::from_bits(dx_t_k32[i]);
            me.weight32[i] = f32::from_bits(weight32[i]);
            i += 1;
        }
        me.nodes = i;
        me
    }

    /// The node tables as IEEE bit patterns (for the generator of [`super::band_tables`]):
    /// c₂/λ and weight (f64), c₂/λ_max, c₂/λ − c₂/λ_max and weight (f32).
    #[cfg(test)]
    pub(super) fn node_bits(&self) -> NodeBits<'_> {
        let n = self.nodes;
        (
            &self.x_t_k[..n],
            &self.weight[..n],
            self.x_min_t_k32,
            &self.dx_t_k32[..n],
            &self.weight32[..n],
        )
    }

    /// The response this radiance integrates over.
    pub fn response(&self) -> CameraResponse {
        self.response
    }

    /// Number of quadrature nodes (0 for the flat response, which is closed-form).
    pub fn nodes(&self) -> usize {
        self.nodes
    }

    /// Band radiance of a blackbody, W m⁻² sr⁻¹, for a temperature already validated
    /// to lie in [0, [`T_MAX_K`]].
    fn blackbody(&self, t_k: f64) -> f64 {
        if t_k <= 0.0 {
            return 0.0;
        }
        if let Some(k) = self.flat_w_m2_sr_k4 {
            let t2 = t_k * t_k;
            return k * t2 * t2;
        }
        let inv_t = 1.0 / t_k;
        let mut sum = 0.0;
        for (x, w) in self.x_t_k.iter().zip(&self.weight).take(self.nodes) {
            sum += w / libm::expm1(x * inv_t);
        }
        sum
    }

    /// Band radiance i(T, ε) = ε·∫B(λ,T)R(λ)dλ (Eq. 1 with the response), W m⁻² sr⁻¹.
    ///
    /// `t_k` in [0, 10 000] K, `emissivity` in [0, 1]. Exactly 0 at 0 K; relative error
    /// ≤ 1e-9 from 1.5 K to 5000 K (see the module docs for below).
    ///
    /// # Errors
    /// [`SensorError`] for NaN, infinite, negative or too large T, or ε outside [0, 1].
    pub fn radiance_w_m2_sr(&self, t_k: f64, emissivity: f64) -> Result<f64, SensorError> {
        let t = check_temperature(t_k)?;
        let e = check_emissivity(emissivity)?;
        Ok(e * self.blackbody(t))
    }

    /// Emissive power F(T) = π·i(T, ε) (Eq. 6), W m⁻².
    ///
    /// # Errors
    /// As [`BandRadiance::radiance_w_m2_sr`].
    pub fn emissive_power_w_m2(&self, t_k: f64, emissivity: f64) -> Result<f64, SensorError> {
        Ok(core::f64::consts::PI * self.radiance_w_m2_sr(t_k, emissivity)?)
    }

    /// Temperature derivative of the band radiance, ∂i/∂T, W m⁻² sr⁻¹ K⁻¹: what one
    /// kelvin changes the signal by (NETD, the inverse T_rad). Same domain and errors as
    /// [`BandRadiance::radiance_w_m2_sr`]; 0 at 0 K.
    ///
    /// # Errors
    /// As [`BandRadiance::radiance_w_m2_sr`].
    pub fn radiance_derivative_w_m2_sr_k(
        &self,
        t_k: f64,
        emissivity: f64,
    ) -> Result<f64, SensorError> {
        let t = check_temperature(t_k)?;
        let e = check_emissivity(emissivity)?;
        Ok(e * self.blackbody_derivative(t))
    }

    fn blackbody_derivative(&self, t_k: f64) -> f64 {
        if t_k <= 0.0 {
            return 0.0;
        }
        if let Some(k) = self.flat_w_m2_sr_k4 {
            return 4.0 * k * t_k * t_k * t_k;
        }
        // d/dT [1/(eˣ − 1)] = x eˣ/(eˣ − 1)² / T = x / (expm1(x)·(−expm1(−x))) / T.
        let inv_t = 1.0 / t_k;
        let mut sum = 0.0;
        for (x_t, w) in self.x_t_k.iter().zip(&self.weight).take(self.nodes) {
            let x = x_t * inv_t;
            let em = libm::expm1(x);
            // Past exp overflow (x > 709.8) the term is below 1e-300: drop it rather
            // than form ∞/∞.
            if em.is_finite() {
                sum += w * x / (em * -libm::expm1(-x));
            }
        }
        sum * inv_t
    }

    /// The temperature T at which ε·L(T) equals `radiance_w_m2_sr`: the inverse of
    /// [`BandRadiance::radiance_w_m2_sr`], K, to about 1e-12 relative. 0 for a radiance
    /// of 0 (or one so small that no temperature of f64 resolves it).
    ///
    /// # Errors
    /// [`SensorError`] for a NaN or negative radiance, ε outside (0, 1], or a radiance
    /// above that of [`T_MAX_K`].
    pub fn temperature_k(
        &self,
        radiance_w_m2_sr: f64,
        emissivity: f64,
    ) -> Result<f64, SensorError> {
        let e = check_range(
            "emissivity",
            emissivity,
            f64::MIN_POSITIVE,
            1.0,
            "0 < emissivity <= 1",
        )?;
        let top = self.blackbody(T_MAX_K);
        let y = check_range(
            "radiance_w_m2_sr",
            radiance_w_m2_sr,
            0.0,
            e * top,
            "0 ..= the radiance at 10 000 K",
        )? / e;
        if y <= 0.0 {
            return Ok(0.0);
        }
        // Safeguarded Newton on ln L(ln T): bracketed, bisection when a step leaves it.
        let (mut lo, mut hi) = (0.0f64, T_MAX_K);
        let mut t = 300.0;
        for _ in 0..200 {
            let l = self.blackbody(t);
            if l > y {
                hi = t;
            } else {
                lo = t;
            }
            let dl = self.blackbody_derivative(t);
            let mut next = if l > 0.0 && dl > 0.0 {
                // ln L(T) ≈ ln L(t) + (t·dl/l)·ln(T/t)
                t * libm::exp((libm::log(y) - libm::log(l)) * l / (t * dl))
            } else {
                f64::NAN
            };
            if !(next > lo && next < hi) {
                next = if lo > 0.0 {
                    libm::sqrt(lo * hi)
                } else {
                    0.5 * hi
                };
            }
            if (next - t).abs() <= 1e-14 * t || hi - lo <= 1e-14 * hi {
                return Ok(next);
            }
            t = next;
        }
        Ok(t)
    }

    /// Band radiance in f32 arithmetic, W m⁻² sr⁻¹, for FPUs without double precision.
    ///
    /// Same quadrature, with the common factor e^(−c₂/λ_max T) pulled out so that no
    /// term goes subnormal before the sum does; relative error ≤ 1e-5 from 13 K
    /// (where L reaches the f32 normal range) to 5000 K. Exactly 0 below 1 K, where
    /// L < 1e-408.
    ///
    /// # Errors
    /// As [`BandRadiance::radiance_w_m2_sr`].
    pub fn radiance_f32(&self, t_k: f32, emissivity: f32) -> Result<f32, SensorError> {
        let t = check_temperature(t_k as f64)? as f32;
        let e = check_emissivity(emissivity as f64)? as f32;
        if t < F32_ZERO_BELOW_K {
            return Ok(0.0);
        }
        let (sum, x_min) = self.scaled_sum_f32(t);
        Ok(e * sum * libm::expf(-x_min))
    }

    /// ln of the blackbody band radiance (ε = 1) in f32, ln(W m⁻² sr⁻¹): finite for every
    /// T ≥ 1 K even where L itself is below the f32 range (below 13 K), with an absolute
    /// error below 1e-4 from 3 K to 5000 K.
    ///
    /// # Errors
    /// As [`BandRadiance::radiance_w_m2_sr`], and for T < 1 K (ln L < −930 there, and
    /// c₂/λT leaves the f32 range for subnormal T).
    pub fn ln_radiance_f32(&self, t_k: f32) -> Result<f32, SensorError> {
        let t = check_range(
            "t_k",
            t_k as f64,
            f64::from(F32_ZERO_BELOW_K),
            T_MAX_K,
            "1 K <= t_k <= 10000 K",
        )? as f32;
        let (sum, x_min) = self.scaled_sum_f32(t);
        Ok(libm::logf(sum) - x_min)
    }

    /// Σ w_k·e^(−(x_k − x_min))/(1 − e^(−x_k)) and x_min, in f32, for T > 0:
    /// L = sum·e^(−x_min). Summed panel by panel to keep the rounding error small.
    fn scaled_sum_f32(&self, t_k: f32) -> (f32, f32) {
        if let Some(k) = self.flat_w_m2_sr_k4 {
            return ((k as f32) * t_k * t_k * t_k * t_k, 0.0);
        }
        let inv_t = 1.0 / t_k;
        let x_min = self.x_min_t_k32 * inv_t;
        let mut total = 0.0f32;
        let n = self.nodes;
        for (dx, w) in self.dx_t_k32[..n]
            .chunks_exact(NODES_PER_PANEL)
            .zip(self.weight32[..n].chunks_exact(NODES_PER_PANEL))
        {
            let mut panel = 0.0f32;
            for (&dx, &w) in dx.iter().zip(w) {
                let d = dx * inv_t;
                panel += w * libm::expf(-d) / -libm::expm1f(-(x_min + d));
            }
            total += panel;
        }
        (total, x_min)
    }
}

/// Validates a temperature: finite, 0 ≤ T ≤ [`T_MAX_K`].
pub(crate) fn check_temperature(t_k: f64) -> Result<f64, SensorError> {
    check_range("t_k", t_k, 0.0, T_MAX_K, "0 <= t_k <= 10000 K")
}

/// Validates an emissivity: finite, 0 ≤ ε ≤ 1.
pub(crate) fn check_emissivity(e: f64) -> Result<f64, SensorError> {
    check_range("emissivity", e, 0.0, 1.0, "0 <= emissivity <= 1")
}

/// Panel boundaries for `bell` into `out`; returns the number of panels.
fn panel_breaks(bell: &SkewedBell, out: &mut [f64; MAX_PANELS + 1]) -> Result<usize, SensorError> {
    let (lo, hi) = (bell.band_min_um, bell.band_max_um);
    // Points that must be panel ends: the band ends, a few widths around both edges.
    let (r, wr, f, wf) = (
        bell.rise_um,
        bell.rise_width_um,
        bell.fall_um,
        bell.fall_width_um,
    );
    let mut keys = [
        lo,
        hi,
        r - 8.0 * wr,
        r - 2.0 * wr,
        r + 2.0 * wr,
        r + 6.0 * wr,
        r + 12.0 * wr,
        f - 3.0 * wf,
        f,
        f + 3.0 * wf,
        f + 7.0 * wf,
    ];
    for k in keys.iter_mut() {
        *k = k.clamp(lo, hi);
    }
    keys.sort_unstable_by(f64::total_cmp);
    let too_wide = SensorError::OutOfRange {
        name: "band_max_um",
        value: hi,
        expected: "a band that fits in 24 quadrature panels (about 20 um)",
    };
    out[0] = lo;
    let mut n = 0;
    for pair in keys.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        if b - a <= 1e-9 {
            continue;
        }
        let pieces = libm::ceil((b - a) / MAX_PANEL_UM - 1e-9).max(1.0) as usize;
        for i in 1..=pieces {
            n += 1;
            if n > MAX_PANELS {
                return Err(too_wide);
            }
            out[n] = if i == pieces {
                b
            } else {
                a + (b - a) * i as f64 / pieces as f64
            };
        }
    }
    // The low-temperature pile-up against λ_max gets a narrow panel of its own.
    if n > 0 && out[n] - out[n - 1] > TAIL_PANEL_UM + 1e-9 {
        n += 1;
        if n > MAX_PANELS {
            return Err(too_wide);
        }
        out[n] = hi;
        out[n - 1] = hi - TAIL_PANEL_UM;
    }
    Ok(n)
}

/// Widths of the last panels of a tabulated response, µm, from its long-wavelength end
/// backwards: below about 20 K the integrand is an exponential piling up against the end
/// of the table (d ln B/dλ = c₂/(λ²T) = 15/µm at 17.9 µm and 3 K), so the panels there
/// shrink to keep B's degree-9 interpolant within 1e-9 (5.9e-9 at 2 K, 9e-10 at 3 K for
/// the TIR table); 2 µm in all.
const TABLE_TAIL_PANELS_UM: [f64; 5] = [0.2, 0.3, 0.4, 0.5, 0.6];

/// Panel boundaries of `table` as sample indices into `out`, ascending from 0 to the
/// last sample; returns the number of panels. The last 2 µm in the panels of
/// [`TABLE_TAIL_PANELS_UM`], the rest in equal panels of at most [`MAX_PANEL_UM`] (both
/// rounded to whole sample intervals, at least one each): 16 panels for the TIR table.
fn table_breaks(
    table: &TabulatedResponse,
    out: &mut [usize; MAX_PANELS + 1],
) -> Result<usize, SensorError> {
    let too_wide = SensorError::OutOfRange {
        name: "samples_micro",
        value: table.last_um() - table.first_um,
        expected: "a table that fits in 24 quadrature panels (about 20 um)",
    };
    let intervals = |width_um: f64| (libm::round(width_um / table.step_um) as usize).max(1);
    // From the end backwards: the tail panels, as long as the table lasts.
    let mut tail = [0usize; TABLE_TAIL_PANELS_UM.len()];
    let mut tail_count = 0;
    let mut end = table.len() - 1;
    for &w in &TABLE_TAIL_PANELS_UM {
        let n = intervals(w);
        if end <= n {
            break;
        }
        end -= n;
        tail[tail_count] = end;
        tail_count += 1;
    }
    // [0, end] in equal panels of at most MAX_PANEL_UM.
    let per_panel = (libm::floor(MAX_PANEL_UM / table.step_um + 1e-9) as usize).max(1);
    let uniform = end.div_ceil(per_panel);
    // The tail's first boundary is `end` itself, the last the table's end.
    let panels = uniform + tail_count;
    if panels > MAX_PANELS {
        return Err(too_wide);
    }
    for (p, o) in out[..=uniform].iter_mut().enumerate() {
        *o = p * end / uniform;
    }
    for i in 1..tail_count {
        out[uniform + i] = tail[tail_count - 1 - i];
    }
    out[panels] = table.len() - 1;
    Ok(panels)
}

/// (c₂)⁴ in (µm K)⁴.
fn c2_pow4() -> f64 {
    let c2 = C2_UM_K;
    c2 * c2 * c2 * c2
}

/// ∫₀^∞ x³/(eˣ − 1) dx by the same 10-point Gauss–Legendre rule on panels of width 1
/// over x ∈ [0, 80] (the rest is below 1e-29 of the total): a numerical value, so that
/// the flat response checks the quadrature and the constants c₁, c₂ against σ instead
/// of assuming σT⁴/π.
fn flat_integral() -> f64 {
    let mut sum = 0.0;
    for p in 0..80 {
        let mid = p as f64 + 0.5;
        for &(node, w) in &GAUSS_LEGENDRE_10 {
            for x in [mid - 0.5 * node, mid + 0.5 * node] {
                sum += 0.5 * w * x * x * x / libm::expm1(x);
            }
        }
    }
    sum
}

/// Never reached: the built-in response validates. Kept out of line so the happy path
/// stays small; returns an empty (flat) model instead of panicking.
#[cold]
fn unreachable_band() -> BandRadiance {
    let mut flat = BandRadiance::empty(CameraResponse::Flat);
    flat.flat_w_m2_sr_k4 = Some(STEFAN_BOLTZMANN_W_M2_K4 / core::f64::consts::PI);
    flat
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫₀^∞ x³/(eˣ − 1) dx = π⁴/15 in closed form.
    const PI4_OVER_15: f64 = core::f64::consts::PI
        * core::f64::consts::PI
        * core::f64::consts::PI
        * core::f64::consts::PI
        / 15.0;

    #[test]
    fn size_is_as_documented() {
        // 240 nodes × (8 + 8 + 4 + 4) bytes plus the response and the flat constant.
        let size = core::mem::size_of::<BandRadiance>();
        assert_eq!(size, 5_872);
        assert_eq!(core::mem::size_of::<crate::sensor::NoiseField>(), 1_360);
    }

    #[test]
    fn tir_model_needs_17_panels() {
        let b = BandRadiance::hayabusa2_tir_bell();
        assert_eq!(b.nodes(), 170);
        assert!(b.flat_w_m2_sr_k4.is_none());
    }

    #[test]
    fn measured_table_needs_16_panels() {
        let b = BandRadiance::hayabusa2_tir();
        assert_eq!(b.nodes(), 160);
        let mut breaks = [0usize; MAX_PANELS + 1];
        let n = table_breaks(&TabulatedResponse::HAYABUSA2_TIR, &mut breaks).unwrap();
        assert_eq!(n, 16);
        // 5.01 um + 0.01 um per index: 11 panels of 0.99 um to 15.91 um, then the tail.
        assert_eq!(
            breaks[..=n],
            [
                0, 99, 198, 297, 396, 495, 594, 693, 792, 891, 990, 1090, 1150, 1200, 1240, 1270,
                1290
            ]
        );
        assert_eq!(b.response(), CameraResponse::default());
    }

    #[test]
    fn flat_integral_is_pi4_over_15() {
        assert!((flat_integral() / PI4_OVER_15 - 1.0).abs() < 1e-14);
        let k = flat_integral() * C1_W_UM4_M2_SR / c2_pow4();
        let want = STEFAN_BOLTZMANN_W_M2_K4 / core::f64::consts::PI;
        assert!((k / want - 1.0).abs() < 1e-13, "{k} vs {want}");
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        let b = BandRadiance::hayabusa2_tir();
        assert!(b.radiance_w_m2_sr(f64::NAN, 1.0).is_err());
        assert!(b.radiance_w_m2_sr(-1.0, 1.0).is_err());
        assert!(b.radiance_w_m2_sr(300.0, 1.5).is_err());
        assert!(b.radiance_f32(f32::INFINITY, 1.0).is_err());
        assert_eq!(b.radiance_w_m2_sr(0.0, 1.0), Ok(0.0));
        assert_eq!(b.radiance_f32(0.0, 1.0), Ok(0.0));
    }
}
