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
//! The sweeps run one column at a time (every column is independent: unit torque c):
//! the backward recursion for column c only touches c and its ancestors (`F_i[:, c]`
//! is zero elsewhere), so `F[:, c]` is carried up the ancestor path in a local, and
//! the forward recursion for column c needs `P_i[:, c]` only for the bodies before
//! c, kept in an nv-long buffer. That replaces two nv x nv blocks of 6-vectors (on a
//! 7-dof arm with 8 states per SIMD vector, 2 x 49 x 6 x 64 bytes = 38 KB: more than
//! the 32 KB L1 data cache) by nv 6-vectors. Only the upper triangle `i <= c` is computed; each entry is written
//! to both triangles as it is found, and `Minv[i, c]` is zeroed first only for the
//! bodies i that are not ancestors of c (none in a chain). Leaves keep no `P`.
//!
//! Body inertias reach the base frame by one parallel-axis shift from the centre of
//! mass ([`RigidInertia::from_com_transformed`]).

use crate::algo::kinematics::{update_x0, update_xup};
use crate::data::Data;
use crate::deriv_data::DerivData;
use crate::model::Model;
use crate::real::Real;
use crate::spatial::{ArticulatedInertia, RigidInertia, Sym3, V3};

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
        let m = T::splat(model.inertia[i].m);
        let inertia = RigidInertia::from_com_transformed(m, V3::splat(dd.com[i]), &Sym3::splat(dd.i_com[i]), &x0);
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
/// (or of a base-frame ABA). Writes all of `minv` (nv, nv), row-major; uses `dd.pm[..nv]`.
#[inline(always)]
pub fn minverse_sweeps<T: Real>(model: &Model, data: &Data<T>, dd: &mut DerivData<T>, minv: &mut [T]) {
    let n = model.nv;
    let chain = (0..n).all(|i| model.parent[i] == i.checked_sub(1));
    let (s, u, d_inv) = (&dd.s[..n], &data.u_col[..n], &data.d_inv[..n]);
    // P_i[:, c] of the current column c, per body
    let p_col = &mut dd.pm[..n];
    for c in 0..n {
        // Backward, up the ancestors of c: Minv[c, c] = 1/D_c and F_lambda(c)[:, c] =
        // U_c / D_c (F_c[:, c] = 0: a unit torque at c leaves c's children unloaded), then
        // Minv[i, c] = -J_i^T F_i[:, c] / D_i, F_lambda(i)[:, c] = F_i[:, c] + U_i Minv[i, c].
        if !chain {
            for i in 0..c {
                minv[i * n + c] = T::zero();
            }
        }
        minv[c * n + c] = d_inv[c];
        let mut f = u[c].scale(d_inv[c]);
        let mut up = model.parent[c];
        while let Some(i) = up {
            let m = -(s[i].dot(&f) * d_inv[i]);
            minv[i * n + c] = m;
            up = model.parent[i];
            if up.is_some() {
                f = f + u[i].scale(m);
            }
        }
        // Forward, bodies 0..=c: Minv[i, c] -= U_i^T P_lambda(i)[:, c] / D_i,
        // P_i[:, c] = P_lambda(i)[:, c] + J_i Minv[i, c] (needed by bodies i < j <= c only).
        for i in 0..=c {
            let keep_p = i < c && dd.sub_start[i + 1] - dd.sub_start[i] > 1;
            let m = match model.parent[i] {
                Some(p) => {
                    let a = p_col[p];
                    let m = minv[i * n + c] - a.dot(&u[i]) * d_inv[i];
                    if keep_p {
                        p_col[i] = a + s[i].scale(m);
                    }
                    m
                }
                None => {
                    let m = minv[i * n + c];
                    if keep_p {
                        p_col[i] = s[i].scale(m);
                    }
                    m
                }
            };
            minv[i * n + c] = m;
            minv[c * n + i] = m;
        }
    }
}
