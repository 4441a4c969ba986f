//! The private test law's tangent against finite differences (so engine tests rest on a correct law).

mod fe_support;
use czid_core::{CohesiveLaw, Gap, LawState};
use fe_support::TestBilinear;

#[test]
fn test_law_tangent_matches_finite_differences() {
    let law = TestBilinear::new(1e5, 60.0, 0.3);
    let prev = LawState::default();
    for g in [[0.0007, 0.0], [0.003, 0.0], [0.0008, 0.0003], [0.002, -0.004], [-0.001, 0.002]] {
        let gap = Gap::new(g[0], g[1]);
        let ev = law.evaluate(&gap, &prev);
        for j in 0..2 {
            let h = 1e-9;
            let mut gp = gap;
            gp[j] += h;
            let mut gm = gap;
            gm[j] -= h;
            let d = (law.evaluate(&gp, &prev).traction - law.evaluate(&gm, &prev).traction) / (2.0 * h);
            for i in 0..2 {
                let scale = ev.tangent.abs().max().max(1.0);
                assert!(
                    (d[i] - ev.tangent[(i, j)]).abs() < 1e-5 * scale,
                    "{g:?} ({i},{j}): fd {} vs {}",
                    d[i],
                    ev.tangent[(i, j)]
                );
            }
        }
    }
}
