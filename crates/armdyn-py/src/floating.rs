//! The floating-base methods of `NumericModel` (a free-flyer root joint; see
//! `armdyn_core::algo::floating` for the layout of the arrays, Pinocchio's): rnea, crba
//! and aba dispatch here when the model floats, and every other method refuses.
//!
//! `q` is `(7 + n,)` or `(N, 7 + n)`, `v` (`qd`), `a` (`qdd`) and `tau` `(6 + n,)` or
//! `(N, 6 + n)`; a batch is run row by row (no SIMD lanes nor threads yet). The
//! quaternion `q[3:7]` (x, y, z, w) must have unit length to within [`QUATERNION_TOL`]:
//! anything further from it is refused, never silently used.

use crate::{as_f64, all_finite, guard, new_array, slice, NumericModel, Shape};
use armdyn_core::algo::floating::{aba_floating, crba_floating, rnea_floating, NQ_BASE, NV_BASE};
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
                "'{}' has a floating base (free-flyer root joint): only rnea, crba and aba support it yet",
                self.name
            )));
        }
        Ok(())
    }

    /// Check the arguments `(name, object, width)`: each `(width,)` or `(N, width)`, the
    /// same N for all, finite; the first is `q`, whose quaternions must be unit.
    fn floating_states<'py, const K: usize>(
        &self,
        args: [(&str, &Bound<'py, PyAny>, usize); K],
    ) -> PyResult<(Shape, [Bound<'py, PyArrayDyn<f64>>; K])> {
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
                         (floating base: q has 7 + {n} entries, velocities and torques 6 + {n}), got {other:?}",
                        self.name,
                        n = self.model.nv
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
        let nq = self.model.nv + NQ_BASE;
        for (row, state) in q.chunks_exact(nq).enumerate() {
            let norm = state[3..7].iter().map(|x| x * x).sum::<f64>().sqrt();
            if (norm - 1.0).abs() > QUATERNION_TOL {
                let at = if q.len() > nq { format!(" (row {row})") } else { String::new() };
                return Err(PyValueError::new_err(format!(
                    "q{at}: the base quaternion q[3:7] (x, y, z, w) has length {norm}, not 1 \
                     (to within {QUATERNION_TOL:e}): normalise it first"
                )));
            }
        }
        let arrays: [Bound<'py, PyArrayDyn<f64>>; K] = arrays.try_into().ok().expect("K arrays");
        Ok((shape.expect("at least one argument"), arrays))
    }

    /// Run `f(data, inputs, output)` on every state of `args`, into a fresh array of
    /// shape `out_shape` per state.
    fn floating_op<'py, const K: usize>(
        &self,
        py: Python<'py>,
        args: [(&str, &Bound<'py, PyAny>, usize); K],
        out_shape: &[usize],
        f: impl Fn(&mut armdyn_core::Data<f64>, [&[f64]; K], &mut [f64]),
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guard(|| {
            let widths = args.map(|a| a.2);
            let (shape, arrays) = self.floating_states(args)?;
            let rows = match shape {
                Shape::Single => None,
                Shape::Batch(rows) => Some(rows),
            };
            let dims: Vec<usize> = rows.into_iter().chain(out_shape.iter().copied()).collect();
            let out = new_array(py, &dims);
            // SAFETY: inputs read-only and `out` fresh, GIL held throughout.
            let ins: [&[f64]; K] = std::array::from_fn(|k| unsafe { slice(&arrays[k]) });
            let o = unsafe { out.as_slice_mut().expect("fresh array") };
            let per_row: usize = out_shape.iter().product();
            self.with_scratch(|s| {
                for r in 0..rows.unwrap_or(1) {
                    let row: [&[f64]; K] = std::array::from_fn(|k| &ins[k][r * widths[k]..(r + 1) * widths[k]]);
                    f(&mut s.data, row, &mut o[r * per_row..(r + 1) * per_row]);
                }
            });
            Ok(out)
        })
    }

    /// Floating-base inverse dynamics: tau (6 + n) from q (7 + n), v, a (6 + n).
    pub(crate) fn rnea_floating<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        a: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (nq, nv) = (self.model.nv + NQ_BASE, self.model.nv + NV_BASE);
        let out = self.floating_op(py, [("q", q, nq), ("qd", v, nv), ("qdd", a, nv)], &[nv], |d, [q, v, a], o| {
            rnea_floating(&self.model, d, q, v, a, o)
        })?;
        finite(out)
    }

    /// Floating-base inertia matrix (6 + n, 6 + n) from q (7 + n).
    pub(crate) fn crba_floating<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (nq, nv) = (self.model.nv + NQ_BASE, self.model.nv + NV_BASE);
        let out = self.floating_op(py, [("q", q, nq)], &[nv, nv], |d, [q], o| crba_floating(&self.model, d, q, o))?;
        finite(out)
    }

    /// Floating-base forward dynamics: a (6 + n) from q (7 + n), v, tau (6 + n).
    pub(crate) fn aba_floating<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        tau: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (nq, nv) = (self.model.nv + NQ_BASE, self.model.nv + NV_BASE);
        let out = self.floating_op(py, [("q", q, nq), ("qd", v, nv), ("tau", tau, nv)], &[nv], |d, [q, v, tau], o| {
            aba_floating(&self.model, d, q, v, tau, o)
        })?;
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
fn finite(out: Bound<'_, PyArrayDyn<f64>>) -> PyResult<Bound<'_, PyArrayDyn<f64>>> {
    // SAFETY: `out` is ours and not yet returned.
    if all_finite(unsafe { slice(&out) }) {
        Ok(out)
    } else {
        Err(PyFloatingPointError::new_err("the result is not finite: an overflow from finite inputs"))
    }
}
