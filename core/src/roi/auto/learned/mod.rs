//! `auto-v2`: `auto` with a learned region stage. Each 8×8-pixel cell is classified
//! target or background by a forest of boosted trees over scale-free features of the
//! cell, of its 4×4-pixel windows (a second look at 4-px resolution: a 3–12 px far
//! target keeps its contrast there) and of its surroundings ([`features`]: level
//! within the frame, steps, contrast against boxes of 8–64 px and their texture); the
//! target cells are grouped into 8-connected components, the strongest (summed score)
//! wins, the target cells near it across the body's own level join it once the
//! confidence has rated it (stage 4c, [`AutoV2::link_cells`]), and its cells gate
//! `auto`'s full-resolution refinement (outermost boundaries,
//! saturated targets); the box is grown to the whole body ([`body`]: faces hotter and
//! colder than the background joined to the winner), a small box is then cut to its
//! half maximum ([`half_max`]: far targets' blur) and a saturated blob by the optics'
//! reach ([`saturated`]).
//! A box's confidence is a logistic model of P(hit) over statistics of the winner
//! itself (its cells, sides touched, mean cell score, the contrast of its border
//! against the ring of background around it in the ring's own spread, the texture of
//! its interior cells and whether it is small (1–2 cells), [`shape`]; none counts the
//! background's other components), fitted on our renders
//! (`confidence_weights.rs`).
//!
//! Unlike `auto`'s "the outline is a step" rule, the region stage learns what the
//! background looks like (cloud texture, the limb, a real camera's shading and hot
//! pixels) from our renders, and a cloud edge touching the target is not part of it.

pub mod blob;
mod blob_weights;
pub mod body;
mod cells;
mod confidence_weights;
pub mod earth_mask;
pub mod features;
pub mod forest;
mod forest_trees;
pub mod half_max;
pub mod lanes;
pub mod limb;
pub mod look;
pub mod narrow;
pub mod order;
pub mod polygon;
pub mod prescreen;
pub mod saturated;
pub mod segments;
pub mod shape;
pub mod small;
pub mod smooth;
pub mod spot;
mod spot_trees;

use super::super::plane::Window;
use super::super::{BoxRule, DetectError, Detection, Detector, Roi, Scratch};
use super::decision::choose_target;
use super::edges::{CellStats, EdgeComponents, label_edge_cells};
use super::noise::{NOISE_BINS, noise_sigma_second};
use super::refine::{Region, build_gate, count_saturation, outline};
use super::rules::{MIN_SATURATED_PX, SATURATED_TAU_FACTOR};
use crate::capacity::{ConstInit, FrameCapacity, Reference};
use crate::frame::Frame;
use cells::{CellPlanes, cell_plane, fill_cells};
use features::{FEATURES, FrameLevels, Integrals, cell_features, integrate, levels};

/// Parameters of `auto-v2`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AutoV2 {
    /// Tracking prior: the last frame's box, or `None` to search the whole frame. With
    /// a prior, every stage runs first on a window around it (the prior grown by
    /// [`TRACK_MARGIN_PX`] + its longer side on every side,
    /// cut to the frame; none over [`TRACK_MAX_WINDOW_PERMILLE`] of the frame); that
    /// box stands when it passes the gate, overlaps the prior and no side of it lies on
    /// a border of the window inside the frame, else the whole frame is searched. Any box is accepted; it is cut to the frame, and an
    /// empty result means no prior.
    pub prior: Option<Roi>,
    /// The look of the prior's target on the last frame ([`look::Look::measure`] of
    /// the last box), or `None`. With a prior and a look, a fast path runs first: the
    /// prior's cells taken for the target's and refined by stages 5–8 in a window
    /// around it (the classifier does not run; a saturated blob there whose box
    /// follows the prior is taken instead, as stage 2b boxes it) when the prior's place
    /// still looks as the last look says ([`look::Look::matches`]); its box stands when
    /// it stays in the window, follows the prior ([`TRACK_FAST_MIN_IOU_PERMILLE`],
    /// [`TRACK_FAST_SIDE_SLACK_PX`]) and stands out on every side
    /// ([`look::Look::stands_out`]), with confidence [`TRACKED_SCORE_PERMILLE`];
    /// otherwise the call goes on as with the prior alone.
    pub look: Option<look::Look>,
    /// Full-resolution boundary threshold, multiples of σ: 1..=1000. Default 8 (as `auto`).
    /// Stage 2c's refinement uses the lesser of this and [`DEEP_SPACE_FINE_SIGMA`].
    pub fine_sigma: u16,
    /// A cell is a target cell when its score reaches this, score units
    /// ([`forest::SCORE_ONE`] per unit of log-odds): -4096..=4096. Default 0 (even
    /// odds): on family A (seed 7001: realistic, paper, fixtures), each of 0, −256 and
    /// −512 with its own refitted confidence model and its lowest gate within the
    /// false-alarm bound, 0 gives the best summed mean IoU (1.908 vs 1.854 and 1.848).
    pub cell_score: i16,
    /// Boxes whose confidence (a calibrated P(hit), [`Winner::score_permille`]) is
    /// below this are dropped (no target), ‰: 0..=1000. Default 550: on family A
    /// (famA25, paperAm, fixA), the lowest threshold in steps of 50 whose false alarms
    /// stay ≤ 2 % on the no-target frames of every kind (realistic 1 of 60, fixtures 0
    /// of 80; 500: realistic 2 of 60). Re-chosen by the same rule for session 26's
    /// refitted confidence: 550 again (realistic 1 of 60, its second-highest no-target
    /// winner at 525; fixtures' highest 489). Since family A has 300 more realistic
    /// frames without a target (famAE, session 33) no gate up to 650 meets the rule
    /// there; kept at 550 as the trade-off, measured for session 39's confidence
    /// (`docs/detectors.md` § Session 39: 500 / 550 / 600 / 650 → family A 2.440 /
    /// 2.418 / 2.379 / 2.355, famAE8 18 / 14 / 12 / 10 of 300).
    pub min_score_permille: u16,
    /// A box that is a saturated blob is cut by this many pixels per side (off the
    /// frame's edges; [`saturated`]), px: 0..=8. A property of the camera: the reach of
    /// its optics' blur. Default 2: the flight camera, the Hayabusa2 TIR with its optics
    /// point-spread function ([`saturated::PSF_RADIUS_PX`]; the `realistic` world), where
    /// family A's realistic set chooses 2 of 0–3 (mean IoU 0.376, 0.414, 0.482, 0.457 at
    /// 0, 1, 2, 3). Set 0 for a camera without optics blur (the `paper` world, the
    /// fixtures and the test-set composites: there 0 is best, 2 costs 0.20 and 0.05);
    /// at 0 stage 7 also takes a box over a sky clipped at DN 0 as over deep space
    /// when it holds saturated pixels ([`half_max::Background::ClutteredSharp`]).
    pub saturated_erode_px: u8,
    /// The whole body grown from the winner ([`body`]: faces hotter and colder than
    /// the background joined to it). [`body::BodyParams::OFF`] turns it off.
    pub body: body::BodyParams,
    /// Stage 3's cascade ([`prescreen`]): classify only the seed cells and the
    /// neighbours of target cells (the same components, unless one holds no seed).
    /// Default on; off classifies every cell (the cost's worst case).
    pub prescreen: bool,
    /// Stage 2b ([`blob`]): how the frame's largest saturated blob competes with the
    /// cell classifier's winner. Default [`BlobRule::Compete`].
    pub blob: BlobRule,
    /// Stage 2c ([`smooth`]): a window whose cells fit a smooth surface within noise is
    /// deep space, and the cells departing from the surface are the target's (instead
    /// of the classifier's) where the refinement finds a boundary of
    /// [`DEEP_SPACE_FINE_SIGMA`] σ (at most `fine_sigma`) in them; such a box carries
    /// [`DEEP_SPACE_SCORE_PERMILLE`], or [`BORDER_PIECE_SCORE_PERMILLE`] for cells cut
    /// by one side of the window that no piece of the Earth's disc could be
    /// ([`EARTH_MIN_CHORD_CELLS`]) or by a corner with an outline that bends
    /// ([`limb::Outline::Bends`]: the disc's is one arc). Otherwise, and when
    /// the frame has a saturated blob (stage 2b decides then), the classifier decides.
    /// Default on.
    pub deep_space: bool,
    /// Stage 2e ([`earth_mask`]): where stage 2c finds no deep space and the frame holds
    /// both the Earth and sky, the sky beside the Earth fitted alone (the Earth's
    /// cells and [`earth_mask::EXCLUDED_CELLS`] around them left out), its departing
    /// cells boxed as stage 2c's are, unless their component reaches the Earth's
    /// margin ([`earth_mask::MARGIN_CELLS`]); such a box carries
    /// [`SKY_BESIDE_EARTH_SCORE_PERMILLE`]. Default on (with `deep_space`).
    pub sky_beside_earth: bool,
    /// Stage 2d ([`small`]): where stage 2c takes the window for deep space but no
    /// cell departs as a target's, a small target searched at the pixel scale; its box
    /// carries [`SMALL_TARGET_SCORE_PERMILLE`]. Default on since session 68 (off before:
    /// at its first thresholds it boxed 19 of the real dark frame's 100 target-less
    /// windows, `docs/detectors.md` § Session 30). With [`small::MIN_Z`] 12,
    /// [`small::MIN_SIDE_PX`] and [`small::BOX_SIGMA`] 2, chosen on family A (seeds
    /// 7001–7201, ½ convention): summed mean IoU +0.0280 (famAF, the far radiometry
    /// set, +0.0233), false alarms unchanged but famAF's 3 → 4 of 60 (the Moon, a
    /// compact warm disc over deep space); § Session 68.
    pub small_target: bool,
    /// Stage 4b: how many of the classifier's strongest components (by summed cell
    /// energy) the confidence model rates, the most confident winning; 1 keeps the
    /// strongest (sessions 26–31); 1..=[`MAX_CANDIDATES`], else
    /// [`DetectError::InvalidParameter`]. Default 3, chosen on family A (seed 7001;
    /// summed gated mean IoU of realistic, paper and fixtures, ½ convention: 1 → 2.036,
    /// 2 → 2.057, 3 and 4 → 2.066, the smallest on the plateau; with the forest
    /// retrained for feature 32: 3 → 2.078, 4 → 2.082, kept): the strongest component
    /// is often a cloud deck, the limb or the frame's edge, and the target a weaker
    /// component the confidence model rates higher (`docs/detectors.md` § Session 32).
    pub candidates: u8,
    /// Stage 5e ([`spot`]): when every other stage answers "no target", the frame's
    /// strongest small spots against their clutter, each grown to a region and rated by
    /// its own forest (P(hit)); the most confident one's box when it reaches the gate.
    /// Default on: on family A (seed 7001) radiometry far (signal-to-clutter ≥ 3) rises
    /// from 0.03 and no target-less frame is boxed (`docs/detectors.md` § Session 34).
    pub spot: bool,
    /// Stage 5e also competes with a weak answer (session 46): when the other stages'
    /// box of a whole-frame search (not a tracking window's, where the prior says where
    /// the target is) is rated below this, ‰, the spots are rated too, and the most confident
    /// spot replaces that box when it is rated higher (both are calibrated P(hit), so
    /// the likelier hit wins: a far target among clutter against a piece of the limb
    /// or a cloud edge passed at 0.6). A region answer rated at least this stands, under
    /// the gate too: a gate above it then gives "no target" rather than a spot (the
    /// answer does not depend on the gate). Only with [`AutoV2::spot`]; 0 turns it off
    /// (the spots run only when no region stage has an answer); 0..=1000, else
    /// [`DetectError::InvalidParameter`]. It costs one run of stage 5e (at most 5.5 M
    /// Cortex-M7 instructions per 328×248 frame) on the frames whose answer is rated
    /// below it. Default 800, chosen on family A (seeds 7001 and 7201; summed gated
    /// mean IoU of famA, paper A, fixtures A and famAF, ½ convention, change against 0):
    /// 700 → +0.0089, **800 → +0.0126**, 900 → +0.0156 (but famAT, the Tango close
    /// row, −0.0064, and paper A −0.0008), 1 000 → +0.0068; 800 is the largest value at
    /// which no family A set loses. No false alarm added on any set (`docs/detectors.md`
    /// § Session 46).
    pub spot_competes_below_permille: u16,
    /// Stage 5f ([`polygon`], session 55): on a whole-frame search whose answer is
    /// "no target" or rated below [`polygon::MAX_SCORE_PERMILLE`], the frame's straight
    /// outline — long straight edges meeting at agreeing corners — is the answer when
    /// it has one rated higher ([`polygon::Outline::score_permille`]) and passing the
    /// gate. Default on: on family A (seeds 7001, 7101, 7201) summed mean IoU +0.054,
    /// famA's radiometry close 0.382 → 0.553, the Tango close set 0.383 → 0.475, no false
    /// alarm added on famAE (fixtures A: 1 of 80; `docs/detectors.md` § Session 55).
    /// Since session 59 a shorter outline closed by the frame's border (a body cut by
    /// the frame, [`polygon::MIN_BORDER_OUTLINE_PX`]) counts too: famAT +0.020. It
    /// costs one pass of the segment detector ([`segments`]) on those frames (the
    /// flight demo's Tango frame +3.3 M Cortex-M7 instructions).
    pub outline: bool,
    /// Stage 4c: after the confidence rated the winner, target cells of other
    /// components up to this many cells from the winner's (Chebyshev) join it where
    /// the cell midway is at the body's level ([`bridges_body`]), cells: 1 joins
    /// nothing, 2 bridges a gap of one cell; 1..=[`MAX_LINK_CELLS`], else
    /// [`DetectError::InvalidParameter`]. A large target's flat faces score as
    /// background inside, so its target cells come scattered over it (edges, face
    /// boundaries) and the winner is one piece; joined after the rating, the box grows
    /// but whether there is a target (the winner, its confidence) does not change.
    /// Default 2: on family A (seed 7001; summed gated mean IoU of famA4, paper A,
    /// fixtures A, famAF, ½ convention) 1 → 2.472, **2 → 2.487**, 3 → 2.483, no
    /// false alarm added (`docs/detectors.md` § Session 37).
    pub link_cells: u8,
    /// A tracker's candidate floor, ‰ of confidence, or `None` (the default: off). With
    /// `Some(f)`, a region-stage winner rated below [`AutoV2::min_score_permille`] but
    /// at least `f` is still refined by stages 4c–8 and kept as the frame's candidate
    /// ([`AutoV2Work::candidate`]) before the call goes on (stage 5e; "no target" if
    /// nothing else passes the gate): the evidence a tracker confirms over several
    /// frames ([`crate::roi::track`]). The answer of the call does not change; the
    /// refinement costs one more pass of stages 4c–8 on frames whose winner lies under
    /// the gate. 0..=1000, else [`DetectError::InvalidParameter`].
    pub candidate_floor_permille: Option<u16>,
}

/// Confidence of a box of stage 2c (deep space), ‰: its hit rate (IoU ≥ ½) on family
/// A (seed 7001, `auto_v2_cells predict`, realistic erode 2, paper and fixtures erode
/// 0). Session 39, on session 38's renders (famA8, paper A, fixtures A, famAF, famAE8):
/// 85 hits of 102 boxes — fixtures 67 of 67, paper 6 of 6, realistic 12 of 29 (famA8 9
/// of 14, far radiometry famAF 3 of 14: boxes of a faint far target's brightest face,
/// inside its truth box), 2 on frames without a target. Session 29 measured 109 of 110
/// (990 ‰) on the renders of its day. Above the default gate: no box changes with it.
pub const DEEP_SPACE_SCORE_PERMILLE: u16 = 833;

/// Confidence of a box of stage 2c whose component is cut by one side of the window
/// (shorter along it than [`EARTH_MIN_CHORD_CELLS`]), ‰: its hit rate (IoU ≥ ½) on
/// family A (session 51, seeds 7001–7201: famA, paper A, fixtures A, famAF, famAT,
/// famAE, famASE; the renders before the cloud masses): 12 of 14 boxes (six fixtures
/// the classifier boxed alike before; Tango's panels and cubes cut by the frame over
/// deep space, `famAT/000049`, `000119`, `000135`, `000287`, `000295`, `famA/000135`;
/// the misses a part of a target, `famA/000035`, and an Earth-filled frame whose smooth
/// night side passed the deep-space test, `famAF/000035`), none on a frame without a
/// target. On the renders with cloud masses: 12 of 13 (`famAF/000035` no longer).
/// Also the confidence of stage 2c's corner pieces ([`in_corner`], session 53): on
/// session 52's renders the stage's border boxes of family A (both kinds) hit 16 of 20
/// (the corner pieces 3 of 4: `famA/000039`, `000119`, `famAT/000237`; the miss a
/// panel of `famAT/000050`, IoU 0.16), 800 ‰, within the sampling error of 857 (kept:
/// no box moves with it).
pub const BORDER_PIECE_SCORE_PERMILLE: u16 = 857;

/// Stage 2c: the strongest cell of a component cut by one side must reach this code
/// (1 + its departure in thresholds: 2 is one threshold, 6 spreads of the sky's fit)
/// to be boxed, and at this code a plateau's share of seeds
/// ([`BORDER_PLATEAU_SEED_DIV`]). The camera's shading departs from the fit at the
/// frame's edges by a threshold or so (`famASE/000047`: the bright top edge of a
/// target-less frame, boxed at 2); a target's faces depart by many. Chosen on family A
/// in session 51: 3 was the smallest that boxed no frame without a target, and kept the
/// summed mean IoU (5 and 8 gave back the gain, famAT 0.346 → 0.338 → 0.334). Session
/// 59 lowers it to 2 with the plateau test: a faint panel of Tango cut by the frame
/// (`famAT/000115`, `000185`, `000269`, `000271`: code 2) was left to the classifier,
/// which missed it.
pub const BORDER_PIECE_MIN_CODE: u8 = 2;

/// Stage 2c: a component cut by one side whose strongest cell departs no further than
/// [`BORDER_PIECE_MIN_CODE`] is boxed only when at least this share (1/n) of its cells
/// are seeds: a face cut by the frame departs as a plateau (its cells seeds, weak ones
/// only along its outline), the shading's misfit at the frame's edge as a ramp (a few
/// seeds amid weak cells: `famAE/000274`, 24 cells of which at most 5 seeds;
/// `famAF/000453`, 22 and 5). Chosen on family A (seeds 7001–7201, ½ convention,
/// with code 2): without the test famAT +0.0093 but a false alarm on famAE and
/// famAF −0.0014; 1/4 and **1/3** famAT +0.0093, no false alarm and no set lower (the
/// stricter of the tie); 1/2 +0.0034.
pub const BORDER_PLATEAU_SEED_DIV: u32 = 3;

/// Stage 2c: a departing component cut by one side of the window is boxed (not left to
/// the classifier) only when shorter along that side than this, cells (16: 128 px).
/// From low orbit the Earth's limb has a radius of curvature in the image of
/// f·tan ρ ≥ 2 300 px (ρ 64–70° from 800–400 km, f 1 140 px), so a piece of the disc
/// cut by one side alone is at most c²/8R ≈ 6 px deep and, to show at all (1 px
/// deep), at least 2√(2R) ≈ 136 px long. A component on two sides or longer may be
/// the disc (session 31's geometry; a high orbit, where the disc fits in the frame,
/// would need another bound); in a corner, the outline tells ([`in_corner`]). The
/// paper's camera at 10 871 km sees a smaller disc, R ≈ 700 px
/// ([`EARTH_MIN_LIMB_RADIUS_PX`]): a piece 1 px deep is then ≥ 75 px long, so pieces
/// of the disc shorter than this bound exist, 1–3 px deep: stage 4d's arc test on the
/// box catches them unless the box is deeper than the disc ([`deeper_than_the_disc`]).
pub const EARTH_MIN_CHORD_CELLS: usize = 16;

/// Whether a stage-2c component with cell box `w8` on plane `(pw, ph)` touches exactly
/// one side of it and is shorter along that side than [`EARTH_MIN_CHORD_CELLS`]: no
/// piece of the Earth's disc looks so ([`EARTH_MIN_CHORD_CELLS`]), a target cut by
/// the frame does.
fn cut_by_one_side(w8: CellStats, (pw, ph): (usize, usize)) -> bool {
    let chord = if on_vertical_side(w8, pw) {
        w8.y_end().saturating_sub(usize::from(w8.y0))
    } else {
        w8.x_end().saturating_sub(usize::from(w8.x0))
    };
    w8.sides_touched((pw, ph)) == 1 && chord < EARTH_MIN_CHORD_CELLS
}

/// Stage 4d's test: whether box `r` is the Earth at the frame's border, its limb
/// ([`limb::is_limb`]) or its disc saturated in a corner ([`limb::is_saturated_disc`],
/// deep space beyond it no warmer than [`SKY_RANGE_DIVISOR`] and [`SKY_NOISE_SIGMAS`]
/// allow over the frame's levels `lv`).
fn earth_at_border(frame: &Frame<'_>, r: Roi, lv: &FrameLevels) -> bool {
    let sky_max_dn = u32::from(lv.p2)
        + (u32::from(lv.p50.saturating_sub(lv.p2)) / SKY_RANGE_DIVISOR)
            .max(SKY_NOISE_SIGMAS * lv.sigma);
    limb::is_limb(frame, r) || limb::is_saturated_disc(frame, r, sky_max_dn)
}

/// Whether cell box `w8` on a plane `pw` cells wide touches the left or right side (a
/// piece cut by one side: its chord runs down that side).
fn on_vertical_side(w8: CellStats, pw: usize) -> bool {
    w8.x0 == 0 || w8.x_end() >= pw
}

/// The smallest radius of curvature of the Earth's limb in the image, px: the camera
/// at 10 871 km from the Earth's centre (the paper's scene) sees the disc's edge as an
/// arc of ~700–830 px (`limb`'s module docs); nearer the Earth it is larger.
pub const EARTH_MIN_LIMB_RADIUS_PX: u32 = 700;

/// Slack on the disc's greatest depth, px: the refined box's side may stand a pixel or
/// two beyond the limb (the optics' blur, the boundary's staircase).
pub const LIMB_DEPTH_SLACK_PX: u32 = 2;

/// Whether the box `r` of a stage-2c component cut by one side (cell box `w8` on plane
/// `(pw, ph)`) reaches deeper into the frame than a piece of the Earth's disc cut by that
/// side could: a chord `c` of a circle of radius R sags by c²/8R, so a piece as long
/// along the side as `r` is at most c²/(8 · [`EARTH_MIN_LIMB_RADIUS_PX`]) +
/// [`LIMB_DEPTH_SLACK_PX`] deep. A target's face cut by the side with a straight edge
/// across it passes stage 4d's arc test, but not this. Session 53, family A (seeds
/// 7001–7201, ½ convention): pieces taken for the limb before boxed now (`famA/000049`
/// 0 → 0.84, `famAT/000251`, `000253`, `fixA/000042`), summed mean IoU 2.5176 →
/// 2.5224, famAT 0.3768 → 0.3830, no false alarm added on any set.
fn deeper_than_the_disc(r: Roi, w8: CellStats, (pw, _): (usize, usize)) -> bool {
    let (chord, depth) = if on_vertical_side(w8, pw) {
        (u32::from(r.height()), u32::from(r.width()))
    } else {
        (u32::from(r.width()), u32::from(r.height()))
    };
    depth > chord * chord / (8 * EARTH_MIN_LIMB_RADIUS_PX) + LIMB_DEPTH_SLACK_PX
}

