//! Tests of the Reynolds element: exact Jacobian, consistency, manufactured-solution
//! convergence, and what SUPG does on an advection-dominated problem.

use super::element::*;
use crate::fem::p2tri::P2Triangle;
use crate::fem::quadrature::DUNAVANT6;
use nalgebra::{DMatrix, DVector};
use std::f64::consts::PI;

// ---------------------------------------------------------------- lubricant laws

/// Exponential (Barus/Roelands-like) law eta_bar = exp(19 P).
fn eta_exp19(p: f64) -> (f64, f64) {
    let e = (19.0 * p).exp();
    (e, 19.0 * e)
}
fn d2eta_exp19(p: f64) -> f64 {
    361.0 * (19.0 * p).exp()
}

const P_H: f64 = 0.845e9;
/// Dowson-Higginson in P units: rho_bar = (5.9e8 + 1.34 p)/(5.9e8 + p), p = P p_H.
fn rho_dh(p: f64) -> (f64, f64) {
    let q = 5.9e8 + P_H * p;
    ((5.9e8 + 1.34 * P_H * p) / q, P_H * 0.34 * 5.9e8 / (q * q))
}
fn d2rho_dh(p: f64) -> f64 {
    let q = 5.9e8 + P_H * p;
    -2.0 * P_H * P_H * 0.34 * 5.9e8 / (q * q * q)
}

fn fluid_exp_dh(lambda_bar: f64) -> Fluid<'static> {
    Fluid { eta: &eta_exp19, rho: &rho_dh, d2eta: &d2eta_exp19, d2rho: &d2rho_dh, lambda_bar }
}

// ---------------------------------------------------------------- helpers

/// Tiny deterministic generator (no external crate): uniform in [0, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }
}

/// Rigid-body entrainment field (u0 - om z, w0 + om x) at the vertices (divergence-free).
fn rigid_vel(verts: &[[f64; 2]; 3], u0: f64, w0: f64, om: f64) -> [[f64; 2]; 3] {
    std::array::from_fn(|k| [u0 - om * verts[k][1], w0 + om * verts[k][0]])
}

/// Central finite-difference Jacobian, compared entry by entry with the exact one.
/// Returns the largest row-relative error max_j |J_ij - Jfd_ij| / max_j |J_ij|.
fn fd_jacobian_error(verts: &[[f64; 2]; 3], p: &[f64; 6], h: &[f64; 6], vel: &[[f64; 2]; 3], fluid: &Fluid, stab: &Stabilisation) -> f64 {
    fd_jacobian_error_of(|p, h| reynolds_element(verts, p, h, vel, fluid, stab), p, h, 1e-6)
}

/// The largest row-relative difference between the Jacobian an element kernel `eval`
/// returns at (`p`, `h`) and central differences of its residual with steps `step`.
fn fd_jacobian_error_of(eval: impl Fn(&[f64; 6], &[f64; 6]) -> ElementOut, p: &[f64; 6], h: &[f64; 6], step: f64) -> f64 {
    let out = eval(p, h);
    let mut fd = [[0.0; 12]; 6];
    for j in 0..12 {
        let (mut pp, mut hp) = (*p, *h);
        let (mut pm, mut hm) = (*p, *h);
        if j < 6 {
            pp[j] += step;
            pm[j] -= step;
        } else {
            hp[j - 6] += step;
            hm[j - 6] -= step;
        }
        let rp = eval(&pp, &hp).r;
        let rm = eval(&pm, &hm).r;
        for i in 0..6 {
            fd[i][j] = (rp[i] - rm[i]) / (2.0 * step);
        }
    }
    let mut worst: f64 = 0.0;
    for i in 0..6 {
        let exact: Vec<f64> = out.dr_dp[i].iter().chain(out.dr_dh[i].iter()).copied().collect();
        let scale = exact.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(scale > 0.0);
        for j in 0..12 {
            worst = worst.max((exact[j] - fd[i][j]).abs() / scale);
        }
    }
    worst
}

// ---------------------------------------------------------------- Jacobian

/// A random, not too distorted triangle of size 0.1..0.5 in [-1, 1.7]^2.
fn random_triangle(rng: &mut Lcg) -> [[f64; 2]; 3] {
    let s = rng.range(0.1, 0.5);
    let c = [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)];
    [
        [c[0], c[1]],
        [c[0] + s * rng.range(0.7, 1.3), c[1] + s * rng.range(-0.3, 0.3)],
        [c[0] + s * rng.range(-0.3, 0.5), c[1] + s * rng.range(0.7, 1.3)],
    ]
}

fn jacobian_check(stab: Stabilisation) {
    let mut rng = Lcg(12345);
    let fluid = fluid_exp_dh(0.3);
    let mut worst: f64 = 0.0;
    for trial in 0..20 {
        let verts = random_triangle(&mut rng);
        let p: [f64; 6] = std::array::from_fn(|_| rng.range(0.0, 0.8));
        let h: [f64; 6] = std::array::from_fn(|_| rng.range(0.3, 1.5));
        let vel = if trial % 2 == 0 {
            rigid_vel(&verts, rng.range(0.2, 1.0), rng.range(-0.5, 0.5), rng.range(-2.0, 2.0))
        } else {
            // general affine field (not divergence-free): the Jacobian must still be exact
            std::array::from_fn(|_| [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)])
        };
        let e = fd_jacobian_error(&verts, &p, &h, &vel, &fluid, &stab);
        worst = worst.max(e);
    }
    println!("supg = {}: worst row-relative Jacobian error vs central FD = {worst:.2e}", stab.supg);
    assert!(worst < 1e-6, "Jacobian error {worst}");
}

