//! What a root compliance costs a DCB run as it nears the limit the model accepts:
//! `cargo run --release -p czid-models --example root_compliance_limit`.
//!
//! For bilinear laws of rising steepness on the paper's and Hartlen's DCBs, the root compliance is
//! set to a share `2 c_r |dT/du|` of the law's steepest softening (see
//! `czid_models::effects::ROOT_COMPLIANCE_SHARE`) and the run timed: whether the window solved it,
//! its steps, and its time (or the error).
use czid_core::CohesiveLaw;
use czid_models::dcb::{self, Dcb};
use czid_models::effects::steepest_mode_one_softening;
use czid_models::laws::Bilinear;

fn main() {
    let laws = [(15.0, 0.7), (27.0, 0.744), (40.0, 0.6), (60.0, 0.6)];
    println!("| specimen | law σ (MPa) / G_Ic (N/mm) | share | c_r (mm/MPa) | windowed | steps | time (s) |");
    println!("|---|---|---|---|---|---|---|");
    for (specimen, base) in [("paper", Dcb::paper()), ("Hartlen DCB-01", Dcb::hartlen_dcb01())] {
        for (sigma, g) in laws {
            let law = Bilinear::bk(1e5, sigma, 40.0, g, 1.6, 2.0).expect("valid law");
            let slope = steepest_mode_one_softening(&law as &dyn CohesiveLaw);
            for share in [0.3, 0.5, 0.6, 0.7, 0.8] {
                let mut d = base.clone();
                d.effects.root_compliance = share / (2.0 * slope);
                let clock = std::time::Instant::now();
                let run = dcb::simulate_with_stats(&d, &law);
                let t = clock.elapsed().as_secs_f64();
                let (windowed, steps) = match &run {
                    Ok((_, s)) => (s.windowed.to_string(), s.steps.to_string()),
                    Err(e) if e.to_string().contains("effects.root_compliance") => ("refused".into(), "-".into()),
                    Err(_) => ("failed".into(), "-".into()),
                };
                println!(
                    "| {specimen} | {sigma} / {g} | {share} | {:.3e} | {windowed} | {steps} | {t:.3} |",
                    d.effects.root_compliance
                );
            }
        }
    }
}
