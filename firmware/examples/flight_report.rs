//! Checks and tabulates a run of scripts/flight.sh (host side, std):
//!
//! ```text
//! flight_report DIR TARGET...
//! ```
//!
//! DIR holds `host-detect.jsonl` (`tirroi detect --method all --json` on the embedded
//! frames), `host-demo.log` (examples/host.rs), and per target `TARGET.log` (the
//! firmware's semihosting output under QEMU), `TARGET.rc` (QEMU's exit status) and
//! `TARGET.size` (`arm-none-eabi-size -A`); optionally `callgrind.txt` (`frame method
//! instructions` per line, x86-64).
//!
//! Fails (exit 1) when a firmware run failed, a box or foreground count differs from
//! the host's, an on-board sensor frame differs from the host's, or the firmware does
//! not fit the flash and RAM of `memory.x`. Writes `DIR/report.md` with the tables the
//! flight page (`docs/flight.md`) shows, and prints it.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use tirroi_core::frame::FRAME_PIXELS;

/// Pixels per frame (the core's frame size).
const PIXELS: f64 = FRAME_PIXELS as f64;
/// Clock of the rad-tolerant Cortex-M7 the time estimate is for, Hz.
const CLOCK_HZ: f64 = 100e6;

/// One line of a log: its kind and its `key=value` fields.
struct Line {
    kind: String,
    fields: BTreeMap<String, String>,
}

fn parse_log(text: &str) -> Vec<Line> {
    text.lines()
        .filter_map(|line| {
            let mut words = line.split_whitespace();
            let kind = words.next()?.to_string();
            let fields = words
                .filter_map(|w| w.split_once('='))
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect();
            Some(Line { kind, fields })
        })
        .collect()
}

fn read(path: &Path) -> Result<String, String> {
    fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))
}

fn field<'a>(line: &'a Line, key: &str) -> &'a str {
    line.fields.get(key).map_or("-", String::as_str)
}

fn num(line: &Line, key: &str) -> Option<u64> {
    line.fields.get(key)?.parse().ok()
}

/// A run's detections: (frame, method) → "box fg".
fn detections(lines: &[Line]) -> BTreeMap<(String, String), String> {
    lines
        .iter()
        .filter(|l| l.kind == "detect")
        .map(|l| {
            (
                (
                    field(l, "frame").to_string(),
                    field(l, "method").to_string(),
                ),
                format!("box={} fg={}", field(l, "box"), field(l, "fg")),
            )
        })
        .collect()
}

/// `LENGTH = 2048K` of the region `name` in memory.x, bytes.
fn memory_length(memory_x: &str, name: &str) -> Option<u64> {
    let line = memory_x
        .lines()
        .find(|l| l.trim_start().starts_with(name) && l.contains("LENGTH"))?;
    let value = line
        .split("LENGTH")
        .nth(1)?
        .trim_start_matches([' ', '='])
        .trim();
    let (digits, unit) = value.split_at(value.find(|c: char| !c.is_ascii_digit())?);
    let n: u64 = digits.parse().ok()?;
    Some(match unit.chars().next()? {
        'K' => n * 1024,
        'M' => n * 1024 * 1024,
        _ => n,
    })
}

/// Section sizes of `arm-none-eabi-size -A`.
fn sections(text: &str) -> BTreeMap<String, u64> {
    text.lines()
        .filter_map(|l| {
            let mut w = l.split_whitespace();
            let name = w.next()?;
            let size = w.next()?.parse().ok()?;
            name.starts_with('.').then(|| (name.to_string(), size))
        })
        .collect()
}

fn mega(n: u64) -> String {
    format!("{:.2} M", n as f64 / 1e6)
}

struct Target {
    name: String,
    lines: Vec<Line>,
    sizes: BTreeMap<String, u64>,
}

impl Target {
    fn detect(&self, frame: &str, method: &str) -> Option<&Line> {
        self.lines.iter().find(|l| {
            l.kind == "detect" && field(l, "frame") == frame && field(l, "method") == method
        })
    }

    fn sensor(&self) -> Option<&Line> {
        self.lines.iter().find(|l| l.kind == "sensor")
    }

    fn line(&self, kind: &str) -> Option<&Line> {
        self.lines.iter().find(|l| l.kind == kind)
    }
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some((dir, targets)) = args.split_first() else {
        eprintln!("usage: flight_report DIR TARGET...");
        return ExitCode::from(2);
    };
    match run(Path::new(dir), targets) {
        Ok(failures) if failures.is_empty() => {
            println!("flight: all checks passed");
            ExitCode::SUCCESS
        }
        Ok(failures) => {
            for f in &failures {
                eprintln!("flight: FAILED: {f}");
            }
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("flight: error: {e}");
            ExitCode::from(2)
        }
    }
}

