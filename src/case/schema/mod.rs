//! The scene-file schema: serde structs in SI units, each followed by the list of its keys
//! (meaning, unit, range, default) used by the strict validator in [`super::spec`].
//!
//! Keep each `*_FIELDS` list in step with the struct above it: the test
//! `known_keys_match_structs` serialises a full scene and checks both directions.
//!
//! The top level and the physical sections are here; `effects` and `numerics` hold the
//! rest (the macros below are defined before them, so they see them).
use std::fmt;

use serde::{Deserialize, Serialize};

use super::spec::{Field, Kind, Presence, Range};

/// Builds a [`Field`] in a const context.
macro_rules! f {
    ($key:literal, $what:literal, $unit:literal, $kind:expr, $presence:expr) => {
        Field { key: $key, what: $what, unit: $unit, kind: $kind, presence: $presence, note: "" }
    };
    ($key:literal, $what:literal, $unit:literal, $kind:expr, $presence:expr, note = $note:literal) => {
        Field { key: $key, what: $what, unit: $unit, kind: $kind, presence: $presence, note: $note }
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

mod effects;
mod numerics;
pub use effects::*;
pub use numerics::*;

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
    /// Accuracy target and adaptive refinement.
    #[serde(default)]
    pub accuracy: Accuracy,
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
        "parameter sweep: lists of operating values, one converged solve per combination (entrainment speed outermost, slide-to-roll innermost), each started from the previous converged state on one mesh; with accuracy.target each point refined adaptively by itself",
        "",
        Kind::Table(SWEEP_FIELDS),
        Presence::Default("none (one operating point)")
    ),
    f!(
        "accuracy",
        "accuracy target: adaptive refinement of the contact face until the estimated errors are below it",
        "",
        Kind::Table(ACCURACY_FIELDS),
        Presence::Default("target 0.01 for a lubricated single-point scene without [mesh]; none otherwise (a sweep refines only with a target of its own)")
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
// [accuracy]

/// Default relative error target of a lubricated scene without `[mesh]` keys.
pub const DEFAULT_ACCURACY_TARGET: f64 = 0.01;

/// `[accuracy]`: what a lubricated solve must reach, by adaptive refinement.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Accuracy {
    /// Relative error target of hc and hm (and fx, fz when friction is on): the contact
    /// face is refined where the error indicator is largest until the estimated error of
    /// each is below it. 0: no refinement (the mesh of `[mesh]`). When absent: 0.01 for a
    /// lubricated elastic single-point scene without `[mesh]` keys, else 0 (filled in by
    /// the parser).
    pub target: f64,
    /// Most refinement levels after the first solve; default 8.
    pub max_levels: u32,
    /// Fraction theta of the goal-oriented indicator (the mass-flux residual weighted by
    /// the adjoints of hc, hm and, with friction, fx and fz) that the marked elements
    /// carry (Doerfler marking); default 0.9. 0: every level refines the whole pressurised
    /// zone instead.
    pub marking: f64,
    /// Most unknowns a level may have: a level that would exceed it is not solved, and the
    /// last level's result is written with its estimated error (exit 4); default 800,000.
    pub max_unknowns: u64,
    /// Wall-time budget of the refinement levels after the first, in seconds from the start
    /// of the run: a level still running when it is spent is abandoned and the last
    /// converged level's result is written with its estimated error (exit 4); 0: no
    /// budget; default 3600.
    pub max_seconds: f64,
}

/// Default of `accuracy.marking`. Measured on table2-ue2 (docs/accuracy.md, "What a level
/// refines"): 0.5 marks a few triangles at the outlet spike per level, and hc barely moves
/// between levels while it is 0.7 % off (the change-based estimate cannot see it); 0.9 gives
/// the films of the whole-zone refinement with a third of the unknowns.
pub const DEFAULT_MARKING: f64 = 0.9;

/// Default of `accuracy.max_unknowns`: about 6.5 GB per rank on 2 ranks with MUMPS's block
/// low-rank LU (the peak of a level grows like its unknowns to the power 1.2-1.4).
/// cases/hard/heavy-2gpa's level 5 (789,564 unknowns) peaked at 6.7 GB per rank and took its
/// hm estimate from 1.35 % to 0.17 %; with the full-rank LU the same memory held 600,000.
pub const DEFAULT_MAX_UNKNOWNS: u64 = 800_000;

/// Default of `accuracy.max_seconds`: one hour, about 2.5 times the longest run measured at
/// the default target on 2 ranks (cases/hard/heavy-3gpa, 1,325 s) and three to five times the
/// slowest Moes points (M = 700, L = 7: 1,220 s; M = 1000, L = 20: 778 s), so that a slower or
/// busier machine still ends them; a former budget of 1800 s was spent, next to two other
/// jobs, in M = 1000, L = 10's last level. It still ends, with a labelled result, the runs
/// whose fine levels Newton cannot take (hours of continuation otherwise), and a level the
/// time left cannot hold is not begun (docs/accuracy.md).
pub const DEFAULT_MAX_SECONDS: f64 = 3600.0;

/// Element size growth of a mesh refined adaptively by default (no `[mesh]` table): the
/// solid under the refined face coarsens by one element size per unit depth.
pub const ADAPTIVE_GROWTH: f64 = 1.0;

/// Inlet edge x_min/a of a scene refined adaptively by default that does not set it: the
/// classic Reynolds domain of the multigrid literature (X from -4.5). At light loads the
/// inlet build-up reaches beyond X = -3 (Moes M = 10, L = 6: hc 1.5 % and hm 2.9 % low
/// on X >= -3), and an accuracy target must not be capped by the domain.
pub const ADAPTIVE_X_MIN: f64 = -4.5;

/// Gradient-jump factor c_J (`reynolds.gradient_jump`) of a scene refined adaptively by
/// default that does not set it: the smallest factor measured that takes table2-ue2's
/// largest pressure scallop along X = 0 at target 0.005 from 0.0025 p_H to 0.0005 p_H (the
/// films unchanged); 0.03 does the same with a coarser first level further off, and 0.1
/// closes the film of the 0.25 a first level at the side lobe (those three measured before
/// the coefficient stopped growing at a/32). Hand-made meshes keep 0: their validation
/// tables and regression references were measured without it (docs/accuracy.md, "Smooth
/// fields").
pub const ADAPTIVE_GRADIENT_JUMP: f64 = 0.01;

/// The gradient-jump factor an adaptive level is solved again with when Newton does not
/// converge with a smaller one (positive): at Moes M = 100, L = 20 (alpha p_H = 34) the
/// outlet spike is one element wide on the 0.0625 a and 0.03125 a levels and the
/// pressure-viscosity continuation stops short of the scene's alpha with c_J = 0.01 and 0.1;
/// with 1 every level converges, pmax drops (the spike is smoothed at the mesh scale) and hc,
/// hm move by 0.1 % and 0.3 % (docs/accuracy.md, "Newton on fine levels at high M and L").
pub const RAISED_GRADIENT_JUMP: f64 = 1.0;

/// Core box of a scene that asks for `output.subsurface` without a `[mesh]` table: element
/// size, half width and depth (units of a). Measured on the dry Hertz scene against Huber
/// and Hamilton (docs/subsurface.md): on the plain default mesh (0.25 a on the face)
/// sigma_r is 2 % off at the surface and the sliding maxima 0.04 a from their place. A box
/// of 0.125 a over the Hertz circle brings the axis stresses within 0.7 % of p_H, but
/// leaves the von Mises maximum of the sliding contact at mu = 0.3 0.009-0.012 a deeper
/// than Hamilton's (2.2 % of its distance from the centre) on every depth of the box: the
/// traction is resolved at the face. 0.0625 a over |X|, |Z| <= 0.625 (the maxima lie
/// within |X| <= 0.35) brings both sliding maxima within 0.005 a (0.9 %) for 1.5 times the
/// unknowns of the 0.125 a box. One layer below the face is what the profile just below
/// the surface needs (the square on the face alone leaves sigma_y 1.3 % off at depth).
pub const SUBSURFACE_CORE_SIZE: f64 = 0.0625;
/// Half width of the default subsurface core box (units of a).
pub const SUBSURFACE_CORE_HALF_WIDTH: f64 = 0.625;
/// Depth of the default subsurface core box (units of a).
pub const SUBSURFACE_CORE_DEPTH: f64 = 0.25;

impl Default for Accuracy {
    fn default() -> Self {
        // target < 0: not given (the parser fills it in).
        Accuracy {
            target: -1.0,
            max_levels: 8,
            marking: DEFAULT_MARKING,
            max_unknowns: DEFAULT_MAX_UNKNOWNS,
            max_seconds: DEFAULT_MAX_SECONDS,
        }
    }
}

/// Keys of `[accuracy]`.
pub const ACCURACY_FIELDS: &[Field] = &[
    f!(
        "target",
        "relative error target of hc and hm (and fx, fz with friction); 0: no refinement, the [mesh] as given",
        "",
        Kind::Number(Range::Closed(0.0, 0.2)),
        Presence::Default("0.01 for a lubricated elastic single-point scene without [mesh]; 0 otherwise"),
        note = "refinement stops when the estimated relative error of every target quantity is below it; the estimate is the change between the last two levels (see docs/accuracy.md)"
    ),
    f!(
        "max_levels",
        "most refinement levels after the first solve",
        "",
        Kind::Number(Range::Closed(1.0, 12.0)),
        Presence::Default("8")
    ),
    f!(
        "marking",
        "fraction of the goal-oriented error indicator (mass-flux residual weighted by the adjoints of hc, hm and, with friction, fx and fz) carried by the elements each level refines (Doerfler marking); 0: the whole pressurised zone at every level",
        "",
        Kind::Number(Range::Closed(0.0, 1.0)),
        Presence::Default("0.9"),
        note = "0.9 reaches the films of whole-zone refinement with about a third of the unknowns on table2-ue2; much lower fractions refine too little for the change between levels to measure the error (docs/accuracy.md)"
    ),
    f!(
        "max_unknowns",
        "most unknowns (elastic + pressure + h0) a refinement level may have",
        "",
        Kind::Number(Range::Closed(1e4, 1e9)),
        Presence::Default("800000"),
        note = "a level that would exceed it refines only the marked triangles of largest indicator that fit, once per run, when even the next full level's change could take every estimate below the target; otherwise, or when those carry less than a quarter of the marked indicator, it is not solved: the last level's result is written with its estimated error, summary.json says accuracy.reached = false, and the exit code is 4 (6-7 GB per rank on 2 ranks at 800,000; raise it on a larger machine)"
    ),
    f!(
        "max_seconds",
        "wall-time budget of the refinement levels after the first, from the start of the run; 0: none",
        "s",
        Kind::Number(Range::Closed(0.0, 1e7)),
        Presence::Default("3600"),
        note = "a level predicted from a monolithic level before it not to end in the time left is cut to the unknowns that fit, or not begun; a level still running when the budget is spent is abandoned on every rank at its next check: the last converged level's result is written with its estimated error, summary.json says accuracy.reached = false, and the exit code is 4; the first level always runs to its end"
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
    f!("ball_radius", "ball radius R_B", "m", Kind::Number(Range::Positive), Presence::Required),
    f!("disc_track_radius", "radius of the contact track on the disc R_D", "m", Kind::Number(Range::Positive), Presence::Default("0.04")),
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
    f!("ball", "elastic material of the ball B", "", Kind::Table(MATERIAL_FIELDS), Presence::Required),
    f!("disc", "elastic material of the disc D", "", Kind::Table(MATERIAL_FIELDS), Presence::Required),
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
    f!("young_modulus", "Young's modulus E", "Pa", Kind::Number(Range::Positive), Presence::Required),
    f!("poisson_ratio", "Poisson's ratio nu", "", Kind::Number(Range::Open(-1.0, 0.5)), Presence::Required),
];

// ---------------------------------------------------------------------------------------
// [lubricant]

/// Default Roelands reference pressure P_R (Pa).
pub const DEFAULT_ROELANDS_REFERENCE_PRESSURE: f64 = crate::physics::rheology::ROELANDS_REFERENCE_PRESSURE;
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
    f!(
        "pressure_viscosity",
        "pressure-viscosity coefficient alpha",
        "1/Pa",
        Kind::Number(Range::NonNegative),
        Presence::Conditional("required unless effects.viscosity = \"constant\" or lubricant.roelands_exponent is given")
    ),
    f!("roelands_reference_pressure", "Roelands reference pressure P_R", "Pa", Kind::Number(Range::Positive), Presence::Default("1.96e8")),
    f!(
        "roelands_exponent",
        "Roelands pressure-viscosity index z_R",
        "",
        Kind::Number(Range::LeftOpen(0.0, 2.0)),
        Presence::Default("alpha P_R / (ln eta_R + 9.67)"),
        note = "only with effects.viscosity = \"roelands\""
    ),
    f!("density", "reference density rho_R", "kg/m^3", Kind::Number(Range::Positive), Presence::Default("870")),
    f!("ree_eyring_stress", "Ree-Eyring stress tau0", "Pa", Kind::Number(Range::Positive), Presence::Default("6.2e6")),
];

// ---------------------------------------------------------------------------------------
// [operating]

fn default_tilt_angle() -> f64 {
    90.0
}

/// `[operating]`: load and kinematics (docs/model.md section 3).
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
    /// Coulomb friction coefficient mu of a dry scene's surface traction q = mu p (in +x,
    /// on the disc) when `effects.surface_traction = "friction"`; default 0.
    #[serde(default)]
    pub friction_coefficient: f64,
}

