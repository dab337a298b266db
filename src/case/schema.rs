//! The scene-file schema: serde structs in SI units, each followed by the list of its keys
//! (meaning, unit, range, default) used by the strict validator in [`super::spec`].
//!
//! Keep each `*_FIELDS` list in step with the struct above it: the test
//! `known_keys_match_structs` serialises a full scene and checks both directions.
use std::fmt;

use serde::{Deserialize, Serialize};

use super::spec::{Field, Kind, Presence, Range};

/// Builds a [`Field`] in a const context.
macro_rules! f {
    ($key:literal, $what:literal, $unit:literal, $kind:expr, $presence:expr) => {
        Field {
            key: $key,
            what: $what,
            unit: $unit,
            kind: $kind,
            presence: $presence,
            note: "",
        }
    };
    ($key:literal, $what:literal, $unit:literal, $kind:expr, $presence:expr, note = $note:literal) => {
        Field {
            key: $key,
            what: $what,
            unit: $unit,
            kind: $kind,
            presence: $presence,
            note: $note,
        }
    };
}

/// Defines a string-valued choice enum: serde names, `NAMES`, `ALL`, `as_str`, `Default`.
macro_rules! choice_enum {
    ($(#[$m:meta])* pub enum $name:ident { $($(#[$vm:meta])* $var:ident = $s:literal,)+ } default = $def:ident) => {
        $(#[$m])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
        pub enum $name {
            $($(#[$vm])* #[serde(rename = $s)] $var,)+
        }
        impl $name {
            /// The strings accepted in the scene file, in declaration order.
            pub const NAMES: &'static [&'static str] = &[$($s),+];
            /// All variants, in the order of `NAMES`.
            pub const ALL: &'static [$name] = &[$($name::$var),+];
            /// The scene-file string of this variant.
            pub fn as_str(self) -> &'static str {
                match self { $($name::$var => $s,)+ }
            }
        }
        impl Default for $name {
            fn default() -> Self { $name::$def }
        }
        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result { f.write_str(self.as_str()) }
        }
    };
}

// ---------------------------------------------------------------------------------------
// Top level

/// A validated scene (the contents of `case.toml`), all quantities in SI units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Scene name, used in output paths and reports. Optional in the file: defaults to the
    /// file stem (or the parent directory name for a file called `case.toml`).
    #[serde(default)]
    pub name: String,
    /// Geometry of ball and disc.
    pub geometry: Geometry,
    /// Elastic materials of ball and disc.
    pub materials: Materials,
    /// Lubricant properties; required when `effects.lubrication = "reynolds"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lubricant: Option<Lubricant>,
    /// Load and kinematics.
    pub operating: Operating,
    /// Which physics is simulated (defaults: the paper's model).
    #[serde(default)]
    pub effects: Effects,
    /// Reynolds domain and its discretisation options.
    #[serde(default)]
    pub reynolds: ReynoldsDomain,
    /// Mesh of the equivalent elastic cube.
    #[serde(default)]
    pub mesh: MeshSettings,
    /// Output directory and formats.
    #[serde(default)]
    pub output: OutputSettings,
    /// Optional parameter sweep: lists that replace `[operating]` values, one solve per
    /// combination.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sweep: Option<Sweep>,
    /// Plausibility limits the user accepts (see [`super::plausible`]).
    #[serde(default)]
    pub checks: Checks,
}

/// `[checks]`: the plausibility checks a scene accepts outside their usual range.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Checks {
    /// Names of derived quantities allowed outside their usual (soft) range, e.g.
    /// `["memory"]` for a run over several nodes.
    pub accept: Vec<String>,
}

/// Keys of `[checks]`.
pub const CHECKS_FIELDS: &[Field] = &[f!(
    "accept",
    "derived quantities allowed outside their usual range (a warning instead of an error; docs/robustness.md)",
    "",
    Kind::ChoiceList(super::plausible::ACCEPT_NAMES),
    Presence::Default("[] (none)")
)];

