//! Stage 5f: a target's straight outline. A spacecraft at close range over the Earth is
//! a polygon to an eye — long straight edges meeting at corners, faces of one level —
//! where the cell classifier, which reads 8-px cells and their context, scores a large
//! cold body over cloud as background (session 54: `famA/000003`, 187 of its 195 cells
//! below even odds). The frame's straight edges ([`super::segments`]) are joined into
//! groups:
//! - at a **corner**, two segments whose ends lie within [`CORNER_REACH_PX`] (or whose
//!   lines cross within it beyond both ends: two edges that each stop short of a
//!   rounded corner) and whose lines cross at [`MIN_CORNER_DEG`] or more, when the two
//!   edges agree on which side
//!   the wedge between them lies (the region inside a corner is darker, or brighter,
//!   across both edges: two edges of one face do; a cloud edge that happens to end near
//!   the limb's does half the time);
//! - along a **continuation**, two segments within [`CORNER_REACH_PX`] end to end whose
//!   lines differ by under [`MAX_CONTINUATION_DEG`], with the same dark side, the second
//!   within [`CONTINUATION_OFFSET_PX`] of the first's line (an edge broken by noise or by
//!   a cloud behind it).
//!
//! The group with at least one corner and the longest edges in total is the outline;
//! it is the answer's candidate when its edges reach [`MIN_OUTLINE_PX`] — or
//! [`MIN_BORDER_OUTLINE_PX`] when it is **closed by the frame's border** (every end
//! that meets no other segment lies on the border: a body cut by the frame, its
//! in-frame edges and the border around the region between them; session 59) — its
//! box the
//! box of its segments' ends joined with the boxes of the other groups with a corner
//! that reach within [`ABSORB_REACH_PX`] of it (a spacecraft's parts: a cylinder's
//! sides meet the cube's face at a T, not at a corner) and of the groups without one
//! that run square to its longest edge ([`MAX_PART_SQUARE_DEG`]) and end within
//! [`MAX_PART_OVERHANG_PERCENT`] of its size past it, carried to the sides of the
//! frame its free ends reach when it is closed by the border. Its confidence is family A's
//! hit rate of the stage's answers with as many corners ([`Outline::score_permille`]).
//! The Earth gives straight edges too (cloud decks,
//! the limb's pieces), but rarely two long ones meeting at an agreeing corner: on
//! family A's 300 realistic frames without a target (famAE, seed 7101) no group of
//! 50 px.
//!
//! Memory: on the stack the group of each segment (1 B each), which of its ends meet
//! another's and each group's longest segment (1 B each) and the groups' sums (16 B
//! each) in the union-find: 1 824 B for [`MAX_SEGMENTS`]; no scratch.
//! Cost: every pair of segments once (at most 4 560 pairs for 96).

use super::segments::{DIRECTION_ONE, MAX_SEGMENTS, Segment};
use crate::capacity::ConstInit;
use crate::roi::Roi;
use crate::roi::components::{Components, Stats};

/// Farthest apart two segments' ends may lie to meet, pixels: the optics blur a corner
/// over 2–3 px and each segment's ends are read from its blocks' spread (within a
/// pixel or two of the true corner).
pub const CORNER_REACH_PX: i32 = 6;

/// Least angle between two lines meeting at a corner, degrees: a spacecraft's faces
/// meet at 45–135° in projection; two pieces of one bending edge (the limb, a cloud's
/// rim) meet under 20°, the two sides of a thin cloud streak at its tip at 20–30°
/// (`famASE/000465`, boxed at 20°). Chosen on family A: 20° → 30° summed mean IoU
/// +0.0005, famAT −0.0021, famASE's false alarms 16 → 15 of 480 (held out −0.0032).
pub const MIN_CORNER_DEG: f32 = 30.0;

/// Largest angle between two pieces of one straight edge, degrees: the scatter of two
/// pieces' directions under noise (each read from tens of blocks), well under a
/// corner's least ([`MIN_CORNER_DEG`]); the limb's pieces bend by less too.
pub const MAX_CONTINUATION_DEG: f32 = 10.0;

/// Farthest a continuation's middle may lie from the first piece's line, pixels.
pub const CONTINUATION_OFFSET_PX: i32 = 2;

/// Shortest outline (its segments' summed length), pixels. Chosen on family A (seeds
/// 7001, 7101, 7201; the stage's first form — one confidence, 750 ‰, no joined groups —
/// replayed offline on this detector's segments): 50 / 60 / 80 px →
/// summed mean IoU of famA, paperA, fixA and famAF +0.038 / +0.035 / +0.029, famAT
/// +0.091 / +0.068 / +0.035, no false alarm added on famAE and 1 of fixA's 80
/// no-target frames (a fixture's aliased limb, a staircase of horizontal pieces, with
/// a texture edge at a corner); famAE's longest group is 49 px.
pub const MIN_OUTLINE_PX: u32 = 50;

/// Confidence of an outline with fewer than [`MANY_CORNERS`] corners, ‰: family A's hit
/// rate (IoU ≥ ½) of the stage's answers with 1 or 2 corners, 37 of 51 (seeds 7001,
/// 7101, 7201, the answers under 750 ‰ or none; held out 44 of 94). It competes with any
/// answer less confident.
pub const FEW_CORNERS_SCORE_PERMILLE: u16 = 725;

/// Confidence of an outline with [`MANY_CORNERS`] corners or more, ‰: family A's hit
/// rate of those answers, 36 of 42 (held out 61 of 70). Where the other stages answered
/// at 725–857 ‰, such an outline's box scores 0.81 against their 0.77 on family A (47
/// frames; held out 0.77 against 0.72 on 45), no target-less frame among them.
pub const MANY_CORNERS_SCORE_PERMILLE: u16 = 857;

