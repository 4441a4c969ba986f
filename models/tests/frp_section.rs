//! Fibre-section analysis of the paper's RC beam against a hand section analysis written out here
//! (closed-form arithmetic, no calls to the section code), and the beam's configuration.
//!
//! The section ([`FrpBeamSpec::paper`]): b = 200, h = 450 mm; 3 Ø16 at d = 402 mm, 2 Ø10 at
//! d' = 45 mm; f'c = 47 MPa, E_c = 4700 √f'c, f_t = 0.395 (f'c/0.8)^0.55; E_s = 200 GPa,
//! f_y = 500 MPa, E_h = 2 GPa; ε_cu = 0.0035; CFRP plate 100 × 0.999 mm, E_f = 200 GPa.

use czid_models::frp::{FrpBeamSpec, RcSection, RebarLayer, UltimateLimit};
use std::f64::consts::PI;

// The hand analysis' inputs, written out (not read from the code's defaults).
const B: f64 = 200.0;
const H: f64 = 450.0;
const D: f64 = 450.0 - 30.0 - 10.0 - 8.0; // cover, stirrup, half a Ø16
const D2: f64 = 30.0 + 10.0 + 5.0; // cover, stirrup, half a Ø10
const FC: f64 = 47.0;
const ES: f64 = 200_000.0;
const FY: f64 = 500.0;
const EH: f64 = 2_000.0;
const ECU: f64 = 0.0035;
const EF: f64 = 200_000.0;
const AF: f64 = 100.0 * 0.999;
const HF: f64 = 450.0 + 0.999 / 2.0;

fn areas() -> (f64, f64) {
    (3.0 * PI * 16.0 * 16.0 / 4.0, 2.0 * PI * 10.0 * 10.0 / 4.0)
}

fn ec() -> f64 {
    4700.0 * FC.sqrt()
}

fn ft() -> f64 {
    0.395 * (FC / 0.8).powf(0.55)
}

/// Positive root of `a x² + b x + c = 0`.
fn root(a: f64, b: f64, c: f64) -> f64 {
    (-b + (b * b - 4.0 * a * c).sqrt()) / (2.0 * a)
}

fn assert_within(value: f64, expected: f64, tolerance: f64, what: &str) -> f64 {
    let difference = (value - expected) / expected;
    assert!(difference.abs() <= tolerance, "{what}: {value:.4e} vs hand {expected:.4e} ({:+.2} %)", 100.0 * difference);
    difference
}

/// Cracking moment by hand. Assumptions: uncracked section, linear elastic concrete (E_c) in
/// tension and compression, bars as (n − 1) A_s of concrete (the concrete they displace
/// deducted), cracking when the bottom fibre reaches f_t: `M_cr = f_t I_tr/(h − ȳ)`.
fn hand_cracking_moment() -> f64 {
    let (a_s, a_s2) = areas();
    let n1 = ES / ec() - 1.0;
    let area = B * H + n1 * (a_s + a_s2);
    let centroid = (B * H * H / 2.0 + n1 * (a_s * D + a_s2 * D2)) / area;
    let inertia = B * H.powi(3) / 12.0
        + B * H * (H / 2.0 - centroid).powi(2)
        + n1 * a_s * (D - centroid).powi(2)
        + n1 * a_s2 * (centroid - D2).powi(2);
    ft() * inertia / (H - centroid)
}

