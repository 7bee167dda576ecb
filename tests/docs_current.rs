//! The numbers README.md and docs/ show are what the code prints now (issue 17 § 6):
//! the memory tables (`tirroi memory`), the procedural demo (`tirroi demo`, all but the
//! times), the README's results summary against the committed `docs/results.md` (and,
//! when the main job has run here, `docs/results.md` against its `paper-run/tables.md`),
//! the `--help` of every subcommand (the registry's methods, one `--repeat` range,
//! defaults, wrapped lines), and the README's note that `eval`/`tune` need the main
//! job's `paper-run/`. Cheap: it never runs the main job.
//!
//! When a table is stale, regenerate it with the command the failure names and paste
//! its output (the times of the demo are the release build's: `cargo run --release --
//! demo`).

mod cli_common;

use std::path::Path;

use cli_common::run;
use tirroi::core::Method;

fn read(rel: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn stdout(args: &[&str]) -> String {
    let o = run(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).unwrap()
}

/// The rows (cells, trimmed) of the Markdown table whose header line starts with
/// `header`.
fn table(text: &str, header: &str) -> Vec<Vec<String>> {
    let mut lines = text.lines().skip_while(|l| !l.starts_with(header));
    assert!(lines.next().is_some(), "no table starting {header:?}");
    lines
        .skip(1)
        .take_while(|l| l.starts_with('|'))
        .map(|l| {
            l.trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect()
}

/// A detector's name as the docs write it (Otsu, WGE, DoG) → the registry's.
fn method_name(cell: &str) -> String {
    cell.split_whitespace().next().unwrap_or("").to_lowercase()
}

/// "15 216 (16 KiB)" → "15216".
fn digits(cell: &str) -> String {
    cell.split('(')
        .next()
        .unwrap()
        .chars()
        .filter(char::is_ascii_digit)
        .collect()
}

#[test]
fn memory_tables_are_what_tirroi_memory_prints() {
    let out = stdout(&["memory"]);
    let docs = read("docs/detectors.md");
    let cmd = "regenerate from `tirroi memory`";
    // Every capacity: docs/detectors.md's table against the command's second table.
    let printed = table(&out, "| detector | 328x248");
    let written = table(&docs, "| detector | 328×248");
    assert_eq!(printed.len(), Method::ALL.len(), "{out}");
    assert_eq!(written.len(), printed.len(), "docs/detectors.md: {cmd}");
    for (w, p) in written.iter().zip(&printed) {
        assert_eq!(method_name(&w[0]), p[0], "docs/detectors.md: {cmd}");
        let w: Vec<String> = w[1..].iter().map(|c| digits(c)).collect();
        assert_eq!(w, p[1..].to_vec(), "docs/detectors.md, {}: {cmd}", p[0]);
    }
    // The 328×248 column of the detectors' overview.
    let printed = table(&out, "| detector | scratch bytes |");
    let written = table(&docs, "| detector | what it does | scratch bytes");
    assert_eq!(written.len(), printed.len(), "docs/detectors.md: {cmd}");
    for (w, p) in written.iter().zip(&printed) {
        assert_eq!(method_name(&w[0]), p[0], "docs/detectors.md: {cmd}");
        assert_eq!(digits(&w[2]), p[1], "docs/detectors.md, {}: {cmd}", p[0]);
    }
}

#[test]
fn demo_table_is_what_tirroi_demo_prints() {
    let out = stdout(&["demo", "--repeat", "1"]);
    let header = "| frame | method |";
    let printed = table(&out, header);
    let written = table(&read("docs/results.md"), header);
    // Every frame of the demo with every method of the registry.
    assert_eq!(printed.len() % Method::ALL.len(), 0);
    assert_eq!(
        written.len(),
        printed.len(),
        "docs/results.md § The procedural demo: regenerate from `cargo run --release -- demo`"
    );
    for (w, p) in written.iter().zip(&printed) {
        // All but the last cell, the time (machine-dependent).
        assert_eq!(
            w[..w.len() - 1],
            p[..p.len() - 1],
            "docs/results.md § The procedural demo: regenerate from `cargo run --release -- demo`"
        );
    }
    let methods: Vec<&str> = printed.iter().map(|r| r[1].as_str()).collect();
    for m in Method::ALL {
        assert!(
            methods.contains(&m.name()),
            "{} missing from the demo",
            m.name()
        );
    }
}

/// Decimal numbers with at least two decimals in `text` ("0.773–0.877" → both).
fn decimals(text: &str) -> Vec<String> {
    text.split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .map(|t| t.trim_matches('.'))
        .filter(|t| {
            t.split_once('.')
                .is_some_and(|(a, b)| !a.is_empty() && b.len() >= 2)
        })
        .map(str::to_string)
        .collect()
}

#[test]
fn readme_results_are_the_committed_results() {
    let readme = read("README.md");
    let results = read("docs/results.md");
    let section: String = readme
        .lines()
        .skip_while(|l| *l != "## Results")
        .skip(1)
        .take_while(|l| !l.starts_with("## "))
        .collect::<Vec<_>>()
        .join("\n");
    // The two worlds' bullets: their IoU figures are the main job's, in docs/results.md.
    let worlds: String = section
        .split("\n- ")
        .filter(|b| {
            b.starts_with("**The paper's world**") || b.starts_with("**The realistic world**")
        })
        .collect::<Vec<_>>()
        .join("\n");
    let known = decimals(&results);
    let numbers = decimals(&worlds);
    assert!(
        numbers.len() >= 10,
        "README § Results lost its figures: {worlds}"
    );
    // A figure with d decimals is a docs/results.md figure rounded to d decimals.
    let rounds_to = |v: &str, n: &str| {
        let d = n.split_once('.').map_or(0, |(_, b)| b.len());
        v.split_once('.').is_some_and(|(_, b)| b.len() >= d)
            && v.parse::<f64>().is_ok_and(|x| format!("{x:.d$}") == n)
    };
    for n in &numbers {
        assert!(
            known.iter().any(|v| rounds_to(v, n)),
            "README § Results quotes {n}, which docs/results.md does not hold: update the summary from docs/results.md"
        );
    }
    // After the main job ran here: docs/results.md holds its tables verbatim.
    let run = Path::new(env!("CARGO_MANIFEST_DIR")).join("paper-run/tables.md");
    if let Ok(tables) = std::fs::read_to_string(&run) {
        let stale: Vec<&str> = tables
            .lines()
            .filter(|l| l.starts_with('|') && !results.contains(l))
            .collect();
        assert!(
            stale.is_empty(),
            "docs/results.md lacks {} rows of {} (the main job's output): paste its tables, e.g. {:?}",
            stale.len(),
            run.display(),
            stale.first()
        );
    }
}

#[test]
fn eval_and_tune_examples_say_they_need_the_main_job() {
    let readme = read("README.md");
    for sub in ["tirroi eval --images paper", "tirroi tune --images paper"] {
        let line = readme
            .lines()
            .find(|l| l.contains(sub))
            .unwrap_or_else(|| panic!("README has no `{sub}` example"));
        assert!(
            line.contains("paper-run/"),
            "README's `{sub}` example must say it needs the main job's paper-run/: {line}"
        );
    }
}

#[test]
fn every_help_lists_the_registry_defaults_ranges_and_wraps() {
    let subcommands = [
        "detect",
        "memory",
        "fixtures",
        "demo",
        "sensor",
        "sensor-fit",
        "eval",
        "paper",
        "render",
        "merge",
        "tune",
        "earth-texture",
    ];
    let mut repeat_lines = Vec::new();
    for sub in subcommands {
        let help = stdout(&[sub, "--help"]);
        // Wrapped: clap's default width is 100 columns without a terminal.
        for l in help.lines() {
            assert!(
                l.chars().count() <= 100,
                "`{sub} --help` has a long line: {l}"
            );
        }
        if help.contains("--method") {
            let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
            assert!(
                help.contains(&names.join(", ")),
                "`{sub} --help` does not list {names:?}"
            );
        }
        if let Some(i) = help.find("--repeat <REPEAT>") {
            let text: String = help[i..].split("\n\n").next().unwrap().to_string();
            assert!(text.contains("[default: "), "`{sub} --help`: {text}");
            repeat_lines.push((
                sub,
                text.split_whitespace()
                    .skip(2)
                    .take(6)
                    .collect::<Vec<_>>()
                    .join(" "),
            ));
        }
    }
    // One --repeat range everywhere, shown, and enforced.
    assert!(repeat_lines.len() >= 4, "{repeat_lines:?}");
    for (sub, text) in &repeat_lines {
        assert_eq!(text, &repeat_lines[0].1, "`{sub} --repeat` differs");
        assert!(text.contains("1..=1000"), "{sub}: {text}");
        for bad in ["0", "1001"] {
            let o = run(&[sub, "--repeat", bad]);
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{sub} --repeat {bad}: {err}");
            assert!(
                err.contains("is not in 1..=1000"),
                "{sub} --repeat {bad}: {err}"
            );
        }
    }
    // detect explains the columns it prints.
    let detect = stdout(&["detect", "--help"]);
    for word in ["threshold:", "foreground:", "score"] {
        assert!(
            detect.contains(word),
            "`detect --help` does not explain {word}"
        );
    }
}
