//! The joint torque regressor: `tau = Y(q, qd, qdd) pi`, inverse dynamics written
//! linear in the standard parameters (Atkeson, An and Hollerbach 1986; Khalil and
//! Dombre, *Modeling, Identification and Control of Robots*, 2002, ch. 12).
//!
//! Columns, for `nj` links (every description joint's child link, in joint order, fixed
//! joints included) and `nv` movable joints:
//!
//! * `10 nj` inertial columns, link by link, parameters in Pinocchio's order
//!   `[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]` with the inertia about the
//!   link frame's origin, in the link frame (docs/architecture.md);
//! * `4 nv` joint columns, joint by joint: `[qdd_i, qd_i, sign(qd_i), 1]`, the
//!   coefficients of the armature `Ia`, viscous `Fv`, Coulomb `Fc` and `offset`.
//!
//! The net force on body b is linear in its inertia: `f_b = I_b a_b + v_b x* I_b v_b`
//! (RBDA eq. 5.9). For each unit parameter of a link carried by body b, that force is
//! built with the unit inertia moved into b's frame, and carried up to every ancestor
//! j of b: `Y[j, col] = S_j^T (^j X_b)^* f` (the backward pass of RBDA Table 5.1,
//! column by column).

use crate::data::Data;
use crate::model::Model;
use crate::real::Real;
use crate::spatial::{Motion, RigidInertia, Sym3, Xform, V3};

/// Number of columns of the regressor: `10 (nlinks - 1) + 4 nv`.
pub fn regressor_columns(model: &Model) -> usize {
    10 * (model.nlinks() - 1) + 4 * model.nv
}

/// Unit inertial parameter `k` (0..10, the order above) as a spatial inertia.
fn unit_inertia(k: usize) -> RigidInertia<f64> {
    let mut i = RigidInertia::zero();
    let mut s = Sym3::zero();
    match k {
        0 => i.m = 1.0,
        1 => i.h = V3::new(1.0, 0.0, 0.0),
        2 => i.h = V3::new(0.0, 1.0, 0.0),
        3 => i.h = V3::new(0.0, 0.0, 1.0),
        4 => s.xx = 1.0,
        5 => s.xy = 1.0,
        6 => s.yy = 1.0,
        7 => s.xz = 1.0,
        8 => s.yz = 1.0,
        _ => s.zz = 1.0,
    }
    i.ibar = s;
    i
}

/// `Y(q, qd, qdd)`: (nv, [`regressor_columns`]) row-major in `y`. `q`, `qd`, `qdd`: (nv,).
///
/// Gravity enters as the base acceleration `a_0 = [0; -g]`, as in the RNEA, so that
/// `Y pi = rnea(q, qd, qdd)` with the joint dynamics included. Writes `data.xup`,
/// `data.v`, `data.a`.
#[inline(always)]
pub fn regressor<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], qd: &[T], qdd: &[T], y: &mut [T]) {
    let n = model.nv;
    let cols = regressor_columns(model);
    assert!(q.len() == model.nq && qd.len() == n && qdd.len() == n && y.len() == n * cols, "state length");
    // Forward pass of RBDA Table 5.1: v_i, a_i (gravity included).
    let a0 = Motion::new(V3::splat(model.a0.w), V3::splat(model.a0.v));
    for i in 0..n {
        let kind = model.kind[i];
        let xup = model.xup(i, q);
        let (vp, a) = match model.parent[i] {
            Some(p) => (xup.apply_motion(&data.v[p]), xup.apply_motion(&data.a[p])),
            None => (Motion::zero(), xup.apply_motion(&a0)),
        };
        let v = vp + kind.s_times(qd[i]);
        let vjp = model.joint_parent_velocity(i, &xup, vp, &data.vjp);
        data.vjp[i] = vjp;
        data.a[i] = a + kind.s_times(qdd[i]) + kind.v_cross_s(&vjp, qd[i]);
        data.v[i] = v;
        data.xup[i] = xup;
    }
    y.fill(T::zero());
    // Inertial columns, link by link (link 0 is the base: no columns).
    for l in 1..model.nlinks() {
        let link = model.links[l];
        let Some(b) = link.body else { continue }; // welded to the base: never moves
        let link_x_body = Xform::from_pose(&link.rotation, link.translation);
        let (v, a) = (data.v[b], data.a[b]);
        for k in 0..10 {
            let col = 10 * (l - 1) + k;
            // the unit parameter, given in the link frame, as an inertia in body b's frame
            let unit = RigidInertia::splat(&unit_inertia(k).tr_transform(&link_x_body));
            let mut f = unit.mul_motion(&a) + v.cross_force(&unit.mul_motion(&v));
            let mut j = b;
            loop {
                y[j * cols + col] = model.kind[j].s_dot(&f);
                match model.parent[j] {
                    Some(p) => {
                        f = data.xup[j].tr_apply_force(&f);
                        j = p;
                    }
                    None => break,
                }
            }
        }
    }
    // Joint columns: Ia qdd + Fv qd + Fc sign(qd) + offset.
    let first = 10 * (model.nlinks() - 1);
    for i in 0..n {
        let row = i * cols + first + 4 * i;
        y[row] = qdd[i];
        y[row + 1] = qd[i];
        y[row + 2] = qd[i].sign0();
        y[row + 3] = T::splat(1.0);
    }
}
