//! Tests of the shear law: closed forms, limits, symmetry and the Newton solver.
use super::*;

/// Paper Table 1 Eyring stress (Pa) and a typical EHL film point.
const TAU0: f64 = 6.2e6;
const ETA: f64 = 0.08;
const H: f64 = 2.0e-7;
const RE: ShearLaw = ShearLaw::ReeEyring { tau0: TAU0 };

fn point(grad_p: [f64; 2], slide: [f64; 2]) -> FilmPoint {
    FilmPoint { eta: ETA, h: H, grad_p, slide }
}

fn rotate(v: [f64; 2], angle: f64) -> [f64; 2] {
    let (s, c) = angle.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}

fn dist(u: [f64; 2], v: [f64; 2]) -> f64 {
    norm([u[0] - v[0], u[1] - v[1]])
}

/// Independent reference: integral_0^h gammadot dy by composite Simpson with `n` (even)
/// intervals, using sinh directly (no series, no Gauss-Legendre). Returns the integral
/// and integral |gammadot| dy (the magnitude that sets the rounding floor).
fn simpson_slide(law: &ShearLaw, pt: &FilmPoint, t0: [f64; 2], n: usize) -> ([f64; 2], f64) {
    let dy = pt.h / n as f64;
    let (mut g, mut mag) = ([0.0; 2], 0.0);
    for i in 0..=n {
        let w = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        } * dy
            / 3.0;
        let tau = shear_at(t0, pt.grad_p, i as f64 * dy);
        let te = norm(tau);
        let factor = match *law {
            ShearLaw::ReeEyring { tau0 } if te > 0.0 => (te / tau0).sinh() / (te / tau0),
            _ => 1.0,
        };
        g[0] += w * tau[0] / pt.eta * factor;
        g[1] += w * tau[1] / pt.eta * factor;
        mag += w * te / pt.eta * factor;
    }
    (g, mag)
}

/// Slide (m/s) giving the dimensionless uniform-film number eta |slide|/(h tau0) = n.
fn slide_for(n: f64, angle: f64) -> [f64; 2] {
    rotate([n * H * TAU0 / ETA, 0.0], angle)
}

/// Gradient (Pa/m) giving h |g| / tau0 = n.
fn grad_for(n: f64, angle: f64) -> [f64; 2] {
    rotate([n * TAU0 / H, 0.0], angle)
}

#[test]
fn gauss_legendre_rule_exact_for_degree_9_and_accurate_for_exponentials() {
    // Degree <= 9 exact on one and on several panels (up to rounding).
    for m in [1, 3, 7] {
        for k in 0..=9 {
            let mut q = 0.0;
            for_each_node(m, |y, w| q += w * y.powi(k));
            assert!((q - 1.0 / (k + 1) as f64).abs() < 1e-15, "m = {m}, Y^{k}: {q}");
        }
    }
    // Degree 10 is not exact on one panel: the rule really has 5 points.
    let mut q = 0.0;
    for_each_node(1, |y, w| q += w * y.powi(10));
    assert!((q - 1.0 / 11.0).abs() > 1e-7);
    // The integrand of the solver grows like exp(|a| Y). The 5-point error on a panel
    // of width L is L^11 (5!)^4 / (11 (10!)^3) f^(10) = 3.9e-13 (c L)^10 L f, and the
    // panel count keeps c L < 1, so the relative error is < 3.9e-13 (observed 3.1e-13
    // at c = 50, c L = 0.98): well below the 1e-12 Newton tolerance.
    for c in [0.3, 5.0, 50.0, 150.0, -80.0] {
        let mut q = 0.0;
        for_each_node(panel_count([c, 0.0]), |y, w| q += w * (c * y).exp());
        let exact = c.exp_m1() / c;
        assert!(((q - exact) / exact).abs() < 4e-13, "c = {c}: {q} vs {exact}");
    }
}

