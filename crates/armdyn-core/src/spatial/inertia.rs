//! Spatial inertias: rigid-body (RBDA 2.13) and articulated-body (RBDA 7.1).

use super::{Force, Motion, Sym3, Xform, M3, V3};
use crate::real::Real;
use std::ops::{Add, AddAssign};

/// A rigid body's spatial inertia about a frame's origin, in that frame's axes:
///
/// ```text
/// I = [ ibar   h^x ]      m: mass,  h = m c: first moment (c: centre of mass),
///     [ -h^x   m 1 ]      ibar = I_c - m c^x c^x: rotational inertia about the origin.
/// ```
#[derive(Clone, Copy, Default, Debug, PartialEq)]
pub struct RigidInertia<T> {
    pub m: T,
    pub h: V3<T>,
    pub ibar: Sym3<T>,
}

impl<T: Real> RigidInertia<T> {
    #[inline(always)]
    pub fn zero() -> Self {
        RigidInertia { m: T::zero(), h: V3::zero(), ibar: Sym3::zero() }
    }
    /// From mass `m`, centre of mass `c` and the inertia tensor `i_c` about the centre
    /// of mass (all in the frame's axes): `ibar = i_c + m (|c|^2 1 - c c^T)`.
    pub fn from_mass_com(m: T, c: V3<T>, i_c: Sym3<T>) -> Self {
        let ibar = i_c - Sym3::outer_scaled(c, m);
        RigidInertia { m, h: c.scale(m), ibar: ibar.add_diag(m * c.dot(c)) }
    }
    #[inline(always)]
    pub fn splat(i: &RigidInertia<f64>) -> Self {
        RigidInertia { m: T::splat(i.m), h: V3::splat(i.h), ibar: Sym3::splat(i.ibar) }
    }
    /// Centre of mass `h / m` (zero for a massless body).
    pub fn com(&self) -> V3<T>
    where
        T: PartialEq,
    {
        if self.m == T::zero() {
            V3::zero()
        } else {
            self.h.scale(T::splat(1.0) / self.m)
        }
    }
    /// `I v`: `n = ibar w + h x v`, `f = m v - h x w`.
    #[inline(always)]
    pub fn mul_motion(&self, v: &Motion<T>) -> Force<T> {
        Force::new(self.ibar.mul_v(v.w) + self.h.cross(v.v), v.v.scale(self.m) - self.h.cross(v.w))
    }
    /// `^B X_A^T I ^B X_A`: this inertia (about B, B axes) expressed about A, in A axes.
    ///
    /// With `h' = E^T h`, `ibar' = E^T ibar E` (rotated to A's axes, still about B's
    /// origin), shifting by `r` (RBDA eq. 2.63 rearranged with `a^x b^x = b a^T - a.b 1`):
    /// `h_A = h' + m r`, `ibar_A = ibar' - (h' r^T + r h'^T) - m r r^T + (2 r.h' + m r.r) 1`.
    #[inline(always)]
    pub fn tr_transform(&self, x: &Xform<T>) -> Self {
        let (e, r, m) = (&x.e, x.r, self.m);
        let h1 = e.tr_mul_v(self.h);
        let ibar1 = self.ibar.rotate_tr(e);
        let ibar = ibar1 - Sym3::sym_outer(h1, r) - Sym3::outer_scaled(r, m);
        let diag = (r.dot(h1) + r.dot(h1)) + m * r.dot(r);
        RigidInertia { m, h: h1 + r.scale(m), ibar: ibar.add_diag(diag) }
    }

    /// The rotational inertia about the centre of mass `c = com()`, in this frame's
    /// axes: `I_c = ibar - m (|c|^2 1 - c c^T)` (the parallel-axis theorem, RBDA eq. 2.63
    /// read backwards; `ibar` itself for a massless body).
    pub fn rotational_inertia_about_com(&self) -> Sym3<T>
    where
        T: PartialEq,
    {
        let c = self.com();
        let h = c.scale(self.m);
        (self.ibar + Sym3::outer_scaled(c, self.m)).add_diag(-h.dot(c))
    }