#[test]
fn jacobian_matches_finite_differences_galerkin() {
    jacobian_check(Stabilisation::none());
}

#[test]
fn jacobian_matches_finite_differences_supg() {
    jacobian_check(Stabilisation::supg(1.0));
}

/// The stabilisation the EHL solver uses by default (`reynolds.stabilisation = "supg"`):
/// Habchi's Peclet number, strong residual with frozen lubricant properties, penalty term.
fn production_supg() -> Stabilisation {
    Stabilisation { residual: StrongResidual::FrozenLubricant, film_peclet: true, penalty: 50.0, ..Stabilisation::default() }
}

#[test]
fn jacobian_matches_finite_differences_production_supg() {
    jacobian_check(production_supg());
    jacobian_check(Stabilisation { residual: StrongResidual::Couette, film_peclet: true, ..Stabilisation::default() });
}

#[test]
fn jacobian_matches_finite_differences_supg_diffusive_regime() {
    // large lambda_bar^-1 (small Pe) exercises the series branch of xi(Pe)
    let fluid = fluid_exp_dh(1e-4);
    let verts = [[0.0, 0.0], [0.2, 0.02], [0.05, 0.18]];
    let p = [0.1, 0.2, 0.05, 0.15, 0.12, 0.08];
    let h = [1.0, 1.1, 0.9, 1.05, 1.0, 0.95];
    let vel = rigid_vel(&verts, 1.0, 0.1, 0.5);
    let e = fd_jacobian_error(&verts, &p, &h, &vel, &fluid, &Stabilisation::supg(1.0));
    assert!(e < 1e-6, "{e}");
}

#[test]
fn xi_branches_agree_and_limits() {
    // series and closed form agree at the switch, derivative matches FD
    let (a, da) = xi(1e-2 - 1e-12);
    let (b, db) = xi(1e-2 + 1e-12);
    assert!((b - a - da * 2e-12).abs() < 1e-13 && (da - db).abs() < 1e-9, "{a} {b} {da} {db}");
    for pe in [1e-3, 0.05, 0.7, 3.0, 30.0] {
        let (_, d) = xi(pe);
        let fd = (xi(pe * (1.0 + 1e-6)).0 - xi(pe * (1.0 - 1e-6)).0) / (2e-6 * pe);
        assert!((d - fd).abs() < 1e-7 * (1.0 + d.abs()), "pe {pe}: {d} vs {fd}");
    }
    assert!((xi(1e-5).0 - 1e-5 / 3.0).abs() < 1e-15);
    assert_eq!(xi(1e4).0, 1.0 - 1e-4);
    assert!(xi(1e4).1 > 0.0 && xi(800.0).1.is_finite());
}

// ---------------------------------------------------------------- consistency

#[test]
fn constant_fields_give_the_couette_term_only() {
    // Triangle (0,0), (2,0), (0,1): area 1, grad L = (-1/2,-1), (1/2,0), (0,1).
    // int grad N_vertex k = A/3 grad L_k; int grad N_mid(a,b) = -4A/3 grad L_c (c the third).
    // With v = (1, 1/2): v.grad L = (-1, 1/2, 1/2), so
    // R = -rho H (v . int grad N) = -rho H [-1/3, 1/6, 1/6, -2/3, 4/3, -2/3].
    let verts = [[0.0, 0.0], [2.0, 0.0], [0.0, 1.0]];
    let vel = [[1.0, 0.5]; 3];
    let fluid = fluid_exp_dh(0.5);
    let pc = 0.4;
    let hc = 0.7;
    let rho_h = rho_dh(pc).0 * hc;
    let expect = [-1.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0, -2.0 / 3.0, 4.0 / 3.0, -2.0 / 3.0].map(|x| -rho_h * x);
    for stab in [Stabilisation::none(), Stabilisation::supg(1.0)] {
        let out = reynolds_element(&verts, &[pc; 6], &[hc; 6], &vel, &fluid, &stab);
        for i in 0..6 {
            assert!((out.r[i] - expect[i]).abs() < 1e-13, "{stab:?} node {i}: {} vs {}", out.r[i], expect[i]);
        }
    }
}

