//! `summary.json`, typed: [`Summary`] for a lubricated run, [`DrySummary`] for a dry Hertz
//! run. The solver fills them; mesh sequencing (`--start-from`), the hard suite's checks and
//! `paper-findings` read [`Summary`] back. The regression runner compares two summaries key
//! by key as generic JSON, so both are written through [`to_json`] (keys sorted, as before).
//!
//! JSON has no NaN: a non-finite number is written as null and read back as NaN.
use crate::case::Scene;
use crate::error::{Error, ResultExt};
use serde::{Deserialize, Deserializer, Serialize};

/// Keys of summary.json that may be null: absent optional values (the mesh quality of rigid
/// solids, which have no 3D mesh; a film formula outside the setting it was fitted in), not
/// non-finite numbers ([`null_paths`] skips them).
pub const MAY_BE_NULL: &[&str] = &[
    "worst_quality",
    "spin_centre_z_m",
    "hc_hamrock_dowson_m",
    "hm_hamrock_dowson_m",
    "hc_nijenbanning_m",
    "moes",
    "entrainment_speed_m_s",
    "snes_reason",
    "path",
];

/// The dotted paths (`film.hc_m`, `solver.path[2]`) of the nulls in a summary `v`: its
/// non-finite numbers, apart from [`MAY_BE_NULL`] and everything below those keys, and the
/// scene echo. The writer refuses a summary with any; the hard suite reports them.
pub fn null_paths(v: &serde_json::Value) -> Vec<String> {
    fn walk(v: &serde_json::Value, path: &str, out: &mut Vec<String>) {
        match v {
            serde_json::Value::Null => out.push(path.to_string()),
            serde_json::Value::Object(m) => {
                for (k, x) in m {
                    if path.is_empty() && k == "scene" || MAY_BE_NULL.contains(&k.as_str()) {
                        continue;
                    }
                    walk(x, &if path.is_empty() { k.clone() } else { format!("{path}.{k}") }, out);
                }
            }
            serde_json::Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    walk(x, &format!("{path}[{i}]"), out);
                }
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    walk(v, "", &mut out);
    out
}

/// Reads null (a NaN or infinity when written) as NaN.
fn nan_if_null<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// The summary of a converged lubricated operating point.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Summary {
    /// Scene name.
    pub case: String,
    /// MPI ranks of the run.
    pub ranks: usize,
    pub converged: bool,
    pub hertz: HertzSummary,
    pub operating: OperatingSummary,
    pub kinematics: KinematicsSummary,
    pub mesh: MeshSummary,
    pub film: FilmSummary,
    pub pressure: PressureSummary,
    /// Moes' dimensionless load and material parameters (null for rigid or isoviscous
    /// scenes that have none).
    pub moes: Option<MoesSummary>,
    pub solver: SolverSummary,
    pub timing: Timing,
    /// Peak resident memory of the largest rank (MB).
    pub peak_rss_mb: f64,
    /// Which effects were simulated and which were not (see `app::lubricated::effects_report`).
    pub effects: serde_json::Value,
    /// The scene as solved (after `--set` overrides).
    pub scene: Scene,
    /// With a friction model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<FrictionSummary>,
}

/// Hertz contact of the scene.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct HertzSummary {
    pub a_m: f64,
    pub ph_pa: f64,
    pub e_prime_pa: f64,
}

/// The operating point.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct OperatingSummary {
    pub load_n: f64,
    pub entrainment_speed_m_s: Option<f64>,
    pub slide_to_roll: f64,
    pub tilt_angle_deg: f64,
}

/// Surface velocities of the kinematics model.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct KinematicsSummary {
    pub model: String,
    #[serde(rename = "omega_B_rad_s", deserialize_with = "nan_if_null")]
    pub omega_b_rad_s: f64,
    #[serde(rename = "omega_D_rad_s", deserialize_with = "nan_if_null")]
    pub omega_d_rad_s: f64,
    #[serde(rename = "U_BO_m_s", deserialize_with = "nan_if_null")]
    pub u_bo_m_s: f64,
    #[serde(rename = "U_DO_m_s", deserialize_with = "nan_if_null")]
    pub u_do_m_s: f64,
    /// z of the spin pole (m), with spin kinematics.
    pub spin_centre_z_m: Option<f64>,
}

/// The mesh.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MeshSummary {
    pub elements: usize,
    pub nodes: usize,
    pub dofs_total: usize,
    pub contact_triangles: usize,
    pub contact_size_a: f64,
    pub worst_quality: Option<f64>,
    pub worst_quality_measure: String,
    /// Dry runs only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_aspect_ratio: Option<f64>,
}

/// Film thickness (m): central, minimum and where, the film constant h0, and the curve fits
/// of Hamrock and Dowson and of Nijenbanning, Venner and Moes for comparison (fits to
/// numerical films of their day, not checks of this one: docs/validation.md).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FilmSummary {
    #[serde(deserialize_with = "nan_if_null")]
    pub hc_m: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub hm_m: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub hm_x_m: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub hm_z_m: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub h0_m: f64,
    pub hc_hamrock_dowson_m: Option<f64>,
    pub hm_hamrock_dowson_m: Option<f64>,
    /// The central film of Nijenbanning, Venner and Moes (1994), a fit to circular-contact
    /// films in Moes' groups (absent from summaries written before it was reported).
    #[serde(default)]
    pub hc_nijenbanning_m: Option<f64>,
}

