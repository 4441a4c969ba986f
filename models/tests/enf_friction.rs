//! Coulomb friction between the cracked faces of an ENF (`effects.crack_face_friction`).
//!
//! Beam theory of the ENF's cracked part (Carlsson, Gillespie & Pipes 1986): each arm carries half
//! the bending moment `M = P x / 2` of the section at `x` from the support, so each bends with the
//! curvature `κ = P x / (4 E I)`, `I = b h³/12`; for the arms to follow each other the support's
//! reaction `P/2` under the lower arm is shared through their contact at the end `x = 0`, which
//! therefore carries `P/4`. The faces slip over each other there by `h ∫₀ᵃ κ dx = 3 P a²/(2 E b h²)`
//! (zero at the crack front). With friction `μ` the end resists that slip with `μ P/4`, which does
//! the work `∫ μ (P/4) d(3 P a²/(2 E b h²)) = 3 μ a² P²/(16 E b h²)` over a loading from 0 to `P`
//! (to first order in `μ`: the friction also stiffens the beam a little).

mod fe_support;
use czid_core::{columns, CohesiveLaw, ForwardModel, LawState, Record};
use czid_models::enf::Enf;
use czid_models::fe::interface::{contact_stored, FRICTION_WORK, SLIP};
use czid_models::fe::newton::{Newton, NewtonSettings};
use czid_models::fe::PointKind;
use czid_models::laws::Bilinear;

fn col<'a>(r: &'a Record, c: &str) -> &'a [f64] {
    r.column(c).unwrap()
}

/// Hartlen's ENF-03 with a plausible glass/epoxy mode II law (G_IIc 3.5 N/mm, 60 MPa).
fn specimen(mu: f64) -> (Enf, Bilinear) {
    let mut e = Enf::hartlen_enf03();
    e.mesh.interface_element = 0.25;
    e.control.output_points = 60;
    e.effects.crack_face_friction = mu;
    (e, Bilinear::bk(1e5, 40.0, 60.0, 1.0, 3.5, 2.0).unwrap())
}

fn run(mu: f64) -> Record {
    let (e, law) = specimen(mu);
    e.simulate(&law).unwrap_or_else(|f| panic!("μ = {mu}: {}", f.error))
}

#[test]
fn zero_friction_is_the_frictionless_model() {
    // The field at 0, written or left out, is the frictionless model, record for record.
    let (_, law) = specimen(0.0);
    let base = Enf::hartlen_enf03();
    let written = toml::to_string(&base).unwrap();
    assert!(written.contains("crack_face_friction = 0.0\n"));
    let left_out: Enf = toml::from_str(&written.replace("crack_face_friction = 0.0\n", "")).unwrap();
    assert_eq!(left_out, base);
    let (a, b) = (run(0.0), specimen(0.0).0.simulate(&law).unwrap());
    assert_eq!(a, b);
    // A vanishing coefficient takes the friction code path and lands on the frictionless curve.
    let tiny = run(1e-9);
    assert_ne!(tiny, a, "a non-zero coefficient must take the friction path");
    let (p0, p1) = (col(&a, columns::LOAD), col(&tiny, columns::LOAD));
    assert_eq!(p0.len(), p1.len());
    let worst = p0.iter().zip(p1).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    let peak = p0.iter().fold(0.0f64, |m, v| m.max(*v));
    assert!(worst < 1e-6 * peak, "μ = 1e-9 moves the load by {worst} N");
}

#[test]
fn energy_balances_with_friction_through_propagation() {
    // The records' balance W = U + D (D the cohesive and the friction dissipation) through the
    // unstable propagation, to the 0.5 % the ENF and MMB energy tests allow for the trapezoidal
    // rule; and the friction adds dissipation before the crack moves.
    let (with, without) = (run(0.3), run(0.0));
    let (w, u, d) = (
        col(&with, columns::EXTERNAL_WORK),
        col(&with, columns::ELASTIC_ENERGY),
        col(&with, columns::DISSIPATED_ENERGY),
    );
    let worst = (1..w.len()).map(|i| (w[i] - u[i] - d[i]).abs() / w[i]).fold(0.0, f64::max);
    let tip = col(&with, columns::CRACK_TIP);
    println!("μ = 0.3: worst |W − U − D| / W = {worst:.3e}; crack tip {:.2} mm", tip.last().unwrap());
    assert!(*tip.last().unwrap() > 40.0, "the crack ran");
    assert!(worst < 0.005, "energy balance {worst}");
    assert!(d.windows(2).all(|p| p[1] >= p[0] - 1e-9 * p[0].abs().max(1.0)), "dissipation decreased");
    // At a third of the run the crack has not moved: the dissipation is mostly friction's.
    let i = w.len() / 3;
    let d0 = col(&without, columns::DISSIPATED_ENERGY)[i];
    println!("at {:.3} mm: D = {:.4} N·mm with μ = 0.3, {d0:.4} without", col(&with, columns::DISPLACEMENT)[i], d[i]);
    assert!(d[i] > d0 + 1e-3 * w[i], "friction dissipates");
}

