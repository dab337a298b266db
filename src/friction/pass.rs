//! The friction pass (docs/model.md section 7): on the converged pressure and film, the shear
//! stress on the disc surface at every point of the Reynolds rectangle Omega_c, from the
//! per-point law of [`super::shear`], and its integrals, the traction forces on the disc
//! Fx, Fz and the friction coefficients fx = Fx/L, fz = Fz/L.
//!
//! The pressure is P2 on each contact triangle; its gradient is taken inside the element
//! (discontinuous across edges, as the shear stress of the paper's P2 solution is). The
//! integrals cover every triangle of Omega_c (the cavitated zone included: the model has no
//! film-fraction, so the full film is sheared there; its share is small because the
//! viscosity is low and the film thick) with the degree-6 Dunavant rule, adapted per
//! triangle ([`adapted_rules`]): where the rule on a triangle and on its four quarters
//! disagree, each quarter is treated the same way. Inside a triangle P, H and grad P are
//! polynomials but the stress need not be smooth: under spin the sliding velocity vanishes
//! at a point of the contact, and the stress turns around it at a magnitude near
//! tau0 ln(eta |slide| / (h tau0)). A fixed rule's error on the triangle holding that point
//! is of the order of its area, with a sign that depends on where the point falls
//! (docs/model.md section 7).
use super::shear::{disc_shear_stress, film_slide, FilmPoint, ShearLaw};
use crate::error::Error;
use crate::fem::geometry::AffineTri;
use crate::fem::p2tri::{p2_tri_eval, p2_tri_eval_grad};
use crate::mesh::spec::Rect;
use crate::mesh::Mesh;
use crate::physics::Kinematics;

/// The converged solution on the contact face as the friction pass reads it
/// (dimensionless): nodal pressure and film, and where a point lies.
pub trait FaceSolution {
    /// The mesh whose contact face carries the solution.
    fn mesh(&self) -> &Mesh;
    /// Nodal pressure P (0 on the Dirichlet edges).
    fn p_node(&self, n: u32) -> f64;
    /// Nodal film H.
    fn h_node(&self, n: u32) -> f64;
    /// Whether the mesh is the half domain z <= 0 of a symmetric scene.
    fn half(&self) -> bool;
    /// The contact triangle containing (x, z) and the point's barycentric coordinates (on a
    /// half domain, of the mirror image of a point z > 0).
    fn locate(&self, x: f64, z: f64) -> Option<(usize, [f64; 3])>;
}

/// How the pass's triangles are shared out between processes: which ones this process
/// evaluates, and every process's results gathered on every process. Each triangle's
/// values are computed by one process and every sum runs in triangle order on every
/// process, so the result does not depend on how the triangles were shared.
pub trait Share {
    /// Whether item `k` (a triangle of the pass, in its order) is this process's.
    fn mine(&self, k: usize) -> bool;
    /// Every process's `local` values, concatenated in process order, on every process;
    /// an error on every process when one of them failed (none is left waiting).
    fn gather(&self, local: Result<Vec<f64>, Error>) -> Result<Vec<f64>, Error>;
}

/// Every triangle on this process alone.
pub struct Alone;

impl Share for Alone {
    fn mine(&self, _k: usize) -> bool {
        true
    }
    fn gather(&self, local: Result<Vec<f64>, Error>) -> Result<Vec<f64>, Error> {
        local
    }
}

/// `f(k)` for every item k < `n` this process holds, and every item's values on every
/// process, in item order.
fn shared(share: &dyn Share, n: usize, mut f: impl FnMut(usize) -> Result<Vec<f64>, Error>) -> Result<Vec<Vec<f64>>, Error> {
    let mut local = || -> Result<Vec<f64>, Error> {
        let mut out = Vec::new();
        for k in (0..n).filter(|&k| share.mine(k)) {
            let v = f(k)?;
            out.extend([k as f64, v.len() as f64]);
            out.extend(v);
        }
        Ok(out)
    };
    let all = share.gather(local())?;
    let mut items: Vec<Option<Vec<f64>>> = vec![None; n];
    for (k, v) in records(&all) {
        items[k] = Some(v.to_vec());
    }
    items.into_iter().map(|v| v.ok_or_else(|| Error::other("friction pass: a triangle no process evaluated"))).collect()
}

