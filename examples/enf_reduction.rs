//! G_IIc of the bundled real ENF tests by closed-form data reduction (no cohesive law): beam
//! theory with the modulus calibrated from the initial compliance at a0, and the compliance-based
//! beam method (equivalent crack length at the onset), on the toe-compensated curves the problem
//! files read. Compare with `czid identify examples/hartlen-enf/enf0N.toml`.
//!
//! `cargo run --release --example enf_reduction`

use std::path::Path;

use czid_models::enf::Enf;
use czid_models::enf_reduction::reduce;
use czid_problems::problem_file::LoadedProblem;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    println!("| test | C₀ (mm/N) | E_f (MPa) | onset (N at mm) | a_e (mm) | G_IIc beam (N/mm) | G_IIc CBBM (N/mm) |");
    println!("|---|---|---|---|---|---|---|");
    for n in ["03", "04", "05"] {
        let problem = LoadedProblem::read(&root.join(format!("examples/hartlen-enf/enf{n}.toml")))?;
        let enf = as_enf(&problem)?;
        let e = &problem.experiments[0];
        let r = reduce(&enf, e.load.x(), e.load.y(), [0.2, 0.6])?;
        println!(
            "| ENF-{n} | {:.4e} | {:.0} | {:.0} at {:.3} | {:.2} | {:.3} | {:.3} |",
            r.compliance0, r.modulus, r.onset.0, r.onset.1, r.equivalent_crack, r.g_iic_beam, r.g_iic_cbbm
        );
    }
    Ok(())
}

/// The problem file's ENF model as its concrete type (models travel as trait objects).
fn as_enf(problem: &LoadedProblem) -> Result<Enf, Box<dyn std::error::Error>> {
    let mut tree = serde_json::to_value(&problem.file.experiment[0].model)?;
    tree.as_object_mut().ok_or("the model is not a table")?.remove("type");
    Ok(serde_json::from_value(tree)?)
}
