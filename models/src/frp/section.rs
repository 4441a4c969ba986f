//! Fibre-section analysis of a rectangular reinforced-concrete section, optionally with an FRP
//! plate bonded to its soffit: moment–curvature by strain compatibility and equilibrium, and the
//! cracking, yield and ultimate moments.
//!
//! Assumptions:
//! * plane sections remain plane and the plate is perfectly bonded (no slip): the strain at depth
//!   `y` below the top fibre is `ε(y) = ε_top + φ y`, tension positive, sagging curvature `φ ≥ 0`;
//! * the concrete is cut into `concrete_layers` horizontal layers (midpoint rule); each bar layer
//!   is a fibre at its centroid, and the concrete it displaces is removed (a fibre of negative
//!   area with the concrete's stress at that depth);
//! * the plate is a fibre at `h + t_f/2` (adhesive thickness neglected); it carries no strain from
//!   before bonding (the beam is taken as unloaded when plated);
//! * axial force zero (pure bending); moments are taken about mid-depth `h/2` and are in N·mm.
//!
//! For a given curvature, equilibrium `N(ε_top) = 0` is solved by bisection on the top strain
//! between `−φ y_max` (every fibre compressed) and 0 (every fibre stretched), which always bracket
//! a root. Characteristic points are found by bisection on the curvature of a strain condition
//! evaluated on the monotonic curves of the materials:
//! * **cracking**: the bottom concrete fibre (`y = h`) reaches `ε_t = f_t/E_c`;
//! * **yield**: the deepest bar layer reaches `ε_y = f_y/E_s`;
//! * **ultimate**: the top fibre reaches `−ε_cu` (crushing), or the plate reaches its rupture
//!   strain, whichever comes first.

use crate::materials::{Concrete, Frp, Steel, UniaxialMaterial, UniaxialState};
use czid_core::error::require_positive;
use czid_core::{CzError, Result};
use serde::{Deserialize, Serialize};

const OWNER: &str = "rc section";

fn default_layers() -> usize {
    RcSection::DEFAULT_LAYERS
}

/// A layer of bars: total area at one depth.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RebarLayer {
    /// Total bar area of the layer (mm²), e.g. 3 Ø16 = 3 · π 16²/4 = 603 mm².
    pub area: f64,
    /// Depth of the bars' centroid below the top fibre (mm).
    pub depth: f64,
}

impl RebarLayer {
    /// `count` bars of diameter `diameter` (mm) at depth `depth` (mm).
    pub fn bars(count: u32, diameter: f64, depth: f64) -> Self {
        RebarLayer { area: f64::from(count) * std::f64::consts::PI * diameter * diameter / 4.0, depth }
    }
}

/// An FRP plate bonded to the soffit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrpPlate {
    /// Plate width b_f (mm).
    pub width: f64,
    /// Plate thickness t_f (mm), the thickness the modulus refers to.
    pub thickness: f64,
    /// Plate material.
    pub material: Frp,
}

impl FrpPlate {
    /// Cross-section area `b_f t_f` (mm²).
    pub fn area(&self) -> f64 {
        self.width * self.thickness
    }
}

/// A rectangular RC section, optionally plated (see the [module documentation](self)).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RcSection {
    /// Width b (mm).
    pub width: f64,
    /// Overall depth h (mm).
    pub height: f64,
    /// Concrete.
    pub concrete: Concrete,
    /// Steel of every bar layer.
    pub steel: Steel,
    /// Bar layers (tension and compression bars alike), any order.
    pub bars: Vec<RebarLayer>,
    /// FRP plate on the soffit, if the section is strengthened.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plate: Option<FrpPlate>,
    /// Number of concrete layers (default 400).
    #[serde(default = "default_layers")]
    pub concrete_layers: usize,
}

/// Equilibrium state of a section at one curvature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SectionPoint {
    /// Curvature φ (1/mm), sagging positive.
    pub curvature: f64,
    /// Strain of the top fibre (negative in compression).
    pub top_strain: f64,
    /// Bending moment (N·mm), sagging positive.
    pub moment: f64,
    /// Depth of the neutral axis below the top fibre, `−ε_top/φ` (mm; infinite at φ = 0).
    pub neutral_axis: f64,
    /// Strain of the deepest bar layer.
    pub steel_strain: f64,
    /// Strain of the plate, if any.
    pub plate_strain: Option<f64>,
}