#[test]
fn the_load_at_a_deflection_and_the_peak_grow_with_friction() {
    let records: Vec<(f64, Record)> = [0.0, 0.2, 0.4].iter().map(|&mu| (mu, run(mu))).collect();
    let x = col(&records[0].1, columns::DISPLACEMENT).to_vec();
    let peak = |r: &Record| col(r, columns::LOAD).iter().fold(0.0f64, |m, v| m.max(*v));
    for pair in records.windows(2) {
        let ((m0, r0), (m1, r1)) = (&pair[0], &pair[1]);
        // Before the peak the rows are on the same output grid of deflections.
        let ipk = col(r0, columns::LOAD)
            .iter()
            .enumerate()
            .fold(0, |m, (i, v)| if *v > col(r0, columns::LOAD)[m] { i } else { m });
        let rows = ipk.min(col(r1, columns::LOAD).len());
        for (i, xi) in x.iter().enumerate().take(rows).skip(1) {
            assert!((col(r1, columns::DISPLACEMENT)[i] - xi).abs() <= 1e-12 * xi);
            let (p0, p1) = (col(r0, columns::LOAD)[i], col(r1, columns::LOAD)[i]);
            assert!(p1 > p0, "at {xi} mm: μ = {m1} gives {p1} N, μ = {m0} {p0} N");
        }
        println!("peak {:.1} N at μ = {m0}, {:.1} N at μ = {m1}", peak(r0), peak(r1));
        assert!(peak(r1) > peak(r0), "peak load with μ = {m1}");
    }
}

#[test]
fn an_unstable_enf_with_friction_still_follows_the_crack() {
    // The case of `enf_beam.rs` where the dissipation constraint can be met on an elastic
    // unloading of the contact instead of the crack's growth: with friction that unloading
    // dissipates too (the faces slip back), so the path's guard against it (a step that
    // dissipates nothing is refused) must still lead along the crack.
    let mut e = Enf::hartlen_enf03();
    e.a0 = 33.5;
    e.material.e11 = 32_554.79;
    e.mesh.interface_element = 0.25;
    e.control.max_displacement = Some(5.58);
    e.effects.crack_face_friction = 0.3;
    let law = Bilinear::bk(1e5, 9.654621, 31.94808, 0.8162914, 3.485673, 2.0).unwrap();
    let rec = e.simulate(&law).unwrap_or_else(|f| panic!("{}", f.error));
    let (x, p) = (col(&rec, columns::DISPLACEMENT), col(&rec, columns::LOAD));
    let diss = col(&rec, columns::DISSIPATED_ENERGY);
    assert!((x.last().unwrap() - 5.58).abs() < 1e-9, "ends at {}", x.last().unwrap());
    assert!(diss.windows(2).all(|w| w[1] >= w[0] - 1e-9 * w[0].abs().max(1.0)), "dissipation decreased");
    let peak = x.iter().zip(p).fold((0.0, 0.0f64), |m, (x, p)| if *p > m.1 { (*x, *p) } else { m });
    let after: Vec<f64> = x.iter().copied().skip_while(|v| *v < peak.0).collect();
    assert!(after.iter().all(|v| *v > 0.5 * peak.0), "a row fell back towards zero opening");
    let tip = col(&rec, columns::CRACK_TIP);
    println!("peak {:.1} N at {:.3} mm; crack tip at the end {:.2} mm", peak.1, peak.0, tip.last().unwrap());
    assert!(*tip.last().unwrap() > e.a0 + 5.0, "the crack ran (tip at {})", tip.last().unwrap());
}

