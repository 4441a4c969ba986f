//! Runs a DCB over a population of laws (`benches/common/population.rs`), for timing, profiling
//! and comparing records between two builds:
//!
//! `cargo run --release --example dcb_population -- [paper|hartlen] [laws] [time|records] [repeats]`
//!
//! * `time` (default): every law `repeats` times (default 3), the mean time per run (ms);
//! * `records`: every record in full precision (one line per row: law, row, then each column),
//!   for `diff` or a relative comparison between builds.
//!
//! The paper's DCB at the mesh of `examples/paper-dcb/problem.toml` (0.1 mm interface elements) to
//! 10 mm; Hartlen's DCB-01 (0.2 mm) to 30 mm. Small rotations, the default engine (the window).

#[path = "../benches/common/population.rs"]
mod population;

use czid_core::ForwardModel;
use czid_models::dcb::Dcb;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let case = args.get(1).map_or("paper", |s| s.as_str());
    let n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(50);
    let mode = args.get(3).map_or("time", |s| s.as_str());
    let repeats: usize = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(3);
    let (dcb, laws) = match case {
        "hartlen" => (Dcb::hartlen_dcb01(), population::hartlen_laws(n, 1)),
        _ => {
            let mut d = Dcb::paper();
            d.mesh.interface_element = 0.1;
            d.mesh.arm_element = 0.5;
            d.control.max_displacement = Some(10.0);
            (d, population::paper_laws(n, 1))
        }
    };
    if mode == "records" {
        for (k, law) in laws.iter().enumerate() {
            match dcb.simulate(law.as_ref()) {
                Ok(rec) => {
                    for i in 0..rec.rows() {
                        let row: Vec<String> = rec.columns().iter().map(|c| format!("{:.17e}", c.values[i])).collect();
                        println!("{k} {i} {}", row.join(" "));
                    }
                }
                Err(f) => println!("{k} failed: {}", f.error),
            }
        }
        return;
    }
    let t = std::time::Instant::now();
    let mut failed = 0;
    for _ in 0..repeats {
        for law in &laws {
            failed += usize::from(dcb.simulate(law.as_ref()).is_err());
        }
    }
    let runs = repeats * laws.len();
    println!(
        "{case}: {} laws × {repeats}: {:.3} ms per run ({failed} failed runs)",
        laws.len(),
        t.elapsed().as_secs_f64() * 1e3 / runs as f64
    );
}