/// Corners from which an outline is rated [`MANY_CORNERS_SCORE_PERMILLE`]: a face's
/// quadrilateral shows three or four, a cloud deck's straight pieces one or two.
pub const MANY_CORNERS: u8 = 3;

/// The highest confidence an outline carries, ‰ (the stage runs only where the other
/// stages' answer is rated below it).
pub const MAX_SCORE_PERMILLE: u16 = MANY_CORNERS_SCORE_PERMILLE;

/// How far from the outline's box another group with a corner may reach and still be
/// part of the target, pixels (one pass: the groups it takes do not take more). On
/// family A +0.007 summed mean IoU, held out +0.015, no false alarm added (session 55,
/// at 2 px). Session 59: as far as two segments' ends may lie to meet at a corner
/// ([`CORNER_REACH_PX`]; a part's edges stop as short of the body's as a corner's
/// do): family A (seeds 7001–7201, ½ convention) 2 / 4 / **6** / 10 / 16 px → famA
/// 0.6224 / 0.6224 / **0.6243** / 0.6243 / 0.6243, famAT 0.5368 / 0.5368 / **0.5379** /
/// 0.5379 / 0.5379, no set lower, no false alarm added; held out at 6 px +0.0061 (famBW
/// +0.0028, famB +0.0019, paperBT +0.0014).
pub const ABSORB_REACH_PX: i32 = CORNER_REACH_PX;

/// Shortest outline closed by the frame's border, pixels: a group with a corner whose
/// every free end (one that meets no other segment) lies within [`CORNER_REACH_PX`] of
/// the frame's border is a piece of a body cut by the frame (a panel's corner, two of
/// its edges and the border around the region between them). Such a piece shows only
/// its edges inside the frame, 24–45 px for Tango's panels at close range
/// (`famAT/000013`: 45 px, `000043`: 40 px), under [`MIN_OUTLINE_PX`], and the
/// classifier, whose cells there lack their context, misses it. Chosen on family A
/// (seeds 7001–7201, ½ convention, change of the summed mean IoU): 20 → famAT +0.0228
/// but a false alarm on famAE (`000212`: a cloud's tip at the top border, two edges of
/// 11 px, the segment detector's shortest being [`super::segments::MIN_LENGTH_PX`]);
/// **25 → famAT +0.0202**, famA +0.0027, no false alarm added; 30 → famAT +0.0168.
pub const MIN_BORDER_OUTLINE_PX: u32 = 25;

/// Confidence of an outline closed by the frame's border shorter than
/// [`MIN_OUTLINE_PX`], ‰: such a piece shows one or two corners, so it is rated as
/// the outlines with few corners ([`FEW_CORNERS_SCORE_PERMILLE`]). Family A's 9 of 9
/// hits (famA 1, famAT 8; none on a frame without a target) are too few for a class
/// of its own; held out 15 of 22 (famBW's winged target gives 6 of the misses: a wing's
/// or the body's piece of a target cut by the frame, boxed alone).
pub const BORDER_OUTLINE_SCORE_PERMILLE: u16 = FEW_CORNERS_SCORE_PERMILLE;

/// A group without a corner joins the outline's box (within [`ABSORB_REACH_PX`]) when
/// its longest edge runs within this many degrees of parallel or perpendicular to the
/// outline's longest edge: a part's own straight edges (a cylinder's sides along the
/// body's face, a wing's edges), where cloud edges run any way. Session 59, family A
/// (seeds 7001–7201, ½ convention; against cornered groups only): any length (the
/// segment detector's 10 px) / ≥ 15 / ≥ 20 / ≥ 30 px → summed change of famA, paper
/// A, fixtures A and famAF +0.0053 / +0.0042 / +0.0031 / +0.0013 (famAT +0.0029 /
/// +0.0024 / +0.0018 / +0.0003, paperAT +0.0020 / +0.0016 / +0.0015 / 0), no set lower
/// and no false alarm added at any; held out at any length +0.0036 (famBW +0.0054,
/// paperBT +0.0022; famBT −0.0035, the real Earth −0.0009). Without the direction test
/// (any group of ≥ 20 px) −0.0026 at 2 px, +0.0012 at 6 px (famAT −0.0038). The same
/// tolerance as a continuation's ([`MAX_CONTINUATION_DEG`]).
pub const MAX_PART_SQUARE_DEG: f32 = MAX_CONTINUATION_DEG;

/// Farthest a group without a corner may reach past the outline's box and still join
/// it, % of the box's longer side: a part's own straight edges (a cylinder's sides, a
/// boom, a wing's edge that meets the body at a T) end within about the body's size;
/// the limb's straight pieces and a cloud deck's edges run on across the frame, and one
/// taken in carries the box with it (the main job's `realistic/000200`, multi-2: the
/// limb's arc, its pieces one group without a corner, passes 25 px above the body but
/// its box, x 15–321, overlaps the body's; the answer was that box, IoU 0.06, now the
/// body's, 0.96).
/// Chosen on family A (seeds 7001–7201, ½ convention, change of the summed mean IoU of
/// famA, paper A, fixtures A and famAF): 50 / **75–200** % → +0.0003 / **+0.0013**
/// (famAT +0.0058 / +0.0029, paper Tango A −0.0015 / 0), no false alarm changed; held
/// out at 100 % +0.0073 (famBT +0.0069); the main job's realistic multi-2 0.504 →
/// 0.519, Tango 0.564 → 0.566, no other row moved. Bounding the groups with a corner
/// too (a wing's, a panel's): family A −0.0017; they keep no bound. Measuring the reach
/// from a group's segments instead of its box (the limb's arc then stays out too):
/// family A −0.0034 (a part's diagonal edges are taken by their box).
pub const MAX_PART_OVERHANG_PERCENT: i32 = 100;

