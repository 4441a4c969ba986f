//! Newton's iterations over the window: assembly, the block tridiagonal elimination, chord
//! corrections.

use czid_core::{Gap, LawState};

use super::Solver;
use crate::fe::newton::CHORD_CONTRACTION;
use crate::fe::segment::{self, End};
use crate::fe::window::blocks::{add, addv, blk_mul, blk_vec, sub, zb, Blk, Lu, Vct};
use crate::fe::window::layout::gap_at;

impl<'a, const D: usize> Solver<'a, D> {
    pub(super) fn gap(&self, node: usize, q: &Vct<D>) -> Gap {
        gap_at(self.lay.cp(node), q)
    }

    /// Assembles the window's residual (into `res`) and Jacobian blocks at the current `q`, `c`;
    /// returns the residual's largest entry and the scale of the internal forces.
    pub(super) fn assemble(&mut self, states: &[LawState], tangent: bool) -> Result<(f64, f64), ()> {
        let (i0, i1) = (self.i0, self.i1);
        let lay = &self.lay;
        self.stats.assemblies += 1;
        // Linear parts.
        for j in i0..=i1 {
            // The control's column at node j: its own coupling, or the right region's through it.
            let mut ctl = None;
            // The node's diagonal block: the linear one, with the condensed regions' stiffness at
            // the window's ends. It is built in the tangent's slot, and read in place where nothing
            // is added to it: a block of seven unknowns is 392 bytes, and building it in a local
            // to copy it into the slot cost the MMB a copy per node of every assembly.
            let ends = j == i0 || (j == i1 && j < lay.last);
            let mut r = if tangent || ends {
                let mut own;
                let a: &mut Blk<D> = if tangent {
                    self.jd[j] = lay.kd[j];
                    &mut self.jd[j]
                } else {
                    own = lay.kd[j];
                    &mut own
                };
                if j == i1 && j < lay.last {
                    let k = j - lay.first;
                    add(a, &self.es_aa[k]);
                    let mut e_up = lay.ku[j];
                    add(&mut e_up, &self.es_ab[k]);
                    let s = blk_mul(&e_up, &self.tr[j + 1]);
                    add(a, &s);
                    if let Some(tc) = self.trc.get(j + 1) {
                        ctl = Some(blk_vec(&e_up, tc));
                    }
                }
                if j == i0 {
                    let s = blk_mul(&lay.kl[j - 1], &self.tl[j - 1]);
                    add(a, &s);
                }
                blk_vec(a, &self.q[j])
            } else {
                blk_vec(&lay.kd[j], &self.q[j])
            };
            if j > i0 && lay.control_nodes.is_some_and(|(a, b)| a <= j && j <= b) {
                let mut v = ctl.unwrap_or([0.0; D]);
                addv(&mut v, &lay.kc[j]);
                ctl = Some(v);
            }
            if j > i0 {
                let v = blk_vec(&lay.kl[j - 1], &self.q[j - 1]);
                addv(&mut r, &v);
            }
            if j < i1 {
                let v = blk_vec(&lay.ku[j], &self.q[j + 1]);
                addv(&mut r, &v);
                if tangent {
                    self.ju[j] = lay.ku[j];
                    self.jl[j] = lay.kl[j];
                }
            }
            if j == i0 {
                let v = blk_vec(&lay.kl[j - 1], &self.tlc[j - 1]);
                for a in 0..D {
                    r[a] += (v[a] + lay.kc[j][a]) * self.c;
                }
            }
            if let Some(v) = ctl {
                for a in 0..D {
                    r[a] += v[a] * self.c;
                }
            }
            self.res[j] = r;
        }
        // Interface: law at the window's points, segments between them. Both loops run over the
        // window's slices of the node-indexed arrays (no index checks but the point-indexed ones).
        let (k0, k1) = (i0 - lay.first, i1 - lay.first);
        let chain = &lay.chain[k0..=k1];
        let mut ok = true;
        for (cp, q) in chain.iter().zip(&self.q[i0..=i1]) {
            let pi = cp.point;
            let g = gap_at(cp, q);
            let ev = self.law.evaluate(&g, &states[pi]);
            // The law's own tangent: with segments the forces are continuous at a point's elastic
            // limit, and Newton converges there with the one-sided tangent, while the nodal rule's
            // loading-branch bias would be an inconsistent Jacobian (linear convergence, or
            // divergence, for a point converging just inside its limit).
            let d = ev.tangent;
            if !(ev.traction.iter().all(|v| v.is_finite()) && d.iter().all(|v| v.is_finite())) {
                ok = false;
            }
            self.gaps[pi] = g;
            self.ev[pi] = ev;
            self.dt[pi] = d;
        }
        if !ok {
            return Err(());
        }
        let (gaps, evs, dts) = (&self.gaps, &self.ev, &self.dt);
        let res = &mut self.res[i0..=i1];
        let jd = &mut self.jd[i0..=i1];
        let (ju, jl) = (&mut self.ju[i0..i1], &mut self.jl[i0..i1]);
        let segs = lay.segs[k0..k1].iter().zip(chain.windows(2));
        let out = self.fronts[k0..k1].iter_mut().zip(&mut self.seg_stored[k0..k1]);
        for (k, ((sg, cps), (fronts, stored))) in segs.zip(out).enumerate() {
            let end =
                |i: usize| End { gap: gaps[i], t: evs[i].traction, d: dts[i], trial: &evs[i].state, state: &states[i] };
            let sf = segment::integrate(sg, &end(sg.a), &end(sg.b), self.law, Some(&self.mode_one));
            *fronts = sf.fronts;
            *stored = sf.stored;
            let (res_a, res_b) = res.split_at_mut(k + 1);
            let (jd_a, jd_b) = jd.split_at_mut(k + 1);
            let ends = [(&cps[0].grad, &mut res_a[k]), (&cps[1].grad, &mut res_b[0])];
            for (x, (gx, r)) in ends.into_iter().enumerate() {
                for a in 0..D {
                    r[a] += gx[0][a] * sf.f[x][0] + gx[1][a] * sf.f[x][1];
                }
                if !tangent {
                    continue;
                }
                for (y, cy) in cps.iter().enumerate() {
                    let gy = &cy.grad;
                    let jac = &sf.jac[x][y];
                    let blk = match (x, y) {
                        (0, 0) => &mut jd_a[k],
                        (1, 1) => &mut jd_b[0],
                        (0, 1) => &mut ju[k],
                        _ => &mut jl[k],
                    };
                    for a in 0..D {
                        let r0 = gx[0][a] * jac[(0, 0)] + gx[1][a] * jac[(1, 0)];
                        let r1 = gx[0][a] * jac[(0, 1)] + gx[1][a] * jac[(1, 1)];
                        if r0 == 0.0 && r1 == 0.0 {
                            continue;
                        }
                        for b in 0..D {
                            blk[a][b] += r0 * gy[0][b] + r1 * gy[1][b];
                        }
                    }
                }
            }
        }
        // Reaction at the control unknown.
        let [left, window, right] = self.control_forces();
        // Only the left region's where the control couples to no node of the interface (a DCB).
        let react = if lay.control_nodes.is_some() { left + window + right } else { left };
        self.reaction = react;
        let mut rmax = 0.0f64;
        let mut fmax = react.abs();
        for j in i0..=i1 {
            for a in 0..D {
                rmax = rmax.max(self.res[j][a].abs());
            }
            // Interface forces give the scale of the internal forces in the window.
            let pi = lay.cp(j).point;
            fmax = fmax.max(self.ev[pi].traction.norm() * lay.cp(j).weight);
        }
        Ok((rmax, fmax))
    }

