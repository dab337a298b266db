//! The numerical sections: `[reynolds]` (domain, cavitation, stabilisation, coupling),
//! `[mesh]` and `[output]`.
use super::*;

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

/// The same for a solve that starts with plain Newton from a coarser mesh's pressure (an
/// adaptive level after one that plain Newton solved, `--start-from`, a sequenced study):
/// Newton takes 7-19 steps from there, the monolithic ones on an LU reused over three
/// steps, and the condensation, 4-7 s at 2,700-3,700 pressure unknowns, is not paid back.
/// Adaptive levels at 2 ranks (docs/performance.md, "Couplings"): at 1,476-1,956 pressure
/// unknowns the condensed level is faster (table2-ue2's level 1: 4.2 s against 7.8 s), at
/// 2,706-3,748 the monolithic one (its level 2: 7.1 s against 12.9 s), and the next
/// monolithic level starts from its displacement. A level that goes to the continuation at
/// once keeps [`AUTO_MONOLITHIC_ABOVE`]: its many steps pay the condensation back.
pub const AUTO_MONOLITHIC_ABOVE_SEQUENCED: usize = 2500;

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
    /// Dimensionless cavitation penalty factor xi (> 0): with `effects.cavitation =
    /// "penalty"` the term -xi min(P, 0) is added to the dimensionless Reynolds residual;
    /// with "complementarity" the first solve from the Hertz start uses it (at most 1e3);
    /// default 1e4.
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
    /// Gradient-jump factor c_J >= 0 (crate::reynolds::jump): the pressure-slope jumps
    /// across the contact edges are penalised with gamma_E = c_J kappa |v| min(h_E, a/32)^3. It removes
    /// the P2 vertex mode (node-to-node wiggles in the Hertz zone) and vanishes for a smooth
    /// pressure (consistent); 0 = off.
    pub gradient_jump: f64,
    /// "auto" | "condensed" | "monolithic"; default "auto" (condensed up to 4,000 pressure
    /// unknowns, 8,000 in a sweep, monolithic above). The same discrete problem either way.
    pub coupling: Coupling,
}

/// Default isotropic artificial diffusion factor.
pub const DEFAULT_ARTIFICIAL_DIFFUSION: f64 = 0.0;
/// Default crosswind diffusion factor.
pub const DEFAULT_CROSSWIND_DIFFUSION: f64 = 0.0;
/// Default gradient-jump factor c_J.
pub const DEFAULT_GRADIENT_JUMP: f64 = 0.0;

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
            gradient_jump: DEFAULT_GRADIENT_JUMP,
            coupling: Coupling::Auto,
        }
    }
}