fn run(dir: &Path, target_names: &[String]) -> Result<Vec<String>, String> {
    let mut failures = Vec::new();
    let memory_x_path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../memory.x");
    let memory_x = read(&memory_x_path)?;
    let flash_budget = memory_length(&memory_x, "FLASH")
        .ok_or_else(|| format!("{}: no FLASH LENGTH", memory_x_path.display()))?;
    let ram_budget = memory_length(&memory_x, "RAM")
        .ok_or_else(|| format!("{}: no RAM LENGTH", memory_x_path.display()))?;

    let host = parse_log(&read(&dir.join("host-demo.log"))?);
    let host_detections = detections(&host);
    let host_checksum = host
        .iter()
        .find(|l| l.kind == "sensor")
        .map(|l| field(l, "checksum").to_string())
        .ok_or("host-demo.log has no sensor line")?;
    let frames: Vec<String> = host
        .iter()
        .filter(|l| l.kind == "link")
        .map(|l| field(l, "frame").to_string())
        .collect();
    let methods: Vec<String> = host
        .iter()
        .filter(|l| l.kind == "memory")
        .map(|l| field(l, "method").to_string())
        .collect();
    // The columns of the instruction tables: every method, then the trackers tracking.
    let mut columns = methods.clone();
    for tracking in ["auto+prior", "auto-v2+prior", "auto-v2+sequence"] {
        if host.iter().any(|l| field(l, "method") == tracking) {
            columns.push(tracking.to_string());
        }
    }

    // The host CLI's boxes for the embedded frames.
    let mut cli = BTreeMap::new();
    for (n, line) in read(&dir.join("host-detect.jsonl"))?.lines().enumerate() {
        let v: serde_json::Value =
            serde_json::from_str(line).map_err(|e| format!("host-detect.jsonl:{}: {e}", n + 1))?;
        let file = v["file"].as_str().unwrap_or_default();
        let stem = Path::new(file)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or_default()
            .to_string();
        let method = v["method"].as_str().unwrap_or_default().to_string();
        let bbox = match v["bbox"].as_array() {
            Some(b) => b
                .iter()
                .map(|x| x.as_u64().map_or("?".to_string(), |x| x.to_string()))
                .collect::<Vec<_>>()
                .join(","),
            None => "none".to_string(),
        };
        cli.insert((stem, method), bbox);
    }
    for frame in &frames {
        for method in &methods {
            let ours = host_detections
                .get(&(frame.clone(), method.clone()))
                .map(|s| {
                    s.split_whitespace()
                        .next()
                        .unwrap_or("")
                        .trim_start_matches("box=")
                        .to_string()
                });
            match (cli.get(&(frame.clone(), method.clone())), ours) {
                (Some(c), Some(o)) if *c == o => {}
                (c, o) => failures.push(format!(
                    "{frame}/{method}: `tirroi detect` box {c:?}, firmware workload on the host {o:?}"
                )),
            }
        }
    }

    let mut targets = Vec::new();
    for name in target_names {
        let rc = read(&dir.join(format!("{name}.rc")))?.trim().to_string();
        let lines = parse_log(&read(&dir.join(format!("{name}.log")))?);
        let sizes = sections(&read(&dir.join(format!("{name}.size")))?);
        if rc != "0" {
            failures.push(format!(
                "{name}: QEMU exited with status {rc} (see {name}.log)"
            ));
        }
        if !lines.iter().any(|l| l.kind == "done") {
            failures.push(format!("{name}: the demo did not finish (no `done` line)"));
        }
        for l in lines.iter().filter(|l| l.kind == "error") {
            failures.push(format!(
                "{name}: error on frame {}: {}",
                field(l, "frame"),
                field(l, "what")
            ));
        }
        let theirs = detections(&lines);
        if theirs.len() != host_detections.len() {
            failures.push(format!(
                "{name}: {} detections, the host {}",
                theirs.len(),
                host_detections.len()
            ));
        }
        for (key, want) in &host_detections {
            match theirs.get(key) {
                Some(got) if got == want => {}
                got => failures.push(format!(
                    "{name}: {}/{}: firmware {got:?}, host {want:?}",
                    key.0, key.1
                )),
            }
        }
        let target = Target {
            name: name.clone(),
            lines,
            sizes,
        };
        match target.sensor() {
            Some(s) if field(s, "checksum") == host_checksum => {}
            s => failures.push(format!(
                "{name}: on-board sensor frame checksum {:?}, host {host_checksum}",
                s.map(|s| field(s, "checksum"))
            )),
        }
        targets.push(target);
    }

    let mut md = String::new();
    memory_tables(
        &mut md,
        &targets,
        &methods,
        flash_budget,
        ram_budget,
        &mut failures,
    );
    instruction_tables(&mut md, &targets, &frames, &columns, dir)?;
    fpu_table(&mut md, &targets, &columns);
    let _ = writeln!(
        md,
        "\nBoxes: every detector's box and foreground count on every frame, on every \
         target, equal the host's ({} comparisons per target; the embedded frames also \
         against `tirroi detect`); the on-board sensor frame is the same on every target \
         and on the host (FNV-1a {host_checksum}).",
        host_detections.len()
    );
    if !failures.is_empty() {
        let _ = writeln!(
            md,
            "\n**{} check(s) FAILED**: see the script's output.",
            failures.len()
        );
    }
    let path = dir.join("report.md");
    fs::write(&path, &md).map_err(|e| format!("{}: {e}", path.display()))?;
    println!("{md}");
    Ok(failures)
}

