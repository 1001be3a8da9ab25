//! Spatial motion vectors `[w; v]` (RBDA 2.2).

use super::{Force, V3};
use crate::real::Real;
use std::ops::{Add, AddAssign, Sub};

/// A spatial motion vector: angular part `w`, linear part `v` (velocity of the
/// body-fixed point at the frame origin). Velocities, accelerations, joint axes `S`.
#[derive(Clone, Copy, Default, Debug, PartialEq)]
pub struct Motion<T> {
    pub w: V3<T>,
    pub v: V3<T>,
}

impl<T: Real> Motion<T> {
    #[inline(always)]
    pub fn new(w: V3<T>, v: V3<T>) -> Self {
        Motion { w, v }
    }
    #[inline(always)]
    pub fn zero() -> Self {
        Motion::new(V3::zero(), V3::zero())
    }
    /// `self x m` — the motion cross product `crm(self) m` (RBDA eq. 2.31).
    #[inline(always)]
    pub fn cross_motion(&self, m: &Motion<T>) -> Motion<T> {
        Motion::new(self.w.cross(m.w), self.w.cross(m.v) + self.v.cross(m.w))
    }
    /// `self x* f` — the force cross product `crf(self) f = -crm(self)^T f` (RBDA eq. 2.32).
    #[inline(always)]
    pub fn cross_force(&self, f: &Force<T>) -> Force<T> {
        Force::new(self.w.cross(f.n) + self.v.cross(f.f), self.w.cross(f.f))
    }
    /// The scalar product with a force (power).
    #[inline(always)]
    pub fn dot(&self, f: &Force<T>) -> T {
        self.w.dot(f.n) + self.v.dot(f.f)
    }
    #[inline(always)]
    pub fn scale(&self, s: T) -> Self {
        Motion::new(self.w.scale(s), self.v.scale(s))
    }
    /// As `[w; v]`.
    #[inline(always)]
    pub fn to_array(&self) -> [T; 6] {
        [self.w.x, self.w.y, self.w.z, self.v.x, self.v.y, self.v.z]
    }
}

impl<T: Real> Add for Motion<T> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Motion::new(self.w + o.w, self.v + o.v)
    }
}
impl<T: Real> Sub for Motion<T> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Motion::new(self.w - o.w, self.v - o.v)
    }
}
impl<T: Real> AddAssign for Motion<T> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}
