//! Joint models. Every movable joint is re-framed at model build so that it moves
//! about (revolute) or along (prismatic) the z axis of its placement frame; the motion
//! subspace `S` is then a constant unit vector and the products with it below pick
//! components instead of multiplying by zeros (RBDA 4.4, Table 4.1 `Rz`/`Pz`).

use crate::real::Real;
use crate::spatial::{ArticulatedInertia, Force, Motion, RigidInertia, Xform, M3, V3};

/// A movable joint's type after re-framing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation by q about z: `S = [0 0 1 0 0 0]^T`.
    RevoluteZ,
    /// Translation by q along z: `S = [0 0 0 0 0 1]^T`.
    PrismaticZ,
}

impl JointKind {
    /// `S` as a motion vector.
    #[inline(always)]
    pub fn s<T: Real>(self) -> Motion<T> {
        self.s_times(T::splat(1.0))
    }

    /// `S x` for a joint-space scalar `x` (velocity, acceleration).
    #[inline(always)]
    pub fn s_times<T: Real>(self, x: T) -> Motion<T> {
        let z = T::zero();
        match self {
            JointKind::RevoluteZ => Motion::new(V3::new(z, z, x), V3::zero()),
            JointKind::PrismaticZ => Motion::new(V3::zero(), V3::new(z, z, x)),
        }
    }

    /// `^A X_B S`: the axis expressed in frame A, for `x = ^B X_A` (B the body frame):
    /// `w = E^T S_w`, `v = E^T S_v + r x w` (as `Xform::inv_apply_motion`), with
    /// `E^T e_z` = row 2 of `E` picked instead of multiplied out.
    #[inline(always)]
    pub fn s_in<T: Real>(self, x: &Xform<T>) -> Motion<T> {
        let ez = x.e.rows[2];
        match self {
            JointKind::RevoluteZ => Motion::new(ez, x.r.cross(ez)),
            JointKind::PrismaticZ => Motion::new(V3::zero(), ez),
        }
    }

    /// `S^T f`: the component of a force along the joint's motion.
    #[inline(always)]
    pub fn s_dot<T: Real>(self, f: &Force<T>) -> T {
        match self {
            JointKind::RevoluteZ => f.n.z,
            JointKind::PrismaticZ => f.f.z,
        }
    }

    /// `v x (S x)`: the velocity-product term of RBDA eq. 5.7 / Table 5.1 (`v_i x v_J`).
    #[inline(always)]
    pub fn v_cross_s<T: Real>(self, v: &Motion<T>, x: T) -> Motion<T> {
        // w x (0,0,x) = (w.y x, -w.x x, 0)
        let z = T::zero();
        let cross_ez = |a: V3<T>| V3::new(a.y * x, -(a.x * x), z);
        match self {
            JointKind::RevoluteZ => Motion::new(cross_ez(v.w), cross_ez(v.v)),
            JointKind::PrismaticZ => Motion::new(V3::zero(), cross_ez(v.w)),
        }
    }

    /// `I S` for a rigid inertia: `[ibar e_z; -h x e_z]` or `[h x e_z; m e_z]`.
    #[inline(always)]
    pub fn rigid_inertia_s<T: Real>(self, i: &RigidInertia<T>) -> Force<T> {
        let z = T::zero();
        // h x e_z = (h.y, -h.x, 0)
        match self {
            JointKind::RevoluteZ => Force::new(i.ibar.col(2), V3::new(-i.h.y, i.h.x, z)),
            JointKind::PrismaticZ => Force::new(V3::new(i.h.y, -i.h.x, z), V3::new(z, z, i.m)),
        }
    }

    /// `U = I^A S` for an articulated inertia: one of its columns.
    #[inline(always)]
    pub fn articulated_inertia_s<T: Real>(self, ia: &ArticulatedInertia<T>) -> Force<T> {
        match self {
            JointKind::RevoluteZ => ia.col(2),
            JointKind::PrismaticZ => ia.col(5),
        }
    }

    /// `^i X_{lambda(i)} = X_J(q) X_T` (RBDA Table 5.1 `jcalc`), with `xtree` = `X_T`, the
    /// transform from the parent body's frame to the joint's placement frame.
    ///
    /// Revolute: `X_J = rot(Rz(q)^T)`, so `E = Rz(q)^T E_T` (rows of `E_T` mixed by c, s)
    /// and `r = r_T`. Prismatic: `X_J = xlt(q e_z)`, so `E = E_T`, `r = r_T + q E_T^T e_z`.
    #[inline(always)]
    pub fn xup<T: Real>(self, xtree: &Xform<f64>, q: T) -> Xform<T> {
        let [e0, e1, e2] = xtree.e.rows;
        let (e0, e1, e2) = (V3::<T>::splat(e0), V3::<T>::splat(e1), V3::<T>::splat(e2));
        match self {
            JointKind::RevoluteZ => {
                let (s, c) = q.sin_cos();
                Xform {
                    e: M3::from_rows(e0.scale(c) + e1.scale(s), e1.scale(c) - e0.scale(s), e2),
                    r: V3::splat(xtree.r),
                }
            }
            JointKind::PrismaticZ => {
                Xform { e: M3::from_rows(e0, e1, e2), r: V3::<T>::splat(xtree.r) + e2.scale(q) }
            }
        }
    }
}
