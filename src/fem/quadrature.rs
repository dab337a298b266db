//! Quadrature rules on the reference simplices, stored as data.
//!
//! * Reference tetrahedron: vertices (0,0,0), (1,0,0), (0,1,0), (0,0,1); volume 1/6.
//!   Barycentric coordinates of a reference point `xi` are
//!   `(1 - xi0 - xi1 - xi2, xi0, xi1, xi2)`.
//! * Reference triangle: vertices (0,0), (1,0), (0,1); area 1/2.
//!   Barycentric coordinates `(1 - xi0 - xi1, xi0, xi1)`.
//!
//! Weights are scaled so that they sum to the reference measure (1/6 resp. 1/2); the
//! integral over a physical (affine) simplex is `|det J| * sum_q w_q f(x(xi_q))`.
//!
//! All built-in rules are fully symmetric with positive weights and interior points
//! (no negative-weight rules such as Keast's 11-point one). Rules of higher degree than the
//! tabulated ones are collapsed (Duffy / conical-product) Gauss-Legendre rules, also with
//! positive weights.
//!
//! | simplex | degree | points | source |
//! |---------|--------|--------|--------|
//! | tet     | 1      | 1      | centroid |
//! | tet     | 2      | 4      | classical S31 rule, a = (5 - sqrt 5)/20 |
//! | tet     | 3      | 8      | two S31 orbits (solved here; also exact for sum lambda_i^4) |
//! | tet     | 5      | 14     | Walkington / Jaskowiec-Sukumar 14-point rule (2 x S31 + S22) |
//! | tri     | 1      | 1      | centroid |
//! | tri     | 2      | 3      | Strang-Fix interior 3-point rule |
//! | tri     | 4      | 6      | Dunavant 6-point rule |
//! | tri     | 5      | 7      | Radon 7-point rule |
//! | tri     | 6      | 12     | Dunavant 12-point rule ([`DUNAVANT6`], 15 digits) |
//! | tri     | 8      | 16     | Dunavant 16-point rule |
//!
//! Constants were refined to 40 digits by Gauss-Newton on the moment equations; the
//! unit tests check every monomial up to the rule's degree.
use std::sync::{LazyLock, OnceLock};

/// A quadrature rule on a `D`-dimensional reference simplex: points in reference
/// Cartesian coordinates and weights summing to the reference measure.
#[derive(Clone, Debug)]
pub struct QuadRule<const D: usize> {
    /// Human-readable identification of the rule.
    pub name: &'static str,
    /// Total polynomial degree integrated exactly.
    pub degree: u32,
    /// Quadrature points, reference Cartesian coordinates.
    pub points: Vec<[f64; D]>,
    /// Quadrature weights (sum = 1/6 on the tetrahedron, 1/2 on the triangle).
    pub weights: Vec<f64>,
}

/// Quadrature rule on the reference tetrahedron.
pub type TetRule = QuadRule<3>;
/// Quadrature rule on the reference triangle.
pub type TriRule = QuadRule<2>;

impl<const D: usize> QuadRule<D> {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.weights.len()
    }
    /// True if the rule has no points (never the case for the built-in rules).
    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }
    /// Iterate over `(point, weight)` pairs.
    pub fn iter(&self) -> impl Iterator<Item = ([f64; D], f64)> + '_ {
        self.points.iter().copied().zip(self.weights.iter().copied())
    }
    /// Sum of the weights (the reference measure).
    pub fn weight_sum(&self) -> f64 {
        self.weights.iter().sum()
    }
}

/// Orbit generators for fully symmetric rules, in barycentric form.
enum TetOrbit {
    /// Centroid (1 point).
    S4(f64),
    /// (a, a, a, 1-3a) and permutations (4 points), weight.
    S31(f64, f64),
    /// (a, a, 1/2-a, 1/2-a) and permutations (6 points), weight.
    S22(f64, f64),
}

