//! Forward-mode dual numbers with a fixed-size gradient.
//!
//! A [`Dual<N>`] carries a value `v` and the gradient `d` of that value with respect to
//! `N` independent unknowns. Seeding the unknowns with [`Dual::variable`] and evaluating
//! a residual with ordinary arithmetic gives the residual and its exact Jacobian row in
//! one pass (no finite differences, no hand-written derivatives to keep in sync).
//!
//! Rules (x = (x.v, x.d), y = (y.v, y.d)):
//! - x + y = (x.v + y.v, x.d + y.d), x * y = (x.v y.v, x.v y.d + y.v x.d),
//!   x / y = (x.v / y.v, (x.d y.v - x.v y.d) / y.v^2);
//! - scalar laws through [`Dual::chain`]: f(x) = (f(x.v), f'(x.v) x.d), used for
//!   `powi`, `sqrt`, `exp`, `ln` and for the lubricant laws eta(P), rho(P).

use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// Value and gradient with respect to `N` unknowns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dual<const N: usize> {
    /// Value.
    pub v: f64,
    /// Gradient: `d[k]` = d(value)/d(unknown k).
    pub d: [f64; N],
}

impl<const N: usize> Default for Dual<N> {
    fn default() -> Self {
        Self::constant(0.0)
    }
}

impl<const N: usize> From<f64> for Dual<N> {
    fn from(v: f64) -> Self {
        Self::constant(v)
    }
}

impl<const N: usize> Dual<N> {
    /// A constant (zero gradient).
    pub fn constant(v: f64) -> Self {
        Self { v, d: [0.0; N] }
    }

    /// The unknown number `i` with value `v` (gradient = unit vector e_i).
    pub fn variable(v: f64, i: usize) -> Self {
        let mut d = [0.0; N];
        d[i] = 1.0;
        Self { v, d }
    }

    /// Apply a scalar law given its value `f = f(x.v)` and derivative `df = f'(x.v)`:
    /// returns (f, df * x.d).
    pub fn chain(self, f: f64, df: f64) -> Self {
        let mut d = self.d;
        for e in d.iter_mut() {
            *e *= df;
        }
        Self { v: f, d }
    }

    /// Integer power x^n (n may be negative or zero).
    pub fn powi(self, n: i32) -> Self {
        if n == 0 {
            return Self::constant(1.0);
        }
        let f = self.v.powi(n);
        let df = n as f64 * self.v.powi(n - 1);
        self.chain(f, df)
    }

    /// Square root (derivative 1/(2 sqrt x); infinite at x = 0).
    pub fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        self.chain(s, 0.5 / s)
    }

    /// Exponential.
    pub fn exp(self) -> Self {
        let e = self.v.exp();
        self.chain(e, e)
    }

    /// Natural logarithm.
    pub fn ln(self) -> Self {
        self.chain(self.v.ln(), 1.0 / self.v)
    }

    /// 1/x.
    pub fn recip(self) -> Self {
        let r = 1.0 / self.v;
        self.chain(r, -r * r)
    }
}

impl<const N: usize> Add for Dual<N> {
    type Output = Self;
    fn add(mut self, o: Self) -> Self {
        self.v += o.v;
        for (a, b) in self.d.iter_mut().zip(o.d.iter()) {
            *a += b;
        }
        self
    }
}

impl<const N: usize> Sub for Dual<N> {
    type Output = Self;
    fn sub(mut self, o: Self) -> Self {
        self.v -= o.v;
        for (a, b) in self.d.iter_mut().zip(o.d.iter()) {
            *a -= b;
        }
        self
    }
}

impl<const N: usize> Mul for Dual<N> {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        let mut d = [0.0; N];
        for k in 0..N {
            d[k] = self.v * o.d[k] + o.v * self.d[k];
        }
        Self { v: self.v * o.v, d }
    }
}

impl<const N: usize> Div for Dual<N> {
    type Output = Self;
    fn div(self, o: Self) -> Self {
        let inv = 1.0 / o.v;
        let q = self.v * inv;
        let mut d = [0.0; N];
        for k in 0..N {
            d[k] = (self.d[k] - q * o.d[k]) * inv;
        }
        Self { v: q, d }
    }
}

impl<const N: usize> Neg for Dual<N> {
    type Output = Self;
    fn neg(mut self) -> Self {
        self.v = -self.v;
        for a in self.d.iter_mut() {
            *a = -*a;
        }
        self
    }
}

impl<const N: usize> Add<f64> for Dual<N> {
    type Output = Self;
    fn add(mut self, c: f64) -> Self {
        self.v += c;
        self
    }
}

impl<const N: usize> Sub<f64> for Dual<N> {
    type Output = Self;
    fn sub(mut self, c: f64) -> Self {
        self.v -= c;
        self
    }
}

impl<const N: usize> Mul<f64> for Dual<N> {
    type Output = Self;
    fn mul(mut self, c: f64) -> Self {
        self.v *= c;
        for a in self.d.iter_mut() {
            *a *= c;
        }
        self
    }
}

