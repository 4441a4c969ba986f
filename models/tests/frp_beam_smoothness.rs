//! Smoothness of the FRP beam's debonded length in the bond law's parameters.
//!
//! The debonded front is located inside the element (where the law, along the gap interpolated
//! between the last failed interface point and the next, reaches failure), so the record's
//! debonded length is a continuous function of the state instead of growing by whole 10 mm
//! points. This test takes central finite differences of the debonded length at the two events
//! of the paper's objective with respect to σ_t (`strength_t`) and Δu_t,c (`u_c_t`) of the paper's
//! Table 8 law, with steps of 10⁻³ and 5 × 10⁻⁴ of a realistic identification range (σ_t in
//! [5, 25] MPa, Δu_t,c in [0.05, 0.4] mm), and compares the two slopes:
//!
//! * **onset of local debonding**: the debonded length when the load first reaches 98 % of its
//!   largest value (on the rising branch, just before the run jumps through the unstable IC
//!   debonding; see `czid_core::event::OnsetOfDebonding`);
//! * **end of the test**: the debonded length when the mid-span deflection first reaches the test's
//!   last reading, here 26 mm (a debonding plateau of this model; `czid_core::event::EndOfTest`).
//!
//! **The path.** The beam runs with `control.damage_tolerance = 1`: no step is repeated smaller
//! because the law's damage departs from the extrapolated one, so the runs take the same 176 steps
//! but for one step cut once, where Newton's method failed, in one run (checked below). At the default tolerance (0.05) the halving decisions change with
//! the parameters and every output jumps with them, not only the debonded length: measured, the
//! mid-span deflection at 200 kN on the rising branch has slopes (σ_t) at the two steps of
//! −0.221 and −0.353 mm/MPa (37 % apart), against −0.06463 and −0.06462 with the fixed schedule.
//!
//! **Measured** (`cargo test -p czid-models --test frp_beam_smoothness -- --nocapture`), relative
//! difference of the two slopes, located front / the former count of failed points (fronts
//! extrapolated from the damage ahead, recomputed here from the same runs' damage profiles):
//!
//! | event | σ_t | Δu_t,c |
//! |---|---|---|
//! | onset (98 % of the peak) | 2.7 % / 1.8 % | 5.2 % / 55 % |
//! | end (26 mm) | 6.4 % / 8.3 % | 1.4 % / 5.3 % |
//!
//! A 5 % agreement holds in two of the four cases (5.2 % and 6.4 % for the others); what is left
//! is the path itself (the peak load, read from the same runs, has slopes 3.7 % and 3.1 % apart):
//! kinks of the interface and the fibres crossed within a step. The test asserts 8 % for the
//! located front, and that the former measure fails that check where it jumps (55 %).
//!
//! **The identification's path** (`examples/frp-beam/identify.toml`: half the step, 0.025 mm,
//! the end read at the test's last deflection, 24.5 mm) is closer to a converged path but rougher:
//!
//! | event | σ_t | Δu_t,c |
//! |---|---|---|
//! | onset | 6.3 % | 94 % |
//! | end (24.5 mm) | 2.1 % | 46 % |
//!
//! A finer path resolves the bursts of IC debonding (a crack's debonded stretch running at nearly
//! fixed elongation), and an event read where the load first reaches a level, or the deflection
//! first reaches a value, moves by a burst when a parameter moves one across that point. The
//! second test pins both facts (σ_t within 8 %, Δu_t,c beyond 20 %).

use czid_core::event::{EndOfTest, OnsetOfDebonding};
use czid_core::{columns, Record, Response};
use czid_models::fe::crack;
use czid_models::frp::beam::{BeamRun, FrpBeam};
use czid_models::laws::StCzm;

/// Fraction of the peak load at which the onset is read.
const ONSET_FRACTION: f64 = 0.98;

/// The path of the runs: the fixed step schedule's step (mm of soffit elongation) and the test's
/// last deflection (mm), where the end event is read.
#[derive(Clone, Copy)]
struct Path {
    step: f64,
    end: f64,
    /// Steps cut where Newton's method failed, at most, in a run (the only change of schedule).
    max_cuts: usize,
}

/// The paper's beam at its default step, the end on a debonding plateau of that path.
const DEFAULT_PATH: Path = Path { step: 0.05, end: 26.0, max_cuts: 1 };
/// The path of `examples/frp-beam/identify.toml`: half the step, the test's last reading.
const IDENTIFICATION_PATH: Path = Path { step: 0.025, end: 24.5, max_cuts: 3 };

fn run(path: Path, strength_t: f64, u_c_t: f64) -> BeamRun {
    let law = StCzm::sawtooth(12.0, 0.02513, 0.1457, strength_t, 0.02897, u_c_t).unwrap();
    let mut beam = FrpBeam::paper().unwrap();
    beam.control.set_fixed_schedule(path.step);
    let run = beam.run(&law, true).unwrap();
    // The schedule is fixed; a step cut once when Newton's method fails is the only change.
    assert!(run.stats.cuts <= path.max_cuts, "σ_t = {strength_t}, Δu_t,c = {u_c_t}: {} cuts", run.stats.cuts);
    run
}

