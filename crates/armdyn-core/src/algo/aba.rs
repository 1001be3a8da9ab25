//! Forward dynamics by the articulated-body algorithm (RBDA Table 7.1).

use crate::data::Data;
use crate::model::Model;
use crate::real::Real;
use crate::spatial::{ArticulatedInertia, Motion, RigidInertia, V3};

/// `qdd = M(q)^-1 (tau - C(q, qd) qd - g(q))`. `q`, `qd`, `tau`, `qdd`: (nv,).
///
/// Gravity enters as the base acceleration `a_0 = [0; -g]`. Bodies of zero
/// articulated inertia about their joint axis (`D_i = 0`) give inf/NaN, as M is then
/// singular.
#[inline(always)]
pub fn aba<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], qd: &[T], tau: &[T], qdd: &mut [T]) {
    let n = model.nv;
    assert!(q.len() == n && qd.len() == n && tau.len() == n && qdd.len() == n, "state length");
    // Pass 1 (root to leaves): velocities, velocity-product accelerations c_i,
    // I^A_i = I_i and p^A_i = v_i x* I_i v_i.
    for i in 0..n {
        let kind = model.kind[i];
        let xup = kind.xup(&model.xtree[i], q[i]);
        let vj = kind.s_times(qd[i]);
        let v = match model.parent[i] {
            Some(p) => xup.apply_motion(&data.v[p]) + vj,
            None => vj,
        };
        let inertia = RigidInertia::splat(&model.inertia[i]);
        data.c[i] = kind.v_cross_s(&v, qd[i]);
        data.ia[i] = ArticulatedInertia::from_rigid(&inertia);
        data.pa[i] = v.cross_force(&inertia.mul_motion(&v));
        data.xup[i] = xup;
        data.v[i] = v;
    }
    // Pass 2 (leaves to root): U_i = I^A_i S_i, D_i = S_i^T U_i, u_i = tau_i - S_i^T p^A_i;
    // the parent receives X^T (I^A - U U^T / D) X and X^T (p^A + I^a c + U u / D).
    for i in (0..n).rev() {
        let kind = model.kind[i];
        let u_col = kind.articulated_inertia_s(&data.ia[i]);
        // Joint dynamics: the rotor inertia Ia adds to D_i = S^T I^A S + Ia, and friction
        // and offset are torques the motor does not deliver to the link:
        // u_i = tau_i - Fv qd_i - Fc sign(qd_i) - offset - S^T p^A_i.
        let jd = &model.joint_dynamics[i];
        let d_inv = T::splat(1.0) / (kind.s_dot(&u_col) + T::splat(jd.armature));
        let mut u = tau[i] - kind.s_dot(&data.pa[i]);
        if model.has_joint_dynamics {
            u -= jd.passive_torque(qd[i]);
        }
        data.u_col[i] = u_col;
        data.d_inv[i] = d_inv;
        data.u[i] = u;
        if let Some(p) = model.parent[i] {
            let ia = data.ia[i].sub_outer(&u_col, d_inv);
            let pa = data.pa[i] + ia.mul_motion(&data.c[i]) + u_col.scale(u * d_inv);
            let xup = data.xup[i];
            let ia_p = ia.tr_transform(&xup);
            let pa_p = xup.tr_apply_force(&pa);
            data.ia[p] += ia_p;
            data.pa[p] += pa_p;
        }
    }
    // Pass 3 (root to leaves): a'_i = X a_lambda + c_i, qdd_i = (u_i - U_i^T a'_i) / D_i,
    // a_i = a'_i + S_i qdd_i.
    let a0 = Motion::new(V3::splat(model.a0.w), V3::splat(model.a0.v));
    for i in 0..n {
        let kind = model.kind[i];
        let ap = match model.parent[i] {
            Some(p) => data.xup[i].apply_motion(&data.a[p]),
            None => data.xup[i].apply_motion(&a0),
        };
        let a = ap + data.c[i];
        let qddi = (data.u[i] - a.dot(&data.u_col[i])) * data.d_inv[i];
        qdd[i] = qddi;
        data.a[i] = a + kind.s_times(qddi);
    }
}
