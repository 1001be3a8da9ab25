//! Analytical derivatives of inverse dynamics, after J. Carpentier and N. Mansard,
//! "Analytical Derivatives of Rigid Body Dynamics Algorithms", RSS 2018 (Algorithm 1
//! and its Section IV.B), written in base-frame ("world") quantities.
//!
//! Everything below is in base coordinates. `J_i` is joint i's axis (`^0X_i S_i`), `v_i`,
//! `a_i` body i's velocity and acceleration (`a_0 = [0; -g]`), `I_i` its inertia,
//! `f_i = I_i a_i + v_i x* I_i v_i - f^ext_i`, and `F_i`, `I^c_i`, `B^c_i` the sums of
//! `f_k`, `I_k`, `B_k` over the subtree of i. In base coordinates a joint's axis only
//! changes when an ancestor moves: `dJ_j/dq_i = J_i x J_j` for i supporting j.
//!
//! Moving q_i turns the subtree of i rigidly about `J_i`; a quantity attached to it then
//! changes by `J_i x` (motions) or `J_i x*` (forces), except for what the subtree
//! inherits from its (unmoved) parent lambda: with
//!
//! ```text
//! dV_i = v_lambda x J_i,    dA_i = a_lambda x J_i + v_lambda x dV_i      (paper eq. 9-10)
//! dv_k/dq_i = J_i x v_k + dV_i,   and   df_k/dq_i = J_i x* f_k + I_k dA_i + B_k dV_i
//! df_k/dqd_i = I_k (2 dV_i) + B_k J_i                                      (paper eq. 12)
//! B_k = v_k x* I_k - I_k (v_k x) + (I_k v_k) xbar,    (h xbar) m := m x* h
//! ```
//!
//! for every body k in the subtree of i. `tau_j = J_j^T F_j` then gives, for j an
//! ancestor of i or i itself (`J_j` does not move with q_i),
//! `dtau_j/dq_i = J_j^T (J_i x* F_i + I^c_i dA_i + B^c_i dV_i)`, and for j a descendant
//! of i (the `J_i x` terms of `J_j` and `F_j` cancel, as `crf = -crm^T`)
//! `dtau_j/dq_i = J_j^T (I^c_j dA_i + B^c_j dV_i)`; likewise for qd with
//! `(2 dV_i, J_i)` in place of `(dA_i, dV_i)`, and `M_ji = J_j^T I^c_max(i,j) J_i`.
//!
//! `B_k` has a sparse closed form (our derivation, expanding the three products with
//! `I = [Ibar h^x; -h^x m]`): only its left column of 3x3 blocks is non-zero,
//!
//! ```text
//! B_k = [ S - N^x   0 ]     S = w^x Ibar - Ibar w^x - v^x h^x - h^x v^x  (symmetric)
//!       [ -2 P^x    0 ]     [N; P] = I_k v_k  (angular and linear momentum)
//! ```
//!
//! so the subtree sums are one symmetric 3x3 and two 3-vectors per body.

use crate::algo::external::{body_forces, Coordinates, ExternalForces, ForceFrame};
use crate::algo::floating::NV_BASE;
use crate::algo::kinematics::{update_x0, update_xup};
use crate::data::Data;
use crate::deriv_data::DerivData;
use crate::model::Model;
use crate::real::Real;
use crate::spatial::{Force, Motion, RigidInertia, Sym3, V3};

/// `B^c_i m = [S w - N x w; w x 2P]` for the subtree sums of body i (only `m`'s angular
/// part `w` matters), given `p2 = 2P`.
#[inline(always)]
fn b_apply<T: Real>(dd: &DerivData<T>, i: usize, p2: V3<T>, m: &Motion<T>) -> Force<T> {
    let w = m.w;
    Force::new(dd.bs[i].mul_v(w) - dd.bn[i].cross(w), w.cross(p2))
}

