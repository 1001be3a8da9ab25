//! Analytical derivatives of the floating-base dynamics (`algo::floating`, Pinocchio's
//! free-flyer root joint), on the tangent space as Pinocchio's `computeRNEADerivatives`
//! and `computeABADerivatives`: `d/dq` is the derivative along `integrate(q, dq)` at
//! `dq = 0`, `dq` (6 + nv) in the order of `v` (the base's displacement in its own
//! frame, linear then angular, then the joints).
//!
//! The free flyer is a 6-dof joint whose motion subspace is the identity in the base
//! frame (J. Carpentier and N. Mansard, "Analytical Derivatives of Rigid Body Dynamics
//! Algorithms", RSS 2018). Everything is written in the base frame at this instant,
//! held fixed in space while the derivatives are taken (any inertial frame will do at
//! `dq = 0`): the base's axes are then the unit motions `e_b`, gravity is the constant
//! fictitious acceleration `a_0 = [0; -R^T g]`, and the fixed-base passes of
//! `rnea_derivatives.rs` run unchanged once the root bodies' parent is the base, moving
//! with `v_B` and `a_B` (`velocity_pass_on`, `acceleration_pass_on`), its axes added as
//! the common ancestor of every body (`derivative_terms_in`). Moving `dq_b` turns the
//! whole robot rigidly about `e_b`: what follows the robot changes by `e_b x` and the
//! base's own axes with it, so in the base's 6x6 block the `e_b x* F` terms cancel
//! against those of the axes (as within one joint's columns), leaving, with `dV_b = 0`
//! (the world, the base's parent, is at rest) and `dA_b = a_0 x e_b`:
//!
//! ```text
//! dtau_c/dq_b = e_c^T I^c_B (a_0 x e_b),   M_cb = e_c^T I^c_B e_b,
//! dtau_c/dv_b = e_c^T (I^c_B (v_B x e_b) + B^c_B e_b)
//! ```
//!
//! with `I^c_B`, `B^c_B` the whole robot's composite inertia and `B` (base included).
//! In the velocity derivative `v_B x e_b` stands where a 1-dof joint has `2 dV`: the
//! free flyer's own `dJ/dt v = v_B x v_B` vanishes for every `v`, so only the bodies'
//! `(v_k x J_k) qd_k` depend on `v_b`, by `e_b x (v_k - v_B)` (`derivative_terms_in`).
//!
//! Forward dynamics as for a fixed base (`aba_derivatives.rs`): `dqdd/dx = -M^-1 dtau/dx`
//! at `qdd = aba(q, v, tau)`; M^-1 here from M's sparse `L^T D L` factors (RBDA 6.5, the
//! tree's sparsity, the base's six velocities a chain above the root joints), which
//! also solve for the two products row by row instead of forming them.
//!
//! External wrenches: in the link frames only (they move with their links; wrenches
//! fixed in space would need their own terms, as `ForceFrame::World` has for a fixed
//! base, and a world frame that is not the base's).

use crate::algo::external::{generalized_forces, local_in_body, ExternalForces, ForceFrame};
use crate::algo::floating::{
    aba_floating, base_motion, crba_floating, gravity_acceleration, put_base_block, NQ_BASE, NV_BASE,
};
use crate::algo::ltdl::{factorize, identity, solve};
use crate::algo::rnea_derivatives::{
    acceleration_pass_on, b_sym, derivative_terms_in, subtree_sums, velocity_pass_on, Placement,
};
use crate::data::Data;
use crate::deriv_data::DerivData;
use crate::model::Model;
use crate::real::Real;
use crate::spatial::{Force, Motion, RigidInertia, V3};