/// A segment's end within this many quarter pixels of the frame's outermost pixel
/// centres (1 px) lies at the border: the 2×2 blocks nearest it are centred half a
/// pixel inside, and a segment's end is read from its blocks' spread.
pub const BORDER_END_Q: i32 = 4;

/// The outline the stage found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Outline {
    /// The box of its segments' ends, pixels, cut to the frame.
    pub roi: Roi,
    /// Its segments' summed length, pixels.
    pub length_px: u32,
    /// Its segments.
    pub segments: u8,
    /// Its corners (of its own group, not of the groups its box took in).
    pub corners: u8,
    /// Whether every free end of its segments lies on the frame's border (the box is
    /// then carried to the sides they reach).
    pub closed_by_border: bool,
}

impl Outline {
    /// The outline's confidence, a calibrated P(hit), ‰: [`BORDER_OUTLINE_SCORE_PERMILLE`]
    /// under [`MIN_OUTLINE_PX`] (closed by the border), else
    /// [`FEW_CORNERS_SCORE_PERMILLE`] or, from [`MANY_CORNERS`] corners,
    /// [`MANY_CORNERS_SCORE_PERMILLE`].
    pub const fn score_permille(&self) -> u16 {
        if self.length_px < MIN_OUTLINE_PX {
            BORDER_OUTLINE_SCORE_PERMILLE
        } else if self.corners >= MANY_CORNERS {
            MANY_CORNERS_SCORE_PERMILLE
        } else {
            FEW_CORNERS_SCORE_PERMILLE
        }
    }
}

/// `cos²` of an angle in `DIRECTION_ONE⁴` units (the dot product of two directions is
/// in `DIRECTION_ONE²`).
fn cos2_scaled(deg: f32) -> i64 {
    let c = libm::cosf(deg.to_radians()) * (DIRECTION_ONE * DIRECTION_ONE) as f32;
    (c * c) as i64
}

/// The two ends of `s`, quarter pixels.
fn ends(s: &Segment) -> [(i32, i32); 2] {
    [
        (i32::from(s.x0_q), i32::from(s.y0_q)),
        (i32::from(s.x1_q), i32::from(s.y1_q)),
    ]
}

/// How segments `a` and `b` meet: `Some(true)` at a corner, `Some(false)` along a
/// continuation, `None` when they do not.
fn meeting(
    a: &Segment,
    b: &Segment,
    corner_cos2: i64,
    continuation_cos2: i64,
) -> Option<(bool, usize, usize)> {
    let (ea, eb) = (ends(a), ends(b));
    // The closest pair of ends (quarter pixels).
    let mut best = (i64::MAX, 0usize, 0usize);
    for (i, p) in ea.iter().enumerate() {
        for (j, q) in eb.iter().enumerate() {
            let (dx, dy) = (i64::from(p.0 - q.0), i64::from(p.1 - q.1));
            let d2 = dx * dx + dy * dy;
            if d2 < best.0 {
                best = (d2, i, j);
            }
        }
    }
    let reach_q = i64::from(CORNER_REACH_PX * 4);
    // Two corner ends each within the reach of the lines' crossing lie within twice it.
    if best.0 > 4 * reach_q * reach_q {
        return None;
    }
    let ends_meet = best.0 <= reach_q * reach_q;
    let (da, db) = (
        (i32::from(a.dir_x), i32::from(a.dir_y)),
        (i32::from(b.dir_x), i32::from(b.dir_y)),
    );
    let dot = i64::from(da.0 * db.0 + da.1 * db.1);
    if dot * dot <= corner_cos2 && (ends_meet || crossing_near(a, b, best.1, best.2, reach_q)) {
        // A corner: along each segment away from the meeting point, the other's
        // gradient must point to the same side (both edges bound the wedge's region).
        let (pa, oa) = (ea[best.1], ea[1 - best.1]);
        let (pb, ob) = (eb[best.2], eb[1 - best.2]);
        let along_a = (oa.0 - pa.0, oa.1 - pa.1);
        let along_b = (ob.0 - pb.0, ob.1 - pb.1);
        let side_a =
            i64::from(da.0) * i64::from(along_b.0) + i64::from(da.1) * i64::from(along_b.1);
        let side_b =
            i64::from(db.0) * i64::from(along_a.0) + i64::from(db.1) * i64::from(along_a.1);
        return (side_a.signum() == side_b.signum()).then_some((true, best.1, best.2));
    }
    if ends_meet && dot > 0 && dot * dot >= continuation_cos2 {
        // A continuation: b's middle near a's line (a's gradient is its normal).
        let mid = |e: [(i32, i32); 2]| (e[0].0 + e[1].0, e[0].1 + e[1].1);
        let (ma, mb) = (mid(ea), mid(eb));
        // Twice the middles, quarter pixels, times the normal's DIRECTION_ONE.
        let off =
            i64::from(mb.0 - ma.0) * i64::from(da.0) + i64::from(mb.1 - ma.1) * i64::from(da.1);
        let limit = i64::from(2 * 4 * CONTINUATION_OFFSET_PX) * i64::from(DIRECTION_ONE);
        return (off.abs() <= limit).then_some((false, best.1, best.2));
    }
    None
}

/// Farthest an edge's segment may run past the corner it meets, pixels: a segment's
/// ends are read within a pixel of the edge's; the optics round a corner, so an edge
/// stops short of it, never beyond.
pub const CORNER_OVERSHOOT_PX: i32 = 1;

