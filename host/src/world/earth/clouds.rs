//! Sub-grid cloud texture of the Earth ([`CloudField`], `earth_model.texture =
//! "clouds"`): an energy-conserving stochastic downscaling of the 1° OLR grid to the
//! camera's ~4 km pixels.
//!
//! At every point the brightness temperature is
//!
//! T = s · (T_clear + grain − min(m · ΔT_local, [`MAX_LOCAL_COLD_K`]))
//!
//! - T_clear(φ): the Eq. 10 temperature of the clear-sky zonal OLR climatology
//!   (`CLEAR_SKY_OLR_W_M2`, CERES EBAF), smooth in latitude;
//! - the cloud partition comes from the flux F̃ (the 1° fluxes interpolated bilinearly
//!   between cell centres, so no parameter jumps at cell borders): the share of clear
//!   flux that is missing, r = 1 − F̃/F_clear, sets the cloud fraction
//!   c = min(√(r / [`OVERCAST_DEFICIT`]), [`MAX_CLOUD_FRACTION`]) and a mean
//!   cloud-top flux F_clear − r·F_clear/c, i.e. a cloud top ΔT = 15.5…75 K colder than
//!   the clear surface;
//! - m = a steep smoothstep of (n − θ): n is a fractal field (value noise on the 3-D
//!   unit sphere × Earth radius, so there is no seam and no pole singularity; octaves
//!   with lattices of [`OCTAVE_LATTICE_KM`], amplitude ratio [`OCTAVE_GAIN`], the coarse
//!   ones stretched north–south so that bands run east–west) and θ its (1 − c)
//!   quantile, so about a share c of the area is cloudy; the transition width
//!   [`EDGE_WIDTH_SIGMA`] gives 1–3 px cloud edges at 4 km per pixel;
//! - ΔT_local grows from 0.7 ΔT at a cloud's edge to 1.3 ΔT in its core; the edge
//!   width grows with ΔT (cold high-cloud fringes are softer than low-cloud edges);
//! - deep convection (ΔT above [`DEEP_CONVECTION_ONSET_K`]): the coarse octaves weigh
//!   [`DEEP_COARSE_WEIGHT`] and the [`MESOSCALE_OCTAVES`] take their variance, the edge
//!   width grows with them, the tops are flat and carry their own texture
//!   ([`CLOUD_TOP_TEXTURE_K`] per σ of the finer octaves): clusters and anvils instead of
//!   one deck hundreds of km wide; beyond [`EDGE_WIDTH_FULL_DEPTH_K`] a deck's edge
//!   steps as a 40 K cloud and the rest of its depth comes inside it (cold cores,
//!   [`DEEP_CORE_WIDTHS`] edge widths in);
//! - cold fragments (session 38): where a fragment field z (a 20 km value-noise octave
//!   compressed ×3 north–south, plus a 150 km one that clusters them, in σ) exceeds
//!   [`FRAGMENT_THRESHOLD_SIGMA`] (anywhere, clear or cloudy), a top 18–40 K colder than the
//!   clear sky covers what is below it, with a 1–2 px edge: the small cold cloud elements
//!   and dashes (towers, cirrus fragments) of real 4 km imagery, 1–12 px across, which
//!   the cloud partition alone never made (its low clouds are 10–21 K deep, its deep
//!   ones wide decks). They are in the tile, so the cell's balance below keeps the flux.
//!   [`CloudField::with_cloud_fragments`] (session 52, the `realistic` presets) binds
//!   them to the clouds: a lower threshold at and inside a cloud, a higher one in clear
//!   air, and a top 18–28 K below the cloud (or clear sky) under it;
//! - a threshold shift δ and a scale s, one pair per 1° cell: the cell's mean σT⁴,
//!   measured on 16 × 16 points, equals its flux F. δ moves the cloud threshold θ + δ
//!   (more or less cloud where the noise realisation has too little or too much); s
//!   scales the whole temperature only for the rest δ cannot reach (within
//!   ±[`MAX_THRESHOLD_SHIFT_SIGMA`] σ). Within [`SHIFT_BLEND_DEG`] (δ) and
//!   [`BORDER_BLEND_DEG`] (s) of a cell border they blend with the neighbour's
//!   (smoothstep), so the field is continuous. Three
//!   passes, each lazy per cell: δ of the cell alone; δ again with the neighbours'
//!   first δ blended in; s from the mean with every final δ blended as rendered.
//!
//! The field is a deterministic function of (latitude, longitude, day, seed): the
//! octaves' rotations and offsets come from (seed, day), the lattice values from the
//! seed. Per 1° cell, the coarse octaves on a 9 × 9 node grid, the shifts δ and a tile
//! are computed once (thread-safe; the values do not depend on which thread or which
//! order): the tile holds the temperature before s on 1/[`TILE_NODES_PER_DEG`]° nodes
//! (both borders included, so neighbouring tiles agree on their shared border), and s
//! is the exact mean over the tile's bilinear interpolant (Gauss–Legendre), which is
//! what [`CloudField::temperature_k`] returns (times s), with the neighbours' s blended
//! in along the borders as rendered (`build_final_scale`): the rendered field itself
//! keeps each cell's flux. [`CloudField::fill`] builds every cell up front (the dataset
//! library does, once per day and seed); otherwise cells are built on first use.

use std::sync::OnceLock;

use tirroi_core::sensor::planck::STEFAN_BOLTZMANN_W_M2_K4;
use tirroi_core::sensor::rng::Xoshiro128pp;

use super::OlrGrid;
use super::builtin::{CLEAR_SKY_OLR_W_M2, profile};
use super::flux_to_temperature_k;
use crate::world::geom::Rotation;