    /// A body's inertia about frame A's origin in A's axes, from its mass `m`, centre of
    /// mass `c` and rotational inertia `i_c` about the centre of mass, both given in a
    /// frame B (`c` in B coordinates, `i_c` in B's axes), with `x = ^B X_A` (`E`, `r`).
    ///
    /// The same inertia as `from_mass_com(m, c, i_c).tr_transform(x)`, with one
    /// parallel-axis shift (RBDA eq. 2.63) at A's origin instead of a rotation of `h`
    /// and `ibar` followed by a shift: `c_A = r + E^T c`, `h = m c_A`,
    /// `ibar = E^T i_c E + m (|c_A|^2 1 - c_A c_A^T) = E^T i_c E + (h.c_A) 1 - h c_A^T`
    /// (116 flops against 156).
    #[inline(always)]
    pub fn from_com_transformed(m: T, c: V3<T>, i_c: &Sym3<T>, x: &Xform<T>) -> Self {
        Self::shifted_from_com(m, x.r + x.e.tr_mul_v(c), i_c.rotate_tr(&x.e))
    }

    /// The parallel-axis shift of the two constructors around it: mass `m` at `c_a`
    /// (A coordinates) with rotational inertia `rotated` about the centre of mass (A's
    /// axes): `h = m c_A`, `ibar = rotated + (h.c_A) 1 - h c_A^T`.
    #[inline(always)]
    fn shifted_from_com(m: T, c_a: V3<T>, rotated: Sym3<T>) -> Self {
        let h = c_a.scale(m);
        // h c_A^T, upper triangle (symmetric: h is parallel to c_A)
        let hc = Sym3 {
            xx: h.x * c_a.x,
            yy: h.y * c_a.y,
            zz: h.z * c_a.z,
            xy: h.x * c_a.y,
            xz: h.x * c_a.z,
            yz: h.y * c_a.z,
        };
        RigidInertia { m, h, ibar: (rotated - hc).add_diag(h.dot(c_a)) }
    }

    /// [`Self::from_com_transformed`] for `i_c = diag(d)`: `E^T diag(d) E` has entries
    /// `sum_l d_l E[l][j] E[l][k]` (39 flops instead of the 75 of a general `E^T i_c E`;
    /// 80 in all).
    #[inline(always)]
    pub fn from_com_transformed_diagonal(m: T, c: V3<T>, d: V3<T>, x: &Xform<T>) -> Self {
        let [e0, e1, e2] = x.e.rows;
        let (a0, a1, a2) = (e0.scale(d.x), e1.scale(d.y), e2.scale(d.z));
        let rotated = Sym3 {
            xx: a0.x * e0.x + a1.x * e1.x + a2.x * e2.x,
            yy: a0.y * e0.y + a1.y * e1.y + a2.y * e2.y,
            zz: a0.z * e0.z + a1.z * e1.z + a2.z * e2.z,
            xy: a0.x * e0.y + a1.x * e1.y + a2.x * e2.y,
            xz: a0.x * e0.z + a1.x * e1.z + a2.x * e2.z,
            yz: a0.y * e0.z + a1.y * e1.z + a2.y * e2.z,
        };
        Self::shifted_from_com(m, x.r + x.e.tr_mul_v(c), rotated)
    }
}

impl<T: Real> Add for RigidInertia<T> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        RigidInertia { m: self.m + o.m, h: self.h + o.h, ibar: self.ibar + o.ibar }
    }
}
impl<T: Real> AddAssign for RigidInertia<T> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

/// An articulated-body inertia: a symmetric 6x6 `[a b; b^T c]` (`a`, `c` symmetric).
#[derive(Clone, Copy, Default, Debug, PartialEq)]
pub struct ArticulatedInertia<T> {
    pub a: Sym3<T>,
    pub b: M3<T>,
    pub c: Sym3<T>,
}