/// The records of a gathered [`shared`] buffer: each item's index and its values (the
/// buffer holds k, the number of values, then the values, item after item).
fn records(all: &[f64]) -> Vec<(usize, &[f64])> {
    let mut out = Vec::new();
    let mut i = 0;
    while i + 1 < all.len() {
        let (k, len) = (all[i] as usize, all[i + 1] as usize);
        out.push((k, &all[i + 2..i + 2 + len]));
        i += 2 + len;
    }
    out
}

/// What the pass needs besides the fields: the shear law, the viscosity law, the surface
/// velocities and the scales that turn the dimensionless fields into SI units.
pub struct FrictionSetup {
    pub law: ShearLaw,
    /// eta(p) in Pa.s for p in Pa.
    pub eta: Box<dyn Fn(f64) -> f64>,
    pub kinematics: Kinematics,
    /// Hertz radius a (m), Hertz pressure p_H (Pa), film scale a^2/R (m).
    pub a: f64,
    pub ph: f64,
    pub hs: f64,
    /// The Reynolds rectangle Omega_c (units of a).
    pub rect: Rect,
    /// Normal load L (N) for the friction coefficients.
    pub load: f64,
}

/// Result of the friction pass.
#[derive(Debug, Clone)]
pub struct FrictionResult {
    /// Traction forces on the disc (N), over the whole Reynolds rectangle (a half-domain
    /// solve is mirrored).
    pub fx_n: f64,
    pub fz_n: f64,
    /// Friction coefficients Fx/L, Fz/L.
    pub fx: f64,
    pub fz: f64,
    /// Shear stress on the disc (tau_yx, tau_yz at y = 0, Pa) at the 6 P2 nodes of every
    /// contact triangle inside Omega_c: (triangle index, values).
    pub nodal: Vec<(usize, [[f64; 2]; 6])>,
    /// Largest |tau| on the disc at the nodes (Pa).
    pub tau_max: f64,
    /// The adapted rule: triangles of Omega_c, those subdivided, and the stress
    /// evaluations it took.
    pub quadrature: QuadratureReport,
    /// fx and fz by the fixed 12-point rule on every triangle, for comparison.
    pub fixed_rule: [f64; 2],
    /// The adapted rule's points, which [`friction_gradient`] differentiates.
    pub rules: QuadratureRules,
    /// Wall time (s).
    pub seconds: f64,
}

/// Whether contact triangle `t` lies in Omega_c (its centroid does).
fn in_rect(fields: &dyn FaceSolution, t: usize, r: &Rect) -> bool {
    let tri = fields.mesh().contact_tris[t];
    let (mut x, mut z) = (0.0, 0.0);
    for &n in &tri[..3] {
        let c = fields.mesh().nodes[n as usize];
        x += c[0] / 3.0;
        z += c[2] / 3.0;
    }
    x > r.x0 && x < r.x1 && z > r.z0 && z < r.z1
}

/// The data of one contact triangle the stress evaluation needs: vertices (units of a),
/// barycentric gradients, nodal P and H. Built once per triangle.
struct TriFields {
    v: [[f64; 2]; 3],
    geo: AffineTri,
    p: [f64; 6],
    h: [f64; 6],
}

impl TriFields {
    fn new(fields: &dyn FaceSolution, t: usize) -> Self {
        let mesh = fields.mesh();
        let tri = mesh.contact_tris[t];
        let v: [[f64; 2]; 3] = std::array::from_fn(|i| {
            let c = mesh.nodes[tri[i] as usize];
            [c[0], c[2]]
        });
        TriFields { v, geo: AffineTri::new(&v), p: tri.map(|n| fields.p_node(n)), h: tri.map(|n| fields.h_node(n)) }
    }

    /// What the shear stress at barycentric point `b` depends on: the P2 pressure, film and
    /// pressure gradient (dimensionless) and the point (units of a).
    fn inputs(&self, b: [f64; 3]) -> PointInputs {
        let (v, p, h) = (&self.v, &self.p, &self.h);
        let g = p2_tri_eval_grad(p, b, &self.geo.grad_bary);
        let (x, z) = ((0..3).map(|i| b[i] * v[i][0]).sum::<f64>(), (0..3).map(|i| b[i] * v[i][1]).sum::<f64>());
        PointInputs { v: [p2_tri_eval(p, b), p2_tri_eval(h, b), g[0], g[1]], at: [x, z] }
    }

    /// The shear stress on the disc at barycentric point `b` (Pa).
    fn stress(&self, s: &FrictionSetup, b: [f64; 3]) -> Result<[f64; 2], Error> {
        self.inputs(b).stress(s)
    }
}

