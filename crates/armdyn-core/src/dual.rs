//! Dual numbers `re + sum_k du_k ε_k` (`ε_j ε_k = 0`): the algorithms, generic over
//! [`Real`], run on them to give exact first derivatives along `N` directions at once
//! (forward-mode automatic differentiation) where no analytical derivative is written
//! yet: the joints of several coordinates (`algo/tangent_derivatives.rs`). Each operation
//! carries the derivatives by the chain rule, so `du[k]` is the derivative along
//! direction `k` to rounding, not a finite difference; the value is computed once for
//! all `N` (loops over `du` that LLVM vectorises).

use crate::real::{sin_cos, Real};
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// `re + sum_k du[k] ε_k`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dual<const N: usize> {
    pub re: f64,
    pub du: [f64; N],
}

impl<const N: usize> Default for Dual<N> {
    fn default() -> Self {
        Dual { re: 0.0, du: [0.0; N] }
    }
}

impl<const N: usize> Dual<N> {
    /// A constant: every derivative zero.
    #[inline(always)]
    pub fn constant(re: f64) -> Self {
        Dual { re, du: [0.0; N] }
    }
    #[inline(always)]
    fn map(self, re: f64, f: impl Fn(f64) -> f64) -> Self {
        Dual { re, du: self.du.map(f) }
    }
}

impl<const N: usize> Add for Dual<N> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Dual { re: self.re + o.re, du: std::array::from_fn(|k| self.du[k] + o.du[k]) }
    }
}
impl<const N: usize> Sub for Dual<N> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Dual { re: self.re - o.re, du: std::array::from_fn(|k| self.du[k] - o.du[k]) }
    }
}
// the product and quotient rules use + and - (not a slip: clippy's suspicious_arithmetic_impl)
#[allow(clippy::suspicious_arithmetic_impl)]
impl<const N: usize> Mul for Dual<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Dual { re: self.re * o.re, du: std::array::from_fn(|k| self.du[k] * o.re + self.re * o.du[k]) }
    }
}
#[allow(clippy::suspicious_arithmetic_impl)]
impl<const N: usize> Div for Dual<N> {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        let q = self.re / o.re;
        Dual { re: q, du: std::array::from_fn(|k| (self.du[k] - q * o.du[k]) / o.re) }
    }
}
impl<const N: usize> Neg for Dual<N> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self.map(-self.re, |d| -d)
    }
}
impl<const N: usize> AddAssign for Dual<N> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}
impl<const N: usize> SubAssign for Dual<N> {
    #[inline(always)]
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}
impl<const N: usize> MulAssign for Dual<N> {
    #[inline(always)]
    fn mul_assign(&mut self, o: Self) {
        *self = *self * o;
    }
}

impl<const N: usize> Real for Dual<N> {
    /// One state: the lanes are the value (the derivatives travel alongside).
    const LANES: usize = 1;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        Dual::constant(x)
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = sin_cos(self.re);
        (self.map(s, |d| c * d), self.map(c, |d| -s * d))
    }
    #[inline(always)]
    fn lane(self, _k: usize) -> f64 {
        self.re
    }
    #[inline(always)]
    fn set_lane(&mut self, _k: usize, x: f64) {
        *self = Dual::constant(x);
    }
    /// Coulomb friction's sign: constant away from 0, so its derivative is 0 (as the
    /// analytical derivatives take it).
    #[inline(always)]
    fn sign0(self) -> Self {
        Dual::constant(f64::sign0(self.re))
    }
}