/// Keys of the top level of the scene file.
pub const SCENE_FIELDS: &[Field] = &[
    f!(
        "name",
        "scene name, used for the default output directory",
        "",
        Kind::Text,
        Presence::Default("the file stem")
    ),
    f!(
        "geometry",
        "geometry of ball B and disc D",
        "",
        Kind::Table(GEOMETRY_FIELDS),
        Presence::Required
    ),
    f!(
        "materials",
        "elastic materials of ball B and disc D",
        "",
        Kind::Table(MATERIALS_FIELDS),
        Presence::Required
    ),
    f!(
        "lubricant",
        "lubricant properties",
        "",
        Kind::Table(LUBRICANT_FIELDS),
        Presence::Conditional("required when effects.lubrication = \"reynolds\"")
    ),
    f!(
        "operating",
        "operating conditions: load and kinematics",
        "",
        Kind::Table(OPERATING_FIELDS),
        Presence::Required
    ),
    f!(
        "effects",
        "which physics is simulated",
        "",
        Kind::Table(EFFECTS_FIELDS),
        Presence::Default("the paper's model")
    ),
    f!(
        "reynolds",
        "Reynolds domain in units of the Hertz radius a",
        "",
        Kind::Table(REYNOLDS_FIELDS),
        Presence::Default("the square [-3, 3]^2")
    ),
    f!(
        "mesh",
        "mesh of the equivalent elastic cube",
        "",
        Kind::Table(MESH_FIELDS),
        Presence::Default("the values below")
    ),
    f!(
        "output",
        "output directory and formats",
        "",
        Kind::Table(OUTPUT_FIELDS),
        Presence::Default("the values below")
    ),
    f!(
        "sweep",
        "parameter sweep: lists of operating values, one converged solve per combination (entrainment speed outermost, slide-to-roll innermost), each started from the previous converged state",
        "",
        Kind::Table(SWEEP_FIELDS),
        Presence::Default("none (one operating point)")
    ),
    f!(
        "checks",
        "physical plausibility checks: quantities accepted outside their usual range",
        "",
        Kind::Table(CHECKS_FIELDS),
        Presence::Default("none accepted")
    ),
];

// ---------------------------------------------------------------------------------------
// [geometry]

/// Default radius of the contact track on the disc R_D (m).
pub const DEFAULT_DISC_TRACK_RADIUS: f64 = 0.04;

fn default_disc_track_radius() -> f64 {
    DEFAULT_DISC_TRACK_RADIUS
}

/// `[geometry]`: a ball with a spherical end on a flat disc.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Geometry {
    /// Ball radius R_B (m), > 0. It is also the reduced radius R of the contact.
    pub ball_radius: f64,
    /// Radius of the contact track on the disc R_D (m), > 0; default 0.04 (not given in
    /// the paper). It sets the disc's spin omega_D = U_DO/R_D.
    #[serde(default = "default_disc_track_radius")]
    pub disc_track_radius: f64,
}

/// Keys of `[geometry]`.
pub const GEOMETRY_FIELDS: &[Field] = &[
    f!(
        "ball_radius",
        "ball radius R_B",
        "m",
        Kind::Number(Range::Positive),
        Presence::Required
    ),
    f!(
        "disc_track_radius",
        "radius of the contact track on the disc R_D",
        "m",
        Kind::Number(Range::Positive),
        Presence::Default("0.04")
    ),
];

// ---------------------------------------------------------------------------------------
// [materials]

/// `[materials]`: the two solids.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Materials {
    /// Material of the ball B.
    pub ball: ElasticMaterial,
    /// Material of the disc D.
    pub disc: ElasticMaterial,
}

/// Keys of `[materials]`.
pub const MATERIALS_FIELDS: &[Field] = &[
    f!(
        "ball",
        "elastic material of the ball B",
        "",
        Kind::Table(MATERIAL_FIELDS),
        Presence::Required
    ),
    f!(
        "disc",
        "elastic material of the disc D",
        "",
        Kind::Table(MATERIAL_FIELDS),
        Presence::Required
    ),
];

/// `[materials.ball]` / `[materials.disc]`: an isotropic linear elastic material.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElasticMaterial {
    /// Young's modulus E (Pa), > 0.
    pub young_modulus: f64,
    /// Poisson's ratio nu (dimensionless), in (-1, 0.5).
    pub poisson_ratio: f64,
}

