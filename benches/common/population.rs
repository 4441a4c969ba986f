//! Laws a run is benchmarked with: a population drawn as an identification draws it (uniform in
//! each parameter's range, log-uniform where the problem file says `scale = "log"`), so a
//! benchmark cycles through many laws instead of repeating one whose runs a cache could serve.
//! Shared by `benches/forward.rs`, `examples/dcb_population.rs` and `examples/mmb_population.rs`.

use czid_core::CohesiveLaw;
use czid_models::laws::{Bilinear, StCzm};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `n` ST-CZM laws in the parameter ranges of `examples/paper-dcb/problem.toml` (MPa, mm), the
/// first one Shi & Zhang's Table 3.
pub fn paper_laws(n: usize, seed: u64) -> Vec<Box<dyn CohesiveLaw>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut laws: Vec<Box<dyn CohesiveLaw>> =
        vec![Box::new(StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).expect("Table 3 is valid"))];
    while laws.len() < n {
        let lin = |rng: &mut ChaCha8Rng, lo: f64, hi: f64| lo + (hi - lo) * rng.random::<f64>();
        let log = |rng: &mut ChaCha8Rng, lo: f64, hi: f64| lo * (hi / lo).powf(rng.random::<f64>());
        let (sn, uen, ucn) = (lin(&mut rng, 10.0, 60.0), log(&mut rng, 1e-4, 1e-3), log(&mut rng, 1.5e-3, 1e-2));
        let (st, uet, uct) = (lin(&mut rng, 10.0, 80.0), log(&mut rng, 1e-4, 1e-3), log(&mut rng, 1.5e-3, 1e-2));
        if let Ok(law) = StCzm::sawtooth(sn, uen, ucn, st, uet, uct) {
            laws.push(Box::new(law));
        }
    }
    laws
}

/// `n` bilinear (B-K) laws for Hartlen's glass/epoxy DCB: strength 20–60 MPa, G_Ic 0.5–1.2 N/mm,
/// penalty 10⁵ MPa/mm, mode II twice mode I; the first one the forward bench's law (30 MPa,
/// 0.8 N/mm).
pub fn hartlen_laws(n: usize, seed: u64) -> Vec<Box<dyn CohesiveLaw>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut laws: Vec<Box<dyn CohesiveLaw>> =
        vec![Box::new(Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0).expect("the bench's law is valid"))];
    while laws.len() < n {
        let s = 20.0 + 40.0 * rng.random::<f64>();
        let g = 0.5 + 0.7 * rng.random::<f64>();
        if let Ok(law) = Bilinear::bk(1e5, s, 1.3 * s, g, 2.0 * g, 2.0) {
            laws.push(Box::new(law));
        }
    }
    laws
}

/// `n` bilinear (B-K) laws in the parameter ranges of `examples/mixed-mode-synthetic/problem.toml`
/// (σ_n 5–80 and σ_t 5–120 MPa log-uniform, G_Ic 0.2–2 and G_IIc 0.3–8 N/mm, η 1–4; penalty
/// 10⁵ MPa/mm), the first one the MMB bench's law (`Mmb::hartlen_half_mode_two`).
#[allow(dead_code)] // `benches/forward.rs` and `examples/mmb_population.rs` use it, `examples/dcb_population.rs` does not
pub fn mixed_mode_laws(n: usize, seed: u64) -> Vec<Bilinear> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut laws = vec![Bilinear::bk(1e5, 25.0, 35.0, 0.8, 3.0, 2.2).expect("the bench's law is valid")];
    while laws.len() < n {
        let lin = |rng: &mut ChaCha8Rng, lo: f64, hi: f64| lo + (hi - lo) * rng.random::<f64>();
        let log = |rng: &mut ChaCha8Rng, lo: f64, hi: f64| lo * (hi / lo).powf(rng.random::<f64>());
        let (sn, gi, st) = (log(&mut rng, 5.0, 80.0), lin(&mut rng, 0.2, 2.0), log(&mut rng, 5.0, 120.0));
        let (gii, eta) = (lin(&mut rng, 0.3, 8.0), lin(&mut rng, 1.0, 4.0));
        if let Ok(law) = Bilinear::bk(1e5, sn, st, gi, gii, eta) {
            laws.push(law);
        }
    }
    laws
}
