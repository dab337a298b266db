//! Mesh sequencing (`--start-from DIR`): Newton starts from the converged pressure of an
//! earlier run, typically the same scene on a coarser mesh, interpolated onto this mesh.
//!
//! Every converged lubricated point writes its nodal contact-face pressure to
//! [`FACE_PRESSURE`] next to `summary.json`. A later run reads both, rebuilds the earlier
//! run's mesh from the scene recorded in `summary.json` (the mesher is deterministic),
//! checks that the file's nodes are that mesh's contact nodes, and interpolates the P2
//! pressure. Everything is read and checked before the output folder is touched.
use crate::case::Scene;
use crate::error::Error;
use crate::mesh::{ContactLocator, Mesh};
use crate::output::summary::{DrySummary, Summary};
use std::path::{Path, PathBuf};

/// Nodal pressure on the contact face: `x_m,z_m,p_pa`, one row per contact node in the
/// mesh's order (0 on the Dirichlet edges of the Reynolds rectangle).
pub const FACE_PRESSURE: &str = "face_pressure.csv";

/// The CSV text of [`FACE_PRESSURE`]: `p_node` gives the dimensionless nodal pressure.
pub fn face_pressure_csv(mesh: &Mesh, p_node: &dyn Fn(u32) -> f64, a: f64, ph: f64) -> String {
    let mut s = String::from("x_m,z_m,p_pa\n");
    for &n in &mesh.contact_nodes {
        let c = mesh.nodes[n as usize];
        s.push_str(&format!("{:e},{:e},{:e}\n", c[0] * a, c[2] * a, p_node(n) * ph));
    }
    s
}

/// A converged earlier run: its contact-face mesh and nodal pressure.
pub struct EarlierRun {
    pub dir: PathBuf,
    mesh: Mesh,
    locator: ContactLocator,
    /// Pressure (Pa) by mesh node (0 off the contact face).
    p_pa: Vec<f64>,
    /// Hertz radius of the earlier scene (m): its mesh is in units of it.
    a: f64,
    /// The earlier run's central film (m).
    pub hc_m: f64,
}