/// Keys of `[materials.ball]` and `[materials.disc]`.
pub const MATERIAL_FIELDS: &[Field] = &[
    f!(
        "young_modulus",
        "Young's modulus E",
        "Pa",
        Kind::Number(Range::Positive),
        Presence::Required
    ),
    f!(
        "poisson_ratio",
        "Poisson's ratio nu",
        "",
        Kind::Number(Range::Open(-1.0, 0.5)),
        Presence::Required
    ),
];

// ---------------------------------------------------------------------------------------
// [lubricant]

/// Default Roelands reference pressure P_R (Pa).
pub const DEFAULT_ROELANDS_REFERENCE_PRESSURE: f64 =
    crate::physics::rheology::ROELANDS_REFERENCE_PRESSURE;
/// Default reference density rho_R (kg/m^3).
pub const DEFAULT_DENSITY: f64 = 870.0;
/// Default Ree-Eyring stress tau0 (Pa) (paper Table 1).
pub const DEFAULT_REE_EYRING_STRESS: f64 = 6.2e6;

fn default_roelands_reference_pressure() -> f64 {
    DEFAULT_ROELANDS_REFERENCE_PRESSURE
}
fn default_density() -> f64 {
    DEFAULT_DENSITY
}
fn default_ree_eyring_stress() -> f64 {
    DEFAULT_REE_EYRING_STRESS
}

/// `[lubricant]`: the oil (isothermal).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lubricant {
    /// Reference (ambient-pressure) viscosity eta_R (Pa.s), > 0.
    pub viscosity: f64,
    /// Pressure-viscosity coefficient alpha (1/Pa), >= 0. Required unless
    /// `effects.viscosity = "constant"` or `roelands_exponent` is given; also used for the
    /// Hamrock-Dowson and Moes references.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pressure_viscosity: Option<f64>,
    /// Roelands reference pressure P_R (Pa), > 0; default 1.96e8.
    #[serde(default = "default_roelands_reference_pressure")]
    pub roelands_reference_pressure: f64,
    /// Roelands pressure-viscosity index z_R (dimensionless), in (0, 2]. Optional: derived
    /// as z_R = alpha P_R / (ln eta_R + 9.67) when absent. Only with `effects.viscosity =
    /// "roelands"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roelands_exponent: Option<f64>,
    /// Reference density rho_R (kg/m^3), > 0; default 870.
    #[serde(default = "default_density")]
    pub density: f64,
    /// Ree-Eyring stress tau0 (Pa), > 0; default 6.2e6.
    #[serde(default = "default_ree_eyring_stress")]
    pub ree_eyring_stress: f64,
}

/// Keys of `[lubricant]`.
pub const LUBRICANT_FIELDS: &[Field] = &[
    f!("viscosity", "reference viscosity eta_R", "Pa.s", Kind::Number(Range::Positive), Presence::Required),
    f!("pressure_viscosity", "pressure-viscosity coefficient alpha", "1/Pa", Kind::Number(Range::NonNegative),
        Presence::Conditional("required unless effects.viscosity = \"constant\" or lubricant.roelands_exponent is given")),
    f!("roelands_reference_pressure", "Roelands reference pressure P_R", "Pa", Kind::Number(Range::Positive),
        Presence::Default("1.96e8")),
    f!("roelands_exponent", "Roelands pressure-viscosity index z_R", "", Kind::Number(Range::LeftOpen(0.0, 2.0)),
        Presence::Default("alpha P_R / (ln eta_R + 9.67)"), note = "only with effects.viscosity = \"roelands\""),
    f!("density", "reference density rho_R", "kg/m^3", Kind::Number(Range::Positive), Presence::Default("870")),
    f!("ree_eyring_stress", "Ree-Eyring stress tau0", "Pa", Kind::Number(Range::Positive), Presence::Default("6.2e6")),
];

// ---------------------------------------------------------------------------------------
// [operating]

fn default_tilt_angle() -> f64 {
    90.0
}

