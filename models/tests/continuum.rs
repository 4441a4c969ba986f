//! The continuum DCB against closed forms and published values it does not share code with:
//! Timoshenko's cantilever, corrected beam theory (Williams / Hashemi), NASA CompDam's DCB
//! example; energy balance and mesh convergence.

use czid_core::{columns, CohesiveLaw, ForwardModel, Record};
use czid_models::beamtest::Material;
use czid_models::continuum::grid::{rows, uniform, Grid};
use czid_models::continuum::{elasticity, path, ContinuumProblem, PathSettings, SolverKind};
use czid_models::dcb_2d::Dcb2d;
use czid_models::laws::{Bilinear, StCzm};

fn paper_law() -> StCzm {
    StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap()
}

fn peak(r: &Record) -> (f64, f64) {
    let p = r.column(columns::LOAD).unwrap();
    let d = r.column(columns::DISPLACEMENT).unwrap();
    let i = (0..p.len()).max_by(|&a, &b| p[a].total_cmp(&p[b])).unwrap();
    (p[i], d[i])
}

/// Corrected beam theory: `G = P² (a + χh)² / (b E I)` at `G = G_Ic`, with Williams' / Hashemi's
/// `χ = √(E11/(11 G13) (3 − 2 (Γ/(1+Γ))²))`, `Γ = 1.18 √(E11 E22) / G13`.
fn cbt_critical_load(m: &Material, b: f64, h: f64, a: f64, gc: f64) -> f64 {
    let gamma = 1.18 * (m.e11 * m.e22).sqrt() / m.g13;
    let chi = ((m.e11 / (11.0 * m.g13)) * (3.0 - 2.0 * (gamma / (1.0 + gamma)).powi(2))).sqrt();
    let ei = m.e11 * b * h.powi(3) / 12.0;
    (b * ei * gc).sqrt() / (a + chi * h)
}

/// Load on corrected beam theory's propagation branch at opening `delta`: `δ = 2 P (a+χh)³ /
/// (3 E I)` with `P = √(b E I G_c) / (a + χh)`.
fn cbt_propagation_load(m: &Material, b: f64, h: f64, gc: f64, delta: f64) -> f64 {
    let ei = m.e11 * b * h.powi(3) / 12.0;
    // a_eff³ · 2/(3EI) · √(bEI Gc)/a_eff = δ  ⇒  a_eff² = 3 EI δ / (2 √(bEI Gc)).
    let a_eff = (3.0 * ei * delta / (2.0 * (b * ei * gc).sqrt())).sqrt();
    (b * ei * gc).sqrt() / a_eff
}

/// Load at opening `x` on the last stretch of the path reaching it (linear between rows).
fn load_at(d: &[f64], p: &[f64], x: f64) -> f64 {
    let i = (1..d.len()).rev().find(|&i| d[i - 1] <= x && x <= d[i]).expect("the path reaches x");
    p[i - 1] + (p[i] - p[i - 1]) * (x - d[i - 1]) / (d[i] - d[i - 1])
}

