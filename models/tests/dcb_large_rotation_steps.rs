//! Large-rotation DCB runs (co-rotational arms, whole mesh) take one step per output, and the
//! states they reach do not depend on the steps taken to reach them.
//!
//! The path's shift predictor translates the solution around the crack front by the front's
//! predicted advance. Under large rotations it leaves the arms' axial displacements to the
//! extrapolation (they carry the shortening of the rotated arm, which does not travel with the
//! front). Translating them made the first two Newton iterations of every step useless and held the
//! steps at an eighth of the output spacing. These tests pin the step count and check the result:
//! the same specimens run with eight times as many outputs (each step then at most an eighth of
//! the spacing, as the steps were before) reach the same states at the common openings.
//!
//! A coarser beam mesh is a cheaper large-rotation solve: with `interface_subdivision = 1` (beam
//! elements as long as the interface elements instead of a quarter of them) the same runs stay
//! within 0.1 % of the default mesh's, at a quarter of the unknowns. The mesh kept fine only in a
//! zone that moves with the front (`fe::fine_zone`, on by default: the free arm behind in the
//! pre-crack arm's elements, the intact part ahead in elements of half a decay length) stays far
//! closer than that to the mesh fine everywhere.
//!
//! The specimens are Hartlen's DCB-01..03 of `examples/hartlen-dcb/` (a0 and final opening from the
//! files) with the bilinear law of `dcb01.toml`.

use czid_core::{columns, Record};
use czid_models::dcb::{self, Dcb};
use czid_models::laws::Bilinear;

/// (a0, final opening) of `dcb01.toml`, `dcb02.toml`, `dcb03.toml` (mm).
const SPECIMENS: [(&str, f64, f64); 3] = [("DCB-01", 37.64, 30.8), ("DCB-02", 33.005, 36.9), ("DCB-03", 25.391, 26.7)];

fn specimen(a0: f64, end: f64, outputs: usize) -> Dcb {
    let mut d = Dcb::hartlen_dcb01();
    d.a0 = a0;
    d.control.max_displacement = Some(end);
    d.control.output_points = outputs;
    d.effects.large_rotation = true;
    d
}

/// The DCB's run options with the beam mesh fine everywhere, as the model builds it.
const KEEP_MESH: czid_models::fe::RunOptions = czid_models::fe::RunOptions { fine_zone: false, ..dcb::RUN_OPTIONS };

fn law() -> Bilinear {
    Bilinear::bk(1e5, 30.0, 30.0, 0.8, 2.0, 2.0).unwrap()
}

fn col<'a>(r: &'a Record, c: &str) -> &'a [f64] {
    r.column(c).unwrap()
}

#[test]
fn large_rotation_runs_take_about_one_step_per_output() {
    for (name, a0, end) in SPECIMENS {
        let (rec, stats) = dcb::simulate_with_stats(&specimen(a0, end, 100), &law()).unwrap();
        let per_step = stats.assemblies as f64 / stats.steps as f64;
        println!("{name}: {stats:?}, {per_step:.2} assemblies per step, {} rows", rec.rows());
        assert!(!stats.windowed, "large rotations run on the whole mesh");
        // 100 outputs: a few more steps where the crack starts; 294 steps of 7.8 assemblies each
        // on DCB-01 when the axial displacements were translated too.
        assert!(stats.steps <= 130, "{name}: {} steps for 100 outputs", stats.steps);
        // 4.3–4.5 with the axial predictor (`fe::path`), 4.9 before it.
        assert!(per_step <= 5.0, "{name}: {per_step:.2} assemblies per step");
    }
}

#[test]
fn large_rotation_states_do_not_depend_on_the_steps_taken() {
    for (name, a0, end) in SPECIMENS {
        // On the mesh as built: the fine zone moves at commits, so with eight times as many steps
        // it moves at other states (a difference of the order of the zone's own, below), which
        // would hide what this test checks.
        let coarse = dcb::simulate_with_options(&specimen(a0, end, 100), &law(), &KEEP_MESH).unwrap().0;
        let fine = dcb::simulate_with_options(&specimen(a0, end, 800), &law(), &KEEP_MESH).unwrap().0;
        let (xc, pc, ac) =
            (col(&coarse, columns::DISPLACEMENT), col(&coarse, columns::LOAD), col(&coarse, columns::DEBONDED_LENGTH));
        let (xf, pf, af) =
            (col(&fine, columns::DISPLACEMENT), col(&fine, columns::LOAD), col(&fine, columns::DEBONDED_LENGTH));
        let peak = pc.iter().cloned().fold(0.0, f64::max);
        let (mut load, mut length, mut compared) = (0.0f64, 0.0f64, 0);
        for (i, x) in xc.iter().enumerate() {
            // The fine run's row at the same opening (both grids are even: every eighth row).
            let Some(j) = xf.iter().position(|v| (v - x).abs() <= 1e-9 * end) else { continue };
            load = load.max((pc[i] - pf[j]).abs() / peak);
            length = length.max((ac[i] - af[j]).abs());
            compared += 1;
        }
        println!("{name}: {compared} openings compared; load within {load:.2e} of the peak, debonded length within {length:.2e} mm");
        assert!(compared >= 100, "{name}: only {compared} common openings");
        // Both are converged solutions of the same equations (Newton to 1e-9 of the internal
        // forces); what is left is the path's history in the law, far below the 0.1 % a coarser
        // solve would be allowed.
        assert!(load <= 1e-6, "{name}: loads differ by {load:.2e} of the peak");
        assert!(length <= 1e-4, "{name}: debonded lengths differ by {length:.2e} mm");
    }
}

