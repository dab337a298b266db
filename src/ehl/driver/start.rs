//! Where Newton starts: the dry Hertz state (or another mesh's pressure) with its elastic
//! deflection and an H0 that opens the film everywhere, a previous operating point, or for
//! rigid solids a consistent pressure found by frozen-film solves.
use super::problem::hc_guess;
use crate::case::Scene;
use crate::context::Context;
use crate::ehl::condensed::CondensedSystem;
use crate::ehl::layout::Layout;
use crate::ehl::system::EhlProblem;
use crate::error::Error;
use crate::mesh::{Mesh, Partition};
use crate::petsc::snes::Snes;
use crate::petsc::{self, Ksp, Matrix, Vector};
use crate::solid::{assembly, dofmap::DofMap, hertz_load};

/// Where Newton starts.
#[derive(Clone, Copy)]
pub enum Start<'s> {
    /// The dry Hertz pressure and its deflection, H0 from Hamrock-Dowson's central film.
    Hertz,
    /// A converged state of a neighbouring operating point on the same mesh (monolithic
    /// layout, as in [`super::EhlSolution::x`]).
    Previous(&'s [f64]),
    /// A pressure field P(X, Z) from another mesh (mesh sequencing: a coarser level's
    /// converged solution, interpolated), its deflection, and H0 so that the central film
    /// is `hc` (dimensionless). `label` names it in the log. `tries`: plain Newton and
    /// then the continuation, plain Newton alone, or the continuation alone ([`Tries`]). With
    /// `last_resorts` false the load and speed continuations and the Hertz start are not
    /// tried after the continuations nearest the scene (tilt, pressure-viscosity) fail:
    /// the caller has a remedy of its own to try first. `ramp`: when a continuation's ramp
    /// gives up ([`RampLimits`]).
    /// `coarser`: the coarser level's own state, when it was solved on the monolithic
    /// coupling: its displacement interpolated at this mesh's nodes replaces the elastic
    /// solve under the pressure on a monolithic level ([`coarser_displacement`]).
    Pressure {
        p: &'s dyn Fn(f64, f64) -> f64,
        hc: f64,
        label: &'s str,
        tries: Tries,
        milder: Option<Milder<'s>>,
        last_resorts: bool,
        ramp: RampLimits,
        coarser: Option<Coarser<'s>>,
    },
}

/// What is tried from another mesh's pressure ([`Start::Pressure`]) before the last resorts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tries {
    /// Plain Newton, then the continuation from the same start.
    PlainThenContinuation,
    /// Plain Newton alone: the caller's own remedy costs less than the continuation (a
    /// level made finer than the one before by quartering is meshed again halved).
    Plain,
    /// The continuation at once: the coarser level itself needed it
    /// ([`super::policy::Attempt::ladder`]).
    Continuation,
}

/// When a continuation's ramp gives up: after `failures` failed steps (None: no such
/// limit), or when a failed step would be followed by a factor below `smallest_ratio`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RampLimits {
    pub failures: Option<usize>,
    pub smallest_ratio: f64,
}

impl RampLimits {
    /// Steps down to a factor of 1.05: below it a ramp crawls (M = 100, L = 20's 0.125 a
    /// level with a floor of 1.005 converged after 179 Newton iterations, where the zone's
    /// mesh then took 30).
    pub const DEFAULT: RampLimits = RampLimits { failures: None, smallest_ratio: 1.05 };
    /// For a caller whose own remedy costs less than a long ramp: give up at the second
    /// failed step.
    pub const BEFORE_A_REMEDY: RampLimits = RampLimits { failures: Some(2), smallest_ratio: 1.05 };
    /// For a solve with no remedy left but the last resorts, which have never converged
    /// from a coarser level's pressure: steps down to a factor of 1.01. The step from
    /// 62.6 to 68.3 GPa^-1 (a factor of 1.09) failed on raised levels of M = 20, L = 20 and
    /// M = 50, L = 20, and the ramp gave up at its square root 1.044; at M = 100, L = 20
    /// 62.59 -> 65.36 -> 68.25 converged in 8 and 7 iterations.
    pub const PATIENT: RampLimits = RampLimits { failures: None, smallest_ratio: 1.01 };
}

/// A coarser level's converged monolithic state (U, P and H0 in its layout) on its mesh.
#[derive(Clone, Copy)]
pub struct Coarser<'s> {
    pub mesh: &'s Mesh,
    pub layout: &'s Layout,
    pub x: &'s [f64],
}

/// A coarser level's path through a continuation: the pressure field at `ts[0]` of the
/// continuation named `parameter`, with its central film `hc`, and the values of t < 1
/// its ramp converged at. The continuation from a [`Start::Pressure`] solves its milder
/// problem from that field and ramps through the same values.
#[derive(Clone, Copy)]
pub struct Milder<'s> {
    pub parameter: &'static str,
    pub ts: &'s [f64],
    pub p: &'s dyn Fn(f64, f64) -> f64,
    pub hc: f64,
    pub label: &'s str,
}

