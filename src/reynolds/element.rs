//! Element residual and exact Jacobian of the dimensionless Reynolds equation on one
//! straight P2 triangle. See the module documentation of [`crate::reynolds`] for the
//! formulas.

use super::dual::Dual;
use crate::fem::p2tri::P2Triangle;
use crate::fem::quadrature::DUNAVANT6;

/// Number of element unknowns differentiated: 6 nodal P then 6 nodal H.
pub const NDOF: usize = 12;

/// Dual number over the 12 element unknowns (P_0..P_5, H_0..H_5).
pub type D12 = Dual<NDOF>;

/// Lubricant laws in dimensionless form, all functions of the dimensionless pressure P.
///
/// `eta(P) = (eta_bar, d eta_bar/dP)`, `rho(P) = (rho_bar, d rho_bar/dP)`.
/// `d2eta`, `d2rho` give the second derivatives d^2 eta_bar/dP^2 and d^2 rho_bar/dP^2:
/// the SUPG strong residual contains grad eps = eps_P grad P + eps_H grad H, and the
/// exact Jacobian of eps_P needs them. They are not evaluated when SUPG is off.
pub struct Fluid<'a> {
    /// eta_bar(P) and d eta_bar/dP.
    pub eta: &'a dyn Fn(f64) -> (f64, f64),
    /// rho_bar(P) and d rho_bar/dP.
    pub rho: &'a dyn Fn(f64) -> (f64, f64),
    /// d^2 eta_bar/dP^2.
    pub d2eta: &'a dyn Fn(f64) -> f64,
    /// d^2 rho_bar/dP^2.
    pub d2rho: &'a dyn Fn(f64) -> f64,
    /// lambda_bar = 12 eta_R Ue R^2 / (a^3 p_H).
    pub lambda_bar: f64,
}

fn unit_law(_: f64) -> (f64, f64) {
    (1.0, 0.0)
}
fn zero_law(_: f64) -> f64 {
    0.0
}

impl Fluid<'static> {
    /// Incompressible, iso-viscous lubricant: eta_bar = rho_bar = 1.
    pub fn constant(lambda_bar: f64) -> Self {
        Fluid { eta: &unit_law, rho: &unit_law, d2eta: &zero_law, d2rho: &zero_law, lambda_bar }
    }
}

/// Streamline-upwind Petrov-Galerkin (SUPG) stabilisation settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stabilisation {
    /// Add the SUPG term.
    pub supg: bool,
    /// Multiplier delta of the stabilisation parameter tau (1.0 by default).
    pub delta: f64,
    /// Isotropic artificial diffusion (Habchi et al.): eps_id = id * h_e * |beta| is added to
    /// the diffusion coefficient of the Galerkin term, with beta = (d rho_bar/dP) H v the
    /// convection velocity of P in the Couette term. Inconsistent by O(h): 0 switches it off.
    pub id: f64,
    /// Crosswind diffusion: eps_cd = cd * h_e * |beta| acts across the streamlines only,
    /// eps_cd [grad P . grad N_i - (t . grad P)(t . grad N_i)], t = v/|v|. It damps the
    /// crosswind stripes (P2 film modes that the Couette term cannot see, since it only
    /// differentiates along v) and leaves the streamline balance alone. Inconsistent by
    /// O(h) like `id`; 0 switches it off.
    pub cd: f64,
    /// Cavitation penalty factor xi of the equation (0: none). The caller adds the lumped
    /// penalty xi area_i pen(P_i) to row i; the SUPG strong residual needs the same term as
    /// a field, xi sum_j pen(P_j) N_j, or SUPG is inconsistent where the film cavitates
    /// (there the penalty, not the Reynolds operator, balances div(rho H v)).
    pub penalty: f64,
    /// Which terms the strong residual keeps (see [`StrongResidual`]).
    pub residual: StrongResidual,
    /// Peclet number (and so tau) on Habchi's convection velocity beta = (d rho_bar/dP) H v
    /// instead of v (see the module documentation).
    pub film_peclet: bool,
    /// Factor c_J of the gradient-jump term on the interior edges ([`super::jump`]; 0: off).
    /// The assembly adds it edge by edge; the element kernel does not see it.
    pub jump: f64,
    /// Cavitation as the complementarity condition ([`super::cavitation::complementarity`]):
    /// where the discrete pressure is not positive the exact solution's residual is the
    /// cavitation multiplier, not zero, so SUPG drops its strong residual there.
    pub complementarity: bool,
}