#[test]
fn linear_pressure_gives_the_exact_flux() {
    // P = 0.3 + 1.2 X - 0.8 Z, H constant, constant laws: eps constant, r_strong = 0,
    // R_i = (eps grad P - rho H v) . int grad N_i exactly, with or without SUPG.
    let verts = [[0.0, 0.0], [2.0, 0.0], [0.0, 1.0]];
    let g = [1.2, -0.8];
    let tri = P2Triangle::new(&verts);
    let p: [f64; 6] = tri.nodes().map(|x| 0.3 + g[0] * x[0] + g[1] * x[1]);
    let hc = 1.3;
    let lambda = 2.0;
    let eps = hc * hc * hc / lambda;
    let v = [1.0, 0.5];
    let fl = [eps * g[0] - hc * v[0], eps * g[1] - hc * v[1]];
    // int grad N_i from the hand values above
    let gl = [[-0.5, -1.0], [0.5, 0.0], [0.0, 1.0]];
    let int_grad: [[f64; 2]; 6] = [
        gl[0].map(|x| x / 3.0),
        gl[1].map(|x| x / 3.0),
        gl[2].map(|x| x / 3.0),
        gl[2].map(|x| -4.0 * x / 3.0),
        gl[0].map(|x| -4.0 * x / 3.0),
        gl[1].map(|x| -4.0 * x / 3.0),
    ];
    for stab in [Stabilisation::none(), Stabilisation::supg(1.0)] {
        let out = reynolds_element(&verts, &p, &[hc; 6], &[v; 3], &Fluid::constant(lambda), &stab);
        for i in 0..6 {
            let e = fl[0] * int_grad[i][0] + fl[1] * int_grad[i][1];
            assert!((out.r[i] - e).abs() < 1e-13, "node {i}: {} vs {e}", out.r[i]);
        }
    }
}

// ---------------------------------------------------------------- a tiny mesh + solver

/// Structured P2 mesh of [lo, hi]^2, n squares per side, each cut along its diagonal.
struct Mesh {
    nodes: Vec<[f64; 2]>,
    tris: Vec<[usize; 6]>,
    boundary: Vec<bool>,
}

fn square_mesh(n: usize, lo: f64, hi: f64) -> Mesh {
    let m = 2 * n + 1;
    let id = |i: usize, j: usize| j * m + i;
    let step = (hi - lo) / (2 * n) as f64;
    let mut nodes = Vec::new();
    let mut boundary = Vec::new();
    for j in 0..m {
        for i in 0..m {
            nodes.push([lo + i as f64 * step, lo + j as f64 * step]);
            boundary.push(i == 0 || j == 0 || i == m - 1 || j == m - 1);
        }
    }
    let mut tris = Vec::new();
    for b in 0..n {
        for a in 0..n {
            let (i, j) = (2 * a, 2 * b);
            // (i,j) -> (i+2,j) -> (i+2,j+2) and (i,j) -> (i+2,j+2) -> (i,j+2)
            tris.push([id(i, j), id(i + 2, j), id(i + 2, j + 2), id(i + 1, j), id(i + 2, j + 1), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 2, j + 2), id(i, j + 2), id(i + 1, j + 1), id(i + 1, j + 2), id(i, j + 1)]);
        }
    }
    Mesh { nodes, tris, boundary }
}

struct Problem<'a> {
    mesh: &'a Mesh,
    h: Vec<f64>,
    vel: &'a dyn Fn(f64, f64) -> [f64; 2],
    fluid: &'a Fluid<'a>,
    stab: Stabilisation,
    source: Option<&'a dyn Fn(f64, f64) -> f64>,
}

/// Newton's method with the exact Jacobian, P = 0 on the boundary, dense LU.
/// Returns the nodal P and the number of Newton iterations.
fn solve(pb: &Problem) -> (Vec<f64>, usize) {
    let mesh = pb.mesh;
    let mut dof = vec![usize::MAX; mesh.nodes.len()];
    let mut ndof = 0;
    for (k, &b) in mesh.boundary.iter().enumerate() {
        if !b {
            dof[k] = ndof;
            ndof += 1;
        }
    }
    let mut p = vec![0.0; mesh.nodes.len()];
    for it in 1..=30 {
        let mut r = DVector::<f64>::zeros(ndof);
        let mut jac = DMatrix::<f64>::zeros(ndof, ndof);
        for t in &mesh.tris {
            let verts = [mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]]];
            let pe: [f64; 6] = t.map(|k| p[k]);
            let he: [f64; 6] = t.map(|k| pb.h[k]);
            let ve: [[f64; 2]; 3] = std::array::from_fn(|k| (pb.vel)(verts[k][0], verts[k][1]));
            let out = reynolds_element_with_source(&verts, &pe, &he, &ve, pb.fluid, &pb.stab, pb.source);
            for i in 0..6 {
                let gi = dof[t[i]];
                if gi == usize::MAX {
                    continue;
                }
                r[gi] += out.r[i];
                for j in 0..6 {
                    let gj = dof[t[j]];
                    if gj != usize::MAX {
                        jac[(gi, gj)] += out.dr_dp[i][j];
                    }
                }
            }
        }
        let dp = jac.lu().solve(&(-r)).expect("singular Jacobian");
        for (k, &g) in dof.iter().enumerate() {
            if g != usize::MAX {
                p[k] += dp[g];
            }
        }
        let scale = p.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        if dp.amax() < 1e-12 * scale {
            return (p, it);
        }
    }
    panic!("Newton did not converge");
}

/// L2 norm of P_h - P_exact (degree-6 quadrature on each element).
fn l2_error(mesh: &Mesh, p: &[f64], exact: &dyn Fn(f64, f64) -> f64) -> f64 {
    let mut s = 0.0;
    for t in &mesh.tris {
        let tri = P2Triangle::new(&[mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]]]);
        for q in DUNAVANT6.iter() {
            let n = P2Triangle::shape(&q.l);
            let ph: f64 = (0..6).map(|i| n[i] * p[t[i]]).sum();
            let x = tri.point(&q.l);
            s += q.w * tri.area * (ph - exact(x[0], x[1])).powi(2);
        }
    }
    s.sqrt()
}

