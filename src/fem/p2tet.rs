//! Quadratic (P2) Lagrange basis on the reference tetrahedron, VTK node order.
//!
//! Nodes: `v0, v1, v2, v3, mid(0,1), mid(1,2), mid(0,2), mid(0,3), mid(1,3), mid(2,3)`
//! (VTK_QUADRATIC_TETRA). With barycentric coordinates `l_k` the shape functions are
//! `N_k = l_k (2 l_k - 1)` for the vertices and `N_{4+e} = 4 l_i l_j` for edge `e = (i, j)`.
//!
//! Vector fields use node-major element DOFs `[u_x0, u_y0, u_z0, u_x1, ...]` (30 per tet).

/// Vertex pairs of the six edges, in the order of the midside nodes 4..10.
pub const TET_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [0, 2], [0, 3], [1, 3], [2, 3]];

/// Reference coordinates of the 10 nodes.
pub const P2_TET_REF_NODES: [[f64; 3]; 10] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.5, 0.0, 0.0],
    [0.5, 0.5, 0.0],
    [0.0, 0.5, 0.0],
    [0.0, 0.0, 0.5],
    [0.5, 0.0, 0.5],
    [0.0, 0.5, 0.5],
];

/// Gradients of the barycentric coordinates with respect to the reference coordinates.
pub const TET_REF_GRAD_BARY: [[f64; 3]; 4] = [[-1.0, -1.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// Barycentric coordinates `(1 - x - y - z, x, y, z)` of a reference point.
#[inline(always)]
pub fn tet_bary(xi: [f64; 3]) -> [f64; 4] {
    [1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]]
}

/// P2 shape-function values from barycentric coordinates.
#[inline(always)]
pub fn p2_tet_basis_bary(l: [f64; 4]) -> [f64; 10] {
    let mut n = [0.0; 10];
    for k in 0..4 {
        n[k] = l[k] * (2.0 * l[k] - 1.0);
    }
    for (e, [i, j]) in TET_EDGES.iter().enumerate() {
        n[4 + e] = 4.0 * l[*i] * l[*j];
    }
    n
}

/// P2 shape-function values at a reference point.
#[inline(always)]
pub fn p2_tet_basis(xi: [f64; 3]) -> [f64; 10] {
    p2_tet_basis_bary(tet_bary(xi))
}

/// Gradients of the P2 shape functions given the barycentric coordinates `l` of the point
/// and the (constant) gradients `g` of the four barycentric coordinates in whichever
/// frame is wanted: with [`TET_REF_GRAD_BARY`] these are reference gradients, with
/// [`crate::fem::geometry::AffineTet::grad_bary`] physical gradients.
///
/// `grad N_k = (4 l_k - 1) g_k`, `grad N_{4+e} = 4 (l_j g_i + l_i g_j)`.
#[inline(always)]
pub fn p2_tet_grads_bary(l: [f64; 4], g: &[[f64; 3]; 4]) -> [[f64; 3]; 10] {
    let mut d = [[0.0; 3]; 10];
    for k in 0..4 {
        let s = 4.0 * l[k] - 1.0;
        for c in 0..3 {
            d[k][c] = s * g[k][c];
        }
    }
    for (e, [i, j]) in TET_EDGES.iter().enumerate() {
        let (li, lj) = (4.0 * l[*i], 4.0 * l[*j]);
        for c in 0..3 {
            d[4 + e][c] = lj * g[*i][c] + li * g[*j][c];
        }
    }
    d
}

/// Reference gradients `dN_k/dxi` of the P2 shape functions at a reference point.
#[inline(always)]
pub fn p2_tet_ref_grads(xi: [f64; 3]) -> [[f64; 3]; 10] {
    p2_tet_grads_bary(tet_bary(xi), &TET_REF_GRAD_BARY)
}

/// Evaluate a P2 vector field (30 node-major DOFs) at a point given by its barycentric
/// coordinates.
#[inline]
pub fn p2_tet_eval(values: &[f64; 30], bary: [f64; 4]) -> [f64; 3] {
    let n = p2_tet_basis_bary(bary);
    let mut u = [0.0; 3];
    for a in 0..10 {
        for c in 0..3 {
            u[c] += n[a] * values[3 * a + c];
        }
    }
    u
}

/// Evaluate a P2 scalar field (10 nodal values) at a point given by its barycentric
/// coordinates.
#[inline]
pub fn p2_tet_eval_scalar(values: &[f64; 10], bary: [f64; 4]) -> f64 {
    let n = p2_tet_basis_bary(bary);
    n.iter().zip(values).map(|(n, v)| n * v).sum()
}

/// Physical coordinates of the 10 P2 nodes of a straight-sided tetrahedron with the
/// given vertices (midside nodes at the edge midpoints, VTK order).
#[inline]
pub fn p2_tet_node_coords(verts: &[[f64; 3]; 4]) -> [[f64; 3]; 10] {
    let mut x = [[0.0; 3]; 10];
    x[..4].copy_from_slice(verts);
    for (e, [i, j]) in TET_EDGES.iter().enumerate() {
        for c in 0..3 {
            x[4 + e][c] = 0.5 * (verts[*i][c] + verts[*j][c]);
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pts() -> Vec<[f64; 3]> {
        vec![[0.1, 0.2, 0.3], [0.25, 0.25, 0.25], [0.7, 0.1, 0.05], [0.0, 0.3, 0.6], [0.33, 0.01, 0.5]]
    }

    #[test]
    fn partition_of_unity_and_zero_grad_sum() {
        for p in pts() {
            let n = p2_tet_basis(p);
            assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-14);
            let g = p2_tet_ref_grads(p);
            for c in 0..3 {
                assert!(g.iter().map(|v| v[c]).sum::<f64>().abs() < 1e-14);
            }
        }
    }

    #[test]
    fn kronecker_at_nodes() {
        for (i, x) in P2_TET_REF_NODES.iter().enumerate() {
            let n = p2_tet_basis(*x);
            for (j, v) in n.iter().enumerate() {
                let e = if i == j { 1.0 } else { 0.0 };
                assert!((v - e).abs() < 1e-15, "N_{j}(x_{i}) = {v}");
            }
        }
        // Midside nodes are the midpoints of the listed edges.
        for (e, [i, j]) in TET_EDGES.iter().enumerate() {
            for c in 0..3 {
                let m = 0.5 * (P2_TET_REF_NODES[*i][c] + P2_TET_REF_NODES[*j][c]);
                assert_eq!(m, P2_TET_REF_NODES[4 + e][c]);
            }
        }
    }

    /// A general quadratic and its gradient.
    fn quad(x: [f64; 3]) -> (f64, [f64; 3]) {
        let [a, b, c] = x;
        let v = 1.0 + 2.0 * a - b + 0.5 * c + 3.0 * a * a - a * b + 2.0 * b * c + 0.7 * c * c - 1.3 * a * c + 0.4 * b * b;
        let g = [2.0 + 6.0 * a - b - 1.3 * c, -1.0 - a + 2.0 * c + 0.8 * b, 0.5 + 2.0 * b + 1.4 * c - 1.3 * a];
        (v, g)
    }

    #[test]
    fn reproduces_quadratics() {
        let nodal: Vec<f64> = P2_TET_REF_NODES.iter().map(|x| quad(*x).0).collect();
        let nodal: [f64; 10] = nodal.try_into().unwrap();
        for p in pts() {
            let (v, g) = quad(p);
            let n = p2_tet_basis(p);
            let vh: f64 = n.iter().zip(&nodal).map(|(n, v)| n * v).sum();
            assert!((vh - v).abs() < 1e-13);
            assert!((p2_tet_eval_scalar(&nodal, tet_bary(p)) - v).abs() < 1e-13);
            let d = p2_tet_ref_grads(p);
            for c in 0..3 {
                let gh: f64 = (0..10).map(|a| d[a][c] * nodal[a]).sum();
                assert!((gh - g[c]).abs() < 1e-13);
            }
        }
    }

    #[test]
    fn grads_match_finite_differences() {
        let h = 1e-6;
        for p in pts() {
            let d = p2_tet_ref_grads(p);
            for c in 0..3 {
                let mut pp = p;
                let mut pm = p;
                pp[c] += h;
                pm[c] -= h;
                let (np, nm) = (p2_tet_basis(pp), p2_tet_basis(pm));
                for a in 0..10 {
                    assert!(((np[a] - nm[a]) / (2.0 * h) - d[a][c]).abs() < 1e-8);
                }
            }
        }
    }

    #[test]
    fn vector_eval() {
        let mut vals = [0.0; 30];
        for a in 0..10 {
            let x = P2_TET_REF_NODES[a];
            vals[3 * a] = quad(x).0;
            vals[3 * a + 1] = x[0] - 2.0 * x[2];
            vals[3 * a + 2] = x[1] * x[2];
        }
        let p = [0.2, 0.3, 0.1];
        let u = p2_tet_eval(&vals, tet_bary(p));
        assert!((u[0] - quad(p).0).abs() < 1e-13);
        assert!((u[1] - (p[0] - 2.0 * p[2])).abs() < 1e-14);
        assert!((u[2] - p[1] * p[2]).abs() < 1e-14);
    }
}
