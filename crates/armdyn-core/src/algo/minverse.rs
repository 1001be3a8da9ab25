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
//! Storage: column c of `F` is non-zero at one body at a time in the backward pass
//! (the ancestor of c being visited, which hands it on to its parent), so `F` needs nv
//! 6-vectors, not nv x nv; on a chain the same holds for `P` in the forward pass (each
//! body overwrites its parent's `P` in place). That replaces two nv x nv blocks of
//! 6-vectors (on a 7-dof arm with 8 states per SIMD vector, 2 x 49 x 6 x 64 bytes =
//! 38 KB: more than the 32 KB L1 data cache) by 2 nv (a tree keeps `P`'s block: siblings
//! both read their parent's). Only the upper triangle `c >= i`
//! is computed, each entry written to both triangles as it is found; on a chain every
//! entry `(i, c > i)` is in i's subtree, so nothing needs zeroing first. Leaves keep no `P`.
//!
//! Body inertias reach the base frame by one parallel-axis shift from the centre of
//! mass ([`RigidInertia::from_com_transformed`]), with a cheaper rotation when the
//! inertia about the centre of mass is diagonal in the body's axes, as in most robot
//! descriptions (UR5, iiwa14; not the Panda's identified inertias).

use crate::algo::aba::{articulated_inertias, BaseFrame};
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
    assert!(q.len() == model.nq && minv.len() == n * n, "argument size");
    update_xup(model, data, q);
    update_x0(model, data);
    for i in 0..n {
        let x0 = data.x0[i];
        dd.s[i] = model.kind[i].s_in(&x0);
        let m = T::splat(model.inertia[i].m);
        let (c, i_c) = (V3::splat(dd.com[i]), Sym3::splat(dd.i_com[i]));
        let inertia = if dd.i_com_diagonal[i] {
            RigidInertia::from_com_transformed_diagonal(m, c, V3::new(i_c.xx, i_c.yy, i_c.zz), &x0)
        } else {
            RigidInertia::from_com_transformed(m, c, &i_c, &x0)
        };
        data.ia[i] = ArticulatedInertia::from_rigid(&inertia);
    }
    // RBDA Table 7.1, pass 2 without bias forces: no transform, all inertias share the base frame
    articulated_inertias(model, data, &BaseFrame(&dd.s[..]), None);
    minverse_sweeps(model, data, dd, minv);
}

/// The two passes over unit torques (module docs), given the base-frame `dd.s` (`J_i`),
/// `data.u_col` (`U_i`) and `data.d_inv` (`1 / D_i`) of [`articulated_inertias`] in base
/// coordinates (with or without bias forces). Writes all of `minv` (nv, nv), row-major;
/// uses `dd.fm[..nv]` and `dd.pm` (its first nv entries on a chain).
#[inline(always)]
pub fn minverse_sweeps<T: Real>(model: &Model, data: &Data<T>, dd: &mut DerivData<T>, minv: &mut [T]) {
    let n = model.nv;
    let chain = (0..n).all(|i| model.parent[i] == i.checked_sub(1));
    if !chain {
        // entries (i, c > i) with c outside i's subtree start from 0 in the forward pass
        minv.fill(T::zero());
    }
    let (s, u, d_inv) = (&dd.s[..n], &data.u_col[..n], &data.d_inv[..n]);
    // Backward. F_i[:, c] sits in f_col[c]: column c is loaded at one body at a time (the
    // ancestor of c being visited), which hands it on to its parent.
    let f_col = &mut dd.fm[..n];
    for i in (0..n).rev() {
        let (si, ui, di) = (s[i], u[i], d_inv[i]);
        let below = &dd.sub[dd.sub_start[i] + 1..dd.sub_start[i + 1]];
        minv[i * n + i] = di;
        for &c in below {
            minv[i * n + c] = -(si.dot(&f_col[c]) * di);
        }
        if model.parent[i].is_some() {
            // F_i[:, i] = 0: a unit torque at i leaves i's children unloaded
            f_col[i] = ui.scale(di);
            for &c in below {
                f_col[c] += ui.scale(minv[i * n + c]);
            }
        }
    }
    // Forward, upper triangle (c >= i), both triangles written. P_i[:, c] sits in
    // p[i * stride + c]: on a chain (stride 0) each body overwrites its parent's P in
    // place, column by column; in a tree siblings need their parent's, so each body has
    // its own row. P_i[:, i] is never read (children only read columns c > i), nor a leaf's.
    let stride = if chain { 0 } else { n };
    let p = &mut dd.pm[..];
    for i in 0..n {
        let (si, ui, di) = (s[i], u[i], d_inv[i]);
        let keep_p = dd.sub_start[i + 1] - dd.sub_start[i] > 1;
        minv[i * n + i] = match model.parent[i] {
            Some(l) => minv[i * n + i] - p[l * stride + i].dot(&ui) * di,
            None => minv[i * n + i],
        };
        for c in i + 1..n {
            let m = match model.parent[i] {
                Some(l) => {
                    let a = p[l * stride + c];
                    let m = minv[i * n + c] - a.dot(&ui) * di;
                    if keep_p {
                        p[i * stride + c] = a + si.scale(m);
                    }
                    m
                }
                None => {
                    let m = minv[i * n + c];
                    if keep_p {
                        p[i * stride + c] = si.scale(m);
                    }
                    m
                }
            };
            minv[i * n + c] = m;
            minv[c * n + i] = m;
        }
    }
}