/// Partial derivatives of `tau = rnea_floating(q, v, a)`: `q` (7 + nv), `v`, `a`
/// (6 + nv), laid out as `algo::floating` says. Writes `dtau_dq` (along the tangent
/// space, see the module), `dtau_dv` and `m` = `dtau/da` = M(q), each (6 + nv)^2
/// row-major, `[i * (6 + nv) + j] = d tau_i / d x_j`. Joint friction and rotor inertia
/// as for a fixed base. Uses `data.xup`, `data.x0`.
///
/// `ext`: external wrenches given in the link frames ([`ForceFrame::Local`]; Pinocchio's
/// `fext`), then `tau = rnea_floating(q, v, a) - sum_L J_L^T w_L`. They move with their
/// links like the bodies' inertial forces, so they enter through the bodies' bias forces
/// alone (`velocity_pass_on`); those on links welded to the base only shift the base's
/// wrench by a constant of the base frame, which has no derivative.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn rnea_derivatives_floating<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    dd: &mut DerivData<T>,
    q: &[T],
    v: &[T],
    a: &[T],
    ext: Option<&ExternalForces<T>>,
    dtau_dq: &mut [T],
    dtau_dv: &mut [T],
    m: &mut [T],
) {
    let s = model.nv + NV_BASE;
    assert!(q.len() == model.nq + NQ_BASE && v.len() == s && a.len() == s, "state length");
    assert!(dtau_dq.len() == s * s && dtau_dv.len() == s * s && m.len() == s * s, "output size");
    assert!(ext.is_none_or(|e| e.frame == ForceFrame::Local), "floating base: wrenches in link frames only");
    let g = gravity_acceleration(model, q);
    let vb = base_motion(&v[..NV_BASE]);
    let ab = base_motion(&a[..NV_BASE]) + g;
    let (qj, vj, aj) = (&q[NQ_BASE..], &v[NV_BASE..], &a[NV_BASE..]);
    velocity_pass_on(model, data, dd, qj, vj, ext, Some(vb));
    acceleration_pass_on(model, dd, vj, aj, Some((vb, ab)));
    subtree_sums(model, dd, ext);
    let at = Placement { stride: s, base: Some((g.v, vb)) };
    derivative_terms_in(model, dd, ext, dtau_dq, dtau_dv, Some(&mut *m), at);
    base_block(model, dd, &vb, g.v, dtau_dq, dtau_dv, m);
}

/// The base's 6x6 blocks (module docs), after the passes: the subtree sums of the root
/// bodies plus the base's own inertia and `B` give `I^c_B`, `B^c_B = [S - N^x, 0; -2P^x, 0]`
/// (`rnea_derivatives.rs`). `a_0 x e_b` is 0 for a linear `e_b` (so is that column of
/// `dtau/dq`) and `[0; g x e]` for an angular one; `B e_b` is 0 for a linear `e_b`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn base_block<T: Real>(
    model: &Model,
    dd: &DerivData<T>,
    vb: &Motion<T>,
    g: V3<T>,
    dtau_dq: &mut [T],
    dtau_dv: &mut [T],
    m: &mut [T],
) {
    let s = model.nv + NV_BASE;
    let ib = RigidInertia::splat(&model.base_inertia);
    let h = ib.mul_motion(vb);
    let (mut ic, mut bs, mut bn, mut bp) = (ib, b_sym(&ib, vb), h.n, h.f);
    for i in (0..model.nv).filter(|&i| model.parent[i].is_none()) {
        ic += dd.ic[i];
        bs = bs + dd.bs[i];
        bn += dd.bn[i];
        bp += dd.bp[i];
    }
    let p2 = bp + bp;
    for k in 0..3 {
        let mut unit = [T::zero(); 3];
        unit[k] = T::splat(1.0);
        let e = V3::from_array(unit);
        let (linear, angular) = (Motion::new(V3::zero(), e), Motion::new(e, V3::zero()));
        let fq = ic.mul_motion(&Motion::new(V3::zero(), g.cross(e)));
        let fv_lin = ic.mul_motion(&vb.cross_motion(&linear));
        let fv_ang = ic.mul_motion(&vb.cross_motion(&angular)) + Force::new(bs.mul_v(e) - bn.cross(e), e.cross(p2));
        for (r, x) in fq.f.to_array().into_iter().chain(fq.n.to_array()).enumerate() {
            dtau_dq[r * s + k] = T::zero();
            dtau_dq[r * s + 3 + k] = x;
        }
        for (c, fv) in [(k, fv_lin), (3 + k, fv_ang)] {
            for (r, x) in fv.f.to_array().into_iter().chain(fv.n.to_array()).enumerate() {
                dtau_dv[r * s + c] = x;
            }
        }
    }
    put_base_block(&ic, m, s);
}

