//! The analytical derivatives of the RNEA for models with joints of several coordinates
//! (`joint_multi.rs`), on the tangent space as Pinocchio's: the 1-dof sweep
//! (`rnea_derivatives.rs`, `floating_derivatives.rs`) run on the chain of parts, then a
//! correction per joint from the chain's coordinates to the joint's.
//!
//! The chain of parts, read as an ordinary tree of 1-dof joints `P_0(ε_0) ⋯ P_n-1(ε_n-1)`
//! at `ε = 0` with rates `ė`, `ë` and the ordinary velocity products, moves the child
//! with the relative twist `v_J = J(ε) ė`, `J`'s column `k` the part's axis `S_k` seen
//! from the child, `exp(-ε_n-1 ad_S_n-1) ⋯ exp(-ε_k+1 ad_S_k+1) S_k`; so the joint's
//! velocity `v` and acceleration `a = d/dt v_J` are the chain's at `ė = J^-1 v`,
//! `ë = J^-1 (a - J̇ ė)`, and its torque is `J^-T` times the chain's. At `ε = 0`,
//! `J = 1` and `J̇ ė = Δ(v) = sum_k<l v_k v_l [S_k, S_l]` (`[,]` the motion cross
//! product), so with `τ_ch` the chain's function:
//!
//! * `dτ/da = M`;
//! * `dτ/dv = dτ_ch/dė - M dΔ/dv` (the sweep run at `ë = a - Δ(v)`);
//! * `dτ/dδ_m = dτ_ch/dε_m + dτ_ch/dė dė/dε_m + M dë/dε_m - (dJ/dε_m)^T τ` (the last on
//!   the joint's own rows), with `dė/dε_m = -dJ/dε_m v` and
//!   `dë/dε_m = -dJ/dε_m (a - Δ(v)) - d(J̇ ė)/dε_m`, whose second derivatives of `J` are
//!   `[S_m, [S_m, S_k]]` and `[S_hi, [S_lo, S_k]]` (`ε`'s order in the product).
//!
//! External wrenches (in the link frames on a floating base) enter the chain's function:
//! the sweep takes them, and `τ` in the last term is the torque with them (`τ = J^-T τ_ch`,
//! whatever `τ_ch` holds).
//!
//! Joint friction and rotor inertia on a joint's coordinates act on its own velocity and
//! acceleration (`Ia a + Fv v + ...`, as MuJoCo's armature and damping on a ball joint),
//! outside the change of coordinates: the sweep's are taken out of `M`, `dtau/dv` and
//! `tau` where the corrections use the chain's rigid-body terms.
//!
//! Arrays as `tangent_derivatives.rs` (a floating base's six first).

use crate::algo::external::{generalized_forces, ExternalForces};
use crate::algo::floating::NV_BASE;
use crate::algo::floating_derivatives::generalized_forces_floating;
use crate::algo::floating_kinematics::base_widths;
use crate::algo::ltdl::{factorize, identity, solve};
use crate::algo::{rnea, rnea_derivatives, rnea_derivatives_floating, rnea_floating};
use crate::data::Data;
use crate::deriv_data::DerivData;
use crate::joint_multi::MultiKind;
use crate::model::Model;

/// Largest number of parts of a joint (a free joint's six).
const MAX_PARTS: usize = 6;

/// A joint's parts' axes in its own frame, `[w; v]`.
fn axes(kind: MultiKind) -> [[f64; 6]; MAX_PARTS] {
    let mut s = [[0.0; 6]; MAX_PARTS];
    for (k, &(part, axis)) in kind.parts().iter().enumerate() {
        let linear = part == crate::joint::JointKind::PrismaticZ;
        s[k][if linear { 3 } else { 0 }..][..3].copy_from_slice(&axis);
    }
    s
}

/// The motion cross product `[w1; v1] x [w2; v2] = [w1 x w2; w1 x v2 + v1 x w2]`.
fn cross(a: &[f64; 6], b: &[f64; 6]) -> [f64; 6] {
    let c = |x: &[f64], y: &[f64]| [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]];
    let (ww, wv, vw) = (c(&a[..3], &b[..3]), c(&a[..3], &b[3..]), c(&a[3..], &b[..3]));
    [ww[0], ww[1], ww[2], wv[0] + vw[0], wv[1] + vw[1], wv[2] + vw[2]]
}

