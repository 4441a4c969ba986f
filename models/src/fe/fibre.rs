//! Fibre-section beam element: a two-node beam whose axial force and bending moment come from
//! uniaxial materials at fibres through the depth, with their history.
//!
//! Kinematics are those of [`super::beam`]: linear `u` and `θ` along the element, so the axial
//! strain `ε` and the curvature `κ = θ'` are constant and one section at the element's middle
//! integrates it exactly. A fibre at height `z` above the layer's centroid has the strain
//! `ε − z κ − ε₀` (plane sections; `ε₀` an initial, stress-free strain such as shrinkage). The
//! section forces are `N = Σ σ A` and `M = −Σ σ A z` (work-conjugate to `ε` and `κ`), their
//! tangent the fibres' `Σ E_t A [1, −z; −z, z²]`. Transverse shear is not part of the fibre
//! section: the layer's linear shear stiffness `κGA` (its [`super::mesh::Section`] with a zero
//! axial modulus) carries it.
//!
//! Energies per fibre: the recoverable part is the material's ([`FibreMaterial::stored_energy`]),
//! the work is integrated step by step along the straight strain path by Simpson's rule with the
//! material itself evaluated at the middle of the step ([`FibreMaterial::step_work`]), so that work
//! minus recoverable energy is the energy the material dissipated (cracking, crushing, yielding).

use serde::{Deserialize, Serialize};

use super::banded::StiffnessBand;
use super::mesh::NONE;
use crate::materials::{
    Concrete, PreparedConcrete, PreparedSteel, Steel, UniaxialMaterial, UniaxialResponse, UniaxialState,
};

/// The material of a fibre.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum FibreMaterial {
    /// Concrete (secant unloading to the origin: its recoverable energy is `½ σ ε`).
    Concrete(Concrete),
    /// Steel (elastic unloading: its recoverable energy is `σ²/(2 E_s)`).
    Steel(Steel),
    /// Concrete that does not crack (linear elastic in tension, the concrete's own curve in
    /// compression): concrete between discrete cracks, whose tension the bond of the bars limits.
    UncrackedConcrete(Concrete),
    /// Concrete of a cracked segment of length `s` lumped into a crack element of length `l`: no
    /// tension (the crack is open), the concrete's own curve in compression at the element strain
    /// times `ratio = l/s` (recoverable energy `½ σ ε`, as a secant material).
    CrackedConcrete {
        /// The concrete.
        concrete: Concrete,
        /// Element length over segment length.
        ratio: f64,
    },
    /// Steel of a cracked segment of length `s` lumped into a crack element of length `l` (its
    /// elongation at a crack collects over the crack spacing): the steel sees the element strain
    /// times `ratio = l/s` (recoverable energy `σ²/(2 E_s ratio)` per unit volume of the element).
    CrackSteel {
        /// The bars' steel.
        steel: Steel,
        /// Element length over transfer length.
        ratio: f64,
    },
}

impl FibreMaterial {
    /// Stress, tangent and trial state at the mechanical `strain` from the committed `state`.
    #[inline]
    pub fn respond(&self, strain: f64, state: &UniaxialState) -> UniaxialResponse {
        match self {
            FibreMaterial::Concrete(c) => c.respond(strain, state),
            FibreMaterial::Steel(s) => s.respond(strain, state),
            FibreMaterial::UncrackedConcrete(c) => {
                if strain < 0.0 {
                    c.respond(strain, state)
                } else {
                    UniaxialResponse { stress: c.elastic_modulus * strain, tangent: c.elastic_modulus, state: *state }
                }
            }
            FibreMaterial::CrackedConcrete { concrete, ratio } => {
                if strain < 0.0 {
                    let mut r = concrete.respond(strain * ratio, state);
                    r.tangent *= ratio;
                    r
                } else {
                    UniaxialResponse { stress: 0.0, tangent: 0.0, state: *state }
                }
            }
            FibreMaterial::CrackSteel { steel, ratio } => {
                let mut r = steel.respond(strain * ratio, state);
                r.tangent *= ratio;
                r
            }
        }
    }