/// The terms of the SUPG strong residual r = div(rho_bar H v) - div(eps grad P) + penalty.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StrongResidual {
    /// Every term: the exact residual of the discrete fields (fully consistent).
    Full,
    /// div(eps grad P) with the lubricant properties frozen inside the element:
    /// eps Lap P + (d eps/dH) grad H . grad P, without (d eps/dP) |grad P|^2.
    FrozenLubricant,
    /// The Couette (and penalty) part only: streamline diffusion of the Couette flux.
    Couette,
}

impl Default for Stabilisation {
    /// SUPG on, delta = 1, full strong residual, Pe on |v|.
    fn default() -> Self {
        Self {
            supg: true,
            delta: 1.0,
            id: 0.0,
            cd: 0.0,
            penalty: 0.0,
            residual: StrongResidual::Full,
            film_peclet: false,
            jump: 0.0,
            complementarity: false,
        }
    }
}

impl Stabilisation {
    /// Plain Galerkin.
    pub fn none() -> Self {
        Self { supg: false, ..Self::default() }
    }
    /// SUPG with multiplier `delta`.
    pub fn supg(delta: f64) -> Self {
        Self { delta, ..Self::default() }
    }
}

/// Element residual and its exact Jacobian.
#[derive(Clone, Debug)]
pub struct ElementOut {
    /// R_i, i = local node.
    pub r: [f64; 6],
    /// dR_i/dP_j.
    pub dr_dp: [[f64; 6]; 6],
    /// dR_i/dH_j.
    pub dr_dh: [[f64; 6]; 6],
    /// dR_i/dg_j, g_j the nodal cavitation multiplier the SUPG term was given (zero
    /// without one; see [`reynolds_element_with_multiplier`]).
    pub dr_dm: [[f64; 6]; 6],
}

/// Upwind function xi(Pe) = coth(Pe) - 1/Pe and its derivative.
/// xi ~ Pe/3 for small Pe (series below Pe = 1e-2, avoiding cancellation), xi -> 1 for large Pe.
pub fn xi(pe: f64) -> (f64, f64) {
    if pe < 0.0 {
        // xi is odd; a negative Peclet number only arises from an unphysical (negative)
        // film inside an element, where the stabilisation must stay bounded.
        let (v, d) = xi(-pe);
        return (-v, d);
    }
    if pe < 1e-2 {
        let p2 = pe * pe;
        (pe * (1.0 / 3.0 - p2 / 45.0 + 2.0 * p2 * p2 / 945.0), 1.0 / 3.0 - p2 / 15.0 + 2.0 * p2 * p2 / 189.0)
    } else {
        let s = pe.sinh(); // inf for pe > ~710: 1/s^2 = 0, fine
        (1.0 / pe.tanh() - 1.0 / pe, 1.0 / (pe * pe) - 1.0 / (s * s))
    }
}

/// Length of the triangle in the direction of `v` (Tezduyar's h_UGN):
/// h_s = 2 |v| / sum_k |v . grad L_k|. Returns 0 for v = 0.
pub fn streamline_length(tri: &P2Triangle, v: [f64; 2]) -> f64 {
    streamline_length_from_gradients(&tri.grad_l, v)
}

/// [`streamline_length`] from the barycentric gradients `g` of a triangle.
pub fn streamline_length_from_gradients(g: &[[f64; 2]; 3], v: [f64; 2]) -> f64 {
    let vn = (v[0] * v[0] + v[1] * v[1]).sqrt();
    if vn == 0.0 {
        return 0.0;
    }
    let s: f64 = g.iter().map(|g| (v[0] * g[0] + v[1] * g[1]).abs()).sum();
    2.0 * vn / s
}

/// Film response dH/dP of the elastic solid to a pressure mode of wavelength h_e, over
/// h_e, in the dimensionless units of the Reynolds equation (H = h R/a^2, P = p/p_H): a
/// pressure p over a patch of size s deflects a half-space by about 2 p s/(pi E'), which is
/// 2 s P/pi^2 in these units.
pub const ELASTIC_FILM_RESPONSE: f64 = 2.0 / (std::f64::consts::PI * std::f64::consts::PI);

