//! The scene file (`case.toml`): schema, units, strict validation and which effects are on.
//!
//! Entry points: [`load_scene`] (from a file) and [`parse_scene`] (from text). Both return
//! a fully validated [`Scene`] in SI units, or a [`SceneError`] whose Display is one clear
//! message naming the dotted key, the value and what is allowed.
//!
//! Validation runs in three passes:
//! 1. the text is parsed into a `toml::Table` and walked against the key lists of
//!    [`schema`] ([`spec::check_table`]): unknown keys (with the closest known key
//!    suggested), missing required keys, wrong types, non-finite and out-of-range numbers,
//!    unknown choices;
//! 2. serde deserialises the table into [`Scene`] (defaults filled in);
//! 3. cross-field checks ([`Scene::validate`]): Reynolds rectangle inside the cube's top face,
//!    lubricant and entrainment speed present when lubricated, Roelands-only keys, etc.
//!
//! [`reference_markdown`] renders the schema (keys, meaning, unit, range, default) as
//! Markdown: docs/scene-reference.md is its output (a test keeps the two equal).
pub mod error;
pub mod plausible;
pub mod schema;
pub mod spec;

use crate::error::Error;
use std::path::Path;

use serde::Deserialize;

pub use error::{SceneError, SceneErrorKind};
pub use schema::*;

use crate::physics::film_formulas::nijenbanning_central;
use crate::physics::{equivalent_solid, DensityLaw, HamrockDowson, Hertz, Kinematics, Material, MoesParameters, Scales, ViscosityLaw};
use spec::fmt_num;

/// Reads and validates the scene file at `path`. The scene name defaults to the file stem,
/// or to the parent directory's name when the file is called `case.toml` or `scene.toml`.
/// Every error names the file.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    load_scene_with(path, &[])
}

/// As [`load_scene`], with command-line overrides `KEY=VALUE` (dotted key, TOML value; a
/// value that is not valid TOML is taken as a string) applied before validation, so an
/// override is checked like the file's own keys.
pub fn load_scene_with(path: &Path, overrides: &[String]) -> Result<Scene, SceneError> {
    let text = read_bounded(path, MAX_SCENE_BYTES).map_err(|e| SceneError::new(SceneErrorKind::Io(e)).in_file(path.to_path_buf()))?;
    parse_scene_with(&text, &default_name(path), overrides).map_err(|e| match (&e.kind, overridden(&e, overrides)) {
        // The value came from the command line, not from the file.
        (SceneErrorKind::Syntax(m), _) if m.starts_with("--set ") => SceneError::from(SceneErrorKind::Conflict(m.clone())),
        (_, Some(o)) => SceneError::from(SceneErrorKind::Conflict(format!("--set {o}: {}", e.kind))),
        _ => e.in_file(path.to_path_buf()),
    })
}

/// The largest scene file read (bytes): the biggest shipped scene is a few kB, a sweep of
/// three 1000-value lists about 20 kB.
pub const MAX_SCENE_BYTES: u64 = 1 << 20;

/// Reads a text file of at most `limit` bytes. Anything but a regular file (a FIFO, a
/// device such as /dev/zero, a folder) is refused before it is opened, so the read never
/// blocks or runs without end.
pub fn read_bounded(path: &Path, limit: u64) -> std::io::Result<String> {
    use std::io::{Error, ErrorKind, Read};
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        let what = if meta.is_dir() { "a folder" } else { "not a regular file (a pipe, socket or device)" };
        return Err(Error::new(ErrorKind::InvalidInput, format!("{what}; a scene must be a regular file")));
    }
    if meta.len() > limit {
        return Err(Error::new(ErrorKind::InvalidInput, format!("{} bytes, more than the limit of {limit} bytes", meta.len())));
    }
    let mut text = String::new();
    std::fs::File::open(path)?.take(limit + 1).read_to_string(&mut text)?;
    if text.len() as u64 > limit {
        return Err(Error::new(ErrorKind::InvalidInput, format!("more than the limit of {limit} bytes")));
    }
    Ok(text)
}