    /// Stiffness of unloading from `stress` at `strain` (MPa): elastic for the steels, the secant
    /// `σ/ε` for the concretes (they unload to the origin).
    #[inline]
    pub fn unloading_stiffness(&self, strain: f64, stress: f64) -> f64 {
        match self {
            FibreMaterial::Steel(s) => s.elastic_modulus,
            FibreMaterial::CrackSteel { steel, ratio } => steel.elastic_modulus * ratio,
            FibreMaterial::Concrete(_)
            | FibreMaterial::UncrackedConcrete(_)
            | FibreMaterial::CrackedConcrete { .. } => {
                if strain.abs() > 1e-12 {
                    (stress / strain).max(0.0)
                } else {
                    0.0
                }
            }
        }
    }

    /// Recoverable energy per unit volume at `strain` with stress `stress` (MPa = N·mm/mm³).
    #[inline]
    pub fn stored_energy(&self, strain: f64, stress: f64) -> f64 {
        match self {
            FibreMaterial::Concrete(_)
            | FibreMaterial::UncrackedConcrete(_)
            | FibreMaterial::CrackedConcrete { .. } => 0.5 * stress * strain,
            FibreMaterial::Steel(s) => 0.5 * stress * stress / s.elastic_modulus,
            FibreMaterial::CrackSteel { steel, ratio } => 0.5 * stress * stress / (steel.elastic_modulus * ratio),
        }
    }

    /// Work per unit volume along the straight strain path `e0 → e1` from the committed `state`,
    /// stresses `s0` and `s1` at the ends (Simpson's rule, middle stress from the material).
    #[inline]
    pub fn step_work(&self, state: &UniaxialState, (e0, s0): (f64, f64), (e1, s1): (f64, f64)) -> f64 {
        if e1 == e0 {
            return 0.0;
        }
        let sm = self.respond(0.5 * (e0 + e1), state).stress;
        (e1 - e0) / 6.0 * (s0 + 4.0 * sm + s1)
    }
}

/// A [`FibreMaterial`] with its constants worked out once (see [`FibreMaterial::prepared`]): the
/// same stresses, tangents and states, for the inner loops of an assembly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PreparedMaterial {
    /// [`FibreMaterial::Concrete`].
    Concrete(PreparedConcrete),
    /// [`FibreMaterial::Steel`].
    Steel(PreparedSteel),
    /// [`FibreMaterial::UncrackedConcrete`] (the concrete and its elastic modulus).
    UncrackedConcrete(PreparedConcrete, f64),
    /// [`FibreMaterial::CrackedConcrete`].
    CrackedConcrete(PreparedConcrete, f64),
    /// [`FibreMaterial::CrackSteel`].
    CrackSteel(PreparedSteel, f64),
}

impl FibreMaterial {
    /// The material with its constants worked out.
    pub fn prepared(&self) -> PreparedMaterial {
        match self {
            FibreMaterial::Concrete(c) => PreparedMaterial::Concrete(c.prepared()),
            FibreMaterial::Steel(s) => PreparedMaterial::Steel(s.prepared()),
            FibreMaterial::UncrackedConcrete(c) => PreparedMaterial::UncrackedConcrete(c.prepared(), c.elastic_modulus),
            FibreMaterial::CrackedConcrete { concrete, ratio } => {
                PreparedMaterial::CrackedConcrete(concrete.prepared(), *ratio)
            }
            FibreMaterial::CrackSteel { steel, ratio } => PreparedMaterial::CrackSteel(steel.prepared(), *ratio),
        }
    }
}