#[test]
fn cantilever_tip_deflection_matches_timoshenko() {
    // The paper's arm as a cantilever: 50 mm long, 1.62 mm thick, 20 mm wide, clamped at x = 50,
    // pulled at the mid-thickness node of its free end as the DCB's hinge is.
    let m = Dcb2d::paper().material;
    let (l, h, b) = (50.0, 1.62, 20.0);
    let grid = Grid::new(uniform(0.0, l, 0.5), vec![rows(0.0, h, 4)], b);
    let nc = grid.xs.len();
    let clamp: Vec<usize> = (0..5)
        .flat_map(|r| {
            let n = grid.node(0, nc - 1, r);
            [2 * n, 2 * n + 1]
        })
        .collect();
    let tip = grid.node(0, 0, 2);
    let p = ContinuumProblem {
        grid,
        stiffness: elasticity::plane_stress(&m, "test").unwrap(),
        large: false,
        cohesive: Vec::new(),
        contact: Vec::new(),
        contact_stiffness: 0.0,
        fixed: clamp,
        control: vec![(2 * tip + 1, 1.0)],
        solver: SolverKind::Band,
    };
    let settings = PathSettings {
        target: 1.0,
        outputs: 1,
        max_dissipation: 1.0,
        max_opening_step: 1.0,
        max_iterations: 5,
        tolerance: 1e-10,
        damage_threshold: 1.0,
        crack_origin: 0.0,
        stop_tip: f64::INFINITY,
    };
    let law = paper_law();
    let (rows, _) = path::run(&p, &law, &settings).unwrap();
    let last = rows.last().unwrap();
    let compliance = last.control / last.reaction;
    let i = b * h.powi(3) / 12.0;
    let timoshenko = l.powi(3) / (3.0 * m.e11 * i) + l / (5.0 / 6.0 * m.g13 * b * h);
    let rel = compliance / timoshenko - 1.0;
    eprintln!("cantilever: {compliance:.6} mm/N vs Timoshenko {timoshenko:.6} ({:+.3} %)", 100.0 * rel);
    assert!(rel.abs() < 0.005, "tip compliance {compliance} mm/N vs Timoshenko {timoshenko}: {:.3} %", 100.0 * rel);
}

#[test]
fn paper_dcb_peak_matches_corrected_beam_theory_and_energy_balances() {
    let dcb = Dcb2d::paper();
    let law = paper_law();
    let mut run = dcb.clone();
    run.control.max_displacement = Some(6.0);
    let r = run.simulate(&law).unwrap();
    let (p, _) = peak(&r);
    let cbt = cbt_critical_load(&dcb.material, dcb.width, dcb.h, dcb.a0, law.fracture_energy()[0]);
    eprintln!("paper DCB: peak {p:.3} N vs corrected beam theory {cbt:.3} N");
    assert!((p / cbt - 1.0).abs() < 0.015, "peak {p} N vs corrected beam theory {cbt} N");
    // Energy balance at every recorded state: the external work against the arms' strain energy
    // and the interface's work, each integrated where it arises.
    let w = r.column(columns::EXTERNAL_WORK).unwrap();
    let u = r.column(columns::ELASTIC_ENERGY).unwrap();
    let d = r.column(columns::DISSIPATED_ENERGY).unwrap();
    for i in 1..w.len() {
        assert!((w[i] - u[i] - d[i]).abs() <= 0.005 * w[i], "row {i}: W {} U {} D {}", w[i], u[i], d[i]);
    }
    // The dissipated energy is G_Ic over the new crack, plus part of the process zone's.
    let grown = r.column(columns::DEBONDED_LENGTH).unwrap();
    let zone = r.column(columns::PROCESS_ZONE_LENGTH).unwrap();
    let k = w.len() - 1;
    let gb = law.fracture_energy()[0] * dcb.width;
    assert!(grown[k] > 10.0, "the crack grew {} mm", grown[k]);
    assert!(d[k] >= gb * grown[k] && d[k] <= gb * (grown[k] + zone[k]), "D {} for {} + {} mm", d[k], grown[k], zone[k]);
    // Propagation: corrected beam theory's branch at the last opening.
    let delta = r.column(columns::DISPLACEMENT).unwrap()[k];
    let load = r.column(columns::LOAD).unwrap()[k];
    let branch = cbt_propagation_load(&dcb.material, dcb.width, dcb.h, law.fracture_energy()[0], delta);
    let worst = (1..w.len()).map(|i| ((w[i] - u[i] - d[i]) / w[i]).abs()).fold(0.0, f64::max);
    eprintln!("paper DCB: {load:.3} N at {delta:.3} mm vs {branch:.3} N; worst energy imbalance {worst:.2e}");
    assert!((load / branch - 1.0).abs() < 0.03, "load {load} N at {delta} mm vs corrected beam theory {branch} N");
}

