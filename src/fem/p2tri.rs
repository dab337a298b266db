//! Quadratic (P2) Lagrange basis on the reference triangle.
//!
//! Nodes: `v0, v1, v2, mid(0,1), mid(1,2), mid(2,0)` (VTK_QUADRATIC_TRIANGLE), in the
//! 2D coordinates `(x, z)` of the contact plane. With barycentric coordinates `l_k`:
//! `N_k = l_k (2 l_k - 1)` for the vertices, `N_{3+e} = 4 l_i l_j` for edge `e = (i, j)`.

/// Vertex pairs of the three edges, in the order of the midside nodes 3..6.
pub const TRI_EDGES: [[usize; 2]; 3] = [[0, 1], [1, 2], [2, 0]];

/// Reference coordinates of the 6 nodes.
pub const P2_TRI_REF_NODES: [[f64; 2]; 6] = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5]];

/// Gradients of the barycentric coordinates with respect to the reference coordinates.
pub const TRI_REF_GRAD_BARY: [[f64; 2]; 3] = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]];

/// Barycentric coordinates `(1 - s - t, s, t)` of a reference point.
#[inline(always)]
pub fn tri_bary(xi: [f64; 2]) -> [f64; 3] {
    [1.0 - xi[0] - xi[1], xi[0], xi[1]]
}

/// P2 shape-function values from barycentric coordinates.
#[inline(always)]
pub fn p2_tri_basis_bary(l: [f64; 3]) -> [f64; 6] {
    [
        l[0] * (2.0 * l[0] - 1.0),
        l[1] * (2.0 * l[1] - 1.0),
        l[2] * (2.0 * l[2] - 1.0),
        4.0 * l[0] * l[1],
        4.0 * l[1] * l[2],
        4.0 * l[2] * l[0],
    ]
}

/// P2 shape-function values at a reference point.
#[inline(always)]
pub fn p2_tri_basis(xi: [f64; 2]) -> [f64; 6] {
    p2_tri_basis_bary(tri_bary(xi))
}

/// Gradients of the P2 shape functions from barycentric coordinates `l` and the constant
/// gradients `g` of the barycentric coordinates (reference: [`TRI_REF_GRAD_BARY`];
/// physical: [`crate::fem::geometry::AffineTri::grad_bary`]).
#[inline(always)]
pub fn p2_tri_grads_bary(l: [f64; 3], g: &[[f64; 2]; 3]) -> [[f64; 2]; 6] {
    let mut d = [[0.0; 2]; 6];
    for k in 0..3 {
        let s = 4.0 * l[k] - 1.0;
        d[k] = [s * g[k][0], s * g[k][1]];
    }
    for (e, [i, j]) in TRI_EDGES.iter().enumerate() {
        let (li, lj) = (4.0 * l[*i], 4.0 * l[*j]);
        for c in 0..2 {
            d[3 + e][c] = lj * g[*i][c] + li * g[*j][c];
        }
    }
    d
}

/// Reference gradients of the P2 shape functions at a reference point.
#[inline(always)]
pub fn p2_tri_ref_grads(xi: [f64; 2]) -> [[f64; 2]; 6] {
    p2_tri_grads_bary(tri_bary(xi), &TRI_REF_GRAD_BARY)
}

/// Evaluate a P2 scalar field on a triangle (6 nodal values) at a point given by its
/// barycentric coordinates (e.g. the film thickness or pressure on a contact-face element).
#[inline]
pub fn p2_tri_eval(values: &[f64; 6], bary: [f64; 3]) -> f64 {
    let n = p2_tri_basis_bary(bary);
    n.iter().zip(values).map(|(n, v)| n * v).sum()
}

/// Gradient of a P2 scalar field on a triangle (6 nodal values) at barycentric point `bary`,
/// from the gradients `g` of the barycentric coordinates ([`crate::fem::AffineTri`]'s
/// `grad_bary`); `bary` may lie outside the triangle (the polynomial extended).
#[inline]
pub fn p2_tri_eval_grad(values: &[f64; 6], bary: [f64; 3], g: &[[f64; 2]; 3]) -> [f64; 2] {
    let d = p2_tri_grads_bary(bary, g);
    let mut grad = [0.0; 2];
    for (dk, v) in d.iter().zip(values) {
        grad[0] += dk[0] * v;
        grad[1] += dk[1] * v;
    }
    grad
}

