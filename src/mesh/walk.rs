//! Point location in a tetrahedral mesh by walking across faces: from a starting
//! tetrahedron, step to the neighbour across the face opposite the most negative
//! barycentric coordinate until every coordinate is non-negative. The domain (a box) is
//! convex, so the walk reaches the point; queries in a spatially coherent order (Morton)
//! start next to their answer and take a few steps each.

use super::Mesh;
use std::collections::HashMap;

/// Tolerance on barycentric coordinates for "inside" (points on faces and edges).
const BARY_TOL: f64 = 1e-10;

/// Steps after which a walk gives up (a cycle on a degenerate configuration) and the
/// tetrahedra are searched one by one.
const MAX_STEPS: usize = 100_000;

/// Barycentric coordinates of `p` in the tetrahedron `v`.
pub fn tet_barycentric(v: &[[f64; 3]; 4], p: [f64; 3]) -> [f64; 4] {
    let d = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let det3 = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| {
        a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])
    };
    let (e1, e2, e3, q) = (d(v[1], v[0]), d(v[2], v[0]), d(v[3], v[0]), d(p, v[0]));
    let det = det3(e1, e2, e3);
    let l1 = det3(q, e2, e3) / det;
    let l2 = det3(e1, q, e3) / det;
    let l3 = det3(e1, e2, q) / det;
    [1.0 - l1 - l2 - l3, l1, l2, l3]
}

/// The face neighbours of every tetrahedron of a mesh, for [`TetWalk::locate`].
pub struct TetWalk {
    /// Per tetrahedron, the neighbour across the face opposite vertex i (-1: boundary).
    neighbours: Vec<[i32; 4]>,
}

impl TetWalk {
    pub fn new(mesh: &Mesh) -> Self {
        let mut faces: HashMap<[u32; 3], (u32, u8)> = HashMap::with_capacity(2 * mesh.tets.len());
        let mut neighbours = vec![[-1i32; 4]; mesh.tets.len()];
        for (t, tet) in mesh.tets.iter().enumerate() {
            for i in 0..4 {
                let mut f = [0usize, 1, 2, 3].map(|k| tet[k]);
                f[i] = u32::MAX;
                f.sort_unstable();
                let key = [f[0], f[1], f[2]];
                match faces.remove(&key) {
                    Some((s, j)) => {
                        neighbours[t][i] = s as i32;
                        neighbours[s as usize][j as usize] = t as i32;
                    }
                    None => {
                        faces.insert(key, (t as u32, i as u8));
                    }
                }
            }
        }
        TetWalk { neighbours }
    }

    /// The tetrahedron of `mesh` holding `p` and the barycentric coordinates of `p` in it,
    /// walking from tetrahedron `from`; None when `p` lies outside the mesh.
    pub fn locate(&self, mesh: &Mesh, p: [f64; 3], from: usize) -> Option<(usize, [f64; 4])> {
        let corners = |t: usize| std::array::from_fn(|k| mesh.nodes[mesh.tets[t][k] as usize]);
        let mut t = from.min(mesh.tets.len().checked_sub(1)?);
        for _ in 0..MAX_STEPS {
            let l = tet_barycentric(&corners(t), p);
            let (i, worst) = l.iter().enumerate().fold((0, f64::INFINITY), |m, (i, &v)| if v < m.1 { (i, v) } else { m });
            if worst >= -BARY_TOL {
                return Some((t, l));
            }
            match self.neighbours[t][i] {
                -1 => return None,
                n => t = n as usize,
            }
        }
        (0..mesh.tets.len()).find_map(|t| {
            let l = tet_barycentric(&corners(t), p);
            l.iter().all(|&v| v >= -BARY_TOL).then_some((t, l))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{generate, MeshSpec};

    #[test]
    fn barycentric_coordinates_reproduce_the_point() {
        let v = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 3.0]];
        let p = [0.3, 0.2, 0.9];
        let l = tet_barycentric(&v, p);
        for c in 0..3 {
            let x: f64 = (0..4).map(|k| l[k] * v[k][c]).sum();
            assert!((x - p[c]).abs() < 1e-14);
        }
        assert!(l.iter().all(|&x| x > 0.0));
        assert!(tet_barycentric(&v, [1.0, 1.0, 1.0]).iter().any(|&x| x < 0.0));
    }

    /// Every node of a refined mesh is found in a coarser mesh of the same box, and a P1
    /// field (x + 2y - z) interpolated there is exact; a point outside the box is not found.
    #[test]
    fn the_walk_finds_the_nodes_of_a_finer_mesh() {
        let coarse = generate(&MeshSpec::paper_default()).unwrap();
        let mut spec = MeshSpec::paper_default();
        spec.ring = Some(crate::mesh::Ring { inner: 0.9, outer: 1.1, size: 0.125 });
        let fine = generate(&spec).unwrap();
        let walk = TetWalk::new(&coarse);
        let f = |p: [f64; 3]| p[0] + 2.0 * p[1] - p[2];
        let mut from = 0;
        for &n in &crate::mesh::morton_order(&fine) {
            let p = fine.nodes[n as usize];
            let (t, l) = walk.locate(&coarse, p, from).unwrap_or_else(|| panic!("node {n} at {p:?} not found"));
            let v: f64 = (0..4).map(|k| l[k] * f(coarse.nodes[coarse.tets[t][k] as usize])).sum();
            assert!((v - f(p)).abs() < 1e-9, "{v} against {}", f(p));
            from = t;
        }
        assert!(walk.locate(&coarse, [1e3, 0.0, 0.0], 0).is_none());
    }
}