/// Yield moment by hand. Assumptions: cracked section, concrete carries no tension and is linear
/// elastic (E_c) in compression, compression bars elastic as (n − 1) A_s', the plate (if any)
/// linear as n_f A_f at h + t_f/2; the tension bars just at f_y. Neutral axis from the first
/// moment of the transformed section, `b c²/2 + (n − 1) A_s' (c − d') = n A_s (d − c) + n_f A_f (h_f − c)`;
/// moment from the forces about the top fibre.
fn hand_yield_moment(plate: bool) -> f64 {
    let (a_s, a_s2) = areas();
    let n = ES / ec();
    let a_f = if plate { AF } else { 0.0 };
    let n_f = EF / ec();
    let c =
        root(B / 2.0, (n - 1.0) * a_s2 + n * a_s + n_f * a_f, -((n - 1.0) * a_s2 * D2 + n * a_s * D + n_f * a_f * HF));
    let curvature = FY / ES / (D - c);
    let concrete = 0.5 * ec() * curvature * c * B * c;
    let top_bars = (ES - ec()) * curvature * (c - D2) * a_s2;
    let plate_force = EF * curvature * (HF - c) * a_f;
    let bars = a_s * FY;
    // Equilibrium holds by construction of c.
    assert!((concrete + top_bars - bars - plate_force).abs() < 1e-6 * bars);
    bars * D + plate_force * HF - concrete * c / 3.0 - top_bars * D2
}

/// Ultimate moment by hand (unplated). Assumptions: EC2 rectangular stress block for
/// f_ck ≤ 50 MPa (λ = 0.8, η = 1, mean strength f_c, no partial factors) with the top fibre at
/// ε_cu = 0.0035; tension bars yielded and hardening, `σ_s = f_y + E_h (ε_s − ε_y)`, with
/// `ε_s = ε_cu (d − c)/c`; top bars elastic, `σ_s' = E_s ε_cu (c − d')/c` (checked below), outside
/// the block (λ c < d', checked) so no concrete is displaced. Equilibrium times c is the quadratic
/// `η f_c b λ c² + A_s' E_s ε_cu (c − d') = A_s [(f_y − E_h ε_y) c + E_h ε_cu (d − c)]`.
fn hand_ultimate_moment() -> f64 {
    let (a_s, a_s2) = areas();
    let (lambda, eta) = (0.8, 1.0);
    let eps_y = FY / ES;
    let block = eta * FC * B * lambda;
    let c = root(
        block,
        a_s2 * ES * ECU - a_s * (FY - EH * eps_y) + a_s * EH * ECU,
        -(a_s2 * ES * ECU * D2 + a_s * EH * ECU * D),
    );
    let eps_s = ECU * (D - c) / c;
    let eps_s2 = ECU * (c - D2) / c;
    assert!(eps_s > eps_y && eps_s2.abs() < eps_y && lambda * c < D2, "hand assumptions: c = {c}");
    let concrete = block * c;
    let top_bars = a_s2 * ES * eps_s2;
    let bars = a_s * (FY + EH * (eps_s - eps_y));
    assert!((concrete + top_bars - bars).abs() < 1e-6 * bars);
    concrete * (D - lambda * c / 2.0) + top_bars * (D - D2)
}

fn paper_section() -> RcSection {
    FrpBeamSpec::paper().unwrap().section.unplated()
}

#[test]
fn the_hand_analysis_reads_the_same_section() {
    let section = paper_section();
    let (a_s, a_s2) = areas();
    assert_eq!((section.width, section.height), (B, H));
    assert!((section.bars[0].area - a_s).abs() < 1e-9 && section.bars[0].depth == D);
    assert!((section.bars[1].area - a_s2).abs() < 1e-9 && section.bars[1].depth == D2);
    assert!((section.concrete.elastic_modulus - ec()).abs() < 1e-9);
    assert!((section.concrete.tensile_strength - ft()).abs() < 1e-12);
    assert_eq!(section.concrete.crushing_strain, ECU);
    let steel = &section.steel;
    assert_eq!((steel.elastic_modulus, steel.yield_strength, steel.hardening_modulus), (ES, FY, EH));
}

