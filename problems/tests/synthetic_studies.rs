//! The synthetic studies' data against the identifications that fit them: the mesh a problem
//! file identifies with must not bias what its data, made on a finer mesh, can show.

use std::path::Path;

use czid_core::{columns, Curve, Record};
use czid_problems::problem_file::LoadedProblem;
use czid_problems::synthetic::TruthFile;

fn col<'a>(r: &'a Record, c: &str) -> &'a [f64] {
    r.column(c).unwrap()
}

/// The loads of `coarse` interpolated at the abscissae of `fine` (those inside its range): the
/// largest difference (N), where (mm), and how many abscissae were compared. An MMB's recorded
/// displacement excludes the lever's compliance, which depends on the mesh, so the runs'
/// abscissae differ.
fn largest_load_difference(fine: &Record, coarse: &Record) -> (f64, f64, usize) {
    let (xf, pf) = (col(fine, columns::DISPLACEMENT), col(fine, columns::LOAD));
    let curve = Curve::from_path(col(coarse, columns::DISPLACEMENT), col(coarse, columns::LOAD)).unwrap();
    let (lo, hi) = (curve.x()[0], curve.x_max());
    let mut worst = (0.0f64, 0.0, 0);
    for (&x, &p) in xf.iter().zip(pf).filter(|(x, _)| (lo..=hi).contains(*x)) {
        let d = (curve.at(x) - p).abs();
        worst.2 += 1;
        if d > worst.0 {
            (worst.0, worst.1) = (d, x);
        }
    }
    worst
}

/// `examples/mixed-mode-synthetic` makes its MMB data with the beam model on a finer mesh
/// (`truth-mmb.toml`: 0.1 mm interface and 0.5 mm arm elements, 200 outputs) than it identifies
/// with (`problem.toml`: 0.2 and 1 mm, 100 outputs). At the truth's law the identification's loads
/// must stay within the data's load noise of the data mesh's. The ENF files take one beam element
/// per interface element; the MMB's mode I part has a shorter process zone, and with one its
/// loads move by about twice the noise (printed).
#[test]
fn the_mixed_mode_studys_mmb_mesh_reproduces_its_data_mesh_within_the_load_noise() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/mixed-mode-synthetic");
    let truth = TruthFile::read(&dir.join("truth-mmb.toml")).unwrap();
    let identification = |overrides: &[(String, String)]| {
        let problem = LoadedProblem::read_with(&dir.join("problem.toml"), overrides).unwrap();
        let entry = problem
            .file
            .experiment
            .into_iter()
            .find(|e| e.name.as_deref() == Some("mmb"))
            .expect("an experiment `mmb`");
        entry.model.simulate(truth.law.as_ref()).unwrap_or_else(|f| panic!("{}", f.error))
    };
    let data = truth.model.simulate(truth.law.as_ref()).unwrap_or_else(|f| panic!("{}", f.error));
    let peak = col(&data, columns::LOAD).iter().fold(0.0f64, |m, v| m.max(*v));
    let (worst, at, compared) = largest_load_difference(&data, &identification(&[]));
    let one = [("models.mmb.mesh.interface_subdivision".to_string(), "1".to_string())];
    let (worst_one, at_one, _) = largest_load_difference(&data, &identification(&one));
    let sd = truth.noise.load_sd;
    println!(
        "largest load difference from the data's mesh: {worst:.3} N at {at:.2} mm ({:.1e} of the {peak:.1} N peak); \
         with one beam element per interface element {worst_one:.3} N at {at_one:.2} mm; load noise {sd} N",
        worst / peak
    );
    assert!(sd > 0.0, "the truth file's load noise");
    // The data's 200 outputs, bar the last few the coarse run may not reach.
    assert!(compared >= 190, "only {compared} abscissae compared");
    assert!(worst <= sd, "the identification's mesh moves the load by {worst} N at {at} mm");
}
