//! Closed-form stresses inside an elastic half-space loaded by a circular Hertz contact,
//! the references of the subsurface stress recovery (docs/subsurface.md).
//!
//! Frame of the references (not the solver's): `x`, `y` in the surface, `z` the depth
//! (positive into the solid), lengths in units of the contact radius a. The surface
//! carries the Hertz pressure `p0 sqrt(1 - r^2)` (pushing into the solid) and, for the
//! sliding contact, the tangential traction `q0 sqrt(1 - r^2)` in `+x` (`q0 = mu p0`).
//! Stresses are returned in units of `p0` (normal part) or `q0` (tangential part), tension
//! positive, as `[xx, yy, zz, xy, yz, xz]`.
//!
//! - [`huber_axis`]: Huber (1904) on the axis, as given by Johnson, *Contact Mechanics*
//!   (1985), Eq. (3.45).
//! - [`hamilton_normal`], [`hamilton_tangential`]: Hamilton, "Explicit equations for the
//!   stresses beneath a sliding spherical contact", Proc. IMechE 197C (1983) 53-59, in
//!   terms of his auxiliary quantities A, S, M, N, phi, G, H.
//!
//! The unit tests do not trust the transcription: they check that the fields satisfy
//! equilibrium and the Beltrami-Michell compatibility equations (finite differences) and
//! carry the prescribed surface tractions, which determines the decaying elastic field
//! uniquely.

/// Stress components `[xx, yy, zz, xy, yz, xz]`.
pub type Stress6 = [f64; 6];

/// Huber's stresses on the axis r = 0 at depth `z` (units of a): `(sigma_z, sigma_r)` in
/// units of p0, `sigma_theta = sigma_r`:
/// `sigma_z = -1/(1 + z^2)`, `sigma_r = -(1 + nu)(1 - z atan(1/z)) + 1/(2 (1 + z^2))`.
pub fn huber_axis(z: f64, nu: f64) -> (f64, f64) {
    let sz = -1.0 / (1.0 + z * z);
    let at = if z > 0.0 { z * (1.0 / z).atan() } else { 0.0 };
    let sr = -(1.0 + nu) * (1.0 - at) + 0.5 / (1.0 + z * z);
    (sz, sr)
}

/// Hamilton's auxiliary quantities at (r^2, z).
struct Aux {
    a: f64,
    s: f64,
    m: f64,
    n: f64,
    phi: f64,
    g: f64,
    h: f64,
}

fn aux(r2: f64, z: f64) -> Aux {
    let a = r2 + z * z - 1.0;
    let s = (a * a + 4.0 * z * z).sqrt();
    let m = (0.5 * (s + a)).max(0.0).sqrt();
    let n = (0.5 * (s - a)).max(0.0).sqrt();
    let phi = (1.0 / m).atan();
    let g = m * m - n * n + z * m - n;
    let h = 2.0 * m * n + m + z * n;
    Aux { a, s, m, n, phi, g, h }
}

/// Below this r^2 the axis formulas are used (the general ones divide by r^4).
const AXIS_R2: f64 = 1e-14;

/// Stresses of the Hertz pressure (units of p0) at (x, y, z), z >= 0.
pub fn hamilton_normal(x: f64, y: f64, z: f64, nu: f64) -> Stress6 {
    let r2 = x * x + y * y;
    if r2 < AXIS_R2 {
        let (sz, sr) = huber_axis(z, nu);
        return [sr, sr, sz, 0.0, 0.0, 0.0];
    }
    let Aux { a, s, m, n, phi, g, h } = aux(r2, z);
    let (x2, y2) = (x * x, y * y);
    let common = (1.0 - nu) * n * z * z - (1.0 - 2.0 * nu) / 3.0 * (n * s + 2.0 * a * n + 1.0) - nu * m * z;
    let sxx = (1.0 + nu) * z * phi + ((y2 - x2) / r2 * common - n * (x2 + 2.0 * nu * y2) - m * x2 * z / s) / r2;
    let syy = (1.0 + nu) * z * phi + ((x2 - y2) / r2 * common - n * (y2 + 2.0 * nu * x2) - m * y2 * z / s) / r2;
    let szz = -n + z * m / s;
    let r4 = r2 * r2;
    let sxy = x * y * (1.0 - 2.0 * nu) / r4 * (-n * r2 + 2.0 / 3.0 * n * (s + 2.0 * a) - z * (z * n + m) + 2.0 / 3.0)
        + x * y * z / r4 * (-m * r2 / s - z * n + m);
    let k = z * h / (g * g + h * h);
    let syz = -z * y * (n / s - k);
    let sxz = -z * x * (n / s - k);
    [sxx, syy, szz, sxy, syz, sxz]
}

