//! Criterion benchmarks of each detector on a frame of each scene kind the renderer
//! makes (deep space, full Earth, multi-material over the Earth, detection Scale 1 and
//! Scale 3 of the same pose, Tango), so that the run time is known per scene type.
//! `cargo bench --bench scenes`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use tirroi::core::{BoxRule, Frame, Method};
use tirroi::host::dataset::{Library, plan};
use tirroi::host::eval::bank::DetectorBank;
use tirroi::host::world::scene::SceneFile;

/// One close-range pose per scene kind, fixed so that the frames are the same every run.
const SCENES: &str = r#"
[dataset]
seed = 11
thermal_states = 1

[earth_model]
days = 1

[[scene]]
name = "deep-space"
range_m = 25.0
earth = false

[[scene]]
name = "earth"
range_m = 25.0
earth_off_boresight_deg = 10.0

[[scene]]
name = "multi-material"
material = "multi-1"
range_m = 25.0
earth_off_boresight_deg = 20.0

[[scene]]
name = "detection"
count = 2
mode = "detection"
scale = [1, 3]
range_m = 25.0
earth_off_boresight_deg = 20.0

[[scene]]
name = "tango"
target = "tango"
range_m = 20.0
earth_off_boresight_deg = 20.0
"#;

fn detectors(c: &mut Criterion) {
    let file = SceneFile::parse(SCENES, "benches/scenes.rs").expect("scene file parses");
    let plans = plan(&file);
    let library = Library::build(&file, &plans).expect("library");
    let mut bank = DetectorBank::default();
    bank.set_box_rule(BoxRule::LargestComponent);
    for p in &plans {
        let (frame, _) = library.render(&file, p).expect("renders");
        let mut name = file.scenes[p.scene].name.clone().unwrap_or_default();
        if let Some(s) = p.scale {
            name = format!("{name}-scale{s}");
        }
        let view = Frame::new(&frame.dn, frame.width, frame.height, 14).expect("frame");
        let mut g = c.benchmark_group(format!("detect/{name}"));
        for m in Method::ALL {
            g.bench_function(m.name(), |b| {
                b.iter(|| black_box(bank.detect(m, black_box(&view)).expect("detects")))
            });
        }
        g.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = detectors
}
criterion_main!(benches);
