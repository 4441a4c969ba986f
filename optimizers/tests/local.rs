//! Local methods reach Rosenbrock's minimum (1, …, 1) to 1e-8, on a wide box, on a box with
//! the minimum well inside, and on a box whose upper corner is the minimum.

use czid_core::{Budget, NoObserver};
use czid_optimizers::testfns::{Function, TestFunction};
use czid_optimizers::{optimizer_from_config, LocalOptimizer, LocalSettings, NelderMead};

const METHODS: [&str; 4] = ["nelder-mead", "lbfgs", "gauss-newton", "levenberg-marquardt"];

fn error_at(method: &str, problem: &TestFunction, start: &[f64], budget: usize) -> (f64, usize) {
    let mut t = toml::Table::new();
    t.insert("start".into(), toml::Value::Array(start.iter().map(|&v| toml::Value::Float(v)).collect()));
    let opt = optimizer_from_config(method, &toml::Value::Table(t)).unwrap();
    let r = opt.minimize(problem, &Budget::evaluations(budget), 0, &mut NoObserver).unwrap();
    let err = r.best_x.iter().map(|x| (x - 1.0).abs()).fold(0.0, f64::max);
    (err, r.evaluations)
}

fn check(problem: &TestFunction, start: &[f64], label: &str) {
    for m in METHODS {
        let (err, evals) = error_at(m, problem, start, 20_000);
        eprintln!("{label:<28} {m:<20} max|x−1| = {err:.2e} in {evals} evaluations");
        assert!(err <= 1e-8, "{m} on {label}: error {err:e}");
    }
}

#[test]
fn rosenbrock_wide_box() {
    let p = TestFunction::new(Function::Rosenbrock, 2).unwrap();
    check(&p, &[-1.2, 1.0], "2-D [-5,10]² from (-1.2,1)");
    let p4 = TestFunction::new(Function::Rosenbrock, 4).unwrap();
    check(&p4, &[0.0; 4], "4-D [-5,10]⁴ from 0");
}

#[test]
fn rosenbrock_optimum_inside_bounds() {
    let p = TestFunction::new(Function::Rosenbrock, 2).unwrap().with_bounds(-1.5, 2.0).unwrap();
    check(&p, &[-1.2, 1.0], "2-D [-1.5,2]² (inside)");
}

#[test]
fn rosenbrock_optimum_at_bounds() {
    let p = TestFunction::new(Function::Rosenbrock, 2).unwrap().with_bounds(-2.0, 1.0).unwrap();
    check(&p, &[-1.2, 0.5], "2-D [-2,1]² (at the corner)");
}

#[test]
fn local_method_starts_from_a_given_point() {
    let p = TestFunction::new(Function::Rosenbrock, 2).unwrap();
    let nm = NelderMead::new(LocalSettings::default()).unwrap();
    let r = nm.minimize_from(&p, &Budget::evaluations(3000), &[0.9, 0.8], &mut NoObserver).unwrap();
    assert!(r.best.value < 1e-12, "{}", r.best.value);
}

/// Budgets smaller than a method's first batch (Nelder–Mead's initial simplex, a finite-difference
/// gradient) and targets met within it end the run cleanly, never beyond the budget.
#[test]
fn tiny_budgets_and_early_targets_end_cleanly() {
    let p = TestFunction::new(Function::Rosenbrock, 4).unwrap();
    for m in METHODS {
        let opt = optimizer_from_config(m, &toml::Value::Table(toml::Table::new())).unwrap();
        for budget in 1..=7 {
            let r = opt.minimize(&p, &Budget::evaluations(budget), 0, &mut NoObserver).unwrap();
            assert!(r.evaluations <= budget, "{m}: {} evaluations for a budget of {budget}", r.evaluations);
            assert!(r.evaluations >= 1, "{m}: no evaluation for a budget of {budget}");
        }
        // Any value meets this target: the run stops after its first batch of evaluations.
        let early = Budget { evaluations: 1000, target: Some(f64::INFINITY) };
        let r = opt.minimize(&p, &early, 0, &mut NoObserver).unwrap();
        assert!(r.evaluations <= 9, "{m}: {} evaluations past a target met at once", r.evaluations);
    }
}
