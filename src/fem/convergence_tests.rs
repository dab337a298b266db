//! Manufactured-solution convergence test of the P2 elasticity element (test-only).
//!
//! Unit cube, Kuhn mesh with n = 2, 4, 8 cells per direction, Dirichlet data from the
//! exact field on the whole boundary (nodal interpolation), body force
//! `f = -div sigma(u)` derived analytically, system solved with a small CSR +
//! Jacobi-preconditioned CG. Expected rates: L2 ~ h^3, H1 seminorm ~ h^2.
use super::elasticity::{elasticity_stiffness, lame, stress_from_grad};
use super::loads::body_force_load;
use super::norms::{h1_seminorm_error_sq, l2_error_sq};
use super::quadrature::tet_rule;
use super::testmesh::kuhn_box_mesh;
use std::f64::consts::PI;

/// 1D factor of a separable exact field: value, first and second derivative.
#[derive(Clone, Copy)]
enum F1 {
    Sin(f64),
    Cos(f64),
    Exp(f64),
}

impl F1 {
    fn eval(self, x: f64) -> [f64; 3] {
        match self {
            F1::Sin(k) => [(k * x).sin(), k * (k * x).cos(), -k * k * (k * x).sin()],
            F1::Cos(k) => [(k * x).cos(), -k * (k * x).sin(), -k * k * (k * x).cos()],
            F1::Exp(k) => {
                let e = (k * x).exp();
                [e, k * e, k * k * e]
            }
        }
    }
}

/// u_c(x, y, z) = F[c][0](x) F[c][1](y) F[c][2](z), a different smooth field per component.
const FIELD: [[F1; 3]; 3] =
    [[F1::Sin(PI), F1::Sin(PI), F1::Sin(PI)], [F1::Exp(1.0), F1::Sin(PI), F1::Cos(0.5 * PI)], [F1::Cos(PI), F1::Sin(2.0), F1::Exp(0.5)]];

/// Per component, per direction: [value, d1, d2] of each 1D factor.
fn factors(x: [f64; 3]) -> [[[f64; 3]; 3]; 3] {
    std::array::from_fn(|c| std::array::from_fn(|d| FIELD[c][d].eval(x[d])))
}

fn exact_u(x: [f64; 3]) -> [f64; 3] {
    let f = factors(x);
    std::array::from_fn(|c| f[c][0][0] * f[c][1][0] * f[c][2][0])
}

/// grad[c][d] = du_c/dx_d.
fn exact_grad(x: [f64; 3]) -> [[f64; 3]; 3] {
    let f = factors(x);
    std::array::from_fn(|c| std::array::from_fn(|d| (0..3).map(|e| f[c][e][if e == d { 1 } else { 0 }]).product()))
}

/// hess[c][d][e] = d^2 u_c / dx_d dx_e (product rule on the separable factors).
fn exact_hess(x: [f64; 3]) -> [[[f64; 3]; 3]; 3] {
    let f = factors(x);
    std::array::from_fn(|c| {
        std::array::from_fn(|d| {
            std::array::from_fn(|e| {
                (0..3)
                    .map(|m| {
                        let order = (m == d) as usize + (m == e) as usize;
                        f[c][m][order]
                    })
                    .product()
            })
        })
    })
}

/// Body force f = -div sigma(u). With sigma = lambda div(u) I + mu (grad u + grad u^T):
/// (div sigma)_i = (lambda + mu) d_i (div u) + mu Laplace u_i
///               = (lambda + mu) sum_j d_i d_j u_j + mu sum_j d_j d_j u_i.
fn body_force(x: [f64; 3], lambda: f64, mu: f64) -> [f64; 3] {
    let h = exact_hess(x);
    std::array::from_fn(|i| {
        let grad_div: f64 = (0..3).map(|j| h[j][i][j]).sum();
        let lap: f64 = (0..3).map(|j| h[i][j][j]).sum();
        -((lambda + mu) * grad_div + mu * lap)
    })
}

/// Minimal CSR matrix.
struct Csr {
    n: usize,
    ptr: Vec<usize>,
    col: Vec<u32>,
    val: Vec<f64>,
}