/// How a run follows a running crack: its factorisations a step, the crack grown (mm), and its
/// loads against a run with four times as many recorded states, read at this run's states
/// (relative to the peak, sorted).
struct PathCheck {
    stats: czid_models::continuum::path::Stats,
    per_step: f64,
    grown: f64,
    differences: Vec<f64>,
}

fn follow(dcb: &Dcb2d, law: &Bilinear) -> PathCheck {
    let (r, stats) = dcb.simulate_with_stats(law).unwrap();
    let per_step = stats.factorisations as f64 / stats.steps as f64;
    let grown = *r.column(columns::DEBONDED_LENGTH).unwrap().last().unwrap();
    let mut fine = dcb.clone();
    fine.control.output_points *= 4;
    let f = fine.simulate(law).unwrap();
    let (d, p) = (r.column(columns::DISPLACEMENT).unwrap(), r.column(columns::LOAD).unwrap());
    let (df, pf) = (f.column(columns::DISPLACEMENT).unwrap(), f.column(columns::LOAD).unwrap());
    let top = peak(&r).0;
    let end = df[df.len() - 1];
    let mut differences: Vec<f64> =
        d.iter().zip(p).filter(|(&x, _)| x <= end).map(|(&x, &y)| (load_at(df, pf, x) - y).abs() / top).collect();
    differences.sort_by(f64::total_cmp);
    eprintln!(
        "{} steps, {per_step:.1} factorisations a step, crack grown {grown:.1} mm; loads at {} states vs a run with {} states: median difference {:.2e}, worst {:.2e} of the peak",
        stats.steps,
        d.len(),
        df.len(),
        differences[differences.len() / 2],
        differences[differences.len() - 1]
    );
    PathCheck { stats, per_step, grown, differences }
}

/// While the crack runs, cohesive points cross the onset and the unloading kinks of their law in
/// every step. Newton with a residual-guided line search used to crawl there (10–19 iterations a
/// step, a third of the steps cut after 20): short updates kept the points on the wrong side of
/// their kinks. A handful of iterations a step is the norm, and the path does not depend on how
/// the steps fall: four times as many recorded states give the same loads at this run's states.
#[test]
fn a_running_crack_costs_a_few_newton_iterations_per_step_and_the_steps_do_not_move_the_path() {
    let mut dcb = Dcb2d::paper();
    dcb.control.max_displacement = Some(15.0);
    let c = follow(&dcb, &Bilinear::bk(1e5, 15.0, 15.0, 0.57, 2.0, 2.0).unwrap());
    assert!(c.grown > 20.0, "the crack grew {} mm", c.grown);
    assert!(c.per_step <= 12.0, "{} factorisations a step ({:?})", c.per_step, c.stats);
    // A path that converges at the tolerance never needs the round-off floor.
    assert_eq!(c.stats.floor_steps, 0, "{:?}", c.stats);
    let worst = c.differences[c.differences.len() - 1];
    assert!(worst < 2e-3, "worst difference {worst} of the peak");
}