enum TriOrbit {
    /// Centroid (1 point).
    S3(f64),
    /// (a, a, 1-2a) and permutations (3 points), weight.
    S21(f64, f64),
    /// (a, b, 1-a-b) and permutations (6 points), weight.
    S111(f64, f64, f64),
}

fn expand_tet(name: &'static str, degree: u32, orbits: &[TetOrbit]) -> TetRule {
    let mut bary: Vec<([f64; 4], f64)> = Vec::new();
    for o in orbits {
        match *o {
            TetOrbit::S4(w) => bary.push(([0.25; 4], w)),
            TetOrbit::S31(a, w) => {
                let b = 1.0 - 3.0 * a;
                for i in 0..4 {
                    let mut l = [a; 4];
                    l[i] = b;
                    bary.push((l, w));
                }
            }
            TetOrbit::S22(a, w) => {
                let b = 0.5 - a;
                for (i, j) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
                    let mut l = [b; 4];
                    l[i] = a;
                    l[j] = a;
                    bary.push((l, w));
                }
            }
        }
    }
    TetRule {
        name,
        degree,
        points: bary.iter().map(|(l, _)| [l[1], l[2], l[3]]).collect(),
        weights: bary.iter().map(|(_, w)| *w).collect(),
    }
}

fn expand_tri(name: &'static str, degree: u32, orbits: &[TriOrbit]) -> TriRule {
    let mut bary: Vec<([f64; 3], f64)> = Vec::new();
    for o in orbits {
        match *o {
            TriOrbit::S3(w) => bary.push(([1.0 / 3.0; 3], w)),
            TriOrbit::S21(a, w) => {
                let b = 1.0 - 2.0 * a;
                for l in [[a, a, b], [a, b, a], [b, a, a]] {
                    bary.push((l, w));
                }
            }
            TriOrbit::S111(a, b, w) => {
                let c = 1.0 - a - b;
                for l in [[a, b, c], [a, c, b], [b, a, c], [b, c, a], [c, a, b], [c, b, a]] {
                    bary.push((l, w));
                }
            }
        }
    }
    TriRule { name, degree, points: bary.iter().map(|(l, _)| [l[1], l[2]]).collect(), weights: bary.iter().map(|(_, w)| *w).collect() }
}

/// Barycentric points of the classical 4-point degree-2 tetrahedron rule (weights 1/24):
/// a = (5 + 3 sqrt 5)/20 on one vertex, b = (5 - sqrt 5)/20 on the others.
pub const TET4_BARY: [[f64; 4]; 4] = {
    const A: f64 = 0.585_410_196_624_968_454_461_4;
    const B: f64 = 0.138_196_601_125_010_515_179_5;
    [[A, B, B, B], [B, A, B, B], [B, B, A, B], [B, B, B, A]]
};

static TET_D1: LazyLock<TetRule> = LazyLock::new(|| expand_tet("tet centroid (1 pt, deg 1)", 1, &[TetOrbit::S4(1.0 / 6.0)]));

static TET_D2: LazyLock<TetRule> =
    LazyLock::new(|| expand_tet("tet S31 (4 pt, deg 2)", 2, &[TetOrbit::S31(0.138_196_601_125_010_515_179_5, 1.0 / 24.0)]));

static TET_D3: LazyLock<TetRule> = LazyLock::new(|| {
    expand_tet(
        "tet 2xS31 positive (8 pt, deg 3)",
        3,
        &[
            TetOrbit::S31(0.328_054_696_711_426_647_335_8, 0.023_087_994_418_643_690_387_27),
            TetOrbit::S31(0.106_952_273_932_930_682_771_7, 0.018_578_672_248_022_976_279_4),
        ],
    )
});

static TET_D5: LazyLock<TetRule> = LazyLock::new(|| {
    expand_tet(
        "tet Walkington 14 pt (deg 5)",
        5,
        &[
            TetOrbit::S31(0.310_885_919_263_300_609_797_3, 0.018_781_320_953_002_641_799_86),
            TetOrbit::S31(0.092_735_250_310_891_226_402_32, 0.012_248_840_519_393_658_257_29),
            TetOrbit::S22(0.045_503_704_125_649_649_491_88, 0.007_091_003_462_846_911_073_012),
        ],
    )
});