/// The `--set KEY=VALUE` whose key the error is about, if any.
fn overridden<'a>(e: &SceneError, overrides: &'a [String]) -> Option<&'a String> {
    let path = match &e.kind {
        SceneErrorKind::UnknownKey { path, .. } | SceneErrorKind::WrongType { path, .. } | SceneErrorKind::NotAllowed { path, .. } => {
            path.as_str()
        }
        _ => return None,
    };
    // The last override of that key (or of the list it indexes) wins.
    let base = path.split('[').next().unwrap_or(path);
    overrides.iter().rev().find(|o| {
        o.split_once('=').is_some_and(|(k, _)| {
            k.trim() == base || base.starts_with(&format!("{}.", k.trim())) || k.trim().starts_with(&format!("{base}."))
        })
    })
}

fn default_name(path: &Path) -> String {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("scene");
    if stem == "case" || stem == "scene" {
        let parent = path.parent().and_then(|p| p.file_name()).and_then(|s| s.to_str());
        if let Some(p) = parent.filter(|p| !p.is_empty()) {
            return p.to_string();
        }
    }
    stem.to_string()
}

/// Parses and validates scene text; `default_name` is used when the text has no `name`.
pub fn parse_scene(text: &str, default_name: &str) -> Result<Scene, SceneError> {
    parse_scene_with(text, default_name, &[])
}

/// As [`parse_scene`], with `KEY=VALUE` overrides (see [`load_scene_with`]).
pub fn parse_scene_with(text: &str, default_name: &str, overrides: &[String]) -> Result<Scene, SceneError> {
    let mut table: toml::Table = toml::from_str(text).map_err(|e| SceneErrorKind::Syntax(syntax_message(text, &e)))?;
    for o in overrides {
        apply_override(&mut table, o)?;
    }
    spec::check_table(SCENE_FIELDS, &table, SCENE_FIELDS, "")?;
    let hand_mesh = table.contains_key("mesh");
    let reynolds_key = |k: &str| table.get("reynolds").and_then(|r| r.as_table()).is_some_and(|r| r.contains_key(k));
    let (inlet_given, jump_given) = (reynolds_key("x_min"), reynolds_key("gradient_jump"));
    let mut scene = Scene::deserialize(toml::Value::Table(table))
        .map_err(|e| SceneErrorKind::Syntax(format!("scene does not match the schema: {e}")))?;
    // A lubricated, elastic, single-point scene whose mesh nobody made by hand is refined
    // to the default target when it gives none; refined adaptively (its own target or the
    // default; a sweep only with its own, since every point is then refined by itself) it
    // also gets the adaptive mesh defaults (docs/accuracy.md).
    let refinable =
        !hand_mesh && scene.effects.lubrication == LubricationModel::Reynolds && scene.effects.elasticity == ElasticityModel::Elastic;
    if scene.accuracy.target < 0.0 {
        scene.accuracy.target = if refinable && scene.sweep.is_none() { schema::DEFAULT_ACCURACY_TARGET } else { 0.0 };
    }
    if refinable && scene.accuracy.target > 0.0 {
        scene.mesh.growth = schema::ADAPTIVE_GROWTH;
        if !inlet_given {
            scene.reynolds.x_min = schema::ADAPTIVE_X_MIN;
        }
        if !jump_given {
            scene.reynolds.gradient_jump = schema::ADAPTIVE_GRADIENT_JUMP;
        }
    }
    // A scene that asks for the subsurface stresses without making its mesh by hand gets
    // the core box below the contact they need (docs/subsurface.md); a scene that does not
    // ask pays nothing.
    if !hand_mesh && scene.output.subsurface {
        scene.mesh.core_size = schema::SUBSURFACE_CORE_SIZE;
        scene.mesh.core_half_width = schema::SUBSURFACE_CORE_HALF_WIDTH;
        scene.mesh.core_depth = schema::SUBSURFACE_CORE_DEPTH;
    }
    if scene.name.is_empty() {
        if default_name.trim().is_empty() {
            return Err(SceneErrorKind::MissingField {
                path: "name".into(),
                description: "scene name, used for the default output directory".into(),
            }
            .into());
        }
        scene.name = default_name.to_string();
    }
    if scene.output.dir.is_empty() {
        scene.output.dir = format!("out/{}", scene.name);
    }
    scene.validate()?;
    Ok(scene)
}