/// The dimensionless P, H, dP/dX, dP/dZ at a point (X, Z) of a contact triangle.
#[derive(Clone, Copy)]
struct PointInputs {
    v: [f64; 4],
    at: [f64; 2],
}

impl PointInputs {
    /// The film at the point in SI units, as the shear law reads it.
    fn film_point(&self, s: &FrictionSetup) -> FilmPoint {
        let ([pv, hv, gx, gz], [x, z]) = (self.v, self.at);
        let vel = s.kinematics.at(x * s.a, z * s.a);
        // The film's pressure is non-negative; the P2 interpolant's small undershoot at the
        // cavitation boundary is not a physical tension: the viscosity sees max(p, 0).
        let pa = pv.max(0.0) * s.ph;
        FilmPoint { eta: (s.eta)(pa), h: hv * s.hs, grad_p: [gx * s.ph / s.a, gz * s.ph / s.a], slide: [vel.du(), vel.dw()] }
    }

    fn error(&self, e: impl std::fmt::Display) -> Error {
        Error::numerical(format!("friction pass at (x, z) = ({:.4}a, {:.4}a): {e}", self.at[0], self.at[1]))
    }

    /// The shear stress on the disc (Pa).
    fn stress(&self, s: &FrictionSetup) -> Result<[f64; 2], Error> {
        disc_shear_stress(&s.law, &self.film_point(s)).map_err(|e| self.error(e))
    }

    /// d(stress)/d(P, H, dP/dX, dP/dZ) (Pa per unit of each), by implicit differentiation of
    /// the no-slip constraint G(t0; P, H, grad P) = slide (the slide depends on the place
    /// only): dt0/dv = -(dG/dt0)^-1 dG/dv, with dG/dt0 exact from the shear law and dG/dv a
    /// central difference of G at fixed t0 (the shear law's integrals, no Newton solve per
    /// difference: the gradient costs 3.6 passes). A relative step of 1e-6 keeps
    /// the difference's error near 1e-10; the viscosity's kink at P = 0 lies where the film is
    /// thick and the stress small.
    fn stress_derivatives(&self, s: &FrictionSetup) -> Result<[[f64; 2]; 4], Error> {
        let t0 = self.stress(s)?;
        let j = film_slide(&s.law, &self.film_point(s), t0).map_err(|e| self.error(e))?.jacobian;
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        let mut d = [[0.0; 2]; 4];
        // Floors: P and its gradient are O(1) in the Hertz zone; H is never 0.
        const FLOOR: [f64; 4] = [1e-3, 0.0, 1e-3, 1e-3];
        for k in 0..4 {
            let step = 1e-6 * self.v[k].abs().max(FLOOR[k]);
            let (mut up, mut down) = (*self, *self);
            up.v[k] += step;
            down.v[k] -= step;
            let g = |p: &PointInputs| film_slide(&s.law, &p.film_point(s), t0).map(|f| f.slide).map_err(|e| self.error(e));
            let (a, b) = (g(&up)?, g(&down)?);
            let dg = [(a[0] - b[0]) / (2.0 * step), (a[1] - b[1]) / (2.0 * step)];
            d[k] = [-(j[1][1] * dg[0] - j[0][1] * dg[1]) / det, -(-j[1][0] * dg[0] + j[0][0] * dg[1]) / det];
        }
        Ok(d)
    }
}

/// The derivatives of the friction coefficients with respect to the nodal solution: for each
/// contact node touched by Omega_c, (node, dfx/dP, dfx/dH, dfz/dP, dfz/dH), nodes ascending.
/// The goal-oriented marking weights the discretisation error by them (the adjoint of fx
/// and fz), as it does for the films.
pub struct FrictionGradient {
    pub nodes: Vec<(u32, [f64; 4])>,
}