/// Keys of `[operating]`.
pub const OPERATING_FIELDS: &[Field] = &[
    f!("load", "normal load L", "N", Kind::Number(Range::Positive), Presence::Required),
    f!(
        "entrainment_speed",
        "entrainment speed Ue",
        "m/s",
        Kind::Number(Range::Positive),
        Presence::Conditional("required when effects.lubrication = \"reynolds\"")
    ),
    f!("slide_to_roll", "slide-to-roll ratio SRR (fraction, 0.05 = 5 %)", "", Kind::Number(Range::AbsAtMost(2.0)), Presence::Default("0")),
    f!(
        "tilt_angle",
        "tilt angle lambda of the ball's rotation axis",
        "degrees",
        Kind::Number(Range::LeftOpen(0.0, 90.0)),
        Presence::Default("90"),
        note = "lambda = 0 is singular: the ball spin omega_B = U_BO/(R_B sin lambda) would be infinite"
    ),
    f!(
        "friction_coefficient",
        "dry scene: Coulomb coefficient mu of the surface traction q = mu p in +x (effects.surface_traction = \"friction\")",
        "",
        Kind::Number(Range::Closed(0.0, 1.0)),
        Presence::Default("0")
    ),
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
    f!(
        "entrainment_speed",
        "entrainment speeds Ue",
        "m/s",
        Kind::NumberList(Range::Positive),
        Presence::Default("operating.entrainment_speed")
    ),
    f!(
        "tilt_angle",
        "tilt angles lambda",
        "degrees",
        Kind::NumberList(Range::LeftOpen(0.0, 90.0)),
        Presence::Default("operating.tilt_angle")
    ),
    f!(
        "slide_to_roll",
        "slide-to-roll ratios SRR (fractions)",
        "",
        Kind::NumberList(Range::AbsAtMost(2.0)),
        Presence::Default("operating.slide_to_roll")
    ),
];
