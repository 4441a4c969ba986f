//! The discrete continuum problem: quadrilateral arms, nodal cohesive points along the crack
//! path, contact points on pre-cracked faces, held and controlled unknowns; and its assembly.
//!
//! Interface integration: see [`super::interface`].
//!
//! Kinematics of a point: with lower nodes, the opening and slip are the interpolated `[v_up − v_low,
//! u_up − u_low]` (the reference frame: the arms' faces stay nearly parallel to `x` where the
//! interface is intact); without one, the point lies on a symmetry plane (a half model): opening
//! `2 v_up`, no slip, and the point holds half the specimen's interface (`factor = ½`).

use czid_core::{CohesiveLaw, Gap, LawState, Tangent};
use nalgebra::{Matrix3, Vector4};
use rayon::prelude::*;

use super::grid::Grid;
use super::quad::{ElementForce, ElementTangent, Quad};
use super::solver::{SolverKind, System};

/// An integration point of the interface: it interpolates the gap linearly between two node
/// pairs (`shape` weighs them) across the interface, or between two nodes and a symmetry plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InterfacePoint {
    /// Position along the specimen (mm).
    pub x: f64,
    /// Nodes on the upper face.
    pub upper: [usize; 2],
    /// Nodes on the lower face; `None`: a symmetry plane.
    pub lower: Option<[usize; 2]>,
    /// Weights of the two node pairs (1, 0 for a point at a node).
    pub shape: [f64; 2],
    /// Integration weight: the area the point stands for (mm²).
    pub area: f64,
}

/// Largest number of unknowns one interface point's gap depends on.
const TERMS: usize = 8;

impl InterfacePoint {
    /// Share of the specimen's interface the point's energy stands for.
    pub fn factor(&self) -> f64 {
        if self.lower.is_some() {
            1.0
        } else {
            0.5
        }
    }

    /// The unknowns a gap depends on: (unknown, gap component, coefficient); zero coefficients pad.
    fn terms(&self) -> [(usize, usize, f64); TERMS] {
        let mut t = [(0, 0, 0.0); TERMS];
        for k in 0..2 {
            let (up, w) = (self.upper[k], self.shape[k]);
            match self.lower {
                Some(lo) => {
                    let lo = lo[k];
                    t[4 * k] = (2 * up + 1, 0, w);
                    t[4 * k + 1] = (2 * lo + 1, 0, -w);
                    t[4 * k + 2] = (2 * up, 1, w);
                    t[4 * k + 3] = (2 * lo, 1, -w);
                }
                None => t[4 * k] = (2 * up + 1, 0, 2.0 * w),
            }
        }
        t
    }

    /// `[opening, slip]` (mm) at displacements `u`, and the terms it is made of.
    fn gap(&self, u: &[f64]) -> (Gap, [(usize, usize, f64); TERMS]) {
        let terms = self.terms();
        let mut g = Gap::zeros();
        for &(dof, comp, c) in &terms {
            if c != 0.0 {
                g[comp] += c * u[dof];
            }
        }
        (g, terms)
    }

    /// Derivative of the effective opening `√(⟨g_n⟩² + g_t²)` at gap `g` with respect to the
    /// unknowns, as (unknown, coefficient) pairs.
    pub fn opening_gradient(&self, g: &Gap) -> Vec<(usize, f64)> {
        let norm = (g[0].max(0.0).powi(2) + g[1] * g[1]).sqrt();
        // At a closed, unslipped point the opening direction is taken as pure mode I.
        let dir = if norm > 0.0 { [g[0].max(0.0) / norm, g[1] / norm] } else { [1.0, 0.0] };
        self.terms().iter().filter(|t| t.2 != 0.0).map(|&(dof, comp, c)| (dof, c * dir[comp])).collect()
    }
}

