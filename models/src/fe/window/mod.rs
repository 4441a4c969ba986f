//! Windowed solution of a crack growing along one interface: only the nodes around the crack
//! front are solved for; the cracked part behind it and the intact part ahead of it are linear
//! and enter exactly through their condensed stiffness.
//!
//! **The regions.** Nodes are split into a left region `L` (the loaded end: the cracked arms, whose
//! interface points have failed and carry no traction in opening), a window `W` (the process
//! zone and its neighbourhood, solved by Newton) and a right region `R` (the intact interface,
//! whose points are still elastic: traction `K₀ g`). With small rotations the beams are linear, so
//! `L` and `R` are linear elastic substructures with no load but at their boundary with `W` (and
//! the prescribed control unknown in `L`). Every matrix of this engine couples neighbouring nodes
//! only, so eliminating a region node by node (block tridiagonal elimination) leaves a node-sized
//! stiffness on the window's end node: `q_{j+1} = T_{j+1} q_j` in `R` and
//! `q_{j−1} = T_{j−1} q_j + t_{j−1} c` in `L` (`c` the control unknown). Newton then works on the
//! window's unknowns only, and the result is the solution of the whole problem — exactly, not an
//! approximation — as long as the points of `L` and `R` are what their region assumes.
//!
//! **A control ahead of the crack.** A specimen loaded away from its cracked end (a mixed-mode
//! bending test: supports at both ends, the lever's saddle at mid-span, ahead of the front) has
//! the control unknown coupled to one node of the interface, and supports inside the regions.
//! Supports only leave their nodes with fewer unknowns. The control's column is carried by
//! whichever region holds its node: in `R` the elimination gives `q_{j+1} = T_{j+1} q_j +
//! t_{j+1} c` and the control's force from `R` as `a·q_{i1} + s c` on the window's last node, in
//! the window it is a term of the residual, and in `L` it is eliminated as the DCB's. The cracked
//! faces' contact points behind the interface belong to `L`, where open faces carry nothing;
//! that they stay open is checked like the failed points'.
//!
//! **Checks.** That is verified, not assumed: the law's response is checked to be `K₀ g` over a box
//! of gaps containing the origin (its corners, the elastic domain being convex) and zero for failed
//! material in opening; after every step the unknowns of `R` and `L` are recovered over
//! [`CHECK_DECAYS`] decay lengths `(4EI/k_f)^{1/4}` of the beam on its elastic interface from the
//! window and their gaps checked; at the end of the run every point is checked. A step whose
//! check fails is repeated with a wider window; a run whose final check fails (or that does not
//! fit the assumptions) is repeated on the whole mesh by [`super::path`]. A run
//! that gives up part way, where the path turns back (a specimen splitting), the window reaches
//! the far end or it spans three quarters of the interface (a process zone as long as the
//! specimen, where it saves little), hands its last committed state to the whole mesh, which goes
//! on from there (`Resume`) instead of starting again from rest.
//!
//! **Cost.** The right region is eliminated once per run (from the far end: the elimination up to
//! any node is a prefix of the same sweep), the left one incrementally as points fail and leave the
//! window; a Newton iteration costs law evaluations and a block tridiagonal solve over the window,
//! independent of the specimen's length.
//!
//! **Energies** of `L` and `R` follow from Clapeyron's theorem: a linear substructure loaded only
//! at its boundary stores half the work of the boundary forces on the boundary displacements (the
//! control among them, with each region's share of its force).

mod blocks;
mod layout;
mod solver;

use std::any::Any;
use std::cell::RefCell;
use std::rc::Rc;

use czid_core::CohesiveLaw;

use super::assembly::FeProblem;
use super::newton::CHORD_BELOW;
use super::run_types::{PathSettings, Resume, RunStats, StepRow};
use super::segment::ModeOne;
use layout::{linear_domain, node_dofs, Layout};
use solver::Solver;

/// Decay lengths of the condensed regions checked after every step. The intact region ahead of
/// the window is a beam on an elastic foundation loaded at the window's end only, so its gaps
/// decay within an envelope `e^{−x/λ}` set by that end's displacement and rotation: four decay
/// lengths on they are below 2 % of it, and a point there leaving the elastic box would need the
/// window's end fifty times beyond it (that end is itself checked). Every point is checked again
/// at the end of the run. Ten decay lengths cost 6 % more instructions on the paper's DCB; the
/// records of the paper's and Hartlen's DCB populations are the same with one, four or ten.
const CHECK_DECAYS: f64 = 4.0;

/// A node leaves the window for a step when the predictor opens its point to this many times the
/// law's failure opening ([`Solver::condense_failing`])...
const CONDENSE_OPENING: f64 = 1.5;
/// ... and it lies this many nodes behind the last such node.
const CONDENSE_MARGIN: usize = 4;
// Chord steps ([`CHORD_BELOW`], the residual relative to the interface forces here): they spare
// the tangent's assembly and the block elimination; on the paper's DCB the step that takes the
// residual from about 10⁻⁸ to the tolerance is such a step, and a run factorises 222 times
// instead of 289.

