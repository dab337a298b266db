//! Linear (P1) element of the dimensionless Reynolds equation on one straight triangle
//! (Galerkin, optionally with the SUPG of [`super::element`]), with its exact Jacobian (forward-mode duals over the 3 nodal P and 3 nodal H):
//! ```text
//!   R_i = int_T [ eps grad P . grad L_i - rho_bar H (v . grad L_i) ],
//!   eps = rho_bar H^3 / (eta_bar lambda_bar).
//! ```
//! Used on the 4 sub-triangles of each P2 face triangle ("P1-iso-P2" pressure): the same
//! nodes as P2, but every basis function integrates to area/3 > 0, so every nodal pressure
//! carries load (a P2 vertex function integrates to zero).
use super::dual::Dual;
use super::element::{streamline_length_from_gradients, strong_residual, supg_tau, Fluid, PointFields, Stabilisation};
use super::quadrature::DUNAVANT6;

type D6 = Dual<6>;

/// Residual, dR/dP and dR/dH of one P1 triangle. `vel`: entrainment at the 3 vertices.
pub fn reynolds_p1_element(verts: &[[f64; 2]; 3], p: &[f64; 3], h: &[f64; 3], vel: &[[f64; 2]; 3], fluid: &Fluid) -> ([f64; 3], [[f64; 3]; 3], [[f64; 3]; 3]) {
    reynolds_p1_element_stab(verts, p, h, vel, fluid, &Stabilisation::none())
}

