//! Point location on the contact face.

use super::Mesh;

/// Tolerance on barycentric coordinates for "inside".
const BARY_TOL: f64 = 1e-12;

/// Barycentric coordinates of `p` in the 2D triangle `(a, b, c)`.
pub(crate) fn barycentric(a: [f64; 2], b: [f64; 2], c: [f64; 2], p: [f64; 2]) -> [f64; 3] {
    let det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
    let l1 = ((p[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (p[1] - a[1])) / det;
    let l2 = ((b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1])) / det;
    [1.0 - l1 - l2, l1, l2]
}

/// True if all barycentric coordinates are >= `-BARY_TOL`.
pub(crate) fn inside(l: &[f64; 3]) -> bool {
    l.iter().all(|&v| v >= -BARY_TOL)
}

/// Bucket grid over the contact rectangle (cells of size `h_c`) for fast
/// repeated [`Mesh::locate_contact`]-style queries.
#[derive(Clone, Debug)]
pub struct ContactLocator {
    x0: f64,
    z0: f64,
    h: f64,
    nx: usize,
    nz: usize,
    /// Per cell: contact triangles whose bounding box meets the cell.
    cells: Vec<Vec<u32>>,
}

impl ContactLocator {
    /// Builds the bucket grid for `mesh`.
    pub fn new(mesh: &Mesh) -> Self {
        let r = mesh.spec.contact;
        let h = mesh.contact_size;
        let nx = ((r.x1 - r.x0) / h).round().max(1.0) as usize;
        let nz = ((r.z1 - r.z0) / h).round().max(1.0) as usize;
        let mut loc = ContactLocator { x0: r.x0, z0: r.z0, h, nx, nz, cells: vec![Vec::new(); nx * nz] };
        for (k, c) in mesh.contact_tris.iter().enumerate() {
            let p = [c[0], c[1], c[2]].map(|i| mesh.nodes[i as usize]);
            let (i0, i1) = loc.range(p.iter().map(|q| q[0]), loc.x0, nx);
            let (j0, j1) = loc.range(p.iter().map(|q| q[2]), loc.z0, nz);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    loc.cells[i + nx * j].push(k as u32);
                }
            }
        }
        loc
    }

    /// Cell index range covered by the coordinate values `v` along one axis.
    fn range(&self, v: impl Iterator<Item = f64> + Clone, origin: f64, n: usize) -> (usize, usize) {
        let lo = v.clone().fold(f64::INFINITY, f64::min);
        let hi = v.fold(f64::NEG_INFINITY, f64::max);
        (self.cell(lo, origin, n), self.cell(hi, origin, n))
    }

    /// Clamped cell index of coordinate `v`.
    fn cell(&self, v: f64, origin: f64, n: usize) -> usize {
        (((v - origin) / self.h).floor().max(0.0) as usize).min(n - 1)
    }

    /// Same contract as [`Mesh::locate_contact`], in O(1).
    pub fn locate(&self, mesh: &Mesh, x: f64, z: f64) -> Option<(usize, [f64; 3])> {
        let r = mesh.spec.contact;
        if !r.contains(x, z, BARY_TOL * self.h) {
            return None;
        }
        let (i, j) = (self.cell(x, self.x0, self.nx), self.cell(z, self.z0, self.nz));
        self.cells[i + self.nx * j].iter().find_map(|&k| {
            let l = mesh.contact_barycentric(k as usize, x, z);
            inside(&l).then_some((k as usize, l))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn barycentric_reproduces_point() {
        let (a, b, c) = ([0.0, 0.0], [2.0, 0.0], [0.0, 1.0]);
        let l = barycentric(a, b, c, [0.5, 0.25]);
        let x = l[0] * a[0] + l[1] * b[0] + l[2] * c[0];
        let z = l[0] * a[1] + l[1] * b[1] + l[2] * c[1];
        assert!((x - 0.5).abs() < 1e-15 && (z - 0.25).abs() < 1e-15);
        assert!(inside(&l));
        assert!(!inside(&barycentric(a, b, c, [2.0, 1.0])));
    }
}