/// Why the window cannot run a problem (the caller then solves the whole mesh).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Unfit {
    /// The problem does not have the structure the window needs.
    Structure(&'static str),
    /// A step or the final check failed.
    Run(&'static str),
}

impl Unfit {
    /// What went wrong, for the run's statistics.
    pub(crate) fn reason(self) -> &'static str {
        match self {
            Unfit::Structure(r) | Unfit::Run(r) => r,
        }
    }
}

/// Why a windowed run gave up, and the state it reached when the whole mesh can go on from it.
pub(crate) type GaveUp = (Unfit, Option<Box<Resume>>);

/// The bits of what a windowed run of a problem whose gaps have no shear takes from `law`
/// besides its evaluations at such gaps: the opening extent of the elastic box the condensed
/// regions' gaps are checked against, which is found on mixed gaps (`None` where the law has no
/// box, and the whole mesh would run). Its shear extent, `−h ≤ 0 ≤ h` with `h > 0`, decides
/// nothing at a zero shear gap. Such a model adds them to its law's
/// [`czid_core::CohesiveLaw::mode_one_key`].
pub(crate) fn opening_key(law: &dyn CohesiveLaw) -> Option<[u64; 2]> {
    let lin = linear_domain(law, &ModeOne::of(law)?)?;
    Some([lin.lo[0].to_bits(), lin.hi[0].to_bits()])
}

/// Solves `p` along `s` with the window; the rows at the output abscissae. A run that gives up
/// where the path turns back or the window reaches the far end also returns its last committed
/// state, for the whole mesh to go on from.
pub(crate) fn run(p: &FeProblem, law: &dyn CohesiveLaw, s: &PathSettings) -> Result<(Vec<StepRow>, RunStats), GaveUp> {
    run_tuned(p, law, s, CONDENSE_OPENING, CHORD_BELOW)
}

/// [`run`] with the opening (times the failure opening) beyond which a predicted point leaves the
/// window for its step, and the residual below which Newton reuses its last factorisation.
fn run_tuned(
    p: &FeProblem,
    law: &dyn CohesiveLaw,
    s: &PathSettings,
    condense_opening: f64,
    chord_below: f64,
) -> Result<(Vec<StepRow>, RunStats), GaveUp> {
    let unfit = |why: Unfit| (why, None);
    let (d, layout) = prepared(p).map_err(unfit)?;
    let mode_one =
        ModeOne::of(law).ok_or(Unfit::Structure("the law has no elastic domain in mode I")).map_err(unfit)?;
    let lin = linear_domain(law, &mode_one)
        .ok_or(Unfit::Structure("the law is not linear near the origin"))
        .map_err(unfit)?;
    macro_rules! with {
        ($d:literal) => {{
            let lay = layout
                .downcast::<Layout<$d>>()
                .map_err(|_| Unfit::Structure("layout of another node size"))
                .map_err(unfit)?;
            let mut solver = Solver::new(p, law, s, lay, lin, mode_one).map_err(unfit)?;
            solver.condense_opening = condense_opening;
            solver.chord_below = chord_below;
            solver.run().map_err(|why| (why, solver.resume.take()))
        }};
    }
    match d {
        2 => with!(2),
        3 => with!(3),
        4 => with!(4),
        6 => with!(6),
        7 => with!(7),
        _ => with!(8),
    }
}

/// How many problems' layouts a thread keeps.
const LAYOUTS_KEPT: usize = 4;

/// A problem, its node block size and its layout (a `Layout<D>` of that size).
struct Prepared {
    problem: FeProblem,
    d: usize,
    layout: Rc<dyn Any>,
}

thread_local! {
    /// Layouts of the last problems run on this thread, most recent last. A layout does not depend
    /// on the law, so the runs of an identification (one problem per experiment, thousands of
    /// laws) build it once.
    static LAYOUTS: RefCell<Vec<Prepared>> = const { RefCell::new(Vec::new()) };
}