/// Stage 2c's seed cells of a component: those departing beyond the weak code.
#[derive(Debug, Clone, Copy)]
struct Seeds {
    /// The strongest code of the seeds above the fitted sky (their residual in
    /// `work.sum`, `f32` bits, as stage 2c left it; 0: none).
    up: u8,
    /// The strongest code of the seeds at or below the fitted sky (0: none). Nothing
    /// the camera sees is colder than deep space, so a target's cells depart upwards,
    /// while the sky in a corner of a smooth Earth-filled frame departs downwards from
    /// the surface fitted to the Earth; next to a bright target the fit may overshoot,
    /// so weaker cells beside it depart downwards (`famA/000105`: up 5, down 2).
    down: u8,
    /// How many seeds the component holds.
    count: u16,
}

impl Seeds {
    /// The strongest seed's code (0: no seed, a component of weak departures alone).
    fn strongest(self) -> u8 {
        self.up.max(self.down)
    }

    /// Whether every seed departs upwards.
    fn upwards(self) -> bool {
        self.down == 0
    }

    /// Whether a component of `cells` cells with these seeds is a target's piece cut by
    /// the frame: its strongest seed beyond [`BORDER_PIECE_MIN_CODE`], or at it with
    /// the seeds a plateau's share ([`BORDER_PLATEAU_SEED_DIV`]).
    fn departs_as_a_face(self, cells: u16) -> bool {
        let strongest = self.strongest();
        strongest > BORDER_PIECE_MIN_CODE
            || strongest == BORDER_PIECE_MIN_CODE
                && BORDER_PLATEAU_SEED_DIV * u32::from(self.count) >= u32::from(cells)
    }
}

/// The [`Seeds`] of stage 2c's component `root` over the first `n8` cells, in one pass.
fn seeds_of<C: FrameCapacity>(work: &mut AutoV2Work<C>, n8: usize, root: u8) -> Seeds {
    let mut seeds = Seeds {
        up: 0,
        down: 0,
        count: 0,
    };
    for i in 0..n8 {
        let (label, code) = (
            work.labels8.as_ref().get(i).copied().unwrap_or(0),
            work.labels4.as_ref().get(i).copied().unwrap_or(0),
        );
        if label != 0 && code > smooth::WEAK_CODE && work.comps.find(label) == root {
            let residual = work.sum.as_ref().get(i).map_or(0.0, |&r| f32::from_bits(r));
            let side = if residual > 0.0 {
                &mut seeds.up
            } else {
                &mut seeds.down
            };
            *side = (*side).max(code);
            seeds.count = seeds.count.saturating_add(1);
        }
    }
    seeds
}

/// Whether a stage-2c component with cell box `w8` on plane `(pw, ph)` lies in a
/// corner of it: it touches two adjacent sides (not a band across the window) and is
/// shorter than [`EARTH_MIN_CHORD_CELLS`] along both. The Earth's disc cut by a
/// corner looks so too; its in-frame outline is one nearly straight arc, a target's
/// bends ([`limb::Outline::Bends`], tested on the refined box).
fn in_corner(w8: CellStats, (pw, ph): (usize, usize)) -> bool {
    let (left, top, right, bottom) = (w8.x0 == 0, w8.y0 == 0, w8.x_end() >= pw, w8.y_end() >= ph);
    let across = w8.x_end().saturating_sub(usize::from(w8.x0));
    let down = w8.y_end().saturating_sub(usize::from(w8.y0));
    w8.sides_touched((pw, ph)) == 2
        && (left || right)
        && (top || bottom)
        && across < EARTH_MIN_CHORD_CELLS
        && down < EARTH_MIN_CHORD_CELLS
}

/// `r` carried out to each side of window `win` (plane `(pw, ph)` of its cells) that the
/// cell box `w8` touches.
fn to_touched_sides(r: Roi, w8: CellStats, (pw, ph): (usize, usize), win: Window) -> Roi {
    let (x1, y1) = ((win.x0 + win.w) as u16, (win.y0 + win.h) as u16);
    Roi {
        x0: if w8.x0 == 0 { win.x0 as u16 } else { r.x0 },
        y0: if w8.y0 == 0 { win.y0 as u16 } else { r.y0 },
        x1: if w8.x_end() >= pw { x1 } else { r.x1 },
        y1: if w8.y_end() >= ph { y1 } else { r.y1 },
    }
}

/// Confidence of a box of stage 2d (a small target over deep space, [`small`]), ‰:
/// its hit rate (IoU ≥ ½) on family A with session 68's thresholds (seeds 7001–7201:
/// famA 3 of 5, famAF 15 of 22, one of the 22 the Moon on a frame without a target;
/// paper A and fixtures A give none): 18 of 27. (Session 30's thresholds: 12 of 22,
/// 545 ‰, under the gate.) Held out: 22 of 30.
pub const SMALL_TARGET_SCORE_PERMILLE: u16 = 667;

/// Stage 2c's box side moves out to its cells' where they reach this many cells beyond
/// the refined box: a face too faint for a boundary of `fine_sigma` σ.
pub const DEEP_SPACE_FACE_CELLS: usize = 1;

/// Stage 2c's full-resolution boundary threshold, σ (at most [`AutoV2::fine_sigma`]).
/// Over deep space the background is a fitted smooth surface under white noise: a
/// step across two pixels (noise √2 σ) of 6 σ is 4.2 of their σ, about 3 in 10⁵ pixels
/// by chance, while targets cut by a corner over the shaded sky show steps of 7–8 σ
/// (`famA/000039`: 14 DN at σ 2 DN, `000119`: 6.5 σ) that 8 σ misses. Chosen on
/// family A (session 53, seeds 7001–7201, ½ convention, with the corner rule; summed
/// mean IoU of famA, paper A, fixtures A, famAF and famAT, Tango close): 8 → 2.4938 /
/// 0.3664, 7 → 2.4968 / 0.3701, **6 → 2.4965 / 0.3739**, 5 → 2.4939 / 0.3716; no
/// false alarm added on famAE, famASE or any other set.
pub const DEEP_SPACE_FINE_SIGMA: u16 = 6;

/// A box of stages 2b–8 under this many pixels on a side is no target (stage 5e's spots
/// may still answer): nothing is imaged on fewer than 2 px across (the optics' blur; the
/// `realistic` world's smallest far target is 3 px), while the real camera's hot pixel
/// is one. Session 53, family A (seeds 7001–7201, ½ convention): the 1-px boxes were hot
/// pixels the confidence rated 0.87–0.90 in frames without a target (`famAE/000032`,
/// `000119`, `famA/000084`, `famAT/000138`) or one pixel of a far target the spots then
/// box whole (`famAF/000318`, `000330`); summed mean IoU 2.5083 → 2.5176, false alarms
/// famA 1 → 0, famAE 10 → 8, famAT 1 → 0, famAT's IoU 0.3769 → 0.3768.
/// Stage 2c's and 2d's boxes must reach it too, else the next stage decides.
pub const MIN_BOX_SIDE_PX: u16 = 2;

/// Tracking window margin around the prior, pixels, on top of the prior's longer side
/// (`auto`'s default, room for a move of several pixels per frame). The window is
/// about three times the prior across: the cells' levels, the noise and the forest's
/// context are the window's own, and a target that fills much of its window is then
/// the window's "background". Chosen on family A (seed 7001; each frame's box tracked
/// again with itself as the prior, summed mean IoU ½ of famA, paperA, fixA): margin
/// 16 px + the longer side / 8, / 4, / 2, / 1: 1.994, 2.014, 2.008, 2.023 (no prior:
/// 2.027).
pub const TRACK_MARGIN_PX: usize = 16;

/// A tracking window over more than this share of the frame's pixels, ‰, is not
/// searched: the whole frame is at once. Such a window saves less than half of a
/// whole-frame search, and when the target is lost in it the call pays both: with the
/// cap a call with a prior costs at most 1½ whole-frame searches (the worst case of
/// `auto-v2+prior`, docs/flight.md).
pub const TRACK_MAX_WINDOW_PERMILLE: usize = 500;

/// The fast tracking path's window ([`AutoV2::look`]): the prior grown by this many
/// pixels plus its longer side / [`TRACK_FAST_MARGIN_DIVISOR`] on every side (`auto`'s
/// tracking window): room for a move of several pixels per frame and for the body
/// stage's ring; the classifier does not run there, so the window's own levels do not
/// shrink the box as they do in [`TRACK_MARGIN_PX`]'s window.
pub const TRACK_FAST_MARGIN_PX: usize = 16;

/// See [`TRACK_FAST_MARGIN_PX`].
pub const TRACK_FAST_MARGIN_DIVISOR: usize = 8;

/// The fast path's box must overlap the prior by at least this IoU, ‰: a box that
/// drifted further from the last one is left to the search. Chosen on family A (seed
/// 7001, `--track jitter`): 300 / 500 / 600 / 700 → summed mean IoU change +0.065 /
/// +0.054 / +0.048 / +0.031 against tracking without the fast path.
pub const TRACK_FAST_MIN_IOU_PERMILLE: u64 = 300;

/// Each side of the fast path's box may lie at most this many pixels plus
/// [`TRACK_FAST_SIDE_SLACK_PERMILLE`] of the prior's width (height) from the prior's
/// side: a target moves a few pixels and grows by a few per cent between frames, a box
/// that grew more took in background (the tracker would drift). The jittered priors of
/// `--track jitter` lie within 4 px + 10 %.
pub const TRACK_FAST_SIDE_SLACK_PX: u32 = 4;

/// See [`TRACK_FAST_SIDE_SLACK_PX`], ‰.
pub const TRACK_FAST_SIDE_SLACK_PERMILLE: u32 = 100;

/// A tracker's window ([`Window::around`] `prior` by `margin`), `None` when it covers
/// more than [`TRACK_MAX_WINDOW_PERMILLE`] of the frame: the window search's and the
/// fast path's cap.
fn capped_window(
    frame: &Frame<'_>,
    prior: Roi,
    margin: impl FnOnce(Roi) -> usize,
) -> Option<(Roi, Window)> {
    let (p, win) = Window::around(frame, prior, margin)?;
    let frame_px = frame.width() * frame.height();
    (win.w * win.h * 1000 <= frame_px * TRACK_MAX_WINDOW_PERMILLE).then_some((p, win))
}

/// Whether the fast path's box `r` follows the prior `p` (both cut to the frame): an
/// IoU of [`TRACK_FAST_MIN_IOU_PERMILLE`] or more and every side within
/// [`TRACK_FAST_SIDE_SLACK_PX`] + [`TRACK_FAST_SIDE_SLACK_PERMILLE`] of the prior's.
pub(crate) fn follows_prior(p: &Roi, r: &Roi) -> bool {
    let inter = u64::from(p.intersection(r).area());
    let union = u64::from(p.area()) + u64::from(r.area()) - inter;
    let slack = |size: u16| {
        TRACK_FAST_SIDE_SLACK_PX + u32::from(size) * TRACK_FAST_SIDE_SLACK_PERMILLE / 1000
    };
    let (sx, sy) = (slack(p.width()), slack(p.height()));
    let near = |a: u16, b: u16, s: u32| u32::from(a.abs_diff(b)) <= s;
    inter * 1000 >= union * TRACK_FAST_MIN_IOU_PERMILLE
        && near(r.x0, p.x0, sx)
        && near(r.x1, p.x1, sx)
        && near(r.y0, p.y0, sy)
        && near(r.y1, p.y1, sy)
}

/// Confidence of a box of the fast tracking path, ‰: its hit rate (IoU ≥ ½) on family
/// A (seed 7001: famA, paper A, fixtures A, famAF, famAT) with `tirroi eval --track
/// jitter`, 710 of 726 (12 of the 16 misses far targets of famAF, 67 of 79 there);
/// held out 596 of 599 (`docs/detectors.md` § Session 41). A P(hit) given a prior on
/// the target: a wrong prior whose box passes the look's checks is not in it (no false
/// alarm added on family A's `--track sequence`).
pub const TRACKED_SCORE_PERMILLE: u16 = 978;

/// The answer "no target": no box, confidence 0.
const NO_TARGET: Detection = Detection {
    roi: None,
    threshold: 0,
    foreground_px: 0,
    score_permille: 0,
};

/// Where stage 2b finds the saturated counts per cell in `labels4`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Counts {
    /// As [`prepare`] left them (the cell planes' pass counted them).
    FromPrepare,
    /// Overwritten by stage 3: counted again ([`blob::saturated_counts`]).
    Recount,
}

/// Deep space beyond a saturated disc ([`limb::is_saturated_disc`]) is no warmer than
/// the frame's 2nd percentile of cell means plus a quarter of the way to their median:
/// the sky is the frame's coldest level, the Earth beside a saturated target's piece
/// lies at the clouds' (famA/000348: a target's saturated sliver in a corner over the
/// Earth, an edge as straight as the limb's).
const SKY_RANGE_DIVISOR: u32 = 4;

/// ... and at least this many pixel noise σ above that percentile (a frame mostly deep
/// space has its median there too; the sky read past the disc's edge carries the
/// edge's blur and the noise: famAE/000018, 2.1 σ above the clipped sky, session 54).
const SKY_NOISE_SIGMAS: u32 = 3;

/// Relabelling step of the classifier's and stage 2c's cell codes when their cells
/// need more labels than there are (codes are quarter units of log-odds: 2 units).
const CELL_RELABEL_CODES: u8 = 8;

/// Relabelling step of the blob's cells when they need more labels than there are
/// (a frame strewn with clipped pixels), pixels at the top DN per cell.
const BLOB_RELABEL_PX: u8 = 8;

impl AutoV2 {
    /// The defaults (every field's documentation says why), as a constant: a tracker
    /// or a flight `static` is built from it at compile time.
    pub const DEFAULT: AutoV2 = AutoV2 {
        prior: None,
        look: None,
        fine_sigma: 8,
        cell_score: 0,
        min_score_permille: 550,
        saturated_erode_px: 2,
        body: body::BodyParams::DEFAULT,
        prescreen: true,
        blob: BlobRule::Compete,
        deep_space: true,
        sky_beside_earth: true,
        small_target: true,
        candidates: 3,
        spot: true,
        spot_competes_below_permille: 800,
        outline: true,
        link_cells: 2,
        candidate_floor_permille: None,
    };
}

impl Default for AutoV2 {
    fn default() -> Self {
        AutoV2::DEFAULT
    }
}

/// How stage 2b's saturated blob ([`blob`]) enters the decision.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BlobRule {
    /// No blob stage: the cell classifier alone (session 26's `auto-v2`).
    Off,
    /// The blob is the winner when its confidence ([`blob::BlobStats::score_permille`])
    /// reaches the gate ([`AutoV2::min_score_permille`]) and is above the classifier
    /// winner's (0 without one); otherwise the classifier's winner stands. On family A
    /// (famA25, paperAm, fixA) this beats taking the blob whenever it passes the gate
    /// (summed gated mean IoU 2.027 vs 2.006; the classifier alone 1.987): a target
    /// that saturates only in part keeps the classifier's box with its unsaturated faces.
    Compete,
    /// The largest blob, when the frame has one, is the winner whatever its
    /// confidence, and the classifier does not run: the blob model's training data
    /// (`scripts/train-auto.py --blob`).
    Always,
}

/// What the region stage chose on the last frame (for the confidence model's
/// training and for telemetry): `None` before any frame or without a component.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Winner {
    /// Target cells (8×8) of the winning component.
    pub cells: u16,
    /// Its cell box, cells.
    pub box_w_cells: u8,
    /// Its cell box, cells.
    pub box_h_cells: u8,
    /// Sides of the frame its cell box touches (0..=4).
    pub sides: u8,
    /// Summed class codes of its cells (quarter units of log-odds above the cell threshold).
    pub code_sum: u32,
    /// Its best cell's code.
    pub code_max: u8,
    /// Components found in the frame.
    pub components: u16,
    /// The runner-up's summed energy relative to the winner's, ‰ (0: no runner-up).
    pub runner_up_permille: u16,
    /// Its outline and border contrast ([`shape::winner_shape`]).
    pub shape: shape::WinnerShape,
    /// Rough pixels inside it, ‰ ([`shape::roughness_permille`]): cloud texture vs a
    /// target's flat faces.
    pub rough_permille: u16,
}

/// Number of the confidence model's features ([`Winner::confidence_features`]).
pub const CONFIDENCE_FEATURES: usize = 25;

/// A winner of at most this many 8×8 cells is "small" for the confidence's size-class
/// terms, cells: a far target of 3–12 px lies in one or two cells, and a linear weight
/// on the cell count alone rates it like a single noise cell.
pub const SMALL_WINNER_CELLS: u16 = 2;

impl Winner {
    /// The confidence model's integer features (`scripts/train-auto.py` computes the
    /// same from the training dumps): log codes of the cells and of the cell box's
    /// area, the box's fill ‰, sides touched, the mean code × 16, the best code, the
    /// log code of the component count, the runner-up ‰, and the winner's own shape
    /// ([`shape::WinnerShape`]): compactness ‰ (16 · cells / perimeter², 1000 for a
    /// square, capped there), the border contrast in σ and in the ring's spread (log
    /// codes); then how it meets the frame's edge and how flat it is: log codes of its
    /// cell sides on the frame's edge and of its reach into the frame, the sides it
    /// spans, the spread of its cells' levels (log code) and that minus the contrast in
    /// σ (a log ratio), its mean step code, its interior cells ‰ of its cells, their
    /// mean step code, the straightness ‰ (its cell box's outline over its own, capped
    /// at 1000); and terms per size class: small (at most [`SMALL_WINNER_CELLS`]: 1,
    /// else 0), small × the clutter contrast, small × the mean code × 16, and "touches
    /// the frame's edge" × the mean code × 16; last, its roughness ‰
    /// ([`shape::roughness_permille`]). Which of them the model uses is
    /// `confidence_weights.rs`' choice (weight 0: unused).
    pub fn confidence_features(&self) -> [i32; CONFIDENCE_FEATURES] {
        let cells = u32::from(self.cells).max(1);
        let area = u32::from(self.box_w_cells) * u32::from(self.box_h_cells);
        let sh = &self.shape;
        let perimeter = u64::from(sh.perimeter_cells).max(1);
        let compact = (16 * u64::from(cells) * 1000 / (perimeter * perimeter)).min(1000);
        let box_outline = 2 * (u64::from(self.box_w_cells) + u64::from(self.box_h_cells));
        let straight = (box_outline * 1000 / perimeter).min(1000);
        let mean16 = (self.code_sum * 16 / cells) as i32;
        let clutter = i32::from(sh.clutter_code);
        let small = i32::from(self.cells <= SMALL_WINNER_CELLS);
        [
            features::log_code(cells - 1),
            features::log_code(area.max(1) - 1),
            (cells * 1000 / area.max(1)) as i32,
            i32::from(self.sides),
            mean16,
            i32::from(self.code_max),
            features::log_code(u32::from(self.components)),
            i32::from(self.runner_up_permille),
            compact as i32,
            i32::from(sh.contrast_code),
            clutter,
            features::log_code(u32::from(sh.edge_sides)),
            features::log_code(u32::from(sh.reach_cells)),
            i32::from(sh.spans),
            i32::from(sh.spread_code),
            i32::from(sh.spread_code) - i32::from(sh.contrast_code),
            i32::from(sh.step_mean_code),
            (u32::from(sh.interior_cells) * 1000 / cells) as i32,
            i32::from(sh.interior_step_code),
            straight as i32,
            small,
            small * clutter,
            small * mean16,
            i32::from(self.sides > 0) * mean16,
            i32::from(self.rough_permille),
        ]
    }

    /// Confidence that the winner's box is a hit, ‰: the logistic of the fitted
    /// weights (`confidence_weights.rs`, 4096 per unit of log-odds) over
    /// [`Self::confidence_features`].
    pub fn score_permille(&self) -> u16 {
        weighted_logistic_permille(
            &self.confidence_features(),
            &confidence_weights::WEIGHTS,
            confidence_weights::BIAS,
        )
    }
}

/// `auto-v2`'s buffers (planes of 8×8 cells: `HalfCells`; of 4×4 cells: `Cells`).
/// `labels4` first holds the 8×8 cells' class codes (stage 3), then the 4×4 gate, then
/// the body stage's marks of 8×8 cells ([`body`]).
#[derive(Debug, Clone)]
pub struct AutoV2Work<C: FrameCapacity = Reference> {
    mean_dn: C::HalfCells<u16>,
    step_code: C::HalfCells<u8>,
    sum: C::HalfCells<u32>,
    sum_sq: C::HalfCells<u32>,
    sum_q: C::HalfCells<u32>,
    edges: C::HalfCells<u16>,
    labels8: C::HalfCells<u8>,
    labels4: C::Cells<u8>,
    dilated4: C::Cells<u8>,
    comps: EdgeComponents,
    cell_sums: C::CellRow<u32>,
    pixel_row: C::Row<u16>,
    col_sat: C::Row<u16>,
    row_sat: C::Column<u16>,
    hist: [u32; NOISE_BINS + 1],
    flag_row: C::Row<bool>,
    winner: Option<Winner>,
    blob: Option<blob::BlobStats>,
    blob_won: bool,
    tracked: bool,
    deep_space: Option<smooth::DeepSpace>,
    spot: Option<(Roi, u16)>,
    outline: Option<polygon::Outline>,
    candidate: Option<(Roi, u16)>,
}

impl<C: FrameCapacity> AutoV2Work<C> {
    /// Stage 5e's rated spots of window `win` ([`spot::rated_spots`]): the integral
    /// planes, free once the other stages have run, lend its column sums.
    fn rate_spots(
        &mut self,
        frame: &Frame<'_>,
        win: Window,
        lv: &FrameLevels,
    ) -> [Option<spot::RatedSpot>; spot::SPOTS] {
        spot::rated_spots(
            frame,
            win,
            lv,
            self.sum.as_mut(),
            self.sum_sq.as_mut(),
            self.sum_q.as_mut(),
        )
    }

    /// The frame's straight edges ([`segments::detect`]): the integral planes, free
    /// once the other stages have run, lend the marks (one bit per pixel).
    fn segments(&mut self, frame: &Frame<'_>, sigma: u32, out: &mut [segments::Segment]) -> usize {
        let pixels = frame.width() * frame.height();
        match segments::Marks::new(self.sum.as_mut(), self.sum_sq.as_mut(), pixels) {
            Some(mut marks) => segments::detect(frame, sigma, &mut marks, out),
            None => 0,
        }
    }