#[test]
fn unstrengthened_moments_match_the_hand_analysis() {
    let moments = paper_section().moments().unwrap();
    let cracking = assert_within(moments.cracking.moment, hand_cracking_moment(), 0.05, "cracking");
    let yielding = assert_within(moments.yielding.moment, hand_yield_moment(false), 0.05, "yield");
    let ultimate = assert_within(moments.ultimate.moment, hand_ultimate_moment(), 0.05, "ultimate");
    assert_eq!(moments.ultimate_limit, UltimateLimit::ConcreteCrushing);
    // The figures, kN·m (measured: fibre 27.50 / 111.77 / 125.94; hand 27.62 / 110.57 / 127.77).
    println!(
        "cracking {:.2} vs {:.2} ({:+.2} %), yield {:.2} vs {:.2} ({:+.2} %), ultimate {:.2} vs {:.2} ({:+.2} %)",
        moments.cracking.moment / 1e6,
        hand_cracking_moment() / 1e6,
        100.0 * cracking,
        moments.yielding.moment / 1e6,
        hand_yield_moment(false) / 1e6,
        100.0 * yielding,
        moments.ultimate.moment / 1e6,
        hand_ultimate_moment() / 1e6,
        100.0 * ultimate
    );
    // The differences have known signs and sizes: Hognestad's curve is slightly softer than the
    // linear concrete at cracking; tension softening over the 150 mm band adds to the yield
    // moment; the Hognestad block (area 0.71 f_c c) is shallower in force than EC2's 0.8 f_c c, so
    // the neutral axis is deeper and the lever arm shorter at the ultimate state.
    assert!(cracking.abs() < 0.01 && yielding > 0.0 && yielding < 0.02 && ultimate < 0.0 && ultimate > -0.03);
}

#[test]
fn strengthened_yield_moment_matches_the_hand_analysis() {
    let section = FrpBeamSpec::paper().unwrap().section;
    let yielding = section.yielding().unwrap();
    assert_within(yielding.moment, hand_yield_moment(true), 0.05, "plated yield");
    // The plate raises every moment of the section.
    let plain = paper_section().moments().unwrap();
    let plated = section.moments().unwrap();
    assert!(plated.cracking.moment > plain.cracking.moment);
    assert!(plated.yielding.moment > 1.1 * plain.yielding.moment);
    assert!(plated.ultimate.moment > 1.5 * plain.ultimate.moment);
}

#[test]
fn uncracked_stiffness_is_the_transformed_section() {
    // Far below cracking the section is linear: M/φ = E_c I_tr (I_tr as in the hand cracking
    // analysis: M_cr (h − ȳ)/f_t).
    let section = paper_section();
    let point = section.at_curvature(1e-8).unwrap();
    let (a_s, a_s2) = areas();
    let n1 = ES / ec() - 1.0;
    let centroid = (B * H * H / 2.0 + n1 * (a_s * D + a_s2 * D2)) / (B * H + n1 * (a_s + a_s2));
    let inertia = hand_cracking_moment() * (H - centroid) / ft();
    assert_within(point.moment / point.curvature, ec() * inertia, 2e-3, "E_c I_tr");
    assert_within(point.neutral_axis, centroid, 1e-3, "neutral axis");
}

#[test]
fn path_following_reproduces_the_monotonic_points_and_unloads() {
    let section = paper_section();
    let moments = section.moments().unwrap();
    let ultimate = moments.ultimate.curvature;
    let curvatures: Vec<f64> = (1..=60).map(|i| ultimate * f64::from(i) / 60.0).collect();
    let path = section.moment_curvature(&curvatures).unwrap();
    // Not exactly: as the neutral axis rises after cracking, the compressed fibres just above it
    // see their strain fall and unload along their secant, which the monotonic curves ignore
    // (a difference of about 1e-4 here).
    for (point, &curvature) in path.iter().zip(&curvatures) {
        let monotonic = section.at_curvature(curvature).unwrap();
        assert!((point.moment - monotonic.moment).abs() < 1e-3 * monotonic.moment, "{curvature}");
    }
    let last = path.last().unwrap();
    assert!((last.moment - moments.ultimate.moment).abs() < 1e-3 * last.moment);
    // Unloading from three times the yield curvature: the moment falls steadily and reaches zero
    // at a permanent curvature held by the yielded bars (concrete has no plastic strain here, so
    // it is the steel's), well above zero.
    let mut state = section.initial_state();
    let peak_curvature = 3.0 * moments.yielding.curvature;
    let up: Vec<f64> = (1..=40).map(|i| peak_curvature * f64::from(i) / 40.0).collect();
    section.moment_curvature_from(&mut state, &up).unwrap();
    let down: Vec<f64> = (1..=40).map(|i| peak_curvature * (1.0 - f64::from(i) / 40.0)).collect();
    let unloaded = section.moment_curvature_from(&mut state, &down).unwrap();
    let zero = unloaded.iter().position(|p| p.moment < 0.0).unwrap();
    assert!(unloaded[..=zero].windows(2).all(|w| w[1].moment < w[0].moment));
    assert!(unloaded[zero].curvature > 0.3 * peak_curvature, "{:?}", unloaded[zero]);
}