impl Csr {
    fn from_triplets(n: usize, mut t: Vec<(u32, u32, f64)>) -> Csr {
        t.sort_unstable_by_key(|&(r, c, _)| ((r as u64) << 32) | c as u64);
        let mut ptr = vec![0usize; n + 1];
        let mut col = Vec::new();
        let mut val: Vec<f64> = Vec::new();
        let mut last: Option<(u32, u32)> = None;
        for (r, c, v) in t {
            if last == Some((r, c)) {
                *val.last_mut().unwrap() += v;
            } else {
                col.push(c);
                val.push(v);
                ptr[r as usize + 1] += 1;
                last = Some((r, c));
            }
        }
        for i in 0..n {
            ptr[i + 1] += ptr[i];
        }
        Csr { n, ptr, col, val }
    }
    fn matvec(&self, x: &[f64], y: &mut [f64]) {
        for i in 0..self.n {
            let mut s = 0.0;
            for k in self.ptr[i]..self.ptr[i + 1] {
                s += self.val[k] * x[self.col[k] as usize];
            }
            y[i] = s;
        }
    }
    fn diag(&self) -> Vec<f64> {
        (0..self.n).map(|i| (self.ptr[i]..self.ptr[i + 1]).find(|&k| self.col[k] as usize == i).map_or(0.0, |k| self.val[k])).collect()
    }
    fn max_asym(&self) -> f64 {
        let mut m: f64 = 0.0;
        for i in 0..self.n {
            for k in self.ptr[i]..self.ptr[i + 1] {
                let j = self.col[k] as usize;
                let kt = (self.ptr[j]..self.ptr[j + 1]).find(|&q| self.col[q] as usize == i).unwrap();
                m = m.max((self.val[k] - self.val[kt]).abs());
            }
        }
        m
    }
}

/// Jacobi-preconditioned conjugate gradients; returns (solution, iterations).
fn pcg(a: &Csr, b: &[f64], rtol: f64, max_it: usize) -> (Vec<f64>, usize) {
    let n = a.n;
    let dinv: Vec<f64> = a.diag().iter().map(|d| 1.0 / d).collect();
    let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(a, b)| a * b).sum::<f64>();
    let mut x = vec![0.0; n];
    let mut r = b.to_vec();
    let mut z: Vec<f64> = r.iter().zip(&dinv).map(|(r, d)| r * d).collect();
    let mut p = z.clone();
    let mut q = vec![0.0; n];
    let mut rz = dot(&r, &z);
    let bnorm = dot(b, b).sqrt();
    for it in 0..max_it {
        if dot(&r, &r).sqrt() <= rtol * bnorm {
            return (x, it);
        }
        a.matvec(&p, &mut q);
        let alpha = rz / dot(&p, &q);
        for i in 0..n {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
            z[i] = r[i] * dinv[i];
        }
        let rz_new = dot(&r, &z);
        let beta = rz_new / rz;
        rz = rz_new;
        for i in 0..n {
            p[i] = z[i] + beta * p[i];
        }
    }
    panic!("PCG did not converge in {max_it} iterations");
}