/// Mean Earth radius the noise lives on, km (the lattice sizes are in km on it).
pub const NOISE_RADIUS_KM: f64 = 6371.0;
/// Kilometres per degree of latitude on [`NOISE_RADIUS_KM`].
pub const KM_PER_DEG: f64 = NOISE_RADIUS_KM * std::f64::consts::PI / 180.0;
/// Lattice spacing of each noise octave, km: the first [`COARSE_OCTAVES`] are cached per
/// 1° cell on a 1/8° node grid and interpolated; the rest are evaluated per ray.
pub const OCTAVE_LATTICE_KM: [f64; 7] = [400.0, 200.0, 100.0, 50.0, 25.0, 12.0, 6.0];
/// Octaves cached per cell (lattices ≥ 100 km, sampled every 1/8° ≈ 14 km).
pub const COARSE_OCTAVES: usize = 3;
/// Amplitude ratio of successive octaves (halving lattices): sets the spectral slope of
/// the cloud interiors; the sharp edges set the rest.
pub const OCTAVE_GAIN: f64 = 0.65;
/// North–south compression of the coarse octaves (their features run east–west, as
/// frontal cloud bands and cirrus streets).
pub const ZONAL_STRETCH: f64 = 2.0;
/// Width of the cloud-edge transition in units of the noise's standard deviation.
pub const EDGE_WIDTH_SIGMA: f64 = 0.10;
/// The edge width grows as (ΔT / [`MIN_CLOUD_COLD_K`])^this: deep, cold cloud fringes
/// (anvil cirrus) are much softer than low-cloud edges, so the 2-px steps stay within
/// the real scenes' range from trade cumulus to deep convection. (Evaluated as
/// x²·√x.)
pub const EDGE_WIDTH_DEPTH_EXPONENT: f64 = 2.5;
/// Share of a cloud's depth ΔT reached at its edge; the core reaches 2 − this (0.7:
/// a 15.5 K low cloud steps by ~11 K at its edge, the real mild scene's 2-px p99).
/// Session 38: was 0.65; with the clear grain at its stated amplitude (below) the
/// trade-cumulus patches' share of 2-px steps over 10 K fell to 0.65–0.75 % (range
/// 0.8–3.5 %, real 1.2 %); at 0.7 it is 1.1–1.3 %.
pub const EDGE_DEPTH_SHARE: f64 = 0.7;
/// Missing clear-sky flux share r at which a point is overcast: the cloud fraction is
/// c = √(r / r_overcast), so thin deficits come as many shallow (low) clouds and large
/// ones as deep, wide decks (r = 0.05: 41 % cloud; r = 0.45: 95 %).
pub const OVERCAST_DEFICIT: f64 = 0.3;
/// Largest cloud fraction of a point (overcast decks keep some gaps).
pub const MAX_CLOUD_FRACTION: f64 = 0.95;
/// Cloud tops are at least this much colder than the clear surface, K.
pub const MIN_CLOUD_COLD_K: f64 = 15.5;
/// ... and at most this much, K: deep-convective tops of 195–210 K over the Eq. 10
/// clear sky of the tropics (~268 K), so that the deepest 1° cells of the built-in field
/// (~100 W m⁻² at a cloud fraction of 0.95) are reached by the cloud partition itself.
/// (Session 24: was 40 K; cells below ~150 W m⁻² then saturated their threshold shift
/// at −[`MAX_THRESHOLD_SHIFT_SIGMA`] and the scale s took 3–7 % off the whole cell,
/// blended with the neighbours' over only [`BORDER_BLEND_DEG`]: 1°-cell blocks with
/// straight edges, 6–14 K steps along the borders.)
pub const MAX_CLOUD_COLD_K: f64 = 75.0;
/// Cap of the texture's local depth ΔT_local, K (the coldest convective cores with their
/// top texture; the 80 K upper bound on cloud-top depth).
pub const MAX_LOCAL_COLD_K: f64 = 80.0;
/// Cloud depth ΔT beyond which the edge width stops growing and the edge stops
/// deepening, K (the full deep-convective regime, [`DEEP_CONVECTION_FULL_K`]): growing
/// on as ΔT^[`EDGE_WIDTH_DEPTH_EXPONENT`], the edges of the deepest decks would spread
/// over several noise σ and the cloud field would fade into a uniform blend; stepping
/// by the full ΔT, they would put too many 2-px steps above 10 K.
pub const EDGE_WIDTH_FULL_DEPTH_K: f64 = 40.0;
/// The depth a cloud top has beyond [`EDGE_WIDTH_FULL_DEPTH_K`] is reached this many
/// edge widths inside the cloud (smoothstep): the deepest decks step at their edges as
/// a 40 K cloud and get colder towards their cores (the coldest tops of convective
/// clusters sit inside their anvils), so the 2-px steps at deck edges stay within the
/// real convective scene's range.
pub const DEEP_CORE_WIDTHS: f64 = 3.0;
/// Peak-to-peak amplitude of the clear-sky grain (unresolved trade cumulus, surface
/// and humidity texture), K: the finest (6 km) octave in its own σ, clipped at ±1 σ.
/// Session 38 fixed its normalisation: it divided by the whole noise's σ, ~17× the
/// finest octave's, so the grain was ~0.06 K rms instead of ~1 K, and the real image's
/// small steps were missing (2-px steps over 0.5 K: 31 % ours, 62 % real; now 66 %).
pub const CLEAR_GRAIN_K: f64 = 2.0;
/// Half-width of the band along each cell border where the scale s blends with the
/// neighbour cell's, in cell fractions (0.15° ≈ 17 km of latitude: about 4 px at 4 km
/// on each side). Session 24: was 0.05°; the deepest cells' s still differs from the
/// neighbours' by up to ~1.7 % (their threshold shift at its bound), a ~3.5 K step at
/// 210 K, which over 0.1° drew straight lines along the borders; over 0.3° it is a
/// gradient of about 0.5 K per pixel, under the cloud texture's.
pub const BORDER_BLEND_DEG: f64 = 0.15;
/// Half-width of the band along each cell border where the cloud threshold shift
/// blends with the neighbour's, degrees (0.35°: the threshold changes smoothly over
/// 80 km, so no cloud is cut along a cell border).
pub const SHIFT_BLEND_DEG: f64 = 0.35;
/// Cloud depth ΔT from which a cloud deck counts as deep convection, K: from here its
/// noise loses large-scale power and its tops flatten (fully at
/// [`DEEP_CONVECTION_FULL_K`]; smoothstep in between). Deep decks built from the same
/// octaves as low clouds are single blobs hundreds of km wide, whose 2-D spectrum is
/// steeper (−3.4…−3.7 over 8–200 km) than real convective scenes (−3.1).
pub const DEEP_CONVECTION_ONSET_K: f64 = 25.0;
/// Cloud depth ΔT at which the deep-convective regime is full, K (deeper tops, up to
/// [`MAX_CLOUD_COLD_K`], keep the full regime).
pub const DEEP_CONVECTION_FULL_K: f64 = 40.0;
/// Weight of the coarse (≥ 100 km) octaves in a full deep-convective regime: deep
/// convection comes as clusters of 20–100 km cells and anvils, not as one deck.
pub const DEEP_COARSE_WEIGHT: f64 = 0.3;
/// The mesoscale octaves (indices into [`OCTAVE_LATTICE_KM`]: 50 and 25 km) that take
/// the coarse octaves' lost variance in the deep-convective regime, so the noise's
/// variance (and so the cloud fraction of a threshold) is kept. The finer octaves
/// (12 and 6 km) keep their amplitude: amplifying them puts power below the tile's
/// 3.5 km node spacing.
pub const MESOSCALE_OCTAVES: std::ops::Range<usize> = 3..6;
/// Amplitude of a deep-convective cloud top's own texture per σ of the finer (12 and
/// 6 km) octaves, K: it restores the small-scale power that soft deep-cloud edges lack
/// (real convective scenes: spectrum slope −3.1; without it −3.4…−3.8 here), while the
/// 2-px steps stay within the real scenes' range (it is a few K, not an edge).
pub const CLOUD_TOP_TEXTURE_K: f64 = 3.0;
/// Amplitude of every other cloud top's texture per σ of the finer octaves, K, unless
/// a scene file sets it (`earth_model.cloud_top_texture_k`,
/// [`CloudField::with_cloud_top_texture`]): 0, flat tops (the `realistic` presets set
/// 5 since session 45; the other scene files and `tirroi earth-texture` keep 0). Real 4 km imagery has grainy tops (`tirroi earth-texture
/// --stats`, 5 × 5 σ on cloud tops: real 2.8 / 7.0 K at p50 / p90, ours 1.55 / 3.75 K
/// at 0; docs/scenes.md § Cloud-top texture).
pub const LOW_TOP_TEXTURE_K: f64 = 0.0;
/// The cloud-top texture's noise is clipped at this many σ (so it stays a few K).
pub const CLOUD_TOP_TEXTURE_CLIP: f64 = 2.0;
/// Lattice of the cold-fragment noise, km: a value-noise peak above a high threshold
/// is a few km to ~15 km across, 1–4 px at 4 km (session 38: real longwave imagery at
/// 4 km holds small cloud elements 16–40 K colder than their surroundings, 2.7 per
/// 10⁴ px in the mild reference scene; the cloud partition alone made none, as its low
/// clouds are 10–21 K deep and its deep ones wide decks).
pub const FRAGMENT_LATTICE_KM: f64 = 20.0;
/// East–west elongation of the fragments (their lattice compressed north–south by this):
/// the real scene's small cold elements are often dashes along the flow.
pub const FRAGMENT_STRETCH: f64 = 3.0;
/// Lattice of the noise that clusters the fragments, km: they come in groups tens to
/// hundreds of km wide (fields of towers, broken cirrus), not spread evenly.
pub const FRAGMENT_CLUSTER_LATTICE_KM: f64 = 150.0;
/// Weight of the cluster noise (in its σ) added to the fragment noise (in its σ).
pub const FRAGMENT_CLUSTER_GAIN: f64 = 1.0;
/// Threshold of the fragment field z = n_f/σ_f + gain·n_c/σ_c, in σ of z: above it a
/// point belongs to a fragment. Sets their number (calibrated on the cold-feature count
/// of `TextureStats`, see `tests/earth_texture.rs`).
pub const FRAGMENT_THRESHOLD_SIGMA: f64 = 2.55;
/// Width of a fragment's edge, σ of z: about 2 km across a dash and 6 km along it
/// (the 20 km lattice, compressed ×3), and no finer than the tile's 3.5 km nodes, so a
/// fragment steps within 1–2 px as a small cumulonimbus tower or a cirrus fragment does.
pub const FRAGMENT_EDGE_SIGMA: f64 = 0.3;
/// A fragment's top is this much colder than the clear sky at its edge, K ...
pub const FRAGMENT_MIN_COLD_K: f64 = 18.0;
/// ... and this much at its core, K (tops of congestus and small cumulonimbus cells).
pub const FRAGMENT_MAX_COLD_K: f64 = 40.0;
/// Rise of z above the threshold over which a fragment reaches its core depth, σ of z.
pub const FRAGMENT_CORE_SIGMA: f64 = 0.6;
/// Threshold of the fragment field in clear air, σ of z, with
/// [`CloudField::with_cloud_fragments`]: the real mild scene holds 0.2 compact cold
/// features per 10⁴ px of clear background against 3–47 among clouds, so clear air
/// keeps only the rare fragment (calibrated with the next two on `tirroi earth-texture
/// --stats`, 24 patches: 3.9 / 2.45 / 0.5 left 18 % of them on clear background, these
/// 17 %, the real scene 4 %; a higher clear threshold no longer moved it, as the rest
/// lie at clouds' edges).
pub const CLOUD_FRAGMENT_CLEAR_THRESHOLD_SIGMA: f64 = 4.5;
/// Threshold of the fragment field at and inside a cloud, σ of z, with
/// [`CloudField::with_cloud_fragments`]: sets their number (compact cold features 3.21
/// per 10⁴ px over 24 patches, the real mild scene 3.02; 2.2 gave 5.96).
pub const CLOUD_FRAGMENT_THRESHOLD_SIGMA: f64 = 2.4;
// `CloudField::fragment` leaves early under the cloud threshold, the lower of the two.
const _: () = assert!(CLOUD_FRAGMENT_THRESHOLD_SIGMA <= CLOUD_FRAGMENT_CLEAR_THRESHOLD_SIGMA);
/// Distance outside a cloud's threshold over which the fragment threshold falls from
/// its clear-air to its cloud value, noise σ: about one edge width of a deep cloud, so
/// the fragments cluster at a cloud's fringe as well as inside it (0.5 put 1.22 per 10⁴
/// px on clear background).
pub const CLOUD_FRAGMENT_REACH_SIGMA: f64 = 0.3;
/// A cloud-bound fragment's top at its core lies this much below the cloud or clear sky
/// under it, K (the real mild scene's compact cold features: 21 K below their
/// surroundings at the median, 29 K at p90, 44.5 K at most).
pub const CLOUD_FRAGMENT_MAX_COLD_K: f64 = 28.0;
/// Largest radius of [`CloudField::with_regional_balance`], cells (a 9 × 9 window:
/// 900 km, the scale of the largest cloud systems a frame shows).
pub const MAX_REGIONAL_RADIUS_CELLS: usize = 4;
/// Step of the regional balance's derivative of a cell's flux with its shift, noise σ.
const REGIONAL_STEP_SIGMA: f64 = 0.05;
/// Largest correction of a window's mean shift by the regional balance, noise σ (a
/// window of clear or overcast cells, whose flux no shift moves, keeps its mean shift).
const MAX_REGIONAL_CORRECTION_SIGMA: f64 = 2.0;
/// Sample points per axis of a cell's energy balance (16 × 16, cell-centred).
pub const BALANCE_SAMPLES: usize = 16;
/// Largest shift of a cell's cloud threshold its balance may use, noise σ (session 24:
/// was 6; the deepest cells need their cores, [`DEEP_CORE_WIDTHS`] edge widths inside
/// the clouds, over most of their area).
pub const MAX_THRESHOLD_SHIFT_SIGMA: f64 = 12.0;
/// Margin of the local clear sky above the Eq. 10 temperature of the interpolated flux,
/// K: where a cell is warmer than the clear-sky climatology its clear sky warms with it.
pub const CLEAR_MARGIN_K: f64 = 1.0;
/// Where a cell's flux lies beyond what its threshold shift can reach (clearer than its
/// texture without clouds, or colder than overcast), the shift stops where the flux is
/// this share of the reachable range short of that end. Session 38: it went to
/// ±[`MAX_THRESHOLD_SHIFT_SIGMA`] (2.2 % of the cells of field (7201, 0)), 12 σ from a
/// neighbour's shift of about 0, and the blended threshold then cut the neighbour's
/// clouds along the cell's border: straight-edged clear or overcast blocks
/// (`realistic-no-target-clean` seed 7201, frame 2). Now 0 cells at the bound and
/// neighbouring shifts ≥ 7 σ apart on 0.9 % of the borders (4.0 % before).
const UNREACHED_SHARE: f64 = 0.005;
/// Most false-position steps of a cell's threshold shift (it stops once the balance
/// points' mean flux is within [`SOLVE_TOLERANCE`]; the scale s takes the rest).
const SOLVE_STEPS: usize = 40;
/// Relative flux error at which a threshold shift is taken (10⁻⁴: far below the
/// 0.5 % the cells keep; s removes it).
const SOLVE_TOLERANCE: f64 = 1e-4;
/// Newton steps of a cell's final scale (the quartic is monotone and near-linear
/// around the stand-alone s, a few steps reach machine precision).
const FINAL_SCALE_NEWTON_STEPS: usize = 8;
/// Tile nodes per degree: 1/32° ≈ 3.5 km, finer than the camera's ~4 km pixel, so the
/// renderer interpolates bilinearly between nodes at about the pixel scale.
pub const TILE_NODES_PER_DEG: usize = 32;
/// Tile nodes per axis (both borders included).
const TILE_NODES: usize = TILE_NODES_PER_DEG + 1;
/// Temperature of a tile's code 0, K.
const TILE_OFFSET_K: f64 = 100.0;
/// Temperature step of a tile's code, K (0.005 K: 100…427 K in 16 bits; the
/// quantisation is far below the 0.5 K of the real data and is in the balance).
const TILE_STEP_K: f64 = 0.005;
/// Gauss–Legendre nodes (on [0, 1]) and weights per tile node interval and axis for a
/// tile's scale s: 3 points integrate a polynomial of degree ≤ 5 exactly, and σT⁴ of
/// the bilinear interpolant is of degree 4 along each axis, so s is measured on the
/// exact mean of what is rendered (up to the cos φ weight's curvature, ~10⁻⁸ over a
/// 1/32° interval).
const GAUSS3: [(f64, f64); 3] = [
    (0.112_701_665_379_258_3, 5.0 / 18.0),
    (0.5, 8.0 / 18.0),
    (0.887_298_334_620_741_7, 5.0 / 18.0),
];
/// Every [`GAUSS3`] point of a tile axis: (fraction of the cell in [0, 1], weight), 3
/// per node interval, in order.
fn tile_gauss_points() -> impl Iterator<Item = (f64, f64)> {
    let last = (TILE_NODES - 1) as f64;
    (0..TILE_NODES - 1).flat_map(move |k| GAUSS3.map(|(x, w)| ((k as f64 + x) / last, w)))
}
/// Coarse node grid per cell axis (1/8° spacing, both borders included).
const NODES: usize = 9;
/// Lattice table side (values repeat every 32 lattice cells; each octave is rotated and
/// offset differently, so the repeat never lines up).
const TABLE: usize = 32;
/// Quantiles kept of the noise's distribution.
const QUANTILES: usize = 256;
/// Random directions the noise's distribution is measured on.
const DISTRIBUTION_SAMPLES: usize = 8192;

