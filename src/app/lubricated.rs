//! The lubricated scene: the full EHL system (elasticity + Reynolds + load balance) solved
//! by Newton, and the converged point's results written by [`super::point`]. A scene with `[sweep]` solves every operating point of the sweep on the
//! same mesh and condensed elastic block, each point from the previous converged state
//! (see [`super::sweep`]).
use super::point::post_point;
use super::{collective, Context, Outcome};
use crate::case::{FrictionModel, Scene};
use crate::ehl::driver::{self, EhlSolver};
use crate::ehl::layout::Layout;
use crate::error::{Error, ResultExt};
use crate::friction::pass::{FaceSolution, FrictionSetup};
use crate::friction::shear::ShearLaw;
use crate::mesh::{self, Mesh};
use crate::solid::dofmap::DofMap;
use serde_json::json;
use std::time::Instant;

/// What one mesh needs, built once per run.
pub struct Setup {
    pub mesh: Mesh,
    pub part: mesh::Partition,
    pub dofs: DofMap,
    pub layout: Layout,
    pub half: bool,
    pub mesh_s: f64,
    pub worst_quality: f64,
}

/// The elastic scene's mesh (the equivalent cube with its contact face) under the size
/// field `field` (None: the scene's own mesh keys), on the half domain when `half`.
pub fn solid_mesh(scene: &Scene, half: bool, field: Option<std::sync::Arc<crate::mesh::size_field::SizeField>>) -> Result<Mesh, Error> {
    let mut spec = super::dry::mesh_spec(scene, half);
    spec.size_field = field;
    mesh::generate(&spec).context("mesh")
}

impl Setup {
    pub fn new(ctx: &Context, scene: &Scene) -> Result<Setup, Error> {
        Self::with_size_field(ctx, scene, None)
    }

    /// As [`Setup::new`], the contact face refined to `field` as well (adaptive
    /// refinement; elastic solids only).
    pub fn with_size_field(
        ctx: &Context,
        scene: &Scene,
        field: Option<std::sync::Arc<crate::mesh::size_field::SizeField>>,
    ) -> Result<Setup, Error> {
        let t0 = Instant::now();
        let half = scene.uses_half_domain();
        if half {
            ctx.log("symmetry: the scene is symmetric about z = 0 (uniform entrainment, no spin): solving the half domain z <= 0 (effects.symmetry = \"off\" solves the full domain)");
        }
        let rigid = scene.effects.elasticity == crate::case::ElasticityModel::Rigid;
        let (mesh, part) = if rigid {
            // Rigid solids: the Reynolds rectangle alone, no 3D mesh.
            let m = mesh::face::face_mesh(&super::dry::mesh_spec(scene, half))?;
            let p = mesh::face::face_partition(&m, ctx.size);
            (m, p)
        } else {
            let m = solid_mesh(scene, half, field)?;
            let p = mesh::partition(&m, ctx.size);
            (m, p)
        };
        let quality = mesh::quality(&mesh);
        let dofs = DofMap::new(&mesh, &part, ctx.size);
        let layout = Layout::new(&mesh, &part, &dofs, &mesh.spec.contact, half, ctx.size);
        let (n_u, n_p) = layout.counts();
        ctx.log(format!(
            "mesh: {} P2 tetrahedra, {} nodes, h_c = {} a, {} contact triangles; unknowns: {} elastic + {} pressure + h0 = {}",
            mesh.tets.len(),
            mesh.nodes.len(),
            mesh.contact_size,
            mesh.contact_tris.len(),
            n_u,
            n_p,
            layout.total()
        ));
        Ok(Setup { mesh, part, dofs, layout, half, mesh_s: t0.elapsed().as_secs_f64(), worst_quality: quality.min_dihedral_deg })
    }
}