// ---------------------------------------------------------------- manufactured solutions

/// Manufactured P = sin(pi X) sin(pi Z) on [0,1]^2, H = 1 + (X^2 + Z^2)/2 (exactly P2).
fn p_exact(x: f64, z: f64) -> f64 {
    (PI * x).sin() * (PI * z).sin()
}
fn grad_p_exact(x: f64, z: f64) -> [f64; 2] {
    [PI * (PI * x).cos() * (PI * z).sin(), PI * (PI * x).sin() * (PI * z).cos()]
}
fn h_exact(x: f64, z: f64) -> f64 {
    1.0 + 0.5 * (x * x + z * z)
}

/// f = -div(eps grad P) + div(rho H v) for the manufactured P, H and an affine,
/// divergence-free v, written out independently of the element code:
/// div(eps grad P) = eps Lap P + (eps_P grad P + eps_H grad H) . grad P,
/// div(rho H v) = rho' H v . grad P + rho v . grad H.
fn mms_source(fluid: &Fluid, vel: &dyn Fn(f64, f64) -> [f64; 2], x: f64, z: f64) -> f64 {
    let p = p_exact(x, z);
    let gp = grad_p_exact(x, z);
    let lap_p = -2.0 * PI * PI * p;
    let h = h_exact(x, z);
    let gh = [x, z];
    let (eta, deta) = (fluid.eta)(p);
    let (rho, drho) = (fluid.rho)(p);
    let eps = rho * h.powi(3) / (eta * fluid.lambda_bar);
    let eps_p = eps * (drho / rho - deta / eta);
    let eps_h = 3.0 * eps / h;
    let div_flux = eps * lap_p + (eps_p * gp[0] + eps_h * gh[0]) * gp[0] + (eps_p * gp[1] + eps_h * gh[1]) * gp[1];
    let v = vel(x, z);
    let conv = drho * h * (v[0] * gp[0] + v[1] * gp[1]) + rho * (v[0] * gh[0] + v[1] * gh[1]);
    -div_flux + conv
}

/// Solves the manufactured problem on n = 4, 8, 16 and returns the L2 errors.
fn mms_errors(fluid: &Fluid, vel: &dyn Fn(f64, f64) -> [f64; 2], stab: Stabilisation) -> Vec<f64> {
    let src = |x: f64, z: f64| mms_source(fluid, vel, x, z);
    let mut errs = Vec::new();
    for n in [4, 8, 16] {
        let mesh = square_mesh(n, 0.0, 1.0);
        let h = mesh.nodes.iter().map(|x| h_exact(x[0], x[1])).collect();
        let pb = Problem { mesh: &mesh, h, vel, fluid, stab, source: Some(&src) };
        let (p, its) = solve(&pb);
        let e = l2_error(&mesh, &p, &p_exact);
        println!("  n = {n:2}: L2 error {e:.3e} ({its} Newton its)");
        errs.push(e);
    }
    errs
}

fn orders(errs: &[f64]) -> Vec<f64> {
    errs.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}

#[test]
fn manufactured_solution_converges_at_third_order_constant_laws() {
    // eps = H^3 / 8 in [0.125, 1]; v = (1, 0)
    let fluid = Fluid::constant(8.0);
    let vel = |_: f64, _: f64| [1.0, 0.0];
    for stab in [Stabilisation::none(), Stabilisation::supg(1.0)] {
        println!("constant laws, {stab:?}");
        let errs = mms_errors(&fluid, &vel, stab);
        let o = orders(&errs);
        println!("  observed orders {o:?}");
        assert!(o[1] > 2.8 && o[1] < 3.3, "order {o:?}");
        assert!(errs[2] < 2e-4);
    }
}

#[test]
fn manufactured_solution_converges_at_third_order_nonlinear_laws() {
    // eta = exp(2 P), Dowson-Higginson rho, spinning entrainment field: Newton on the
    // full nonlinear residual with the exact Jacobian.
    fn eta2(p: f64) -> (f64, f64) {
        let e = (2.0 * p).exp();
        (e, 2.0 * e)
    }
    fn d2eta2(p: f64) -> f64 {
        4.0 * (2.0 * p).exp()
    }
    let fluid = Fluid { eta: &eta2, rho: &rho_dh, d2eta: &d2eta2, d2rho: &d2rho_dh, lambda_bar: 4.0 };
    let vel = |x: f64, z: f64| [1.0 + 0.3 * z, -0.3 * x];
    for stab in [Stabilisation::none(), Stabilisation::supg(1.0)] {
        println!("nonlinear laws, {stab:?}");
        let errs = mms_errors(&fluid, &vel, stab);
        let o = orders(&errs);
        println!("  observed orders {o:?}");
        assert!(o[1] > 2.8 && o[1] < 3.3, "order {o:?}");
    }
    // The solver's default SUPG drops (d eps/dP) |grad P|^2 from the strong residual: that
    // inconsistency is O(tau) = O(h^2/eps) where diffusion dominates; the observed order
    // must stay at least 2 (first-order Couette-only SUPG is the contrast).
    let stab = Stabilisation { residual: StrongResidual::FrozenLubricant, film_peclet: true, ..Stabilisation::default() };
    println!("nonlinear laws, production SUPG");
    let errs = mms_errors(&fluid, &vel, stab);
    let o = orders(&errs);
    println!("  observed orders {o:?}");
    assert!(o[1] > 1.9, "order {o:?}");
}