/// One noise octave: rotation (rows), frequency and offset.
#[derive(Debug, Clone)]
struct Octave {
    rot: [[f64; 3]; 3],
    inv_lattice_km: f64,
    stretch: f64,
    offset: [f64; 3],
    amplitude: f64,
}

impl Octave {
    /// An octave of lattice `lattice_km`, compressed north–south by `stretch`, with a
    /// uniformly random rotation (Shoemake's random unit quaternion) and offset drawn
    /// from `unif` (six draws in [0, 1)).
    fn random(
        unif: &mut impl FnMut() -> f64,
        lattice_km: f64,
        stretch: f64,
        amplitude: f64,
    ) -> Octave {
        let (u1, u2, u3) = (unif(), unif(), unif());
        let tau = 2.0 * std::f64::consts::PI;
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        let [x, y, z, w] = [
            a * libm::sin(tau * u2),
            a * libm::cos(tau * u2),
            b * libm::sin(tau * u3),
            b * libm::cos(tau * u3),
        ];
        let rot = Rotation::from_quaternion([w, x, y, z]).0;
        let offset = [unif() * 1e3, unif() * 1e3, unif() * 1e3];
        Octave {
            rot,
            inv_lattice_km: 1.0 / lattice_km,
            stretch,
            offset,
            amplitude,
        }
    }
}

/// What a cell caches: coarse noise at its 9 × 9 nodes and its balance factors.
#[derive(Debug, Clone)]
struct Cell {
    coarse: [f32; NODES * NODES],
    /// Threshold shift balancing the cell on its own (no blending), σ units × σ.
    shift: f64,
}

/// A cell's final threshold shift, given its neighbours' (stand-alone) blended in.
#[derive(Debug, Clone, Copy)]
struct Balance {
    shift: f64,
}

/// What the renderer reads of a cell: its temperatures before the scale s on a
/// [`TILE_NODES`]² node grid (both borders included, shared with the neighbours),
/// quantised to [`TILE_STEP_K`], and the cell's scale s.
#[derive(Debug, Clone)]
struct Tile {
    /// (T − [`TILE_OFFSET_K`]) / [`TILE_STEP_K`], rounded, row-major (south → north);
    /// inline, so a lookup follows one pointer (the cell's box) to its nodes.
    t: [u16; TILE_NODES * TILE_NODES],
    /// The cell's scale s: its flux over the tile's mean σT⁴, to the ¼ power.
    s: f64,
}

/// A point's texture inputs before its cell's threshold shift.
#[derive(Debug, Clone, Copy)]
struct Point {
    t_clear: f64,
    dt: f64,
    theta: f64,
    n: f64,
    /// Edge transition width (grows with ΔT), noise units.
    width: f64,
    /// Weight of the deep-convective regime, 0…1 (from ΔT).
    deep: f64,
    /// Cloud-top texture of a deep-convective cloud, K (added to its depth).
    top_texture: f64,
    /// Texture of the other clouds' tops, K ([`CloudField::with_cloud_top_texture`]; 0 by
    /// default), faded in from the cloud's edge as the core deepens.
    low_texture: f64,
    /// The clear-sky temperature without its grain, K: the reference of session 38's
    /// fragment tops.
    fragment_clear_k: f64,
    /// The fragment field in its σ (see [`CloudField::fragment`]).
    z_fragment: f64,
}

/// The cloud texture of one daily OLR grid (see the module docs). Cheap to clone only
/// before use (the per-cell caches are cloned with it).
#[derive(Debug)]
pub struct CloudField {
    flux: Vec<f32>,
    table: Vec<f32>,
    octaves: Vec<Octave>,
    /// The cold fragments' noise and the noise that clusters them.
    fragment_octaves: [Octave; 2],
    /// Standard deviation of each of `fragment_octaves`.
    fragment_sigma: [f64; 2],
    quantiles: [f64; QUANTILES + 1],
    sigma: f64,
    /// Standard deviation of the octaves finer than the mesoscale ones (σ × their
    /// share of the variance, square-rooted).
    small_sigma: f64,
    /// Σ a² of the coarse octaves over that of the mesoscale ones.
    coarse_over_meso_var: f64,
    /// Texture of the tops outside deep convection, K per σ of the finer octaves
    /// ([`LOW_TOP_TEXTURE_K`] unless set).
    low_top_texture_k: f64,
    /// Radius, cells, of the window of stand-alone threshold shifts each cell's final
    /// shift is the mean of (0: each cell balanced on its own, the default; see
    /// [`CloudField::with_regional_balance`]).
    regional_radius_cells: usize,
    /// Cold fragments bound to the clouds ([`CloudField::with_cloud_fragments`]).
    cloud_fragments: bool,
    /// Every cell's regional shift (the window's mean stand-alone shift plus the window's
    /// correction, [`CloudField::regional_shift`]), built on use.
    regional_shifts: Vec<OnceLock<f64>>,
    /// Every cell's mean stand-alone shift over its window, built on use.
    mean_shifts: Vec<OnceLock<f64>>,
    /// Every cell's flux at the mean shifts and its derivative, built on use.
    mean_shift_fluxes: Vec<OnceLock<(f64, f64)>>,
    /// Every cell's flux at the regional shifts (its target with a regional balance),
    /// W m⁻², built on use.
    regional_fluxes: Vec<OnceLock<f64>>,
    clear_t_k: Vec<f64>,
    cells: Vec<OnceLock<Box<Cell>>>,
    balance: Vec<OnceLock<Balance>>,
    tiles: Vec<OnceLock<Box<Tile>>>,
    /// Every cell's final scale s (with the border blend, see
    /// [`CloudField::build_final_scale`]), built on use.
    final_scales: Vec<OnceLock<f64>>,
    /// Every cell's final scale s in one flat array, row-major, once [`CloudField::fill`] has
    /// built them all: the border blend reads up to four neighbours' s per ray, and
    /// this spares it the pointer chase into each neighbour's tile.
    scales: OnceLock<Vec<f64>>,
}

impl Clone for CloudField {
    fn clone(&self) -> Self {
        CloudField {
            flux: self.flux.clone(),
            table: self.table.clone(),
            octaves: self.octaves.clone(),
            fragment_octaves: self.fragment_octaves.clone(),
            fragment_sigma: self.fragment_sigma,
            quantiles: self.quantiles,
            sigma: self.sigma,
            small_sigma: self.small_sigma,
            coarse_over_meso_var: self.coarse_over_meso_var,
            low_top_texture_k: self.low_top_texture_k,
            regional_radius_cells: self.regional_radius_cells,
            cloud_fragments: self.cloud_fragments,
            regional_shifts: self.regional_shifts.clone(),
            mean_shifts: self.mean_shifts.clone(),
            mean_shift_fluxes: self.mean_shift_fluxes.clone(),
            regional_fluxes: self.regional_fluxes.clone(),
            clear_t_k: self.clear_t_k.clone(),
            cells: self.cells.clone(),
            balance: self.balance.clone(),
            tiles: self.tiles.clone(),
            final_scales: self.final_scales.clone(),
            scales: self.scales.clone(),
        }
    }
}