static TRI_D1: LazyLock<TriRule> = LazyLock::new(|| expand_tri("tri centroid (1 pt, deg 1)", 1, &[TriOrbit::S3(0.5)]));

static TRI_D2: LazyLock<TriRule> = LazyLock::new(|| expand_tri("tri 3 pt (deg 2)", 2, &[TriOrbit::S21(1.0 / 6.0, 1.0 / 6.0)]));

static TRI_D4: LazyLock<TriRule> = LazyLock::new(|| {
    expand_tri(
        "tri Dunavant 6 pt (deg 4)",
        4,
        &[
            TriOrbit::S21(0.445_948_490_915_964_886_318_3, 0.111_690_794_839_005_732_847_5),
            TriOrbit::S21(0.091_576_213_509_770_743_459_57, 0.054_975_871_827_660_933_819_16),
        ],
    )
});

static TRI_D5: LazyLock<TriRule> = LazyLock::new(|| {
    expand_tri(
        "tri Radon 7 pt (deg 5)",
        5,
        &[
            TriOrbit::S3(9.0 / 80.0),
            TriOrbit::S21(0.101_286_507_323_456_338_801, 0.062_969_590_272_413_576_297_84),
            TriOrbit::S21(0.470_142_064_105_115_089_770_4, 0.066_197_076_394_253_090_368_82),
        ],
    )
});

static TRI_D8: LazyLock<TriRule> = LazyLock::new(|| {
    expand_tri(
        "tri Dunavant 16 pt (deg 8)",
        8,
        &[
            TriOrbit::S3(0.072_157_803_838_893_584_125_55),
            TriOrbit::S21(0.459_292_588_292_723_156_028_8, 0.047_545_817_133_642_312_396_95),
            TriOrbit::S21(0.170_569_307_751_760_206_622_3, 0.051_608_685_267_359_125_140_9),
            TriOrbit::S21(0.050_547_228_317_030_975_458_42, 0.016_229_248_811_599_040_155_46),
            TriOrbit::S111(0.263_112_829_634_638_113_421_8, 0.008_394_777_409_957_605_337_214, 0.013_615_157_087_217_497_132_42),
        ],
    )
});

// ---------------------------------------------------------------------------------------
// The degree-6 triangle rule in barycentric form

/// [`DUNAVANT6`]: the 12-point, degree-6 symmetric rule of D. A. Dunavant, "High degree
/// efficient symmetrical Gaussian quadrature rules for the triangle", IJNME 21 (1985),
/// table entry p = 6; all weights positive, all points interior. In barycentric form
/// (L0, L1, L2) with weights summing to 1, so the integral over a triangle of area A is
/// A * sum_q w_q f(x_q): the form the contact-face kernels (Reynolds, friction) use.
/// [`tri_rule`]`(6)` is the same rule in reference coordinates.
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

static TRI_D6: LazyLock<TriRule> = LazyLock::new(|| TriRule {
    name: "tri Dunavant 12 pt (deg 6)",
    degree: 6,
    points: DUNAVANT6.iter().map(|q| [q.l[1], q.l[2]]).collect(),
    weights: DUNAVANT6.iter().map(|q| 0.5 * q.w).collect(),
});

const MAX_COLLAPSED: usize = 40;
static TET_COLLAPSED: [OnceLock<TetRule>; MAX_COLLAPSED + 1] = [const { OnceLock::new() }; MAX_COLLAPSED + 1];
static TRI_COLLAPSED: [OnceLock<TriRule>; MAX_COLLAPSED + 1] = [const { OnceLock::new() }; MAX_COLLAPSED + 1];

