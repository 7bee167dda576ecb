//! Criterion benchmarks of every ROI detector on realistic 328×248 14-bit frames: a
//! two-part target over a textured Earth-like background with noise, and over deep
//! space. One group per detector, and `auto` in tracking mode; `cargo bench --bench
//! detectors`.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use tirroi::core::roi::adaptive::{Adaptive, AdaptiveScratch};
use tirroi::core::roi::auto::{Auto, AutoScratch};
use tirroi::core::roi::dog::{Dog, DogScratch};
use tirroi::core::roi::otsu::{Otsu, OtsuScratch};
use tirroi::core::roi::wge::{Wge, WgeScratch};
use tirroi::core::{Detector, Frame};
use tirroi::host::imaging::fixture::{self, Fixture};

fn frames() -> Vec<(&'static str, Fixture)> {
    fixture::standard_set()
        .into_iter()
        .filter(|(name, _)| matches!(*name, "deep-space" | "earth"))
        .map(|(name, spec)| (name, fixture::render(&spec)))
        .collect()
}

fn bench_detector<D: Detector>(
    c: &mut Criterion,
    detector: D,
    scratch: &mut tirroi::core::roi::Scratch<D::Work<tirroi::core::Reference>>,
) {
    let mut group = c.benchmark_group(D::NAME);
    for (name, fx) in frames() {
        let frame = Frame::reference(&fx.frame.pixels).expect("fixture frames are 328x248");
        group.bench_with_input(BenchmarkId::from_parameter(name), &frame, |b, frame| {
            b.iter(|| {
                detector
                    .detect(black_box(frame), scratch)
                    .expect("default parameters are valid")
            })
        });
    }
    group.finish();
}

fn otsu(c: &mut Criterion) {
    bench_detector(c, Otsu::default(), &mut OtsuScratch::new());
}

fn adaptive(c: &mut Criterion) {
    bench_detector(c, Adaptive::default(), &mut AdaptiveScratch::new());
}

fn wge(c: &mut Criterion) {
    bench_detector(c, Wge::default(), &mut WgeScratch::new());
}

fn dog(c: &mut Criterion) {
    bench_detector(c, Dog::default(), &mut Box::new(DogScratch::new()));
}

fn auto(c: &mut Criterion) {
    bench_detector(c, Auto::default(), &mut AutoScratch::new());
}

/// `auto` in tracking mode: the prior is the fixture's truth box moved by 3 px and
/// grown by 2 px on each side, as a tracker would hand it over.
fn auto_tracking(c: &mut Criterion) {
    let mut group = c.benchmark_group("auto-tracking");
    let mut scratch = AutoScratch::new();
    for (name, fx) in frames() {
        let frame = Frame::reference(&fx.frame.pixels).expect("fixture frames are 328x248");
        let t = fx.truth;
        let prior = tirroi::core::Roi::new(t.x0 + 1, t.y0 + 1, t.x1 + 5, t.y1 + 5);
        let auto = Auto::default().with_prior(Some(prior));
        group.bench_with_input(BenchmarkId::from_parameter(name), &frame, |b, frame| {
            b.iter(|| {
                auto.detect(black_box(frame), &mut scratch)
                    .expect("default parameters are valid")
            })
        });
    }
    group.finish();
}

criterion_group!(detectors, otsu, adaptive, wge, dog, auto, auto_tracking);
criterion_main!(detectors);