/// Clear-sky table step, degrees of latitude.
const CLEAR_STEP_DEG: f64 = 0.1;

/// Weights of the (previous, own, next) cell at fraction `t` ∈ [0, 1] of a cell along
/// one axis: ½ on a border, smoothly 0 at `width` (cell fractions) inside.
fn blend_weights(t: f64, width: f64) -> [f64; 3] {
    let side = |d: f64| 0.5 * smoothstep(1.0 - d / width);
    let (a, c) = (side(t), side(1.0 - t));
    [a, 1.0 - a - c, c]
}

/// One empty lazy slot per 1° cell of the grid.
fn per_cell<T>() -> Vec<OnceLock<T>> {
    (0..OlrGrid::ROWS * OlrGrid::COLS)
        .map(|_| OnceLock::new())
        .collect()
}

fn smoothstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// Unit vector of (lat, lon) in the Earth-fixed frame (z north, x at longitude 0).
pub fn unit_vector(lat_deg: f64, lon_deg: f64) -> [f64; 3] {
    let (sl, cl) = (
        libm::sin(lat_deg.to_radians()),
        libm::cos(lat_deg.to_radians()),
    );
    let (so, co) = (
        libm::sin(lon_deg.to_radians()),
        libm::cos(lon_deg.to_radians()),
    );
    [cl * co, cl * so, sl]
}

impl CloudField {
    /// The texture of `grid` (W m⁻², the map's own, eclipse-scaled if so) for `day` and
    /// `seed`. Costs ~10 ms (the noise's distribution); cells are filled on use.
    pub fn new(grid: &OlrGrid, day: u64, seed: u64) -> CloudField {
        let mut rng = Xoshiro128pp::seed_from_u64(crate::seed::splitmix64(seed ^ 0xC10D_5EED));
        let table: Vec<f32> = (0..TABLE * TABLE * TABLE)
            .map(|_| (f64::from(rng.next_u32()) / f64::from(u32::MAX) * 2.0 - 1.0) as f32)
            .collect();
        let mut drng = Xoshiro128pp::seed_from_u64(crate::seed::splitmix64(
            seed ^ crate::seed::splitmix64(day.wrapping_add(0xDA7)),
        ));
        let mut unif = || f64::from(drng.next_u32()) / 4_294_967_296.0;
        let mut amplitude = 1.0;
        let octaves: Vec<Octave> = OCTAVE_LATTICE_KM
            .iter()
            .enumerate()
            .map(|(i, &l)| {
                let stretch = if i < COARSE_OCTAVES {
                    ZONAL_STRETCH
                } else {
                    1.0
                };
                let o = Octave::random(&mut unif, l, stretch, amplitude);
                amplitude *= OCTAVE_GAIN;
                o
            })
            .collect();
        // The fragments' own stream, so the cloud partition's octaves are those of
        // the texture without fragments.
        let mut frng = Xoshiro128pp::seed_from_u64(crate::seed::splitmix64(
            seed ^ crate::seed::splitmix64(day.wrapping_add(0xF4A6)),
        ));
        let mut funif = || f64::from(frng.next_u32()) / 4_294_967_296.0;
        let fragment_octaves = [
            Octave::random(&mut funif, FRAGMENT_LATTICE_KM, FRAGMENT_STRETCH, 1.0),
            Octave::random(&mut funif, FRAGMENT_CLUSTER_LATTICE_KM, 1.0, 1.0),
        ];
        let rows = (180.0 / CLEAR_STEP_DEG) as usize + 1;
        let clear_t_k = (0..rows)
            .map(|i| {
                flux_to_temperature_k(profile(
                    &CLEAR_SKY_OLR_W_M2,
                    i as f64 * CLEAR_STEP_DEG - 90.0,
                ))
            })
            .collect();
        let mut field = CloudField {
            flux: grid.values().to_vec(),
            table,
            octaves,
            fragment_octaves,
            fragment_sigma: [1.0; 2],
            quantiles: [0.0; QUANTILES + 1],
            sigma: 1.0,
            small_sigma: 1.0,
            coarse_over_meso_var: 1.0,
            low_top_texture_k: LOW_TOP_TEXTURE_K,
            regional_radius_cells: 0,
            cloud_fragments: false,
            regional_shifts: per_cell(),
            mean_shifts: per_cell(),
            mean_shift_fluxes: per_cell(),
            regional_fluxes: per_cell(),
            clear_t_k,
            cells: per_cell(),
            balance: per_cell(),
            tiles: per_cell(),
            final_scales: per_cell(),
            scales: OnceLock::new(),
        };
        // The noise's distribution on random directions (fixed stream: deterministic).
        let mut srng = Xoshiro128pp::seed_from_u64(0x5A3F_1E5D);
        let mut fragment_moments = [(0.0f64, 0.0f64); 2];
        let mut values: Vec<f64> = (0..DISTRIBUTION_SAMPLES)
            .map(|_| {
                let z = f64::from(srng.next_u32()) / 4_294_967_296.0 * 2.0 - 1.0;
                let phi = f64::from(srng.next_u32()) / 4_294_967_296.0 * std::f64::consts::TAU;
                let r = (1.0 - z * z).sqrt();
                let p = [r * libm::cos(phi), r * libm::sin(phi), z];
                for (k, o) in field.fragment_octaves.iter().enumerate() {
                    let v = field.octave_noise(o, p);
                    fragment_moments[k].0 += v;
                    fragment_moments[k].1 += v * v;
                }
                field.noise(p, 0..field.octaves.len())
            })
            .collect();
        let count = DISTRIBUTION_SAMPLES as f64;
        field.fragment_sigma = fragment_moments.map(|(s, s2)| {
            let m = s / count;
            (s2 / count - m * m).max(1e-12).sqrt()
        });
        values.sort_by(f64::total_cmp);
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        let var = values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / values.len() as f64;
        field.sigma = var.sqrt();
        let all = Self::octave_var(&field.octaves, 0..field.octaves.len());
        let small = Self::octave_var(&field.octaves, MESOSCALE_OCTAVES.end..field.octaves.len());
        field.small_sigma = field.sigma * (small / all).sqrt();
        field.coarse_over_meso_var = Self::octave_var(&field.octaves, 0..COARSE_OCTAVES)
            / Self::octave_var(&field.octaves, MESOSCALE_OCTAVES);
        for (q, slot) in field.quantiles.iter_mut().enumerate() {
            let idx = (q * (values.len() - 1)) / QUANTILES;
            *slot = values[idx];
        }
        field
    }

    /// The field with the tops outside deep convection textured by `k` K per σ of the
    /// finer (12 and 6 km) octaves, clipped at ±[`CLOUD_TOP_TEXTURE_CLIP`] σ (0: flat,
    /// [`LOW_TOP_TEXTURE_K`]; NaN or negative values count as 0). Call it on a new field,
    /// before any temperature is read: cells are built, and cached, on first use. Each
    /// cell's flux is kept as before (the texture is in the tile the balance measures).
    pub fn with_cloud_top_texture(mut self, k: f64) -> CloudField {
        self.low_top_texture_k = if k.is_finite() { k.max(0.0) } else { 0.0 };
        self
    }

    /// The field with each cell's cloud threshold shift the mean of the stand-alone
    /// shifts of the (2 · `radius_cells` + 1)² cells around it (rows beyond the poles
    /// left out), and each cell's flux what that renders (0: every cell balanced on its
    /// own, the default). With the shift of a cell alone, the cloud partition of a
    /// smooth 1° flux field is the same share of every cell: the shift cancels the
    /// noise's mean over the cell, so the octaves coarser than a cell cannot gather
    /// clouds into masses and each cell holds its own blotches (session 51: a third of
    /// the real image's cloud masses at 60–400 km). With a regional shift the clouds
    /// follow the coarse octaves across cells (masses and bands), and the 1° fluxes
    /// vary around the grid's as the masses do (up to ~30 % in a cell); their mean over
    /// 6 × 6 cells stays within 2.4 % of the grid's, +0.17 % on average
    /// (`tests/earth_texture.rs`). `radius_cells` above [`MAX_REGIONAL_RADIUS_CELLS`] is
    /// taken as it. Call it on a new field, before any temperature is read.
    pub fn with_regional_balance(mut self, radius_cells: usize) -> CloudField {
        self.regional_radius_cells = radius_cells.min(MAX_REGIONAL_RADIUS_CELLS);
        self
    }

    /// The field with its cold fragments bound to the clouds (`true`; `false`, the
    /// default: the fragments of session 38, anywhere, their tops 18–40 K below the clear
    /// sky, hidden by colder cloud). The real mild scene's compact cold features (at
    /// most 60 px, more than 16 K below their 11 × 11 median) lie among clouds, on a
    /// background at least 5 K below the clear sea, for 96 % of them (0.2 per 10⁴ px of
    /// clear background against 3–47 among clouds), and reach 224 K; the session-38
    /// fragments did so for 14 % (median of 8 patches) and never lay more than 40 K
    /// below the clear sky (session 52, `tirroi earth-texture --stats`). Here the
    /// fragment field's threshold is lower at and near a cloud than in clear air, and a
    /// fragment's top lies below the cloud (or clear sky) under it: a tower out of a
    /// deck, a cold core in a cirrus band. Call it on a new field, before any
    /// temperature is read; each cell keeps its flux (the fragments are in the tile the
    /// balance measures).
    pub fn with_cloud_fragments(mut self, on: bool) -> CloudField {
        self.cloud_fragments = on;
        self
    }

    /// Sum of the octaves in `range` at unit vector `p`.
    fn noise(&self, p: [f64; 3], range: std::ops::Range<usize>) -> f64 {
        self.octaves[range]
            .iter()
            .map(|o| self.octave_noise(o, p))
            .sum()
    }

    /// One octave `o` at unit vector `p` (its amplitude included).
    #[inline]
    fn octave_noise(&self, o: &Octave, p: [f64; 3]) -> f64 {
        let s = NOISE_RADIUS_KM * o.inv_lattice_km;
        let v = [p[0] * s, p[1] * s, p[2] * s * o.stretch];
        let q = [
            o.rot[0][0] * v[0] + o.rot[0][1] * v[1] + o.rot[0][2] * v[2] + o.offset[0],
            o.rot[1][0] * v[0] + o.rot[1][1] * v[1] + o.rot[1][2] * v[2] + o.offset[1],
            o.rot[2][0] * v[0] + o.rot[2][1] * v[1] + o.rot[2][2] * v[2] + o.offset[2],
        ];
        o.amplitude * self.value_noise(q)
    }

