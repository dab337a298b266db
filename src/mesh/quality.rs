//! Element quality measures.

use super::refine::{det6, dist, TET_EDGES};
use super::Mesh;

/// Worst-case quality over a mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quality {
    /// Smallest dihedral angle (degrees).
    pub min_dihedral_deg: f64,
    /// Largest aspect ratio `h_max / (2 sqrt(6) r_in)` (1 for a regular tet).
    pub max_aspect_ratio: f64,
    /// Smallest (signed) tet volume.
    pub min_volume: f64,
}

/// Cross product.
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Dot product.
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Difference `a - b`.
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Outward (unnormalised) normal of the face opposite vertex `k`.
fn outward_normal(p: &[[f64; 3]; 4], k: usize) -> [f64; 3] {
    let f: Vec<usize> = (0..4).filter(|&i| i != k).collect();
    let n = cross(sub(p[f[1]], p[f[0]]), sub(p[f[2]], p[f[0]]));
    if dot(n, sub(p[k], p[f[0]])) > 0.0 {
        n.map(|c| -c)
    } else {
        n
    }
}

/// `(min dihedral angle in degrees, aspect ratio, signed volume)` of a tet.
pub fn tet_quality(p: &[[f64; 3]; 4]) -> (f64, f64, f64) {
    let n = [0, 1, 2, 3].map(|k| outward_normal(p, k));
    let norm = n.map(|v| dot(v, v).sqrt());
    let mut min_angle = f64::INFINITY;
    for &(i, j) in &TET_EDGES {
        let c = (dot(n[i], n[j]) / (norm[i] * norm[j])).clamp(-1.0, 1.0);
        min_angle = min_angle.min(std::f64::consts::PI - c.acos());
    }
    let vol = det6([&p[0], &p[1], &p[2], &p[3]]) / 6.0;
    let area: f64 = norm.iter().sum::<f64>() * 0.5;
    let r_in = 3.0 * vol.abs() / area;
    let h_max = TET_EDGES.iter().map(|&(a, b)| dist(&p[a], &p[b])).fold(0.0, f64::max);
    (min_angle.to_degrees(), h_max / (2.0 * 6f64.sqrt() * r_in), vol)
}

/// Worst-case quality over all tets of `mesh`.
pub fn quality(mesh: &Mesh) -> Quality {
    let mut q = Quality { min_dihedral_deg: f64::INFINITY, max_aspect_ratio: 0.0, min_volume: f64::INFINITY };
    for t in 0..mesh.tets.len() {
        let (a, r, v) = tet_quality(&mesh.tet_corners(t));
        q.min_dihedral_deg = q.min_dihedral_deg.min(a);
        q.max_aspect_ratio = q.max_aspect_ratio.max(r);
        q.min_volume = q.min_volume.min(v);
    }
    q
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_tet() {
        let s = 1.0 / 2f64.sqrt();
        let p = [[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]].map(|v| v.map(|c| c * s));
        let (a, r, v) = tet_quality(&p);
        assert!((a - (1.0f64 / 3.0).acos().to_degrees()).abs() < 1e-12);
        assert!((r - 1.0).abs() < 1e-12);
        assert!(v.abs() > 0.0);
    }

    /// Over cubic cells, bisection generates 3 similarity classes (tags 3, 2, 1),
    /// all with dihedral angles >= 45 deg (the Kuhn tet's minimum).
    #[test]
    fn bisection_shapes_of_cube() {
        use crate::mesh::refine::Bisector;
        let mut b = Bisector::kuhn(&[vec![0.0, 1.0], vec![0.0, 1.0], vec![0.0, 1.0]]);
        let mut min_angle = f64::INFINITY;
        for _ in 0..6 {
            for i in 0..b.tets.len() {
                b.bisect(i);
            }
            for t in &b.tets {
                let p = t.map(|i| b.verts[i as usize]);
                min_angle = min_angle.min(tet_quality(&p).0);
            }
        }
        assert!((min_angle - 45.0).abs() < 1e-9, "{min_angle}");
    }

    #[test]
    fn kuhn_tet_angles() {
        // Kuhn tet of the unit cube: dihedral angles 45, 60, 90 degrees.
        let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 1.0, 1.0]];
        let (a, _, v) = tet_quality(&p);
        assert!((a - 45.0).abs() < 1e-12);
        assert!((v - 1.0 / 6.0).abs() < 1e-15);
    }
}
