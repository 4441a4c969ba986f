//! Times the reference (continuum) run of a `gap-bench` DCB case's base model at given law
//! values: `reference_run SEED INDEX STRENGTH G_IC [DUMP_FILE] [--large-rotation]` (the last
//! switches large rotations on in both models, as a refit that names them runs the reference).

use czid_core::ForwardModel;
use czid_models::dcb::Dcb;
use czid_models::dcb_2d::Dcb2d;
use czid_models::laws::Bilinear;
use czid_problems::diagnose::bench::Family;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let usage = "usage: reference_run SEED INDEX STRENGTH G_IC [DUMP_FILE] (integers SEED, INDEX; \
                 the law's strength in MPa and G_Ic in N/mm)";
    let number = |i: usize| -> f64 {
        a.get(i).and_then(|v| v.parse().ok()).unwrap_or_else(|| {
            eprintln!("{usage}");
            std::process::exit(2)
        })
    };
    let (seed, index) = (number(1) as u64, number(2) as usize);
    let (strength, g) = (number(3), number(4));
    let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15).wrapping_add(index as u64));
    let draw = Family::Dcb.draw(index, &mut rng);
    let setup = Family::Dcb.base_setup(&draw).unwrap();
    let json = serde_json::to_value(setup.models["dcb"].as_ref()).unwrap();
    let mut fields = json.clone();
    fields.as_object_mut().unwrap().remove("type");
    let mut beam: Dcb = serde_json::from_value(fields).unwrap();
    beam.effects.large_rotation = a.iter().any(|v| v == "--large-rotation");
    let law = Bilinear::bk(1e5, strength, strength, g, 2.0, 2.0).unwrap();
    let t = Instant::now();
    let r = beam.simulate(&law).unwrap();
    println!(
        "beam: {:.3} s, {} rows, output_points {}",
        t.elapsed().as_secs_f64(),
        r.rows(),
        beam.control.output_points
    );
    let reference = Dcb2d::from_beam(&beam).unwrap();
    println!("mesh {:?} end {:?}", reference.mesh, reference.control.max_displacement);
    let t = Instant::now();
    let (rec, stats) = reference.simulate_with_stats(&law).unwrap();
    println!("reference: {:.2} s, {} rows, {:?}", t.elapsed().as_secs_f64(), rec.rows(), stats);
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for c in rec.columns() {
        c.name.hash(&mut h);
        for v in &c.values {
            v.to_bits().hash(&mut h);
        }
    }
    println!("record bits hash {:016x}", h.finish());
    if let Some(path) = a.get(5).filter(|v| !v.starts_with("--")) {
        let mut out = String::new();
        for c in rec.columns() {
            out += &format!("{} {}\n", c.name, c.values.iter().map(|v| format!("{v:e}")).collect::<Vec<_>>().join(" "));
        }
        std::fs::write(path, out).unwrap();
    }
}
