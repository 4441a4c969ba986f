//! The segment rule of the interface and the windowed solver: segment forces against exact
//! integrals and their Jacobian against finite differences, continuity as fronts cross points,
//! and the windowed solution against the solution of the whole mesh.

#![allow(clippy::needless_range_loop)] // index loops mirror the matrix algebra being checked

mod fe_support;
use czid_core::{CohesiveLaw, Gap, LawState};
use czid_models::dcb::Dcb;
use czid_models::fe::segment::{integrate, End, ModeOne, Segment};
use czid_models::fe::{self, PathSettings, RunOptions};
use czid_models::laws::{Bilinear, StCzm};
use fe_support::TestBilinear;

/// Forces of a segment of unit weight between virgin points at gaps `ga`, `gb` (tractions from
/// the law).
fn forces(law: &dyn CohesiveLaw, ga: Gap, gb: Gap, m: Option<&ModeOne>) -> fe::segment::SegmentForces {
    let init = LawState::default();
    let (ea, eb) = (law.evaluate(&ga, &init), law.evaluate(&gb, &init));
    let a = End { gap: ga, t: ea.traction, d: ea.tangent, trial: &ea.state, state: &init };
    let b = End { gap: gb, t: eb.traction, d: eb.tangent, trial: &eb.state, state: &init };
    let s = Segment { a: 0, b: 1, x: 0.0, len: 1.0, weight: 1.0 };
    integrate(&s, &a, &b, law, m)
}

/// `∫ N T(g(η)) dη` on the monotone virgin law by Simpson's rule on pieces split at `kinks`
/// (openings where the law's slope jumps), so exact for a law linear between them.
fn exact(law: &dyn CohesiveLaw, ga: Gap, gb: Gap, kinks: &[f64]) -> [Gap; 2] {
    let mut bp = vec![0.0, 1.0];
    for &g in kinks {
        let eta = (ga[0] - g) / (ga[0] - gb[0]);
        if eta > 0.0 && eta < 1.0 {
            bp.push(eta);
        }
    }
    bp.sort_by(f64::total_cmp);
    let mut f = [Gap::zeros(); 2];
    for w in bp.windows(2) {
        let n = 2000;
        for k in 0..=n {
            let eta = w[0] + (w[1] - w[0]) * k as f64 / n as f64;
            let c = if k == 0 || k == n {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            } * (w[1] - w[0])
                / (3.0 * n as f64);
            let t = law.evaluate(&(ga * (1.0 - eta) + gb * eta), &LawState::default()).traction;
            f[0] += t * ((1.0 - eta) * c);
            f[1] += t * (eta * c);
        }
    }
    f
}

#[test]
fn segment_forces_are_exact_for_laws_linear_along_the_path() {
    // Sawtooth and bilinear laws are linear between their kinks: with a linear gap the segment's
    // traction field is exact, and so are its forces, wherever the fronts lie.
    let st = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
    let m = ModeOne::of(&st).unwrap();
    for (ga, gb) in [
        (0.0010, 0.0001),  // onset front inside
        (0.0040, 0.0020),  // failure front inside
        (0.0040, 0.0001),  // both
        (0.0020, 0.0010),  // none: damaged throughout
        (0.00020, 0.0001), // none: elastic
    ] {
        let (ga, gb) = (Gap::new(ga, 0.0), Gap::new(gb, 0.0));
        let f = forces(&st, ga, gb, Some(&m)).f;
        let e = exact(&st, ga, gb, &[m.onset, m.failure.unwrap()]);
        for i in 0..2 {
            assert!((f[i] - e[i]).norm() <= 1e-9 * e[0].norm().max(1e-6), "{ga:?} {gb:?}: {:?} vs {:?}", f[i], e[i]);
        }
    }
    // Mixed mode, fronts located along the segment by bisection: along a straight gap path
    // whose mode mix changes, the bilinear (B-K) law is not linear between its kinks, so the
    // piecewise linear field is an approximation (here over a segment spanning the whole
    // softening branch).
    let bl = Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0).unwrap();
    let (ga, gb) = (Gap::new(0.0200, 0.0080), Gap::new(0.0001, 0.00005));
    let f = forces(&bl, ga, gb, None).f;
    let e = exact(&bl, ga, gb, &[]);
    for i in 0..2 {
        assert!((f[i] - e[i]).norm() <= 0.05 * e[0].norm(), "{:?} vs {:?}", f[i], e[i]);
    }
}