impl<const N: usize> Div<f64> for Dual<N> {
    type Output = Self;
    fn div(self, c: f64) -> Self {
        self * (1.0 / c)
    }
}

impl<const N: usize> Add<Dual<N>> for f64 {
    type Output = Dual<N>;
    fn add(self, x: Dual<N>) -> Dual<N> {
        x + self
    }
}

impl<const N: usize> Sub<Dual<N>> for f64 {
    type Output = Dual<N>;
    fn sub(self, x: Dual<N>) -> Dual<N> {
        -x + self
    }
}

impl<const N: usize> Mul<Dual<N>> for f64 {
    type Output = Dual<N>;
    fn mul(self, x: Dual<N>) -> Dual<N> {
        x * self
    }
}

#[allow(clippy::suspicious_arithmetic_impl)] // c / x = c * (1/x)
impl<const N: usize> Div<Dual<N>> for f64 {
    type Output = Dual<N>;
    fn div(self, x: Dual<N>) -> Dual<N> {
        x.recip() * self
    }
}

impl<const N: usize> AddAssign for Dual<N> {
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

impl<const N: usize> SubAssign for Dual<N> {
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}

impl<const N: usize> MulAssign<f64> for Dual<N> {
    fn mul_assign(&mut self, c: f64) {
        *self = *self * c;
    }
}

impl<const N: usize> AddAssign<f64> for Dual<N> {
    fn add_assign(&mut self, c: f64) {
        self.v += c;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type D2 = Dual<2>;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-13 * (1.0 + b.abs())
    }

    fn check(x: D2, v: f64, d: [f64; 2]) {
        assert!(close(x.v, v), "value {} vs {}", x.v, v);
        assert!(close(x.d[0], d[0]), "d0 {} vs {}", x.d[0], d[0]);
        assert!(close(x.d[1], d[1]), "d1 {} vs {}", x.d[1], d[1]);
    }

    #[test]
    fn arithmetic_matches_hand_derivatives() {
        // x = 1.5, y = -0.7, unknowns (x, y)
        let (a, b) = (1.5, -0.7);
        let x = D2::variable(a, 0);
        let y = D2::variable(b, 1);
        check(x + y, a + b, [1.0, 1.0]);
        check(x - y, a - b, [1.0, -1.0]);
        check(x * y, a * b, [b, a]);
        check(x / y, a / b, [1.0 / b, -a / (b * b)]);
        check(-x, -a, [-1.0, 0.0]);
        check(x * 3.0 + 2.0, 3.0 * a + 2.0, [3.0, 0.0]);
        check(2.0 - y, 2.0 - b, [0.0, -1.0]);
        check(2.0 / y, 2.0 / b, [0.0, -2.0 / (b * b)]);
        check(y / 4.0, b / 4.0, [0.0, 0.25]);
        // f = x^2 y / (1 + x y): df/dx = (2 x y (1 + x y) - x^2 y * y) / (1 + x y)^2
        let f = x * x * y / (1.0 + x * y);
        let q = 1.0 + a * b;
        check(f, a * a * b / q, [(2.0 * a * b * q - a * a * b * b) / (q * q), (a * a * q - a * a * b * a) / (q * q)]);
    }

    #[test]
    fn elementary_functions_match_hand_derivatives() {
        let (a, b) = (1.3, 0.4);
        let x = D2::variable(a, 0);
        let y = D2::variable(b, 1);
        check(x.powi(3), a.powi(3), [3.0 * a * a, 0.0]);
        check(x.powi(-2), a.powi(-2), [-2.0 * a.powi(-3), 0.0]);
        check(x.powi(0), 1.0, [0.0, 0.0]);
        check(x.sqrt(), a.sqrt(), [0.5 / a.sqrt(), 0.0]);
        check(y.exp(), b.exp(), [0.0, b.exp()]);
        check(x.ln(), a.ln(), [1.0 / a, 0.0]);
        // exp(x y): d/dx = y exp(x y), d/dy = x exp(x y)
        let e = (a * b).exp();
        check((x * y).exp(), e, [b * e, a * e]);
        // sqrt(x^2 + y^2)
        let r = (a * a + b * b).sqrt();
        check((x * x + y * y).sqrt(), r, [a / r, b / r]);
        // ln(x / y)
        check((x / y).ln(), (a / b).ln(), [1.0 / a, -1.0 / b]);
    }

    #[test]
    fn chain_applies_a_scalar_law() {
        // Barus-like law eta = exp(19 u), u = x * y
        let (a, b) = (0.2, 0.3);
        let x = D2::variable(a, 0);
        let y = D2::variable(b, 1);
        let u = x * y;
        let eta = u.chain((19.0 * u.v).exp(), 19.0 * (19.0 * u.v).exp());
        let e = (19.0 * a * b).exp();
        check(eta, e, [19.0 * b * e, 19.0 * a * e]);
    }
}
