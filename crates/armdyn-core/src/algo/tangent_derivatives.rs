//! The derivatives of the RNEA and the ABA on the tangent space for models with joints
//! of several coordinates (`joint_multi.rs`), fixed or floating base, by forward-mode
//! automatic differentiation: the second opinion the analytical ones
//! (`multi_derivatives.rs`, what the bindings call) are tested against, written from the
//! definition alone: the RNEA runs on [`Dual`] numbers carrying [`DIRECTIONS`]
//! directions at a time, the velocity coordinates' for `d tau / dq` (the configuration
//! moved along the tangent direction, `q ⊕ ε e_m`, as Pinocchio's `integrate`), then for
//! `d tau / dv`. The results are exact to rounding, as the analytical derivatives of the
//! 1-dof algorithms (`rnea_derivatives.rs`), at `2 nv / DIRECTIONS` dual-number passes
//! instead of one sweep.
//!
//! The ABA's follow from the RNEA's at `a = aba(q, v, tau)`:
//! `da/dq = -M^-1 dtau/dq`, `da/dv = -M^-1 dtau/dv` (differentiate `M a + h = tau`).
//!
//! Arrays: `q` (nq,) with a floating base's 7 first; `v`, `a`, `tau` (nv,); outputs
//! (nv, nv) row-major, `[r * nv + m] = d out_r / d x_m` (nq, nv include the base's).

use crate::algo::floating::quaternion_rotation;
use crate::algo::floating_kinematics::base_widths;
use crate::algo::multi_derivatives::{forward_and_inverse, minus_minv_times};
use crate::algo::{crba, crba_floating, rnea, rnea_floating};
use crate::data::Data;
use crate::deriv_data::DerivData;
use crate::dual::Dual;
use crate::joint_multi::MultiKind;
use crate::model::Model;
use crate::spatial::V3;

/// Directions carried by one dual-number pass.
pub const DIRECTIONS: usize = 4;
type D = Dual<DIRECTIONS>;

/// The workspaces of one derivative call: dual-number RNEA, the f64 CRBA / M^-1, and
/// the argument buffers. Allocated once per thread.
pub struct TangentWork {
    data: Data<D>,
    data64: Data<f64>,
    deriv: DerivData<f64>,
    q: Vec<D>,
    v: Vec<D>,
    a: Vec<D>,
    tau: Vec<D>,
    acc: Vec<f64>,
    product: Vec<f64>,
}

impl TangentWork {
    pub fn new(model: &Model, floating: bool) -> Self {
        let (qb, vb) = base_widths(floating);
        let (nq, nv) = (model.nq + qb, model.nv + vb);
        TangentWork {
            data: Data::new(model),
            data64: Data::new(model),
            deriv: DerivData::new(model),
            q: vec![D::default(); nq],
            v: vec![D::default(); nv],
            a: vec![D::default(); nv],
            tau: vec![D::default(); nv],
            acc: vec![0.0; nv],
            product: vec![0.0; nv * nv],
        }
    }
}

/// `d quat` for the unit quaternion `x, y, z, w` at `q[0..4]` turned by `ε e_k` in its
/// own frame, `1/2 quat ⊗ (e_k, 0)`, into direction `lane` of `out`.
fn quaternion_turn(q: &[f64], k: usize, out: &mut [D], lane: usize) {
    let (qv, w) = (V3::new(q[0], q[1], q[2]), q[3]);
    let mut e = [0.0; 3];
    e[k] = 1.0;
    let e = V3::from_array(e);
    let dv = (e.scale(w) + qv.cross(e)).scale(0.5);
    for (o, d) in out.iter_mut().zip(dv.to_array().into_iter().chain([-0.5 * qv.dot(e)])) {
        o.du[lane] = d;
    }
}

/// `ε`-move of the origin at `p` (3) by `ε R(quat) e_k`: a free body's translation
/// along its own axis `k`, into direction `lane` of `out`.
fn slide(quat: &[f64], k: usize, out: &mut [D], lane: usize) {
    let r = quaternion_rotation(quat[0], quat[1], quat[2], quat[3]);
    for (o, d) in out.iter_mut().zip(r.col(k).to_array()) {
        o.du[lane] = d;
    }
}

