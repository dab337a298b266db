//! Subsurface stresses in the disc (`output.subsurface = true`, docs/subsurface.md): the
//! displacement of the disc under the contact-face traction (the converged pressure and,
//! with `effects.surface_traction = "friction"`, the friction pass's shear stresses), the
//! recovered stress field, its maxima, and the outputs: `subsurface.vtu` (the region under
//! the contact), `subsurface_axis.csv` (the stresses along the contact's axis) and PNG maps
//! of the von Mises and orthogonal shear stresses on the sections z = 0 and x = 0.
//!
//! Units: the elastic problem is solved with a unit Young's modulus and the traction in
//! units of p_H, so the stress comes out in units of p_H (the stress of a body loaded by
//! tractions depends on its Poisson ratio only) and the displacement in units of
//! a p_H / E_disc.
#![allow(clippy::needless_range_loop)]
use crate::case::StressRecovery;
use crate::error::Error;
use crate::fem::elasticity::lame;
use crate::mesh::{partition, Mesh, Partition, Rect};
use crate::output::vtu::{write_vtu_single_type, Field, VTK_QUADRATIC_TETRA};
use crate::petsc::{self, ffi, Ksp, Vector};
use crate::solid::assembly::{assemble_stiffness, tet_vertices};
use crate::solid::dofmap::DofMap;
use crate::solid::stress::{eval_p2, peak_vertex, principal, recover_nodal, recover_spr, tresca, von_mises, Sym, PEAK_BAND};
use serde_json::json;
use std::path::Path;
use std::time::Instant;

/// Depth of the region under the contact whose stresses are recovered and written (units of a).
pub const REGION_DEPTH: f64 = 3.0;

/// Integrals of the face traction (units of p_H, components x, y, z of the solver's frame)
/// against the 6 P2 basis functions of contact triangle `t`.
pub type FaceLoad<'a> = dyn Fn(usize) -> [[f64; 3]; 6] + 'a;

/// Load vector of a face traction in the numbering `dofs` (this rank's triangles: those
/// whose tetrahedron `rank` owns).
pub fn assemble_face_traction(
    comm: ffi::MPI_Comm,
    mesh: &Mesh,
    part: &Partition,
    dofs: &DofMap,
    rank: usize,
    load: &FaceLoad,
) -> petsc::Result<Vector> {
    let b = Vector::new(comm, dofs.local(rank))?;
    b.set_all(0.0)?;
    for (t, tri) in mesh.contact_tris.iter().enumerate() {
        if part.tet_rank[mesh.contact_tri_tet[t] as usize] as usize != rank {
            continue;
        }
        let fe = load(t);
        let mut idx = Vec::with_capacity(18);
        let mut val = Vec::with_capacity(18);
        for i in 0..6 {
            for c in 0..3 {
                let d = dofs.node_dof[tri[i] as usize][c];
                if d >= 0 && fe[i][c] != 0.0 {
                    idx.push(d);
                    val.push(fe[i][c]);
                }
            }
        }
        b.set_values(&idx, &val, true)?;
    }
    b.assemble()?;
    Ok(b)
}

/// The per-node displacement `[u_x, u_y, u_z]` (0 on constrained components) of a gathered
/// solution in the numbering `dofs`.
pub fn node_displacements(dofs: &DofMap, sol: &[f64], scale: f64) -> Vec<[f64; 3]> {
    dofs.node_dof.iter().map(|d| d.map(|i| if i < 0 { 0.0 } else { scale * sol[i as usize] })).collect()
}

/// A displacement `[u_x, u_y, u_z]` per mesh node.
pub type NodeField = Vec<[f64; 3]>;

/// Cost of the extra elastic solve.
#[derive(Debug, Clone, Copy, Default)]
pub struct SolveCost {
    pub seconds: f64,
    /// Resident memory added while the factorisation was alive (MB; freed memory the
    /// allocator reuses does not show).
    pub rss_increase_mb: f64,
    /// Memory of the MUMPS factorisation (MB, INFOG(22)).
    pub factor_mb: Option<f64>,
    pub unknowns: usize,
}