/// Solve the manufactured problem on an n^3 Kuhn mesh; returns (L2 error, H1-seminorm error).
fn solve(n: usize, lambda: f64, mu: f64) -> (f64, f64, usize) {
    let (nodes, tets) = kuhn_box_mesh([n; 3], [0.0; 3], [1.0; 3]);
    let nn = nodes.len();
    let on_bnd = |x: &[f64; 3]| x.iter().any(|&c| c.abs() < 1e-12 || (c - 1.0).abs() < 1e-12);
    // DOF numbering: free DOFs get consecutive ids; Dirichlet DOFs carry the exact value.
    let mut free = vec![u32::MAX; 3 * nn];
    let mut g = vec![0.0; 3 * nn];
    let mut nfree = 0u32;
    for (i, x) in nodes.iter().enumerate() {
        if on_bnd(x) {
            g[3 * i..3 * i + 3].copy_from_slice(&exact_u(*x));
        } else {
            for c in 0..3 {
                free[3 * i + c] = nfree;
                nfree += 1;
            }
        }
    }
    let nf = nfree as usize;
    let mut rhs = vec![0.0; nf];
    let mut trip = Vec::with_capacity(tets.len() * 900);
    let rule_f = tet_rule(8);
    for t in &tets {
        let v: [[f64; 3]; 4] = std::array::from_fn(|m| nodes[t[m] as usize]);
        let k = elasticity_stiffness(&v, lambda, mu);
        let f = body_force_load(&v, |x| body_force(x, lambda, mu), rule_f);
        let gdof = |r: usize| 3 * t[r / 3] as usize + r % 3;
        for r in 0..30 {
            let fr = free[gdof(r)];
            if fr == u32::MAX {
                continue;
            }
            rhs[fr as usize] += f[r];
            for c in 0..30 {
                let gc = gdof(c);
                let fc = free[gc];
                if fc == u32::MAX {
                    rhs[fr as usize] -= k[r][c] * g[gc];
                } else {
                    trip.push((fr, fc, k[r][c]));
                }
            }
        }
    }
    let a = Csr::from_triplets(nf, trip);
    let amax = a.val.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(a.max_asym() <= 1e-14 * amax, "assembled matrix not symmetric");
    let (x, iters) = pcg(&a, &rhs, 1e-12, 20 * nf + 100);
    let mut u = g;
    for i in 0..3 * nn {
        if free[i] != u32::MAX {
            u[i] = x[free[i] as usize];
        }
    }
    let rule_e = tet_rule(8);
    let (mut e0, mut e1) = (0.0, 0.0);
    for t in &tets {
        let v: [[f64; 3]; 4] = std::array::from_fn(|m| nodes[t[m] as usize]);
        let ul: [f64; 30] = std::array::from_fn(|r| u[3 * t[r / 3] as usize + r % 3]);
        e0 += l2_error_sq(&v, &ul, exact_u, rule_e);
        e1 += h1_seminorm_error_sq(&v, &ul, exact_grad, rule_e);
    }
    (e0.sqrt(), e1.sqrt(), iters)
}

#[test]
fn manufactured_body_force_matches_finite_differences() {
    let (lambda, mu) = lame(1.0, 0.3);
    let h = 1e-5;
    for x in [[0.3, 0.6, 0.2], [0.9, 0.1, 0.45], [0.5, 0.5, 0.5]] {
        // Check the hand-derived gradient against FD of u.
        let g = exact_grad(x);
        for d in 0..3 {
            let (mut xp, mut xm) = (x, x);
            xp[d] += h;
            xm[d] -= h;
            let (up, um) = (exact_u(xp), exact_u(xm));
            for c in 0..3 {
                assert!(((up[c] - um[c]) / (2.0 * h) - g[c][d]).abs() < 1e-8);
            }
        }
        // f = -div sigma with sigma from the exact gradient, divergence by central FD.
        let f = body_force(x, lambda, mu);
        let mut div = [0.0; 3];
        for j in 0..3 {
            let (mut xp, mut xm) = (x, x);
            xp[j] += h;
            xm[j] -= h;
            let sp = stress_from_grad(&exact_grad(xp), lambda, mu);
            let sm = stress_from_grad(&exact_grad(xm), lambda, mu);
            for i in 0..3 {
                div[i] += (sp[i][j] - sm[i][j]) / (2.0 * h);
            }
        }
        for i in 0..3 {
            assert!((f[i] + div[i]).abs() < 1e-6 * (1.0 + f[i].abs()), "f[{i}] = {} vs {}", f[i], -div[i]);
        }
    }
}

#[test]
fn p2_elasticity_converges_at_optimal_rates() {
    let (lambda, mu) = lame(1.0, 0.3);
    let ns = [2usize, 4, 8];
    let res: Vec<(f64, f64, usize)> = ns.iter().map(|&n| solve(n, lambda, mu)).collect();
    for (n, (e0, e1, it)) in ns.iter().zip(&res) {
        eprintln!("n = {n}: L2 error {e0:.4e}, H1 error {e1:.4e}, PCG its {it}");
    }
    for k in 1..ns.len() {
        let r0 = (res[k - 1].0 / res[k].0).log2();
        let r1 = (res[k - 1].1 / res[k].1).log2();
        eprintln!("rates {} -> {}: L2 {r0:.3}, H1 {r1:.3}", ns[k - 1], ns[k]);
        if k == ns.len() - 1 {
            assert!(r0 > 2.7, "L2 rate {r0}");
            assert!(r1 > 1.8, "H1 rate {r1}");
        }
    }
}
