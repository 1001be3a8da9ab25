//! The inverse of the joint-space inertia matrix without forming M, by the
//! articulated-body recursion applied to unit torques: J. Carpentier, "Analytical
//! inverse of the joint space inertia matrix" (2018, the algorithm behind Pinocchio's
//! `computeMinverse`); also Carpentier & Mansard, RSS 2018, Section IV.C.
//!
//! Column c of M^-1 is the ABA's `qdd` for `tau = e_c` with no velocity and no gravity
//! (RBDA Table 7.1 with `c_i = 0`, `p^A_i = 0`). The bias forces of all columns are
//! carried together: `F_i` (6 x nv) is `p^A_i` per column, non-zero only for the columns
//! of i's subtree, and `P_i` (6 x nv) the accelerations `a_i` per column:
//!
//! ```text
//! backward (i = n..1):  Minv[i, i] = 1/D_i,  Minv[i, c] = -S_i^T F_i[:, c] / D_i (c below i)
//!                       F_lambda[:, c] += X_i^T (F_i[:, c] + U_i Minv[i, c])   (c in subtree(i))
//! forward (i = 1..n):   Minv[i, c] -= U_i^T X_i P_lambda[:, c] / D_i,  P_i[:, c] = X_i P_lambda[:, c] + S_i Minv[i, c]
//! ```
//!
//! The forward pass only fills the columns `c >= i` (the upper triangle: with parents
//! before children, `P_lambda[:, c]` is ready for them); the rest follows by symmetry.

use crate::algo::kinematics::update_xup;
use crate::data::Data;
use crate::deriv_data::DerivData;
use crate::model::Model;
use crate::real::Real;
use crate::spatial::{ArticulatedInertia, Force, RigidInertia};

/// `M(q)^-1` (nv, nv), row-major in `minv`, with M including the rotor inertias
/// (`M + diag(Ia)`, as `crba`). `q`: (nv,). Writes `data.xup`, `data.ia`,
/// `data.u_col`, `data.d_inv`.
#[inline(always)]
pub fn minverse<T: Real>(model: &Model, data: &mut Data<T>, dd: &mut DerivData<T>, q: &[T], minv: &mut [T]) {
    let n = model.nv;
    assert!(q.len() == n && minv.len() == n * n, "argument size");
    update_xup(model, data, q);
    for i in 0..n {
        data.ia[i] = ArticulatedInertia::from_rigid(&RigidInertia::splat(&model.inertia[i]));
    }
    // Articulated inertias (RBDA Table 7.1, pass 2 without the bias forces).
    for i in (0..n).rev() {
        let kind = model.kind[i];
        let u_col = kind.articulated_inertia_s(&data.ia[i]);
        // the rotor inertia adds to the joint's own inertia: D_i = S^T I^A S + Ia (as in aba)
        let d_inv = T::splat(1.0) / (kind.s_dot(&u_col) + T::splat(model.joint_dynamics[i].armature));
        data.u_col[i] = u_col;
        data.d_inv[i] = d_inv;
        if let Some(p) = model.parent[i] {
            let ia = data.ia[i].sub_outer(&u_col, d_inv).tr_transform(&data.xup[i]);
            data.ia[p] += ia;
        }
    }
    minverse_from_articulated(model, data, dd, minv);
}

/// The two passes over unit torques, given `data.xup`, `data.u_col` (`U_i = I^A_i S_i`)
/// and `data.d_inv` (`1 / D_i`) from an articulated-body pass (`minverse` or `aba`).
#[inline(always)]
pub fn minverse_from_articulated<T: Real>(model: &Model, data: &Data<T>, dd: &mut DerivData<T>, minv: &mut [T]) {
    let n = model.nv;
    minv.fill(T::zero());
    for i in (0..n).rev() {
        let (kind, u, d_inv) = (model.kind[i], data.u_col[i], data.d_inv[i]);
        let (start, end) = (dd.sub_start[i], dd.sub_start[i + 1]);
        minv[i * n + i] = d_inv;
        for k in start + 1..end {
            let c = dd.sub[k];
            minv[i * n + c] = -(kind.s_dot(&dd.fm[i * n + c]) * d_inv);
        }
        if let Some(p) = model.parent[i] {
            let xup = data.xup[i];
            for k in start..end {
                let c = dd.sub[k];
                let f = dd.fm[i * n + c] + u.scale(minv[i * n + c]);
                dd.fm[p * n + c] += xup.tr_apply_force(&f);
            }
        }
        // F_i has been used: zero it for the next call (rows are only written by children)
        for k in start..end {
            dd.fm[i * n + dd.sub[k]] = Force::zero();
        }
    }
    for i in 0..n {
        let (kind, u, d_inv) = (model.kind[i], data.u_col[i], data.d_inv[i]);
        match model.parent[i] {
            Some(p) => {
                let xup = data.xup[i];
                for c in i..n {
                    let a = xup.apply_motion(&dd.pm[p * n + c]);
                    let m = minv[i * n + c] - a.dot(&u) * d_inv;
                    minv[i * n + c] = m;
                    dd.pm[i * n + c] = a + kind.s_times(m);
                }
            }
            None => {
                for c in i..n {
                    dd.pm[i * n + c] = kind.s_times(minv[i * n + c]);
                }
            }
        }
    }
    for i in 0..n {
        for c in i + 1..n {
            minv[c * n + i] = minv[i * n + c];
        }
    }
}