/// Current resident set size (MB) from /proc/self/statm (NaN where unavailable).
pub fn current_rss_mb() -> f64 {
    let page = unsafe { libc::sysconf(libc::_SC_PAGESIZE) } as f64;
    std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().nth(1).and_then(|v| v.parse::<f64>().ok()))
        .map(|pages| pages * page / 1048576.0)
        .unwrap_or(f64::NAN)
}

/// Options prefix of the subsurface elastic solve (`-subsurface_ksp_type`, ...).
pub const PREFIX: &str = "subsurface_";

/// Solves the elastic problem of the disc (unit Young's modulus, Poisson ratio `nu`) under
/// each face traction of `loads`, on this rank alone (one MUMPS Cholesky on
/// PETSC_COMM_SELF, one back substitution per load). The cost covers the first load.
pub fn solve_alone(mesh: &Mesh, nu: f64, loads: &[&FaceLoad]) -> Result<(Vec<NodeField>, SolveCost), Error> {
    let pe = |e: petsc::PetscError| Error::from(e).context("subsurface elastic solve");
    let t0 = Instant::now();
    let rss0 = current_rss_mb();
    let selfc = unsafe { ffi::RSMPI_COMM_SELF };
    let part = partition(mesh, 1);
    let dofs = DofMap::new(mesh, &part, 1);
    let k = assemble_stiffness(selfc, mesh, &part, &dofs, 0, nu).map_err(pe)?;
    unsafe { ffi::MatSetOption(k.raw(), ffi::MatOption_MAT_SPD, ffi::PetscBool_PETSC_TRUE) };
    petsc::options::set_default(&format!("-{PREFIX}ksp_type"), "preonly").map_err(pe)?;
    petsc::options::set_default(&format!("-{PREFIX}pc_type"), "cholesky").map_err(pe)?;
    petsc::options::set_default(&format!("-{PREFIX}pc_factor_mat_solver_type"), "mumps").map_err(pe)?;
    petsc::options::set_default(&format!("-{PREFIX}mat_mumps_icntl_7"), "4").map_err(pe)?;
    let ksp = Ksp::with_prefix(selfc, &k, PREFIX).map_err(pe)?;
    let mut out = Vec::new();
    let mut cost = SolveCost::default();
    for (i, load) in loads.iter().enumerate() {
        let b = assemble_face_traction(selfc, mesh, &part, &dofs, 0, load).map_err(pe)?;
        let x = Vector::new(selfc, dofs.local(0)).map_err(pe)?;
        ksp.solve(&b, &x).map_err(pe)?;
        if i == 0 {
            cost = SolveCost {
                seconds: t0.elapsed().as_secs_f64(),
                rss_increase_mb: current_rss_mb() - rss0,
                factor_mb: ksp.mumps_factor_mb(),
                unknowns: dofs.total(),
            };
        }
        out.push(node_displacements(&dofs, &x.local_values().map_err(pe)?, 1.0));
    }
    Ok((out, cost))
}

/// What the recovery needs besides the mesh and the displacement.
pub struct Params<'a> {
    /// Poisson ratio of the disc (the stiffness had a unit Young's modulus).
    pub nu: f64,
    /// Young's modulus of the disc (Pa): displacement in m = a p_H / E * the solution.
    pub e: f64,
    pub a: f64,
    pub ph: f64,
    /// The contact rectangle (units of a): the region's extent in x and z.
    pub rect: Rect,
    /// Half domain z <= 0 (sections mirrored).
    pub half: bool,
    pub png: bool,
    pub vtu: bool,
    /// Description of the load (for the log and summary.json).
    pub traction: &'a str,
    pub method: StressRecovery,
}

/// The recovered field on the region under the contact.
pub struct Recovered<'a> {
    pub mesh: &'a Mesh,
    /// Tetrahedra of the region (centroid inside the rectangle, depth <= [`REGION_DEPTH`]).
    pub tets: Vec<usize>,
    /// Recovered stress per node (units of p_H; zero off the region).
    pub nodal: Vec<Sym>,
    /// Tetrahedra evaluated by the recovery (the region and its neighbours).
    pub evaluated: usize,
}

/// A maximum of a scalar of the stress field: value and position (units of a).
#[derive(Debug, Clone, Copy)]
pub struct Extremum {
    pub value: f64,
    pub at: [f64; 3],
    /// The full tensor there.
    pub stress: Sym,
}