#[test]
fn eyring_factors_series_and_closed_forms_agree() {
    let z = eyring_factors(0.0);
    assert_eq!(z, EyringFactors { f: 1.0, fp_over_t: 1.0 / 3.0, cosh_m1: 0.0 });
    // Series branch against sinh/t (no cancellation in it) and against the closed form
    // (t cosh t - sinh t)/t^3 (cancellation ~ eps/t^2, hence the looser tolerance).
    for t in [1e-3, 0.05, 0.3, 0.4999] {
        let e = eyring_factors(t);
        let fp = (t * t.cosh() - t.sinh()) / t.powi(3);
        assert!(((e.f - t.sinh() / t) / e.f).abs() < 4e-16, "F({t})");
        assert!(((e.fp_over_t - fp) / fp).abs() < 1e-15 / (t * t), "F'/t({t})");
        assert!(((e.cosh_m1 - (t.cosh() - 1.0)) / e.cosh_m1).abs() < 1e-15 / (t * t));
    }
    // Continuity across the branch switch.
    let (lo, hi) = (eyring_factors(SERIES_T * (1.0 - 1e-15)), eyring_factors(SERIES_T));
    assert!(((lo.f - hi.f) / hi.f).abs() < 1e-15);
    assert!(((lo.fp_over_t - hi.fp_over_t) / hi.fp_over_t).abs() < 1e-14);
}

#[test]
fn zero_slide_and_zero_gradient_give_exactly_zero() {
    for law in [RE, ShearLaw::Newtonian] {
        let t0 = disc_shear_stress(&law, &point([0.0; 2], [0.0; 2])).unwrap();
        assert_eq!(t0, [0.0, 0.0]);
        assert!(t0[0].is_sign_positive() && t0[1].is_sign_positive());
    }
}

/// Test 1. g = 0: the stress is uniform across the film, so sinh(|t0|/tau0) =
/// eta |slide|/(h tau0) and t0 is parallel to the slide (outside closed form).
#[test]
fn uniform_film_limit_matches_asinh_law() {
    for n in [1e-3, 1e-1, 1.0, 10.0, 1e2, 1e3, 1e4] {
        for angle in [0.0, 0.7, 2.0, -2.9] {
            let slide = slide_for(n, angle);
            let t0 = disc_shear_stress(&RE, &point([0.0; 2], slide)).unwrap();
            let expected = TAU0 * n.asinh();
            let rel = (norm(t0) - expected).abs() / expected;
            assert!(rel < 1e-10, "n = {n}, angle {angle}: |t0| = {} vs {expected} ({rel:e})", norm(t0));
            let sin_between = (t0[0] * slide[1] - t0[1] * slide[0]) / (norm(t0) * norm(slide));
            assert!(sin_between.abs() < 1e-12 && dot(t0, slide) > 0.0, "not parallel: {sin_between:e}");
        }
    }
}

/// Test 2. tau0 >> all stresses: Ree-Eyring -> Newtonian eta slide/h - h g/2. The
/// first correction is relative O((tau/tau0)^2 / 6) ~ 1e-13 here, so 1e-9 is safe
/// (tighter than the ~1e-6 the physics needs).
#[test]
fn newtonian_limit_for_huge_tau0() {
    let slide = [1.3, -0.4];
    let grad = [3e12, -1.5e12];
    let pt = point(grad, slide);
    let newton = newtonian_disc_stress(&pt);
    let scale = (ETA * norm(slide) / H).max(H * norm(grad));
    let law = ShearLaw::ReeEyring { tau0: 1e6 * scale };
    let t0 = disc_shear_stress(&law, &pt).unwrap();
    let rel = dist(t0, newton) / norm(newton);
    assert!(rel < 1e-9, "{t0:?} vs {newton:?}: {rel:e}");
    assert_eq!(disc_shear_stress(&ShearLaw::Newtonian, &pt).unwrap(), newton);
}

/// Test 3. Newtonian closed form with a pressure gradient satisfies the flow-rate
/// constraint integral_0^h (t0 + y g)/eta dy = slide (Simpson is exact for a linear
/// integrand, so only rounding remains).
#[test]
fn newtonian_closed_form_satisfies_flow_rate_constraint() {
    let law = ShearLaw::Newtonian;
    for (slide, grad) in [([2.0, 0.0], [1e12, 0.0]), ([-0.5, 0.8], [-4e12, 7e11]), ([0.0, 0.0], [2e13, -3e13])] {
        let pt = point(grad, slide);
        let t0 = disc_shear_stress(&law, &pt).unwrap();
        let (g, mag) = simpson_slide(&law, &pt, t0, 2000);
        assert!(dist(g, slide) <= 1e-12 * (norm(slide) + mag), "{g:?} vs {slide:?}");
        let fs = film_slide(&law, &pt, t0).unwrap();
        assert!(dist(fs.slide, slide) <= 1e-12 * (norm(slide) + mag));
    }
}

