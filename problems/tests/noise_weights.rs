//! `weights = "noise"`: each term in units of its readings' noise, so that the objective is χ².
//!
//! A synthetic DCB test made by the identification's own model, with Gaussian noise of known
//! standard deviation, is scored at the true law: the residuals are then the noise draws, and the
//! objective must equal the χ² computed directly from the readings and the record, term by term.

use std::collections::BTreeMap;

use czid_core::{columns, CohesiveLaw, ForwardModel, Parameter, ParameterSpace};
use czid_models::dcb::Dcb;
use czid_models::laws::Bilinear;
use czid_problems::data::{Experiment, ReadingNoise};
use czid_problems::identification::{Identification, Setup};
use czid_problems::problem_file::LoadedProblem;
use czid_problems::synthetic::{synthesize, Noise};

const LOAD_SD: f64 = 0.4; // N
const LENGTH_SD: f64 = 0.3; // mm

fn setup() -> Setup {
    let mut d = Dcb::hartlen_dcb01();
    d.control.max_displacement = Some(16.0);
    d.control.output_points = 80;
    let law: Box<dyn CohesiveLaw> = Box::new(Bilinear::bk(1e5, 30.0, 30.0, 0.8, 2.0, 2.0).unwrap());
    let models: BTreeMap<String, Box<dyn ForwardModel>> =
        [("dcb".to_string(), Box::new(d) as Box<dyn ForwardModel>)].into();
    Setup { law, models }
}

fn identification(noise: ReadingNoise) -> (Identification, f64) {
    let setup = setup();
    let record = setup.models["dcb"].simulate(setup.law.as_ref()).unwrap();
    let data =
        synthesize(&record, 200, Some(16.0), &Noise { load_sd: LOAD_SD, length_sd: LENGTH_SD, seed: 5 }).unwrap();
    // χ² straight from the readings and the record, interpolated as the objective does.
    let load = record.curve(columns::DISPLACEMENT, columns::LOAD).unwrap();
    let length = record.curve(columns::DISPLACEMENT, columns::DEBONDED_LENGTH).unwrap();
    let chi2: f64 = data
        .displacement
        .iter()
        .zip(data.load.iter().zip(&data.debonded_length))
        .map(|(&d, (&p, &l))| ((p - load.at(d)) / LOAD_SD).powi(2) + ((l - length.at(d)) / LENGTH_SD).powi(2))
        .sum();
    let experiment = Experiment { noise, ..data.experiment("dcb").unwrap() };
    let space = ParameterSpace::new(vec![
        Parameter::new("law.strength_n", "MPa", 5.0, 80.0).log(),
        Parameter::new("law.g_ic", "N/mm", 0.2, 2.0),
    ])
    .unwrap();
    let mut id = Identification::new(setup, space, &[experiment], true).unwrap();
    id.noise_weights().unwrap();
    (id, chi2)
}

#[test]
fn with_the_stated_noise_the_objective_is_chi_squared() {
    let (id, chi2) = identification(ReadingNoise { load: Some(LOAD_SD), debonded_length: Some(LENGTH_SD) });
    let f = id.simulate(&[30.0, 0.8]).unwrap().evaluation.value;
    println!("f = {f:.6}, χ² = {chi2:.6}");
    assert!((f - chi2).abs() <= 1e-9 * chi2, "f = {f}, χ² = {chi2}");
    // The residuals are 200 load and 200 length draws (a length of zero, before the crack grows,
    // is read without noise): χ² is near the number of noisy readings.
    assert!((150.0..600.0).contains(&chi2), "χ² = {chi2}");
    // Away from the truth it grows.
    assert!(id.simulate(&[30.0, 0.9]).unwrap().evaluation.value > 2.0 * f);
}

#[test]
fn without_a_stated_noise_the_noise_is_estimated_from_the_readings() {
    let (stated, _) = identification(ReadingNoise { load: Some(LOAD_SD), debonded_length: None });
    let (estimated, _) = identification(ReadingNoise::default());
    let (ws, we) = (stated.weights(), estimated.weights());
    // The load's weight is ||y||²/σ²: the estimate of σ from the readings' scatter is within a
    // third of the truth here (200 readings of a smooth curve).
    let ratio = (ws[0].1 / we[0].1).sqrt();
    println!("estimated σ / stated σ = {ratio:.3}");
    assert!((0.67..1.5).contains(&ratio), "estimated σ / stated σ = {ratio}");
    assert_eq!(ws[1].1, we[1].1, "the length's weight is estimated in both");
}

#[test]
fn noise_weights_need_every_events_uncertainty_and_a_positive_stated_noise() {
    let dir = std::env::temp_dir().join(format!("czid-noise-weights-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/frp-beam");
    let text = std::fs::read_to_string(root.join("identify.toml"))
        .unwrap()
        .replace("file = \"identify/synthetic.csv\"", &format!("file = {:?}", root.join("identify/synthetic.csv")))
        .replace("weights = \"balanced\"", "weights = \"noise\"");
    // As the file stands (every event has an uncertainty) it reads.
    let path = dir.join("noise.toml");
    std::fs::write(&path, &text).unwrap();
    LoadedProblem::read(&path).unwrap().identification().unwrap();
    // Without the onset's uncertainty, the error names the event and the fix.
    let first = text.find("uncertainty = ").unwrap();
    let line_end = first + text[first..].find('\n').unwrap();
    std::fs::write(&path, format!("{}{}", &text[..first], &text[line_end..])).unwrap();
    let err = LoadedProblem::read(&path).unwrap().identification().unwrap_err().to_string();
    assert!(err.contains("debonded_length_at_onset") && err.contains("uncertainty"), "{err}");
    // A stated noise must be a positive number.
    let bad = text.replace("load = \"load_N\"", "load = \"load_N\"\nload_noise = -5.0");
    std::fs::write(&path, bad).unwrap();
    let err = LoadedProblem::read(&path).map(|_| ()).unwrap_err().to_string();
    assert!(err.contains("load_noise"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
