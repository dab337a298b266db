//! Linear isotropic elasticity on P2 tetrahedra.
//!
//! The elastic half-spaces of the contact are replaced by one equivalent linear-elastic
//! body; its element stiffness is the bilinear form
//! `a(u, v) = int_T sigma(u) : eps(v) dx`, `sigma = lambda tr(eps) I + 2 mu eps`,
//! `eps = (grad u + grad u^T)/2`.
//! For a straight-sided P2 tetrahedron the integrand is a polynomial of degree 2, so the
//! 4-point degree-2 rule integrates it exactly.
//!
//! In terms of `G_ab[i][j] = int_T dN_a/dx_i dN_b/dx_j dx` the 3x3 block coupling node `a`
//! (row) and node `b` (column) is
//! `K[3a+i][3b+j] = lambda G_ab[i][j] + mu G_ab[j][i] + mu delta_ij tr G_ab`.
use super::geometry::AffineTet;
use super::p2tet::p2_tet_grads_bary;
use super::quadrature::TET4_BARY;

/// Lamé parameters `(lambda, mu)` from Young's modulus `e` and Poisson's ratio `nu`:
/// `lambda = E nu / ((1 + nu)(1 - 2 nu))`, `mu = E / (2 (1 + nu))`.
#[inline]
pub fn lame(e: f64, nu: f64) -> (f64, f64) {
    (e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), e / (2.0 * (1.0 + nu)))
}

/// Cauchy stress `sigma = lambda tr(eps) I + 2 mu eps` from a displacement gradient
/// `grad[c][d] = du_c/dx_d`.
#[inline]
pub fn stress_from_grad(grad: &[[f64; 3]; 3], lambda: f64, mu: f64) -> [[f64; 3]; 3] {
    let tr = grad[0][0] + grad[1][1] + grad[2][2];
    let mut s = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            s[i][j] = mu * (grad[i][j] + grad[j][i]);
        }
        s[i][i] += lambda * tr;
    }
    s
}

/// Strain-energy density `sigma : eps / 2` for a displacement gradient.
#[inline]
pub fn strain_energy_density(grad: &[[f64; 3]; 3], lambda: f64, mu: f64) -> f64 {
    let tr = grad[0][0] + grad[1][1] + grad[2][2];
    let mut ee = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            let e = 0.5 * (grad[i][j] + grad[j][i]);
            ee += e * e;
        }
    }
    0.5 * lambda * tr * tr + mu * ee
}

/// Core kernel; `set(row, col, value)` is called exactly once per entry.
#[inline(always)]
fn stiffness_impl(verts: &[[f64; 3]; 4], lambda: f64, mu: f64, mut set: impl FnMut(usize, usize, f64)) {
    let geo = AffineTet::new(verts);
    // Each of the 4 points has reference weight 1/24.
    let w = geo.abs_det() / 24.0;
    let mut d = [[[0.0f64; 3]; 10]; 4];
    for q in 0..4 {
        d[q] = p2_tet_grads_bary(TET4_BARY[q], &geo.grad_bary);
    }
    for a in 0..10 {
        for b in a..10 {
            let mut g = [[0.0f64; 3]; 3];
            for dq in &d {
                let (da, db) = (dq[a], dq[b]);
                for i in 0..3 {
                    for j in 0..3 {
                        g[i][j] += da[i] * db[j];
                    }
                }
            }
            let tr = mu * w * (g[0][0] + g[1][1] + g[2][2]);
            let (lw, mw) = (lambda * w, mu * w);
            for i in 0..3 {
                for j in 0..3 {
                    let mut v = lw * g[i][j] + mw * g[j][i];
                    if i == j {
                        v += tr;
                    }
                    set(3 * a + i, 3 * b + j, v);
                    if a != b {
                        set(3 * b + j, 3 * a + i, v);
                    }
                }
            }
        }
    }
}

/// Element stiffness matrix (30 x 30, node-major DOFs `[u_x0, u_y0, u_z0, u_x1, ...]`) of
/// the isotropic linear-elastic P2 tetrahedron with vertices `verts` and Lamé parameters
/// `lambda`, `mu`: `K[r][c] = a(phi_c, phi_r)`, integrated exactly.
#[inline]
pub fn elasticity_stiffness(verts: &[[f64; 3]; 4], lambda: f64, mu: f64) -> [[f64; 30]; 30] {
    let mut k = [[0.0; 30]; 30];
    stiffness_impl(verts, lambda, mu, |r, c, v| k[r][c] = v);
    k
}

/// Same as [`elasticity_stiffness`], written row-major into a flat buffer
/// (`out[30 * r + c]`), the layout expected by `MatSetValues`.
#[inline]
pub fn elasticity_stiffness_flat(verts: &[[f64; 3]; 4], lambda: f64, mu: f64, out: &mut [f64; 900]) {
    stiffness_impl(verts, lambda, mu, |r, c, v| out[30 * r + c] = v);
}