/// The structure of one joint's algebra in its parts' basis (the axes are unit
/// coordinate vectors, so a product's coordinates are its dot products with them):
/// `c[k][l][p]` = `[S_k, S_l]`'s coordinate `p`, `cc[h][l][k][p]` = `[S_h, [S_l, S_k]]`'s.
struct Algebra {
    n: usize,
    c: [[[f64; MAX_PARTS]; MAX_PARTS]; MAX_PARTS],
    cc: [[[[f64; MAX_PARTS]; MAX_PARTS]; MAX_PARTS]; MAX_PARTS],
}

impl Algebra {
    fn new(kind: MultiKind) -> Self {
        let s = axes(kind);
        let n = kind.parts().len();
        let coords =
            |x: [f64; 6]| std::array::from_fn(|p| if p < n { (0..6).map(|i| x[i] * s[p][i]).sum() } else { 0.0 });
        let mut c = [[[0.0; MAX_PARTS]; MAX_PARTS]; MAX_PARTS];
        let mut cc = [[[[0.0; MAX_PARTS]; MAX_PARTS]; MAX_PARTS]; MAX_PARTS];
        for k in 0..n {
            for l in 0..n {
                let b = cross(&s[k], &s[l]);
                c[k][l] = coords(b);
                for h in 0..n {
                    cc[h][k][l] = coords(cross(&s[h], &b));
                }
            }
        }
        Algebra { n, c, cc }
    }

    /// `dJ/dε_m` (n x n, `[p][k]`): `-[S_m, S_k]` for `m > k`, else 0.
    fn dj(&self, m: usize) -> [[f64; MAX_PARTS]; MAX_PARTS] {
        let mut d = [[0.0; MAX_PARTS]; MAX_PARTS];
        for k in 0..m {
            for p in 0..self.n {
                d[p][k] = -self.c[m][k][p];
            }
        }
        d
    }

    /// `Δ(v) = sum_k<l v_k v_l [S_k, S_l]`.
    fn delta(&self, v: &[f64]) -> [f64; MAX_PARTS] {
        let mut d = [0.0; MAX_PARTS];
        for k in 0..self.n {
            for l in k + 1..self.n {
                for p in 0..self.n {
                    d[p] += v[k] * v[l] * self.c[k][l][p];
                }
            }
        }
        d
    }

    /// `d(J̇ ė)/dε_m` at `ε = 0`, `ė = v`, with `dė = dė/dε_m`.
    fn djdot(&self, m: usize, v: &[f64], de: &[f64; MAX_PARTS]) -> [f64; MAX_PARTS] {
        let n = self.n;
        let mut out = [0.0; MAX_PARTS];
        // J̇ ė = sum_l sum_k<l (dJ_k/dε_l) ė_l ė_k, dJ_k/dε_l = -[S_l, S_k]
        for l in 0..n {
            for k in 0..l {
                for p in 0..n {
                    // the rates' change
                    out[p] -= self.c[l][k][p] * (de[l] * v[k] + v[l] * de[k]);
                    // J's second derivative, ε_m and ε_l both after k in the product
                    if m > k {
                        let (hi, lo) = (m.max(l), m.min(l));
                        out[p] += self.cc[hi][lo][k][p] * v[l] * v[k];
                    }
                }
            }
        }
        out
    }
}

/// The workspaces of [`rnea_derivatives_multi`]: the sweep's, the chain's accelerations
/// and the torques. Allocated once per thread.
pub struct MultiWork {
    data: Data<f64>,
    deriv: DerivData<f64>,
    a_chain: Vec<f64>,
    tau: Vec<f64>,
    /// The external wrenches' generalized forces.
    tau_ext: Vec<f64>,
    /// The ABA's accelerations and M's factors ([`aba_derivatives_multi`]).
    acc: Vec<f64>,
    product: Vec<f64>,
    algebras: Vec<Algebra>,
}

impl MultiWork {
    pub fn new(model: &Model, floating: bool) -> Self {
        let nv = model.nv + base_widths(floating).1;
        MultiWork {
            data: Data::new(model),
            deriv: DerivData::new(model),
            a_chain: vec![0.0; nv],
            tau: vec![0.0; nv],
            tau_ext: vec![0.0; nv],
            acc: vec![0.0; nv],
            product: vec![0.0; nv * nv],
            algebras: model.multi.iter().map(|j| Algebra::new(j.kind)).collect(),
        }
    }
}

