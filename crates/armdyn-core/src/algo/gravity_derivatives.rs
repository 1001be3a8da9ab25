//! `dg/dq`, the derivative of the gravity torques `g(q) = rnea(q, 0, 0)`: the
//! `rnea_derivatives` recursion (Carpentier & Mansard, RSS 2018) with `v = 0`,
//! `qdd = 0`. Every body then has the base-frame acceleration `a_0 = [0; -g]`, so
//! `F_i = I^c_i a_0`, `dA_i = a_0 x J_i`, and the `B` terms vanish:
//!
//! ```text
//! dg_j/dq_i = J_j^T (J_i x* F_i + I^c_i dA_i)   j = i or an ancestor of i
//! dg_i/dq_j = (I^c_i J_i)^T dA_j                j a strict ancestor of i
//! ```

use crate::algo::kinematics::{update_x0, update_xup};
use crate::data::Data;
use crate::deriv_data::DerivData;
use crate::model::Model;
use crate::real::Real;
use crate::spatial::{Motion, RigidInertia, V3};

/// `dg/dq` (nv, nv) row-major in `dg_dq` (`[i * nv + j] = d g_i / d q_j`). `q`: (nv,).
#[inline(always)]
pub fn gravity_derivatives<T: Real>(model: &Model, data: &mut Data<T>, dd: &mut DerivData<T>, q: &[T], dg_dq: &mut [T]) {
    let n = model.nv;
    assert!(q.len() == model.nq && dg_dq.len() == n * n, "argument size");
    update_xup(model, data, q);
    update_x0(model, data);
    let a0 = Motion::new(V3::splat(model.a0.w), V3::splat(model.a0.v));
    for i in 0..n {
        let x0 = data.x0[i];
        let s = model.kind[i].s_in(&x0);
        dd.s[i] = s;
        dd.dadq[i] = a0.cross_motion(&s);
        dd.ic[i] = RigidInertia::splat(&model.inertia[i]).tr_transform(&x0);
    }
    for i in (0..n).rev() {
        if let Some(p) = model.parent[i] {
            let ic = dd.ic[i];
            dd.ic[p] += ic;
        }
    }
    dg_dq.fill(T::zero());
    for i in 0..n {
        let (s, ic) = (dd.s[i], dd.ic[i]);
        let fa = ic.mul_motion(&s);
        let fq = s.cross_force(&ic.mul_motion(&a0)) + ic.mul_motion(&dd.dadq[i]);
        dg_dq[i * n + i] = s.dot(&fq);
        let mut a = model.parent[i];
        while let Some(j) = a {
            dg_dq[j * n + i] = dd.s[j].dot(&fq);
            dg_dq[i * n + j] = dd.dadq[j].dot(&fa);
            a = model.parent[j];
        }
    }
}