/// The discrete problem.
#[derive(Clone, Debug)]
pub struct ContinuumProblem {
    /// The mesh of the arms.
    pub grid: Grid,
    /// Plane-stress stiffness of the arms (MPa).
    pub stiffness: Matrix3<f64>,
    /// Total Lagrangian large displacements instead of small strain.
    pub large: bool,
    /// Cohesive points along the crack path, in increasing `x`.
    pub cohesive: Vec<InterfacePoint>,
    /// Frictionless contact points on pre-cracked faces.
    pub contact: Vec<InterfacePoint>,
    /// Normal penalty of the contact points (MPa/mm).
    pub contact_stiffness: f64,
    /// Unknowns held at zero.
    pub fixed: Vec<usize>,
    /// Unknowns moved by the applied displacement `δ`, each with its factor (unknown = factor × δ);
    /// the load is the reactions summed with the same factors.
    pub control: Vec<(usize, f64)>,
    /// Which factorisation to use.
    pub solver: SolverKind,
}

/// Trial state of the interface after an assembly.
#[derive(Clone, Debug, Default)]
pub struct InterfaceTrial {
    /// Gap of each cohesive point.
    pub gaps: Vec<Gap>,
    /// Traction of each cohesive point (MPa).
    pub tractions: Vec<nalgebra::Vector2<f64>>,
    /// Law state of each cohesive point.
    pub states: Vec<LawState>,
}

/// What one assembly produced.
pub struct Assembled {
    /// Internal forces (N).
    pub force: Vec<f64>,
    /// Strain energy of the arms (N·mm).
    pub bulk_energy: f64,
    /// The interface's trial state.
    pub interface: InterfaceTrial,
    /// Bubble amplitudes per element (large displacements).
    pub bubbles: Vec<Vector4<f64>>,
}

/// The elements and, in small strain, the arms' constant stiffness matrix, assembled once.
pub struct Elements {
    list: Vec<([usize; 4], Quad)>,
    linear: Option<System>,
}

impl ContinuumProblem {
    /// Number of unknowns.
    pub fn unknowns(&self) -> usize {
        2 * self.grid.nodes()
    }

    /// The elements (in small strain, the arms' stiffness matrix assembled once: each Newton
    /// iteration copies it and multiplies by it instead of visiting every element).
    pub fn elements(&self) -> Elements {
        let list = self.grid.elements();
        let linear = (!self.large).then(|| {
            let tangents: Vec<ElementTangent> = list
                .par_iter()
                .map(|(_, q)| q.respond(&ElementForce::zeros(), &self.stiffness, false, &Vector4::zeros()).tangent)
                .collect();
            let mut bulk = self.system();
            for ((nodes, _), k) in list.iter().zip(&tangents) {
                let dofs: [usize; 8] = std::array::from_fn(|i| 2 * nodes[i / 2] + i % 2);
                for a in 0..8 {
                    for b in 0..8 {
                        bulk.add(dofs[a], dofs[b], k[(a, b)]);
                    }
                }
            }
            bulk
        });
        Elements { list, linear }
    }

    /// An empty system with this problem's pattern.
    pub fn system(&self) -> System {
        let pairs: Vec<(usize, usize)> = self
            .cohesive
            .iter()
            .chain(&self.contact)
            .flat_map(|p| p.lower.map(|l| [(p.upper[0], l[0]), (p.upper[1], l[1])]))
            .flatten()
            .collect();
        let bw = self.grid.bandwidth(&pairs);
        let n = self.unknowns();
        let per = self.grid.per_column;
        let grid = &self.grid;
        System::new(self.solver, n, bw, |dof| {
            // Elements couple nodes of neighbouring columns; interface points couple nodes of one
            // column (the two faces). The pattern: every node of the column and its neighbours.
            let c = dof / 2 / per;
            let lo = c.saturating_sub(1);
            let hi = (c + 1).min(grid.xs.len() - 1);
            (2 * lo * per..2 * (hi + 1) * per).collect()
        })
    }

