//! The search: scoring parameter sets on frames ([`evaluate`]), the grid pass and the
//! coordinate refinement per method ([`search_method`], [`search`]), and `trials.csv`.

use std::collections::HashMap;
use std::path::Path;

use tirroi_core::{BoxRule, Method};

use tirroi_core::roi::Params;

use super::space::{grid, neighbours};
use crate::eval::bank::DetectorBank;
use crate::eval::scoring::{self, EvalError, EvalOptions, FrameScore, TruthRow};

/// One parameter set of one method scored on a set of frames.
#[derive(Debug, Clone, PartialEq)]
pub struct Trial {
    /// Method name.
    pub method: &'static str,
    /// The parameters, as `Params`' `Display` (`name=value` pairs).
    pub params: String,
    /// Mean IoU over the frames with a target (`eval::scoring`'s definition).
    pub mean_iou: f64,
    /// Median IoU over the frames with a target.
    pub median_iou: f64,
    /// Share of the frames without a target where a box came back (0 without such frames).
    pub false_alarm_rate: f64,
    /// Mean core time per frame, ms (one run per frame, frames in parallel).
    pub mean_time_ms: f64,
}

impl Trial {
    /// Whether `self` scores better than `other`: a higher mean IoU (over the frames
    /// with a target: frames without one cannot raise it), or a mean IoU within 10⁻⁹
    /// and a lower false-alarm rate, or both equal and a mean time at least 25 % lower.
    /// (One-run times of frames scored in parallel, beside PNG decoding and whatever
    /// else the machine runs, scatter by 10–20 %: without the margin, equal detections
    /// would be ranked by timing noise and the search would not repeat itself.) The
    /// objective stays the paper's mean IoU; false alarms only break ties, so a dataset
    /// without target-less frames tunes exactly as before.
    pub fn beats(&self, other: &Trial) -> bool {
        const EPS: f64 = 1e-9;
        let same_iou = (self.mean_iou - other.mean_iou).abs() <= EPS;
        let same_alarms = (self.false_alarm_rate - other.false_alarm_rate).abs() <= EPS;
        self.mean_iou > other.mean_iou + EPS
            || (same_iou && self.false_alarm_rate < other.false_alarm_rate - EPS)
            || (same_iou && same_alarms && self.mean_time_ms < 0.75 * other.mean_time_ms)
    }
}

/// How to search.
#[derive(Debug, Clone)]
pub struct SearchOptions {
    /// Bit depth of the frames (None: from the file, as `tirroi eval`).
    pub bits: Option<u8>,
    /// Most refinement moves after the grid (0: the grid alone). Default 12.
    pub refine_steps: usize,
    /// Grid sets refined per method (the best by mean IoU). Default 3.
    pub starts: usize,
}

impl Default for SearchOptions {
    fn default() -> Self {
        SearchOptions {
            bits: None,
            refine_steps: 12,
            starts: 3,
        }
    }
}

/// The best parameter set of one method and its trial.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodBest {
    /// The parameters.
    pub params: Params,
    /// Their scores on the frames searched.
    pub trial: Trial,
    /// Refinement moves made from the grid set this one was reached from (fewer than
    /// [`SearchOptions::refine_steps`]: the refinement stopped at a local optimum).
    pub moves: usize,
}

/// What [`search`] found.
pub struct TuneResult {
    /// Every candidate scored, grouped by method (in the order asked), each method's
    /// in the order scored.
    pub trials: Vec<Trial>,
    /// The best set of each method, in the order asked.
    pub best: Vec<MethodBest>,
    /// Default detectors with each searched method's best set in place.
    pub bank: DetectorBank,
}

/// Scores `params` on `rows` (frames in parallel, one run each).
///
/// # Errors
/// [`EvalError`] naming the frame for an unreadable file or a detector error.
pub fn evaluate(
    images: &Path,
    rows: &[TruthRow],
    params: &Params,
    bits: Option<u8>,
) -> Result<Trial, EvalError> {
    let mut trials = evaluate_together(images, rows, &[*params], bits)?;
    Ok(trials.remove(0))
}

