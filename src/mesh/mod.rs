//! Graded, conforming P2 tetrahedral mesh of the equivalent solid (a box),
//! its contact face, boundary flags, quality report and rank partition.
//!
//! All lengths are dimensionless (units of the Hertz radius `a`).
//!
//! Algorithm ([`generate`]):
//! 1. coarse tensor grid of 16-cells anchored at the origin
//!    ([`spec::coarse_breaks`]);
//! 2. Kuhn triangulation (6 tets per box, same orientation everywhere);
//! 3. Maubach newest-vertex bisection of every tet whose longest edge exceeds
//!    `sqrt(3) h(d)`, `h(d) = h_c + g d`, `d` = distance of its bounding box
//!    to the contact rectangle, followed by conformity closure; the optional core
//!    square, ring and patch lower `h(d)` near them the same way;
//! 4. P2 nodes at the edge midpoints (straight-sided), contact triangles and
//!    boundary flags.
//!
//! Over the contact rectangle the result is a uniform Kuhn grid of spacing
//! `h_c = 16 / 2^L` (see [`MeshSpec::actual_contact_size`]).

mod assemble;
pub mod face;
mod locate;
mod partition;
mod quality;
mod refine;
pub mod size_field;
pub mod spec;

mod walk;

#[cfg(test)]
mod tests;

use crate::error::Error;
pub use locate::ContactLocator;
pub use partition::{equal_blocks, morton3, morton_order, partition, Partition};
pub use quality::{quality, tet_quality, Quality};
pub use spec::{MeshSpec, Rect, Ring};
pub use walk::{tet_barycentric, TetWalk};

/// A P2 tetrahedral mesh of the box with its contact face.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// P2 nodes: vertices first (`0..n_vertices`), then edge midpoints.
    pub nodes: Vec<[f64; 3]>,
    /// Number of tet vertices (corner nodes).
    pub n_vertices: usize,
    /// VTK quadratic tets: `v0, v1, v2, v3, mid(0,1), mid(1,2), mid(0,2),
    /// mid(0,3), mid(1,3), mid(2,3)`; positive orientation
    /// (`det[v1-v0, v2-v0, v3-v0] > 0`).
    pub tets: Vec<[u32; 10]>,
    /// P2 triangles of the top face `y = 0` inside the contact rectangle:
    /// `v0, v1, v2, mid(0,1), mid(1,2), mid(2,0)`. Orientation: positive
    /// signed area in the `(x, z)` plane, i.e.
    /// `(x1-x0)(z2-z0) - (x2-x0)(z1-z0) > 0` (so the 2D map from the
    /// reference triangle to `(x, z)` has a positive Jacobian). Note that,
    /// because `x × z = -y`, this is clockwise when seen from `+y`.
    pub contact_tris: Vec<[u32; 6]>,
    /// The tet each contact triangle is a face of.
    pub contact_tri_tet: Vec<u32>,
    /// Sorted unique node ids of the contact triangles.
    pub contact_nodes: Vec<u32>,
    /// Per node: lies on the clamped bottom face `y = -D`.
    pub clamped: Vec<bool>,
    /// Per node: lies on the symmetry plane `z = 0` (only when `half_z`).
    pub symmetry: Vec<bool>,
    /// Actual contact element size `h_c = 16 / 2^L` used.
    pub contact_size: f64,
    /// The specification the mesh was generated from.
    pub spec: MeshSpec,
}

/// Generates the mesh described by `spec` (validated first).
pub fn generate(spec: &MeshSpec) -> Result<Mesh, Error> {
    let h = spec.validate()?;
    Ok(assemble::assemble(refined_bisector(spec, h), spec, h))
}

/// A rectangle refinement: bounding box corners, element size, optional radial limits.
type BoxRefinement = ([f64; 3], [f64; 3], f64, Option<(f64, f64)>);

