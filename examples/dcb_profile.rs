//! Runs a DCB repeatedly, for profilers and timing:
//! `cargo run --release --example dcb_profile -- [paper|hartlen] [runs]` (defaults: paper, 20).
//! The paper's DCB with the identified law (Shi & Zhang, Table 3) or Hartlen's DCB-01 with a
//! bilinear law (G_Ic = 0.8 N/mm), the two runs of `benches/forward.rs`. With 1 run it is what
//! `valgrind --tool=callgrind` should count.
use czid_core::{CohesiveLaw, ForwardModel};
use czid_models::dcb::{self, Dcb};
use czid_models::laws::{Bilinear, StCzm};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let case = args.get(1).map_or("paper", |s| s.as_str());
    let runs: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(20);
    let (d, law): (Dcb, Box<dyn CohesiveLaw>) = match case {
        "hartlen" => (Dcb::hartlen_dcb01(), Box::new(Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0).unwrap())),
        _ => (Dcb::paper(), Box::new(StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap())),
    };
    if runs <= 1 {
        d.simulate(law.as_ref()).unwrap();
        return;
    }
    let (_, stats) = dcb::simulate_with_stats(&d, law.as_ref()).unwrap();
    let t = std::time::Instant::now();
    for _ in 0..runs {
        d.simulate(law.as_ref()).unwrap();
    }
    println!("{case}: {stats:?}; {:.2} ms per run", t.elapsed().as_secs_f64() * 1e3 / runs as f64);
}
