//! Affine geometry of straight-sided simplices.
//!
//! The map from the reference element is `x(xi) = v0 + J xi` with the columns of `J`
//! the edge vectors `v1 - v0, v2 - v0, (v3 - v0)`. Physical gradients follow from
//! `grad_x N = J^{-T} grad_xi N`; for P2 it is cheaper to use the (constant) physical
//! gradients of the barycentric coordinates, [`AffineTet::grad_bary`], together with
//! [`crate::fem::p2tet::p2_tet_grads_bary`].
//!
//! Degenerate elements (det J = 0) give non-finite inverses; callers are expected to pass
//! valid meshes. Volumes use |det J|, so negatively oriented elements are still integrated
//! correctly.
use super::p2tet::{p2_tet_grads_bary, tet_bary};
use super::p2tri::{p2_tri_grads_bary, tri_bary};

#[inline(always)]
fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline(always)]
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
#[inline(always)]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Signed volume of the tetrahedron `(v0, v1, v2, v3)`: `det J / 6`; positive for the
/// expected (right-handed) orientation.
#[inline]
pub fn tet_signed_volume(v: &[[f64; 3]; 4]) -> f64 {
    let (e1, e2, e3) = (sub3(v[1], v[0]), sub3(v[2], v[0]), sub3(v[3], v[0]));
    dot(e1, cross(e2, e3)) / 6.0
}

/// Affine map of a straight-sided tetrahedron from its 4 vertices.
#[derive(Clone, Copy, Debug)]
pub struct AffineTet {
    /// Vertex 0 (image of the reference origin).
    pub x0: [f64; 3],
    /// Jacobian `J[i][k] = dx_i / dxi_k` (columns are the edge vectors from v0).
    pub jac: [[f64; 3]; 3],
    /// `det J` (signed; 6 times the signed volume).
    pub det: f64,
    /// `J^{-T}`: maps reference gradients to physical gradients.
    pub jinv_t: [[f64; 3]; 3],
    /// Physical gradients of the 4 barycentric coordinates (constant on the element);
    /// `grad_bary[k] = J^{-T} grad_xi l_k`, summing to zero.
    pub grad_bary: [[f64; 3]; 4],
}

impl AffineTet {
    /// Build the affine map from the 4 vertex coordinates (the first 4 P2 nodes).
    #[inline]
    pub fn new(v: &[[f64; 3]; 4]) -> Self {
        let (e1, e2, e3) = (sub3(v[1], v[0]), sub3(v[2], v[0]), sub3(v[3], v[0]));
        let c1 = cross(e2, e3);
        let c2 = cross(e3, e1);
        let c3 = cross(e1, e2);
        let det = dot(e1, c1);
        let inv = 1.0 / det;
        let g1 = [c1[0] * inv, c1[1] * inv, c1[2] * inv];
        let g2 = [c2[0] * inv, c2[1] * inv, c2[2] * inv];
        let g3 = [c3[0] * inv, c3[1] * inv, c3[2] * inv];
        let g0 = [-(g1[0] + g2[0] + g3[0]), -(g1[1] + g2[1] + g3[1]), -(g1[2] + g2[2] + g3[2])];
        let mut jac = [[0.0; 3]; 3];
        let mut jinv_t = [[0.0; 3]; 3];
        for i in 0..3 {
            jac[i] = [e1[i], e2[i], e3[i]];
            jinv_t[i] = [g1[i], g2[i], g3[i]];
        }
        AffineTet { x0: v[0], jac, det, jinv_t, grad_bary: [g0, g1, g2, g3] }
    }

    /// Element volume `|det J| / 6`.
    #[inline]
    pub fn volume(&self) -> f64 {
        self.det.abs() / 6.0
    }

    /// `|det J|`, the factor converting reference-tet quadrature weights to physical ones.
    #[inline]
    pub fn abs_det(&self) -> f64 {
        self.det.abs()
    }

    /// Physical point of a reference point.
    #[inline]
    pub fn map(&self, xi: [f64; 3]) -> [f64; 3] {
        let mut x = self.x0;
        for i in 0..3 {
            x[i] += self.jac[i][0] * xi[0] + self.jac[i][1] * xi[1] + self.jac[i][2] * xi[2];
        }
        x
    }

