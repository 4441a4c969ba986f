//! Fuzzing of the two readers a user feeds by hand: problem files (TOML) and test data (CSV).
//!
//! Each reader gets 10 000 generated inputs from a fixed seed (the same inputs on every run and
//! machine, so a failure reproduces). A reader must answer every one with a value or an error
//! that names something, never a panic; no `catch_unwind` hides one. The problem-file cases
//! start from the bundled examples (every law and model type, every key they hold or default)
//! and mutate keys, values, tables and text; a check at the end asserts that every key was
//! mutated at least once. The CSV cases draw headers, cells and reading options from pools of
//! valid and hostile values, and every accepted file is checked for what the reader promises
//! (finite values, strictly increasing displacements, curves of equal length).

use czid_core::ParameterSpace;
use czid_models::enf::Enf;
use czid_models::laws::{Bilinear, Bridging, Exponential};
use czid_problems::data::{CrackMeasure, ExperimentSpec, ForceUnit, LengthUnit};
use czid_problems::problem_file::LoadedProblem;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use toml::Value;

const CASES: usize = 10_000;

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples")
}

/// A step of a path into a TOML document.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Step {
    Key(String),
    Index(usize),
}

type KeyPath = Vec<Step>;

/// Every path in `v` (tables, arrays and leaves), depth first.
fn paths(v: &Value, at: &mut KeyPath, out: &mut Vec<KeyPath>) {
    match v {
        Value::Table(t) => {
            for (k, child) in t {
                at.push(Step::Key(k.clone()));
                out.push(at.clone());
                paths(child, at, out);
                at.pop();
            }
        }
        Value::Array(a) => {
            for (i, child) in a.iter().enumerate() {
                at.push(Step::Index(i));
                out.push(at.clone());
                paths(child, at, out);
                at.pop();
            }
        }
        _ => {}
    }
}

fn node<'a>(v: &'a mut Value, path: &[Step]) -> Option<&'a mut Value> {
    path.iter().try_fold(v, |n, s| match s {
        Step::Key(k) => n.get_mut(k.as_str()),
        Step::Index(i) => n.get_mut(*i),
    })
}

/// A key path without array indices, e.g. `experiment.model.mesh.arm_element` (what coverage
/// counts: one key of the file format, whichever experiment or parameter holds it).
fn key_name(path: &[Step]) -> String {
    path.iter()
        .filter_map(|s| match s {
            Step::Key(k) => Some(k.as_str()),
            Step::Index(_) => None,
        })
        .collect::<Vec<_>>()
        .join(".")
}

/// A hostile or ordinary TOML value.
fn value(rng: &mut ChaCha8Rng) -> Value {
    const FLOATS: [f64; 14] = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.5,
        1e-300,
        5e-324,
        1e300,
        f64::MAX,
        -f64::MAX,
        f64::MIN_POSITIVE,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    const STRINGS: [&str; 12] = [
        "",
        "x",
        "dcb",
        "bilinear",
        "log",
        "balanced",
        "crack_length",
        "mm",
        "../../no/such/file.csv",
        "ünïcödé ✓",
        "levenberg-marquardt",
        "type",
    ];
    match rng.random_range(0..9) {
        0 | 1 => Value::Float(FLOATS[rng.random_range(0..FLOATS.len())]),
        2 => Value::Float(rng.random_range(-1e6..1e6)),
        3 => Value::Integer([0, 1, -1, 2, i64::MAX, i64::MIN, 100_000][rng.random_range(0..7)]),
        4 => Value::Boolean(rng.random()),
        5 => Value::String(STRINGS[rng.random_range(0..STRINGS.len())].to_string()),
        6 => Value::String("7".repeat(rng.random_range(0..3000))),
        7 => Value::Array((0..rng.random_range(0..4)).map(|_| Value::Float(rng.random_range(-10.0..10.0))).collect()),
        _ => Value::Table(toml::Table::new()),
    }
}