/// Under large displacements (total Lagrangian arms) each step starts from the state extrapolated
/// along the last step of the same control. From the last state alone a front-opening step
/// started with a residual about ten times the load and took 6 to 18 damped Newton iterations:
/// this run took 12.6 factorisations a step (6.9 with the extrapolation), and Hartlen's DCB-01 to
/// 30 mm 3543 over 236 steps (906 over 110). How the steps fall moves the loads read between the
/// recorded states by the front's element-by-element ripple, which the total Lagrangian path
/// shows with or without the extrapolation: against four times as many recorded states, at most
/// 8.5 × 10⁻³ of the peak both ways (where the crack starts to run), 4.7 × 10⁻⁴ in the median
/// (1.0 × 10⁻³ without the extrapolation).
#[test]
fn a_running_crack_under_large_displacements_costs_a_few_newton_iterations_per_step() {
    let mut dcb = Dcb2d::hartlen_dcb01();
    dcb.effects.large_rotation = true;
    dcb.control.max_displacement = Some(20.0);
    let c = follow(&dcb, &Bilinear::bk(1e5, 60.0, 60.0, 0.8, 2.0, 2.0).unwrap());
    assert!(c.grown > 30.0, "the crack grew {} mm", c.grown);
    assert!(c.per_step <= 10.0, "{} factorisations a step ({:?})", c.per_step, c.stats);
    assert_eq!(c.stats.floor_steps, 0, "{:?}", c.stats);
    let (median, worst) = (c.differences[c.differences.len() / 2], c.differences[c.differences.len() - 1]);
    assert!(median < 3e-3 && worst < 1e-2, "median {median}, worst {worst} of the peak");
}

#[test]
fn hartlen_dcb_with_a_short_process_zone_peaks_at_corrected_beam_theory() {
    let mut dcb = Dcb2d::hartlen_dcb01();
    dcb.control.max_displacement = Some(8.0);
    let law = Bilinear::bk(1e5, 60.0, 60.0, 0.8, 2.0, 2.0).unwrap();
    let r = dcb.simulate(&law).unwrap();
    let (p, _) = peak(&r);
    let cbt = cbt_critical_load(&dcb.material, dcb.width, dcb.h, dcb.a0, 0.8);
    eprintln!("Hartlen DCB: peak {p:.3} N vs corrected beam theory {cbt:.3} N");
    assert!((p / cbt - 1.0).abs() < 0.015, "peak {p} N vs corrected beam theory {cbt} N");
}

#[test]
fn compdam_dcb_example() {
    // NASA CompDam_DGD `examples/interlaminar` DCB: peak 8.0 N, 4.38 N at 4.5 mm opening.
    let dcb = Dcb2d {
        a0: 50.8,
        length: 150.0,
        width: 1.0,
        h: 3.8,
        material: Material { e11: 171_420.0, e22: 9_080.0, g13: 5_290.0, nu13: 0.0, plane: Default::default() },
        mesh: czid_models::continuum::ContinuumMesh { interface_element: 0.2, ..Default::default() },
        control: czid_models::beamtest::ControlSettings { max_displacement: Some(4.5), ..Default::default() },
        effects: Default::default(),
        solver: SolverKind::Band,
    };
    let law = Bilinear::bk(1e5, 62.3, 62.3, 0.277, 0.788, 2.0).unwrap();
    let r = dcb.simulate(&law).unwrap();
    let (p, _) = peak(&r);
    assert!((p / 8.0 - 1.0).abs() < 0.03, "peak {p} N vs 8.0 N");
    let d = r.column(columns::DISPLACEMENT).unwrap();
    let load = r.column(columns::LOAD).unwrap();
    let at = load_at(d, load, 4.5);
    eprintln!("CompDam DCB: peak {p:.3} N (8.0), {at:.3} N at 4.5 mm (4.38)");
    assert!((at / 4.38 - 1.0).abs() < 0.03, "load at 4.5 mm {at} N vs 4.38 N");
}

/// The peak on the two finest meshes of the convergence study in the book.
#[test]
fn paper_dcb_peak_converges_with_the_mesh() {
    let law = paper_law();
    let peaks: Vec<f64> = [0.1, 0.05]
        .iter()
        .map(|&e| {
            let mut dcb = Dcb2d::paper();
            dcb.mesh.interface_element = e;
            dcb.control.max_displacement = Some(3.0);
            peak(&dcb.simulate(&law).unwrap()).0
        })
        .collect();
    eprintln!("paper DCB peaks at 0.1 and 0.05 mm: {peaks:?}");
    assert!((peaks[0] / peaks[1] - 1.0).abs() < 0.005, "peaks {peaks:?}");
}

