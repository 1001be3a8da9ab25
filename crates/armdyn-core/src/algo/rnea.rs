//! Inverse dynamics by the recursive Newton-Euler algorithm (RBDA Table 5.1).

use crate::data::Data;
use crate::model::Model;
use crate::real::Real;
use crate::spatial::{Force, Motion, RigidInertia};

/// `tau = M(q) qdd + C(q, qd) qd + g(q)`.
///
/// `q`, `qd`, `qdd`, `tau`: (nv,). Gravity enters as the base acceleration
/// `a_0 = [0; -g]` (RBDA 5.3). Writes `data.xup`, `data.v`, `data.a`, `data.f`.
#[inline(always)]
pub fn rnea<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], qd: &[T], qdd: &[T], tau: &mut [T]) {
    rnea_tree(model, data, q, qd, qdd, tau, None);
}

/// The RNEA over the movable joints: [`rnea`] when `base` is None (the base at rest, its
/// acceleration `a_0 = [0; -g]`); with `base = Some((v_B, a_B))` the base moves with
/// spatial velocity `v_B` and acceleration `a_B` (base frame, gravity's `-g` included),
/// and the sum of the forces the root bodies exert on the base, `sum ^B X_i^* f_i`
/// (base frame), is returned (zero without `base`). Slices as in [`rnea`].
#[inline(always)]
pub(crate) fn rnea_tree<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    q: &[T],
    qd: &[T],
    qdd: &[T],
    tau: &mut [T],
    base: Option<(Motion<T>, Motion<T>)>,
) -> Force<T> {
    let n = model.nv;
    assert!(q.len() == model.nq && qd.len() == n && qdd.len() == n && tau.len() == n, "state length");
    let a0 = Motion::new(crate::spatial::V3::splat(model.a0.w), crate::spatial::V3::splat(model.a0.v));
    // Forward pass: velocities, accelerations, and the net force on each body
    // f_i = I_i a_i + v_i x* I_i v_i (RBDA eq. 5.9).
    for i in 0..n {
        let kind = model.kind[i];
        let xup = model.xup(i, q);
        let (vp, a) = match (model.parent[i], &base) {
            (Some(p), _) => (xup.apply_motion(&data.v[p]), xup.apply_motion(&data.a[p])),
            (None, Some((vb, ab))) => (xup.apply_motion(vb), xup.apply_motion(ab)),
            (None, None) => (Motion::zero(), xup.apply_motion(&a0)),
        };
        let v = vp + kind.s_times(qd[i]);
        // the velocity product with the joint's parent velocity (joint_multi.rs)
        let vjp = model.joint_parent_velocity(i, &xup, vp, &data.vjp);
        data.vjp[i] = vjp;
        let a = a + kind.s_times(qdd[i]) + kind.v_cross_s(&vjp, qd[i]);
        let inertia = RigidInertia::splat(&model.inertia[i]);
        data.f[i] = inertia.mul_motion(&a) + v.cross_force(&inertia.mul_motion(&v));
        data.xup[i] = xup;
        data.v[i] = v;
        data.a[i] = a;
    }
    // Backward pass: tau_i = S_i^T f_i; f_lambda += ^i X_lambda^T f_i.
    let mut on_base = Force::zero();
    for i in (0..n).rev() {
        tau[i] = model.kind[i].s_dot(&data.f[i]);
        match model.parent[i] {
            Some(p) => {
                let fp = data.xup[i].tr_apply_force(&data.f[i]);
                data.f[p] += fp;
            }
            None if base.is_some() => on_base += data.xup[i].tr_apply_force(&data.f[i]),
            None => {}
        }
    }
    if model.has_joint_dynamics {
        add_joint_dynamics(model, qd, qdd, tau);
    }
    on_base
}

/// `tau_i += Ia_i qdd_i + Fv_i qd_i + Fc_i sign(qd_i) + offset_i` (docs/architecture.md), all (nv,).
#[inline(always)]
pub fn add_joint_dynamics<T: Real>(model: &Model, qd: &[T], qdd: &[T], tau: &mut [T]) {
    for i in 0..model.nv {
        let jd = &model.joint_dynamics[i];
        tau[i] += T::splat(jd.armature) * qdd[i]
            + T::splat(jd.viscous) * qd[i]
            + T::splat(jd.coulomb) * qd[i].sign0()
            + T::splat(jd.offset);
    }
}

/// Gravity torques `g(q) = rnea(q, 0, 0)`. `q`, `g`: (nv,).
#[inline(always)]
pub fn gravity<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], g: &mut [T]) {
    let zeros = std::mem::take(&mut data.zeros);
    rnea(model, data, q, &zeros, &zeros, g);
    data.zeros = zeros;
}

/// Nonlinear effects `h(q, qd) = C(q, qd) qd + g(q) = rnea(q, qd, 0)`. All (nv,).
#[inline(always)]
pub fn bias<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], qd: &[T], h: &mut [T]) {
    let zeros = std::mem::take(&mut data.zeros);
    rnea(model, data, q, qd, &zeros, h);
    data.zeros = zeros;
}
