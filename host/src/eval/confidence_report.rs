//! The confidence figures of an evaluation ([`crate::eval::confidence`]) for every method
//! (or predictions set), every group and overall, under each truth convention given:
//! the Markdown `tirroi eval` prints, `confidence.csv` and `calibration.csv` in `--out`,
//! and the `--curve` CSV.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Serialize;

use crate::eval::confidence::{self, CALIBRATION_TOLERANCE, CurvePoint, DECILES, Decile, Outcome};
use crate::eval::scoring::{EvalError, FrameScore, TruthCoverage};

/// One method over one group under one truth convention.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConfidenceRow {
    /// Method or predictions set.
    pub method: String,
    /// Truth convention: `half` (pixels ≥ ½ covered) or `quarter` (> ¼ covered).
    pub truth: &'static str,
    /// Group column (`all` for every frame).
    pub group: String,
    /// Group value.
    pub value: String,
    /// Frames with a target.
    pub target_frames: usize,
    /// Frames without a target.
    pub empty_frames: usize,
    /// Share of the frames with a target whose box is a hit (every box counts).
    pub hit_rate: f64,
    /// Share of the frames without a target with a box.
    pub false_alarm_rate: f64,
    /// [`confidence::auc`]; `None` when undefined.
    pub auc: Option<f64>,
    /// [`confidence::max_gap`] over the deciles; `None` without boxes.
    pub calibration_gap: Option<f64>,
}