    /// Solves the block tridiagonal system `J Δq = −res` over the window and adds `Δq` to `q`;
    /// returns the largest correction relative to the largest unknown.
    pub(super) fn correct(&mut self) -> Result<f64, ()> {
        self.stats.factorizations += 1;
        let mut lus = std::mem::take(&mut self.lus);
        let mut rhs = std::mem::take(&mut self.rhs);
        rhs.resize(self.i1 - self.i0 + 1, [0.0; D]);
        let out = self.eliminate(&mut lus, &mut rhs);
        self.lus = lus;
        self.rhs = rhs;
        out
    }

    /// A chord correction: [`Solver::correct`] with the block factors of its last call, for the
    /// residual of the current unknowns.
    pub(super) fn correct_chord(&mut self) -> f64 {
        let lus = std::mem::take(&mut self.lus);
        let mut rhs = std::mem::take(&mut self.rhs);
        for j in self.i0..=self.i1 {
            rhs[j - self.i0] = self.forward_row(&lus, &rhs, j);
        }
        let out = self.substitute(&lus, &rhs);
        self.lus = lus;
        self.rhs = rhs;
        out
    }

    /// Block elimination of the window's tangent, `D_j = J_jj − J_{j,j−1} D_{j−1}⁻¹ J_{j−1,j}`
    /// (the LU factors of each `D_j` into `lus`), with the residual's forward elimination in the
    /// same pass; then [`Solver::substitute`].
    pub(super) fn eliminate(&mut self, lus: &mut Vec<Lu<D>>, rhs: &mut [Vct<D>]) -> Result<f64, ()> {
        let i0 = self.i0;
        let n = self.i1 + 1 - i0;
        lus.resize(n, Lu { m: zb::<D>(), perm: [0; D] });
        for j in i0..=self.i1 {
            // `D_j` is built and factorised in its own slot (see `Lu::factorize`).
            let k = j - i0;
            let (done, rest) = lus.split_at_mut(k);
            let lu = &mut rest[0];
            lu.m = self.jd[j];
            if j > i0 {
                let x = done[k - 1].solve_blk(&self.ju[j - 1]);
                let s = blk_mul(&self.jl[j - 1], &x);
                sub(&mut lu.m, &s);
            }
            rhs[k] = self.forward_row(done, rhs, j);
            if !lu.factorize() {
                // Only the blocks factorised so far are factors.
                lus.truncate(k);
                return Err(());
            }
        }
        Ok(self.substitute(lus, rhs))
    }