/// Coordinates of the 6 P2 nodes of a straight-sided triangle with the given vertices.
#[inline]
pub fn p2_tri_node_coords(verts: &[[f64; 2]; 3]) -> [[f64; 2]; 6] {
    let mut x = [[0.0; 2]; 6];
    x[..3].copy_from_slice(verts);
    for (e, [i, j]) in TRI_EDGES.iter().enumerate() {
        for c in 0..2 {
            x[3 + e][c] = 0.5 * (verts[*i][c] + verts[*j][c]);
        }
    }
    x
}

/// Mass matrix of a straight P2 triangle, integral of N_i N_j (closed form, area/180 * ...).
pub fn p2_tri_mass(area: f64) -> [[f64; 6]; 6] {
    const M: [[f64; 6]; 6] = [
        [6., -1., -1., 0., -4., 0.],
        [-1., 6., -1., 0., 0., -4.],
        [-1., -1., 6., -4., 0., 0.],
        [0., 0., -4., 32., 16., 16.],
        [-4., 0., 0., 16., 32., 16.],
        [0., -4., 0., 16., 16., 32.],
    ];
    M.map(|row| row.map(|m| m * area / 180.0))
}

/// Area of a straight triangle in the (X, Z) plane (unsigned).
pub fn tri_area(v: &[[f64; 2]; 3]) -> f64 {
    0.5 * ((v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[2][0] - v[0][0]) * (v[1][1] - v[0][1])).abs()
}

/// Integral of the P2 basis functions over a triangle: 0 at vertices, area/3 at midpoints.
pub fn p2_tri_weights(area: f64) -> [f64; 6] {
    [0.0, 0.0, 0.0, area / 3.0, area / 3.0, area / 3.0]
}

/// The nodes sharing a triangle with each node of the P2 triangles `tris` (the node itself
/// included; sorted): the stencil of a row assembled from those triangles.
pub fn node_rings(tris: &[[u32; 6]]) -> std::collections::HashMap<u32, Vec<u32>> {
    let mut ring: std::collections::HashMap<u32, Vec<u32>> = std::collections::HashMap::new();
    for tri in tris {
        for &n in tri {
            ring.entry(n).or_default().extend_from_slice(tri);
        }
    }
    for v in ring.values_mut() {
        v.sort_unstable();
        v.dedup();
    }
    ring
}

/// A straight P2 triangle in physical coordinates, with what the Reynolds element needs:
///
/// Local node order: v0, v1, v2, mid(0,1), mid(1,2), mid(2,0). With barycentric
/// coordinates L0, L1, L2 (constant gradients g_k = grad L_k on a straight triangle):
/// - vertices: N_k = L_k (2 L_k - 1), grad N_k = (4 L_k - 1) g_k, Lap N_k = 4 |g_k|^2;
/// - mid-sides (a, b) = (0,1), (1,2), (2,0): N = 4 L_a L_b,
///   grad N = 4 (L_b g_a + L_a g_b), Lap N = 8 g_a . g_b.
///
/// Second derivatives are constant on the element, so Lap of a P2 field is exact.
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

