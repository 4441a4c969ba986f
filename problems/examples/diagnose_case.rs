//! Makes one `gap-bench` case's synthetic test and diagnoses it alone, timing the making and the
//! diagnosis's stages and counting the forward runs of each.
//!
//! ```text
//! cargo run --release -p czid-problems --example diagnose_case -- \
//!     --truth continuum --cases 4 --nulls 6 --seed 31 \
//!     --effects fibre_bridging,machine_compliance,seating_toe,load_offset,crack_length_offset,displacement_gain \
//!     --case 21 [--out summary.json] [--refit large_rotation]
//! cargo run --release -p czid-problems --example diagnose_case -- \
//!     --family beam --truth beam --cases 20 --nulls 20 --seed 7 --case 2
//! ```

use czid_problems::diagnose::bench::{BenchOptions, Family, Plan};
use czid_problems::diagnose::gauge::tally;
use czid_problems::diagnose::run::diagnose_subject;
use std::sync::Mutex;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |name: &str| args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).cloned();
    let opts = BenchOptions {
        cases: arg("--cases").map_or(4, |v| v.parse().expect("--cases")),
        nulls: arg("--nulls").map_or(6, |v| v.parse().expect("--nulls")),
        seed: arg("--seed").map_or(31, |v| v.parse().expect("--seed")),
        effects: arg("--effects").map(|v| v.split(',').map(String::from).collect()).unwrap_or_default(),
        family: arg("--family").map_or(Family::Dcb, |v| v.parse().expect("--family")),
        truth: arg("--truth").unwrap_or_else(|| "continuum".into()).parse().expect("--truth"),
    };
    let index: usize = arg("--case").expect("--case N").parse().expect("--case");
    let plan = Plan::new(&opts).expect("plan");
    let clock = Instant::now();
    let (made, prepared) = plan.prepare_case(index);
    let prepared = prepared.expect("the case's test");
    println!(
        "case {index}: {} on {}, size {:?}, {} readings; test made in {:.1} s",
        made.planted,
        made.specimen,
        made.size,
        made.readings,
        clock.elapsed().as_secs_f64()
    );
    print_tally("making the test", &tally::snapshot(), &Default::default());
    let last = Mutex::new((Instant::now(), String::from("start"), tally::snapshot()));
    let diagnosing = Instant::now();
    let mut options = prepared.options;
    // Candidates to refit whatever their score (on request: they take no part in the verdict), e.g.
    // to measure what a candidate removes from clean tests.
    if let Some(names) = arg("--refit") {
        options.always_refit.extend(names.split(',').map(String::from));
    }
    options.progress = Some(Box::new(move |m: &str| {
        let mut l = last.lock().unwrap();
        let now = tally::snapshot();
        println!("  {:7.1} s  {:50} ({:.1} s)", diagnosing.elapsed().as_secs_f64(), l.1, l.0.elapsed().as_secs_f64());
        print_tally("", &now, &l.2);
        *l = (Instant::now(), m.to_string(), now);
    }));
    let before = tally::snapshot();
    let d = diagnose_subject(&prepared.subject, &prepared.start, plan.library(), &options).expect("diagnosis");
    let seconds = diagnosing.elapsed().as_secs_f64();
    println!("diagnosis: {seconds:.1} s");
    print_tally("diagnosis total", &tally::snapshot(), &before);
    println!("base fit at {:?}", d.base.parameters.iter().map(|p| p.value).collect::<Vec<_>>());
    println!(
        "base: chi2/dof {:.4}, structure p {:.3e}, model-form shift {:.3} (floor uncertainty {:.3}) noise units, evaluations {}",
        d.base.reduced_chi2, d.base.structure_p, d.model_form.shift_rms, d.model_form.floor_rms, d.base.evaluations
    );
    for c in &d.candidates {
        if let Some(r) = &c.refit {
            println!(
                "  refit {:22} evaluations {:4} shrinkage {:.4} dBIC {:.1} reestimated {:?}",
                c.name, r.evaluations, r.shrinkage, r.delta_bic, r.chi2_reestimated
            );
            let values: Vec<f64> = r.parameters.iter().chain(&r.effect).map(|v| v.value).collect();
            println!("    chi2 {:.1} at {values:?}", r.chi2);
        }
    }
    println!("verdict: {:?} cause {:?} more_missing {}", d.outcome.kind, d.outcome.cause, d.outcome.more_missing);
    let summary = serde_json::json!({
        "case": index,
        "data_seconds": made.data_seconds,
        "diagnosis_seconds": seconds,
        "outcome": d.outcome,
        "ranking": d.candidates.iter().map(|c| (c.name.clone(), c.score.as_ref().map(|s| (s.statistic, s.significant)))).collect::<Vec<_>>(),
        "refits": d.candidates.iter().filter_map(|c| c.refit.as_ref().map(|r| (c.name.clone(), r.chi2, r.shrinkage, r.delta_bic, r.chi2_reestimated, r.evaluations))).collect::<Vec<_>>(),
        "base_chi2": d.base.chi2,
        "base_parameters": d.base.parameters.iter().map(|p| p.value).collect::<Vec<_>>(),
        "verdict": d.verdict,
    });
    if let Some(out) = arg("--out") {
        std::fs::write(out, serde_json::to_string_pretty(&summary).unwrap()).expect("write");
    }
}

fn print_tally(
    what: &str,
    now: &std::collections::BTreeMap<String, (usize, std::time::Duration)>,
    before: &std::collections::BTreeMap<String, (usize, std::time::Duration)>,
) {
    for (model, (n, t)) in now {
        let (n0, t0) = before.get(model).copied().unwrap_or_default();
        if n > &n0 {
            println!("      {what} {model}: {} runs, {:.1} s summed", n - n0, (*t - t0).as_secs_f64());
        }
    }
}