/// The friction measures of the loading branch, stepped by Newton's method on the model's own
/// problem: a law too strong to damage at these loads, so the only dissipation is friction's.
struct Branch {
    load: f64,
    external_work: f64,
    elastic_energy: f64,
    /// Friction work from the contact points' states (their return mapping's `μ p |Δs|`).
    friction_work: f64,
    /// `Σ A p` and `Σ A |τ|` over the contact points (N).
    contact_force: f64,
    friction_force: f64,
    /// Largest `|τ| − μ p` (MPa) and the share of the contact force on slipping points.
    excess: f64,
    slipping_share: f64,
}

fn loading_branch(mu: f64, deflection: f64, steps: usize) -> Branch {
    let (mut e, _) = specimen(mu);
    e.mesh.interface_element = 0.5;
    let law = Bilinear::bk(1e5, 400.0, 600.0, 10.0, 35.0, 2.0).unwrap();
    let (p, scale) = e.problem(&law).unwrap();
    let mut nw = Newton::new(&p, &law, NewtonSettings::default());
    let n = nw.asm.n();
    let (mut q, mut states) = (vec![0.0; n], vec![law.initial_state(); p.points.len()]);
    let (mut work, mut reaction) = (0.0, 0.0);
    for k in 1..=steps {
        let c_old = q[p.control];
        q[p.control] = deflection / scale.displacement * k as f64 / steps as f64;
        nw.solve_displacement(&p, &law, &states, &mut q).unwrap_or_else(|f| panic!("step {k}: {f:?}"));
        let r = nw.f[p.control];
        work += 0.5 * (reaction + r) * (q[p.control] - c_old);
        reaction = r;
        for (s, ev) in states.iter_mut().zip(&nw.asm.trial) {
            *s = ev.state;
        }
    }
    let mut stored = vec![0.0; p.points.len()];
    let mut b = Branch {
        load: reaction * scale.load,
        external_work: work,
        elastic_energy: 0.0,
        friction_work: 0.0,
        contact_force: 0.0,
        friction_force: 0.0,
        excess: f64::NEG_INFINITY,
        slipping_share: 0.0,
    };
    for (i, pt) in p.points.iter().enumerate() {
        let (ev, g, s): (_, _, &LawState) = (&nw.asm.trial[i], &nw.asm.gaps[i], &states[i]);
        let w = pt.area * pt.factor;
        match pt.kind {
            PointKind::Cohesive => {
                assert_eq!(s.damage, 0.0, "the law is not to damage on this branch");
                stored[i] = law.stored_energy(g, s);
            }
            PointKind::Contact => {
                stored[i] = contact_stored(ev, g);
                let (pressure, tau) = (-ev.traction[0], ev.traction[1].abs());
                assert!(s.history[FRICTION_WORK] >= 0.0, "negative friction work at point {i}");
                b.friction_work += w * s.history[FRICTION_WORK];
                b.contact_force += w * pressure;
                b.friction_force += w * tau;
                b.excess = b.excess.max(tau - mu * pressure);
                // A slipping point has moved its slip in the last step to keep |τ| = μ p.
                if pressure > 0.0 && (tau - mu * pressure).abs() <= 1e-12 * pressure.max(1.0) && s.history[SLIP] != 0.0
                {
                    b.slipping_share += w * pressure;
                }
            }
        }
    }
    b.slipping_share /= b.contact_force.max(1e-300);
    b.elastic_energy = nw.asm.structural_energy(&p, &q) + nw.asm.interface_stored(&p, &stored);
    b
}