/// As [`reynolds_p1_element`], with the SUPG term of [`Stabilisation`] (P is linear, so
/// Lap P = 0 in the strong residual; the penalty enters it interpolated linearly).
pub fn reynolds_p1_element_stab(verts: &[[f64; 2]; 3], p: &[f64; 3], h: &[f64; 3], vel: &[[f64; 2]; 3], fluid: &Fluid, stab: &Stabilisation) -> ([f64; 3], [[f64; 3]; 3], [[f64; 3]; 3]) {
    let (x, z) = (verts.map(|v| v[0]), verts.map(|v| v[1]));
    let det = (x[1] - x[0]) * (z[2] - z[0]) - (x[2] - x[0]) * (z[1] - z[0]);
    let area = 0.5 * det.abs();
    // grad L_k = (z_{k+1} - z_{k+2}, x_{k+2} - x_{k+1}) / det
    let g: [[f64; 2]; 3] = std::array::from_fn(|k| {
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        [(z[a] - z[b]) / det, (x[b] - x[a]) / det]
    });
    let pd: [D6; 3] = std::array::from_fn(|j| D6::variable(p[j], j));
    let hd: [D6; 3] = std::array::from_fn(|j| D6::variable(h[j], 3 + j));
    let mut gp = [D6::constant(0.0); 2];
    for j in 0..3 {
        for c in 0..2 {
            gp[c] += pd[j] * g[j][c];
        }
    }
    let mut res = [D6::constant(0.0); 3];
    for q in DUNAVANT6.iter() {
        let l = q.l;
        let wq = q.w * area;
        let mut pq = D6::constant(0.0);
        let mut hq = D6::constant(0.0);
        for j in 0..3 {
            pq += pd[j] * l[j];
            hq += hd[j] * l[j];
        }
        let v = [0, 1].map(|c| l[0] * vel[0][c] + l[1] * vel[1][c] + l[2] * vel[2][c]);
        let (eta, deta) = (fluid.eta)(pq.v);
        let (rho, drho) = (fluid.rho)(pq.v);
        let eta_d = pq.chain(eta, deta);
        let rho_d = pq.chain(rho, drho);
        let eps = rho_d * hq * hq * hq / (eta_d * fluid.lambda_bar);
        let rho_h = rho_d * hq;
        for i in 0..3 {
            let flux = gp[0] * g[i][0] + gp[1] * g[i][1];
            let vg = v[0] * g[i][0] + v[1] * g[i][1];
            res[i] += (eps * flux - rho_h * vg) * wq;
        }
        if stab.supg {
            let vn = (v[0] * v[0] + v[1] * v[1]).sqrt();
            if vn == 0.0 {
                continue;
            }
            let drho_d = pq.chain(drho, (fluid.d2rho)(pq.v));
            let mut gh = [D6::constant(0.0); 2];
            for j in 0..3 {
                for c in 0..2 {
                    gh[c] += hd[j] * g[j][c];
                }
            }
            let div_v: f64 = (0..3).map(|k| vel[k][0] * g[k][0] + vel[k][1] * g[k][1]).sum();
            let mut pen = D6::constant(0.0);
            if stab.penalty > 0.0 {
                for j in 0..3 {
                    let (pv, pdv) = super::cavitation::penalty_law(p[j]);
                    pen += pd[j].chain(pv, pdv) * (stab.penalty * l[j]);
                }
            }
            let fields = PointFields { h: hq, grad_p: gp, grad_h: gh, rho: rho_d, drho: drho_d, eta: eta_d, deta: pq.chain(deta, (fluid.d2eta)(pq.v)), eps };
            // P is linear: Lap P = 0.
            let r_strong = strong_residual(stab, &fields, fluid.lambda_bar, D6::constant(0.0), v, div_v, pen);
            let tau = supg_tau(stab, vn, streamline_length_from_gradients(&g, v), eps, drho_d, hq);
            let t_r = tau * r_strong * wq;
            for i in 0..3 {
                res[i] += t_r * (v[0] * g[i][0] + v[1] * g[i][1]);
            }
        }
    }
    let r = res.map(|d| d.v);
    let dp = res.map(|d| [d.d[0], d.d[1], d.d[2]]);
    let dh = res.map(|d| [d.d[3], d.d[4], d.d[5]]);
    (r, dp, dh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reynolds::element::StrongResidual;

    /// A lubricant law: value and derivative.
    type Law = fn(f64) -> (f64, f64);

    fn laws() -> (Law, Law) {
        (|p: f64| ((2.0 * p).exp(), 2.0 * (2.0 * p).exp()), |p: f64| ((1.0 + 2.0 * p) / (1.0 + p), 1.0 / ((1.0 + p) * (1.0 + p))))
    }

    #[test]
    fn jacobian_matches_central_differences() {
        let (eta, rho) = laws();
        let zero = |_: f64| 0.0;
        let fluid = Fluid { eta: &eta, rho: &rho, d2eta: &zero, d2rho: &zero, lambda_bar: 0.3 };
        let verts = [[0.1, -0.2], [0.6, 0.05], [0.2, 0.4]];
        let vel = [[1.0, 0.1], [0.9, -0.2], [1.1, 0.0]];
        let (p, h) = ([0.3, 0.7, 0.5], [0.4, 0.25, 0.6]);
        let (_, dp, dh) = reynolds_p1_element(&verts, &p, &h, &vel, &fluid);
        let d = 1e-6;
        for j in 0..3 {
            let (mut pp, mut pm) = (p, p);
            pp[j] += d;
            pm[j] -= d;
            let (rp, _, _) = reynolds_p1_element(&verts, &pp, &h, &vel, &fluid);
            let (rm, _, _) = reynolds_p1_element(&verts, &pm, &h, &vel, &fluid);
            let (mut hp, mut hm) = (h, h);
            hp[j] += d;
            hm[j] -= d;
            let (sp, _, _) = reynolds_p1_element(&verts, &p, &hp, &vel, &fluid);
            let (sm, _, _) = reynolds_p1_element(&verts, &p, &hm, &vel, &fluid);
            for i in 0..3 {
                assert!((dp[i][j] - (rp[i] - rm[i]) / (2.0 * d)).abs() < 1e-7 * (1.0 + dp[i][j].abs()));
                assert!((dh[i][j] - (sp[i] - sm[i]) / (2.0 * d)).abs() < 1e-7 * (1.0 + dh[i][j].abs()));
            }
        }
    }

    #[test]
    fn supg_jacobian_matches_central_differences() {
        let eta = |p: f64| ((2.0 * p).exp(), 2.0 * (2.0 * p).exp());
        let d2eta = |p: f64| 4.0 * (2.0 * p).exp();
        let rho = |p: f64| ((1.0 + 2.0 * p) / (1.0 + p), 1.0 / ((1.0 + p) * (1.0 + p)));
        let d2rho = |p: f64| -2.0 / ((1.0 + p) * (1.0 + p) * (1.0 + p));
        let fluid = Fluid { eta: &eta, rho: &rho, d2eta: &d2eta, d2rho: &d2rho, lambda_bar: 0.3 };
        let verts = [[0.1, -0.2], [0.6, 0.05], [0.2, 0.4]];
        let vel = [[1.0, 0.1], [0.9, -0.2], [1.1, 0.0]];
        // one node inside the penalty's quadratic zone, one below it
        let (p, h) = ([0.3, -4e-4, -0.05], [0.4, 0.25, 0.6]);
        for residual in [StrongResidual::Full, StrongResidual::FrozenLubricant, StrongResidual::Couette] {
            let stab = Stabilisation { residual, film_peclet: true, penalty: 30.0, ..Stabilisation::default() };
            let (_, dp, dh) = reynolds_p1_element_stab(&verts, &p, &h, &vel, &fluid, &stab);
            let d = 1e-7;
            for j in 0..3 {
                let (mut pp, mut pm) = (p, p);
                pp[j] += d;
                pm[j] -= d;
                let (rp, _, _) = reynolds_p1_element_stab(&verts, &pp, &h, &vel, &fluid, &stab);
                let (rm, _, _) = reynolds_p1_element_stab(&verts, &pm, &h, &vel, &fluid, &stab);
                let (mut hp, mut hm) = (h, h);
                hp[j] += d;
                hm[j] -= d;
                let (sp, _, _) = reynolds_p1_element_stab(&verts, &p, &hp, &vel, &fluid, &stab);
                let (sm, _, _) = reynolds_p1_element_stab(&verts, &p, &hm, &vel, &fluid, &stab);
                for i in 0..3 {
                    assert!((dp[i][j] - (rp[i] - rm[i]) / (2.0 * d)).abs() < 1e-6 * (1.0 + dp[i][j].abs()), "{residual:?} dP {i} {j}");
                    assert!((dh[i][j] - (sp[i] - sm[i]) / (2.0 * d)).abs() < 1e-6 * (1.0 + dh[i][j].abs()), "{residual:?} dH {i} {j}");
                }
            }
        }
    }

    /// Constant P and H with a uniform velocity: the flux rho H v is divergence-free, so the
    /// residuals of an element sum to zero (sum of grad L_i = 0), whatever the laws.
    #[test]
    fn uniform_state_residuals_sum_to_zero() {
        let (eta, rho) = laws();
        let zero = |_: f64| 0.0;
        let fluid = Fluid { eta: &eta, rho: &rho, d2eta: &zero, d2rho: &zero, lambda_bar: 0.3 };
        let (r, _, _) = reynolds_p1_element(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], &[0.5; 3], &[0.2; 3], &[[1.0, 0.0]; 3], &fluid);
        assert!((r[0] + r[1] + r[2]).abs() < 1e-14);
        // Exact Couette part: -rho H v . grad L_i * area; grad L_0 = (-1, -1), area 1/2.
        let expect0 = -(rho(0.5).0 * 0.2) * (-1.0) * 0.5;
        assert!((r[0] - expect0).abs() < 1e-14, "{} vs {expect0}", r[0]);
    }
}