/// `[operating]`: load and kinematics (physics.md section 3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Operating {
    /// Normal load L (N), > 0.
    pub load: f64,
    /// Entrainment speed Ue = (U_BO + U_DO)/2 (m/s), > 0. Required unless
    /// `effects.lubrication = "none"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub entrainment_speed: Option<f64>,
    /// Slide-to-roll ratio SRR = (U_BO - U_DO)/Ue (fraction: 0.05 = 5 %), |SRR| <= 2;
    /// default 0.
    #[serde(default)]
    pub slide_to_roll: f64,
    /// Tilt angle lambda between the normal y and the ball's rotation axis (degrees), in
    /// (0, 90]; default 90 (no ball spin). lambda = 0 is singular and rejected.
    #[serde(default = "default_tilt_angle")]
    pub tilt_angle: f64,
}

/// Keys of `[operating]`.
pub const OPERATING_FIELDS: &[Field] = &[
    f!("load", "normal load L", "N", Kind::Number(Range::Positive), Presence::Required),
    f!("entrainment_speed", "entrainment speed Ue", "m/s", Kind::Number(Range::Positive),
        Presence::Conditional("required when effects.lubrication = \"reynolds\"")),
    f!("slide_to_roll", "slide-to-roll ratio SRR (fraction, 0.05 = 5 %)", "", Kind::Number(Range::AbsAtMost(2.0)),
        Presence::Default("0")),
    f!("tilt_angle", "tilt angle lambda of the ball's rotation axis", "degrees", Kind::Number(Range::LeftOpen(0.0, 90.0)),
        Presence::Default("90"),
        note = "lambda = 0 is singular: the ball spin omega_B = U_BO/(R_B sin lambda) would be infinite"),
];

// ---------------------------------------------------------------------------------------
// [sweep]

/// `[sweep]`: lists of operating values (each replaces the `[operating]` value). The
/// points are the Cartesian product, entrainment speed outermost and slide-to-roll
/// innermost, each list in the order given.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Sweep {
    /// Entrainment speeds Ue (m/s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub entrainment_speed: Option<Vec<f64>>,
    /// Tilt angles lambda (degrees).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tilt_angle: Option<Vec<f64>>,
    /// Slide-to-roll ratios SRR (fractions).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub slide_to_roll: Option<Vec<f64>>,
}

/// Keys of `[sweep]`.
pub const SWEEP_FIELDS: &[Field] = &[
    f!("entrainment_speed", "entrainment speeds Ue", "m/s", Kind::NumberList(Range::Positive), Presence::Default("operating.entrainment_speed")),
    f!("tilt_angle", "tilt angles lambda", "degrees", Kind::NumberList(Range::LeftOpen(0.0, 90.0)), Presence::Default("operating.tilt_angle")),
    f!("slide_to_roll", "slide-to-roll ratios SRR (fractions)", "", Kind::NumberList(Range::AbsAtMost(2.0)), Presence::Default("operating.slide_to_roll")),
];

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
        /// Rolling, sliding and spinning (physics.md section 3).
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
        /// Penalty term -xi min(p, 0) (xi = `reynolds.penalty`).
        Penalty = "penalty",
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
    /// "penalty" | "none"; default "penalty".
    pub cavitation: CavitationModel,
    /// "auto" | "off"; default "auto".
    pub symmetry: SymmetryMode,
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
    f!(
        "elasticity",
        "deformation of the solids",
        "",
        Kind::Choice(ElasticityModel::NAMES),
        Presence::Default("\"elastic\"")
    ),
    f!(
        "viscosity",
        "pressure-viscosity law",
        "",
        Kind::Choice(ViscosityModel::NAMES),
        Presence::Default("\"roelands\"")
    ),
    f!(
        "density",
        "pressure-density law",
        "",
        Kind::Choice(DensityModel::NAMES),
        Presence::Default("\"dowson-higginson\"")
    ),
    f!(
        "kinematics",
        "surface velocities (spin or uniform)",
        "",
        Kind::Choice(KinematicsModel::NAMES),
        Presence::Default("\"spin\"")
    ),
    f!(
        "friction",
        "shear-stress model of the friction pass",
        "",
        Kind::Choice(FrictionModel::NAMES),
        Presence::Default("\"ree-eyring\"")
    ),
    f!(
        "cavitation",
        "cavitation model",
        "",
        Kind::Choice(CavitationModel::NAMES),
        Presence::Default("\"penalty\"")
    ),
    f!(
        "symmetry",
        "use of a symmetry plane",
        "",
        Kind::Choice(SymmetryMode::NAMES),
        Presence::Default("\"auto\"")
    ),
];