/// Scores several parameter sets, of different methods and with one box rule, in one
/// pass over the frames (each frame is read once for all of them); one trial per set,
/// in order.
///
/// # Errors
/// [`EvalError`] when two sets are of one method or their box rules differ, and as
/// [`evaluate`].
pub fn evaluate_together(
    images: &Path,
    rows: &[TruthRow],
    sets: &[Params],
    bits: Option<u8>,
) -> Result<Vec<Trial>, EvalError> {
    if sets.is_empty() {
        return Ok(Vec::new());
    }
    let methods: Vec<Method> = sets.iter().map(Params::method).collect();
    for (k, p) in sets.iter().enumerate() {
        if methods[..k].contains(&p.method()) {
            return Err(EvalError(format!(
                "parameter sets scored together need distinct methods: {}",
                sets.iter()
                    .map(|p| format!("{} {}", p.method(), p))
                    .collect::<Vec<_>>()
                    .join("; ")
            )));
        }
    }
    // Each set brings its own box rule (`DetectorBank::set_params`).
    let options = EvalOptions {
        methods,
        repeat: 1,
        box_rule: None,
        bits,
        track: scoring::Track::Off,
        fits_offset_dn: None,
        crop: None,
    };
    let make_bank = || {
        let mut bank = DetectorBank::default();
        for p in sets {
            bank.set_params(*p);
        }
        bank
    };
    let scores = scoring::score(images, rows, &options, &make_bank, &|| {})?;
    Ok(sets
        .iter()
        .map(|p| {
            let name = p.method().name();
            let mine: Vec<&FrameScore> = scores.iter().filter(|s| s.method == name).collect();
            let s = scoring::stats(name, "all", "all", &mine);
            Trial {
                method: name,
                params: p.to_string(),
                mean_iou: s.mean_iou,
                median_iou: s.median_iou,
                false_alarm_rate: s.false_alarm_rate,
                mean_time_ms: s.mean_time_ms,
            }
        })
        .collect())
}

/// One method's search: its trials so far, each parameter set once.
struct MethodSearch {
    method: Method,
    trials: Vec<Trial>,
    seen: HashMap<String, usize>,
    grid: Vec<(Params, usize)>,
}

impl MethodSearch {
    fn record(&mut self, p: &Params, t: Trial, on_trial: &dyn Fn(&Trial)) -> usize {
        on_trial(&t);
        self.trials.push(t);
        let i = self.trials.len() - 1;
        self.seen.insert(p.to_string(), i);
        i
    }

    /// Index of the trial of `p`, scoring it first when new.
    fn score(
        &mut self,
        p: &Params,
        images: &Path,
        rows: &[TruthRow],
        options: &SearchOptions,
        on_trial: &dyn Fn(&Trial),
    ) -> Result<usize, EvalError> {
        if let Some(&i) = self.seen.get(&p.to_string()) {
            return Ok(i);
        }
        let t = evaluate(images, rows, p, options.bits)?;
        Ok(self.record(p, t, on_trial))
    }

    /// Steepest ascent from each of the best grid sets; the best end point.
    fn refine(
        &mut self,
        images: &Path,
        rows: &[TruthRow],
        options: &SearchOptions,
        on_trial: &dyn Fn(&Trial),
    ) -> Result<MethodBest, EvalError> {
        let mut ranked = self.grid.clone();
        // By mean IoU, grid order among equals.
        ranked.sort_by(|a, b| {
            self.trials[b.1]
                .mean_iou
                .total_cmp(&self.trials[a.1].mean_iou)
        });
        let mut best: Option<(Params, usize, usize)> = None;
        for &(start, start_at) in ranked.iter().take(options.starts.max(1)) {
            let (mut here, mut at, mut moves) = (start, start_at, 0);
            while moves < options.refine_steps {
                let mut next: Option<(Params, usize)> = None;
                for p in neighbours(&here) {
                    let i = self.score(&p, images, rows, options, on_trial)?;
                    let incumbent = next.map_or(at, |(_, n)| n);
                    if self.trials[i].beats(&self.trials[incumbent]) {
                        next = Some((p, i));
                    }
                }
                match next {
                    Some((p, i)) => {
                        (here, at) = (p, i);
                        moves += 1;
                    }
                    None => break,
                }
            }
            if best.is_none_or(|(_, b, _)| self.trials[at].beats(&self.trials[b])) {
                best = Some((here, at, moves));
            }
        }
        let Some((params, at, moves)) = best else {
            return Err(EvalError(format!("{}: empty candidate grid", self.method)));
        };
        Ok(MethodBest {
            params,
            trial: self.trials[at].clone(),
            moves,
        })
    }
}

