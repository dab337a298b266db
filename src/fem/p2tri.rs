//! Quadratic (P2) Lagrange basis on the reference triangle.
//!
//! Nodes: `v0, v1, v2, mid(0,1), mid(1,2), mid(2,0)` (VTK_QUADRATIC_TRIANGLE), in the
//! 2D coordinates `(x, z)` of the contact plane. With barycentric coordinates `l_k`:
//! `N_k = l_k (2 l_k - 1)` for the vertices, `N_{3+e} = 4 l_i l_j` for edge `e = (i, j)`.

/// Vertex pairs of the three edges, in the order of the midside nodes 3..6.
pub const TRI_EDGES: [[usize; 2]; 3] = [[0, 1], [1, 2], [2, 0]];

/// Reference coordinates of the 6 nodes.
pub const P2_TRI_REF_NODES: [[f64; 2]; 6] = [
    [0.0, 0.0],
    [1.0, 0.0],
    [0.0, 1.0],
    [0.5, 0.0],
    [0.5, 0.5],
    [0.0, 0.5],
];

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

#[cfg(test)]
mod tests {
    use super::*;

    fn pts() -> Vec<[f64; 2]> {
        vec![
            [0.1, 0.2],
            [1.0 / 3.0, 1.0 / 3.0],
            [0.7, 0.1],
            [0.0, 0.6],
            [0.45, 0.5],
        ]
    }

    fn quad(x: [f64; 2]) -> (f64, [f64; 2]) {
        let [s, t] = x;
        (
            0.3 - s + 2.0 * t + 1.5 * s * s - 0.7 * s * t + 2.2 * t * t,
            [-1.0 + 3.0 * s - 0.7 * t, 2.0 - 0.7 * s + 4.4 * t],
        )
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
                assert_eq!(
                    0.5 * (P2_TRI_REF_NODES[*i][c] + P2_TRI_REF_NODES[*j][c]),
                    P2_TRI_REF_NODES[3 + e][c]
                );
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
}
