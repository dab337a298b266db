//! The monolithic EHL system: residual and exact Jacobian of
//!   elasticity:      K U + c M^T P = 0                    (U rows; c = E'/(pi E_eq))
//!   Reynolds:        R(P, H(U, H0)) + penalty(P) = 0       (P rows)
//!   load balance:    integral of P over the Reynolds domain - W = 0   (H0 row)
//! with the film H = H0 + (X^2 + Z^2)/2 - U_y (docs/model.md section 5, dimensionless).
//! Only the Reynolds rows depend on the iterate, so after the first assembly the Jacobian
//! keeps its U and H0 rows and only the P rows are zeroed and refilled.
use super::layout::Layout;
use crate::fem::p2tri::{p2_tri_mass, p2_tri_weights, tri_area};
use crate::mesh::{Mesh, Partition};
use crate::pcall;
use crate::petsc::snes::{Eval, Problem};
use crate::petsc::{ffi, Matrix, Result, Vector};
use crate::reynolds::element::{reynolds_element, reynolds_element_with_multiplier, ElementOut, Fluid, Stabilisation};
use crate::reynolds::jump::{interior_edges, EdgeJump, JumpRows};
use crate::reynolds::multiplier::{FaceElement, Multipliers};
use crate::solid::dofmap::DofMap;
use mpi::topology::SimpleCommunicator;

pub use crate::reynolds::cavitation::{clip_pressure_step, complementarity, penalty_law, CAVITATION_SMOOTHING, PRESSURE_STEP_FLOOR};

/// The floor of a Newton step's nodal pressure ([`PRESSURE_STEP_FLOOR`]); the options
/// `-ehl_pressure_step_floor VALUE` and `-ehl_pressure_step_clip false` change it.
pub fn pressure_step_floor() -> Option<f64> {
    crate::ehl_options::get().pressure_step_floor
}

/// Lubricant laws in dimensionless form: eta_bar(P), rho_bar(P) with their P-derivatives.
pub struct Lubricant {
    pub eta: Box<dyn Fn(f64) -> (f64, f64) + Send + Sync>,
    pub rho: Box<dyn Fn(f64) -> (f64, f64) + Send + Sync>,
    /// Second derivatives (needed by the exact Jacobian of the SUPG term).
    pub d2eta: Box<dyn Fn(f64) -> f64 + Send + Sync>,
    pub d2rho: Box<dyn Fn(f64) -> f64 + Send + Sync>,
}

impl Lubricant {
    /// The laws as the Reynolds element takes them, with the speed parameter lambda_bar.
    pub fn fluid(&self, lambda_bar: f64) -> Fluid<'_> {
        Fluid { eta: &*self.eta, rho: &*self.rho, d2eta: &*self.d2eta, d2rho: &*self.d2rho, lambda_bar }
    }

    /// Why the nodal pressures `p` are outside the laws' domain, if they are: one is not a
    /// number, or the viscosity or its derivatives overflow at the largest (Barus at
    /// alpha p_H = 34 beyond P = 20). The residual stays finite there (eps -> 0), but the
    /// Jacobian holds inf/inf = NaN, and a Newton direction through it makes every step of
    /// the line search NaN. The margin covers a P2 interpolant's overshoot of its nodal
    /// values between the nodes.
    pub fn out_of_range(&self, p: impl IntoIterator<Item = f64>) -> Option<String> {
        let p_max = p.into_iter().fold(f64::NEG_INFINITY, |m, v| if m.is_nan() || v.is_nan() { f64::NAN } else { m.max(v) });
        let p = 1.5 * p_max.max(0.0);
        let (eta, deta) = (self.eta)(p);
        let ok = [eta, deta, (self.d2eta)(p), (self.rho)(p).0, (self.rho)(p).1, (self.d2rho)(p)].iter().all(|v| v.is_finite());
        (!ok || !p_max.is_finite()).then(|| format!("nodal pressure P = {p_max:.3e} p_H, beyond what the lubricant laws can evaluate"))
    }
}

/// Everything the EHL residual needs besides the iterate.
pub struct EhlParams {
    /// lambda_bar = 12 eta_R Ue R^2 / (a^3 p_H).
    pub lambda_bar: f64,
    /// Traction factor c = E'/(pi E_eq).
    pub traction: f64,
    /// Load target W = integral of P (2 pi / 3 on the full domain, pi / 3 on a half domain).
    pub load: f64,
    /// Cavitation penalty factor xi (dimensionless, per unit nodal area).
    pub penalty: f64,
    pub stabilisation: Stabilisation,
    /// Dimensionless entrainment velocity (Um, Wm)/Ue as a function of (X, Z).
    pub velocity: Box<dyn Fn(f64, f64) -> [f64; 2] + Send + Sync>,
    /// Poisson ratio of the equivalent solid.
    pub nu: f64,
}