impl<'s> Start<'s> {
    /// Another mesh's pressure `p` with central film `hc`, named `label`, with no coarser
    /// state: plain Newton first, then every continuation and the Hertz start.
    pub fn from_pressure(p: &'s dyn Fn(f64, f64) -> f64, hc: f64, label: &'s str) -> Start<'s> {
        Start::Pressure {
            p,
            hc,
            label,
            tries: Tries::PlainThenContinuation,
            milder: None,
            last_resorts: true,
            ramp: RampLimits::DEFAULT,
            coarser: None,
        }
    }

    /// The starting pressure P(X, Z) and central film of a start that is not a previous
    /// state: the Hertz pressure with Hamrock-Dowson's hc, or the given field.
    pub(super) fn pressure(&self, scene: &Scene) -> (&'s dyn Fn(f64, f64) -> f64, f64) {
        match *self {
            Start::Pressure { p, hc, .. } => (p, hc),
            _ => (&hertz_load::hertz_pressure, hc_guess(scene)),
        }
    }

    /// The coarser level's monolithic state, if the start carries one.
    pub(super) fn coarser(&self) -> Option<Coarser<'s>> {
        match *self {
            Start::Pressure { coarser, .. } => coarser,
            _ => None,
        }
    }

    /// A coarser level's state short of the scene, if the start carries one.
    pub(super) fn milder(&self) -> Option<Milder<'s>> {
        match *self {
            Start::Pressure { milder, .. } => milder,
            _ => None,
        }
    }

    /// Whether the load and speed continuations and the Hertz start follow when the
    /// attempts from this start fail (see [`Start::Pressure`]).
    pub(super) fn last_resorts(&self) -> bool {
        match *self {
            Start::Pressure { last_resorts, .. } => last_resorts,
            _ => true,
        }
    }

    /// When a continuation's ramp gives up (see [`Start::Pressure`]).
    pub(super) fn ramp(&self) -> RampLimits {
        match *self {
            Start::Pressure { ramp, .. } => ramp,
            _ => RampLimits::DEFAULT,
        }
    }

    pub(super) fn label(&self) -> &str {
        match self {
            Start::Hertz => "the Hertz start",
            Start::Previous(_) => "the previous operating point",
            Start::Pressure { label, .. } => label,
        }
    }
}

/// Solves the displacement under the pressure `p(X, Z)` (the Hertz pressure, or a coarser
/// level's) interpolated at the P2 nodes (the discrete pressure of the start, so the start
/// satisfies the elastic rows exactly and equals the condensed path's start): the starting
/// state of Newton.
#[allow(clippy::too_many_arguments)]
pub(super) fn elastic_start(
    comm: petsc::ffi::MPI_Comm,
    ctx: &Context,
    mesh: &Mesh,
    part: &Partition,
    dofs: &DofMap,
    k: &Matrix,
    nu: f64,
    p: &dyn Fn(f64, f64) -> f64,
) -> petsc::Result<Vec<f64>> {
    let nodal = |v: &[[f64; 2]; 3]| -> [f64; 6] {
        let p = crate::fem::p2tri::p2_tri_node_coords(v).map(|q| p(q[0], q[1]));
        let m = crate::fem::p2tri::p2_tri_mass(crate::fem::p2tri::tri_area(v));
        std::array::from_fn(|i| (0..6).map(|j| m[i][j] * p[j]).sum())
    };
    let b = assembly::assemble_pressure_load(comm, mesh, part, dofs, ctx.rank, assembly::traction_factor(nu), &nodal)?;
    // K is symmetric positive definite (constrained dofs are eliminated): a MUMPS Cholesky
    // under its own prefix, so the Newton solver's flags (-ksp_type gmres, ...) do not reach it.
    for (k, v) in [("ksp_type", "preonly"), ("pc_type", "cholesky"), ("pc_factor_mat_solver_type", "mumps"), ("mat_mumps_icntl_7", "4")] {
        petsc::options::set_default(&format!("-{START_PREFIX}{k}"), v)?;
    }
    let u = Vector::new(comm, dofs.local(ctx.rank))?;
    Ksp::solve_once_more_with_workspace(comm, k, START_PREFIX, &b, &u)?;
    u.gather_all()
}

/// The displacement of the coarser state `c` at every node of `mesh` (P2 interpolation in
/// the coarser mesh's tetrahedra), or None when a node lies outside it. The coarser state
/// satisfies its own elastic equations; on the finer mesh its residual is the
/// discretisation's change, which Newton's first step (linear in U) removes. It replaces
/// an elastic Cholesky of the finer mesh (9 s of table2-ue2's 199,642-unknown level).
pub(super) fn coarser_displacement(c: &Coarser, mesh: &Mesh) -> Option<Vec<[f64; 3]>> {
    let walk = crate::mesh::TetWalk::new(c.mesh);
    let value = |n: u32, k: usize| {
        let d = c.layout.u[n as usize][k];
        if d >= 0 {
            c.x[d as usize]
        } else {
            0.0
        }
    };
    let mut u = vec![[0.0; 3]; mesh.nodes.len()];
    let mut from = 0;
    for n in crate::mesh::morton_order(mesh) {
        let (t, l) = walk.locate(c.mesh, mesh.nodes[n as usize], from)?;
        let tet = &c.mesh.tets[t];
        let values: [f64; 30] = std::array::from_fn(|i| value(tet[i / 3], i % 3));
        u[n as usize] = crate::fem::p2tet::p2_tet_eval(&values, l);
        from = t;
    }
    Some(u)
}

