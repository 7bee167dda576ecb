//! `tirroi_host::report::plots`: every figure is a decodable PNG of its documented size, the same
//! input gives the same bytes, empty input is a "no data" error that writes nothing, and
//! `pareto_front` agrees with a brute-force check.

use std::path::Path;

use tirroi::core::Roi;
use tirroi::host::imaging::overlay::{METHOD_COLOURS, TRUTH_COLOUR};
use tirroi::host::report::plots::{
    self, ExampleFrame, GradientFrame, IouPoint, TradeoffPoint, example_grid,
    gradient_distribution, intensity_histogram, iou_against_distance, pareto_front,
    runtime_against_iou,
};

/// A small deterministic generator (PCG-style LCG), uniform in [0, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

const W: usize = 64;
const H: usize = 48;

/// A 64×48 frame: a textured "Earth" in the lower half, a warm box `roi`, noise.
fn frame(seed: u64, roi: Roi) -> Vec<u16> {
    let mut rng = Lcg(seed);
    let mut dn = vec![0u16; W * H];
    for y in 0..H {
        for x in 0..W {
            let earth = if y > 28 {
                4000.0 + 800.0 * ((x / 5 + y / 4) % 3) as f64
            } else {
                600.0
            };
            let v = if roi.contains(x as u16, y as u16) {
                9000.0
            } else {
                earth
            };
            dn[y * W + x] = (v + 40.0 * rng.next()) as u16;
        }
    }
    dn
}

fn decode(path: &Path) -> image::RgbImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8()
}

fn iou_points() -> Vec<IouPoint> {
    let mut rng = Lcg(3);
    let mut points = Vec::new();
    for group in ["mono", "multi 1", "multi 2"] {
        for method in ["dog", "otsu", "scene-aware", "adaptive", "wge"] {
            for _ in 0..12 {
                points.push(IouPoint {
                    method: method.into(),
                    group: group.into(),
                    range_m: 15.0 + 35.0 * rng.next(),
                    iou: rng.next(),
                });
            }
        }
    }
    points
}

fn tradeoff_points(n: usize, seed: u64, levels: f64) -> Vec<TradeoffPoint> {
    let mut rng = Lcg(seed);
    let methods = ["otsu", "adaptive", "wge", "dog", "scene-aware"];
    (0..n)
        .map(|i| TradeoffPoint {
            method: methods[i % methods.len()].into(),
            params: format!("p{i}"),
            // Quantised so ties in time and in IoU occur.
            mean_time_ms: (0.1 + 20.0 * rng.next() * levels).round() / levels,
            mean_iou: (rng.next() * levels).round() / levels,
        })
        .collect()
}

/// Draws every figure into `dir`; returns the five paths.
fn draw_all(dir: &Path) -> [std::path::PathBuf; 5] {
    let rois = [Roi::new(20, 8, 40, 24), Roi::new(5, 20, 25, 40)];
    let frames: Vec<Vec<u16>> = rois
        .iter()
        .enumerate()
        .map(|(i, r)| frame(i as u64, *r))
        .collect();
    let paths = [
        dir.join("iou.png"),
        dir.join("hist.png"),
        dir.join("grad.png"),
        dir.join("grid.png"),
        dir.join("tradeoff.png"),
    ];
    iou_against_distance(&iou_points(), "IoU against distance", &paths[0]).unwrap();
    intensity_histogram(
        &[("scale 3", &frames[0]), ("scale 1", &frames[1])],
        14,
        "Scale 3 intensity histogram",
        &paths[1],
    )
    .unwrap();
    let grad: Vec<GradientFrame> = frames
        .iter()
        .zip(rois)
        .map(|(f, truth)| GradientFrame {
            label: "(a)".into(),
            dn: f,
            width: W,
            height: H,
            truth,
        })
        .collect();
    gradient_distribution(&grad, &paths[2]).unwrap();
    let examples: Vec<ExampleFrame> = frames
        .iter()
        .zip(rois)
        .map(|(f, truth)| ExampleFrame {
            caption: "(a) multi-material, 23 m".into(),
            dn: f,
            width: W,
            height: H,
            truth,
            boxes: vec![
                ("otsu".into(), Some(Roi::new(0, 29, 64, 48))),
                (
                    "adaptive".into(),
                    Some(Roi::new(truth.x0 + 2, truth.y0, truth.x1, truth.y1)),
                ),
                ("dog".into(), None),
                ("scene-aware".into(), Some(truth)),
            ],
        })
        .collect();
    example_grid(&examples, &paths[3]).unwrap();
    runtime_against_iou(
        &tradeoff_points(40, 9, 100.0),
        "Run time against IoU",
        &paths[4],
    )
    .unwrap();
    paths
}