/// What ended the section's capacity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UltimateLimit {
    /// The top fibre reached the crushing strain ε_cu.
    ConcreteCrushing,
    /// The plate reached its rupture strain.
    PlateRupture,
}

/// The characteristic points of a section.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SectionMoments {
    /// First cracking of the bottom fibre.
    pub cracking: SectionPoint,
    /// First yield of the deepest bars.
    pub yielding: SectionPoint,
    /// Ultimate state.
    pub ultimate: SectionPoint,
    /// What governs the ultimate state.
    pub ultimate_limit: UltimateLimit,
}

#[derive(Clone, Copy, Debug)]
enum Material {
    Concrete,
    Steel,
    Plate,
}

#[derive(Clone, Copy, Debug)]
struct Fibre {
    depth: f64,
    area: f64,
    material: Material,
}

/// Committed material histories of every fibre of a section, for path-following analyses.
#[derive(Clone, Debug, PartialEq)]
pub struct SectionState {
    fibres: Vec<UniaxialState>,
}

impl RcSection {
    /// Default number of concrete layers: 400 (about 1 mm each for a 450 mm beam).
    pub const DEFAULT_LAYERS: usize = 400;

    /// Checks the geometry and the materials; errors name the offending value.
    pub fn validate(&self) -> Result<()> {
        require_positive(OWNER, "width", self.width)?;
        require_positive(OWNER, "height", self.height)?;
        self.concrete.validate()?;
        self.steel.validate()?;
        if self.concrete_layers < 10 {
            return Err(CzError::invalid(OWNER, "concrete_layers", self.concrete_layers as f64, "must be at least 10"));
        }
        if self.bars.is_empty() {
            return Err(CzError::config(format!("{OWNER}: bars"), "at least one bar layer is needed"));
        }
        for bar in &self.bars {
            require_positive(OWNER, "bars.area", bar.area)?;
            require_positive(OWNER, "bars.depth", bar.depth)?;
            if bar.depth >= self.height {
                return Err(CzError::invalid(
                    OWNER,
                    "bars.depth",
                    bar.depth,
                    format!("must lie inside the section, above h = {}", self.height),
                ));
            }
            if bar.area >= self.width * self.height / 10.0 {
                return Err(CzError::invalid(OWNER, "bars.area", bar.area, "must be below a tenth of b h"));
            }
        }
        if let Some(plate) = &self.plate {
            require_positive(OWNER, "plate.width", plate.width)?;
            require_positive(OWNER, "plate.thickness", plate.thickness)?;
            plate.material.validate()?;
            if plate.width > self.width {
                return Err(CzError::invalid(
                    OWNER,
                    "plate.width",
                    plate.width,
                    format!("must not exceed the section width {}", self.width),
                ));
            }
        }
        Ok(())
    }

    /// The section without its plate.
    pub fn unplated(&self) -> Self {
        RcSection { plate: None, ..self.clone() }
    }

    /// Depth of the deepest bar layer (mm).
    pub fn effective_depth(&self) -> f64 {
        self.bars.iter().map(|b| b.depth).fold(0.0, f64::max)
    }

    fn fibres(&self) -> Vec<Fibre> {
        let n = self.concrete_layers;
        let thickness = self.height / n as f64;
        let mut fibres: Vec<Fibre> = (0..n)
            .map(|i| Fibre {
                depth: (i as f64 + 0.5) * thickness,
                area: self.width * thickness,
                material: Material::Concrete,
            })
            .collect();
        for bar in &self.bars {
            fibres.push(Fibre { depth: bar.depth, area: bar.area, material: Material::Steel });
            // The concrete the bar displaces.
            fibres.push(Fibre { depth: bar.depth, area: -bar.area, material: Material::Concrete });
        }
        if let Some(plate) = &self.plate {
            fibres.push(Fibre {
                depth: self.height + 0.5 * plate.thickness,
                area: plate.area(),
                material: Material::Plate,
            });
        }
        fibres
    }

    /// A virgin state (no history) for [`RcSection::moment_curvature_from`].
    pub fn initial_state(&self) -> SectionState {
        SectionState { fibres: vec![UniaxialState::default(); self.fibres().len()] }
    }

    fn material(&self, material: Material) -> &dyn UniaxialMaterial {
        match material {
            Material::Concrete => &self.concrete,
            Material::Steel => &self.steel,
            // `fibres` only creates plate fibres when there is a plate.
            Material::Plate => self.plate.as_ref().map_or(&self.steel as &dyn UniaxialMaterial, |p| &p.material),
        }
    }