    /// What the region stage chose on the last frame (`None` when stage 4d found its
    /// box to be the Earth's limb at the frame's border, or the box was under
    /// [`MIN_BOX_SIDE_PX`]).
    pub fn winner(&self) -> Option<Winner> {
        self.winner
    }

    /// The largest saturated blob of the last frame (stage 2b), whether it won or not:
    /// `None` when the stage is off or the frame has fewer than
    /// [`blob::MIN_FRAME_SATURATED_PX`] pixels at the top DN.
    pub fn blob(&self) -> Option<blob::BlobStats> {
        self.blob
    }

    /// Whether the last frame's box (or, below the gate, its candidate) was the
    /// saturated blob ([`Self::blob`], whose confidence it carries) rather than the
    /// classifier's [`Self::winner`].
    pub fn blob_won(&self) -> bool {
        self.blob_won
    }

    /// What stage 2c saw on the last frame when it took the window for deep space
    /// (its box, if any, is then the stage's); `None` otherwise.
    pub fn deep_space(&self) -> Option<smooth::DeepSpace> {
        self.deep_space
    }

    /// `d`, the fast tracking path's box, as the call's answer: the flag set and what
    /// the other stages would have left cleared (nothing ran; telemetry reads these).
    fn tracked_box(&mut self, d: Detection) -> Detection {
        self.tracked = true;
        self.winner = None;
        self.blob = None;
        self.blob_won = false;
        self.deep_space = None;
        self.spot = None;
        self.outline = None;
        d
    }

    /// Whether the last frame's box came from the fast tracking path
    /// ([`AutoV2::look`]; it carries [`TRACKED_SCORE_PERMILLE`], and no other stage
    /// ran: [`Self::winner`], [`Self::blob`], [`Self::deep_space`] and [`Self::spot`]
    /// are then `None`).
    pub fn tracked(&self) -> bool {
        self.tracked
    }

    /// Stage 5e's answer on the last frame (its most confident spot's box and
    /// confidence ‰, whether or not it reached the gate) when the stage ran and no
    /// other stage's box is the answer; `None` when another stage answered (also when
    /// the spots competed with its box and lost,
    /// [`AutoV2::spot_competes_below_permille`]) or the stage is off.
    pub fn spot(&self) -> Option<(Roi, u16)> {
        self.spot
    }

    /// Stage 5f's outline when it was the last frame's answer ([`polygon`]: it
    /// competes with an answer under its confidence, or none, on a whole-frame search);
    /// `None` otherwise.
    pub fn outline(&self) -> Option<polygon::Outline> {
        self.outline
    }

    /// The stage whose box `answer` is (the last frame's answer, as the call returned
    /// it): read from the telemetry above, which only the answering stage sets;
    /// `None` for no box. A flight computer logs it beside the box (why this box);
    /// `tirroi eval` groups its statistics by it.
    pub fn stage(&self, answer: Option<Roi>) -> Option<Stage> {
        let r = answer?;
        Some(if self.tracked {
            Stage::Tracked
        } else if self.outline.is_some() {
            Stage::Outline
        } else if self.spot.is_some_and(|(b, _)| b == r) {
            Stage::Spot
        } else if self.blob_won {
            Stage::Blob
        } else if self.deep_space.is_some() {
            Stage::DeepSpace
        } else {
            Stage::Classifier
        })
    }

    /// The last frame's candidate below the gate ([`AutoV2::candidate_floor_permille`]):
    /// the region stage's winner refined, or else stage 5e's most confident spot,
    /// with its confidence ‰, when that lies in `[floor, gate)`; `None` when the call
    /// answered with a box, found nothing at the floor or the floor is off.
    pub fn candidate(&self) -> Option<(Roi, u16)> {
        self.candidate
    }
}

impl<C: FrameCapacity> ConstInit for AutoV2Work<C> {
    const INIT: Self = AutoV2Work {
        mean_dn: ConstInit::INIT,
        step_code: ConstInit::INIT,
        sum: ConstInit::INIT,
        sum_sq: ConstInit::INIT,
        sum_q: ConstInit::INIT,
        edges: ConstInit::INIT,
        labels8: ConstInit::INIT,
        labels4: ConstInit::INIT,
        dilated4: ConstInit::INIT,
        comps: ConstInit::INIT,
        cell_sums: ConstInit::INIT,
        pixel_row: ConstInit::INIT,
        col_sat: ConstInit::INIT,
        row_sat: ConstInit::INIT,
        hist: [0; NOISE_BINS + 1],
        flag_row: ConstInit::INIT,
        winner: None,
        blob: None,
        blob_won: false,
        tracked: false,
        deep_space: None,
        spot: None,
        outline: None,
        candidate: None,
    };
}

/// The stage of `auto-v2` that gave a frame's box ([`AutoV2Work::stage`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Stage {
    /// The fast tracking path ([`AutoV2::look`]): the last box's look found again.
    Tracked,
    /// Stage 2b: the frame's largest saturated blob ([`blob`], stage 8's cut).
    Blob,
    /// Stages 2c–2e: cells departing from a fitted sky ([`smooth`]: deep space, a
    /// small target there, or the sky beside the Earth).
    DeepSpace,
    /// Stages 3–8: the cell classifier's winner, refined.
    Classifier,
    /// Stage 5e: a small target among clutter ([`spot`]).
    Spot,
    /// Stage 5f: the frame's straight outline ([`polygon`]).
    Outline,
}

impl Stage {
    /// Every stage, in the order above.
    pub const ALL: [Stage; 6] = [
        Stage::Tracked,
        Stage::Blob,
        Stage::DeepSpace,
        Stage::Classifier,
        Stage::Spot,
        Stage::Outline,
    ];

    /// The stage's name in reports: `tracked`, `blob`, `deep-space`, `classifier`,
    /// `spot`, `outline`.
    pub const fn name(self) -> &'static str {
        match self {
            Stage::Tracked => "tracked",
            Stage::Blob => "blob",
            Stage::DeepSpace => "deep-space",
            Stage::Classifier => "classifier",
            Stage::Spot => "spot",
            Stage::Outline => "outline",
        }
    }
}

/// `auto-v2`'s scratch memory at capacity `C`.
pub type AutoV2Scratch<C = Reference> = Scratch<AutoV2Work<C>, C>;

/// Bytes of [`AutoV2Scratch`] at 328×248 (budget 48 KiB, checked at compile time).
pub const SCRATCH_BYTES: usize = core::mem::size_of::<AutoV2Scratch>();
const _: () = assert!(
    SCRATCH_BYTES <= 48 * 1024,
    "auto-v2's scratch exceeds 48 KiB"
);

/// Calls `f(cx, cy, features)` for every 8×8 cell of `frame` (training data for the
/// classifier; the same pass the detector runs, [`cell_pass`]). Returns the noise σ
/// used, DN.
pub fn for_each_cell_features<C: FrameCapacity>(
    frame: &Frame<'_>,
    work: &mut AutoV2Work<C>,
    mut f: impl FnMut(usize, usize, &[i32; FEATURES]),
) -> u32 {
    let (_, lv) = cell_pass(frame, work, false, |cx, cy, feats| {
        f(cx, cy, feats);
        0
    });
    lv.sigma
}

/// Stage 5e's spots of the whole `frame`, rated (training data for the spot forest;
/// the same code the detector runs, [`spot::rated_spots`], with the frame's noise and
/// levels), whatever the other stages answer.
pub fn rated_spots<C: FrameCapacity>(
    frame: &Frame<'_>,
    work: &mut AutoV2Work<C>,
) -> [Option<spot::RatedSpot>; spot::SPOTS] {
    let win = Window::full(frame);
    let (_, lv) = prepare_cells(frame, work, win);
    work.rate_spots(frame, win, &lv)
}

/// The straight edges of the whole `frame` ([`segments::detect`] with the frame's
/// noise σ; the integral planes lend the marks) into `out`; returns how many.
pub fn frame_segments<C: FrameCapacity>(
    frame: &Frame<'_>,
    work: &mut AutoV2Work<C>,
    out: &mut [segments::Segment],
) -> usize {
    let win = Window::full(frame);
    let (_, lv) = prepare_cells(frame, work, win);
    work.segments(frame, lv.sigma, out)
}

/// Stage 5f ([`polygon`]): the frame's straight outline, from its segments (on the
/// stack, [`segments::MAX_SEGMENTS`] of 16 B) found with the integral planes' marks.
#[inline(never)]
fn outline_stage<C: FrameCapacity>(
    frame: &Frame<'_>,
    work: &mut AutoV2Work<C>,
    sigma: u32,
) -> Option<polygon::Outline> {
    let mut segs = [segments::Segment::default(); segments::MAX_SEGMENTS];
    let n = work.segments(frame, sigma, &mut segs);
    polygon::strongest(segs.get(..n)?, frame.width(), frame.height())
}

/// Stages 1–3: prepares the planes ([`prepare`]), computes the features of the 8×8
/// cells (with their 4×4-pixel windows, [`cells::sub_window_extremes`]) and stores the
/// code `code(cx, cy, features)` returns in `labels4[cy · pw + cx]`: of every cell
/// (`screen` false), or of the cells [`prescreen::cascade`] reaches (`screen` true; the
/// others 0). The one cell loop of both the detector and the training dump.
fn cell_pass<C: FrameCapacity>(
    frame: &Frame<'_>,
    work: &mut AutoV2Work<C>,
    screen: bool,
    code: impl FnMut(usize, usize, &[i32; FEATURES]) -> u8,
) -> ((usize, usize), FrameLevels) {
    let win = Window::full(frame);
    let (plane, lv) = prepare(frame, work, win);
    classify_cells(frame, work, win, plane, lv, screen, code);
    (plane, lv)
}

/// Stage 4 on the codes in `labels4` (cells from code 1): 8-connected components in
/// `labels8`/`comps`, relabelled from a code `relabel_codes` higher when there are more
/// than the labels; the strongest (summed code) as `(root label, its cells' box and
/// statistics, labels used)`, `None` without one. Shared by the classifier's cells, the
/// saturated blob's and stage 2c's.
///
/// Kept out of line: inlined into `run_in` at its three call sites it cost the M7
/// +0.29 M instructions on every embedded frame (`scripts/flight.sh`, auto-v2 mean
/// 13.17 → 13.50 M; `run_in`'s hot loops spill more), out of line 13.21 M; x86 unchanged.
#[inline(never)]
fn strongest_component<C: FrameCapacity>(
    work: &mut AutoV2Work<C>,
    plane8: (usize, usize),
    relabel_codes: u8,
) -> Option<(u8, CellStats, usize)> {
    let n8 = plane8.0 * plane8.1;
    let next = label_edge_cells(
        work.labels4.as_ref().get(..n8)?,
        work.labels8.as_mut().get_mut(..n8)?,
        plane8.0,
        1,
        relabel_codes,
        &mut work.comps,
    );
    let (root, w8) = choose_target(&work.comps, next, plane8, 0)?;
    Some((root, w8, next))
}

/// Stage 2c's component: the strongest (as [`strongest_component`] chooses); when it
/// holds no seed (a cell coded above [`smooth::WEAK_CODE`]), the strongest seeded
/// component of at least [`DEEP_SPACE_FALLBACK_MIN_CELLS`] cells instead, if any
/// (else the weak one: the stage then hands over, as without it), with its
/// [`Seeds`] (one pass over the cells when the strongest is seeded). A band of the
/// shading's weak residuals along the frame's edge can outweigh a faint target's
/// seeded cells (`famAT/000023`, `000107`, `000175`, `000223`: 12–320 DN targets over
/// the shaded sky, each a 3–9-cell seeded component behind a weak band).
fn deep_space_component<C: FrameCapacity>(
    work: &mut AutoV2Work<C>,
    plane8: (usize, usize),
) -> Option<(u8, CellStats, usize, Seeds)> {
    let n8 = plane8.0 * plane8.1;
    let (root, w8, next) = strongest_component(work, plane8, CELL_RELABEL_CODES)?;
    let seeds = seeds_of(work, n8, root);
    if seeds.strongest() > 0 {
        return Some((root, w8, next, seeds));
    }
    // The roots of the components holding a seed (labels are `u8`).
    let mut flags = [0u8; 256];
    let cells = work.labels8.as_ref().get(..n8)?.iter();
    for (&l, &code) in cells.zip(work.labels4.as_ref()) {
        if l != 0 && code > smooth::WEAK_CODE {
            if let Some(f) = flags.get_mut(usize::from(work.comps.find(l))) {
                *f = SEEDED_ROOT;
            }
        }
    }
    let Some((root, w8)) =
        strongest_flagged_root(work, &flags, next, DEEP_SPACE_FALLBACK_MIN_CELLS)
    else {
        return Some((root, w8, next, seeds));
    };
    Some((root, w8, next, seeds_of(work, n8, root)))
}

/// A root's flag in [`strongest_flagged_root`]: its component holds a seed (and
/// nothing that rules it out).
const SEEDED_ROOT: u8 = 1;

/// Of the roots `1..next` of `labels8`'s components whose `flags` entry is exactly
/// [`SEEDED_ROOT`], the strongest (summed energy) of at least `min_cells` cells, with
/// its cell statistics (ties: the lowest label, as `choose_target`); `None` when none.
fn strongest_flagged_root<C: FrameCapacity>(
    work: &AutoV2Work<C>,
    flags: &[u8; 256],
    next: usize,
    min_cells: usize,
) -> Option<(u8, CellStats)> {
    let mut best: Option<(u8, CellStats)> = None;
    for (l, &f) in flags.iter().enumerate().take(next).skip(1) {
        if f != SEEDED_ROOT || work.comps.parents().get(l) != Some(&(l as u8)) {
            continue;
        }
        let Some(c) = work.comps.stats(l) else {
            continue;
        };
        if usize::from(c.area) >= min_cells && best.is_none_or(|(_, b)| c.energy > b.energy) {
            best = Some((l as u8, *c));
        }
    }
    best
}

/// Fewest cells of the seeded component stage 2c takes when its strongest component
/// holds no seed ([`deep_space_component`]): smaller seeded components are what the
/// fitted sky's own texture and shading give there (paper A's far sky, `000128`,
/// `000135`; famAE's shading edge, `000166`: false alarm), while a small target is
/// stage 2d's and 5e's. Chosen on family A (seeds 7001–7201, ½ convention, change of
/// the summed mean IoU of famA, paper A, fixtures A, famAF and famAT): 2 → +0.0129
/// and one false alarm added (famAE 6 → 7 of 300), **3 → +0.0143** (famAT 0.4753 →
/// 0.4878, famAF +0.0012, famA +0.0006; no set lower, no false alarm added), 4 →
/// +0.0106.
pub const DEEP_SPACE_FALLBACK_MIN_CELLS: usize = 3;

/// What stages 2c and 2e make of a component of departing cells.
enum Departure {
    /// The target's box (or [`NO_TARGET`] under the gate).
    Boxed(Detection),
    /// Not a target over the sky (the Earth's, by its geometry or sign): the
    /// classifier decides.
    Classifier,
    /// No box of [`MIN_BOX_SIDE_PX`] (a cell's noise, a hot pixel): stage 2d may look
    /// at the pixel scale.
    NoBox,
}

/// Fewest cells of stage 2e's component: one departing cell beside the Earth is the
/// fitted sky's noise or a hot pixel as often as a target (the Python replay of
/// session 57 took components of 2 cells and more). Family A (session 58): 3 → no
/// box moves (held out −0.0008), 4 → −0.0023, 6 → −0.0116 (fixtures A's small
/// targets beside the Earth).
pub const SKY_MIN_CELLS: u16 = 2;

/// Confidence of a box of stage 2e (the sky beside the Earth), ‰: its hit rate
/// (IoU ≥ ½) on family A (session 58, seeds 7001–7201): 26 of 31 (famA 4 of 5, famAT
/// 3 of 4, famAF 1 of 4: far targets boxed in part, fixtures A 18 of 18; none on a
/// frame without a target).
pub const SKY_BESIDE_EARTH_SCORE_PERMILLE: u16 = 839;

/// Stage 2e's component: labelled as stage 2c's ([`strongest_component`]), the
/// strongest (summed code) of those holding a seed, of at least [`SKY_MIN_CELLS`]
/// cells, none of them at [`earth_mask::MARGIN_CELLS`] of the Earth (`dilated4`
/// holds the cells' distances to it), with its [`Seeds`]; `None` without one.
fn sky_component<C: FrameCapacity>(
    work: &mut AutoV2Work<C>,
    plane8: (usize, usize),
) -> Option<(u8, CellStats, usize, Seeds)> {
    let n8 = plane8.0 * plane8.1;
    // Nothing the camera sees is colder than deep space: only cells departing upwards
    // from the fitted sky are a target's (`sum` holds the residuals, `f32` bits).
    for (code, &r) in work
        .labels4
        .as_mut()
        .iter_mut()
        .zip(work.sum.as_ref())
        .take(n8)
    {
        if f32::from_bits(r).is_nan() || f32::from_bits(r) <= 0.0 {
            *code = 0;
        }
    }
    let (_, _, next) = strongest_component(work, plane8, CELL_RELABEL_CODES)?;
    // Per root (labels are `u8`): seeded, and at the Earth's margin (refused).
    const AT_MARGIN: u8 = 2;
    let mut flags = [0u8; 256];
    let cells = work.labels8.as_ref().get(..n8)?.iter();
    for ((&l, &code), &d) in cells.zip(work.labels4.as_ref()).zip(work.dilated4.as_ref()) {
        if l == 0 {
            continue;
        }
        if let Some(f) = flags.get_mut(usize::from(work.comps.find(l))) {
            *f |= (u8::from(code > smooth::WEAK_CODE) * SEEDED_ROOT)
                | (u8::from(d <= earth_mask::MARGIN_CELLS) * AT_MARGIN);
        }
    }
    let (root, w8) = strongest_flagged_root(work, &flags, next, usize::from(SKY_MIN_CELLS))?;
    Some((root, w8, next, seeds_of(work, n8, root)))
}

/// Largest [`AutoV2::link_cells`], cells.
pub const MAX_LINK_CELLS: usize = 3;

/// Most sweeps of stage 4c over the cell plane (a component joined in one sweep can
/// bring others within reach in the next): a chain that needs more is left partly
/// joined, deterministically.
const MAX_LINK_PASSES: usize = 4;

/// Most target cells outside the winner stage 4c looks at per call (each looks at its
/// ≤ (2 · [`MAX_LINK_CELLS`] + 1)² neighbours): the stage stops there, the winner partly
/// joined, deterministically. A bound on the work, not a choice: on 3 220 frames of ten
/// sets (family A and B, the test sets; the gate off, so on every winner) a call looked
/// at 19 cells at most.
const MAX_LINK_LOOKS: usize = 256;

/// Whether target cells `a` and `b` (indices into the `pw`-wide plane of cell means
/// `mean_dn`) are one body across the gap between them: the cell midway departs from
/// the frame's level `level_dn` on the same side as both, by at least half the lesser
/// of their departures (the body's flat face between two of its edges, not the
/// background between two cloud fragments).
fn bridges_body(mean_dn: &[u16], pw: usize, level_dn: u16, a: usize, b: usize) -> bool {
    let pw = pw.max(1);
    let (ax, ay, bx, by) = (a % pw, a / pw, b % pw, b / pw);
    let m = (ay + by) / 2 * pw + (ax + bx) / 2;
    let dep =
        |i: usize| i32::from(mean_dn.get(i).copied().unwrap_or(level_dn)) - i32::from(level_dn);
    let (da, db, dm) = (dep(a), dep(b), dep(m));
    let same_side = (da > 0 && db > 0 && dm > 0) || (da < 0 && db < 0 && dm < 0);
    same_side && 2 * dm.abs() >= da.abs().min(db.abs())
}

/// Stage 4c ([`AutoV2::link_cells`]): joins to the winner `root` (labels in `labels8`,
/// `n8` cells of the `plane8` plane) every component with a cell within `reach` cells
/// of one of the winner's that [`bridges_body`] links to it, sweeping the winner's
/// cell box grown by `reach` until nothing joins ([`MAX_LINK_PASSES`] at most) or
/// [`MAX_LINK_LOOKS`] cells outside the winner were looked at. Returns the
/// root and statistics of the joined winner, `None` when nothing joined (or `reach`
/// ≤ 1).
fn join_linked<C: FrameCapacity>(
    work: &mut AutoV2Work<C>,
    plane8: (usize, usize),
    n8: usize,
    root: u8,
    reach: usize,
    level_dn: u16,
) -> Option<(u8, CellStats)> {
    join_linked_counted(work, plane8, n8, root, reach, level_dn).0
}

/// [`join_linked`] and the number of cells outside the winner it looked at.
fn join_linked_counted<C: FrameCapacity>(
    work: &mut AutoV2Work<C>,
    (pw, ph): (usize, usize),
    n8: usize,
    mut root: u8,
    reach: usize,
    level_dn: u16,
) -> (Option<(u8, CellStats)>, usize) {
    let mut looks = 0usize;
    let (Some(labels), Some(mean_dn)) = (
        work.labels8.as_ref().get(..n8),
        work.mean_dn.as_ref().get(..n8),
    ) else {
        return (None, looks);
    };
    if reach <= 1 || pw == 0 {
        return (None, looks);
    }
    let reach = reach.min(MAX_LINK_CELLS);
    let comps = &mut work.comps;
    let mut joined = false;
    'sweeps: for _ in 0..MAX_LINK_PASSES {
        let mut changed = false;
        // Only cells within `reach` of the winner's cell box can join it; the box is
        // read again on every row and after every join (a raster sweep carries a
        // chain rightwards and downwards in one pass, as over the whole plane).
        let Some(&first) = comps.stats(usize::from(root)) else {
            break;
        };
        let mut b = first;
        let mut y = usize::from(b.y0).saturating_sub(reach);
        while y < (b.y_end() + reach).min(ph) {
            let mut x = usize::from(b.x0).saturating_sub(reach);
            while x < (b.x_end() + reach).min(pw) {
                let (cx, cy, i) = (x, y, y * pw + x);
                x += 1;
                let l = labels.get(i).copied().unwrap_or(0);
                if l == 0 {
                    continue;
                }
                let r = comps.find(l);
                if r == root {
                    continue;
                }
                // The bound on the work (see `MAX_LINK_LOOKS`).
                if looks == MAX_LINK_LOOKS {
                    break 'sweeps;
                }
                looks += 1;
                let near = (cy.saturating_sub(reach)..(cy + reach + 1).min(ph)).any(|ny| {
                    (cx.saturating_sub(reach)..(cx + reach + 1).min(pw)).any(|nx| {
                        let j = ny * pw + nx;
                        labels.get(j).is_some_and(|&lj| {
                            lj != 0
                                && comps.find(lj) == root
                                && bridges_body(mean_dn, pw, level_dn, i, j)
                        })
                    })
                });
                if near {
                    root = comps.union(root, r);
                    b = comps.stats(usize::from(root)).copied().unwrap_or(b);
                    changed = true;
                    joined = true;
                }
            }
            y += 1;
        }
        if !changed {
            break;
        }
    }
    let out = if joined {
        comps.stats(usize::from(root)).map(|&s| (root, s))
    } else {
        None
    };
    (out, looks)
}

