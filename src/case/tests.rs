//! Tests of the scene file: valid scenes, round trips, and one test per class of bad input.
use super::spec::{Field, Kind};
use super::*;

/// Example 1: a paper case with every key written out (Table 1, Ue = 3 m/s, SRR = 5 %,
/// lambda = 2 deg).
const PAPER_SPIN: &str = r#"
name = "paper-spin-2deg"

[geometry]
ball_radius = 0.08
disc_track_radius = 0.04

[materials.ball]
young_modulus = 210e9
poisson_ratio = 0.3

[materials.disc]
young_modulus = 210e9
poisson_ratio = 0.3

[lubricant]
viscosity = 0.012
pressure_viscosity = 23e-9
roelands_reference_pressure = 1.96e8
roelands_exponent = 0.8591
density = 870.0
ree_eyring_stress = 6.2e6

[operating]
load = 1500.0
entrainment_speed = 3.0
slide_to_roll = 0.05
tilt_angle = 2.0

[effects]
lubrication = "reynolds"
elasticity = "elastic"
viscosity = "roelands"
density = "dowson-higginson"
kinematics = "spin"
friction = "ree-eyring"
cavitation = "penalty"
symmetry = "auto"

[reynolds]
x_min = -3.0
x_max = 3.0
z_min = -3.0
z_max = 3.0
penalty = 1e4
stabilisation = "supg"

[mesh]
cube_size = 60.0
contact_size = 0.25
growth = 0.5

[output]
dir = "out/paper-spin-2deg"
shear_profile_z = -0.12e-3
vtu = true
png = false

[sweep]
entrainment_speed = [2.0, 3.0]
tilt_angle = [90, 7, 2]
slide_to_roll = [0.0, 0.05]
"#;

/// Example 2: dry Hertz contact, minimal (no lubricant, no name, defaults elsewhere).
const DRY_HERTZ: &str = r#"
[geometry]
ball_radius = 0.08

[materials.ball]
young_modulus = 210e9
poisson_ratio = 0.3

[materials.disc]
young_modulus = 210e9
poisson_ratio = 0.3

[operating]
load = 1500

[effects]
lubrication = "none"
"#;

fn err(text: &str) -> String {
    match parse_scene(text, "t") {
        Ok(s) => panic!("expected an error, got {s:?}"),
        Err(e) => e.to_string(),
    }
}

/// PAPER_SPIN with `old` replaced by `new` (which must occur exactly once).
fn paper_with(old: &str, new: &str) -> String {
    assert_eq!(PAPER_SPIN.matches(old).count(), 1, "'{old}' must occur once");
    PAPER_SPIN.replace(old, new)
}

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

#[test]
fn full_scene_parses() {
    let s = parse_scene(PAPER_SPIN, "ignored").unwrap();
    assert_eq!(s.name, "paper-spin-2deg");
    assert_eq!(s.geometry.ball_radius, 0.08);
    assert_eq!(s.materials.disc.poisson_ratio, 0.3);
    let l = s.lubricant.as_ref().unwrap();
    assert_eq!(l.roelands_exponent, Some(0.8591));
    assert_eq!(s.operating.entrainment_speed, Some(3.0));
    assert_eq!(s.operating.tilt_angle, 2.0);
    assert_eq!(s.effects, Effects::default());
    assert_eq!(s.reynolds, ReynoldsDomain::default());
    assert_eq!(s.mesh, MeshSettings::default());
    assert!(s.output.vtu && !s.output.png);
}

#[test]
fn full_scene_round_trips_through_toml_and_json() {
    let s = parse_scene(PAPER_SPIN, "x").unwrap();
    let text = toml::to_string(&s).unwrap();
    let back = parse_scene(&text, "other").unwrap();
    assert_eq!(s, back, "round trip through:\n{text}");
    let json = serde_json::to_value(&s).unwrap();
    assert_eq!(json["effects"]["density"], "dowson-higginson");
    assert_eq!(json["operating"]["tilt_angle"], 2.0);
    let from_json: Scene = serde_json::from_value(json).unwrap();
    assert_eq!(from_json, s);
}

