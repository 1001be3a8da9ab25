//! The floating-base methods of `NumericModel` (a free-flyer root joint; see
//! `armdyn_core::algo::floating` for the layout of the arrays, Pinocchio's): rnea, crba
//! and aba dispatch here when the model floats (the kinematics and energies to
//! `centroidal.rs`), and every other method refuses.
//!
//! `q` is `(7 + n,)` or `(N, 7 + n)`, `v` (`qd`), `a` (`qdd`) and `tau` `(6 + n,)` or
//! `(N, 6 + n)`; a batch runs as the fixed-base ones do (SIMD lanes, `threads` threads,
//! the GIL released; bit for bit the single calls). The
//! quaternion `q[3:7]` (x, y, z, w) must have unit length to within [`QUATERNION_TOL`]:
//! anything further from it is refused, never silently used.

use crate::{all_finite, as_f64, guard, new_array, slice, thread_arg, NumericModel, Shape};
use armdyn_core::algo::floating::{aba_floating, crba_floating, rnea_floating, NQ_BASE, NV_BASE};
use armdyn_core::batch;
use armdyn_core::model::BodyMotion;
use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::{PyFloatingPointError, PyNotImplementedError, PyValueError};
use pyo3::prelude::*;

/// How far `|q[3:7]|` may be from 1.
pub const QUATERNION_TOL: f64 = 1e-9;

impl NumericModel {
    /// `Err(NotImplementedError)` for a floating-base model: the methods that call this
    /// compute fixed-base quantities only.
    pub(crate) fn fixed_base_only(&self) -> PyResult<()> {
        if self.floating {
            return Err(PyNotImplementedError::new_err(format!(
                "'{}' has a floating base (free-flyer root joint): only rnea, crba, aba, their derivatives, minverse, forward_kinematics, jacobian, jacobian_dot, coriolis_matrix, regressor and the energies support it yet",
                self.name
            )));
        }
        Ok(())
    }

    /// `Err(ValueError)` naming `what` for a model with joints of several coordinates
    /// (spherical, planar, free): for the methods whose algorithms take 1-dof joints
    /// only (their velocity products and derivatives are written for one axis per body).
    pub(crate) fn one_dof_only(&self, what: &str) -> PyResult<()> {
        if let Some(j) = self.model.multi.first() {
            return Err(PyValueError::new_err(format!(
                "{what}: '{}' has joints of several coordinates (the first: '{}'): {what} takes revolute and \
                 prismatic joints only (yet); rnea, crba, aba, gravity, bias, their derivatives, minverse, \
                 forward_kinematics, jacobian, jacobian_dot, coriolis_matrix, regressor, the energies and the \
                 centroidal map take them",
                self.name,
                self.joint_name(j.body)
            )));
        }
        Ok(())
    }

    /// The name of the joint of body `b` (a coordinate name without its `.wx`-style suffix
    /// for the parts of a joint of several coordinates).
    fn joint_name(&self, b: usize) -> &str {
        let c = &self.coordinate_names[b];
        match self.model.motion[b] {
            BodyMotion::Axis => c,
            _ => c.rsplit_once('.').map_or(c.as_str(), |(j, _)| j),
        }
    }

