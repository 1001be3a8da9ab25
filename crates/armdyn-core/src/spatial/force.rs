//! Spatial force vectors `[n; f]` (RBDA 2.3).

use super::V3;
use crate::real::Real;
use std::ops::{Add, AddAssign, Sub, SubAssign};

/// A spatial force vector: moment `n` about the frame origin, resultant `f`.
/// Also used for momenta and for the columns `U = I^A S` of articulated inertias.
#[derive(Clone, Copy, Default, Debug, PartialEq)]
pub struct Force<T> {
    pub n: V3<T>,
    pub f: V3<T>,
}

impl<T: Real> Force<T> {
    #[inline(always)]
    pub fn new(n: V3<T>, f: V3<T>) -> Self {
        Force { n, f }
    }
    #[inline(always)]
    pub fn zero() -> Self {
        Force::new(V3::zero(), V3::zero())
    }
    #[inline(always)]
    pub fn scale(&self, s: T) -> Self {
        Force::new(self.n.scale(s), self.f.scale(s))
    }
    /// As `[n; f]`.
    #[inline(always)]
    pub fn to_array(&self) -> [T; 6] {
        [self.n.x, self.n.y, self.n.z, self.f.x, self.f.y, self.f.z]
    }
}

impl<T: Real> Add for Force<T> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Force::new(self.n + o.n, self.f + o.f)
    }
}
impl<T: Real> Sub for Force<T> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Force::new(self.n - o.n, self.f - o.f)
    }
}
impl<T: Real> AddAssign for Force<T> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}
impl<T: Real> SubAssign for Force<T> {
    #[inline(always)]
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}