/// The figures of an evaluation (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// Per method, truth convention and group (`all` first for each method).
    pub rows: Vec<ConfidenceRow>,
    /// The curve over all frames, per method and truth convention.
    pub curves: Vec<(String, &'static str, Vec<CurvePoint>)>,
    /// The deciles over all frames, per method and truth convention.
    pub deciles: Vec<(String, &'static str, [Decile; DECILES])>,
}

fn row(
    method: &str,
    truth: &'static str,
    group: &str,
    value: &str,
    outcomes: &[Outcome],
) -> ConfidenceRow {
    let targets = outcomes.iter().filter(|o| o.has_target).count();
    let at_zero = confidence::point(outcomes, f64::NEG_INFINITY);
    ConfidenceRow {
        method: method.into(),
        truth,
        group: group.into(),
        value: value.into(),
        target_frames: targets,
        empty_frames: outcomes.len() - targets,
        hit_rate: at_zero.hit_rate,
        false_alarm_rate: at_zero.false_alarm_rate,
        auc: confidence::auc(outcomes),
        calibration_gap: confidence::max_gap(&confidence::calibration(outcomes)),
    }
}

impl Report {
    /// The figures of `conventions`: each a truth convention and the scores against its
    /// boxes (the same frames and boxes).
    pub fn new(conventions: &[(TruthCoverage, Vec<FrameScore>)]) -> Report {
        let mut report = Report {
            rows: Vec::new(),
            curves: Vec::new(),
            deciles: Vec::new(),
        };
        for (coverage, scores) in conventions {
            let truth = coverage.name();
            let mut methods: Vec<&str> = Vec::new();
            for s in scores {
                if !methods.contains(&s.method.as_str()) {
                    methods.push(&s.method);
                }
            }
            for m in methods {
                let mine: Vec<&FrameScore> = scores.iter().filter(|s| s.method == m).collect();
                let all: Vec<Outcome> = mine.iter().map(|s| s.outcome()).collect();
                report.rows.push(row(m, truth, "all", "all", &all));
                report
                    .curves
                    .push((m.to_string(), truth, confidence::curve(&all)));
                report
                    .deciles
                    .push((m.to_string(), truth, confidence::calibration(&all)));
                let mut by: BTreeMap<(&str, &str), Vec<Outcome>> = BTreeMap::new();
                for s in &mine {
                    for (k, v) in &s.groups {
                        by.entry((k, v)).or_default().push(s.outcome());
                    }
                }
                for ((k, v), o) in by {
                    report.rows.push(row(m, truth, k, v, &o));
                }
            }
        }
        report
    }

    /// Markdown: the overall figures per method and truth convention, then the deciles
    /// holding boxes under the first convention.
    pub fn markdown(&self) -> String {
        let opt = |v: Option<f64>| v.map_or_else(|| "–".to_string(), |v| format!("{v:.3}"));
        let mut s = String::from(
            "Confidence (all frames; hit: IoU >= 0.5; AUC and deciles: docs/results.md § Confidence)\n\n\
             | method | truth | target frames | no-target frames | hit rate | false alarms | AUC | max decile gap | calibrated (gap <= 0.1) |\n\
             |---|---|---|---|---|---|---|---|---|\n",
        );
        for r in self.rows.iter().filter(|r| r.group == "all") {
            let calibrated = match r.calibration_gap {
                None => "–",
                Some(g) if g <= CALIBRATION_TOLERANCE => "yes",
                Some(_) => "no",
            };
            s.push_str(&format!(
                "| {} | {} | {} | {} | {:.3} | {} | {} | {} | {calibrated} |\n",
                r.method,
                r.truth,
                r.target_frames,
                r.empty_frames,
                r.hit_rate,
                if r.empty_frames == 0 {
                    "–".to_string()
                } else {
                    format!("{:.3}", r.false_alarm_rate)
                },
                opt(r.auc),
                opt(r.calibration_gap),
            ));
        }
        let Some(first) = self.deciles.first().map(|d| d.1) else {
            return s;
        };
        s.push_str(&format!(
            "\nCalibration per score decile (truth: {first}; deciles holding boxes)\n\n\
             | method | decile | boxes | mean score | hit rate | gap |\n|---|---|---|---|---|---|\n"
        ));
        for (m, truth, deciles) in &self.deciles {
            if *truth != first {
                continue;
            }
            for d in deciles.iter().filter(|d| d.boxes > 0) {
                s.push_str(&format!(
                    "| {m} | {:.1}-{:.1} | {} | {:.3} | {:.3} | {} |\n",
                    d.lower,
                    d.upper,
                    d.boxes,
                    d.mean_score,
                    d.hit_rate,
                    opt(d.gap())
                ));
            }
        }
        s
    }

    /// Writes the curves as CSV:
    /// `method,truth,threshold,hit_rate,false_alarm_rate,false_positive_rate` (the first
    /// point of each curve has threshold `inf`).
    ///
    /// # Errors
    /// [`EvalError`] naming the file that cannot be written.
    pub fn write_curve(&self, path: &Path) -> Result<(), EvalError> {
        let mut csv =
            String::from("method,truth,threshold,hit_rate,false_alarm_rate,false_positive_rate\n");
        for (m, truth, points) in &self.curves {
            for p in points {
                let t = if p.threshold.is_finite() {
                    format!("{:.6}", p.threshold)
                } else {
                    "inf".into()
                };
                csv.push_str(&format!(
                    "{m},{truth},{t},{:.6},{:.6},{:.6}\n",
                    p.hit_rate, p.false_alarm_rate, p.false_positive_rate
                ));
            }
        }
        write(path, &csv)
    }

    /// Writes `confidence.csv` (every row) and `calibration.csv` (every decile) into `out`.
    ///
    /// # Errors
    /// [`EvalError`] naming the file that cannot be written.
    pub fn write_tables(&self, out: &Path) -> Result<(), EvalError> {
        let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.4}"));
        let mut csv = String::from(
            "method,truth,group,value,target_frames,empty_frames,hit_rate,false_alarm_rate,auc,calibration_gap\n",
        );
        for r in &self.rows {
            csv.push_str(&format!(
                "{},{},{},{},{},{},{:.4},{:.4},{},{}\n",
                r.method,
                r.truth,
                r.group,
                r.value,
                r.target_frames,
                r.empty_frames,
                r.hit_rate,
                r.false_alarm_rate,
                opt(r.auc),
                opt(r.calibration_gap)
            ));
        }
        write(&out.join("confidence.csv"), &csv)?;
        let mut csv = String::from("method,truth,lower,upper,boxes,mean_score,hit_rate\n");
        for (m, truth, deciles) in &self.deciles {
            for d in deciles {
                csv.push_str(&format!(
                    "{m},{truth},{:.1},{:.1},{},{:.4},{:.4}\n",
                    d.lower, d.upper, d.boxes, d.mean_score, d.hit_rate
                ));
            }
        }
        write(&out.join("calibration.csv"), &csv)
    }
}

fn write(path: &Path, text: &str) -> Result<(), EvalError> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| EvalError(format!("{}: cannot write: {e}", dir.display())))?;
    }
    std::fs::write(path, text)
        .map_err(|e| EvalError(format!("{}: cannot write: {e}", path.display())))
}