    /// Physical point of a point given by barycentric coordinates.
    #[inline]
    pub fn map_bary(&self, l: [f64; 4]) -> [f64; 3] {
        self.map([l[1], l[2], l[3]])
    }

    /// Reference coordinates of a physical point (inverse affine map).
    #[inline]
    pub fn to_ref(&self, x: [f64; 3]) -> [f64; 3] {
        let d = sub3(x, self.x0);
        // xi = J^{-1} d, and J^{-1} = (J^{-T})^T.
        let mut xi = [0.0; 3];
        for k in 0..3 {
            xi[k] = self.jinv_t[0][k] * d[0] + self.jinv_t[1][k] * d[1] + self.jinv_t[2][k] * d[2];
        }
        xi
    }

    /// Physical gradient `J^{-T} g` of a reference gradient `g`.
    #[inline]
    pub fn phys_grad(&self, g: [f64; 3]) -> [f64; 3] {
        let m = &self.jinv_t;
        [
            m[0][0] * g[0] + m[0][1] * g[1] + m[0][2] * g[2],
            m[1][0] * g[0] + m[1][1] * g[1] + m[1][2] * g[2],
            m[2][0] * g[0] + m[2][1] * g[1] + m[2][2] * g[2],
        ]
    }

    /// Physical gradients of the 10 P2 shape functions at a point given by barycentric
    /// coordinates.
    #[inline]
    pub fn p2_grads_bary(&self, l: [f64; 4]) -> [[f64; 3]; 10] {
        p2_tet_grads_bary(l, &self.grad_bary)
    }

    /// Physical gradients of the 10 P2 shape functions at a reference point.
    #[inline]
    pub fn p2_grads(&self, xi: [f64; 3]) -> [[f64; 3]; 10] {
        p2_tet_grads_bary(tet_bary(xi), &self.grad_bary)
    }

    /// Gradient `G[c][d] = du_c/dx_d` of a P2 vector field (30 node-major DOFs) at a point
    /// given by barycentric coordinates.
    #[inline]
    pub fn p2_eval_grad(&self, values: &[f64; 30], l: [f64; 4]) -> [[f64; 3]; 3] {
        let d = self.p2_grads_bary(l);
        let mut g = [[0.0; 3]; 3];
        for a in 0..10 {
            for c in 0..3 {
                let u = values[3 * a + c];
                for k in 0..3 {
                    g[c][k] += u * d[a][k];
                }
            }
        }
        g
    }
}

/// Affine map of a straight-sided triangle in the contact plane, coordinates `(x, z)`.
#[derive(Clone, Copy, Debug)]
pub struct AffineTri {
    /// Vertex 0.
    pub x0: [f64; 2],
    /// Jacobian `J[i][k] = dx_i / dxi_k`.
    pub jac: [[f64; 2]; 2],
    /// `det J` (signed; twice the signed area).
    pub det: f64,
    /// Physical gradients of the 3 barycentric coordinates.
    pub grad_bary: [[f64; 2]; 3],
}