/// SUPG parameter tau = delta h_e / (2|v|) xi(Pe) at a quadrature point (|v| = `vn` > 0),
/// with Pe = |beta| h_e / (2 eps) on the convection velocity beta of P in the Couette term
/// when `stab.film_peclet`, else on |v|. beta = (d rho_bar/dP) H v for a compressible
/// lubricant (Habchi's); an incompressible one (drho = 0) convects P only through the
/// elastic film, beta = [`ELASTIC_FILM_RESPONSE`] h_e v. Any tau keeps SUPG consistent (it
/// multiplies the strong residual); this one sets how strongly it acts. Shared by the P2
/// and P1 elements; exact through the duals.
pub fn supg_tau<const N: usize>(stab: &Stabilisation, vn: f64, h_e: f64, eps: Dual<N>, drho: Dual<N>, h: Dual<N>) -> Dual<N> {
    let pe_v = (vn * h_e * 0.5) / eps;
    let pe = match (stab.film_peclet, drho.v != 0.0) {
        (true, true) => pe_v * drho * h,
        (true, false) => pe_v * (ELASTIC_FILM_RESPONSE * h_e),
        (false, _) => pe_v,
    };
    let (xv, dxv) = xi(pe.v);
    pe.chain(xv, dxv) * (stab.delta * h_e / (2.0 * vn))
}

/// The fields and lubricant properties at one quadrature point, as duals over the element
/// unknowns (P2 or P1 element): what the SUPG strong residual needs.
pub struct PointFields<const N: usize> {
    /// H, grad P, grad H.
    pub h: Dual<N>,
    pub grad_p: [Dual<N>; 2],
    pub grad_h: [Dual<N>; 2],
    /// rho_bar, d rho_bar/dP, eta_bar, d eta_bar/dP (the derivatives as duals: they carry
    /// rho'' and eta'').
    pub rho: Dual<N>,
    pub drho: Dual<N>,
    pub eta: Dual<N>,
    pub deta: Dual<N>,
    /// eps = rho_bar H^3 / (eta_bar lambda_bar).
    pub eps: Dual<N>,
}

/// SUPG strong residual r = div(rho_bar H v) - [eps Lap P + grad eps . grad P] + pen with
/// the terms `stab.residual` keeps (see [`StrongResidual`]); `lap_p` is Lap P (0 for P1),
/// `pen` the interpolated penalty xi pen(P). Shared by the P2 and P1 elements.
pub fn strong_residual<const N: usize>(
    stab: &Stabilisation,
    q: &PointFields<N>,
    lambda_bar: f64,
    lap_p: Dual<N>,
    v: [f64; 2],
    div_v: f64,
    pen: Dual<N>,
) -> Dual<N> {
    let (gp, gh) = (&q.grad_p, &q.grad_h);
    // div(rho H v) = v . grad(rho H) + rho H div v, grad(rho H) = rho' H grad P + rho grad H
    let drho_h = q.drho * q.h;
    let conv = (drho_h * gp[0] + q.rho * gh[0]) * v[0] + (drho_h * gp[1] + q.rho * gh[1]) * v[1] + q.rho * q.h * div_v;
    if stab.residual == StrongResidual::Couette {
        return conv + pen;
    }
    // grad eps = eps_P grad P + eps_H grad H, eps_P = eps (rho'/rho - eta'/eta), eps_H = 3 eps / H
    // (written without dividing by H); FrozenLubricant drops eps_P grad P.
    let eps_h = q.rho * q.h * q.h * 3.0 / (q.eta * lambda_bar);
    let eps_p = if stab.residual == StrongResidual::Full { q.eps * (q.drho / q.rho - q.deta / q.eta) } else { Dual::constant(0.0) };
    let g_eps = [eps_p * gp[0] + eps_h * gh[0], eps_p * gp[1] + eps_h * gh[1]];
    let div_flux = q.eps * lap_p + g_eps[0] * gp[0] + g_eps[1] * gp[1];
    conv - div_flux + pen
}

/// Element residual and exact Jacobian of the Reynolds equation (no source term).
///
/// `verts`: the 3 vertices; `p`, `h`: nodal P and H (order v0, v1, v2, m01, m12, m20);
/// `vel`: entrainment velocity (u_bar, w_bar) at the 3 vertices (affine inside).
/// The film H should be positive (eps ~ H^3; nothing here clips it) and eta_bar, rho_bar
/// nonzero. Any vertex orientation is accepted.
pub fn reynolds_element(
    verts: &[[f64; 2]; 3],
    p: &[f64; 6],
    h: &[f64; 6],
    vel: &[[f64; 2]; 3],
    fluid: &Fluid,
    stab: &Stabilisation,
) -> ElementOut {
    reynolds_element_with_source(verts, p, h, vel, fluid, stab, None)
}

