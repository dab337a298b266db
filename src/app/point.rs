//! One converged operating point's results: the checks that keep an unphysical state from
//! being reported, the log lines, the friction pass shared out over the ranks, the face's
//! files (profiles, plots, VTU, the pressure a later run starts from), the subsurface
//! stresses when asked for, and summary.json. Used by the single solve, the sweep, the
//! convergence study and the adaptive loop alike.
use super::face_files::{write_face_vtu, write_plots, write_profiles};
use super::lubricated::{effects_report, friction_setup, OverRanks, Setup};
use super::{collective, Context};
use crate::case::Scene;
use crate::ehl::driver::EhlSolution;
use crate::ehl::post::{FieldsOnFace, FilmStats};
use crate::error::Error;
use crate::friction::pass::{friction_pass, stress_at, FrictionResult, FrictionSetup};
use crate::physics::HamrockDowson;
use serde_json::json;
use std::path::Path;
use std::time::Instant;

/// The headline numbers of one converged operating point (SI units), for the sweep table.
#[derive(Debug, Clone, Default)]
pub struct PointResult {
    pub hc: f64,
    pub hm: f64,
    pub pmax: f64,
    pub load_error: f64,
    pub fx: Option<f64>,
    pub fz: Option<f64>,
    /// Film along the transverse centre line x = 0: (z / a, h in m) (rank 0).
    pub profile_x0: Vec<[f64; 2]>,
}

/// Post-processing of one converged point: film statistics and log line on every rank, the
/// friction pass shared out over the ranks, and on rank 0 every output file in `dir`
/// (profiles, plots, VTU, summary.json last). Returns the point's numbers (rank 0; the others return the film
/// numbers without friction). `computed`: the friction pass already run on this state, if
/// any (an adaptive level's). Collective: the peak-memory reduction and the friction pass.
pub fn post_point(
    ctx: &Context,
    scene: &Scene,
    setup: &Setup,
    sol: &EhlSolution,
    condensation_s: Option<f64>,
    computed: Option<FrictionResult>,
    dir: &Path,
) -> Result<PointResult, Error> {
    let t_post = Instant::now();
    let fields = FieldsOnFace::new(&setup.mesh, &setup.layout, &sol.x);
    let st = fields.stats();
    refuse_unphysical(sol, &st)?;
    let film = report_film(ctx, scene, setup, &fields, &st);
    let peak = collective::max_f64(&ctx.world, crate::output::peak_rss_mb());
    let fset = friction_setup(scene, setup.mesh.spec.contact);
    // The pass shares its triangles out over the ranks.
    let friction = match (&fset, computed) {
        (Some(fs), None) => Some(friction_pass(&fields, fs, &OverRanks(ctx))?),
        (Some(_), computed) => computed,
        (None, _) => None,
    };
    let (hs, ph) = (scene.scales().film_scale(), scene.hertz().ph);
    let mut res = PointResult {
        hc: st.hc * hs,
        hm: st.hm * hs,
        pmax: st.pmax * ph,
        load_error: film.load_error,
        fx: None,
        fz: None,
        profile_x0: Vec::new(),
    };
    if ctx.rank != 0 {
        return Ok(res);
    }
    if let Some(f) = &friction {
        report_friction(ctx, scene, f);
        res.fx = Some(f.fx);
        res.fz = Some(f.fz);
    }
    let lines = write_face_outputs(ctx, scene, setup, &fields, fset.as_ref(), friction.as_ref(), dir)?;
    res.profile_x0 = lines.profile_x0.clone();
    let subsurface = if scene.output.subsurface {
        Some(subsurface_point(ctx, scene, setup, &fields, friction.as_ref(), sol, condensation_s, dir)?)
    } else {
        None
    };
    let post = Post { film, lines, peak, condensation_s, post_s: t_post.elapsed().as_secs_f64() };
    let mut summary = point_summary(ctx, scene, setup, sol, &st, &post, friction.as_ref())?;
    if let Some(s) = subsurface {
        summary["subsurface"] = s;
        summary["timing"]["subsurface_s"] = summary["subsurface"]["total_s"].clone();
    }
    ctx.write_summary_to(dir, &summary)?;
    Ok(res)
}