    /// Axial force (N) and moment about mid-depth (N·mm) for a strain profile, with the trial
    /// states written to `trial` when given.
    fn resultants(
        &self,
        fibres: &[Fibre],
        top_strain: f64,
        curvature: f64,
        committed: Option<&SectionState>,
        mut trial: Option<&mut Vec<UniaxialState>>,
    ) -> (f64, f64) {
        let mid = 0.5 * self.height;
        let (mut force, mut moment) = (0.0, 0.0);
        for (i, fibre) in fibres.iter().enumerate() {
            let strain = top_strain + curvature * fibre.depth;
            let previous = committed.map_or(UniaxialState::default(), |s| s.fibres[i]);
            let response = self.material(fibre.material).respond(strain, &previous);
            if let Some(trial) = trial.as_deref_mut() {
                trial[i] = response.state;
            }
            force += response.stress * fibre.area;
            moment += response.stress * fibre.area * (fibre.depth - mid);
        }
        (force, moment)
    }

    /// Top strain in equilibrium (`N = 0`) at `curvature`, by bisection.
    fn balance(&self, fibres: &[Fibre], curvature: f64, committed: Option<&SectionState>) -> Result<f64> {
        let deepest = fibres.iter().map(|f| f.depth).fold(0.0, f64::max);
        let force = |top: f64| self.resultants(fibres, top, curvature, committed, None).0;
        // With monotonic or secant histories, every fibre compressed gives N ≤ 0 and every fibre
        // stretched N ≥ 0; plastic strains in the steel may shift that, so widen if needed.
        let (mut low, mut high) = (-curvature * deepest, 0.0);
        let mut widen = 1e-4 + curvature * deepest;
        for _ in 0..60 {
            if force(low) <= 0.0 {
                break;
            }
            low -= widen;
            widen *= 2.0;
        }
        let mut widen = 1e-4 + curvature * deepest;
        for _ in 0..60 {
            if force(high) >= 0.0 {
                break;
            }
            high += widen;
            widen *= 2.0;
        }
        if !(force(low) <= 0.0 && force(high) >= 0.0) {
            return Err(CzError::Simulation(format!(
                "{OWNER}: no strain profile in axial equilibrium at curvature {curvature:e} 1/mm"
            )));
        }
        for _ in 0..200 {
            let middle = 0.5 * (low + high);
            if middle <= low || middle >= high {
                break;
            }
            if force(middle) <= 0.0 {
                low = middle;
            } else {
                high = middle;
            }
        }
        Ok(0.5 * (low + high))
    }

    fn point(
        &self,
        fibres: &[Fibre],
        curvature: f64,
        top_strain: f64,
        committed: Option<&SectionState>,
    ) -> SectionPoint {
        let (_, moment) = self.resultants(fibres, top_strain, curvature, committed, None);
        SectionPoint {
            curvature,
            top_strain,
            moment,
            neutral_axis: if curvature > 0.0 { -top_strain / curvature } else { f64::INFINITY },
            steel_strain: top_strain + curvature * self.effective_depth(),
            plate_strain: self.plate.as_ref().map(|p| top_strain + curvature * (self.height + 0.5 * p.thickness)),
        }
    }

    /// The equilibrium state at `curvature` (1/mm) on the materials' monotonic curves.
    pub fn at_curvature(&self, curvature: f64) -> Result<SectionPoint> {
        self.validate()?;
        if !(curvature.is_finite() && curvature >= 0.0) {
            return Err(CzError::invalid(OWNER, "curvature", curvature, "must be finite and not negative (sagging)"));
        }
        let fibres = self.fibres();
        let top = self.balance(&fibres, curvature, None)?;
        Ok(self.point(&fibres, curvature, top, None))
    }