/// Direction `lane` of `out` (holding `q`'s values) set to `d q / dε` for `q ⊕ ε e_m`:
/// the configuration moved along velocity coordinate `m`, as Pinocchio's
/// `integrate(q, ε e_m)`, to first order (exactly, in dual numbers).
pub fn tangent_direction(model: &Model, floating: bool, q: &[f64], m: usize, out: &mut [D], lane: usize) {
    let (qb, vb) = base_widths(floating);
    if m < vb {
        match m {
            0..=2 => slide(&q[3..7], m, &mut out[0..3], lane),
            _ => quaternion_turn(&q[3..7], m - 3, &mut out[3..7], lane),
        }
        return;
    }
    let b = m - vb;
    let Some(j) = model.multi.iter().rev().find(|j| j.body <= b) else {
        out[qb + model.idx_q[b]].du[lane] = 1.0;
        return;
    };
    let part = b - j.body;
    if part >= j.kind.parts().len() {
        out[qb + model.idx_q[b]].du[lane] = 1.0; // a 1-dof body after the joint
        return;
    }
    let at = qb + j.idx_q;
    match j.kind {
        MultiKind::Spherical => quaternion_turn(&q[at..at + 4], part, &mut out[at..at + 4], lane),
        MultiKind::Free if part < 3 => slide(&q[at + 3..at + 7], part, &mut out[at..at + 3], lane),
        MultiKind::Free => quaternion_turn(&q[at + 3..at + 7], part - 3, &mut out[at + 3..at + 7], lane),
        MultiKind::Planar => {
            let (c, s) = (q[at + 2], q[at + 3]);
            let d = match part {
                0 => [c, s, 0.0, 0.0],
                1 => [-s, c, 0.0, 0.0],
                _ => [0.0, 0.0, -s, c],
            };
            for (o, d) in out[at..at + 4].iter_mut().zip(d) {
                o.du[lane] = d;
            }
        }
    }
}

fn rnea_dual(model: &Model, floating: bool, w: &mut TangentWork) {
    if floating {
        rnea_floating(model, &mut w.data, &w.q, &w.v, &w.a, &mut w.tau);
    } else {
        rnea(model, &mut w.data, &w.q, &w.v, &w.a, &mut w.tau);
    }
}

/// `out[v] = x` with no derivative.
fn constant(x: &[f64], out: &mut [D]) {
    out.iter_mut().zip(x).for_each(|(o, &x)| *o = D::constant(x));
}

/// The (nv, nv) `out`, [`DIRECTIONS`] columns a pass: before each, `reset(w)` clears the
/// inputs' directions and `seed(w, lane, m)` puts column `m`'s in `lane`; the RNEA's
/// `du[lane]` is then column `m`.
fn columns_by_passes(
    model: &Model,
    floating: bool,
    w: &mut TangentWork,
    out: &mut [f64],
    reset: impl Fn(&mut TangentWork),
    seed: impl Fn(&mut TangentWork, usize, usize),
) {
    let nv = w.tau.len();
    for first in (0..nv).step_by(DIRECTIONS) {
        let columns = first..nv.min(first + DIRECTIONS);
        reset(w);
        for (lane, m) in columns.clone().enumerate() {
            seed(w, lane, m);
        }
        rnea_dual(model, floating, w);
        for (lane, m) in columns.enumerate() {
            for r in 0..nv {
                out[r * nv + m] = w.tau[r].du[lane];
            }
        }
    }
}

/// `dtau/dq` and `dtau/dv` (nv, nv) at `(q, v, a)`, [`DIRECTIONS`] columns per pass.
#[allow(clippy::too_many_arguments)]
fn rnea_partials(
    model: &Model,
    floating: bool,
    w: &mut TangentWork,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    dq: &mut [f64],
    dv: &mut [f64],
) {
    constant(a, &mut w.a);
    constant(v, &mut w.v);
    let along_q = |w: &mut TangentWork, lane: usize, m: usize| tangent_direction(model, floating, q, m, &mut w.q, lane);
    columns_by_passes(model, floating, w, dq, |w| constant(q, &mut w.q), along_q);
    constant(q, &mut w.q);
    columns_by_passes(model, floating, w, dv, |w| constant(v, &mut w.v), |w, lane, m| w.v[m].du[lane] = 1.0);
}

/// `(dtau/dq, dtau/dv, M)` at `(q, v, a)`: the tangent-space derivatives of the RNEA (see
/// the module) and the joint-space inertia matrix. Joint friction and rotor inertia are
/// included, as in `rnea` (`sign(qd)` has derivative 0).
#[allow(clippy::too_many_arguments)]
pub fn rnea_derivatives_tangent(
    model: &Model,
    floating: bool,
    w: &mut TangentWork,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    dtau_dq: &mut [f64],
    dtau_dv: &mut [f64],
    m: &mut [f64],
) {
    rnea_partials(model, floating, w, q, v, a, dtau_dq, dtau_dv);
    if floating {
        crba_floating(model, &mut w.data64, q, m);
    } else {
        crba(model, &mut w.data64, q, m);
    }
}

/// `(da/dq, da/dv, M^-1)` at `(q, v, tau)`: with `a = aba(q, v, tau)`,
/// `da/dx = -M^-1 dtau/dx` (see the module).
#[allow(clippy::too_many_arguments)]
pub fn aba_derivatives_tangent(
    model: &Model,
    floating: bool,
    w: &mut TangentWork,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    da_dq: &mut [f64],
    da_dv: &mut [f64],
    minv: &mut [f64],
) {
    let mut acc = std::mem::take(&mut w.acc);
    forward_and_inverse(model, floating, &mut w.data64, &mut w.deriv, q, v, tau, &mut acc, minv);
    // dtau/dq and dtau/dv into the outputs, then -M^-1 times each
    rnea_partials(model, floating, w, q, v, &acc, da_dq, da_dv);
    w.acc = acc;
    minus_minv_times(minv, [da_dq, da_dv], &mut w.product);
}