/// The symmetric block `S = w^x Ibar - Ibar w^x - (v^x h^x + h^x v^x)` of `B` for a
/// body of base-frame inertia `i` moving with base-frame velocity `v`:
/// `K + K^T - (v h^T + h v^T) + 2 (v . h) 1` with `K = w^x Ibar`. On the diagonal the
/// outer products and `v . h` partly cancel: `S_xx = 2 K_xx + 2 (v_y h_y + v_z h_z)`, and
/// so on.
#[inline(always)]
pub(crate) fn b_sym<T: Real>(i: &RigidInertia<T>, v: &Motion<T>) -> Sym3<T> {
    let (w, vv, h) = (v.w, v.v, i.h);
    // columns of w^x Ibar
    let (k0, k1, k2) = (w.cross(i.ibar.col(0)), w.cross(i.ibar.col(1)), w.cross(i.ibar.col(2)));
    let (px, py, pz) = (vv.x * h.x, vv.y * h.y, vv.z * h.z);
    let (dx, dy, dz) = (k0.x + py + pz, k1.y + px + pz, k2.z + px + py);
    Sym3 {
        xx: dx + dx,
        yy: dy + dy,
        zz: dz + dz,
        xy: k1.x + k0.y - (vv.x * h.y + h.x * vv.y),
        xz: k2.x + k0.z - (vv.x * h.z + h.x * vv.z),
        yz: k2.y + k1.z - (vv.y * h.z + h.y * vv.z),
    }
}

/// The forward pass's velocity part (independent of `qdd`), shared by
/// `rnea_derivatives` and `aba_derivatives`: writes `data.xup`, `data.x0`, `dd.fx` (the
/// external forces `f^x_i` in base coordinates, whatever their frame; only if `ext` is
/// given) and per body the base-frame `dd.s` (`J_i`), `dd.v`, `dd.dvdq`, `dd.ic` (body i's
/// own inertia), `dd.bn`, `dd.bp` (its momentum `I_i v_i`), `dd.bs`, and in `dd.f` the bias
/// force `p_i = v_i x* I_i v_i - f^x_i` (RBDA 5.3 and Table 7.1): the acceleration pass
/// adds `I_i a_i`, the base-frame ABA starts its bias forces from it. This is where the
/// external forces enter both derivative algorithms.
///
/// A root body's parent does not move (`v_lambda = 0`): `v_i = J_i qd_i`, `dV_i = 0`.
#[inline(always)]
pub(crate) fn velocity_pass<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    dd: &mut DerivData<T>,
    q: &[T],
    qd: &[T],
    ext: Option<&ExternalForces<T>>,
) {
    velocity_pass_on(model, data, dd, q, qd, ext, None);
}

/// [`velocity_pass`] on a base moving with velocity `base = Some(v_B)` (base
/// coordinates): the root bodies' parent is then the base, `v_lambda = v_B` (a floating
/// base, `floating_derivatives.rs`); `None` is the fixed base at rest.
#[inline(always)]
pub(crate) fn velocity_pass_on<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    dd: &mut DerivData<T>,
    q: &[T],
    qd: &[T],
    ext: Option<&ExternalForces<T>>,
    base: Option<Motion<T>>,
) {
    update_xup(model, data, q);
    update_x0(model, data);
    // without external forces nothing reads dd.fx
    if let Some(e) = ext {
        body_forces(model, data, e, Coordinates::Base, &mut dd.fx);
    }
    for i in 0..model.nv {
        let x0 = data.x0[i];
        let s = model.kind[i].s_in(&x0);
        let (v, dvdq) = match (model.parent[i], base) {
            (Some(p), _) => {
                let vp = dd.v[p];
                (vp + s.scale(qd[i]), vp.cross_motion(&s))
            }
            (None, Some(vb)) => (vb + s.scale(qd[i]), vb.cross_motion(&s)),
            (None, None) => (s.scale(qd[i]), Motion::zero()),
        };
        let inertia = RigidInertia::splat(&model.inertia[i]).tr_transform(&x0);
        let h = inertia.mul_motion(&v);
        dd.bs[i] = b_sym(&inertia, &v);
        dd.bn[i] = h.n;
        dd.bp[i] = h.f;
        // the bias force p_i; external forces enter here, once for both derivative algorithms
        let mut p = v.cross_force(&h);
        if ext.is_some() {
            p -= dd.fx[i];
        }
        dd.f[i] = p;
        dd.ic[i] = inertia;
        dd.dvdq[i] = dvdq;
        dd.s[i] = s;
        dd.v[i] = v;
    }
}