#[test]
fn a_bridging_law_has_a_front_where_its_matrix_fails() {
    // The matrix's failure inside a law with a bridging tail is a kink its damage does not mark
    // (the tail still carries load): the segment places a front there too, so the forces stay
    // exact for the piecewise linear law, and their Jacobian is the forces' derivative.
    let matrix = Bilinear::bk(1e5, 30.0, 30.0, 0.8, 2.0, 2.0).unwrap();
    let law = matrix.with_bridging_tail(0.5, 1.0).unwrap().unwrap();
    let m = ModeOne::of(law.as_ref()).unwrap();
    let (matrix_failure, _, _) = m.inner[0].expect("the matrix's failure");
    assert!((matrix_failure - 2.0 * 0.8 / 30.0).abs() < 1e-12, "{matrix_failure}");
    for (ga, gb) in [(0.08, 0.03), (0.08, 0.0001), (1.2, 0.03)] {
        let (ga, gb) = (Gap::new(ga, 0.0), Gap::new(gb, 0.0));
        let f = forces(law.as_ref(), ga, gb, Some(&m)).f;
        let e = exact(law.as_ref(), ga, gb, &[m.onset, matrix_failure, m.failure.unwrap()]);
        for i in 0..2 {
            assert!((f[i] - e[i]).norm() <= 1e-9 * e[0].norm(), "{ga:?} {gb:?}: {:?} vs {:?}", f[i], e[i]);
        }
        let sf = forces(law.as_ref(), ga, gb, Some(&m));
        let scale = sf.jac.iter().flatten().map(|j| j.norm()).fold(0.0, f64::max);
        let h = 1e-7 * ga.norm();
        for j in 0..2 {
            let d = Gap::new(h, 0.0);
            let (p, q) = if j == 0 {
                (forces(law.as_ref(), ga + d, gb, Some(&m)), forces(law.as_ref(), ga - d, gb, Some(&m)))
            } else {
                (forces(law.as_ref(), ga, gb + d, Some(&m)), forces(law.as_ref(), ga, gb - d, Some(&m)))
            };
            for i in 0..2 {
                let fd = (p.f[i][0] - q.f[i][0]) / (2.0 * h);
                let an = sf.jac[i][j][(0, 0)];
                assert!((fd - an).abs() <= 1e-6 * scale, "{ga:?} {gb:?}: ∂f{i}/∂g{j} = {an} vs {fd}");
            }
        }
    }
}