// ---------------------------------------------------------------------------------------
// [reynolds]

choice_enum! {
    /// `reynolds.stabilisation`: stabilisation of the Reynolds equation.
    pub enum Stabilisation {
        /// Streamline-upwind Petrov-Galerkin, Habchi's Peclet number, strong residual with
        /// the lubricant properties frozen inside each element (the default).
        Supg = "supg",
        /// SUPG with the complete strong residual (fully consistent; needs meshes that
        /// resolve the outlet pressure drop, Newton fails on the default mesh).
        SupgExact = "supg-exact",
        /// SUPG whose strong residual keeps only the Couette term (first-order consistent).
        SupgCouette = "supg-couette",
        /// Plain Galerkin.
        Off = "none",
    } default = Supg
}

choice_enum! {
    /// `reynolds.coupling`: how Newton's linear systems couple the film to the solid.
    pub enum Coupling {
        /// "condensed" up to [`AUTO_MONOLITHIC_ABOVE`] pressure unknowns (a sweep: up to
        /// [`AUTO_MONOLITHIC_ABOVE_SWEEP`]), "monolithic" above.
        Auto = "auto",
        /// The elastic block eliminated once onto the contact face (a dense face
        /// compliance); Newton on (P, H0) with a dense LU: fastest on small meshes, but
        /// its cost grows as the cube of the pressure unknowns.
        Condensed = "condensed",
        /// U, P and H0 in one sparse matrix, factorised by MUMPS at every Newton step from
        /// the Hertz start, every third step (GMRES on the last factorisation in between)
        /// from a start near the solution.
        Monolithic = "monolithic",
    } default = Auto
}

/// `reynolds.coupling = "auto"` solves the monolithic system above this many pressure
/// unknowns. Measured on table2-ue2 (2 ranks, README "Coupling"): at 3,220 pressure
/// unknowns the condensed solve takes 14.0 s and the monolithic 17.8 s, at 4,824 they take
/// 35.7 s and 29.2 s, at 11,040 337 s and 96.5 s.
pub const AUTO_MONOLITHIC_ABOVE: usize = 4000;

/// The same for a sweep, which condenses once for all its points, so only the cost of a
/// Newton step counts: on case2's mesh (6,353 pressure unknowns, 2 ranks; `ci/bench`: 16
/// iterations, 95.9 s with a 33 s condensation, 99.8 s with a 10 s assembly) a condensed
/// step (dense LU) takes about 3.9 s and a monolithic one (sparse LU of 123,828 unknowns)
/// about 5.6 s; the dense LU grows as n^3, so the two meet near 8,000.
pub const AUTO_MONOLITHIC_ABOVE_SWEEP: usize = 8000;

/// Default dimensionless cavitation penalty factor xi.
pub const DEFAULT_PENALTY: f64 = 1e4;