#[test]
fn every_figure_is_a_png_of_its_documented_size() {
    let dir = tempfile::tempdir().unwrap();
    let paths = draw_all(dir.path());
    // Three groups: three panels in a row.
    assert_eq!(plots::panel_figure_size(3), (960, 500));
    assert_eq!(decode(&paths[0]).dimensions(), (960, 500));
    assert_eq!(
        decode(&paths[1]).dimensions(),
        (plots::WIDTH, plots::HEIGHT)
    );
    assert_eq!(decode(&paths[2]).dimensions(), plots::panel_figure_size(2));
    assert_eq!(plots::panel_figure_size(2), (800, 500));
    assert_eq!(plots::panel_figure_size(4), (960, 936));
    // Grid: two 64×48 frames magnified 7× (448 ≤ max(900 / 2, 260)); columns with
    // 12 px gaps; 12 + 336 + 46 + 18·4 method lines + 44 px high.
    let grid = decode(&paths[3]);
    assert_eq!(
        grid.dimensions(),
        (2 * 448 + 3 * 12, 12 + 336 + 46 + 18 * 4 + 44)
    );
    assert_eq!(
        decode(&paths[4]).dimensions(),
        (plots::WIDTH, plots::HEIGHT)
    );
    // The grid draws the truth box and each method's box in its colour.
    let has = |c: [u8; 3]| grid.pixels().any(|p| p.0 == c);
    assert!(has(TRUTH_COLOUR));
    assert!(has(METHOD_COLOURS[0]) && has(METHOD_COLOURS[1]));
    assert!(
        has(plots::EXTRA_METHOD_COLOURS[0]),
        "scene-aware takes the first extra colour"
    );
}

#[test]
fn same_input_same_bytes() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    for (pa, pb) in draw_all(a.path()).iter().zip(draw_all(b.path())) {
        let (ba, bb) = (std::fs::read(pa).unwrap(), std::fs::read(&pb).unwrap());
        assert!(ba == bb, "{} differs between two runs", pa.display());
    }
}

#[test]
fn empty_input_is_a_no_data_error_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("empty.png");
    let nan = [IouPoint {
        method: "otsu".into(),
        group: "g".into(),
        range_m: f64::NAN,
        iou: 0.5,
    }];
    let errors = [
        iou_against_distance(&[], "t", &p).unwrap_err(),
        iou_against_distance(&nan, "t", &p).unwrap_err(),
        intensity_histogram(&[], 14, "t", &p).unwrap_err(),
        intensity_histogram(&[("empty", &[])], 14, "t", &p).unwrap_err(),
        gradient_distribution(&[], &p).unwrap_err(),
        example_grid(&[], &p).unwrap_err(),
        runtime_against_iou(&[], "t", &p).unwrap_err(),
    ];
    for e in errors {
        assert!(e.0.contains("no data") && e.0.contains("empty.png"), "{e}");
    }
    assert!(!p.exists());
    assert!(pareto_front(&[]).is_empty());
}