/// `(dtau/dq, dtau/dv, M)` at `(q, v, a)` on the tangent space (see the module), each
/// (nv, nv) row-major, `nv` with a floating base's six; with the external wrenches `ext`
/// (a fixed base only).
#[allow(clippy::too_many_arguments)]
pub fn rnea_derivatives_multi(
    model: &Model,
    floating: bool,
    w: &mut MultiWork,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    ext: Option<&ExternalForces<f64>>,
    dtau_dq: &mut [f64],
    dtau_dv: &mut [f64],
    m: &mut [f64],
) {
    let (qb, vb) = base_widths(floating);
    let nv = model.nv + vb;
    // the chain's accelerations, ë = a - Δ(v) on each joint's block, and the torques
    w.a_chain.copy_from_slice(a);
    for (j, alg) in model.multi.iter().zip(&w.algebras) {
        let o = vb + j.body;
        let d = alg.delta(&v[o..o + alg.n]);
        for p in 0..alg.n {
            w.a_chain[o + p] -= d[p];
        }
    }
    if floating {
        rnea_derivatives_floating(model, &mut w.data, &mut w.deriv, q, v, &w.a_chain, ext, dtau_dq, dtau_dv, m);
        rnea_floating(model, &mut w.data, q, v, a, &mut w.tau);
    } else {
        rnea_derivatives(model, &mut w.data, &mut w.deriv, q, v, &w.a_chain, ext, dtau_dq, dtau_dv, m);
        rnea(model, &mut w.data, q, v, a, &mut w.tau);
    }
    if let Some(e) = ext {
        external_torques(model, floating, &mut w.data, &mut w.deriv, q, e, &mut w.tau_ext);
        w.tau.iter_mut().zip(&w.tau_ext).for_each(|(t, x)| *t -= *x);
    }
    debug_assert_eq!(q.len(), model.nq + qb);
    for (j, alg) in model.multi.iter().zip(&w.algebras) {
        let (o, n) = (vb + j.body, alg.n);
        let vj = &v[o..o + n];
        let d = alg.delta(vj);
        // the joint's own friction and rotor inertia, out of the rigid-body terms (module doc)
        let jd = |p: usize| model.joint_dynamics[j.body + p];
        let ia = |r: usize, p: usize| if r == o + p { jd(p).armature } else { 0.0 };
        let fv = |r: usize, p: usize| if r == o + p { jd(p).viscous } else { 0.0 };
        let tau_rb: [f64; MAX_PARTS] = std::array::from_fn(|p| {
            if p < n {
                w.tau[o + p] - jd(p).armature * a[o + p] - jd(p).passive_torque(v[o + p])
            } else {
                0.0
            }
        });
        // dτ/dδ_m first, from the chain's dτ/dė (before its own correction)
        for mcol in 0..n {
            let dj = alg.dj(mcol);
            let de: [f64; MAX_PARTS] = std::array::from_fn(|p| -(0..n).map(|k| dj[p][k] * vj[k]).sum::<f64>());
            let jdd = alg.djdot(mcol, vj, &de);
            let dd: [f64; MAX_PARTS] =
                std::array::from_fn(|p| -(0..n).map(|k| dj[p][k] * (a[o + k] - d[k])).sum::<f64>() - jdd[p]);
            for r in 0..nv {
                let mut x = 0.0;
                for p in 0..n {
                    x += (dtau_dv[r * nv + o + p] - fv(r, p)) * de[p] + (m[r * nv + o + p] - ia(r, p)) * dd[p];
                }
                dtau_dq[r * nv + o + mcol] += x;
            }
            for r in 0..n {
                dtau_dq[(o + r) * nv + o + mcol] -= (0..n).map(|p| dj[p][r] * tau_rb[p]).sum::<f64>();
            }
        }
        // dτ/dv = dτ_ch/dė - M dΔ/dv
        for mcol in 0..n {
            let dd: [f64; MAX_PARTS] = std::array::from_fn(|p| {
                (0..n)
                    .map(|k| {
                        if k < mcol {
                            vj[k] * alg.c[k][mcol][p]
                        } else if k > mcol {
                            vj[k] * alg.c[mcol][k][p]
                        } else {
                            0.0
                        }
                    })
                    .sum()
            });
            for r in 0..nv {
                dtau_dv[r * nv + o + mcol] -= (0..n).map(|p| (m[r * nv + o + p] - ia(r, p)) * dd[p]).sum::<f64>();
            }
        }
    }
}