/// `[reynolds]`: the Reynolds rectangle Omega_c on the top face, in units of the Hertz
/// radius a, and its numerical options. It must contain the Hertz circle and lie inside
/// the top face of the cube.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ReynoldsDomain {
    /// Inlet edge x_min/a, <= -1; default -3.
    pub x_min: f64,
    /// Outlet edge x_max/a, >= 1; default 3.
    pub x_max: f64,
    /// Side edge z_min/a, <= -1; default -3.
    pub z_min: f64,
    /// Side edge z_max/a, >= 1; default 3.
    pub z_max: f64,
    /// Dimensionless cavitation penalty factor xi (> 0): the term -xi min(P, 0) is added
    /// to the dimensionless Reynolds residual; default 1e4.
    pub penalty: f64,
    /// "supg" | "supg-exact" | "supg-couette" | "none"; default "supg".
    pub stabilisation: Stabilisation,
    /// Isotropic artificial diffusion factor delta_ID >= 0 (Habchi et al.): eps_ID =
    /// delta_ID h_e |(d rho_bar/dP) H u_bar| is added to the Reynolds diffusion coefficient;
    /// it vanishes with the element size h_e, but at h_e = 0.25 a and delta_ID = 10 it carries
    /// about a fifth of the Couette flux in the contact and thins the film by O(1), so the
    /// default is 0 (off); experimental.
    pub artificial_diffusion: f64,
    /// Crosswind diffusion factor delta_CD >= 0: eps_CD = delta_CD h_e |(d rho_bar/dP) H
    /// u_bar| acting across the streamlines only. It removes the crosswind stripes of the
    /// SUPG film (one-node dips at the side lobes) and changes hc by under 0.1 % at
    /// delta_CD = 0.1 on table2-ue2, but it also smears the side lobes of a heavily loaded
    /// contact (hm -9.5 % at 2 GPa), so the default is 0 (README "Crosswind diffusion").
    pub crosswind_diffusion: f64,
    /// "auto" | "condensed" | "monolithic"; default "auto" (condensed up to 4,000 pressure
    /// unknowns, 8,000 in a sweep, monolithic above). The same discrete problem either way.
    pub coupling: Coupling,
}

/// Default isotropic artificial diffusion factor.
pub const DEFAULT_ARTIFICIAL_DIFFUSION: f64 = 0.0;
/// Default crosswind diffusion factor.
pub const DEFAULT_CROSSWIND_DIFFUSION: f64 = 0.0;

impl Default for ReynoldsDomain {
    fn default() -> Self {
        ReynoldsDomain {
            x_min: -3.0,
            x_max: 3.0,
            z_min: -3.0,
            z_max: 3.0,
            penalty: DEFAULT_PENALTY,
            stabilisation: Stabilisation::Supg,
            artificial_diffusion: DEFAULT_ARTIFICIAL_DIFFUSION,
            crosswind_diffusion: DEFAULT_CROSSWIND_DIFFUSION,
            coupling: Coupling::Auto,
        }
    }
}

/// Keys of `[reynolds]`.
pub const REYNOLDS_FIELDS: &[Field] = &[
    f!("x_min", "inlet edge of the Reynolds rectangle x_min/a", "a", Kind::Number(Range::AtMost(-1.0)), Presence::Default("-3"),
        note = "the rectangle must contain the Hertz circle and lie inside the top face: |x_min| < mesh.cube_size/2"),
    f!("x_max", "outlet edge of the Reynolds rectangle x_max/a", "a", Kind::Number(Range::AtLeast(1.0)), Presence::Default("3"),
        note = "the rectangle must contain the Hertz circle and lie inside the top face: x_max < mesh.cube_size/2"),
    f!("z_min", "side edge of the Reynolds rectangle z_min/a", "a", Kind::Number(Range::AtMost(-1.0)), Presence::Default("-3"),
        note = "the rectangle must contain the Hertz circle and lie inside the top face: |z_min| < mesh.cube_size/2"),
    f!("z_max", "side edge of the Reynolds rectangle z_max/a", "a", Kind::Number(Range::AtLeast(1.0)), Presence::Default("3"),
        note = "the rectangle must contain the Hertz circle and lie inside the top face: z_max < mesh.cube_size/2"),
    f!("penalty", "dimensionless cavitation penalty factor xi", "", Kind::Number(Range::Positive), Presence::Default("1e4")),
    f!("stabilisation", "stabilisation of the Reynolds equation", "", Kind::Choice(Stabilisation::NAMES),
        Presence::Default("\"supg\"")),
    f!("artificial_diffusion", "isotropic artificial diffusion factor delta_ID (eps_ID = delta_ID h_e |rho' H u|; 0 = off; experimental: inconsistent, changes the film)", "",
        Kind::Number(Range::AtLeast(0.0)), Presence::Default("0")),
    f!("crosswind_diffusion", "crosswind diffusion factor delta_CD (eps_CD = delta_CD h_e |rho' H u|, across the streamlines only; removes the crosswind stripes; 0 = off)", "",
        Kind::Number(Range::AtLeast(0.0)), Presence::Default("0")),
    f!("coupling", "how Newton couples film and solid: the elastic block condensed onto the contact face (dense LU, fast on small meshes) or one sparse monolithic matrix (MUMPS; fast on fine meshes); auto = condensed up to 4,000 pressure unknowns (a sweep: 8,000)", "",
        Kind::Choice(Coupling::NAMES), Presence::Default("\"auto\"")),
];