/// The cheapest built-in tetrahedron rule exact for polynomials of total degree `degree`.
///
/// Degrees 0..=5 use the symmetric positive rules of the table in the module docs
/// (degree 4 uses the 14-point degree-5 rule). Degrees 6..=40 use a cached collapsed
/// Gauss-Legendre rule ([`tet_collapsed_gauss`]). Panics above 40.
pub fn tet_rule(degree: u32) -> &'static TetRule {
    match degree {
        0 | 1 => &TET_D1,
        2 => &TET_D2,
        3 => &TET_D3,
        4 | 5 => &TET_D5,
        d if (d as usize) <= MAX_COLLAPSED => TET_COLLAPSED[d as usize].get_or_init(|| tet_collapsed_gauss(d)),
        d => panic!("tet_rule: degree {d} > {MAX_COLLAPSED} not supported"),
    }
}

/// The cheapest built-in triangle rule exact for polynomials of total degree `degree`.
///
/// Degrees 0..=8 use the symmetric positive rules of the table in the module docs
/// (3 -> 6-point degree 4, 7 -> 16-point degree 8). Degrees 9..=40 use a cached
/// collapsed Gauss-Legendre rule ([`tri_collapsed_gauss`]). Panics above 40.
pub fn tri_rule(degree: u32) -> &'static TriRule {
    match degree {
        0 | 1 => &TRI_D1,
        2 => &TRI_D2,
        3 | 4 => &TRI_D4,
        5 => &TRI_D5,
        6 => &TRI_D6,
        7 | 8 => &TRI_D8,
        d if (d as usize) <= MAX_COLLAPSED => TRI_COLLAPSED[d as usize].get_or_init(|| tri_collapsed_gauss(d)),
        d => panic!("tri_rule: degree {d} > {MAX_COLLAPSED} not supported"),
    }
}

/// `n`-point Gauss-Legendre rule on [0, 1]: (nodes, weights), weights sum to 1.
/// Exact for polynomials of degree `2n - 1`.
pub fn gauss_legendre_01(n: usize) -> (Vec<f64>, Vec<f64>) {
    assert!(n >= 1);
    // (P_n(t), P_{n-1}(t)) by the three-term recurrence.
    let legendre = |t: f64| {
        let (mut p0, mut p1) = (1.0, t);
        for k in 2..=n {
            let kf = k as f64;
            let p2 = ((2.0 * kf - 1.0) * t * p1 - (kf - 1.0) * p0) / kf;
            p0 = p1;
            p1 = p2;
        }
        (p1, p0)
    };
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n {
        // Initial guess (Tricomi), then Newton on P_n.
        let mut t = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        for _ in 0..100 {
            let (p, pm1) = legendre(t);
            let dp = n as f64 * (t * p - pm1) / (t * t - 1.0);
            let dt = p / dp;
            t -= dt;
            if dt.abs() < 1e-16 {
                break;
            }
        }
        let (p, pm1) = legendre(t);
        let dp = n as f64 * (t * p - pm1) / (t * t - 1.0);
        x[i] = 0.5 * (1.0 - t);
        // Weight on [-1,1] is 2/((1-t^2) P_n'(t)^2); halved for [0,1].
        w[i] = 1.0 / ((1.0 - t * t) * dp * dp);
    }
    (x, w)
}

/// Collapsed (Duffy / conical-product) Gauss-Legendre rule on the reference tetrahedron,
/// exact for total degree `degree`, positive weights. Map
/// `x = u, y = v (1-u), z = w (1-u)(1-v)`, Jacobian `(1-u)^2 (1-v)`.
pub fn tet_collapsed_gauss(degree: u32) -> TetRule {
    let p = degree as usize;
    let (nu, nv, nw) = ((p + 4) / 2, (p + 3) / 2, (p + 2) / 2);
    let (xu, wu) = gauss_legendre_01(nu);
    let (xv, wv) = gauss_legendre_01(nv);
    let (xw, ww) = gauss_legendre_01(nw);
    let mut points = Vec::with_capacity(nu * nv * nw);
    let mut weights = Vec::with_capacity(nu * nv * nw);
    for i in 0..nu {
        for j in 0..nv {
            for k in 0..nw {
                let (u, v, w) = (xu[i], xv[j], xw[k]);
                points.push([u, v * (1.0 - u), w * (1.0 - u) * (1.0 - v)]);
                weights.push(wu[i] * wv[j] * ww[k] * (1.0 - u) * (1.0 - u) * (1.0 - v));
            }
        }
    }
    TetRule { name: "tet collapsed Gauss-Legendre", degree, points, weights }
}

