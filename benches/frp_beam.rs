//! The FRP-strengthened beam run to complete debonding, as an identification of the beam's
//! interface law performs it many times: the paper's beam (`FrpBeam::paper()`: 10 mm interface
//! elements, 30 fibres through the depth, 0.05 mm elongation steps) with the Table 8 ST-CZM, from
//! zero load through IC debonding and the load drop to the state after complete debonding. The
//! book's FRP beam chapter lists the measured median and where the time goes.

use criterion::{criterion_group, criterion_main, Criterion};
use czid_core::ForwardModel;
use czid_models::frp::beam::FrpBeam;

fn frp_beam(c: &mut Criterion) {
    let mut g = c.benchmark_group("forward");
    g.sample_size(10);
    let beam = FrpBeam::paper().unwrap();
    let law = FrpBeam::table8_law().unwrap();
    g.bench_function("frp_beam_table8_to_complete_debonding", |b| b.iter(|| beam.simulate(&law).unwrap()));
    g.finish();
}

criterion_group!(benches, frp_beam);
criterion_main!(benches);
