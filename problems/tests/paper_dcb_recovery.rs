//! The paper-DCB study on its bundled synthetic data (Table 3 law, 1000 readings, 0.02 N and
//! 0.1 mm noise): the hybrid (MIGA, then Levenberg–Marquardt) recovers what a DCB determines and
//! says what it does not.

use czid_problems::identify::{identify, RunOptions};
use czid_problems::output::OutputDir;
use czid_problems::problem_file::LoadedProblem;
use std::path::Path;

/// Shi & Zhang's Table 3, in the order of the problem file's `[[parameter]]` tables.
const TRUTH: [f64; 6] = [27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273];

#[test]
fn hybrid_recovers_strength_and_critical_opening_within_two_percent() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/paper-dcb/problem.toml");
    let problem = LoadedProblem::read(&file).unwrap();
    let dir = std::env::temp_dir().join(format!("czid-paper-dcb-recovery-{}", std::process::id()));
    let out = OutputDir::create(&dir, true, false).unwrap();
    let opts = RunOptions { optimizer: Some("hybrid".into()), budget: Some(600), ..RunOptions::default() };
    let res = identify(&problem, &opts, &out).unwrap();

    let value = |k: &str| res.parameters[k].value;
    let error = |k: &str, truth: f64| value(k) / truth - 1.0;
    for (k, truth) in [("law.strength_n", TRUTH[0]), ("law.u_c_n", TRUTH[2])] {
        eprintln!("{k}: {:.6e} ({:+.3} %), {}", value(k), 100.0 * error(k, truth), res.parameters[k].verdict);
        assert!(error(k, truth).abs() < 0.02, "{k} = {} is not within 2 % of {truth}", value(k));
        assert!(res.parameters[k].verdict.starts_with("determined"), "{k}: {}", res.parameters[k].verdict);
    }
    let g = 0.5 * value("law.strength_n") * value("law.u_c_n");
    let g_truth = 0.5 * TRUTH[0] * TRUTH[2];
    assert!((g / g_truth - 1.0).abs() < 2e-3, "G_Ic {g} against {g_truth}");
    // A symmetric DCB never slips: the shear parameters are reported as not determined.
    for k in ["law.strength_t", "law.u_e_t", "law.u_c_t"] {
        assert_eq!(res.parameters[k].verdict, "not determined by these data", "{k}");
    }
    // The fit is as good as the truth's: the misfit left is the noise.
    let id = problem.identification().unwrap();
    let at_truth = id.simulate(&TRUTH).unwrap().evaluation.value;
    eprintln!("f = {:.4e}, at the truth {at_truth:.4e}", res.objective);
    assert!(res.objective <= 1.01 * at_truth, "f = {} against {at_truth} at the truth", res.objective);
    std::fs::remove_dir_all(&dir).ok();
}
