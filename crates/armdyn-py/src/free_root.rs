//! A floating base as a free joint at the root, for the methods that have no
//! floating-base form of their own: the Coriolis matrix, the Jacobian's time derivative
//! and the regressor.
//!
//! A floating-base robot (Pinocchio's `JointModelFreeFlyer` root) is the same mechanism as
//! a fixed-base robot whose base link hangs from the world on a free joint: the joint's
//! `q` (position, quaternion x y z w) and `v` (linear, angular, in the base frame) are
//! Pinocchio's free-flyer layout, so the arrays are the floating model's unchanged. The
//! algorithms for joints of several coordinates (`joint_multi.rs`) then run as written.
//! The fast floating-base paths (`algo::floating`) stay for rnea, crba, aba and their
//! derivatives, where speed is measured.

use crate::floating::finite;
use crate::{slice, NumericModel};
use armdyn_core::algo::coriolis::CoriolisWork;
use armdyn_core::algo::floating::NV_BASE;
use armdyn_core::{algo, batch, batch_derivatives as bd, Data, JointDynamics, JointSpec, JointType, Model, ModelError};
use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;

/// The free-rooted model of a floating-base robot: a free joint from the world to the
/// base link (mass `base.0`, centre of mass `base.1` and inertia about it `base.2`, base
/// frame), then `joints` (their parent indices shifted by one), with the joints'
/// friction and rotor inertia `jd` (one per velocity coordinate of `joints`).
pub(crate) fn free_rooted(
    joints: &[JointSpec],
    gravity: [f64; 3],
    base: (f64, [f64; 3], [[f64; 3]; 3]),
    jd: &[JointDynamics],
) -> Result<Model, ModelError> {
    let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let root = JointSpec {
        parent: None,
        jtype: JointType::Free,
        rotation: identity,
        translation: [0.0; 3],
        axis: [0.0, 0.0, 1.0],
        mass: base.0,
        com: base.1,
        inertia: base.2,
    };
    let shifted = joints.iter().map(|j| JointSpec { parent: Some(j.parent.map_or(0, |p| p + 1)), ..j.clone() });
    let specs: Vec<JointSpec> = std::iter::once(root).chain(shifted).collect();
    let mut model = Model::new(&specs, gravity)?;
    for (b, d) in jd.iter().enumerate() {
        model.set_joint_dynamics(b + NV_BASE, *d)?;
    }
    Ok(model)
}

/// The free root's joint columns in the regressor, which a floating base drops.
pub(crate) const ROOT_JOINT_COLUMNS: usize = 4 * NV_BASE;

impl NumericModel {
    /// The model these methods run on: the free-rooted one for a floating base.
    pub(crate) fn whole(&self) -> &Model {
        self.free_root.as_ref().unwrap_or(&self.model)
    }

    /// The Coriolis matrix of a floating-base robot, (6 + n, 6 + n) (or (N, ..)).
    pub(crate) fn coriolis_free_root<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (m, (nq, nv)) = (self.whole(), self.widths());
        let out = self.op_on(
            py,
            m,
            [("q", q, nq), ("qd", qd, nv)],
            &[nv, nv],
            threads,
            |[q, qd], o| algo::coriolis_matrix(m, &mut Data::new(m), &mut CoriolisWork::new(m), q, qd, o),
            |m, [q, qd], o, t| batch::coriolis_matrix(m, q, qd, o, t),
        )?;
        finite(out)
    }

    /// `dJ/dt` of link `link` (description order) of a floating-base robot, (6, 6 + n).
    pub(crate) fn jacobian_dot_free_root<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: &Bound<'py, PyAny>,
        link: usize,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (m, (nq, nv)) = (self.whole(), self.widths());
        let l = link + 1; // the world is the free-rooted model's link 0
        let out = self.op_on(
            py,
            m,
            [("q", q, nq), ("qd", qd, nv)],
            &[6, nv],
            threads,
            |[q, qd], o| algo::jacobian_dot(m, &mut Data::new(m), q, qd, l, o),
            |m, [q, qd], o, t| bd::jacobian_dot(m, q, qd, l, o, t),
        )?;
        finite(out)
    }

    /// The regressor of a floating-base robot, (6 + n, P) with `P = 10 nlinks + 4 n`: the
    /// base link's ten columns first, then every other link's, then each joint velocity
    /// coordinate's four (the free root's own joint columns are dropped: the base has no
    /// motor).
    pub(crate) fn regressor_free_root<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: &Bound<'py, PyAny>,
        qdd: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (m, (nq, nv)) = (self.whole(), self.widths());
        let full = algo::regressor_columns(m);
        let y = self.op_on(
            py,
            m,
            [("q", q, nq), ("qd", qd, nv), ("qdd", qdd, nv)],
            &[nv, full],
            threads,
            |[q, qd, qdd], o| algo::regressor(m, &mut Data::new(m), q, qd, qdd, o),
            batch::regressor,
        )?;
        let y = finite(y)?;
        // drop the free root's 4 x 6 joint columns
        let (first, drop) = (10 * (m.nlinks() - 1), ROOT_JOINT_COLUMNS);
        let mut dims = y.shape().to_vec();
        *dims.last_mut().expect("2 or 3 dimensions") = full - drop;
        let out = crate::new_array(py, &dims);
        // SAFETY: `y` is ours, `out` fresh; neither is visible to Python yet.
        let (src, dst) = (unsafe { slice(&y) }, unsafe { out.as_slice_mut().expect("fresh array") });
        for (row, o) in src.chunks_exact(full).zip(dst.chunks_exact_mut(full - drop)) {
            o[..first].copy_from_slice(&row[..first]);
            o[first..].copy_from_slice(&row[first + drop..]);
        }
        Ok(out)
    }
}