/// Test 4a. Strongly non-Newtonian stresses with a pressure gradient (h|g|/tau0 = 5..50)
/// in general directions: the returned t0 satisfies the constraint evaluated by an
/// independent 20000-interval Simpson rule. Simpson's error is ~ (|a|/20000)^4/180 <=
/// 3e-13 relative, and the floor of any evaluation is eps times integral |gammadot| dy
/// (stresses of both signs cancel), so the check is relative to |slide| + that
/// magnitude. Where |slide| dominates the magnitude this is a plain relative check
/// (observed errors <= 1.4e-13).
#[test]
fn strongly_non_newtonian_with_gradient_satisfies_constraint() {
    for stress_range in [5.0, 20.0, 50.0] {
        for (n, slide_angle, grad_angle) in [(0.3, 0.0, 1.0), (30.0, 2.0, -0.5), (3e3, -1.0, 2.5), (1e5, 0.4, 0.4)] {
            let pt = point(grad_for(stress_range, grad_angle), slide_for(n, slide_angle));
            let t0 = disc_shear_stress(&RE, &pt).unwrap();
            let (g, mag) = simpson_slide(&RE, &pt, t0, 20000);
            let err = dist(g, pt.slide) / (norm(pt.slide) + mag);
            assert!(err < 1e-8, "range {stress_range}, n {n}: {g:?} vs {:?} ({err:e})", pt.slide);
        }
    }
}

/// Test 4b. g parallel to the slide: the problem is one-dimensional along e = g/|g| and
/// G = (h tau0/eta) (cosh(s0 + a) - cosh(s0))/a in closed form, hence
/// s0 = -a/2 + asinh(b a / (2 sinh(a/2))) (a, b signed components along e).
#[test]
fn collinear_gradient_matches_closed_form() {
    for a in [0.5, 5.0, -20.0, 50.0] {
        for b in [0.0, 0.2, -7.0, 1e4] {
            let angle = 0.9;
            let pt = point(grad_for(a, angle), slide_for(b, angle));
            let s0 = -0.5 * a + (b * a / (2.0 * (0.5 * a).sinh())).asinh();
            let expected = rotate([TAU0 * s0, 0.0], angle);
            let t0 = disc_shear_stress(&RE, &pt).unwrap();
            let err = dist(t0, expected) / (norm(expected) + TAU0);
            assert!(err < 1e-12, "a {a}, b {b}: {t0:?} vs {expected:?} ({err:e})");
        }
    }
}

/// Test 4b'. Newton's collinear start is that closed form, for any direction and also where
/// the film's stresses cancel (a = 400: +-200 tau0 across it): the start meets the
/// criterion, and across the pressure gradient it lies nearer the solution than the
/// uniform-film start (a thick film under the outlet spike: |a| = 100 at 1 rad from the
/// slide, b = 1e12).
#[test]
fn the_collinear_start_solves_the_collinear_problem() {
    use super::eyring::{collinear_stress, film_integrals, starting_stress};
    for (a, b) in [(2.0, 0.3), (-20.0, 1e4), (50.0, -7.0), (400.0, 1e8)] {
        let angle: f64 = -2.1;
        let e = [angle.cos(), angle.sin()];
        let s = collinear_stress([b * e[0], b * e[1]], [a * e[0], a * e[1]]);
        let s0 = -0.5 * a + (b * a / (2.0 * (0.5 * a).sinh())).asinh();
        let expected = [s0 * e[0], s0 * e[1]];
        assert!(dist(s, expected) <= 1e-12 * (1.0 + a.abs()), "a {a}, b {b}: {s:?} vs {expected:?}");
        let int = film_integrals(s, [a * e[0], a * e[1]]);
        let r = dist(int.g, [b * e[0], b * e[1]]);
        assert!(r <= 1e-12 * (b.abs() + int.magnitude), "a {a}, b {b}: residual {r:e}");
    }
    let (b, a) = ([1e12, 0.0], [100.0 * 1f64.cos(), 100.0 * 1f64.sin()]);
    let solution = super::eyring::solve_dimensionless(b, a).unwrap();
    let (near, far) = (dist(collinear_stress(b, a), solution), dist(starting_stress(b, a), solution));
    assert!(near < 0.1 * far, "collinear start {near} from the solution, uniform start {far}");
}