/// The forward pass's acceleration part, after [`velocity_pass`]: `dd.a`, `dd.dadq` and
/// the net forces `f_i = I_i a_i + p_i` of the bodies in `dd.f` (`I_i a_i` added to the
/// velocity pass's bias force `p_i = v_i x* I_i v_i - f^x_i`).
/// `a_i = a_lambda + J_i qdd_i + (v_i x J_i) qd_i`, where `v_i x J_i = v_lambda x J_i = dV_i`.
///
/// At a root `v_lambda = 0` and `dV_i = 0`, so `a_i = a_0 + J_i qdd_i` and
/// `dA_i = a_0 x J_i`, which for `a_0 = [0; -g]` is `[0; -g x J_i^w]`.
#[inline(always)]
pub(crate) fn acceleration_pass<T: Real>(model: &Model, dd: &mut DerivData<T>, qd: &[T], qdd: &[T]) {
    acceleration_pass_on(model, dd, qd, qdd, None);
}

/// [`acceleration_pass`] on a base moving with `base = Some((v_B, a_B))` (base
/// coordinates, `a_B` with gravity's `-g`), after [`velocity_pass_on`] with `v_B`: the
/// root bodies' parent is then the base (`v_lambda = v_B`, `a_lambda = a_B`).
#[inline(always)]
pub(crate) fn acceleration_pass_on<T: Real>(
    model: &Model,
    dd: &mut DerivData<T>,
    qd: &[T],
    qdd: &[T],
    base: Option<(Motion<T>, Motion<T>)>,
) {
    let a0 = Motion::new(V3::splat(model.a0.w), V3::splat(model.a0.v));
    let a0_linear = model.a0.w == V3::zero();
    for i in 0..model.nv {
        let s = dd.s[i];
        let parent = match (model.parent[i], base) {
            (Some(p), _) => Some((dd.v[p], dd.a[p])),
            (None, b) => b,
        };
        let (a, dadq) = match parent {
            Some((vp, ap)) => {
                let dvdq = dd.dvdq[i];
                (ap + s.scale(qdd[i]) + dvdq.scale(qd[i]), ap.cross_motion(&s) + vp.cross_motion(&dvdq))
            }
            None if a0_linear => (a0 + s.scale(qdd[i]), Motion::new(V3::zero(), a0.v.cross(s.w))),
            None => (a0 + s.scale(qdd[i]), a0.cross_motion(&s)),
        };
        dd.dadq[i] = dadq;
        dd.f[i] = dd.ic[i].mul_motion(&a) + dd.f[i];
        dd.a[i] = a;
    }
}

/// The backward pass: the subtree sums `dd.ic`, `dd.bs`, `dd.bn`, `dd.bp`, `dd.f`, `dd.fx`
/// (`dd.fx` only for forces fixed in space; zeroed for forces in link frames, untouched
/// without external forces).
#[inline(always)]
pub(crate) fn subtree_sums<T: Real>(model: &Model, dd: &mut DerivData<T>, ext: Option<&ExternalForces<T>>) {
    let world_ext = matches!(ext, Some(e) if e.frame == ForceFrame::World);
    if matches!(ext, Some(e) if e.frame != ForceFrame::World) {
        // forces given in link frames move with their links like the inertial forces
        dd.fx.iter_mut().for_each(|f| *f = Force::zero());
    }
    for i in (0..model.nv).rev() {
        if let Some(p) = model.parent[i] {
            let (ic, bs, bn, bp, f) = (dd.ic[i], dd.bs[i], dd.bn[i], dd.bp[i], dd.f[i]);
            dd.ic[p] += ic;
            dd.bs[p] = dd.bs[p] + bs;
            dd.bn[p] += bn;
            dd.bp[p] += bp;
            dd.f[p] += f;
            if world_ext {
                let fx = dd.fx[i];
                dd.fx[p] += fx;
            }
        }
    }
}