/// Wang & Williams' crack-tip correction of the ENF, `a + 0.42 χ h` (χ as corrected beam
/// theory's for the DCB).
fn ww_crack(m: &Material, h: f64, a: f64) -> f64 {
    let gamma = 1.18 * (m.e11 * m.e22).sqrt() / m.g13;
    let chi = ((m.e11 / (11.0 * m.g13)) * (3.0 - 2.0 * (gamma / (1.0 + gamma)).powi(2))).sqrt();
    a + 0.42 * chi * h
}

/// ENF compliance with shear, `(3a³ + 2L³)/(8 E b h³) + 3L/(10 G13 b h)`.
fn enf_compliance(m: &Material, b: f64, h: f64, l: f64, a: f64) -> f64 {
    (3.0 * a.powi(3) + 2.0 * l.powi(3)) / (8.0 * m.e11 * b * h.powi(3)) + 3.0 * l / (10.0 * m.g13 * b * h)
}

fn initial_compliance(r: &Record) -> f64 {
    r.column(columns::DISPLACEMENT).unwrap()[1] / r.column(columns::LOAD).unwrap()[1]
}

#[test]
fn enf_compliance_matches_timoshenko_uncracked_and_wang_williams_cracked() {
    use czid_models::enf_2d::Enf2d;
    // A short process zone (τ = 150 MPa) and a stiff penalty: the elastic response is the arms'.
    let law = Bilinear::bk(1e6, 60.0, 150.0, 0.8, 2.0, 2.0).unwrap();
    let mut enf = Enf2d::hartlen_enf03();
    let (m, b, h, l) = (enf.material.clone(), enf.width, enf.h, enf.half_span);
    enf.control.max_displacement = Some(0.5);
    enf.control.output_points = 2;
    // Nearly uncracked (a0 = 1 mm): three-point bending of a Timoshenko beam 2h deep.
    enf.a0 = 1.0;
    let c = initial_compliance(&enf.simulate(&law).unwrap());
    let timoshenko = enf_compliance(&m, b, h, l, 1.0);
    eprintln!("ENF a0 = 1 mm: compliance {c:.6} mm/N vs Timoshenko {timoshenko:.6}");
    assert!((c / timoshenko - 1.0).abs() < 0.01);
    // Cracked (a0 = 40 mm): beam theory leaves out the root rotation at the crack front, Wang and
    // Williams' correction adds it; the continuum lies between, near the corrected value.
    enf.a0 = 40.0;
    let c = initial_compliance(&enf.simulate(&law).unwrap());
    let plain = enf_compliance(&m, b, h, l, 40.0);
    let corrected = enf_compliance(&m, b, h, l, ww_crack(&m, h, 40.0));
    eprintln!("ENF a0 = 40 mm: compliance {c:.6} mm/N; Timoshenko {plain:.6}, Wang–Williams {corrected:.6}");
    assert!(c > plain && c < corrected, "{c} outside ({plain}, {corrected})");
    assert!((c / corrected - 1.0).abs() < 0.02);
}

#[test]
fn enf_with_a_long_crack_peaks_at_wang_williams_and_balances_energy() {
    use czid_models::enf_2d::Enf2d;
    let law = Bilinear::bk(1e6, 60.0, 150.0, 0.8, 2.0, 2.0).unwrap();
    let mut enf = Enf2d::hartlen_enf03();
    enf.a0 = 40.0;
    let r = enf.simulate(&law).unwrap();
    let (p, _) = peak(&r);
    let a = ww_crack(&enf.material, enf.h, enf.a0);
    let ww = 4.0 * enf.width / (3.0 * a) * (enf.material.e11 * enf.h.powi(3) * 2.0).sqrt();
    eprintln!("ENF a0 = 40 mm: peak {p:.2} N vs Wang–Williams {ww:.2} N");
    assert!((p / ww - 1.0).abs() < 0.03);
    // The crack ran to the nose, and the energy balances all the way.
    let tip = r.column(columns::CRACK_TIP).unwrap();
    assert!(*tip.last().unwrap() > 48.0, "crack tip {}", tip.last().unwrap());
    let w = r.column(columns::EXTERNAL_WORK).unwrap();
    let u = r.column(columns::ELASTIC_ENERGY).unwrap();
    let d = r.column(columns::DISSIPATED_ENERGY).unwrap();
    for i in 1..w.len() {
        assert!((w[i] - u[i] - d[i]).abs() <= 0.005 * w[i], "row {i}: W {} U {} D {}", w[i], u[i], d[i]);
    }
}