/// The node block size and layout of `p`, from this thread's cache or built.
fn prepared(p: &FeProblem) -> Result<(usize, Rc<dyn Any>), Unfit> {
    let hit = LAYOUTS.with(|c| c.borrow().iter().rev().find(|e| e.problem == *p).map(|e| (e.d, e.layout.clone())));
    if let Some(hit) = hit {
        return Ok(hit);
    }
    let (nodes, owner, fixed) = node_dofs(p)?;
    let d = match nodes.iter().map(|n| n.d).max().unwrap_or(0) {
        0..=2 => 2,
        3 => 3,
        4 => 4,
        5 | 6 => 6,
        7 => 7,
        _ => 8,
    };
    let layout: Rc<dyn Any> = match d {
        2 => Rc::new(Layout::<2>::new(p, &nodes, &owner, &fixed)?),
        3 => Rc::new(Layout::<3>::new(p, &nodes, &owner, &fixed)?),
        4 => Rc::new(Layout::<4>::new(p, &nodes, &owner, &fixed)?),
        6 => Rc::new(Layout::<6>::new(p, &nodes, &owner, &fixed)?),
        7 => Rc::new(Layout::<7>::new(p, &nodes, &owner, &fixed)?),
        _ => Rc::new(Layout::<8>::new(p, &nodes, &owner, &fixed)?),
    };
    LAYOUTS.with(|c| {
        let mut c = c.borrow_mut();
        if c.len() == LAYOUTS_KEPT {
            c.remove(0);
        }
        c.push(Prepared { problem: p.clone(), d, layout: layout.clone() });
    });
    Ok((d, layout))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dcb::Dcb;
    use crate::laws::StCzm;

    #[test]
    fn points_that_leave_the_window_for_a_step_and_do_not_fail_repeat_it_with_the_whole_window() {
        // Condensing points predicted at a tenth of the failure opening takes out points that do
        // not fail in the step: each such step is repeated with the whole window, and the records
        // are those of the default run (a node the window leaves out for a step is the one it
        // would have solved, failed and open) and of a run that never condenses.
        let law = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
        let mut d = Dcb::paper();
        d.control.max_displacement = Some(6.0);
        let (p, _) = d.problem().unwrap();
        let path = PathSettings::new(3.0, 30, d.a0);
        let (default, s_default) = run_tuned(&p, &law, &path, CONDENSE_OPENING, CHORD_BELOW).unwrap();
        let (eager, s_eager) = run_tuned(&p, &law, &path, 0.1, CHORD_BELOW).unwrap();
        let (never, s_never) = run_tuned(&p, &law, &path, f64::INFINITY, CHORD_BELOW).unwrap();
        println!("default {s_default:?}\neager   {s_eager:?}\nnever   {s_never:?}");
        assert!(s_eager.cuts > s_default.cuts, "the eager condensation had to repeat steps");
        assert!(default.last().unwrap().crack.debonded > 5.0, "the crack ran");
        for other in [&eager, &never] {
            assert_eq!(other.len(), default.len());
            for (a, b) in default.iter().zip(other) {
                let w = a.external_work.abs().max(1e-9);
                assert!((a.reaction - b.reaction).abs() <= 1e-9 * a.reaction.abs().max(1e-9), "{a:?}\n{b:?}");
                assert!((a.dissipated_energy - b.dissipated_energy).abs() <= 1e-9 * w, "{a:?}\n{b:?}");
                assert!((a.elastic_energy - b.elastic_energy).abs() <= 1e-9 * w, "{a:?}\n{b:?}");
                assert!((a.crack.debonded - b.crack.debonded).abs() <= 1e-7, "{a:?}\n{b:?}");
            }
        }
    }

    #[test]
    fn chord_corrections_reach_the_states_of_full_newton_steps() {
        // Once the residual is small, Newton reuses its last factorisation: the states are
        // Newton's to its tolerance either way, and fewer factorisations are needed.
        let paper: Box<dyn CohesiveLaw> =
            Box::new(StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap());
        let hartlen: Box<dyn CohesiveLaw> =
            Box::new(crate::laws::Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0).unwrap());
        for (d, law, end) in [(Dcb::paper(), paper, 6.0), (Dcb::hartlen_dcb01(), hartlen, 20.0)] {
            let (p, _) = d.problem().unwrap();
            let path = PathSettings::new(end, 50, d.a0);
            let (chord, s_chord) = run_tuned(&p, law.as_ref(), &path, CONDENSE_OPENING, CHORD_BELOW).unwrap();
            let (full, s_full) = run_tuned(&p, law.as_ref(), &path, CONDENSE_OPENING, 0.0).unwrap();
            println!("chord {s_chord:?}\nfull  {s_full:?}");
            assert!(s_chord.factorizations < s_full.factorizations, "the chord steps saved factorisations");
            assert!(full.last().unwrap().crack.debonded > 5.0, "the crack ran");
            assert_eq!(chord.len(), full.len());
            let peak = full.iter().fold(0.0f64, |m, r| m.max(r.reaction.abs()));
            for (a, b) in full.iter().zip(&chord) {
                let w = a.external_work.abs().max(1e-9);
                assert!((a.reaction - b.reaction).abs() <= 1e-9 * peak, "{a:?}\n{b:?}");
                assert!((a.dissipated_energy - b.dissipated_energy).abs() <= 1e-9 * w, "{a:?}\n{b:?}");
                assert!((a.elastic_energy - b.elastic_energy).abs() <= 1e-9 * w, "{a:?}\n{b:?}");
                assert!((a.crack.debonded - b.crack.debonded).abs() <= 1e-7, "{a:?}\n{b:?}");
            }
        }
    }
}