#[test]
fn minimal_dry_scene_gets_defaults() {
    let s = parse_scene(DRY_HERTZ, "dry-hertz").unwrap();
    assert_eq!(s.name, "dry-hertz");
    assert_eq!(s.output.dir, "out/dry-hertz");
    assert!(s.output.vtu && s.output.png);
    assert_eq!(s.geometry.disc_track_radius, 0.04);
    assert_eq!(s.operating.load, 1500.0);
    assert_eq!(s.operating.tilt_angle, 90.0);
    assert_eq!(s.operating.slide_to_roll, 0.0);
    assert_eq!(s.operating.entrainment_speed, None);
    assert_eq!(s.effects.lubrication, LubricationModel::Dry);
    assert!(s.lubricant.is_none() && s.viscosity_law().is_none() && s.kinematics().is_none());
    assert!(s.moes().is_none() && s.hamrock_dowson().is_none());
    // Round trip of a scene with absent optional parts.
    assert_eq!(parse_scene(&toml::to_string(&s).unwrap(), "zz").unwrap(), s);
}

/// Every key of the schema lists appears in a serialised full scene, and the serialised
/// scene passes the key walk: the lists match the structs.
#[test]
fn known_keys_match_structs() {
    fn all_present(fields: &'static [Field], t: &toml::Table, prefix: &str) {
        for f in fields {
            let path = format!("{prefix}{}", f.key);
            let v = t.get(f.key).unwrap_or_else(|| panic!("schema key '{path}' missing from the serialised scene"));
            if let Kind::Table(sub) = f.kind {
                all_present(sub, v.as_table().expect("table"), &format!("{path}."));
            }
        }
    }
    let s = parse_scene(PAPER_SPIN, "x").unwrap();
    let toml::Value::Table(t) = toml::Value::try_from(&s).unwrap() else { panic!() };
    all_present(SCENE_FIELDS, &t, "");
    spec::check_table(SCENE_FIELDS, &t, SCENE_FIELDS, "").unwrap();
    // And the count of serialised keys equals the count of schema keys at every level.
    fn count_fields(fields: &'static [Field]) -> usize {
        fields.iter().map(|f| 1 + if let Kind::Table(s) = f.kind { count_fields(s) } else { 0 }).sum()
    }
    fn count_value(t: &toml::Table) -> usize {
        t.values().map(|v| 1 + v.as_table().map_or(0, count_value)).sum()
    }
    assert_eq!(count_fields(SCENE_FIELDS), count_value(&t));
}

#[test]
fn choice_names_match_serde() {
    fn check<T: serde::Serialize + serde::de::DeserializeOwned + PartialEq + std::fmt::Debug + Copy>(all: &[T], names: &[&str]) {
        assert_eq!(all.len(), names.len());
        for (v, n) in all.iter().zip(names) {
            assert_eq!(serde_json::to_value(v).unwrap(), serde_json::Value::String(n.to_string()));
            assert_eq!(serde_json::from_value::<T>(serde_json::Value::String(n.to_string())).unwrap(), *v);
        }
    }
    check(LubricationModel::ALL, LubricationModel::NAMES);
    check(ElasticityModel::ALL, ElasticityModel::NAMES);
    check(ViscosityModel::ALL, ViscosityModel::NAMES);
    check(DensityModel::ALL, DensityModel::NAMES);
    check(KinematicsModel::ALL, KinematicsModel::NAMES);
    check(FrictionModel::ALL, FrictionModel::NAMES);
    check(CavitationModel::ALL, CavitationModel::NAMES);
    check(SymmetryMode::ALL, SymmetryMode::NAMES);
    check(Stabilisation::ALL, Stabilisation::NAMES);
    check(Coupling::ALL, Coupling::NAMES);
    assert_eq!(LubricationModel::Dry.to_string(), "none");
}

