//! A run stopped at a checkpoint and resumed ends exactly as an uninterrupted run.

mod common;

use common::{Flaky, StopAt};
use czid_core::{Budget, NoObserver, Optimizer, Problem};
use czid_optimizers::checkpoint::resume_from_file;
use czid_optimizers::observers::Observers;
use czid_optimizers::testfns::{Zdt, ZdtKind};
use czid_optimizers::{optimizer_from_config, CheckpointWriter};

fn temp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("czid-resume-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join("state.json")
}

fn stop_and_resume(opt: &dyn Optimizer, problem: &dyn Problem, budget: usize, stop_at: usize) {
    let budget = Budget::evaluations(budget);
    let full = opt.minimize(problem, &budget, 7, &mut NoObserver).unwrap();

    // Stopped by an observer after iteration `stop_at`, checkpointed every iteration.
    let path = temp(opt.name());
    let mut writer = CheckpointWriter::new(&path, 1).unwrap();
    let mut stop = StopAt(stop_at);
    let partial = opt.minimize(problem, &budget, 7, &mut Observers(vec![&mut writer, &mut stop])).unwrap();
    assert!(partial.evaluations < full.evaluations);
    let resumed = resume_from_file(opt, problem, &budget, &path, &mut NoObserver).unwrap();
    assert_eq!(resumed, full, "{}: observer stop", opt.name());

    // Stopped by a smaller budget (a generation limit), then given the full budget.
    let mut writer = CheckpointWriter::new(&path, 1).unwrap();
    let short = Budget::evaluations(budget.evaluations / 2);
    opt.minimize(problem, &short, 7, &mut writer).unwrap();
    let resumed = resume_from_file(opt, problem, &budget, &path, &mut NoObserver).unwrap();
    assert_eq!(resumed, full, "{}: budget stop", opt.name());
    std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
}

#[test]
fn miga_and_ga_resume_exactly() {
    let p = Flaky::rastrigin(5);
    let empty = toml::Value::Table(Default::default());
    stop_and_resume(optimizer_from_config("miga", &empty).unwrap().as_ref(), &p, 3000, 7);
    stop_and_resume(optimizer_from_config("ga", &empty).unwrap().as_ref(), &p, 3000, 7);
}

#[test]
fn nsga2_resumes_exactly() {
    let p = Zdt::new(ZdtKind::Zdt3, 12).unwrap();
    let empty = toml::Value::Table(Default::default());
    stop_and_resume(optimizer_from_config("nsga2", &empty).unwrap().as_ref(), &p, 4000, 9);
}

#[test]
fn hybrid_resumes_exactly_in_either_phase() {
    let p = Flaky::rastrigin(4);
    let settings: toml::Value = toml::from_str(
        "global = { type = \"miga\" }\nlocal = { type = \"levenberg-marquardt\" }\nlocal_fraction = 0.3",
    )
    .unwrap();
    let hybrid = optimizer_from_config("hybrid", &settings).unwrap();
    let budget = Budget::evaluations(2000);
    let full = hybrid.minimize(&p, &budget, 3, &mut NoObserver).unwrap();
    // The global phase (MIGA, 1400 evaluations) has 14 generations: stopped in it, then in the
    // polish.
    for stop_at in [6, 17] {
        let path = temp(&format!("hybrid-{stop_at}"));
        let mut writer = CheckpointWriter::new(&path, 1).unwrap();
        let mut stop = StopAt(stop_at);
        let partial = hybrid.minimize(&p, &budget, 3, &mut Observers(vec![&mut writer, &mut stop])).unwrap();
        assert!(partial.evaluations < full.evaluations, "stopped at {stop_at}");
        let state = std::fs::read_to_string(&path).unwrap();
        let phase = if stop_at < 14 { "\"phase\":\"global\"" } else { "\"phase\":\"local\"" };
        assert!(state.contains(phase), "stopped at {stop_at}: {}", &state[..60.min(state.len())]);
        let resumed = resume_from_file(hybrid.as_ref(), &p, &budget, &path, &mut NoObserver).unwrap();
        assert_eq!(resumed, full, "hybrid stopped at iteration {stop_at}");
        std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
    }
}

#[test]
fn resume_rejects_foreign_state() {
    let p = Flaky::rastrigin(5);
    let empty = toml::Value::Table(Default::default());
    let miga = optimizer_from_config("miga", &empty).unwrap();
    let nsga2 = optimizer_from_config("nsga2", &empty).unwrap();
    let path = temp("foreign");
    let mut writer = CheckpointWriter::new(&path, 1).unwrap();
    miga.minimize(&p, &Budget::evaluations(200), 1, &mut writer).unwrap();
    let err = resume_from_file(nsga2.as_ref(), &p, &Budget::evaluations(400), &path, &mut NoObserver).unwrap_err();
    assert!(err.to_string().contains("checkpoint"), "{err}");
    let lm = optimizer_from_config("lm", &empty).unwrap();
    assert!(resume_from_file(lm.as_ref(), &p, &Budget::evaluations(400), &path, &mut NoObserver).is_err());
    std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
}
