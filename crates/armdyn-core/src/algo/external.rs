//! External forces: one wrench per link, and what they do to the joints.
//!
//! A wrench on link `L` is `w_L = [f; n]` (force, then moment: the API's `[linear;
//! angular]` order, as the Jacobian's `[v; w]` rows), given in one of two frames
//! ([`ForceFrame`]). Its generalized force is `tau_ext = sum_L J_L^T w_L` (RBDA 5.3:
//! external forces enter the RNEA as `f_i = I_i a_i + v_i x* I_i v_i - f^x_i`), so
//!
//! * inverse dynamics with external forces is `rnea(q, qd, qdd) - tau_ext`;
//! * forward dynamics with external forces is `aba(q, qd, tau + tau_ext)`,
//!
//! since `M qdd + C qd + g = tau + tau_ext`. Computing `tau_ext` in its own backward pass
//! leaves `rnea.rs` and `aba.rs` as they are. The derivative algorithms instead take the
//! forces into their bodies' bias forces (`rnea_derivatives::velocity_pass`). Both start
//! from [`body_forces`], the one place a link's wrench is moved to its body.

use crate::algo::kinematics::{update_x0, update_xup};
use crate::algo::{aba, rnea};
use crate::data::Data;
use crate::deriv_data::DerivData;
use crate::model::Model;
use crate::real::Real;
use crate::spatial::{Force, M3, V3};

/// The frame external wrenches are given in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ForceFrame {
    /// The link's own frame: force and moment about the link frame's origin, in link
    /// axes (Pinocchio's LOCAL). The wrench moves with the link.
    Local,
    /// The base frame: force and moment about the base frame's origin, in base axes
    /// (Pinocchio's WORLD). The wrench stays fixed in space when the link moves.
    World,
}

/// External wrenches: `wrenches` is `(nlinks, 6)` row-major, one `[f; n]` per link of
/// the description (base first, its row has no effect on the joints).
#[derive(Clone, Copy, Debug)]
pub struct ExternalForces<'a, T> {
    pub wrenches: &'a [T],
    pub frame: ForceFrame,
}

impl<'a, T: Real> ExternalForces<'a, T> {
    /// Link `k`'s wrench as a spatial force `[n; f]` in its given frame.
    #[inline(always)]
    pub(crate) fn raw(&self, k: usize) -> Force<T> {
        let w = &self.wrenches[6 * k..6 * k + 6];
        Force::new(V3::new(w[3], w[4], w[5]), V3::new(w[0], w[1], w[2]))
    }
}

/// Link `k`'s wrench (given in its own frame) in the frame of the body carrying it:
/// `f_b = R f`, `n_b = R n + p x f_b` with `(R, p)` the link's constant pose in the body.
#[inline(always)]
pub(crate) fn local_in_body<T: Real>(model: &Model, k: usize, w: &Force<T>) -> Force<T> {
    let lf = &model.links[k];
    let r = M3::<T>::splat(lf.rotation);
    let f = r.mul_v(w.f);
    Force::new(r.mul_v(w.n) + V3::splat(lf.translation).cross(f), f)
}

/// The coordinates [`body_forces`] gives each body's external force in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Coordinates {
    /// The body's own frame (about its origin, in its axes): RBDA's `^iX_0^* f^x_i`.
    Body,
    /// The base frame (about the base origin, in base axes) for every body.
    Base,
}

/// The external force `f^x_i` on each body, the sum of its links' wrenches, in
/// `coords`, into `out` (nv,): a link's wrench is first placed on the body carrying it
/// (its constant pose there for `Local`), then moved by `^iX_0` (`data.x0`, which must
/// be current) when its frame and `coords` differ. Inlined, so that `coords` (a constant
/// at each call) leaves one case per frame in the loop, as when it was written out twice.
#[inline(always)]
pub(crate) fn body_forces<T: Real>(
    model: &Model,
    data: &Data<T>,
    ext: &ExternalForces<T>,
    coords: Coordinates,
    out: &mut [Force<T>],
) {
    assert_eq!(ext.wrenches.len(), 6 * model.nlinks(), "f_ext size");
    out.iter_mut().for_each(|f| *f = Force::zero());
    for k in 0..model.nlinks() {
        if let Some(b) = model.links[k].body {
            let w = ext.raw(k);
            out[b] += match (ext.frame, coords) {
                (ForceFrame::Local, Coordinates::Body) => local_in_body(model, k, &w),
                (ForceFrame::Local, Coordinates::Base) => data.x0[b].tr_apply_force(&local_in_body(model, k, &w)),
                (ForceFrame::World, Coordinates::Body) => data.x0[b].apply_force(&w),
                (ForceFrame::World, Coordinates::Base) => w,
            };
        }
    }
}

/// `tau_ext = sum_L J_L^T w_L` (nv,): the joint torques balancing the external wrenches,
/// by one backward pass over the body forces of [`body_forces`] (`tau_i = S_i^T F_i`,
/// `F_lambda += X^T F_i`, RBDA Table 5.1). Uses `dd.f` as scratch; writes `data.xup`
/// (and `data.x0` for `World`).
pub fn generalized_forces<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    dd: &mut DerivData<T>,
    q: &[T],
    ext: &ExternalForces<T>,
    tau_ext: &mut [T],
) {
    let n = model.nv;
    assert!(q.len() == model.nq && tau_ext.len() == n && ext.wrenches.len() == 6 * model.nlinks(), "argument size");
    update_xup(model, data, q);
    if ext.frame == ForceFrame::World {
        update_x0(model, data);
    }
    body_forces(model, data, ext, Coordinates::Body, &mut dd.f);
    for i in (0..n).rev() {
        tau_ext[i] = model.kind[i].s_dot(&dd.f[i]);
        if let Some(p) = model.parent[i] {
            let fp = data.xup[i].tr_apply_force(&dd.f[i]);
            dd.f[p] += fp;
        }
    }
}

/// Inverse dynamics with external wrenches: `tau = M qdd + C qd + g - sum_L J_L^T w_L`.
/// `q`, `qd`, `qdd`, `tau`: (nv,).
pub fn rnea_ext<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    dd: &mut DerivData<T>,
    q: &[T],
    qd: &[T],
    qdd: &[T],
    ext: &ExternalForces<T>,
    tau: &mut [T],
) {
    let mut tau_ext = std::mem::take(&mut dd.tau);
    generalized_forces(model, data, dd, q, ext, &mut tau_ext);
    rnea(model, data, q, qd, qdd, tau);
    for (t, e) in tau.iter_mut().zip(&tau_ext) {
        *t -= *e;
    }
    dd.tau = tau_ext;
}

/// Forward dynamics with external wrenches: `qdd = aba(q, qd, tau + sum_L J_L^T w_L)`.
/// `q`, `qd`, `tau`, `qdd`: (nv,).
pub fn aba_ext<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    dd: &mut DerivData<T>,
    q: &[T],
    qd: &[T],
    tau: &[T],
    ext: &ExternalForces<T>,
    qdd: &mut [T],
) {
    let mut total = std::mem::take(&mut dd.tau);
    generalized_forces(model, data, dd, q, ext, &mut total);
    for (t, u) in total.iter_mut().zip(tau) {
        *t += *u;
    }
    aba(model, data, q, qd, &total, qdd);
    dd.tau = total;
}