#[test]
fn manufactured_solution_incompressible_piezoviscous_converges_at_second_order() {
    // An incompressible lubricant with a pressure-dependent viscosity (eta = exp(2 P),
    // rho = 1): the production SUPG (frozen-lubricant residual, Peclet number from the
    // elastic film response since d rho/dP = 0) keeps order 2 at least; the Couette-only
    // residual with tau on |v|, its predecessor, is the low-order contrast (and shows that
    // this test can tell them apart).
    fn eta2(p: f64) -> (f64, f64) {
        let e = (2.0 * p).exp();
        (e, 2.0 * e)
    }
    fn d2eta2(p: f64) -> f64 {
        4.0 * (2.0 * p).exp()
    }
    fn unit(_: f64) -> (f64, f64) {
        (1.0, 0.0)
    }
    fn zero2(_: f64) -> f64 {
        0.0
    }
    let fluid = Fluid { eta: &eta2, rho: &unit, d2eta: &d2eta2, d2rho: &zero2, lambda_bar: 150.0 };
    let vel = |x: f64, z: f64| [1.0 + 0.3 * z, -0.3 * x];
    let production = Stabilisation { residual: StrongResidual::FrozenLubricant, film_peclet: true, ..Stabilisation::default() };
    let o = orders(&mms_errors(&fluid, &vel, production));
    println!("incompressible, production SUPG: observed orders {o:?}");
    assert!(o[1] > 1.9, "order {o:?}");
    // The former fallback: Couette residual, tau on |v| (no film Peclet number).
    let couette = Stabilisation { residual: StrongResidual::Couette, film_peclet: false, ..Stabilisation::default() };
    let oc = orders(&mms_errors(&fluid, &vel, couette));
    println!("incompressible, Couette-only SUPG: observed orders {oc:?}");
    assert!(oc[1] < 1.5, "Couette-only order {oc:?}");
}

// ---------------------------------------------------------------- what SUPG is for

/// eta_bar = rho_bar = 1 + P makes eps = H^3/lambda constant while the Couette term
/// div((1 + P) H v) = v . grad P (H = 1) advects P: the residual is that of the linear
/// advection-diffusion problem -eps Lap P + v . grad P = 1, P = 0 on the boundary.
fn one_plus_p(p: f64) -> (f64, f64) {
    (1.0 + p, 1.0)
}
fn zero(_: f64) -> f64 {
    0.0
}

/// Solves the boundary-layer problem (eps = 1e-6, v = (1, 0), f = 1, n = 16) and returns
/// (min P over all nodes, max P over all nodes, P on the centre line Z = 1/2).
fn boundary_layer(stab: Stabilisation) -> (f64, f64, Vec<f64>) {
    let fluid = Fluid { eta: &one_plus_p, rho: &one_plus_p, d2eta: &zero, d2rho: &zero, lambda_bar: 1e6 };
    let n = 16;
    let mesh = square_mesh(n, 0.0, 1.0);
    let vel = |_: f64, _: f64| [1.0, 0.0];
    let one = |_: f64, _: f64| 1.0;
    let pb = Problem { mesh: &mesh, h: vec![1.0; mesh.nodes.len()], vel: &vel, fluid: &fluid, stab, source: Some(&one) };
    let (p, _) = solve(&pb);
    let m = 2 * n + 1;
    let line: Vec<f64> = (0..m).map(|i| p[n * m + i]).collect();
    let lo = p.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = p.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    (lo, hi, line)
}

#[test]
fn supg_removes_the_oscillations_of_an_advection_dominated_problem() {
    // Exact solution: P ~ X away from the layers (outflow layer at X = 1 of width 1e-6,
    // characteristic layers at Z = 0, 1), 0 <= P < 1.
    let (lo_g, hi_g, line_g) = boundary_layer(Stabilisation::none());
    let (lo_s, hi_s, line_s) = boundary_layer(Stabilisation::supg(1.0));
    let m = line_s.len();
    let dx = 1.0 / (m - 1) as f64;
    // centre-line error against the reduced solution P = X upstream of the outflow layer
    // (X <= 3/4: SUPG smears the layer over about two elements, h = 1/16)
    let upstream = |line: &[f64]| (0..=(3 * (m - 1)) / 4).map(|i| (line[i] - i as f64 * dx).abs()).fold(0.0, f64::max);
    let wiggles = |line: &[f64]| (1..m - 1).filter(|&i| line[i] < line[i - 1] - 1e-12 && line[i + 1] > line[i] + 1e-12).count();
    println!("Galerkin: min {lo_g:.3e} max {hi_g:.3e}, upstream error {:.3e}, local minima {}", upstream(&line_g), wiggles(&line_g));
    println!("SUPG    : min {lo_s:.3e} max {hi_s:.3e}, upstream error {:.3e}, local minima {}", upstream(&line_s), wiggles(&line_s));
    println!("centre line Galerkin {:?}", line_g.iter().map(|x| (x * 1000.0).round() / 1000.0).collect::<Vec<_>>());
    println!("centre line SUPG     {:?}", line_s.iter().map(|x| (x * 1000.0).round() / 1000.0).collect::<Vec<_>>());
    // Galerkin oscillates with O(1) amplitude all the way upstream, and overshoots wildly
    assert!(upstream(&line_g) > 0.5 && wiggles(&line_g) > 5 && hi_g > 2.0 && lo_g < -1.0);
    // SUPG: no interior local minimum on the centre line (no oscillation), accurate
    // upstream of the layer, no overshoot above the exact bound 1 or below 0
    assert!(upstream(&line_s) < 1e-2, "{}", upstream(&line_s));
    assert_eq!(wiggles(&line_s), 0);
    assert!(hi_s < 1.0 && lo_s > -1e-3, "SUPG min {lo_s} max {hi_s}");
}

