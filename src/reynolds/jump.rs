//! Gradient-jump (continuous interior penalty) stabilisation of the pressure.
//!
//! Each interior edge E of the contact face, shared by the P2 triangles A and B, adds
//! ```text
//!   s_E(P, N_i) = gamma_E int_E [dP/dn] [dN_i/dn] ds,   [g] = g_A - g_B,
//!   gamma_E = c_J kappa |v(E)| min(h_E, h_R)^3,
//! ```
//! to the Reynolds rows of the nine nodes of A and B (h_E the edge's length, v the
//! entrainment velocity at its midpoint, kappa = [`super::element::ELASTIC_FILM_RESPONSE`],
//! c_J the scene's `reynolds.gradient_jump`).
//!
//! **Why.** In the Hertz zone the Reynolds equation degenerates (eps -> 0) and the pressure
//! is fixed by the film it makes through the solid, like a Lagrange multiplier. A P2
//! pressure has a mode the film hardly sees: vertex values down, mid-side values up (a P2
//! vertex function integrates to zero, so the mode carries no load, and the solid smooths
//! its deflection away). Nothing in the Galerkin or SUPG rows controls it, and it shows
//! as node-to-node wiggles of about 1 % p_H along the centre lines. The mode makes the
//! slope dP/dn jump at every edge by about its amplitude over h; a smooth pressure has
//! continuous slopes, so the term vanishes for the exact solution (consistent: the exact
//! solution satisfies the discrete equations; at a cavitation boundary P and its slope
//! are continuous too). On the discrete P2 field of a smooth pressure the jumps are
//! O(h^2 |P'''|).
//!
//! **Scale.** A pressure mode of amplitude A and wavelength h deflects the film by about
//! kappa h A, which changes a Reynolds row by about rho kappa |v| A h^2; the jump term of
//! the same mode is about gamma_E A / h. gamma_E = c_J kappa |v| h_E^3 makes the two of
//! the same order for c_J ~ 1, whatever the mesh size.
//!
//! **Only where the pressure is resolved.** On edges longer than h_R = [`RESOLVED_EDGE`]
//! the coefficient stays at its value for h_R. There the jumps are those of unresolved
//! features (the side lobes' fall, the outlet spike: O(p_H/a) per edge), not of the
//! vertex mode, and the full term smooths them into a different film: table2-ue2's 0.25 a
//! first level had hm 35 % low at c_J = 0.01, and the coarse levels' films moved enough
//! for the level-change estimate to ask for a level more (Moes M = 200, L = 10) or to miss
//! the target at the budget (spin-0.5deg's fz). The wiggles the term is for appear on the
//! resolved levels (0.0156 a and finer on table2-ue2), where it acts in full. The
//! coefficient depends on
//! geometry and velocity only, so the term is linear in P and its Jacobian is the matrix
//! below.
use crate::fem::p2tri::P2Triangle;

/// Two-point Gauss rule on [0, 1]: exact for the quadratic products of the two slopes
/// (each linear along the edge).
const GAUSS2: [(f64, f64); 2] = [(0.211_324_865_405_187_1, 0.5), (0.788_675_134_594_812_9, 0.5)];

/// Barycentric coordinates of point `x` in triangle `t` (outside it: the affine extension).
fn barycentric(t: &P2Triangle, x: [f64; 2]) -> [f64; 3] {
    let d = [x[0] - t.verts[0][0], x[1] - t.verts[0][1]];
    let l1 = t.grad_l[1][0] * d[0] + t.grad_l[1][1] * d[1];
    let l2 = t.grad_l[2][0] * d[0] + t.grad_l[2][1] * d[1];
    [1.0 - l1 - l2, l1, l2]
}