impl PreparedMaterial {
    /// Exactly [`FibreMaterial::respond`].
    #[inline(always)]
    pub fn respond(&self, strain: f64, state: &UniaxialState) -> UniaxialResponse {
        match self {
            PreparedMaterial::Concrete(c) => c.respond(strain, state),
            PreparedMaterial::Steel(s) => s.respond(strain, state),
            PreparedMaterial::UncrackedConcrete(c, ec) => {
                if strain < 0.0 {
                    c.respond(strain, state)
                } else {
                    UniaxialResponse { stress: ec * strain, tangent: *ec, state: *state }
                }
            }
            PreparedMaterial::CrackedConcrete(c, ratio) => {
                if strain < 0.0 {
                    let mut r = c.respond(strain * ratio, state);
                    r.tangent *= ratio;
                    r
                } else {
                    UniaxialResponse { stress: 0.0, tangent: 0.0, state: *state }
                }
            }
            PreparedMaterial::CrackSteel(s, ratio) => {
                let mut r = s.respond(strain * ratio, state);
                r.tangent *= ratio;
                r
            }
        }
    }

    /// Exactly [`FibreMaterial::unloading_stiffness`].
    #[inline]
    pub fn unloading_stiffness(&self, strain: f64, stress: f64) -> f64 {
        match self {
            PreparedMaterial::Steel(s) => s.elastic_modulus(),
            PreparedMaterial::CrackSteel(s, ratio) => s.elastic_modulus() * ratio,
            PreparedMaterial::Concrete(_)
            | PreparedMaterial::UncrackedConcrete(..)
            | PreparedMaterial::CrackedConcrete(..) => {
                if strain.abs() > 1e-12 {
                    (stress / strain).max(0.0)
                } else {
                    0.0
                }
            }
        }
    }

    /// Exactly [`FibreMaterial::step_work`].
    #[inline]
    pub fn step_work(&self, state: &UniaxialState, (e0, s0): (f64, f64), (e1, s1): (f64, f64)) -> f64 {
        if e1 == e0 {
            return 0.0;
        }
        let sm = self.respond(0.5 * (e0 + e1), state).stress;
        (e1 - e0) / 6.0 * (s0 + 4.0 * sm + s1)
    }
}

/// A fibre of a [`FibreSection`] with its material prepared ([`FibreSection::prepared`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreparedFibre {
    /// [`Fibre::z`].
    pub z: f64,
    /// [`Fibre::area`].
    pub area: f64,
    /// [`Fibre::initial_strain`].
    pub initial_strain: f64,
    /// The fibre's material.
    pub material: PreparedMaterial,
}

impl PreparedFibre {
    /// Exactly [`FibreSection::strain`] of the fibre.
    #[inline(always)]
    pub fn strain(&self, e: [f64; 2]) -> f64 {
        e[0] - self.z * e[1] - self.initial_strain
    }
}

/// One fibre of a section.
#[derive(Clone, Debug, PartialEq)]
pub struct Fibre {
    /// Height above the layer's centroid (mm).
    pub z: f64,
    /// Area (mm²); negative to take out the concrete a bar displaces.
    pub area: f64,
    /// Index into [`FibreSection::materials`].
    pub material: usize,
    /// Stress-free initial strain (e.g. free shrinkage of concrete).
    pub initial_strain: f64,
}

/// A cross-section as fibres.
#[derive(Clone, Debug, PartialEq)]
pub struct FibreSection {
    /// The materials the fibres refer to.
    pub materials: Vec<FibreMaterial>,
    /// The fibres.
    pub fibres: Vec<Fibre>,
}

/// Section response at generalised strains `[ε, κ]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SectionResponse {
    /// `[N, M]` (N, N·mm).
    pub force: [f64; 2],
    /// `∂[N, M]/∂[ε, κ]`.
    pub tangent: [[f64; 2]; 2],
}

impl FibreSection {
    /// Mechanical strain of fibre `f` at generalised strains `e = [ε, κ]`.
    #[inline]
    pub fn strain(&self, f: &Fibre, e: [f64; 2]) -> f64 {
        e[0] - f.z * e[1] - f.initial_strain
    }

