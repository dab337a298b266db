//! The cavitation multiplier of complementarity cavitation, node by node.
//!
//! Where the film cavitates, the Reynolds residual does not vanish: the condition P >= 0
//! absorbs it, and its density is the cavitation multiplier. The SUPG strong residual must
//! subtract it there, or the elements at the free boundary are stabilised against a
//! residual the exact solution does not have (docs/numerics.md, "Cavitation as
//! complementarity"). The penalty model carries it implicitly: xi pen(P_k) tends to the
//! row's residual per unit area. Here it is measured directly: g_k is node k's Galerkin
//! residual (the Reynolds row without SUPG) over its lumped area, and the element weighs
//! it by 1 - pressurised(P_k) ([`super::element::reynolds_element_with_multiplier`]).
//!
//! g_k depends on the unknowns of every triangle around k, so a row's exact Jacobian
//! reaches the triangles around its element's nodes (two rings). [`Multipliers::chain`]
//! gives the entries that fall inside the Reynolds rows' own pattern (the nodes sharing a
//! triangle with the row's node) and drops those beyond: the two-ring pattern made each LU
//! a third dearer, and Newton took as many iterations without it (docs/numerics.md,
//! "Cavitation as complementarity"). Each coupling maps the entries to its own columns.

use super::element::{reynolds_element, ElementOut, Fluid, Stabilisation};
use std::collections::HashMap;

/// One contact triangle as the multiplier sees it: its 6 nodes, vertices, entrainment
/// velocity at the vertices and nodal P and H.
pub struct FaceElement<'a> {
    pub nodes: &'a [u32; 6],
    pub verts: &'a [[f64; 2]; 3],
    pub vel: &'a [[f64; 2]; 3],
    pub p: [f64; 6],
    pub h: [f64; 6],
}

/// The part of a stabilisation the multiplier is measured with: the Galerkin term (with
/// any artificial diffusion, which is part of the discrete operator), no SUPG.
pub fn galerkin_part(stab: &Stabilisation) -> Stabilisation {
    Stabilisation { supg: false, jump: 0.0, penalty: 0.0, ..*stab }
}

/// The nodal multipliers g_k of the contact face at one iterate.
pub struct Multipliers {
    /// Lumped area (a sixth of each triangle's) of each contact node.
    area: HashMap<u32, f64>,
    /// The triangles around each contact node.
    around: HashMap<u32, Vec<usize>>,
    /// The nodes sharing a triangle with each contact node (sorted): a Reynolds row's
    /// pattern.
    ring: HashMap<u32, Vec<u32>>,
    /// g_k at the last [`Multipliers::evaluate`].
    value: HashMap<u32, f64>,
}

impl Multipliers {
    /// For the contact triangles `tris` (node lists) with areas `areas`.
    pub fn new(tris: &[[u32; 6]], areas: &[f64]) -> Self {
        let mut area: HashMap<u32, f64> = HashMap::new();
        let mut around: HashMap<u32, Vec<usize>> = HashMap::new();
        for (t, (tri, a)) in tris.iter().zip(areas).enumerate() {
            for &n in tri {
                *area.entry(n).or_insert(0.0) += a / 6.0;
                let list = around.entry(n).or_default();
                if list.last() != Some(&t) {
                    list.push(t);
                }
            }
        }
        Multipliers { area, around, ring: crate::fem::p2tri::node_rings(tris), value: HashMap::new() }
    }

    /// g_k at every contact node from the Galerkin residuals of all `n` triangles
    /// (`element(t)` gives triangle t with its fields).
    pub fn evaluate<'a>(&mut self, n: usize, element: impl Fn(usize) -> FaceElement<'a>, fluid: &Fluid, stab: &Stabilisation) {
        let galerkin = galerkin_part(stab);
        let mut sum: HashMap<u32, f64> = HashMap::with_capacity(self.area.len());
        for t in 0..n {
            let e = element(t);
            let out = reynolds_element(e.verts, &e.p, &e.h, e.vel, fluid, &galerkin);
            for (k, &node) in e.nodes.iter().enumerate() {
                *sum.entry(node).or_insert(0.0) += out.r[k];
            }
        }
        self.value = sum.into_iter().map(|(node, g)| (node, g / self.area[&node])).collect();
    }

    /// g at the nodes of one triangle (0 at a node never evaluated).
    pub fn of(&self, nodes: &[u32; 6]) -> [f64; 6] {
        nodes.map(|n| self.value.get(&n).copied().unwrap_or(0.0))
    }

    /// The multiplier's part of a row element's Jacobian: with `dr_dm` = dR_i/dg_k of the
    /// element on `nodes`, calls `add(i, node, dR_i/dP_node, dR_i/dH_node)` for every node
    /// of the triangles around each k that row i depends on and that shares a triangle with
    /// row i's node (the row's pattern; the module documentation says why the rest is
    /// dropped). Summed over every element, the entries inside that pattern are exact.
    pub fn chain<'a>(
        &self,
        nodes: &[u32; 6],
        dr_dm: &[[f64; 6]; 6],
        element: impl Fn(usize) -> FaceElement<'a>,
        fluid: &Fluid,
        stab: &Stabilisation,
        mut add: impl FnMut(usize, u32, f64, f64),
    ) {
        let galerkin = galerkin_part(stab);
        // Neighbouring nodes share triangles: each triangle's Galerkin derivatives once.
        let mut done: Vec<(usize, ElementOut)> = Vec::new();
        for (k, &node) in nodes.iter().enumerate() {
            if (0..6).all(|i| dr_dm[i][k] == 0.0) {
                continue;
            }
            let inv_area = 1.0 / self.area[&node];
            for &t in &self.around[&node] {
                let e = element(t);
                let Some(row) = e.nodes.iter().position(|&m| m == node) else { continue };
                let at = match done.iter().position(|(u, _)| *u == t) {
                    Some(at) => at,
                    None => {
                        done.push((t, reynolds_element(e.verts, &e.p, &e.h, e.vel, fluid, &galerkin)));
                        done.len() - 1
                    }
                };
                let out = &done[at].1;
                for i in 0..6 {
                    let c = dr_dm[i][k] * inv_area;
                    if c == 0.0 {
                        continue;
                    }
                    let ring = &self.ring[&nodes[i]];
                    for (m, &col) in e.nodes.iter().enumerate() {
                        if ring.binary_search(&col).is_ok() {
                            add(i, col, c * out.dr_dp[row][m], c * out.dr_dh[row][m]);
                        }
                    }
                }
            }
        }
    }
}