impl EhlParams {
    /// What is added to a Reynolds row's diagonal before it scales the row: 1e-6 xi. It caps
    /// the scale of the contact's rows (diagonals down to 1e-11 under exp(alpha p)), whose
    /// residual is a sum of O(1) terms: scaled by 1e11 its round-off alone is 1e-5. The
    /// complementarity form has no xi and keeps the floor of the penalty solve at xi = 1e3
    /// that starts it (without it Newton stalled at residual norms of 2e-6 on
    /// cases/examples/barus-newtonian, and the Jacobian's norm was 4.8e7 instead of 2e3).
    pub fn row_scale_floor(&self) -> f64 {
        if self.stabilisation.complementarity {
            1e-3
        } else {
            self.penalty * 1e-6
        }
    }

    /// A new operating point: the speed parameter, the cavitation penalty (which the SUPG
    /// strong residual carries too) and whether cavitation is the complementarity form.
    pub fn set_operating(&mut self, lambda_bar: f64, penalty: f64, complementarity: bool) {
        self.lambda_bar = lambda_bar;
        self.penalty = penalty;
        self.stabilisation.complementarity = complementarity;
        self.stabilisation.penalty = penalty;
    }
}

/// The iterate of the last complementarity residual and, per owned P row, the
/// complementarity function's derivatives in P and F there.
struct Cavitated {
    at: Vec<f64>,
    slopes: Vec<(f64, f64)>,
}

/// One contact triangle as the Reynolds assembly sees it.
struct ContactElement {
    nodes: [u32; 6],
    verts: [[f64; 2]; 3],
    vel: [[f64; 2]; 3],
    /// (X^2 + Z^2)/2 at the 6 nodes: the rigid gap of the ball.
    gap: [f64; 6],
    area: f64,
}

/// The gradient-jump terms of the contact edges whose first triangle passes `mine`, with
/// the coefficient `c_j` (none when it is 0): (triangle A, triangle B, the edge's term).
pub(crate) fn jump_terms_of(mesh: &Mesh, c_j: f64, mine: impl Fn(usize) -> bool) -> Vec<(usize, usize, EdgeJump)> {
    if c_j <= 0.0 {
        return Vec::new();
    }
    interior_edges(&mesh.contact_tris)
        .into_iter()
        .filter(|&(a, _, _)| mine(a))
        .map(|(a, b, e)| {
            (a, b, EdgeJump::new(&mesh.contact_tris[a], &mesh.contact_tri_xz(a), &mesh.contact_tris[b], &mesh.contact_tri_xz(b), e))
        })
        .collect()
}

/// The EHL problem on one rank.
pub struct EhlSystem<'a> {
    pub world: &'a SimpleCommunicator,
    pub mesh: &'a Mesh,
    pub part: &'a Partition,
    pub dofs: &'a DofMap,
    pub layout: &'a Layout,
    pub rank: usize,
    pub params: EhlParams,
    pub lubricant: Lubricant,
    /// Stiffness in the displacement-only numbering of `dofs` (for K U).
    stiffness: Matrix,
    elements: Vec<ContactElement>,
    /// Every contact triangle (all ranks'), with the nodal cavitation multipliers measured
    /// on them, when the scene's cavitation is the complementarity form.
    face: Option<(Vec<ContactElement>, Multipliers)>,
    /// Gradient-jump terms of the interior contact edges whose first triangle is this rank's.
    jumps: Vec<JumpRows>,
    /// Nodal penalty weights (area of the node's share of its triangles) of owned P nodes.
    penalty_nodes: Vec<(i32, u32, f64)>,
    jacobian_built: bool,
    /// Global P rows this rank owns (zeroed and refilled at each Jacobian).
    p_rows: Vec<i32>,
    /// Complementarity cavitation: the iterate of the last residual and, per owned P row,
    /// the complementarity function's derivatives in P and F there.
    cavitated: Option<Cavitated>,
    u_work: Vector,
    ku_work: Vector,
    /// Counters for reports.
    pub residual_evals: usize,
    pub jacobian_evals: usize,
    /// Step-limiter factors applied at each Newton step (1 = full Newton step).
    pub step_limits: Vec<f64>,
    /// Where (X, Z) the film closed in the last solve, if it did (see
    /// [`super::step::FILM_COLLAPSE`]).
    pub collapse: Option<[f64; 2]>,
    /// Constant scale of each Reynolds row (indexed by global row), 1 by default; see
    /// [`EhlSystem::scale_rows`].
    row_scale: std::collections::HashMap<i32, f64>,
}

