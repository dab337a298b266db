//! A posteriori error indicator of the Reynolds equation on P2 triangles: the local mass
//! flux the discrete solution fails to conserve.
//!
//! For the dimensionless equation div(rho_bar H v) - div(eps grad P) + pen(P) = 0 the
//! indicator of a triangle K is
//!
//!   eta_K = int_K |r| dA + 1/2 sum_{edges e of K} int_e |[eps dP/dn]| ds,
//!
//! with r the complete strong residual of the discrete fields (every term, the cavitation
//! penalty included) and [.] the jump of the normal Poiseuille flux across an interior
//! edge (the Couette flux rho_bar H v is continuous: H and P are). Both parts are a mass
//! flow (units of rho_bar H v times a length), so they add without weights: eta_K is the
//! flow that is not balanced in K, which is where the film transport (the inlet
//! meniscus, the outlet constriction and spike, the side lobes, a spin pole) is
//! under-resolved. It is used to mark elements; the error of hc and hm is estimated from
//! the change between refinement levels (see `app::adapt`).

use super::cavitation::Cavitation;
use super::dual::Dual;
use super::element::{strong_residual, Fluid, PointFields, Stabilisation, StrongResidual};
use crate::fem::p2tri::P2Triangle;
use crate::fem::quadrature::DUNAVANT6;

type D1 = Dual<1>;

/// Two-point Gauss rule on [0, 1]: abscissae and weights.
const GAUSS2: [(f64, f64); 2] = [(0.211_324_865_405_187_1, 0.5), (0.788_675_134_594_812_9, 0.5)];

/// The parts of one element's indicator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElementResidual {
    /// int_K |r| dA.
    pub interior: f64,
    /// Outward normal Poiseuille flux eps dP/dn at the two Gauss points of each edge
    /// (edge e from vertex e to vertex e+1, points ordered along it), times the Gauss
    /// weight and the edge length: summed with the neighbour's values at the same points
    /// (in reverse order) it gives int_e [eps dP/dn] ds by point.
    pub edge_flux: [[f64; 2]; 3],
}

/// Fields at one point: value and gradient of P and H, as constants for the strong residual.
fn fields_at(tri: &P2Triangle, l: &[f64; 3], p: &[f64; 6], h: &[f64; 6], fluid: &Fluid) -> (PointFields<1>, f64) {
    let n = P2Triangle::shape(l);
    let dn = tri.grad(l);
    let (mut pq, mut hq, mut gp, mut gh) = (0.0, 0.0, [0.0; 2], [0.0; 2]);
    for j in 0..6 {
        pq += p[j] * n[j];
        hq += h[j] * n[j];
        for c in 0..2 {
            gp[c] += p[j] * dn[j][c];
            gh[c] += h[j] * dn[j][c];
        }
    }
    let (eta, deta) = (fluid.eta)(pq);
    let (rho, drho) = (fluid.rho)(pq);
    let eps = rho * hq.powi(3) / (eta * fluid.lambda_bar);
    let c = D1::constant;
    let f =
        PointFields { h: c(hq), grad_p: gp.map(c), grad_h: gh.map(c), rho: c(rho), drho: c(drho), eta: c(eta), deta: c(deta), eps: c(eps) };
    (f, pq)
}

/// The indicator parts of one P2 triangle with nodal `p`, `h` (order v0, v1, v2, m01,
/// m12, m20), entrainment velocity `vel` at the vertices (affine inside) and the
/// cavitation treatment `cavitation` (a nodal penalty is interpolated as in the stabilised
/// element; with complementarity the residual counts where the film is pressurised, less
/// the nodal cavitation multipliers `multiplier` as the stabilised element subtracts them,
/// [`super::multiplier`]).
pub fn element_residual(
    verts: &[[f64; 2]; 3],
    p: &[f64; 6],
    h: &[f64; 6],
    vel: &[[f64; 2]; 3],
    fluid: &Fluid,
    cavitation: Cavitation,
    multiplier: Option<&[f64; 6]>,
) -> ElementResidual {
    let tri = P2Triangle::new(verts);
    let mut lap_p = 0.0;
    for j in 0..6 {
        lap_p += p[j] * tri.lap[j];
    }
    let div_v: f64 = (0..3).map(|k| vel[k][0] * tri.grad_l[k][0] + vel[k][1] * tri.grad_l[k][1]).sum();
    let pen_nodes: [f64; 6] = std::array::from_fn(|j| match (cavitation, multiplier) {
        (Cavitation::Penalty(xi), _) => xi * super::cavitation::penalty_law(p[j]).0,
        (Cavitation::Complementarity, Some(g)) => -(1.0 - super::cavitation::pressurised(D1::constant(p[j])).v) * g[j],
        _ => 0.0,
    });
    let stab = Stabilisation { residual: StrongResidual::Full, ..Stabilisation::default() };
    let mut interior = 0.0;
    for q in DUNAVANT6.iter() {
        let l = &q.l;
        let (f, _) = fields_at(&tri, l, p, h, fluid);
        let n = P2Triangle::shape(l);
        let v = [0, 1].map(|c| l[0] * vel[0][c] + l[1] * vel[1][c] + l[2] * vel[2][c]);
        let pen: f64 = (0..6).map(|j| pen_nodes[j] * n[j]).sum();
        let r = strong_residual(&stab, &f, fluid.lambda_bar, D1::constant(lap_p), v, div_v, D1::constant(pen));
        let weight = if cavitation == Cavitation::Complementarity {
            let pq: f64 = (0..6).map(|j| p[j] * n[j]).sum();
            super::cavitation::pressurised(D1::constant(pq)).v
        } else {
            1.0
        };
        interior += q.w * tri.area * r.v.abs() * weight;
    }
    // Outward normal of edge a -> b: (dz, -dx)/len for a counter-clockwise triangle in
    // (X, Z), the opposite for a clockwise one.
    let [x0, x1, x2] = *verts;
    let orient = ((x1[0] - x0[0]) * (x2[1] - x0[1]) - (x2[0] - x0[0]) * (x1[1] - x0[1])).signum();
    let mut edge_flux = [[0.0; 2]; 3];
    for (e, flux) in edge_flux.iter_mut().enumerate() {
        let (a, b) = (e, (e + 1) % 3);
        let (d, len) = (
            [verts[b][0] - verts[a][0], verts[b][1] - verts[a][1]],
            ((verts[b][0] - verts[a][0]).powi(2) + (verts[b][1] - verts[a][1]).powi(2)).sqrt(),
        );
        let nrm = [orient * d[1] / len, -orient * d[0] / len];
        for (g, &(s, w)) in GAUSS2.iter().enumerate() {
            let mut l = [0.0; 3];
            l[a] = 1.0 - s;
            l[b] = s;
            let (f, _) = fields_at(&tri, &l, p, h, fluid);
            flux[g] = w * len * f.eps.v * (f.grad_p[0].v * nrm[0] + f.grad_p[1].v * nrm[1]);
        }
    }
    ElementResidual { interior, edge_flux }
}

