//! Film and pressure quantities from a converged EHL state (dimensionless, on every rank):
//! central and minimum film thickness, maximum pressure, load balance and profiles.
use super::layout::Layout;
use crate::fem::p2tri::{p2_tri_weights, tri_area};
use crate::mesh::{ContactLocator, Mesh};

/// Nodal pressure and film of one contact triangle (6 P2 nodes).
pub struct FieldsOnFace<'a> {
    pub mesh: &'a Mesh,
    pub layout: &'a Layout,
    pub x: &'a [f64],
    locator: ContactLocator,
}

/// The headline numbers of a solution (dimensionless).
#[derive(Debug, Clone, Copy)]
pub struct FilmStats {
    pub hc: f64,
    pub hm: f64,
    pub hm_at: [f64; 2],
    pub pmax: f64,
    pub pmax_at: [f64; 2],
    pub load: f64,
    pub h0: f64,
    /// Minimum of the P2 pressure field (lattice search; the interpolant can undershoot
    /// the nodal values next to a steep pressure spike).
    pub pmin: f64,
    /// Minimum nodal pressure (the unknowns: what the cavitation penalty acts on).
    pub pmin_nodes: f64,
}

impl<'a> FieldsOnFace<'a> {
    pub fn new(mesh: &'a Mesh, layout: &'a Layout, x: &'a [f64]) -> Self {
        FieldsOnFace { mesh, layout, x, locator: ContactLocator::new(mesh) }
    }

    /// Nodal pressure P (0 on the Dirichlet edges).
    pub fn p_node(&self, n: u32) -> f64 {
        Layout::value(self.x, self.layout.p[n as usize])
    }

    /// Nodal film H = H0 + (X^2 + Z^2)/2 - U_y.
    pub fn h_node(&self, n: u32) -> f64 {
        self.layout.film(self.mesh, self.x, n)
    }

    /// Whether the mesh is the half domain z <= 0 of a symmetric scene.
    pub fn half(&self) -> bool {
        self.mesh.spec.half_z
    }

    /// The contact triangle containing (x, z) and the point's barycentric coordinates. On a
    /// half domain a point z > 0 is located at its mirror image (x, -z).
    pub fn locate(&self, x: f64, z: f64) -> Option<(usize, [f64; 3])> {
        let z = if self.half() { -z.abs() } else { z };
        self.locator.locate(self.mesh, x, z)
    }

    /// (P, H) at a point of the contact face, by P2 interpolation.
    pub fn at(&self, x: f64, z: f64) -> Option<(f64, f64)> {
        let (t, b) = self.locate(x, z)?;
        let tri = self.mesh.contact_tris[t];
        let p = tri.map(|n| self.p_node(n));
        let h = tri.map(|n| self.h_node(n));
        Some((crate::fem::p2_tri_eval(&p, b), crate::fem::p2_tri_eval(&h, b)))
    }

    /// Central film, minimum film (searched on a lattice of 15 points per triangle),
    /// maximum pressure, and the load integral.
    pub fn stats(&self) -> FilmStats {
        let (mut hm, mut hm_at) = (f64::INFINITY, [0.0; 2]);
        let (mut pmax, mut pmax_at) = (f64::NEG_INFINITY, [0.0; 2]);
        let mut pmin = f64::INFINITY;
        let mut load = 0.0;
        const K: usize = 4;
        for tri in &self.mesh.contact_tris {
            let p = tri.map(|n| self.p_node(n));
            let h = tri.map(|n| self.h_node(n));
            let v = [0, 1, 2].map(|i| {
                let c = self.mesh.nodes[tri[i] as usize];
                [c[0], c[2]]
            });
            let w = p2_tri_weights(tri_area(&v));
            load += (0..6).map(|k| w[k] * p[k]).sum::<f64>();
            for i in 0..=K {
                for j in 0..=(K - i) {
                    let b = [i as f64 / K as f64, j as f64 / K as f64, (K - i - j) as f64 / K as f64];
                    let (pv, hv) = (crate::fem::p2_tri_eval(&p, b), crate::fem::p2_tri_eval(&h, b));
                    let at = [b[0] * v[0][0] + b[1] * v[1][0] + b[2] * v[2][0], b[0] * v[0][1] + b[1] * v[1][1] + b[2] * v[2][1]];
                    if hv < hm {
                        hm = hv;
                        hm_at = at;
                    }
                    if pv > pmax {
                        pmax = pv;
                        pmax_at = at;
                    }
                    pmin = pmin.min(pv);
                }
            }
        }
        let hc = self.at(0.0, 0.0).map(|v| v.1).unwrap_or(f64::NAN);
        let pmin_nodes = self.mesh.contact_nodes.iter().map(|&n| self.p_node(n)).fold(f64::INFINITY, f64::min);
        FilmStats { hc, hm, hm_at, pmax, pmax_at, load, h0: self.x[self.layout.h0 as usize], pmin, pmin_nodes }
    }

    /// Samples (X, Z, P, H) on the segment from `a` to `b` with `n` points.
    pub fn profile(&self, a: [f64; 2], b: [f64; 2], n: usize) -> Vec<[f64; 4]> {
        (0..n)
            .filter_map(|i| {
                let t = i as f64 / (n - 1) as f64;
                let (x, z) = (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
                self.at(x, z).map(|(p, h)| [x, z, p, h])
            })
            .collect()
    }
}