impl<'a> EhlSystem<'a> {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        world: &'a SimpleCommunicator,
        mesh: &'a Mesh,
        part: &'a Partition,
        dofs: &'a DofMap,
        layout: &'a Layout,
        rank: usize,
        params: EhlParams,
        lubricant: Lubricant,
        stiffness: Matrix,
    ) -> Result<Self> {
        let element = |tri: &[u32; 6]| {
            let xz = |n: u32| {
                let c = mesh.nodes[n as usize];
                [c[0], c[2]]
            };
            let verts = [xz(tri[0]), xz(tri[1]), xz(tri[2])];
            let vel = verts.map(|v| (params.velocity)(v[0], v[1]));
            let gap = tri.map(|n| Layout::gap(mesh.nodes[n as usize]));
            ContactElement { nodes: *tri, verts, vel, gap, area: tri_area(&verts) }
        };
        let elements = (0..mesh.contact_tris.len())
            .filter(|&t| part.tet_rank[mesh.contact_tri_tet[t] as usize] as usize == rank)
            .map(|t| element(&mesh.contact_tris[t]))
            .collect();
        let face = params.stabilisation.complementarity.then(|| {
            let all: Vec<ContactElement> = mesh.contact_tris.iter().map(element).collect();
            let areas: Vec<f64> = all.iter().map(|e| e.area).collect();
            let multipliers = Multipliers::new(&mesh.contact_tris, &areas);
            (all, multipliers)
        });
        let c_j = params.stabilisation.jump;
        let jumps = jump_terms_of(mesh, c_j, |a| part.tet_rank[mesh.contact_tri_tet[a] as usize] as usize == rank)
            .into_iter()
            .map(|(_, _, edge)| {
                let rows = edge.nodes.iter().map(|&n| layout.p[n as usize]).collect();
                JumpRows::new(edge, rows, c_j, &*params.velocity)
            })
            .collect();
        // Nodal areas for the penalty, from all contact triangles (every rank sees the mesh).
        let mut node_area = std::collections::HashMap::<u32, f64>::new();
        for tri in &mesh.contact_tris {
            let xz = |n: u32| {
                let c = mesh.nodes[n as usize];
                [c[0], c[2]]
            };
            let a = tri_area(&[xz(tri[0]), xz(tri[1]), xz(tri[2])]);
            for &n in tri {
                *node_area.entry(n).or_insert(0.0) += a / 6.0;
            }
        }
        let (lo, hi) = (layout.ranges[rank] as i32, layout.ranges[rank + 1] as i32);
        let mut penalty_nodes: Vec<(i32, u32, f64)> = mesh
            .contact_nodes
            .iter()
            .filter_map(|&n| {
                let d = layout.p[n as usize];
                (d >= lo && d < hi).then(|| (d, n, node_area[&n]))
            })
            .collect();
        penalty_nodes.sort_unstable_by_key(|e| e.0);
        let p_rows = penalty_nodes.iter().map(|e| e.0).collect();
        let comm = crate::petsc::comm_world();
        let u_work = Vector::new(comm, dofs.local(rank))?;
        let ku_work = u_work.duplicate()?;
        Ok(EhlSystem {
            world,
            mesh,
            part,
            dofs,
            layout,
            rank,
            params,
            lubricant,
            stiffness,
            elements,
            face,
            jumps,
            penalty_nodes,
            jacobian_built: false,
            p_rows,
            cavitated: None,
            u_work,
            ku_work,
            residual_evals: 0,
            jacobian_evals: 0,
            step_limits: Vec::new(),
            collapse: None,
            row_scale: std::collections::HashMap::new(),
        })
    }

    /// The factor of every scaled row (the Reynolds rows after `scale_rows`), as
    /// (global row, factor); rows not listed are unscaled.
    pub fn row_scales(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.row_scale.iter().map(|(&d, &s)| (d as usize, s))
    }

    fn scale_of(&self, row: i32) -> f64 {
        if row < 0 {
            return 0.0;
        }
        *self.row_scale.get(&row).unwrap_or(&1.0)
    }

    /// Nodal film thickness H = H0 + gap - U_y at the 6 nodes of a contact element.
    fn element_film(&self, x: &[f64], e: &ContactElement) -> [f64; 6] {
        let h0 = x[self.layout.h0 as usize];
        std::array::from_fn(|i| h0 + e.gap[i] - self.layout.uy(x, e.nodes[i]))
    }

    fn element_pressure(&self, x: &[f64], e: &ContactElement) -> [f64; 6] {
        e.nodes.map(|n| Layout::value(x, self.layout.p[n as usize]))
    }

    fn fluid(&self) -> Fluid<'_> {
        self.lubricant.fluid(self.params.lambda_bar)
    }

    /// Contact triangle `e` with its fields at `x`, as the multiplier sees it.
    fn face_element<'e>(&self, x: &[f64], e: &'e ContactElement) -> FaceElement<'e> {
        FaceElement { nodes: &e.nodes, verts: &e.verts, vel: &e.vel, p: self.element_pressure(x, e), h: self.element_film(x, e) }
    }

    /// Measures the nodal cavitation multipliers at `x` when SUPG needs them (complementarity).
    fn measure_multipliers(&mut self, x: &[f64]) {
        if !(self.params.stabilisation.complementarity && self.params.stabilisation.supg) {
            return;
        }
        let Some((all, mut m)) = self.face.take() else { return };
        m.evaluate(all.len(), |t| self.face_element(x, &all[t]), &self.fluid(), &self.params.stabilisation);
        self.face = Some((all, m));
    }

    /// The Reynolds element at `x`, with the cavitation multipliers when they are measured.
    fn reynolds(&self, x: &[f64], e: &ContactElement, fluid: &Fluid) -> ElementOut {
        let (p, h) = (self.element_pressure(x, e), self.element_film(x, e));
        let stab = &self.params.stabilisation;
        match &self.face {
            Some((_, m)) if stab.complementarity && stab.supg => {
                reynolds_element_with_multiplier(&e.verts, &p, &h, &e.vel, fluid, stab, &m.of(&e.nodes))
            }
            _ => reynolds_element(&e.verts, &p, &h, &e.vel, fluid, stab),
        }
    }

    /// Writes the iterate's displacement block into the displacement-only work vector.
    fn load_u(&self, x: &[f64]) -> Result<()> {
        let base = self.layout.ranges[self.rank];
        self.u_work.set_local_values(&x[base..base + self.layout.n_u[self.rank]])
    }

    /// Adds K (in layout numbering) into J, element by element (first Jacobian only).
    fn add_stiffness(&self, j: &Matrix) -> Result<()> {
        crate::solid::assembly::add_stiffness(j, self.mesh, self.part, self.rank, self.params.nu, |tet| {
            let mut idx = [-1i32; 30];
            for (i, &n) in tet.iter().enumerate() {
                idx[3 * i..3 * i + 3].copy_from_slice(&self.layout.u[n as usize]);
            }
            idx
        })
    }

    /// The constant coupling blocks: c M in the U_y rows and the load-balance row.
    fn add_constant_couplings(&self, j: &Matrix) -> Result<()> {
        for e in &self.elements {
            let m = p2_tri_mass(e.area);
            let rows: [i32; 6] = e.nodes.map(|n| self.layout.u[n as usize][1]);
            let cols: [i32; 6] = e.nodes.map(|n| self.layout.p[n as usize]);
            let vals: Vec<f64> = m.iter().flat_map(|r| r.iter().map(|v| v * self.params.traction)).collect();
            j.add_values(&rows, &cols, &vals)?;
            let w = p2_tri_weights(e.area);
            j.add_values(&[self.layout.h0], &cols, &w)?;
        }
        Ok(())
    }
}