/// The derivatives of [`friction_pass`]'s fx and fz with respect to the nodal P and H, by
/// the chain rule through the P2 interpolation of P, H and grad P at each point of the
/// pass's adapted rule `rules` (the pass's on the same `fields`), held fixed; the triangles
/// shared out by `share`.
pub fn friction_gradient(
    fields: &dyn FaceSolution,
    s: &FrictionSetup,
    rules: &QuadratureRules,
    share: &dyn Share,
) -> Result<FrictionGradient, Error> {
    use crate::fem::p2tri::{p2_tri_basis_bary, p2_tri_grads_bary};
    let mesh = fields.mesh();
    // A half domain doubles Fx and cancels Fz (friction_pass).
    let (cx, cz) = if fields.half() { (2.0, 0.0) } else { (1.0, 1.0) };
    // Each triangle's share: (dfx/dP, dfx/dH, dfz/dP, dfz/dH) at its 6 nodes.
    let per_triangle = shared(share, rules.0.len(), |k| {
        let (t, rule) = &rules.0[k];
        let tf = TriFields::new(fields, *t);
        let area = crate::fem::p2tri::tri_area(&tf.v) * s.a * s.a;
        let mut e = vec![0.0; 24];
        for q in rule {
            let d = tf.inputs(q.l).stress_derivatives(s)?;
            let (n, dn) = (p2_tri_basis_bary(q.l), p2_tri_grads_bary(q.l, &tf.geo.grad_bary));
            let w = q.w * area / s.load;
            for i in 0..6 {
                for (c, scale) in [(0, cx), (1, cz)] {
                    // dtau/dP_i = dtau/dP N_i + dtau/dgrad P . grad N_i; dtau/dH_i = dtau/dH N_i.
                    e[4 * i + 2 * c] += scale * w * (d[0][c] * n[i] + d[2][c] * dn[i][0] + d[3][c] * dn[i][1]);
                    e[4 * i + 2 * c + 1] += scale * w * d[1][c] * n[i];
                }
            }
        }
        Ok(e)
    })?;
    let mut acc: std::collections::BTreeMap<u32, [f64; 4]> = std::collections::BTreeMap::new();
    for ((t, _), e) in rules.0.iter().zip(&per_triangle) {
        for (i, &node) in mesh.contact_tris[*t].iter().enumerate() {
            let a = acc.entry(node).or_insert([0.0; 4]);
            for c in 0..4 {
                a[c] += e[4 * i + c];
            }
        }
    }
    Ok(FrictionGradient { nodes: acc.into_iter().collect() })
}

/// Largest error of Fx and Fz the adapted rule aims at, as a fraction of the friction
/// force's magnitude (docs/model.md section 7): far below the changes between adaptive
/// levels that the estimate reads (0.1 % at a quarter of a 0.01 target).
const QUADRATURE_TOL: f64 = 1e-4;
/// Deepest subdivision: parts of 1/32 of a triangle's size (0.0078 a in a 0.25 a triangle).
const MAX_DEPTH: usize = 5;
/// The magnitude the tolerance is relative to never falls below this fraction of the sum
/// of the triangles' |contributions|: without sliding or spin the stresses cancel over the
/// contact and the force is small against them.
const CANCELLATION_FLOOR: f64 = 1e-2;

/// One point of a contact triangle's adapted rule: barycentric coordinates in the triangle
/// and the weight as a fraction of its area.
#[derive(Clone, Copy, Debug, PartialEq)]
struct RulePoint {
    l: [f64; 3],
    w: f64,
}

/// The adapted rule of every contact triangle of Omega_c: (triangle, its points).
#[derive(Clone, Debug)]
pub struct QuadratureRules(Vec<(usize, Vec<RulePoint>)>);

/// The adapted rules, the forces (Fx, Fz) they give on the solved domain (N), and what they
/// took.
struct AdaptedRules {
    rules: QuadratureRules,
    force: [f64; 2],
    report: QuadratureReport,
}

/// What the adapted rule took on one pass.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct QuadratureReport {
    /// Triangles of Omega_c.
    pub triangles: usize,
    /// Those whose rule was subdivided at least once.
    pub subdivided: usize,
    /// Stress evaluations of the adaptation (the fixed rule takes 12 per triangle).
    pub evaluations: usize,
    /// The forces (Fx, Fz) of the fixed rule on every triangle, on the solved domain (N):
    /// how much the adaptation moved them.
    pub fixed: [f64; 2],
}

/// The Dunavant points of the sub-triangle with vertices `v` (barycentric coordinates in
/// the contact triangle) that covers the fraction `frac` of it.
fn sub_points(v: &[[f64; 3]; 3], frac: f64) -> [RulePoint; 12] {
    std::array::from_fn(|k| {
        let q = &crate::fem::quadrature::DUNAVANT6[k];
        RulePoint { l: std::array::from_fn(|i| q.l[0] * v[0][i] + q.l[1] * v[1][i] + q.l[2] * v[2][i]), w: q.w * frac }
    })
}

/// The four sub-triangles of `v` cut at its edges' midpoints.
fn quarters(v: &[[f64; 3]; 3]) -> [[[f64; 3]; 3]; 4] {
    let mid = |a: usize, b: usize| -> [f64; 3] { std::array::from_fn(|i| 0.5 * (v[a][i] + v[b][i])) };
    let (m01, m12, m20) = (mid(0, 1), mid(1, 2), mid(2, 0));
    [[v[0], m01, m20], [m01, v[1], m12], [m20, m12, v[2]], [m12, m20, m01]]
}