#[test]
fn enf_with_a_short_crack_snaps_back() {
    use czid_models::enf_2d::Enf2d;
    // a0 / L = 0.5: unstable under displacement control; the path follows the crack front, with
    // the deflection at the nose falling while the crack runs.
    let law = Bilinear::bk(1e6, 60.0, 150.0, 0.8, 2.0, 2.0).unwrap();
    let mut enf = Enf2d::hartlen_enf03();
    enf.a0 = 25.0;
    let r = enf.simulate(&law).unwrap();
    let d = r.column(columns::DISPLACEMENT).unwrap();
    let back = d.windows(2).map(|w| (w[0] - w[1]).max(0.0)).fold(0.0, f64::max);
    let tip = r.column(columns::CRACK_TIP).unwrap();
    eprintln!(
        "ENF a0 = 25 mm: largest fall of the deflection {back:.4} mm, crack tip at {:.2} mm",
        tip.last().unwrap()
    );
    assert!(back > 0.01, "no snap-back recorded");
    assert!(*tip.last().unwrap() > 45.0);
}

#[test]
fn a_beam_dcb_maps_to_its_continuum_with_its_effects_as_material_changes() {
    use czid_models::dcb::Dcb;
    let mut beam = Dcb::hartlen_dcb01();
    let plain = Dcb2d::from_beam(&beam).unwrap();
    assert_eq!((plain.a0, plain.length, plain.width, plain.h), (beam.a0, beam.length, beam.width, beam.h));
    assert_eq!(plain.material, beam.material);
    beam.effects.root_compliance = 2e-4;
    beam.effects.shear_compliance = 3e-4;
    beam.effects.machine_compliance = 0.005;
    beam.effects.crack_length_offset = 1.5;
    let c = Dcb2d::from_beam(&beam).unwrap();
    // Through-thickness compliance of an arm, h / (2 E22), grows by the root compliance.
    let grown = beam.h / (2.0 * c.material.e22) - beam.h / (2.0 * beam.material.e22);
    assert!((grown - 2e-4).abs() < 1e-15, "{grown}");
    assert!((1.0 / c.material.g13 - 1.0 / beam.material.g13 - 3e-4).abs() < 1e-15);
    assert_eq!((c.effects.machine_compliance, c.effects.crack_length_offset), (0.005, 1.5));
    beam.symmetry = czid_models::dcb::Symmetry::Full;
    beam.h_lower = Some(2.0);
    assert!(Dcb2d::from_beam(&beam).unwrap_err().to_string().contains("equal arms"));
}

/// A short, coarse run of Hartlen's DCB (quick; for the effects' checks).
fn quick_hartlen() -> Dcb2d {
    let mut dcb = Dcb2d::hartlen_dcb01();
    dcb.mesh.interface_element = 0.5;
    dcb.mesh.thickness_elements = 2;
    dcb.control.max_displacement = Some(6.0);
    dcb.control.output_points = 30;
    dcb
}