/// A converged Newton can still hold an unphysical state: it is never reported as a result.
/// Every rank holds the whole iterate, so every rank reaches the same verdict.
fn refuse_unphysical(sol: &EhlSolution, st: &FilmStats) -> Result<(), Error> {
    if sol.x.iter().any(|v| !v.is_finite()) || ![st.hc, st.hm, st.pmax, st.pmin, st.load].iter().all(|v| v.is_finite()) {
        return Err(Error::numerical("the converged state contains NaN or infinite values; no result written"));
    }
    if st.hm <= 0.0 {
        return Err(Error::numerical(format!(
            "the converged film is not positive everywhere (minimum H = {:.3e} at ({:.3}a, {:.3}a)); no result written",
            st.hm, st.hm_at[0], st.hm_at[1]
        )));
    }
    Ok(())
}

/// What the log says of a point's film, kept for its summary.
struct FilmReport {
    /// The relative error of the load balance (the integral of P against its target).
    load_error: f64,
    /// The pressure near the inlet's edge (units of p_H), if the face reaches there.
    inlet: Option<f64>,
    hd: Option<HamrockDowson>,
    nvm: Option<f64>,
}

/// The result's log line, a warning when the inlet cuts off the pressure's build-up, and
/// the film formulas beside the result.
fn report_film(ctx: &Context, scene: &Scene, setup: &Setup, fields: &FieldsOnFace, st: &FilmStats) -> FilmReport {
    let target = if setup.half { std::f64::consts::PI / 3.0 } else { 2.0 * std::f64::consts::PI / 3.0 };
    let load_error = (st.load - target).abs() / target;
    let (hs, ph) = (scene.scales().film_scale(), scene.hertz().ph);
    ctx.log(format!(
        "result: hc = {:.4e} m, hm = {:.4e} m at ({:.3}a, {:.3}a), pmax = {:.4e} Pa, load error {:.2e}",
        st.hc * hs,
        st.hm * hs,
        st.hm_at[0],
        st.hm_at[1],
        st.pmax * ph,
        load_error
    ));
    // How much of the inlet's pressure build-up the domain cuts off.
    let rect = setup.mesh.spec.contact;
    let inlet = fields.at(rect.x0 + INLET_PROBE, 0.0).map(|v| v.0);
    if let Some(w) = inlet.and_then(|p| inlet_warning(p, rect.x0, scene.accuracy.target)) {
        ctx.log(w);
    }
    let (hd, nvm) = (scene.hamrock_dowson(), scene.nijenbanning_hc());
    if let Some(line) = formulas_line(hd.as_ref(), nvm, st.hc * hs, st.hm * hs) {
        ctx.log(line);
    }
    FilmReport { load_error, inlet, hd, nvm }
}

/// The friction pass's log line, and a warning where the friction coefficient is not a
/// lubricated contact's.
fn report_friction(ctx: &Context, scene: &Scene, f: &FrictionResult) {
    ctx.log(format!(
        "friction ({}): fx = {:.5e}, fz = {:.5e} (Fx = {:.4e} N, Fz = {:.4e} N), max |tau| on the disc {:.4e} Pa ({:.2} s; the rule subdivided on {} of {} triangles, {} stress evaluations)",
        scene.effects.friction,
        f.fx,
        f.fz,
        f.fx_n,
        f.fz_n,
        f.tau_max,
        f.seconds,
        f.quadrature.subdivided,
        f.quadrature.triangles,
        f.quadrature.evaluations
    ));
    // A lubricated contact's friction coefficient is of order 0.01-0.1; above 1 the
    // Newtonian law has carried exp(alpha p) viscosities into shear stresses no
    // lubricant sustains (the limiting shear stress is what Ree-Eyring adds).
    if f.fx.hypot(f.fz) > 1.0 {
        ctx.log(format!(
            "warning: the friction coefficient sqrt(fx^2 + fz^2) = {:.3e} is above 1: with effects.friction = \"{}\" the shear stress reaches {:.3e} Pa, far above any lubricant's limiting shear stress; effects.friction = \"ree-eyring\" bounds it",
            f.fx.hypot(f.fz),
            scene.effects.friction,
            f.tau_max
        ));
    }
}

