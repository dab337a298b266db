//! Quadrature on triangles.
//!
//! [`DUNAVANT6`]: the 12-point, degree-6 symmetric rule of D. A. Dunavant, "High degree
//! efficient symmetrical Gaussian quadrature rules for the triangle", IJNME 21 (1985),
//! table entry p = 6. All weights are positive and all points are interior. Points are
//! given in barycentric coordinates (L0, L1, L2); weights are normalised to sum to 1, so
//! the integral over a triangle of area A is A * sum_q w_q f(x_q).
//! The unit test checks exactness on every monomial of degree <= 6.

/// One quadrature point: barycentric coordinates and weight (weights sum to 1).
#[derive(Clone, Copy, Debug)]
pub struct QuadPoint {
    /// Barycentric coordinates (L0, L1, L2), summing to 1.
    pub l: [f64; 3],
    /// Weight, relative to the triangle area.
    pub w: f64,
}

const A1: f64 = 0.249_286_745_170_910;
const B1: f64 = 0.501_426_509_658_179;
const W1: f64 = 0.116_786_275_726_379;
const A2: f64 = 0.063_089_014_491_502;
const B2: f64 = 0.873_821_971_016_996;
const W2: f64 = 0.050_844_906_370_207;
const C1: f64 = 0.053_145_049_844_817;
const C2: f64 = 0.310_352_451_033_784;
const C3: f64 = 0.636_502_499_121_399;
const W3: f64 = 0.082_851_075_618_374;

const fn qp(l0: f64, l1: f64, l2: f64, w: f64) -> QuadPoint {
    QuadPoint { l: [l0, l1, l2], w }
}

/// Dunavant's 12-point rule, exact for polynomials of degree <= 6.
pub const DUNAVANT6: [QuadPoint; 12] = [
    qp(B1, A1, A1, W1),
    qp(A1, B1, A1, W1),
    qp(A1, A1, B1, W1),
    qp(B2, A2, A2, W2),
    qp(A2, B2, A2, W2),
    qp(A2, A2, B2, W2),
    qp(C1, C2, C3, W3),
    qp(C1, C3, C2, W3),
    qp(C2, C1, C3, W3),
    qp(C2, C3, C1, W3),
    qp(C3, C1, C2, W3),
    qp(C3, C2, C1, W3),
];

#[cfg(test)]
mod tests {
    use super::*;

    /// Integral of L0^a L1^b L2^c over a triangle of area A: A * 2 a! b! c! / (a+b+c+2)!.
    fn exact(a: u32, b: u32, c: u32) -> f64 {
        let f = |n: u32| (1..=n).map(|k| k as f64).product::<f64>();
        2.0 * f(a) * f(b) * f(c) / f(a + b + c + 2)
    }

    #[test]
    fn dunavant6_is_exact_to_degree_6() {
        for a in 0..=6u32 {
            for b in 0..=(6 - a) {
                for c in 0..=(6 - a - b) {
                    let q: f64 = DUNAVANT6
                        .iter()
                        .map(|p| {
                            p.w * p.l[0].powi(a as i32)
                                * p.l[1].powi(b as i32)
                                * p.l[2].powi(c as i32)
                        })
                        .sum();
                    let e = exact(a, b, c);
                    assert!((q - e).abs() < 1e-14, "L0^{a} L1^{b} L2^{c}: {q} vs {e}");
                }
            }
        }
        // and it is not exact at degree 7 (so the test above means something)
        let q: f64 = DUNAVANT6.iter().map(|p| p.w * p.l[0].powi(7)).sum();
        assert!((q - exact(7, 0, 0)).abs() > 1e-8);
        for p in DUNAVANT6.iter() {
            assert!((p.l.iter().sum::<f64>() - 1.0).abs() < 1e-14 && p.w > 0.0);
        }
    }
}