/// `(da/dq, da/dv, M^-1)` at `(q, v, tau)` (and `ext`, as [`rnea_derivatives_multi`]):
/// with `a = aba(q, v, tau)`, `da/dx = -M^-1 dtau/dx` (differentiate `M a + h = tau`),
/// `dtau/dx` and `M` from [`rnea_derivatives_multi`], `M^-1` applied by M's sparse
/// factors (`ltdl.rs`: the tree's depth, not nv, sets the cost of each column).
#[allow(clippy::too_many_arguments)]
pub fn aba_derivatives_multi(
    model: &Model,
    floating: bool,
    w: &mut MultiWork,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    ext: Option<&ExternalForces<f64>>,
    da_dq: &mut [f64],
    da_dv: &mut [f64],
    minv: &mut [f64],
) {
    let (mut acc, mut h) = (std::mem::take(&mut w.acc), std::mem::take(&mut w.product));
    // a = aba(q, v, tau + tau_ext)
    let total: &[f64] = match ext {
        Some(e) => {
            external_torques(model, floating, &mut w.data, &mut w.deriv, q, e, &mut w.tau_ext);
            w.tau_ext.iter_mut().zip(tau).for_each(|(x, t)| *x += *t);
            &w.tau_ext
        }
        None => tau,
    };
    if floating {
        crate::algo::aba_floating(model, &mut w.data, q, v, total, &mut acc);
    } else {
        crate::algo::aba(model, &mut w.data, q, v, total, &mut acc);
    }
    // M goes into `h`, then becomes its factors; dtau/dq and dtau/dv become -M^-1 times them
    rnea_derivatives_multi(model, floating, w, q, v, &acc, ext, da_dq, da_dv, &mut h);
    identity(minv, acc.len());
    if floating {
        factorize::<f64, NV_BASE>(model, &mut h);
        solve::<f64, 3, NV_BASE>(model, &h, [minv, da_dq, da_dv], [1.0, -1.0, -1.0]);
    } else {
        factorize::<f64, 0>(model, &mut h);
        solve::<f64, 3, 0>(model, &h, [minv, da_dq, da_dv], [1.0, -1.0, -1.0]);
    }
    (w.acc, w.product) = (acc, h);
}

/// The RNEA's derivatives (`rnea`, `x` = `a`: [`rnea_derivatives_multi`]) or the ABA's
/// (`x` = `tau`: [`aba_derivatives_multi`]) into `outs`: what one call and each row of a
/// batch run.
pub fn tangent_derivatives(
    model: &Model,
    floating: bool,
    rnea: bool,
    w: &mut MultiWork,
    [q, v, x]: [&[f64]; 3],
    ext: Option<&ExternalForces<f64>>,
    [o0, o1, o2]: [&mut [f64]; 3],
) {
    if rnea {
        rnea_derivatives_multi(model, floating, w, q, v, x, ext, o0, o1, o2)
    } else {
        aba_derivatives_multi(model, floating, w, q, v, x, ext, o0, o1, o2)
    }
}

/// `acc = aba(q, v, tau)` and `minv = M^-1(q)`, fixed or floating base.
#[allow(clippy::too_many_arguments)]
pub(crate) fn forward_and_inverse(
    model: &Model,
    floating: bool,
    data: &mut Data<f64>,
    deriv: &mut DerivData<f64>,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    acc: &mut [f64],
    minv: &mut [f64],
) {
    if floating {
        crate::algo::aba_floating(model, data, q, v, tau, acc);
        crate::algo::minverse_floating(model, data, deriv, q, minv);
    } else {
        crate::algo::aba(model, data, q, v, tau, acc);
        crate::algo::minverse(model, data, deriv, q, minv);
    }
}

/// `tau_ext = sum_L J_L^T w_L` (nv, a floating base's six first) of the wrenches `ext`.
fn external_torques(
    model: &Model,
    floating: bool,
    data: &mut Data<f64>,
    deriv: &mut DerivData<f64>,
    q: &[f64],
    ext: &ExternalForces<f64>,
    tau_ext: &mut [f64],
) {
    if floating {
        generalized_forces_floating(model, data, deriv, q, ext, tau_ext);
    } else {
        generalized_forces(model, data, deriv, q, ext, tau_ext);
    }
}

/// Each `d` (nv, nv) replaced by `-minv d`, through the (nv, nv) scratch `product`.
pub(crate) fn minus_minv_times<const K: usize>(minv: &[f64], ds: [&mut [f64]; K], product: &mut [f64]) {
    let nv = product.len().isqrt();
    for d in ds {
        for r in 0..nv {
            for c in 0..nv {
                product[r * nv + c] = -(0..nv).map(|k| minv[r * nv + k] * d[k * nv + c]).sum::<f64>();
            }
        }
        d.copy_from_slice(product);
    }
}
