//! `[effects]`: which physical effects are on, as choice enums.
use super::*;

// ---------------------------------------------------------------------------------------
// [effects]

choice_enum! {
    /// `effects.lubrication`: is there a lubricant film?
    pub enum LubricationModel {
        /// Full-system EHL: Reynolds equation coupled with elasticity.
        Reynolds = "reynolds",
        /// Dry Hertz contact: the Hertz pressure is applied as traction; the lubricant is
        /// ignored (and may be absent).
        Dry = "none",
    } default = Reynolds
}

choice_enum! {
    /// `effects.elasticity`: deformable or rigid solids.
    pub enum ElasticityModel {
        /// Linear elastic equivalent solid (paper Eq. 8).
        Elastic = "elastic",
        /// Rigid solids: u2 = 0 in the film (hydrodynamic lubrication).
        Rigid = "rigid",
    } default = Elastic
}

choice_enum! {
    /// `effects.viscosity`: pressure-viscosity law.
    pub enum ViscosityModel {
        /// Roelands (paper Eq. 6).
        Roelands = "roelands",
        /// Barus eta_R exp(alpha p).
        Barus = "barus",
        /// eta = eta_R.
        Constant = "constant",
    } default = Roelands
}

choice_enum! {
    /// `effects.density`: pressure-density law.
    pub enum DensityModel {
        /// Dowson-Higginson.
        DowsonHigginson = "dowson-higginson",
        /// rho = rho_R.
        Incompressible = "incompressible",
    } default = DowsonHigginson
}

choice_enum! {
    /// `effects.kinematics`: surface velocities.
    pub enum KinematicsModel {
        /// Rolling, sliding and spinning (docs/model.md section 3).
        Spin = "spin",
        /// Uniform surface velocities U_BO, U_DO, no spin.
        Uniform = "uniform",
    } default = Spin
}

choice_enum! {
    /// `effects.friction`: the shear-stress post-processing pass.
    pub enum FrictionModel {
        /// Ree-Eyring (paper Section 3).
        ReeEyring = "ree-eyring",
        /// Newtonian shear.
        Newtonian = "newtonian",
        /// No friction computation.
        Off = "none",
    } default = ReeEyring
}

choice_enum! {
    /// `effects.cavitation`: how p >= 0 is enforced.
    pub enum CavitationModel {
        /// Penalty term -xi min(p, 0) (xi = `reynolds.penalty`): p is held at -O(1/xi) where
        /// the film cavitates, and the films carry an error that falls slowly with xi.
        Penalty = "penalty",
        /// The Reynolds condition exactly: p >= 0, the Reynolds residual >= 0 and their
        /// product 0 at every node, solved by semismooth Newton (Fischer-Burmeister) from a
        /// penalty solution (xi = min(`reynolds.penalty`, 1e3)) or a coarser level's
        /// pressure. The result does not depend on xi, and SUPG subtracts the cavitation
        /// multiplier where the film cavitates (docs/numerics.md). A penalty scene refined
        /// to a target switches to it once the penalty's own error stands in the way
        /// (docs/accuracy.md).
        Complementarity = "complementarity",
        /// None: negative pressures are kept.
        Off = "none",
    } default = Penalty
}

choice_enum! {
    /// `effects.symmetry`: may the solver use a symmetry plane?
    pub enum SymmetryMode {
        /// Use the plane z = 0 when the case is symmetric (no spin, see the solver).
        Auto = "auto",
        /// Always solve the full domain.
        Off = "off",
    } default = Auto
}

choice_enum! {
    /// `effects.surface_traction`: the tangential traction on the contact face in the
    /// subsurface stress field (`output.subsurface`); the normal problem never sees it.
    pub enum SurfaceTraction {
        /// Only the normal pressure loads the solid.
        Off = "none",
        /// Also the shear stresses of the friction pass on the disc (lubricated scene), or
        /// q = mu p in +x (dry scene, mu = `operating.friction_coefficient`).
        Friction = "friction",
    } default = Off
}

choice_enum! {
    /// `output.subsurface_recovery`: how the continuous stress field is recovered from the
    /// element stresses.
    pub enum StressRecovery {
        /// Superconvergent patch recovery (a polynomial fitted around every vertex).
        Spr = "spr",
        /// Volume-weighted average of the element values at each node.
        Average = "average",
    } default = Spr
}

/// `[effects]`: which physics is simulated. Every key is optional; the defaults are the
/// paper's model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Effects {
    /// "reynolds" | "none" (dry Hertz); default "reynolds".
    pub lubrication: LubricationModel,
    /// "elastic" | "rigid"; default "elastic".
    pub elasticity: ElasticityModel,
    /// "roelands" | "barus" | "constant"; default "roelands".
    pub viscosity: ViscosityModel,
    /// "dowson-higginson" | "incompressible"; default "dowson-higginson".
    pub density: DensityModel,
    /// "spin" | "uniform"; default "spin".
    pub kinematics: KinematicsModel,
    /// "ree-eyring" | "newtonian" | "none"; default "ree-eyring".
    pub friction: FrictionModel,
    /// "penalty" | "complementarity" | "none"; default "penalty".
    pub cavitation: CavitationModel,
    /// "auto" | "off"; default "auto".
    pub symmetry: SymmetryMode,
    /// "none" | "friction"; default "none".
    pub surface_traction: SurfaceTraction,
}

/// Keys of `[effects]`.
pub const EFFECTS_FIELDS: &[Field] = &[
    f!(
        "lubrication",
        "lubricant film (\"none\" = dry Hertz traction)",
        "",
        Kind::Choice(LubricationModel::NAMES),
        Presence::Default("\"reynolds\"")
    ),
    f!("elasticity", "deformation of the solids", "", Kind::Choice(ElasticityModel::NAMES), Presence::Default("\"elastic\"")),
    f!("viscosity", "pressure-viscosity law", "", Kind::Choice(ViscosityModel::NAMES), Presence::Default("\"roelands\"")),
    f!("density", "pressure-density law", "", Kind::Choice(DensityModel::NAMES), Presence::Default("\"dowson-higginson\"")),
    f!("kinematics", "surface velocities (spin or uniform)", "", Kind::Choice(KinematicsModel::NAMES), Presence::Default("\"spin\"")),
    f!("friction", "shear-stress model of the friction pass", "", Kind::Choice(FrictionModel::NAMES), Presence::Default("\"ree-eyring\"")),
    f!("cavitation", "cavitation model", "", Kind::Choice(CavitationModel::NAMES), Presence::Default("\"penalty\"")),
    f!("symmetry", "use of a symmetry plane", "", Kind::Choice(SymmetryMode::NAMES), Presence::Default("\"auto\"")),
    f!(
        "surface_traction",
        "tangential traction of the subsurface stress field (output.subsurface)",
        "",
        Kind::Choice(SurfaceTraction::NAMES),
        Presence::Default("\"none\"")
    ),
];