    /// Trilinear value noise (smoothstep weights) of the lattice table at `q`.
    #[inline]
    fn value_noise(&self, q: [f64; 3]) -> f64 {
        let f = [q[0].floor(), q[1].floor(), q[2].floor()];
        let t = [q[0] - f[0], q[1] - f[1], q[2] - f[2]];
        let w = t.map(|t| t * t * (3.0 - 2.0 * t));
        let m = TABLE as i64 - 1;
        let i = f.map(|f| (f as i64) & m);
        let j = i.map(|i| (i + 1) & m);
        let n = TABLE as i64;
        let at = |x: i64, y: i64, z: i64| f64::from(self.table[(x + n * (y + n * z)) as usize]);
        let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
        let x00 = lerp(at(i[0], i[1], i[2]), at(j[0], i[1], i[2]), w[0]);
        let x10 = lerp(at(i[0], j[1], i[2]), at(j[0], j[1], i[2]), w[0]);
        let x01 = lerp(at(i[0], i[1], j[2]), at(j[0], i[1], j[2]), w[0]);
        let x11 = lerp(at(i[0], j[1], j[2]), at(j[0], j[1], j[2]), w[0]);
        lerp(lerp(x00, x10, w[1]), lerp(x01, x11, w[1]), w[2])
    }

    /// Quantile q ∈ [0, 1] of the noise's distribution (linear between the kept ones).
    fn quantile(&self, q: f64) -> f64 {
        let x = q.clamp(0.0, 1.0) * QUANTILES as f64;
        let i = (x as usize).min(QUANTILES - 1);
        let t = x - i as f64;
        self.quantiles[i] + (self.quantiles[i + 1] - self.quantiles[i]) * t
    }

    /// Clear-sky temperature at latitude `lat_deg`, K.
    fn clear_t(&self, lat_deg: f64) -> f64 {
        let x = ((lat_deg + 90.0) / CLEAR_STEP_DEG).clamp(0.0, (self.clear_t_k.len() - 1) as f64);
        let i = (x as usize).min(self.clear_t_k.len() - 2);
        let t = x - i as f64;
        self.clear_t_k[i] + (self.clear_t_k[i + 1] - self.clear_t_k[i]) * t
    }

    /// The 1° flux interpolated bilinearly between cell centres, W m⁻².
    fn flux_at(&self, lat_deg: f64, lon_deg: f64) -> f64 {
        let y = (lat_deg + 89.5).clamp(0.0, (OlrGrid::ROWS - 1) as f64);
        let r0 = (y as usize).min(OlrGrid::ROWS - 2);
        let ty = y - r0 as f64;
        let x = lon_deg.rem_euclid(360.0) - 0.5;
        let fx = x.floor();
        let tx = x - fx;
        let n = OlrGrid::COLS as i64;
        let c0 = (fx as i64).rem_euclid(n) as usize;
        let c1 = (c0 + 1) % OlrGrid::COLS;
        let at = |r: usize, c: usize| f64::from(self.flux[r * OlrGrid::COLS + c]);
        let a = at(r0, c0) + (at(r0, c1) - at(r0, c0)) * tx;
        let b = at(r0 + 1, c0) + (at(r0 + 1, c1) - at(r0 + 1, c0)) * tx;
        a + (b - a) * ty
    }

    /// What a point needs before its cell's threshold shift: (clear temperature with
    /// grain, K; cloud depth ΔT, K; base threshold θ; noise n).
    /// `n` holds the noise's (coarse, mesoscale, finer) parts; they are weighted by the
    /// deep-convective regime of the point's ΔT.
    /// `z_fragment` is the fragment field in its σ (see [`FRAGMENT_THRESHOLD_SIGMA`]).
    fn point(
        &self,
        lat_deg: f64,
        lon_deg: f64,
        n: [f64; 3],
        n_fine: f64,
        z_fragment: f64,
    ) -> Point {
        let n_small = n[2];
        let f = self.flux_at(lat_deg, lon_deg);
        let t_clear = self
            .clear_t(lat_deg)
            .max(flux_to_temperature_k(f) + CLEAR_MARGIN_K);
        let f_clear = STEFAN_BOLTZMANN_W_M2_K4 * t_clear.powi(4);
        let r = (1.0 - f / f_clear).clamp(0.0, 0.9);
        let c = (r / OVERCAST_DEFICIT).sqrt().min(MAX_CLOUD_FRACTION);
        let grain = CLEAR_GRAIN_K * (n_fine / self.small_sigma).clamp(-1.0, 1.0) * 0.5;
        let (dt, theta) = if c <= 1e-4 {
            (MIN_CLOUD_COLD_K, self.quantile(1.0 - 1e-4))
        } else {
            let f_top = (f_clear - r * f_clear / c).max(1.0);
            let dt =
                (t_clear - flux_to_temperature_k(f_top)).clamp(MIN_CLOUD_COLD_K, MAX_CLOUD_COLD_K);
            (dt, self.quantile(1.0 - c))
        };
        // High (cold, deep) cloud edges are softer than low ones: the width grows with
        // ΔT (thin cirrus fringes of anvils and fronts).
        let depth = dt.min(EDGE_WIDTH_FULL_DEPTH_K) / MIN_CLOUD_COLD_K;
        let width = EDGE_WIDTH_SIGMA * self.sigma * depth * depth * depth.sqrt();
        let deep = smoothstep(
            (dt - DEEP_CONVECTION_ONSET_K) / (DEEP_CONVECTION_FULL_K - DEEP_CONVECTION_ONSET_K),
        );
        // The mesoscale gain g steepens the noise's gradient about g times: the edge
        // width (in noise units) grows with it, so the edges keep their width in km.
        let (n, width) = if deep > 0.0 {
            let (wc, gm) = self.deep_weights(deep);
            (wc * n[0] + gm * n[1] + n[2], width * gm)
        } else {
            (n[0] + n[1] + n[2], width)
        };
        // Deep cloud tops are not flat at the camera's scale (overshooting tops, gravity
        // waves, anvil cirrus): the finer octaves, in their own σ, give them texture.
        let texture =
            (n_small / self.small_sigma).clamp(-CLOUD_TOP_TEXTURE_CLIP, CLOUD_TOP_TEXTURE_CLIP);
        let top_texture = deep * CLOUD_TOP_TEXTURE_K * texture;
        // The other tops: the field's own amplitude (0 by default, flat), faded in from
        // the cloud's edge where it is used (the edges keep their steps).
        let low_texture = (1.0 - deep) * self.low_top_texture_k * texture;
        Point {
            t_clear: t_clear + grain,
            dt,
            theta,
            n,
            width,
            deep,
            top_texture,
            low_texture,
            fragment_clear_k: t_clear,
            z_fragment,
        }
    }

    fn cell(&self, row: usize, col: usize) -> &Cell {
        self.cells[row * OlrGrid::COLS + col].get_or_init(|| Box::new(self.build_cell(row, col)))
    }

    fn balance(&self, row: usize, col: usize) -> Balance {
        *self.balance[row * OlrGrid::COLS + col].get_or_init(|| self.build_balance(row, col))
    }

    fn tile(&self, row: usize, col: usize) -> &Tile {
        self.tiles[row * OlrGrid::COLS + col].get_or_init(|| Box::new(self.build_tile(row, col)))
    }

    /// The cell's final scale s (from the flat array once [`CloudField::fill`] ran).
    #[inline]
    fn final_scale(&self, row: usize, col: usize) -> f64 {
        let i = row * OlrGrid::COLS + col;
        match self.scales.get() {
            Some(scales) => scales[i],
            None => *self.final_scales[i].get_or_init(|| self.build_final_scale(row, col)),
        }
    }

    /// The cell's final scale s: what is rendered within [`BORDER_BLEND_DEG`] of a border
    /// is the tile times the blend of the own s with the neighbours', so a stand-alone s
    /// (the tile's) misses the flux by up to ~0.7 % where neighbours' s differ. With
    /// the neighbours' stand-alone s in the blend, the own s solves
    /// mean((w·s + b)⁴·σt⁴) = F exactly on the tile's interpolant (the [`GAUSS3`]
    /// points; w the own blend weight, b the neighbours' blended s; a quartic in s,
    /// Newton from the stand-alone s). Left: the neighbours' own change from their
    /// stand-alone s, second order in the blend band's share of the cell.
    fn build_final_scale(&self, row: usize, col: usize) -> f64 {
        let tile = self.tile(row, col);
        let mut nb = [[0.0f64; 3]; 3];
        for (dr, line) in nb.iter_mut().enumerate() {
            for (dc, v) in line.iter_mut().enumerate() {
                if dr != 1 || dc != 1 {
                    let (r, c) = Self::neighbour(row, col, dr, dc);
                    *v = self.tile(r, c).s;
                }
            }
        }
        let lat0 = row as f64 - 90.0;
        // (fraction, Gauss weight, blend weights) of every Gauss point along an axis.
        let gauss: Vec<(f64, f64, [f64; 3])> = tile_gauss_points()
            .map(|(u, w)| (u, w, blend_weights(u, BORDER_BLEND_DEG)))
            .collect();
        // Moments m_k = Σ weight · C(4, k)·w^k·b^(4−k)·σt⁴: flux(s) = Σ m_k s^k / Σ weight.
        let mut m = [0.0f64; 5];
        let mut wsum = 0.0;
        for &(u, wu, wy) in &gauss {
            let wl = wu * libm::cos((lat0 + u).to_radians());
            for &(v, wv, wx) in &gauss {
                let t = tile.interpolate(u, v);
                let q = wl * wv * STEFAN_BOLTZMANN_W_M2_K4 * (t * t) * (t * t);
                wsum += wl * wv;
                if wy[1] == 1.0 && wx[1] == 1.0 {
                    // Away from the borders only the own s counts.
                    m[4] += q;
                    continue;
                }
                let mut b = 0.0;
                for (dr, wyr) in wy.iter().enumerate() {
                    for (dc, wxc) in wx.iter().enumerate() {
                        b += wyr * wxc * nb[dr][dc];
                    }
                }
                let own = wy[1] * wx[1];
                let (o2, b2) = (own * own, b * b);
                m[0] += q * b2 * b2;
                m[1] += q * 4.0 * own * b2 * b;
                m[2] += q * 6.0 * o2 * b2;
                m[3] += q * 4.0 * o2 * own * b;
                m[4] += q * o2 * o2;
            }
        }
        let target = self.target(row, col) * wsum;
        let mut x = tile.s;
        for _ in 0..FINAL_SCALE_NEWTON_STEPS {
            let f = m[0] + x * (m[1] + x * (m[2] + x * (m[3] + x * m[4])));
            let df = m[1] + x * (2.0 * m[2] + x * (3.0 * m[3] + x * 4.0 * m[4]));
            if df <= 0.0 {
                break;
            }
            x -= (f - target) / df;
        }
        if x.is_finite() && x > 0.0 { x } else { tile.s }
    }

