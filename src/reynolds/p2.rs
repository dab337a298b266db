//! Straight-sided quadratic (P2) triangle.
//!
//! Local node order: v0, v1, v2, mid(0,1), mid(1,2), mid(2,0). With barycentric
//! coordinates L0, L1, L2 (constant gradients g_k = grad L_k on a straight triangle):
//! - vertices: N_k = L_k (2 L_k - 1), grad N_k = (4 L_k - 1) g_k, Lap N_k = 4 |g_k|^2;
//! - mid-sides (a, b) = (0,1), (1,2), (2,0): N = 4 L_a L_b,
//!   grad N = 4 (L_b g_a + L_a g_b), Lap N = 8 g_a . g_b.
//!
//! Second derivatives are constant on the element, so Lap of a P2 field is exact.

/// Mid-side node k (3, 4, 5) joins vertices `EDGES[k - 3]`.
pub const EDGES: [[usize; 2]; 3] = [[0, 1], [1, 2], [2, 0]];

/// Geometry of one straight P2 triangle.
#[derive(Clone, Copy, Debug)]
pub struct P2Triangle {
    /// Vertex coordinates.
    pub verts: [[f64; 2]; 3],
    /// Area (positive whatever the vertex orientation).
    pub area: f64,
    /// Gradients of the barycentric coordinates, g_k = grad L_k.
    pub grad_l: [[f64; 2]; 3],
    /// Laplacians of the six shape functions (constant).
    pub lap: [f64; 6],
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

impl P2Triangle {
    /// Geometry from the three vertices. Panics on a degenerate triangle.
    pub fn new(verts: &[[f64; 2]; 3]) -> Self {
        let [x0, x1, x2] = *verts;
        let det = (x1[0] - x0[0]) * (x2[1] - x0[1]) - (x2[0] - x0[0]) * (x1[1] - x0[1]);
        assert!(det.abs() > 0.0, "degenerate triangle {verts:?}");
        // L_k = (a_k + b_k x + c_k z) / det
        let grad_l = [
            [(x1[1] - x2[1]) / det, (x2[0] - x1[0]) / det],
            [(x2[1] - x0[1]) / det, (x0[0] - x2[0]) / det],
            [(x0[1] - x1[1]) / det, (x1[0] - x0[0]) / det],
        ];
        let mut lap = [0.0; 6];
        for k in 0..3 {
            lap[k] = 4.0 * dot(grad_l[k], grad_l[k]);
        }
        for (m, [a, b]) in EDGES.iter().enumerate() {
            lap[3 + m] = 8.0 * dot(grad_l[*a], grad_l[*b]);
        }
        Self {
            verts: *verts,
            area: 0.5 * det.abs(),
            grad_l,
            lap,
        }
    }

    /// Shape function values at barycentric point `l`.
    pub fn shape(l: &[f64; 3]) -> [f64; 6] {
        crate::fem::p2tri::p2_tri_basis_bary(*l)
    }

    /// Shape function gradients at barycentric point `l`.
    pub fn grad(&self, l: &[f64; 3]) -> [[f64; 2]; 6] {
        let g = &self.grad_l;
        let mut out = [[0.0; 2]; 6];
        for k in 0..3 {
            let s = 4.0 * l[k] - 1.0;
            out[k] = [s * g[k][0], s * g[k][1]];
        }
        for (m, [a, b]) in EDGES.iter().enumerate() {
            let (a, b) = (*a, *b);
            out[3 + m] = [
                4.0 * (l[b] * g[a][0] + l[a] * g[b][0]),
                4.0 * (l[b] * g[a][1] + l[a] * g[b][1]),
            ];
        }
        out
    }

    /// Physical point of barycentric point `l`.
    pub fn point(&self, l: &[f64; 3]) -> [f64; 2] {
        let v = &self.verts;
        [
            l[0] * v[0][0] + l[1] * v[1][0] + l[2] * v[2][0],
            l[0] * v[0][1] + l[1] * v[1][1] + l[2] * v[2][1],
        ]
    }

    /// Coordinates of the six nodes.
    pub fn nodes(&self) -> [[f64; 2]; 6] {
        let v = &self.verts;
        let mid = |a: usize, b: usize| [0.5 * (v[a][0] + v[b][0]), 0.5 * (v[a][1] + v[b][1])];
        [v[0], v[1], v[2], mid(0, 1), mid(1, 2), mid(2, 0)]
    }

    /// Integrals of the shape functions, int N_i: 0 at vertices, area/3 at mid-sides.
    /// A P2 field's integral (e.g. the load, int P) is `sum_i load_weights[i] * P_i`.
    pub fn load_weights(&self) -> [f64; 6] {
        let t = self.area / 3.0;
        [0.0, 0.0, 0.0, t, t, t]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: [[f64; 2]; 3] = [[0.3, -0.2], [1.4, 0.1], [0.5, 0.9]];

    /// A quadratic q(x, z) = 1 + 2x - z + 0.5 x^2 - 1.5 x z + 0.7 z^2 and its gradient.
    fn q(p: [f64; 2]) -> f64 {
        let (x, z) = (p[0], p[1]);
        1.0 + 2.0 * x - z + 0.5 * x * x - 1.5 * x * z + 0.7 * z * z
    }
    fn gq(p: [f64; 2]) -> [f64; 2] {
        let (x, z) = (p[0], p[1]);
        [2.0 + x - 1.5 * z, -1.0 - 1.5 * x + 1.4 * z]
    }

    #[test]
    fn p2_interpolates_quadratics_exactly() {
        let e = P2Triangle::new(&T);
        assert!((e.area - 0.5 * ((1.1 * 1.1) - (0.2 * 0.3))).abs() < 1e-14);
        let nodal: Vec<f64> = e.nodes().iter().map(|&n| q(n)).collect();
        let lap: f64 = (0..6).map(|i| e.lap[i] * nodal[i]).sum();
        assert!((lap - (1.0 + 1.4)).abs() < 1e-12, "Laplacian {lap}");
        for l in [[0.2, 0.3, 0.5], [0.6, 0.1, 0.3], [1.0 / 3.0; 3]] {
            let x = e.point(&l);
            let n = P2Triangle::shape(&l);
            let g = e.grad(&l);
            let v: f64 = (0..6).map(|i| n[i] * nodal[i]).sum();
            let gx: f64 = (0..6).map(|i| g[i][0] * nodal[i]).sum();
            let gz: f64 = (0..6).map(|i| g[i][1] * nodal[i]).sum();
            assert!((v - q(x)).abs() < 1e-13);
            assert!((gx - gq(x)[0]).abs() < 1e-12 && (gz - gq(x)[1]).abs() < 1e-12);
        }
        // partition of unity, Kronecker property at nodes
        let bary = [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.5, 0.5, 0.0],
            [0.0, 0.5, 0.5],
            [0.5, 0.0, 0.5],
        ];
        for (j, l) in bary.iter().enumerate() {
            let n = P2Triangle::shape(l);
            for i in 0..6 {
                assert!((n[i] - if i == j { 1.0 } else { 0.0 }).abs() < 1e-15);
            }
        }
        // load weights integrate the quadratic exactly (compare with quadrature)
        let w = e.load_weights();
        let int_w: f64 = (0..6).map(|i| w[i] * nodal[i]).sum();
        let int_q: f64 = super::super::quadrature::DUNAVANT6
            .iter()
            .map(|p| p.w * e.area * q(e.point(&p.l)))
            .sum();
        assert!((int_w - int_q).abs() < 1e-13);
    }
}