/// Test 4c. Symmetries: t0(-g, -slide) = -t0(g, slide) (tau -> -tau leaves F unchanged),
/// and rotating (slide, g) by an angle rotates t0 (the law is isotropic).
#[test]
fn sign_flip_and_rotation_symmetry() {
    for (range, n) in [(0.0, 2.0), (5.0, 0.5), (30.0, 200.0)] {
        let pt = point(grad_for(range, 0.3), slide_for(n, -1.2));
        let t0 = disc_shear_stress(&RE, &pt).unwrap();
        let flipped = point([-pt.grad_p[0], -pt.grad_p[1]], [-pt.slide[0], -pt.slide[1]]);
        let tf = disc_shear_stress(&RE, &flipped).unwrap();
        assert!(dist(tf, [-t0[0], -t0[1]]) <= 1e-14 * norm(t0), "flip: {tf:?} vs {t0:?}");
        let scale = norm(t0) + H * norm(pt.grad_p);
        for angle in [0.5, 1.9, -2.7] {
            let rotated = point(rotate(pt.grad_p, angle), rotate(pt.slide, angle));
            let tr = disc_shear_stress(&RE, &rotated).unwrap();
            let err = dist(tr, rotate(t0, angle)) / scale;
            assert!(err < 1e-10, "range {range}, angle {angle}: {err:e}");
        }
    }
}

/// Test 5. The analytic Jacobian dG/dt0 matches central differences of G. Step 1e-5 tau0:
/// truncation ~ (1e-5)^2 / 6 and rounding ~ eps/1e-5, both < 1e-10 relative to |J|
/// (observed <= 5e-11), so 1e-8 is a safe and still sharp bound.
#[test]
fn jacobian_matches_finite_differences() {
    let cases = [
        ([0.0, 0.0], [0.01, -0.02]),   // tiny stresses: series branch everywhere
        ([0.3, 0.1], [-0.1, 0.2]),     // crosses |s| = 0.5 inside the film
        ([1.0, -2.0], [5.0, 3.0]),     // strongly non-Newtonian
        ([-12.0, 4.0], [30.0, -10.0]), // large gradient, many panels
    ];
    for (s0, a) in cases {
        let pt = point([a[0] * TAU0 / H, a[1] * TAU0 / H], [0.0; 2]);
        let t0 = [s0[0] * TAU0, s0[1] * TAU0];
        let j = film_slide(&RE, &pt, t0).unwrap().jacobian;
        let jmax = j.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        let d = 1e-5 * TAU0;
        for col in 0..2 {
            let (mut tp, mut tm) = (t0, t0);
            tp[col] += d;
            tm[col] -= d;
            let gp = film_slide(&RE, &pt, tp).unwrap().slide;
            let gm = film_slide(&RE, &pt, tm).unwrap().slide;
            for row in 0..2 {
                let fd = (gp[row] - gm[row]) / (2.0 * d);
                let err = (fd - j[row][col]).abs() / jmax;
                assert!(err < 1e-8, "s0 {s0:?}, a {a:?}, J[{row}][{col}] = {} vs fd {fd} ({err:e})", j[row][col]);
            }
        }
        assert_eq!(j[0][1], j[1][0]);
    }
}

