//! Unit tests of the parameter search.

use std::path::Path;

use tirroi_core::roi::Params;
use tirroi_core::roi::dog::Dog;
use tirroi_core::{BoxRule, Method};

use super::*;
use crate::eval::scoring::TruthRow;
use crate::eval::split::{Where, filter, parse_where};

#[test]
fn grids_hold_the_defaults_and_are_valid() {
    for m in Method::ALL {
        let g = grid(m);
        for rule in [BoxRule::AllForeground, BoxRule::LargestComponent] {
            assert!(g.contains(&defaults(m, rule)), "{m} {rule:?}");
        }
        assert!(g.iter().all(|p| is_valid(p) && p.method() == m));
        let mut names: Vec<String> = g.iter().map(Params::to_string).collect();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), g.len(), "{m}: a set twice");
    }
    // The sizes the module documentation gives.
    let sizes = Method::ALL.map(|m| grid(m).len());
    assert_eq!(sizes, [2, 126, 144, 96, 20, 1]);
}

#[test]
fn sets_scored_together_need_distinct_methods_and_keep_their_own_rules() {
    let lc = BoxRule::LargestComponent;
    let af = BoxRule::AllForeground;
    let a = defaults(Method::Adaptive, lc);
    let none = Path::new("/nonexistent");
    assert!(evaluate_together(none, &[], &[a, a], None).is_err());
    assert_eq!(evaluate_together(none, &[], &[], None), Ok(Vec::new()));

    // The procedural fixture frames, on disk with their truth.
    let dir = std::env::temp_dir().join(format!("tirroi-tune-rules-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut rows = Vec::new();
    for (name, spec) in crate::imaging::fixture::standard_set() {
        let fx = crate::imaging::fixture::render(&spec);
        let file = format!("{name}.png");
        crate::imaging::image_io::write_png16(&dir.join(&file), &fx.frame).unwrap();
        rows.push(TruthRow {
            file,
            roi: fx.truth,
            groups: Vec::new(),
            range_m: None,
            bits: None,
            signal_to_clutter: None,
            sequence: None,
        });
    }
    // Sets of different rules scored together score as each alone.
    let sets = [a, defaults(Method::Wge, af)];
    let together = evaluate_together(&dir, &rows, &sets, None).unwrap();
    for (p, t) in sets.iter().zip(&together) {
        let alone = evaluate(&dir, &rows, p, None).unwrap();
        assert_eq!((&t.params, t.mean_iou), (&alone.params, alone.mean_iou));
    }
    // And the rule matters on these frames, so the check above has teeth.
    let wge_lc = evaluate(&dir, &rows, &defaults(Method::Wge, lc), None).unwrap();
    assert!((wge_lc.mean_iou - together[1].mean_iou).abs() > 0.05);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn neighbours_step_one_rung() {
    let p = defaults(Method::Adaptive, BoxRule::LargestComponent);
    let n: Vec<String> = neighbours(&p).iter().map(Params::to_string).collect();
    assert_eq!(
        n,
        [
            "block=41 offset_dn=64 box=all-foreground",
            "block=37 offset_dn=64 box=largest-component",
            "block=47 offset_dn=64 box=largest-component",
            "block=41 offset_dn=48 box=largest-component",
            "block=41 offset_dn=96 box=largest-component",
        ]
    );
    let top = Params::Dog(Dog {
        levels: 8,
        ..Dog::default()
    });
    assert!(neighbours(&top).iter().all(is_valid));
}

#[test]
fn where_parses_and_filters() {
    assert!(parse_where("mode").is_err());
    assert!(parse_where("colour=red").is_err());
    assert!(parse_where("range=near").is_err());
    assert!(parse_where("mode=").is_err());
    let w = |s: &str| parse_where(s).unwrap();
    let row = |file: &str, g: &[(&str, &str)]| TruthRow {
        file: file.into(),
        roi: tirroi_core::Roi::new(0, 0, 1, 1),
        groups: g
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect(),
        range_m: None,
        bits: None,
        signal_to_clutter: None,
        sequence: None,
    };
    let rows = [
        row("a", &[("mode", "radiometry"), ("range", "close")]),
        row("b", &[("mode", "radiometry"), ("range", "far")]),
        row("c", &[("mode", "detection"), ("range", "close")]),
        row("d", &[]),
    ];
    let files =
        |ws: &[Where]| -> Vec<String> { filter(&rows, ws).into_iter().map(|r| r.file).collect() };
    assert_eq!(files(&[]), ["a", "b", "c", "d"]);
    assert_eq!(files(&[w("mode=radiometry"), w("range=close")]), ["a"]);
    assert_eq!(files(&[w("range=close"), w("range=far")]), ["a", "b", "c"]);
    assert!(files(&[w("material=mono")]).is_empty());
}