/// As [`reynolds_element`], for the equation with a right-hand side f(X, Z):
/// -div(eps grad P) + div(rho_bar H vel) = f. The source enters the Galerkin part as
/// -int f N_i and the SUPG strong residual as r_strong - f (so SUPG stays consistent).
/// Used for manufactured solutions; the physical problem has f = 0.
pub fn reynolds_element_with_source(
    verts: &[[f64; 2]; 3],
    p: &[f64; 6],
    h: &[f64; 6],
    vel: &[[f64; 2]; 3],
    fluid: &Fluid,
    stab: &Stabilisation,
    source: Option<&dyn Fn(f64, f64) -> f64>,
) -> ElementOut {
    reynolds_element_general(verts, p, h, vel, fluid, stab, source, None)
}

/// As [`reynolds_element`], with the nodal cavitation multiplier `g` of complementarity
/// cavitation in the SUPG strong residual. Where the film cavitates the exact solution's
/// strong residual is the multiplier (the Reynolds residual that the condition P >= 0
/// absorbs), not zero. The penalty's SUPG term carries it as xi pen(P_j); under
/// complementarity SUPG subtracts sum_j (1 - pressurised(P_j)) g_j N_j, with g_j the node's
/// Galerkin residual per unit area (`super::multiplier`), the penalty's limit. Without it
/// the elements at the free boundary see a residual the exact solution does not have, and
/// on coarse meshes the outlet film is far off (table2-ue2 at 0.25 a: hm +12 %).
/// `out.dr_dm` holds dR_i/dg_j for the caller's chain rule.
pub fn reynolds_element_with_multiplier(
    verts: &[[f64; 2]; 3],
    p: &[f64; 6],
    h: &[f64; 6],
    vel: &[[f64; 2]; 3],
    fluid: &Fluid,
    stab: &Stabilisation,
    g: &[f64; 6],
) -> ElementOut {
    reynolds_element_general(verts, p, h, vel, fluid, stab, None, Some(g))
}