/// Applies one random mutation to `doc`; returns the key it touched.
fn mutate(doc: &mut Value, all: &[KeyPath], rng: &mut ChaCha8Rng) -> Option<String> {
    let path = &all[rng.random_range(0..all.len())];
    let name = key_name(path);
    let (last, parent) = path.split_last()?;
    match rng.random_range(0..10) {
        // Remove the key (or the array element).
        0 => match (node(doc, parent)?, last) {
            (Value::Table(t), Step::Key(k)) => {
                t.remove(k);
            }
            (Value::Array(a), Step::Index(i)) if *i < a.len() => {
                a.remove(*i);
            }
            _ => return None,
        },
        // An unknown key beside it.
        1 => {
            if let Value::Table(t) = node(doc, parent)? {
                t.insert("no_such_key".into(), value(rng));
            }
        }
        // Another value of the same kind scaled, or a value of any kind.
        _ => {
            let slot = node(doc, path)?;
            *slot = match slot {
                Value::Float(f) if rng.random_bool(0.3) => Value::Float(*f * rng.random_range(-3.0..3.0)),
                _ => value(rng),
            };
        }
    }
    Some(name)
}

/// Damages the text itself: a cut, a stray character, a doubled line.
fn damage(text: &str, rng: &mut ChaCha8Rng) -> String {
    let chars: Vec<char> = text.chars().collect();
    let at = rng.random_range(0..=chars.len());
    match rng.random_range(0..3) {
        0 => chars[..at].iter().collect(),
        1 => {
            let stray = ['[', ']', '=', '"', '\'', '#', '\n', '{', '.', 'é'][rng.random_range(0..10)];
            chars[..at].iter().chain(std::iter::once(&stray)).chain(&chars[at..]).collect()
        }
        _ => {
            let lines: Vec<&str> = text.lines().collect();
            let k = rng.random_range(0..lines.len().max(1));
            let mut out: Vec<&str> = lines.clone();
            if let Some(l) = lines.get(k) {
                out.insert(k, l);
            }
            out.join("\n")
        }
    }
}

/// The bundled examples as documents whose laws and models are written out in full (every key,
/// defaults included), plus variants with the laws and models no example uses.
fn seeds() -> Vec<(PathBuf, Value)> {
    let files = [
        "paper-dcb/problem.toml",
        "hartlen-dcb/dcb01.toml",
        "hartlen-dcb/joint.toml",
        "frp-pull/problem.toml",
        "frp-beam/diagnose/problem.toml",
    ];
    let mut out = Vec::new();
    for f in files {
        let path = examples().join(f);
        let problem = LoadedProblem::read(&path).unwrap_or_else(|e| panic!("{f}: {e}"));
        let mut doc: Value = toml::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        doc["law"] = Value::try_from(&problem.file.law).unwrap();
        for (i, entry) in problem.file.experiment.iter().enumerate() {
            doc["experiment"][i]["model"] = Value::try_from(&entry.model).unwrap();
        }
        out.push((path, doc));
    }
    // Laws and models without an example of their own, on the Hartlen DCB problem.
    let (path, base) = out[1].clone();
    let matrix = Bilinear::bk(1e5, 30.0, 30.0, 0.8, 2.0, 2.0).unwrap();
    let tail = Bilinear::bk(1e4, 3.0, 3.0, 1.5, 3.0, 2.0).unwrap();
    let laws: Vec<Box<dyn czid_core::CohesiveLaw>> = vec![
        Box::new(Exponential::new(30.0, 0.01, 30.0, 0.02).unwrap()),
        Box::new(Bridging::new(matrix, tail).unwrap()),
    ];
    for law in laws {
        let mut doc = base.clone();
        doc["law"] = Value::try_from(&law).unwrap();
        out.push((path.clone(), doc));
    }
    let enf: Box<dyn czid_core::ForwardModel> = Box::new(Enf::hartlen_enf03());
    let mut doc = base.clone();
    doc["experiment"][0]["model"] = Value::try_from(&enf).unwrap();
    out.push((path.clone(), doc));
    // The optional keys no example sets.
    let mut doc = base;
    let data = doc["experiment"][0]["data"].as_table_mut().unwrap();
    data.insert("range".into(), Value::Array(vec![Value::Float(0.0), Value::Float(100.0)]));
    data.insert("length_unit".into(), Value::String("mm".into()));
    data.insert("force_unit".into(), Value::String("N".into()));
    doc["objective"]["weights"] = toml::from_str::<Value>("load = 1.0\ndebonded_length = 0.5").unwrap();
    doc["optimizer"].as_table_mut().unwrap().insert("target".into(), Value::Float(1e-9));
    let polish: Value = toml::from_str("type = \"nelder-mead\"\nsettings = { restarts = 1 }").unwrap();
    let mut optimizers = toml::Table::new();
    optimizers.insert("polish".into(), polish);
    doc.as_table_mut().unwrap().insert("optimizers".into(), Value::Table(optimizers));
    out.push((path, doc));
    out
}