#[test]
fn bad_frames_are_errors_naming_the_frame() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.png");
    let dn = vec![100u16; 10];
    let e = intensity_histogram(&[("hot", &[20_000])], 14, "t", &p).unwrap_err();
    assert!(e.to_string().contains("'hot'"), "{e}");
    assert!(intensity_histogram(&[("a", &dn)], 0, "t", &p).is_err());
    assert!(intensity_histogram(&[("a", &dn)], 17, "t", &p).is_err());
    let g = GradientFrame {
        label: "short".into(),
        dn: &dn,
        width: 4,
        height: 4,
        truth: Roi::EMPTY,
    };
    assert!(
        gradient_distribution(&[g], &p)
            .unwrap_err()
            .0
            .contains("'short'")
    );
    let tiny = GradientFrame {
        label: "tiny".into(),
        dn: &dn,
        width: 5,
        height: 2,
        truth: Roi::EMPTY,
    };
    assert!(gradient_distribution(&[tiny], &p).is_err());
    let x = ExampleFrame {
        caption: "cap".into(),
        dn: &dn,
        width: 3,
        height: 3,
        truth: Roi::EMPTY,
        boxes: vec![],
    };
    assert!(example_grid(&[x], &p).unwrap_err().0.contains("'cap'"));
    assert!(!p.exists());
}

#[test]
fn edge_cases_draw_without_panicking() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("edge.png");
    // One point, one distance; a constant frame with an empty truth box; zero times.
    let one = [IouPoint {
        method: "mystery".into(),
        group: "g".into(),
        range_m: 30.0,
        iou: 1.0,
    }];
    iou_against_distance(&one, "", &p).unwrap();
    let flat = vec![7u16; W * H];
    let g = GradientFrame {
        label: "flat".into(),
        dn: &flat,
        width: W,
        height: H,
        truth: Roi::EMPTY,
    };
    gradient_distribution(&[g], &p).unwrap();
    intensity_histogram(&[("flat", &flat)], 8, "8-bit", &p).unwrap();
    let x = ExampleFrame {
        caption: String::new(),
        dn: &flat,
        width: W,
        height: H,
        truth: Roi::new(60, 40, 200, 200),
        boxes: vec![("otsu".into(), Some(Roi::EMPTY))],
    };
    example_grid(&[x], &p).unwrap();
    let zero = [
        TradeoffPoint {
            method: "otsu".into(),
            params: String::new(),
            mean_time_ms: 0.0,
            mean_iou: 0.2,
        },
        TradeoffPoint {
            method: "wge".into(),
            params: "x".into(),
            mean_time_ms: f64::NAN,
            mean_iou: 0.9,
        },
    ];
    runtime_against_iou(&zero, "zero time", &p).unwrap();
    assert_eq!(pareto_front(&zero), vec![0]);
}

/// Brute force: `i` is optimal when no `j` is at least as good in both and better in one.
fn brute_front(points: &[TradeoffPoint]) -> Vec<usize> {
    let ok = |p: &TradeoffPoint| p.mean_time_ms.is_finite() && p.mean_iou.is_finite();
    let mut front: Vec<usize> = (0..points.len())
        .filter(|&i| {
            let p = &points[i];
            ok(p)
                && !points.iter().any(|q| {
                    ok(q)
                        && q.mean_time_ms <= p.mean_time_ms
                        && q.mean_iou >= p.mean_iou
                        && (q.mean_time_ms < p.mean_time_ms || q.mean_iou > p.mean_iou)
                })
        })
        .collect();
    front.sort_by(|&a, &b| {
        points[a]
            .mean_time_ms
            .total_cmp(&points[b].mean_time_ms)
            .then(a.cmp(&b))
    });
    front
}

#[test]
fn pareto_front_matches_brute_force() {
    for seed in 0..300 {
        let n = (seed % 40) as usize;
        // Coarse levels give many ties, fine levels almost none.
        let levels = [3.0, 10.0, 1e6][seed as usize % 3];
        let mut points = tradeoff_points(n, seed, levels);
        if seed % 7 == 0 && n > 2 {
            points[1].mean_iou = f64::NAN;
            points[2].mean_time_ms = f64::INFINITY;
        }
        let front = pareto_front(&points);
        assert_eq!(front, brute_front(&points), "seed {seed}");
        // Along the front, time and IoU both rise.
        for w in front.windows(2) {
            let (a, b) = (&points[w[0]], &points[w[1]]);
            assert!(a.mean_time_ms <= b.mean_time_ms && a.mean_iou <= b.mean_iou);
        }
    }
}
