//! Problem files and identification problems, on a toy law and a toy model whose exact answer is
//! known, and every bad-input case a user can make.

use czid_core::{
    columns, CohesiveLaw, CzError, ForwardModel, Gap, LawEval, LawState, ParameterInfo, Problem, Record,
    SimulationFailure, Tangent, Traction,
};
use czid_problems::problem_file::LoadedProblem;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A linear spring that never damages.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Spring {
    stiffness: f64,
}

#[typetag::serde(name = "toy_spring")]
impl CohesiveLaw for Spring {
    fn validate(&self) -> czid_core::Result<()> {
        czid_core::error::require_positive("law toy_spring", "stiffness", self.stiffness)
    }
    fn evaluate(&self, gap: &Gap, previous: &LawState) -> LawEval {
        LawEval {
            traction: Traction::new(self.stiffness * gap[0], self.stiffness * gap[1]),
            tangent: Tangent::identity() * self.stiffness,
            state: *previous,
        }
    }
    fn fracture_energy(&self) -> [f64; 2] {
        [f64::INFINITY; 2]
    }
    fn initial_stiffness(&self) -> [f64; 2] {
        [self.stiffness; 2]
    }
    fn strength(&self) -> [f64; 2] {
        [f64::INFINITY; 2]
    }
    fn parameters(&self) -> Vec<ParameterInfo> {
        vec![ParameterInfo { name: "stiffness", value: self.stiffness, unit: "MPa/mm", meaning: "spring stiffness" }]
    }
}

/// A patch of interface of area `area` opened by the control displacement.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Patch {
    area: f64,
    max_opening: f64,
    /// A law this stiff or stiffer makes the run fail half way (MPa/mm; none by default).
    #[serde(default)]
    fails_from: Option<f64>,
}

#[typetag::serde(name = "toy_patch")]
impl ForwardModel for Patch {
    fn name(&self) -> &str {
        "toy_patch"
    }
    fn validate(&self) -> czid_core::Result<()> {
        czid_core::error::require_positive("model toy_patch", "area", self.area)
    }
    fn simulate(&self, law: &dyn CohesiveLaw) -> Result<Record, SimulationFailure> {
        let mut r =
            Record::new(&[(columns::DISPLACEMENT, "mm"), (columns::LOAD, "N"), (columns::DEBONDED_LENGTH, "mm")]);
        let mut state = law.initial_state();
        for i in 0..=20 {
            let d = self.max_opening * i as f64 / 20.0;
            let e = law.evaluate(&Gap::new(d, 0.0), &state);
            state = e.state;
            r.push(&[d, self.area * e.traction[0], d]);
            if i == 10 && self.fails_from.is_some_and(|k| law.initial_stiffness()[0] >= k) {
                let error = CzError::Simulation("no convergence half way (a test model's failure)".into());
                return Err(SimulationFailure { error, partial: r });
            }
        }
        Ok(r)
    }
}

fn problem_text(extra_param: &str) -> String {
    format!(
        r#"
[law]
type = "toy_spring"
stiffness = 50.0

[[experiment]]
name = "patch"
[experiment.data]
file = "patch.csv"
displacement = "d"
load = "P"
crack = "L"
crack_measure = "debonded_length"
[experiment.model]
type = "toy_patch"
area = 2.0
max_opening = 1.0

[[parameter]]
path = "law.stiffness"
unit = "MPa/mm"
lower = 10.0
upper = 200.0
{extra_param}

[optimizer]
type = "miga"
budget = 100
"#
    )
}

/// Data made by hand: P = 2 mm² × 80 MPa/mm × d, so the answer is stiffness = 80.
/// (A scratch folder removed when the test ends.)
fn setup_dir(name: &str, problem: &str) -> Scratch {
    let dir = Scratch(tempfile::Builder::new().prefix(&format!("czid-pf-{name}-")).tempdir().unwrap());
    let mut csv = String::from("d,P,L\n");
    for i in 0..=10 {
        let d = i as f64 / 10.0;
        csv.push_str(&format!("{d},{},{d}\n", 160.0 * d));
    }
    std::fs::write(dir.join("patch.csv"), csv).unwrap();
    std::fs::write(dir.join("problem.toml"), problem).unwrap();
    dir
}