#[test]
fn effects_switched_off_are_the_base_model_and_switched_on_act_as_declared() {
    let law = Bilinear::bk(1e5, 30.0, 30.0, 0.8, 2.0, 2.0).unwrap();
    let base = quick_hartlen();
    let r0 = base.simulate(&law).unwrap();
    // Null values: bit for bit the base model.
    let mut nulls = base.clone();
    nulls.effects = czid_models::continuum::ContinuumEffects {
        machine_compliance: 0.0,
        crack_length_offset: 0.0,
        displacement_offset: 0.0,
        large_rotation: false,
        load_offset: 0.0,
        seating_toe: 0.0,
    };
    assert_eq!(nulls.simulate(&law).unwrap(), r0);
    let d0 = r0.column(columns::DISPLACEMENT).unwrap();
    let p0 = r0.column(columns::LOAD).unwrap();

    // Machine compliance: the same states, each recorded C_m P further.
    let mut m = base.clone();
    m.effects.machine_compliance = 0.004;
    let r = m.simulate(&law).unwrap();
    let (d, p) = (r.column(columns::DISPLACEMENT).unwrap(), r.column(columns::LOAD).unwrap());
    for i in 0..d.len().min(d0.len()) {
        assert!((p[i] - p0[i]).abs() < 1e-9 * p0[i].abs().max(1.0));
        assert!((d[i] - d0[i] - 0.004 * p0[i]).abs() < 1e-9, "row {i}");
    }

    // Displacement offset: an unloaded toe, then every state shifted.
    let mut o = base.clone();
    o.effects.displacement_offset = 0.3;
    let r = o.simulate(&law).unwrap();
    let d = r.column(columns::DISPLACEMENT).unwrap();
    assert_eq!((d[0], r.column(columns::LOAD).unwrap()[0]), (0.0, 0.0));
    assert!((d[2] - d0[1] - 0.3).abs() < 1e-12);

    // A longer crack: more compliant (beam theory's a³ for the leading term), and the crack
    // front where the offset puts it.
    let mut c = base.clone();
    c.effects.crack_length_offset = 3.0;
    let r = c.simulate(&law).unwrap();
    let compliance = |r: &Record| r.column(columns::DISPLACEMENT).unwrap()[1] / r.column(columns::LOAD).unwrap()[1];
    let ratio = compliance(&r) / compliance(&r0);
    let a = base.a0;
    let cube = ((a + 3.0) / a).powi(3);
    assert!(ratio > 1.0 && ratio < cube, "compliance ratio {ratio} (a³ ratio {cube})");
    assert_eq!(r.column(columns::CRACK_TIP).unwrap()[0], a + 3.0);
}

#[test]
fn large_displacements_agree_with_small_strain_at_small_openings_and_follow_the_astm_correction_at_large_ones() {
    let law = Bilinear::bk(1e5, 30.0, 30.0, 0.8, 2.0, 2.0).unwrap();
    let mut small = quick_hartlen();
    small.control.max_displacement = Some(30.0);
    let mut large = small.clone();
    large.effects.large_rotation = true;
    let (rs, rl) = (small.simulate(&law).unwrap(), large.simulate(&law).unwrap());
    let c = |r: &Record| r.column(columns::DISPLACEMENT).unwrap()[1] / r.column(columns::LOAD).unwrap()[1];
    assert!((c(&rl) / c(&rs) - 1.0).abs() < 1e-3, "initial compliance {} vs {}", c(&rl), c(&rs));
    // At 25 mm (δ/a about 0.3) the loads differ by the geometric non-linearity, which ASTM D5528
    // corrects G for with F = 1 − 0.3 (δ/a)² − 1.5 δt/a².
    let at = |r: &Record| load_at(r.column(columns::DISPLACEMENT).unwrap(), r.column(columns::LOAD).unwrap(), 25.0);
    let (ps, pl) = (at(&rs), at(&rl));
    // At the same G_c the load scales as 1/√F (the hinges' offset t = 0 here).
    let a = load_at(rs.column(columns::DISPLACEMENT).unwrap(), rs.column(columns::CRACK_TIP).unwrap(), 25.0);
    let f = 1.0 - 0.3 * (25.0 / a).powi(2);
    eprintln!(
        "Hartlen DCB at 25 mm (a = {a:.1} mm): small strain {ps:.3} N, large {pl:.3} N, ratio {:.4} vs 1/√F = {:.4}",
        pl / ps,
        1.0 / f.sqrt()
    );
    assert!(pl > ps && (pl / ps * f.sqrt() - 1.0).abs() < 0.01, "{pl} vs {ps}");
}

