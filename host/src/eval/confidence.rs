//! What a detector's confidence (`Detection::score`, 0–1) is worth: the hit rate and
//! the false-alarm rate as the score threshold sweeps, the area under that curve, and
//! the calibration per score decile. One definition for built-in methods and for
//! predictions read from files (`docs/results.md` § Confidence).
//!
//! Each frame is an [`Outcome`]: whether it has a target, the score of the detector's
//! box (`None`: no box), and whether that box is a hit (IoU ≥ ½ with the truth,
//! [`crate::eval::scoring::HIT_IOU`]). At a threshold `t` a box *counts* when its score
//! is ≥ `t`; a box under the threshold counts as no box (`null`).
//!
//! **The curve** ([`curve`]) is the detection-level ROC over frames:
//! - *positives* are the frames with a target; one is found at `t` when its box counts
//!   and is a hit. Hit rate `HR(t)` = found / positives.
//! - *negatives* are the frames without a target (at the score of their box, if any)
//!   **and** the frames with a target whose box is not a hit (a false positive at its
//!   score; the same frame is also a miss among the positives). False-positive rate
//!   `FPR(t)` = negatives whose box counts / negatives.
//! - beside them, the plain false-alarm rate `FAR(t)` = frames without a target whose box
//!   counts / frames without a target (what the tables call false alarms).
//!
//! The points are `t = +∞` (nothing counts: (0, 0)) and every distinct score, highest
//! first. **AUC** ([`auc`]) is the trapezoid area under (FPR, HR) from (0, 0) through
//! the points, closed by a flat line from the last point to FPR = 1 at the last hit
//! rate (frames without a box never count, whatever the threshold). It equals
//! `P(s⁺ > s⁻) + ½·P(s⁺ = s⁻)` over all (positive, negative) pairs, where a positive's
//! `s⁺` is its box's score if it is a hit and −∞ otherwise, a negative's `s⁻` is its
//! box's score and −∞ without a box, and a pair with `s⁺ = −∞` scores 0 (a miss is never
//! ranked above anything). It is undefined (`None`) without positives or negatives.
//!
//! **Calibration** ([`calibration`]): every box (frames with and without a target) falls
//! in decile `k = ⌊10·s⌋` (k = 0..9, a score of 1 in decile 9; the score is rounded to
//! 6 decimals first, so 0.7 stored as f32 is in decile 7). Per decile: the boxes, their
//! mean score and their hit rate (a box on a frame without a target is not a hit). A
//! calibrated confidence has `|hit rate − mean score| ≤ 0.1` in every decile that holds
//! boxes ([`max_gap`]).

use serde::Serialize;

/// One frame as the confidence measures see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outcome {
    /// The frame has a target (its truth box is not empty).
    pub has_target: bool,
    /// The detector's confidence in its box, 0–1; `None` when it returned no box.
    pub score: Option<f32>,
    /// The box is a hit: the frame has a target and IoU ≥ ½.
    pub hit: bool,
}

impl Outcome {
    /// Whether the box counts at `threshold` (a box whose score is ≥ it).
    pub fn counts(&self, threshold: f64) -> bool {
        self.score.is_some_and(|s| f64::from(s) >= threshold)
    }

    /// A frame with a target whose box counts at `threshold` and is a hit.
    pub fn found(&self, threshold: f64) -> bool {
        self.has_target && self.hit && self.counts(threshold)
    }

    /// A negative of the curve: no target, or a target with a box that is not a hit.
    pub fn negative(&self) -> bool {
        !self.has_target || (self.score.is_some() && !self.hit)
    }
}

/// One point of the curve ([`curve`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CurvePoint {
    /// Score threshold (a box counts when its score is ≥ it); `+∞` for the first point.
    pub threshold: f64,
    /// Share of the frames with a target found (box counts, IoU ≥ ½); 0 without any.
    pub hit_rate: f64,
    /// Share of the frames without a target whose box counts; 0 without any.
    pub false_alarm_rate: f64,
    /// Share of the negatives (frames without a target, and frames whose box is not a
    /// hit) whose box counts: the curve's x; 0 without any.
    pub false_positive_rate: f64,
}

fn share(n: usize, of: usize) -> f64 {
    if of == 0 { 0.0 } else { n as f64 / of as f64 }
}

/// The rates at one threshold.
pub fn point(outcomes: &[Outcome], threshold: f64) -> CurvePoint {
    let targets = outcomes.iter().filter(|o| o.has_target).count();
    let empty = outcomes.len() - targets;
    let negatives = outcomes.iter().filter(|o| o.negative()).count();
    let found = outcomes.iter().filter(|o| o.found(threshold)).count();
    let alarms = outcomes
        .iter()
        .filter(|o| !o.has_target && o.counts(threshold))
        .count();
    let false_positives = outcomes
        .iter()
        .filter(|o| o.negative() && o.counts(threshold))
        .count();
    CurvePoint {
        threshold,
        hit_rate: share(found, targets),
        false_alarm_rate: share(alarms, empty),
        false_positive_rate: share(false_positives, negatives),
    }
}