/// A scratch folder that reads as its path and is removed when it goes out of scope.
struct Scratch(tempfile::TempDir);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        self.0.path()
    }
}

fn read(dir: &Path) -> czid_core::Result<LoadedProblem> {
    LoadedProblem::read(&dir.join("problem.toml"))
}

#[test]
fn the_known_answer_has_zero_objective_and_others_do_not() {
    let dir = setup_dir("known", &problem_text(""));
    let p = read(&dir).unwrap();
    let id = p.identification().unwrap();
    // Balanced weights: f = 1 at the initial guess.
    assert!((id.evaluate(&id.space().to_unit(&[50.0])).unwrap().value - 1.0).abs() < 1e-12);
    let at_truth = id.simulate(&[80.0]).unwrap().evaluation;
    assert!(at_truth.value < 1e-24, "{}", at_truth.value);
    let off = id.simulate(&[90.0]).unwrap().evaluation;
    assert!(off.value > 1e-3);
    // The debonded-length term fits exactly whatever the stiffness, so the load carries all misfit.
    assert_eq!(off.objectives.len(), 2);
    assert!(off.objectives[1] < 1e-24 && off.objectives[0] > 1e-3);
}

#[test]
fn bad_inputs_are_named() {
    let cases: Vec<(&str, String, &str)> = vec![
        ("typo", problem_text("scal = \"log\""), "scal"),
        (
            "inverted",
            problem_text("").replace("lower = 10.0\nupper = 200.0", "lower = 200.0\nupper = 10.0"),
            "inverted",
        ),
        ("outside", problem_text("").replace("stiffness = 50.0", "stiffness = 500.0"), "within its bounds"),
        ("unknown-law", problem_text("").replace("toy_spring\"\nstiffness", "no_such_law\"\nstiffness"), "no_such_law"),
        ("unknown-model", problem_text("").replace("toy_patch", "no_such_model"), "no_such_model"),
        ("bad-path", problem_text("").replace("law.stiffness", "law.stiffnes"), "stiffnes"),
        ("negative", problem_text("").replace("area = 2.0", "area = -2.0"), "area"),
        ("missing-file", problem_text("").replace("patch.csv", "absent.csv"), "absent.csv"),
        ("missing-column", problem_text("").replace("load = \"P\"", "load = \"Q\""), "no column `Q`"),
        // Guards against inputs that used to give a silently wrong answer.
        (
            "zero-weights",
            problem_text("")
                .replace("[optimizer]", "[objective]\nweights = { load = 0.0, debonded_length = 0.0 }\n\n[optimizer]"),
            "weight 0",
        ),
        (
            "one-row",
            problem_text("").replace("file = \"patch.csv\"", "file = \"patch.csv\"\nrange = [0.5, 0.55]"),
            "at least 2",
        ),
        ("infinite-bound", problem_text("").replace("upper = 200.0", "upper = inf"), "upper"),
        // A number written as a string inside the law: the key and its line are named.
        (
            "quoted-number",
            problem_text("").replace("stiffness = 50.0", "stiffness = \"50\""),
            "`law.stiffness`, line 4",
        ),
        (
            "subnormal-log-bound",
            problem_text("").replace("lower = 10.0\nupper = 200.0", "lower = 5e-324\nupper = 200.0\nscale = \"log\""),
            "smallest normal",
        ),
    ];
    for (name, text, expect) in cases {
        let dir = setup_dir(name, &text);
        let err: CzError = match read(&dir) {
            Err(e) => e,
            Ok(p) => p.identification().expect_err(name),
        };
        let msg = err.to_string();
        eprintln!("{name}: {msg}");
        assert!(msg.contains(expect), "{name}: `{msg}` should mention `{expect}`");
    }
}