/// What the centre lines of the face give the summary: the film along X = 0 (z / a, h in
/// m), and along X = 0 and Z = 0 the largest jump of the pressure slope and the largest
/// scallop (docs/accuracy.md, "Smooth fields").
struct CentreLines {
    profile_x0: Vec<[f64; 2]>,
    jumps: [f64; 2],
    wiggles: [f64; 2],
}

/// The face's files (rank 0): the centre-line profiles (with the shear stresses when
/// friction is on) and the shear profile, the plots, the VTU and the nodal pressure a later
/// run can start from (`--start-from`); the smoothness log line.
fn write_face_outputs(
    ctx: &Context,
    scene: &Scene,
    setup: &Setup,
    fields: &FieldsOnFace,
    fset: Option<&FrictionSetup>,
    friction: Option<&FrictionResult>,
    dir: &Path,
) -> Result<CentreLines, Error> {
    let (hs, a, ph) = (scene.scales().film_scale(), scene.hertz().a, scene.hertz().ph);
    let tau = |x: f64, z: f64| -> Result<Option<[f64; 2]>, Error> {
        match fset {
            Some(fs) => stress_at(fields, fs, x, z).transpose(),
            None => Ok(None),
        }
    };
    // The scene's Reynolds rectangle (a half-domain solve is mirrored by FieldsOnFace).
    let r = &crate::mesh::Rect { x0: scene.reynolds.x_min, x1: scene.reynolds.x_max, z0: scene.reynolds.z_min, z1: scene.reynolds.z_max };
    let profile = |from: [f64; 2], to: [f64; 2]| -> Result<Vec<Vec<f64>>, Error> {
        let mut rows = Vec::new();
        for s in fields.profile(from, to, 601) {
            let mut row = vec![s[0] * a, s[1] * a, s[2] * ph, s[3] * hs];
            if let Some(t) = tau(s[0], s[1])? {
                row.extend(t);
            }
            rows.push(row);
        }
        Ok(rows)
    };
    let prof_x0 = profile([0.0, r.z0], [0.0, r.z1])?;
    let prof_z0 = profile([r.x0, 0.0], [r.x1, 0.0])?;
    // Wiggles of the same two lines (docs/accuracy.md, "Smooth fields").
    let (line_x0, line_z0) = (([0.0, r.z0], [0.0, r.z1]), ([r.x0, 0.0], [r.x1, 0.0]));
    let lines = [line_x0, line_z0].map(|(a, b)| fields.slope_jumps(a, b, 20001));
    let jumps = lines.each_ref().map(|l| l.largest().0);
    let wiggles = lines.each_ref().map(|l| l.largest_scallop());
    ctx.log(format!(
        "smoothness: the largest pressure scallop is {:.4} p_H along X = 0 (at Z = {:.3} a) and {:.4} p_H along Z = 0 (at X = {:.3} a)",
        wiggles[0].0, wiggles[0].1[1], wiggles[1].0, wiggles[1].1[0]
    ));
    let wiggles = wiggles.map(|w| w.0);
    let with_tau = friction.is_some();
    write_profiles(dir, "profile_x0.csv", &prof_x0, with_tau)?;
    write_profiles(dir, "profile_z0.csv", &prof_z0, with_tau)?;
    if with_tau {
        let zl = scene.output.shear_profile_z / a;
        let line = profile([r.x0, zl], [r.x1, zl])?;
        write_profiles(dir, "shear_profile.csv", &line, true)?;
    }
    if scene.output.png {
        write_plots(dir, fields, a, ph, hs, &prof_x0, &prof_z0)?;
        if let Some(f) = friction {
            let zl = scene.output.shear_profile_z / a;
            super::plots::friction_plots(dir, fields, f, a, scene.output.shear_profile_z, &profile([r.x0, zl], [r.x1, zl])?)?;
        }
        if let Some(k) = scene.kinematics() {
            super::plots::velocity_plots(dir, &k, a, r)?;
        }
    }
    if scene.output.vtu {
        write_face_vtu(dir, fields, a, ph, hs, friction)?;
    }
    // The nodal pressure a later run can start from (--start-from).
    let face_p = dir.join(super::restart::FACE_PRESSURE);
    crate::output::write_atomic(&face_p, super::restart::face_pressure_csv(&setup.mesh, &|n| fields.p_node(n), a, ph).as_bytes())
        .map_err(Error::writing(&face_p))?;
    Ok(CentreLines { profile_x0: prof_x0.iter().map(|r| [r[1] / a, r[3]]).collect(), jumps, wiggles })
}

