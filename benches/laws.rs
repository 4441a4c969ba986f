//! Cost of one cohesive-law evaluation, the innermost call of every forward model.
//!
//! Each law is evaluated through `&dyn CohesiveLaw`, as the finite-element engine calls it, on two
//! branches: *loading* (the gap lies beyond the committed damage surface, so damage is updated and
//! the consistent tangent built) and *unloading* (inside it: the damaged secant).
//!
//! Run: `cargo bench --bench laws -- --warm-up-time 1 --measurement-time 3`.

use criterion::{criterion_group, criterion_main, Criterion};
use czid_core::{CohesiveLaw, Gap};
use czid_models::laws::{Bilinear, Bridging, Exponential, StCzm, StrengthShape};
use std::hint::black_box;

/// Each law with a mixed-mode gap in its softening range (mm).
fn cases() -> Vec<(&'static str, Box<dyn CohesiveLaw>, Gap)> {
    let table3 = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).expect("valid");
    let exponential_shape = table3
        .clone()
        .with_shapes(StrengthShape::Exponential { alpha: 4.0 }, StrengthShape::Exponential { alpha: 4.0 })
        .expect("valid");
    let trilinear_shape = table3
        .clone()
        .with_shapes(
            StrengthShape::Trilinear { kink_fraction: 0.2, kink_strength_ratio: 0.3 },
            StrengthShape::Trilinear { kink_fraction: 0.2, kink_strength_ratio: 0.3 },
        )
        .expect("valid");
    let bilinear = Bilinear::bk(1e5, 30.0, 45.0, 0.28, 0.9, 2.1).expect("valid");
    let bridging = Bridging::trilinear(1e5, [30.0, 45.0, 0.25, 0.8], [3.0, 4.5, 0.5, 1.0], 2.0).expect("valid");
    vec![
        ("st_czm sawtooth", Box::new(table3), Gap::new(0.0012, 0.0008)),
        ("st_czm exponential shape", Box::new(exponential_shape), Gap::new(0.0012, 0.0008)),
        ("st_czm trilinear shape", Box::new(trilinear_shape), Gap::new(0.0012, 0.0008)),
        ("bilinear", Box::new(bilinear), Gap::new(0.005, 0.004)),
        ("exponential", Box::new(Exponential::new(30.0, 0.001, 40.0, 0.002).expect("valid")), Gap::new(0.002, 0.002)),
        ("bridging", Box::new(bridging), Gap::new(0.02, 0.02)),
    ]
}

fn evaluate(c: &mut Criterion) {
    let mut group = c.benchmark_group("law evaluate");
    for (name, law, gap) in cases() {
        let law: &dyn CohesiveLaw = law.as_ref();
        // Committed at 80 % of the gap: evaluating at the gap loads further, at half of it unloads.
        let committed = law.evaluate(&(0.8 * gap), &law.initial_state()).state;
        assert!(committed.damage > 0.0 && committed.damage < 1.0, "{name}: pick a gap in the softening range");
        let inside = 0.5 * gap;
        group.bench_function(format!("{name}/loading"), |b| {
            b.iter(|| law.evaluate(black_box(&gap), black_box(&committed)))
        });
        group.bench_function(format!("{name}/unloading"), |b| {
            b.iter(|| law.evaluate(black_box(&inside), black_box(&committed)))
        });
    }
    group.finish();
}

criterion_group!(benches, evaluate);
criterion_main!(benches);
