//! Integration of the dimensionless Hertz pressure P = sqrt(1 - X^2 - Z^2) (zero outside the
//! unit circle) against the P2 basis of a contact triangle. P has an infinite gradient on
//! the circle, so triangles the circle crosses are split recursively before a degree-5 rule
//! is applied; the load it produces is checked against the exact 2 pi / 3.
use crate::fem;

/// Dimensionless Hertz pressure.
pub fn hertz_pressure(x: f64, z: f64) -> f64 {
    let r2 = x * x + z * z;
    if r2 < 1.0 {
        (1.0 - r2).sqrt()
    } else {
        0.0
    }
}

/// Integrals of P N_i over the P2 triangle `v` (i = the 6 P2 nodes), splitting the
/// sub-triangles the unit circle crosses `depth` times.
pub fn hertz_p2_load(v: &[[f64; 2]; 3], depth: u32) -> [f64; 6] {
    let mut out = [0.0; 6];
    // Barycentric corners of the sub-triangle, relative to the element.
    let root = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    accumulate(v, &root, depth, &mut out);
    out
}

fn to_xy(v: &[[f64; 2]; 3], b: &[f64; 3]) -> [f64; 2] {
    [b[0] * v[0][0] + b[1] * v[1][0] + b[2] * v[2][0], b[0] * v[0][1] + b[1] * v[1][1] + b[2] * v[2][1]]
}

fn crosses_circle(v: &[[f64; 2]; 3], sub: &[[f64; 3]; 3]) -> bool {
    let pts = sub.map(|b| to_xy(v, &b));
    let inside = pts.iter().filter(|p| p[0] * p[0] + p[1] * p[1] < 1.0).count();
    if inside > 0 && inside < 3 {
        return true;
    }
    // All corners outside: the circle may still cut an edge; test the edge distance to 0.
    if inside == 0 {
        for i in 0..3 {
            let (a, b) = (pts[i], pts[(i + 1) % 3]);
            let d = [b[0] - a[0], b[1] - a[1]];
            let t = (-(a[0] * d[0] + a[1] * d[1]) / (d[0] * d[0] + d[1] * d[1])).clamp(0.0, 1.0);
            let c = [a[0] + t * d[0], a[1] + t * d[1]];
            if c[0] * c[0] + c[1] * c[1] < 1.0 {
                return true;
            }
        }
    }
    false
}

fn accumulate(v: &[[f64; 2]; 3], sub: &[[f64; 3]; 3], depth: u32, out: &mut [f64; 6]) {
    if depth > 0 && crosses_circle(v, sub) {
        let mid = |i: usize, j: usize| [0, 1, 2].map(|k| 0.5 * (sub[i][k] + sub[j][k]));
        let (m01, m12, m20) = (mid(0, 1), mid(1, 2), mid(2, 0));
        for s in [[sub[0], m01, m20], [m01, sub[1], m12], [m20, m12, sub[2]], [m01, m12, m20]] {
            accumulate(v, &s, depth - 1, out);
        }
        return;
    }
    // Area of the sub-triangle relative to the element (in barycentric space).
    let det = |a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]| (b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]);
    let rel = det(&sub[0], &sub[1], &sub[2]).abs();
    let area = 0.5 * ((v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[2][0] - v[0][0]) * (v[1][1] - v[0][1])).abs();
    for (xi, w) in fem::tri_rule(5).iter() {
        // Reference point (s, t) mapped to the sub-triangle; weights sum to 1/2.
        let (s, t) = (xi[0], xi[1]);
        let b = [0, 1, 2].map(|k| (1.0 - s - t) * sub[0][k] + s * sub[1][k] + t * sub[2][k]);
        let xy = to_xy(v, &b);
        let p = hertz_pressure(xy[0], xy[1]);
        if p == 0.0 {
            continue;
        }
        let n = fem::p2tri::p2_tri_basis_bary(b);
        for i in 0..6 {
            out[i] += w * 2.0 * area * rel * p * n[i];
        }
    }
}