/// `[[onset, end] located, [onset, end] counted]` of a run, read by the event responses.
fn events(path: Path, run: &BeamRun) -> [[f64; 2]; 2] {
    let rec = &run.record;
    let threshold = FrpBeam::paper().unwrap().control.damage_threshold;
    // The same states with the former debonded length, recomputed from the damage profiles.
    let mut counted =
        Record::new(&[(columns::DISPLACEMENT, "mm"), (columns::LOAD, "N"), (columns::DEBONDED_LENGTH, "mm")]);
    let (p, d) = (rec.column(columns::LOAD).unwrap(), rec.column(columns::DISPLACEMENT).unwrap());
    for (i, pr) in run.profiles.iter().enumerate() {
        let mut scratch = vec![0.0; pr.x.len()];
        counted.push(&[d[i], p[i], crack::measure(&pr.x, &pr.damage, threshold, pr.x[0], &mut scratch).debonded]);
    }
    let onset = OnsetOfDebonding::new(ONSET_FRACTION).unwrap();
    let end = EndOfTest::at(path.end).unwrap();
    [rec, &counted].map(|r| [onset.predict(r, &[0.0]).unwrap()[0], end.predict(r, &[0.0]).unwrap()[0]])
}

/// Central-difference slopes at steps `h` and `h/2` of the parameter `which` (0: σ_t, 1: Δu_t,c):
/// `[measure][event][step]`.
fn slopes(path: Path, which: usize, h: f64) -> [[[f64; 2]; 2]; 2] {
    let mut out = [[[0.0; 2]; 2]; 2];
    for (k, step) in [h, 0.5 * h].into_iter().enumerate() {
        let at = |s: f64| {
            let (mut st, mut uc) = (14.0, 0.1504);
            if which == 0 {
                st += s;
            } else {
                uc += s;
            }
            events(path, &run(path, st, uc))
        };
        let (plus, minus) = (at(step), at(-step));
        for m in 0..2 {
            for e in 0..2 {
                out[m][e][k] = (plus[m][e] - minus[m][e]) / (2.0 * step);
            }
        }
    }
    out
}

/// The relative differences of the two slopes, `[parameter][event][measure]` (located front,
/// former count), printed as they are measured.
fn differences(path: Path) -> [[[f64; 2]; 2]; 2] {
    let base = events(path, &run(path, 14.0, 0.1504));
    println!(
        "step {} mm, end at {} mm: onset {:.2} mm, end {:.2} mm (former measure {:.2}, {:.2})",
        path.step, path.end, base[0][0], base[0][1], base[1][0], base[1][1]
    );
    let mut out = [[[0.0; 2]; 2]; 2];
    for (which, name, range) in [(0, "σ_t", 20.0), (1, "Δu_t,c", 0.35)] {
        let s = slopes(path, which, 1e-3 * range);
        for (e, event) in ["onset", "end"].into_iter().enumerate() {
            let rel = |m: usize| (s[m][e][0] - s[m][e][1]).abs() / s[m][e][1].abs();
            println!(
                "{name:>7} {event:>5}: located {:+.4e} / {:+.4e} ({:.1} %), former {:+.4e} / {:+.4e} ({:.1} %)",
                s[0][e][0],
                s[0][e][1],
                100.0 * rel(0),
                s[1][e][0],
                s[1][e][1],
                100.0 * rel(1)
            );
            out[which][e] = [rel(0), rel(1)];
        }
    }
    out
}

#[test]
fn debonded_length_events_have_consistent_finite_difference_slopes() {
    let d = differences(DEFAULT_PATH);
    let mut former_worst = 0.0f64;
    for (which, name) in [(0, "σ_t"), (1, "Δu_t,c")] {
        for (e, event) in ["onset", "end"].into_iter().enumerate() {
            assert!(d[which][e][0] < 0.08, "{name}, {event}: {:.1} %", 100.0 * d[which][e][0]);
            former_worst = former_worst.max(d[which][e][1]);
        }
    }
    assert!(former_worst > 0.08, "the former measure passes too ({former_worst})");
}

/// On the identification's finer path the σ_t slopes still agree; the Δu_t,c slopes do not (the
/// finer path resolves the bursts of debonding, see the module documentation): pinned both ways,
/// so that a change to either shows.
#[test]
fn on_the_identifications_path_the_strength_slopes_agree_and_the_opening_slopes_do_not() {
    let d = differences(IDENTIFICATION_PATH);
    for (e, event) in ["onset", "end"].into_iter().enumerate() {
        assert!(d[0][e][0] < 0.08, "σ_t, {event}: {:.1} %", 100.0 * d[0][e][0]);
    }
    assert!(d[1][0][0].max(d[1][1][0]) > 0.2, "Δu_t,c: {:?}", d[1]);
}
