//! Engine kernels against finite differences and a dense solve: the co-rotational element's
//! forces are the gradient of its energy and its tangent the Jacobian of its forces; the
//! large-rotation gap gradients/Hessians likewise; the band LU solves like a dense one.

#![allow(clippy::needless_range_loop)] // index loops mirror the matrix algebra being checked

use czid_models::fe::banded::BandMatrix;
use czid_models::fe::corotational;
use czid_models::fe::interface::{kinematics, InterfacePoint, PointKind, POINT_DOFS};
use czid_models::fe::mesh::{Layer, Mesh, Section};

#[test]
fn corotational_forces_and_tangent_match_finite_differences() {
    let s = Section { e: 20_000.0, g: 2_000.0, b: 25.0, h: 2.7 };
    let q = [0.01, 0.3, 0.4, -0.02, 1.1, 0.55];
    let el = corotational::element(&s, 1.0, 2.5, &q);
    for j in 0..6 {
        let h = 1e-6;
        let (mut qp, mut qm) = (q, q);
        qp[j] += h;
        qm[j] -= h;
        let (ep, em) = (corotational::element(&s, 1.0, 2.5, &qp), corotational::element(&s, 1.0, 2.5, &qm));
        let fd_f = (ep.energy - em.energy) / (2.0 * h);
        assert!((fd_f - el.force[j]).abs() < 1e-5 * el.force.iter().fold(1.0f64, |m, v| m.max(v.abs())), "force {j}");
        for i in 0..6 {
            let fd_k = (ep.force[i] - em.force[i]) / (2.0 * h);
            let scale = el.tangent.iter().flatten().fold(1.0f64, |m, v| m.max(v.abs()));
            assert!((fd_k - el.tangent[i][j]).abs() < 1e-6 * scale, "K[{i}][{j}]: {fd_k} vs {}", el.tangent[i][j]);
        }
    }
}

#[test]
fn large_rotation_gap_derivatives_match_finite_differences() {
    let s = Section { e: 20_000.0, g: 2_000.0, b: 25.0, h: 2.7 };
    let layers = vec![
        Layer { section: s, y: 1.35, axial: true, first: 0, last: 1 },
        Layer { section: s, y: 4.05, axial: true, first: 0, last: 1 },
    ];
    let mesh = Mesh::new(vec![0.0, 1.0], layers, 0).unwrap();
    let n = mesh.n_dofs();
    let q: Vec<f64> = (0..n).map(|i| 0.05 * ((i as f64) * 1.7).sin()).collect();
    let mut hess = [[[0.0; POINT_DOFS]; POINT_DOFS]; 2];
    for lower in [Some(0), None] {
        let pt = InterfacePoint { node: 0, upper: 1, lower, area: 1.0, factor: 1.0, kind: PointKind::Cohesive };
        let k = kinematics(&mesh, &pt, &q, true, &mut hess);
        let h0 = hess;
        for (a, &da) in k.dofs.iter().enumerate() {
            if da == usize::MAX {
                continue;
            }
            let h = 1e-6;
            let (mut qp, mut qm) = (q.clone(), q.clone());
            qp[da] += h;
            qm[da] -= h;
            let (kp, km) = (kinematics(&mesh, &pt, &qp, true, &mut hess), kinematics(&mesh, &pt, &qm, true, &mut hess));
            for c in 0..2 {
                let fd = (kp.gap[c] - km.gap[c]) / (2.0 * h);
                assert!((fd - k.grad[c][a]).abs() < 1e-8, "grad {c} {a}");
                // (On a symmetry plane only the upper side's block is written: the lower side
                // has no unknowns.)
                for b in (0..POINT_DOFS).filter(|&b| k.dofs[b] != usize::MAX) {
                    let fdh = (kp.grad[c][b] - km.grad[c][b]) / (2.0 * h);
                    assert!((fdh - h0[c][b][a]).abs() < 1e-6, "hess {c} {b} {a}: {fdh} vs {}", h0[c][b][a]);
                }
            }
        }
    }
}

#[test]
fn band_lu_solves_like_a_dense_solve() {
    for bw in [3usize, 4, 5, 7, 11] {
        let n = 40;
        let mut a = BandMatrix::zeros(n, bw);
        let mut dense = vec![vec![0.0; n]; n];
        for i in 0..n {
            for j in i.saturating_sub(bw)..=(i + bw).min(n - 1) {
                let v = if i == j {
                    10.0 + i as f64
                } else {
                    ((i * 7 + j * 3) % 5) as f64 - 2.0 + 0.1 * (i as f64 - j as f64)
                };
                a.add(i, j, v);
                dense[i][j] = v;
            }
        }
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
        let mut b: Vec<f64> = (0..n).map(|i| (0..n).map(|j| dense[i][j] * x[j]).sum()).collect();
        let mut b2 = b.clone();
        let mut b3 = b.clone();
        a.factorize().unwrap();
        a.solve_in_place(&mut b);
        a.solve2_in_place(&mut b2, &mut b3);
        for i in 0..n {
            assert!((b[i] - x[i]).abs() < 1e-10, "bw {bw}");
            assert!((b2[i] - x[i]).abs() < 1e-10 && (b3[i] - x[i]).abs() < 1e-10);
        }
    }
}