/// Stresses of the tangential traction `sqrt(1 - r^2)` in +x (units of q0) at (x, y, z).
pub fn hamilton_tangential(x: f64, y: f64, z: f64, nu: f64) -> Stress6 {
    let r2 = x * x + y * y;
    if r2 < AXIS_R2 {
        let at = if z > 0.0 { z * (1.0 / z).atan() } else { 0.0 };
        return [0.0, 0.0, 0.0, 0.0, 0.0, -1.0 + 1.5 * at - z * z / (2.0 * (1.0 + z * z))];
    }
    let Aux { a, s, m, n, phi, .. } = aux(r2, z);
    let (x2, y2, z2) = (x * x, y * y, z * z);
    let r4 = r2 * r2;
    let c = 1.0 - 2.0 * nu;
    let fx = 1.5 - 2.0 * x2 / r2;
    let gx = 0.5 - 2.0 * x2 / r2;
    let gy = 0.5 - 2.0 * y2 / r2;
    let sxx = -x * (nu / 4.0 + 1.0) * phi
        + x * m / r4 * (fx * (s * nu - 2.0 * a * nu + z2) + x2 * z2 / s + 7.0 * nu * r2 / 4.0 - 2.0 * nu * x2 + r2)
        + x * z * n / r4 * (fx * (-s / 6.0 * c - a / 3.0 * c - 0.5 * (z2 + 3.0)) + x2 / s - nu * r2 / 4.0 - 7.0 * r2 / 4.0)
        + 4.0 * x * z / (3.0 * r4) * fx * c;
    let syy = -0.75 * nu * x * phi
        + x * m / r4 * (gy * (nu * (s - 2.0 * a + r2) + z2) + y2 * z2 / s + 0.75 * nu * r2)
        + z * x * n / r4 * (gy * (-s / 6.0 * c - a / 3.0 * c - 0.5 * z2 - 1.5) + y2 / s - 0.75 * nu * r2 - 0.25 * r2)
        + 4.0 / 3.0 * z * x / r4 * gy * c;
    let szz = z * x * n / (2.0 * r2) * (1.0 - (r2 + z2 + 1.0) / s);
    let sxy = 0.5 * y * (0.5 * nu - 1.0) * phi
        + y * m / r4 * (x2 * z2 / s + nu * ((s - 2.0 * a) * gx - 2.0 * x2 + 0.25 * r2) + 0.5 * r2 + z2 * gx)
        + y * z * n / r4 * (gx * (-c * (s / 6.0 + a / 3.0) - 0.5 * z2 - 1.5 - 0.5 * r2) + 0.25 * nu * r2 + x2 / s - 0.5 * y2 - 1.5 * x2)
        + 4.0 * y * z / (3.0 * r4) * gx * c;
    let syz = x * y * z / (2.0 * r4) * (m * (0.5 + (0.5 * z2 - 1.5 - 0.5 * r2) / s) + 0.5 * z * n * (-3.0 + (5.0 + z2 + r2) / s));
    let sxz =
        1.5 * z * phi + z * m / r2 * (1.0 + x2 / r2 - x2 / s) + n / r2 * (-0.75 * (s + 2.0 * a) + z2 - 0.75 - 0.25 * r2 + 0.5 * z2 * gx);
    [sxx, syy, szz, sxy, syz, sxz]
}

/// Sliding Hertz contact: `p0 * (normal + mu * tangential)`, in units of p0.
pub fn hamilton_sliding(x: f64, y: f64, z: f64, nu: f64, mu: f64) -> Stress6 {
    let n = hamilton_normal(x, y, z, nu);
    let t = hamilton_tangential(x, y, z, nu);
    std::array::from_fn(|k| n[k] + mu * t[k])
}

/// Von Mises stress of a tensor `[xx, yy, zz, xy, yz, xz]`.
pub fn von_mises(s: &Stress6) -> f64 {
    let d = (s[0] - s[1]).powi(2) + (s[1] - s[2]).powi(2) + (s[2] - s[0]).powi(2);
    (0.5 * d + 3.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5])).sqrt()
}