/// What the run simulates and what it skips, from the scene's `[effects]` (for the log
/// and summary.json).
pub fn effects_report(scene: &Scene, half: bool) -> serde_json::Value {
    use crate::case::{CavitationModel, DensityModel, KinematicsModel, ViscosityModel};
    let e = &scene.effects;
    let mut simulated =
        vec![format!("Reynolds equation (P2, {} stabilisation) with the load balance for h0", scene.reynolds.stabilisation)];
    let mut skipped = Vec::new();
    match e.elasticity {
        crate::case::ElasticityModel::Elastic => simulated
            .push("elastic deformation: P2 equivalent cube (reynolds.coupling: condensed onto the contact face or monolithic)".into()),
        crate::case::ElasticityModel::Rigid => skipped.push("elastic deformation and the 3D mesh (effects.elasticity = \"rigid\")".into()),
    }
    simulated.push(match e.viscosity {
        ViscosityModel::Roelands => "pressure-viscosity: Roelands".to_string(),
        ViscosityModel::Barus => "pressure-viscosity: Barus".to_string(),
        ViscosityModel::Constant => {
            skipped.push("pressure dependence of the viscosity (effects.viscosity = \"constant\")".to_string());
            "viscosity: constant".to_string()
        }
    });
    match e.density {
        DensityModel::DowsonHigginson => simulated.push("compressibility: Dowson-Higginson".into()),
        DensityModel::Incompressible => skipped.push("compressibility (effects.density = \"incompressible\")".into()),
    }
    match e.kinematics {
        KinematicsModel::Spin => {
            simulated.push("spin kinematics: non-uniform entrainment (Um(z), Wm(x)) from the ball and disc rotations".into())
        }
        KinematicsModel::Uniform => skipped.push("spin (effects.kinematics = \"uniform\": U_B = U_BO, U_D = U_DO, W = 0)".into()),
    }
    match e.cavitation {
        CavitationModel::Complementarity => simulated.push(format!(
            "cavitation: the Reynolds condition as complementarity (P >= 0, its residual >= 0, their product 0), from the penalty solution at xi = {}",
            driver::complementarity_start_penalty(scene)
        )),
        CavitationModel::Penalty => simulated.push(format!("cavitation: penalty, xi = {}", scene.reynolds.penalty)),
        CavitationModel::Off => skipped.push("cavitation (effects.cavitation = \"none\": negative pressures kept)".into()),
    }
    match e.friction {
        FrictionModel::Off => skipped.push("friction pass (effects.friction = \"none\")".into()),
        f => simulated.push(format!("friction pass: {f} shear stresses, forces on the disc")),
    }
    if half {
        skipped.push("the half z > 0 of the domain (symmetric scene; results mirrored)".into());
    }
    json!({
        "lubrication": e.lubrication.as_str(), "elasticity": e.elasticity.as_str(), "viscosity": e.viscosity.as_str(),
        "density": e.density.as_str(), "kinematics": e.kinematics.as_str(), "friction": e.friction.as_str(),
        "cavitation": e.cavitation.as_str(),
        "symmetry": if half { "half domain z <= 0" } else { "full domain" },
        "simulated": simulated, "skipped": skipped,
    })
}