fn memory_tables(
    md: &mut String,
    targets: &[Target],
    methods: &[String],
    flash_budget: u64,
    ram_budget: u64,
    failures: &mut Vec<String>,
) {
    let _ = writeln!(
        md,
        "**Firmware memory** (ELF sections; budget from memory.x: flash {} KiB, RAM {} KiB)\n",
        flash_budget / 1024,
        ram_budget / 1024
    );
    let _ = writeln!(
        md,
        "| target | .text | .rodata (frames) | .data | flash total | .bss | static RAM | stack peak | RAM total | RAM use |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|");
    for t in targets {
        let s = |k: &str| t.sizes.get(k).copied().unwrap_or(0);
        let flash = s(".vector_table") + s(".text") + s(".rodata") + s(".data") + s(".ARM.exidx");
        let statics = s(".data") + s(".bss") + s(".uninit");
        let stack = t.line("ram").and_then(|l| num(l, "stack_peak"));
        let ram = statics + stack.unwrap_or(0);
        let _ = writeln!(
            md,
            "| `{}` | {} | {} | {} | {} ({:.0} %) | {} | {} | {} | {} | {:.0} % |",
            t.name,
            s(".text"),
            s(".rodata"),
            s(".data"),
            flash,
            100.0 * flash as f64 / flash_budget as f64,
            s(".bss"),
            statics,
            stack.map_or("-".into(), |v| v.to_string()),
            ram,
            100.0 * ram as f64 / ram_budget as f64
        );
        if flash > flash_budget {
            failures.push(format!("{}: flash {flash} B > {flash_budget} B", t.name));
        }
        if stack.is_none() {
            failures.push(format!("{}: no stack peak reported", t.name));
        }
        if ram > ram_budget {
            failures.push(format!(
                "{}: static RAM {statics} B + stack peak {} B > {ram_budget} B",
                t.name,
                stack.unwrap_or(0)
            ));
        }
    }

    let _ = writeln!(
        md,
        "\n**Per detector** (scratch = `size_of` its `Scratch` on the target; stack = deepest \
         stack of the call over all frames, measured by painting)\n"
    );
    let mut header = String::from("| detector |");
    let mut rule = String::from("|---|");
    for t in targets {
        let _ = write!(header, " scratch `{0}` | stack `{0}` |", t.name);
        rule.push_str("---|---|");
    }
    let _ = writeln!(md, "{header}\n{rule}");
    for m in methods {
        let mut row = format!("| {m} |");
        for t in targets {
            let scratch = t
                .lines
                .iter()
                .find(|l| l.kind == "memory" && field(l, "method") == m)
                .and_then(|l| num(l, "scratch"));
            let stack = t
                .lines
                .iter()
                .filter(|l| l.kind == "detect" && field(l, "method") == m)
                .filter_map(|l| num(l, "stack"))
                .max();
            let _ = write!(
                row,
                " {} | {} |",
                scratch.map_or("-".into(), |v| v.to_string()),
                stack.map_or("-".into(), |v| v.to_string())
            );
        }
        let _ = writeln!(md, "{row}");
    }
}