    /// The state arguments `(name, object)` of a method whose first argument is `q`:
    /// [`crate::states`] when `q` and the velocities have the same length (1-dof joints),
    /// else [`Self::floating_states`] with `q` `nq` long.
    pub(crate) fn joint_states<'py, const K: usize>(
        &self,
        args: [(&str, &Bound<'py, PyAny>); K],
    ) -> PyResult<(Shape, [Bound<'py, PyArrayDyn<f64>>; K])> {
        if !self.model.has_multi() {
            return crate::states(self.model.nv, args);
        }
        let mut k = 0;
        self.floating_states(args.map(|(name, obj)| {
            k += 1;
            (name, obj, if k == 1 { self.model.nq } else { self.model.nv })
        }))
    }

    /// Check the arguments `(name, object, width)`: each `(width,)` or `(N, width)`, the
    /// same N for all, finite; the first is `q`, whose quaternions (and planar joints'
    /// `cos, sin`) must be unit. A model without a floating base or joints of several
    /// coordinates has its arguments checked by [`crate::states`] (every width is dof).
    pub(crate) fn floating_states<'py, const K: usize>(
        &self,
        args: [(&str, &Bound<'py, PyAny>, usize); K],
    ) -> PyResult<(Shape, [Bound<'py, PyArrayDyn<f64>>; K])> {
        if !self.floating && !self.model.has_multi() {
            return crate::states(self.model.nv, args.map(|(name, obj, _)| (name, obj)));
        }
        let mut shape = None;
        let mut arrays = Vec::with_capacity(K);
        for (name, obj, width) in args {
            let a = as_f64(obj, name)?;
            let s = match a.shape() {
                [m] if *m == width => Shape::Single,
                [rows, m] if *m == width => Shape::Batch(*rows),
                other => {
                    return Err(PyValueError::new_err(format!(
                        "{name}: expected shape ({width},) for one state or (N, {width}) for a batch of '{}' \
                         (q has {nq} entries, velocities and torques {nv}), got {other:?}",
                        self.name,
                        nq = self.widths().0,
                        nv = self.widths().1,
                    )))
                }
            };
            if *shape.get_or_insert(s) != s {
                return Err(PyValueError::new_err(format!("{name}: the number of states does not match q's")));
            }
            // SAFETY: read-only, GIL held.
            let values = unsafe { slice(&a) };
            if !all_finite(values) {
                return Err(PyValueError::new_err(format!("{name} contains NaN or inf")));
            }
            arrays.push(a);
        }
        // SAFETY: read-only, GIL held.
        let q = unsafe { slice(&arrays[0]) };
        self.check_unit_blocks(q)?;
        let arrays: [Bound<'py, PyArrayDyn<f64>>; K] = arrays.try_into().expect("K arrays");
        Ok((shape.expect("at least one argument"), arrays))
    }

    /// Every quaternion of the configurations `q` (rows of `nq`: the base's `q[3:7]`, each
    /// spherical or free joint's) and every planar joint's `(cos, sin)` must have unit
    /// length to within [`QUATERNION_TOL`]: anything else is refused, never used.
    pub(crate) fn check_unit_blocks(&self, q: &[f64]) -> PyResult<()> {
        let qb = if self.floating { NQ_BASE } else { 0 };
        let nq = self.model.nq + qb;
        let base = self.floating.then_some((3, 4, "the base quaternion", "x, y, z, w"));
        let joints = self.model.multi.iter().map(|j| {
            let (off, len) = j.kind.unit_block();
            let what = if len == 4 { "the quaternion" } else { "the (cos, sin) pair" };
            (qb + j.idx_q + off, len, what, if len == 4 { "x, y, z, w" } else { "cos, sin" })
        });
        for (row, state) in q.chunks_exact(nq.max(1)).enumerate() {
            for (k, (start, len, what, layout)) in base.into_iter().chain(joints.clone()).enumerate() {
                let norm = state[start..start + len].iter().map(|x| x * x).sum::<f64>().sqrt();
                if (norm - 1.0).abs() > QUATERNION_TOL {
                    let at = if q.len() > nq { format!(" (row {row})") } else { String::new() };
                    let of = match (base.is_some(), k) {
                        (true, 0) => String::new(),
                        (b, k) => format!(" of joint '{}'", self.joint_name(self.model.multi[k - b as usize].body)),
                    };
                    return Err(PyValueError::new_err(format!(
                        "q{at}: {what}{of} q[{start}:{}] ({layout}) has length {norm}, not 1 \
                         (to within {QUATERNION_TOL:e}): normalise it first",
                        start + len
                    )));
                }
            }
        }
        Ok(())
    }

    /// `single(data, inputs, output)` for one state, `batched(model, inputs, output,
    /// threads)` for a batch (GIL released), into a fresh array of shape `out_shape` per
    /// state. Also for a fixed base (the centroidal quantities, `centroidal.rs`).
    pub(crate) fn floating_op<'py, const K: usize>(
        &self,
        py: Python<'py>,
        args: [(&str, &Bound<'py, PyAny>, usize); K],
        out_shape: &[usize],
        threads: Option<i64>,
        single: impl FnOnce(&mut armdyn_core::Data<f64>, [&[f64]; K], &mut [f64]),
        batched: impl FnOnce(&armdyn_core::Model, [&[f64]; K], &mut [f64], Option<usize>) + Send,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let single = |ins: [&[f64]; K], o: &mut [f64]| self.with_scratch(|s| single(&mut s.data, ins, o));
        self.op_on(py, &self.model, args, out_shape, threads, single, batched)
    }

    /// [`Self::floating_op`] on `model` (this one's, or another of the same widths, e.g.
    /// `free_root.rs`'s), `single(inputs, output)` bringing its own workspace.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn op_on<'py, const K: usize>(
        &self,
        py: Python<'py>,
        model: &armdyn_core::Model,
        args: [(&str, &Bound<'py, PyAny>, usize); K],
        out_shape: &[usize],
        threads: Option<i64>,
        single: impl FnOnce([&[f64]; K], &mut [f64]),
        batched: impl FnOnce(&armdyn_core::Model, [&[f64]; K], &mut [f64], Option<usize>) + Send,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guard(|| {
            let threads = thread_arg(threads)?;
            let (shape, arrays) = self.floating_states(args)?;
            match shape {
                Shape::Single => {
                    let out = new_array(py, out_shape);
                    // SAFETY: inputs read-only and `out` fresh, GIL held throughout.
                    let ins: [&[f64]; K] = std::array::from_fn(|k| unsafe { slice(&arrays[k]) });
                    let o = unsafe { out.as_slice_mut().expect("fresh array") };
                    single(ins, o);
                    Ok(out)
                }
                Shape::Batch(rows) => {
                    let dims: Vec<usize> = std::iter::once(rows).chain(out_shape.iter().copied()).collect();
                    let out = new_array(py, &dims);
                    let readonly: Vec<_> = arrays.iter().map(|a| a.readonly()).collect();
                    let ins: [&[f64]; K] = std::array::from_fn(|k| readonly[k].as_slice().expect("contiguous"));
                    // SAFETY: `out` is fresh and not visible to Python until returned.
                    let o = unsafe { out.as_slice_mut().expect("fresh array") };
                    py.detach(|| batched(model, ins, o, threads));
                    Ok(out)
                }
            }
        })
    }

    /// Floating-base inverse dynamics: tau (6 + n) from q (7 + n), v, a (6 + n).
    pub(crate) fn rnea_floating<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        a: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (nq, nv) = (self.model.nq + NQ_BASE, self.model.nv + NV_BASE);
        let out = self.floating_op(
            py,
            [("q", q, nq), ("qd", v, nv), ("qdd", a, nv)],
            &[nv],
            threads,
            |d, [q, v, a], o| rnea_floating(&self.model, d, q, v, a, o),
            batch::rnea_floating,
        )?;
        finite(out)
    }

    /// Floating-base inertia matrix (6 + n, 6 + n) from q (7 + n).
    pub(crate) fn crba_floating<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (nq, nv) = (self.model.nq + NQ_BASE, self.model.nv + NV_BASE);
        let out = self.floating_op(
            py,
            [("q", q, nq)],
            &[nv, nv],
            threads,
            |d, [q], o| crba_floating(&self.model, d, q, o),
            batch::crba_floating,
        )?;
        finite(out)
    }

    /// Floating-base forward dynamics: a (6 + n) from q (7 + n), v, tau (6 + n).
    pub(crate) fn aba_floating<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        tau: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (nq, nv) = (self.model.nq + NQ_BASE, self.model.nv + NV_BASE);
        let out = self.floating_op(
            py,
            [("q", q, nq), ("qd", v, nv), ("tau", tau, nv)],
            &[nv],
            threads,
            |d, [q, v, tau], o| aba_floating(&self.model, d, q, v, tau, o),
            batch::aba_floating,
        )?;
        // SAFETY: `out` is ours and not yet returned.
        if !all_finite(unsafe { slice(&out) }) {
            return Err(PyValueError::new_err(format!(
                "aba: the floating-base inertia matrix of '{}' is singular at this state (a body or subtree \
                 without mass or inertia?), or the result overflows: no finite acceleration",
                self.name
            )));
        }
        Ok(out)
    }
}

/// `out`, or a `FloatingPointError` if it holds NaN or inf (inputs were checked finite).
pub(crate) fn finite(out: Bound<'_, PyArrayDyn<f64>>) -> PyResult<Bound<'_, PyArrayDyn<f64>>> {
    // SAFETY: `out` is ours and not yet returned.
    if all_finite(unsafe { slice(&out) }) {
        Ok(out)
    } else {
        Err(PyFloatingPointError::new_err("the result is not finite: an overflow from finite inputs"))
    }
}
