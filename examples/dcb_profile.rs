//! Runs the paper's DCB (Table 3) repeatedly, for profilers: `cargo run --release --example dcb_profile`.
use czid_core::ForwardModel;
use czid_models::dcb::{self, Dcb};
use czid_models::laws::StCzm;

fn main() {
    let law = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
    let d = Dcb::paper();
    let (_, stats) = dcb::simulate_with_stats(&d, &law).unwrap();
    let n = 20;
    let t = std::time::Instant::now();
    for _ in 0..n {
        d.simulate(&law).unwrap();
    }
    println!("{stats:?}; {:.2} ms per run", t.elapsed().as_secs_f64() * 1e3 / n as f64);
}