/// The curve: `t = +∞`, then every distinct box score, highest first (module docs).
pub fn curve(outcomes: &[Outcome]) -> Vec<CurvePoint> {
    let mut scores: Vec<f32> = outcomes.iter().filter_map(|o| o.score).collect();
    scores.sort_by(|a, b| b.total_cmp(a));
    scores.dedup();
    std::iter::once(f64::INFINITY)
        .chain(scores.into_iter().map(f64::from))
        .map(|t| point(outcomes, t))
        .collect()
}

/// Area under the curve (module docs); `None` without frames with a target or without
/// negatives.
pub fn auc(outcomes: &[Outcome]) -> Option<f64> {
    let positives = outcomes.iter().filter(|o| o.has_target).count();
    let negatives = outcomes.iter().filter(|o| o.negative()).count();
    if positives == 0 || negatives == 0 {
        return None;
    }
    let points = curve(outcomes);
    let mut area = 0.0;
    for w in points.windows(2) {
        let (a, b) = (w[0], w[1]);
        area += (b.false_positive_rate - a.false_positive_rate) * (a.hit_rate + b.hit_rate) / 2.0;
    }
    let last = points[points.len() - 1];
    area += (1.0 - last.false_positive_rate) * last.hit_rate;
    Some(area)
}

/// Number of score deciles.
pub const DECILES: usize = 10;

/// Largest gap `|hit rate − mean score|` in a decile that the issue accepts as
/// calibrated (issue 16: "per score decile the hit rate within 0.1 of the score").
pub const CALIBRATION_TOLERANCE: f64 = 0.1;

/// The boxes of one score decile ([`calibration`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Decile {
    /// Lower bound of the decile's scores, inclusive (k/10).
    pub lower: f64,
    /// Upper bound, exclusive ((k+1)/10; the last decile includes 1).
    pub upper: f64,
    /// Boxes whose score falls in the decile.
    pub boxes: usize,
    /// Their mean score (0 when there are none).
    pub mean_score: f64,
    /// Share of them that are hits (0 when there are none).
    pub hit_rate: f64,
}

impl Decile {
    /// `|hit rate − mean score|`, `None` for a decile without boxes.
    pub fn gap(&self) -> Option<f64> {
        (self.boxes > 0).then(|| (self.hit_rate - self.mean_score).abs())
    }
}

/// The decile of a score in 0–1: `⌊10·s⌋` after rounding `s` to 6 decimals, 9 for 1.
pub fn decile_of(score: f32) -> usize {
    let micro = (f64::from(score).clamp(0.0, 1.0) * 1e6).round() as usize;
    (micro / 100_000).min(DECILES - 1)
}

/// Boxes, mean score and hit rate per score decile (module docs).
pub fn calibration(outcomes: &[Outcome]) -> [Decile; DECILES] {
    let mut sum = [0.0f64; DECILES];
    let mut hits = [0usize; DECILES];
    let mut boxes = [0usize; DECILES];
    for o in outcomes {
        if let Some(s) = o.score {
            let k = decile_of(s);
            boxes[k] += 1;
            sum[k] += f64::from(s);
            hits[k] += usize::from(o.hit && o.has_target);
        }
    }
    std::array::from_fn(|k| Decile {
        lower: k as f64 / DECILES as f64,
        upper: (k + 1) as f64 / DECILES as f64,
        boxes: boxes[k],
        mean_score: if boxes[k] == 0 {
            0.0
        } else {
            sum[k] / boxes[k] as f64
        },
        hit_rate: share(hits[k], boxes[k]),
    })
}