#[test]
fn a_coarser_beam_mesh_under_large_rotations_stays_within_a_tenth_of_a_percent() {
    for (name, a0, end) in SPECIMENS {
        let fine = dcb::simulate_with_stats(&specimen(a0, end, 100), &law()).unwrap();
        let mut d = specimen(a0, end, 100);
        d.mesh.interface_subdivision = 1;
        let coarse = dcb::simulate_with_stats(&d, &law()).unwrap();
        let (pf, pc) = (col(&fine.0, columns::LOAD), col(&coarse.0, columns::LOAD));
        let (af, ac) = (col(&fine.0, columns::DEBONDED_LENGTH), col(&coarse.0, columns::DEBONDED_LENGTH));
        let peak = pf.iter().cloned().fold(0.0, f64::max);
        let load = pf.iter().zip(pc).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / peak;
        let grown = af.last().unwrap() - af[0];
        let length = af.iter().zip(ac).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        println!(
            "{name}: subdivision 1 against 4: load within {load:.2e} of the peak, debonded length within \
             {length:.4} mm of {grown:.1} mm grown; {} against {} assemblies",
            coarse.1.assemblies, fine.1.assemblies
        );
        assert_eq!(pf.len(), pc.len());
        assert!(load <= 1e-3, "{name}: loads differ by {load:.2e} of the peak");
        assert!(length <= 1e-3 * grown, "{name}: debonded lengths differ by {length:.4} mm");
    }
}

#[test]
fn cutting_the_far_intact_part_leaves_the_large_rotation_records_unchanged() {
    for (name, a0, end) in SPECIMENS {
        let d = specimen(a0, end, 100);
        let cut = dcb::simulate_with_options(&d, &law(), &KEEP_MESH).unwrap();
        let whole =
            dcb::simulate_with_options(&d, &law(), &czid_models::fe::RunOptions { cut_far_field: false, ..KEEP_MESH })
                .unwrap();
        let (pc, pw) = (col(&cut.0, columns::LOAD), col(&whole.0, columns::LOAD));
        let (ac, aw) = (col(&cut.0, columns::DEBONDED_LENGTH), col(&whole.0, columns::DEBONDED_LENGTH));
        let (ec, ew) = (col(&cut.0, columns::ELASTIC_ENERGY), col(&whole.0, columns::ELASTIC_ENERGY));
        let peak = pw.iter().cloned().fold(0.0, f64::max);
        let top = ew.iter().cloned().fold(0.0, f64::max);
        let load = pw.iter().zip(pc).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / peak;
        let length = aw.iter().zip(ac).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        let energy = ew.iter().zip(ec).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / top;
        println!(
            "{name}: cut against whole mesh: load within {load:.2e} of the peak, debonded length within {length:.2e} mm, \
             elastic energy within {energy:.2e} of its largest; {} against {} assemblies",
            cut.1.assemblies, whole.1.assemblies
        );
        assert_eq!(pw.len(), pc.len());
        // The cut sits 25 decay lengths ahead of the onset front, where the deflection has all
        // but vanished: what is left is Newton's tolerance (10⁻⁹ of the forces), far inside the
        // 0.1 % a coarser large-rotation solve may differ by (the test above).
        assert!(load <= 1e-7, "{name}: loads differ by {load:.2e} of the peak");
        assert!(length <= 1e-5, "{name}: debonded lengths differ by {length:.2e} mm");
        assert!(energy <= 1e-7, "{name}: elastic energies differ by {energy:.2e}");
    }
}

