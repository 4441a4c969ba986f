//! The table of the book's "Beam or continuum?" chapter: the beam model (with and without its
//! root-rotation effect) against the continuum model on the same specimens and laws, and the
//! continuum's mesh convergence and solver times.
//!
//! Run with `cargo run --release -p czid-models --example beam_or_continuum`.

use czid_core::{columns, CohesiveLaw, ForwardModel, Record};
use czid_models::continuum::SolverKind;
use czid_models::dcb::Dcb;
use czid_models::dcb_2d::Dcb2d;
use czid_models::laws::{Bilinear, StCzm};

struct Figures {
    compliance: f64,
    peak: f64,
    propagation: f64,
}

fn figures(r: &Record, at: f64) -> Figures {
    figures_until(r, at, f64::INFINITY)
}

/// Figures with the peak taken while the crack tip is short of `tip_limit` (mm): an ENF's crack
/// stops under the nose in a test, and a load that rises again once a model's crack has run past
/// it is no peak of the test.
fn figures_until(r: &Record, at: f64, tip_limit: f64) -> Figures {
    let p = r.column(columns::LOAD).unwrap();
    let d = r.column(columns::DISPLACEMENT).unwrap();
    let tip = r.column(columns::CRACK_TIP).unwrap();
    let i = (1..d.len()).rev().find(|&i| d[i - 1] <= at && at <= d[i]).unwrap_or(d.len() - 1);
    let propagation = p[i - 1] + (p[i] - p[i - 1]) * (at - d[i - 1]) / (d[i] - d[i - 1]).max(1e-300);
    let peak = p.iter().zip(tip).filter(|(_, &t)| t < tip_limit).map(|(&v, _)| v).fold(0.0, f64::max);
    Figures { compliance: d[1] / p[1], peak, propagation }
}

fn row(name: &str, f: &Figures, reference: &Figures) {
    let pct = |a: f64, b: f64| 100.0 * (a / b - 1.0);
    println!(
        "| {name} | {:.5} ({:+.2} %) | {:.3} ({:+.2} %) | {:.3} ({:+.2} %) |",
        f.compliance,
        pct(f.compliance, reference.compliance),
        f.peak,
        pct(f.peak, reference.peak),
        f.propagation,
        pct(f.propagation, reference.propagation)
    );
}