/// The largest `|hit rate − mean score|` over the deciles holding boxes; `None` when no
/// decile does.
pub fn max_gap(deciles: &[Decile]) -> Option<f64> {
    deciles.iter().filter_map(Decile::gap).reduce(f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn o(has_target: bool, score: Option<f32>, hit: bool) -> Outcome {
        Outcome {
            has_target,
            score,
            hit,
        }
    }

    /// The pair definition of the module docs, by brute force over every pair.
    fn auc_by_pairs(outcomes: &[Outcome]) -> Option<f64> {
        let pos: Vec<Option<f32>> = outcomes
            .iter()
            .filter(|x| x.has_target)
            .map(|x| if x.hit { x.score } else { None })
            .collect();
        let neg: Vec<Option<f32>> = outcomes
            .iter()
            .filter(|x| x.negative())
            .map(|x| x.score)
            .collect();
        if pos.is_empty() || neg.is_empty() {
            return None;
        }
        let mut sum = 0.0;
        for p in &pos {
            for n in &neg {
                sum += match (p, n) {
                    (None, _) => 0.0,
                    (Some(_), None) => 1.0,
                    (Some(a), Some(b)) if a > b => 1.0,
                    (Some(a), Some(b)) if a == b => 0.5,
                    _ => 0.0,
                };
            }
        }
        Some(sum / (pos.len() * neg.len()) as f64)
    }

    fn lists() -> Vec<Vec<Outcome>> {
        vec![
            // Perfect: every target hit at 0.9, silent on the empty frames.
            vec![
                o(true, Some(0.9), true),
                o(true, Some(0.9), true),
                o(false, None, false),
            ],
            // The paper's four: score 1 for every box, a false alarm, a wrong box, a miss.
            vec![
                o(true, Some(1.0), true),
                o(true, Some(1.0), false),
                o(true, None, false),
                o(false, Some(1.0), false),
                o(false, None, false),
            ],
            // Mixed scores with ties between a hit and a false alarm.
            vec![
                o(true, Some(0.8), true),
                o(true, Some(0.6), true),
                o(true, Some(0.3), false),
                o(true, Some(0.2), true),
                o(false, Some(0.6), false),
                o(false, Some(0.1), false),
                o(false, None, false),
                o(false, Some(0.95), false),
            ],
        ]
    }

    #[test]
    fn auc_equals_the_pair_count() {
        for list in lists() {
            let a = auc(&list).unwrap();
            let b = auc_by_pairs(&list).unwrap();
            assert!((a - b).abs() < 1e-12, "{a} vs {b} on {list:?}");
        }
        // Perfect ranking by hand: area 1.
        assert!((auc(&lists()[0]).unwrap() - 1.0).abs() < 1e-12);
        // The paper's four by hand: positives {hit@1, miss, miss}, negatives {wrong@1,
        // alarm@1, silent}: the hit ties two (½ each) and beats one → (½+½+1)/9.
        assert!((auc(&lists()[1]).unwrap() - 2.0 / 9.0).abs() < 1e-12);
        // Undefined without positives or negatives.
        assert_eq!(auc(&[o(false, Some(0.5), false)]), None);
        assert_eq!(auc(&[o(true, Some(0.5), true)]), None);
    }

    #[test]
    fn curve_points_by_counting() {
        let list = &lists()[2];
        let c = curve(list);
        // +∞, then 0.95, 0.8, 0.6, 0.3, 0.2, 0.1.
        let t: Vec<f64> = c.iter().map(|p| p.threshold).collect();
        assert_eq!(t[0], f64::INFINITY);
        assert_eq!(t.len(), 7);
        assert_eq!((c[0].hit_rate, c[0].false_alarm_rate), (0.0, 0.0));
        for p in &c {
            // Count by hand at each threshold.
            let th = p.threshold;
            let found = list
                .iter()
                .filter(|x| x.has_target && x.hit && x.score.is_some_and(|s| f64::from(s) >= th))
                .count();
            let alarms = list
                .iter()
                .filter(|x| !x.has_target && x.score.is_some_and(|s| f64::from(s) >= th))
                .count();
            assert_eq!(p.hit_rate, found as f64 / 4.0);
            assert_eq!(p.false_alarm_rate, alarms as f64 / 4.0);
        }
        // At 0.6: hits 0.8 and 0.6 (2 of 4); alarms 0.95 and 0.6 (2 of 4); negatives
        // are the 4 empty frames and the wrong box at 0.3 → 2 of 5.
        let at = point(list, 0.6);
        assert_eq!(
            (at.hit_rate, at.false_alarm_rate, at.false_positive_rate),
            (0.5, 0.5, 0.4)
        );
    }

    #[test]
    fn deciles_by_hand() {
        let list = [
            o(true, Some(0.7), true),
            o(true, Some(0.75), false),
            o(false, Some(0.79), false),
            o(true, Some(1.0), true),
            o(true, Some(0.05), false),
            o(true, None, false),
        ];
        let d = calibration(&list);
        assert_eq!(d.iter().map(|x| x.boxes).sum::<usize>(), 5);
        assert_eq!(d[7].boxes, 3);
        assert!((d[7].mean_score - (0.7f64 + 0.75 + 0.79) / 3.0).abs() < 1e-6);
        assert!((d[7].hit_rate - 1.0 / 3.0).abs() < 1e-12);
        assert_eq!((d[9].boxes, d[9].hit_rate), (1, 1.0));
        assert_eq!((d[0].boxes, d[0].hit_rate), (1, 0.0));
        assert_eq!(d[3].gap(), None);
        let gap = max_gap(&d).unwrap();
        assert!((gap - (d[7].mean_score - 1.0 / 3.0)).abs() < 1e-12, "{gap}");
        for (s, k) in [
            (0.0, 0),
            (0.1, 1),
            (0.7, 7),
            (0.3, 3),
            (0.999_999_9, 9),
            (1.0, 9),
        ] {
            assert_eq!(decile_of(s), k, "{s}");
        }
    }
}