/// Dörfler marking: the fewest elements, largest indicators first, whose indicators add
/// up to at least `theta` of the total; elements with `eligible[k] = false` (already at
/// the smallest size allowed) are skipped. Returns a mark per element.
pub fn dorfler_mark(eta: &[f64], eligible: &[bool], theta: f64) -> Vec<bool> {
    let total: f64 = eta.iter().zip(eligible).filter(|(_, &ok)| ok).map(|(e, _)| *e).sum();
    let mut order: Vec<usize> = (0..eta.len()).filter(|&k| eligible[k]).collect();
    order.sort_by(|&a, &b| eta[b].total_cmp(&eta[a]));
    let mut marked = vec![false; eta.len()];
    let mut sum = 0.0;
    for k in order {
        if sum >= theta * total {
            break;
        }
        marked[k] = true;
        sum += eta[k];
    }
    marked
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRI: [[f64; 2]; 3] = [[0.0, 0.0], [0.5, 0.0], [0.0, 0.5]];

    fn nodes(f: impl Fn(f64, f64) -> f64) -> [f64; 6] {
        crate::fem::p2tri::p2_tri_node_coords(&TRI).map(|q| f(q[0], q[1]))
    }

    #[test]
    fn an_exact_solution_has_no_interior_residual() {
        // Constant lubricant, H = 1, v = (1, 0): P = X^2 - Z^2 is harmonic and the film
        // uniform, so every term of div(H v) - div(H^3 grad P / lambda) vanishes.
        let fluid = Fluid::constant(1.0);
        let vel = [[1.0, 0.0]; 3];
        let r0 = element_residual(&TRI, &nodes(|x, z| x * x - z * z), &[1.0; 6], &vel, &fluid, Cavitation::Off, None);
        assert!(r0.interior < 1e-13, "{}", r0.interior);
        // A film rising along the flow, H = 1 + X, with P = 0: r = dH/dX = 1, so
        // int |r| = area.
        let r1 = element_residual(&TRI, &[0.0; 6], &nodes(|x, _| 1.0 + x), &vel, &fluid, Cavitation::Off, None);
        assert!((r1.interior - 0.125).abs() < 1e-13, "{}", r1.interior);
    }

    #[test]
    fn edge_fluxes_of_a_smooth_field_cancel_between_neighbours() {
        // Two triangles sharing the edge (0.5, 0)-(0, 0.5): the outward fluxes of one
        // global P2 field are opposite at the same points.
        let fluid = Fluid::constant(1.0);
        let other = [[0.5, 0.5], [0.0, 0.5], [0.5, 0.0]];
        let f = |x: f64, z: f64| 1.0 + x * z + 2.0 * x * x;
        let h = [0.7; 6];
        let vel = [[1.0, 0.0]; 3];
        let a = element_residual(&TRI, &nodes(f), &h, &vel, &fluid, Cavitation::Off, None);
        let pb = crate::fem::p2tri::p2_tri_node_coords(&other).map(|q| f(q[0], q[1]));
        let b = element_residual(&other, &pb, &h, &vel, &fluid, Cavitation::Off, None);
        // TRI's edge 1 runs (0.5, 0) -> (0, 0.5), other's edge 1 the other way: the
        // points match in reverse order.
        for g in 0..2 {
            assert!((a.edge_flux[1][g] + b.edge_flux[1][1 - g]).abs() < 1e-13, "{a:?} {b:?}");
        }
        assert!(a.edge_flux[1][0].abs() > 1e-3);
    }

    #[test]
    fn dorfler_marks_the_largest_until_the_fraction() {
        let eta = [1.0, 5.0, 2.0, 2.0];
        assert_eq!(dorfler_mark(&eta, &[true; 4], 0.5), vec![false, true, false, false]);
        assert_eq!(dorfler_mark(&eta, &[true; 4], 0.6), vec![false, true, true, false]);
        assert_eq!(dorfler_mark(&eta, &[true, false, true, true], 0.5), vec![false, false, true, true]);
    }
}