/// The jump matrix of the edge from `e0` to `e1` shared by triangles `a` and `b` (their
/// vertices): `m[i][j] = int_E [dN_i/dn] [dN_j/dn] ds` over the 12 local basis functions,
/// A's six (taken with +) then B's six (with -). Symmetric, positive semi-definite; a
/// P2 field that is one quadratic over A and B has no jump, so its 12 nodal values are in
/// the kernel.
pub fn jump_matrix(a: &[[f64; 2]; 3], b: &[[f64; 2]; 3], e0: [f64; 2], e1: [f64; 2]) -> [[f64; 12]; 12] {
    let (ta, tb) = (P2Triangle::new(a), P2Triangle::new(b));
    let t = [e1[0] - e0[0], e1[1] - e0[1]];
    let len = t[0].hypot(t[1]);
    let n = [t[1] / len, -t[0] / len];
    let mut m = [[0.0; 12]; 12];
    for &(s, w) in &GAUSS2 {
        let x = [e0[0] + s * t[0], e0[1] + s * t[1]];
        let (ga, gb) = (ta.grad(&barycentric(&ta, x)), tb.grad(&barycentric(&tb, x)));
        let dn: [f64; 12] =
            std::array::from_fn(|k| if k < 6 { ga[k][0] * n[0] + ga[k][1] * n[1] } else { -(gb[k - 6][0] * n[0] + gb[k - 6][1] * n[1]) });
        for i in 0..12 {
            for j in 0..12 {
                m[i][j] += w * len * dn[i] * dn[j];
            }
        }
    }
    m
}

/// Edge length (units of a) above which the coefficient no longer grows: the size below
/// which an adaptive level resolves the Hertz zone's pressure (the first levels are at
/// 0.25 a and 0.125 a).
pub const RESOLVED_EDGE: f64 = 0.03125;

/// The coefficient gamma_E = c_J kappa |v| min(h_E, [`RESOLVED_EDGE`])^3 of an edge of
/// length `h_e` with the entrainment velocity `v` at its midpoint.
pub fn jump_coefficient(c_j: f64, h_e: f64, v: [f64; 2]) -> f64 {
    c_j * super::element::ELASTIC_FILM_RESPONSE * v[0].hypot(v[1]) * h_e.min(RESOLVED_EDGE).powi(3)
}

/// One interior edge's term folded onto its distinct nodes (the two shared vertices and
/// the shared mid-side node appear once): `nodes` and the matrix `m` (row-major,
/// `nodes.len()` squared), without the coefficient gamma_E.
#[derive(Clone, Debug)]
pub struct EdgeJump {
    pub nodes: Vec<u32>,
    pub m: Vec<f64>,
    /// Edge length h_E and midpoint (for gamma_E).
    pub h_e: f64,
    pub mid: [f64; 2],
}

impl EdgeJump {
    /// The edge shared by triangles with nodes `na`, `nb` (P2 order) and vertices `va`,
    /// `vb`; `edge` gives the shared vertices' node numbers.
    pub fn new(na: &[u32; 6], va: &[[f64; 2]; 3], nb: &[u32; 6], vb: &[[f64; 2]; 3], edge: [u32; 2]) -> Self {
        let pos = |n: u32| va[na.iter().position(|&m| m == n).expect("edge vertex in triangle A")];
        let (e0, e1) = (pos(edge[0]), pos(edge[1]));
        let m12 = jump_matrix(va, vb, e0, e1);
        let mut nodes: Vec<u32> = Vec::with_capacity(9);
        let slot: [usize; 12] = std::array::from_fn(|k| {
            let n = if k < 6 { na[k] } else { nb[k - 6] };
            match nodes.iter().position(|&m| m == n) {
                Some(i) => i,
                None => {
                    nodes.push(n);
                    nodes.len() - 1
                }
            }
        });
        let d = nodes.len();
        let mut m = vec![0.0; d * d];
        for i in 0..12 {
            for j in 0..12 {
                m[slot[i] * d + slot[j]] += m12[i][j];
            }
        }
        let h_e = (e1[0] - e0[0]).hypot(e1[1] - e0[1]);
        EdgeJump { nodes, m, h_e, mid: [0.5 * (e0[0] + e1[0]), 0.5 * (e0[1] + e1[1])] }
    }
}