#[allow(clippy::too_many_arguments)]
fn reynolds_element_general(
    verts: &[[f64; 2]; 3],
    p: &[f64; 6],
    h: &[f64; 6],
    vel: &[[f64; 2]; 3],
    fluid: &Fluid,
    stab: &Stabilisation,
    source: Option<&dyn Fn(f64, f64) -> f64>,
    multiplier: Option<&[f64; 6]>,
) -> ElementOut {
    let tri = P2Triangle::new(verts);
    let pd: [D12; 6] = std::array::from_fn(|j| D12::variable(p[j], j));
    let hd: [D12; 6] = std::array::from_fn(|j| D12::variable(h[j], 6 + j));

    // P2 second derivatives are constant: Lap P, Lap H once per element.
    // (Lap H does not enter the residual.)
    let mut lap_p = D12::constant(0.0);
    for j in 0..6 {
        lap_p += pd[j] * tri.lap[j];
    }
    // div vel (zero for rigid-body entrainment; kept so the strong residual is exact
    // for any affine field): div v = sum_k v_k . grad L_k
    let div_v: f64 = (0..3).map(|k| vel[k][0] * tri.grad_l[k][0] + vel[k][1] * tri.grad_l[k][1]).sum();

    // Nodal cavitation penalty xi pen(P_j), interpolated in the SUPG strong residual.
    let pen_nodes: [D12; 6] = std::array::from_fn(|j| {
        if stab.supg && stab.penalty > 0.0 {
            let (v, d) = super::cavitation::penalty_law(p[j]);
            pd[j].chain(v, d) * stab.penalty
        } else {
            D12::constant(0.0)
        }
    });

    // The multiplier's nodal weights 1 - pressurised(P_j) (as duals: they depend on P_j).
    let cavitated: Option<[D12; 6]> = multiplier
        .filter(|_| stab.supg && stab.complementarity)
        .map(|_| std::array::from_fn(|j| D12::constant(1.0) - super::cavitation::pressurised(pd[j])));
    let mut dr_dm = [[0.0; 6]; 6];

    let mut res = [D12::constant(0.0); 6];
    for q in DUNAVANT6.iter() {
        let l = &q.l;
        let wq = q.w * tri.area;
        let n = P2Triangle::shape(l);
        let dn = tri.grad(l);

        let mut pq = D12::constant(0.0);
        let mut hq = D12::constant(0.0);
        let mut gp = [D12::constant(0.0); 2];
        let mut gh = [D12::constant(0.0); 2];
        for j in 0..6 {
            pq += pd[j] * n[j];
            hq += hd[j] * n[j];
            for c in 0..2 {
                gp[c] += pd[j] * dn[j][c];
                gh[c] += hd[j] * dn[j][c];
            }
        }
        let v = [l[0] * vel[0][0] + l[1] * vel[1][0] + l[2] * vel[2][0], l[0] * vel[0][1] + l[1] * vel[1][1] + l[2] * vel[2][1]];
        let x = tri.point(l);
        let f = source.map_or(0.0, |s| s(x[0], x[1]));

        let (eta, deta) = (fluid.eta)(pq.v);
        let (rho, drho) = (fluid.rho)(pq.v);
        let eta_d = pq.chain(eta, deta);
        let rho_d = pq.chain(rho, drho);
        let h3 = hq * hq * hq;
        let eps = rho_d * h3 / (eta_d * fluid.lambda_bar);
        let rho_h = rho_d * hq;

        // Galerkin: eps grad P . grad N_i - rho H (v . grad N_i) - f N_i
        let v_dn: [f64; 6] = std::array::from_fn(|i| v[0] * dn[i][0] + v[1] * dn[i][1]);
        let vn = (v[0] * v[0] + v[1] * v[1]).sqrt();
        // d rho_bar/dP as a dual (built from rho''): needed by the artificial diffusion and SUPG.
        let diffusion = stab.id > 0.0 || stab.cd > 0.0;
        let drho_d = if diffusion || stab.supg { pq.chain(drho, (fluid.d2rho)(pq.v)) } else { D12::constant(0.0) };
        // Artificial diffusion coefficients factor * h_e |rho' H v| (isotropic, crosswind),
        // with their exact derivatives through the duals.
        let beta_he = if diffusion {
            let beta = drho_d * hq * vn;
            (if beta.v < 0.0 { -beta } else { beta }) * streamline_length(&tri, v)
        } else {
            D12::constant(0.0)
        };
        let eps_g = eps + beta_he * stab.id;
        let eps_c = beta_he * stab.cd;
        let crosswind = stab.cd > 0.0 && vn > 0.0;
        let (tx, tz) = if vn > 0.0 { (v[0] / vn, v[1] / vn) } else { (0.0, 0.0) };
        for i in 0..6 {
            let flux = gp[0] * dn[i][0] + gp[1] * dn[i][1];
            res[i] += (eps_g * flux - rho_h * v_dn[i] - f * n[i]) * wq;
            if crosswind {
                // crosswind only: grad P . grad N - (t . grad P)(t . grad N)
                let cw = flux - (gp[0] * tx + gp[1] * tz) * (dn[i][0] * tx + dn[i][1] * tz);
                res[i] += eps_c * cw * wq;
            }
        }

        if stab.supg {
            if vn == 0.0 || (stab.complementarity && pq.v <= 0.0) {
                continue; // the SUPG weight v . grad N_i vanishes, or the film cavitates
            }
            let gate = if stab.complementarity { super::cavitation::pressurised(pq) } else { D12::constant(1.0) };
            let mut pen = D12::constant(0.0);
            for j in 0..6 {
                pen += pen_nodes[j] * n[j];
            }
            if let (Some(g), Some(c)) = (multiplier, &cavitated) {
                for j in 0..6 {
                    pen -= c[j] * (g[j] * n[j]);
                }
            }
            let fields = PointFields {
                h: hq,
                grad_p: gp,
                grad_h: gh,
                rho: rho_d,
                drho: drho_d,
                eta: eta_d,
                deta: pq.chain(deta, (fluid.d2eta)(pq.v)),
                eps,
            };
            let r_strong = strong_residual(stab, &fields, fluid.lambda_bar, lap_p, v, div_v, pen) - f;

            // tau = delta h_e / (2|v|) xi(Pe), h_e = streamline length
            let tau = supg_tau(stab, vn, streamline_length(&tri, v), eps, drho_d, hq);
            let t_g = tau * gate * wq;
            let t_r = t_g * r_strong;
            for i in 0..6 {
                res[i] += t_r * v_dn[i];
            }
            if let Some(c) = &cavitated {
                for i in 0..6 {
                    for j in 0..6 {
                        dr_dm[i][j] -= t_g.v * v_dn[i] * c[j].v * n[j];
                    }
                }
            }
        }
    }

    let mut out = ElementOut { r: [0.0; 6], dr_dp: [[0.0; 6]; 6], dr_dh: [[0.0; 6]; 6], dr_dm };
    for i in 0..6 {
        out.r[i] = res[i].v;
        out.dr_dp[i].copy_from_slice(&res[i].d[..6]);
        out.dr_dh[i].copy_from_slice(&res[i].d[6..]);
    }
    out
}
