//! Criterion benchmarks of the renderer: one frame of each scene kind of the `quick`
//! preset (radiometry close and far, detection close and far, Tango), from the shared
//! library (meshes, thermal solutions, Earth maps built once) to the noisy DN frame,
//! and the 16-bit PNG encode of one frame. `cargo bench --bench render`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use tirroi::host::dataset::{Library, plan};
use tirroi::host::world::scene::SceneFile;

fn frames(c: &mut Criterion) {
    let file = SceneFile::preset("quick").expect("the quick preset parses");
    let plans = plan(&file);
    let library = Library::build(&file, &plans).expect("library");
    let mut g = c.benchmark_group("render_frame");
    for (i, spec) in file.scenes.iter().enumerate() {
        let name = spec.name.clone().unwrap_or_else(|| format!("scene-{i}"));
        // The first pose of the kind that sees the Earth.
        let Some(p) = plans.iter().find(|p| p.scene == i) else {
            continue;
        };
        g.bench_function(name, |b| {
            b.iter(|| black_box(library.render(&file, black_box(p)).expect("renders")))
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = frames
}
criterion_main!(benches);
