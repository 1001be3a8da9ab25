//! Plücker coordinate transforms (RBDA 2.8, Table 2.5 / 2.8).

use super::{Force, Motion, M3, V3};
use crate::real::Real;

/// `^B X_A`: the transform of motion vectors from frame A to frame B, stored as
/// Featherstone's `(E, r)`:
///
/// * `e`: rotation taking A coordinates to B coordinates (`E = R_AB^T`, where the
///   columns of `R_AB` are B's axes in A);
/// * `r`: position of B's origin in A coordinates.
///
/// As a 6x6 matrix `^B X_A = [E 0; -E r^x E]`, and for forces `^B X_A^* = [E -E r^x; 0 E]`.
#[derive(Clone, Copy, Default, Debug, PartialEq)]
pub struct Xform<T> {
    pub e: M3<T>,
    pub r: V3<T>,
}

impl<T: Real> Xform<T> {
    #[inline(always)]
    pub fn identity() -> Self {
        Xform { e: M3::identity(), r: V3::zero() }
    }
    /// From the pose of frame B in frame A: rotation `R_AB` (B's axes in A) and
    /// origin `p_AB`.
    #[inline(always)]
    pub fn from_pose(r_ab: &M3<T>, p_ab: V3<T>) -> Self {
        Xform { e: r_ab.transpose(), r: p_ab }
    }
    /// The pose of B in A: `(R_AB, p_AB)`.
    #[inline(always)]
    pub fn to_pose(&self) -> (M3<T>, V3<T>) {
        (self.e.transpose(), self.r)
    }
    #[inline(always)]
    pub fn splat(x: &Xform<f64>) -> Self {
        Xform { e: M3::splat(x.e), r: V3::splat(x.r) }
    }
    /// `^B X_A m`: `w' = E w`, `v' = E (v - r x w)`.
    #[inline(always)]
    pub fn apply_motion(&self, m: &Motion<T>) -> Motion<T> {
        Motion::new(self.e.mul_v(m.w), self.e.mul_v(m.v - self.r.cross(m.w)))
    }
    /// `^B X_A^* f`: `n' = E (n - r x f)`, `f' = E f`.
    #[inline(always)]
    pub fn apply_force(&self, f: &Force<T>) -> Force<T> {
        Force::new(self.e.mul_v(f.n - self.r.cross(f.f)), self.e.mul_v(f.f))
    }
    /// `^A X_B m` (the inverse): `w = E^T w'`, `v = E^T v' + r x w`.
    #[inline(always)]
    pub fn inv_apply_motion(&self, m: &Motion<T>) -> Motion<T> {
        let w = self.e.tr_mul_v(m.w);
        Motion::new(w, self.e.tr_mul_v(m.v) + self.r.cross(w))
    }
    /// `^B X_A^T f = ^A X_B^* f`: a force in B expressed in A:
    /// `f = E^T f'`, `n = E^T n' + r x f`.
    #[inline(always)]
    pub fn tr_apply_force(&self, f: &Force<T>) -> Force<T> {
        let ff = self.e.tr_mul_v(f.f);
        Force::new(self.e.tr_mul_v(f.n) + self.r.cross(ff), ff)
    }
    /// `^C X_A = self * x` where `self = ^C X_B`, `x = ^B X_A`:
    /// `E = E_CB E_BA`, `r = r_BA + E_BA^T r_CB`.
    #[inline(always)]
    pub fn compose(&self, x: &Xform<T>) -> Xform<T> {
        Xform { e: self.e.mul_m(&x.e), r: x.r + x.e.tr_mul_v(self.r) }
    }
}