/// Element residual/action `K u` for a local displacement vector, without forming `K`
/// explicitly (useful for matrix-free products and energy checks).
pub fn elasticity_apply(verts: &[[f64; 3]; 4], lambda: f64, mu: f64, u: &[f64; 30]) -> [f64; 30] {
    let geo = AffineTet::new(verts);
    let w = geo.abs_det() / 24.0;
    let mut out = [0.0; 30];
    for l in &TET4_BARY {
        let d = p2_tet_grads_bary(*l, &geo.grad_bary);
        let mut g = [[0.0; 3]; 3];
        for a in 0..10 {
            for c in 0..3 {
                for k in 0..3 {
                    g[c][k] += u[3 * a + c] * d[a][k];
                }
            }
        }
        let s = stress_from_grad(&g, lambda, mu);
        for a in 0..10 {
            for i in 0..3 {
                out[3 * a + i] += w * (s[i][0] * d[a][0] + s[i][1] * d[a][1] + s[i][2] * d[a][2]);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::p2tet::{p2_tet_basis_bary, p2_tet_node_coords};
    use crate::fem::quadrature::tet_rule;
    use nalgebra::{DMatrix, Matrix3, Vector3};

    fn verts() -> [[f64; 3]; 4] {
        [[0.1, -0.2, 0.3], [1.3, 0.1, 0.2], [0.2, 0.9, -0.1], [0.4, 0.3, 1.1]]
    }
    fn lm() -> (f64, f64) {
        lame(1.0, 0.3)
    }
    fn maxabs(k: &[[f64; 30]; 30]) -> f64 {
        k.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()))
    }

    #[test]
    fn lame_values() {
        let (l, m) = lame(1.0, 0.3);
        assert!((l - 0.3 / (1.3 * 0.4)).abs() < 1e-15);
        assert!((m - 1.0 / 2.6).abs() < 1e-15);
    }

    #[test]
    fn symmetric_and_flat_consistent() {
        let (l, m) = lm();
        let k = elasticity_stiffness(&verts(), l, m);
        let mut f = [0.0; 900];
        elasticity_stiffness_flat(&verts(), l, m, &mut f);
        let s = maxabs(&k);
        for r in 0..30 {
            for c in 0..30 {
                assert!((k[r][c] - k[c][r]).abs() <= 1e-15 * s);
                assert_eq!(k[r][c], f[30 * r + c]);
            }
        }
    }

    fn rigid_modes(x: &[[f64; 3]; 10]) -> Vec<[f64; 30]> {
        let mut modes = Vec::new();
        for c in 0..3 {
            let mut u = [0.0; 30];
            for a in 0..10 {
                u[3 * a + c] = 1.0;
            }
            modes.push(u);
        }
        for axis in 0..3 {
            let mut w = [0.0; 3];
            w[axis] = 1.0;
            let mut u = [0.0; 30];
            for a in 0..10 {
                let p = x[a];
                let r = [w[1] * p[2] - w[2] * p[1], w[2] * p[0] - w[0] * p[2], w[0] * p[1] - w[1] * p[0]];
                u[3 * a..3 * a + 3].copy_from_slice(&r);
            }
            modes.push(u);
        }
        modes
    }

    #[test]
    fn rigid_body_modes_in_null_space() {
        let (l, m) = lm();
        let v = verts();
        let k = elasticity_stiffness(&v, l, m);
        let s = maxabs(&k);
        for u in rigid_modes(&p2_tet_node_coords(&v)) {
            let un = u.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            for r in 0..30 {
                let ku: f64 = (0..30).map(|c| k[r][c] * u[c]).sum();
                assert!(ku.abs() <= 1e-12 * s * un, "row {r}: {ku}");
            }
        }
    }

    #[test]
    fn patch_test_linear_field() {
        let (l, m) = lm();
        let v = verts();
        let x = p2_tet_node_coords(&v);
        let a = [[0.3, -0.2, 0.5], [0.1, 0.4, -0.7], [0.6, 0.2, -0.1]];
        let b = [0.1, 0.2, -0.3];
        let mut u = [0.0; 30];
        for n in 0..10 {
            for c in 0..3 {
                u[3 * n + c] = b[c] + (0..3).map(|d| a[c][d] * x[n][d]).sum::<f64>();
            }
        }
        let k = elasticity_stiffness(&v, l, m);
        let uku: f64 = (0..30).map(|r| u[r] * (0..30).map(|c| k[r][c] * u[c]).sum::<f64>()).sum();
        let sig = stress_from_grad(&a, l, m);
        let mut se = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                se += sig[i][j] * 0.5 * (a[i][j] + a[j][i]);
            }
        }
        let vol = AffineTet::new(&v).volume();
        assert!((uku - vol * se).abs() < 1e-13 * uku.abs(), "{uku} vs {}", vol * se);
        // Matrix-free action agrees with K u.
        let ku = elasticity_apply(&v, l, m, &u);
        for r in 0..30 {
            let kr: f64 = (0..30).map(|c| k[r][c] * u[c]).sum();
            assert!((kr - ku[r]).abs() < 1e-13 * maxabs(&k));
        }
        // The P2 stress of a linear field is constant: the element traction balance
        // K u equals the consistent boundary load, whose total force is zero.
        for c in 0..3 {
            let tot: f64 = (0..10).map(|n| ku[3 * n + c]).sum();
            assert!(tot.abs() < 1e-13);
        }
    }

    #[test]
    fn psd_with_six_zero_eigenvalues() {
        let (l, m) = lm();
        for v in [
            verts(),
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            [[0.0, 0.0, 0.0], [3.0, 0.1, 0.0], [0.2, 0.05, 0.02], [0.1, 0.2, 0.4]],
        ] {
            let k = elasticity_stiffness(&v, l, m);
            let mat = DMatrix::from_fn(30, 30, |r, c| k[r][c]);
            let eig = mat.symmetric_eigen();
            let emax = eig.eigenvalues.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            let zeros = eig.eigenvalues.iter().filter(|e| e.abs() < 1e-10 * emax).count();
            let neg = eig.eigenvalues.iter().filter(|e| **e < -1e-10 * emax).count();
            assert_eq!(zeros, 6, "eigenvalues {:?}", eig.eigenvalues);
            assert_eq!(neg, 0);
        }
    }

    /// Independent check: strain energy computed by quadrature with the 14-point rule and
    /// displacement gradients obtained by central finite differences of the interpolated
    /// field in physical space (the physical-to-barycentric map solved with nalgebra), then
    /// `K_rc = E(e_r + e_c) - E(e_r) - E(e_c)` (exact for the quadratic energy).
    #[test]
    fn entries_match_energy_differentiation() {
        let (l, m) = lm();
        let v = verts();
        let k = elasticity_stiffness(&v, l, m);
        let jm = Matrix3::from_fn(|i, j| v[j + 1][i] - v[0][i]);
        let jinv = jm.try_inverse().unwrap();
        let bary = |x: [f64; 3]| {
            let xi = jinv * Vector3::new(x[0] - v[0][0], x[1] - v[0][1], x[2] - v[0][2]);
            [1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]]
        };
        let field = |u: &[f64; 30], x: [f64; 3]| {
            let n = p2_tet_basis_bary(bary(x));
            let mut r = [0.0; 3];
            for a in 0..10 {
                for c in 0..3 {
                    r[c] += n[a] * u[3 * a + c];
                }
            }
            r
        };
        let rule = tet_rule(5);
        let det = jm.determinant().abs();
        let energy = |u: &[f64; 30]| {
            let h = 1e-4;
            let mut e = 0.0;
            for (p, w) in rule.iter() {
                let x: [f64; 3] = std::array::from_fn(|i| v[0][i] + (0..3).map(|j| jm[(i, j)] * p[j]).sum::<f64>());
                let mut g = [[0.0; 3]; 3];
                for d in 0..3 {
                    let (mut xp, mut xm) = (x, x);
                    xp[d] += h;
                    xm[d] -= h;
                    let (up, um) = (field(u, xp), field(u, xm));
                    for c in 0..3 {
                        g[c][d] = (up[c] - um[c]) / (2.0 * h);
                    }
                }
                e += w * det * strain_energy_density(&g, l, m);
            }
            e
        };
        let unit = |r: usize| {
            let mut u = [0.0; 30];
            u[r] = 1.0;
            u
        };
        let s = maxabs(&k);
        for (r, c) in [(0, 0), (0, 1), (3, 14), (12, 12), (13, 29), (29, 29), (5, 22), (17, 8)] {
            let mut uc = unit(r);
            uc[c] += 1.0;
            let kn = if r == c { 2.0 * energy(&unit(r)) } else { energy(&uc) - energy(&unit(r)) - energy(&unit(c)) };
            assert!((kn - k[r][c]).abs() < 1e-7 * s, "K[{r}][{c}] = {} vs numerical {kn}", k[r][c]);
        }
    }

    #[test]
    fn timing_report() {
        // Not a strict benchmark; prints the per-element cost in release builds.
        let (l, m) = lm();
        let mut v = verts();
        let n = if cfg!(debug_assertions) { 2_000 } else { 200_000 };
        let mut acc = 0.0;
        let mut out = [0.0; 900];
        let t = std::time::Instant::now();
        for i in 0..n {
            v[3][2] = 1.1 + 1e-7 * i as f64;
            elasticity_stiffness_flat(&v, l, m, &mut out);
            acc += out[37];
        }
        let dt = t.elapsed().as_secs_f64();
        eprintln!("elasticity_stiffness_flat: {:.3} us/element (acc {acc:.3})", 1e6 * dt / n as f64);
    }
}