pub fn run(ctx: &Context, scene: &Scene, earlier: Option<&super::restart::EarlierRun>) -> Result<Outcome, Error> {
    let hertz = scene.hertz();
    ctx.log(format!("Hertz: a = {:.5e} m, p_H = {:.5e} Pa; lambda_bar = {:.4e}", hertz.a, hertz.ph, driver::lambda_bar(scene)));
    if let Some(zc) = scene.spin_pole_over_a() {
        let inside = if zc.abs() < 1.0 {
            ": inside the Hertz circle, so the lubricant circulates on closed streamlines in the contact (the hardest spin regime)"
        } else {
            ""
        };
        ctx.log(format!("spin: the mean surface velocity turns about (0, {zc:.3}a){inside}"));
    }
    if scene.accuracy.target > 0.0 {
        if scene.is_sweep() {
            return super::sweep::run_adaptive(ctx, scene);
        }
        return super::adapt::run(ctx, scene, earlier).map(|a| a.outcome);
    }
    let setup = Setup::new(ctx, scene)?;
    crate::interrupt::check("the mesh")?;
    let report = effects_report(scene, setup.half);
    for part in ["simulated", "skipped"] {
        ctx.log(format!("{part}: {}", report[part].as_array().unwrap().iter().filter_map(|v| v.as_str()).collect::<Vec<_>>().join("; ")));
    }
    let mut solver = EhlSolver::new(ctx, scene, &setup.mesh, &setup.part, &setup.dofs, &setup.layout, setup.half, earlier.is_some())?;
    // The speed exponents' adjoint, right after the solve, solves on Newton's factorisation.
    solver.keep_newton(scene.output.speed_exponents && !scene.is_sweep());
    if scene.is_sweep() {
        return super::sweep::run(ctx, scene, &setup, &solver).map(|()| Outcome::Done);
    }
    let sol = match earlier {
        None => solver.solve(ctx, scene, None)?,
        // Mesh sequencing: the earlier run's pressure, in this scene's scales.
        Some(e) => e.solve(ctx, scene, &solver)?,
    };
    crate::interrupt::check("the Newton solve")?;
    // The friction pass and every output file go to a staging folder, moved into the
    // output folder only when complete and not interrupted.
    let exponents = super::sensitivity::of_state(ctx, scene, &solver, &setup.mesh, &setup.layout, &sol.x);
    ctx.write_results(|dir| {
        post_point(ctx, scene, &setup, &sol, solver.condensation_s, None, dir)?;
        super::sensitivity::add_to_summary(ctx, dir, exponents.as_ref()).map(|()| Outcome::Done)
    })
}

/// The friction setup of the scene on the Reynolds rectangle `rect`, or None when
/// `effects.friction = "none"`.
pub fn friction_setup(scene: &Scene, rect: crate::mesh::Rect) -> Option<FrictionSetup> {
    let law = match scene.effects.friction {
        FrictionModel::Off => return None,
        FrictionModel::Newtonian => ShearLaw::Newtonian,
        FrictionModel::ReeEyring => ShearLaw::ReeEyring { tau0: scene.lubricant.as_ref()?.ree_eyring_stress },
    };
    let (hertz, scales) = (scene.hertz(), scene.scales());
    let visc = scene.viscosity_law().expect("lubricated scene");
    Some(FrictionSetup {
        law,
        eta: Box::new(move |p| visc.viscosity_and_derivative(p).0),
        kinematics: scene.kinematics()?,
        a: hertz.a,
        ph: hertz.ph,
        hs: scales.film_scale(),
        rect,
        load: scene.operating.load,
    })
}

/// The friction pass's triangles shared out over every rank, round robin (collective).
pub(super) struct OverRanks<'a>(pub(super) &'a Context);

impl crate::friction::pass::Share for OverRanks<'_> {
    fn mine(&self, k: usize) -> bool {
        k % self.0.size == self.0.rank
    }
    fn gather(&self, local: Result<Vec<f64>, Error>) -> Result<Vec<f64>, Error> {
        collective::agree(&self.0.world, local).map(|v| collective::all_gather_f64(&self.0.world, &v))
    }
}

/// The friction pass reads the EHL solution through [`FaceSolution`] (so `friction` does
/// not depend on `ehl`).
impl FaceSolution for crate::ehl::post::FieldsOnFace<'_> {
    fn mesh(&self) -> &crate::mesh::Mesh {
        self.mesh
    }
    fn p_node(&self, n: u32) -> f64 {
        crate::ehl::post::FieldsOnFace::p_node(self, n)
    }
    fn h_node(&self, n: u32) -> f64 {
        crate::ehl::post::FieldsOnFace::h_node(self, n)
    }
    fn half(&self) -> bool {
        crate::ehl::post::FieldsOnFace::half(self)
    }
    fn locate(&self, x: f64, z: f64) -> Option<(usize, [f64; 3])> {
        crate::ehl::post::FieldsOnFace::locate(self, x, z)
    }
}
