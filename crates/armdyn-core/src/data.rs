//! The per-thread workspace: every intermediate of the algorithms, allocated once for
//! a model and reused by every call (no allocation per call or per state).

use crate::model::Model;
use crate::real::Real;
use crate::spatial::{ArticulatedInertia, Force, Motion, RigidInertia, Xform};

/// Workspace for one model, one state at a time (`T = f64`) or one group of lanes
/// (`T = F64x4`, `F64x8`). Vectors are indexed by body (0..nv); names follow RBDA.
#[derive(Clone, Debug)]
pub struct Data<T> {
    /// `^i X_{lambda(i)}`: parent frame -> body frame.
    pub xup: Vec<Xform<T>>,
    /// `^i X_0`: base frame -> body frame.
    pub x0: Vec<Xform<T>>,
    /// Body spatial velocity `v_i` and acceleration `a_i` (body frame).
    pub v: Vec<Motion<T>>,
    pub a: Vec<Motion<T>>,
    /// Velocity-product acceleration `c_i = v_i x S_i qd_i` (ABA).
    pub c: Vec<Motion<T>>,
    /// The velocity of body i's joint's parent, in body i's frame (the velocity product's
    /// left factor, `Model::joint_parent_velocity`).
    pub vjp: Vec<Motion<T>>,
    /// RNEA: net force transmitted across joint i, body frame.
    pub f: Vec<Force<T>>,
    /// CRBA: composite rigid-body inertia of the subtree at i, body frame.
    pub ic: Vec<RigidInertia<T>>,
    /// ABA: articulated inertia `I^A_i`, bias force `p^A_i`, `U_i = I^A_i S_i`,
    /// `1 / D_i = 1 / (S_i^T U_i)`, `u_i = tau_i - S_i^T p^A_i`. Body frame after `aba`;
    /// base frame (with `J_i` for `S_i`) after `minverse` and `aba_derivatives` (which
    /// also leaves `c`, `a` in base coordinates).
    pub ia: Vec<ArticulatedInertia<T>>,
    pub pa: Vec<Force<T>>,
    pub u_col: Vec<Force<T>>,
    pub d_inv: Vec<T>,
    pub u: Vec<T>,
    /// Zeros of length nv (the `qd = 0` / `qdd = 0` arguments of gravity and bias).
    pub zeros: Vec<T>,
}

impl<T: Real> Data<T> {
    pub fn new(model: &Model) -> Self {
        let n = model.nv;
        Data {
            xup: vec![Xform::identity(); n],
            x0: vec![Xform::identity(); n],
            v: vec![Motion::zero(); n],
            a: vec![Motion::zero(); n],
            c: vec![Motion::zero(); n],
            vjp: vec![Motion::zero(); n],
            f: vec![Force::zero(); n],
            ic: vec![RigidInertia::zero(); n],
            ia: vec![ArticulatedInertia::from_rigid(&RigidInertia::zero()); n],
            pa: vec![Force::zero(); n],
            u_col: vec![Force::zero(); n],
            d_inv: vec![T::zero(); n],
            u: vec![T::zero(); n],
            zeros: vec![T::zero(); n],
        }
    }
}