/// What post-processing measured of a point, for its summary.
struct Post {
    film: FilmReport,
    lines: CentreLines,
    /// The largest peak resident memory of a rank (MB).
    peak: f64,
    condensation_s: Option<f64>,
    post_s: f64,
}

/// summary.json of one converged point (without its subsurface section).
fn point_summary(
    ctx: &Context,
    scene: &Scene,
    setup: &Setup,
    sol: &EhlSolution,
    st: &FilmStats,
    post: &Post,
    friction: Option<&FrictionResult>,
) -> Result<serde_json::Value, Error> {
    let (mesh, layout) = (&setup.mesh, &setup.layout);
    let hertz = scene.hertz();
    let (hs, a, ph) = (scene.scales().film_scale(), hertz.a, hertz.ph);
    let (hd, nvm, load_error, inlet) = (post.film.hd.as_ref(), post.film.nvm, post.film.load_error, post.film.inlet);
    let (jumps, wiggles, peak, condensation_s) = (post.lines.jumps, post.lines.wiggles, post.peak, post.condensation_s);
    let (n_u, n_p) = layout.counts();
    let kin = scene.kinematics().expect("lubricated scene");
    use crate::output::summary::*;
    let summary = Summary {
        case: scene.name.clone(),
        ranks: ctx.size,
        converged: sol.report.converged,
        hertz: HertzSummary { a_m: a, ph_pa: ph, e_prime_pa: hertz.e_prime },
        operating: OperatingSummary {
            load_n: scene.operating.load,
            entrainment_speed_m_s: scene.operating.entrainment_speed,
            slide_to_roll: scene.operating.slide_to_roll,
            tilt_angle_deg: scene.operating.tilt_angle,
        },
        kinematics: KinematicsSummary {
            model: scene.effects.kinematics.as_str().to_string(),
            omega_b_rad_s: kin.omega_b,
            omega_d_rad_s: kin.omega_d,
            u_bo_m_s: kin.u_bo,
            u_do_m_s: kin.u_do,
            spin_centre_z_m: kin.spin_centre(),
        },
        mesh: MeshSummary {
            elements: mesh.tets.len(),
            nodes: mesh.nodes.len(),
            dofs_total: layout.total(),
            contact_triangles: mesh.contact_tris.len(),
            contact_size_a: mesh.contact_size,
            worst_quality: setup.worst_quality.is_finite().then_some(setup.worst_quality),
            worst_quality_measure: "minimum dihedral angle (degrees)".into(),
            max_aspect_ratio: None,
        },
        film: FilmSummary {
            hc_m: st.hc * hs,
            hm_m: st.hm * hs,
            hm_x_m: st.hm_at[0] * a,
            hm_z_m: st.hm_at[1] * a,
            h0_m: st.h0 * hs,
            hc_hamrock_dowson_m: hd.map(|h| h.central_film_thickness()),
            hm_hamrock_dowson_m: hd.map(|h| h.minimum_film_thickness()),
            hc_nijenbanning_m: nvm,
        },
        pressure: PressureSummary {
            pmax_pa: st.pmax * ph,
            pmax_x_m: st.pmax_at[0] * a,
            pmax_z_m: st.pmax_at[1] * a,
            pmin_pa: st.pmin * ph,
            pmin_nodes_pa: st.pmin_nodes * ph,
            load_error_rel: load_error,
            slope_jump_x0: Some(jumps[0]),
            slope_jump_z0: Some(jumps[1]),
            wiggle_x0: Some(wiggles[0]),
            wiggle_z0: Some(wiggles[1]),
            inlet_over_ph: inlet,
        },
        moes: scene.moes().map(|m| MoesSummary { m: m.m, l: m.l }),
        solver: SolverSummary {
            newton_iterations: sol.newton_total,
            snes_reason: sol.report.reason.clone(),
            residual_norm: sol.report.residual_norm,
            dofs_elastic: n_u,
            dofs_reynolds: n_p,
            path: sol.steps.clone(),
            half_domain: setup.half,
            penalty: scene.reynolds.penalty,
            stabilisation: scene.reynolds.stabilisation.as_str().to_string(),
            coupling: sol.coupling.name().to_string(),
        },
        timing: Timing {
            mesh_s: setup.mesh_s,
            assembly_s: sol.assembly_s,
            solve_s: sol.solve_s,
            post_s: Some(post.post_s),
            total_s: ctx.start.elapsed().as_secs_f64(),
            // Only when the elastic block was condensed (not for rigid solids).
            condensation_s,
            friction_s: friction.map(|f| f.seconds),
        },
        peak_rss_mb: peak,
        effects: effects_report(scene, setup.half),
        scene: scene.clone(),
        friction: friction.map(|f| FrictionSummary {
            model: scene.effects.friction.as_str().to_string(),
            fx: f.fx,
            fz: f.fz,
            fx_n: f.fx_n,
            fz_n: f.fz_n,
            tau_max_pa: f.tau_max,
            quadrature: Some(FrictionQuadratureSummary {
                triangles: f.quadrature.triangles,
                subdivided: f.quadrature.subdivided,
                stress_evaluations: f.quadrature.evaluations,
                fixed_rule_fx: f.fixed_rule[0],
                fixed_rule_fz: f.fixed_rule[1],
            }),
        }),
    };
    to_json(&summary)
}