#[test]
fn problem_files_never_panic_and_every_key_is_fuzzed() {
    let seeds = seeds();
    let mut rng = ChaCha8Rng::seed_from_u64(20261124);
    let mut keys = BTreeSet::new();
    let mut touched = BTreeSet::new();
    let mut all_paths = Vec::new();
    for (_, doc) in &seeds {
        let mut p = Vec::new();
        paths(doc, &mut Vec::new(), &mut p);
        keys.extend(p.iter().map(|k| key_name(k)).filter(|k| !k.is_empty()));
        all_paths.push(p);
    }
    let (mut accepted, mut refused) = (0, 0);
    for case in 0..CASES {
        let s = case % seeds.len();
        let (path, seed) = &seeds[s];
        let mut doc = seed.clone();
        for _ in 0..rng.random_range(1..=3) {
            if let Some(k) = mutate(&mut doc, &all_paths[s], &mut rng) {
                touched.insert(k);
            }
        }
        let Ok(mut text) = toml::to_string(&doc) else { continue };
        if rng.random_bool(0.1) {
            text = damage(&text, &mut rng);
        }
        match LoadedProblem::parse(&text, path) {
            Ok(problem) => {
                accepted += 1;
                // What `identify` does with a file before its first simulation.
                if let Ok(setup) = problem.setup() {
                    if let Ok(space) = ParameterSpace::new(problem.file.parameter.clone()) {
                        if let Ok(x) = space.read(&setup) {
                            let _ = space.check_within(&x);
                        }
                    }
                    let _ = setup.validate();
                }
            }
            Err(e) => {
                refused += 1;
                assert!(!e.to_string().trim().is_empty(), "case {case}: an empty error message");
            }
        }
    }
    let missed: Vec<&String> = keys.difference(&touched).collect();
    assert!(missed.is_empty(), "keys never fuzzed: {missed:?}");
    // Both outcomes occur, so the generator neither breaks every file nor leaves them all valid.
    assert!(accepted > 100 && refused > 100, "{accepted} accepted, {refused} refused");
}