#[test]
fn segment_jacobian_matches_finite_differences() {
    let st = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
    let bl = TestBilinear::new(1e5, 60.0, 0.3);
    let m = ModeOne::of(&st).unwrap();
    // (law, end gaps, mode I fronts, tolerance relative to the Jacobian's largest block)
    type Case<'a> = (&'a dyn CohesiveLaw, Gap, Gap, Option<&'a ModeOne>, f64);
    let cases: [Case; 4] = [
        (&st, Gap::new(0.0010, 0.0), Gap::new(0.0001, 0.0), Some(&m), 1e-6),
        (&st, Gap::new(0.0040, 0.0), Gap::new(0.0020, 0.0), Some(&m), 1e-6),
        (&st, Gap::new(0.0040, 0.0), Gap::new(0.0001, 0.0), Some(&m), 1e-6),
        // Mixed mode: the fronts' normal from the damage gradient.
        (&bl, Gap::new(0.0030, 0.0020), Gap::new(0.0002, 0.0001), None, 1e-4),
    ];
    for (law, ga, gb, mo, tol) in cases {
        let sf = forces(law, ga, gb, mo);
        let scale = sf.jac.iter().flatten().map(|j| j.norm()).fold(0.0, f64::max);
        for j in 0..2 {
            for c in 0..2 {
                let h = 1e-7 * ga.norm();
                let mut d = Gap::zeros();
                d[c] = h;
                let (p, q) = if j == 0 {
                    (forces(law, ga + d, gb, mo), forces(law, ga - d, gb, mo))
                } else {
                    (forces(law, ga, gb + d, mo), forces(law, ga, gb - d, mo))
                };
                for i in 0..2 {
                    let fd = (p.f[i] - q.f[i]) / (2.0 * h);
                    for r in 0..2 {
                        let an = sf.jac[i][j][(r, c)];
                        assert!(
                            (fd[r] - an).abs() <= tol * scale,
                            "{ga:?} {gb:?}: ∂f{i}[{r}]/∂g{j}[{c}] = {an} vs {}",
                            fd[r]
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn segment_forces_are_continuous_as_fronts_cross_points() {
    // Sweep the far end's gap through the law's elastic limit and failure opening: the forces
    // change continuously (the nodal rule jumps in slope at each crossing and, summed over a
    // process zone, makes the resistance to crack growth depend on where the front lies).
    let st = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
    let m = ModeOne::of(&st).unwrap();
    for (ga, lo, hi) in [(0.001, 0.0002, 0.00035), (0.004, 0.0030, 0.0035)] {
        let mut prev: Option<[Gap; 2]> = None;
        let n = 4000;
        let mut worst = 0.0f64;
        for k in 0..=n {
            let gb = lo + (hi - lo) * k as f64 / n as f64;
            let f = forces(&st, Gap::new(ga, 0.0), Gap::new(gb, 0.0), Some(&m)).f;
            if let Some(p) = prev {
                worst = worst.max((f[0] - p[0]).norm().max((f[1] - p[1]).norm()));
            }
            prev = Some(f);
        }
        // A jump would show as one step much larger than the others (forces of order 10 N).
        assert!(worst < 1e-2, "largest change between neighbouring gaps {worst}");
    }
}

fn paper_path(target: f64, outputs: usize) -> PathSettings {
    PathSettings::new(target, outputs, 0.0)
}

#[test]
fn windowed_solution_equals_the_whole_mesh_solution() {
    let table3 = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
    let bilinear = Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0).unwrap();
    let cases: [(Dcb, &dyn CohesiveLaw, f64); 2] =
        [(Dcb::paper(), &table3, 3.0), (Dcb::hartlen_dcb01(), &bilinear, 7.5)];
    for (d, law, arm_deflection) in cases {
        let (p, _) = d.problem().unwrap();
        let mut path = paper_path(arm_deflection, 30);
        path.crack_origin = d.a0;
        let run = |window: bool| {
            let o = RunOptions { window, ..RunOptions::segments() };
            fe::run_with(&p, law, &path, &o).unwrap_or_else(|f| panic!("{}", f.error))
        };
        let ((whole, sw), (win, sv)) = (run(false), run(true));
        println!("whole mesh {sw:?}\nwindow     {sv:?}");
        assert!(sv.windowed && !sw.windowed);
        assert_eq!(whole.len(), win.len());
        let mut worst = [0.0f64; 4];
        for (a, b) in whole.iter().zip(&win) {
            assert_eq!(a.control, b.control);
            let w = a.external_work.abs().max(1e-9);
            worst[0] = worst[0].max((a.reaction - b.reaction).abs() / a.reaction.abs().max(1e-9));
            worst[1] = worst[1].max((a.elastic_energy - b.elastic_energy).abs() / w);
            worst[2] = worst[2].max((a.dissipated_energy - b.dissipated_energy).abs() / w);
            worst[3] = worst[3].max((a.crack.debonded - b.crack.debonded).abs());
        }
        println!(
            "worst differences: load {:.1e}, elastic {:.1e}, dissipated {:.1e} (of W), debonded {:.1e} mm",
            worst[0], worst[1], worst[2], worst[3]
        );
        // Both converge to the Newton tolerance (1e-9 of the internal forces).
        assert!(worst[0] < 1e-7 && worst[1] < 1e-7 && worst[2] < 1e-7 && worst[3] < 1e-5, "{worst:?}");
        assert!(win.last().unwrap().crack.debonded > 1.0, "the crack ran");
    }
}

#[test]
fn a_thread_that_ran_other_problems_gives_the_records_of_a_fresh_one() {
    // Windowed runs keep their problem's layout and their work arrays per thread for the next run:
    // what another specimen, another law or a failed run left behind must not show in a record.
    use czid_core::ForwardModel;
    let table3 = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
    let bilinear = Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0).unwrap();
    let mut short = Dcb::paper();
    short.control.max_displacement = Some(4.0);
    let mut thinner = short.clone();
    thinner.h = 1.5;
    let fresh = |d: Dcb, law: StCzm| std::thread::spawn(move || d.simulate(&law).unwrap()).join().unwrap();
    let expected = fresh(thinner.clone(), table3.clone());
    // This thread first runs other problems and laws (one of them on a longer specimen, so its
    // arrays are larger than the next run needs).
    short.simulate(&table3).unwrap();
    Dcb::hartlen_dcb01().simulate(&bilinear).unwrap();
    let other_law = StCzm::sawtooth(45.0, 0.0004, 0.005, 60.0, 0.0004, 0.005).unwrap();
    thinner.simulate(&other_law).unwrap();
    let reused = thinner.simulate(&table3).unwrap();
    assert_eq!(reused, expected, "a reused thread gives the fresh thread's record, bit for bit");
    // The same specimen changed after a run is not served the old specimen's layout.
    let changed = fresh(short.clone(), table3.clone());
    assert_ne!(changed, expected, "the two specimens differ");
    assert_eq!(short.simulate(&table3).unwrap(), changed);
}

#[test]
fn debonded_length_follows_the_damage_threshold() {
    // A lower threshold counts part of the process zone as debonded: the debonded length grows by
    // the distance between the fronts at damage 0.5 and at complete failure, the process zone
    // shrinks by as much, and both the window and the whole mesh place that front alike.
    let law = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
    let mut d = Dcb::paper();
    d.control.max_displacement = Some(4.0);
    d.control.output_points = 20;
    let (p, _) = d.problem().unwrap();
    let run = |threshold: f64, window: bool| {
        let mut path = paper_path(2.0, 20);
        path.crack_origin = d.a0;
        path.damage_threshold = threshold;
        let o = RunOptions { window, ..RunOptions::segments() };
        fe::run_with(&p, &law, &path, &o).unwrap_or_else(|f| panic!("{}", f.error)).0
    };
    let (full, half, half_whole) = (run(1.0 - 1e-9, true), run(0.5, true), run(0.5, false));
    let (a, b, c) = (full.last().unwrap().crack, half.last().unwrap().crack, half_whole.last().unwrap().crack);
    println!(
        "debonded {:.4} mm (complete failure), {:.4} mm (damage 0.5); process zone {:.4} / {:.4}",
        a.debonded, b.debonded, a.process_zone, b.process_zone
    );
    assert!(b.debonded > a.debonded && b.debonded < a.debonded + a.process_zone);
    assert!((a.debonded + a.process_zone - b.debonded - b.process_zone).abs() < 1e-9);
    assert!((b.debonded - c.debonded).abs() < 1e-6);
}

#[test]
fn mixed_mode_fronts_are_where_bisection_puts_them() {
    // The debonded-length front along a segment, found by the secant search on how far the damage
    // is from the level, against bisection to round-off on the same yes/no question, on the B-K
    // bilinear law over mixed-mode segments: the same float wherever the damage crosses the level
    // once, and never more than a few units in the last place apart.
    let law = Bilinear::bk(1e5, 20.0, 40.0, 0.5, 1.5, 2.0).unwrap();
    // Mode I onset opening σ_n/K (mm).
    let onset = 20.0 / 1e5;
    let (mut same, mut cases) = (0, 0);
    for k in 0..400 {
        let f = |i: u32| ((k * 7919 + i as usize * 104_729) % 1000) as f64 / 1000.0;
        // One end inside the process zone or beyond, the other nearer the elastic limit.
        let ga = Gap::new(onset * (1.0 + 40.0 * f(1)), onset * 3.0 * (f(2) - 0.3));
        let gb = Gap::new(onset * (0.5 + 4.0 * f(3)), onset * 2.0 * (f(4) - 0.5));
        let virgin = LawState::default();
        let (sa, sb) = (virgin, virgin);
        for level in [1e-9, 0.3, 0.9, 1.0 - 1e-9] {
            let Some(eta) = fe::segment::level_front(&law, ga, gb, &sa, &sb, level) else { continue };
            // Bisection as the front was found before, from the less damaged end.
            let beyond = |g: Gap, s: &LawState| law.evaluate(&g, s).state.damage >= level;
            let a_short = !beyond(ga, &sa);
            let gap = |eta: f64| ga * (1.0 - eta) + gb * eta;
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            loop {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                let e = if a_short { mid } else { 1.0 - mid };
                if beyond(gap(e), if a_short { &sa } else { &sb }) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            let expected = if a_short { lo } else { 1.0 - lo };
            cases += 1;
            same += usize::from(eta.to_bits() == expected.to_bits());
            assert!((eta - expected).abs() <= 8.0 * f64::EPSILON, "case {k}, level {level}: {eta} against {expected}");
        }
    }
    println!("{same} of {cases} fronts at bisection's float");
    assert!(cases > 400, "{cases} fronts only");
    assert!(same * 10 >= cases * 9, "{same} of {cases} at bisection's float");
}