// ---------------------------------------------------------------------------------------
// [mesh]

/// Smallest allowed contact element size (units of a): 16/2^10.
pub const MIN_CONTACT_SIZE: f64 = 16.0 / 1024.0;

/// `[mesh]`: the graded tetrahedral mesh of the equivalent cube, in units of a.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MeshSettings {
    /// Edge of the equivalent cube (units of a), in [20, 200]; default 60.
    pub cube_size: f64,
    /// Element size on the contact face (units of a), in [1/64, 16]; default 0.25. The
    /// mesher uses [`MeshSettings::contact_size_rounded`] (rounded down to 16/2^k).
    pub contact_size: f64,
    /// Element size growth per unit distance from the contact (dimensionless), in (0, 2];
    /// default 0.5.
    pub growth: f64,
    /// Element size in the core square |X|, |Z| <= core_half_width (units of a), finer
    /// than contact_size; 0 (default): no core refinement.
    pub core_size: f64,
    /// Half width of the core square (units of a), default 1.25.
    pub core_half_width: f64,
    /// Element size in the ring ring_inner <= sqrt(X^2 + Z^2) <= ring_outer around the
    /// Hertz circle (units of a); 0 (default): no ring refinement.
    pub ring_size: f64,
    /// Inner radius of the ring (units of a), default 0.75.
    pub ring_inner: f64,
    /// Outer radius of the ring (units of a), default 1.25.
    pub ring_outer: f64,
    /// Element size in the patch rectangle patch_x_min <= X <= patch_x_max,
    /// patch_z_min <= Z <= patch_z_max (units of a); 0 (default): no patch.
    pub patch_size: f64,
    /// Patch rectangle (units of a); with patch_size > 0, min < max on both axes.
    pub patch_x_min: f64,
    pub patch_x_max: f64,
    pub patch_z_min: f64,
    pub patch_z_max: f64,
    /// Radial limits of the patch (units of a): with patch_r_max > 0, only the part of the
    /// rectangle with patch_r_min <= sqrt(X^2 + Z^2) <= patch_r_max is refined; 0 (default):
    /// the whole rectangle.
    pub patch_r_min: f64,
    pub patch_r_max: f64,
}

impl Default for MeshSettings {
    fn default() -> Self {
        MeshSettings {
            cube_size: 60.0,
            contact_size: 0.25,
            growth: 0.5,
            core_size: 0.0,
            core_half_width: 1.25,
            ring_size: 0.0,
            ring_inner: 0.75,
            ring_outer: 1.25,
            patch_size: 0.0,
            patch_x_min: 0.0,
            patch_x_max: 0.0,
            patch_z_min: 0.0,
            patch_z_max: 0.0,
            patch_r_min: 0.0,
            patch_r_max: 0.0,
        }
    }
}

impl MeshSettings {
    /// The contact element size rounded down to the form 16/2^k (units of a).
    pub fn contact_size_rounded(&self) -> f64 {
        crate::mesh::spec::dyadic_size(self.contact_size).max(MIN_CONTACT_SIZE)
    }
}