#[test]
fn invalid_sections_are_named() {
    let section = paper_section();
    let message = |s: RcSection| s.validate().unwrap_err().to_string();
    assert!(message(RcSection { width: -200.0, ..section.clone() }).contains("`width`"));
    let mut deep = section.clone();
    deep.bars.push(RebarLayer { area: 100.0, depth: 460.0 });
    assert!(message(deep).contains("`bars.depth`"));
    assert!(message(RcSection { bars: vec![], ..section.clone() }).contains("bars"));
    assert!(message(RcSection { concrete_layers: 3, ..section.clone() }).contains("`concrete_layers`"));
    let mut wide = FrpBeamSpec::paper().unwrap().section;
    if let Some(plate) = wide.plate.as_mut() {
        plate.width = 300.0;
    }
    assert!(message(wide).contains("`plate.width`"));
    assert!(section.at_curvature(-1e-6).unwrap_err().to_string().contains("`curvature`"));
}

#[test]
fn beam_configuration_round_trips_and_is_plausible() {
    let spec = FrpBeamSpec::paper().unwrap();
    let text = toml::to_string(&spec).unwrap();
    let back: FrpBeamSpec = toml::from_str(&text).unwrap();
    assert_eq!(back, spec);
    back.validate().unwrap();
    assert!(toml::from_str::<FrpBeamSpec>(&text.replace("load_spacing", "load_spaceing")).is_err());
    // The paper's figures.
    assert_eq!((spec.beam_length, spec.plate_length, spec.section.width, spec.section.height), (4000.0, 3800.0, B, H));
    let plate = spec.section.plate.as_ref().unwrap();
    assert_eq!((plate.width, plate.thickness), (100.0, 0.999));
    assert_eq!(spec.shear_span(), 1200.0);
    // Under-reinforced: ρ = A_s/(b d) well below the balanced ratio (ACI: 0.85 β1 f'c/f_y ·
    // 600/(600 + f_y), β1 = 0.85 − 0.05 (f'c − 28)/7).
    let rho = areas().0 / (B * D);
    let beta1 = 0.85 - 0.05 * (FC - 28.0) / 7.0;
    let balanced = 0.85 * beta1 * FC / FY * 600.0 / (600.0 + FY);
    assert!(rho < 0.3 * balanced, "ρ = {rho}, balanced {balanced}");
    // Shear does not govern: the shear at the plated section's flexural capacity stays below the
    // ACI shear capacity (0.17 √f'c b d + A_v f_yt d/s).
    let ultimate = spec.section.ultimate().unwrap().0.moment;
    let shear = spec.load_for_moment(ultimate) / 2.0;
    let capacity = 0.17 * FC.sqrt() * B * D + 2.0 * PI * 25.0 * 300.0 * D / 100.0;
    assert!((spec.shear_capacity() - capacity).abs() < 1e-6 * capacity);
    assert!(shear < capacity, "V = {shear} N, capacity {capacity} N");
    // Long-joint debonding load b_f √(2 G_f E_f t_f) of the plate (48.7 kN).
    let g_f = 0.308 * ft().sqrt();
    assert!((spec.plate_debonding_load() - 100.0 * (2.0 * g_f * EF * 0.999).sqrt()).abs() < 1e-6);
}
