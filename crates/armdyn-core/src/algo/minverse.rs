//! The inverse of the joint-space inertia matrix without forming M, by the
//! articulated-body recursion applied to unit torques: J. Carpentier, "Analytical
//! inverse of the joint space inertia matrix" (2018, the algorithm behind Pinocchio's
//! `computeMinverse`); also Carpentier & Mansard, RSS 2018, Section IV.C.
//!
//! Column c of M^-1 is the ABA's `qdd` for `tau = e_c` with no velocity and no gravity
//! (RBDA Table 7.1 with `c_i = 0`, `p^A_i = 0`). Everything is in base-frame ("world")
//! coordinates, as in Pinocchio: the articulated inertias `I^A_i`, `U_i = I^A_i J_i`
//! (`J_i` = joint i's axis in the base frame) and `D_i = J_i^T U_i + Ia_i`. Then no
//! spatial transform is needed per (body, column) pair, only 6-vector sums and dot
//! products. The bias forces of all columns are carried together: `F_i` (6 x nv) is
//! `p^A_i` per column, non-zero only for the columns of i's strict subtree, and `P_i`
//! (6 x nv) the accelerations `a_i` per column:
//!
//! ```text
//! backward (i = n..1):  Minv[i, i] = 1/D_i,  Minv[i, c] = -J_i^T F_i[:, c] / D_i  (c below i)
//!                       F_lambda[:, c] = F_i[:, c] + U_i Minv[i, c]              (c in subtree(i))
//! forward (i = 1..n):   Minv[i, c] -= U_i^T P_lambda[:, c] / D_i,  P_i[:, c] = P_lambda[:, c] + J_i Minv[i, c]
//! ```
//!
//! `F_lambda[:, c] =` rather than `+=`: column c of `F_lambda` receives from the one
//! child whose subtree holds c, so nothing needs zeroing between calls. The forward pass
//! only fills the columns `c >= i` (the upper triangle: with parents before children,
//! `P_lambda[:, c]` is ready for them; the rest follows by symmetry), and leaves keep
//! no `P`.

use crate::algo::kinematics::{update_x0, update_xup};
use crate::data::Data;
use crate::deriv_data::DerivData;
use crate::model::Model;
use crate::real::Real;
use crate::spatial::{ArticulatedInertia, RigidInertia};

/// `M(q)^-1` (nv, nv), row-major in `minv`, with M including the rotor inertias
/// (`M + diag(Ia)`, as `crba`). `q`: (nv,). Writes `data.xup`, `data.x0`, `dd.s` (the
/// base-frame axes `J_i`) and, in base-frame coordinates, `data.ia`, `data.u_col`,
/// `data.d_inv`.
#[inline(always)]
pub fn minverse<T: Real>(model: &Model, data: &mut Data<T>, dd: &mut DerivData<T>, q: &[T], minv: &mut [T]) {
    let n = model.nv;
    assert!(q.len() == n && minv.len() == n * n, "argument size");
    update_xup(model, data, q);
    update_x0(model, data);
    for i in 0..n {
        let x0 = data.x0[i];
        dd.s[i] = model.kind[i].s_in(&x0);
        let inertia = RigidInertia::splat(&model.inertia[i]).tr_transform(&x0);
        data.ia[i] = ArticulatedInertia::from_rigid(&inertia);
    }
    articulated_inertias_world(model, data, dd);
    minverse_sweeps(model, data, dd, minv);
}

/// RBDA Table 7.1, pass 2 without bias forces, in base-frame coordinates: given
/// `data.ia[i]` = body i's own inertia and `dd.s` = `J_i`, turns `data.ia` into the
/// articulated inertias and writes `data.u_col` (`U_i = I^A_i J_i`) and `data.d_inv`
/// (`1 / (J_i^T U_i + Ia_i)`). No transform: all inertias share the base frame.
#[inline(always)]
pub fn articulated_inertias_world<T: Real>(model: &Model, data: &mut Data<T>, dd: &DerivData<T>) {
    for i in (0..model.nv).rev() {
        let u_col = data.ia[i].mul_motion(&dd.s[i]);
        // the rotor inertia adds to the joint's own inertia: D_i = J^T I^A J + Ia (as in aba)
        let d_inv = T::splat(1.0) / (dd.s[i].dot(&u_col) + T::splat(model.joint_dynamics[i].armature));
        data.u_col[i] = u_col;
        data.d_inv[i] = d_inv;
        if let Some(p) = model.parent[i] {
            let ia = data.ia[i].sub_outer(&u_col, d_inv);
            data.ia[p] += ia;
        }
    }
}

/// The two passes over unit torques (module docs), given the base-frame `dd.s` (`J_i`),
/// `data.u_col` (`U_i`) and `data.d_inv` (`1 / D_i`) of [`articulated_inertias_world`]
/// (or of a base-frame ABA).
#[inline(always)]
pub fn minverse_sweeps<T: Real>(model: &Model, data: &Data<T>, dd: &mut DerivData<T>, minv: &mut [T]) {
    let n = model.nv;
    // entries (i, c > i) with c outside i's subtree start from 0 in the forward pass
    minv.fill(T::zero());
    for i in (0..n).rev() {
        let (s, u, d_inv) = (dd.s[i], data.u_col[i], data.d_inv[i]);
        let (start, end) = (dd.sub_start[i], dd.sub_start[i + 1]);
        minv[i * n + i] = d_inv;
        for k in start + 1..end {
            let c = dd.sub[k];
            minv[i * n + c] = -(s.dot(&dd.fm[i * n + c]) * d_inv);
        }
        if let Some(p) = model.parent[i] {
            // F_i[:, i] = 0: a unit torque at i leaves i's children unloaded
            dd.fm[p * n + i] = u.scale(d_inv);
            for k in start + 1..end {
                let c = dd.sub[k];
                dd.fm[p * n + c] = dd.fm[i * n + c] + u.scale(minv[i * n + c]);
            }
        }
    }
    for i in 0..n {
        let (s, u, d_inv) = (dd.s[i], data.u_col[i], data.d_inv[i]);
        let leaf = dd.sub_start[i + 1] - dd.sub_start[i] == 1;
        match model.parent[i] {
            Some(p) => {
                for c in i..n {
                    let a = dd.pm[p * n + c];
                    let m = minv[i * n + c] - a.dot(&u) * d_inv;
                    minv[i * n + c] = m;
                    if !leaf {
                        dd.pm[i * n + c] = a + s.scale(m);
                    }
                }
            }
            None => {
                for c in i..n {
                    dd.pm[i * n + c] = s.scale(minv[i * n + c]);
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