/// The subsurface stresses of one converged point (rank 0, `output.subsurface`): the disc's
/// own elastic problem (its Poisson ratio, a unit Young's modulus) under the converged face
/// pressure and, with `effects.surface_traction = "friction"`, the friction pass's shear
/// stresses on the disc; one MUMPS Cholesky on rank 0 (the condensed Newton keeps no 3D
/// displacement). Returns the `subsurface` object of summary.json.
#[allow(clippy::too_many_arguments)]
fn subsurface_point(
    ctx: &Context,
    scene: &Scene,
    setup: &Setup,
    fields: &FieldsOnFace,
    friction: Option<&FrictionResult>,
    sol: &EhlSolution,
    condensation_s: Option<f64>,
    dir: &Path,
) -> Result<serde_json::Value, Error> {
    use super::subsurface as sub;
    let t0 = Instant::now();
    let mesh = &setup.mesh;
    let hertz = scene.hertz();
    let with_friction = scene.effects.surface_traction == crate::case::SurfaceTraction::Friction;
    // The friction pass's nodal shear stresses (Pa) per contact triangle.
    let mut tau: Vec<Option<[[f64; 2]; 6]>> = vec![None; mesh.contact_tris.len()];
    if with_friction {
        let f =
            friction.ok_or_else(|| Error::invalid("effects.surface_traction = \"friction\" needs the friction pass (effects.friction)"))?;
        for (t, v) in &f.nodal {
            tau[*t] = Some(*v);
        }
    }
    let load_with = |t: usize, shear: bool| -> [[f64; 3]; 6] {
        let tri = mesh.contact_tris[t];
        let v = [0, 1, 2].map(|i| {
            let c = mesh.nodes[tri[i] as usize];
            [c[0], c[2]]
        });
        let m = crate::fem::p2tri::p2_tri_mass(crate::fem::p2tri::tri_area(&v));
        let p = tri.map(|n| fields.p_node(n));
        let q = if shear { tau[t].unwrap_or([[0.0; 2]; 6]) } else { [[0.0; 2]; 6] };
        std::array::from_fn(|i| {
            let w = |f: &dyn Fn(usize) -> f64| (0..6).map(|j| m[i][j] * f(j)).sum::<f64>();
            [w(&|j| q[j][0] / hertz.ph), -w(&|j| p[j]), w(&|j| q[j][1] / hertz.ph)]
        })
    };
    let disc = scene.disc_material();
    let load = |t: usize| load_with(t, true);
    let pressure_only = |t: usize| load_with(t, false);
    // With the friction traction, the pressure-only field too (one more back substitution).
    let loads: Vec<&sub::FaceLoad> = if with_friction { vec![&load, &pressure_only] } else { vec![&load] };
    let (us, cost) = sub::solve_alone(mesh, disc.nu, &loads)?;
    let u = &us[0];
    let traction = if with_friction {
        format!("EHL pressure and the {} shear stresses on the disc", scene.effects.friction)
    } else {
        "EHL pressure".to_string()
    };
    let params = sub::Params {
        nu: disc.nu,
        e: disc.e,
        a: hertz.a,
        ph: hertz.ph,
        rect: crate::mesh::Rect {
            x0: scene.reynolds.x_min,
            x1: scene.reynolds.x_max,
            z0: scene.reynolds.z_min,
            z1: if setup.half { 0.0 } else { scene.reynolds.z_max },
        },
        half: setup.half,
        png: scene.output.png,
        vtu: scene.output.vtu,
        traction: &traction,
        method: scene.output.subsurface_recovery,
    };
    let log = |m: String| ctx.log(m);
    let mut obj = sub::recover_and_write(mesh, u, &params, dir, &log)?;
    if with_friction {
        let p2 = sub::Params { traction: "EHL pressure", ..params };
        obj["pressure_only"] = sub::maxima_only(mesh, &us[1], &p2);
    }
    obj["solve"] = json!({
        "kind": "rank 0: the disc's own elastic problem (MUMPS Cholesky)",
        "seconds": cost.seconds, "rss_increase_mb": cost.rss_increase_mb, "mumps_factor_mb": cost.factor_mb, "unknowns": cost.unknowns,
        "ehl_solve_s": sol.solve_s,
    });
    // The monolithic coupling condenses nothing: no key rather than a null, which the
    // summary's check takes for a number that is not finite.
    if let Some(c) = condensation_s {
        obj["solve"]["condensation_s"] = json!(c);
    }
    obj["total_s"] = json!(t0.elapsed().as_secs_f64());
    ctx.log(format!(
        "subsurface: {:.2} s (elastic solve {:.2} s, MUMPS factor {:.0} MB; the EHL solve took {:.2} s)",
        t0.elapsed().as_secs_f64(),
        cost.seconds,
        cost.factor_mb.unwrap_or(f64::NAN),
        sol.solve_s
    ));
    Ok(obj)
}

