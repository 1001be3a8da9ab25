//! The workspace of the derivative algorithms (`rnea_derivatives`, `aba_derivatives`,
//! `minverse`, `gravity_derivatives`) and of the external-force wrappers, beside
//! [`crate::Data`]: allocated once for a model, reused by every call.

use crate::algo::floating::NV_BASE;
use crate::model::Model;
use crate::real::Real;
use crate::spatial::{Force, Motion, RigidInertia, Sym3, V3};

/// Per-thread scratch of the derivative algorithms. Per-body vectors are indexed by body
/// (0..nv) and hold base-frame ("world", Carpentier & Mansard's `o` frame) quantities;
/// `(nv, nv)` blocks are row-major.
#[derive(Clone, Debug)]
pub struct DerivData<T> {
    /// `J_i = ^0X_i S_i`: joint i's motion axis in base coordinates.
    pub s: Vec<Motion<T>>,
    /// Body velocity `v_i` and acceleration `a_i` (gravity included: `a_0 = [0; -g]`), base frame.
    pub v: Vec<Motion<T>>,
    pub a: Vec<Motion<T>>,
    /// `dV/dq_i = v_lambda(i) x J_i` and `dA/dq_i = a_lambda x J_i + v_lambda x dV/dq_i`
    /// (the parts of the motion derivatives that do not follow the subtree's rigid motion).
    pub dvdq: Vec<Motion<T>>,
    pub dadq: Vec<Motion<T>>,
    /// Composite (subtree) rigid-body inertia, base frame.
    pub ic: Vec<RigidInertia<T>>,
    /// The subtree sum of `B_k = v_k x* I_k - I_k v_k x + (I_k v_k) xbar` as its three
    /// non-zero blocks `B = [S - N^x, 0; -2 P^x, 0]`: `S` symmetric, `N`, `P` the
    /// subtree's angular and linear momentum (see `rnea_derivatives.rs`).
    pub bs: Vec<Sym3<T>>,
    pub bn: Vec<V3<T>>,
    pub bp: Vec<V3<T>>,
    /// Subtree sum of the net forces `f_k = I_k a_k + v_k x* I_k v_k - f^ext_k`.
    pub f: Vec<Force<T>>,
    /// Subtree sum of the external forces that stay fixed in space (`ForceFrame::World`).
    pub fx: Vec<Force<T>>,
    /// Minverse: `F_i` (nv x nv forces, row i = body, column = unit torque) and the
    /// accelerations `P_i` (nv x nv motions). `minverse_sweeps` keeps `F` per column in
    /// `fm[..nv]` and, on a chain, `P` per column in `pm[..nv]` (see `minverse.rs`).
    pub fm: Vec<Force<T>>,
    pub pm: Vec<Motion<T>>,
    /// Minverse: per body, the centre of mass `c` (body frame) and the rotational inertia
    /// `I_c` about it (body axes), from `model.inertia` (constants of the model).
    pub com: Vec<V3<f64>>,
    pub i_com: Vec<Sym3<f64>>,
    /// Whether `i_com[i]` is diagonal (its off-diagonal entries are then exactly 0).
    pub i_com_diagonal: Vec<bool>,
    /// Bodies of the subtree of i (i first, ascending): `sub[sub_start[i]..sub_start[i + 1]]`.
    pub sub: Vec<usize>,
    pub sub_start: Vec<usize>,
    /// Joint-space vectors (nv,) and matrices (nv, nv) between steps.
    pub qdd: Vec<T>,
    pub tau: Vec<T>,
    pub dq: Vec<T>,
    pub dqd: Vec<T>,
    /// A floating base's velocity-space scratch (`floating_derivatives.rs`): the
    /// accelerations (6 + nv) and the factors of M ((6 + nv)^2).
    pub qdd_floating: Vec<T>,
    pub factor: Vec<T>,
}

impl<T: Real> DerivData<T> {
    pub fn new(model: &Model) -> Self {
        let n = model.nv;
        let mut sub = Vec::new();
        let mut sub_start = Vec::with_capacity(n + 1);
        for i in 0..n {
            sub_start.push(sub.len());
            sub.extend((i..n).filter(|&c| model.supports(i, c)));
        }
        sub_start.push(sub.len());
        let i_com: Vec<Sym3<f64>> =
            model.inertia.iter().map(|i| diagonal_if_rounding(i.rotational_inertia_about_com(), i)).collect();
        DerivData {
            s: vec![Motion::zero(); n],
            v: vec![Motion::zero(); n],
            a: vec![Motion::zero(); n],
            dvdq: vec![Motion::zero(); n],
            dadq: vec![Motion::zero(); n],
            ic: vec![RigidInertia::zero(); n],
            bs: vec![Sym3::zero(); n],
            bn: vec![V3::zero(); n],
            bp: vec![V3::zero(); n],
            f: vec![Force::zero(); n],
            fx: vec![Force::zero(); n],
            fm: vec![Force::zero(); n * n],
            pm: vec![Motion::zero(); n * n],
            com: model.inertia.iter().map(|i| i.com()).collect(),
            i_com_diagonal: i_com.iter().map(|s| s.xy == 0.0 && s.xz == 0.0 && s.yz == 0.0).collect(),
            i_com,
            sub,
            sub_start,
            qdd: vec![T::zero(); n],
            tau: vec![T::zero(); n],
            dq: vec![T::zero(); n * n],
            dqd: vec![T::zero(); n * n],
            qdd_floating: vec![T::zero(); n + NV_BASE],
            factor: vec![T::zero(); (n + NV_BASE) * (n + NV_BASE)],
        }
    }

    /// The bodies of the subtree rooted at `i`, `i` first.
    #[inline(always)]
    pub fn subtree(&self, i: usize) -> &[usize] {
        &self.sub[self.sub_start[i]..self.sub_start[i + 1]]
    }
}

/// `i_c` (the rotational inertia about the centre of mass read back off `body`, see
/// `RigidInertia::rotational_inertia_about_com`) with off-diagonal entries that are
/// rounding residue set to 0: a tensor given diagonal comes back with off-diagonal
/// entries of the order of `eps m |c|^2` (the parallel-axis term they went through),
/// and the diagonal case has a cheaper base-frame rotation (`minverse`).
fn diagonal_if_rounding(mut i_c: Sym3<f64>, body: &RigidInertia<f64>) -> Sym3<f64> {
    let c = body.com();
    let scale = body.m * c.dot(c) + i_c.xx.abs() + i_c.yy.abs() + i_c.zz.abs();
    let tol = 16.0 * f64::EPSILON * scale;
    if i_c.xy.abs() <= tol && i_c.xz.abs() <= tol && i_c.yz.abs() <= tol {
        i_c.xy = 0.0;
        i_c.xz = 0.0;
        i_c.yz = 0.0;
    }
    i_c
}