/// Whether the lines of `a` and `b` (not parallel) cross beyond a's end `end_a` and b's
/// end `end_b`, within `reach_q` quarter pixels of each along its line (or
/// [`CORNER_OVERSHOOT_PX`] before it): the optics round a corner, so each edge's segment
/// stops short of it by up to the reach, and two ends short by 5 px each at a right
/// angle lie 7 px apart though the corner is plain (`famAT/000233`, a 30-px panel's
/// corner at the border). An edge that runs on past the other's line (a texture edge
/// crossing the limb) makes no corner.
fn crossing_near(a: &Segment, b: &Segment, end_a: usize, end_b: usize, reach_q: i64) -> bool {
    let (ea, eb) = (ends(a), ends(b));
    let (pa, oa, pb, ob) = (ea[end_a], ea[1 - end_a], eb[end_b], eb[1 - end_b]);
    let (na, nb) = (
        (i64::from(a.dir_x), i64::from(a.dir_y)),
        (i64::from(b.dir_x), i64::from(b.dir_y)),
    );
    // With normals n and directions u = (−n_y, n_x), the lines cross at pa + t·u_a,
    // t = ((pb − pa)·n_b) / (u_a·n_b), and at pb + s·u_b, s = ((pa − pb)·n_a) / (u_b·n_a);
    // u_a·n_b = det and u_b·n_a = −det (n in DIRECTION_ONE units: t = num · DIRECTION_ONE
    // / det quarter pixels). Each is signed outwards (from the segment's other end).
    let det = na.0 * nb.1 - na.1 * nb.0;
    if det == 0 {
        return false;
    }
    let outward = |p: (i32, i32), o: (i32, i32), n: (i64, i64)| {
        (-i64::from(p.0 - o.0) * n.1 + i64::from(p.1 - o.1) * n.0).signum()
    };
    let (dx, dy) = (i64::from(pb.0 - pa.0), i64::from(pb.1 - pa.1));
    let one = i64::from(DIRECTION_ONE);
    // t·|det| and s·|det|, outwards.
    let t = (dx * nb.0 + dy * nb.1) * one * outward(pa, oa, na) * det.signum();
    let s = (dx * na.0 + dy * na.1) * one * outward(pb, ob, nb) * det.signum();
    let (lo, hi) = (
        -i64::from(CORNER_OVERSHOOT_PX * 4) * det.abs(),
        reach_q * det.abs(),
    );
    (lo..=hi).contains(&t) && (lo..=hi).contains(&s)
}

/// The sides of a `w_q` × `h_q` frame (quarter pixels) that point (`x`, `y`) lies
/// within `reach_q` of, measured from the outermost pixel centres: bits left, top,
/// right, bottom.
fn border_sides(x: i32, y: i32, reach_q: i32, (w_q, h_q): (i32, i32)) -> u8 {
    u8::from(x <= reach_q)
        | u8::from(y <= reach_q) << 1
        | u8::from(x >= w_q - 4 - reach_q) << 2
        | u8::from(y >= h_q - 4 - reach_q) << 3
}

/// A group's sums: its segments' summed length, count, corners and the box of their
/// ends (quarter pixels).
#[derive(Debug, Clone, Copy)]
struct Group {
    length_q: u32,
    segments: u8,
    corners: u8,
    /// Free ends off the frame's border.
    open_ends: u8,
    /// Sides of the frame its free ends reach: bits left, top, right, bottom.
    border_sides: u8,
    x0_q: i16,
    y0_q: i16,
    x1_q: i16,
    y1_q: i16,
}

impl Group {
    /// Segment `s` alone.
    fn of(s: &Segment) -> Self {
        Group {
            length_q: u32::from(s.length_q),
            segments: 1,
            corners: 0,
            open_ends: 0,
            border_sides: 0,
            x0_q: s.x0_q.min(s.x1_q),
            y0_q: s.y0_q.min(s.y1_q),
            x1_q: s.x0_q.max(s.x1_q),
            y1_q: s.y0_q.max(s.y1_q),
        }
    }

    /// Whether `other`'s box reaches within `reach_q` quarter pixels of this one's.
    fn reaches(&self, other: &Group, reach_q: i16) -> bool {
        other.x0_q <= self.x1_q + reach_q
            && other.x1_q >= self.x0_q - reach_q
            && other.y0_q <= self.y1_q + reach_q
            && other.y1_q >= self.y0_q - reach_q
    }

    /// Whether `other`'s box reaches past this one's by at most
    /// [`MAX_PART_OVERHANG_PERCENT`] of this one's longer side.
    fn holds_part(&self, other: &Group) -> bool {
        let past = |a: i16, b: i16| (i32::from(a) - i32::from(b)).max(0);
        let overhang = past(self.x0_q, other.x0_q)
            .max(past(other.x1_q, self.x1_q))
            .max(past(self.y0_q, other.y0_q))
            .max(past(other.y1_q, self.y1_q));
        let side = past(self.x1_q, self.x0_q).max(past(self.y1_q, self.y0_q));
        overhang * 100 <= side * MAX_PART_OVERHANG_PERCENT
    }
}

impl ConstInit for Group {
    const INIT: Self = Group {
        length_q: 0,
        segments: 0,
        corners: 0,
        open_ends: 0,
        border_sides: 0,
        x0_q: i16::MAX,
        y0_q: i16::MAX,
        x1_q: i16::MIN,
        y1_q: i16::MIN,
    };
}

