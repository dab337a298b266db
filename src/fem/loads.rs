//! Consistent load vectors for P2 elements.
use super::geometry::{AffineTet, AffineTri};
use super::p2tet::p2_tet_basis;
use super::p2tri::p2_tri_basis;
use super::quadrature::{TetRule, TriRule};

/// Consistent body-force load of a P2 tetrahedron, `F[3a+i] = int_T f_i(x) N_a(x) dx`
/// (node-major, 30 entries), integrated with `rule` on the reference tetrahedron.
/// Choose the rule degree as 2 + the degree of `f` (exact) or higher for smooth
/// non-polynomial `f`.
pub fn body_force_load(verts: &[[f64; 3]; 4], f: impl Fn([f64; 3]) -> [f64; 3], rule: &TetRule) -> [f64; 30] {
    let geo = AffineTet::new(verts);
    let det = geo.abs_det();
    let mut out = [0.0; 30];
    for (p, w) in rule.iter() {
        let n = p2_tet_basis(p);
        let fx = f(geo.map(p));
        let wd = w * det;
        for a in 0..10 {
            let s = wd * n[a];
            out[3 * a] += s * fx[0];
            out[3 * a + 1] += s * fx[1];
            out[3 * a + 2] += s * fx[2];
        }
    }
    out
}

/// Consistent scalar surface load of a P2 triangle of the contact plane,
/// `F_i = int_S p(x, z) N_i dS` (6 entries, P2 triangle node order), with the triangle given
/// by its 3 vertices in the plane coordinates `(x, z)`. This is the pressure term of the
/// elasticity equations on the contact face; the caller puts it on the normal (y)
/// component with the sign of the surface normal.
///
/// For constant `p` the vertex entries vanish and each midside entry is `p |S| / 3`.
pub fn tri_normal_load(verts2d: &[[f64; 2]; 3], p: impl Fn(f64, f64) -> f64, rule: &TriRule) -> [f64; 6] {
    let geo = AffineTri::new(verts2d);
    let det = geo.abs_det();
    let mut out = [0.0; 6];
    for (q, w) in rule.iter() {
        let n = p2_tri_basis(q);
        let x = geo.map(q);
        let s = w * det * p(x[0], x[1]);
        for a in 0..6 {
            out[a] += s * n[a];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::quadrature::{tet_rule, tri_rule};

    #[test]
    fn tri_constant_pressure() {
        let v = [[0.1, 0.2], [1.1, 0.4], [0.3, 1.5]];
        let area = AffineTri::new(&v).area();
        for deg in [2, 4, 5, 8] {
            let f = tri_normal_load(&v, |_, _| 2.5, tri_rule(deg));
            for a in 0..3 {
                assert!(f[a].abs() < 1e-15);
            }
            for a in 3..6 {
                assert!((f[a] - 2.5 * area / 3.0).abs() < 1e-14);
            }
        }
        // Clockwise orientation gives the same result.
        let vf = [v[0], v[2], v[1]];
        let f = tri_normal_load(&vf, |_, _| 1.0, tri_rule(2));
        assert!((f[4] - area / 3.0).abs() < 1e-14);
    }

    #[test]
    fn tri_total_equals_integral() {
        let v = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        // int over the unit triangle of x^2 z = 2! 1! / 5! = 1/60; of exp(x+z) = 1 (exactly: e^s s ds from 0..1 = 1).
        let f = tri_normal_load(&v, |x, z| x * x * z, tri_rule(5));
        assert!((f.iter().sum::<f64>() - 1.0 / 60.0).abs() < 1e-15);
        let f = tri_normal_load(&v, |x, z| (x + z).exp(), tri_rule(20));
        assert!((f.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        let f8 = tri_normal_load(&v, |x, z| (x + z).exp(), tri_rule(8));
        assert!((f8.iter().sum::<f64>() - 1.0).abs() < 1e-8);
        // Weighted by a linear function: sum_i F_i * l(node_i) = int p l.
        let nodes = crate::fem::p2tri::p2_tri_node_coords(&v);
        let f = tri_normal_load(&v, |x, _| x, tri_rule(4));
        let s: f64 = (0..6).map(|a| f[a] * nodes[a][1]).sum(); // int x z = 1/24
        assert!((s - 1.0 / 24.0).abs() < 1e-15);
    }

    #[test]
    fn body_force_consistency() {
        let v = [[0.1, -0.2, 0.3], [1.3, 0.1, 0.2], [0.2, 0.9, -0.1], [0.4, 0.3, 1.1]];
        let geo = AffineTet::new(&v);
        let f = body_force_load(&v, |_| [1.0, -2.0, 0.5], tet_rule(2));
        // Constant force: vertex entries -vol/20, midside +vol/5 (P2 property).
        for a in 0..4 {
            assert!((f[3 * a] + geo.volume() / 20.0).abs() < 1e-15);
        }
        for a in 4..10 {
            assert!((f[3 * a + 1] + 2.0 * geo.volume() / 5.0).abs() < 1e-15);
        }
        let tot: f64 = (0..10).map(|a| f[3 * a + 2]).sum();
        assert!((tot - 0.5 * geo.volume()).abs() < 1e-15);
        // Against a much finer rule for a smooth non-polynomial force.
        let g = |x: [f64; 3]| [x[0].sin(), (x[1] * x[2]).cos(), (x[0] - x[2]).exp()];
        let f5 = body_force_load(&v, g, tet_rule(5));
        let f20 = body_force_load(&v, g, tet_rule(20));
        for r in 0..30 {
            assert!((f5[r] - f20[r]).abs() < 1e-3 * geo.volume());
        }
        // Polynomial force of degree 3 integrated exactly with a degree-5 rule.
        let p = |x: [f64; 3]| [x[0] * x[1] * x[2], x[0].powi(3), 1.0 + x[1] * x[1]];
        let a = body_force_load(&v, p, tet_rule(5));
        let b = body_force_load(&v, p, tet_rule(12));
        for r in 0..30 {
            assert!((a[r] - b[r]).abs() < 1e-15);
        }
    }
}