/// An edge's term on the global unknowns of its nodes, as an assembly uses it.
#[derive(Clone, Debug)]
pub struct JumpRows {
    pub edge: EdgeJump,
    /// The unknown of each of `edge.nodes` (-1: none, a Dirichlet node with P = 0).
    pub rows: Vec<i32>,
    /// gamma_E at the present velocity field.
    pub gamma: f64,
}

impl JumpRows {
    /// The term of `edge` on the unknowns `rows`, gamma_E from the factor `c_j` and the
    /// entrainment velocity field.
    pub fn new(edge: EdgeJump, rows: Vec<i32>, c_j: f64, velocity: &dyn Fn(f64, f64) -> [f64; 2]) -> Self {
        let mut t = JumpRows { edge, rows, gamma: 0.0 };
        t.set_velocity(c_j, velocity);
        t
    }

    /// gamma_E for a new velocity field.
    pub fn set_velocity(&mut self, c_j: f64, velocity: &dyn Fn(f64, f64) -> [f64; 2]) {
        self.gamma = jump_coefficient(c_j, self.edge.h_e, velocity(self.edge.mid[0], self.edge.mid[1]));
    }

    /// The Jacobian entry of rows a and b (positions in `rows`).
    pub fn entry(&self, a: usize, b: usize) -> f64 {
        self.gamma * self.edge.m[a * self.rows.len() + b]
    }

    /// Row a's residual for the unknowns `x` (indexed by `rows`).
    pub fn residual_row(&self, a: usize, x: &[f64]) -> f64 {
        (0..self.rows.len()).filter(|&b| self.rows[b] >= 0).map(|b| self.entry(a, b) * x[self.rows[b] as usize]).sum()
    }
}

impl EdgeJump {
    /// The edge's bilinear form without gamma_E, int_E [dP/dn] [dZ/dn] ds, for nodal
    /// values `p`, `z` indexed by node number.
    pub fn form(&self, p: &[f64], z: &[f64]) -> f64 {
        let d = self.nodes.len();
        let (pe, ze): (Vec<f64>, Vec<f64>) = self.nodes.iter().map(|&n| (p[n as usize], z[n as usize])).unzip();
        (0..d).map(|i| ze[i] * (0..d).map(|j| self.m[i * d + j] * pe[j]).sum::<f64>()).sum()
    }
}

/// Each edge's term gamma_E form_E(P, Z) of s(P, Z) = sum_E gamma_E int_E [dP/dn] [dZ/dn] ds.
/// `edges`: (triangle A, triangle B, the edge, gamma_E); `p`, `z` nodal values indexed by
/// node number.
///
/// With Z the adjoint of a value J, the sum z . S(P) is the first-order change of J if the
/// term were removed (a residual perturbation r moves J by -z . r, and removing the term is
/// r = -S(P)).
pub fn edge_terms(edges: &[(usize, usize, EdgeJump, f64)], p: &[f64], z: &[f64]) -> Vec<f64> {
    edges.iter().map(|(_, _, e, gamma)| gamma * e.form(p, z)).collect()
}

/// Each triangle's share of s(P, Z): half of |`terms`| ([`edge_terms`]) of each of its
/// interior edges.
///
/// With Z the adjoint of a value J, this is the part of J's discretisation error the term
/// makes: the term breaks Galerkin orthogonality, so J(u) - J(u_h) holds, besides the
/// residual weighted by the adjoint's interpolation error, -s(P_h, Z_h). A term that
/// moves a film value shows there, and refining where it does shrinks gamma_E.
pub fn triangle_shares(edges: &[(usize, usize, EdgeJump, f64)], n_tris: usize, terms: &[f64]) -> Vec<f64> {
    let mut share = vec![0.0; n_tris];
    for ((a, b, _, _), t) in edges.iter().zip(terms) {
        share[*a] += 0.5 * t.abs();
        share[*b] += 0.5 * t.abs();
    }
    share
}

