//! Runs a beam-test model repeatedly, for profilers and timing:
//! `cargo run --release --example dcb_profile -- [paper|hartlen|hartlen-large|hartlen-large-coarse|enf|mmb] [runs]`
//! (defaults: paper, 20). The paper's DCB with the identified law (Shi & Zhang, Table 3), Hartlen's
//! DCB-01 with a bilinear law (G_Ic = 0.8 N/mm), the same with large rotations (co-rotational, whole
//! mesh), Hartlen's ENF-03 at its identified law and an MMB at G_II/G = 0.5: the runs of
//! `benches/forward.rs`. With 1 run it is what
//! `valgrind --tool=callgrind` or `perf record` should count.
use czid_core::{CohesiveLaw, ForwardModel};
use czid_models::dcb::{self, Dcb};
use czid_models::enf::{self, Enf};
use czid_models::laws::{Bilinear, StCzm};
use czid_models::mmb::Mmb;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let case = args.get(1).map_or("paper", |s| s.as_str());
    let runs: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(20);
    if case == "enf" || case == "mmb" {
        return split_beam(case, runs);
    }
    let (d, law): (Dcb, Box<dyn CohesiveLaw>) = match case {
        "hartlen" => (Dcb::hartlen_dcb01(), Box::new(Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0).unwrap())),
        "hartlen-large" => {
            let mut d = Dcb::hartlen_dcb01();
            d.effects.large_rotation = true;
            (d, Box::new(Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0).unwrap()))
        }
        "hartlen-large-coarse" => {
            let mut d = Dcb::hartlen_dcb01();
            d.effects.large_rotation = true;
            d.mesh.interface_subdivision = 1;
            (d, Box::new(Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0).unwrap()))
        }
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

/// The ENF and MMB cases (whole-mesh solves).
fn split_beam(case: &str, runs: usize) {
    let (e, enf_law) = Enf::hartlen_enf03_identified();
    let (m, mmb_law) = Mmb::hartlen_half_mode_two();
    let run = || {
        if case == "enf" {
            e.simulate(&enf_law).unwrap();
        } else {
            m.simulate(&mmb_law).unwrap();
        }
    };
    if runs <= 1 {
        return run();
    }
    let stats =
        if case == "enf" { enf::simulate_with_stats(&e, &enf_law).unwrap().1 } else { m.run_rows(&mmb_law).unwrap().1 };
    let t = std::time::Instant::now();
    for _ in 0..runs {
        run();
    }
    println!("{case}: {stats:?}; {:.2} ms per run", t.elapsed().as_secs_f64() * 1e3 / runs as f64);
}