/// Where the inlet's cut-off is measured: the centre-line pressure this far (units of a)
/// inside the inlet boundary X = `reynolds.x_min`, in p_H (summary.json's
/// `pressure.inlet_over_ph`).
const INLET_PROBE: f64 = 0.5;

/// The largest ratio measured between the films' relative change when the inlet moves from
/// X = -4.5 to -9 and that pressure (2 ranks, target 0.01, Moes points; pressure in p_H,
/// then the changes of hc and hm): M = 5, L = 2: 5.1e-3, +0.33 %, +2.0 %; M = 10, L = 6:
/// 2.2e-3, +0.38 %, +0.55 %; M = 20, L = 5: 9.8e-4, +0.23 %, +0.32 %; M = 100, L = 10:
/// 1.2e-4, +0.11 %, +0.07 %. The ratio runs from 2.5 to 9; a longer inlet always thickens
/// the film (the cut-off build-up starves it).
const INLET_STARVATION_RATIO: f64 = 9.0;

/// A warning when the domain's inlet may starve the films by more than the accuracy
/// `target` (0.01 without one): `p_inlet` the pressure (p_H) [`INLET_PROBE`] inside the
/// inlet boundary `x_min` (units of a). The accuracy estimate does not see this error: it
/// belongs to the domain, which refinement does not change.
fn inlet_warning(p_inlet: f64, x_min: f64, target: f64) -> Option<String> {
    let target = if target > 0.0 { target } else { 0.01 };
    let bound = INLET_STARVATION_RATIO * p_inlet;
    (bound > target).then(|| {
        format!(
            "warning: the pressure {INLET_PROBE} a inside the inlet (reynolds.x_min = {x_min}) is {p_inlet:.2e} p_H: the domain cuts off part of the inlet's pressure build-up, and a longer inlet would thicken hc and hm by up to about {:.1} % (the accuracy estimate does not include it; set reynolds.x_min further upstream for a fully flooded contact)",
            100.0 * bound
        )
    })
}