/// Sets the dotted key of `KEY=VALUE` in `table` (creating missing sections).
fn apply_override(table: &mut toml::Table, o: &str) -> Result<(), SceneError> {
    let bad = |why: &str| SceneError::from(SceneErrorKind::Syntax(format!("--set {o}: {why}")));
    let (key, value) = o.split_once('=').ok_or_else(|| bad("expected KEY=VALUE, e.g. mesh.core_size=0.0625"))?;
    let (key, value) = (key.trim(), value.trim());
    let parts: Vec<&str> = key.split('.').collect();
    if parts.iter().any(|p| p.is_empty()) {
        return Err(bad("the key must be dotted names, e.g. operating.load"));
    }
    let value = match toml::from_str::<toml::Table>(&format!("v = {value}")) {
        Ok(mut t) => t.remove("v").expect("parsed above"),
        Err(_) => toml::Value::String(value.to_string()),
    };
    let mut t = table;
    for (i, p) in parts[..parts.len() - 1].iter().enumerate() {
        let entry = t.entry(p.to_string()).or_insert_with(|| toml::Value::Table(toml::Table::new()));
        t = entry.as_table_mut().ok_or_else(|| bad(&format!("'{}' is not a section", parts[..=i].join("."))))?;
    }
    t.insert(parts[parts.len() - 1].to_string(), value);
    Ok(())
}

/// One-line TOML syntax message: `line L, column C: what`.
fn syntax_message(text: &str, e: &toml::de::Error) -> String {
    let what = e.message().trim().replace('\n', "; ");
    match e.span() {
        Some(span) => {
            let before = &text[..span.start.min(text.len())];
            let line = before.matches('\n').count() + 1;
            let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
            format!("line {line}, column {column}: {what}")
        }
        None => what,
    }
}

/// The scene-file reference, docs/scene-reference.md: a short preamble, then the schema as
/// Markdown tables (key, meaning, unit, allowed values, default), one per section.
pub fn reference_markdown() -> String {
    format!("{REFERENCE_PREAMBLE}{}", spec::reference_markdown(SCENE_FIELDS))
}

const REFERENCE_PREAMBLE: &str = "\
# Scene file reference

<!-- Generated from src/case/schema.rs by `ehl-petsc --scene-reference`; do not edit.
     tests/scene_reference.rs keeps this file equal to the generated text. Regenerate with
     target/release/ehl-petsc --scene-reference > docs/scene-reference.md -->

A scene is a TOML file with the sections below. Every key is checked before anything is
solved: an unknown key (with the closest known key suggested), a missing required key, a
wrong type, a number out of range or a contradiction between keys (a Roelands exponent with
Barus viscosity, a swept tilt angle with uniform kinematics, ...) stops the run with exit
code 2 and a message naming the key. Keys that are valid but have no effect (a tilt angle
with uniform kinematics, friction without lubrication or without sliding) print a warning
at the start of the run. `--set KEY=VALUE` on the command line overrides a key before the
check (`--set operating.load=2000`, `--set effects.friction=none`).

