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
use super::shear::{disc_shear_stress, FilmPoint, ShearLaw};
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
pub struct FrictionSetup<'a> {
    pub law: ShearLaw,
    /// eta(p) in Pa.s for p in Pa.
    pub eta: &'a dyn Fn(f64) -> f64,
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

    /// The shear stress on the disc at barycentric point `b` (Pa).
    fn stress(&self, s: &FrictionSetup, b: [f64; 3]) -> Result<[f64; 2], Error> {
        let (v, p, h) = (&self.v, &self.p, &self.h);
        let (pv, hv, g) = (p2_tri_eval(p, b), p2_tri_eval(h, b), p2_tri_eval_grad(p, b, &self.geo.grad_bary));
        let (x, z) = ((0..3).map(|i| b[i] * v[i][0]).sum::<f64>(), (0..3).map(|i| b[i] * v[i][1]).sum::<f64>());
        let (xm, zm) = (x * s.a, z * s.a);
        let vel = s.kinematics.at(xm, zm);
        // The film's pressure is non-negative; the P2 interpolant's small undershoot at the
        // cavitation boundary is not a physical tension: the viscosity sees max(p, 0).
        let pa = pv.max(0.0) * s.ph;
        let pt = FilmPoint { eta: (s.eta)(pa), h: hv * s.hs, grad_p: [g[0] * s.ph / s.a, g[1] * s.ph / s.a], slide: [vel.du(), vel.dw()] };
        disc_shear_stress(&s.law, &pt).map_err(|e| Error::numerical(format!("friction pass at (x, z) = ({x:.4}a, {z:.4}a): {e}")))
    }
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
