//! Runs the paper's FRP beam repeatedly, for profilers and timing:
//! `cargo run --release --example frp_beam_profile -- [paper|identify] [runs] [step] [element] [tolerance] [max deflection]` (defaults: paper,
//! 10). `paper` is `FrpBeam::paper()` with the Table 8 law (the run of `benches/frp_beam.rs`);
//! `identify` the same beam with the fixed step schedule of `examples/frp-beam/identify.toml`
//! (`damage_tolerance = 1`). With 1 run it is what `valgrind --tool=callgrind` or `perf record`
//! should count.
use czid_models::frp::beam::FrpBeam;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let case = args.get(1).map_or("paper", |s| s.as_str());
    let runs: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(10);
    let mut beam = FrpBeam::paper().unwrap();
    if case == "identify" {
        let step = beam.control.elongation_step;
        beam.control.set_fixed_schedule(step);
    }
    // Optional overrides: elongation step (mm), interface element (mm), damage tolerance.
    let arg = |i: usize| args.get(i).and_then(|s| s.parse::<f64>().ok());
    if let Some(v) = arg(3) {
        beam.control.elongation_step = v;
    }
    if let Some(v) = arg(4) {
        beam.mesh.interface_element = v;
    }
    if let Some(v) = arg(5) {
        beam.control.damage_tolerance = v;
    }
    beam.control.max_deflection = arg(6);
    let law = FrpBeam::table8_law().unwrap();
    let first = beam.run(&law, false).unwrap();
    if runs <= 1 {
        return;
    }
    let t = std::time::Instant::now();
    for _ in 0..runs {
        beam.run(&law, false).unwrap();
    }
    println!(
        "{case}: {:?}, {} rows, end {:?}; {:.2} ms per run",
        first.stats,
        first.record.rows(),
        first.end,
        t.elapsed().as_secs_f64() * 1e3 / runs as f64
    );
}