impl AffineTri {
    /// Build the affine map from the 3 vertex coordinates.
    #[inline]
    pub fn new(v: &[[f64; 2]; 3]) -> Self {
        let e1 = [v[1][0] - v[0][0], v[1][1] - v[0][1]];
        let e2 = [v[2][0] - v[0][0], v[2][1] - v[0][1]];
        let det = e1[0] * e2[1] - e2[0] * e1[1];
        let inv = 1.0 / det;
        let g1 = [e2[1] * inv, -e2[0] * inv];
        let g2 = [-e1[1] * inv, e1[0] * inv];
        let g0 = [-(g1[0] + g2[0]), -(g1[1] + g2[1])];
        AffineTri { x0: v[0], jac: [[e1[0], e2[0]], [e1[1], e2[1]]], det, grad_bary: [g0, g1, g2] }
    }
    /// Area `|det J| / 2`.
    #[inline]
    pub fn area(&self) -> f64 {
        self.det.abs() / 2.0
    }
    /// `|det J|`.
    #[inline]
    pub fn abs_det(&self) -> f64 {
        self.det.abs()
    }
    /// Physical point of a reference point.
    #[inline]
    pub fn map(&self, xi: [f64; 2]) -> [f64; 2] {
        [self.x0[0] + self.jac[0][0] * xi[0] + self.jac[0][1] * xi[1], self.x0[1] + self.jac[1][0] * xi[0] + self.jac[1][1] * xi[1]]
    }
    /// Physical gradients of the 6 P2 shape functions at a reference point.
    #[inline]
    pub fn p2_grads(&self, xi: [f64; 2]) -> [[f64; 2]; 6] {
        p2_tri_grads_bary(tri_bary(xi), &self.grad_bary)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::p2tet::p2_tet_ref_grads;

    fn verts() -> [[f64; 3]; 4] {
        [[0.1, -0.2, 0.3], [1.3, 0.1, 0.2], [0.2, 0.9, -0.1], [0.4, 0.3, 1.1]]
    }

    #[test]
    fn jacobian_inverse_and_volume() {
        let v = verts();
        let g = AffineTet::new(&v);
        assert!(g.det > 0.0);
        assert!((g.volume() - tet_signed_volume(&v)).abs() < 1e-15);
        // J^T J^{-T} = I
        for i in 0..3 {
            for j in 0..3 {
                let s: f64 = (0..3).map(|k| g.jac[k][i] * g.jinv_t[k][j]).sum();
                assert!((s - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14);
            }
        }
        for k in 0..4 {
            let x = g.map_bary(std::array::from_fn(|m| if m == k { 1.0 } else { 0.0 }));
            for c in 0..3 {
                assert!((x[c] - v[k][c]).abs() < 1e-15);
            }
        }
        let xi = [0.2, 0.3, 0.1];
        let back = g.to_ref(g.map(xi));
        for c in 0..3 {
            assert!((back[c] - xi[c]).abs() < 1e-14);
        }
        // Barycentric gradients: grad l_k . (v_m - v_0) = delta_km - delta_k0.
        for k in 0..4 {
            for m in 1..4 {
                let e = sub3(v[m], v[0]);
                let want = if k == m {
                    1.0
                } else if k == 0 {
                    -1.0
                } else {
                    0.0
                };
                assert!((dot(g.grad_bary[k], e) - want).abs() < 1e-14);
            }
        }
        // Flipped orientation: same volume, negative det.
        let vf = [v[0], v[2], v[1], v[3]];
        let gf = AffineTet::new(&vf);
        assert!(gf.det < 0.0 && (gf.volume() - g.volume()).abs() < 1e-15);
    }

    #[test]
    fn physical_grads_consistent() {
        let g = AffineTet::new(&verts());
        let xi = [0.15, 0.25, 0.35];
        let a = g.p2_grads(xi);
        let r = p2_tet_ref_grads(xi);
        for n in 0..10 {
            let b = g.phys_grad(r[n]);
            for c in 0..3 {
                assert!((a[n][c] - b[c]).abs() < 1e-13);
            }
        }
    }

    #[test]
    fn triangle_map() {
        let v = [[0.1, 0.2], [1.1, 0.4], [0.3, 1.5]];
        let t = AffineTri::new(&v);
        let area = 0.5 * ((v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[2][0] - v[0][0]) * (v[1][1] - v[0][1]));
        assert!((t.area() - area.abs()).abs() < 1e-15);
        for k in 0..3 {
            for m in 1..3 {
                let e = [v[m][0] - v[0][0], v[m][1] - v[0][1]];
                let want = if k == m {
                    1.0
                } else if k == 0 {
                    -1.0
                } else {
                    0.0
                };
                let d = t.grad_bary[k][0] * e[0] + t.grad_bary[k][1] * e[1];
                assert!((d - want).abs() < 1e-14);
            }
        }
        let x = t.map([1.0, 0.0]);
        assert!((x[0] - v[1][0]).abs() < 1e-15 && (x[1] - v[1][1]).abs() < 1e-15);
    }
}
