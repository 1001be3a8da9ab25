//! Joint-space inertia matrix by the composite rigid-body algorithm (RBDA Table 6.2).

use crate::algo::kinematics::update_xup;
use crate::data::Data;
use crate::model::Model;
use crate::real::Real;
use crate::spatial::RigidInertia;

/// `M(q)`: the full symmetric (nv, nv) joint-space inertia matrix, row-major in `m`.
///
/// Composite inertias `I^c_i` are accumulated leaf to root (`I^c_lambda += X^T I^c_i X`),
/// then `F = I^c_i S_i` is carried up the ancestors `j` of `i`:
/// `H_ij = H_ji = S_j^T (^j X_i^* F)`. Entries of bodies on different branches are 0.
#[inline(always)]
pub fn crba<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], m: &mut [T]) {
    let n = model.nv;
    assert!(q.len() == n && m.len() == n * n, "state length");
    update_xup(model, data, q);
    for i in 0..n {
        data.ic[i] = RigidInertia::splat(&model.inertia[i]);
    }
    for i in (0..n).rev() {
        if let Some(p) = model.parent[i] {
            let ic = data.ic[i].tr_transform(&data.xup[i]);
            data.ic[p] += ic;
        }
    }
    m.fill(T::zero());
    for i in 0..n {
        let mut f = model.kind[i].rigid_inertia_s(&data.ic[i]);
        m[i * n + i] = model.kind[i].s_dot(&f);
        let mut j = i;
        while let Some(p) = model.parent[j] {
            f = data.xup[j].tr_apply_force(&f);
            j = p;
            let h = model.kind[j].s_dot(&f);
            m[i * n + j] = h;
            m[j * n + i] = h;
        }
    }
    // rotor inertias (armature) on the diagonal
    if model.has_joint_dynamics {
        for i in 0..n {
            m[i * n + i] += T::splat(model.joint_dynamics[i].armature);
        }
    }
}
