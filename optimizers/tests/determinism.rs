//! Same seed ⇒ bit-identical results with 1 and 2 threads, for every optimizer.

mod common;

use common::{with_threads, Flaky};
use czid_core::{Budget, NoObserver, OptimizationResult, Problem};
use czid_optimizers::optimizer_from_config;
use czid_optimizers::testfns::{by_name, Zdt, ZdtKind};

fn run(name: &str, settings: &str, problem: &dyn Problem, budget: usize, threads: usize) -> OptimizationResult {
    let settings: toml::Value = toml::from_str(settings).unwrap();
    let opt = optimizer_from_config(name, &settings).unwrap();
    with_threads(threads, || opt.minimize(problem, &Budget::evaluations(budget), 42, &mut NoObserver).unwrap())
}

fn assert_bit_identical(a: &OptimizationResult, b: &OptimizationResult) {
    // Compare through the bits so that NaN placeholders compare too.
    let bits = |r: &OptimizationResult| {
        let mut v: Vec<u64> = r.best_x.iter().map(|x| x.to_bits()).collect();
        v.push(r.best.value.to_bits());
        v.extend(r.history.iter().flat_map(|&(n, f)| [n as u64, f.to_bits()]));
        v.extend(
            r.pareto.iter().flat_map(|(x, e)| x.iter().chain(&e.objectives).map(|v| v.to_bits()).collect::<Vec<_>>()),
        );
        v.extend([r.evaluations as u64, r.failures as u64]);
        v
    };
    assert_eq!(bits(a), bits(b));
}

fn check(name: &str, settings: &str, problem: &dyn Problem, budget: usize) -> OptimizationResult {
    let one = run(name, settings, problem, budget, 1);
    let two = run(name, settings, problem, budget, 2);
    assert_bit_identical(&one, &two);
    assert!(one.evaluations <= budget && one.evaluations > 0, "{name}: {} evaluations", one.evaluations);
    one
}

#[test]
fn population_methods_are_thread_count_independent_with_failures() {
    let p = Flaky::rastrigin(6);
    for (name, settings) in [
        ("miga", ""),
        ("ga", ""),
        ("miga", "topology = \"random\"\nemigrants = \"random\"\nreplacement = \"random\"\nencoding = \"gray\""),
    ] {
        let r = check(name, settings, &p, 3000);
        assert!(r.failures > 0, "{name}: the flaky problem should fail sometimes");
        assert!(r.best.value < 1e29 && r.best_x[0] <= 4.0 && r.best_x[0] >= -4.5);
    }
    let r = check("nsga2", "", &p, 2000);
    assert!(r.failures > 0);
}

#[test]
fn nsga2_is_thread_count_independent_on_zdt() {
    let p = Zdt::new(ZdtKind::Zdt1, 10).unwrap();
    let r = check("nsga2", "population = 40", &p, 2000);
    assert!(!r.pareto.is_empty());
}

#[test]
fn local_methods_are_thread_count_independent() {
    let ras = by_name("rastrigin4").unwrap();
    let rosen = by_name("rosenbrock3").unwrap();
    check("nelder-mead", "", ras.as_ref(), 1500);
    check("lbfgs", "", ras.as_ref(), 1500);
    check("lbfgs", "differences = \"forward\"", rosen.as_ref(), 1500);
    check("gauss-newton", "", rosen.as_ref(), 500);
    check("levenberg-marquardt", "", rosen.as_ref(), 500);
    check("hybrid", "local_fraction = 0.3", ras.as_ref(), 2000);
}