/// Keys of `[mesh]`.
pub const MESH_FIELDS: &[Field] = &[
    f!(
        "cube_size",
        "edge of the equivalent cube",
        "a",
        Kind::Number(Range::Closed(20.0, 200.0)),
        Presence::Default("60")
    ),
    f!(
        "contact_size",
        "element size on the contact face (rounded down to 16/2^k)",
        "a",
        Kind::Number(Range::Closed(MIN_CONTACT_SIZE, 16.0)),
        Presence::Default("0.25")
    ),
    f!(
        "growth",
        "element size growth per unit distance from the contact",
        "",
        Kind::Number(Range::LeftOpen(0.0, 2.0)),
        Presence::Default("0.5")
    ),
    f!(
        "core_size",
        "element size in the core square around the Hertz contact (rounded down to 16/2^k; 0: no core)",
        "a",
        Kind::Number(Range::Closed(0.0, 16.0)),
        Presence::Default("0")
    ),
    f!(
        "core_half_width",
        "half width of the core square |X|, |Z| <= w",
        "a",
        Kind::Number(Range::Closed(0.25, 8.0)),
        Presence::Default("1.25")
    ),
    f!(
        "ring_size",
        "element size in the ring around the Hertz circle, ring_inner <= r <= ring_outer (rounded down to 16/2^k; 0: no ring)",
        "a",
        Kind::Number(Range::Closed(0.0, 16.0)),
        Presence::Default("0")
    ),
    f!(
        "ring_inner",
        "inner radius of the ring",
        "a",
        Kind::Number(Range::Closed(0.0, 8.0)),
        Presence::Default("0.75")
    ),
    f!(
        "ring_outer",
        "outer radius of the ring (must exceed ring_inner)",
        "a",
        Kind::Number(Range::LeftOpen(0.0, 8.0)),
        Presence::Default("1.25")
    ),
    f!(
        "patch_size",
        "element size in the patch rectangle, e.g. around an outlet constriction or a spin pole (rounded down to 16/2^k; 0: no patch)",
        "a",
        Kind::Number(Range::Closed(0.0, 16.0)),
        Presence::Default("0")
    ),
    f!("patch_x_min", "patch rectangle: lowest X", "a", Kind::Number(Range::Closed(-8.0, 8.0)), Presence::Default("0")),
    f!("patch_x_max", "patch rectangle: highest X (must exceed patch_x_min when patch_size > 0)", "a", Kind::Number(Range::Closed(-8.0, 8.0)), Presence::Default("0")),
    f!("patch_z_min", "patch rectangle: lowest Z", "a", Kind::Number(Range::Closed(-8.0, 8.0)), Presence::Default("0")),
    f!("patch_z_max", "patch rectangle: highest Z (must exceed patch_z_min when patch_size > 0)", "a", Kind::Number(Range::Closed(-8.0, 8.0)), Presence::Default("0")),
    f!("patch_r_min", "patch: refine only where sqrt(X^2 + Z^2) >= patch_r_min (with patch_r_max > 0)", "a", Kind::Number(Range::Closed(0.0, 8.0)), Presence::Default("0")),
    f!(
        "patch_r_max",
        "patch: refine only where sqrt(X^2 + Z^2) <= patch_r_max, a sector of an annulus for a side lobe along the contact edge (must exceed patch_r_min; 0: the whole rectangle)",
        "a",
        Kind::Number(Range::Closed(0.0, 8.0)),
        Presence::Default("0")
    ),
];

// ---------------------------------------------------------------------------------------
// [output]

/// `[output]`: where and what to write.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OutputSettings {
    /// Output directory (relative to the working directory); default `"out/<name>"`.
    pub dir: String,
    /// Write VTU field files; default true.
    pub vtu: bool,
    /// Write PNG plots; default true.
    pub png: bool,
    /// z (m) of the rolling-direction line along which the friction pass writes its
    /// shear-stress profile (`shear_profile.csv`); default 0 (the centre line).
    pub shear_profile_z: f64,
}

impl Default for OutputSettings {
    fn default() -> Self {
        // `dir` is filled with "out/<name>" after parsing.
        OutputSettings {
            dir: String::new(),
            vtu: true,
            png: true,
            shear_profile_z: 0.0,
        }
    }
}

/// Keys of `[output]`.
pub const OUTPUT_FIELDS: &[Field] = &[
    f!(
        "dir",
        "output directory",
        "",
        Kind::Text,
        Presence::Default("\"out/<name>\"")
    ),
    f!(
        "vtu",
        "write VTU field files",
        "",
        Kind::Bool,
        Presence::Default("true")
    ),
    f!(
        "png",
        "write PNG plots",
        "",
        Kind::Bool,
        Presence::Default("true")
    ),
    f!(
        "shear_profile_z",
        "z of the rolling-direction line of the shear-stress profile (shear_profile.csv)",
        "m",
        Kind::Number(Range::Any),
        Presence::Default("0")
    ),
];