#[test]
fn a_mesh_fine_only_around_the_front_stays_within_a_tenth_of_a_percent_of_the_fine_mesh() {
    for (name, a0, end) in SPECIMENS {
        let d = specimen(a0, end, 100);
        let coarse = dcb::simulate_with_stats(&d, &law()).unwrap();
        let fine = dcb::simulate_with_options(&d, &law(), &KEEP_MESH).unwrap();
        let (pc, pf) = (col(&coarse.0, columns::LOAD), col(&fine.0, columns::LOAD));
        let (ac, af) = (col(&coarse.0, columns::DEBONDED_LENGTH), col(&fine.0, columns::DEBONDED_LENGTH));
        let (ec, ef) = (col(&coarse.0, columns::ELASTIC_ENERGY), col(&fine.0, columns::ELASTIC_ENERGY));
        let (dc, df) = (col(&coarse.0, columns::DISSIPATED_ENERGY), col(&fine.0, columns::DISSIPATED_ENERGY));
        let (wc, wf) = (col(&coarse.0, columns::EXTERNAL_WORK), col(&fine.0, columns::EXTERNAL_WORK));
        let peak = pf.iter().cloned().fold(0.0, f64::max);
        let work = wf.iter().cloned().fold(0.0, f64::max);
        let rel =
            |a: &[f64], b: &[f64], top: f64| a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / top;
        let (load, energy, dissipated) = (rel(pc, pf, peak), rel(ec, ef, work), rel(dc, df, work));
        let length = rel(ac, af, 1.0);
        let grown = af.last().unwrap() - af[0];
        // Each run's own energy balance, at every row.
        let balance = |w: &[f64], e: &[f64], d: &[f64]| {
            (0..w.len()).map(|i| (w[i] - e[i] - d[i]).abs()).fold(0.0, f64::max) / work
        };
        let (balance, balance_fine) = (balance(wc, ec, dc), balance(wf, ef, df));
        println!(
            "{name}: fine zone against the fine mesh: load within {load:.2e} of the peak, debonded length within \
             {length:.2e} mm of {grown:.1} mm grown, elastic and dissipated energies within {energy:.2e} and \
             {dissipated:.2e} of the work; balance {balance:.2e} ({balance_fine:.2e} on the fine mesh); {} against {} \
             assemblies",
            coarse.1.assemblies, fine.1.assemblies
        );
        assert_eq!(pc.len(), pf.len());
        assert!(load <= 1e-3, "{name}: loads differ by {load:.2e} of the peak");
        assert!(length <= 1e-3 * grown, "{name}: debonded lengths differ by {length:.2e} mm");
        assert!(energy <= 1e-3 && dissipated <= 1e-3, "{name}: energies differ by {energy:.2e}, {dissipated:.2e}");
        assert!(balance <= 5e-4, "{name}: the run's energy balance is off by {balance:.2e} of the work");
    }
}

/// Both arms meshed (`symmetry = "full"`), equal and unequal: the specimen tilts as the upper arm
/// is pulled and the lower one held, and the path's predictor translates only the opening with the
/// front, not the tilt.
#[test]
fn both_arms_meshed_take_few_steps_and_reach_the_same_states() {
    for h_lower in [None, Some(2.2)] {
        let name = format!("DCB-01, both arms, lower arm {} mm", h_lower.unwrap_or(2.7));
        let full = |outputs: usize| {
            let mut d = specimen(37.64, 30.8, outputs);
            d.symmetry = dcb::Symmetry::Full;
            d.h_lower = h_lower;
            dcb::simulate_with_options(&d, &law(), &KEEP_MESH).unwrap()
        };
        let ((coarse, stats), (fine, _)) = (full(100), full(800));
        let per_step = stats.assemblies as f64 / stats.steps as f64;
        let (xc, pc) = (col(&coarse, columns::DISPLACEMENT), col(&coarse, columns::LOAD));
        let (xf, pf) = (col(&fine, columns::DISPLACEMENT), col(&fine, columns::LOAD));
        let (ac, af) = (col(&coarse, columns::DEBONDED_LENGTH), col(&fine, columns::DEBONDED_LENGTH));
        let peak = pc.iter().cloned().fold(0.0, f64::max);
        let (mut load, mut length) = (0.0f64, 0.0f64);
        for (i, x) in xc.iter().enumerate() {
            let Some(j) = xf.iter().position(|v| (v - x).abs() <= 1e-9 * 30.8) else { continue };
            load = load.max((pc[i] - pf[j]).abs() / peak);
            length = length.max((ac[i] - af[j]).abs());
        }
        println!(
            "{name}: {stats:?}, {per_step:.2} assemblies per step; eight times as many outputs: load within {load:.2e} \
             of the peak, debonded length within {length:.2e} mm"
        );
        // 105 and 123 steps of 4.9 and 9.0 assemblies; 4391 steps of 14 assemblies each for 60
        // outputs when the predictor translated the tilt.
        assert!(stats.steps <= 130, "{name}: {} steps for 100 outputs", stats.steps);
        assert!(per_step <= 12.0, "{name}: {per_step:.2} assemblies per step");
        assert!(load <= 1e-6, "{name}: loads differ by {load:.2e} of the peak");
        assert!(length <= 1e-4, "{name}: debonded lengths differ by {length:.2e} mm");
    }
}