#[test]
fn jacobian_matches_finite_differences_with_artificial_diffusion() {
    jacobian_check(Stabilisation { id: 0.3, ..production_supg() });
    jacobian_check(Stabilisation { cd: 0.3, ..production_supg() });
}

#[test]
fn crosswind_diffusion_acts_across_the_streamlines_only() {
    // Entrainment along X: a pressure that varies along X only is untouched by the crosswind
    // term, and one that varies along Z only sees it as the isotropic diffusion of the same
    // factor (the streamline part t . grad P is zero there).
    let verts = [[0.0, 0.0], [0.3, 0.05], [0.1, 0.25]];
    let mids = [[0.15, 0.025], [0.2, 0.15], [0.05, 0.125]];
    let nodes: Vec<[f64; 2]> = verts.iter().chain(mids.iter()).copied().collect();
    let vel = [[1.0, 0.0]; 3];
    let fluid = fluid_exp_dh(0.5);
    let h = [0.7, 0.72, 0.69, 0.71, 0.705, 0.695];
    let base = production_supg();
    let close = |a: &[f64; 6], b: &[f64; 6]| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-12 * (1.0 + y.abs()));
    let along_x: [f64; 6] = std::array::from_fn(|k| 0.3 + 0.8 * nodes[k][0] - 0.5 * nodes[k][0] * nodes[k][0]);
    let r0 = reynolds_element(&verts, &along_x, &h, &vel, &fluid, &base).r;
    let rc = reynolds_element(&verts, &along_x, &h, &vel, &fluid, &Stabilisation { cd: 0.5, ..base }).r;
    assert!(close(&rc, &r0), "crosswind term acted along the stream: {rc:?} vs {r0:?}");
    let along_z: [f64; 6] = std::array::from_fn(|k| 0.3 + 0.8 * nodes[k][1] - 0.5 * nodes[k][1] * nodes[k][1]);
    let r0 = reynolds_element(&verts, &along_z, &h, &vel, &fluid, &base).r;
    let rc = reynolds_element(&verts, &along_z, &h, &vel, &fluid, &Stabilisation { cd: 0.5, ..base }).r;
    let ri = reynolds_element(&verts, &along_z, &h, &vel, &fluid, &Stabilisation { id: 0.5, ..base }).r;
    assert!(close(&rc, &ri), "crosswind {rc:?} vs isotropic {ri:?}");
    assert!(!close(&rc, &r0), "the crosswind term did nothing across the stream");
}

#[test]
fn a_pressure_step_stops_at_the_floor_and_leaves_other_steps_alone() {
    use super::cavitation::clip_pressure_step;
    let floor = -0.1;
    // heavy-3gpa's side lobe from a coarser mesh: 0.3 p_H predicted to fall to -1 p_H.
    let y = clip_pressure_step(0.3, 1.3, floor);
    assert!((0.3 - y - floor).abs() < 1e-15, "new P = {}", 0.3 - y);
    // A step that stays above the floor, up or down, is kept exactly (also into the
    // penalty's converged range, -O(1/xi)).
    for (p, y) in [(0.3, 0.2), (0.3, 0.3009), (-0.05, -0.4), (1e-4, 0.0601)] {
        assert_eq!(clip_pressure_step(p, y, floor), y);
    }
    // Below the floor already: may rise, may not fall further.
    assert_eq!(clip_pressure_step(-0.2, -0.15, floor), -0.15);
    assert_eq!(clip_pressure_step(-0.2, 0.5, floor), 0.0);
}