/// Root of an increasing `f` on `[lo, hi]` by bisection; `None` if it has none there or a run fails.
fn bisect(f: impl Fn(f64) -> Option<f64>, mut lo: f64, mut hi: f64) -> Option<f64> {
    if f(lo)? > 0.0 || f(hi)? < 0.0 {
        return None;
    }
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if f(mid)? < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

fn compare(title: &str, beam: Dcb, continuum: Dcb2d, law: &dyn CohesiveLaw, at: f64) {
    println!("\n{title} (propagation load at {at} mm opening)\n");
    println!("| model | initial compliance (mm/N) | peak (N) | propagation load (N) |");
    println!("|---|---|---|---|");
    let t = std::time::Instant::now();
    let (rc, stats) = continuum.simulate_with_stats(law).unwrap();
    let seconds = t.elapsed().as_secs_f64();
    let reference = figures(&rc, at);
    row("continuum (dcb_2d)", &reference, &reference);
    let base = figures(&beam.simulate(law).unwrap(), at);
    row("beam (dcb)", &base, &reference);
    let mut root = beam.clone();
    root.effects.root_compliance = beam.h / (2.0 * beam.material.e22);
    match root.simulate(law) {
        Ok(r) => row("beam + root_compliance = h/(2 E22)", &figures(&r, at), &reference),
        Err(f) => println!("| beam + root_compliance = h/(2 E22) | failed: {} | | |", f.error),
    }
    // Each compliance effect sized so that the beam's initial compliance is the continuum's.
    for effect in ["root_compliance", "shear_compliance"] {
        let set = |b: &mut Dcb, v: f64| match effect {
            "root_compliance" => b.effects.root_compliance = v,
            _ => b.effects.shear_compliance = v,
        };
        let initial = |v: f64| {
            let mut b = beam.clone();
            set(&mut b, v);
            b.control.max_displacement = Some(0.05 * beam.control.max_displacement.unwrap_or(1.0));
            b.control.output_points = 2;
            b.simulate(law).ok().map(|r| figures(&r, 0.0).compliance)
        };
        // Up to the largest root compliance the law accepts in series (beyond it the run is refused).
        let hi = match effect {
            "root_compliance" => {
                czid_models::effects::ROOT_COMPLIANCE_SHARE
                    / (2.0 * czid_models::effects::steepest_mode_one_softening(law))
            }
            _ => 2e-3,
        };
        let Some(v) = bisect(|v| initial(v).map(|c| c - reference.compliance), 0.0, hi) else {
            println!("| beam + {effect} | no size matches the continuum's compliance | | |");
            continue;
        };
        let mut b = beam.clone();
        set(&mut b, v);
        match b.simulate(law) {
            Ok(r) => row(&format!("beam + {effect} = {v:.3e} (fitted)"), &figures(&r, at), &reference),
            Err(f) => println!("| beam + {effect} = {v:.3e} (fitted) | failed: {} | | |", f.error),
        }
    }
    println!(
        "\ncontinuum run: {seconds:.2} s, {} unknowns, {} steps, {} factorisations, solver {:.2} s",
        stats.unknowns, stats.steps, stats.factorisations, stats.solver_seconds
    );
}

fn main() {
    let paper = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
    let mut beam = Dcb::paper();
    beam.control.max_displacement = Some(6.0);
    let mut cont = Dcb2d::paper();
    cont.control.max_displacement = Some(6.0);
    compare("Paper DCB, Table 3 ST-CZM", beam, cont.clone(), &paper, 5.0);

    let hartlen = Bilinear::bk(1e5, 60.0, 60.0, 0.8, 2.0, 2.0).unwrap();
    let mut beam = Dcb::hartlen_dcb01();
    beam.control.max_displacement = Some(12.0);
    let mut c = Dcb2d::hartlen_dcb01();
    c.control.max_displacement = Some(12.0);
    compare("Hartlen DCB-01, bilinear σ = 60 MPa, G_Ic = 0.8 N/mm", beam, c, &hartlen, 10.0);

    // ENF: Hartlen's ENF-03 geometry with a 40 mm crack and a short process zone.
    let enf_law = Bilinear::bk(1e6, 60.0, 150.0, 0.8, 2.0, 2.0).unwrap();
    let mut beam = czid_models::enf::Enf::hartlen_enf03();
    beam.a0 = 40.0;
    let mut c = czid_models::enf_2d::Enf2d::hartlen_enf03();
    c.a0 = 40.0;
    let rc = c.simulate(&enf_law).unwrap();
    let at = 0.98 * rc.column(columns::DISPLACEMENT).unwrap().last().unwrap();
    println!(
        "\nHartlen ENF geometry, a0 = 40 mm, bilinear τ = 150 MPa, G_IIc = 2 N/mm (load at {at:.2} mm deflection)\n"
    );
    println!("| model | initial compliance (mm/N) | peak (N) | load (N) |");
    println!("|---|---|---|---|");
    let nose = beam.half_span;
    let reference = figures_until(&rc, at, nose);
    row("continuum (enf_2d)", &reference, &reference);
    row("beam (enf)", &figures_until(&beam.simulate(&enf_law).unwrap(), at, nose), &reference);
    let mut root = beam.clone();
    root.effects.root_compliance = beam.h / (2.0 * beam.material.e22);
    match root.simulate(&enf_law) {
        Ok(r) => row("beam + root_compliance = h/(2 E22)", &figures_until(&r, at, nose), &reference),
        Err(f) => println!("| beam + root_compliance = h/(2 E22) | failed: {} | | |", f.error),
    }

    // Large displacements: Hartlen's DCB to 30 mm opening (δ/a reaches 0.3).
    let mut beam = Dcb::hartlen_dcb01();
    beam.effects.large_rotation = true;
    let mut c = Dcb2d::hartlen_dcb01();
    c.effects.large_rotation = true;
    println!("\nHartlen DCB-01 to 30 mm, large displacements in both models (load at 25 mm opening)\n");
    println!("| model | initial compliance (mm/N) | peak (N) | load (N) |");
    println!("|---|---|---|---|");
    let t = std::time::Instant::now();
    let rc = c.simulate(&hartlen).unwrap();
    let seconds = t.elapsed().as_secs_f64();
    let reference = figures(&rc, 25.0);
    row("continuum, total Lagrangian", &reference, &reference);
    row("beam, co-rotational", &figures(&beam.simulate(&hartlen).unwrap(), 25.0), &reference);
    let mut small = Dcb2d::hartlen_dcb01();
    small.effects.large_rotation = false;
    row("continuum, small strain", &figures(&small.simulate(&hartlen).unwrap(), 25.0), &reference);
    println!("\ncontinuum large-displacement run: {seconds:.2} s");

    println!("\nMesh convergence and solvers (paper DCB to 10 mm opening)\n");
    println!("| interface element (mm) | interface points | elements through the arm | solver | unknowns | stored entries | peak (N) | run (s) | solver (s) |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for (element, points, solver, thickness) in [
        (0.2, 4, SolverKind::Band, 4),
        (0.1, 0, SolverKind::Band, 4),
        (0.1, 2, SolverKind::Band, 4),
        (0.1, 4, SolverKind::Band, 4),
        (0.1, 4, SolverKind::Sparse, 4),
        (0.1, 4, SolverKind::Band, 8),
        (0.05, 4, SolverKind::Band, 4),
    ] {
        let mut m = Dcb2d::paper();
        m.mesh.interface_element = element;
        m.mesh.interface_points = points;
        m.mesh.thickness_elements = thickness;
        m.solver = solver;
        m.control.max_displacement = Some(10.0);
        let t = std::time::Instant::now();
        let (r, s) = m.simulate_with_stats(&paper).unwrap();
        let seconds = t.elapsed().as_secs_f64();
        let peak = r.column(columns::LOAD).unwrap().iter().cloned().fold(0.0, f64::max);
        println!(
            "| {element} | {points} | {thickness} | {solver:?} | {} | {} | {peak:.3} | {seconds:.2} | {:.2} |",
            s.unknowns, s.stored, s.solver_seconds
        );
    }
}
