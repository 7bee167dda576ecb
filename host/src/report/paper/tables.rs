//! Tables 6–8 beside the paper's, and the table of `auto` (Markdown).

use tirroi_core::Method;

use crate::eval::scoring::{self, FrameScore};

use super::{PaperRow, PaperScores, TABLE6, TABLE7, TABLE8};

pub(super) fn group_of<'a>(s: &'a FrameScore, key: &str) -> Option<&'a str> {
    s.groups
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
}

/// Our numbers for (method, group) over `scores` filtered to a range band.
fn ours(
    scores: &[FrameScore],
    method: &str,
    key: &str,
    value: &str,
    band: &str,
) -> scoring::GroupStats {
    let sel: Vec<&FrameScore> = scores
        .iter()
        .filter(|s| s.method == method)
        .filter(|s| key.is_empty() || group_of(s, key) == Some(value))
        .filter(|s| group_of(s, "range") == Some(band))
        .collect();
    scoring::stats(method, key, value, &sel)
}

/// One table beside the paper's: method, group, ours (mean, median IoU, hit rate, mean
/// time) and the paper's (mean, median IoU, mean time).
pub fn table(
    title: &str,
    scores: &[FrameScore],
    paper: &[PaperRow],
    key: &str,
    band: &str,
) -> String {
    let mut s = format!(
        "{title}\n\n| method | {} | frames | mean IoU | median IoU | IoU ≥ 0.5 | mean time [ms] | paper mean IoU | paper median IoU | paper time [ms] |\n|---|---|---|---|---|---|---|---|---|---|\n",
        if key.is_empty() { "target" } else { key }
    );
    for &(method, value, p_mean, p_median, p_time) in paper {
        let o = ours(scores, method, key, value, band);
        s.push_str(&format!(
            "| {method} | {value} | {} | {:.3} | {:.3} | {:.2} | {:.3} | {p_mean:.3} | {p_median:.3} | {p_time:.3} |\n",
            o.frames, o.mean_iou, o.median_iou, o.hit_rate, o.mean_time_ms
        ));
    }
    // Ours beyond the paper (`auto`, `auto-v2`): one row per group of the paper's rows.
    let mut values: Vec<&str> = Vec::new();
    for &(_, value, ..) in paper {
        if !values.contains(&value) {
            values.push(value);
        }
    }
    for m in Method::ALL.iter().filter(|m| !Method::PAPER.contains(m)) {
        let method = m.name();
        for &value in &values {
            let o = ours(scores, method, key, value, band);
            s.push_str(&format!(
                "| {method} | {value} | {} | {:.3} | {:.3} | {:.2} | {:.3} | – | – | – |\n",
                o.frames, o.mean_iou, o.median_iou, o.hit_rate, o.mean_time_ms
            ));
        }
    }
    s
}

/// The far-range summary: mean IoU per method and group (the paper reports none).
pub fn far_table(
    title: &str,
    scores: &[FrameScore],
    key: &str,
    values: &[&str],
    band: &str,
) -> String {
    let mut s = format!("{title}\n\n| method |");
    for v in values {
        s.push_str(&format!(" {key} {v} |"));
    }
    s.push_str(" mean time [ms] |\n|---|");
    s.push_str(&"---|".repeat(values.len() + 1));
    s.push('\n');
    for m in Method::ALL {
        s.push_str(&format!("| {} |", m.name()));
        let mut t = 0.0;
        for v in values {
            let o = ours(scores, m.name(), key, v, band);
            s.push_str(&format!(" {:.3} ({}) |", o.mean_iou, o.frames));
            t += o.mean_time_ms / values.len() as f64;
        }
        s.push_str(&format!(" {t:.3} |\n"));
    }
    s
}

/// `auto` against the best of the paper's four on every row of Tables 6–8 and of the
/// far-range summaries: mean IoU and median core time per frame (ms) of auto, of the
/// method with the highest mean IoU among the four, and of adaptive (the speed goal).
pub fn auto_table(scores: &PaperScores) -> String {
    let mut s = String::from(
        "`auto` against the best of the paper's four per row (test split; times: median core time per frame)\n\n| table | row | frames | auto mean IoU | best of four | its mean IoU | auto median time [ms] | its median time [ms] | adaptive median time [ms] |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    // (table, its scores, group column, group values, range band)
    type Row<'a> = (&'a str, &'a [FrameScore], &'a str, &'a [&'a str], &'a str);
    let rows: [Row<'_>; 5] = [
        (
            "6",
            &scores.radiometry,
            "material",
            &["mono", "multi-1", "multi-2"],
            "close",
        ),
        ("7", &scores.detection, "scale", &["1", "2", "3"], "close"),
        ("8", &scores.tango, "", &["tango"], "close"),
        (
            "far radiometry",
            &scores.radiometry,
            "material",
            &["mono", "multi-1", "multi-2"],
            "far",
        ),
        (
            "far detection",
            &scores.detection,
            "scale",
            &["1", "2", "3"],
            "far",
        ),
    ];
    for (table, scores, key, values, band) in rows {
        for &value in values {
            let a = ours(scores, Method::Auto.name(), key, value, band);
            let best = Method::PAPER
                .iter()
                .map(|m| ours(scores, m.name(), key, value, band))
                .max_by(|x, y| x.mean_iou.total_cmp(&y.mean_iou));
            let Some(best) = best else { continue };
            let adaptive = ours(scores, Method::Adaptive.name(), key, value, band);
            s.push_str(&format!(
                "| {table} | {value} | {} | {:.3} | {} | {:.3} | {:.3} | {:.3} | {:.3} |\n",
                a.frames,
                a.mean_iou,
                best.method,
                best.mean_iou,
                a.median_time_ms,
                best.median_time_ms,
                adaptive.median_time_ms
            ));
        }
    }
    s
}

