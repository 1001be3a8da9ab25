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
    crba_tree(model, data, q, m, 0);
}

/// [`crba`] into the lower-right (nv, nv) block of an (off + nv)-square matrix `m`
/// (row-major), which is zeroed first. With `off = 6` (a floating base, `algo::floating`)
/// it also writes the base-joint columns: rows 0..6 of column `6 + i` (and row `6 + i`
/// of columns 0..6) hold `F = ^B X_i^* I^c_i S_i` carried on to the base, ordered
/// `[f; n]` (force, then moment: the floating base's velocity is `[v; w]`); and it
/// returns the composite inertia of the tree the base carries, `sum ^B X_r^T I^c_r ^B X_r`
/// over the root bodies `r` (base frame; zero when `off = 0`).
#[inline(always)]
pub(crate) fn crba_tree<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], m: &mut [T], off: usize) -> RigidInertia<T> {
    let n = model.nv;
    let stride = n + off;
    assert!(q.len() == model.nq && m.len() == stride * stride && (off == 0 || off == 6), "state length");
    update_xup(model, data, q);
    for i in 0..n {
        data.ic[i] = RigidInertia::splat(&model.inertia[i]);
    }
    let mut on_base = RigidInertia::zero();
    for i in (0..n).rev() {
        match model.parent[i] {
            Some(p) => {
                let ic = data.ic[i].tr_transform(&data.xup[i]);
                data.ic[p] += ic;
            }
            None if off > 0 => on_base += data.ic[i].tr_transform(&data.xup[i]),
            None => {}
        }
    }
    m.fill(T::zero());
    for i in 0..n {
        let mut f = model.kind[i].rigid_inertia_s(&data.ic[i]);
        let row = (off + i) * stride;
        m[row + off + i] = model.kind[i].s_dot(&f);
        let mut j = i;
        while let Some(p) = model.parent[j] {
            f = data.xup[j].tr_apply_force(&f);
            j = p;
            let h = model.kind[j].s_dot(&f);
            m[row + off + j] = h;
            m[(off + j) * stride + off + i] = h;
        }
        if off > 0 {
            let fb = data.xup[j].tr_apply_force(&f);
            for (k, h) in fb.f.to_array().into_iter().chain(fb.n.to_array()).enumerate() {
                m[row + k] = h;
                m[k * stride + off + i] = h;
            }
        }
    }
    // rotor inertias (armature) on the diagonal
    if model.has_joint_dynamics {
        for i in 0..n {
            m[(off + i) * stride + off + i] += T::splat(model.joint_dynamics[i].armature);
        }
    }
    on_base
}
