//! The floating-base derivatives and M^-1 (`armdyn_core::algo::floating_derivatives`):
//! `rnea_derivatives`, `aba_derivatives` and `minverse` of `derivatives.rs` dispatch
//! here when the model floats. Arguments as in `floating.rs` (`q` `(7 + n,)` or
//! `(N, 7 + n)` with a unit quaternion, `v`, `a`, `tau` `(6 + n,)` or `(N, 6 + n)`); every
//! output is `(6 + n, 6 + n)` (or `(N, 6 + n, 6 + n)`), in the order of `v`; `d/dq` is
//! on the tangent space (Pinocchio's). `out=` as for a fixed base. A batch runs in the
//! lane kernels of `batch_derivatives` (`threads` threads, the GIL released; bit for bit
//! the single calls). External wrenches: in the link frames only (`frame="local"`).

use crate::derivatives::{check_f_ext, outputs_given, parse_frame};
use crate::{all_finite, guard, new_array, slice, thread_arg, NumericModel, Scratch, Shape};
use armdyn_core::algo::floating::{NQ_BASE, NV_BASE};
use armdyn_core::algo::multi_derivatives::{tangent_derivatives, MultiWork};
use armdyn_core::algo::{ExternalForces, ForceFrame};
use armdyn_core::{algo, batch_derivatives as bd, Model};
use numpy::{PyArrayDyn, PyArrayMethods};
use pyo3::exceptions::{PyNotImplementedError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

/// External wrenches in the link frames, `(nlinks, 6)` per state, or none.
type Ext<'a> = Option<&'a [f64]>;

/// Check the states (`floating_states`) and `f_ext` (link frames only), then run
/// `single` on the model's workspace or `batched` with the GIL released, into `R`
/// (6 + n)^2 outputs per state: fresh arrays or the caller's `out`. A result that is not
/// finite (a singular M) is an error naming `what`.
#[allow(clippy::too_many_arguments)]
fn run<'py, const K: usize, const R: usize>(
    m: &NumericModel,
    py: Python<'py>,
    what: &str,
    args: [(&str, &Bound<'py, PyAny>, usize); K],
    f_ext: Option<&Bound<'py, PyAny>>,
    frame: &str,
    threads: Option<i64>,
    out: Option<&Bound<'py, PyAny>>,
    single: impl FnOnce(&Model, &mut Scratch, [&[f64]; K], Ext<'_>, [&mut [f64]; R]),
    batched: impl FnOnce(&Model, [&[f64]; K], Ext<'_>, [&mut [f64]; R], Option<usize>) + Send,
) -> PyResult<[Bound<'py, PyArrayDyn<f64>>; R]> {
    guard(|| {
        let threads = thread_arg(threads)?;
        if f_ext.is_some() && frame != "local" && m.floating {
            return Err(PyNotImplementedError::new_err(format!(
                "{what}: f_ext with frame='{frame}' is not available for a floating base (root_joint='free-flyer'); \
                 give the wrenches in the link frames (frame='local')"
            )));
        }
        let (shape, arrays) = m.floating_states(args)?;
        let ext_arr = f_ext.map(|f| check_f_ext(m, f, shape)).transpose()?;
        let s = m.widths().1;
        let dims: Vec<usize> = match shape {
            Shape::Single => vec![s, s],
            Shape::Batch(rows) => vec![rows, s, s],
        };
        let outs: [Bound<'py, PyArrayDyn<f64>>; R] = match out {
            None => std::array::from_fn(|_| new_array(py, &dims)),
            Some(o) => {
                let mut inputs: Vec<(&str, &Bound<'py, PyArrayDyn<f64>>)> =
                    args.iter().map(|(name, _, _)| *name).zip(arrays.iter()).collect();
                if let Some(e) = ext_arr.as_ref() {
                    inputs.push(("f_ext", e));
                }
                outputs_given(o, &dims, &inputs)?
            }
        };
        // SAFETY: the outputs are fresh, or the caller's checked ones (C-contiguous,
        // writeable, disjoint from the inputs and each other).
        let os: [&mut [f64]; R] = {
            let mut it = outs.iter().map(|o| unsafe { o.as_slice_mut().expect("C-contiguous array") });
            std::array::from_fn(|_| it.next().expect("R outputs"))
        };
        match shape {
            Shape::Single => {
                // SAFETY: inputs read-only, GIL held throughout.
                let ins: [&[f64]; K] = std::array::from_fn(|k| unsafe { slice(&arrays[k]) });
                let ext = ext_arr.as_ref().map(|a| unsafe { slice(a) });
                m.with_scratch(|sc| single(&m.model, sc, ins, ext, os));
            }
            Shape::Batch(_) => {
                let readonly: Vec<_> = arrays.iter().map(|a| a.readonly()).collect();
                let ins: [&[f64]; K] = std::array::from_fn(|k| readonly[k].as_slice().expect("contiguous"));
                let ext_ro = ext_arr.as_ref().map(|a| a.readonly());
                let ext = ext_ro.as_ref().map(|a| a.as_slice().expect("contiguous"));
                let model = &m.model;
                py.detach(|| batched(model, ins, ext, os, threads));
            }
        }
        // SAFETY: the outputs are ours (or the caller's, checked above), GIL held.
        if !outs.iter().all(|o| all_finite(unsafe { slice(o) })) {
            return Err(PyValueError::new_err(format!(
                "{what}: the result is not finite: the floating-base inertia matrix of '{}' is singular at this \
                 state (a body or subtree without mass or inertia?), or the state overflows",
                m.name
            )));
        }
        Ok(outs)
    })
}

/// The core's wrenches in `frame`.
fn with_frame(e: Ext<'_>, frame: ForceFrame) -> Option<ExternalForces<'_, f64>> {
    e.map(|wrenches| ExternalForces { wrenches, frame })
}

/// The core's wrenches in the link frames.
fn local(e: Ext<'_>) -> Option<ExternalForces<'_, f64>> {
    with_frame(e, ForceFrame::Local)
}

/// ``(dtau_dq, dtau_dv, M)`` of a floating-base model from q (7 + n), v, a (6 + n).
#[allow(clippy::too_many_arguments)]
pub(crate) fn rnea_derivatives<'py>(
    m: &NumericModel,
    py: Python<'py>,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    a: &Bound<'py, PyAny>,
    f_ext: Option<&Bound<'py, PyAny>>,
    frame: &str,
    threads: Option<i64>,
    out: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyTuple>> {
    let (nq, nv) = (m.model.nq + NQ_BASE, m.model.nv + NV_BASE);
    let o = run(
        m,
        py,
        "rnea_derivatives",
        [("q", q, nq), ("qd", v, nv), ("qdd", a, nv)],
        f_ext,
        frame,
        threads,
        out,
        |md, sc, [q, v, a], e, [o0, o1, o2]| {
            let (data, deriv) = sc.deriv(md);
            algo::rnea_derivatives_floating(md, data, deriv, q, v, a, local(e).as_ref(), o0, o1, o2)
        },
        |md, args, e, outs, t| bd::rnea_derivatives_floating(md, args, e.map(|w| (w, ForceFrame::Local)), outs, t),
    )?;
    PyTuple::new(py, o)
}

/// ``(dqdd_dq, dqdd_dv, Minv)`` of a floating-base model from q (7 + n), v, tau (6 + n).
#[allow(clippy::too_many_arguments)]
pub(crate) fn aba_derivatives<'py>(
    m: &NumericModel,
    py: Python<'py>,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    tau: &Bound<'py, PyAny>,
    f_ext: Option<&Bound<'py, PyAny>>,
    frame: &str,
    threads: Option<i64>,
    out: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyTuple>> {
    let (nq, nv) = (m.model.nq + NQ_BASE, m.model.nv + NV_BASE);
    let o = run(
        m,
        py,
        "aba_derivatives",
        [("q", q, nq), ("qd", v, nv), ("tau", tau, nv)],
        f_ext,
        frame,
        threads,
        out,
        |md, sc, [q, v, tau], e, [o0, o1, o2]| {
            let (data, deriv) = sc.deriv(md);
            algo::aba_derivatives_floating(md, data, deriv, q, v, tau, local(e).as_ref(), o0, o1, o2)
        },
        |md, args, e, outs, t| bd::aba_derivatives_floating(md, args, e.map(|w| (w, ForceFrame::Local)), outs, t),
    )?;
    PyTuple::new(py, o)
}

/// M^-1 of a floating-base model from q (7 + n): (6 + n, 6 + n).
pub(crate) fn minverse<'py>(
    m: &NumericModel,
    py: Python<'py>,
    q: &Bound<'py, PyAny>,
    threads: Option<i64>,
    out: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let nq = m.model.nq + NQ_BASE;
    let [o] = run(
        m,
        py,
        "minverse",
        [("q", q, nq)],
        None,
        "local",
        threads,
        out,
        |md, sc, [q], _, [o]| {
            let (data, deriv) = sc.deriv(md);
            algo::minverse_floating(md, data, deriv, q, o)
        },
        |md, [q], _, [o], t| bd::minverse_floating(md, q, o, t),
    )?;
    Ok(o)
}

/// The derivatives of a model with joints of several coordinates, fixed or floating base
/// (`algo::multi_derivatives`: the 1-dof sweep on the joints' parts, corrected to the
/// tangent space): the
/// RNEA's (`rnea = true`: `(dtau_dq, dtau_dv, M)` from `qdd`) or the ABA's
/// (`(dqdd_dq, dqdd_dv, Minv)` from `tau`), with external wrenches (in the link frames
/// on a floating base, as [`run`] checks); a batch runs on `threads` threads, one state
/// at a time on each (the GIL released).
#[allow(clippy::too_many_arguments)]
pub(crate) fn tangent<'py>(
    m: &NumericModel,
    py: Python<'py>,
    rnea: bool,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    third: &Bound<'py, PyAny>,
    f_ext: Option<&Bound<'py, PyAny>>,
    frame: &str,
    threads: Option<i64>,
    out: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyTuple>> {
    let what = if rnea { "rnea_derivatives" } else { "aba_derivatives" };
    let floating = m.floating;
    let (nq, nv) = m.widths();
    let args = [("q", q, nq), ("qd", v, nv), (if rnea { "qdd" } else { "tau" }, third, nv)];
    let frame_of = parse_frame(frame)?;
    let o = run(
        m,
        py,
        what,
        args,
        f_ext,
        frame,
        threads,
        out,
        |md, sc, ins, e, outs| {
            let w = sc.multi_work.get_or_insert_with(|| MultiWork::new(md, floating));
            tangent_derivatives(md, floating, rnea, w, ins, with_frame(e, frame_of).as_ref(), outs)
        },
        |md, ins, e, outs, t| bd::multi_derivatives(md, floating, rnea, ins, e.map(|e| (e, frame_of)), outs, t),
    )?;
    PyTuple::new(py, o)
}
