//! Settings: documented defaults, unknown keys rejected, invalid values named.

use czid_core::{Budget, CzError, NoObserver};
use czid_optimizers::testfns::by_name;
use czid_optimizers::{optimizer_from_config, optimizer_from_table, MigaSettings, REGISTRY};

fn table(s: &str) -> toml::Value {
    toml::from_str(s).unwrap()
}

fn err_of(name: &str, s: &str) -> CzError {
    optimizer_from_config(name, &table(s)).err().expect("should be rejected")
}

#[test]
fn every_registered_name_builds_with_defaults() {
    for entry in REGISTRY {
        let opt = optimizer_from_config(entry.name, &table("")).unwrap();
        assert_eq!(opt.name(), entry.name);
    }
    assert_eq!(optimizer_from_config("lm", &table("")).unwrap().name(), "levenberg-marquardt");
}

#[test]
fn isight_defaults() {
    let s = MigaSettings::default();
    assert_eq!((s.islands, s.sub_population, s.elite, s.migration_interval), (10, 10, 1, 5));
    assert_eq!(
        (s.crossover_rate, s.mutation_rate, s.migration_rate, s.relative_tournament_size),
        (1.0, 0.01, 0.5, 0.5)
    );
    assert_eq!((s.tournament_size(), s.migrants()), (5, 5));
}

#[test]
fn invalid_settings_name_the_setting() {
    match err_of("miga", "mutation_rate = 1.5") {
        CzError::InvalidParameter { name, .. } => assert_eq!(name, "mutation_rate"),
        e => panic!("{e}"),
    }
    match err_of("ga", "population = 1") {
        CzError::InvalidParameter { name, owner, .. } => {
            assert_eq!((name.as_str(), owner.as_str()), ("population", "optimizer ga"))
        }
        e => panic!("{e}"),
    }
    match err_of("nsga2", "population = 30") {
        CzError::InvalidParameter { name, .. } => assert_eq!(name, "population"),
        e => panic!("{e}"),
    }
    match err_of("miga", "bits_per_gene = 60") {
        CzError::InvalidParameter { name, .. } => assert_eq!(name, "bits_per_gene"),
        e => panic!("{e}"),
    }
    let unknown = err_of("miga", "islandz = 3").to_string();
    assert!(unknown.contains("islandz"), "{unknown}");
    let bad_type = err_of("nelder-mead", "tolerance = \"small\"").to_string();
    assert!(bad_type.contains("tolerance") || bad_type.contains("string"), "{bad_type}");
    assert!(optimizer_from_config("simplex", &table("")).err().unwrap().to_string().contains("miga"));
    assert!(optimizer_from_table(&table("islands = 3")).is_err());
    let hybrid = optimizer_from_table(&table("type = \"hybrid\"\nlocal = { type = \"miga\" }"));
    assert!(hybrid.is_err(), "a global method is not a local one");
}

#[test]
fn problem_files_build_optimizers_by_type() {
    let opt = optimizer_from_table(&table(
        "type = \"miga\"\nislands = 4\nsub_population = 6\ntopology = \"fully-connected\"\nreplacement = \"worst-if-better\"",
    ))
    .unwrap();
    let p = by_name("griewank4").unwrap();
    let r = opt.minimize(p.as_ref(), &Budget::evaluations(500), 3, &mut NoObserver).unwrap();
    assert!(r.evaluations <= 500 && r.best.value.is_finite());
}

#[test]
fn too_small_budgets_and_bad_starts_are_errors_not_panics() {
    let p = by_name("rastrigin3").unwrap();
    let miga = optimizer_from_config("miga", &table("")).unwrap();
    assert!(miga.minimize(p.as_ref(), &Budget::evaluations(50), 0, &mut NoObserver).is_err());
    let nm = optimizer_from_config("nelder-mead", &table("start = [1.0]")).unwrap();
    assert!(nm.minimize(p.as_ref(), &Budget::evaluations(50), 0, &mut NoObserver).is_err());
    // Gauss–Newton on a problem without residuals stops gracefully, spending little.
    let gn = optimizer_from_config("gauss-newton", &table("")).unwrap();
    let r = gn.minimize(p.as_ref(), &Budget::evaluations(50), 0, &mut NoObserver).unwrap();
    assert!(r.evaluations <= 50);
}

#[test]
fn budget_target_stops_early() {
    let p = by_name("rosenbrock2").unwrap();
    let lm = optimizer_from_config("lm", &table("")).unwrap();
    let budget = Budget { evaluations: 10_000, target: Some(1e-6) };
    let r = lm.minimize(p.as_ref(), &budget, 0, &mut NoObserver).unwrap();
    assert!(r.best.value <= 1e-6 && r.evaluations < 1000, "{} {}", r.best.value, r.evaluations);
}