fn dot2(a: [f64; 2], b: [f64; 2]) -> f64 {
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
            lap[k] = 4.0 * dot2(grad_l[k], grad_l[k]);
        }
        for (m, [a, b]) in TRI_EDGES.iter().enumerate() {
            lap[3 + m] = 8.0 * dot2(grad_l[*a], grad_l[*b]);
        }
        Self { verts: *verts, area: 0.5 * det.abs(), grad_l, lap }
    }

    /// Shape function values at barycentric point `l`.
    pub fn shape(l: &[f64; 3]) -> [f64; 6] {
        p2_tri_basis_bary(*l)
    }

    /// Shape function gradients at barycentric point `l`.
    pub fn grad(&self, l: &[f64; 3]) -> [[f64; 2]; 6] {
        p2_tri_grads_bary(*l, &self.grad_l)
    }

    /// Physical point of barycentric point `l`.
    pub fn point(&self, l: &[f64; 3]) -> [f64; 2] {
        let v = &self.verts;
        [l[0] * v[0][0] + l[1] * v[1][0] + l[2] * v[2][0], l[0] * v[0][1] + l[1] * v[1][1] + l[2] * v[2][1]]
    }

    /// Coordinates of the six nodes.
    pub fn nodes(&self) -> [[f64; 2]; 6] {
        p2_tri_node_coords(&self.verts)
    }

    /// Integrals of the shape functions, int N_i: 0 at vertices, area/3 at mid-sides.
    /// A P2 field's integral (e.g. the load, int P) is `sum_i load_weights[i] * P_i`.
    pub fn load_weights(&self) -> [f64; 6] {
        p2_tri_weights(self.area)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pts() -> Vec<[f64; 2]> {
        vec![[0.1, 0.2], [1.0 / 3.0, 1.0 / 3.0], [0.7, 0.1], [0.0, 0.6], [0.45, 0.5]]
    }

    fn quad(x: [f64; 2]) -> (f64, [f64; 2]) {
        let [s, t] = x;
        (0.3 - s + 2.0 * t + 1.5 * s * s - 0.7 * s * t + 2.2 * t * t, [-1.0 + 3.0 * s - 0.7 * t, 2.0 - 0.7 * s + 4.4 * t])
    }

    #[test]
    fn partition_kronecker_grads() {
        for p in pts() {
            let n = p2_tri_basis(p);
            assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-14);
            let g = p2_tri_ref_grads(p);
            for c in 0..2 {
                assert!(g.iter().map(|v| v[c]).sum::<f64>().abs() < 1e-14);
            }
        }
        for (i, x) in P2_TRI_REF_NODES.iter().enumerate() {
            let n = p2_tri_basis(*x);
            for (j, v) in n.iter().enumerate() {
                assert!((v - if i == j { 1.0 } else { 0.0 }).abs() < 1e-15);
            }
        }
        for (e, [i, j]) in TRI_EDGES.iter().enumerate() {
            for c in 0..2 {
                assert_eq!(0.5 * (P2_TRI_REF_NODES[*i][c] + P2_TRI_REF_NODES[*j][c]), P2_TRI_REF_NODES[3 + e][c]);
            }
        }
    }

    #[test]
    fn reproduces_quadratics() {
        let nodal: [f64; 6] = std::array::from_fn(|a| quad(P2_TRI_REF_NODES[a]).0);
        for p in pts() {
            let (v, g) = quad(p);
            assert!((p2_tri_eval(&nodal, tri_bary(p)) - v).abs() < 1e-13);
            let d = p2_tri_ref_grads(p);
            for c in 0..2 {
                let gh: f64 = (0..6).map(|a| d[a][c] * nodal[a]).sum();
                assert!((gh - g[c]).abs() < 1e-13);
            }
        }
    }

    #[test]
    fn grads_match_finite_differences() {
        let h = 1e-6;
        for p in pts() {
            let d = p2_tri_ref_grads(p);
            for c in 0..2 {
                let (mut pp, mut pm) = (p, p);
                pp[c] += h;
                pm[c] -= h;
                let (np, nm) = (p2_tri_basis(pp), p2_tri_basis(pm));
                for a in 0..6 {
                    assert!(((np[a] - nm[a]) / (2.0 * h) - d[a][c]).abs() < 1e-8);
                }
            }
        }
    }

    // The physical P2Triangle.

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
        let bary = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]];
        for (j, l) in bary.iter().enumerate() {
            let n = P2Triangle::shape(l);
            for i in 0..6 {
                assert!((n[i] - if i == j { 1.0 } else { 0.0 }).abs() < 1e-15);
            }
        }
        // load weights integrate the quadratic exactly (compare with quadrature)
        let w = e.load_weights();
        let int_w: f64 = (0..6).map(|i| w[i] * nodal[i]).sum();
        let int_q: f64 = crate::fem::quadrature::DUNAVANT6.iter().map(|p| p.w * e.area * q(e.point(&p.l))).sum();
        assert!((int_w - int_q).abs() < 1e-13);
    }

    #[test]
    fn p2_triangle_gradients_equal_the_former_reynolds_formula_bit_for_bit() {
        // The Reynolds element computed 4 (L_b g_a + L_a g_b) for a mid-side gradient; the
        // shared kernel computes (4 L_b) g_a + (4 L_a) g_b. A factor 4 is exact in binary
        // floating point, so both give the same bits and the solver's results do not move.
        let e = P2Triangle::new(&T);
        let g = e.grad_l;
        for l in [[0.2, 0.3, 0.5], [0.6, 0.1, 0.3], [1.0 / 3.0; 3], [0.013, 0.871, 0.116]] {
            let d = e.grad(&l);
            for k in 0..3 {
                let s = 4.0 * l[k] - 1.0;
                assert_eq!(d[k], [s * g[k][0], s * g[k][1]]);
            }
            for (m, [a, b]) in TRI_EDGES.iter().enumerate() {
                let (a, b) = (*a, *b);
                assert_eq!(d[3 + m], [4.0 * (l[b] * g[a][0] + l[a] * g[b][0]), 4.0 * (l[b] * g[a][1] + l[a] * g[b][1])]);
            }
        }
    }
}
