//! Analytical derivatives of forward dynamics, after J. Carpentier and N. Mansard,
//! "Analytical Derivatives of Rigid Body Dynamics Algorithms", RSS 2018, Section IV.C:
//! differentiating `ID(q, qd, FD(q, qd, tau)) = tau` gives
//!
//! ```text
//! dFD/dq = -M^-1 dID/dq,   dFD/dqd = -M^-1 dID/dqd,   dFD/dtau = M^-1,
//! ```
//!
//! with the inverse-dynamics derivatives taken at `qdd = FD(q, qd, tau)`. One ABA gives
//! `qdd` and the articulated inertias that `minverse_from_articulated` turns into M^-1;
//! `rnea_derivatives` gives `dID/dq`, `dID/dqd`; two (nv x nv) products finish.
//!
//! Joint friction, rotor inertia and offset follow without a case of their own: `aba`
//! puts `Ia` into `D_i = S^T I^A S + Ia` (so M^-1 is that of `M + diag(Ia)`), and
//! `rnea_derivatives` adds `diag(Fv)` to `dID/dqd` (Coulomb friction: 0, see there).

use crate::algo::aba;
use crate::algo::external::{generalized_forces, ExternalForces};
use crate::algo::minverse::minverse_from_articulated;
use crate::algo::rnea_derivatives::rnea_derivatives;
use crate::data::Data;
use crate::deriv_data::DerivData;
use crate::model::Model;
use crate::real::Real;

/// Partial derivatives of `qdd = aba(q, qd, tau)` (with external wrenches `ext`, if any:
/// `M qdd + C qd + g = tau + sum_L J_L^T w_L`).
///
/// `q`, `qd`, `tau`: (nv,). Writes `dqdd_dq`, `dqdd_dqd` and `minv` = `dqdd/dtau` =
/// M(q)^-1, each (nv, nv) row-major, `[i * nv + j] = d qdd_i / d x_j`; and `qdd` (nv,).
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
    assert!(q.len() == n && qd.len() == n && tau.len() == n, "state length");
    assert!(dqdd_dq.len() == n * n && dqdd_dqd.len() == n * n && minv.len() == n * n, "output size");
    let mut total = std::mem::take(&mut dd.tau);
    match ext {
        Some(e) => {
            generalized_forces(model, data, dd, q, e, &mut total);
            total.iter_mut().zip(tau).for_each(|(t, u)| *t += *u);
        }
        None => total.copy_from_slice(tau),
    }
    let mut qdd = std::mem::take(&mut dd.qdd);
    aba(model, data, q, qd, &total, &mut qdd);
    dd.tau = total;
    minverse_from_articulated(model, data, dd, minv);
    // dID/dq and dID/dqd at qdd; dqdd_dq serves as scratch for the unused M.
    let (mut dq, mut dqd) = (std::mem::take(&mut dd.dq), std::mem::take(&mut dd.dqd));
    rnea_derivatives(model, data, dd, q, qd, &qdd, ext, &mut dq, &mut dqd, dqdd_dq);
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