/// Partial derivatives of `tau = rnea(q, qd, qdd)` (with external wrenches `ext`, if
/// any: `tau = M qdd + C qd + g - sum_L J_L^T w_L`), joint friction, rotor inertia and
/// offset included (see [`add_joint_dynamics_derivatives`]).
///
/// `q`, `qd`, `qdd`: (nv,). Writes `dtau_dq`, `dtau_dqd` and `m` = `dtau/dqdd` = M(q),
/// each (nv, nv) row-major, `[i * nv + j] = d tau_i / d x_j`. Uses `data.xup`, `data.x0`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn rnea_derivatives<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    dd: &mut DerivData<T>,
    q: &[T],
    qd: &[T],
    qdd: &[T],
    ext: Option<&ExternalForces<T>>,
    dtau_dq: &mut [T],
    dtau_dqd: &mut [T],
    m: &mut [T],
) {
    let n = model.nv;
    assert!(q.len() == model.nq && qd.len() == n && qdd.len() == n, "state length");
    assert!(dtau_dq.len() == n * n && dtau_dqd.len() == n * n && m.len() == n * n, "output size");
    velocity_pass(model, data, dd, q, qd, ext);
    acceleration_pass(model, dd, qd, qdd);
    subtree_sums(model, dd, ext);
    derivative_terms(model, dd, ext, dtau_dq, dtau_dqd, Some(m));
}

/// The (body, ancestor) terms of the module docs from the passes' results, into
/// `dtau_dq`, `dtau_dqd` and (if given) `m`, then the joint dynamics' terms.
///
/// Per body i, with `w` the angular part of `J_i` and `2P = 2 P^c_i`:
/// `I^c_i J_i`, `B^c_i J_i = [S w - N x w; w x 2P]` and the angular part of `B^c_i^T J_i`,
/// `S w + N x w + 2P x J_i^v` (sharing `S w` and `N x w`); per ancestor j, five spatial
/// dot products. A root j has `dV_j = 0`, which drops its `B dV` and `I (2 dV)` terms.
#[inline(always)]
pub(crate) fn derivative_terms<T: Real>(
    model: &Model,
    dd: &DerivData<T>,
    ext: Option<&ExternalForces<T>>,
    dtau_dq: &mut [T],
    dtau_dqd: &mut [T],
    m: Option<&mut [T]>,
) {
    derivative_terms_in(model, dd, ext, dtau_dq, dtau_dqd, m, Placement { stride: model.nv, base: None });
}

/// Where [`derivative_terms_in`] writes: the matrices are `stride` wide (row-major).
/// `base: None`: a fixed base, the joints' block is the whole matrix (`stride = nv`).
/// `base: Some((g, v_B))`: a floating base (`floating_derivatives.rs`), after the `_on`
/// passes with the base's motion: `stride = 6 + nv`, the base's six velocities (linear,
/// angular) first, then the joints; `g` is gravity's fictitious acceleration `-R^T g`,
/// `v_B` the base's velocity (base frame).
#[derive(Clone, Copy)]
pub(crate) struct Placement<T> {
    pub stride: usize,
    pub base: Option<(V3<T>, Motion<T>)>,
}

