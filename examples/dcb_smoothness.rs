//! Finite-difference sensitivities of the DCB's load and debonded length at fixed openings, for
//! steps of 1 % and 0.5 % of a strength and a toughness parameter (the table behind
//! `models/tests/dcb_smoothness.rs`): `cargo run --release --example dcb_smoothness -- [paper|hartlen]`.
use czid_core::{columns, CohesiveLaw, ForwardModel, Record};
use czid_models::dcb::Dcb;
use czid_models::laws::{Bilinear, StCzm};

fn at(rec: &Record, c: &str, x: f64) -> f64 {
    let (d, v) = (rec.column(columns::DISPLACEMENT).unwrap(), rec.column(c).unwrap());
    d.iter().position(|v| (v - x).abs() < 1e-9).map_or(f64::NAN, |i| v[i])
}

type Scaled = Box<dyn Fn(usize, f64) -> Box<dyn CohesiveLaw>>;

fn main() {
    let case = std::env::args().nth(1).unwrap_or_else(|| "paper".into());
    let (d, names, xs, law): (Dcb, [&str; 2], Vec<f64>, Scaled) = if case == "hartlen" {
        let mut d = Dcb::hartlen_dcb01();
        d.control.output_points = 60;
        let law: Scaled = Box::new(|k, f| {
            let (s, g) = if k == 0 { (30.0 * f, 0.8) } else { (30.0, 0.8 * f) };
            Box::new(Bilinear::bk(1e5, s, 40.0, g, 1.6, 2.0).unwrap())
        });
        (d, ["strength_n", "g_ic"], vec![3.0, 5.0, 6.0, 8.0, 10.0, 15.0, 20.0, 25.0, 30.0], law)
    } else {
        let mut d = Dcb::paper();
        d.control.max_displacement = Some(10.5);
        d.control.output_points = 105;
        let law: Scaled = Box::new(|k, f| {
            let (s, u) = if k == 0 { (27.0 * f, 0.003273) } else { (27.0, 0.003273 * f) };
            Box::new(StCzm::sawtooth(s, 0.00027, u, 40.0, 0.00025, 0.003273).unwrap())
        });
        (d, ["strength_n", "u_c_n"], vec![1.0, 1.5, 1.8, 2.0, 2.2, 3.0, 4.0, 6.0, 8.0, 10.0], law)
    };
    let base = d.simulate(law(0, 1.0).as_ref()).unwrap();
    for (k, name) in names.iter().enumerate() {
        println!("{case} DCB, ∂/∂ln {name} (steps 1 % / 0.5 %)");
        let fd = |h: f64| {
            let (p, m) = (d.simulate(law(k, 1.0 + h).as_ref()).unwrap(), d.simulate(law(k, 1.0 - h).as_ref()).unwrap());
            xs.iter()
                .map(|&x| {
                    let f = |c| (at(&p, c, x) - at(&m, c, x)) / (2.0 * h);
                    (f(columns::LOAD), f(columns::DEBONDED_LENGTH))
                })
                .collect::<Vec<_>>()
        };
        let (a, b) = (fd(0.01), fd(0.005));
        for (i, x) in xs.iter().enumerate() {
            println!(
                "  δ = {x:5.1} mm: P = {:8.4} N, dP {:+.5e} / {:+.5e} (ratio {:.4}); a = {:7.3} mm, da {:+.5e} / {:+.5e} (ratio {:.4})",
                at(&base, columns::LOAD, *x),
                a[i].0,
                b[i].0,
                a[i].0 / b[i].0,
                at(&base, columns::DEBONDED_LENGTH, *x),
                a[i].1,
                b[i].1,
                a[i].1 / b[i].1
            );
        }
    }
}
