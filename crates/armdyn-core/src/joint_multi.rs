//! Joints of several coordinates (spherical, planar, free), in Pinocchio's layouts.
//!
//! Such a joint is built as a chain of 1-dof bodies, its *parts*, one per velocity
//! coordinate, all at the same place: the first (the *head*) carries the joint's whole
//! motion, computed from its configuration block `q[idx_q..idx_q + nq]`; every part is
//! then a revolute or prismatic joint about one axis of the moved joint frame, always at
//! coordinate 0, and the later parts (the *tails*) sit at constant re-framings of the
//! head (the core keeps each body's axis along z, `joint.rs`). The parts' motion
//! subspaces together are the joint's `S` in the child frame (constant there), so the
//! velocities, the CRBA, the ABA (whose massless parts hand their children's articulated
//! inertia on unchanged) and the Jacobians are the joint's own. One term differs: the
//! velocity product. The joint's is `v_i x (S qd)` = `v_p x (S qd)` with `v_p` the
//! parent's velocity in the child frame (Pinocchio's `c = 0` joints); a chain of parts
//! would give each part `v_k x S_k qd_k`, with the earlier parts' rates inside `v_k`. The
//! algorithms therefore take each part's velocity product with the velocity its joint's
//! parent has ([`crate::Model::joint_parent_velocity`]).
//!
//! Layouts (velocities in the child frame's axes):
//! * spherical: `q` = unit quaternion `x, y, z, w` (4), `v` = angular velocity (3);
//! * planar (the placement frame's x-y plane): `q` = `x, y, cos th, sin th` (4), `v` =
//!   `vx, vy, wz` (3);
//! * free: `q` = position (3) then unit quaternion (4), `v` = linear then angular (6).

use crate::algo::floating::quaternion_rotation;
use crate::joint::JointKind;
use crate::real::Real;
use crate::spatial::{Xform, M3, V3};

/// A joint of several coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MultiKind {
    Spherical,
    Planar,
    Free,
}

const EX: [f64; 3] = [1.0, 0.0, 0.0];
const EY: [f64; 3] = [0.0, 1.0, 0.0];
const EZ: [f64; 3] = [0.0, 0.0, 1.0];

impl MultiKind {
    /// Configuration coordinates.
    pub fn nq(self) -> usize {
        match self {
            MultiKind::Spherical | MultiKind::Planar => 4,
            MultiKind::Free => 7,
        }
    }

    /// The parts in the order of the velocity coordinates: each a 1-dof kind about (along)
    /// an axis of the joint frame.
    pub fn parts(self) -> &'static [(JointKind, [f64; 3])] {
        use JointKind::{PrismaticZ as P, RevoluteZ as R};
        match self {
            MultiKind::Spherical => &[(R, EX), (R, EY), (R, EZ)],
            MultiKind::Planar => &[(P, EX), (P, EY), (R, EZ)],
            MultiKind::Free => &[(P, EX), (P, EY), (P, EZ), (R, EX), (R, EY), (R, EZ)],
        }
    }

    /// The unit-length blocks of a configuration block: `(offset, length)` of the
    /// quaternion, or of the planar joint's `(cos, sin)`.
    pub fn unit_block(self) -> (usize, usize) {
        match self {
            MultiKind::Spherical => (0, 4),
            MultiKind::Planar => (2, 2),
            MultiKind::Free => (3, 4),
        }
    }

    /// The joint's motion at configuration `q` (its block, `nq` long): the child frame's
    /// axes (columns) and origin in the placement frame.
    #[inline(always)]
    pub fn motion<T: Real>(self, q: &[T]) -> (M3<T>, V3<T>) {
        match self {
            MultiKind::Spherical => (quaternion_rotation(q[0], q[1], q[2], q[3]), V3::zero()),
            MultiKind::Free => (quaternion_rotation(q[3], q[4], q[5], q[6]), V3::new(q[0], q[1], q[2])),
            MultiKind::Planar => {
                let (z, one, c, s) = (T::zero(), T::splat(1.0), q[2], q[3]);
                let r = M3::from_rows(V3::new(c, -s, z), V3::new(s, c, z), V3::new(z, z, one));
                (r, V3::new(q[0], q[1], z))
            }
        }
    }

    /// The head part's `^i X_lambda(i)`: the placement `xtree` (`^P X_parent`), the
    /// joint's motion at `q`, then the head's re-framing `frame_t` (`Ra^T`, z to the
    /// first part's axis): `E = Ra^T R_M^T E_T`, `r = r_T + E_T^T p_M`.
    #[inline(always)]
    pub fn head_xup<T: Real>(self, xtree: &Xform<f64>, frame_t: &M3<f64>, q: &[T]) -> Xform<T> {
        let (rm, pm) = self.motion(q);
        let et = M3::splat(xtree.e);
        let e = M3::splat(*frame_t).mul_m(&rm.transpose().mul_m(&et));
        Xform { e, r: V3::splat(xtree.r) + et.tr_mul_v(pm) }
    }
}