    /// Internal forces and (when `system` is given) the tangent at displacements `u`, from the
    /// committed interface states `committed` and bubble guesses `bubbles`.
    pub fn assemble(
        &self,
        elements: &Elements,
        law: &dyn CohesiveLaw,
        u: &[f64],
        committed: &[LawState],
        bubbles: &[Vector4<f64>],
        mut system: Option<&mut System>,
    ) -> Assembled {
        let n = self.unknowns();
        let mut force = vec![0.0; n];
        let mut bulk_energy = 0.0;
        let mut new_bubbles = Vec::new();
        // The cohesive points' gaps and laws, evaluated side by side (each on its own); their
        // contributions are added below in the points' order, so the sums are the same whatever
        // the threads.
        let points = || -> Vec<_> {
            self.cohesive
                .par_iter()
                .zip(committed)
                .map(|(p, prev)| {
                    let (g, terms) = p.gap(u);
                    (g, terms, law.evaluate(&g, prev))
                })
                .collect()
        };
        let mut evaluated = None;
        match &elements.linear {
            Some(bulk) => {
                // The arms' linear forces (and tangent copy) beside the interface's points.
                let (_, e) = rayon::join(
                    || {
                        bulk.mul_vec(u, &mut force);
                        if let Some(s) = system.as_deref_mut() {
                            s.copy_from(bulk);
                        }
                    },
                    points,
                );
                evaluated = Some(e);
                bulk_energy = 0.5 * u.iter().zip(&force).map(|(a, b)| a * b).sum::<f64>();
            }
            None => {
                if let Some(s) = system.as_deref_mut() {
                    s.clear();
                }
                let gather = |nodes: &[usize; 4]| ElementForce::from_fn(|i, _| u[2 * nodes[i / 2] + i % 2]);
                let responses: Vec<_> = elements
                    .list
                    .par_iter()
                    .enumerate()
                    .map(|(i, (nodes, q))| q.respond(&gather(nodes), &self.stiffness, true, &bubbles[i]))
                    .collect();
                for ((nodes, _), r) in elements.list.iter().zip(&responses) {
                    bulk_energy += r.energy;
                    let dofs: [usize; 8] = std::array::from_fn(|i| 2 * nodes[i / 2] + i % 2);
                    for a in 0..8 {
                        force[dofs[a]] += r.force[a];
                    }
                    if let Some(s) = system.as_deref_mut() {
                        for a in 0..8 {
                            for b in 0..8 {
                                s.add(dofs[a], dofs[b], r.tangent[(a, b)]);
                            }
                        }
                    }
                }
                new_bubbles = responses.iter().map(|r| r.bubbles).collect();
            }
        }
        let evaluated = evaluated.unwrap_or_else(points);
        let m = evaluated.len();
        let mut trial = InterfaceTrial {
            gaps: Vec::with_capacity(m),
            tractions: Vec::with_capacity(m),
            states: Vec::with_capacity(m),
        };
        for (p, (g, terms, ev)) in self.cohesive.iter().zip(evaluated) {
            self.add_point(p, &terms, &ev.traction, &ev.tangent, &mut force, system.as_deref_mut());
            trial.gaps.push(g);
            trial.tractions.push(ev.traction);
            trial.states.push(ev.state);
        }
        for p in &self.contact {
            let (g, terms) = p.gap(u);
            let k = if g[0] < 0.0 { self.contact_stiffness } else { 0.0 };
            let t = nalgebra::Vector2::new(k * g[0], 0.0);
            let tan = Tangent::new(k, 0.0, 0.0, 0.0);
            self.add_point(p, &terms, &t, &tan, &mut force, system.as_deref_mut());
        }
        Assembled { force, bulk_energy, interface: trial, bubbles: new_bubbles }
    }

    fn add_point(
        &self,
        p: &InterfacePoint,
        terms: &[(usize, usize, f64); TERMS],
        t: &nalgebra::Vector2<f64>,
        tan: &Tangent,
        force: &mut [f64],
        system: Option<&mut System>,
    ) {
        let w = p.area * p.factor();
        for &(dof, comp, c) in terms {
            if c != 0.0 {
                force[dof] += w * c * t[comp];
            }
        }
        if let Some(s) = system {
            // A term of zero weight adds nothing (its products are zero and skipped).
            for &(di, ci, cv) in terms.iter().filter(|t| t.2 != 0.0) {
                for &(dj, cj, cw) in terms.iter().filter(|t| t.2 != 0.0) {
                    let v = w * cv * cw * tan[(ci, cj)];
                    if v != 0.0 {
                        s.add(di, dj, v);
                    }
                }
            }
        }
    }

    /// Stored (recoverable) energy of the contact points at `u` (N·mm).
    pub fn contact_energy(&self, u: &[f64]) -> f64 {
        self.contact
            .iter()
            .map(|p| {
                let g = p.gap(u).0[0].min(0.0);
                0.5 * self.contact_stiffness * g * g * p.area * p.factor()
            })
            .sum()
    }
}
