//! Forward-model benchmarks: full DCB runs as an identification performs them thousands of times.
//!
//! * `dcb_paper_population`: Shi & Zhang's DCB at the mesh of `examples/paper-dcb/problem.toml`
//!   (0.1 mm interface elements, to 10 mm), one iteration per law of a population of 50 ST-CZM
//!   laws drawn in that problem's parameter ranges (`benches/common/population.rs`): an
//!   identification's runs, which no cache across runs of one law can serve.
//! * `dcb_hartlen_population`: Hartlen's DCB-01 to 30 mm over 50 bilinear laws (20–60 MPa,
//!   G_Ic 0.5–1.2 N/mm).
//! * `dcb_paper_table3`: Shi & Zhang's DCB, 0.1 mm interface elements, ST-CZM Table 3, to the
//!   default final opening (crack 60 % of the way to the end by beam theory).
//! * `dcb_hartlen_30mm`: Hartlen's DCB-01 to 30 mm opening, bilinear law (G_Ic = 0.8 N/mm).
//! * `enf_hartlen03_identified`: Hartlen's ENF-03 as `examples/hartlen-enf/enf03.toml` runs it
//!   (0.25 mm interface elements of one beam element each, to the end of the test), at the law and
//!   modulus identified from it; solved on the whole mesh (its mode II process zone spans the
//!   crack's path, see the book's Mixed mode chapter).
//!
//! * `mmb_hartlen_half_mode_two`: an MMB (ASTM D6671) of Hartlen's ENF specimen with the lever for
//!   G_II/G = 0.5 (c = 43.72 mm), 0.2 mm interface elements, a B-K law, to 7 mm (about 9 mm of
//!   crack growth): `examples/mixed-mode-synthetic/problem.toml`'s MMB at its truth; on the window
//!   around the crack front (the saddle's control ahead of it, the open cracked faces behind).
//! * `mmb_mixed_mode_population`: the same MMB over 50 bilinear laws drawn in the box of
//!   `examples/mixed-mode-synthetic/problem.toml` (the first the one above): runs whose process
//!   zone reaches the saddle hand their state to the whole mesh part way, as an identification's do.
//!
//! * `dcb_hartlen_large_rotation_population`: the Hartlen population above with large rotations
//!   (co-rotational arms, solved on the whole mesh).
//!
//! * `dcb_2d_paper_10mm`: the same DCB on the continuum model (`dcb_2d`, 0.1 mm interface
//!   elements, 4 Gauss points each, band LU) to 10 mm opening: the mesh its convergence check
//!   accepts (see the book's "Beam or continuum?" chapter).
//!
//! The beam cases with the default discretisation (interface segments, beam elements of a quarter of the
//! interface element where the crack runs) and solver (the window around the crack front); the
//! forward models chapter of the book lists the measured medians, and `examples/dcb_profile.rs`
//! runs the same cases for profilers.

#[path = "common/population.rs"]
mod population;

use criterion::{criterion_group, criterion_main, Criterion};
use czid_core::ForwardModel;
use czid_models::dcb::Dcb;
use czid_models::dcb_2d::Dcb2d;
use czid_models::enf::Enf;
use czid_models::laws::{Bilinear, StCzm};
use czid_models::mmb::Mmb;

fn forward(c: &mut Criterion) {
    let mut g = c.benchmark_group("forward");
    g.sample_size(20);
    // Each iteration runs the next law of the population, so the median is over all of them.
    let mut paper_example = Dcb::paper();
    paper_example.mesh.interface_element = 0.1;
    paper_example.mesh.arm_element = 0.5;
    paper_example.control.max_displacement = Some(10.0);
    let laws = population::paper_laws(50, 1);
    let mut k = 0;
    g.bench_function("dcb_paper_population", |b| {
        b.iter(|| {
            k = (k + 1) % laws.len();
            paper_example.simulate(laws[k].as_ref()).unwrap()
        })
    });
    let hartlen_laws = population::hartlen_laws(50, 1);
    let hartlen_dcb = Dcb::hartlen_dcb01();
    let mut k = 0;
    g.bench_function("dcb_hartlen_population", |b| {
        b.iter(|| {
            k = (k + 1) % hartlen_laws.len();
            hartlen_dcb.simulate(hartlen_laws[k].as_ref()).unwrap()
        })
    });
    let paper = Dcb::paper();
    let t3 = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
    g.bench_function("dcb_paper_table3", |b| b.iter(|| paper.simulate(&t3).unwrap()));
    let hartlen = Dcb::hartlen_dcb01();
    let law = Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0).unwrap();
    g.bench_function("dcb_hartlen_30mm", |b| b.iter(|| hartlen.simulate(&law).unwrap()));
    let (enf, mode_two) = Enf::hartlen_enf03_identified();
    g.bench_function("enf_hartlen03_identified", |b| b.iter(|| enf.simulate(&mode_two).unwrap()));
    let (mmb, mixed) = Mmb::hartlen_half_mode_two();
    g.bench_function("mmb_hartlen_half_mode_two", |b| b.iter(|| mmb.simulate(&mixed).unwrap()));
    let mixed_laws = population::mixed_mode_laws(50, 1);
    let mut k = 0;
    g.bench_function("mmb_mixed_mode_population", |b| {
        b.iter(|| {
            k = (k + 1) % mixed_laws.len();
            mmb.simulate(&mixed_laws[k]).unwrap()
        })
    });
    g.finish();
    // Large rotations: the co-rotational beams run on the whole mesh, 0.3–0.6 s a run.
    let mut large = c.benchmark_group("forward_large_rotation");
    large.sample_size(10);
    let mut hartlen_large = Dcb::hartlen_dcb01();
    hartlen_large.effects.large_rotation = true;
    let mut k = 0;
    large.bench_function("dcb_hartlen_large_rotation_population", |b| {
        b.iter(|| {
            k = (k + 1) % hartlen_laws.len();
            hartlen_large.simulate(hartlen_laws[k].as_ref()).unwrap()
        })
    });
    large.finish();
    let mut slow = c.benchmark_group("forward_continuum");
    slow.sample_size(10);
    let mut continuum = Dcb2d::paper();
    continuum.control.max_displacement = Some(10.0);
    slow.bench_function("dcb_2d_paper_10mm", |b| b.iter(|| continuum.simulate(&t3).unwrap()));
    slow.finish();
}

criterion_group!(benches, forward);
criterion_main!(benches);