    /// Node `j`'s row of the forward elimination of `−res`, from the rows before it. (Inlined:
    /// it runs per node of every correction; as a call it cost a run 1 % more instructions.)
    #[inline(always)]
    pub(super) fn forward_row(&self, lus: &[Lu<D>], rhs: &[Vct<D>], j: usize) -> Vct<D> {
        let i0 = self.i0;
        let mut r = self.res[j];
        for a in 0..D {
            r[a] = -r[a];
        }
        if j > i0 {
            let y = lus[j - 1 - i0].solve(&rhs[j - 1 - i0]);
            let v = blk_vec(&self.jl[j - 1], &y);
            for a in 0..D {
                r[a] -= v[a];
            }
        }
        r
    }

    /// Back substitution of the eliminated system: adds `Δq` to `q` and returns the largest
    /// correction relative to the largest unknown.
    pub(super) fn substitute(&mut self, lus: &[Lu<D>], rhs: &[Vct<D>]) -> f64 {
        let (i0, i1) = (self.i0, self.i1);
        let (mut dmax, mut qmax) = (0.0f64, 0.0f64);
        let mut next = [0.0; D];
        for j in (i0..=i1).rev() {
            let mut r = rhs[j - i0];
            if j < i1 {
                let v = blk_vec(&self.ju[j], &next);
                for a in 0..D {
                    r[a] -= v[a];
                }
            }
            let x = lus[j - i0].solve(&r);
            for a in 0..D {
                self.q[j][a] += x[a];
                dmax = dmax.max(x[a].abs());
                qmax = qmax.max(self.q[j][a].abs());
            }
            next = x;
        }
        dmax / qmax.max(1e-300)
    }

    /// Newton iterations at the control value `self.c` from the predictor in `q`.
    pub(super) fn solve(&mut self, states: &[LawState]) -> Result<usize, ()> {
        let max_it = self.s.newton.max_iterations;
        let mut stalled = false;
        // Whether the next correction reuses the last factorisation (a chord step), and the
        // residual of the last one that did.
        let mut chord = false;
        let mut chord_from = f64::INFINITY;
        for it in 0..=max_it {
            let (rmax, fmax) = self.assemble(states, !chord)?;
            let tol = self.s.newton.tolerance * fmax.max(1e-300);
            if !rmax.is_finite() {
                return Err(());
            }
            if rmax <= tol || (stalled && rmax <= 1e4 * tol) {
                return Ok(it);
            }
            if it == max_it {
                break;
            }
            let rel = rmax / fmax.max(1e-300);
            if chord && rel > CHORD_CONTRACTION * chord_from {
                // The chord does not contract: a full Newton step from here (the tangent was not
                // assembled, so assemble again).
                chord = false;
                chord_from = f64::INFINITY;
                self.assemble(states, true)?;
            }
            stalled = if chord {
                chord_from = rel;
                self.correct_chord()
            } else {
                self.correct()?
            } <= 1e-12;
            chord = rel <= self.chord_below;
        }
        Err(())
    }
}
