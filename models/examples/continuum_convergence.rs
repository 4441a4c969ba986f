//! How far the continuum DCB's load curve is from converged through the arm's thickness, and how
//! well one coarsening step (the diagnosis's estimate of its model-form floor's uncertainty)
//! measures that: `cargo run --release -p czid-models --example continuum_convergence`.
//!
//! Hartlen's DCB-01 to 29 mm and the paper's DCB to 14.5 mm, bilinear laws, 2 to 8 elements through
//! each arm; RMS load differences (N) over 90 common openings.
use czid_core::{columns, CohesiveLaw, ForwardModel};
use czid_models::dcb::Dcb;
use czid_models::dcb_2d::Dcb2d;
use czid_models::laws::Bilinear;

/// The load at `grid`, interpolated linearly in the record's openings.
fn loads_at(model: &Dcb2d, law: &dyn CohesiveLaw, grid: &[f64]) -> Vec<f64> {
    let r = model.simulate(law).unwrap_or_else(|f| panic!("{}", f.error));
    let (x, p) = (r.column(columns::DISPLACEMENT).unwrap(), r.column(columns::LOAD).unwrap());
    grid.iter()
        .map(|&g| {
            let j = x.partition_point(|&v| v < g).clamp(1, x.len() - 1);
            let w = (g - x[j - 1]) / (x[j] - x[j - 1]);
            p[j - 1] + w * (p[j] - p[j - 1])
        })
        .collect()
}

fn rms(a: &[f64], b: &[f64]) -> f64 {
    (a.iter().zip(b).map(|(u, v)| (u - v).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
}

fn main() {
    let cases = [
        ("Hartlen DCB-01", Dcb::hartlen_dcb01(), 29.0, Bilinear::bk(1e5, 30.0, 30.0, 0.8, 2.0, 2.0).unwrap()),
        ("paper DCB", Dcb::paper(), 14.5, Bilinear::bk(1e5, 35.0, 35.0, 0.5, 2.0, 2.0).unwrap()),
    ];
    println!("| specimen | elements through each arm | RMS from 8 elements (N) |");
    println!("|---|---|---|");
    for (name, mut beam, end, law) in cases {
        beam.control.max_displacement = Some(end + 0.5);
        beam.control.output_points = 100;
        let grid: Vec<f64> = (1..=90).map(|i| i as f64 * end / 90.0).collect();
        let curves: Vec<(usize, Vec<f64>)> = [2usize, 3, 4, 6, 8]
            .into_iter()
            .map(|n| {
                let mut m = Dcb2d::from_beam(&beam).unwrap();
                m.mesh.thickness_elements = n;
                (n, loads_at(&m, &law, &grid))
            })
            .collect();
        let finest = &curves[curves.len() - 1].1;
        for (n, p) in &curves[..curves.len() - 1] {
            println!("| {name} | {n} | {:.4} |", rms(p, finest));
        }
        println!("| {name} | 3 against 4 (the diagnosis's estimate) | {:.4} |", rms(&curves[1].1, &curves[2].1));
    }
}