/// Options prefix of the start's elastic solve (`-start_pc_type`, `-start_mat_mumps_icntl_7`).
const START_PREFIX: &str = "start_";

/// H0 of the start: the central film `hc` (estimated, or a coarser level's) over the
/// starting deflection at the centre, raised if needed so that the starting film is
/// positive everywhere (a coarse mesh's dry deflection is not flat in the contact). `uy`
/// gives U_y at a contact node.
pub(super) fn start_h0(hc: f64, mesh: &Mesh, uy: &dyn Fn(u32) -> f64) -> Result<f64, Error> {
    let centre = mesh.locate_contact(0.0, 0.0).ok_or_else(|| Error::other("contact centre not on the contact face"))?;
    let uy_centre = crate::fem::p2_tri_eval(&mesh.contact_tris[centre.0].map(uy), centre.1);
    let min_gap = mesh.contact_nodes.iter().map(|&n| Layout::gap(mesh.nodes[n as usize]) - uy(n)).fold(f64::INFINITY, f64::min);
    Ok((hc + uy_centre).max(0.5 * hc - min_gap))
}

/// A consistent start for rigid solids. The Hertz start is far from a rigid solution, and
/// at P = 0 the Reynolds rows do not depend on H0 (dR/dH0 = div(3 H^2 grad P) = 0), so
/// Newton on (P, H0) takes useless steps. Instead: solve the pressure of a frozen film
/// (P only), and adjust H0 until its load is within 2 % of the target, by a secant method
/// on log W(log H0) (the first step assumes W ~ 1/H0); each frozen-film solve starts from
/// the previous pressure scaled to the target load. The full Newton finishes from there.
pub(super) fn rigid_start(
    ctx: &Context,
    system: &mut CondensedSystem,
    x0: &mut [f64],
    (lo, hi): (usize, usize),
    local: usize,
) -> Result<(), Error> {
    let comm = petsc::comm_world();
    let n = x0.len();
    let np = n - 1;
    x0[..np].iter_mut().for_each(|p| *p = 0.0);
    let mut h0 = x0[np];
    let (d, o) = system.preallocation();
    let j = Matrix::new_aij(comm, local, &d, &o)?;
    let x = Vector::new(comm, local)?;
    // Its own options prefix: the frozen-film solves cross the cavitation penalty's kink
    // node by node and may need more iterations than the main Newton's default.
    for (k, v) in [
        ("-rigid_start_snes_max_it", "200"),
        ("-rigid_start_snes_rtol", "1e-8"),
        ("-rigid_start_snes_stol", "0"),
        ("-rigid_start_snes_linesearch_type", "bt"),
    ] {
        petsc::options::set_default(k, v)?;
    }
    petsc::ksp::set_direct_solver_defaults("rigid_start_")?;
    let snes = Snes::new(comm, "rigid_start_")?;
    let target = system.params.load;
    let mut prev: Option<(f64, f64)> = None;
    let mut result = Ok(());
    for it in 0..12 {
        system.fixed_h0 = Some(h0);
        x0[np] = h0;
        system.scale_rows(x0)?;
        x.set_local_values(&x0[lo..hi])?;
        let r = snes.solve(system, &x, &j)?;
        if !r.converged {
            if prev.is_none() && it < 4 {
                // A too thin first guess: the frozen film is much thinner than the
                // solution's, its pressure enormous. Start over from a thicker film.
                ctx.log(format!("rigid start {}: H0 = {h0:.5e}: {} ; trying a 4 times thicker film", it + 1, r.reason));
                h0 *= 4.0;
                x0[..np].iter_mut().for_each(|p| *p = 0.0);
                continue;
            }
            result =
                Err(Error::not_converged(format!("rigid start: the pressure of the film H0 = {h0:.4e} did not converge ({})", r.reason)));
            break;
        }
        let xs = x.gather_all()?;
        x0[..np].copy_from_slice(&xs[..np]);
        let w = system.load(x0);
        ctx.log(format!("rigid start {}: H0 = {h0:.5e}, load {:.4} of the target ({} iterations)", it + 1, w / target, r.iterations));
        if !(w > 0.0) || (w / target - 1.0).abs() < 0.02 {
            break;
        }
        // Slope of log W against log H0: secant once two points are known, else -1.
        let slope = match prev {
            Some((h_old, w_old)) if (h0 / h_old).ln().abs() > 1e-12 => ((w / w_old).ln() / (h0 / h_old).ln()).clamp(-4.0, -0.25),
            _ => -1.0,
        };
        prev = Some((h0, w));
        let factor = ((target / w).ln() / slope).clamp(-2.0, 2.0).exp();
        h0 *= factor;
        // The pressure scales roughly with the load: start the next solve from it.
        let s = target / w;
        x0[..np].iter_mut().for_each(|p| *p *= s);
    }
    system.fixed_h0 = None;
    x0[np] = h0;
    result
}