/// Most components stage 4b rates ([`AutoV2::candidates`]): the model's cost per
/// rated component is a pass over the cell plane.
pub const MAX_CANDIDATES: usize = 4;

// `AutoV2::validate`'s message names the bound.
const _: () = assert!(MAX_CANDIDATES == 4);

/// The [`MAX_CANDIDATES`] components of most energy among labels `1..next`, most
/// first, with `strongest` (the labelling's choice) first (label 0: none), and the
/// number of components.
fn strongest_roots(
    comps: &EdgeComponents,
    next: usize,
    strongest: u8,
) -> ([(u8, u32); MAX_CANDIDATES], u16) {
    let mut ranked = [(0u8, 0u32); MAX_CANDIDATES];
    let mut components = 0u16;
    let energy = |l: usize| comps.stats(l).map_or(0, |c| c.energy);
    if let Some(first) = ranked.first_mut() {
        *first = (strongest, energy(usize::from(strongest)));
    }
    for l in 1..next {
        if comps.parent(l) != Some(l as u8) {
            continue;
        }
        components = components.saturating_add(1);
        if l == usize::from(strongest) {
            continue;
        }
        let e = energy(l);
        // Insertion after the strongest: ties keep the lower label first.
        let mut item = (l as u8, e);
        for slot in ranked.iter_mut().skip(1) {
            if slot.0 == 0 || item.1 > slot.1 {
                core::mem::swap(slot, &mut item);
                if item.0 == 0 {
                    break;
                }
            }
        }
    }
    (ranked, components)
}

/// The statistics of component `root` (cell statistics `w8`) of `labels8` for the
/// confidence model, given the frame's component count and the runner-up's energy;
/// marks its cells in `dilated4` (free until stage 5's gate).
#[allow(clippy::too_many_arguments)]
fn rate_component<C: FrameCapacity>(
    frame: &Frame<'_>,
    win: Window,
    work: &mut AutoV2Work<C>,
    plane8: (usize, usize),
    lv: FrameLevels,
    n8: usize,
    root: u8,
    w8: CellStats,
    components: u16,
    runner_up: u32,
) -> Winner {
    let n8 = n8
        .min(work.labels4.as_ref().len())
        .min(work.labels8.as_ref().len())
        .min(work.mean_dn.as_ref().len())
        .min(work.step_code.as_ref().len());
    // The component's best cell score is its confidence's best code.
    let mut best = i32::MIN;
    let mut code_sum = 0u32;
    {
        let labels8 = &work.labels8.as_ref()[..n8];
        let codes = &work.labels4.as_ref()[..n8];
        let member = work.dilated4.as_mut();
        for (i, (&l, &c)) in labels8.iter().zip(codes).enumerate() {
            let is_member = l != 0 && work.comps.find(l) == root;
            if is_member {
                code_sum += u32::from(c);
                best = best.max(i32::from(c));
            }
            if let Some(m) = member.get_mut(i) {
                *m = u8::from(is_member);
            }
        }
    }
    let shape = shape::winner_shape(
        work.dilated4.as_ref().get(..n8).unwrap_or_default(),
        &work.labels4.as_ref()[..n8],
        &work.mean_dn.as_ref()[..n8],
        &work.step_code.as_ref()[..n8],
        plane8,
        (
            usize::from(w8.x0),
            usize::from(w8.y0),
            usize::from(w8.x_last),
            usize::from(w8.y_last),
        ),
        lv.sigma,
    );
    let rough_permille = shape::roughness_permille(
        frame,
        (win.x0, win.y0),
        work.dilated4.as_ref().get(..n8).unwrap_or_default(),
        plane8.0,
        usize::from(w8.area),
        lv.sigma,
    );
    Winner {
        rough_permille,
        cells: w8.area,
        box_w_cells: w8.x_last - w8.x0 + 1,
        box_h_cells: w8.y_last - w8.y0 + 1,
        sides: w8.sides_touched(plane8),
        code_sum,
        code_max: best.clamp(0, 255) as u8,
        components,
        runner_up_permille: (u64::from(runner_up) * 1000 / u64::from(w8.energy.max(1))).min(1000)
            as u16,
        shape,
    }
}

/// Stage 3 on prepared planes ([`prepare`]): see [`cell_pass`].
fn classify_cells<C: FrameCapacity>(
    frame: &Frame<'_>,
    work: &mut AutoV2Work<C>,
    win: Window,
    plane: (usize, usize),
    lv: FrameLevels,
    screen: bool,
    mut code: impl FnMut(usize, usize, &[i32; FEATURES]) -> u8,
) {
    let ints = Integrals {
        sum: work.sum.as_mut(),
        sum_sq: work.sum_sq.as_mut(),
        sum_q: work.sum_q.as_mut(),
        edges: work.edges.as_mut(),
    };
    let (mean_dn, step_code) = (work.mean_dn.as_ref(), work.step_code.as_ref());
    let mut feats = [0i32; FEATURES];
    let classify = |cx: usize, cy: usize| {
        let sub = cells::sub_window_extremes(frame, win, (cx, cy));
        cell_features(
            mean_dn,
            step_code,
            &ints,
            plane,
            lv,
            (cx, cy),
            sub,
            &mut feats,
        );
        code(cx, cy, &feats)
    };
    // `labels8` (the marks) and `dilated4` (the worklist) are free until stage 4.
    let rule = prescreen::SeedRule::new(&lv);
    prescreen::cascade(
        plane,
        work.labels4.as_mut(),
        work.labels8.as_mut(),
        work.dilated4.as_mut(),
        |cx, cy| !screen || rule.is_seed(mean_dn, step_code, ints.sum, plane, (cx, cy)),
        classify,
    );
}

/// Stages 1–2: noise, cell planes, levels, integrals.
fn prepare<C: FrameCapacity>(
    frame: &Frame<'_>,
    work: &mut AutoV2Work<C>,
    win: Window,
) -> ((usize, usize), FrameLevels) {
    let (plane, lv) = prepare_cells(frame, work, win);
    integrate_cells(work, plane, lv);
    (plane, lv)
}

/// Stages 1–2 without the integrals ([`integrate_cells`]): noise, cell planes, levels.
#[inline(always)]
fn prepare_cells<C: FrameCapacity>(
    frame: &Frame<'_>,
    work: &mut AutoV2Work<C>,
    win: Window,
) -> ((usize, usize), FrameLevels) {
    let plane = cell_plane(win);
    // Every window of a frame that fits the capacity has at most the planes' cells;
    // `min` says so to the compiler (no panic path in the slicing below).
    let n = (plane.0 * plane.1)
        .min(work.mean_dn.as_ref().len())
        .min(work.step_code.as_ref().len())
        .min(work.labels4.as_ref().len());
    let sigma = noise_sigma_second(frame, win, &mut work.hist, work.pixel_row.as_mut());
    fill_cells(
        frame,
        win,
        sigma,
        CellPlanes {
            mean_dn: &mut work.mean_dn.as_mut()[..n],
            step_code: &mut work.step_code.as_mut()[..n],
            // Free until stage 3 (its codes): the saturated blob reads them first.
            saturated_px: &mut work.labels4.as_mut()[..n],
        },
        work.cell_sums.as_mut(),
        work.col_sat.as_mut(),
    );
    let lv = levels(
        &work.mean_dn.as_ref()[..n],
        &work.step_code.as_ref()[..n],
        sigma,
        frame.max_dn(),
    );
    (plane, lv)
}

/// Stage 2's integrals of the cell planes (the classifier's context features).
fn integrate_cells<C: FrameCapacity>(
    work: &mut AutoV2Work<C>,
    plane: (usize, usize),
    lv: FrameLevels,
) {
    let n = (plane.0 * plane.1)
        .min(work.mean_dn.as_ref().len())
        .min(work.step_code.as_ref().len());
    integrate(
        &work.mean_dn.as_ref()[..n],
        &work.step_code.as_ref()[..n],
        plane,
        lv,
        &mut Integrals {
            sum: work.sum.as_mut(),
            sum_sq: work.sum_sq.as_mut(),
            sum_q: work.sum_q.as_mut(),
            edges: work.edges.as_mut(),
        },
    );
}

/// A fitted logistic model's P, ‰: the logistic of `bias + Σ feature · weight`, weights
/// and bias in 4096 per unit of log-odds (`scripts/train-auto.py`'s scale), as the
/// confidence of the classifier's winner and of the saturated blob use it.
pub(crate) fn weighted_logistic_permille(features: &[i32], weights: &[i32], bias: i32) -> u16 {
    let z = features
        .iter()
        .zip(weights)
        .fold(i64::from(bias), |z, (&f, &w)| {
            z + i64::from(f) * i64::from(w)
        });
    // 4096 per unit of log-odds → score units (256 per unit).
    let units = i64::from(forest::SCORE_ONE);
    logistic_permille((z * units / 4096).clamp(-(1 << 20), 1 << 20) as i32)
}

/// Logistic of a score (score units) in ‰, integer: a 33-point table of the logistic
/// over −8…8 log-odds, linear between.
pub(crate) fn logistic_permille(score: i32) -> u16 {
    const TABLE: [u16; 33] = [
        0, 1, 1, 2, 2, 4, 7, 11, 18, 29, 47, 76, 119, 182, 269, 378, 500, 622, 731, 818, 881, 924,
        953, 971, 982, 989, 993, 996, 998, 998, 999, 999, 1000,
    ];
    // Half a unit of log-odds per table step.
    let half = forest::SCORE_ONE / 2;
    let x = score.clamp(-16 * half, 16 * half) + 16 * half;
    let i = (x / half) as usize;
    let frac = x % half;
    let a = i32::from(TABLE[i.min(32)]);
    let b = i32::from(TABLE[(i + 1).min(32)]);
    (a + (b - a) * frac / half) as u16
}

impl AutoV2 {
    /// Sets the tracking prior ([`AutoV2::prior`]).
    pub const fn with_prior(self, prior: Option<Roi>) -> Self {
        AutoV2 { prior, ..self }
    }

    /// Sets the look of the prior's target on the last frame ([`AutoV2::look`]).
    pub const fn with_look(self, look: Option<look::Look>) -> Self {
        AutoV2 { look, ..self }
    }

    /// The tracking window around the prior, `None` without a prior, for an empty one
    /// (cut to the frame) or when the window is over [`TRACK_MAX_WINDOW_PERMILLE`] of
    /// the frame.
    fn tracking_window(&self, frame: &Frame<'_>) -> Option<(Roi, Window)> {
        capped_window(frame, self.prior?, |p| {
            TRACK_MARGIN_PX + usize::from(p.width().max(p.height()))
        })
    }

    /// The detection: in the tracking window first when there is a prior (its box
    /// stands when it passes the gate, overlaps the prior and is not cut by the
    /// window's border inside the frame), else on the whole frame.
    fn run<C: FrameCapacity>(&self, frame: &Frame<'_>, work: &mut AutoV2Work<C>) -> Detection {
        work.candidate = None;
        if let Some(d) = self.track_fast(frame, work) {
            return d;
        }
        if let Some((prior, win)) = self.tracking_window(frame) {
            let d = self.run_in(frame, work, win);
            if d.roi.is_some_and(|r| win.keeps(frame, &prior, &r)) {
                return d;
            }
        }
        self.run_in(frame, work, Window::full(frame))
    }