const WHOLE: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// A triangle's rule being adapted: its fields, its area (m^2) and what it has taken so far.
struct Adapting<'a> {
    tf: &'a TriFields,
    s: &'a FrictionSetup,
    area: f64,
    points: Vec<RulePoint>,
    evaluations: usize,
}

impl Adapting<'_> {
    /// The force (N) of `pts` on the triangle.
    fn force(&mut self, pts: &[RulePoint]) -> Result<[f64; 2], Error> {
        let mut f = [0.0; 2];
        for q in pts {
            let tau = self.tf.stress(self.s, q.l)?;
            f[0] += q.w * self.area * tau[0];
            f[1] += q.w * self.area * tau[1];
        }
        self.evaluations += pts.len();
        Ok(f)
    }

    /// Takes the sub-triangle `v` (fraction `frac` of the triangle, force `coarse` by its own
    /// rule): when the rule on its four quarters agrees with `coarse` within `tol` (N), or
    /// at `depth` MAX_DEPTH, its own rule is kept; otherwise each quarter is taken the same
    /// way with a quarter of the tolerance. Returns the force of the points kept.
    fn take(&mut self, v: &[[f64; 3]; 3], frac: f64, coarse: [f64; 2], tol: f64, depth: usize) -> Result<[f64; 2], Error> {
        if depth >= MAX_DEPTH {
            self.points.extend(sub_points(v, frac));
            return Ok(coarse);
        }
        let kids = quarters(v);
        let mut parts = [[0.0; 2]; 4];
        for (k, kid) in kids.iter().enumerate() {
            parts[k] = self.force(&sub_points(kid, frac / 4.0))?;
        }
        let fine = [parts.iter().map(|p| p[0]).sum::<f64>(), parts.iter().map(|p| p[1]).sum::<f64>()];
        if (fine[0] - coarse[0]).abs().max((fine[1] - coarse[1]).abs()) <= tol {
            // The coarse rule's error is about the difference: the quarters' is smaller by
            // 2^7 where the stress is smooth, and the gradient then needs a quarter of the
            // points.
            self.points.extend(sub_points(v, frac));
            return Ok(coarse);
        }
        let mut f = [0.0; 2];
        for (kid, part) in kids.iter().zip(parts) {
            let g = self.take(kid, frac / 4.0, part, tol / 4.0, depth + 1)?;
            f[0] += g[0];
            f[1] += g[1];
        }
        Ok(f)
    }
}

/// The adapted rule of every contact triangle of Omega_c. The tolerance of a triangle is
/// its share by area of QUADRATURE_TOL times the force's magnitude by the fixed rule, so
/// that the errors add up to about QUADRATURE_TOL of it (a triangle's error is estimated
/// by the difference between its rule and its quarters', a sub-triangle's error in turn by
/// its own quarters). The same rule serves the pass and its gradient, which therefore is
/// the derivative of the value the pass reports.
fn adapted_rules(fields: &dyn FaceSolution, s: &FrictionSetup, share: &dyn Share) -> Result<AdaptedRules, Error> {
    let mesh = fields.mesh();
    let tris: Vec<usize> = (0..mesh.contact_tris.len()).filter(|&t| in_rect(fields, t, &s.rect)).collect();
    // The fixed rule on every triangle: the coarse value each adaptation starts from, and
    // the scale of the tolerance; with the triangle's area (m^2).
    let fixed = shared(share, tris.len(), |k| {
        let tf = TriFields::new(fields, tris[k]);
        let area = crate::fem::p2tri::tri_area(&tf.v) * s.a * s.a;
        let mut a = Adapting { tf: &tf, s, area, points: Vec::new(), evaluations: 0 };
        let f = a.force(&sub_points(&WHOLE, 1.0))?;
        Ok(vec![f[0], f[1], area])
    })?;
    let areas: Vec<f64> = fixed.iter().map(|f| f[2]).collect();
    let mut report = QuadratureReport { triangles: tris.len(), evaluations: 12 * tris.len(), ..Default::default() };
    let (mut total, mut area_total, mut absolute) = ([0.0; 2], 0.0, 0.0);
    for (f, area) in fixed.iter().zip(&areas) {
        total[0] += f[0];
        total[1] += f[1];
        area_total += area;
        absolute += f[0].hypot(f[1]);
    }
    report.fixed = total;
    let scale = total[0].hypot(total[1]).max(CANCELLATION_FLOOR * absolute);
    // Each triangle's adapted rule: its force, its evaluations, then its points (l, w).
    let adapted = shared(share, tris.len(), |k| {
        let tf = TriFields::new(fields, tris[k]);
        let area = areas[k];
        let mut a = Adapting { tf: &tf, s, area, points: Vec::new(), evaluations: 0 };
        let tol = QUADRATURE_TOL * scale * area / area_total;
        let f = a.take(&WHOLE, 1.0, [fixed[k][0], fixed[k][1]], tol, 0)?;
        let mut v = vec![f[0], f[1], a.evaluations as f64];
        v.extend(a.points.iter().flat_map(|q| [q.l[0], q.l[1], q.l[2], q.w]));
        Ok(v)
    })?;
    let mut rules = Vec::with_capacity(tris.len());
    let mut force = [0.0; 2];
    for (&t, v) in tris.iter().zip(&adapted) {
        force[0] += v[0];
        force[1] += v[1];
        report.evaluations += v[2] as usize;
        let points: Vec<RulePoint> = v[3..].chunks_exact(4).map(|q| RulePoint { l: [q[0], q[1], q[2]], w: q[3] }).collect();
        report.subdivided += usize::from(points.len() > 12);
        rules.push((t, points));
    }
    Ok(AdaptedRules { rules: QuadratureRules(rules), force, report })
}

