//! The friction pass (docs/model.md section 7): on the converged pressure and film, the shear
//! stress on the disc surface at every point of the Reynolds rectangle Omega_c, from the
//! per-point law of [`super::shear`], and its integrals, the traction forces on the disc
//! Fx, Fz and the friction coefficients fx = Fx/L, fz = Fz/L.
//!
//! The pressure is P2 on each contact triangle; its gradient is taken inside the element
//! (discontinuous across edges, as the shear stress of the paper's P2 solution is). The
//! integrals use the degree-6 Dunavant rule on every triangle of Omega_c (the cavitated
//! zone included: the model has no film-fraction, so the full film is sheared there; its
//! share is small because the viscosity is low and the film thick).
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
/// the chain rule through the P2 interpolation of P, H and grad P at each quadrature point
/// (serial, the same on every rank).
pub fn friction_gradient(fields: &dyn FaceSolution, s: &FrictionSetup) -> Result<FrictionGradient, Error> {
    use crate::fem::p2tri::{p2_tri_basis_bary, p2_tri_grads_bary};
    let mesh = fields.mesh();
    let mut acc: std::collections::BTreeMap<u32, [f64; 4]> = std::collections::BTreeMap::new();
    // A half domain doubles Fx and cancels Fz (friction_pass).
    let (cx, cz) = if fields.half() { (2.0, 0.0) } else { (1.0, 1.0) };
    for t in 0..mesh.contact_tris.len() {
        if !in_rect(fields, t, &s.rect) {
            continue;
        }
        let tf = TriFields::new(fields, t);
        let area = crate::fem::p2tri::tri_area(&tf.v) * s.a * s.a;
        let nodes = mesh.contact_tris[t];
        for q in crate::fem::quadrature::DUNAVANT6.iter() {
            let d = tf.inputs(q.l).stress_derivatives(s)?;
            let (n, dn) = (p2_tri_basis_bary(q.l), p2_tri_grads_bary(q.l, &tf.geo.grad_bary));
            let w = q.w * area / s.load;
            for i in 0..6 {
                let e = acc.entry(nodes[i]).or_insert([0.0; 4]);
                for (c, scale) in [(0, cx), (1, cz)] {
                    // dtau/dP_i = dtau/dP N_i + dtau/dgrad P . grad N_i; dtau/dH_i = dtau/dH N_i.
                    e[2 * c] += scale * w * (d[0][c] * n[i] + d[2][c] * dn[i][0] + d[3][c] * dn[i][1]);
                    e[2 * c + 1] += scale * w * d[1][c] * n[i];
                }
            }
        }
    }
    Ok(FrictionGradient { nodes: acc.into_iter().collect() })
}

/// Runs the pass over Omega_c (serial; call it on one rank).
pub fn friction_pass(fields: &dyn FaceSolution, s: &FrictionSetup) -> Result<FrictionResult, Error> {
    let t0 = std::time::Instant::now();
    let mesh = fields.mesh();
    let (mut fx_n, mut fz_n, mut tau_max) = (0.0, 0.0, 0.0f64);
    let mut nodal = Vec::new();
    const NODES: [[f64; 3]; 6] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]];
    for t in 0..mesh.contact_tris.len() {
        if !in_rect(fields, t, &s.rect) {
            continue;
        }
        let tf = TriFields::new(fields, t);
        let area = crate::fem::p2tri::tri_area(&tf.v) * s.a * s.a;
        for q in crate::fem::quadrature::DUNAVANT6.iter() {
            let tau = tf.stress(s, q.l)?;
            fx_n += q.w * area * tau[0];
            fz_n += q.w * area * tau[1];
        }
        let mut vals = [[0.0; 2]; 6];
        for (k, b) in NODES.iter().enumerate() {
            vals[k] = tf.stress(s, *b)?;
            tau_max = tau_max.max(vals[k][0].hypot(vals[k][1]));
        }
        nodal.push((t, vals));
    }
    if fields.half() {
        // Half domain of a symmetric scene: tau_yx is even in z and tau_yz odd, so the
        // mirror half doubles Fx and cancels Fz exactly.
        fx_n *= 2.0;
        fz_n = 0.0;
    }
    Ok(FrictionResult { fx_n, fz_n, fx: fx_n / s.load, fz: fz_n / s.load, nodal, tau_max, seconds: t0.elapsed().as_secs_f64() })
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
        let grad = friction_gradient(&f, &s).unwrap();
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
                    let r = friction_pass(&f, &s).unwrap();
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