    /// The cell's rendered tile: every node's temperature with the final shifts
    /// blended as in the module docs, then s from the mean σT⁴ of the bilinear
    /// interpolant the renderer reads (its exact mean: [`GAUSS3`] points per node interval,
    /// points, cos φ weighted), so the cell keeps its flux in what is rendered.
    fn build_tile(&self, row: usize, col: usize) -> Tile {
        let cell = self.cell(row, col);
        let mut nb = [[0.0f64; 3]; 3];
        for (dr, line) in nb.iter_mut().enumerate() {
            for (dc, v) in line.iter_mut().enumerate() {
                let (r, c) = Self::neighbour(row, col, dr, dc);
                *v = self.balance(r, c).shift;
            }
        }
        let (lat0, lon0) = (row as f64 - 90.0, col as f64);
        let last = (TILE_NODES - 1) as f64;
        let mut t = [0u16; TILE_NODES * TILE_NODES];
        // sin/cos of each node column's longitude once (unit vectors are separable).
        let lon_sc: Vec<(f64, f64)> = (0..TILE_NODES)
            .map(|j| {
                let r = (lon0 + j as f64 / last).to_radians();
                (libm::sin(r), libm::cos(r))
            })
            .collect();
        for i in 0..TILE_NODES {
            let u = i as f64 / last;
            let lat = lat0 + u;
            let (sl, cl) = (libm::sin(lat.to_radians()), libm::cos(lat.to_radians()));
            let wy = blend_weights(u, SHIFT_BLEND_DEG);
            for (j, &(so, co)) in lon_sc.iter().enumerate() {
                let v = j as f64 / last;
                let lon = lon0 + v;
                let wx = blend_weights(v, SHIFT_BLEND_DEG);
                let mut shift = 0.0;
                for (dr, wyr) in wy.iter().enumerate() {
                    for (dc, wxc) in wx.iter().enumerate() {
                        shift += wyr * wxc * nb[dr][dc];
                    }
                }
                let p = self.point_at(cell, lat, lon, u, v, [cl * co, cl * so, sl]);
                let k = (self.temperature(&p, shift) - TILE_OFFSET_K) / TILE_STEP_K;
                t[i * TILE_NODES + j] = k.round().clamp(0.0, f64::from(u16::MAX)) as u16;
            }
        }
        let mut tile = Tile { t, s: 1.0 };
        // The exact cos φ-weighted mean of σT⁴ over the interpolant: 3 × 3 Gauss points
        // in every node interval (the interpolant is bilinear there).
        let (mut sum, mut wsum) = (0.0, 0.0);
        let gauss: Vec<(f64, f64)> = tile_gauss_points().collect();
        for &(u, wu) in &gauss {
            let w = wu * libm::cos((lat0 + u).to_radians());
            let mut line = 0.0;
            for &(v, wv) in &gauss {
                let t = tile.interpolate(u, v);
                line += wv * (t * t) * (t * t);
            }
            sum += w * STEFAN_BOLTZMANN_W_M2_K4 * line;
            wsum += w * (TILE_NODES - 1) as f64;
        }
        let target = self.target(row, col);
        if sum > 0.0 {
            tile.s = (target / (sum / wsum)).sqrt().sqrt();
        }
        tile
    }

    /// Builds every cell's tile now, in parallel (rayon), instead of on first use: the
    /// renderer then only reads. The values are those a lazy build gives (each is a
    /// function of the cell alone), so the result does not depend on the thread count.
    /// Costs about 28 s of CPU for the 64 800 cells in a release build (~0.43 ms per
    /// cell: two threshold solves on 16 × 16 points and 33 × 33 tile nodes; measured
    /// before session 23's Gauss-exact, border-aware scale s, which adds two passes of
    /// 96 × 96 interpolant points per cell), and holds
    /// about 165 MB ([`CloudField::memory_bytes`]: 2.2 kB of tile and 0.3 kB of coarse
    /// noise per cell).
    pub fn fill(&self) {
        use rayon::prelude::*;
        let n = OlrGrid::ROWS * OlrGrid::COLS;
        let split = |i: usize| (i / OlrGrid::COLS, i % OlrGrid::COLS);
        (0..n).into_par_iter().for_each(|i| {
            let (r, c) = split(i);
            self.cell(r, c);
        });
        (0..n).into_par_iter().for_each(|i| {
            let (r, c) = split(i);
            self.balance(r, c);
        });
        (0..n).into_par_iter().for_each(|i| {
            let (r, c) = split(i);
            self.tile(r, c);
        });
        let scales = (0..n)
            .into_par_iter()
            .map(|i| {
                let (r, c) = split(i);
                self.final_scale(r, c)
            })
            .collect();
        self.scales.get_or_init(|| scales);
    }

    /// Heap memory held by the built cells and tiles, bytes.
    pub fn memory_bytes(&self) -> usize {
        let n = OlrGrid::ROWS * OlrGrid::COLS;
        let cells = self.cells.iter().filter(|c| c.get().is_some()).count();
        let tiles = self.tiles.iter().filter(|c| c.get().is_some()).count();
        n * (size_of::<OnceLock<Box<Cell>>>()
            + size_of::<OnceLock<Balance>>()
            + size_of::<OnceLock<Box<Tile>>>())
            + cells * size_of::<Cell>()
            + tiles * size_of::<Tile>()
            + (self.flux.len() + self.table.len()) * size_of::<f32>()
    }

    /// Cell (row + dr, col + dc): rows clamped at the poles, columns wrapped.
    fn neighbour(row: usize, col: usize, dr: usize, dc: usize) -> (usize, usize) {
        let r = (row + dr).saturating_sub(1).min(OlrGrid::ROWS - 1);
        let c = (col + OlrGrid::COLS + dc - 1) % OlrGrid::COLS;
        (r, c)
    }

    /// The cell's 16 × 16 balance points (cell-centred) with their cos φ weights and
    /// (u, v) fractions.
    fn balance_points(&self, cell: &Cell, row: usize, col: usize) -> Vec<(Point, f64, f64, f64)> {
        let (lat0, lon0) = (row as f64 - 90.0, col as f64);
        let mut pts = Vec::with_capacity(BALANCE_SAMPLES * BALANCE_SAMPLES);
        let lon_sc: Vec<(f64, f64)> = (0..BALANCE_SAMPLES)
            .map(|j| {
                let r = (lon0 + (j as f64 + 0.5) / BALANCE_SAMPLES as f64).to_radians();
                (libm::sin(r), libm::cos(r))
            })
            .collect();
        for i in 0..BALANCE_SAMPLES {
            let u = (i as f64 + 0.5) / BALANCE_SAMPLES as f64;
            let lat = lat0 + u;
            let (sl, w) = (libm::sin(lat.to_radians()), libm::cos(lat.to_radians()));
            for (j, &(so, co)) in lon_sc.iter().enumerate() {
                let v = (j as f64 + 0.5) / BALANCE_SAMPLES as f64;
                let lon = lon0 + v;
                let p = self.point_at(cell, lat, lon, u, v, [w * co, w * so, sl]);
                pts.push((p, w, u, v));
            }
        }
        pts
    }

    /// The weighted mean σT⁴ of `pts` with the own shift `d` (point i's shift:
    /// a_i·d + b_i), W m⁻².
    fn mean_flux(&self, pts: &[(Point, f64, f64, f64)], ab: &[(f64, f64)], d: f64) -> f64 {
        let wsum: f64 = pts.iter().map(|p| p.1).sum();
        pts.iter()
            .zip(ab)
            .map(|((p, w, _, _), (a, b))| {
                w * STEFAN_BOLTZMANN_W_M2_K4 * self.temperature(p, a * d + b).powi(4)
            })
            .sum::<f64>()
            / wsum
    }

    /// The shift in [−lim, lim] whose weighted mean σT⁴ of `pts` (shift of point i:
    /// a_i·δ + b_i) is `target` (bisection: the flux rises with the threshold).
    fn solve_shift(
        &self,
        pts: &[(Point, f64, f64, f64)],
        ab: &[(f64, f64)],
        target: f64,
    ) -> (f64, f64) {
        let flux_of = |d: f64| self.mean_flux(pts, ab, d);
        let lim = MAX_THRESHOLD_SHIFT_SIGMA * self.sigma;
        let (lo_f, hi_f) = (flux_of(-lim), flux_of(lim));
        // A flux the shift cannot reach: the least shift that gets within
        // UNREACHED_SHARE of the reachable end (the cell just cleared or just overcast),
        // not the bound itself (s takes the rest).
        // (Checked before the clamp, whose bounds must be ordered and not NaN.)
        let d = if hi_f.partial_cmp(&lo_f) != Some(std::cmp::Ordering::Greater) {
            0.0
        } else {
            let margin = UNREACHED_SHARE * (hi_f - lo_f);
            let target = target.clamp(lo_f + margin, hi_f - margin);
            // Illinois false position: the flux is smooth and monotone in the shift.
            let (mut a, mut fa, mut b, mut fb) = (-lim, lo_f - target, lim, hi_f - target);
            let mut side = 0i8;
            let mut d = 0.5 * (a + b);
            for _ in 0..SOLVE_STEPS {
                d = (a * fb - b * fa) / (fb - fa);
                let fd = flux_of(d) - target;
                if fd.abs() <= SOLVE_TOLERANCE * target {
                    break;
                }
                if fd < 0.0 {
                    (a, fa) = (d, fd);
                    if side < 0 {
                        fb *= 0.5;
                    }
                    side = -1;
                } else {
                    (b, fb) = (d, fd);
                    if side > 0 {
                        fa *= 0.5;
                    }
                    side = 1;
                }
            }
            d
        };
        (d, flux_of(d))
    }

