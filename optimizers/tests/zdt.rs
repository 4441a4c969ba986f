//! NSGA-II on ZDT1–3 (30 variables, population 100, 200 generations) against pymoo's
//! reference IGD (0.00445, 0.00441, 0.00549): the median over 10 seeds must be within 1.5×.

use czid_core::{Budget, NoObserver, Optimizer};
use czid_optimizers::metrics::{hypervolume_2d, igd};
use czid_optimizers::testfns::{zdt_front, Zdt, ZdtKind};
use czid_optimizers::{Nsga2, Nsga2Settings};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    0.5 * (v[(v.len() - 1) / 2] + v[v.len() / 2])
}

/// IGD and hypervolume of the final front for seeds 0..10.
fn study(kind: ZdtKind) -> (Vec<f64>, Vec<f64>) {
    let problem = Zdt::new(kind, 30).unwrap();
    let reference = zdt_front(kind, 100);
    let nsga2 = Nsga2::new(Nsga2Settings::default()).unwrap();
    // 100 initial + 200 generations of 100 children.
    let budget = Budget::evaluations(100 + 200 * 100);
    (0..10u64)
        .map(|seed| {
            let r = nsga2.minimize(&problem, &budget, seed, &mut NoObserver).unwrap();
            assert_eq!(r.evaluations, budget.evaluations);
            let front: Vec<[f64; 2]> = r.pareto.iter().map(|(_, e)| [e.objectives[0], e.objectives[1]]).collect();
            (igd(&front, &reference), hypervolume_2d(&front, [1.0, 1.0]))
        })
        .unzip()
}

#[test]
fn zdt1_igd_and_hypervolume() {
    let (igds, hvs) = study(ZdtKind::Zdt1);
    let (m, h) = (median(igds), median(hvs));
    eprintln!("ZDT1 median IGD {m:.5} (pymoo 0.00445), median HV {h:.4}");
    assert!(m <= 1.5 * 0.00445, "ZDT1 median IGD {m}");
    assert!(h >= 0.65, "ZDT1 median hypervolume {h}");
}

#[test]
fn zdt2_igd() {
    let m = median(study(ZdtKind::Zdt2).0);
    eprintln!("ZDT2 median IGD {m:.5} (pymoo 0.00441)");
    assert!(m <= 1.5 * 0.00441, "ZDT2 median IGD {m}");
}

#[test]
fn zdt3_igd() {
    let m = median(study(ZdtKind::Zdt3).0);
    eprintln!("ZDT3 median IGD {m:.5} (pymoo 0.00549)");
    assert!(m <= 1.5 * 0.00549, "ZDT3 median IGD {m}");
}