#[test]
fn the_beam_models_name_their_continuum_counterpart_as_reference() {
    use czid_core::ForwardModel;
    let mut dcb = czid_models::dcb::Dcb::hartlen_dcb01();
    dcb.effects.load_offset = 1.5;
    let reference = dcb.reference().expect("a DCB of equal arms has a continuum counterpart");
    assert_eq!(reference.name(), "dcb_2d");
    assert_eq!(serde_json::to_value(&reference).unwrap()["effects"]["load_offset"], serde_json::json!(1.5));
    let enf = czid_models::enf::Enf::hartlen_enf03();
    assert_eq!(enf.reference().unwrap().name(), "enf_2d");
    assert!(czid_models::frp::beam::FrpBeam::paper().unwrap().reference().is_none());
}

/// A long total-Lagrangian run of the paper's DCB, stiffer and opened to 34 mm (the crack near
/// 120 mm along the 180 mm specimen), whose last steps meet the residual's round-off floor: the
/// residual settles at 1.0–1.3 × 10⁻⁸ of the load against a 10⁻⁸ tolerance and no cut lowers it.
/// The path used to stop there, 1.6 mm short of the end (32.5 of 34.1 mm of opening). Where it
/// would stop, it now accepts steps at that floor: it reaches the end and its energy still
/// balances. About two minutes (118 steps, 5 of them at the floor): `cargo test --release -p czid-models --test continuum -- --ignored`.
#[test]
#[ignore = "a ten-minute run; the floor's logic has unit tests in continuum::path"]
fn a_long_large_rotation_run_is_followed_past_the_residuals_round_off_floor() {
    // Case 9 of the large-rotation gap-bench of seed 43: the paper's beam DCB with its law and
    // modulus, made a continuum as the bench makes its tests (half the interface element, six
    // elements through each arm).
    let end = 34.144_253_208_618_63;
    let mut beam = czid_models::dcb::Dcb::paper();
    beam.material.e11 = 141_259.029_080_672_45;
    beam.control.max_displacement = Some(end);
    beam.effects.large_rotation = true;
    let mut dcb = Dcb2d::from_beam(&beam).unwrap();
    dcb.mesh.interface_element *= 0.5;
    dcb.mesh.thickness_elements = 6;
    let law =
        Bilinear::bk(1e5, 28.848_763_861_520_474, 28.848_763_861_520_474, 0.498_770_105_861_469_8, 2.0, 2.0).unwrap();
    let (r, stats) = dcb.simulate_with_stats(&law).unwrap();
    let d = r.column(columns::DISPLACEMENT).unwrap();
    assert!(*d.last().unwrap() >= end * (1.0 - 1e-9), "stopped at {} of {end} mm", d.last().unwrap());
    // The run did meet the floor (it used to stop there), and went on from it.
    assert!(stats.floor_steps > 0, "{stats:?}");
    let w = r.column(columns::EXTERNAL_WORK).unwrap();
    let u = r.column(columns::ELASTIC_ENERGY).unwrap();
    let dis = r.column(columns::DISSIPATED_ENERGY).unwrap();
    let worst = (1..w.len()).map(|i| ((w[i] - u[i] - dis[i]) / w[i]).abs()).fold(0.0, f64::max);
    eprintln!(
        "reached {} mm in {} steps, {} at the floor; worst energy imbalance {worst:.2e}",
        d.last().unwrap(),
        stats.steps,
        stats.floor_steps
    );
    assert!(worst <= 0.005, "energy imbalance {worst}");
}