    /// The fast tracking path ([`AutoV2::look`]): in a window around the prior, when
    /// the prior's place still looks as the last look says, the window's largest
    /// saturated blob refined as stage 2b's (when its box follows the prior), else the
    /// prior's cells refined by stages 5–8; `Some` when that box stays in the window,
    /// follows the prior ([`follows_prior`]) and stands out on every side, else `None`
    /// (the search decides). Costs the window's noise and cell planes, at most two
    /// refinements and the looks of the prior's place and the boxes.
    #[inline(never)]
    fn track_fast<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoV2Work<C>,
    ) -> Option<Detection> {
        let last = self.look?;
        if TRACKED_SCORE_PERMILLE < self.min_score_permille {
            return None;
        }
        // Not over half the frame (the search decides, as for the window of the prior
        // alone: a refused box pays both).
        let (p, win) = capped_window(frame, self.prior?, |p| {
            TRACK_FAST_MARGIN_PX
                + usize::from(p.width().max(p.height())) / TRACK_FAST_MARGIN_DIVISOR
        })?;
        let (plane8, lv) = prepare_cells(frame, work, win);
        // The last box's place on this frame still looks as the last look says (before
        // any refinement: a refused place costs the cell planes only).
        if !last.matches(&look::Look::measure(frame, p)?, lv.sigma) {
            return None;
        }
        // A box found here stands when it stays in the window, follows the prior and
        // stands out from its strips on every side.
        let accepts = |r: &Roi| {
            win.keeps(frame, &p, r)
                && follows_prior(&p, r)
                && look::Look::measure(frame, *r)
                    .is_some_and(|now| now.stands_out(last.departure_dn()))
        };
        // A winner refined by stages 5–8 in the window, kept when its box is accepted.
        let refine = |work: &mut AutoV2Work<C>, winner| {
            let d = self.finish(
                frame,
                work,
                win,
                plane8,
                lv,
                winner,
                TRACKED_SCORE_PERMILLE,
                false,
            );
            d.roi
                .is_some_and(|r| accepts(&r))
                .then(|| work.tracked_box(d))
        };
        // A saturated target: the window's largest saturated blob, as stage 2b boxes it
        // (the body stage skipped, the optics' reach cut), when its box follows the
        // prior; the blob's cells and the prior's differ by the target's halo.
        if let Some((winner, _)) =
            self.blob_stage(frame, work, win, plane8, lv, Counts::FromPrepare)
        {
            if let Some(d) = refine(work, winner) {
                return Some(d);
            }
        }
        // Otherwise the cells the prior overlaps as the only target cells (code 255;
        // `labels4` held the saturated counts, read by the blob above; `mean_dn` and
        // `step_code`, which the refinement reads, are the window's still).
        let n8 = plane8.0 * plane8.1;
        let codes = work.labels4.as_mut().get_mut(..n8)?;
        codes.fill(0);
        // The cells `[a, b)` along one axis that overlap the prior's pixels `[lo, hi)`
        // (the window starts at `origin`, its plane has `count` cells).
        let overlapped = |lo: u16, hi: u16, origin: usize, count: usize| {
            let (lo, hi) = (usize::from(lo), usize::from(hi));
            let a = lo.saturating_sub(origin) / cells::CELL_PX;
            let b = hi
                .saturating_sub(origin)
                .div_ceil(cells::CELL_PX)
                .min(count);
            (a, b)
        };
        let (ax, bx) = overlapped(p.x0, p.x1, win.x0, plane8.0);
        let (ay, by) = overlapped(p.y0, p.y1, win.y0, plane8.1);
        for cy in ay..by {
            if let Some(row) = codes.get_mut(cy * plane8.0 + ax..cy * plane8.0 + bx.max(ax)) {
                row.fill(u8::MAX);
            }
        }
        let winner = strongest_component(work, plane8, CELL_RELABEL_CODES)?;
        refine(work, winner)
    }

    /// Every stage on the frame's window `win` (the whole frame, or the tracking
    /// window): cell planes, levels and the noise of the window alone.
    fn run_in<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoV2Work<C>,
        win: Window,
    ) -> Detection {
        // Stages 1–2: noise, cell planes, levels (the integrals after stage 2c, which
        // uses their plane as scratch).
        let (plane8, lv) = prepare_cells(frame, work, win);
        work.tracked = false;
        work.spot = None;
        work.outline = None;
        work.candidate = None;
        let d = self.regions_and_spots(frame, work, win, plane8, lv);
        // Stage 5f: a straight outline competes with a weak answer or none, on a
        // whole-frame search (in a tracking window the prior says where the target is),
        // but not where stage 2c boxed a target over deep space (whether or not its box
        // passed the gate, so that the answer above the gate does not depend on it):
        // there the fitted sky gives every departing cell (family A: 11 such boxes an
        // outline rated higher would replace, mean IoU 0.91 → 0.70).
        if !self.outline
            || !win.is_full(frame)
            || work.deep_space.is_some()
            || d.roi.is_some() && d.score_permille >= polygon::MAX_SCORE_PERMILLE
            || polygon::MAX_SCORE_PERMILLE < self.min_score_permille
        {
            return d;
        }
        let Some(outline) = outline_stage(frame, work, lv.sigma) else {
            return d;
        };
        let score_permille = outline.score_permille();
        if score_permille < self.min_score_permille
            || d.roi.is_some() && d.score_permille >= score_permille
        {
            return d;
        }
        // The outline is the answer: no other stage's (telemetry reads these).
        work.outline = Some(outline);
        work.candidate = None;
        work.winner = None;
        work.blob_won = false;
        work.deep_space = None;
        work.spot = None;
        Detection {
            roi: Some(outline.roi),
            threshold: 0,
            foreground_px: u32::from(outline.roi.width()) * u32::from(outline.roi.height()),
            score_permille,
        }
    }

    /// Stages 2b–8 and 5e on the window's planes: every stage but 5f.
    fn regions_and_spots<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoV2Work<C>,
        win: Window,
        plane8: (usize, usize),
        lv: FrameLevels,
    ) -> Detection {
        // A region answer rated at least `spot_competes_below_permille` stands against
        // the spots, under the gate too (then "no target"): the region stages run at
        // the lower of the two, so that the gate only decides whether the answer is
        // given and a stricter gate never brings up another stage's box (the fuzz
        // target's property). The default's spots compete above the gate (800 ≥ 550):
        // the region stages then run at the gate itself, every answer as before. (The
        // copy only when the gates differ: made on every call, it raised the M7 stack
        // peak by 488 B, 11 872 → 12 360 B; session 60's review.)
        let region_gate = if self.spot {
            self.min_score_permille
                .min(self.spot_competes_below_permille)
        } else {
            self.min_score_permille
        };
        let d = if region_gate < self.min_score_permille {
            AutoV2 {
                min_score_permille: region_gate,
                ..*self
            }
            .region_stages(frame, work, win, plane8, lv)
        } else {
            self.region_stages(frame, work, win, plane8, lv)
        };
        let d = if d
            .roi
            .is_some_and(|r| r.width() < MIN_BOX_SIDE_PX || r.height() < MIN_BOX_SIDE_PX)
        {
            // No stage's answer: as stage 4d drops a limb.
            work.winner = None;
            work.blob_won = false;
            work.deep_space = None;
            NO_TARGET
        } else {
            d
        };
        if let Some(r) = d.roi.filter(|_| d.score_permille < self.min_score_permille) {
            // Standing under the gate: no target, and a tracker's candidate at the
            // floor (as a region winner under the gate is).
            if work.candidate.is_none()
                && self
                    .candidate_floor_permille
                    .is_some_and(|f| d.score_permille >= f)
            {
                work.candidate = Some((r, d.score_permille));
            }
            return NO_TARGET;
        }
        if d.roi.is_some() {
            // A weak answer of a whole-frame search: stage 5e competes, the likelier hit
            // wins (in a tracking window the prior says where the target is).
            if self.spot
                && d.score_permille < self.spot_competes_below_permille
                && win.is_full(frame)
            {
                let s = self.spot_stage(frame, work, win, lv);
                if s.roi.is_some() && s.score_permille > d.score_permille {
                    return s;
                }
                // The other stage's box is the answer: the spot is no telemetry of it.
                work.spot = None;
            }
            // (A candidate is kept only with "no target".)
            return d;
        }
        let d = if self.spot {
            self.spot_stage(frame, work, win, lv)
        } else {
            d
        };
        if d.roi.is_some() {
            work.candidate = None;
        } else if work.candidate.is_none() {
            // No region winner at the floor: stage 5e's best spot under the gate.
            work.candidate = work
                .spot
                .filter(|&(_, s)| self.candidate_floor_permille.is_some_and(|f| s >= f));
        }
        d
    }

    /// Stage 5e ([`spot`]) after the other stages answered "no target": the most
    /// confident spot's box when its confidence reaches the gate (the integral planes,
    /// used by then, lend the column sums).
    #[inline(never)]
    fn spot_stage<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoV2Work<C>,
        win: Window,
        lv: FrameLevels,
    ) -> Detection {
        let rated = work.rate_spots(frame, win, &lv);
        // The most confident; the stronger spot on a tie.
        let mut best: Option<spot::RatedSpot> = None;
        for r in rated.iter().flatten() {
            if best.is_none_or(|b| r.score_permille > b.score_permille) {
                best = Some(*r);
            }
        }
        let Some(best) = best else {
            return NO_TARGET;
        };
        work.spot = Some((best.roi, best.score_permille));
        if best.score_permille < self.min_score_permille {
            return NO_TARGET;
        }
        Detection {
            roi: Some(best.roi),
            threshold: 0,
            foreground_px: u32::from(best.roi.width()) * u32::from(best.roi.height()),
            score_permille: best.score_permille,
        }
    }

    /// Stages 2b–8 on the window's planes (every stage but 5e).
    fn region_stages<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoV2Work<C>,
        win: Window,
        plane8: (usize, usize),
        lv: FrameLevels,
    ) -> Detection {
        work.winner = None;
        work.blob = None;
        work.blob_won = false;
        // Stage 2b: the frame's largest saturated blob, rated before the classifier
        // (its labels are redone below if it wins: stage 3 reuses the planes).
        let blob_score = match self.blob {
            BlobRule::Off => None,
            BlobRule::Compete | BlobRule::Always => {
                self.blob_stage(frame, work, win, plane8, lv, Counts::FromPrepare)
            }
        };
        if self.blob == BlobRule::Always {
            if let Some((winner, score_permille)) = blob_score {
                return self.finish_blob(frame, work, win, plane8, lv, winner, score_permille);
            }
        }
        let blob_score = blob_score.map(|(_, score)| score);
        work.deep_space = None;
        // Stage 2c: deep space (a smooth window), unless a saturated blob decides.
        if self.deep_space && blob_score.is_none() {
            if let Some(d) = self.deep_space_stage(frame, work, win, plane8, lv) {
                return d;
            }
        }
        integrate_cells(work, plane8, lv);
        // Stage 3: classify the cells; codes 1..=255 for target cells (the score
        // above the cell threshold, in quarter units of log-odds), 0 otherwise.
        let cell_score = i32::from(self.cell_score);
        classify_cells(
            frame,
            work,
            win,
            plane8,
            lv,
            self.prescreen,
            |_, _, feats| {
                // The flat form of `forest_trees.rs` (built at compile time; the same
                // score as walking its nodes, `forest::score`).
                match forest::FLIGHT.score_reaching(feats, cell_score) {
                    Some(s) => (1 + (s - cell_score) / (forest::SCORE_ONE / 4)).clamp(1, 255) as u8,
                    None => 0,
                }
            },
        );
        // The planes hold every window's cells (`min`: no panic path in the slicing).
        let n8 = (plane8.0 * plane8.1)
            .min(work.labels4.as_ref().len())
            .min(work.labels8.as_ref().len())
            .min(work.mean_dn.as_ref().len())
            .min(work.step_code.as_ref().len());
        // Stage 4: components of target cells, the strongest first.
        work.winner = None;
        let Some((root, _, next)) = strongest_component(work, plane8, CELL_RELABEL_CODES) else {
            return self
                .blob_over(frame, work, win, plane8, lv, blob_score, 0)
                .unwrap_or(NO_TARGET);
        };
        // Stage 4b: the strongest components rated by the confidence model.
        let Some((root, w8, winner)) =
            self.most_confident(frame, win, work, plane8, lv, n8, root, next)
        else {
            return NO_TARGET;
        };
        work.winner = Some(winner);
        let score_permille = winner.score_permille();
        if let Some(d) = self.blob_over(frame, work, win, plane8, lv, blob_score, score_permille) {
            return d;
        }
        let below_gate = score_permille < self.min_score_permille;
        if below_gate
            && self
                .candidate_floor_permille
                .is_none_or(|f| score_permille < f)
        {
            return NO_TARGET;
        }
        // Stage 4c: the target cells near the winner's, at its body's level, join it.
        let (root, w8) = join_linked(work, plane8, n8, root, usize::from(self.link_cells), lv.p50)
            .unwrap_or((root, w8));
        let d = self.finish(
            frame,
            work,
            win,
            plane8,
            lv,
            (root, w8, next),
            score_permille,
            false,
        );
        if below_gate {
            // A tracker's candidate: kept, and the call goes on as without a box.
            work.candidate = d.roi.map(|r| (r, score_permille));
            return NO_TARGET;
        }
        // Stage 4d (session 45): a box that is the Earth's limb at the frame's border, or
        // (session 54) its disc saturated in a corner, is no target (stage 5e's spots
        // may still answer). A candidate under the gate stays
        // one: a target entering the frame shows one straight edge too, and the sequence
        // tracker confirms a candidate by its motion against the ground.
        if d.roi.is_some_and(|r| earth_at_border(frame, r, &lv)) {
            work.winner = None;
            return NO_TARGET;
        }
        d
    }

    /// Stage 4b: of the [`AutoV2::candidates`] strongest components of `labels8`
    /// (`strongest` first, labels `1..next`), the one the confidence model rates
    /// highest (the stronger on a tie), with its cell statistics and its [`Winner`];
    /// `None` without a component. Every candidate is rated whatever
    /// the gate, so the answer above the gate does not depend on it (a box at one
    /// threshold is the box at every lower one; stopping once one passes the gate
    /// saved the M7 0.28 M instructions per frame but broke that).
    #[allow(clippy::too_many_arguments)]
    fn most_confident<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        win: Window,
        work: &mut AutoV2Work<C>,
        plane8: (usize, usize),
        lv: FrameLevels,
        n8: usize,
        strongest: u8,
        next: usize,
    ) -> Option<(u8, CellStats, Winner)> {
        let (ranked, components) = strongest_roots(&work.comps, next, strongest);
        let top_energy = ranked.first().map_or(0, |&(_, e)| e);
        let mut best: Option<(u8, CellStats, Winner, u16)> = None;
        // `validate` keeps it in 1..=MAX_CANDIDATES.
        let rated = usize::from(self.candidates);
        for (k, &(l, _)) in ranked.iter().enumerate().take(rated) {
            if l == 0 {
                break;
            }
            let Some(&stats) = work.comps.stats(usize::from(l)) else {
                continue;
            };
            // The runner-up of the strongest is the second; of any other, the strongest.
            let runner_up = if k == 0 {
                ranked.get(1).map_or(0, |&(_, e)| e)
            } else {
                top_energy
            };
            let w = rate_component(
                frame, win, work, plane8, lv, n8, l, stats, components, runner_up,
            );
            let score = w.score_permille();
            if best.is_none_or(|(_, _, _, b)| score > b) {
                best = Some((l, stats, w, score));
            }
        }
        best.map(|(l, stats, w, _)| (l, stats, w))
    }

    /// Stage 2c ([`smooth`]): when the window is deep space, its departing cells'
    /// strongest component (behind a band of weak cells, a seeded one:
    /// [`deep_space_component`]) refined as the classifier's winner is (stages 5, 7 and 8,
    /// boundaries of [`DEEP_SPACE_FINE_SIGMA`] σ), with [`DEEP_SPACE_SCORE_PERMILLE`]
    /// (a component cut by one side of the window and shorter along it than
    /// [`EARTH_MIN_CHORD_CELLS`], departing upwards by at least
    /// [`BORDER_PIECE_MIN_CODE`], whose box is no limb, or one in a corner
    /// ([`in_corner`]) whose outline bends
    /// ([`limb::Outline::Bends`]): with [`BORDER_PIECE_SCORE_PERMILLE`]); `None` (the classifier
    /// decides) when the window is not deep space, no cell departs, the component's
    /// strongest seed departs downwards (colder than deep space: the Earth read as
    /// smooth), the component touches the border otherwise, or the refinement finds no
    /// boundary (a far target within a cell's noise; the shading's own departures).
    ///
    /// Kept out of line (it runs once per frame): inlined into `run_in`, stage 2d's
    /// code (off by default) cost the M7 +0.22 M instructions on every embedded frame
    /// (`scripts/flight.sh`, `auto-v2` mean 13.21 → 13.43 M; `run_in`'s hot loops
    /// spill more); out of line 13.13 M.
    #[inline(never)]
    fn deep_space_stage<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoV2Work<C>,
        win: Window,
        plane8: (usize, usize),
        lv: FrameLevels,
    ) -> Option<Detection> {
        let n8 = (plane8.0 * plane8.1)
            .min(work.labels4.as_ref().len())
            .min(work.labels8.as_ref().len())
            .min(work.mean_dn.as_ref().len());
        // `labels4` holds the cells' saturated counts (stage 1) and takes the codes.
        // `sum` (the integrals', filled after this stage) holds the residuals.
        let Some(seen) = smooth::deep_space_codes(
            &work.mean_dn.as_ref()[..n8],
            &mut work.labels4.as_mut()[..n8],
            plane8,
            lv.sigma,
            work.sum.as_mut(),
        ) else {
            return if self.sky_beside_earth {
                self.sky_beside_earth_stage(frame, work, win, plane8, lv)
            } else {
                None
            };
        };
        let small_target = |this: &Self, work: &mut AutoV2Work<C>| {
            this.small_target
                .then(|| this.small_target_stage(frame, work, win, lv, seen))
                .flatten()
        };
        let Some((root, w8, next, seeds)) = deep_space_component(work, plane8) else {
            return small_target(self, work);
        };
        // A component of weakly departing cells alone is no target: a small target may
        // still be there at the pixel scale (stage 2d).
        if seeds.strongest() == 0 {
            return small_target(self, work);
        }
        let scores = (DEEP_SPACE_SCORE_PERMILLE, BORDER_PIECE_SCORE_PERMILLE);
        match self.box_departure(
            frame,
            work,
            win,
            plane8,
            lv,
            (root, w8, next),
            (seeds, seen),
            scores,
        ) {
            Departure::Boxed(d) => Some(d),
            // The surface was fitted to the Earth in part (its component departs
            // downwards) or the component is the Earth's (the limb, its disc in a
            // corner): the sky beside the Earth, fitted alone, may still hold a target.
            Departure::Classifier if self.sky_beside_earth => {
                // Stage 2c's codes took the saturated counts' plane.
                blob::saturated_counts(frame, win, work.labels4.as_mut());
                self.sky_beside_earth_stage(frame, work, win, plane8, lv)
            }
            Departure::Classifier => None,
            Departure::NoBox => small_target(self, work),
        }
    }

    /// Stage 2e ([`earth_mask`], [`AutoV2::sky_beside_earth`]): where the window holds
    /// the Earth and enough sky beside it, the sky alone is fitted as stage 2c fits the
    /// window, and its strongest seeded component of at least [`SKY_MIN_CELLS`] cells
    /// that does not reach the Earth's margin is boxed as stage 2c's is
    /// ([`AutoV2::box_departure`]), with [`SKY_BESIDE_EARTH_SCORE_PERMILLE`]; `None`
    /// (the classifier decides) otherwise.
    #[inline(never)]
    fn sky_beside_earth_stage<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoV2Work<C>,
        win: Window,
        plane8: (usize, usize),
        lv: FrameLevels,
    ) -> Option<Detection> {
        let n8 = (plane8.0 * plane8.1)
            .min(work.labels4.as_ref().len())
            .min(work.labels8.as_ref().len())
            .min(work.mean_dn.as_ref().len())
            .min(work.dilated4.as_ref().len());
        // `dilated4` takes the cells' distances to the Earth and `sum_sq` the floods'
        // stack (both free until stage 3); `sum` the residuals, as in stage 2c.
        earth_mask::earth_distance(
            &work.mean_dn.as_ref()[..n8],
            plane8,
            &mut work.dilated4.as_mut()[..n8],
            work.sum_sq.as_mut(),
        )?;
        let distance = &work.dilated4.as_ref()[..n8];
        let seen = smooth::sky_codes(
            &work.mean_dn.as_ref()[..n8],
            &mut work.labels4.as_mut()[..n8],
            plane8,
            lv.sigma,
            work.sum.as_mut(),
            distance,
            earth_mask::EXCLUDED_CELLS,
            earth_mask::MIN_SKY_PERMILLE,
        )?;
        let (root, w8, next, seeds) = sky_component(work, plane8)?;
        let scores = (
            SKY_BESIDE_EARTH_SCORE_PERMILLE,
            SKY_BESIDE_EARTH_SCORE_PERMILLE,
        );
        match self.box_departure(
            frame,
            work,
            win,
            plane8,
            lv,
            (root, w8, next),
            (seeds, seen),
            scores,
        ) {
            Departure::Boxed(d) => Some(d),
            Departure::Classifier | Departure::NoBox => None,
        }
    }

    /// Stages 2c and 2e: the seeded component `(root, w8, next)` of departing cells
    /// (their [`Seeds`]; what the fit saw, kept in the work when boxed) refined and
    /// judged as a target over the fitted sky; its box carries `scores.0`, or
    /// `scores.1` when cut by the window's border.
    #[allow(clippy::too_many_arguments)]
    fn box_departure<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoV2Work<C>,
        win: Window,
        plane8: (usize, usize),
        lv: FrameLevels,
        (root, w8, next): (u8, CellStats, usize),
        (seeds, seen): (Seeds, smooth::DeepSpace),
        (interior_permille, border_permille): (u16, u16),
    ) -> Departure {
        // A component on the window's border may be the Earth's disc in a corner (the
        // rest of the frame deep space): the classifier, trained on such frames,
        // decides, unless the geometry rules the disc out (a target cut by one side,
        // [`cut_by_one_side`]), which gets its own confidence.
        // Nothing the camera sees is colder than deep space, so a target's cells depart
        // upwards from the fitted sky. A strongest component whose strongest seed
        // departs downwards means the smooth surface was fitted to the Earth (an
        // Earth-filled frame with sparse cold clouds passes the deep-space test) and
        // its cold cloud would be boxed: the classifier decides (session 53; session 51
        // applied the same physics to pieces cut by one side, [`Seeds::upwards`]). On
        // family A (seeds 7001–7201, ½ convention): summed mean IoU 2.4965 → 2.5083
        // (famAF 0.2295 → 0.2411: faint far targets over the Earth reach the
        // classifier), famAT 0.3739 → 0.3769, false alarms famAE 19 → 10 of 300,
        // famASE 27 → 15 of 480, famAT 4 → 1, famAF 4 → 3; no set lower.
        if seeds.up <= seeds.down {
            return Departure::Classifier;
        }
        let border = w8.sides_touched(plane8) > 0;
        // A component in a corner is the stage's when its outline bends (tested after
        // the refinement, below).
        let corner = in_corner(w8, plane8);
        if border
            && !corner
            && !(cut_by_one_side(w8, plane8) && seeds.upwards() && seeds.departs_as_a_face(w8.area))
        {
            return Departure::Classifier;
        }
        let score_permille = if border {
            border_permille
        } else {
            interior_permille
        };
        let d = self.finish(
            frame,
            work,
            win,
            plane8,
            lv,
            (root, w8, next),
            score_permille,
            true,
        );
        // A piece of the Earth's limb after all (a smooth night side taken for deep
        // space, its limb crossing the box): stage 4d's test, on the box carried to
        // the window's side the component touches (the refinement may stop a pixel
        // short of it), unless a piece cut by one side is deeper than the disc's.
        // A corner piece must show a target's bend (a disc's corner piece is one arc;
        // a box whose boundary cannot be measured is left to the classifier).
        let carried = d.roi.map(|r| to_touched_sides(r, w8, plane8, win));
        let limb_piece = match carried {
            None => corner,
            Some(c) if corner => limb::outline(frame, c) != limb::Outline::Bends,
            Some(c) => {
                border
                    && !deeper_than_the_disc(c, w8, plane8)
                    && limb::outline(frame, c) == limb::Outline::Arc
            }
        };
        if limb_piece {
            return Departure::Classifier;
        }
        // A box one pixel across is a hot pixel (the real camera's signature): no
        // target is imaged on fewer than 2 px across (the `realistic` world's
        // smallest far target: 3 px).
        let Some(r) = d.roi else {
            return Departure::NoBox;
        };
        if r.width() < MIN_BOX_SIDE_PX || r.height() < MIN_BOX_SIDE_PX {
            // A hot pixel's cell: a small target may still be there (stage 2d).
            return Departure::NoBox;
        }
        work.deep_space = Some(seen);
        Departure::Boxed(if score_permille < self.min_score_permille {
            NO_TARGET
        } else {
            d
        })
    }

    /// Stage 2d ([`small`]) on a window stage 2c took for deep space without a target
    /// cell: the strongest small target's grown box with
    /// [`SMALL_TARGET_SCORE_PERMILLE`], or `None` (the classifier decides) when there is
    /// none, its box grows too far or is under [`small::MIN_SIDE_PX`] a side.
    /// The integral planes (filled after stage 2c) lend the column sums.
    fn small_target_stage<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoV2Work<C>,
        win: Window,
        lv: FrameLevels,
        seen: smooth::DeepSpace,
    ) -> Option<Detection> {
        let c = small::strongest_small_target(
            frame,
            win,
            lv.sigma,
            work.sum.as_mut(),
            work.sum_sq.as_mut(),
            work.sum_q.as_mut(),
        )?;
        let r = small::grown_box(frame, win, c, lv.sigma)?;
        if r.width() < small::MIN_SIDE_PX || r.height() < small::MIN_SIDE_PX {
            return None;
        }
        work.deep_space = Some(seen);
        Some(if SMALL_TARGET_SCORE_PERMILLE < self.min_score_permille {
            NO_TARGET
        } else {
            Detection {
                roi: Some(r),
                threshold: small::MIN_Z.saturating_mul(lv.sigma.max(1)) / 3,
                foreground_px: u32::from(r.x1 - r.x0) * u32::from(r.y1 - r.y0),
                score_permille: SMALL_TARGET_SCORE_PERMILLE,
            }
        })
    }

    /// [`BlobRule::Compete`]: the blob's detection when its confidence `blob_score`
    /// reaches the gate and is above the classifier winner's `classifier_score` (‰; 0
    /// without a winner); `None` leaves the classifier's answer standing.
    #[allow(clippy::too_many_arguments)]
    fn blob_over<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoV2Work<C>,
        win: Window,
        plane8: (usize, usize),
        lv: FrameLevels,
        blob_score: Option<u16>,
        classifier_score: u16,
    ) -> Option<Detection> {
        let score = blob_score?;
        if score < self.min_score_permille || score <= classifier_score {
            return None;
        }
        // The blob's labels again (stage 3 overwrote them): the same frame, the same
        // labels and confidence.
        let (winner, score) = self.blob_stage(frame, work, win, plane8, lv, Counts::Recount)?;
        let d = self.finish_blob(frame, work, win, plane8, lv, winner, score);
        // Stage 4d for the blob too (session 54): the saturated Earth's disc cut by a
        // corner of the frame is no target (stage 5e's spots may still answer).
        if d.roi.is_some_and(|r| earth_at_border(frame, r, &lv)) {
            work.winner = None;
            return Some(NO_TARGET);
        }
        Some(d)
    }

    /// Stages 5–8 on the blob's winner; below the gate, no target.
    #[allow(clippy::too_many_arguments)]
    fn finish_blob<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoV2Work<C>,
        win: Window,
        plane8: (usize, usize),
        lv: FrameLevels,
        winner: (u8, CellStats, usize),
        score_permille: u16,
    ) -> Detection {
        work.blob_won = true;
        if score_permille < self.min_score_permille {
            return NO_TARGET;
        }
        self.finish(frame, work, win, plane8, lv, winner, score_permille, false)
    }

    /// Stage 2b ([`blob`]): the frame's largest saturated blob, its statistics in
    /// `work.blob`, and the winner for stages 5–8 (its root label in `labels8`, its
    /// cell statistics, one past the last label) with its confidence ‰; `None` without
    /// a blob. Uses `labels4` (the saturated counts, [`Counts`]), `labels8`, `comps`
    /// and `dilated4` (the marks), which stage 3 refills.
    fn blob_stage<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoV2Work<C>,
        win: Window,
        plane8: (usize, usize),
        lv: FrameLevels,
        counts: Counts,
    ) -> Option<((u8, CellStats, usize), u16)> {
        let n8 = plane8.0 * plane8.1;
        let plane = work.labels4.as_mut().get_mut(..n8)?;
        let total = match counts {
            Counts::FromPrepare => plane.iter().map(|&c| u32::from(c)).sum(),
            Counts::Recount => blob::saturated_counts(frame, win, plane),
        };
        if total < blob::MIN_FRAME_SATURATED_PX {
            return None;
        }
        let (root, w8, next) = strongest_component(work, plane8, BLOB_RELABEL_PX)?;
        let marks = work.dilated4.as_mut().get_mut(..n8)?;
        for (m, &l) in marks.iter_mut().zip(work.labels8.as_ref().get(..n8)?) {
            *m = u8::from(l != 0 && work.comps.find(l) == root);
        }
        let marks = work.dilated4.as_ref().get(..n8)?;
        let cell_box = (
            usize::from(w8.x0),
            usize::from(w8.y0),
            usize::from(w8.x_last),
            usize::from(w8.y_last),
        );
        let stats = blob::blob_stats(
            frame,
            win,
            work.labels4.as_ref().get(..n8)?,
            work.mean_dn.as_ref().get(..n8)?,
            lv.p50,
            total,
            cell_box,
            |i| marks.get(i).is_some_and(|&m| m != 0),
        );
        work.blob = Some(stats);
        Some(((root, w8, next), stats.score_permille()))
    }

    /// Stages 5–8 on the winner (`root`, its cell statistics, one past the last
    /// label) of `labels8`: `auto`'s refinement in its gate, the whole body, the half
    /// maximum, the saturated cut.
    #[allow(clippy::too_many_arguments)]
    fn finish<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoV2Work<C>,
        win: Window,
        plane8: (usize, usize),
        lv: FrameLevels,
        (root, w8, next): (u8, CellStats, usize),
        score_permille: u16,
        space: bool,
    ) -> Detection {
        let n8 = plane8.0 * plane8.1;
        // Stage 5: the 4×4 gate plane from the 8×8 labels, then `auto`'s refinement.
        let plane4 = (win.w.div_ceil(4), win.h.div_ceil(4));
        let n4 = plane4.0 * plane4.1;
        // The planes hold the frame's cells (`prepare` sized them); called from three
        // places, this is not inlined where that is known, so every plane is taken
        // with `get` (no panic path): a short plane would mean no target.
        {
            let (Some(labels4), Some(labels8)) = (
                work.labels4.as_mut().get_mut(..n4),
                work.labels8.as_ref().get(..n8),
            ) else {
                return NO_TARGET;
            };
            for (cy, row) in labels4.chunks_exact_mut(plane4.0.max(1)).enumerate() {
                for (cx, l) in row.iter_mut().enumerate() {
                    // Every 4×4 cell lies in an 8×8 one (`get`: no panic path).
                    *l = labels8
                        .get((cy / 2) * plane8.0 + cx / 2)
                        .copied()
                        .unwrap_or_default();
                }
            }
        }
        let last = |c: u8, n: usize| ((usize::from(c) * 2 + 1).min(n - 1)) as u8;
        let w4 = CellStats {
            x0: w8.x0.saturating_mul(2),
            y0: w8.y0.saturating_mul(2),
            x_last: last(w8.x_last, plane4.0),
            y_last: last(w8.y_last, plane4.1),
            ..w8
        };
        let region = Region::around(&w4, win);
        let (Some(gate_labels), Some(gate_dilated)) = (
            work.labels4.as_mut().get_mut(..n4),
            work.dilated4.as_mut().get_mut(..n4),
        ) else {
            return NO_TARGET;
        };
        let gate = build_gate(
            gate_labels,
            gate_dilated,
            work.flag_row.as_mut(),
            &mut work.comps,
            root,
            next,
            &region,
            win,
            plane4,
        );
        let max_dn = frame.max_dn();
        let near_sat = max_dn.saturating_sub((4 * lv.sigma).min(u32::from(u16::MAX)) as u16);
        let counts = count_saturation::<C>(
            frame,
            &gate,
            &region,
            near_sat,
            // The region lies inside the frame (`get_mut`: no panic path if not).
            work.col_sat
                .as_mut()
                .get_mut(region.rx0..region.rx1)
                .unwrap_or_default(),
            work.row_sat
                .as_mut()
                .get_mut(region.ry0..region.ry1)
                .unwrap_or_default(),
        );
        let saturated = counts.sat_px >= MIN_SATURATED_PX
            && 8u32.saturating_mul(counts.near_px) < counts.sat_px;
        let _ = SATURATED_TAU_FACTOR;
        let fine_sigma = if space {
            self.fine_sigma.min(DEEP_SPACE_FINE_SIGMA)
        } else {
            self.fine_sigma
        };
        let tau = (u32::from(fine_sigma) * lv.sigma).min(u32::from(u16::MAX)) as u16;
        let noise = super::noise::Noise {
            sigma: lv.sigma,
            clean: false,
        };
        let (roi, edge_px) = outline(frame, &gate, &region, noise, tau, saturated, &counts);
        // Cells of the window to frame pixels, cut to the window.
        let px =
            |c: usize, origin: usize, len: usize| (origin + (c * cells::CELL_PX).min(len)) as u16;
        let cells_box = Roi {
            x0: px(usize::from(w8.x0), win.x0, win.w),
            y0: px(usize::from(w8.y0), win.y0, win.h),
            x1: px(usize::from(w8.x_last) + 1, win.x0, win.w),
            y1: px(usize::from(w8.y_last) + 1, win.y0, win.h),
        };
        let roi = match (roi, space) {
            // Without a boundary inside the gate, the winner's cells are the box (stage
            // 2c's cells are no box: a departure without an outline is the shading's).
            (None, false) => Some(cells_box),
            (None, true) => None,
            (Some(r), false) => Some(r),
            // Stage 2c: a face too faint for a boundary of `fine_sigma` σ still departs
            // at the cells' level (its cells joined the component).
            // A side moves to the cells' when they reach at least
            // `DEEP_SPACE_FACE_CELLS` cells beyond it (a face, not the cells' rounding).
            (Some(r), true) => {
                let reach = (DEEP_SPACE_FACE_CELLS * cells::CELL_PX) as u16;
                Some(Roi {
                    x0: if cells_box.x0 + reach <= r.x0 {
                        cells_box.x0
                    } else {
                        r.x0
                    },
                    y0: if cells_box.y0 + reach <= r.y0 {
                        cells_box.y0
                    } else {
                        r.y0
                    },
                    x1: if cells_box.x1 >= r.x1 + reach {
                        cells_box.x1
                    } else {
                        r.x1
                    },
                    y1: if cells_box.y1 >= r.y1 + reach {
                        cells_box.y1
                    } else {
                        r.y1
                    },
                })
            }
        };
        // Stage 6: the whole body, grown from the winner's cells over cells hotter or
        // colder than the ring around them (`labels4` is free after the refinement).
        // A saturated blob is a whole target already (stage 8 cuts it).
        let roi = roi.map(|r| {
            if space || saturated::is_saturated_blob(frame, r) {
                return r;
            }
            let (Some(marks), Some(labels8), Some(mean_dn)) = (
                work.labels4.as_mut().get_mut(..n8),
                work.labels8.as_ref().get(..n8),
                work.mean_dn.as_ref().get(..n8),
            ) else {
                return r;
            };
            for (m, &l) in marks.iter_mut().zip(labels8) {
                *m = if l != 0 && work.comps.find(l) == root {
                    body::WINNER
                } else {
                    0
                };
            }
            body::body_box(frame, win, mean_dn, marks, lv.sigma, r, self.body)
        });
        // Stage 7: small boxes cut to their half maximum (far targets' blur); over
        // deep space a weaker face counts from the noise alone (no clutter to keep
        // out; session 57), and so over a sky clipped at DN 0 seen through optics
        // that do not blur (no halo around a saturated face; session 59).
        let background = if space {
            half_max::Background::DeepSpace
        } else if self.saturated_erode_px == 0 {
            half_max::Background::ClutteredSharp
        } else {
            half_max::Background::Cluttered
        };
        let roi = roi.map(|r| half_max::half_max_box(frame, r, lv.sigma, background));
        // Stage 8: a saturated blob cut back by the optics' spread; a saturated core
        // (narrower than that spread: a target barely above the top DN) taken to the
        // target's half maximum around it instead (session 60).
        let erode_px = u16::from(self.saturated_erode_px);
        let roi = roi.map(|r| match saturated::saturated_target(frame, r, erode_px) {
            saturated::Saturated::Cut(cut) => cut,
            saturated::Saturated::Core(around) => {
                half_max::half_max_box(frame, around, lv.sigma, background)
            }
            saturated::Saturated::Neither => r,
        });
        Detection {
            roi,
            threshold: tau.into(),
            foreground_px: edge_px,
            score_permille,
        }
    }
}