/// The interior edges of a triangulation given by its P2 node lists and vertex
/// coordinates: (triangle A, triangle B, the two shared vertex nodes), A < B. Edges with a
/// single triangle (the boundary, the symmetry plane of a half domain) have no jump.
pub fn interior_edges(tris: &[[u32; 6]]) -> Vec<(usize, usize, [u32; 2])> {
    let mut seen: std::collections::HashMap<[u32; 2], usize> = std::collections::HashMap::new();
    let mut out = Vec::new();
    for (k, t) in tris.iter().enumerate() {
        for [i, j] in crate::fem::p2tri::TRI_EDGES {
            let key = if t[i] < t[j] { [t[i], t[j]] } else { [t[j], t[i]] };
            match seen.remove(&key) {
                Some(a) => out.push((a, k, key)),
                None => {
                    seen.insert(key, k);
                }
            }
        }
    }
    out.sort_unstable();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit square split along its diagonal from (0, 0) to (1, 1).
    fn square() -> ([[f64; 2]; 3], [[f64; 2]; 3]) {
        ([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]], [[0.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    }

    fn nodal(v: &[[f64; 2]; 3], f: impl Fn(f64, f64) -> f64) -> [f64; 6] {
        P2Triangle::new(v).nodes().map(|x| f(x[0], x[1]))
    }

    #[test]
    fn a_single_quadratic_has_no_jump_and_a_kink_has_the_exact_one() {
        let (a, b) = square();
        let m = jump_matrix(&a, &b, [0.0, 0.0], [1.0, 1.0]);
        let energy = |pa: [f64; 6], pb: [f64; 6]| {
            let p: Vec<f64> = pa.iter().chain(&pb).copied().collect();
            (0..12).map(|i| (0..12).map(|j| p[i] * m[i][j] * p[j]).sum::<f64>()).sum::<f64>()
        };
        let q = |x: f64, z: f64| 1.0 + 0.3 * x - 2.0 * z + x * x - 0.7 * x * z + 1.5 * z * z;
        assert!(energy(nodal(&a, q), nodal(&b, q)).abs() < 1e-12);
        // P = |x - z| / sqrt 2 (the distance to the diagonal): slope +1 on one side and -1
        // on the other along the normal, a jump of 2 over a length sqrt 2: 4 sqrt 2.
        let d = |x: f64, z: f64| (x - z) / 2f64.sqrt();
        let e = energy(nodal(&a, d), nodal(&b, |x, z| -d(x, z)));
        assert!((e - 4.0 * 2f64.sqrt()).abs() < 1e-12, "{e}");
        // A slope jump that varies along the edge: P_A = x^2 - z^2, P_B = 0. On the diagonal
        // (s, s) dP_A/dn = 2 sqrt(2) s, so the energy is int_0^1 8 s^2 sqrt(2) ds.
        let e = energy(nodal(&a, |x, z| (x - z) * (x + z)), [0.0; 6]);
        let exact = 8.0 * 2f64.sqrt() / 3.0;
        assert!((e - exact).abs() < 1e-12, "{e} vs {exact}");
    }

    #[test]
    fn the_folded_edge_term_is_symmetric_and_kills_the_vertex_mode() {
        let (a, b) = square();
        let (na, nb) = ([0, 1, 2, 10, 11, 12], [0, 2, 3, 12, 13, 14]);
        let e = EdgeJump::new(&na, &a, &nb, &b, [0, 2]);
        assert_eq!(e.nodes.len(), 9);
        let d = e.nodes.len();
        for i in 0..d {
            for j in 0..d {
                assert!((e.m[i * d + j] - e.m[j * d + i]).abs() < 1e-14);
            }
        }
        // The P2 vertex mode: vertices -1, mid-sides +1 (the pressure the film cannot see).
        let p: Vec<f64> = e.nodes.iter().map(|&n| if [0, 1, 2, 3].contains(&n) { -1.0 } else { 1.0 }).collect();
        assert!((e.h_e - 2f64.sqrt()).abs() < 1e-14 && e.mid == [0.5, 0.5]);
        let t = JumpRows { edge: e, rows: (0..9).collect(), gamma: 1.0 };
        let energy: f64 = (0..9).map(|a| t.residual_row(a, &p) * p[a]).sum();
        assert!(energy > 1.0, "{energy}");
        // A Dirichlet node (no unknown) has P = 0: its column drops out.
        let t = JumpRows { rows: [-1].into_iter().chain(1..9).collect(), ..t };
        let q: Vec<f64> = [0.0].into_iter().chain(p[1..].iter().copied()).collect();
        let r0: f64 = (1..9).map(|a| t.residual_row(a, &q) * q[a]).sum();
        let full: f64 = (0..9).map(|a| (0..9).map(|b| t.edge.m[a * 9 + b] * q[b]).sum::<f64>() * q[a]).sum();
        assert!((r0 - full).abs() < 1e-12, "{r0} vs {full}");
    }

    #[test]
    fn the_shares_vanish_for_a_smooth_pressure_and_split_a_kink_between_its_triangles() {
        let (a, b) = square();
        let (na, nb) = ([0, 1, 2, 10, 11, 12], [0, 2, 3, 12, 13, 14]);
        let e = EdgeJump::new(&na, &a, &nb, &b, [0, 2]);
        let node_xy = |n: usize| -> [f64; 2] {
            let (k, t) = if let Some(k) = na.iter().position(|&m| m == n as u32) {
                (k, &a)
            } else {
                (nb.iter().position(|&m| m == n as u32).unwrap(), &b)
            };
            P2Triangle::new(t).nodes()[k]
        };
        let field = |f: &dyn Fn(f64, f64) -> f64| -> Vec<f64> {
            (0..15)
                .map(|n| {
                    if [0, 1, 2, 3, 10, 11, 12, 13, 14].contains(&n) {
                        let x = node_xy(n);
                        f(x[0], x[1])
                    } else {
                        0.0
                    }
                })
                .collect()
        };
        let edges = vec![(0, 1, e, 2.0)];
        let z = field(&|x, z| (x - z).abs());
        // A quadratic pressure: no slope jump, no share whatever the adjoint.
        let q = field(&|x, z| 1.0 + x * x - 0.5 * x * z);
        let shares = |p: &[f64], z: &[f64]| triangle_shares(&edges, 2, &edge_terms(&edges, p, z));
        let effect = |p: &[f64], z: &[f64]| edge_terms(&edges, p, z).iter().sum::<f64>();
        assert!(shares(&q, &z).iter().all(|s| s.abs() < 1e-12));
        // The kink |x - z| / sqrt 2 against itself: gamma times the energy 4 sqrt 2, halved.
        let k = field(&|x, z| (x - z).abs() / 2f64.sqrt());
        let s = shares(&k, &k);
        let each = 0.5 * 2.0 * 4.0 * 2f64.sqrt();
        assert!((s[0] - each).abs() < 1e-12 && (s[1] - each).abs() < 1e-12, "{s:?}");
        // The signed effect: the two shares with their sign, and zero for the quadratic.
        assert!((effect(&k, &k) - 2.0 * each).abs() < 1e-12);
        let minus: Vec<f64> = k.iter().map(|v| -v).collect();
        assert!((effect(&k, &minus) + 2.0 * each).abs() < 1e-12);
        assert!(effect(&q, &z).abs() < 1e-12);
    }

    #[test]
    fn interior_edges_pair_the_triangles_that_share_them() {
        let tris = [[0, 1, 2, 10, 11, 12], [0, 2, 3, 12, 13, 14], [1, 4, 2, 15, 16, 11]];
        let edges = interior_edges(&tris);
        assert_eq!(edges, vec![(0, 1, [0, 2]), (0, 2, [1, 2])]);
    }

    #[test]
    fn the_coefficient_scales_with_the_cube_of_the_edge_up_to_the_resolved_size() {
        let g = |h| jump_coefficient(2.0, h, [0.6, 0.8]);
        let r = RESOLVED_EDGE;
        assert!((g(r / 2.0) / g(r / 4.0) - 8.0).abs() < 1e-12);
        assert!((g(r) - 2.0 * super::super::element::ELASTIC_FILM_RESPONSE * r.powi(3)).abs() < 1e-15);
        // Coarser edges keep the resolved size's coefficient.
        assert_eq!(g(4.0 * r), g(r));
    }
}
