//! Analytical derivatives of forward dynamics, after J. Carpentier and N. Mansard,
//! "Analytical Derivatives of Rigid Body Dynamics Algorithms", RSS 2018, Section IV.C:
//! differentiating `ID(q, qd, FD(q, qd, tau)) = tau` gives
//!
//! ```text
//! dFD/dq = -M^-1 dID/dq,   dFD/dqd = -M^-1 dID/dqd,   dFD/dtau = M^-1,
//! ```
//!
//! with the inverse-dynamics derivatives taken at `qdd = FD(q, qd, tau)`. One ABA (in
//! base coordinates) gives `qdd` and the articulated inertias that `minverse_sweeps`
//! turns into M^-1; the passes of `rnea_derivatives` give `dID/dq`, `dID/dqd`; two
//! (nv x nv) products finish.
//!
//! Joint friction, rotor inertia and offset follow without a case of their own: `aba`
//! puts `Ia` into `D_i = S^T I^A S + Ia` (so M^-1 is that of `M + diag(Ia)`), and
//! `rnea_derivatives` adds `diag(Fv)` to `dID/dqd` (Coulomb friction: 0, see there).

use crate::algo::aba::{articulated_inertias, joint_accelerations, BaseFrame};
use crate::algo::external::ExternalForces;
use crate::algo::minverse::minverse_sweeps;
use crate::algo::rnea_derivatives::{acceleration_pass, derivative_terms, subtree_sums, velocity_pass};
use crate::data::Data;
use crate::deriv_data::DerivData;
use crate::model::Model;
use crate::real::Real;
use crate::spatial::{ArticulatedInertia, Motion, V3};

/// Partial derivatives of `qdd = aba(q, qd, tau)` (with external wrenches `ext`, if any:
/// `M qdd + C qd + g = tau + sum_L J_L^T w_L`).
///
/// `q`, `qd`, `tau`: (nv,). Writes `dqdd_dq`, `dqdd_dqd` and `minv` = `dqdd/dtau` =
/// M(q)^-1, each (nv, nv) row-major, `[i * nv + j] = d qdd_i / d x_j`; and `qdd` (nv,).
///
/// One set of kinematics serves everything (as in Pinocchio's `computeABADerivatives`):
/// the velocity pass of `rnea_derivatives` (base-frame axes, velocities, inertias), the
/// ABA in base coordinates on them (`aba_world`), whose articulated inertias give M^-1
/// ([`minverse_sweeps`]), then the acceleration and backward passes of
/// `rnea_derivatives` at `qdd` and its (body, ancestor) terms without M.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn aba_derivatives<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    dd: &mut DerivData<T>,
    q: &[T],
    qd: &[T],
    tau: &[T],
    ext: Option<&ExternalForces<T>>,
    dqdd_dq: &mut [T],
    dqdd_dqd: &mut [T],
    minv: &mut [T],
) {
    let n = model.nv;
    assert!(q.len() == model.nq && qd.len() == n && tau.len() == n, "state length");
    assert!(dqdd_dq.len() == n * n && dqdd_dqd.len() == n * n && minv.len() == n * n, "output size");
    velocity_pass(model, data, dd, q, qd, ext);
    let mut qdd = std::mem::take(&mut dd.qdd);
    aba_world(model, data, dd, qd, tau, &mut qdd);
    acceleration_pass(model, dd, qd, &qdd);
    subtree_sums(model, dd, ext);
    minverse_sweeps(model, data, dd, minv);
    // dID/dq and dID/dqd at qdd
    let (mut dq, mut dqd) = (std::mem::take(&mut dd.dq), std::mem::take(&mut dd.dqd));
    derivative_terms(model, dd, ext, &mut dq, &mut dqd, None);
    // dqdd/dx = -Minv dID/dx
    for i in 0..n {
        for j in 0..n {
            let (mut a, mut b) = (T::zero(), T::zero());
            for k in 0..n {
                let mik = minv[i * n + k];
                a += mik * dq[k * n + j];
                b += mik * dqd[k * n + j];
            }
            dqdd_dq[i * n + j] = -a;
            dqdd_dqd[i * n + j] = -b;
        }
    }
    dd.dq = dq;
    dd.dqd = dqd;
    dd.qdd = qdd;
}

/// The articulated-body algorithm (RBDA Table 7.1) in base coordinates, after
/// [`velocity_pass`]: its pass 1 from the velocity pass's body inertias `dd.ic[i]`, bias
/// forces `dd.f[i]` (`v_i x* I_i v_i - f^x_i`) and `c_i = (v_i x J_i) qd_i = dV_i qd_i`;
/// passes 2 and 3 shared with `aba` ([`articulated_inertias`], [`joint_accelerations`])
/// with `J_i = dd.s[i]` for `S_i`. Writes `qdd` (nv,) and, in base coordinates,
/// `data.ia`, `data.pa`, `data.c`, `data.u_col`, `data.d_inv`, `data.u`, `data.a`.
#[inline(always)]
fn aba_world<T: Real>(model: &Model, data: &mut Data<T>, dd: &DerivData<T>, qd: &[T], tau: &[T], qdd: &mut [T]) {
    for i in 0..model.nv {
        data.ia[i] = ArticulatedInertia::from_rigid(&dd.ic[i]);
        data.pa[i] = dd.f[i];
        data.c[i] = dd.dvdq[i].scale(qd[i]);
    }
    let frames = BaseFrame(&dd.s[..]);
    articulated_inertias(model, data, &frames, Some((qd, tau)));
    let a0 = Motion::new(V3::splat(model.a0.w), V3::splat(model.a0.v));
    joint_accelerations(model, data, &frames, qdd, &a0);
}