impl Stats for Group {
    fn merge(&mut self, other: &Self) {
        self.length_q = self.length_q.saturating_add(other.length_q);
        self.segments = self.segments.saturating_add(other.segments);
        self.corners = self.corners.saturating_add(other.corners);
        self.open_ends = self.open_ends.saturating_add(other.open_ends);
        self.border_sides |= other.border_sides;
        self.x0_q = self.x0_q.min(other.x0_q);
        self.y0_q = self.y0_q.min(other.y0_q);
        self.x1_q = self.x1_q.max(other.x1_q);
        self.y1_q = self.y1_q.max(other.y1_q);
    }
}

/// The groups of the segments: the project's union-find ([`Components`]), one label per
/// segment, the statistics merged on union.
type Groups = Components<u8, Group, [u8; MAX_SEGMENTS], [Group; MAX_SEGMENTS]>;

/// The frame's outline among `segments` (a `width` × `height` frame): the group with a
/// corner and the longest edges of those reaching [`MIN_OUTLINE_PX`] or, closed by the
/// frame's border, [`MIN_BORDER_OUTLINE_PX`]; `None` otherwise.
pub fn strongest(segments: &[Segment], width: usize, height: usize) -> Option<Outline> {
    let n = segments.len().min(MAX_SEGMENTS);
    let segments = segments.get(..n)?;
    let corner_cos2 = cos2_scaled(MIN_CORNER_DEG);
    let continuation_cos2 = cos2_scaled(MAX_CONTINUATION_DEG);
    let mut groups = Groups::INIT;
    for (i, s) in segments.iter().enumerate() {
        groups.make_set(i as u8, Group::of(s));
    }
    // Each segment's ends that meet another's (bits 0 and 1).
    let mut met = [0u8; MAX_SEGMENTS];
    for (i, a) in segments.iter().enumerate() {
        for (j, b) in segments.iter().enumerate().skip(i + 1) {
            let Some((corner, end_a, end_b)) = meeting(a, b, corner_cos2, continuation_cos2) else {
                continue;
            };
            if let Some(m) = met.get_mut(i) {
                *m |= 1 << end_a;
            }
            if let Some(m) = met.get_mut(j) {
                *m |= 1 << end_b;
            }
            let (ri, rj) = (groups.find(i as u8), groups.find(j as u8));
            let root = groups.union(ri, rj);
            if let (true, Some(g)) = (corner, groups.stats_mut(usize::from(root))) {
                g.corners = g.corners.saturating_add(1);
            }
        }
    }
    // The free ends: on the border (the sides they reach) or open; and each group's
    // longest segment (by its root's label; the first of equal lengths).
    let reach_q = CORNER_REACH_PX * 4;
    let (w_q, h_q) = (width as i32 * 4, height as i32 * 4);
    let mut longest = [0u8; MAX_SEGMENTS];
    for (i, (s, &m)) in segments.iter().zip(&met).enumerate() {
        let root = groups.find(i as u8);
        if let Some(l) = longest.get_mut(usize::from(root)) {
            let held = segments.get(usize::from(*l)).map_or(0, |h| h.length_q);
            if groups.find(*l) != root || s.length_q > held {
                *l = i as u8;
            }
        }
        for (k, &(x, y)) in ends(s).iter().enumerate() {
            if m & (1 << k) != 0 {
                continue;
            }
            let sides = border_sides(x, y, reach_q, (w_q, h_q));
            if let Some(g) = groups.stats_mut(usize::from(root)) {
                if sides == 0 {
                    g.open_ends = g.open_ends.saturating_add(1);
                } else {
                    g.border_sides |= sides;
                }
            }
        }
    }
    // The groups (their roots' labels and statistics), and those with a corner.
    let roots = || {
        (0..n)
            .filter(|&l| groups.parent(l) == Some(l as u8))
            .filter_map(|l| groups.stats(l).map(|g| (l, *g)))
    };
    let cornered = || roots().filter(|(_, g)| g.corners > 0);
    let closed_by_border = |g: &Group| g.open_ends == 0 && g.border_sides != 0;
    let (best_root, best) = cornered()
        .filter(|(_, g)| {
            let length_px = g.length_q / 4;
            length_px >= MIN_OUTLINE_PX
                || (closed_by_border(g) && length_px >= MIN_BORDER_OUTLINE_PX)
        })
        .max_by_key(|(_, g)| g.length_q)?;
    let length_px = best.length_q / 4;
    if width == 0 || height == 0 {
        return None;
    }
    // The other groups that reach the box take part in it (its box only: the outline's
    // length, segments and corners stay its own group's): those with a corner, and
    // those without one running square to the outline's longest edge (a part's own
    // straight edges).
    let reach_q = (ABSORB_REACH_PX * 4) as i16;
    let perpendicular_cos2 = cos2_scaled(90.0 - MAX_PART_SQUARE_DEG);
    let square_cos2 = cos2_scaled(MAX_PART_SQUARE_DEG);
    let longest_of = |root: usize| {
        longest
            .get(root)
            .and_then(|&i| segments.get(usize::from(i)))
            .map_or((0, 0), |s| (i64::from(s.dir_x), i64::from(s.dir_y)))
    };
    let best_dir = longest_of(best_root);
    let square = |root: usize| {
        let dir = longest_of(root);
        let dot = best_dir.0 * dir.0 + best_dir.1 * dir.1;
        let dot2 = dot * dot;
        dot2 >= square_cos2 || dot2 <= perpendicular_cos2
    };
    let mut b = best;
    // The groups the box takes (by root label).
    let mut taken = [false; MAX_SEGMENTS];
    for (l, g) in roots() {
        let part = l != best_root
            && best.reaches(&g, reach_q)
            && (g.corners > 0 || (square(l) && best.holds_part(&g)));
        if part {
            b.merge(&g);
        }
        if let Some(t) = taken.get_mut(l) {
            *t = part || l == best_root;
        }
    }
    // Pixels whose centres lie inside the ends' box (an edge lies between two pixels):
    // from the first centre at or after the low end to the last at or before the high
    // end, the box's end one past it. (`max`/`min`, not `clamp`, whose bounds check is
    // a panic path.)
    let last = |n: usize| n.saturating_sub(1).min(usize::from(u16::MAX)) as i32;
    let lo = |q: i16, n: usize| (i32::from(q) + 3).div_euclid(4).max(0).min(last(n)) as u16;
    let hi = |q: i16, n: usize| i32::from(q).div_euclid(4).max(0).min(last(n)) as u16;
    let (mut x0, mut y0) = (lo(b.x0_q, width), lo(b.y0_q, height));
    let (mut x1, mut y1) = (
        hi(b.x1_q, width).max(x0) + 1,
        hi(b.y1_q, height).max(y0) + 1,
    );
    // The sides the box is carried to: those an edge runs into (more across the border
    // than along it) and ends at — the 2×2 blocks end half a pixel inside, so its
    // segment stops there and the box one pixel short of the border — and, for an
    // outline closed by the border, those its free ends reach.
    let mut carried = 0u8;
    for (i, s) in segments.iter().enumerate() {
        if !taken
            .get(usize::from(groups.find(i as u8)))
            .copied()
            .unwrap_or(false)
        {
            continue;
        }
        // Left and right for an edge across the vertical sides, else top and bottom.
        let across = if i32::from(s.dir_x).abs() < i32::from(s.dir_y).abs() {
            0b0101
        } else {
            0b1010
        };
        for (x, y) in ends(s) {
            carried |= border_sides(x, y, BORDER_END_Q, (w_q, h_q)) & across;
        }
    }
    let closed = closed_by_border(&best);
    if closed {
        carried |= best.border_sides;
    }
    let side = |bit: u8| carried & (1 << bit) != 0;
    if side(0) {
        x0 = 0;
    }
    if side(1) {
        y0 = 0;
    }
    if side(2) {
        x1 = last(width) as u16 + 1;
    }
    if side(3) {
        y1 = last(height) as u16 + 1;
    }
    Some(Outline {
        roi: Roi { x0, y0, x1, y1 },
        length_px,
        segments: best.segments,
        corners: best.corners,
        closed_by_border: closed,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A segment from (x0, y0) to (x1, y1), pixels, its gradient towards (gx, gy).
    fn seg(x0: f32, y0: f32, x1: f32, y1: f32, gx: f32, gy: f32) -> Segment {
        let n = libm::sqrtf(gx * gx + gy * gy);
        let len = libm::sqrtf((x1 - x0).powi(2) + (y1 - y0).powi(2));
        Segment {
            x0_q: (x0 * 4.0) as i16,
            y0_q: (y0 * 4.0) as i16,
            x1_q: (x1 * 4.0) as i16,
            y1_q: (y1 * 4.0) as i16,
            dir_x: (gx / n * DIRECTION_ONE as f32) as i16,
            dir_y: (gy / n * DIRECTION_ONE as f32) as i16,
            length_q: (len * 4.0) as u16,
            blocks: (len * 2.0) as u16,
        }
    }

    /// Sides of a dark 60 × 40 rectangle at (29.5, 24.5)–(89.5, 64.5), gradients
    /// outwards, ends 1–2 px short of the corners: top, bottom, left, right.
    fn dark_rectangle() -> [Segment; 4] {
        [
            seg(31.0, 24.5, 88.0, 24.5, 0.0, -1.0),
            seg(31.0, 64.5, 88.0, 64.5, 0.0, 1.0),
            seg(29.5, 26.0, 29.5, 63.0, -1.0, 0.0),
            seg(89.5, 26.0, 89.5, 63.0, 1.0, 0.0),
        ]
    }

    #[test]
    fn a_dark_rectangle_is_an_outline() {
        let sides = dark_rectangle();
        let o = strongest(&sides, 120, 90).unwrap();
        assert_eq!((o.segments, o.corners), (4, 4), "{o:?}");
        assert_eq!(
            o.roi,
            Roi {
                x0: 30,
                y0: 25,
                x1: 90,
                y1: 65
            }
        );
        assert_eq!(o.score_permille(), MANY_CORNERS_SCORE_PERMILLE);
        // Three sides still bound it (two corners); its box is theirs.
        let o = strongest(&sides[..3], 120, 90).unwrap();
        assert_eq!((o.segments, o.corners), (3, 2));
        assert_eq!(o.score_permille(), FEW_CORNERS_SCORE_PERMILLE);
    }

    #[test]
    fn a_part_meeting_the_body_at_a_t_is_taken_in() {
        // The dark rectangle and, to its right, a narrower dark part (a cylinder) from
        // x 89.5 to 119.5, y 34.5–55.5: its long sides end on the body's right side (a
        // T, not a corner) and meet its own far end at corners.
        let body = dark_rectangle();
        let part = [
            seg(91.0, 34.5, 118.0, 34.5, 0.0, -1.0),
            seg(91.0, 55.5, 118.0, 55.5, 0.0, 1.0),
            seg(119.5, 36.0, 119.5, 54.0, 1.0, 0.0),
        ];
        let all: [Segment; 7] = core::array::from_fn(|i| if i < 4 { body[i] } else { part[i - 4] });
        let o = strongest(&all, 160, 90).unwrap();
        // The body is the outline (the longest group); the part's box joins it.
        assert_eq!((o.segments, o.corners), (4, 4), "{o:?}");
        assert_eq!(
            o.roi,
            Roi {
                x0: 30,
                y0: 25,
                x1: 120,
                y1: 65
            }
        );
        // Apart by more than the reach, the part stays out.
        let moved: [Segment; 7] = core::array::from_fn(|i| {
            let mut s = all[i];
            if i >= 4 {
                s.x0_q += 4 * (ABSORB_REACH_PX as i16 + 2);
                s.x1_q += 4 * (ABSORB_REACH_PX as i16 + 2);
            }
            s
        });
        let o = strongest(&moved, 160, 90).unwrap();
        assert_eq!(
            o.roi,
            Roi {
                x0: 30,
                y0: 25,
                x1: 90,
                y1: 65
            }
        );
    }

    #[test]
    fn edges_that_disagree_at_a_corner_or_run_apart_are_no_outline() {
        // The top side and the left side of a dark rectangle meet; the left side's
        // gradient flipped (a brighter region to its right) breaks the corner.
        let [top, _, left, _] = dark_rectangle();
        assert!(strongest(&[top, left], 120, 90).is_some());
        let flipped = seg(29.5, 26.0, 29.5, 63.0, 1.0, 0.0);
        assert!(strongest(&[top, flipped], 120, 90).is_none());
        // Apart by 8 px: no corner.
        let far = seg(29.5, 32.5, 29.5, 70.0, -1.0, 0.0);
        assert!(strongest(&[top, far], 120, 90).is_none());
        // Two pieces of one straight edge: a continuation, no corner, no outline.
        let piece = seg(90.0, 24.5, 140.0, 25.0, 0.0, -1.0);
        assert!(strongest(&[top, piece], 200, 90).is_none());
        // A corner too short in total.
        let short_top = seg(31.0, 24.5, 51.0, 24.5, 0.0, -1.0);
        let short_left = seg(29.5, 26.0, 29.5, 50.0, -1.0, 0.0);
        assert!(strongest(&[short_top, short_left], 120, 90).is_none());
    }

    #[test]
    fn a_piece_cut_by_the_frame_is_closed_by_its_border() {
        // A dark panel's corner in the frame's top-right corner (120 × 90): two edges of
        // 16 and 18 px meeting at (99.5, 17.5) (between pixels), their free ends on the
        // top and right sides.
        // The panel lies between them and the frame's corner (gradients point out of it).
        let left = seg(99.5, 0.0, 99.5, 16.0, -1.0, 0.0);
        let bottom = seg(101.0, 17.5, 119.0, 17.5, 0.0, 1.0);
        let o = strongest(&[left, bottom], 120, 90).unwrap();
        assert!(o.closed_by_border, "{o:?}");
        assert_eq!((o.segments, o.corners), (2, 1));
        assert!(o.length_px < MIN_OUTLINE_PX);
        assert_eq!(o.score_permille(), BORDER_OUTLINE_SCORE_PERMILLE);
        // The box runs on to the two sides the free ends reach.
        assert_eq!(
            o.roi,
            Roi {
                x0: 100,
                y0: 0,
                x1: 120,
                y1: 18
            }
        );
        // The same corner with a free end 12 or 9 px inside the frame is open: under
        // MIN_OUTLINE_PX, no outline.
        let short_bottom = seg(101.0, 17.5, 106.5, 17.5, 0.0, 1.0);
        assert!(strongest(&[left, short_bottom], 120, 90).is_none());
        let inner = seg(101.0, 17.5, 109.5, 17.5, 0.0, 1.0);
        let o = strongest(&[left, inner], 120, 90);
        assert!(o.is_none(), "{o:?}");
        // Closed by the border but under MIN_BORDER_OUTLINE_PX in total (a cloud's
        // tip: two 10-px edges): no outline.
        let tip_a = seg(110.0, 0.0, 110.0, 10.0, -1.0, 0.0);
        let tip_b = seg(111.5, 11.5, 119.0, 11.5, 0.0, 1.0);
        assert!(strongest(&[tip_a, tip_b], 120, 90).is_none());
    }

    #[test]
    fn edges_that_stop_short_of_their_crossing_meet_at_a_corner() {
        // The panel's corner of the test above, each edge 5 px short of (99.5, 17.5): the
        // ends lie 7.1 px apart, beyond CORNER_REACH_PX, but the lines cross within it
        // of both, beyond each end.
        let left = seg(99.5, 0.0, 99.5, 12.5, -1.0, 0.0);
        let bottom = seg(104.5, 17.5, 119.0, 17.5, 0.0, 1.0);
        let o = strongest(&[left, bottom], 120, 90).unwrap();
        assert_eq!((o.segments, o.corners), (2, 1), "{o:?}");
        assert!(o.closed_by_border);
        assert_eq!(
            o.roi,
            Roi::new(100, 0, 120, 18),
            "the same box as the test above's"
        );
        // Short by 7 px each: the crossing is out of reach.
        let far_left = seg(99.5, 0.0, 99.5, 10.5, -1.0, 0.0);
        let far_bottom = seg(106.5, 17.5, 119.0, 17.5, 0.0, 1.0);
        assert!(strongest(&[far_left, far_bottom], 120, 90).is_none());
        // An edge running 3 px past the other's line (a texture edge across the
        // limb), ends 6.3 px apart: no corner.
        let through = seg(99.5, 0.0, 99.5, 20.5, -1.0, 0.0);
        let beside = seg(105.0, 17.5, 119.0, 17.5, 0.0, 1.0);
        assert!(strongest(&[through, beside], 120, 90).is_none());
        // Run 1 px past it (a segment's end read a pixel off): still a corner.
        let reaching = seg(99.5, 0.0, 99.5, 18.5, -1.0, 0.0);
        let o = strongest(&[reaching, beside], 120, 90).unwrap();
        assert_eq!(o.corners, 1, "{o:?}");
    }

    #[test]
    fn an_edge_running_into_the_border_carries_the_box_to_it() {
        // A dark face cut by the left border: its top edge runs into the border (its
        // last blocks' centres half a pixel inside), its right side ends open at the
        // bottom (not closed by the border). The box reaches column 0.
        let top = seg(0.5, 24.5, 60.0, 24.5, 0.0, -1.0);
        let right = seg(61.5, 26.0, 61.5, 63.0, 1.0, 0.0);
        let o = strongest(&[top, right], 120, 90).unwrap();
        assert!(!o.closed_by_border, "{o:?}");
        assert_eq!(o.roi.x0, 0, "{o:?}");
        // An edge along the border (a vertical side at x 0.5, the face starting at
        // column 1) does not: the box starts at column 1.
        let left = seg(0.5, 26.0, 0.5, 63.0, -1.0, 0.0);
        let top = seg(2.0, 24.5, 60.0, 24.5, 0.0, -1.0);
        let o = strongest(&[left, top, right], 120, 90).unwrap();
        assert_eq!(o.roi.x0, 1, "{o:?}");
        // The same at the right border, an end 1 px from the last pixel centre (119).
        let top = seg(60.0, 24.5, 118.0, 24.5, 0.0, -1.0);
        let left = seg(58.5, 26.0, 58.5, 63.0, -1.0, 0.0);
        let o = strongest(&[left, top], 120, 90).unwrap();
        assert!(!o.closed_by_border, "{o:?}");
        assert_eq!(o.roi.x1, 120, "{o:?}");
    }

    #[test]
    fn a_long_outline_closed_by_the_border_reaches_it() {
        // The dark rectangle's left, top and bottom sides cut by the frame's right side
        // at x 89: its box reaches the side; open, it stops at the ends.
        let [top, bottom, left, _] = dark_rectangle();
        let o = strongest(&[top, bottom, left], 90, 90).unwrap();
        assert!(o.closed_by_border, "{o:?}");
        assert_eq!(o.roi.x1, 90);
        let o = strongest(&[top, bottom, left], 120, 90).unwrap();
        assert!(!o.closed_by_border, "{o:?}");
        assert_eq!(o.roi.x1, 89);
    }

    /// The dark rectangle's four sides and `part`.
    fn with_part(part: Segment) -> [Segment; 5] {
        let body = dark_rectangle();
        core::array::from_fn(|i| body.get(i).copied().unwrap_or(part))
    }

    #[test]
    fn a_part_edge_square_to_the_outline_is_taken_in() {
        // A lone edge beside the dark rectangle's right side, parallel to its top (a
        // cylinder's side), 1.5 px away: its box joins; the same edge at 45° (a cloud's)
        // does not, nor one beyond the reach.
        let along = seg(91.0, 40.0, 115.0, 40.0, 0.0, -1.0);
        let o = strongest(&with_part(along), 160, 90).unwrap();
        assert_eq!((o.segments, o.corners), (4, 4), "{o:?}");
        assert_eq!(o.roi.x1, 116);
        let upright = seg(91.0, 30.0, 91.0, 55.0, 1.0, 0.0);
        assert_eq!(strongest(&with_part(upright), 160, 90).unwrap().roi.x1, 92);
        let skew = seg(91.0, 40.0, 108.0, 57.0, 1.0, -1.0);
        assert_eq!(strongest(&with_part(skew), 160, 90).unwrap().roi.x1, 90);
        let far = seg(99.0, 40.0, 120.0, 40.0, 0.0, -1.0);
        assert_eq!(strongest(&with_part(far), 160, 90).unwrap().roi.x1, 90);
    }

    #[test]
    fn an_edge_running_on_past_the_outline_stays_out() {
        // The part edge of the test above run on to the right: the outline's box spans
        // x 29.5–89.5 (60 px), so an edge may reach 60 px past it (x 149.5), no more (a
        // limb's straight piece running across the frame).
        let part = seg(91.0, 40.0, 149.5, 40.0, 0.0, -1.0);
        assert_eq!(strongest(&with_part(part), 200, 90).unwrap().roi.x1, 150);
        let limb = seg(91.0, 40.0, 150.5, 40.0, 0.0, -1.0);
        assert_eq!(strongest(&with_part(limb), 200, 90).unwrap().roi.x1, 90);
        // Running to the frame's border, it would have carried the box there.
        let across = seg(91.0, 40.0, 199.5, 40.0, 0.0, -1.0);
        assert_eq!(strongest(&with_part(across), 200, 90).unwrap().roi.x1, 90);
        // Downwards past the bottom (y 64.5) alike, in a frame 200 px high (3.5 px
        // beside the right side: no continuation of it).
        let down = seg(93.0, 45.0, 93.0, 124.5, 1.0, 0.0);
        let o = strongest(&with_part(down), 200, 200).unwrap();
        assert_eq!((o.roi.x1, o.roi.y1), (94, 125), "{o:?}");
        let down = seg(93.0, 45.0, 93.0, 125.5, 1.0, 0.0);
        let o = strongest(&with_part(down), 200, 200).unwrap();
        assert_eq!((o.roi.x1, o.roi.y1), (90, 65), "{o:?}");
    }

    #[test]
    fn a_broken_side_continues_its_outline() {
        // The bottom side in two pieces (a gap of 4 px), joined along the line; the
        // group holds all five segments.
        let [top, _, left, right] = dark_rectangle();
        let sides = [
            top,
            seg(31.0, 64.5, 55.0, 64.5, 0.0, 1.0),
            seg(59.0, 64.6, 88.0, 64.5, 0.0, 1.0),
            left,
            right,
        ];
        let o = strongest(&sides, 120, 90).unwrap();
        assert_eq!(o.segments, 5, "{o:?}");
    }
}