/// Kuhn coarse mesh refined by Maubach bisection + closure until every tet
/// satisfies `longest_edge <= sqrt(3) (h + growth d)`.
fn refined_bisector(spec: &MeshSpec, h: f64) -> refine::Bisector {
    let mut b = refine::Bisector::kuhn(&spec.coarse_grid());
    let r = spec.contact;
    let (rlo, rhi) = ([r.x0, 0.0, r.z0], [r.x1, 0.0, r.z1]);
    let g = spec.growth;
    let dyadic = spec::dyadic_size;
    // Rectangle refinements (the core square and the patch): bounding box, size and, for
    // the patch, the radial limits it may carry.
    let boxes: Vec<BoxRefinement> = spec
        .core
        .iter()
        .map(|&c| (c, None, spec.core_depth))
        .chain(spec.patch.iter().map(|&p| (p, spec.patch_radii, 0.0)))
        .map(|((c, size), radii, depth)| ([c.x0, -depth, c.z0], [c.x1, 0.0, c.z1], dyadic(size), radii))
        .collect();
    let ring = spec.ring.map(|r| (r.inner, r.outer, dyadic(r.size)));
    b.refine_and_close(|v, t| {
        let d = refine::bbox_distance(v, t, &rlo, &rhi);
        let mut target = h + g * d;
        for (lo, hi, hb, radii) in &boxes {
            // Distance to the rectangle, or to its part inside the annulus: the larger of
            // the two distances, a lower bound of the distance to the intersection (so the
            // grading around it is, if anything, finer than asked).
            let mut db = refine::bbox_distance(v, t, lo, hi);
            if let Some((r0, r1)) = radii {
                db = db.max(refine::ring_distance(v, t, *r0, *r1));
            }
            target = target.min(hb + g * db);
        }
        if let Some((r0, r1, hr)) = ring {
            target = target.min(hr + g * refine::ring_distance(v, t, r0, r1));
        }
        if let Some(f) = &spec.size_field {
            let [(x0, x1), (_, y1), (z0, z1)] = refine::tet_ranges(v, t);
            target = target.min(f.min_over([x0, z0], [x1, z1]) + g * (-y1).max(0.0));
        }
        refine::longest_edge(v, t) > 3f64.sqrt() * target * (1.0 + 1e-10)
    });
    b
}

impl Mesh {
    /// Number of P2 nodes.
    pub fn n_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Coordinates of the 4 corners of tet `t`.
    pub fn tet_corners(&self, t: usize) -> [[f64; 3]; 4] {
        let q = &self.tets[t];
        [0, 1, 2, 3].map(|k| self.nodes[q[k] as usize])
    }

    /// Volume of tet `t` (straight-sided).
    pub fn tet_volume(&self, t: usize) -> f64 {
        let p = self.tet_corners(t);
        refine::det6([&p[0], &p[1], &p[2], &p[3]]) / 6.0
    }

    /// Total volume of the mesh.
    pub fn volume(&self) -> f64 {
        (0..self.tets.len()).map(|t| self.tet_volume(t)).sum()
    }

    /// The `(x, z)` coordinates of the three vertices of contact triangle `k`.
    pub fn contact_tri_xz(&self, k: usize) -> [[f64; 2]; 3] {
        let c = &self.contact_tris[k];
        [0, 1, 2].map(|i| {
            let p = self.nodes[c[i] as usize];
            [p[0], p[2]]
        })
    }

    /// Signed `(x, z)` area of contact triangle `k` (positive by construction).
    pub fn contact_tri_area(&self, k: usize) -> f64 {
        let c = &self.contact_tris[k];
        assemble::area_xz(&self.nodes, [c[0], c[1], c[2]])
    }

    /// Total area of the contact triangles (equals the rectangle's area).
    pub fn top_face_area_in_contact(&self) -> f64 {
        (0..self.contact_tris.len()).map(|k| self.contact_tri_area(k)).sum()
    }

    /// The contact triangle containing `(x, z)` and the barycentric
    /// coordinates of the point in it (w.r.t. its corners `v0, v1, v2`);
    /// `None` outside the contact rectangle. Linear scan; use
    /// [`ContactLocator`] for many queries.
    pub fn locate_contact(&self, x: f64, z: f64) -> Option<(usize, [f64; 3])> {
        (0..self.contact_tris.len()).find_map(|k| {
            let l = self.contact_barycentric(k, x, z);
            locate::inside(&l).then_some((k, l))
        })
    }

    /// Barycentric coordinates of `(x, z)` in contact triangle `k`.
    pub fn contact_barycentric(&self, k: usize, x: f64, z: f64) -> [f64; 3] {
        let c = &self.contact_tris[k];
        let [a, b, d] = [c[0], c[1], c[2]].map(|i| self.nodes[i as usize]);
        locate::barycentric([a[0], a[2]], [b[0], b[2]], [d[0], d[2]], [x, z])
    }
}