impl<T: Real> ArticulatedInertia<T> {
    /// The rigid inertia as a 6x6: `a = ibar`, `b = h^x`, `c = m 1`.
    #[inline(always)]
    pub fn from_rigid(i: &RigidInertia<T>) -> Self {
        let z = T::zero();
        ArticulatedInertia {
            a: i.ibar,
            b: M3::skew(i.h),
            c: Sym3 { xx: i.m, yy: i.m, zz: i.m, xy: z, xz: z, yz: z },
        }
    }
    /// `I^A v`: `n = a w + b v`, `f = b^T w + c v`.
    #[inline(always)]
    pub fn mul_motion(&self, v: &Motion<T>) -> Force<T> {
        Force::new(self.a.mul_v(v.w) + self.b.mul_v(v.v), self.b.tr_mul_v(v.w) + self.c.mul_v(v.v))
    }
    /// Column `j` (0..6) of the 6x6 matrix, as a force (`I^A S` for an axis-aligned `S`).
    #[inline(always)]
    pub fn col(&self, j: usize) -> Force<T> {
        if j < 3 {
            // column j of b^T is row j of b
            Force::new(self.a.col(j), self.b.rows[j])
        } else {
            Force::new(self.b.col(j - 3), self.c.col(j - 3))
        }
    }
    /// `self - u u^T dinv` (the rank-1 update of RBDA Table 7.1, `I^a = I^A - U U^T / d`).
    #[inline(always)]
    pub fn sub_outer(&self, u: &Force<T>, dinv: T) -> Self {
        let (n, f) = (u.n.scale(dinv), u.f);
        ArticulatedInertia {
            a: self.a - Sym3::outer_scaled(u.n, dinv),
            b: self.b - M3::outer(n, f),
            c: self.c - Sym3::outer_scaled(f, dinv),
        }
    }
    /// `^B X_A^T I ^B X_A`: this inertia (B) expressed in A.
    ///
    /// Rotate the blocks to A's axes (`a' = E^T a E`, ...), then shift by `r`:
    /// `[1 r^x; 0 1] [a' b'; b'^T c'] [1 0; -r^x 1]` =
    /// `[a' - K - K^T - P r^x,  b' + P;  ., c']` with `K = b' r^x`, `P = r^x c'`.
    #[inline(always)]
    pub fn tr_transform(&self, x: &Xform<T>) -> Self {
        let (e, r) = (&x.e, x.r);
        let et = e.transpose();
        let a1 = self.a.rotate_tr(e);
        let b1 = et.mul_m(&self.b).mul_m(e);
        let c1 = self.c.rotate_tr(e);
        // K = b' r^x: row i is (row i of b') x r.
        let k = M3::from_rows(b1.rows[0].cross(r), b1.rows[1].cross(r), b1.rows[2].cross(r));
        // P = r^x c': column j is r x (column j of c').
        let c1m = c1.to_m3();
        let p = M3::from_rows(r.cross(c1m.col(0)), r.cross(c1m.col(1)), r.cross(c1m.col(2))).transpose();
        // P r^x: row i is (row i of P) x r; symmetric, keep the upper triangle.
        let prx = M3::from_rows(p.rows[0].cross(r), p.rows[1].cross(r), p.rows[2].cross(r));
        let kk = Sym3 {
            xx: k.at(0, 0) + k.at(0, 0),
            yy: k.at(1, 1) + k.at(1, 1),
            zz: k.at(2, 2) + k.at(2, 2),
            xy: k.at(0, 1) + k.at(1, 0),
            xz: k.at(0, 2) + k.at(2, 0),
            yz: k.at(1, 2) + k.at(2, 1),
        };
        ArticulatedInertia { a: a1 - kk - Sym3::from_m3(&prx), b: b1 + p, c: c1 }
    }
}

impl<T: Real> Add for ArticulatedInertia<T> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        ArticulatedInertia { a: self.a + o.a, b: self.b + o.b, c: self.c + o.c }
    }
}
impl<T: Real> AddAssign for ArticulatedInertia<T> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}