/// With cavitation as complementarity SUPG leaves a cavitated element (P = 0 at every
/// node, where the exact solution's residual is the cavitation multiplier) to plain
/// Galerkin, and a pressurised one to the usual SUPG.
#[test]
fn complementarity_supg_leaves_a_cavitated_element_to_galerkin() {
    // Convection-dominated (eps = H^3/lambda_bar ~ 1e-4): SUPG acts.
    let fluid = fluid_exp_dh(1e4);
    let verts = [[0.0, 0.0], [0.3, 0.05], [0.05, 0.25]];
    let h = [1.0, 1.2, 1.1, 1.1, 1.15, 1.05];
    let vel = [[1.0, 0.0]; 3];
    let supg = production_supg();
    let ncp = Stabilisation { complementarity: true, ..supg };
    let cav = reynolds_element(&verts, &[0.0; 6], &h, &vel, &fluid, &ncp);
    let gal = reynolds_element(&verts, &[0.0; 6], &h, &vel, &fluid, &Stabilisation::none());
    let with_supg = reynolds_element(&verts, &[0.0; 6], &h, &vel, &fluid, &Stabilisation { penalty: 0.0, ..supg });
    for i in 0..6 {
        assert!((cav.r[i] - gal.r[i]).abs() < 1e-14, "row {i}: {} vs {}", cav.r[i], gal.r[i]);
    }
    let scale = gal.r.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    assert!(
        (0..6).any(|i| (with_supg.r[i] - gal.r[i]).abs() > 1e-3 * scale),
        "SUPG must act on this element without complementarity: {:?} vs {:?}",
        with_supg.r,
        gal.r
    );
    let p = [0.4, 0.5, 0.45, 0.47, 0.48, 0.42];
    let a = reynolds_element(&verts, &p, &h, &vel, &fluid, &ncp);
    let b = reynolds_element(&verts, &p, &h, &vel, &fluid, &supg);
    for i in 0..6 {
        assert!((a.r[i] - b.r[i]).abs() < 1e-14 * (1.0 + b.r[i].abs()), "row {i}");
    }
}

/// Under complementarity the SUPG term is weighted by the pressurised ramp of P and
/// subtracts the cavitated nodes' multipliers, each weighted by 1 - pressurised(P_k): the
/// element's Jacobian stays exact on elements that straddle the cavitation boundary
/// (nodal pressures inside and on both sides of the ramp), with and without the
/// multipliers (given nodal values; their own derivatives are the chain rule's, tested on a
/// patch below).
#[test]
fn jacobian_matches_finite_differences_across_the_cavitation_boundary() {
    use crate::reynolds::element::reynolds_element_with_multiplier;
    let mut rng = Lcg(777);
    let fluid = fluid_exp_dh(0.3);
    let stab = Stabilisation { complementarity: true, ..production_supg() };
    let stab = Stabilisation { penalty: 0.0, ..stab };
    let mut worst: f64 = 0.0;
    for _ in 0..20 {
        let verts = random_triangle(&mut rng);
        // Two nodes cavitated, two inside the ramp, two pressurised; every FD step stays on
        // its side (1e-6 against distances of 1e-5 and more to 0 and PRESSURISED_RAMP).
        let ramp = crate::reynolds::cavitation::PRESSURISED_RAMP;
        let p: [f64; 6] = std::array::from_fn(|k| match k % 3 {
            0 => -rng.range(1e-5, 1e-3),
            1 => ramp * rng.range(0.05, 0.95),
            _ => rng.range(0.01, 0.5),
        });
        let h: [f64; 6] = std::array::from_fn(|_| rng.range(0.3, 1.5));
        let vel = rigid_vel(&verts, rng.range(0.2, 1.0), rng.range(-0.5, 0.5), rng.range(-2.0, 2.0));
        let g: [f64; 6] = std::array::from_fn(|_| rng.range(-0.5, 2.0));
        worst = worst.max(fd_jacobian_error(&verts, &p, &h, &vel, &fluid, &stab));
        // The multiplier's weight curves by 6/ramp^2 inside the ramp: with steps of 1e-6 the
        // central differences' own error reaches 1e-5 of the row there; with 1e-7 the worst
        // difference measured is 8e-7.
        let with_g = |p: &[f64; 6], h: &[f64; 6]| reynolds_element_with_multiplier(&verts, p, h, &vel, &fluid, &stab, &g);
        worst = worst.max(fd_jacobian_error_of(with_g, &p, &h, 1e-7));
    }
    assert!(worst < 1e-5, "Jacobian error {worst}");
}