    /// The monotonic state at which `excess(point)` (increasing with curvature) first reaches zero,
    /// by bisection on the curvature; the point returned lies on the safe side (`excess ≤ 0`).
    fn first_point_where(&self, what: &str, excess: impl Fn(&SectionPoint) -> f64) -> Result<SectionPoint> {
        let fibres = self.fibres();
        let at = |curvature: f64| -> Result<SectionPoint> {
            let top = self.balance(&fibres, curvature, None)?;
            Ok(self.point(&fibres, curvature, top, None))
        };
        let mut low = at(0.0)?;
        let mut curvature = 1e-7;
        let mut high = at(curvature)?;
        while excess(&high) < 0.0 {
            low = high;
            curvature *= 2.0;
            if curvature > 1.0 {
                return Err(CzError::Simulation(format!("{OWNER}: {what} never happens up to a curvature of 1/mm")));
            }
            high = at(curvature)?;
        }
        for _ in 0..100 {
            let middle = 0.5 * (low.curvature + high.curvature);
            if middle <= low.curvature || middle >= high.curvature {
                break;
            }
            let point = at(middle)?;
            if excess(&point) < 0.0 {
                low = point;
            } else {
                high = point;
            }
        }
        Ok(low)
    }

    /// First cracking: the bottom concrete fibre reaches `ε_t = f_t/E_c`.
    pub fn cracking(&self) -> Result<SectionPoint> {
        self.validate()?;
        let (h, target) = (self.height, self.concrete.cracking_strain());
        self.first_point_where("cracking", |p| p.top_strain + p.curvature * h - target)
    }

    /// First yield: the deepest bar layer reaches `ε_y = f_y/E_s`.
    pub fn yielding(&self) -> Result<SectionPoint> {
        self.validate()?;
        let target = self.steel.yield_strain();
        self.first_point_where("yield of the bars", |p| p.steel_strain - target)
    }

    /// Ultimate state: crushing of the top fibre at `ε_cu` or rupture of the plate, whichever
    /// happens first.
    ///
    /// Both are found on the section with an unbreakable plate, where top and plate strains grow
    /// continuously with the curvature: had the plate broken during the search, the strains after
    /// the jump would belong to another (unplated) branch.
    pub fn ultimate(&self) -> Result<(SectionPoint, UltimateLimit)> {
        self.validate()?;
        let mut intact = self.clone();
        if let Some(plate) = intact.plate.as_mut() {
            plate.material.tensile_strength = f64::MAX;
        }
        let crushing = self.concrete.crushing_strain;
        let crushed = intact.first_point_where("crushing", |p| -p.top_strain - crushing)?;
        if let (Some(plate), Some(strain)) = (&self.plate, crushed.plate_strain) {
            let rupture = plate.material.rupture_strain();
            if strain >= rupture {
                let ruptured =
                    intact.first_point_where("plate rupture", |p| p.plate_strain.unwrap_or(0.0) - rupture)?;
                return Ok((ruptured, UltimateLimit::PlateRupture));
            }
        }
        Ok((crushed, UltimateLimit::ConcreteCrushing))
    }

    /// Cracking, yield and ultimate points.
    pub fn moments(&self) -> Result<SectionMoments> {
        let (ultimate, ultimate_limit) = self.ultimate()?;
        Ok(SectionMoments { cracking: self.cracking()?, yielding: self.yielding()?, ultimate, ultimate_limit })
    }

    /// Moment–curvature path through `curvatures` (1/mm, any sequence of non-negative values,
    /// unloading included), committing the material histories after each point, from `state`
    /// (updated in place).
    pub fn moment_curvature_from(&self, state: &mut SectionState, curvatures: &[f64]) -> Result<Vec<SectionPoint>> {
        self.validate()?;
        let fibres = self.fibres();
        if state.fibres.len() != fibres.len() {
            return Err(CzError::config(
                format!("{OWNER}: state"),
                format!("has {} fibres, the section {}", state.fibres.len(), fibres.len()),
            ));
        }
        let mut points = Vec::with_capacity(curvatures.len());
        let mut trial = state.fibres.clone();
        for &curvature in curvatures {
            if !(curvature.is_finite() && curvature >= 0.0) {
                return Err(CzError::invalid(OWNER, "curvature", curvature, "must be finite and not negative"));
            }
            let top = self.balance(&fibres, curvature, Some(state))?;
            let point = self.point(&fibres, curvature, top, Some(state));
            self.resultants(&fibres, top, curvature, Some(state), Some(&mut trial));
            state.fibres.clone_from(&trial);
            points.push(point);
        }
        Ok(points)
    }

    /// Moment–curvature path from the virgin state.
    pub fn moment_curvature(&self, curvatures: &[f64]) -> Result<Vec<SectionPoint>> {
        self.moment_curvature_from(&mut self.initial_state(), curvatures)
    }
}