/// What the Newton driver needs of an EHL problem besides residual and Jacobian.
pub trait EhlProblem: Problem {
    /// Changes the operating point seen by the Reynolds rows (for continuation): the
    /// speed parameter lambda_bar and the dimensionless lubricant laws. The elastic rows do
    /// not depend on it.
    /// The cavitation penalty xi enters the penalty rows and the SUPG strong residual.
    /// The operating point: speed, lubricant, cavitation penalty xi and whether the
    /// cavitation condition is the complementarity form.
    fn set_operating(&mut self, lambda_bar: f64, lubricant: Lubricant, penalty: f64, complementarity: bool);
    /// Scales each Reynolds row by the inverse of its Jacobian diagonal at `x` (held constant
    /// afterwards, so the Jacobian stays exact and the solution unchanged). The rows' natural
    /// sizes differ by ten orders of magnitude (eps ~ 1e4 at the inlet, ~1e-9 in the
    /// contact); scaled, the residual norm that the line search watches weighs them alike.
    fn scale_rows(&mut self, x: &[f64]) -> Result<()>;
    /// Replaces the entrainment velocity field (continuation in the tilt angle). Returns
    /// false if the problem does not support it.
    fn set_velocity(&mut self, _velocity: Box<dyn Fn(f64, f64) -> [f64; 2] + Send + Sync>) -> bool {
        false
    }
    /// Where (X, Z in units of a) the last Newton solve stopped because the film closed
    /// (the step limiter drove a nodal film to nothing); cleared by the call.
    fn take_collapse(&mut self) -> Option<[f64; 2]> {
        None
    }
    /// The index of H0 in the state.
    fn h0_index(&self) -> usize;
}

