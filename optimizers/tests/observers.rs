//! The history CSV has one row per iteration; the progress bar and fan-out never stop a run.

use czid_core::{Budget, Optimizer};
use czid_optimizers::testfns::by_name;
use czid_optimizers::{CsvHistory, Miga, MigaSettings, Observers, ProgressBar};

#[test]
fn history_csv_has_a_row_per_generation() {
    let dir = std::env::temp_dir().join(format!("czid-observers-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("history.csv");
    let problem = by_name("griewank3").unwrap();
    let miga = Miga::new(MigaSettings::default()).unwrap();
    let budget = Budget::evaluations(100 + 90 * 5);
    let mut csv = CsvHistory::create(&path).unwrap();
    let mut bar = ProgressBar::hidden(budget.evaluations);
    let r = miga.minimize(problem.as_ref(), &budget, 0, &mut Observers(vec![&mut csv, &mut bar])).unwrap();
    csv.finish().unwrap();
    bar.finish();
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "iteration,evaluations,failures,best_value,x0,x1,x2");
    assert_eq!(lines.len(), 1 + 6, "header + initial population + 5 generations");
    assert!(lines[6].starts_with(&format!("5,{},0,{}", r.evaluations, r.best.value)));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_progress_bar_ends_where_the_run_ended_not_at_the_budget() {
    // Levenberg–Marquardt on Rosenbrock converges long before a budget of 400.
    let problem = by_name("rosenbrock2").unwrap();
    let lm = czid_optimizers::LevenbergMarquardt::new(czid_optimizers::LocalSettings {
        tolerance: 1e-10,
        restarts: 0,
        ..Default::default()
    })
    .unwrap();
    let mut bar = ProgressBar::hidden(400);
    let r = lm.minimize(problem.as_ref(), &Budget::evaluations(400), 0, &mut bar).unwrap();
    bar.finish();
    assert!(r.evaluations < 400, "{}", r.evaluations);
    assert_eq!(bar.position(), r.evaluations);
}