/// Runs the pass over Omega_c, the triangles shared out by `share` (collective when the
/// share spans processes).
pub fn friction_pass(fields: &dyn FaceSolution, s: &FrictionSetup, share: &dyn Share) -> Result<FrictionResult, Error> {
    let t0 = std::time::Instant::now();
    let AdaptedRules { rules, force, report: quadrature } = adapted_rules(fields, s, share)?;
    const NODES: [[f64; 3]; 6] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]];
    let values = shared(share, rules.0.len(), |k| {
        let tf = TriFields::new(fields, rules.0[k].0);
        let mut v = Vec::with_capacity(12);
        for b in &NODES {
            v.extend(tf.stress(s, *b)?);
        }
        Ok(v)
    })?;
    let mut tau_max = 0.0f64;
    let mut nodal = Vec::with_capacity(rules.0.len());
    for ((t, _), v) in rules.0.iter().zip(&values) {
        let vals: [[f64; 2]; 6] = std::array::from_fn(|k| [v[2 * k], v[2 * k + 1]]);
        for x in &vals {
            tau_max = tau_max.max(x[0].hypot(x[1]));
        }
        nodal.push((*t, vals));
    }
    // Half domain of a symmetric scene: tau_yx is even in z and tau_yz odd, so the mirror
    // half doubles Fx and cancels Fz exactly.
    let whole = |f: [f64; 2]| if fields.half() { [2.0 * f[0], 0.0] } else { f };
    let ([fx_n, fz_n], fixed) = (whole(force), whole(quadrature.fixed));
    Ok(FrictionResult {
        fx_n,
        fz_n,
        fx: fx_n / s.load,
        fz: fz_n / s.load,
        nodal,
        tau_max,
        quadrature,
        fixed_rule: [fixed[0] / s.load, fixed[1] / s.load],
        rules,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// The shear stress on the disc at (x, z) (units of a), or None outside the contact face.
/// On a half domain a point z > 0 takes its mirror image's stress with tau_yz negated.
pub fn stress_at(fields: &dyn FaceSolution, s: &FrictionSetup, x: f64, z: f64) -> Option<Result<[f64; 2], Error>> {
    let (t, b) = fields.locate(x, z)?;
    let mirrored = fields.half() && z > 0.0;
    Some(TriFields::new(fields, t).stress(s, b).map(|v| if mirrored { [v[0], -v[1]] } else { v }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::spec::MeshSpec;

    /// A smooth Hertz-like pressure and film on a coarse mesh's contact face.
    struct Smooth {
        mesh: Mesh,
        p: Vec<f64>,
        h: Vec<f64>,
    }

    impl FaceSolution for Smooth {
        fn mesh(&self) -> &Mesh {
            &self.mesh
        }
        fn p_node(&self, n: u32) -> f64 {
            self.p[n as usize]
        }
        fn h_node(&self, n: u32) -> f64 {
            self.h[n as usize]
        }
        fn half(&self) -> bool {
            false
        }
        fn locate(&self, x: f64, z: f64) -> Option<(usize, [f64; 3])> {
            self.mesh.locate_contact(x, z)
        }
    }

    fn fields() -> Smooth {
        let mut spec = MeshSpec::paper_default();
        spec.contact_size = 0.5;
        let mesh = crate::mesh::generate(&spec).unwrap();
        let p = mesh.nodes.iter().map(|c| (-(c[0] * c[0] + c[2] * c[2])).exp() * (1.0 + 0.2 * c[0])).collect();
        let h = mesh.nodes.iter().map(|c| 0.4 + 0.1 * (c[0] * c[0] + c[2] * c[2]) + 0.05 * c[2]).collect();
        Smooth { mesh, p, h }
    }

    /// A Ree-Eyring film under spin and 5 % slide (cases/hard/spin-0.5deg's kinematics),
    /// its viscosity rising by e^25 over the pressure. The sliding velocity vanishes at
    /// (0, -0.17 a), inside the pressurised zone: around that point the stress on the disc
    /// turns with the sliding velocity at a magnitude near tau0 ln(eta |slide| / (h tau0)),
    /// bounded but with no direction at the point itself.
    fn steep_setup(rect: Rect) -> FrictionSetup {
        FrictionSetup {
            law: ShearLaw::ReeEyring { tau0: 5e6 },
            eta: Box::new(|p: f64| 0.01 * (2.5e-8 * p).exp()),
            kinematics: crate::physics::Kinematics::new(3.0, 0.05, 0.5f64.to_radians(), 0.08, 0.04).unwrap(),
            a: 2e-4,
            ph: 1e9,
            hs: 1e-6,
            rect,
            load: 100.0,
        }
    }

    /// The forces by the fixed rule on every triangle cut into 4^depth equal parts.
    fn uniform_forces(f: &dyn FaceSolution, s: &FrictionSetup, depth: usize) -> [f64; 2] {
        let mut parts = vec![WHOLE];
        for _ in 0..depth {
            parts = parts.iter().flat_map(quarters).collect();
        }
        let frac = 0.25f64.powi(depth as i32);
        let mut total = [0.0; 2];
        for t in (0..f.mesh().contact_tris.len()).filter(|&t| in_rect(f, t, &s.rect)) {
            let tf = TriFields::new(f, t);
            let area = crate::fem::p2tri::tri_area(&tf.v) * s.a * s.a;
            let mut a = Adapting { tf: &tf, s, area, points: Vec::new(), evaluations: 0 };
            for v in &parts {
                let g = a.force(&sub_points(v, frac)).unwrap();
                total[0] += g[0];
                total[1] += g[1];
            }
        }
        total
    }

    /// Where the stress turns around the slide's zero inside a triangle, the adapted rule
    /// lands within its tolerance of a brute-force reference (every triangle cut into 256
    /// parts: the fixed rule's error shrinks by about 4.5 per cut there, so the reference is
    /// within 0.01 % of the integral), and the fixed rule alone does not: the test can fail.
    #[test]
    fn the_adapted_rule_integrates_the_turn_of_the_stress_that_the_fixed_rule_misses() {
        let f = fields();
        let s = steep_setup(Rect { x0: -1.5, x1: 1.5, z0: -1.5, z1: 1.5 });
        let reference = uniform_forces(&f, &s, 4);
        let AdaptedRules { rules, force: adapted, report } = adapted_rules(&f, &s, &Alone).unwrap();
        let magnitude = reference[0].hypot(reference[1]);
        let off = |v: [f64; 2]| (v[0] - reference[0]).abs().max((v[1] - reference[1]).abs()) / magnitude;
        assert!(off(report.fixed) > 2e-3, "the fixed rule is off by {:.2e} only", off(report.fixed));
        assert!(off(adapted) < 3e-4, "the adapted rule is off by {:.2e}", off(adapted));
        // Only the triangles where the stress turns or rises steeply are subdivided.
        assert!(report.subdivided > 0 && report.subdivided < report.triangles / 2, "{report:?}");
        // Every rule covers its triangle: the weights sum to 1.
        for (_, rule) in &rules.0 {
            assert!((rule.iter().map(|q| q.w).sum::<f64>() - 1.0).abs() < 1e-12);
        }
    }

    /// Where the stress is smooth (constant viscosity, a Newtonian-like film), the rule is
    /// the fixed one: no triangle is subdivided and the forces are the fixed rule's.
    #[test]
    fn a_smooth_stress_keeps_the_fixed_rule() {
        let f = fields();
        let mut s = steep_setup(Rect { x0: -1.5, x1: 1.5, z0: -1.5, z1: 1.5 });
        s.eta = Box::new(|_| 0.01);
        let AdaptedRules { force: adapted, report, .. } = adapted_rules(&f, &s, &Alone).unwrap();
        assert_eq!(report.subdivided, 0, "{report:?}");
        assert_eq!(adapted, report.fixed);
    }

    /// Shared out over processes, the pass gets each triangle's values back in another order:
    /// the forces, the nodal stresses and the gradient must be the same to the bit.
    #[test]
    fn the_pass_does_not_depend_on_the_order_its_triangles_come_back_in() {
        /// Every triangle here, its records gathered back in reverse order, as another
        /// process's would come interleaved.
        struct Reversed;
        impl Share for Reversed {
            fn mine(&self, _k: usize) -> bool {
                true
            }
            fn gather(&self, local: Result<Vec<f64>, Error>) -> Result<Vec<f64>, Error> {
                let v = local?;
                Ok(super::records(&v)
                    .into_iter()
                    .rev()
                    .flat_map(|(k, r)| [k as f64, r.len() as f64].into_iter().chain(r.iter().copied()))
                    .collect())
            }
        }
        let f = fields();
        let s = steep_setup(Rect { x0: -3.0, x1: 3.0, z0: -3.0, z1: 3.0 });
        let (a, b) = (friction_pass(&f, &s, &Alone).unwrap(), friction_pass(&f, &s, &Reversed).unwrap());
        assert_eq!([a.fx, a.fz, a.tau_max], [b.fx, b.fz, b.tau_max]);
        assert_eq!(a.nodal.len(), b.nodal.len());
        assert!(a.nodal.iter().zip(&b.nodal).all(|(x, y)| x == y));
        let (ga, gb) = (friction_gradient(&f, &s, &a.rules, &Alone).unwrap(), friction_gradient(&f, &s, &b.rules, &Reversed).unwrap());
        assert_eq!(ga.nodes, gb.nodes);
    }

    /// fx and fz of the pass, differenced in one nodal value, against the gradient: the chain
    /// rule through the P2 interpolation and the per-point differences, checked end to end on
    /// a spinning, sliding Ree-Eyring film (both stress components non-zero).
    #[test]
    fn the_friction_gradient_is_the_derivative_of_the_friction_pass() {
        let mut f = fields();
        let eta = |p: f64| 0.01 * (1e-8 * p).exp();
        let kin = crate::physics::Kinematics::new(2.0, 0.5, 60f64.to_radians(), 0.01, 0.04).unwrap();
        let s = FrictionSetup {
            law: ShearLaw::ReeEyring { tau0: 5e6 },
            eta: Box::new(eta),
            kinematics: kin,
            a: 2e-4,
            ph: 1e9,
            hs: 1e-6,
            rect: Rect { x0: -3.0, x1: 3.0, z0: -3.0, z1: 3.0 },
            load: 100.0,
        };
        let grad = friction_gradient(&f, &s, &friction_pass(&f, &s, &Alone).unwrap().rules, &Alone).unwrap();
        let scale = grad.nodes.iter().flat_map(|(_, g)| g.iter()).fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(scale > 0.0);
        // Nodes inside the Hertz circle and next to it, vertices and midpoints.
        let picks: Vec<(u32, [f64; 4])> = grad
            .nodes
            .iter()
            .filter(|(n, _)| f.mesh.nodes[*n as usize][0].hypot(f.mesh.nodes[*n as usize][2]) < 1.3)
            .step_by(7)
            .cloned()
            .collect();
        assert!(picks.len() >= 5);
        for (n, g) in picks {
            for (k, field) in [(0, 'p'), (1, 'h')] {
                let step = 1e-5;
                let mut at = |d: f64| {
                    let v = if field == 'p' { &mut f.p } else { &mut f.h };
                    v[n as usize] += d;
                    let r = friction_pass(&f, &s, &Alone).unwrap();
                    let v = if field == 'p' { &mut f.p } else { &mut f.h };
                    v[n as usize] -= d;
                    [r.fx, r.fz]
                };
                let (up, down) = (at(step), at(-step));
                for c in 0..2 {
                    let fd = (up[c] - down[c]) / (2.0 * step);
                    // Both differences are O(1e-10) of the largest derivative.
                    assert!((fd - g[2 * c + k]).abs() < 1e-6 * scale, "node {n}, d{}/d{field}: {fd} vs {}", ["fx", "fz"][c], g[2 * c + k]);
                }
            }
        }
    }
}