fn instruction_tables(
    md: &mut String,
    targets: &[Target],
    frames: &[String],
    methods: &[String],
    dir: &Path,
) -> Result<(), String> {
    let mut all_frames = frames.to_vec();
    all_frames.push("on-board-sensor".to_string());
    if let Some(t) = targets.first() {
        let _ = writeln!(
            md,
            "\n**Instructions per detector call on the emulated Cortex-M7** (`{}`, QEMU \
             `-icount`, SysTick; millions, and per pixel)\n",
            t.name
        );
        table(md, &all_frames, methods, |f, m| {
            t.detect(f, m).and_then(|l| num(l, "insns"))
        });
        let _ = writeln!(
            md,
            "\nEstimated time per frame on a 100 MHz rad-tolerant Cortex-M7, at one \
             instruction per cycle (the M7 dual-issues, wait states and cache misses cost \
             extra: take ±50 %), mean over the frames above:\n"
        );
        let _ = writeln!(
            md,
            "| detector | mean instructions | ms per frame at 100 MHz | frames/s |"
        );
        let _ = writeln!(md, "|---|---|---|---|");
        for m in methods {
            let v: Vec<u64> = all_frames
                .iter()
                .filter_map(|f| t.detect(f, m).and_then(|l| num(l, "insns")))
                .collect();
            if v.is_empty() {
                continue;
            }
            let mean = v.iter().sum::<u64>() as f64 / v.len() as f64;
            let ms = mean / CLOCK_HZ * 1e3;
            let _ = writeln!(
                md,
                "| {m} | {} | {ms:.0} | {:.1} |",
                mega(mean as u64),
                1e3 / ms
            );
        }
    }
    let cg_path = dir.join("callgrind.txt");
    if cg_path.exists() {
        let mut cg = BTreeMap::new();
        for line in read(&cg_path)?.lines() {
            let w: Vec<&str> = line.split_whitespace().collect();
            if let [f, m, n] = w.as_slice() {
                if let Ok(n) = n.parse::<u64>() {
                    cg.insert((f.to_string(), m.to_string()), n);
                }
            }
        }
        let _ = writeln!(
            md,
            "\n**The same calls on the host, x86-64** (`valgrind --tool=callgrind`, \
             `--toggle-collect` on the detector call; millions, and per pixel)\n"
        );
        table(md, &all_frames, methods, |f, m| {
            cg.get(&(f.to_string(), m.to_string())).copied()
        });
    }
    Ok(())
}

/// A frames × methods table of instruction counts.
fn table(
    md: &mut String,
    frames: &[String],
    methods: &[String],
    count: impl Fn(&str, &str) -> Option<u64>,
) {
    let mut header = String::from("| frame |");
    let mut rule = String::from("|---|");
    for m in methods {
        let _ = write!(header, " {m} |");
        rule.push_str("---|");
    }
    let _ = writeln!(md, "{header}\n{rule}");
    for f in frames {
        let mut row = format!("| {f} |");
        for m in methods {
            match count(f, m) {
                Some(n) => {
                    let _ = write!(row, " {} ({:.0}) |", mega(n), n as f64 / PIXELS);
                }
                None => row.push_str(" - |"),
            }
        }
        let _ = writeln!(md, "{row}");
    }
}

/// A figure read off a target's `sensor` line.
type PerSensorLine = fn(&Line) -> Option<f64>;

fn fpu_table(md: &mut String, targets: &[Target], methods: &[String]) {
    let _ = writeln!(
        md,
        "\n**With and without an FPU** (instructions per pixel on the emulated Cortex-M7, \
         which runs ARMv7-M and ARMv6-M code too; detectors: mean over all frames; the \
         camera model: the on-board sensor frame)\n"
    );
    let mut header = String::from("| work |");
    let mut rule = String::from("|---|");
    for t in targets {
        let _ = write!(header, " `{}` |", t.name);
        rule.push_str("---|");
    }
    let _ = writeln!(md, "{header}\n{rule}");
    for m in methods {
        let mut row = format!("| {m} |");
        for t in targets {
            let v: Vec<u64> = t
                .lines
                .iter()
                .filter(|l| l.kind == "detect" && field(l, "method") == m)
                .filter_map(|l| num(l, "insns"))
                .collect();
            if v.is_empty() {
                row.push_str(" - |");
            } else {
                let mean = v.iter().sum::<u64>() as f64 / v.len() as f64;
                let _ = write!(row, " {:.0} |", mean / PIXELS);
            }
        }
        let _ = writeln!(md, "{row}");
    }
    let rows: [(&str, PerSensorLine); 4] = [
        ("camera model: band radiance from the table", |l| {
            Some(num(l, "radiance_insns")? as f64 / PIXELS)
        }),
        ("camera model: DN map + noise (the pass alone)", |l| {
            Some(num(l, "dn_noise_insns")? as f64 / PIXELS)
        }),
        ("camera model: whole frame (radiance, DN, noise)", |l| {
            Some(num(l, "expose_insns")? as f64 / PIXELS)
        }),
        (
            "camera model: set-up (build-time tables: pointers only), total M",
            |l| Some(num(l, "setup_insns")? as f64 / 1e6),
        ),
    ];
    for (name, f) in rows {
        let mut row = format!("| {name} |");
        for t in targets {
            match t.sensor().and_then(f) {
                Some(v) => {
                    let _ = write!(row, " {v:.0} |");
                }
                None => row.push_str(" - |"),
            }
        }
        let _ = writeln!(md, "{row}");
    }
}