impl core::fmt::Display for AutoV2 {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "fine_sigma={} cell_score={} min_score_permille={} saturated_erode_px={} \
             body_k_sigma={} body_ring_cells={}..={} body_max_share_permille={} \
             body_trim_permille={} prescreen={} blob={:?} deep_space={} sky_beside_earth={} \
             small_target={} \
             candidates={} spot={} spot_competes_below_permille={}",
            self.fine_sigma,
            self.cell_score,
            self.min_score_permille,
            self.saturated_erode_px,
            self.body.k_sigma,
            self.body.ring_from_cells,
            self.body.ring_to_cells,
            self.body.max_share_permille,
            self.body.trim_permille,
            self.prescreen,
            self.blob,
            self.deep_space,
            self.sky_beside_earth,
            self.small_target,
            self.candidates,
            self.spot,
            self.spot_competes_below_permille
        )
    }
}

impl Detector for AutoV2 {
    type Work<C: FrameCapacity> = AutoV2Work<C>;
    const NAME: &'static str = "auto-v2";

    fn validate(&self) -> Result<(), DetectError> {
        if !(1..=1000).contains(&self.fine_sigma) {
            return Err(DetectError::InvalidParameter {
                name: "fine_sigma",
                expected: "1..=1000 (multiples of the pixel noise σ)",
            });
        }
        if !(-4096..=4096).contains(&self.cell_score) {
            return Err(DetectError::InvalidParameter {
                name: "cell_score",
                expected: "-4096..=4096 (score units, 256 per unit of log-odds)",
            });
        }
        if self.min_score_permille > 1000 {
            return Err(DetectError::InvalidParameter {
                name: "min_score_permille",
                expected: "0..=1000",
            });
        }
        if self.spot_competes_below_permille > 1000 {
            return Err(DetectError::InvalidParameter {
                name: "spot_competes_below_permille",
                expected: "0..=1000 (‰ of confidence; 0: off)",
            });
        }
        if self.candidate_floor_permille.is_some_and(|f| f > 1000) {
            return Err(DetectError::InvalidParameter {
                name: "candidate_floor_permille",
                expected: "0..=1000 (‰ of confidence) or none",
            });
        }
        if self.saturated_erode_px > 8 {
            return Err(DetectError::InvalidParameter {
                name: "saturated_erode_px",
                expected: "0..=8 (pixels per side)",
            });
        }
        if !(1..=MAX_CANDIDATES).contains(&usize::from(self.candidates)) {
            return Err(DetectError::InvalidParameter {
                name: "candidates",
                expected: "1..=4 (components rated by the confidence model)",
            });
        }
        if !(1..=MAX_LINK_CELLS).contains(&usize::from(self.link_cells)) {
            return Err(DetectError::InvalidParameter {
                name: "link_cells",
                expected: "1..=3 (cells from the winner's joined to it)",
            });
        }
        if !self.body.is_valid() {
            return Err(DetectError::InvalidParameter {
                name: "body",
                expected: "k_sigma 0..=100, ring 1..=8 to ..=16 cells, \
                           max_share_permille 1..=1000, trim_permille 0..=1000",
            });
        }
        Ok(())
    }

    fn box_rule(&self) -> BoxRule {
        BoxRule::LargestComponent
    }

    fn foreground<C: FrameCapacity, F: FnMut(usize, &[bool])>(
        &self,
        frame: &Frame<'_>,
        work: &mut AutoV2Work<C>,
        mut sink: F,
    ) -> u32 {
        let d = self.run(frame, work);
        let roi = d.roi.unwrap_or(Roi::EMPTY);
        let mask_row = &mut work.flag_row.as_mut()[..frame.width()];
        for y in 0..frame.height() {
            roi.fill_mask_row(y, mask_row);
            sink(y, mask_row);
        }
        d.threshold
    }

    fn detect<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        scratch: &mut Scratch<AutoV2Work<C>, C>,
    ) -> Result<Detection, DetectError> {
        self.validate()?;
        DetectError::check_capacity::<C>(frame)?;
        Ok(self.run(frame, &mut scratch.work))
    }
}
/// A xorshift32 stream from `seed` (≠ 0): the tests' deterministic pseudo-random numbers.
#[cfg(test)]
pub(crate) fn xorshift32(seed: u32) -> impl FnMut() -> u32 {
    let mut s = seed;
    move || {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        s
    }
}

#[cfg(test)]
mod tests {
    use super::features::{FEATURES, log_code};
    use super::*;
    use crate::frame::{FRAME_HEIGHT, FRAME_WIDTH};

    /// A deterministic pseudo-random frame: texture, a bright block, hot pixels.
    fn frame_pixels(seed: u32, bits: u8) -> std::vec::Vec<u16> {
        let mut s = seed.wrapping_mul(2_654_435_761) | 1;
        let top = (1u32 << bits) - 1;
        (0..FRAME_WIDTH * FRAME_HEIGHT)
            .map(|i| {
                s ^= s << 13;
                s ^= s >> 17;
                s ^= s << 5;
                let (x, y) = (i % FRAME_WIDTH, i / FRAME_HEIGHT.max(1));
                let base = (top / 4) + (s % 64) + ((x / 16 + y / 16) as u32 % 3) * 40;
                let target = if (100..140).contains(&x) && (60..90).contains(&(i / FRAME_WIDTH)) {
                    top / 3
                } else {
                    0
                };
                let hot = if s % 5000 == 0 { top } else { 0 };
                (base + target).max(hot).min(top) as u16
            })
            .collect()
    }

    extern crate std;

    #[test]
    fn log_code_is_sixteen_log2() {
        let mut last = -1;
        for v in 0..100_000u32 {
            let c = log_code(v);
            assert!(c >= last, "monotone at {v}");
            last = c;
            let exact = 16.0 * libm::log2(f64::from(v) + 1.0);
            // log2(1 + f) − f ≤ 0.0861 (at f = 0.4427): 1.38 codes, plus the floor.
            assert!(
                f64::from(c) <= exact + 1e-9 && exact - f64::from(c) < 2.4,
                "{v}: {c} vs {exact}"
            );
        }
    }

    #[test]
    fn percentiles_equal_a_sort() {
        let px = frame_pixels(7, 14);
        let vals: std::vec::Vec<u16> = px.iter().step_by(61).copied().take(1271).collect();
        let mut sorted = vals.clone();
        sorted.sort_unstable();
        let lv = features::levels(&vals, &[], 3, 16383);
        let n = vals.len() - 1;
        assert_eq!(lv.p2, sorted[n * 2 / 100]);
        assert_eq!(lv.p50, sorted[n * 50 / 100]);
        assert_eq!(lv.p98, sorted[n * 98 / 100]);
    }

    #[test]
    fn box_features_equal_brute_force() {
        let px = frame_pixels(11, 14);
        let frame = Frame::new(&px, FRAME_WIDTH, FRAME_HEIGHT, 14).unwrap();
        let mut work: std::boxed::Box<AutoV2Work> = std::boxed::Box::new(ConstInit::INIT);
        let mut got = std::vec::Vec::new();
        let sigma = for_each_cell_features(&frame, &mut work, |cx, cy, f| got.push((cx, cy, *f)));
        let (pw, ph) = (41, 31);
        assert_eq!(got.len(), pw * ph);
        // Brute force: cell means from the pixels, box means over the cut boxes.
        let mean = |cx: usize, cy: usize| {
            let (mut s, mut n) = (0u64, 0u64);
            for y in cy * 8..(cy * 8 + 8).min(FRAME_HEIGHT) {
                for x in cx * 8..(cx * 8 + 8).min(FRAME_WIDTH) {
                    s += u64::from(px[y * FRAME_WIDTH + x]);
                    n += 1;
                }
            }
            (s / n) as i64
        };
        for &(cx, cy, f) in got.iter().step_by(37) {
            let m = mean(cx, cy);
            for (k, &r) in features::RADII_CELLS.iter().enumerate() {
                let (x0, y0) = (cx.saturating_sub(r), cy.saturating_sub(r));
                let (x1, y1) = ((cx + r).min(pw - 1), (cy + r).min(ph - 1));
                let (mut s, mut n) = (0i64, 0i64);
                for y in y0..=y1 {
                    for x in x0..=x1 {
                        s += mean(x, y);
                        n += 1;
                    }
                }
                let d = m - s / n;
                let q = (d.unsigned_abs() * 4 / u64::from(sigma)) as u32;
                let want = if d < 0 { -log_code(q) } else { log_code(q) };
                assert_eq!(f[5 + 4 * k], want, "cell ({cx}, {cy}) radius {r}");
            }
            assert!(f.iter().all(|v| v.abs() <= 1 << 16));
            assert_eq!(f.len(), FEATURES);
        }
        // Feature 32: the cell's step code less the frame's 90th percentile of them
        // (a sort of every cell's feature 3).
        let mut steps: std::vec::Vec<i32> = got.iter().map(|(_, _, f)| f[3]).collect();
        steps.sort_unstable();
        let rank = steps[(steps.len() - 1) * features::STEP_RANK_PERCENT / 100];
        assert!(rank > steps[0], "the frame has steps of several sizes");
        for &(cx, cy, f) in &got {
            assert_eq!(f[FEATURES - 1], f[3] - rank, "cell ({cx}, {cy})");
        }
    }

    /// The 4×4-window features against a brute force over the pixels: every 4×4
    /// window at a 2-px stride inside the cell, the 8 neighbours' mean of cell means.
    #[test]
    fn window_features_equal_brute_force() {
        let mut px = frame_pixels(13, 14);
        // A 3×3-pixel hot spot and a 4×4 cold spot inside single cells.
        for y in 41..44 {
            for x in 162..165 {
                px[y * FRAME_WIDTH + x] = 9000;
            }
        }
        for y in 200..204 {
            for x in 18..22 {
                px[y * FRAME_WIDTH + x] = 10;
            }
        }
        let frame = Frame::new(&px, FRAME_WIDTH, FRAME_HEIGHT, 14).unwrap();
        let mut work: std::boxed::Box<AutoV2Work> = std::boxed::Box::new(ConstInit::INIT);
        let mut got = std::vec::Vec::new();
        let sigma = for_each_cell_features(&frame, &mut work, |cx, cy, f| got.push((cx, cy, *f)));
        let (pw, ph) = (41, 31);
        let mean = |cx: usize, cy: usize| {
            let mut s = 0i64;
            for y in cy * 8..cy * 8 + 8 {
                for x in cx * 8..cx * 8 + 8 {
                    s += i64::from(px[y * FRAME_WIDTH + x]);
                }
            }
            s / 64
        };
        let slog = |d: i64| {
            let q = (d.unsigned_abs() * 4 / u64::from(sigma)) as u32;
            if d < 0 { -log_code(q) } else { log_code(q) }
        };
        let o = 5 + 4 * features::RADII_CELLS.len();
        // The frame's cell-mean percentiles by a sort.
        let mut sorted: std::vec::Vec<i64> = (0..pw * ph).map(|i| mean(i % pw, i / pw)).collect();
        sorted.sort_unstable();
        let last = sorted.len() - 1;
        let (p2, p98) = (sorted[last * 2 / 100], sorted[last * 98 / 100]);
        let at_cell = |got: &[(usize, usize, [i32; FEATURES])], c: (usize, usize)| {
            got.iter().find(|g| (g.0, g.1) == c).unwrap().2
        };
        let mut checked_spots = 0;
        for &(cx, cy, f) in &got {
            let spot = (cx, cy) == (20, 5) || (cx, cy) == (2, 25);
            if !spot && (cy * pw + cx) % 23 != 0 {
                continue;
            }
            checked_spots += usize::from(spot);
            let (mut hot, mut cold) = (i64::MIN, i64::MAX);
            for wy in [0, 2, 4] {
                for wx in [0, 2, 4] {
                    let mut s = 0i64;
                    for y in cy * 8 + wy..cy * 8 + wy + 4 {
                        for x in cx * 8 + wx..cx * 8 + wx + 4 {
                            s += i64::from(px[y * FRAME_WIDTH + x]);
                        }
                    }
                    hot = hot.max(s / 16);
                    cold = cold.min(s / 16);
                }
            }
            let (mut s, mut n) = (0i64, 0i64);
            for y in cy.saturating_sub(1)..=(cy + 1).min(ph - 1) {
                for x in cx.saturating_sub(1)..=(cx + 1).min(pw - 1) {
                    if (x, y) != (cx, cy) {
                        s += mean(x, y);
                        n += 1;
                    }
                }
            }
            let reference = s / n;
            let m = mean(cx, cy);
            assert_eq!(f[o], slog(hot - reference), "hot, cell ({cx}, {cy})");
            assert_eq!(f[o + 1], slog(cold - reference), "cold, cell ({cx}, {cy})");
            assert_eq!(f[o + 4], slog(hot - m), "hot vs cell, ({cx}, {cy})");
            assert_eq!(f[o + 5], slog(cold - m), "cold vs cell, ({cx}, {cy})");
            // The clutter-scaled forms: the same sign, at most 16 per σ of contrast.
            for (k, d) in [(2, hot - reference), (3, cold - reference)] {
                let v = i64::from(f[o + k]);
                assert!(v == 0 || v.signum() == d.signum(), "({cx}, {cy}) {k}");
                assert!(v.abs() <= (d.abs() * 16 / i64::from(sigma)).max(1));
            }
            // The frame features (27–31): the windows against the sorted cell means'
            // 2nd and 98th percentiles, their spread, the departure of either sign, the
            // cells to the frame's edge counted by hand.
            let q = o + features::SUB_FEATURES;
            assert_eq!(f[q], slog(cold - p2), "cold vs p2, ({cx}, {cy})");
            assert_eq!(f[q + 1], slog(hot - p98), "hot vs p98, ({cx}, {cy})");
            assert_eq!(f[q + 2], slog(hot - cold), "spread, ({cx}, {cy})");
            assert!(f[q + 2] >= 0);
            assert_eq!(
                f[q + 3],
                f[o + 2].abs().max(f[o + 3].abs()),
                "departure ({cx}, {cy})"
            );
            let edge = [cx, cy, pw - 1 - cx, ph - 1 - cy, 8]
                .into_iter()
                .min()
                .unwrap();
            assert_eq!(f[q + 4], edge as i32, "edge distance, ({cx}, {cy})");
        }
        assert_eq!(checked_spots, 2);
        // The spots: the cold one below the frame's low end, the hot one above its top.
        let q = o + features::SUB_FEATURES;
        assert!(at_cell(&got, (2, 25))[q] < -log_code(4 * 100));
        assert!(at_cell(&got, (20, 5))[q + 1] > log_code(4 * 20));
        assert!(at_cell(&got, (20, 5))[q + 2] > log_code(4 * 20));
        // The spots stand out: a hot window far above its neighbours, a cold one far below.
        let at = |c: (usize, usize)| got.iter().find(|g| (g.0, g.1) == c).unwrap().2;
        assert!(at((20, 5))[o] > log_code(4 * 100), "{:?}", at((20, 5)));
        assert!(at((2, 25))[o + 1] < -log_code(4 * 100), "{:?}", at((2, 25)));
    }

    /// The pre-screen's seed rule on the planes (`prescreen::SeedRule`, what the detector
    /// runs) equals the rule on the cell's features (`is_seed_features`, what the checks
    /// on feature dumps use), on textured frames at three bit depths; and the detector
    /// with the cascade finds the same box as the full pass on them.
    #[test]
    fn seed_rule_on_planes_equals_rule_on_features() {
        let mut seeds = 0;
        for (seed, bits) in [(3, 14), (5, 12), (9, 16)] {
            let px = frame_pixels(seed, bits);
            let frame = Frame::new(&px, FRAME_WIDTH, FRAME_HEIGHT, bits).unwrap();
            let mut work: std::boxed::Box<AutoV2Work> = std::boxed::Box::new(ConstInit::INIT);
            let mut want = std::vec::Vec::new();
            for_each_cell_features(&frame, &mut work, |_, _, f| {
                want.push(prescreen::is_seed_features(f))
            });
            let (plane, lv) = prepare(&frame, &mut work, Window::full(&frame));
            let rule = prescreen::SeedRule::new(&lv);
            for cy in 0..plane.1 {
                for cx in 0..plane.0 {
                    let got = rule.is_seed(
                        work.mean_dn.as_ref(),
                        work.step_code.as_ref(),
                        work.sum.as_ref(),
                        plane,
                        (cx, cy),
                    );
                    assert_eq!(got, want[cy * plane.0 + cx], "({cx}, {cy}) seed {seed}");
                    seeds += usize::from(got);
                }
            }
            let mut scratch = std::boxed::Box::new(AutoV2Scratch::new());
            let on = AutoV2::default().detect(&frame, &mut scratch).unwrap();
            let full = AutoV2 {
                prescreen: false,
                ..AutoV2::default()
            };
            assert_eq!(on, full.detect(&frame, &mut scratch).unwrap());
        }
        // Both outcomes occur (the block's outline seeds, the flat texture does not).
        assert!(seeds > 0 && seeds < 3 * 41 * 31, "{seeds}");
    }

    /// A noisy flat frame (σ ≈ 8 DN) with uniform blocks `(x0, y0, x1, y1, DN above)`.
    fn blocks_frame(blocks: &[(usize, usize, usize, usize, u16)]) -> std::vec::Vec<u16> {
        let mut s = 0x2545_f491u32;
        (0..FRAME_WIDTH * FRAME_HEIGHT)
            .map(|i| {
                s ^= s << 13;
                s ^= s >> 17;
                s ^= s << 5;
                let (x, y) = (i % FRAME_WIDTH, i / FRAME_WIDTH);
                // Sum of 4 uniform draws of 0..16: mean 30, σ ≈ 9.2 DN.
                let noise = (s & 15) + ((s >> 8) & 15) + ((s >> 16) & 15) + ((s >> 24) & 15);
                let lift = blocks
                    .iter()
                    .filter(|b| (b.0..b.2).contains(&x) && (b.1..b.3).contains(&y))
                    .map(|b| b.4)
                    .max()
                    .unwrap_or(0);
                (2000 + noise as u16 + lift).min(16383)
            })
            .collect()
    }

    /// The two blocks of the tracking tests (x0, y0, x1, y1, DN above the background):
    /// a strong one and a weak one, both found on their own.
    const STRONG_BLOCK: (usize, usize, usize, usize, u16) = (60, 60, 120, 110, 3000);
    /// See [`STRONG_BLOCK`].
    const WEAK_BLOCK: (usize, usize, usize, usize, u16) = (230, 150, 270, 190, 1500);

