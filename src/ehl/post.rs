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

    /// The P2 interpolation at (x, z) as nodal weights (summing to 1): a point value of any
    /// nodal field as sum_n w_n f_n.
    pub fn weights_at(&self, x: f64, z: f64) -> Option<Vec<(u32, f64)>> {
        let (t, b) = self.locate(x, z)?;
        let phi = crate::fem::p2tri::p2_tri_basis_bary(b);
        Some(self.mesh.contact_tris[t].iter().zip(phi).map(|(&n, w)| (n, w)).collect())
    }

    /// The P2 pressure and film of contact triangle `k` at the 15 points of its
    /// fourth-order lattice: (X, Z), P, H.
    fn samples(&self, k: usize) -> impl Iterator<Item = ([f64; 2], f64, f64)> {
        const K: usize = 4;
        let tri = &self.mesh.contact_tris[k];
        let (p, h, v) = (tri.map(|n| self.p_node(n)), tri.map(|n| self.h_node(n)), self.mesh.contact_tri_xz(k));
        (0..=K).flat_map(move |i| {
            (0..=(K - i)).map(move |j| {
                let b = [i as f64 / K as f64, j as f64 / K as f64, (K - i - j) as f64 / K as f64];
                let at = [b[0] * v[0][0] + b[1] * v[1][0] + b[2] * v[2][0], b[0] * v[0][1] + b[1] * v[1][1] + b[2] * v[2][1]];
                (at, crate::fem::p2_tri_eval(&p, b), crate::fem::p2_tri_eval(&h, b))
            })
        })
    }

    /// The places where the film comes within the fraction `within` of its minimum `hm`:
    /// each contact triangle's lowest sample below (1 + within) hm, lowest first, thinned
    /// to places at least `separation` (units of a) apart, at most `max` of them. The
    /// first is where hm lies.
    pub fn near_minima(&self, hm: f64, within: f64, separation: f64, max: usize) -> Vec<[f64; 2]> {
        let lows = (0..self.mesh.contact_tris.len()).filter_map(|k| {
            self.samples(k).map(|(at, _, h)| (at, h)).filter(|&(_, h)| h < (1.0 + within) * hm).min_by(|a, b| a.1.total_cmp(&b.1))
        });
        separated_lowest(lows.collect(), separation, max)
    }

    /// Central film, minimum film (searched on a lattice of 15 points per triangle),
    /// maximum pressure, and the load integral.
    pub fn stats(&self) -> FilmStats {
        let (mut hm, mut hm_at) = (f64::INFINITY, [0.0; 2]);
        let (mut pmax, mut pmax_at) = (f64::NEG_INFINITY, [0.0; 2]);
        let mut pmin = f64::INFINITY;
        let mut load = 0.0;
        for (k, tri) in self.mesh.contact_tris.iter().enumerate() {
            let p = tri.map(|n| self.p_node(n));
            let w = p2_tri_weights(tri_area(&self.mesh.contact_tri_xz(k)));
            load += (0..6).map(|i| w[i] * p[i]).sum::<f64>();
            for (at, pv, hv) in self.samples(k) {
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
        let hc = self.at(0.0, 0.0).map(|v| v.1).unwrap_or(f64::NAN);
        let pmin_nodes = self.mesh.contact_nodes.iter().map(|&n| self.p_node(n)).fold(f64::INFINITY, f64::min);
        FilmStats { hc, hm, hm_at, pmax, pmax_at, load, h0: self.x[self.layout.h0 as usize], pmin, pmin_nodes }
    }

    /// dP/ds of contact triangle `k`'s P2 pressure at (x, z) along the unit direction
    /// `dir` (the triangle's polynomial, also just outside it). (x, z) is in the solved
    /// half when the mesh is a half domain; `mirrored` flips the z derivative.
    fn slope_in(&self, k: usize, x: f64, z: f64, dir: [f64; 2], mirrored: bool) -> f64 {
        let geo = crate::fem::AffineTri::new(&self.mesh.contact_tri_xz(k));
        let p = self.mesh.contact_tris[k].map(|n| self.p_node(n));
        let [gx, mut gz] = crate::fem::p2_tri_eval_grad(&p, self.mesh.contact_barycentric(k, x, z), &geo.grad_bary);
        if mirrored {
            gz = -gz;
        }
        gx * dir[0] + gz * dir[1]
    }

    /// The jumps of the pressure slope dP/ds along the segment from `a` to `b` at every
    /// change of contact triangle: (distance from `a`, signed jump, point), in units of a
    /// and p_H/a. The segment is sampled `n` times; at every change of triangle both
    /// polynomials are differentiated at the same point (the midpoint of the two samples).
    pub fn slope_jumps(&self, a: [f64; 2], b: [f64; 2], n: usize) -> SlopeJumps {
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        let dir = [(b[0] - a[0]) / len, (b[1] - a[1]) / len];
        let point = |i: usize| {
            let t = i as f64 / (n - 1) as f64;
            [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
        };
        let tri_at = |q: [f64; 2]| self.locate(q[0], q[1]).map(|(k, _)| k);
        let mut out = Vec::new();
        let mut prev = tri_at(point(0));
        for i in 1..n {
            let (q0, q) = (point(i - 1), point(i));
            let here = tri_at(q);
            let crosses_plane = self.half() && (q0[1] > 0.0) != (q[1] > 0.0);
            if let (Some(k0), Some(k1)) = (prev, here) {
                if k0 != k1 || crosses_plane {
                    let m = [0.5 * (q0[0] + q[0]), 0.5 * (q0[1] + q[1])];
                    // On the mirrored half of a half domain a triangle is differentiated at
                    // the mirror image of the point, its z derivative flipped.
                    let side = |k: usize, qz: f64| {
                        let mirrored = self.half() && qz > 0.0;
                        self.slope_in(k, m[0], if mirrored { -m[1] } else { m[1] }, dir, mirrored)
                    };
                    let s = (i as f64 - 0.5) / (n - 1) as f64 * len;
                    out.push((s, side(k1, q[1]) - side(k0, q0[1]), m));
                }
            }
            prev = here;
        }
        SlopeJumps(out)
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

/// The jumps of the pressure slope along a segment ([`FieldsOnFace::slope_jumps`]): at
/// every change of contact triangle, (distance from the segment's start, signed jump,
/// point), in units of a and p_H/a.
pub struct SlopeJumps(pub Vec<(f64, f64, [f64; 2])>);

impl SlopeJumps {
    /// The largest jump, in p_H/a, and where. The P2 pressure of a smooth field has slope
    /// jumps that vanish like h^2 |P'''|; across a resolved outlet spike they grow as the
    /// mesh resolves its slopes.
    pub fn largest(&self) -> (f64, [f64; 2]) {
        let largest = |w: (f64, [f64; 2]), c: (f64, [f64; 2])| if c.0 > w.0 { c } else { w };
        self.0.iter().map(|&(_, j, at)| (j.abs(), at)).fold((0.0, [f64::NAN; 2]), largest)
    }

    /// Node-to-node wiggles: the largest scallop height |[dP/ds]| l / 8 over the changes of
    /// triangle, in p_H, and where; l is the mean length of the segment's pieces in the two
    /// triangles. A P2 bubble of height A on a piece of length l has end slopes of +-4 A / l,
    /// so a row of scallops of height A (the P2 vertex mode: vertices low, mid-sides high)
    /// jumps by 8 A / l at each crossing: the measure is A. A smooth field gives
    /// O(l^3 |P'''|), which vanishes under refinement, also across a resolved spike; an
    /// under-resolved spike counts as the scallop it draws.
    pub fn largest_scallop(&self) -> (f64, [f64; 2]) {
        let j = &self.0;
        let mut worst = (0.0, [f64::NAN; 2]);
        for k in 0..j.len() {
            // The first and the last piece end at the segment's ends or outside the face:
            // there the other neighbouring piece's length is taken.
            let left = (k > 0).then(|| j[k].0 - j[k - 1].0);
            let right = (k + 1 < j.len()).then(|| j[k + 1].0 - j[k].0);
            let l = match (left, right) {
                (Some(a), Some(b)) => 0.5 * (a + b),
                (Some(a), None) | (None, Some(a)) => a,
                (None, None) => continue,
            };
            let height = j[k].1.abs() * l / 8.0;
            if height > worst.0 {
                worst = (height, j[k].2);
            }
        }
        worst
    }
}

/// The lowest of `places` (position, value), then each next lowest at least `separation`
/// from every one taken, at most `max` of them.
fn separated_lowest(mut places: Vec<([f64; 2], f64)>, separation: f64, max: usize) -> Vec<[f64; 2]> {
    places.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut taken: Vec<[f64; 2]> = Vec::new();
    for (at, _) in places {
        if taken.len() == max {
            break;
        }
        if taken.iter().all(|t| (t[0] - at[0]).hypot(t[1] - at[1]) >= separation) {
            taken.push(at);
        }
    }
    taken
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{generate, partition, MeshSpec, Rect};
    use crate::solid::dofmap::DofMap;

    /// A coarse mesh (0.5 a contact grid on [-3, 3]^2), its layout and a state vector
    /// whose nodal pressures are `p(X, Z)`.
    fn state(p: impl Fn(f64, f64) -> f64) -> (Mesh, Layout, Vec<f64>) {
        let mut spec = MeshSpec::paper_default();
        spec.contact_size = 0.5;
        let mesh = generate(&spec).unwrap();
        let part = partition(&mesh, 1);
        let dofs = DofMap::new(&mesh, &part, 1);
        let rect = Rect { x0: -3.0, x1: 3.0, z0: -3.0, z1: 3.0 };
        let layout = Layout::new(&mesh, &part, &dofs, &rect, false, 1);
        let mut x = vec![0.0; layout.h0 as usize + 1];
        for &n in &mesh.contact_nodes {
            let d = layout.p[n as usize];
            if d >= 0 {
                let c = mesh.nodes[n as usize];
                x[d as usize] = p(c[0], c[2]);
            }
        }
        (mesh, layout, x)
    }

    #[test]
    fn the_near_minima_are_the_separate_dips_within_the_fraction_lowest_first() {
        // A film with two dips, 0.5 at (1, 0) and 0.52 at (-1, 0), set through U_y.
        let (mesh, layout, mut x) = state(|_, _| 0.0);
        let dip = |x: f64, z: f64, cx: f64| (-((x - cx).powi(2) + z * z) / 0.1).exp();
        let film = |x: f64, z: f64| 1.0 - 0.5 * dip(x, z, 1.0) - 0.48 * dip(x, z, -1.0);
        x[layout.h0 as usize] = 0.0;
        for &n in &mesh.contact_nodes {
            let c = mesh.nodes[n as usize];
            let d = layout.u[n as usize][1];
            if d >= 0 {
                x[d as usize] = Layout::gap(c) - film(c[0], c[2]);
            }
        }
        let f = FieldsOnFace::new(&mesh, &layout, &x);
        let st = f.stats();
        assert!((st.hm - 0.5).abs() < 0.02 && (st.hm_at[0] - 1.0).abs() < 0.25, "hm {} at {:?}", st.hm, st.hm_at);
        let near = f.near_minima(st.hm, 0.1, 0.25, 4);
        assert_eq!(near.len(), 2, "{near:?}");
        assert_eq!(near[0], st.hm_at);
        assert!((near[1][0] + 1.0).abs() < 0.25 && near[1][1].abs() < 0.25, "{near:?}");
        // Within 1 % only the lowest dip; at most one place when asked for one.
        assert_eq!(f.near_minima(st.hm, 0.01, 0.25, 4).len(), 1);
        assert_eq!(f.near_minima(st.hm, 0.1, 0.25, 1).len(), 1);
    }

    #[test]
    fn separated_places_keep_their_distance_and_their_order() {
        let places = vec![([0.0, 0.0], 3.0), ([0.1, 0.0], 1.0), ([1.0, 0.0], 2.0), ([0.05, 0.0], 0.5)];
        assert_eq!(separated_lowest(places.clone(), 0.25, 4), vec![[0.05, 0.0], [1.0, 0.0]]);
        assert_eq!(separated_lowest(places.clone(), 0.01, 4), vec![[0.05, 0.0], [0.1, 0.0], [1.0, 0.0], [0.0, 0.0]]);
        assert_eq!(separated_lowest(places, 0.01, 2).len(), 2);
    }

    #[test]
    fn the_slope_jump_is_zero_for_a_quadratic_and_the_kink_or_wiggle_otherwise() {
        // A quadratic is reproduced by P2: no slope jumps (round-off only). The segments keep
        // off the elements next to the rectangle's edges, where P = 0 (Dirichlet).
        let (m, l, x) = state(|x, z| 1.0 - 0.1 * x * x - 0.05 * x * z + 0.02 * z * z);
        let f = FieldsOnFace::new(&m, &l, &x);
        let (j, _) = f.slope_jumps([-2.4, 0.1], [2.4, 0.1], 2001).largest();
        assert!(j < 1e-9, "quadratic: {j}");
        // A kink |X| on the mesh line X = 0: the slope jumps from -1 to +1 there.
        let (m, l, x) = state(|x, _| x.abs());
        let f = FieldsOnFace::new(&m, &l, &x);
        let (j, at) = f.slope_jumps([-2.4, 0.1], [2.4, 0.1], 2001).largest();
        assert!((j - 2.0).abs() < 1e-9 && at[0].abs() < 0.01, "kink: {j} at {at:?}");
        // A node-to-node wiggle of amplitude 0.01 on 0.25-spaced P2 nodes: slope jumps of
        // order 0.01 / 0.25 times a few.
        let (m, l, x) = state(|x, _| 0.01 * ((4.0 * x).round() as i64 % 2) as f64);
        let f = FieldsOnFace::new(&m, &l, &x);
        let (j, _) = f.slope_jumps([-2.4, 0.1], [2.4, 0.1], 2001).largest();
        assert!(j > 0.04, "wiggle: {j}");
    }
    #[test]
    fn the_wiggle_measure_is_the_height_of_the_vertex_mode_and_small_for_a_smooth_field() {
        // The P2 vertex mode of height 0.01 along X: the mid-side nodes of the 0.5 a grid
        // (at odd multiples of 0.25 a in X) 0.01 above the vertices.
        let mode = |v: f64| if ((2.0 * v).round() - 2.0 * v).abs() > 0.1 { 0.01 } else { 0.0 };
        let (m, l, x) = state(|x, _| 1.0 + mode(x));
        let f = FieldsOnFace::new(&m, &l, &x);
        let (w, _) = f.slope_jumps([-2.4, 0.1], [2.4, 0.1], 4001).largest_scallop();
        assert!(w > 0.005 && w < 0.02, "vertex mode: {w}");
        // A smooth field of the same size on the same mesh: an order of magnitude less.
        let (m, l, x) = state(|x, z| 1.0 + 0.05 * (x * 1.3).sin() * (z * 0.7).cos());
        let f = FieldsOnFace::new(&m, &l, &x);
        let (w, _) = f.slope_jumps([-2.4, 0.1], [2.4, 0.1], 4001).largest_scallop();
        assert!(w < 1e-3, "smooth: {w}");
    }
}