/// The film formulas beside the result (Hamrock-Dowson's `hd`, the Nijenbanning-Venner-Moes
/// central film `nvm`), each with the result's difference from it: a user comparing with a
/// formula sees the formula's own spread (docs/validation.md) named, not an error of this
/// solution. None when the scene has no finite, positive formula film (rigid or isoviscous
/// solids).
fn formulas_line(hd: Option<&HamrockDowson>, nvm: Option<f64>, hc: f64, hm: f64) -> Option<String> {
    let ok = |v: f64| v.is_finite() && v > 0.0;
    let hd = hd.filter(|h| ok(h.central_film_thickness()) && ok(h.minimum_film_thickness()))?;
    let d = |x: f64, f: f64| 100.0 * (x / f - 1.0);
    let (c, m) = (hd.central_film_thickness(), hd.minimum_film_thickness());
    let nvm = nvm.map_or(String::new(), |n| format!("; Nijenbanning-Venner-Moes hc {n:.4e} m ({:+.1} %)", d(hc, n)));
    Some(format!(
        "film formulas (curve fits of a few to tens of per cent, not checks; the result's difference in brackets): Hamrock-Dowson hc {c:.4e} m ({:+.1} %), hm {m:.4e} m ({:+.1} %){nvm}",
        d(hc, c),
        d(hm, m)
    ))
}

#[cfg(test)]
mod tests {
    use super::inlet_warning;

    /// The bound (9 times the pressure) against the target, 0.01 without one: M = 5, L = 2
    /// at X = -4.5 (5.1e-3 p_H, hm 2.0 % starved) warns, M = 20, L = 5 (9.8e-4 p_H, 0.32 %)
    /// does not; at target 0.001 it does.
    #[test]
    fn the_inlet_warns_when_its_starvation_may_exceed_the_target() {
        let w = inlet_warning(5.1e-3, -4.5, 0.01).expect("M = 5, L = 2 warns");
        assert!(w.contains("reynolds.x_min = -4.5") && w.contains("4.6 %"), "{w}");
        assert!(inlet_warning(9.8e-4, -4.5, 0.01).is_none());
        assert!(inlet_warning(9.8e-4, -4.5, 0.0).is_none());
        assert!(inlet_warning(9.8e-4, -4.5, 0.001).is_some());
    }
}