/// Partial derivatives of `a = aba_floating(q, v, tau)`: `q` (7 + nv), `v`, `tau`
/// (6 + nv). Writes `da_dq` (tangent space), `da_dv` and `minv` = `da/dtau` = M(q)^-1,
/// each (6 + nv)^2 row-major, `[i * (6 + nv) + j] = d a_i / d x_j`: `aba_floating`, then
/// [`rnea_derivatives_floating`] at its acceleration, then `-M^-1` of its results from
/// M's sparse factors (module docs). Uses `dd.qdd_floating` and `dd.factor`.
///
/// `ext`: wrenches in the link frames, as for [`rnea_derivatives_floating`]; then
/// `a = aba_floating(q, v, tau + sum_L J_L^T w_L)` ([`generalized_forces_floating`]).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn aba_derivatives_floating<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    dd: &mut DerivData<T>,
    q: &[T],
    v: &[T],
    tau: &[T],
    ext: Option<&ExternalForces<T>>,
    da_dq: &mut [T],
    da_dv: &mut [T],
    minv: &mut [T],
) {
    let s = model.nv + NV_BASE;
    assert!(tau.len() == s && minv.len() == s * s, "state length");
    let (mut qdd, mut h) = (std::mem::take(&mut dd.qdd_floating), std::mem::take(&mut dd.factor));
    match ext {
        Some(e) => {
            // tau + tau_ext, in the factors' buffer until M overwrites it
            let total = &mut h[..s];
            generalized_forces_floating(model, data, dd, q, e, total);
            total.iter_mut().zip(tau).for_each(|(t, u)| *t += *u);
            aba_floating(model, data, q, v, &h[..s], &mut qdd);
        }
        None => aba_floating(model, data, q, v, tau, &mut qdd),
    }
    rnea_derivatives_floating(model, data, dd, q, v, &qdd, ext, da_dq, da_dv, &mut h);
    factorize::<T, NV_BASE>(model, &mut h);
    identity(minv, s);
    let (one, minus) = (T::splat(1.0), T::splat(-1.0));
    solve::<T, 3, NV_BASE>(model, &h, [minv, da_dq, da_dv], [one, minus, minus]);
    dd.qdd_floating = qdd;
    dd.factor = h;
}

/// `tau_ext = sum_L J_L^T w_L` (6 + nv) of wrenches given in the link frames on a
/// floating base: the joints' part by the fixed-base backward pass
/// ([`generalized_forces`], which leaves the root bodies' subtree forces in `dd.f`), the
/// base's the wrench those exert on it plus the wrenches on links welded to it, in the
/// base frame, force then moment. `q`: (7 + nv).
pub fn generalized_forces_floating<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    dd: &mut DerivData<T>,
    q: &[T],
    ext: &ExternalForces<T>,
    tau_ext: &mut [T],
) {
    assert!(ext.frame == ForceFrame::Local, "floating base: wrenches in link frames only");
    let (head, tail) = tau_ext.split_at_mut(NV_BASE);
    generalized_forces(model, data, dd, &q[NQ_BASE..], ext, tail);
    let mut fb = Force::zero();
    for i in (0..model.nv).filter(|&i| model.parent[i].is_none()) {
        fb += data.xup[i].tr_apply_force(&dd.f[i]);
    }
    for k in (0..model.nlinks()).filter(|&k| model.links[k].body.is_none()) {
        fb += local_in_body(model, k, &ext.raw(k));
    }
    head[..3].copy_from_slice(&fb.f.to_array());
    head[3..].copy_from_slice(&fb.n.to_array());
}

/// M(q)^-1 of the floating-base tree, (6 + nv)^2 row-major, from `crba_floating` and
/// M's sparse factors (module docs). `q`: (7 + nv). Uses `dd.factor`.
#[inline(always)]
pub fn minverse_floating<T: Real>(model: &Model, data: &mut Data<T>, dd: &mut DerivData<T>, q: &[T], minv: &mut [T]) {
    let s = model.nv + NV_BASE;
    assert!(minv.len() == s * s, "output size");
    let mut h = std::mem::take(&mut dd.factor);
    crba_floating(model, data, q, &mut h);
    factorize::<T, NV_BASE>(model, &mut h);
    identity(minv, s);
    solve::<T, 1, NV_BASE>(model, &h, [minv], [T::splat(1.0)]);
    dd.factor = h;
}