    fn build_cell(&self, row: usize, col: usize) -> Cell {
        let lat0 = row as f64 - 90.0;
        let lon0 = col as f64;
        let mut coarse = [0f32; NODES * NODES];
        for i in 0..NODES {
            for j in 0..NODES {
                let lat = lat0 + i as f64 / (NODES - 1) as f64;
                let lon = lon0 + j as f64 / (NODES - 1) as f64;
                coarse[i * NODES + j] = self.noise(unit_vector(lat, lon), 0..COARSE_OCTAVES) as f32;
            }
        }
        let mut cell = Cell { coarse, shift: 0.0 };
        let pts = self.balance_points(&cell, row, col);
        let ab = vec![(1.0, 0.0); pts.len()];
        cell.shift = self
            .solve_shift(&pts, &ab, f64::from(self.flux[row * OlrGrid::COLS + col]))
            .0;
        cell
    }

    /// The final balance: the own shift with the neighbours' (stand-alone) shifts
    /// blended in as the renderer blends them, then s for the rest. With a regional
    /// balance the shift is the regional one (the cell's flux is what it renders).
    fn build_balance(&self, row: usize, col: usize) -> Balance {
        // With a regional balance the cell keeps what its regional shift renders (its
        // target is that flux), so the shift is the regional one, exactly; solving for
        // it again only returned it to the solver's tolerance.
        if self.regional_radius_cells > 0 {
            return Balance {
                shift: self.regional_shift(row, col),
            };
        }
        let cell = self.cell(row, col);
        let pts = self.balance_points(cell, row, col);
        let ab = self.blend_coefficients(&pts, row, col, |r, c| self.cell(r, c).shift);
        Balance {
            shift: self.solve_shift(&pts, &ab, self.target(row, col)).0,
        }
    }

    /// The mean stand-alone shift of the window of [`CloudField::with_regional_balance`]
    /// around cell (`row`, `col`).
    fn mean_shift(&self, row: usize, col: usize) -> f64 {
        *self.mean_shifts[row * OlrGrid::COLS + col].get_or_init(|| {
            let window = self.window(row, col, self.regional_radius_cells);
            let sum: f64 = window.iter().map(|&(r, c)| self.cell(r, c).shift).sum();
            sum / window.len().max(1) as f64
        })
    }

    /// The mean σT⁴ of cell (`row`, `col`)'s balance points at the mean shifts
    /// ([`CloudField::mean_shift`], blended across its borders as rendered), W m⁻², and
    /// its derivative with every shift moved alike, W m⁻² per noise unit.
    fn mean_shift_flux(&self, row: usize, col: usize) -> (f64, f64) {
        *self.mean_shift_fluxes[row * OlrGrid::COLS + col].get_or_init(|| {
            let cell = self.cell(row, col);
            let pts = self.balance_points(cell, row, col);
            let ab = self.blend_coefficients(&pts, row, col, |r, c| self.mean_shift(r, c));
            let d = self.mean_shift(row, col);
            let eps = REGIONAL_STEP_SIGMA * self.sigma;
            let moved: Vec<(f64, f64)> =
                ab.iter().map(|&(a, b)| (a, b + eps * (1.0 - a))).collect();
            let f0 = self.mean_flux(&pts, &ab, d);
            (f0, (self.mean_flux(&pts, &moved, d + eps) - f0) / eps)
        })
    }

    /// The cell's regional shift: its own stand-alone shift without a regional balance;
    /// with one the window's mean shift plus the one correction γ (a Newton step, the
    /// same for the whole window) that brings the window's mean flux at the mean shifts
    /// to the grid's: the mean of shifts does not keep a region's flux (it is not
    /// linear in the shift; 1 % too little over 6 × 6 cells without it), and a
    /// correction per cell's flux would step from cell to cell (the scale s then shows
    /// the cells as blocks).
    fn regional_shift(&self, row: usize, col: usize) -> f64 {
        let radius = self.regional_radius_cells;
        if radius == 0 {
            return self.cell(row, col).shift;
        }
        *self.regional_shifts[row * OlrGrid::COLS + col].get_or_init(|| {
            let (mut missing, mut slope) = (0.0, 0.0);
            for (r, c) in self.window(row, col, radius) {
                let (f, df) = self.mean_shift_flux(r, c);
                missing += f64::from(self.flux[r * OlrGrid::COLS + c]) - f;
                slope += df;
            }
            let limit = MAX_REGIONAL_CORRECTION_SIGMA * self.sigma;
            let gamma = if slope > 0.0 {
                (missing / slope).clamp(-limit, limit)
            } else {
                0.0
            };
            self.mean_shift(row, col) + gamma
        })
    }

    /// The flux the texture keeps in cell (`row`, `col`), W m⁻²: the grid's, or with a
    /// regional balance what the regional shifts render there.
    fn target(&self, row: usize, col: usize) -> f64 {
        if self.regional_radius_cells == 0 {
            f64::from(self.flux[row * OlrGrid::COLS + col])
        } else {
            self.regional_flux(row, col)
        }
    }

    /// The cells of the (2 · `radius` + 1)² window around cell (`row`, `col`), rows
    /// beyond the poles left out, longitudes wrapped.
    fn window(&self, row: usize, col: usize, radius: usize) -> Vec<(usize, usize)> {
        (row.saturating_sub(radius)..(row + radius + 1).min(OlrGrid::ROWS))
            .flat_map(|r| {
                (0..=2 * radius)
                    .map(move |dc| (r, (col + OlrGrid::COLS + dc - radius) % OlrGrid::COLS))
            })
            .collect()
    }

    /// The mean σT⁴ of cell (`row`, `col`)'s balance points at the regional shifts,
    /// blended across its borders as rendered, W m⁻².
    fn regional_flux(&self, row: usize, col: usize) -> f64 {
        *self.regional_fluxes[row * OlrGrid::COLS + col].get_or_init(|| {
            let cell = self.cell(row, col);
            let pts = self.balance_points(cell, row, col);
            let ab = self.blend_coefficients(&pts, row, col, |r, c| self.regional_shift(r, c));
            self.mean_flux(&pts, &ab, self.regional_shift(row, col))
        })
    }

    /// Per balance point of cell (`row`, `col`): (the own shift's blend weight, the
    /// neighbours' shifts `shift_of` blended), as the renderer blends them.
    fn blend_coefficients(
        &self,
        pts: &[(Point, f64, f64, f64)],
        row: usize,
        col: usize,
        shift_of: impl Fn(usize, usize) -> f64,
    ) -> Vec<(f64, f64)> {
        let mut nb = [[0.0f64; 3]; 3];
        for (dr, line) in nb.iter_mut().enumerate() {
            for (dc, v) in line.iter_mut().enumerate() {
                if dr != 1 || dc != 1 {
                    let (r, c) = Self::neighbour(row, col, dr, dc);
                    *v = shift_of(r, c);
                }
            }
        }
        pts.iter()
            .map(|&(_, _, u, v)| {
                let (wy, wx) = (
                    blend_weights(u, SHIFT_BLEND_DEG),
                    blend_weights(v, SHIFT_BLEND_DEG),
                );
                let mut b = 0.0;
                for (dr, wyr) in wy.iter().enumerate() {
                    for (dc, wxc) in wx.iter().enumerate() {
                        if dr != 1 || dc != 1 {
                            b += wyr * wxc * nb[dr][dc];
                        }
                    }
                }
                (wy[1] * wx[1], b)
            })
            .collect()
    }

    /// Temperature of a point with threshold shift `shift` (before the scale s), K.
    #[inline]
    fn temperature(&self, p: &Point, shift: f64) -> f64 {
        let x = p.n - p.theta - shift;
        let m = smoothstep(x / p.width + 0.5);
        // Deeper (colder) towards a cloud's core: 0.7 ΔT at the edge, 1.3 ΔT well inside.
        let core = smoothstep(x / (1.2 * self.sigma));
        // Deep convection: flat anvil tops (depth 1) instead of the deepening core.
        let depth = EDGE_DEPTH_SHARE + 2.0 * (1.0 - EDGE_DEPTH_SHARE) * core;
        let depth = depth + (1.0 - depth) * p.deep;
        // Tops deeper than EDGE_WIDTH_FULL_DEPTH_K: the edge steps as a cloud that deep,
        // the rest of the depth comes inside (cold cores of the convective clusters).
        let edge_dt = p.dt.min(EDGE_WIDTH_FULL_DEPTH_K);
        // The other tops' texture grows in with the core, so a cloud's edge steps as a
        // flat one does.
        let cold = m * (edge_dt * depth + p.top_texture + core * p.low_texture);
        let cold = if p.dt > edge_dt {
            cold + smoothstep(x / (DEEP_CORE_WIDTHS * p.width)) * (p.dt - edge_dt)
        } else {
            cold
        };
        let t = p.t_clear - cold.min(MAX_LOCAL_COLD_K);
        self.fragment(p, x, t)
    }