/// The multiplier's chain rule: on a patch of P2 triangles straddling a cavitation boundary,
/// the assembled residual with the measured multipliers has, inside the Reynolds rows'
/// pattern, the Jacobian that the element derivatives plus [`Multipliers::chain`] give
/// (central differences in every nodal P and H), and the chain adds nothing beyond it.
#[test]
fn the_multiplier_chain_rule_matches_finite_differences_inside_the_pattern() {
    use crate::reynolds::element::reynolds_element_with_multiplier;
    use crate::reynolds::multiplier::{FaceElement, Multipliers};
    // A 3 x 3 grid of squares on [0, 0.6]^2, each cut into two P2 triangles.
    let n = 3;
    let s = 0.2;
    let vid = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    let mut xy: Vec<[f64; 2]> = (0..=n).flat_map(|i| (0..=n).map(move |j| [i as f64 * s, j as f64 * s])).collect();
    let mut mids = std::collections::HashMap::new();
    let mut mid = |a: u32, b: u32, xy: &mut Vec<[f64; 2]>| {
        *mids.entry((a.min(b), a.max(b))).or_insert_with(|| {
            let (p, q) = (xy[a as usize], xy[b as usize]);
            xy.push([0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])]);
            (xy.len() - 1) as u32
        })
    };
    let mut tris: Vec<[u32; 6]> = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for [a, b, c] in [[vid(i, j), vid(i + 1, j), vid(i + 1, j + 1)], [vid(i, j), vid(i + 1, j + 1), vid(i, j + 1)]] {
                let (m0, m1, m2) = (mid(a, b, &mut xy), mid(b, c, &mut xy), mid(c, a, &mut xy));
                tris.push([a, b, c, m0, m1, m2]);
            }
        }
    }
    let nn = xy.len();
    let verts: Vec<[[f64; 2]; 3]> = tris.iter().map(|t| [xy[t[0] as usize], xy[t[1] as usize], xy[t[2] as usize]]).collect();
    let vel: Vec<[[f64; 2]; 3]> = verts.iter().map(|v| v.map(|_| [1.0, 0.3])).collect();
    let areas: Vec<f64> = verts.iter().map(crate::fem::p2tri::tri_area).collect();
    let fluid = fluid_exp_dh(0.3);
    let stab = Stabilisation { complementarity: true, penalty: 0.0, ..production_supg() };
    // Pressurised for X < 0.3, cavitated beyond (P = -1e-4 .. 0), a band inside the ramp.
    let mut rng = Lcg(4242);
    let ramp = crate::reynolds::cavitation::PRESSURISED_RAMP;
    let p0: Vec<f64> = xy
        .iter()
        .map(|c| {
            if c[0] < 0.25 {
                rng.range(0.05, 0.4)
            } else if c[0] < 0.35 {
                ramp * rng.range(0.1, 0.9)
            } else {
                -rng.range(1e-5, 1e-4)
            }
        })
        .collect();
    let h0: Vec<f64> = (0..nn).map(|_| rng.range(0.4, 1.2)).collect();
    let mut mult = Multipliers::new(&tris, &areas);
    let face =
        |t: usize, p: &[f64], h: &[f64]| -> ([f64; 6], [f64; 6]) { (tris[t].map(|k| p[k as usize]), tris[t].map(|k| h[k as usize])) };
    let residual = |p: &[f64], h: &[f64], mult: &mut Multipliers| -> Vec<f64> {
        mult.evaluate(
            tris.len(),
            |t| {
                let (pe, he) = face(t, p, h);
                FaceElement { nodes: &tris[t], verts: &verts[t], vel: &vel[t], p: pe, h: he }
            },
            &fluid,
            &stab,
        );
        let mut r = vec![0.0; nn];
        for t in 0..tris.len() {
            let (pe, he) = face(t, p, h);
            let out = reynolds_element_with_multiplier(&verts[t], &pe, &he, &vel[t], &fluid, &stab, &mult.of(&tris[t]));
            for k in 0..6 {
                r[tris[t][k] as usize] += out.r[k];
            }
        }
        r
    };
    // The Jacobian: element derivatives plus the multiplier's chain rule (columns: P then H).
    let mut jac = vec![vec![0.0; 2 * nn]; nn];
    residual(&p0, &h0, &mut mult);
    for t in 0..tris.len() {
        let (pe, he) = face(t, &p0, &h0);
        let out = reynolds_element_with_multiplier(&verts[t], &pe, &he, &vel[t], &fluid, &stab, &mult.of(&tris[t]));
        for i in 0..6 {
            for k in 0..6 {
                jac[tris[t][i] as usize][tris[t][k] as usize] += out.dr_dp[i][k];
                jac[tris[t][i] as usize][nn + tris[t][k] as usize] += out.dr_dh[i][k];
            }
        }
        let element = |u: usize| {
            let (pu, hu) = face(u, &p0, &h0);
            FaceElement { nodes: &tris[u], verts: &verts[u], vel: &vel[u], p: pu, h: hu }
        };
        mult.chain(&tris[t], &out.dr_dm, element, &fluid, &stab, |i, col, dp, dh| {
            jac[tris[t][i] as usize][col as usize] += dp;
            jac[tris[t][i] as usize][nn + col as usize] += dh;
        });
    }
    // The Reynolds rows' pattern: the nodes sharing a triangle with the row's node. Inside it
    // the Jacobian is exact; the multiplier's entries beyond it are dropped (never assembled).
    let shares = |r: usize, c: usize| tris.iter().any(|t| t.contains(&(r as u32)) && t.contains(&(c as u32)));
    let step = 1e-7;
    let (mut worst, mut beyond): (f64, f64) = (0.0, 0.0);
    let scale = jac.iter().flatten().fold(0.0f64, |a, b| a.max(b.abs()));
    for c in 0..2 * nn {
        let (mut pp, mut hp, mut pm, mut hm) = (p0.clone(), h0.clone(), p0.clone(), h0.clone());
        if c < nn {
            pp[c] += step;
            pm[c] -= step;
        } else {
            hp[c - nn] += step;
            hm[c - nn] -= step;
        }
        let (rp, rm) = (residual(&pp, &hp, &mut mult), residual(&pm, &hm, &mut mult));
        for r in 0..nn {
            let fd = (rp[r] - rm[r]) / (2.0 * step);
            if shares(r, c % nn) {
                worst = worst.max((fd - jac[r][c]).abs() / scale);
            } else {
                assert_eq!(jac[r][c], 0.0, "entry ({r}, {c}) beyond the pattern");
                beyond = beyond.max(fd.abs() / scale);
            }
        }
    }
    assert!(worst < 1e-6, "Jacobian error {worst} (of the largest entry {scale})");
    // The multiplier is in play: some row depends on a node outside its own triangles, and
    // that dependence is what the pattern drops.
    assert!(beyond > 1e-4, "no row depends on a node beyond its triangles ({beyond}): the multiplier did not act");
}