    /// The fibres with their materials prepared, in order.
    pub fn prepared(&self) -> Vec<PreparedFibre> {
        self.fibres
            .iter()
            .map(|f| PreparedFibre {
                z: f.z,
                area: f.area,
                initial_strain: f.initial_strain,
                material: self.materials[f.material].prepared(),
            })
            .collect()
    }
}

/// Generalised strains `[ε, κ]` of an element of length `l` with nodal `[u1, w1, θ1, u2, w2, θ2]`.
#[inline]
pub fn strains(l: f64, q: &[f64; 6]) -> [f64; 2] {
    [(q[3] - q[0]) / l, (q[5] - q[2]) / l]
}

/// Nodal forces `Bᵀ [N, M] l` and tangent `Bᵀ D B l` of an element of length `l` from its section
/// response (only the `u` and `θ` entries are non-zero).
pub fn element(l: f64, s: &SectionResponse) -> ([f64; 6], [[f64; 6]; 6]) {
    // B: ε = (u2 − u1)/l, κ = (θ2 − θ1)/l.
    let b: [[f64; 6]; 2] = [[-1.0 / l, 0.0, 0.0, 1.0 / l, 0.0, 0.0], [0.0, 0.0, -1.0 / l, 0.0, 0.0, 1.0 / l]];
    let mut f = [0.0; 6];
    let mut k = [[0.0; 6]; 6];
    for i in 0..6 {
        f[i] = (b[0][i] * s.force[0] + b[1][i] * s.force[1]) * l;
        if b[0][i] == 0.0 && b[1][i] == 0.0 {
            continue;
        }
        for j in 0..6 {
            let mut v = 0.0;
            for r in 0..2 {
                for c in 0..2 {
                    v += b[r][i] * s.tangent[r][c] * b[c][j];
                }
            }
            k[i][j] = v * l;
        }
    }
    (f, k)
}

/// `B` of an element of length `l` by columns `[u1, θ1, u2, θ2]` (the others are zero): the
/// column's index among `[u1, w1, θ1, u2, w2, θ2]`, its one non-zero entry `±1/l` and that
/// entry's row (0: `ε`, 1: `κ`).
#[inline]
fn b_columns(l: f64) -> [(usize, f64, usize); 4] {
    let (bn, bp) = (-1.0 / l, 1.0 / l);
    [(0, bn, 0), (2, bn, 1), (3, bp, 0), (5, bp, 1)]
}

/// Adds the nodal forces of [`element`] (section forces `s.force`) to `f` at the element's
/// unknowns `dofs` (`[u1, w1, θ1, u2, w2, θ2]`, [`NONE`] for none); `false` if one is not finite.
#[inline]
pub fn element_forces(l: f64, s: &SectionResponse, dofs: &[usize; 6], f: &mut [f64]) -> bool {
    let mut ok = true;
    for (a, ba, ra) in b_columns(l) {
        // `element`'s sum `(B₀ᵢ N + B₁ᵢ M) l` has this one non-zero term.
        let fa = ba * s.force[ra] * l;
        ok &= fa.is_finite();
        if dofs[a] != NONE {
            f[dofs[a]] += fa;
        }
    }
    ok
}

/// Adds the tangent `Bᵀ D B l` of [`element`] (section tangent `d`) to `k` at the element's
/// unknowns `dofs`, only its non-zero (`u` and `θ`) entries.
#[inline]
pub fn scatter_tangent<K: StiffnessBand>(l: f64, d: &[[f64; 2]; 2], dofs: &[usize; 6], k: &mut K) {
    let cols = b_columns(l);
    for &(a, ba, ra) in &cols {
        let da = dofs[a];
        if da == NONE {
            continue;
        }
        for &(b, bb, rb) in &cols {
            let db = dofs[b];
            if db != NONE && !(K::UPPER_ONLY && db < da) {
                // `element`'s sum over `B D B` has this one non-zero term.
                k.add(da, db, ba * d[ra][rb] * bb * l);
            }
        }
    }
}
