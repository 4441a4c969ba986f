//! Forward-mode dual numbers carrying a value and its gradient with respect to the two gap
//! components.
//!
//! Mixed-mode laws whose damage depends on the mode mixity (bilinear Camanho–Dávila, its bridging
//! superposition) have long chains of derivatives; writing them by hand is where tangents go wrong.
//! Propagating `[∂/∂u_n, ∂/∂u_t]` alongside every value keeps the tangent exact, costs a few extra
//! multiplications and allocates nothing.

use std::ops::{Add, Div, Mul, Sub};

/// A value with its gradient `[∂/∂u_n, ∂/∂u_t]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Dual {
    /// The value.
    pub v: f64,
    /// Its gradient with respect to the gap.
    pub g: [f64; 2],
}

impl Dual {
    /// A quantity that does not depend on the gap.
    pub fn constant(v: f64) -> Self {
        Dual { v, g: [0.0, 0.0] }
    }

    /// A value with an explicit gradient.
    pub fn new(v: f64, g: [f64; 2]) -> Self {
        Dual { v, g }
    }

    fn chain(self, v: f64, dv: f64) -> Self {
        Dual { v, g: [dv * self.g[0], dv * self.g[1]] }
    }

    /// Square root; the derivative is taken as zero at zero (callers only take roots of sums of
    /// squares, whose gradient vanishes there too).
    pub fn sqrt(self) -> Self {
        let r = self.v.sqrt();
        let dr = if r > 0.0 { 0.5 / r } else { 0.0 };
        self.chain(r, dr)
    }

    /// `self^p`. At a zero base the derivative is taken as zero: bases here are non-negative
    /// quantities with a minimum (zero gradient) at zero, and `p > 1/2` is enforced by validation,
    /// so the composite derivative vanishes there.
    pub fn powf(self, p: f64) -> Self {
        if self.v <= 0.0 {
            return Dual::constant(0.0);
        }
        // Pure mode II (a mixity of exactly one, every point of an ENF) skips the library call,
        // which returns exactly one there anyway.
        let r = if self.v == 1.0 { 1.0 } else { self.v.powf(p) };
        self.chain(r, p * r / self.v)
    }

    /// `1 / self`.
    pub fn recip(self) -> Self {
        let r = 1.0 / self.v;
        self.chain(r, -r * r)
    }
}

impl Add for Dual {
    type Output = Dual;
    fn add(self, o: Dual) -> Dual {
        Dual { v: self.v + o.v, g: [self.g[0] + o.g[0], self.g[1] + o.g[1]] }
    }
}

impl Sub for Dual {
    type Output = Dual;
    fn sub(self, o: Dual) -> Dual {
        Dual { v: self.v - o.v, g: [self.g[0] - o.g[0], self.g[1] - o.g[1]] }
    }
}

impl Mul for Dual {
    type Output = Dual;
    fn mul(self, o: Dual) -> Dual {
        Dual { v: self.v * o.v, g: [self.g[0] * o.v + self.v * o.g[0], self.g[1] * o.v + self.v * o.g[1]] }
    }
}

impl Div for Dual {
    type Output = Dual;
    fn div(self, o: Dual) -> Dual {
        let inv = 1.0 / o.v;
        let q = self.v * inv;
        Dual { v: q, g: [(self.g[0] - q * o.g[0]) * inv, (self.g[1] - q * o.g[1]) * inv] }
    }
}

impl Add<f64> for Dual {
    type Output = Dual;
    fn add(self, c: f64) -> Dual {
        Dual { v: self.v + c, g: self.g }
    }
}

impl Sub<Dual> for f64 {
    type Output = Dual;
    fn sub(self, o: Dual) -> Dual {
        Dual { v: self - o.v, g: [-o.g[0], -o.g[1]] }
    }
}

impl Mul<f64> for Dual {
    type Output = Dual;
    fn mul(self, c: f64) -> Dual {
        Dual { v: self.v * c, g: [self.g[0] * c, self.g[1] * c] }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gradients_of_a_composite_match_hand_derivatives() {
        // f(x, y) = sqrt(x² + y²) / (1 + x y)
        let (x, y) = (0.7, -1.3);
        let dx = Dual::new(x, [1.0, 0.0]);
        let dy = Dual::new(y, [0.0, 1.0]);
        let f = (dx * dx + dy * dy).sqrt() / (dx * dy + 1.0);
        let r = (x * x + y * y).sqrt();
        let den = 1.0 + x * y;
        let fx = x / r / den - r * y / (den * den);
        let fy = y / r / den - r * x / (den * den);
        assert!((f.v - r / den).abs() < 1e-15);
        assert!((f.g[0] - fx).abs() < 1e-13 * fx.abs() && (f.g[1] - fy).abs() < 1e-13 * fy.abs());
        let p = dx.powf(2.5);
        assert!((p.g[0] - 2.5 * x.powf(1.5)).abs() < 1e-14);
        let q = (1.0 - dx).recip() * 3.0;
        assert!((q.g[0] - 3.0 / (1.0 - x).powi(2)).abs() < 1e-13);
        assert_eq!(Dual::constant(0.0).powf(1.5).g, [0.0, 0.0]);
    }
}