fn csv_text(rng: &mut ChaCha8Rng, names: &[&str]) -> String {
    const CELLS: [&str; 16] = [
        "0", "1.5", "-3", "2e1", "1e308", "1e-320", "NaN", "inf", "-inf", "", "abc", "1,5", "\"2\"", "0x10", "١", " 4 ",
    ];
    // A third of the files are clean, a third have a few bad cells, a third are anything.
    let hostility = [0.0, 0.03, 1.0][rng.random_range(0..3)];
    let mut s = String::new();
    let header: Vec<&str> = if hostility < 1.0 {
        vec!["Disp", "Force", "CrackExt"]
    } else {
        (0..rng.random_range(0..5)).map(|_| names[rng.random_range(0..names.len())]).collect()
    };
    s.push_str(&header.join(","));
    s.push('\n');
    let mut x = 0.0;
    for _ in 0..rng.random_range(0..40) {
        let width = if hostility < 1.0 { 3 } else { rng.random_range(0..6) };
        let cells: Vec<String> = (0..width)
            .map(|c| {
                if rng.random_bool(hostility * 0.5) {
                    CELLS[rng.random_range(0..CELLS.len())].to_string()
                } else if c == 0 {
                    // Mostly increasing displacements, so the checks after the first row run too.
                    x += rng.random_range(-0.1..1.0);
                    format!("{x}")
                } else {
                    format!("{}", rng.random_range(-100.0..100.0))
                }
            })
            .collect();
        s.push_str(&cells.join(","));
        if rng.random_bool(0.98) {
            s.push('\n');
        }
    }
    s
}

#[test]
fn csv_data_never_panics_and_what_is_accepted_is_sound() {
    const NAMES: [&str; 6] = ["Disp", "Force", "CrackExt", "", "x", "Disp "];
    let dir = std::env::temp_dir().join(format!("czid-fuzz-csv-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let (mut accepted, mut refused) = (0, 0);
    for case in 0..CASES {
        let text = csv_text(&mut rng, &NAMES);
        std::fs::write(dir.join("data.csv"), &text).unwrap();
        let pick = |rng: &mut ChaCha8Rng| NAMES[rng.random_range(0..NAMES.len())].to_string();
        let range = match rng.random_range(0..4) {
            0 => Some([rng.random_range(-5.0..5.0), rng.random_range(-5.0..20.0)]),
            1 => Some([f64::NAN, 1.0]),
            _ => None,
        };
        let spec = ExperimentSpec {
            file: "data.csv".into(),
            displacement: if rng.random_bool(0.8) { "Disp".into() } else { pick(&mut rng) },
            load: if rng.random_bool(0.8) { "Force".into() } else { pick(&mut rng) },
            ordinate: Default::default(),
            moment_unit: Default::default(),
            crack: rng.random_bool(0.5).then(|| pick(&mut rng)),
            crack_measure: if rng.random() { CrackMeasure::CrackLength } else { CrackMeasure::DebondedLength },
            length_unit: [LengthUnit::Millimetre, LengthUnit::Metre, LengthUnit::Inch][rng.random_range(0..3)],
            force_unit: [ForceUnit::N, ForceUnit::KiloNewton, ForceUnit::PoundForce][rng.random_range(0..3)],
            range,
            drop_non_increasing: rng.random(),
            drop_non_finite: rng.random(),
            toe_compensation: match rng.random_range(0..4) {
                0 => Some([rng.random_range(-0.2..0.6), rng.random_range(0.1..1.2)]),
                1 => Some([f64::NAN, 0.5]),
                _ => None,
            },
            load_noise: match rng.random_range(0..4) {
                0 => Some(rng.random_range(-1.0..5.0)),
                1 => Some(f64::NAN),
                _ => None,
            },
            length_noise: None,
        };
        match spec.load(&dir) {
            Ok(e) => {
                accepted += 1;
                let (x, y) = (e.load.x(), e.load.y());
                assert!(!x.is_empty() && x.len() == y.len(), "case {case}: {text:?}");
                assert!(x.windows(2).all(|w| w[1] > w[0]), "case {case}: displacements not increasing: {text:?}");
                assert!(x.iter().chain(y).all(|v| v.is_finite()), "case {case}: non-finite value: {text:?}");
                if let Some(l) = &e.debonded_length {
                    assert_eq!(l.x(), x, "case {case}");
                    assert!(l.y().iter().all(|v| v.is_finite()), "case {case}: {text:?}");
                }
            }
            Err(err) => {
                refused += 1;
                assert!(err.to_string().contains("data.csv"), "case {case}: the error does not name the file: {err}");
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    assert!(accepted > 100 && refused > 100, "{accepted} accepted, {refused} refused");
}