impl EhlProblem for EhlSystem<'_> {
    fn h0_index(&self) -> usize {
        self.layout.h0 as usize
    }
    fn take_collapse(&mut self) -> Option<[f64; 2]> {
        self.collapse.take()
    }
    /// The tilt continuation on the monolithic coupling (as on the condensed one): the
    /// element velocities at the vertices are re-evaluated from the new field.
    fn set_velocity(&mut self, velocity: Box<dyn Fn(f64, f64) -> [f64; 2] + Send + Sync>) -> bool {
        for e in self.elements.iter_mut().chain(self.face.iter_mut().flat_map(|(all, _)| all.iter_mut())) {
            e.vel = e.verts.map(|v| velocity(v[0], v[1]));
        }
        for t in &mut self.jumps {
            t.set_velocity(self.params.stabilisation.jump, &*velocity);
        }
        self.params.velocity = velocity;
        true
    }

    fn set_operating(&mut self, lambda_bar: f64, lubricant: Lubricant, penalty: f64, complementarity: bool) {
        self.params.set_operating(lambda_bar, penalty, complementarity);
        self.lubricant = lubricant;
    }

    fn scale_rows(&mut self, x: &[f64]) -> Result<()> {
        let comm = crate::petsc::comm_world();
        let diag = Vector::new(comm, self.layout.local(self.rank))?;
        diag.set_all(0.0)?;
        let fluid = self.fluid();
        for e in &self.elements {
            let p = self.element_pressure(x, e);
            let h = self.element_film(x, e);
            let out = reynolds_element(&e.verts, &p, &h, &e.vel, &fluid, &self.params.stabilisation);
            let rows: [i32; 6] = e.nodes.map(|n| self.layout.p[n as usize]);
            let d: [f64; 6] = std::array::from_fn(|i| out.dr_dp[i][i].abs());
            diag.set_values(&rows, &d, true)?;
        }
        for t in &self.jumps {
            let d: Vec<f64> = (0..t.rows.len()).map(|i| t.entry(i, i)).collect();
            diag.set_values(&t.rows, &d, true)?;
        }
        diag.assemble()?;
        let all = diag.gather_all()?;
        self.row_scale.clear();
        for n in 0..self.mesh.nodes.len() {
            let d = self.layout.p[n];
            if d >= 0 {
                let v = all[d as usize] + self.params.row_scale_floor();
                self.row_scale.insert(d, if v > 0.0 { 1.0 / v } else { 1.0 });
            }
        }
        Ok(())
    }
}

