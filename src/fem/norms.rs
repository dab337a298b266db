//! Element contributions to discretisation-error norms.
use super::geometry::AffineTet;
use super::p2tet::{p2_tet_basis, p2_tet_grads_bary, tet_bary};
use super::quadrature::TetRule;

/// Squared L2 error `int_T |u_h - u|^2 dx` of a P2 vector field (30 node-major DOFs)
/// against an exact field, integrated with `rule`. Sum over elements and take the square
/// root for the global norm.
pub fn l2_error_sq(verts: &[[f64; 3]; 4], u_local: &[f64; 30], exact: impl Fn([f64; 3]) -> [f64; 3], rule: &TetRule) -> f64 {
    let geo = AffineTet::new(verts);
    let mut s = 0.0;
    for (p, w) in rule.iter() {
        let n = p2_tet_basis(p);
        let ue = exact(geo.map(p));
        let mut uh = [0.0; 3];
        for a in 0..10 {
            for c in 0..3 {
                uh[c] += n[a] * u_local[3 * a + c];
            }
        }
        s += w * ((uh[0] - ue[0]).powi(2) + (uh[1] - ue[1]).powi(2) + (uh[2] - ue[2]).powi(2));
    }
    s * geo.abs_det()
}

/// Squared H1-seminorm error `int_T |grad u_h - grad u|^2 dx` (Frobenius norm) of a P2
/// vector field against the exact gradient `exact_grad(x)[c][d] = du_c/dx_d`.
pub fn h1_seminorm_error_sq(
    verts: &[[f64; 3]; 4],
    u_local: &[f64; 30],
    exact_grad: impl Fn([f64; 3]) -> [[f64; 3]; 3],
    rule: &TetRule,
) -> f64 {
    let geo = AffineTet::new(verts);
    let mut s = 0.0;
    for (p, w) in rule.iter() {
        let d = p2_tet_grads_bary(tet_bary(p), &geo.grad_bary);
        let ge = exact_grad(geo.map(p));
        let mut e = 0.0;
        for c in 0..3 {
            for k in 0..3 {
                let gh: f64 = (0..10).map(|a| u_local[3 * a + c] * d[a][k]).sum();
                e += (gh - ge[c][k]).powi(2);
            }
        }
        s += w * e;
    }
    s * geo.abs_det()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::p2tet::p2_tet_node_coords;
    use crate::fem::quadrature::tet_rule;

    #[test]
    fn quadratic_field_has_zero_error_and_known_norms() {
        let v = [[0.1, -0.2, 0.3], [1.3, 0.1, 0.2], [0.2, 0.9, -0.1], [0.4, 0.3, 1.1]];
        let x = p2_tet_node_coords(&v);
        let f = |p: [f64; 3]| [p[0] * p[1], 1.0 - p[2] * p[2], p[0] + 2.0 * p[1]];
        let g = |p: [f64; 3]| [[p[1], p[0], 0.0], [0.0, 0.0, -2.0 * p[2]], [1.0, 2.0, 0.0]];
        let mut u = [0.0; 30];
        for a in 0..10 {
            u[3 * a..3 * a + 3].copy_from_slice(&f(x[a]));
        }
        assert!(l2_error_sq(&v, &u, f, tet_rule(5)) < 1e-28);
        assert!(h1_seminorm_error_sq(&v, &u, g, tet_rule(5)) < 1e-28);
        // Error against zero: ||u||^2 and |u|_1^2 of the constant field (1, 0, 0).
        let zero = [0.0; 30];
        let vol = AffineTet::new(&v).volume();
        assert!((l2_error_sq(&v, &zero, |_| [1.0, 0.0, 0.0], tet_rule(2)) - vol).abs() < 1e-15);
        let lin = |p: [f64; 3]| [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, p[0] * 0.0]];
        assert!((h1_seminorm_error_sq(&v, &zero, lin, tet_rule(1)) - 5.0 * vol).abs() < 1e-14);
    }
}