/// Collapsed (Duffy) Gauss-Legendre rule on the reference triangle, exact for total
/// degree `degree`, positive weights. Map `x = u, y = v (1-u)`, Jacobian `1-u`.
pub fn tri_collapsed_gauss(degree: u32) -> TriRule {
    let p = degree as usize;
    let (nu, nv) = ((p + 3) / 2, (p + 2) / 2);
    let (xu, wu) = gauss_legendre_01(nu);
    let (xv, wv) = gauss_legendre_01(nv);
    let mut points = Vec::with_capacity(nu * nv);
    let mut weights = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            let (u, v) = (xu[i], xv[j]);
            points.push([u, v * (1.0 - u)]);
            weights.push(wu[i] * wv[j] * (1.0 - u));
        }
    }
    TriRule { name: "tri collapsed Gauss-Legendre", degree, points, weights }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fact(n: u32) -> f64 {
        (1..=n).map(|k| k as f64).product()
    }

    /// Exact integral of x^a y^b z^c over the reference tet: a! b! c! / (a+b+c+3)!.
    fn tet_monomial(a: u32, b: u32, c: u32) -> f64 {
        fact(a) * fact(b) * fact(c) / fact(a + b + c + 3)
    }
    /// Exact integral of x^a y^b over the reference triangle: a! b! / (a+b+2)!.
    fn tri_monomial(a: u32, b: u32) -> f64 {
        fact(a) * fact(b) / fact(a + b + 2)
    }

    fn check_tet(rule: &TetRule) {
        assert!((rule.weight_sum() - 1.0 / 6.0).abs() < 1e-15, "{}", rule.name);
        assert!(rule.weights.iter().all(|&w| w > 0.0), "{}", rule.name);
        for p in &rule.points {
            let l0 = 1.0 - p[0] - p[1] - p[2];
            assert!(p.iter().all(|&x| x > 0.0) && l0 > 0.0, "{}: exterior point", rule.name);
        }
        let d = rule.degree;
        for a in 0..=d {
            for b in 0..=d - a {
                for c in 0..=d - a - b {
                    let q: f64 = rule.iter().map(|(p, w)| w * p[0].powi(a as i32) * p[1].powi(b as i32) * p[2].powi(c as i32)).sum();
                    let ex = tet_monomial(a, b, c);
                    assert!((q - ex).abs() <= 1e-14 * ex.max(1e-3), "{}: x^{a} y^{b} z^{c}: {q} vs {ex}", rule.name);
                }
            }
        }
    }

    fn check_tri(rule: &TriRule) {
        assert!((rule.weight_sum() - 0.5).abs() < 1e-15, "{}", rule.name);
        assert!(rule.weights.iter().all(|&w| w > 0.0), "{}", rule.name);
        for p in &rule.points {
            assert!(p[0] > 0.0 && p[1] > 0.0 && 1.0 - p[0] - p[1] > 0.0, "{}", rule.name);
        }
        let d = rule.degree;
        for a in 0..=d {
            for b in 0..=d - a {
                let q: f64 = rule.iter().map(|(p, w)| w * p[0].powi(a as i32) * p[1].powi(b as i32)).sum();
                let ex = tri_monomial(a, b);
                assert!((q - ex).abs() <= 1e-14 * ex.max(1e-3), "{}: x^{a} y^{b}: {q} vs {ex}", rule.name);
            }
        }
    }

    #[test]
    fn tet_rules_exact() {
        let expect = [(1, 1), (2, 4), (3, 8), (4, 14), (5, 14)];
        for (deg, npts) in expect {
            let r = tet_rule(deg);
            assert_eq!(r.len(), npts);
            assert!(r.degree >= deg);
            check_tet(r);
        }
        for deg in [6, 8, 10, 14] {
            let r = tet_rule(deg);
            assert_eq!(r.degree, deg);
            check_tet(r);
        }
    }

    #[test]
    fn tet_rules_not_exact_beyond_degree() {
        // Sanity: the degree claim is sharp for the tabulated rules (some monomial of
        // degree+1 is missed), so the test above is not vacuous.
        for deg in [1u32, 2, 3, 5] {
            let r = tet_rule(deg);
            let d = r.degree + 1;
            let mut worst: f64 = 0.0;
            for a in 0..=d {
                for b in 0..=d - a {
                    let c = d - a - b;
                    let q: f64 = r.iter().map(|(p, w)| w * p[0].powi(a as i32) * p[1].powi(b as i32) * p[2].powi(c as i32)).sum();
                    let ex = tet_monomial(a, b, c);
                    worst = worst.max((q - ex).abs() / ex);
                }
            }
            assert!(worst > 1e-8, "rule {} seems exact beyond degree", r.name);
        }
    }

    #[test]
    fn tri_rules_exact() {
        let expect = [(1, 1), (2, 3), (4, 6), (5, 7), (8, 16)];
        for (deg, npts) in expect {
            let r = tri_rule(deg);
            assert_eq!(r.len(), npts);
            assert_eq!(r.degree, deg);
            check_tri(r);
        }
        for deg in [9, 12, 20] {
            let r = tri_rule(deg);
            assert_eq!(r.degree, deg);
            check_tri(r);
        }
    }

    #[test]
    fn gauss_legendre_exact() {
        for n in 1..12 {
            let (x, w) = gauss_legendre_01(n);
            for k in 0..(2 * n) as i32 {
                let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(k)).sum();
                assert!((q - 1.0 / (k as f64 + 1.0)).abs() < 1e-14, "n={n} k={k}");
            }
        }
    }

    #[test]
    fn tet4_bary_matches_rule() {
        let r = tet_rule(2);
        for (i, l) in TET4_BARY.iter().enumerate() {
            let p = r.points[i];
            assert!((p[0] - l[1]).abs() < 1e-15 && (p[1] - l[2]).abs() < 1e-15 && (p[2] - l[3]).abs() < 1e-15);
            assert!((l.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        }
    }

    // Dunavant 12-point rule in barycentric form.

    /// Integral of L0^a L1^b L2^c over a triangle of area A: A * 2 a! b! c! / (a+b+c+2)!.
    fn exact_bary(a: u32, b: u32, c: u32) -> f64 {
        let f = |n: u32| (1..=n).map(|k| k as f64).product::<f64>();
        2.0 * f(a) * f(b) * f(c) / f(a + b + c + 2)
    }

    #[test]
    fn dunavant6_is_exact_to_degree_6() {
        for a in 0..=6u32 {
            for b in 0..=(6 - a) {
                for c in 0..=(6 - a - b) {
                    let q: f64 =
                        DUNAVANT6.iter().map(|p| p.w * p.l[0].powi(a as i32) * p.l[1].powi(b as i32) * p.l[2].powi(c as i32)).sum();
                    let e = exact_bary(a, b, c);
                    assert!((q - e).abs() < 1e-14, "L0^{a} L1^{b} L2^{c}: {q} vs {e}");
                }
            }
        }
        // and it is not exact at degree 7 (so the test above means something)
        let q: f64 = DUNAVANT6.iter().map(|p| p.w * p.l[0].powi(7)).sum();
        assert!((q - exact_bary(7, 0, 0)).abs() > 1e-8);
        for p in DUNAVANT6.iter() {
            assert!((p.l.iter().sum::<f64>() - 1.0).abs() < 1e-14 && p.w > 0.0);
        }
    }
}