impl<'a> Recovered<'a> {
    /// Recovers the stresses of the region from the per-node displacement `u`.
    pub fn new(mesh: &'a Mesh, u: &[[f64; 3]], nu: f64, rect: &Rect, method: StressRecovery) -> Recovered<'a> {
        let tets: Vec<usize> = (0..mesh.tets.len())
            .filter(|&t| {
                let v = mesh.tet_corners(t);
                let c: [f64; 3] = std::array::from_fn(|k| v.iter().map(|p| p[k]).sum::<f64>() / 4.0);
                c[0] >= rect.x0 && c[0] <= rect.x1 && c[2] >= rect.z0 && c[2] <= rect.z1 && -c[1] <= REGION_DEPTH
            })
            .collect();
        let mut wanted = vec![false; mesh.nodes.len()];
        for &t in &tets {
            for &n in &mesh.tets[t] {
                wanted[n as usize] = true;
            }
        }
        let (lambda, mu) = lame(1.0, nu);
        let verts = |t: usize| tet_vertices(mesh, &mesh.tets[t]);
        let ue = |t: usize| {
            let mut out = [0.0; 30];
            for (k, &n) in mesh.tets[t].iter().enumerate() {
                out[3 * k..3 * k + 3].copy_from_slice(&u[n as usize]);
            }
            out
        };
        let (nodal, evaluated) = match method {
            StressRecovery::Spr => recover_spr(&mesh.nodes, mesh.n_vertices, &mesh.tets, &verts, &ue, &wanted, lambda, mu),
            StressRecovery::Average => recover_nodal(mesh.nodes.len(), &mesh.tets, &verts, &ue, &wanted, lambda, mu),
        };
        Recovered { mesh, tets, nodal, evaluated }
    }

    fn tet_nodal(&self, t: usize) -> [Sym; 10] {
        self.mesh.tets[t].map(|n| self.nodal[n as usize])
    }

    /// Barycentric coordinates of `p` in tet `t`.
    fn bary(&self, t: usize, p: [f64; 3]) -> [f64; 4] {
        let geo = crate::fem::geometry::AffineTet::new(&self.mesh.tet_corners(t));
        let v0 = self.mesh.tet_corners(t)[0];
        let mut l = [0.0; 4];
        for k in 1..4 {
            l[k] = (0..3).map(|c| geo.grad_bary[k][c] * (p[c] - v0[c])).sum();
        }
        l[0] = 1.0 - l[1] - l[2] - l[3];
        l
    }

    /// The recovered stress at `p` (units of a), if `p` lies in the region.
    pub fn at(&self, p: [f64; 3]) -> Option<Sym> {
        for &t in &self.tets {
            let v = self.mesh.tet_corners(t);
            let inside_box = (0..3).all(|c| {
                let lo = v.iter().map(|q| q[c]).fold(f64::INFINITY, f64::min);
                let hi = v.iter().map(|q| q[c]).fold(f64::NEG_INFINITY, f64::max);
                p[c] >= lo - 1e-12 && p[c] <= hi + 1e-12
            });
            if !inside_box {
                continue;
            }
            let l = self.bary(t, p);
            if l.iter().all(|&x| x >= -1e-10) {
                return Some(eval_p2(&self.tet_nodal(t), l));
            }
        }
        None
    }

    /// The maximum of `f` over the region: over its nodes first, then refined on a lattice
    /// of 8 subdivisions per edge in the tetrahedra around the best node.
    pub fn maximum(&self, f: &dyn Fn(&Sym) -> f64) -> Extremum {
        let mut best = (f64::NEG_INFINITY, 0u32);
        for &t in &self.tets {
            for &n in &self.mesh.tets[t] {
                let v = f(&self.nodal[n as usize]);
                if v > best.0 {
                    best = (v, n);
                }
            }
        }
        let mut ext = Extremum { value: best.0, at: self.mesh.nodes[best.1 as usize], stress: self.nodal[best.1 as usize] };
        const K: usize = 8;
        for &t in self.tets.iter().filter(|&&t| self.mesh.tets[t].contains(&best.1)) {
            let nodal = self.tet_nodal(t);
            let v = self.mesh.tet_corners(t);
            for i in 0..=K {
                for j in 0..=K - i {
                    for k in 0..=K - i - j {
                        let l = [i as f64 / K as f64, j as f64 / K as f64, k as f64 / K as f64, (K - i - j - k) as f64 / K as f64];
                        let s = eval_p2(&nodal, l);
                        let val = f(&s);
                        if val > ext.value {
                            ext = Extremum { value: val, at: std::array::from_fn(|c| (0..4).map(|q| l[q] * v[q][c]).sum()), stress: s };
                        }
                    }
                }
            }
        }
        ext
    }

    /// The maximum of `f` on the plane z = `zc` within `radius` of (x, y) (units of a): a
    /// lattice of step 0.01 a, refined with step 0.002 a around the best point, and placed
    /// at the vertex of the quadratic fitted to the field within [`PEAK_BAND`] of it.
    pub fn maximum_on_plane(&self, f: &dyn Fn(&Sym) -> f64, zc: f64, around: [f64; 2], radius: f64) -> Option<Extremum> {
        let mut best: Option<Extremum> = None;
        let scan = |c: [f64; 2], r: f64, h: f64, best: &mut Option<Extremum>| {
            let n = (r / h).round() as i64;
            for i in -n..=n {
                for j in -n..=n {
                    let p = [c[0] + i as f64 * h, (c[1] + j as f64 * h).min(0.0), zc];
                    if let Some(s) = self.at(p) {
                        let v = f(&s);
                        if best.as_ref().map_or(true, |b| v > b.value) {
                            *best = Some(Extremum { value: v, at: p, stress: s });
                        }
                    }
                }
            }
        };
        scan(around, radius, 0.01, &mut best);
        let c = best.as_ref().map(|b| [b.at[0], b.at[1]])?;
        scan(c, 0.02, 0.002, &mut best);
        // The position: the vertex of the quadratic fitted to the field within PEAK_BAND of
        // the largest value (lattice 0.01 a). A flat maximum's largest sample follows the
        // field's error from element to element (0.05-0.1 % moves it by 0.01-0.03 a:
        // docs/subsurface.md); the fit averages it over the band. On Hamilton's exact field
        // this estimator is 0.0006-0.0017 a from the maximum (unit test in solid::stress).
        let top = best.as_ref()?.value;
        let mut samples = Vec::new();
        let n = (radius / 0.01).round() as i64;
        for i in -n..=n {
            for j in -n..=n {
                let (x, y) = (c[0] + i as f64 * 0.01, c[1] + j as f64 * 0.01);
                if let (true, Some(s)) = (y <= 0.0, self.at([x, y, zc])) {
                    let v = f(&s);
                    if v >= (1.0 - PEAK_BAND) * top {
                        samples.push(([x, y], v));
                    }
                }
            }
        }
        let (lo, hi) = samples.iter().fold(([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]), |(lo, hi), s| {
            ([lo[0].min(s.0[0]), lo[1].min(s.0[1])], [hi[0].max(s.0[0]), hi[1].max(s.0[1])])
        });
        match peak_vertex(&samples) {
            Some(v) if (lo[0]..=hi[0]).contains(&v[0]) && (lo[1]..=hi[1]).contains(&v[1]) => {
                let p = [v[0], v[1], zc];
                self.at(p).map(|s| Extremum { value: f(&s), at: p, stress: s }).or(best)
            }
            _ => best,
        }
    }

    /// Triangles of the section of the region by the plane `coordinate[axis] = c` (in the
    /// plane's 2D coordinates (`plane` picks them) and values of `f` at their corners),
    /// each cut polygon split into triangles and each triangle into 4 (P2 values at the
    /// edge midpoints). `flip`: classify the vertices from the other side (a section lying
    /// on the boundary face z = 0 of a half domain).
    pub fn section(
        &self,
        axis: usize,
        c: f64,
        flip: bool,
        plane: [usize; 2],
        f: &dyn Fn(&Sym) -> f64,
    ) -> (Vec<[[f64; 2]; 3]>, Vec<[f64; 3]>) {
        let (mut tris, mut vals) = (Vec::new(), Vec::new());
        for &t in &self.tets {
            let v = self.mesh.tet_corners(t);
            let d = v.map(|p| if flip { c - p[axis] } else { p[axis] - c });
            let pos: Vec<usize> = (0..4).filter(|&k| d[k] > 0.0).collect();
            let neg: Vec<usize> = (0..4).filter(|&k| d[k] <= 0.0).collect();
            if pos.is_empty() || neg.is_empty() {
                continue;
            }
            let cut = |i: usize, j: usize| -> [f64; 4] {
                let s = d[i] / (d[i] - d[j]);
                let mut l = [0.0; 4];
                l[i] = 1.0 - s;
                l[j] = s;
                l
            };
            let polys: Vec<[[f64; 4]; 3]> = match (neg.len(), pos.len()) {
                (1, 3) => vec![[cut(neg[0], pos[0]), cut(neg[0], pos[1]), cut(neg[0], pos[2])]],
                (3, 1) => vec![[cut(pos[0], neg[0]), cut(pos[0], neg[1]), cut(pos[0], neg[2])]],
                _ => {
                    let q = [cut(neg[0], pos[0]), cut(neg[0], pos[1]), cut(neg[1], pos[1]), cut(neg[1], pos[0])];
                    vec![[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
                }
            };
            let nodal = self.tet_nodal(t);
            let to2d = |l: &[f64; 4]| -> [f64; 2] { plane.map(|k| (0..4).map(|q| l[q] * v[q][k]).sum()) };
            for tri in polys {
                let mid = |a: &[f64; 4], b: &[f64; 4]| -> [f64; 4] { std::array::from_fn(|k| 0.5 * (a[k] + b[k])) };
                let (m01, m12, m20) = (mid(&tri[0], &tri[1]), mid(&tri[1], &tri[2]), mid(&tri[2], &tri[0]));
                for sub in [[tri[0], m01, m20], [m01, tri[1], m12], [m20, m12, tri[2]], [m01, m12, m20]] {
                    tris.push(sub.map(|l| to2d(&l)));
                    vals.push(sub.map(|l| f(&eval_p2(&nodal, l))));
                }
            }
        }
        (tris, vals)
    }
}

/// `sigma_xy`, the orthogonal shear stress (x rolling direction, y normal to the contact).
pub fn tau_xy(s: &Sym) -> f64 {
    s[3]
}

fn extremum_json(name: &str, e: &Extremum, a: f64, ph: f64, out: &mut serde_json::Map<String, serde_json::Value>) {
    out.insert(format!("{name}_pa"), json!(e.value * ph));
    out.insert(format!("{name}_x_m"), json!(e.at[0] * a));
    out.insert(format!("{name}_y_m"), json!(e.at[1] * a));
    out.insert(format!("{name}_z_m"), json!(e.at[2] * a));
    out.insert(format!("{name}_depth_m"), json!(-e.at[1] * a));
}

/// Recovery, outputs and the `subsurface` object of summary.json (rank 0). `u`: per-node
/// displacement of the elastic solve (unit Young's modulus, traction in units of p_H).
pub fn recover_and_write(mesh: &Mesh, u: &[[f64; 3]], p: &Params, dir: &Path, log: &dyn Fn(String)) -> Result<serde_json::Value, Error> {
    let t0 = Instant::now();
    let rec = Recovered::new(mesh, u, p.nu, &p.rect, p.method);
    let recovery_s = t0.elapsed().as_secs_f64();
    let (a, ph) = (p.a, p.ph);
    let vm = rec.maximum(&von_mises);
    let tr = rec.maximum(&tresca);
    let txy = rec.maximum(&|s: &Sym| tau_xy(s).abs());
    let pmin = rec.maximum(&|s: &Sym| -principal(s)[2]);
    let mut obj = serde_json::Map::new();
    obj.insert("body".into(), json!("disc"));
    obj.insert("poisson_ratio".into(), json!(p.nu));
    obj.insert("surface_traction".into(), json!(p.traction));
    obj.insert("recovery".into(), json!(p.method.as_str()));
    obj.insert("region".into(), json!({ "x_min_m": p.rect.x0 * a, "x_max_m": p.rect.x1 * a, "z_min_m": p.rect.z0 * a, "z_max_m": p.rect.z1 * a, "depth_m": REGION_DEPTH * a, "tetrahedra": rec.tets.len() }));
    extremum_json("von_mises_max", &vm, a, ph, &mut obj);
    extremum_json("tresca_max", &tr, a, ph, &mut obj);
    extremum_json("tau_xy_max", &txy, a, ph, &mut obj);
    obj.insert("tau_xy_max_signed_pa".into(), json!(tau_xy(&txy.stress) * ph));
    extremum_json("compression_max", &pmin, a, ph, &mut obj);
    // The von Mises maximum on the plane z = 0 through the contact centre (the plane of the
    // x-y maps; the plane of symmetry of a symmetric load), searched near the 3D maximum.
    if let Some(e) = rec.maximum_on_plane(&von_mises, 0.0, [vm.at[0], vm.at[1]], 0.3) {
        extremum_json("von_mises_max_z0", &e, a, ph, &mut obj);
    }
    log(format!(
        "subsurface ({}): von Mises max {:.4e} Pa at ({:.3}a, depth {:.3}a, {:.3}a); Tresca max {:.4e} Pa at depth {:.3}a; |tau_xy| max {:.4e} Pa at ({:.3}a, depth {:.3}a)",
        p.traction, vm.value * ph, vm.at[0], -vm.at[1], vm.at[2], tr.value * ph, -tr.at[1], txy.value * ph, txy.at[0], -txy.at[1]
    ));
    // The stresses along the axis x = z = 0, depth 0 to REGION_DEPTH.
    let t1 = Instant::now();
    let mut csv = String::from("depth_m,sxx_pa,syy_pa,szz_pa,sxy_pa,syz_pa,sxz_pa,von_mises_pa,tresca_pa\n");
    for i in 0..=300 {
        let d = REGION_DEPTH * i as f64 / 300.0;
        if let Some(s) = rec.at([0.0, -d, 0.0]) {
            csv.push_str(&format!("{:e}", d * a));
            for c in s {
                csv.push_str(&format!(",{:e}", c * ph));
            }
            csv.push_str(&format!(",{:e},{:e}\n", von_mises(&s) * ph, tresca(&s) * ph));
        }
    }
    let path = dir.join("subsurface_axis.csv");
    crate::output::write_atomic(&path, csv.as_bytes()).map_err(Error::writing(&path))?;
    if p.vtu {
        write_region_vtu(&rec, u, p, &dir.join("subsurface.vtu"))?;
    }
    if p.png {
        write_sections(&rec, p, dir, &vm, &txy)?;
    }
    obj.insert("recovery_s".into(), json!(recovery_s));
    obj.insert("output_s".into(), json!(t1.elapsed().as_secs_f64()));
    obj.insert("tetrahedra_evaluated".into(), json!(rec.evaluated));
    Ok(serde_json::Value::Object(obj))
}

/// The maxima of a second load case (no outputs): the `subsurface` object's maxima keys.
pub fn maxima_only(mesh: &Mesh, u: &[[f64; 3]], p: &Params) -> serde_json::Value {
    let rec = Recovered::new(mesh, u, p.nu, &p.rect, p.method);
    let mut obj = serde_json::Map::new();
    obj.insert("surface_traction".into(), json!(p.traction));
    extremum_json("von_mises_max", &rec.maximum(&von_mises), p.a, p.ph, &mut obj);
    extremum_json("tresca_max", &rec.maximum(&tresca), p.a, p.ph, &mut obj);
    let txy = rec.maximum(&|s: &Sym| tau_xy(s).abs());
    extremum_json("tau_xy_max", &txy, p.a, p.ph, &mut obj);
    obj.insert("tau_xy_max_signed_pa".into(), json!(tau_xy(&txy.stress) * p.ph));
    serde_json::Value::Object(obj)
}

fn write_region_vtu(rec: &Recovered, u: &[[f64; 3]], p: &Params, path: &Path) -> Result<(), Error> {
    let mesh = rec.mesh;
    let mut id = vec![u32::MAX; mesh.nodes.len()];
    let mut points = Vec::new();
    let (mut disp, mut stress, mut vm, mut tr, mut txy, mut pr) = (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let uscale = p.a * p.ph / p.e;
    let mut conn = Vec::with_capacity(10 * rec.tets.len());
    for &t in &rec.tets {
        for &n in &mesh.tets[t] {
            if id[n as usize] == u32::MAX {
                id[n as usize] = points.len() as u32;
                let c = mesh.nodes[n as usize];
                points.push(c.map(|v| v * p.a));
                disp.extend(u[n as usize].map(|v| v * uscale));
                let s = rec.nodal[n as usize];
                stress.extend(s.map(|v| v * p.ph));
                vm.push(von_mises(&s) * p.ph);
                tr.push(tresca(&s) * p.ph);
                txy.push(tau_xy(&s) * p.ph);
                pr.extend(principal(&s).map(|v| v * p.ph));
            }
            conn.push(id[n as usize]);
        }
    }
    let fields = [
        Field { name: "displacement_m", components: 3, values: &disp },
        Field { name: "stress_pa", components: 6, values: &stress },
        Field { name: "von_mises_pa", components: 1, values: &vm },
        Field { name: "tresca_pa", components: 1, values: &tr },
        Field { name: "tau_xy_pa", components: 1, values: &txy },
        Field { name: "principal_pa", components: 3, values: &pr },
    ];
    crate::output::write_atomic_with(path, |t| {
        write_vtu_single_type(t, &points, VTK_QUADRATIC_TETRA, &conn, &fields, &[]).map_err(Error::writing(t))
    })
}

/// PNG maps of von Mises and tau_xy on the sections z = 0 (x-y plane) and x = 0 (z-y plane).
fn write_sections(rec: &Recovered, p: &Params, dir: &Path, vm: &Extremum, txy: &Extremum) -> Result<(), Error> {
    use crate::output::plot::{map_plot, MapOpts};
    let ph_mpa = p.ph * 1e-6;
    let depth = 2.0_f64.min(REGION_DEPTH);
    type Scalar = fn(&Sym) -> f64;
    let fields: [(&str, &str, Scalar, bool, &Extremum); 2] =
        [("von_mises", "von Mises stress", von_mises, false, vm), ("tau_xy", "orthogonal shear stress tau_xy", tau_xy, true, txy)];
    for (key, title, f, diverging, ext) in fields {
        let g = |s: &Sym| f(s) * ph_mpa;
        // x-y section through the contact centre (z = 0).
        let (tris, vals) = rec.section(2, 0.0, p.half, [0, 1], &g);
        let opts = MapOpts {
            colorbar_label: format!("{title} (MPa)"),
            diverging,
            x_range: Some((p.rect.x0.max(-2.5), p.rect.x1.min(2.5))),
            y_range: Some((-depth, 0.0)),
            circle: Some((ext.at[0], ext.at[1], 0.03)),
            height: 520,
            ..MapOpts::default()
        };
        let path = dir.join(format!("subsurface_{key}_xy.png"));
        crate::output::write_atomic_with(&path, |t| {
            map_plot(
                t,
                &format!("{title}, section z = 0 (circle: the maximum)"),
                "x / a",
                "y / a (depth below the contact)",
                &tris,
                &vals,
                &opts,
            )
        })?;
        // z-y section through the contact centre (x = 0); a half domain is mirrored.
        let (mut tris, mut vals) = rec.section(0, 0.0, false, [2, 1], &g);
        if p.half {
            for i in 0..tris.len() {
                let t = tris[i].map(|q| [-q[0], q[1]]);
                tris.push(t);
                vals.push(vals[i]);
            }
        }
        let opts = MapOpts {
            x_range: Some((p.rect.z0.max(-2.5), (if p.half { -p.rect.z0 } else { p.rect.z1 }).min(2.5))),
            circle: (ext.at[0].abs() < 0.05).then_some((ext.at[2], ext.at[1], 0.03)),
            ..opts
        };
        let path = dir.join(format!("subsurface_{key}_zy.png"));
        crate::output::write_atomic_with(&path, |t| {
            map_plot(t, &format!("{title}, section x = 0"), "z / a", "y / a (depth below the contact)", &tris, &vals, &opts)
        })?;
    }
    Ok(())
}