Units are SI except where the unit column says `a`: lengths in units of the Hertz radius
a = (3 L R_B / (2 E'))^(1/3), which the program computes from the scene (0.92 mm for the
paper's Table 1). `cases/examples/minimal.toml` shows the smallest lubricated scene: every
key it leaves out takes the default below, and the defaults are the paper's model.

";

fn missing(path: &str) -> SceneError {
    let f = spec::lookup(SCENE_FIELDS, path).expect("schema path");
    let description = f.description_with_condition();
    let path = path.to_string();
    match f.kind {
        spec::Kind::Table(_) => SceneErrorKind::MissingSection { path, description },
        _ => SceneErrorKind::MissingField { path, description },
    }
    .into()
}

fn not_allowed(path: &str, value: f64, allowed: String) -> SceneError {
    SceneErrorKind::NotAllowed { path: path.into(), value: fmt_num(value), allowed }.into()
}

impl Scene {
    /// Cross-field checks (pass 3). Single-field ranges were checked while parsing;
    /// this is public so that programmatically built scenes can be checked too.
    pub fn validate(&self) -> Result<(), SceneError> {
        self.validate_fields_finite()?;
        let r = &self.reynolds;
        let half = self.mesh.cube_size / 2.0;
        // Containment of the Hertz circle (x_min <= -1 <= 1 <= x_max, same in z, hence also
        // x_min < x_max) is a single-field range checked by the walk above; what remains is
        // the cross-field bound by the cube.
        for (v, name) in [(r.x_min, "x_min"), (r.x_max, "x_max"), (r.z_min, "z_min"), (r.z_max, "z_max")] {
            if v.abs() >= half {
                return Err(not_allowed(
                    &format!("reynolds.{name}"),
                    v,
                    format!(
                        "|{name}| must be < mesh.cube_size/2 = {} (units of a) so that the Reynolds rectangle lies inside the top face of the cube",
                        fmt_num(half)
                    ),
                ));
            }
        }

        let m = &self.mesh;
        if m.ring_outer <= m.ring_inner {
            return Err(not_allowed(
                "mesh.ring_outer",
                m.ring_outer,
                format!("must exceed mesh.ring_inner = {} (units of a)", fmt_num(m.ring_inner)),
            ));
        }
        if m.patch_size > 0.0 {
            for (lo, hi, axis) in [(m.patch_x_min, m.patch_x_max, "x"), (m.patch_z_min, m.patch_z_max, "z")] {
                if hi <= lo {
                    return Err(not_allowed(
                        &format!("mesh.patch_{axis}_max"),
                        hi,
                        format!("must exceed mesh.patch_{axis}_min = {} (units of a) when mesh.patch_size > 0", fmt_num(lo)),
                    ));
                }
            }
            if (m.patch_r_min > 0.0 || m.patch_r_max > 0.0) && m.patch_r_max <= m.patch_r_min {
                return Err(not_allowed(
                    "mesh.patch_r_max",
                    m.patch_r_max,
                    format!("must exceed mesh.patch_r_min = {} (units of a) when the patch has radial limits", fmt_num(m.patch_r_min)),
                ));
            }
        }

        let e = &self.effects;
        if let Some(l) = &self.lubricant {
            if l.roelands_exponent.is_some() && e.viscosity != ViscosityModel::Roelands {
                return Err(SceneErrorKind::Conflict(format!(
                    "lubricant.roelands_exponent is given but effects.viscosity = \"{}\": the Roelands index z_R is only used by the Roelands law (remove lubricant.roelands_exponent or set effects.viscosity = \"roelands\")",
                    e.viscosity
                ))
                .into());
            }
            let needs_alpha = match e.viscosity {
                ViscosityModel::Barus => true,
                ViscosityModel::Roelands => l.roelands_exponent.is_none(),
                ViscosityModel::Constant => false,
            };
            if needs_alpha && l.pressure_viscosity.is_none() {
                return Err(missing("lubricant.pressure_viscosity"));
            }
            if e.viscosity == ViscosityModel::Roelands {
                if let Err(msg) = self.viscosity_law_unchecked(l) {
                    return Err(not_allowed(
                        "lubricant.viscosity",
                        l.viscosity,
                        format!("with effects.viscosity = \"roelands\" it must exceed 6.31e-5 Pa.s ({msg})"),
                    ));
                }
            }
        }
        if e.lubrication == LubricationModel::Reynolds {
            if self.lubricant.is_none() {
                return Err(missing("lubricant"));
            }
            if self.operating.entrainment_speed.is_none() {
                return Err(missing("operating.entrainment_speed"));
            }
        }
        if self.accuracy.target > 0.0 {
            let why = if e.lubrication != LubricationModel::Reynolds {
                Some("a dry scene has no film to refine for")
            } else if e.elasticity != ElasticityModel::Elastic {
                Some("adaptive refinement needs the elastic solid (effects.elasticity = \"elastic\")")
            } else {
                None
            };
            if let Some(why) = why {
                return Err(SceneErrorKind::Conflict(format!(
                    "accuracy.target = {} is not supported here: {why} (remove accuracy.target or set it to 0)",
                    self.accuracy.target
                ))
                .into());
            }
        }
        if let Some(sw) = &self.sweep {
            if e.lubrication != LubricationModel::Reynolds {
                return Err(SceneErrorKind::Conflict(
                    "[sweep] is given but effects.lubrication = \"none\": a sweep varies the lubricated operating point (remove [sweep] or set effects.lubrication = \"reynolds\")".into(),
                )
                .into());
            }
            if sw.tilt_angle.is_some() && e.kinematics == KinematicsModel::Uniform {
                return Err(SceneErrorKind::Conflict(
                    "sweep.tilt_angle is given but effects.kinematics = \"uniform\" ignores the tilt angle (remove sweep.tilt_angle or set effects.kinematics = \"spin\")".into(),
                )
                .into());
            }
        }
        if self.output.speed_exponents
            && (e.lubrication != LubricationModel::Reynolds || e.elasticity == ElasticityModel::Rigid || self.sweep.is_some())
        {
            return Err(SceneErrorKind::Conflict(
                "output.speed_exponents = true needs a lubricated elastic single-point scene (effects.lubrication = \"reynolds\", effects.elasticity = \"elastic\", no [sweep]); set output.speed_exponents = false".into(),
            )
            .into());
        }
        if self.output.subsurface && e.elasticity == ElasticityModel::Rigid {
            return Err(SceneErrorKind::Conflict(
                "output.subsurface = true needs the elastic solid, but effects.elasticity = \"rigid\" has no 3D mesh (set effects.elasticity = \"elastic\" or output.subsurface = false)".into(),
            )
            .into());
        }
        if e.surface_traction == SurfaceTraction::Friction {
            if e.lubrication == LubricationModel::Reynolds && e.friction == FrictionModel::Off {
                return Err(SceneErrorKind::Conflict(
                    "effects.surface_traction = \"friction\" applies the shear stresses of the friction pass, but effects.friction = \"none\" (set effects.friction or effects.surface_traction = \"none\")".into(),
                )
                .into());
            }
            if e.lubrication == LubricationModel::Dry && self.operating.friction_coefficient == 0.0 {
                return Err(SceneErrorKind::Conflict(
                    "effects.surface_traction = \"friction\" in a dry scene applies q = mu p with mu = operating.friction_coefficient, which is 0 (give operating.friction_coefficient > 0 or set effects.surface_traction = \"none\")".into(),
                )
                .into());
            }
        }
        // Each list value once and the lists' corners, never every combination (a sweep
        // of three 1000-value lists has 10^9 of them).
        for point in self.check_points() {
            point.validate_kinematics()?;
        }
        Ok(())
    }

    /// The operating points of the scene: the scene itself, or one scene per combination
    /// of the `[sweep]` lists (entrainment speed outermost, slide-to-roll innermost), each
    /// without `[sweep]` and with the `[operating]` values replaced.
    pub fn points(&self) -> Vec<Scene> {
        let Some(sw) = &self.sweep else {
            return vec![self.clone()];
        };
        let op = &self.operating;
        let ues: Vec<Option<f64>> = match &sw.entrainment_speed {
            Some(v) => v.iter().map(|&u| Some(u)).collect(),
            None => vec![op.entrainment_speed],
        };
        let lambdas = sw.tilt_angle.clone().unwrap_or_else(|| vec![op.tilt_angle]);
        let srrs = sw.slide_to_roll.clone().unwrap_or_else(|| vec![op.slide_to_roll]);
        let mut out = Vec::new();
        for &ue in &ues {
            for &lambda in &lambdas {
                for &srr in &srrs {
                    let mut s = self.clone();
                    s.sweep = None;
                    s.operating.entrainment_speed = ue;
                    s.operating.tilt_angle = lambda;
                    s.operating.slide_to_roll = srr;
                    out.push(s);
                }
            }
        }
        out
    }

    /// Contradictions that do not stop the run but that the user should know about (each
    /// names the fields). Printed at the start of a run.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        let e = &self.effects;
        if self.mesh.core_depth > 0.0 && self.mesh.core_size == 0.0 {
            w.push("mesh.core_depth is given but mesh.core_size = 0: there is no core to deepen".into());
        }
        if e.surface_traction == SurfaceTraction::Friction && !self.output.subsurface {
            w.push("effects.surface_traction = \"friction\" only loads the subsurface stress field, which output.subsurface = false does not compute".into());
        }
        if self.operating.friction_coefficient > 0.0
            && (e.lubrication == LubricationModel::Reynolds || e.surface_traction == SurfaceTraction::Off)
        {
            w.push("operating.friction_coefficient is only used by a dry scene with effects.surface_traction = \"friction\" (a lubricated scene takes its traction from the friction pass)".into());
        }
        if e.lubrication == LubricationModel::Dry {
            if e.friction != FrictionModel::Off {
                w.push(format!(
                    "effects.friction = \"{}\" has no effect with effects.lubrication = \"none\" (no film, no shear pass)",
                    e.friction
                ));
            }
            return w;
        }
        let srr_swept = self.sweep.as_ref().is_some_and(|s| s.slide_to_roll.is_some());
        if e.friction != FrictionModel::Off && e.kinematics == KinematicsModel::Uniform && self.operating.slide_to_roll == 0.0 && !srr_swept
        {
            w.push(format!(
                "effects.friction = \"{}\" with effects.kinematics = \"uniform\" and operating.slide_to_roll = 0: there is no sliding, the shear pass only sees the pressure-gradient (Poiseuille) stresses",
                e.friction
            ));
        }
        if let Some(l) = &self.lubricant {
            if e.viscosity == ViscosityModel::Constant && l.pressure_viscosity.is_some() {
                w.push("lubricant.pressure_viscosity is given but effects.viscosity = \"constant\" does not use it (only the Hamrock-Dowson reference film does)".into());
            }
        }
        if e.kinematics == KinematicsModel::Uniform && self.operating.tilt_angle != 90.0 {
            w.push(format!(
                "operating.tilt_angle = {} deg is ignored by effects.kinematics = \"uniform\" (no spin)",
                fmt_num(self.operating.tilt_angle)
            ));
        }
        w
    }

    /// Whether the scene's kinematics and geometry are symmetric about the plane z = 0, so
    /// that half the domain (z <= 0) can be solved: uniform entrainment without spin
    /// (W_B = W_D = 0, U_B and U_D constant). Spin kinematics are not symmetric even at
    /// lambda = 90 deg: the disc spins (U_D = omega_D (R_D + z)).
    pub fn is_symmetric_z(&self) -> bool {
        self.effects.kinematics == KinematicsModel::Uniform || self.effects.lubrication == LubricationModel::Dry
    }

    /// Whether the solver uses the half domain z <= 0: `effects.symmetry = "auto"` and a
    /// symmetric scene.
    pub fn uses_half_domain(&self) -> bool {
        self.effects.symmetry == SymmetryMode::Auto && self.is_symmetric_z()
    }

    /// Whether the scene sweeps its operating point (`[sweep]` given).
    pub fn is_sweep(&self) -> bool {
        self.sweep.is_some()
    }

    fn validate_kinematics(&self) -> Result<(), SceneError> {
        if let Some(ue) = self.operating.entrainment_speed {
            // Kinematics must be constructible (guards against programmatic scenes).
            Kinematics::new(
                ue,
                self.operating.slide_to_roll,
                self.tilt_angle_rad(),
                self.geometry.ball_radius,
                self.geometry.disc_track_radius,
            )
            .map_err(|err| not_allowed("operating.tilt_angle", self.operating.tilt_angle, err.to_string()))?;
        }
        Ok(())
    }

    /// Re-checks single-field ranges (already done while parsing a file) so that scenes
    /// built in code get the same guarantees.
    fn validate_fields_finite(&self) -> Result<(), SceneError> {
        let value =
            toml::Value::try_from(self).map_err(|e| SceneErrorKind::Conflict(format!("scene cannot be represented as TOML: {e}")))?;
        match value {
            toml::Value::Table(t) => spec::check_table(SCENE_FIELDS, &t, SCENE_FIELDS, "").map_err(Into::into),
            _ => unreachable!("a struct serialises to a table"),
        }
    }

    /// Tilt angle lambda in radians.
    pub fn tilt_angle_rad(&self) -> f64 {
        self.operating.tilt_angle.to_radians()
    }

    /// Material of the ball B.
    pub fn ball_material(&self) -> Material {
        let m = self.materials.ball;
        Material::new(m.young_modulus, m.poisson_ratio)
    }

    /// Material of the disc D.
    pub fn disc_material(&self) -> Material {
        let m = self.materials.disc;
        Material::new(m.young_modulus, m.poisson_ratio)
    }

    /// Dry Hertz solution (a, p_H, E') for the scene's load, ball radius and materials.
    pub fn hertz(&self) -> Hertz {
        Hertz::new(self.operating.load, self.geometry.ball_radius, self.ball_material(), self.disc_material())
    }

    /// Material of the equivalent elastic solid (docs/model.md section 6).
    pub fn equivalent_solid(&self) -> Material {
        equivalent_solid(self.ball_material(), self.disc_material())
    }

    /// Hertzian scales (a, p_H, R, E') of the dimensionless solver.
    pub fn scales(&self) -> Scales {
        Scales::from_hertz(&self.hertz())
    }

    fn viscosity_law_unchecked(&self, l: &Lubricant) -> Result<ViscosityLaw, Error> {
        let alpha = l.pressure_viscosity.unwrap_or(0.0);
        Ok(match self.effects.viscosity {
            ViscosityModel::Constant => ViscosityLaw::Constant { eta_r: l.viscosity },
            ViscosityModel::Barus => ViscosityLaw::Barus { eta_r: l.viscosity, alpha },
            ViscosityModel::Roelands => ViscosityLaw::roelands(l.viscosity, alpha, l.roelands_reference_pressure, l.roelands_exponent)?,
        })
    }

    /// The viscosity law selected by `effects.viscosity`, or None without a lubricant.
    pub fn viscosity_law(&self) -> Option<ViscosityLaw> {
        let l = self.lubricant.as_ref()?;
        Some(self.viscosity_law_unchecked(l).expect("validated scene"))
    }

    /// The viscosity's rise over the contact, ln(eta(p_H)/eta_R), or None without a
    /// lubricant.
    pub fn viscosity_rise(&self) -> Option<f64> {
        Some(self.viscosity_law()?.log_ratio_and_derivative(self.hertz().ph).0)
    }

    /// The density law selected by `effects.density`, or None without a lubricant.
    pub fn density_law(&self) -> Option<DensityLaw> {
        let rho_r = self.lubricant.as_ref()?.density;
        Some(match self.effects.density {
            DensityModel::DowsonHigginson => DensityLaw::DowsonHigginson { rho_r },
            DensityModel::Incompressible => DensityLaw::Incompressible { rho_r },
        })
    }

    /// z of the spin pole (where the mean surface velocity vanishes) in units of the Hertz
    /// radius a; None without spin kinematics or an entrainment speed.
    pub fn spin_pole_over_a(&self) -> Option<f64> {
        Some(self.kinematics()?.spin_centre()? / self.hertz().a)
    }

    /// Surface kinematics selected by `effects.kinematics`, or None without an entrainment
    /// speed (dry scenes).
    pub fn kinematics(&self) -> Option<Kinematics> {
        let ue = self.operating.entrainment_speed?;
        let (srr, rb, rd) = (self.operating.slide_to_roll, self.geometry.ball_radius, self.geometry.disc_track_radius);
        Some(
            match self.effects.kinematics {
                KinematicsModel::Spin => Kinematics::new(ue, srr, self.tilt_angle_rad(), rb, rd),
                KinematicsModel::Uniform => Kinematics::uniform(ue, srr, rb, rd),
            }
            .expect("validated scene"),
        )
    }

    /// Pressure-viscosity coefficient used by the film references: `pressure_viscosity`
    /// if given, else d ln eta/dp at p = 0 of the viscosity law.
    pub fn effective_alpha(&self) -> Option<f64> {
        let l = self.lubricant.as_ref()?;
        l.pressure_viscosity.or_else(|| self.viscosity_law().map(|v| v.pressure_viscosity_at_ambient()))
    }

    /// Moes / Hamrock-Dowson dimensionless groups, when lubricated.
    pub fn moes(&self) -> Option<MoesParameters> {
        let l = self.lubricant.as_ref()?;
        let ue = self.operating.entrainment_speed?;
        let h = self.hertz();
        Some(MoesParameters::new(h.load, ue, l.viscosity, self.effective_alpha()?, h.e_prime, h.radius))
    }

    /// The central film of Nijenbanning, Venner and Moes (1994) for this operating point
    /// (m), when the scene is in the setting of its fit (Barus viscosity, incompressible
    /// lubricant, elastic solids): a curve fit, good to a few per cent
    /// ([`nijenbanning_central`]). With Roelands' law at the same ambient alpha the films are
    /// thinner (table2-ue2 lies 15 % below it), so it is not given there.
    pub fn nijenbanning_hc(&self) -> Option<f64> {
        if self.effects.viscosity != ViscosityModel::Barus || self.effects.density != DensityModel::Incompressible {
            return None;
        }
        let p = self.moes()?;
        Some(nijenbanning_central(p.m, p.l) * self.hertz().radius * (2.0 * p.u).sqrt()).filter(|h| h.is_finite() && *h > 0.0)
    }

    /// The central film (m) of the same contact with an isoviscous lubricant: the
    /// Nijenbanning-Venner-Moes fit at the scene's M and L = 0, for elastic solids. A rise
    /// of viscosity with pressure only thickens the film, so this is about its lower bound;
    /// where the lubricant's own pressure-viscosity barely acts (soft solids, light loads)
    /// it is the film itself, and Hamrock-Dowson's piezoviscous fit, which vanishes with
    /// alpha, is far below it.
    pub fn isoviscous_hc(&self) -> Option<f64> {
        if self.effects.elasticity != ElasticityModel::Elastic {
            return None;
        }
        let l = self.lubricant.as_ref()?;
        let ue = self.operating.entrainment_speed?;
        let h = self.hertz();
        let p = MoesParameters::new(h.load, ue, l.viscosity, 0.0, h.e_prime, h.radius);
        Some(nijenbanning_central(p.m, 0.0) * h.radius * (2.0 * p.u).sqrt()).filter(|h| h.is_finite() && *h > 0.0)
    }

    /// The central film (m) expected before solving: Hamrock-Dowson's piezoviscous fit, or
    /// the isoviscous film ([`Scene::isoviscous_hc`]) where that is thicker. The first is
    /// the film of a piezoviscous contact and vanishes with alpha E'; the second takes over
    /// where the viscosity barely rises in the contact (elastic solids only). None without a
    /// lubricant and speed.
    pub fn film_estimate(&self) -> Option<f64> {
        let hd = self.hamrock_dowson().map(|h| h.central_film_thickness()).filter(|h| h.is_finite() && *h > 0.0);
        match (hd, self.isoviscous_hc()) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        }
    }

    /// Hamrock-Dowson reference films for this operating point (k = 1), when lubricated.
    pub fn hamrock_dowson(&self) -> Option<HamrockDowson> {
        let l = self.lubricant.as_ref()?;
        let ue = self.operating.entrainment_speed?;
        let h = self.hertz();
        Some(HamrockDowson::circular(h.load, ue, l.viscosity, self.effective_alpha()?, h.e_prime, h.radius))
    }
}

#[cfg(test)]
mod tests;