impl EarlierRun {
    /// Reads `dir/summary.json` and `dir/face_pressure.csv` and rebuilds the earlier mesh.
    /// Errors name the option, the file and what is wrong.
    pub fn read(dir: &Path) -> Result<EarlierRun, Error> {
        let err = |e: Error| e.context(format!("--start-from {}", dir.display()));
        let summary_path = dir.join("summary.json");
        let text = crate::case::read_bounded(&summary_path, 16 << 20).map_err(|e| {
            err(Error::invalid(format!(
                "cannot read {}: {e} (the folder of a converged lubricated run is expected)",
                summary_path.display()
            )))
        })?;
        // Checked in the order a user can act on: the file is JSON, the scene it stores is
        // valid (it may have been edited), the run converged, then the rest of its fields.
        let value: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| err(Error::format(format!("{} is not valid JSON: {e}", summary_path.display()))))?;
        if serde_json::from_value::<DrySummary>(value.clone()).is_ok() {
            return Err(err(Error::invalid("the earlier run is a dry (Hertz) run: it has no film to start from")));
        }
        let stored: Scene = serde_json::from_value(value["scene"].clone())
            .map_err(|e| err(Error::format(format!("{} holds no scene this version can read: {e}", summary_path.display()))))?;
        let bad_scene = |e: crate::case::SceneError| {
            err(Error::from(e).context(format!("the scene stored in {} is not valid", summary_path.display())))
        };
        stored.validate().map_err(bad_scene)?;
        stored.plausibility().map_err(bad_scene)?;
        super::check_mesh(&stored).map_err(bad_scene)?;
        if value["converged"].as_bool() != Some(true) {
            return Err(err(Error::invalid(format!(
                "{} is not the summary of a converged run (\"converged\" is not true)",
                summary_path.display()
            ))));
        }
        // An adaptively refined run's face pressure lives on its last level's mesh, which
        // the scene alone does not rebuild (the levels' size fields are not stored).
        if let Some(n) = value["accuracy"]["levels"].as_array().map(|l| l.len()).filter(|&n| n > 1) {
            return Err(err(Error::invalid(format!(
                "{} is the summary of a run refined adaptively ({n} levels): its last level's mesh cannot be rebuilt from the scene; start from a run on a fixed mesh (accuracy.target = 0)",
                summary_path.display()
            ))));
        }
        let summary = Summary::from_json(&text).map_err(|e| {
            err(e.context(format!("{} is not the summary of a lubricated run this version can read", summary_path.display())))
        })?;
        let (scene, hc_m, half) = (summary.scene, summary.film.hc_m, summary.solver.half_domain);
        if !hc_m.is_finite() {
            return Err(err(Error::format(format!("{} has no finite film.hc_m", summary_path.display()))));
        }
        let mesh = if scene.effects.elasticity == crate::case::ElasticityModel::Rigid {
            crate::mesh::face::face_mesh(&super::dry::mesh_spec(&scene, half))?
        } else {
            super::dry::build_mesh(&scene, half)?
        };
        let csv_path = dir.join(FACE_PRESSURE);
        let csv = crate::case::read_bounded(&csv_path, 256 << 20).map_err(|e| err(Error::reading(&csv_path)(e)))?;
        let a = scene.hertz().a;
        let (header, rows) =
            crate::output::csv::parse_csv(&csv, &csv_path.display().to_string()).map_err(|e| err(Error::format(e.to_string())))?;
        if header != ["x_m", "z_m", "p_pa"] {
            return Err(err(Error::format(format!(
                "{}: expected the columns x_m,z_m,p_pa, found {}",
                csv_path.display(),
                header.join(",")
            ))));
        }
        if rows.len() != mesh.contact_nodes.len() {
            return Err(err(Error::format(format!(
                "{} has {} nodes, but the mesh of the earlier scene has {} contact nodes (written by another version of the mesher?)",
                csv_path.display(),
                rows.len(),
                mesh.contact_nodes.len()
            ))));
        }
        let mut p_pa = vec![0.0; mesh.nodes.len()];
        for (k, (v, &n)) in rows.iter().zip(&mesh.contact_nodes).enumerate() {
            if !v.iter().all(|x| x.is_finite()) {
                return Err(err(Error::format(format!(
                    "{} data line {}: expected three finite numbers x_m,z_m,p_pa",
                    csv_path.display(),
                    k + 1
                ))));
            }
            let c = mesh.nodes[n as usize];
            if (v[0] / a - c[0]).abs() > 1e-9 || (v[1] / a - c[2]).abs() > 1e-9 {
                return Err(err(Error::format(format!(
                    "{} data line {}: node at ({:.6}a, {:.6}a), but the earlier mesh has its contact node there at ({:.6}a, {:.6}a) (written by another version of the mesher?)",
                    csv_path.display(),
                    k + 1,
                    v[0] / a,
                    v[1] / a,
                    c[0],
                    c[2]
                ))));
            }
            p_pa[n as usize] = v[2];
        }
        let locator = ContactLocator::new(&mesh);
        Ok(EarlierRun { dir: dir.to_path_buf(), mesh, locator, p_pa, a, hc_m })
    }

    /// Newton from this run's pressure for `scene` (whose scales may differ from the
    /// earlier scene's), falling back to the Hertz start. Collective.
    pub fn solve<'a>(
        &self,
        ctx: &'a super::Context,
        scene: &Scene,
        solver: &crate::ehl::driver::EhlSolver<'a>,
    ) -> Result<crate::ehl::driver::EhlSolution, Error> {
        let hertz = scene.hertz();
        let (a, ph) = (hertz.a, hertz.ph);
        let p = |x: f64, z: f64| self.pressure_at(x * a, z * a) / ph;
        let label = format!("the pressure of {} ({} contact nodes)", self.dir.display(), self.mesh.contact_nodes.len());
        let hc = self.hc_m / scene.scales().film_scale();
        solver.solve_from(ctx, scene, crate::ehl::driver::Start::from_pressure(&p, hc, &label))
    }

    /// The earlier pressure (Pa) at (x, z) in metres, by P2 interpolation; 0 outside the
    /// earlier Reynolds rectangle. A half-domain run is mirrored about z = 0.
    pub fn pressure_at(&self, x_m: f64, z_m: f64) -> f64 {
        let (x, mut z) = (x_m / self.a, z_m / self.a);
        if self.mesh.spec.half_z {
            z = -z.abs();
        }
        match self.locator.locate(&self.mesh, x, z) {
            Some((t, b)) => crate::fem::p2_tri_eval(&self.mesh.contact_tris[t].map(|n| self.p_pa[n as usize]), b),
            None => 0.0,
        }
    }
}