impl Problem for EhlSystem<'_> {
    fn residual(&mut self, x: &[f64], f: &Vector) -> Result<Eval> {
        self.residual_evals += 1;
        // Physical domain: H > 0 at every node of every owned contact element (collective).
        let mut bad: Option<String> = None;
        for e in &self.elements {
            let h = self.element_film(x, e);
            if let Some(i) = (0..6).find(|&i| !(h[i] > 0.0) || !h[i].is_finite()) {
                let c = self.mesh.nodes[e.nodes[i] as usize];
                bad = Some(format!("film thickness H = {:.3e} at (X, Z) = ({:.3}, {:.3})", h[i], c[0], c[2]));
                break;
            }
        }
        if bad.is_none() {
            bad = self.lubricant.out_of_range(self.layout.p.iter().filter(|&&d| d >= 0).map(|&d| x[d as usize]));
        }
        let any_bad = crate::collective::max_f64(self.world, if bad.is_some() { 1.0 } else { 0.0 });
        if any_bad > 0.0 {
            return Ok(Eval::Domain(bad.unwrap_or_else(|| "non-positive film on another rank".into())));
        }
        // Elastic rows: K U + c M^T P.
        self.load_u(x)?;
        self.stiffness.mult(&self.u_work, &self.ku_work)?;
        let ku = self.ku_work.local_values()?;
        let base = self.layout.ranges[self.rank] as i32;
        let idx: Vec<i32> = (0..ku.len() as i32).map(|i| base + i).collect();
        f.set_values(&idx, &ku, true)?;
        self.measure_multipliers(x);
        let fluid = self.fluid();
        let mut load_part = 0.0;
        for e in &self.elements {
            let p = self.element_pressure(x, e);
            let m = p2_tri_mass(e.area);
            let rows_u: [i32; 6] = e.nodes.map(|n| self.layout.u[n as usize][1]);
            let mut fu = [0.0; 6];
            for i in 0..6 {
                fu[i] = self.params.traction * (0..6).map(|k| m[i][k] * p[k]).sum::<f64>();
            }
            f.set_values(&rows_u, &fu, true)?;
            let w = p2_tri_weights(e.area);
            load_part += (0..6).map(|k| w[k] * p[k]).sum::<f64>();
            // Reynolds rows.
            let out = self.reynolds(x, e, &fluid);
            let rows_p: [i32; 6] = e.nodes.map(|n| self.layout.p[n as usize]);
            let r: [f64; 6] = std::array::from_fn(|i| out.r[i] * self.scale_of(rows_p[i]));
            f.set_values(&rows_p, &r, true)?;
        }
        for t in &self.jumps {
            let r: Vec<f64> = (0..t.rows.len()).map(|a| t.residual_row(a, x) * self.scale_of(t.rows[a])).collect();
            f.set_values(&t.rows, &r, true)?;
        }
        // Cavitation penalty on owned P nodes: xi * area_i * min(P_i, 0).
        for &(d, _n, area) in &self.penalty_nodes {
            let (v, _) = penalty_law(x[d as usize]);
            if v != 0.0 {
                f.set_values(&[d], &[self.scale_of(d) * self.params.penalty * area * v], true)?;
            }
        }
        if crate::ehl_options::get().monitor {
            let mut maxr: f64 = 0.0;
            let mut at = 0;
            let fluid2 = self.fluid();
            for (k, e) in self.elements.iter().enumerate() {
                let p = self.element_pressure(x, e);
                let h = self.element_film(x, e);
                let out = reynolds_element(&e.verts, &p, &h, &e.vel, &fluid2, &self.params.stabilisation);
                let m = out.r.iter().fold(0.0f64, |a, b| a.max(b.abs()));
                if m > maxr {
                    maxr = m;
                    at = k;
                }
            }
            let e = &self.elements[at];
            eprintln!(
                "ehl_monitor: max |R_reynolds| = {maxr:.3e} at element {:?} P = {:?} H = {:?}",
                e.verts,
                self.element_pressure(x, e),
                self.element_film(x, e)
            );
            eprintln!("ehl_monitor: max |KU| = {:.3e}, h0 = {}", ku.iter().fold(0.0f64, |a, b| a.max(b.abs())), x[self.layout.h0 as usize]);
        }
        let target = if self.rank == self.layout.ranges.len() - 2 { -self.params.load } else { 0.0 };
        f.set_values(&[self.layout.h0], &[load_part + target], true)?;
        if self.params.stabilisation.complementarity {
            self.complementarity_rows(x, f)?;
        }
        if crate::ehl_options::get().monitor {
            f.assemble()?;
            let all = f.gather_all()?;
            if self.rank == 0 {
                let (mut nu, mut np, mut worst, mut worst_at) = (0.0f64, 0.0f64, 0.0f64, 0usize);
                for n in 0..self.mesh.nodes.len() {
                    for c in 0..3 {
                        let d = self.layout.u[n][c];
                        if d >= 0 {
                            nu += all[d as usize].powi(2);
                        }
                    }
                    let d = self.layout.p[n];
                    if d >= 0 {
                        np += all[d as usize].powi(2);
                        if all[d as usize].abs() > worst {
                            worst = all[d as usize].abs();
                            worst_at = n;
                        }
                    }
                }
                let c = self.mesh.nodes[worst_at];
                eprintln!(
                    "ehl_monitor: |F_U| = {:.3e} |F_P| = {:.3e} |F_H0| = {:.3e}; worst P row {:.3e} at ({:.3}, {:.3}) P = {:.4} H = {:.4}",
                    nu.sqrt(),
                    np.sqrt(),
                    all[self.layout.h0 as usize].abs(),
                    worst,
                    c[0],
                    c[2],
                    x[self.layout.p[worst_at] as usize],
                    self.layout.film(self.mesh, x, worst_at as u32)
                );
                let st = super::post::FieldsOnFace::new(self.mesh, self.layout, x).stats();
                eprintln!("ehl_monitor: iterate films hc = {:.6e} hm = {:.6e} (H)", st.hc, st.hm);
            }
        }
        Ok(Eval::Ok)
    }

    /// Fraction to the boundary: the Newton update may shrink the film at any contact node
    /// to no less than `FILM_KEEP` of its current value (H stays positive).
    fn clip_step(&mut self, x: &[f64], y: &mut [f64]) -> Result<usize> {
        let Some(floor) = pressure_step_floor() else { return Ok(0) };
        let mut n = 0;
        for &d in self.layout.p.iter().filter(|&&d| d >= 0) {
            let i = d as usize;
            let c = clip_pressure_step(x[i], y[i], floor);
            if c != y[i] {
                y[i] = c;
                n += 1;
            }
        }
        if n > 0 && crate::ehl_options::get().monitor && self.rank == 0 {
            eprintln!("ehl_monitor: pressure step clipped at {n} nodes (floor {floor})");
        }
        Ok(n)
    }

    fn limit_step(&mut self, x: &[f64], y: &[f64]) -> Result<f64> {
        const FILM_KEEP: f64 = 0.2;
        if !crate::ehl_options::get().film_limiter {
            return Ok(1.0);
        }
        let dh0 = y[self.layout.h0 as usize];
        let nodes = &self.mesh.contact_nodes;
        let h: Vec<f64> = nodes.iter().map(|&n| self.layout.film(self.mesh, x, n)).collect();
        // x_new = x - y: H_new = H - (dh0 - duy)
        let dh: Vec<f64> = nodes.iter().map(|&n| dh0 - self.layout.uy(y, n)).collect();
        let (s, binding) = super::step::film_step_limit(&h, &dh, FILM_KEEP);
        let at = binding.map(|k| {
            let c = self.mesh.nodes[nodes[k] as usize];
            [c[0], c[2], h[k], dh[k]]
        });
        self.step_limits.push(s);
        // As in the condensed system: Newton keeps pushing one nodal film through zero, so
        // stop this solve (a zero step fails the line search at once).
        if let Some(k) = binding.filter(|&k| h[k] < super::step::FILM_COLLAPSE) {
            let c = self.mesh.nodes[nodes[k] as usize];
            self.collapse = Some([c[0], c[2]]);
            return Ok(0.0);
        }
        if crate::ehl_options::get().monitor && self.rank == 0 {
            eprintln!(
                "ehl_monitor: step limiter {s:.3e}, dH0 = {dh0:.3e}, H0 = {:.3e} binding at X,Z,H,dH = {at:?}",
                x[self.layout.h0 as usize]
            );
        }
        Ok(s)
    }

    fn jacobian(&mut self, x: &[f64], j: &Matrix) -> Result<()> {
        self.jacobian_evals += 1;
        if !self.jacobian_built {
            j.zero()?;
            self.add_stiffness(j)?;
            self.add_constant_couplings(j)?;
            pcall!(ffi::MatSetOption(j.raw(), ffi::MatOption_MAT_KEEP_NONZERO_PATTERN, ffi::PetscBool_PETSC_TRUE))?;
        } else {
            // Only the Reynolds rows change: zero them (pattern kept) and refill.
            pcall!(ffi::MatZeroRows(
                j.raw(),
                self.p_rows.len() as i32,
                self.p_rows.as_ptr(),
                0.0,
                std::ptr::null_mut(),
                std::ptr::null_mut()
            ))?;
        }
        self.measure_multipliers(x);
        let fluid = self.fluid();
        for e in &self.elements {
            let out = self.reynolds(x, e, &fluid);
            let rows_p: [i32; 6] = e.nodes.map(|n| self.layout.p[n as usize]);
            if let Some((all, m)) = &self.face {
                let sc: [f64; 6] = rows_p.map(|r| self.scale_of(r));
                let mut err = Ok(());
                m.chain(
                    &e.nodes,
                    &out.dr_dm,
                    |t| self.face_element(x, &all[t]),
                    &fluid,
                    &self.params.stabilisation,
                    |i, n, dp, dh| {
                        let cols = [self.layout.p[n as usize], self.layout.u[n as usize][1], self.layout.h0];
                        let vals = [sc[i] * dp, -sc[i] * dh, sc[i] * dh];
                        if err.is_ok() {
                            err = j.add_values(&rows_p[i..=i], &cols, &vals);
                        }
                    },
                );
                err?;
            }
            let cols_uy: [i32; 6] = e.nodes.map(|n| self.layout.u[n as usize][1]);
            let sc: [f64; 6] = rows_p.map(|r| self.scale_of(r));
            // dR/dP
            let dp: Vec<f64> = (0..36).map(|k| out.dr_dp[k / 6][k % 6] * sc[k / 6]).collect();
            j.add_values(&rows_p, &rows_p, &dp)?;
            // dR/dU_y = -dR/dH ; dR/dH0 = sum_j dR/dH_j
            let neg: Vec<f64> = (0..36).map(|k| -out.dr_dh[k / 6][k % 6] * sc[k / 6]).collect();
            j.add_values(&rows_p, &cols_uy, &neg)?;
            let dh0: [f64; 6] = std::array::from_fn(|i| out.dr_dh[i].iter().sum::<f64>() * sc[i]);
            j.add_values(&rows_p, &[self.layout.h0], &dh0)?;
        }
        for t in &self.jumps {
            let n = t.rows.len();
            let vals: Vec<f64> = (0..n * n).map(|k| t.entry(k / n, k % n) * self.scale_of(t.rows[k / n])).collect();
            j.add_values(&t.rows, &t.rows, &vals)?;
        }
        for &(d, _n, area) in &self.penalty_nodes {
            // Active set includes P = 0 exactly (the kink): nodes sitting at zero pressure,
            // e.g. outside the Hertz circle at the start, stay put instead of being pushed
            // negative by a Newton direction that ignores the penalty.
            let (_, dv) = penalty_law(x[d as usize]);
            if dv != 0.0 || x[d as usize] <= 0.0 {
                j.add_values(
                    &[d],
                    &[d],
                    &[self.scale_of(d) * self.params.penalty * area * dv.max(if CAVITATION_SMOOTHING > 0.0 { 0.0 } else { 1.0 })],
                )?;
            }
        }
        self.jacobian_built = true;
        if self.params.stabilisation.complementarity {
            self.complementarity_jacobian(x, j)?;
        }
        Ok(())
    }
}