/// The largest von Mises stress of the sliding contact (units of p0) and where it is,
/// `(value, x, z)` (units of a) on the plane of symmetry y = 0: a lattice search on
/// |x| <= 1.5, 0 <= z <= 1.5 (step 0.01), refined twice around the best point (steps
/// 0.001 and 0.0001).
pub fn sliding_von_mises_max(nu: f64, mu: f64) -> (f64, f64, f64) {
    let f = |x: f64, z: f64| von_mises(&hamilton_sliding(x, 0.0, z.max(0.0), nu, mu));
    let mut best = (f64::NEG_INFINITY, 0.0, 0.0);
    let scan = |x0: f64, x1: f64, z0: f64, z1: f64, h: f64, best: &mut (f64, f64, f64)| {
        let (nx, nz) = (((x1 - x0) / h).round() as i64, ((z1 - z0) / h).round() as i64);
        for i in 0..=nx {
            for j in 0..=nz {
                let (x, z) = (x0 + i as f64 * h, (z0 + j as f64 * h).max(0.0));
                let v = f(x, z);
                if v > best.0 {
                    *best = (v, x, z);
                }
            }
        }
    };
    scan(-1.5, 1.5, 0.0, 1.5, 0.01, &mut best);
    for h in [0.001, 0.0001] {
        let (x, z) = (best.1, best.2);
        scan(x - 15.0 * h, x + 15.0 * h, z - 15.0 * h, z + 15.0 * h, h, &mut best);
    }
    best
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;

    const NU: f64 = 0.3;

    /// The full tensor as a 3x3 matrix.
    fn full(s: &Stress6) -> [[f64; 3]; 3] {
        [[s[0], s[3], s[5]], [s[3], s[1], s[4]], [s[5], s[4], s[2]]]
    }

    fn at(f: &dyn Fn(f64, f64, f64) -> Stress6, p: [f64; 3]) -> [[f64; 3]; 3] {
        full(&f(p[0], p[1], p[2]))
    }

    fn shifted(p: [f64; 3], d: usize, h: f64) -> [f64; 3] {
        let mut q = p;
        q[d] += h;
        q
    }

    /// Interior points away from the axis and from the contact edge's surface singularity.
    fn points() -> Vec<[f64; 3]> {
        vec![[0.3, 0.2, 0.5], [-0.7, 0.4, 0.3], [1.2, -0.5, 0.8], [0.1, -0.9, 1.4], [-1.5, -1.1, 0.6], [0.5, 0.05, 0.25], [2.5, 1.0, 2.0]]
    }

    /// div sigma = 0 and the Beltrami-Michell equations
    /// `lap sigma_ij + 1/(1 + nu) d_i d_j tr(sigma) = 0` by central differences.
    fn check_field_equations(f: &dyn Fn(f64, f64, f64) -> Stress6) {
        for p in points() {
            let h = 1e-4;
            for i in 0..3 {
                let div: f64 = (0..3).map(|j| (at(f, shifted(p, j, h))[i][j] - at(f, shifted(p, j, -h))[i][j]) / (2.0 * h)).sum();
                assert!(div.abs() < 1e-6, "div sigma[{i}] = {div} at {p:?}");
            }
            let h = 2e-3;
            let tr = |q: [f64; 3]| {
                let s = at(f, q);
                s[0][0] + s[1][1] + s[2][2]
            };
            let s0 = at(f, p);
            for i in 0..3 {
                for j in 0..3 {
                    let lap: f64 =
                        (0..3).map(|d| (at(f, shifted(p, d, h))[i][j] - 2.0 * s0[i][j] + at(f, shifted(p, d, -h))[i][j]) / (h * h)).sum();
                    let didj = if i == j {
                        (tr(shifted(p, i, h)) - 2.0 * tr(p) + tr(shifted(p, i, -h))) / (h * h)
                    } else {
                        let pp = shifted(shifted(p, i, h), j, h);
                        let pm = shifted(shifted(p, i, h), j, -h);
                        let mp = shifted(shifted(p, i, -h), j, h);
                        let mm = shifted(shifted(p, i, -h), j, -h);
                        (tr(pp) - tr(pm) - tr(mp) + tr(mm)) / (4.0 * h * h)
                    };
                    let bm = lap + didj / (1.0 + NU);
                    assert!(bm.abs() < 2e-4, "Beltrami-Michell ({i},{j}) = {bm} at {p:?}");
                }
            }
        }
    }

    #[test]
    fn normal_field_is_an_elastic_field() {
        check_field_equations(&|x, y, z| hamilton_normal(x, y, z, NU));
    }

    #[test]
    fn tangential_field_is_an_elastic_field() {
        check_field_equations(&|x, y, z| hamilton_tangential(x, y, z, NU));
    }

    /// Surface tractions (z -> 0): sigma_zj = -t_j with t the applied traction.
    #[test]
    fn surface_tractions() {
        let z = 1e-9;
        for (x, y) in [(0.2, 0.3), (-0.5, 0.1), (0.7, -0.6), (1.3, 0.2), (-0.4, 1.5)] {
            let r2: f64 = x * x + y * y;
            let p = if r2 < 1.0 { (1.0 - r2).sqrt() } else { 0.0 };
            let n = hamilton_normal(x, y, z, NU);
            assert!((n[2] + p).abs() < 1e-6, "normal: sigma_zz = {} at ({x}, {y}), p = {p}", n[2]);
            assert!(n[4].abs() < 1e-6 && n[5].abs() < 1e-6, "normal: shear traction {:?}", n);
            let t = hamilton_tangential(x, y, z, NU);
            assert!((t[5] + p).abs() < 1e-6, "tangential: sigma_xz = {} at ({x}, {y}), q = {p}", t[5]);
            assert!(t[4].abs() < 1e-6 && t[2].abs() < 1e-6, "tangential: {:?}", t);
        }
    }

    /// Johnson's surface values at the centre (sigma_r = -(1 + 2 nu)/2 p0) and the limits of
    /// the general formulas towards the axis.
    #[test]
    fn axis_and_centre() {
        let (sz, sr) = huber_axis(0.0, NU);
        assert_eq!(sz, -1.0);
        assert!((sr + (1.0 + 2.0 * NU) / 2.0).abs() < 1e-15);
        for z in [0.2, 0.48, 1.0, 2.5] {
            let (sz, sr) = huber_axis(z, NU);
            let g = hamilton_normal(1e-3, 0.0, z, NU);
            assert!((g[2] - sz).abs() < 1e-5 && (g[0] - sr).abs() < 1e-4 && (g[1] - sr).abs() < 1e-4, "z = {z}: {g:?} vs ({sz}, {sr})");
            let t = hamilton_tangential(1e-3, 0.0, z, NU);
            let t0 = hamilton_tangential(0.0, 0.0, z, NU);
            assert!((t[5] - t0[5]).abs() < 1e-4, "z = {z}: {} vs {}", t[5], t0[5]);
        }
    }

    #[test]
    fn sliding_maxima() {
        // Frictionless: on the axis von Mises is |sigma_r - sigma_z|, twice Huber's
        // largest shear stress (0.3100 p0 at 0.481 a).
        let (v, x, z) = sliding_von_mises_max(NU, 0.0);
        let (sz, sr) = huber_axis(z, NU);
        assert!(x.abs() < 1e-3 && (v - (sr - sz).abs()).abs() < 1e-6, "{v} at ({x}, {z})");
        assert!((v - 0.62).abs() < 0.001 && (z - 0.481).abs() < 0.002, "{v} at z = {z}");
        // Friction pulls the maximum forward and up, and above mu ~ 0.3 it jumps to the
        // trailing edge of the surface (tension and traction add up there).
        let mut last = (v, x, z);
        for mu in [0.1, 0.2, 0.3] {
            let m = sliding_von_mises_max(NU, mu);
            assert!(m.0 > last.0 && m.1 > last.1 && m.2 < last.2 && m.2 > 0.3, "mu = {mu}: {m:?}");
            last = m;
        }
        let (_, x, z) = sliding_von_mises_max(NU, 0.4);
        assert!(z == 0.0 && (x + 1.0).abs() < 0.01, "mu = 0.4: maximum at ({x}, {z})");
    }

    /// Johnson: the largest shear stress on the axis is 0.31 p0 at z = 0.48 a (nu = 0.3).
    #[test]
    fn huber_maximum_shear() {
        let (mut best, mut at) = (0.0, 0.0);
        for i in 1..4000 {
            let z = i as f64 * 5e-4;
            let (sz, sr) = huber_axis(z, NU);
            let t = 0.5 * (sr - sz).abs();
            if t > best {
                best = t;
                at = z;
            }
        }
        assert!((best - 0.31).abs() < 0.005, "max shear {best}");
        assert!((at - 0.48).abs() < 0.01, "at z = {at}");
    }
}