#[test]
fn physics_helpers() {
    let s = parse_scene(PAPER_SPIN, "x").unwrap();
    let h = s.hertz();
    assert!(rel(h.a, 0.92052e-3) < 1e-4 && rel(h.ph, 0.84522e9) < 1e-4 && rel(h.e_prime, 230.77e9) < 1e-4);
    let eq = s.equivalent_solid();
    assert!(rel(eq.e, 105e9) < 1e-12 && rel(eq.nu, 0.3) < 1e-12);
    let k = s.kinematics().unwrap();
    assert!(rel(k.u_bo, 3.075) < 1e-12 && rel(k.u_do, 2.925) < 1e-12 && k.spin);
    assert!(rel(k.lambda, 2f64.to_radians()) < 1e-15);
    match s.viscosity_law().unwrap() {
        crate::physics::ViscosityLaw::Roelands { z_r, p_r, .. } => {
            assert!(z_r == 0.8591 && p_r == 1.96e8)
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(s.density_law().unwrap().density(0.0), 870.0);
    let hd = s.hamrock_dowson().unwrap().central_film_thickness();
    assert!((hd * 1e6 - 0.52).abs() < 0.01);
    assert!(rel(s.moes().unwrap().w, 1.015625e-6) < 1e-6);
    // NVM is a fit for Barus, incompressible lubricants only; here (M, L) = (366.0, 7.459)
    // and its H = 3.5881, so hc = H R sqrt(2U) = 0.56687 um (computed apart from this code,
    // from the scene's data and the published formula).
    assert!(s.nijenbanning_hc().is_none());
    let b = parse_scene(
        &paper_with("viscosity = \"roelands\"", "viscosity = \"barus\"")
            .replace("\"dowson-higginson\"", "\"incompressible\"")
            .replace("roelands_reference_pressure = 1.96e8\n", "")
            .replace("roelands_exponent = 0.8591\n", ""),
        "x",
    )
    .unwrap();
    assert!(rel(b.nijenbanning_hc().unwrap(), 0.566873e-6) < 1e-5, "{:?}", b.nijenbanning_hc());
    // Uniform kinematics and derived z_R.
    let u = parse_scene(
        &paper_with("kinematics = \"spin\"", "kinematics = \"uniform\"")
            .replace("roelands_exponent = 0.8591\n", "")
            .replace("tilt_angle = [90, 7, 2]\n", ""),
        "x",
    )
    .unwrap();
    assert!(!u.kinematics().unwrap().spin);
    match u.viscosity_law().unwrap() {
        crate::physics::ViscosityLaw::Roelands { z_r, .. } => assert!((z_r - 0.8591).abs() < 5e-5),
        other => panic!("{other:?}"),
    }
    // Without alpha the references use the law's ambient slope.
    let c = parse_scene(&PAPER_SPIN.replace("pressure_viscosity = 23e-9\n", ""), "x").unwrap();
    assert!(rel(c.effective_alpha().unwrap(), 23e-9) < 1e-3);
}

#[test]
fn contact_size_rounding() {
    let m = |c| MeshSettings { contact_size: c, ..MeshSettings::default() }.contact_size_rounded();
    assert_eq!(m(0.25), 0.25);
    assert_eq!(m(0.3), 0.25);
    assert_eq!(m(0.2), 0.125);
    assert_eq!(m(16.0), 16.0);
    assert_eq!(m(MIN_CONTACT_SIZE), MIN_CONTACT_SIZE);
}

#[test]
fn reference_lists_every_key() {
    let md = reference_markdown();
    for key in ["ball_radius", "poisson_ratio", "roelands_exponent", "tilt_angle", "stabilisation", "growth", "png"] {
        assert!(md.contains(&format!("`{key}`")), "{key} missing from\n{md}");
    }
    assert!(md.contains("## [materials.ball]") && md.contains("## [effects]"));
    // Every table row has its five cells: a `|` inside a cell (|X| <= w) is escaped.
    for row in md.lines().filter(|l| l.starts_with('|')) {
        let bars = row.matches('|').count() - row.matches("\\|").count();
        assert_eq!(bars, 6, "a table row without exactly five cells: {row}");
    }
}

// ---- bad input, one class per test ----------------------------------------------------

#[test]
fn missing_field() {
    let e = err(&paper_with("ball_radius = 0.08\n", ""));
    assert_eq!(e, "missing field 'geometry.ball_radius' (ball radius R_B in m, > 0)");
    let e = err(&paper_with("[operating]\nload = 1500.0\n", "[operating]\n"));
    assert_eq!(e, "missing field 'operating.load' (normal load L in N, > 0)");
}

#[test]
fn missing_section() {
    let text = PAPER_SPIN.replace("[materials.disc]\nyoung_modulus = 210e9\npoisson_ratio = 0.3\n", "");
    assert_eq!(err(&text), "missing section '[materials.disc]' (elastic material of the disc D)");
}

#[test]
fn negative_radius() {
    let e = err(&paper_with("ball_radius = 0.08", "ball_radius = -0.08"));
    assert_eq!(e, "geometry.ball_radius = -0.08 is not allowed: must be > 0 (m)");
}

#[test]
fn poisson_ratio_half() {
    let e = err(&paper_with(
        "[materials.ball]\nyoung_modulus = 210e9\npoisson_ratio = 0.3",
        "[materials.ball]\nyoung_modulus = 210e9\npoisson_ratio = 0.5",
    ));
    assert_eq!(e, "materials.ball.poisson_ratio = 0.5 is not allowed: must be in (-1, 0.5)");
}

#[test]
fn unknown_key_with_suggestion() {
    let e = err(&paper_with("load = 1500.0", "lod = 1500.0"));
    assert_eq!(e, "unknown key 'operating.lod' (did you mean 'load'?)");
    let e = err(&paper_with("[geometry]", "[geometri]"));
    assert_eq!(e, "unknown key 'geometri' (did you mean 'geometry'?)");
    // A key written in the wrong section points to where it belongs.
    let e = err(&paper_with("disc_track_radius = 0.04\n", "disc_track_radius = 0.04\nload = 3.0\n"));
    assert_eq!(e, "unknown key 'geometry.load' (did you mean 'operating.load'?)");
    // Nothing close: list the known keys.
    let e = err(&paper_with("png = false", "png = false\ncolour = true"));
    assert_eq!(
        e,
        "unknown key 'output.colour' (known keys here: dir, vtu, png, shear_profile_z, subsurface, subsurface_recovery, speed_exponents)"
    );
}

#[test]
fn wrong_type() {
    let e = err(&paper_with("load = 1500.0", "load = \"1500\""));
    assert_eq!(e, "operating.load has the wrong type: expected a number (normal load L in N, > 0), found the string \"1500\"");
    let e = err(&paper_with("vtu = true", "vtu = 1"));
    assert!(e.starts_with("output.vtu has the wrong type: expected a boolean"), "{e}");
    let e = err(&paper_with("stabilisation = \"supg\"", "stabilisation = 1"));
    assert!(e.starts_with("reynolds.stabilisation has the wrong type: expected a string"), "{e}");
    let e = err(&format!("geometry = 1\n{}", DRY_HERTZ.replace("[geometry]\nball_radius = 0.08\n", "")));
    assert!(e.starts_with("geometry has the wrong type: expected a table"), "{e}");
}

#[test]
fn non_finite() {
    let e = err(&paper_with("load = 1500.0", "load = inf"));
    assert_eq!(e, "operating.load = inf is not allowed: must be a finite number");
    let e = err(&paper_with("viscosity = 0.012", "viscosity = nan"));
    assert_eq!(e, "lubricant.viscosity = NaN is not allowed: must be a finite number");
}

#[test]
fn zero_tilt_angle() {
    let e = err(&paper_with("tilt_angle = 2.0", "tilt_angle = 0"));
    assert!(e.starts_with("operating.tilt_angle = 0 is not allowed: must be in (0, 90] (degrees); lambda = 0 is singular"), "{e}");
    let e = err(&paper_with("tilt_angle = 2.0", "tilt_angle = 91"));
    assert!(e.starts_with("operating.tilt_angle = 91 is not allowed: must be in (0, 90]"), "{e}");
}

#[test]
fn bad_choice() {
    let e = err(&paper_with("viscosity = \"roelands\"", "viscosity = \"roeland\""));
    assert_eq!(
        e,
        "effects.viscosity = \"roeland\" is not allowed: must be one of \"roelands\", \"barus\", \"constant\" (did you mean \"roelands\"?)"
    );
}

#[test]
fn other_ranges() {
    assert!(err(&paper_with("slide_to_roll = 0.05", "slide_to_roll = -2.5")).starts_with("operating.slide_to_roll = -2.5 is not allowed"));
    assert!(err(&paper_with("cube_size = 60.0", "cube_size = 10")).starts_with("mesh.cube_size = 10 is not allowed: must be in [20, 200]"));
    assert!(err(&paper_with("growth = 0.5", "growth = 0")).starts_with("mesh.growth = 0 is not allowed: must be in (0, 2]"));
    assert!(err(&paper_with(
        "young_modulus = 210e9\npoisson_ratio = 0.3\n\n[lubricant]",
        "young_modulus = 0\npoisson_ratio = 0.3\n\n[lubricant]"
    ))
    .starts_with("materials.disc.young_modulus = 0 is not allowed: must be > 0 (Pa)"));
    assert!(err(&paper_with("dir = \"out/paper-spin-2deg\"", "dir = \"\""))
        .starts_with("output.dir = \"\" is not allowed: must be a non-empty string"));
    assert!(err(&paper_with("pressure_viscosity = 23e-9", "pressure_viscosity = -1e-9"))
        .starts_with("lubricant.pressure_viscosity = -1e-9 is not allowed: must be >= 0"));
}

#[test]
fn reynolds_box_must_contain_hertz_circle() {
    let e = err(&paper_with("x_min = -3.0", "x_min = -0.5"));
    assert_eq!(e, "reynolds.x_min = -0.5 is not allowed: must be <= -1 (a); the rectangle must contain the Hertz circle and lie inside the top face: |x_min| < mesh.cube_size/2");
    let e = err(&paper_with("z_max = 3.0", "z_max = 0.9"));
    assert!(e.starts_with("reynolds.z_max = 0.9 is not allowed: must be >= 1"), "{e}");
    let e = err(&paper_with("x_min = -3.0", "x_min = 4.0"));
    assert!(e.starts_with("reynolds.x_min = 4 is not allowed: must be <= -1 (a)"), "{e}");
    // The cross-field pass gives the same message for scenes built in code.
    let mut s = parse_scene(PAPER_SPIN, "x").unwrap();
    s.reynolds.z_min = -0.25;
    assert_eq!(
        s.validate().unwrap_err().to_string(),
        "reynolds.z_min = -0.25 is not allowed: must be <= -1 (a); the rectangle must contain the Hertz circle and lie inside the top face: |z_min| < mesh.cube_size/2"
    );
}

#[test]
fn reynolds_box_must_fit_the_cube() {
    let e = err(&paper_with("x_max = 3.0", "x_max = 30.0"));
    assert!(e.starts_with("reynolds.x_max = 30 is not allowed: |x_max| must be < mesh.cube_size/2 = 30"), "{e}");
}

#[test]
fn roelands_exponent_needs_roelands() {
    let e = err(&paper_with("viscosity = \"roelands\"", "viscosity = \"barus\""));
    assert!(e.starts_with("lubricant.roelands_exponent is given but effects.viscosity = \"barus\""), "{e}");
    // Without the exponent, Barus is fine.
    parse_scene(&paper_with("viscosity = \"roelands\"", "viscosity = \"barus\"").replace("roelands_exponent = 0.8591\n", ""), "x").unwrap();
}

#[test]
fn lubricated_scene_needs_lubricant_and_speed() {
    let no_lub = DRY_HERTZ.replace("lubrication = \"none\"", "lubrication = \"reynolds\"");
    assert_eq!(err(&no_lub), "missing section '[lubricant]' (lubricant properties; required when effects.lubrication = \"reynolds\")");
    let e = err(&paper_with("entrainment_speed = 3.0\n", ""));
    assert_eq!(
        e,
        "missing field 'operating.entrainment_speed' (entrainment speed Ue in m/s, > 0; required when effects.lubrication = \"reynolds\")"
    );
    let e = err(&PAPER_SPIN.replace("pressure_viscosity = 23e-9\n", "").replace("roelands_exponent = 0.8591\n", ""));
    assert!(
        e.starts_with("missing field 'lubricant.pressure_viscosity' (pressure-viscosity coefficient alpha in 1/Pa, >= 0; required unless"),
        "{e}"
    );
    // Roelands needs eta_R above exp(-9.67).
    let e = err(&paper_with("viscosity = 0.012", "viscosity = 1e-5"));
    assert!(e.starts_with("lubricant.viscosity = 1e-5 is not allowed: with effects.viscosity = \"roelands\""), "{e}");
}

#[test]
fn syntax_error() {
    let e = err("[geometry\nball_radius = 1");
    assert!(e.starts_with("invalid TOML: line 1, column 10: "), "{e}");
    assert!(!e.contains('\n'), "{e}");
    let e = err("[geometry]\nball_radius = 1\nball_radius = 2\n");
    assert!(e.starts_with("invalid TOML: line 3, column 1: "), "{e}");
}

#[test]
fn unreadable_file() {
    let p = std::path::Path::new("/nonexistent-dir-ehl/case.toml");
    let e = load_scene(p).unwrap_err();
    let msg = e.to_string();
    assert!(msg.starts_with("cannot read scene file '/nonexistent-dir-ehl/case.toml': "), "{msg}");
    assert!(msg.contains("No such file"), "{msg}");
    assert!(std::error::Error::source(&e).is_some());
}

#[test]
fn load_from_file_names_scene_and_errors() {
    let dir = std::env::temp_dir().join(format!("ehl-case-test-{}", std::process::id()));
    let sub = dir.join("dry-hertz");
    std::fs::create_dir_all(&sub).unwrap();
    let p = sub.join("case.toml");
    std::fs::write(&p, DRY_HERTZ).unwrap();
    assert_eq!(load_scene(&p).unwrap().name, "dry-hertz");
    let q = dir.join("my-scene.toml");
    std::fs::write(&q, DRY_HERTZ).unwrap();
    assert_eq!(load_scene(&q).unwrap().name, "my-scene");
    std::fs::write(&q, DRY_HERTZ.replace("load = 1500", "load = -1")).unwrap();
    let msg = load_scene(&q).unwrap_err().to_string();
    assert_eq!(msg, format!("{}: operating.load = -1 is not allowed: must be > 0 (N)", q.display()));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn programmatic_scene_is_validated() {
    let mut s = parse_scene(PAPER_SPIN, "x").unwrap();
    s.operating.tilt_angle = 0.0;
    assert!(s.validate().unwrap_err().to_string().starts_with("operating.tilt_angle = 0 is not allowed"));
    let mut s = parse_scene(PAPER_SPIN, "x").unwrap();
    s.geometry.ball_radius = f64::NAN;
    assert!(s.validate().unwrap_err().to_string().contains("must be a finite number"));
}

#[test]
fn sweep_points_are_the_product_in_order() {
    let s = parse_scene(PAPER_SPIN, "x").unwrap();
    let pts = s.points();
    assert_eq!(pts.len(), 2 * 3 * 2);
    // Slide-to-roll innermost, entrainment speed outermost.
    let key = |p: &Scene| (p.operating.entrainment_speed.unwrap(), p.operating.tilt_angle, p.operating.slide_to_roll);
    assert_eq!(key(&pts[0]), (2.0, 90.0, 0.0));
    assert_eq!(key(&pts[1]), (2.0, 90.0, 0.05));
    assert_eq!(key(&pts[2]), (2.0, 7.0, 0.0));
    assert_eq!(key(&pts[11]), (3.0, 2.0, 0.05));
    assert!(pts.iter().all(|p| p.sweep.is_none()));
    // Without [sweep]: the scene itself.
    let mut one = s.clone();
    one.sweep = None;
    assert_eq!(one.points(), vec![one.clone()]);
}

#[test]
fn bad_sweep_lists_name_the_element() {
    let bad = PAPER_SPIN.replace("tilt_angle = [90, 7, 2]", "tilt_angle = [90, 0, 2]");
    let e = parse_scene(&bad, "x").unwrap_err().to_string();
    assert!(e.contains("sweep.tilt_angle[1]") && e.contains("(0, 90]"), "{e}");
    let empty = PAPER_SPIN.replace("tilt_angle = [90, 7, 2]", "tilt_angle = []");
    let e = parse_scene(&empty, "x").unwrap_err().to_string();
    assert!(e.contains("sweep.tilt_angle") && e.contains("non-empty"), "{e}");
    let text = PAPER_SPIN.replace("tilt_angle = [90, 7, 2]", "tilt_angle = \"2\"");
    let e = parse_scene(&text, "x").unwrap_err().to_string();
    assert!(e.contains("sweep.tilt_angle") && e.contains("array"), "{e}");
    let uniform = PAPER_SPIN.replace("kinematics = \"spin\"", "kinematics = \"uniform\"");
    let e = parse_scene(&uniform, "x").unwrap_err().to_string();
    assert!(e.contains("sweep.tilt_angle") && e.contains("uniform"), "{e}");
}

#[test]
fn command_line_overrides_are_validated_like_the_file() {
    let set = |o: &[&str]| parse_scene_with(PAPER_SPIN, "x", &o.iter().map(|s| s.to_string()).collect::<Vec<_>>());
    // A number, a bare word (string), a new section key.
    let e = set(&["mesh.ring_inner=1.5", "mesh.ring_outer=1.0"]).unwrap_err().to_string();
    assert_eq!(e, "mesh.ring_outer = 1 is not allowed: must exceed mesh.ring_inner = 1.5 (units of a)");
    let e =
        set(&["mesh.patch_size=0.01", "mesh.patch_x_min=-0.4", "mesh.patch_x_max=0.4", "mesh.patch_z_min=-0.9", "mesh.patch_z_max=-1.0"])
            .unwrap_err()
            .to_string();
    assert_eq!(e, "mesh.patch_z_max = -1 is not allowed: must exceed mesh.patch_z_min = -0.9 (units of a) when mesh.patch_size > 0");
    // Without a patch size the rectangle is unused (its defaults are empty).
    assert!(set(&["mesh.patch_size=0"]).is_ok());
    let e = set(&[
        "mesh.patch_size=0.01",
        "mesh.patch_x_min=-0.4",
        "mesh.patch_x_max=0.4",
        "mesh.patch_z_min=-1.0",
        "mesh.patch_z_max=-0.9",
        "mesh.patch_r_min=0.97",
    ])
    .unwrap_err()
    .to_string();
    assert_eq!(e, "mesh.patch_r_max = 0 is not allowed: must exceed mesh.patch_r_min = 0.97 (units of a) when the patch has radial limits");
    let s = set(&["operating.load=2000", "effects.friction=none", "mesh.core_size=0.0625"]).unwrap();
    assert_eq!(s.operating.load, 2000.0);
    assert_eq!(s.effects.friction, FrictionModel::Off);
    assert_eq!(s.mesh.core_size, 0.0625);
    // Out of range, unknown key, not KEY=VALUE, a value where a section is.
    let e = set(&["operating.load=-1"]).unwrap_err().to_string();
    assert!(e.contains("operating.load") && e.contains("-1"), "{e}");
    let e = set(&["operating.lod=1"]).unwrap_err().to_string();
    assert!(e.contains("operating.lod") && e.contains("load"), "{e}");
    let e = set(&["operating.load"]).unwrap_err().to_string();
    assert!(e.contains("--set operating.load") && e.contains("KEY=VALUE"), "{e}");
    let e = set(&["name.x=1"]).unwrap_err().to_string();
    assert!(e.contains("'name' is not a section"), "{e}");
}

#[test]
fn subsurface_keys_are_checked_together() {
    // The friction traction needs the friction pass.
    let e = err(&paper_with("friction = \"ree-eyring\"", "friction = \"none\"\nsurface_traction = \"friction\""));
    assert!(e.contains("effects.surface_traction") && e.contains("effects.friction"), "{e}");
    // A dry scene's friction traction needs a coefficient.
    let dry = include_str!("../../cases/dry-hertz.toml");
    let e = err(&dry.replace("lubrication = \"none\"", "lubrication = \"none\"\nsurface_traction = \"friction\""));
    assert!(e.contains("operating.friction_coefficient"), "{e}");
    // Rigid solids have no 3D mesh.
    let e = err(&paper_with("[output]", "[output]\nsubsurface = true").replace("elasticity = \"elastic\"", "elasticity = \"rigid\""));
    assert!(e.contains("output.subsurface") && e.contains("rigid"), "{e}");
    // The speed exponents need the elastic film and one operating point.
    let e = err(&paper_with("[output]", "[output]\nspeed_exponents = true").replace("elasticity = \"elastic\"", "elasticity = \"rigid\""));
    assert!(e.contains("output.speed_exponents") && e.contains("single-point"), "{e}");
    let e = err(&dry.replace("[output]", "[output]\nspeed_exponents = true"));
    assert!(e.contains("output.speed_exponents"), "{e}");
    // The defaults: off, nothing asked.
    let s = parse_scene(PAPER_SPIN, "t").unwrap();
    assert!(!s.output.subsurface);
    assert_eq!(s.effects.surface_traction, SurfaceTraction::Off);
    assert_eq!(s.output.subsurface_recovery, StressRecovery::Spr);
    assert_eq!(s.mesh.core_depth, 0.0);
    // A friction traction that nothing computes is a warning.
    let s =
        parse_scene(&paper_with("friction = \"ree-eyring\"", "friction = \"ree-eyring\"\nsurface_traction = \"friction\""), "t").unwrap();
    assert!(s.warnings().iter().any(|w| w.contains("output.subsurface")), "{:?}", s.warnings());
    let s = parse_scene(&paper_with("[output]", "[output]\nsubsurface = true").replace("growth = ", "core_depth = 1.0\ngrowth = "), "t")
        .unwrap();
    assert!(s.warnings().iter().any(|w| w.contains("mesh.core_depth")), "{:?}", s.warnings());
}

#[test]
fn a_scene_without_mesh_keys_is_refined_with_the_adaptive_defaults() {
    let minimal = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/cases/examples/minimal.toml")).unwrap();
    // No [mesh], no target: the default target, growth 1.0, the inlet at X = -4.5.
    let s = parse_scene(&minimal, "m").unwrap();
    assert_eq!(s.accuracy.target, crate::case::schema::DEFAULT_ACCURACY_TARGET);
    assert_eq!((s.mesh.growth, s.reynolds.x_min), (1.0, -4.5));
    assert_eq!(s.reynolds.gradient_jump, crate::case::schema::ADAPTIVE_GRADIENT_JUMP);
    // Its own target: the same mesh defaults (a target given with --set behaves the same).
    let s = parse_scene_with(&minimal, "m", &["accuracy.target=0.005".into()]).unwrap();
    assert_eq!((s.accuracy.target, s.mesh.growth, s.reynolds.x_min), (0.005, 1.0, -4.5));
    // An inlet the scene gives is kept.
    let s = parse_scene_with(&minimal, "m", &["reynolds.x_min=-6".into()]).unwrap();
    assert_eq!((s.mesh.growth, s.reynolds.x_min), (1.0, -6.0));
    // A gradient-jump factor the scene gives is kept.
    let s = parse_scene_with(&minimal, "m", &["reynolds.gradient_jump=0".into()]).unwrap();
    assert_eq!(s.reynolds.gradient_jump, 0.0);
    // A [mesh] key: the hand-made mesh as given, no refinement, the plain defaults.
    let s = parse_scene_with(&minimal, "m", &["mesh.contact_size=0.25".into()]).unwrap();
    assert_eq!((s.accuracy.target, s.mesh.growth, s.reynolds.x_min), (0.0, 0.5, -3.0));
    assert_eq!(s.reynolds.gradient_jump, 0.0);
    // Target 0 on a scene without [mesh]: the plain defaults.
    let s = parse_scene_with(&minimal, "m", &["accuracy.target=0".into()]).unwrap();
    assert_eq!((s.mesh.growth, s.reynolds.x_min), (0.5, -3.0));
}

#[test]
fn a_scene_asking_for_subsurface_stresses_without_mesh_keys_gets_the_core_box() {
    use crate::case::schema::{SUBSURFACE_CORE_DEPTH, SUBSURFACE_CORE_HALF_WIDTH, SUBSURFACE_CORE_SIZE};
    let core = |s: &Scene| (s.mesh.core_size, s.mesh.core_half_width, s.mesh.core_depth);
    let subsurface = ["output.subsurface=true".to_string()];
    let boxed = (SUBSURFACE_CORE_SIZE, SUBSURFACE_CORE_HALF_WIDTH, SUBSURFACE_CORE_DEPTH);
    let plain = (0.0, 1.25, 0.0);
    // Asked for, no [mesh]: the core box; the rest of the mesh keeps its defaults.
    let s = parse_scene_with(DRY_HERTZ, "t", &subsurface).unwrap();
    assert_eq!(core(&s), boxed);
    assert_eq!((s.mesh.contact_size, s.mesh.growth), (0.25, 0.5));
    assert!(!s.warnings().iter().any(|w| w.contains("mesh.")), "{:?}", s.warnings());
    // Not asked for: nothing changes.
    assert_eq!(core(&parse_scene(DRY_HERTZ, "t").unwrap()), plain);
    // A [mesh] key (in the file or with --set): the scene's own mesh, no core box.
    let own = parse_scene_with(DRY_HERTZ, "t", &[subsurface[0].clone(), "mesh.contact_size=0.25".into()]).unwrap();
    assert_eq!(core(&own), plain);
    let own = parse_scene_with(DRY_HERTZ, "t", &[subsurface[0].clone(), "mesh.core_size=0.0625".into()]).unwrap();
    assert_eq!(core(&own), (0.0625, 1.25, 0.0));
    // A lubricated scene refined to its accuracy target gets it as well.
    let minimal = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/cases/examples/minimal.toml")).unwrap();
    let s = parse_scene_with(&minimal, "m", &subsurface).unwrap();
    assert_eq!(core(&s), boxed);
    assert!(s.accuracy.target > 0.0);
}

/// cases/practice/soft-pdms.toml, a steel ball on PDMS (soft EHL: M = 31.0, L = 2e-4): the
/// isoviscous film is the Nijenbanning-Venner-Moes fit at L = 0, computed apart from this
/// code from the scene's data (E' = 5.2638 MPa, H = 1.53502, hc = H R sqrt(2U) =
/// 7.5399 um), a hundred times Hamrock-Dowson's piezoviscous fit; on the paper's point it
/// lies below that fit.
#[test]
fn isoviscous_film_of_a_soft_contact() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/practice/soft-pdms.toml");
    let soft = crate::case::load_scene(&path).unwrap();
    let iso = soft.isoviscous_hc().unwrap();
    assert!(rel(iso, 7.5399e-6) < 1e-4, "{iso}");
    assert!(rel(soft.film_estimate().unwrap(), iso) < 1e-15);
    assert!(iso > 100.0 * soft.hamrock_dowson().unwrap().central_film_thickness());
    let paper = parse_scene(PAPER_SPIN, "x").unwrap();
    assert!(paper.isoviscous_hc().unwrap() < 0.5 * paper.hamrock_dowson().unwrap().central_film_thickness());
}