#[test]
fn friction_on_the_loading_branch_against_beam_theory_and_the_coulomb_bound() {
    let (e, _) = specimen(0.0);
    let (a, b, h, ex) = (e.a0, e.width, e.h, e.material.axial_modulus());
    let frictionless = loading_branch(0.0, 2.0, 40);
    // The contact force is the quarter of the load beam theory puts at the arms' end.
    let share = frictionless.contact_force / frictionless.load;
    println!("μ = 0: P = {:.2} N, contact force {:.2} N = {share:.4} P", frictionless.load, frictionless.contact_force);
    assert!((share - 0.25).abs() < 0.0125, "contact force {share} P, beam theory P/4");
    assert_eq!(frictionless.friction_work, 0.0);
    for mu in [0.1, 0.3] {
        let r = loading_branch(mu, 2.0, 40);
        // Coulomb: no point carries more than μ p, and the faces slip where they press.
        assert!(r.excess <= 1e-9 * r.contact_force, "|τ| − μ p up to {}", r.excess);
        assert!(r.friction_force <= mu * r.contact_force * (1.0 + 1e-12));
        assert!(r.slipping_share > 0.9, "only {} of the contact force slips", r.slipping_share);
        assert!((r.friction_force / (mu * r.contact_force) - 1.0).abs() < 0.1);
        // The friction work from the points' states closes the balance of the external work
        // (integrated on the reaction, independently of the states).
        let residual = r.external_work - r.elastic_energy;
        let closed = 3.0 * mu * a * a * r.load * r.load / (16.0 * ex * b * h * h);
        println!(
            "μ = {mu}: P = {:.2} N (+{:.3} %), W − U = {residual:.4} N·mm, friction work {:.4} N·mm, beam theory {closed:.4} N·mm, Σ|τ|A = {:.3} N = {:.4} μ Σ p A",
            r.load,
            100.0 * (r.load / frictionless.load - 1.0),
            r.friction_work,
            r.friction_force,
            r.friction_force / (mu * r.contact_force)
        );
        assert!(r.friction_work > 0.0 && r.load > frictionless.load);
        assert!(
            (residual / r.friction_work - 1.0).abs() < 0.02,
            "W − U {residual} vs friction work {}",
            r.friction_work
        );
        assert!(
            (r.friction_work / closed - 1.0).abs() < 0.15,
            "friction work {} vs beam theory {closed}",
            r.friction_work
        );
    }
}

#[test]
fn models_without_contact_refuse_friction_and_bad_values_name_the_field() {
    let (mut e, law) = specimen(-0.1);
    let err = e.simulate(&law).expect_err("a negative coefficient").error.to_string();
    assert!(err.contains("effects.crack_face_friction"), "{err}");
    e.effects.crack_face_friction = f64::NAN;
    assert!(e.simulate(&law).is_err());
    let mut dcb = czid_models::dcb::Dcb::paper();
    dcb.effects.crack_face_friction = 0.3;
    let err = dcb.simulate(&law).expect_err("the DCB has no contact").error.to_string();
    assert!(err.contains("effects.crack_face_friction") && err.contains("DCB"), "{err}");
    // The ENF declares the effect; the DCB has no contact and the MMB's ends do not press.
    let declares = |m: &dyn ForwardModel| m.effects().iter().any(|d| d.name == "crack_face_friction");
    assert!(declares(&Enf::hartlen_enf03()));
    assert!(!declares(&czid_models::mmb::Mmb::hartlen(40.0)));
    assert!(!declares(&czid_models::dcb::Dcb::paper()));
}

#[test]
fn mmb_friction_has_nothing_to_act_on() {
    use czid_models::mmb::Mmb;
    // Beam theory of the MMB: the ENF part of the load, P (c + L)/L, presses the cracked ends
    // together with a quarter of it, the lever's hinge pulls the upper arm off with P c/L, so the
    // ends press with P (L − 3c)/(4L), never positive for the lever lengths of the test (c ≥ L/3,
    // pure mode II at c = L/3). At pure mode II friction then changes nothing. The law and output
    // grid of the MMB's own energy test.
    let mut m = Mmb::hartlen(Mmb::lever_for_mode_ratio(50.0, 1.0));
    m.control.output_points = 100;
    let law = fe_support::TestBilinear::new(1e6, 30.0, 1.0);
    let base = m.simulate(&law).unwrap_or_else(|f| panic!("{}", f.error));
    m.effects.crack_face_friction = 0.5;
    let rec = m.simulate(&law).unwrap_or_else(|f| panic!("{}", f.error));
    let (w, u, d) =
        (col(&rec, columns::EXTERNAL_WORK), col(&rec, columns::ELASTIC_ENERGY), col(&rec, columns::DISSIPATED_ENERGY));
    let worst = (1..w.len()).map(|i| (w[i] - u[i] - d[i]).abs() / w[i]).fold(0.0, f64::max);
    let (p0, p1) = (col(&base, columns::LOAD), col(&rec, columns::LOAD));
    let peak = p0.iter().fold(0.0f64, |m, v| m.max(*v));
    let moved = p0.iter().zip(p1).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    println!("MMB mode II, μ = 0.5: worst balance {worst:.3e}; load moved by at most {moved:.3e} N (peak {peak:.1} N)");
    assert!(worst < 0.005, "energy balance {worst}");
    assert_eq!(p0.len(), p1.len());
    assert!(moved <= 1e-6 * peak, "friction moved the load by {moved} N");
}