    /// Tracking: with a prior on the weaker of two targets, the box is that target's
    /// (the window around the prior is searched first); a prior far from any target,
    /// an empty one, one outside the frame and one of the whole frame give the answer
    /// without a prior (the whole frame is searched).
    #[test]
    fn tracking_keeps_the_prior_target_and_falls_back_to_the_frame() {
        let (strong, weak) = (STRONG_BLOCK, WEAK_BLOCK);
        let px = blocks_frame(&[strong, weak]);
        let frame = Frame::reference(&px).unwrap();
        let mut scratch = std::boxed::Box::new(AutoV2Scratch::new());
        let det = AutoV2::default();
        let free = det.detect(&frame, &mut scratch).unwrap();
        let near = |r: Roi, b: (usize, usize, usize, usize, u16)| {
            r.iou(&Roi::new(b.0 as u16, b.1 as u16, b.2 as u16, b.3 as u16)) > 0.8
        };
        let r = free.roi.expect("the strong block is found without a prior");
        assert!(near(r, strong), "{r:?}");
        // The weak block, tracked from a prior 3 px off and a little small.
        let prior = Roi::new(233, 152, 266, 185);
        let tracked = det
            .with_prior(Some(prior))
            .detect(&frame, &mut scratch)
            .unwrap();
        let r = tracked.roi.expect("the tracked block is found");
        assert!(near(r, weak), "{r:?}");
        assert!(tracked.score_permille >= det.min_score_permille);
        // Same answer twice.
        assert_eq!(
            tracked,
            det.with_prior(Some(prior))
                .detect(&frame, &mut scratch)
                .unwrap()
        );
        // Priors without a target inside, empty, off the frame, the whole frame or with
        // a window over half the frame (here 276 × 248 px, 84 %): the whole frame is
        // searched.
        for p in [
            Roi::new(0, 200, 20, 240),
            Roi::EMPTY,
            Roi::new(400, 300, 420, 320),
            Roi::new(0, 0, FRAME_WIDTH as u16, FRAME_HEIGHT as u16),
            Roi::new(0, 0, 130, 130),
        ] {
            assert_eq!(
                det.with_prior(Some(p))
                    .detect(&frame, &mut scratch)
                    .unwrap(),
                free,
                "{p:?}"
            );
        }
    }