/// Searches the parameters of `method` on `rows`: [`search`] with one method. Returns
/// every trial, in the order scored, and the best.
///
/// # Errors
/// As [`search`].
pub fn search_method(
    images: &Path,
    rows: &[TruthRow],
    method: Method,
    options: &SearchOptions,
    on_trial: &dyn Fn(&Trial),
) -> Result<(Vec<Trial>, MethodBest), EvalError> {
    let mut result = search(images, rows, &[method], options, on_trial)?;
    let best = result.best.remove(0);
    Ok((result.trials, best))
}

/// Searches the parameters of every method of `methods` on `rows` (see the module
/// documentation). The grids of all methods run side by side: each pass over the
/// frames scores one grid set of every method (with the same box rule), so a frame is
/// read once per pass, not once per set. Then each method is refined on its own.
/// `on_trial` sees each trial as it is scored (progress).
///
/// # Errors
/// [`EvalError`] for no rows, an unreadable frame or a detector error.
pub fn search(
    images: &Path,
    rows: &[TruthRow],
    methods: &[Method],
    options: &SearchOptions,
    on_trial: &dyn Fn(&Trial),
) -> Result<TuneResult, EvalError> {
    if rows.is_empty() {
        return Err(EvalError(format!(
            "{}: no frames to tune on",
            images.display()
        )));
    }
    let mut searches: Vec<MethodSearch> = Vec::new();
    for &method in methods {
        if !searches.iter().any(|s| s.method == method) {
            searches.push(MethodSearch {
                method,
                trials: Vec::new(),
                seen: HashMap::new(),
                grid: Vec::new(),
            });
        }
    }
    // Largest-component sets first, then all-foreground ones: the scoring order decides
    // ties (the first scored wins), and the tuned sets in `crate::eval::tuned` came from it.
    for rule in [BoxRule::LargestComponent, BoxRule::AllForeground] {
        let lists: Vec<Vec<Params>> = searches
            .iter()
            .map(|s| {
                grid(s.method)
                    .into_iter()
                    .filter(|p| p.box_rule() == rule)
                    .collect()
            })
            .collect();
        let passes = lists.iter().map(Vec::len).max().unwrap_or(0);
        for pass in 0..passes {
            let mut sets = Vec::new();
            let mut owners = Vec::new();
            for (k, list) in lists.iter().enumerate() {
                if let Some(p) = list.get(pass) {
                    if !searches[k].seen.contains_key(&p.to_string()) {
                        sets.push(*p);
                        owners.push(k);
                    }
                }
            }
            let trials = evaluate_together(images, rows, &sets, options.bits)?;
            for ((p, t), k) in sets.iter().zip(trials).zip(owners) {
                let i = searches[k].record(p, t, on_trial);
                searches[k].grid.push((*p, i));
            }
        }
    }
    let mut result = TuneResult {
        trials: Vec::new(),
        best: Vec::new(),
        bank: DetectorBank::default(),
    };
    for mut s in searches {
        let best = s.refine(images, rows, options, on_trial)?;
        result.bank.set_params(best.params);
        result.trials.append(&mut s.trials);
        result.best.push(best);
    }
    Ok(result)
}

/// `trials.csv`: `method,params,mean_iou,median_iou,mean_time_ms`, one row per trial.
pub fn trials_csv(trials: &[Trial]) -> String {
    let mut s = String::from("method,params,mean_iou,median_iou,mean_time_ms\n");
    for t in trials {
        s.push_str(&format!(
            "{},{},{:.4},{:.4},{:.4}\n",
            t.method, t.params, t.mean_iou, t.median_iou, t.mean_time_ms
        ));
    }
    s
}