/// [`derivative_terms`] written where `at` says. With a floating base the root bodies'
/// parent (the base) moves, so their `dV` is not zero, and each body i also fills the
/// base's rows and columns: the base is an ancestor of every body whose axes `e_b` (unit
/// motions, base frame) do not move with `q_i`, so `dtau_b/dx_i` is `e_b^T` of the
/// forces of row i (`dtau/dq`, `dtau/dqd`, `M`); and `dtau_i/dq_b = J_i^T I^c_i dA_b`
/// with `dA_b = a_0 x e_b` (`dV_b = 0`: the base's parent, the world, is at rest):
/// 0 for the linear `e_b`, `(I^c_i J_i)^f x g` for the angular; and
/// `dtau_i/dqd_b = J_i^T (I^c_i (v_B x e_b) + B^c_i e_b)`, where `v_B x e_b` is the
/// once-counted `2 dV` of a 1-dof joint: the free flyer's `dJ/dt v = v_B x v_B` is 0 for
/// every `v`, so only the descendants' `(v_k x J_k) qd_k` depend on `v_b`, by
/// `e_b x (v_k - v_B)`. As `(m x e_b) . f = -e_b . (m x* f)`, that row is
/// `-(v_B x* I^c_i J_i)` plus the angular part of `B^c_i^T J_i` at the angular `e_b`.
#[inline(always)]
pub(crate) fn derivative_terms_in<T: Real>(
    model: &Model,
    dd: &DerivData<T>,
    ext: Option<&ExternalForces<T>>,
    dtau_dq: &mut [T],
    dtau_dqd: &mut [T],
    mut m: Option<&mut [T]>,
    at: Placement<T>,
) {
    let n = model.nv;
    let floating = at.base.is_some();
    let (w, off) = (at.stride, if floating { NV_BASE } else { 0 });
    // row r, column c of the joints' block
    let ix = |r: usize, c: usize| (off + r) * w + off + c;
    let world_ext = matches!(ext, Some(e) if e.frame == ForceFrame::World);
    // On a chain every (row, column) pair is a body and itself or one of its ancestors,
    // so the loop below writes every entry; elsewhere the unrelated pairs stay 0.
    if !is_chain(model) {
        dtau_dq.fill(T::zero());
        dtau_dqd.fill(T::zero());
        if let Some(m) = m.as_deref_mut() {
            m.fill(T::zero());
        }
    }
    for i in 0..n {
        let s = dd.s[i];
        let ic = dd.ic[i];
        let fa = ic.mul_motion(&s);
        let fa2 = fa + fa;
        // dd.fx is zero unless the forces are fixed in space
        let ft = if world_ext { dd.f[i] + dd.fx[i] } else { dd.f[i] };
        let p2 = dd.bp[i] + dd.bp[i];
        let (sw, nw) = (dd.bs[i].mul_v(s.w), dd.bn[i].cross(s.w));
        let bj = Force::new(sw - nw, s.w.cross(p2));
        let bt = sw + nw + p2.cross(s.v);
        let (fq, fv) = if model.parent[i].is_some() || floating {
            let dvdq = dd.dvdq[i];
            let fq = s.cross_force(&ft) + ic.mul_motion(&dd.dadq[i]) + b_apply(dd, i, p2, &dvdq);
            (fq, ic.mul_motion(&(dvdq + dvdq)) + bj)
        } else {
            (s.cross_force(&ft) + ic.mul_motion(&dd.dadq[i]), bj)
        };
        // row i: the columns of i and its ancestors j (the motion of j moves body i's subtree)
        if let Some(m) = m.as_deref_mut() {
            m[ix(i, i)] = s.dot(&fa);
        }
        dtau_dq[ix(i, i)] = s.dot(&fq);
        dtau_dqd[ix(i, i)] = s.dot(&fv);
        let mut a = model.parent[i];
        while let Some(j) = a {
            let (sj, daj) = (dd.s[j], dd.dadq[j]);
            if let Some(m) = m.as_deref_mut() {
                let mji = sj.dot(&fa);
                m[ix(j, i)] = mji;
                m[ix(i, j)] = mji;
            }
            dtau_dq[ix(j, i)] = sj.dot(&fq);
            dtau_dqd[ix(j, i)] = sj.dot(&fv);
            a = model.parent[j];
            if a.is_some() || floating {
                let dvj = dd.dvdq[j];
                dtau_dq[ix(i, j)] = daj.dot(&fa) + bt.dot(dvj.w);
                dtau_dqd[ix(i, j)] = dvj.dot(&fa2) + bt.dot(sj.w);
            } else {
                dtau_dq[ix(i, j)] = daj.dot(&fa);
                dtau_dqd[ix(i, j)] = bt.dot(sj.w);
            }
            if world_ext {
                // forces fixed in space do not turn with joint j: J_i^T (J_j x* FX_i)
                dtau_dq[ix(i, j)] += s.dot(&sj.cross_force(&dd.fx[i]));
            }
        }
        if let Some((g, vb)) = at.base {
            base_entries(dtau_dq, dtau_dqd, m.as_deref_mut(), w, off + i, [fq, fv, fa], bt, g, vb);
        }
    }
    if model.has_joint_dynamics {
        add_joint_dynamics_at(model, dtau_dqd, m, w, off);
    }
}