/// Pressure (Pa): maximum and where, minimum of the field and of the nodes, and the load
/// balance's relative error.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PressureSummary {
    #[serde(deserialize_with = "nan_if_null")]
    pub pmax_pa: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub pmax_x_m: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub pmax_z_m: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub pmin_pa: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub pmin_nodes_pa: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub load_error_rel: f64,
    /// Node-to-node wiggles of the centre-line profiles: the largest jump of the pressure
    /// slope between neighbouring contact triangles along X = 0 and along Z = 0, in p_H/a
    /// (absent in summaries written before it existed).
    #[serde(default)]
    pub slope_jump_x0: Option<f64>,
    #[serde(default)]
    pub slope_jump_z0: Option<f64>,
    /// Node-to-node wiggles of the same lines: the largest scallop height |[dP/ds]| l / 8
    /// (l the element's length along the line), in p_H (`SlopeJumps::largest_scallop`; absent in
    /// summaries written before it existed).
    #[serde(default)]
    pub wiggle_x0: Option<f64>,
    #[serde(default)]
    pub wiggle_z0: Option<f64>,
    /// The centre-line pressure 0.5 a inside the inlet boundary, in p_H: how much of the
    /// inlet's build-up the domain cuts off (absent in summaries written before it existed).
    #[serde(default)]
    pub inlet_over_ph: Option<f64>,
}

/// Moes' parameters M and L.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct MoesSummary {
    #[serde(rename = "M")]
    pub m: f64,
    #[serde(rename = "L")]
    pub l: f64,
}

/// The Newton solve.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SolverSummary {
    /// Over the whole path.
    pub newton_iterations: usize,
    pub snes_reason: String,
    #[serde(deserialize_with = "nan_if_null")]
    pub residual_norm: f64,
    pub dofs_elastic: usize,
    pub dofs_reynolds: usize,
    /// Every Newton solve of the path (plain Newton, continuation steps).
    pub path: Vec<String>,
    pub half_domain: bool,
    pub penalty: f64,
    pub stabilisation: String,
    /// "condensed", "monolithic" or "rigid".
    pub coupling: String,
}

/// Wall time per phase (s).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Timing {
    pub mesh_s: f64,
    pub assembly_s: f64,
    pub solve_s: f64,
    /// Lubricated runs only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub post_s: Option<f64>,
    pub total_s: f64,
    /// Only when the elastic block was condensed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub condensation_s: Option<f64>,
    /// With a friction model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_s: Option<f64>,
}

/// Friction on the disc.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FrictionSummary {
    pub model: String,
    #[serde(deserialize_with = "nan_if_null")]
    pub fx: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub fz: f64,
    #[serde(rename = "Fx_n", deserialize_with = "nan_if_null")]
    pub fx_n: f64,
    #[serde(rename = "Fz_n", deserialize_with = "nan_if_null")]
    pub fz_n: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub tau_max_pa: f64,
    /// The pass's adapted quadrature (absent in summaries written before it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quadrature: Option<FrictionQuadratureSummary>,
}

/// The friction pass's quadrature: how far it adapted, and what the fixed 12-point rule on
/// every triangle gives instead.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FrictionQuadratureSummary {
    pub triangles: usize,
    pub subdivided: usize,
    pub stress_evaluations: usize,
    pub fixed_rule_fx: f64,
    pub fixed_rule_fz: f64,
}

/// The summary of a dry Hertz run.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct DrySummary {
    pub case: String,
    pub ranks: usize,
    pub converged: bool,
    pub hertz: HertzSummary,
    pub equivalent_solid: EquivalentSolidSummary,
    pub mesh: MeshSummary,
    pub elastic: ElasticSummary,
    pub timing: Timing,
    pub peak_rss_mb: f64,
    pub peak_rss_mb_all_ranks: f64,
    pub scene: Scene,
}

/// The equivalent elastic solid.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct EquivalentSolidSummary {
    pub e_pa: f64,
    pub nu: f64,
}

/// The dry deflection against the half-space solution.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct ElasticSummary {
    pub u2_center_m: f64,
    pub u2_edge_m: f64,
    pub u2_center_halfspace_m: f64,
    pub u2_difference_halfspace_m: f64,
    pub traction_load_error_rel: f64,
}

/// A summary as JSON (keys sorted; non-finite numbers null).
pub fn to_json<T: Serialize>(summary: &T) -> Result<serde_json::Value, Error> {
    serde_json::to_value(summary).map_err(|e| Error::other(format!("cannot encode summary.json: {e}")))
}

impl Summary {
    /// Reads a lubricated run's summary from JSON text.
    pub fn from_json(text: &str) -> Result<Summary, Error> {
        serde_json::from_str(text).map_err(|e| Error::format(e.to_string()))
    }

    /// Reads `dir/summary.json`.
    pub fn read(dir: &std::path::Path) -> Result<Summary, Error> {
        let path = dir.join("summary.json");
        let text = std::fs::read_to_string(&path).map_err(Error::reading(&path))?;
        Summary::from_json(&text).context(path.display().to_string())
    }
}