    /// The temperature `t` (K) of point `p`, `x` above its cloud threshold (noise
    /// units), with its cold fragment if the fragment field is over its threshold: a
    /// sharp-edged top ([`FRAGMENT_EDGE_SIGMA`]) [`FRAGMENT_MIN_COLD_K`] colder at the
    /// edge, deepening over [`FRAGMENT_CORE_SIGMA`], that hides what is below it where it
    /// is colder. Session 38's fragments (the default): threshold
    /// [`FRAGMENT_THRESHOLD_SIGMA`] anywhere, the top down to [`FRAGMENT_MAX_COLD_K`]
    /// below the clear sky. [`CloudField::with_cloud_fragments`]: the threshold falls
    /// from [`CLOUD_FRAGMENT_CLEAR_THRESHOLD_SIGMA`] in clear air to
    /// [`CLOUD_FRAGMENT_THRESHOLD_SIGMA`] at and inside a cloud (over
    /// [`CLOUD_FRAGMENT_REACH_SIGMA`] noise σ outside its edge), and the top lies down
    /// to [`CLOUD_FRAGMENT_MAX_COLD_K`] below `t` itself, never more than
    /// [`MAX_LOCAL_COLD_K`] below the clear sky.
    fn fragment(&self, p: &Point, x: f64, t: f64) -> f64 {
        // Almost every point lies under even the lowest threshold: out before the rest.
        let lowest = if self.cloud_fragments {
            CLOUD_FRAGMENT_THRESHOLD_SIGMA
        } else {
            FRAGMENT_THRESHOLD_SIGMA
        };
        if p.z_fragment - lowest <= -0.5 * FRAGMENT_EDGE_SIGMA {
            return t;
        }
        let (threshold, max_cold_k) = if self.cloud_fragments {
            let near = smoothstep(x / (CLOUD_FRAGMENT_REACH_SIGMA * self.sigma) + 1.0);
            let threshold = CLOUD_FRAGMENT_CLEAR_THRESHOLD_SIGMA
                + (CLOUD_FRAGMENT_THRESHOLD_SIGMA - CLOUD_FRAGMENT_CLEAR_THRESHOLD_SIGMA) * near;
            (threshold, CLOUD_FRAGMENT_MAX_COLD_K)
        } else {
            (FRAGMENT_THRESHOLD_SIGMA, FRAGMENT_MAX_COLD_K)
        };
        let over = p.z_fragment - threshold;
        if over <= -0.5 * FRAGMENT_EDGE_SIGMA {
            return t;
        }
        let cold = FRAGMENT_MIN_COLD_K
            + (max_cold_k - FRAGMENT_MIN_COLD_K) * smoothstep(over / FRAGMENT_CORE_SIGMA);
        let cover = smoothstep(over / FRAGMENT_EDGE_SIGMA + 0.5);
        let top = if self.cloud_fragments {
            (t - cold).max(p.t_clear - MAX_LOCAL_COLD_K)
        } else {
            p.fragment_clear_k - cold
        };
        t - cover * (t - top).max(0.0)
    }

    /// The point at fractions (u lat, v lon) of `cell`.
    fn point_at(&self, cell: &Cell, lat: f64, lon: f64, u: f64, v: f64, p: [f64; 3]) -> Point {
        let s = (NODES - 1) as f64;
        let (y, x) = (u * s, v * s);
        let (i, j) = ((y as usize).min(NODES - 2), (x as usize).min(NODES - 2));
        let (ty, tx) = (y - i as f64, x - j as f64);
        let at = |a: usize, b: usize| f64::from(cell.coarse[a * NODES + b]);
        let a = at(i, j) + (at(i, j + 1) - at(i, j)) * tx;
        let b = at(i + 1, j) + (at(i + 1, j + 1) - at(i + 1, j)) * tx;
        let coarse = a + (b - a) * ty;
        let last = self.octaves.len();
        let meso = self.noise(p, MESOSCALE_OCTAVES);
        let small = self.noise(p, MESOSCALE_OCTAVES.end..last - 1);
        let fine = self.noise(p, last - 1..last);
        self.point(
            lat,
            lon,
            [coarse, meso, small + fine],
            fine,
            self.fragment_z(p),
        )
    }

    /// The fragment field at unit vector `p` in its own σ: the fragment noise plus
    /// [`FRAGMENT_CLUSTER_GAIN`] × the cluster noise, each in its σ, normalised.
    fn fragment_z(&self, p: [f64; 3]) -> f64 {
        let [of, oc] = &self.fragment_octaves;
        let nf = self.octave_noise(of, p) / self.fragment_sigma[0];
        let nc = self.octave_noise(oc, p) / self.fragment_sigma[1];
        (nf + FRAGMENT_CLUSTER_GAIN * nc)
            / (1.0 + FRAGMENT_CLUSTER_GAIN * FRAGMENT_CLUSTER_GAIN).sqrt()
    }

    /// Weights of the (coarse, mesoscale) noise in a deep-convective regime of weight
    /// `deep` ∈ [0, 1]: the coarse octaves × (1 − (1 − [`DEEP_COARSE_WEIGHT`])·deep),
    /// the mesoscale ones × g with g² = 1 + (1 − w_c²)·Σ_coarse a² / Σ_meso a², so the
    /// variance of the sum is kept (the octaves are independent, each of variance ∝ its
    /// amplitude a²).
    fn deep_weights(&self, deep: f64) -> (f64, f64) {
        let wc = 1.0 - (1.0 - DEEP_COARSE_WEIGHT) * deep;
        let gm = (1.0 + (1.0 - wc * wc) * self.coarse_over_meso_var).sqrt();
        (wc, gm)
    }

    /// Σ a² over the octaves in `range` (the variance of their sum, up to one
    /// octave's variance).
    fn octave_var(octaves: &[Octave], range: std::ops::Range<usize>) -> f64 {
        octaves[range]
            .iter()
            .map(|o| o.amplitude * o.amplitude)
            .sum()
    }

    /// Brightness temperature of the texture at (`lat_deg`, `lon_deg`), K: the
    /// bilinear interpolant of the cell's tile (1/[`TILE_NODES_PER_DEG`]° nodes) times
    /// the cell's scale s, blended with the neighbours' s within [`BORDER_BLEND_DEG`] of
    /// a border. Latitude −90…90° (clamped beyond), any longitude. Builds the cell (and
    /// what it needs of its neighbours) on first use unless [`CloudField::fill`] did;
    /// after that a lookup is a few loads and flops.
    #[inline]
    pub fn temperature_k(&self, lat_deg: f64, lon_deg: f64) -> f64 {
        let lat = lat_deg.clamp(-90.0, 90.0);
        // fmod only outside −360…360° (the renderer's atan2 gives −180…180°).
        let lon = if (0.0..360.0).contains(&lon_deg) {
            lon_deg
        } else if (-360.0..0.0).contains(&lon_deg) {
            lon_deg + 360.0
        } else {
            lon_deg.rem_euclid(360.0)
        };
        let row = ((lat + 90.0) as usize).min(OlrGrid::ROWS - 1);
        let col = (lon as usize).min(OlrGrid::COLS - 1);
        let (u, v) = (lat + 90.0 - row as f64, lon - col as f64);
        let tile = self.tile(row, col);
        let t = tile.interpolate(u, v);
        let own_s = self.final_scale(row, col);
        let b = BORDER_BLEND_DEG;
        if u >= b && u <= 1.0 - b && v >= b && v <= 1.0 - b {
            return own_s * t;
        }
        let (wy, wx) = (blend_weights(u, b), blend_weights(v, b));
        // At most one neighbour row and one neighbour column have a weight (the band
        // is narrower than half a cell): the own s, the side neighbours' and the
        // corner's, each read only where its weight is not 0.
        let (dr, ay) = if wy[0] > 0.0 { (0, wy[0]) } else { (2, wy[2]) };
        let (dc, ax) = if wx[0] > 0.0 { (0, wx[0]) } else { (2, wx[2]) };
        let at = |dr: usize, dc: usize| {
            let (r, c) = Self::neighbour(row, col, dr, dc);
            self.final_scale(r, c)
        };
        let mut s = wy[1] * wx[1] * own_s;
        if ax > 0.0 {
            s += wy[1] * ax * at(1, dc);
        }
        if ay > 0.0 {
            s += ay * wx[1] * at(dr, 1);
            if ax > 0.0 {
                s += ay * ax * at(dr, dc);
            }
        }
        s * t
    }

    /// The balance of 1° cell (`row` 0…179 from the south pole, `col` 0…359 from
    /// longitude 0; clamped / wrapped): its final cloud-threshold shift δ in noise σ
    /// (bounded by ±[`MAX_THRESHOLD_SHIFT_SIGMA`]) and its final scale s (dimensionless,
    /// the factor on the temperature that δ could not balance). Builds the cell (and
    /// what it needs of its neighbours) if not built yet. For diagnostics and tests.
    pub fn cell_balance(&self, row: usize, col: usize) -> (f64, f64) {
        let (row, col) = (row.min(OlrGrid::ROWS - 1), col % OlrGrid::COLS);
        (
            self.balance(row, col).shift / self.sigma,
            self.final_scale(row, col),
        )
    }

    /// [`CloudField::temperature_k`] (kept for callers that name the point this way).
    pub fn temperature_at_k(&self, lat_deg: f64, lon_deg: f64) -> f64 {
        self.temperature_k(lat_deg, lon_deg)
    }
    /// The 1° flux of cell (`row`, `col`) the texture conserves, W m⁻²: the grid's,
    /// or with [`CloudField::with_regional_balance`] what the regional shift renders
    /// there (builds the cell's neighbourhood on first use).
    pub fn cell_flux_w_m2(&self, row: usize, col: usize) -> f32 {
        self.target(row.min(OlrGrid::ROWS - 1), col % OlrGrid::COLS) as f32
    }

    /// The grid's 1° flux of cell (`row`, `col`), W m⁻² (what the texture was made
    /// from; [`CloudField::cell_flux_w_m2`] is what it keeps).
    pub fn grid_flux_w_m2(&self, row: usize, col: usize) -> f32 {
        self.flux[row.min(OlrGrid::ROWS - 1) * OlrGrid::COLS + col % OlrGrid::COLS]
    }
}

impl Tile {
    /// The bilinear interpolant of the nodes at fractions (u lat, v lon) of the cell, K
    /// (before the scale s).
    #[inline]
    fn interpolate(&self, u: f64, v: f64) -> f64 {
        let last = (TILE_NODES - 1) as f64;
        let (y, x) = (u.clamp(0.0, 1.0) * last, v.clamp(0.0, 1.0) * last);
        let (i, j) = (
            (y as usize).min(TILE_NODES - 2),
            (x as usize).min(TILE_NODES - 2),
        );
        let (ty, tx) = (y - i as f64, x - j as f64);
        let k = i * TILE_NODES + j;
        let at = |k: usize| f64::from(self.t[k]);
        let a = at(k) + (at(k + 1) - at(k)) * tx;
        let b = at(k + TILE_NODES) + (at(k + TILE_NODES + 1) - at(k + TILE_NODES)) * tx;
        TILE_OFFSET_K + (a + (b - a) * ty) * TILE_STEP_K
    }
}