    /// The fast tracking path: with the last box on the weak block and its look carried
    /// from the last frame, the prior's cells refined alone give the block's box with
    /// [`TRACKED_SCORE_PERMILLE`] (and no other stage's trace); the same prior and look
    /// over a frame without that block (the target left: the prior on background),
    /// over the strong block (another target: its level 1 500 DN above the last box's,
    /// more than half the last departure), or
    /// with a look that stood out by less than [`look::MIN_DEPARTURE_SIGMA`] give the
    /// answer without a look.
    #[test]
    fn the_fast_path_keeps_a_target_that_looks_the_same_and_nothing_else() {
        let px = blocks_frame(&[STRONG_BLOCK, WEAK_BLOCK]);
        let frame = Frame::reference(&px).unwrap();
        let mut scratch = std::boxed::Box::new(AutoV2Scratch::new());
        let truth = Roi::new(230, 150, 270, 190);
        // The last box, a little large and off (as a tracker hands it over), and its
        // look (on this frame: the block has not moved).
        let prior = Roi::new(228, 148, 272, 191);
        let last = look::Look::measure(&frame, prior).expect("a look");
        let det = AutoV2::default().with_prior(Some(prior));
        let fast = det
            .with_look(Some(last))
            .detect(&frame, &mut scratch)
            .unwrap();
        assert!(scratch.work().tracked(), "{fast:?}");
        assert_eq!(scratch.work().stage(fast.roi), Some(Stage::Tracked));
        assert_eq!(fast.score_permille, TRACKED_SCORE_PERMILLE);
        assert!(scratch.work().winner().is_none());
        let r = fast.roi.expect("the tracked block");
        assert!(r.iou(&truth) > 0.9, "{r:?}");
        // The next call without a look: the flag goes (the window's search answers:
        // the classifier's winner around the prior).
        let searched = det.detect(&frame, &mut scratch).unwrap();
        assert!(!scratch.work().tracked());
        assert_eq!(
            scratch.work().stage(searched.roi),
            Some(Stage::Classifier),
            "{searched:?}"
        );
        // `det` with `look` on `frame`: the search decides (the answer without it).
        let mut search_decides = |det: AutoV2, look: look::Look, frame: &Frame<'_>| {
            let want = det.detect(frame, &mut scratch).unwrap();
            let got = det
                .with_look(Some(look))
                .detect(frame, &mut scratch)
                .unwrap();
            assert!(!scratch.work().tracked(), "{got:?}");
            assert_eq!(got, want);
        };
        // The block gone: the prior lies on the background.
        let gone_px = blocks_frame(&[STRONG_BLOCK]);
        search_decides(det, last, &Frame::reference(&gone_px).unwrap());
        // The prior on the strong block (3 000 DN above the background against the weak
        // one's 1 500).
        let on_strong = AutoV2::default().with_prior(Some(Roi::new(62, 62, 118, 108)));
        search_decides(on_strong, last, &frame);
        // A look that did not stand out.
        let faint = look::Look {
            level_dn: last.ring_dn + 1,
            ..last
        };
        search_decides(det, faint, &frame);
    }

    /// A frame of deep space as a real camera shows it: a 2 000 DN pedestal, a shading
    /// 80 DN brighter at the corners than at the centre, noise σ ≈ 9.2 DN, optionally a
    /// hot pixel (+3 000 DN) and a target 60 DN above the sky (a 6.5 σ face).
    fn shaded_sky(target: bool, hot_pixel: bool) -> std::vec::Vec<u16> {
        let mut px = blocks_frame(&[]);
        for (i, v) in px.iter_mut().enumerate() {
            let (x, y) = (i % FRAME_WIDTH, i / FRAME_WIDTH);
            let u = x as f32 / FRAME_WIDTH as f32 * 2.0 - 1.0;
            let w = y as f32 / FRAME_HEIGHT as f32 * 2.0 - 1.0;
            *v += (40.0 * (u * u + w * w)) as u16;
            if target && (120..180).contains(&x) && (90..140).contains(&y) {
                *v += 60;
            }
        }
        if hot_pixel {
            px[200 * FRAME_WIDTH + 40] += 3000;
        }
        px
    }

    /// Stage 2c: over a shaded sky the target's cells depart from the fitted surface
    /// and are boxed with the stage's confidence; a sky with only a hot pixel gets no
    /// box from the stage (1 px across); with the stage off the classifier answers.
    #[test]
    fn a_target_over_a_shaded_sky_is_found_by_the_deep_space_stage() {
        let det = AutoV2::default();
        let mut scratch = std::boxed::Box::new(AutoV2Scratch::new());
        let px = shaded_sky(true, true);
        let frame = Frame::reference(&px).unwrap();
        let d = det.detect(&frame, &mut scratch).unwrap();
        let seen = scratch
            .work()
            .deep_space()
            .expect("deep space, boxed by stage 2c");
        assert!(seen.outliers >= 30, "{seen:?}");
        assert_eq!(d.score_permille, DEEP_SPACE_SCORE_PERMILLE);
        assert_eq!(scratch.work().stage(d.roi), Some(Stage::DeepSpace));
        let r = d.roi.expect("the target's box");
        assert!(r.iou(&Roi::new(120, 90, 180, 140)) > 0.9, "{r:?}");
        assert_eq!(
            d,
            det.detect(&frame, &mut scratch).unwrap(),
            "same answer twice"
        );
        // The hot pixel alone: not the stage's box.
        let px = shaded_sky(false, true);
        let frame = Frame::reference(&px).unwrap();
        let d = det.detect(&frame, &mut scratch).unwrap();
        assert!(scratch.work().deep_space().is_none(), "{d:?}");
        // The stage off: the classifier's answer, not the stage's.
        let off = AutoV2 {
            deep_space: false,
            ..det
        };
        let px = shaded_sky(true, true);
        let frame = Frame::reference(&px).unwrap();
        off.detect(&frame, &mut scratch).unwrap();
        assert!(scratch.work().deep_space().is_none());
    }

    /// The shaded sky of [`shaded_sky`] beside the Earth: a disc of radius 760 px
    /// centred at (700, 700) px, beyond the lower right corner, 1 500 DN above the sky
    /// with colder clouds (−400 DN) in a pattern the cells see as texture; optionally a
    /// target 60 DN above the sky at 40..80 × 30..60.
    fn earth_beside_sky(target: bool) -> std::vec::Vec<u16> {
        let mut px = shaded_sky(false, false);
        for (i, v) in px.iter_mut().enumerate() {
            let (x, y) = ((i % FRAME_WIDTH) as f32, (i / FRAME_WIDTH) as f32);
            let (dx, dy) = (x - 700.0, y - 700.0);
            if dx * dx + dy * dy <= 760.0 * 760.0 {
                let cloud = libm::sinf(x * 0.13) * libm::cosf(y * 0.11) > 0.4;
                *v += if cloud { 1100 } else { 1500 };
            }
            if target && (40.0..80.0).contains(&x) && (30.0..60.0).contains(&y) {
                *v += 60;
            }
        }
        px
    }

    /// Stage 2e: beside a textured Earth (no smooth surface fits the window: stage 2c
    /// finds no deep space) the sky alone is fitted and the target over it boxed with
    /// the stage's confidence, the same twice; without a target, or with the stage
    /// off, the stage gives no box.
    #[test]
    fn a_target_over_the_sky_beside_the_earth_is_found_by_stage_2e() {
        let det = AutoV2::default();
        let mut scratch = std::boxed::Box::new(AutoV2Scratch::new());
        let px = earth_beside_sky(true);
        let frame = Frame::reference(&px).unwrap();
        let d = det.detect(&frame, &mut scratch).unwrap();
        assert!(scratch.work().deep_space().is_some(), "{d:?}");
        assert_eq!(d.score_permille, SKY_BESIDE_EARTH_SCORE_PERMILLE, "{d:?}");
        let r = d.roi.expect("the target's box");
        assert!(r.iou(&Roi::new(40, 30, 80, 60)) > 0.9, "{r:?}");
        assert_eq!(
            d,
            det.detect(&frame, &mut scratch).unwrap(),
            "same answer twice"
        );
        // Without the target: not the stage's box.
        let px = earth_beside_sky(false);
        let frame = Frame::reference(&px).unwrap();
        let d = det.detect(&frame, &mut scratch).unwrap();
        assert!(scratch.work().deep_space().is_none(), "{d:?}");
        // The stage off: not its box.
        let off = AutoV2 {
            sky_beside_earth: false,
            ..det
        };
        let px = earth_beside_sky(true);
        let frame = Frame::reference(&px).unwrap();
        let d = off.detect(&frame, &mut scratch).unwrap();
        assert!(scratch.work().deep_space().is_none(), "{d:?}");
    }

    /// The shaded sky of [`shaded_sky`] (with its hot pixel) and a face `dn` DN off the
    /// sky over `x0..x1` × `y0..y1`.
    fn shaded_sky_with(x0: usize, y0: usize, x1: usize, y1: usize, dn: i32) -> std::vec::Vec<u16> {
        let mut px = shaded_sky(false, true);
        for y in y0..y1 {
            for x in x0..x1 {
                let v = &mut px[y * FRAME_WIDTH + x];
                *v = (i32::from(*v) + dn).clamp(0, 65_535) as u16;
            }
        }
        px
    }

    /// Asserts that stage 2c boxes `px` as a border piece ([`BORDER_PIECE_SCORE_PERMILLE`])
    /// with IoU above `min_iou` against `truth`, the same twice.
    fn assert_border_piece(px: &[u16], truth: Roi, min_iou: f32) {
        let det = AutoV2::default();
        let mut scratch = std::boxed::Box::new(AutoV2Scratch::new());
        let frame = Frame::reference(px).unwrap();
        let d = det.detect(&frame, &mut scratch).unwrap();
        assert!(scratch.work().deep_space().is_some(), "{d:?}");
        assert_eq!(d.score_permille, BORDER_PIECE_SCORE_PERMILLE, "{d:?}");
        let r = d.roi.expect("the piece's box");
        assert!(r.iou(&truth) > min_iou, "{r:?}");
        assert_eq!(
            d,
            det.detect(&frame, &mut scratch).unwrap(),
            "same answer twice"
        );
    }

    /// Stage 2c at the window's border: a face brighter than the sky, cut by one side
    /// and shorter along it than [`EARTH_MIN_CHORD_CELLS`], is boxed with
    /// [`BORDER_PIECE_SCORE_PERMILLE`], and so is a rectangle in a corner (its outline
    /// bends); a band along a whole side (as long as a piece of the Earth's disc), the
    /// Earth's disc across a corner (one straight arc) and a face colder than the sky
    /// (the sky of a corner, the rest Earth) are not the stage's.
    #[test]
    fn a_target_cut_by_one_side_over_a_shaded_sky_is_found_by_the_deep_space_stage() {
        let det = AutoV2::default();
        let mut scratch = std::boxed::Box::new(AutoV2Scratch::new());
        let px = shaded_sky_with(0, 100, 30, 150, 200);
        assert_border_piece(&px, Roi::new(0, 100, 30, 150), 0.8);
        // A rectangle cut by the top-left corner: its outline inside the frame is an L.
        let px = shaded_sky_with(0, 0, 30, 40, 200);
        assert_border_piece(&px, Roi::new(0, 0, 30, 40), 0.8);
        // The Earth's disc (radius 700 px) cutting the same corner, as bright: its
        // boundary is one straight arc.
        let mut limb = shaded_sky(false, true);
        let (cx, cy, radius) = (-470.0f32, -470.0f32, 700.0f32);
        for (i, v) in limb.iter_mut().enumerate() {
            let (x, y) = (
                (i % FRAME_WIDTH) as f32 + 0.5,
                (i / FRAME_WIDTH) as f32 + 0.5,
            );
            if libm::hypotf(x - cx, y - cy) < radius {
                *v += 200;
            }
        }
        for (what, px) in [
            (
                "a band along the left side",
                shaded_sky_with(0, 0, 20, FRAME_HEIGHT, 200),
            ),
            ("the Earth's disc across the top-left corner", limb),
            (
                "a face colder than the sky",
                shaded_sky_with(0, 100, 30, 150, -200),
            ),
        ] {
            let frame = Frame::reference(&px).unwrap();
            let d = det.detect(&frame, &mut scratch).unwrap();
            assert!(
                scratch.work().deep_space().is_none(),
                "{what}: boxed by stage 2c, {d:?}"
            );
        }
    }

    /// Stage 2c: a target cut by the left side, a bright face by the side and a dim one
    /// beyond it. Stage 4d's arc test reads its box as two levels split by one straight
    /// line (the face boundary: a limb to the outline alone), but the piece reaches 40
    /// px into the frame over a 60-px chord, deeper than a piece of the Earth's disc
    /// could (≤ 2.6 px): boxed.
    #[test]
    fn a_deep_piece_cut_by_one_side_is_no_limb() {
        let mut px = shaded_sky(false, true);
        for y in 90..150usize {
            for x in 0..40usize {
                px[y * FRAME_WIDTH + x] += if x < 20 { 200 } else { 80 };
            }
        }
        let frame = Frame::reference(&px).unwrap();
        let truth = Roi::new(0, 90, 40, 150);
        assert!(limb::is_limb(&frame, truth), "the outline alone says limb");
        assert_border_piece(&px, truth, 0.7);
    }

    /// A hot pixel alone in a clipped deep sky (0 DN but for it, as the real camera's
    /// saturated hot pixels and the paper world's sky show) is no target: the region
    /// stages' 1-px box is dropped ([`MIN_BOX_SIDE_PX`]), whatever the confidence.
    #[test]
    fn a_lone_hot_pixel_is_no_target() {
        let det = AutoV2::default();
        let mut scratch = std::boxed::Box::new(AutoV2Scratch::new());
        let mut px = std::vec![0u16; FRAME_WIDTH * FRAME_HEIGHT];
        let top = (1u16 << crate::frame::DEFAULT_BIT_DEPTH) - 1;
        for &(x, y) in &[(72usize, 31usize), (200, 150), (40, 220)] {
            px[y * FRAME_WIDTH + x] = top;
        }
        let frame = Frame::reference(&px).unwrap();
        let d = det.detect(&frame, &mut scratch).unwrap();
        assert_eq!(d.roi, None, "{d:?}");
        assert_eq!(
            d,
            det.detect(&frame, &mut scratch).unwrap(),
            "same answer twice"
        );
    }

    /// Stage 4d's saturated disc (`limb::is_saturated_disc`): the disc of 700 px radius
    /// saturated across the top-left corner of a deep-space frame, with clouds below
    /// saturation in it, is no target; a saturated block cut by the same corner (its
    /// corner bends) is boxed.
    #[test]
    fn a_saturated_disc_in_a_corner_is_no_target() {
        let det = AutoV2::default();
        let mut scratch = std::boxed::Box::new(AutoV2Scratch::new());
        let top = (1u16 << crate::frame::DEFAULT_BIT_DEPTH) - 1;
        let with = |bright: &dyn Fn(f32, f32) -> bool| {
            let mut px = blocks_frame(&[]);
            for (i, v) in px.iter_mut().enumerate() {
                let (x, y) = ((i % FRAME_WIDTH) as f32, (i / FRAME_WIDTH) as f32);
                if bright(x + 0.5, y + 0.5) {
                    // Clouds: 6-px patches every 24 px, below saturation.
                    let cloud = (x as usize % 24) < 6 && (y as usize % 24) < 6;
                    *v = if cloud { 12_000 } else { top };
                }
            }
            px
        };
        // Its edge runs from (0, 174) to (174, 0).
        let px = with(&|x, y| (x + 400.0).hypot(y + 400.0) < 700.0);
        let frame = Frame::reference(&px).unwrap();
        let d = det.detect(&frame, &mut scratch).unwrap();
        assert!(scratch.work().blob().is_some(), "{d:?}");
        assert_eq!(d.roi, None, "{d:?}");
        assert_eq!(
            d,
            det.detect(&frame, &mut scratch).unwrap(),
            "same answer twice"
        );
        let px = with(&|x, y| x < 100.0 && y < 80.0);
        let frame = Frame::reference(&px).unwrap();
        let d = det.detect(&frame, &mut scratch).unwrap();
        let r = d.roi.expect("the block is boxed");
        assert!(r.x1 >= 96 && r.y1 >= 76 && r.x0 == 0 && r.y0 == 0, "{d:?}");
    }

    /// Stage 2c: a face colder than the fitted sky inside the window is no target over
    /// deep space (nothing is colder than it): the window is the Earth read as smooth
    /// with a cold cloud, and the stage leaves it to the classifier; the same face
    /// warmer than the sky is the stage's.
    #[test]
    fn a_face_colder_than_the_sky_is_left_to_the_classifier() {
        // Stage 2c alone: the warm face's rectangle is also an outline (stage 5f), rated
        // above the stage's confidence.
        let det = AutoV2 {
            outline: false,
            ..AutoV2::default()
        };
        let mut scratch = std::boxed::Box::new(AutoV2Scratch::new());
        let px = shaded_sky_with(120, 90, 180, 140, -200);
        let frame = Frame::reference(&px).unwrap();
        let d = det.detect(&frame, &mut scratch).unwrap();
        assert!(scratch.work().deep_space().is_none(), "{d:?}");
        let px = shaded_sky_with(120, 90, 180, 140, 200);
        let frame = Frame::reference(&px).unwrap();
        let d = det.detect(&frame, &mut scratch).unwrap();
        assert!(scratch.work().deep_space().is_some(), "{d:?}");
        assert_eq!(d.score_permille, DEEP_SPACE_SCORE_PERMILLE, "{d:?}");
    }

    /// Stage 2d: a 4×4-px target of 6 σ straddling four cells moves each cell's mean
    /// by 0.4 σ (no departing cell for stage 2c) but stands 18 σ of a 3×3 mean above
    /// its ring: with `small_target` (the default) it is boxed with the stage's
    /// confidence, `null` one ‰ above it, and without the stage there is no box.
    #[test]
    fn a_small_target_over_a_shaded_sky_is_found_by_stage_2d() {
        let mut px = shaded_sky(false, true);
        for y in 62..66 {
            for x in 198..202 {
                px[y * FRAME_WIDTH + x] += 55;
            }
        }
        let frame = Frame::reference(&px).unwrap();
        let mut scratch = std::boxed::Box::new(AutoV2Scratch::new());
        let on = AutoV2::default();
        assert!(on.small_target);
        let d = on.detect(&frame, &mut scratch).unwrap();
        assert!(scratch.work().deep_space().is_some(), "{d:?}");
        assert_eq!(d.score_permille, SMALL_TARGET_SCORE_PERMILLE, "{d:?}");
        let r = d.roi.expect("the small target's box");
        assert!(r.iou(&Roi::new(198, 62, 202, 66)) >= 0.5, "{r:?}");
        assert_eq!(
            d,
            on.detect(&frame, &mut scratch).unwrap(),
            "same answer twice"
        );
        // The gate one ‰ above the stage's confidence: `null`.
        let gated = AutoV2 {
            min_score_permille: SMALL_TARGET_SCORE_PERMILLE + 1,
            ..on
        };
        assert_eq!(gated.detect(&frame, &mut scratch).unwrap().roi, None);
        // Off: stage 2c finds no target cell and gives no box.
        let off = AutoV2 {
            small_target: false,
            ..on
        };
        let d = off.detect(&frame, &mut scratch).unwrap();
        assert!(scratch.work().deep_space().is_none(), "{d:?}");
        // On, without the target: the hot pixel is no small target.
        let px = shaded_sky(false, true);
        let frame = Frame::reference(&px).unwrap();
        let d = on.detect(&frame, &mut scratch).unwrap();
        assert!(scratch.work().deep_space().is_none(), "{d:?}");
    }

    /// Stage 2c's component: behind a stronger band of weak cells (the shading along
    /// two edges), the strongest seeded component of at least
    /// [`DEEP_SPACE_FALLBACK_MIN_CELLS`] cells, not a stronger seeded pair; the weak
    /// band when no seeded component is large enough; the strongest component when
    /// it is seeded.
    #[test]
    fn deep_space_takes_a_seeded_component_behind_a_weak_band() {
        let (pw, ph) = (41usize, 31usize);
        let n = pw * ph;
        let mut work: std::boxed::Box<AutoV2Work> = std::boxed::Box::new(ConstInit::INIT);
        // (pair code, with the three-cell component): the band of weak cells (code 1)
        // on the left column and top row weighs 71; a seeded pair at (20, 20)–(21, 20)
        // and three seeded cells at (30, 10)–(32, 10) (a seed and two weak cells).
        let setup = |work: &mut AutoV2Work, pair: u8, three: bool| {
            let codes = &mut work.labels4.as_mut()[..n];
            codes.fill(0);
            for y in 0..ph {
                codes[y * pw] = smooth::WEAK_CODE;
            }
            codes[..pw].fill(smooth::WEAK_CODE);
            codes[20 * pw + 20] = pair;
            codes[20 * pw + 21] = pair;
            if three {
                codes[10 * pw + 30] = smooth::WEAK_CODE + 1;
                codes[10 * pw + 31] = smooth::WEAK_CODE;
                codes[10 * pw + 32] = smooth::WEAK_CODE;
            }
        };
        let boxed = |w8: CellStats| (w8.x0, w8.y0, w8.x_last, w8.y_last, w8.area);
        // The pair (code 48: 8 each) is stronger than the three cells (3), weaker than
        // the band: the three cells.
        setup(&mut work, 48, true);
        let (_, w8, _, _) = deep_space_component(&mut work, (pw, ph)).unwrap();
        assert_eq!(boxed(w8), (30, 10, 32, 10, 3));
        // Without them the weak band stays (the stage then hands over).
        setup(&mut work, 48, false);
        let (_, w8, _, _) = deep_space_component(&mut work, (pw, ph)).unwrap();
        assert_eq!(boxed(w8), (0, 0, 40, 30, 71));
        // A pair stronger than the band (code 112: 128 each) is the strongest: taken.
        setup(&mut work, 112, true);
        let (_, w8, _, _) = deep_space_component(&mut work, (pw, ph)).unwrap();
        assert_eq!(boxed(w8), (20, 20, 21, 20, 2));
    }

    /// Stage 4c: the body's scattered target cells (gaps of one cell at the body's
    /// level) join the winner; a cold fragment two cells away across a background cell
    /// does not; reach 1 joins nothing; a gap at the level midway joins.
    #[test]
    fn linked_cells_join_across_the_body_not_across_the_background() {
        let (pw, ph) = (41usize, 31usize);
        let n = pw * ph;
        let level = 1000u16;
        let mut work: std::boxed::Box<AutoV2Work> = std::boxed::Box::new(ConstInit::INIT);
        let reset = |work: &mut AutoV2Work| {
            work.mean_dn.as_mut()[..n].fill(level);
            work.labels4.as_mut()[..n].fill(0);
            // The body: cells x 5..=15, y 5..=12 at 600 DN (a cold flat target).
            for y in 5..=12 {
                for x in 5..=15 {
                    work.mean_dn.as_mut()[y * pw + x] = 600;
                }
            }
            // A cold fragment at x 17..=18 beyond a background column (x 16).
            for y in 5..=6 {
                for x in 17..=18 {
                    work.mean_dn.as_mut()[y * pw + x] = 600;
                }
            }
            // Target cells on the body every other cell (the strongest at (5, 5)), and
            // one on the fragment, two cells from the body's (15, 5).
            let mut code = |x: usize, y: usize, c: u8| work.labels4.as_mut()[y * pw + x] = c;
            code(5, 5, 200);
            for (x, y) in [
                (7, 5),
                (9, 5),
                (11, 5),
                (13, 5),
                (15, 5),
                (5, 7),
                (5, 9),
                (5, 11),
            ] {
                code(x, y, 20);
            }
            code(17, 5, 30);
        };
        reset(&mut work);
        let (root, w8, _) = strongest_component(&mut work, (pw, ph), CELL_RELABEL_CODES).unwrap();
        assert_eq!((w8.x0, w8.y0, w8.area), (5, 5, 1), "{w8:?}");
        // Reach 1: nothing joins.
        assert!(join_linked(&mut work, (pw, ph), n, root, 1, level).is_none());
        let (_, joined) = join_linked(&mut work, (pw, ph), n, root, 2, level).unwrap();
        assert_eq!(
            (
                joined.x0,
                joined.y0,
                joined.x_last,
                joined.y_last,
                joined.area
            ),
            (5, 5, 15, 11, 9),
            "{joined:?}"
        );
        // The background column at the fragment's level: the fragment joins too.
        reset(&mut work);
        for y in 5..=6 {
            work.mean_dn.as_mut()[y * pw + 16] = 600;
        }
        let (root, _, _) = strongest_component(&mut work, (pw, ph), CELL_RELABEL_CODES).unwrap();
        let (_, joined) = join_linked(&mut work, (pw, ph), n, root, 2, level).unwrap();
        assert_eq!((joined.x_last, joined.area), (17, 10), "{joined:?}");
        // A body scattered over the whole plane (pairs of cells one cell apart on every
        // other row: 224 components, 448 cells): the work bound stops the joining
        // after MAX_LINK_LOOKS cells looked at, the same way every time.
        let scattered = |work: &mut AutoV2Work| {
            work.mean_dn.as_mut()[..n].fill(600);
            work.labels4.as_mut()[..n].fill(0);
            for y in (0..ph).step_by(2) {
                for x in (0..pw).filter(|x| x % 3 != 2) {
                    work.labels4.as_mut()[y * pw + x] = if (x, y) == (0, 0) { 200 } else { 20 };
                }
            }
            let (root, _, _) = strongest_component(work, (pw, ph), CELL_RELABEL_CODES).unwrap();
            join_linked(work, (pw, ph), n, root, 2, level).unwrap().1
        };
        let first = scattered(&mut work);
        assert_eq!((first.x_last, first.y_last, first.area), (40, 30, 448));
        let again = scattered(&mut work);
        assert_eq!(
            (first.x_last, first.y_last, first.area),
            (again.x_last, again.y_last, again.area)
        );
    }

    /// Stage 4c on random planes: never more than MAX_LINK_LOOKS cells looked at; every
    /// joined cell outside the first winner lies within reach of another joined cell
    /// that the bridge rule links it to (or in its own 8-connected component).
    #[test]
    fn linked_cells_on_random_planes_are_bounded_and_bridged() {
        let (pw, ph) = (41usize, 31usize);
        let n = pw * ph;
        let mut next = xorshift32(0x51ed_0037);
        let mut work: std::boxed::Box<AutoV2Work> = std::boxed::Box::new(ConstInit::INIT);
        let mut most = 0;
        for round in 0..300 {
            let density = 5 + round % 40;
            for i in 0..n {
                work.mean_dn.as_mut()[i] = if next() % 100 < 50 {
                    600
                } else {
                    1000 + (next() % 300) as u16
                };
                work.labels4.as_mut()[i] = if next() % 100 < density {
                    1 + (next() % 60) as u8
                } else {
                    0
                };
            }
            let Some((root, _, _)) = strongest_component(&mut work, (pw, ph), CELL_RELABEL_CODES)
            else {
                continue;
            };
            let first: std::vec::Vec<bool> = (0..n)
                .map(|i| {
                    let l = work.labels8.as_ref()[i];
                    l != 0 && work.comps.find(l) == root
                })
                .collect();
            let (got, looks) = join_linked_counted(&mut work, (pw, ph), n, root, 2, 1100);
            assert!(looks <= MAX_LINK_LOOKS, "{looks}");
            most = most.max(looks);
            let Some((r, _)) = got else { continue };
            let member: std::vec::Vec<bool> = (0..n)
                .map(|i| {
                    let l = work.labels8.as_ref()[i];
                    l != 0 && work.comps.find(l) == r
                })
                .collect();
            for i in (0..n).filter(|&i| member[i] && !first[i]) {
                let (x, y) = (i % pw, i / pw);
                let linked = (y.saturating_sub(2)..(y + 3).min(ph)).any(|ny| {
                    (x.saturating_sub(2)..(x + 3).min(pw)).any(|nx| {
                        let j = ny * pw + nx;
                        j != i
                            && member[j]
                            && (x.abs_diff(nx) <= 1 && y.abs_diff(ny) <= 1
                                || bridges_body(work.mean_dn.as_ref(), pw, 1100, i, j))
                    })
                });
                assert!(
                    linked,
                    "round {round}: cell ({x}, {y}) joined without a link"
                );
            }
        }
        // The random planes reach the bound (it is exercised, not only proven).
        assert_eq!(most, MAX_LINK_LOOKS);
    }

    /// The bridge rule against its definition: same side of the level as both ends,
    /// at least half the lesser departure.
    #[test]
    fn bridges_body_follows_its_rule() {
        let pw = 5;
        let at = |a: u16, m: u16, b: u16| {
            let mut plane = [1000u16; 5];
            (plane[0], plane[1], plane[2]) = (a, m, b);
            bridges_body(&plane, pw, 1000, 0, 2)
        };
        assert!(at(600, 600, 600));
        assert!(at(600, 800, 700)); // 200 ≥ 300 / 2
        assert!(!at(600, 860, 700)); // 140 < 150
        assert!(!at(600, 1000, 600)); // the background between
        assert!(!at(600, 1200, 600)); // the other side
        assert!(!at(600, 700, 1400)); // ends on both sides
        assert!(at(1400, 1300, 1600));
    }

    /// Stage 4b's ranking equals a sort: on random code planes, the labelling's
    /// strongest first, then the other components by energy (most first, the lower
    /// label on a tie), and the component count is the number of roots.
    /// A piece cut by one side departing by one threshold at most is a face when a
    /// third of its cells are seeds (a plateau), not a ramp of weak cells around a few
    /// (the shading's misfit); beyond one threshold any share passes, under none.
    #[test]
    fn a_faint_border_piece_must_depart_as_a_plateau() {
        let seeds = |strongest: u8, count: u16| Seeds {
            up: strongest,
            down: 0,
            count,
        };
        let code = BORDER_PIECE_MIN_CODE;
        assert!(seeds(code, 2).departs_as_a_face(6));
        assert!(!seeds(code, 5).departs_as_a_face(24));
        assert!(seeds(code, 8).departs_as_a_face(24));
        assert!(seeds(code + 1, 1).departs_as_a_face(24));
        assert!(!seeds(code - 1, 24).departs_as_a_face(24));
    }

    #[test]
    fn strongest_roots_equal_a_sort() {
        let (pw, ph) = (41usize, 31usize);
        let mut s = 0x9e37_79b9u32;
        for density in [3u32, 10, 30, 60] {
            let codes: std::vec::Vec<u8> = (0..pw * ph)
                .map(|_| {
                    s ^= s << 13;
                    s ^= s >> 17;
                    s ^= s << 5;
                    if s % 100 < density {
                        (1 + s % 200) as u8
                    } else {
                        0
                    }
                })
                .collect();
            let mut labels = std::vec![0u8; pw * ph];
            let mut comps: EdgeComponents = ConstInit::INIT;
            let next = label_edge_cells(&codes, &mut labels, pw, 1, CELL_RELABEL_CODES, &mut comps);
            let Some((strongest, _)) = choose_target(&comps, next, (pw, ph), 0) else {
                continue;
            };
            let (ranked, components) = strongest_roots(&comps, next, strongest);
            let mut roots: std::vec::Vec<(u8, u32)> = (1..next)
                .filter(|&l| comps.parent(l) == Some(l as u8))
                .map(|l| (l as u8, comps.stats(l).unwrap().energy))
                .collect();
            assert_eq!(usize::from(components), roots.len());
            roots.sort_by_key(|&(l, e)| (l != strongest, core::cmp::Reverse(e), l));
            roots.resize(MAX_CANDIDATES.max(roots.len()), (0, 0));
            assert_eq!(&ranked[..], &roots[..MAX_CANDIDATES], "density {density}");
            // The labelling's choice is the strongest: no other has more energy.
            assert!(ranked.iter().all(|&(_, e)| e <= ranked[0].1));
        }
    }

    /// Stage 4b on a hand-made cell plane: a cross of weak cells spanning the frame
    /// (the labelling's strongest by its many cells, touching every side) and two
    /// compact blocks of confident cells. Rating one candidate keeps the cross; rating
    /// three takes the most confident of the three strongest (brute force: each rated
    /// alone), here a block, whatever the gate.
    #[test]
    fn stage_4b_takes_the_most_confident_of_the_strongest() {
        let (pw, ph) = (41usize, 31usize);
        let n8 = pw * ph;
        let mut work: std::boxed::Box<AutoV2Work> = std::boxed::Box::new(ConstInit::INIT);
        let lv = FrameLevels {
            p2: 990,
            p50: 1000,
            p98: 1400,
            sigma: 8,
            sd_shift: 0,
            max_dn: 16383,
            step_rank_code: 0,
        };
        // A flat frame under the planes: every component's roughness is 0.
        let pixels = std::vec![1000u16; pw * 8 * ph * 8];
        let flat = Frame::new(&pixels, pw * 8, ph * 8, 14).unwrap();
        let win = Window::full(&flat);
        let cross = |x: usize, y: usize| (14..17).contains(&y) || (19..22).contains(&x);
        let block = |x: usize, y: usize, x0: usize, y0: usize, side: usize| {
            (x0..x0 + side).contains(&x) && (y0..y0 + side).contains(&y)
        };
        for i in 0..n8 {
            let (x, y) = (i % pw, i / pw);
            // Codes under 16 weigh 1 each in the energy (`step_value`), 36 weighs 5
            // and 40 weighs 6: the cross (207 cells) outweighs the blocks (96, 45).
            let (code, level) = if cross(x, y) {
                (2, 1400)
            } else if block(x, y, 3, 3, 4) {
                (40, 1300)
            } else if block(x, y, 30, 22, 3) {
                (36, 1250)
            } else {
                (0, 1000)
            };
            work.labels4.as_mut()[i] = code;
            work.mean_dn.as_mut()[i] = level;
            work.step_code.as_mut()[i] = if code > 0 { 40 } else { 8 };
        }
        let (strongest, w8, next) =
            strongest_component(&mut work, (pw, ph), CELL_RELABEL_CODES).unwrap();
        assert_eq!(w8.sides_touched((pw, ph)), 4, "the cross is the strongest");
        let (ranked, components) = strongest_roots(&work.comps, next, strongest);
        assert_eq!(components, 3);
        // Brute force: each of the three rated alone.
        let scores: std::vec::Vec<(u8, u16)> = ranked[..3]
            .iter()
            .map(|&(l, _)| {
                let stats = *work.comps.stats(usize::from(l)).unwrap();
                let runner_up = if l == strongest {
                    ranked[1].1
                } else {
                    ranked[0].1
                };
                let w = rate_component(
                    &flat,
                    win,
                    &mut work,
                    (pw, ph),
                    lv,
                    n8,
                    l,
                    stats,
                    components,
                    runner_up,
                );
                (l, w.score_permille())
            })
            .collect();
        let best = scores
            .iter()
            .fold(scores[0], |b, &s| if s.1 > b.1 { s } else { b });
        assert_ne!(
            best.0, strongest,
            "a block is rated above the cross: {scores:?}"
        );
        let pick = |candidates: u8, gate: u16, work: &mut AutoV2Work| {
            let det = AutoV2 {
                candidates,
                min_score_permille: gate,
                ..AutoV2::default()
            };
            let (l, _, w) = det
                .most_confident(&flat, win, work, (pw, ph), lv, n8, strongest, next)
                .unwrap();
            (l, w.score_permille())
        };
        assert_eq!(pick(1, 1000, &mut work), scores[0]);
        assert_eq!(pick(3, 1000, &mut work), best);
        assert_eq!(
            pick(4, 1000, &mut work),
            best,
            "three components: the fourth is none"
        );
        // The gate does not change the choice (every candidate is rated).
        for gate in [0, scores[0].1, best.1] {
            assert_eq!(pick(3, gate, &mut work), best, "gate {gate}");
        }
    }

    #[test]
    fn detections_are_bounded_and_repeatable() {
        let det = AutoV2::default();
        let mut scratch = std::boxed::Box::new(AutoV2Scratch::new());
        for (seed, bits) in [(1, 12), (2, 14), (3, 16), (4, 8)] {
            let px = frame_pixels(seed, bits);
            for pixels in [
                px.clone(),
                std::vec![0u16; px.len()],
                std::vec![((1u32 << bits) - 1) as u16; px.len()],
            ] {
                let frame = Frame::new(&pixels, FRAME_WIDTH, FRAME_HEIGHT, bits).unwrap();
                let a = det.detect(&frame, &mut scratch).unwrap();
                let b = det.detect(&frame, &mut scratch).unwrap();
                assert_eq!(a, b, "same answer twice");
                assert!(a.score_permille <= 1000);
                match a.roi {
                    Some(r) => {
                        assert!(a.score_permille >= det.min_score_permille);
                        assert!(r.x0 < r.x1 && r.y0 < r.y1);
                        assert!(
                            usize::from(r.x1) <= FRAME_WIDTH && usize::from(r.y1) <= FRAME_HEIGHT
                        );
                    }
                    None => assert_eq!(a.score_permille, 0),
                }
            }
        }
        // A tiny frame and a bad parameter.
        let small = [5u16; 3 * 2];
        let frame = Frame::new(&small, 3, 2, 14).unwrap();
        assert!(det.detect(&frame, &mut scratch).is_ok());
        let bad = AutoV2 {
            min_score_permille: 1001,
            ..det
        };
        assert!(bad.detect(&frame, &mut scratch).is_err());
        let bad = AutoV2 {
            saturated_erode_px: 9,
            ..det
        };
        assert!(bad.detect(&frame, &mut scratch).is_err());
        for candidates in [0, 5] {
            let bad = AutoV2 { candidates, ..det };
            assert!(bad.detect(&frame, &mut scratch).is_err(), "{candidates}");
        }
    }

    /// Stage 2b end to end: a solid saturated 24×16 block in textured background is
    /// the box under [`BlobRule::Always`] (the block itself, no cut) with the blob's
    /// confidence; under [`BlobRule::Compete`] the answer is `Always`'s exactly when
    /// the blob's confidence passes the gate and beats the classifier winner's (`Off`'s
    /// winner), else `Off`'s; with and without a brighter unsaturated target elsewhere.
    /// A ragged clipped plateau across the frame's top is rated low and not taken.
    #[test]
    fn a_solid_saturated_blob_wins_and_a_ragged_plateau_does_not() {
        let bits = 12u8;
        let top = ((1u32 << bits) - 1) as u16;
        let mut scratch = std::boxed::Box::new(AutoV2Scratch::new());
        // Stage 2b's rule alone: the spots (stage 5e) do not compete with its answer.
        let with = |blob| AutoV2 {
            blob,
            saturated_erode_px: 0,
            spot_competes_below_permille: 0,
            outline: false,
            ..AutoV2::default()
        };
        let mut outcomes = [0usize; 2];
        for (seed, (bw, bh)) in [21, 23, 25].into_iter().zip([(24, 16), (5, 5), (6, 4)]) {
            for keep_target in [true, false] {
                let mut px = frame_pixels(seed, bits);
                if !keep_target {
                    px = px.iter().map(|&v| v.min(top / 4 + 200)).collect();
                }
                for y in 120..120 + bh {
                    for x in 200..200 + bw {
                        px[y * FRAME_WIDTH + x] = top;
                    }
                }
                let frame = Frame::new(&px, FRAME_WIDTH, FRAME_HEIGHT, bits).unwrap();
                let always = with(BlobRule::Always).detect(&frame, &mut scratch).unwrap();
                let blob = scratch.work().blob().expect("a blob");
                // The block (a hot pixel may share its cells) in the background.
                let block_px = (bw * bh) as u32;
                assert!(
                    (block_px..=block_px + 2).contains(&blob.saturated_px),
                    "{blob:?}"
                );
                assert_eq!((blob.solid_permille, blob.sides), (1000, 0), "{blob:?}");
                assert!(scratch.work().blob_won());
                if always.roi.is_some() {
                    assert_eq!(scratch.work().stage(always.roi), Some(Stage::Blob));
                }
                assert_eq!(scratch.work().stage(None), None, "no box, no stage");
                assert_eq!(always.score_permille, blob.score_permille());
                if always.roi.is_some() && blob.saturated_px == block_px {
                    let block = Roi::new(200, 120, 200 + bw as u16, 120 + bh as u16);
                    assert_eq!(always.roi, Some(block));
                }
                let off = with(BlobRule::Off).detect(&frame, &mut scratch).unwrap();
                assert!(scratch.work().blob().is_none() && !scratch.work().blob_won());
                let classifier = scratch.work().winner().map_or(0, |w| w.score_permille());
                let compete = with(BlobRule::Compete)
                    .detect(&frame, &mut scratch)
                    .unwrap();
                let wins = blob.score_permille() >= AutoV2::default().min_score_permille
                    && blob.score_permille() > classifier;
                assert_eq!(scratch.work().blob_won(), wins);
                assert_eq!(compete, if wins { always } else { off });
                outcomes[usize::from(wins)] += 1;
            }
        }
        // Both outcomes happen: the bright target beats the blob, alone the blob wins.
        assert!(outcomes[0] > 0 && outcomes[1] > 0, "{outcomes:?}");
        // A clipped plateau along the top edge, full of holes: rated low, not taken.
        let mut px = frame_pixels(22, bits);
        for y in 0..24 {
            for x in 0..FRAME_WIDTH {
                if (x * 7 + y * 3) % 5 != 0 {
                    px[y * FRAME_WIDTH + x] = top;
                }
            }
        }
        let frame = Frame::new(&px, FRAME_WIDTH, FRAME_HEIGHT, bits).unwrap();
        let d = AutoV2::default().detect(&frame, &mut scratch).unwrap();
        let blob = scratch.work().blob().expect("a blob");
        assert!(blob.solid_permille < 900 && blob.sides >= 3, "{blob:?}");
        assert!(
            blob.score_permille() < AutoV2::default().min_score_permille,
            "{blob:?}"
        );
        assert!(!scratch.work().blob_won(), "{d:?}");
    }

    #[test]
    fn confidence_is_the_logistic_of_the_weighted_features() {
        for (cells, w, h, sides, comps, runner) in [
            (1, 1, 1, 0, 1, 0),
            (40, 8, 7, 1, 3, 200),
            (600, 41, 31, 4, 90, 1000),
        ] {
            let win = Winner {
                cells,
                box_w_cells: w,
                box_h_cells: h,
                sides,
                code_sum: u32::from(cells) * 9,
                code_max: 20,
                components: comps,
                runner_up_permille: runner,
                rough_permille: 37 * u16::from(sides),
                shape: shape::WinnerShape {
                    perimeter_cells: 4 * u16::from(w),
                    contrast_code: 40,
                    clutter_code: 20,
                    ..shape::WinnerShape::default()
                },
            };
            let f = win.confidence_features();
            assert_eq!(f[0], log_code(u32::from(cells) - 1));
            assert_eq!(f[4], 9 * 16);
            // Compactness: 16 · cells / perimeter², capped at a square's 1000.
            let p = f64::from(4 * u32::from(w));
            assert_eq!(
                f64::from(f[8]),
                (16.0 * f64::from(cells) * 1000.0 / (p * p))
                    .floor()
                    .min(1000.0)
            );
            assert_eq!((f[9], f[10]), (40, 20));
            assert_eq!(f[24], 37 * i32::from(sides));
            let z: f64 = f
                .iter()
                .zip(confidence_weights::WEIGHTS)
                .map(|(&f, w)| f64::from(f) * f64::from(w))
                .sum::<f64>()
                + f64::from(confidence_weights::BIAS);
            let exact = 1000.0 / (1.0 + libm::exp(-z / 4096.0));
            let got = f64::from(win.score_permille());
            assert!((got - exact).abs() <= 6.0, "{got} vs {exact}");
        }
    }

    #[test]
    fn logistic_table_is_monotone_and_centred() {
        assert_eq!(logistic_permille(0), 500);
        let mut last = 0;
        for s in -5000..5000 {
            let p = logistic_permille(s);
            assert!(p >= last && p <= 1000);
            last = p;
            let exact = 1000.0 / (1.0 + libm::exp(-f64::from(s) / 256.0));
            assert!((f64::from(p) - exact).abs() <= 6.0, "{s}: {p} vs {exact}");
        }
    }
}
