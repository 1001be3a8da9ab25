//! Dual numbers `re + du ε` (`ε² = 0`): the algorithms, generic over [`Real`], run on
//! them to give exact first derivatives along one direction (forward-mode automatic
//! differentiation) where no analytical derivative is written yet: the joints of
//! several coordinates (`algo/tangent_derivatives.rs`). Each operation carries the
//! derivative by the chain rule, so the result's `du` is the directional derivative to
//! rounding, not a finite difference.

use crate::real::{sin_cos, Real};
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// `re + du ε`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dual {
    pub re: f64,
    pub du: f64,
}

impl Dual {
    pub fn new(re: f64, du: f64) -> Self {
        Dual { re, du }
    }
}

impl Add for Dual {
    type Output = Dual;
    #[inline(always)]
    fn add(self, o: Dual) -> Dual {
        Dual::new(self.re + o.re, self.du + o.du)
    }
}
impl Sub for Dual {
    type Output = Dual;
    #[inline(always)]
    fn sub(self, o: Dual) -> Dual {
        Dual::new(self.re - o.re, self.du - o.du)
    }
}
impl Mul for Dual {
    type Output = Dual;
    #[inline(always)]
    fn mul(self, o: Dual) -> Dual {
        Dual::new(self.re * o.re, self.du * o.re + self.re * o.du)
    }
}
impl Div for Dual {
    type Output = Dual;
    #[inline(always)]
    fn div(self, o: Dual) -> Dual {
        let q = self.re / o.re;
        Dual::new(q, (self.du - q * o.du) / o.re)
    }
}
impl Neg for Dual {
    type Output = Dual;
    #[inline(always)]
    fn neg(self) -> Dual {
        Dual::new(-self.re, -self.du)
    }
}
impl AddAssign for Dual {
    #[inline(always)]
    fn add_assign(&mut self, o: Dual) {
        *self = *self + o;
    }
}
impl SubAssign for Dual {
    #[inline(always)]
    fn sub_assign(&mut self, o: Dual) {
        *self = *self - o;
    }
}
impl MulAssign for Dual {
    #[inline(always)]
    fn mul_assign(&mut self, o: Dual) {
        *self = *self * o;
    }
}

impl Real for Dual {
    /// One state: the lanes are the value (the derivative travels alongside).
    const LANES: usize = 1;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        Dual::new(x, 0.0)
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = sin_cos(self.re);
        (Dual::new(s, c * self.du), Dual::new(c, -s * self.du))
    }
    #[inline(always)]
    fn lane(self, _k: usize) -> f64 {
        self.re
    }
    #[inline(always)]
    fn set_lane(&mut self, _k: usize, x: f64) {
        *self = Dual::new(x, 0.0);
    }
    /// Coulomb friction's sign: constant away from 0, so its derivative is 0 (as the
    /// analytical derivatives take it).
    #[inline(always)]
    fn sign0(self) -> Self {
        Dual::new(f64::sign0(self.re), 0.0)
    }
}