/// Keys of `[reynolds]`.
pub const REYNOLDS_FIELDS: &[Field] = &[
    f!("x_min", "inlet edge of the Reynolds rectangle x_min/a", "a", Kind::Number(Range::AtMost(-1.0)), Presence::Default("-3; -4.5 when refined to an accuracy target without a [mesh] table"),
        note = "the rectangle must contain the Hertz circle and lie inside the top face: |x_min| < mesh.cube_size/2"),
    f!("x_max", "outlet edge of the Reynolds rectangle x_max/a", "a", Kind::Number(Range::AtLeast(1.0)), Presence::Default("3"),
        note = "the rectangle must contain the Hertz circle and lie inside the top face: x_max < mesh.cube_size/2"),
    f!("z_min", "side edge of the Reynolds rectangle z_min/a", "a", Kind::Number(Range::AtMost(-1.0)), Presence::Default("-3"),
        note = "the rectangle must contain the Hertz circle and lie inside the top face: |z_min| < mesh.cube_size/2"),
    f!("z_max", "side edge of the Reynolds rectangle z_max/a", "a", Kind::Number(Range::AtLeast(1.0)), Presence::Default("3"),
        note = "the rectangle must contain the Hertz circle and lie inside the top face: z_max < mesh.cube_size/2"),
    f!("penalty", "dimensionless cavitation penalty factor xi", "", Kind::Number(Range::Positive), Presence::Default("1e4"),
        note = "the penalty model's xi; with effects.cavitation = \"complementarity\" only the first solve from the Hertz start uses it, at most 1e3, and the result does not depend on it"),
    f!("stabilisation", "stabilisation of the Reynolds equation", "", Kind::Choice(Stabilisation::NAMES),
        Presence::Default("\"supg\"")),
    f!("artificial_diffusion", "isotropic artificial diffusion factor delta_ID (eps_ID = delta_ID h_e |rho' H u|; 0 = off; experimental: inconsistent, changes the film)", "",
        Kind::Number(Range::AtLeast(0.0)), Presence::Default("0")),
    f!("crosswind_diffusion", "crosswind diffusion factor delta_CD (eps_CD = delta_CD h_e |rho' H u|, across the streamlines only; removes the crosswind stripes; 0 = off)", "",
        Kind::Number(Range::AtLeast(0.0)), Presence::Default("0")),
    f!("gradient_jump", "gradient-jump factor c_J: the pressure-slope jumps across the contact edges are penalised with gamma = c_J kappa |v| min(h, a/32)^3 (consistent: zero for a smooth pressure; removes the node-to-node wiggles of the P2 pressure in the Hertz zone; an adaptive level that does not converge with a factor below 1 is solved again with 1; 0 = off)", "",
        Kind::Number(Range::AtLeast(0.0)), Presence::Default("0; 0.01 when refined to an accuracy target without a [mesh] table")),
    f!("coupling", "how Newton couples film and solid: the elastic block condensed onto the contact face (dense LU, fast on small meshes) or one sparse monolithic matrix (MUMPS; fast on fine meshes); auto = condensed up to 4,000 pressure unknowns (a sweep: 8,000; plain Newton from a coarser mesh's pressure, such as an adaptive level: 2,500)", "",
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
    /// Depth of the core (units of a): > 0 refines the box of the core square down to
    /// this depth (for the subsurface stresses); default 0 (the square on the face).
    pub core_depth: f64,
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
            core_depth: 0.0,
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
        Presence::Default("0.5; 1.0 when refined to an accuracy target without a [mesh] table")
    ),
    f!(
        "core_size",
        "element size in the core square around the Hertz contact (rounded down to 16/2^k; 0: no core)",
        "a",
        Kind::Number(Range::Closed(0.0, 16.0)),
        Presence::Default("0; 0.125 with output.subsurface without a [mesh] table")
    ),
    f!(
        "core_half_width",
        "half width of the core square |X|, |Z| <= w",
        "a",
        Kind::Number(Range::Closed(0.25, 8.0)),
        Presence::Default("1.25; 1 with output.subsurface without a [mesh] table")
    ),
    f!(
        "core_depth",
        "depth of the core box below the face (0: the core square on the face only; > 0 refines the solid below the contact for output.subsurface)",
        "a",
        Kind::Number(Range::Closed(0.0, 8.0)),
        Presence::Default("0; 0.25 with output.subsurface without a [mesh] table")
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
    /// Recover the stresses inside the disc below the contact (subsurface.vtu, section
    /// maps, `subsurface` in summary.json); default false. A scene without a `[mesh]` table
    /// that sets it also gets the core box below the contact ([`super::SUBSURFACE_CORE_SIZE`]).
    pub subsurface: bool,
    /// "spr" | "average"; default "spr".
    pub subsurface_recovery: StressRecovery,
    /// The films' exponents in eta_R Ue (d ln hc / d ln(eta_R Ue), the same for hm) at the
    /// converged state, from their adjoints (`speed_exponents` in summary.json); default
    /// false.
    pub speed_exponents: bool,
}

impl Default for OutputSettings {
    fn default() -> Self {
        // `dir` is filled with "out/<name>" after parsing.
        OutputSettings {
            dir: String::new(),
            vtu: true,
            png: true,
            shear_profile_z: 0.0,
            subsurface: false,
            subsurface_recovery: StressRecovery::Spr,
            speed_exponents: false,
        }
    }
}

/// Keys of `[output]`.
pub const OUTPUT_FIELDS: &[Field] = &[
    f!("dir", "output directory", "", Kind::Text, Presence::Default("\"out/<name>\"")),
    f!("vtu", "write VTU field files", "", Kind::Bool, Presence::Default("true")),
    f!("png", "write PNG plots", "", Kind::Bool, Presence::Default("true")),
    f!(
        "shear_profile_z",
        "z of the rolling-direction line of the shear-stress profile (shear_profile.csv)",
        "m",
        Kind::Number(Range::Any),
        Presence::Default("0")
    ),
    f!(
        "subsurface",
        "recover the stresses in the disc below the contact (one extra elastic solve); without a [mesh] table the mesh gets the core box the stresses need (mesh.core_size 0.125, core_half_width 1, core_depth 0.25)",
        "",
        Kind::Bool,
        Presence::Default("false")
    ),
    f!(
        "subsurface_recovery",
        "stress recovery: superconvergent patch fit or nodal averaging",
        "",
        Kind::Choice(StressRecovery::NAMES),
        Presence::Default("\"spr\"")
    ),
    f!(
        "speed_exponents",
        "the films' exponents in eta_R Ue, d ln hc / d ln(eta_R Ue) and d ln hm / d ln(eta_R Ue), from their adjoints (one extra LU); lubricated elastic single-point scenes",
        "",
        Kind::Bool,
        Presence::Default("false")
    ),
];