impl EhlSystem<'_> {
    /// Replaces each owned Reynolds row's residual F_i by phi(P_i, F_i) (the cavitation
    /// condition as complementarity, [`crate::reynolds::cavitation::complementarity`]) and
    /// records phi's derivatives at `x` for the Jacobian. Assembles `f` (collective).
    fn complementarity_rows(&mut self, x: &[f64], f: &Vector) -> Result<()> {
        f.assemble()?;
        let (lo, _) = f.ownership()?;
        let mut vals = f.local_values()?;
        let mut slopes = Vec::with_capacity(self.p_rows.len());
        for &d in &self.p_rows {
            let i = d as usize - lo;
            let (v, dp, df) = crate::reynolds::cavitation::complementarity(x[d as usize], vals[i]);
            vals[i] = v;
            slopes.push((dp, df));
        }
        f.set_local_values(&vals)?;
        self.cavitated = Some(Cavitated { at: x.to_vec(), slopes });
        Ok(())
    }

    /// The Jacobian of the complementarity rows: d phi/dF times the Reynolds row plus
    /// d phi/dP on the diagonal. Assembles `j` (collective).
    fn complementarity_jacobian(&mut self, x: &[f64], j: &Matrix) -> Result<()> {
        if !self.cavitated.as_ref().is_some_and(|c| c.at.as_slice() == x) {
            let f = Vector::new(crate::petsc::comm_world(), self.layout.local(self.rank))?;
            f.set_all(0.0)?;
            self.residual(x, &f)?;
        }
        j.assemble()?;
        let slopes = &self.cavitated.as_ref().expect("set by the residual just evaluated").slopes;
        let local = self.layout.local(self.rank);
        let lo = self.layout.ranges[self.rank];
        let mut scale = vec![1.0; local];
        for (&d, &(_, df)) in self.p_rows.iter().zip(slopes) {
            scale[d as usize - lo] = df;
        }
        let l = Vector::new(crate::petsc::comm_world(), local)?;
        l.set_local_values(&scale)?;
        pcall!(ffi::MatDiagonalScale(j.raw(), l.raw(), std::ptr::null_mut()))?;
        // The P rows' own diagonal (MatDiagonalSet would also touch the load row, which has
        // no diagonal entry).
        for (&d, &(dp, _)) in self.p_rows.iter().zip(slopes) {
            j.add_values(&[d], &[d], &[dp])?;
        }
        j.assemble()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The penalty continuation changes xi between solves: the penalty rows and the SUPG
    /// strong residual must see the same xi, or SUPG is inconsistent in the cavitated zone.
    #[test]
    fn set_operating_moves_the_penalty_of_rows_and_supg_together() {
        let mut p = EhlParams {
            lambda_bar: 1e-3,
            traction: 1.0,
            load: 1.0,
            penalty: 1e4,
            stabilisation: Stabilisation { penalty: 1e4, ..Default::default() },
            velocity: Box::new(|_, _| [1.0, 0.0]),
            nu: 0.3,
        };
        p.set_operating(2e-3, 1e3, false);
        assert_eq!((p.lambda_bar, p.penalty, p.stabilisation.penalty), (2e-3, 1e3, 1e3));
    }

    /// Barus at alpha p_H = 34 (M = 100, L = 20): exp(34 P) overflows beyond P = 20.8, and a
    /// Newton iterate there must be a domain error, not an inf in the Jacobian.
    #[test]
    fn pressures_whose_viscosity_overflows_are_outside_the_domain() {
        let barus = Lubricant {
            eta: Box::new(|p| ((34.0 * p).exp(), 34.0 * (34.0 * p).exp())),
            rho: Box::new(|_| (1.0, 0.0)),
            d2eta: Box::new(|p| 34.0 * 34.0 * (34.0 * p).exp()),
            d2rho: Box::new(|_| 0.0),
        };
        assert!(barus.out_of_range([0.0, 1.2]).is_none());
        assert!(barus.out_of_range([1.2, 13.0, -0.1]).is_none());
        let why = barus.out_of_range([1.0, 21.3, 0.5]).expect("P = 21.3 overflows");
        assert!(why.contains("2.130e1 p_H"), "{why}");
        assert!(barus.out_of_range([0.5, f64::NAN, 1.0]).is_some());
    }
}