/// Body i's entries in a floating base's rows and columns (see [`derivative_terms_in`]),
/// `c = 6 + i` its row and column in matrices `w` wide: `[fq, fv, fa]` are its forces
/// `dtau/dq`, `dtau/dqd` and `I^c_i J_i`, `bt` the angular part of `B^c_i^T J_i`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn base_entries<T: Real>(
    dtau_dq: &mut [T],
    dtau_dqd: &mut [T],
    m: Option<&mut [T]>,
    w: usize,
    c: usize,
    [fq, fv, fa]: [Force<T>; 3],
    bt: V3<T>,
    g: V3<T>,
    vb: Motion<T>,
) {
    let fv_ = |f: &Force<T>| f.f.to_array().into_iter().chain(f.n.to_array());
    for (b, (xq, xv)) in fv_(&fq).zip(fv_(&fv)).enumerate() {
        dtau_dq[b * w + c] = xq;
        dtau_dqd[b * w + c] = xv;
    }
    if let Some(m) = m {
        for (b, x) in fv_(&fa).enumerate() {
            m[b * w + c] = x;
            m[c * w + b] = x;
        }
    }
    let row_q = &mut dtau_dq[c * w..c * w + NV_BASE];
    row_q[..3].fill(T::zero());
    row_q[3..].copy_from_slice(&fa.f.cross(g).to_array());
    let t = vb.cross_force(&fa);
    let row_v = &mut dtau_dqd[c * w..c * w + NV_BASE];
    row_v[..3].copy_from_slice(&(-t.f).to_array());
    row_v[3..].copy_from_slice(&(bt - t.n).to_array());
}

/// Whether body i's parent is body i - 1 for every i (a serial chain in tree order).
#[inline(always)]
fn is_chain(model: &Model) -> bool {
    model.parent.iter().enumerate().all(|(i, &p)| p == i.checked_sub(1))
}

/// The joint terms `Ia qdd + Fv qd + Fc sign(qd) + offset` of `rnea` (docs/architecture.md), differentiated:
/// `M += diag(Ia)`, `dtau/dqd += diag(Fv)`. `sign(qd)` is piecewise constant, so the Coulomb
/// term adds nothing to `dtau/dqd` for `qd != 0`; at `qd = 0` (where it jumps and has no
/// derivative) we report the same 0, the one-sided derivative of either side, consistent with
/// rnea's `sign(0) = 0`. The offset is constant: nothing. `dtau/dq` is unchanged.
#[inline(always)]
pub fn add_joint_dynamics_derivatives<T: Real>(model: &Model, dtau_dqd: &mut [T], m: Option<&mut [T]>) {
    add_joint_dynamics_at(model, dtau_dqd, m, model.nv, 0);
}

/// [`add_joint_dynamics_derivatives`] into matrices `stride` wide whose joints' block
/// starts at row and column `off`.
#[inline(always)]
fn add_joint_dynamics_at<T: Real>(model: &Model, dtau_dqd: &mut [T], mut m: Option<&mut [T]>, stride: usize, off: usize) {
    for i in 0..model.nv {
        let jd = &model.joint_dynamics[i];
        let k = (off + i) * stride + off + i;
        if let Some(m) = m.as_deref_mut() {
            m[k] += T::splat(jd.armature);
        }
        dtau_dqd[k] += T::splat(jd.viscous);
    }
}