#[test]
fn syntax_errors_give_line_and_column() {
    let dir = setup_dir("syntax", &problem_text("").replace("area = 2.0", "area = = 2.0"));
    let msg = read(&dir).unwrap_err().to_string();
    assert!(msg.contains("line") && msg.contains("column"), "{msg}");
    assert!(msg.contains("problem.toml"), "{msg}");
}

#[test]
fn identify_recovers_the_known_answer_and_writes_results() {
    use czid_problems::identify::{identify, RunOptions};
    use czid_problems::output::OutputDir;
    let dir = setup_dir("identify", &problem_text("").replace("budget = 100", "budget = 400"));
    let p = read(&dir).unwrap();
    let out = OutputDir::create(&dir.join("out"), false, false).unwrap();
    let res = identify(&p, &RunOptions::default(), &out).unwrap();
    let k = res.parameters["law.stiffness"].value;
    assert!((k - 80.0).abs() < 0.8, "identified stiffness {k}, expected 80");
    let verdict = &res.parameters["law.stiffness"].verdict;
    assert!(verdict.starts_with("determined"), "{verdict}");
    assert!(res.evaluations <= 400);
    let history = std::fs::read_to_string(out.file("history.csv")).unwrap();
    assert!(history.lines().next().unwrap().ends_with("law.stiffness (MPa/mm)"), "{history}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.file("result.json")).unwrap()).unwrap();
    for key in ["parameters", "objective", "objective_terms", "evaluations", "wall_seconds"] {
        assert!(json.get(key).is_some(), "result.json lacks `{key}`");
    }
    for f in ["history.csv", "fit.csv", "fit-load.png", "fit-debonded.png", "convergence.png"] {
        assert!(out.file(f).exists(), "{f} missing");
    }
    // Same seed, same answer.
    let out2 = OutputDir::create(&dir.join("out2"), false, false).unwrap();
    let again = identify(&p, &RunOptions::default(), &out2).unwrap();
    assert_eq!(again.parameters["law.stiffness"].value, k);
}

#[test]
fn compare_runs_every_seed_of_a_global_method_once_a_local_one_and_writes_summary() {
    use czid_problems::compare::{compare, CompareOptions};
    use czid_problems::output::OutputDir;
    let dir = setup_dir("compare", &problem_text("").replace("budget = 100", "budget = 200"));
    let p = read(&dir).unwrap();
    let out = OutputDir::create(&dir.join("out"), false, false).unwrap();
    let opts = CompareOptions {
        optimizers: vec!["miga".into(), "nelder-mead".into()],
        seeds: 2,
        budget: None,
        target: 1e-3,
        spread: None,
        resume: false,
        abort_after: None,
        progress: false,
    };
    let comparison = compare(&p, &opts, &out).unwrap();
    let runs = &comparison.runs;
    // Two MIGA seeds; Nelder–Mead draws no random numbers and runs once.
    let rows: Vec<(&str, u64)> = runs.iter().map(|r| (r.optimizer.as_str(), r.seed)).collect();
    assert_eq!(rows, [("miga", 1), ("miga", 2), ("nelder-mead", 1)]);
    assert!(runs.iter().all(|r| r.evaluations <= 200));
    let summary = std::fs::read_to_string(out.file("summary.csv")).unwrap();
    assert_eq!(summary.lines().count(), 4, "{summary}");
    // The best run is inside its own 95 % region, and the table marks every run by its objective.
    let e = comparison.equivalent.as_ref().expect("the region around the best run");
    let best = (0..runs.len()).min_by(|&a, &b| runs[a].best.total_cmp(&runs[b].best)).unwrap();
    assert!(e.inside.contains(&best) && e.threshold > runs[best].best);
    for (k, line) in summary.lines().skip(1).enumerate() {
        let inside = line.split(',').nth(6).unwrap();
        assert_eq!(inside == "yes", runs[k].best <= e.threshold, "{line}");
    }
    for f in ["convergence.csv", "convergence.png", "final_objective.png"] {
        assert!(out.file(f).exists(), "{f} missing");
    }
}

#[test]
fn overrides_replace_values_by_parameter_path() {
    let dir = setup_dir("overrides", &problem_text(""));
    let sets = vec![
        ("law.stiffness".to_string(), "80".to_string()),
        ("models.patch.area".to_string(), "2.0".to_string()),
        ("optimizer.seed".to_string(), "5".to_string()),
    ];
    let p = LoadedProblem::read_with(&dir.join("problem.toml"), &sets).unwrap();
    assert_eq!(p.file.optimizer.seed, 5);
    let id = p.identification().unwrap();
    assert_eq!(id.initial().unwrap(), vec![80.0]);
    for (key, value, expect) in [
        ("models.nope.area", "1", "no experiment named `nope`"),
        ("law.stiffness", "abc", "not a TOML value"),
        ("stiffness", "1", "paths start with"),
    ] {
        let e =
            LoadedProblem::read_with(&dir.join("problem.toml"), &[(key.into(), value.into())]).unwrap_err().to_string();
        assert!(e.contains(expect), "{key}: {e}");
    }
    // A value the file cannot take is blamed on its --set, not on a line of the rebuilt file.
    let sets = vec![
        ("law.stiffness".to_string(), "80".to_string()),
        ("models.patch.area".to_string(), "\"wide\"".to_string()),
        ("models.patch.aera".to_string(), "1.0".to_string()),
    ];
    let e = LoadedProblem::read_with(&dir.join("problem.toml"), &sets).unwrap_err().to_string();
    assert!(e.contains("--set models.patch.area=\"wide\"") && !e.contains("line"), "{e}");
    let e = LoadedProblem::read_with(&dir.join("problem.toml"), &sets[2..]).unwrap_err().to_string();
    assert!(e.contains("--set models.patch.aera=1.0") && e.contains("aera"), "{e}");
}

#[test]
fn an_interrupted_run_is_marked_partial_and_resumes_to_the_same_result() {
    use czid_problems::identify::{identify, RunOptions};
    use czid_problems::output::OutputDir;
    use std::sync::atomic::AtomicBool;
    use std::sync::Arc;
    let dir = setup_dir("resume", &problem_text("").replace("budget = 100", "budget = 400"));
    let p = read(&dir).unwrap();
    let whole =
        identify(&p, &RunOptions::default(), &OutputDir::create(&dir.join("whole"), false, false).unwrap()).unwrap();

    // Ctrl-C before the first generation ends: the run stops there, marked partial.
    let out = OutputDir::create(&dir.join("cut"), false, false).unwrap();
    let stop = RunOptions { stop: Some(Arc::new(AtomicBool::new(true))), ..RunOptions::default() };
    let cut = identify(&p, &stop, &out).unwrap();
    assert!(cut.partial && cut.evaluations < whole.evaluations);
    assert!(out.file("result.partial.json").exists() && !out.file("result.json").exists());
    let rows_before = std::fs::read_to_string(out.file("history.csv")).unwrap().lines().count();

    let out = OutputDir::create(&dir.join("cut"), false, true).unwrap();
    let resumed = identify(&p, &RunOptions { resume: true, ..RunOptions::default() }, &out).unwrap();
    assert!(!resumed.partial);
    assert!(out.file("result.json").exists() && !out.file("result.partial.json").exists());
    assert_eq!(resumed.parameters["law.stiffness"].value, whole.parameters["law.stiffness"].value);
    assert_eq!(resumed.evaluations, whole.evaluations);
    let rows_after = std::fs::read_to_string(out.file("history.csv")).unwrap().lines().count();
    assert!(rows_after > rows_before, "the resumed history lost the interrupted run's rows");
}

#[test]
fn named_optimizers_resolve_by_label_and_are_checked_when_read() {
    let alternatives = "\n[optimizers.polish]\ntype = \"levenberg-marquardt\"\nsettings = { fd_step = 1e-3 }\n";
    let dir = setup_dir("labels", &(problem_text("") + alternatives));
    let p = read(&dir).unwrap();
    let (kind, settings) = p.file.optimizer_named("polish");
    assert_eq!(kind, "levenberg-marquardt");
    assert_eq!(settings["fd_step"].as_float(), Some(1e-3));
    // The file's own optimizer by its type; any other registered name with its defaults.
    assert_eq!(p.file.optimizer_named("miga").0, "miga");
    assert_eq!(p.file.optimizer_named("nsga2"), ("nsga2".to_string(), toml::Value::Table(Default::default())));
    // A label overridden from the command line.
    let sets = vec![("optimizers.polish.settings.fd_step".to_string(), "1e-2".to_string())];
    let q = LoadedProblem::read_with(&dir.join("problem.toml"), &sets).unwrap();
    assert_eq!(q.file.optimizer_named("polish").1["fd_step"].as_float(), Some(1e-2));
    // Unknown names and settings are refused when the file is read, naming the table.
    for (text, expect) in [
        (problem_text("") + &alternatives.replace("levenberg-marquardt", "levenberg"), "[optimizers.polish]"),
        (problem_text("") + &alternatives.replace("fd_step", "fd_stepp"), "fd_stepp"),
        (problem_text("").replace("\"miga\"", "\"migga\""), "[optimizer]"),
    ] {
        let bad = setup_dir("labels-bad", &text);
        let msg = read(&bad).unwrap_err().to_string();
        assert!(msg.contains(expect), "`{msg}` should mention `{expect}`");
    }
}

#[test]
fn a_budget_that_ends_before_convergence_is_said_and_qualifies_the_verdicts() {
    use czid_problems::identify::{identify, RunOptions};
    use czid_problems::output::OutputDir;
    let dir = setup_dir("budget", &problem_text(""));
    let p = read(&dir).unwrap();
    let run = |name: &str, optimizer: &str, budget: usize| {
        let out = OutputDir::create(&dir.join(name), false, false).unwrap();
        let opts = RunOptions { optimizer: Some(optimizer.into()), budget: Some(budget), ..RunOptions::default() };
        identify(&p, &opts, &out).unwrap()
    };
    // MIGA: one generation of 100 is too few to tell; Levenberg–Marquardt: 3 evaluations end it
    // mid-step. Both say so, and every verdict is marked provisional.
    for res in [run("miga-short", "miga", 100), run("lm-short", "levenberg-marquardt", 3)] {
        assert!(!res.converged, "{}", res.optimizer);
        assert!(
            res.warnings.iter().any(|w| w.starts_with("budget exhausted before convergence")),
            "{:?}",
            res.warnings
        );
        let verdict = &res.parameters["law.stiffness"].verdict;
        assert!(verdict.ends_with("provisional: budget exhausted before convergence"), "{verdict}");
    }
    // Levenberg–Marquardt that stops on its own criterion well inside its budget converged.
    let res = run("lm-long", "levenberg-marquardt", 500);
    assert!(res.evaluations < 500 && res.converged, "{} evaluations", res.evaluations);
    assert!(!res.parameters["law.stiffness"].verdict.contains("provisional"));
}

/// A run that fails part way is scored as a broken specimen beyond its last state: each reading
/// it did not reach costs its full value (the data's load and debonded length against zero), not
/// the misfit of its last state held.
#[test]
fn a_run_that_fails_part_way_costs_every_reading_it_did_not_reach() {
    let text = problem_text("").replace("max_opening = 1.0", "max_opening = 1.0\nfails_from = 90.0");
    let dir = setup_dir("fails", &text);
    let p = read(&dir).unwrap();
    let id = p.identification().unwrap();
    let w: Vec<f64> = id.weights().iter().map(|(_, w)| *w).collect();
    let outcome = id.simulate(&[95.0]).unwrap();
    assert_eq!(outcome.failures.len(), 1, "{:?}", outcome.failures);
    assert_eq!(outcome.records["patch"].rows(), 11, "the record keeps the states the run reached");
    // By hand: readings at d = 0, 0.1, …, 1 of P = 160 d and L = d; the run reached d = 0.5 with
    // P = 2 × 95 d and L = d.
    let ds: Vec<f64> = (0..=10).map(|i| i as f64 / 10.0).collect();
    let norm = |f: &dyn Fn(f64) -> f64| ds.iter().map(|&d| f(d).powi(2)).sum::<f64>();
    let load = |d: f64| if d <= 0.5 + 1e-12 { 160.0 * d - 190.0 * d } else { 160.0 * d };
    let length = |d: f64| if d <= 0.5 + 1e-12 { 0.0 } else { d };
    let expected = w[0] * norm(&load) / norm(&|d| 160.0 * d) + w[1] * norm(&length) / norm(&|d| d);
    let f = outcome.evaluation.value;
    assert!((f / expected - 1.0).abs() < 1e-9, "{f} vs {expected}");
    // Holding the last state would have cost far less: the failing run must not look better
    // than a complete one at the same distance from the truth (stiffness 65, below the failure).
    let complete = id.simulate(&[65.0]).unwrap();
    assert!(complete.failures.is_empty());
    assert!(f > 10.0 * complete.evaluation.value, "{f} vs {}", complete.evaluation.value);
}

/// The toy problem with two measured events of the patch: its peak load (160 N at the answer,
/// stiffness 80) and the displacement at 80 N (0.5 mm at the answer).
fn with_events(extra: &str) -> String {
    problem_text("").replace(
        "max_opening = 1.0\n",
        &format!(
            "max_opening = 1.0\n\n[[experiment.event]]\nkind = \"peak_load\"\nvalue = 0.16\nunit = \"kN\"\n\n\
             [[experiment.event]]\nkind = \"displacement_at_load\"\nvalue = 0.5\nunit = \"mm\"\nload = 80.0\n{extra}\n"
        ),
    )
}

#[test]
fn measured_events_are_terms_of_the_objective() {
    let dir = setup_dir("events", &with_events(""));
    let p = read(&dir).unwrap();
    let events = &p.experiments[0].events;
    assert_eq!(
        events.iter().map(|e| (e.name.as_str(), e.value)).collect::<Vec<_>>(),
        [("peak_load", 160.0), ("displacement_at_load", 0.5)]
    );
    let id = p.identification().unwrap();
    let names: Vec<String> = id.weights().into_iter().map(|(n, _)| n).collect();
    assert_eq!(names, ["F:patch", "L:patch", "E:patch:peak_load", "E:patch:displacement_at_load"]);
    // Three kinds of terms (load, debonded length, events), balanced: f = 1 at the initial guess.
    assert_eq!(id.objectives(), 3);
    assert!((id.simulate(&[50.0]).unwrap().evaluation.value - 1.0).abs() < 1e-12);
    assert!(id.simulate(&[80.0]).unwrap().evaluation.value < 1e-24);
    // Off the answer, by hand: at stiffness 100 the peak is 200 N (φ = −40/160) and 80 N is
    // reached at 0.4 mm (φ = 0.1/0.5).
    let id = {
        let dir = setup_dir(
            "events-explicit",
            &with_events("").replace(
                "[optimizer]",
                "[objective]\nweights = { load = 0.0, debonded_length = 0.0, events = 2.0 }\n\n[optimizer]",
            ),
        );
        read(&dir).unwrap().identification().unwrap()
    };
    let off = id.simulate(&[100.0]).unwrap().evaluation;
    let expected = 2.0 * (0.25f64.powi(2) + 0.2f64.powi(2));
    assert!((off.value - expected).abs() < 1e-12, "{} vs {expected}", off.value);
    assert!((off.objectives[2] - expected).abs() < 1e-12);
    // An event's own weight multiplies its α.
    let dir = setup_dir(
        "events-weight",
        &with_events("weight = 0.5").replace(
            "[optimizer]",
            "[objective]\nweights = { load = 1.0, debonded_length = 1.0, events = 2.0 }\n\n[optimizer]",
        ),
    );
    let w = read(&dir).unwrap().identification().unwrap().weights();
    assert_eq!(w[2..].iter().map(|(_, w)| *w).collect::<Vec<_>>(), [2.0, 1.0]);
}

/// An event the fit cannot meet (the displacement at 80 N read as 0.7 mm where the curve says
/// 0.5 mm) is named, with its misfit in uncertainties, and makes the verdicts provisional when its
/// stated uncertainty is small; a generous uncertainty, or none, says nothing.
#[test]
fn an_event_missed_by_more_than_three_uncertainties_is_said_and_qualifies_the_verdicts() {
    use czid_problems::identify::{identify, RunOptions};
    use czid_problems::output::OutputDir;
    let run = |name: &str, uncertainty: &str| {
        let text = with_events(uncertainty).replace("value = 0.5\n", "value = 0.7\n");
        let dir = setup_dir(name, &text);
        let p = read(&dir).unwrap();
        let out = OutputDir::create(&dir.join("out"), true, false).unwrap();
        let opts =
            RunOptions { optimizer: Some("levenberg-marquardt".into()), budget: Some(500), ..Default::default() };
        identify(&p, &opts, &out).unwrap()
    };
    let tight = run("missed-tight", "uncertainty = 0.01");
    assert!(tight.converged);
    let missed = tight.rms_error["E:patch:displacement_at_load"].value;
    assert!(missed > 0.03, "the fit meets the event ({missed} mm)");
    let said: Vec<&String> = tight.warnings.iter().filter(|w| w.starts_with("the fit misses")).collect();
    assert_eq!(said.len(), 1, "{:?}", tight.warnings);
    assert!(said[0].contains("`displacement_at_load` of `patch`"), "{}", said[0]);
    assert!(said[0].contains(&format!("{:.1} times its stated uncertainty", missed / 0.01)), "{}", said[0]);
    let verdict = &tight.parameters["law.stiffness"].verdict;
    assert!(verdict.ends_with("provisional: the fit misses a measured event"), "{verdict}");
    for (name, extra) in [("missed-loose", "uncertainty = 1.0"), ("missed-none", "")] {
        let res = run(name, extra);
        assert!(!res.warnings.iter().any(|w| w.starts_with("the fit misses")), "{name}: {:?}", res.warnings);
        assert!(!res.parameters["law.stiffness"].verdict.contains("provisional"), "{name}");
        assert_eq!(res.parameters["law.stiffness"].value, tight.parameters["law.stiffness"].value, "{name}");
    }
}

#[test]
fn bad_events_are_named_with_their_field() {
    let cases = [
        ("event-unit", with_events("").replace("unit = \"kN\"", "unit = \"mm\""), "event 1 (peak_load): `unit`"),
        ("event-load", with_events("").replace("load = 80.0\n", ""), "event 2 (displacement_at_load): `load`"),
        ("event-fraction", with_events("fraction = 0.9"), "event 2 (displacement_at_load): `fraction`"),
        ("event-kind", with_events("").replace("\"peak_load\"", "\"peak\""), "peak_load"),
        ("event-field", with_events("sigma = 1.0"), "sigma"),
        ("event-twice", with_events("name = \"peak_load\""), "two events of this experiment are named `peak_load`"),
        ("event-uncertainty", with_events("uncertainty = -0.1"), "event 2 (displacement_at_load): `uncertainty`"),
    ];
    for (name, text, expect) in cases {
        let msg = read(&setup_dir(name, &text)).unwrap_err().to_string();
        eprintln!("{name}: {msg}");
        assert!(msg.contains(expect), "{name}: `{msg}` should mention `{expect}`");
    }
}

#[test]
fn a_moment_curve_is_compared_with_the_midspan_moment_column() {
    // The toy patch has no `midspan_moment` column: a moment curve asks for it, by name.
    let text =
        problem_text("").replace("load = \"P\"", "load = \"P\"\nordinate = \"midspan_moment\"\nmoment_unit = \"kN·m\"");
    let p = read(&setup_dir("moment", &text)).unwrap();
    // Read in kN·m, held in N·mm.
    assert_eq!(p.experiments[0].load.y()[10], 160.0e6);
    let err = p.identification().unwrap_err().to_string();
    assert!(err.contains("midspan_moment"), "{err}");
    let bad = problem_text("").replace("load = \"P\"", "load = \"P\"\nordinate = \"moment\"");
    let err = read(&setup_dir("moment-bad", &bad)).unwrap_err().to_string();
    assert!(err.contains("midspan_moment"), "{err}");
}

#[test]
fn truth_files_read_events_with_noise_and_rounding() {
    let dir = Scratch(tempfile::Builder::new().prefix("czid-pf-truth-events-").tempdir().unwrap());
    let truth = "[law]\ntype = \"toy_spring\"\nstiffness = 50.0\n[model]\ntype = \"toy_patch\"\narea = 2.0\n\
                 max_opening = 1.0\n[noise]\npoints = 10\nmax_displacement = 0.8\n\
                 [[event]]\nkind = \"peak_load\"\nresolution = 30.0\n\
                 [[event]]\nkind = \"debonded_length_at_end\"\nsd = 0.01\n";
    std::fs::write(dir.join("truth.toml"), truth).unwrap();
    let t = czid_problems::synthetic::TruthFile::read(&dir.join("truth.toml")).unwrap();
    let (data, events) = t.generate_with_events().unwrap();
    assert_eq!(data.displacement.len(), 10);
    // The peak load of the run (100 N at 1 mm), read to 30 N; the debonded length (= the
    // opening) at the last displacement read, 0.8 mm, with 0.01 mm of noise.
    assert_eq!((events[0].truth, events[0].read), (100.0, 90.0));
    assert!((events[1].truth - 0.8).abs() < 1e-12);
    assert!((events[1].read - 0.8).abs() < 0.05 && events[1].read != 0.8);
    assert_eq!(events[1].spec.at, Some(0.8));
    // Reproducible.
    assert_eq!(t.generate_with_events().unwrap().1, events);
}

#[test]
fn overrides_reach_the_one_model_of_a_model_file() {
    use czid_problems::synthetic::TruthFile;
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/paper-dcb/truth.toml");
    let set = |k: &str, v: &str| vec![(k.to_string(), v.to_string())];
    let t = TruthFile::read_with(&file, &set("model.a0", "45")).unwrap();
    assert_eq!(serde_json::to_value(&t.model).unwrap()["a0"], 45.0);
    let t = TruthFile::read_with(&file, &set("law.strength_n", "20")).unwrap();
    assert_eq!(serde_json::to_value(&t.law).unwrap()["strength_n"], 20.0);
    for (key, value, expect) in [
        ("models.model.a0", "45", "its one [model] is reached as model."),
        ("model.a00", "45", "--set model.a00=45"),
        ("model.a0", "-1", "a0"),
    ] {
        let e = TruthFile::read_with(&file, &set(key, value)).err().unwrap().to_string();
        assert!(e.contains(expect), "{key}: {e}");
    }
    // A problem file has no top-level model.
    let dir = setup_dir("model-override", &problem_text(""));
    let e = LoadedProblem::read_with(&dir.join("problem.toml"), &set("model.a0", "1")).unwrap_err().to_string();
    assert!(e.contains("no top-level [model]"), "{e}");
}

/// The ENF-03 run of the speed figures (`Enf::hartlen_enf03_identified`) is the example file's
/// model at the modulus it identifies: the same specimen, mesh and end of the test.
#[test]
fn the_enf03_speed_run_is_the_example_files_model() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/hartlen-enf/enf03.toml");
    let problem = LoadedProblem::read(&file).unwrap();
    let from_file = serde_json::to_value(&*problem.file.experiment[0].model).unwrap();
    let (mut run, _) = czid_models::enf::Enf::hartlen_enf03_identified();
    run.material.e11 = from_file["material"]["e11"].as_f64().unwrap();
    let built = serde_json::to_value(&run as &dyn ForwardModel).unwrap();
    for field in ["a0", "half_span", "width", "h", "material", "mesh", "control", "effects"] {
        assert_eq!(from_file[field], built[field], "`{field}` of examples/hartlen-enf/enf03.toml");
    }
}