/// The potential Phi* really is the potential of G*: central differences of Phi*
/// reproduce G* (this is what makes the line search on Psi* valid).
#[test]
fn potential_gradient_is_the_flow_integral() {
    for (s0, a) in [([0.2, -0.1], [0.4, 0.3]), ([2.0, 1.0], [-6.0, 2.0]), ([-8.0, 3.0], [20.0, 5.0])] {
        let g = film_integrals(s0, a).g;
        let d = 1e-5;
        for k in 0..2 {
            let (mut sp, mut sm) = (s0, s0);
            sp[k] += d;
            sm[k] -= d;
            let fd = (film_integrals(sp, a).phi - film_integrals(sm, a).phi) / (2.0 * d);
            assert!((fd - g[k]).abs() < 1e-7 * norm(g).max(1.0), "s0 {s0:?}: {fd} vs {}", g[k]);
        }
    }
}

/// Robustness: Newton converges over a wide parameter sweep (pseudo-random directions),
/// from weakly to extremely non-Newtonian and with large pressure gradients (up to
/// h|g|/tau0 = 400, i.e. stresses of +-200 tau0 and sinh ~ 1e86), and the returned t0
/// meets the solver's criterion |G - slide| <= 1e-12 (|slide| + integral |gammadot| dy)
/// (checked with 1e-11; the magnitude is taken from an independent Simpson rule).
#[test]
fn converges_over_wide_parameter_range() {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut angle = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 * std::f64::consts::TAU
    };
    for range in [0.0, 1e-3, 0.3, 3.0, 30.0, 150.0, 400.0] {
        for n in [0.0, 1e-8, 1e-3, 1.0, 1e3, 1e8] {
            let pt = point(grad_for(range, angle()), slide_for(n, angle()));
            let t0 = disc_shear_stress(&RE, &pt).unwrap_or_else(|e| panic!("range {range}, n {n}: {e}"));
            let g = film_slide(&RE, &pt, t0).unwrap().slide;
            let (_, mag) = simpson_slide(&RE, &pt, t0, 2000);
            let err = dist(g, pt.slide);
            assert!(err <= 1e-11 * (norm(pt.slide) + mag), "range {range}, n {n}: {err:e} vs {mag:e}");
        }
    }
}

/// Test 6. Invalid inputs are rejected with a message naming the field.
#[test]
fn invalid_inputs_name_the_field() {
    let good = point([1e12, 0.0], [1.0, 0.0]);
    let cases: [(ShearLaw, FilmPoint, &str); 8] = [
        (RE, FilmPoint { h: 0.0, ..good }, "h (film thickness"),
        (RE, FilmPoint { h: -1e-7, ..good }, "h (film thickness"),
        (ShearLaw::Newtonian, FilmPoint { h: f64::INFINITY, ..good }, "h (film thickness"),
        (RE, FilmPoint { eta: f64::NAN, ..good }, "eta (viscosity"),
        (ShearLaw::Newtonian, FilmPoint { eta: f64::INFINITY, ..good }, "eta (viscosity"),
        (ShearLaw::ReeEyring { tau0: 0.0 }, good, "tau0"),
        (RE, FilmPoint { grad_p: [0.0, f64::NAN], ..good }, "grad_p[1]"),
        (RE, FilmPoint { slide: [f64::NEG_INFINITY, 0.0], ..good }, "slide[0]"),
    ];
    for (law, pt, field) in cases {
        let err = disc_shear_stress(&law, &pt).unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, ShearError::Invalid { .. }) && msg.contains(field), "{msg}");
        assert!(film_slide(&law, &pt, [0.0; 2]).is_err());
    }
    let msg = film_slide(&RE, &good, [f64::NAN, 0.0]).unwrap_err().to_string();
    assert!(msg.contains("t0[0]"), "{msg}");
}

/// Stresses beyond ~700 tau0 overflow sinh: reported as such, not as a panic or NaN.
#[test]
fn overflow_and_no_convergence_are_reported() {
    let err = disc_shear_stress(&RE, &point(grad_for(2000.0, 0.0), [0.0; 2])).unwrap_err();
    assert!(matches!(err, ShearError::Overflow { .. }), "{err}");
    assert!(err.to_string().contains("overflow"), "{err}");
    let msg = ShearError::NoConvergence { iterations: 100, residual: 1e-3, tolerance: 1e-12 }.to_string();
    assert!(msg.contains("did not converge") && msg.contains("residual"), "{msg}");
}