/// Tables 6–8 (close range) of `scores` beside the paper's; `world` is added to the
/// titles (empty: the paper's world).
fn close_tables(scores: &PaperScores, world: &str) -> String {
    let mut s = String::new();
    s.push_str(&table(
        &format!("**Table 6{world}** (radiometry, close range 15–50 m, test split, frames with a target; ours, then the paper's)"),
        &scores.radiometry,
        &TABLE6,
        "material",
        "close",
    ));
    s.push('\n');
    s.push_str(&table(
        &format!(
            "**Table 7{world}** (detection, close range 15–50 m, test split, by Table 5 scale)"
        ),
        &scores.detection,
        &TABLE7,
        "scale",
        "close",
    ));
    s.push('\n');
    s.push_str(&table(
        &format!("**Table 8{world}** (Tango, radiometry, 15–50 m, test split)"),
        &scores.tango,
        &TABLE8,
        "",
        "close",
    ));
    s.push('\n');
    s
}

/// The three tables (close range) and the far-range summaries, Markdown.
pub fn report(scores: &PaperScores) -> String {
    let mut s = close_tables(scores, "");
    s.push_str(&far_table(
        "Far range 340–440 m, radiometry, test split: mean IoU (frames)",
        &scores.radiometry,
        "material",
        &["mono", "multi-1", "multi-2"],
        "far",
    ));
    s.push('\n');
    s.push_str(&far_table(
        "Far range 340–440 m, detection, test split: mean IoU (frames)",
        &scores.detection,
        "scale",
        &["1", "2", "3"],
        "far",
    ));
    s.push('\n');
    s.push_str(&auto_table(scores));
    s
}

/// Share of the frames without a target on which each method returned a box, per kind
/// (radiometry, detection, Tango) and range band, with the no-target frame counts.
pub fn false_alarm_table(title: &str, scores: &PaperScores) -> String {
    let kinds: [(&str, &[FrameScore]); 3] = [
        ("radiometry", &scores.radiometry),
        ("detection", &scores.detection),
        ("tango", &scores.tango),
    ];
    let bands = ["close", "mid", "far"];
    let mut cols: Vec<(&str, &[FrameScore], &str)> = Vec::new();
    for (kind, sc) in kinds {
        for band in bands {
            let any = sc
                .iter()
                .any(|f| !f.has_target() && group_of(f, "range") == Some(band));
            if any {
                cols.push((kind, sc, band));
            }
        }
    }
    let mut s = format!("{title}\n\n| method |");
    for (kind, _, band) in &cols {
        s.push_str(&format!(" {kind} {band} |"));
    }
    s.push_str("\n|---|");
    s.push_str(&"---|".repeat(cols.len()));
    s.push('\n');
    for m in Method::ALL {
        s.push_str(&format!("| {} |", m.name()));
        for (_, sc, band) in &cols {
            let sel: Vec<&FrameScore> = sc
                .iter()
                .filter(|f| f.method == m.name() && !f.has_target())
                .filter(|f| group_of(f, "range") == Some(band))
                .collect();
            let alarms = sel.iter().filter(|f| f.false_alarm()).count();
            s.push_str(&format!(
                " {:.3} ({}) |",
                alarms as f64 / sel.len().max(1) as f64,
                sel.len()
            ));
        }
        s.push('\n');
    }
    s
}

/// The realistic world's Tables 6–8 (close range) beside the paper's numbers, the
/// mid (130–300 m) and far (300–525 m) summaries, the false alarms on frames without a
/// target, and `auto` against the four.
pub fn realistic_report(scores: &PaperScores) -> String {
    let mut s = close_tables(scores, ", realistic world");
    for (band, span) in [("mid", "130–300 m"), ("far", "300–525 m")] {
        s.push_str(&far_table(
            &format!(
                "Realistic world, {band} range {span}, radiometry, test split: mean IoU (frames)"
            ),
            &scores.radiometry,
            "material",
            &["mono", "multi-1", "multi-2"],
            band,
        ));
        s.push('\n');
        s.push_str(&far_table(
            &format!(
                "Realistic world, {band} range {span}, detection, test split: mean IoU (frames)"
            ),
            &scores.detection,
            "scale",
            &["1", "2", "3"],
            band,
        ));
    }
    s.push('\n');
    s.push_str(&false_alarm_table(
        "Realistic world, frames without a target: false-alarm rate (frames)",
        scores,
    ));
    s.push('\n');
    s.push_str(&auto_table(scores));
    s
}
