//! Binding of `armdyn_core::algo::integrate::simulate` as `armdyn._core._simulate`.
//!
//! Low level: `python/armdyn/simulate.py` validates and broadcasts the arguments, and
//! documents them; here every array must already have its exact shape (checked again,
//! a mismatch is a `ValueError`). The GIL is released while integrating.

use super::{guard, thread_arg, NumericModel};
use armdyn_core::algo::integrate::{self, Input, Method, Outputs, Settings};
use numpy::{PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The data of a C-contiguous read-only array, with its shape checked.
fn data<'a>(a: &'a PyReadonlyArrayDyn<'_, f64>, name: &str, shape: &[usize]) -> PyResult<&'a [f64]> {
    if a.shape() != shape {
        return Err(PyValueError::new_err(format!("{name}: shape {:?}, expected {shape:?}", a.shape())));
    }
    a.as_slice().map_err(|_| PyValueError::new_err(format!("{name}: not C-contiguous")))
}

/// Integrate `q0`, `qd0` (N, nv) for `steps` steps of `dt`; see armdyn.simulate.
///
/// torque_kind: "zero", "constant" (torque (N, nv)), "series" (torque (steps, nv)),
/// "series-per-state" (torque (N, steps, nv)), "pd", "pd-gravity", "computed-torque"
/// (kp, kd (nv,), target, target_qd (N, nv)). lower, upper: (nv,). Returns a dict of
/// q, qd, qdd, tau (N, S, nv), q_final, qd_final (N, nv), limit_step, limit_joint,
/// nonfinite_step (N,) int64.
#[pyfunction]
#[pyo3(signature = (model, q0, qd0, dt, steps, stride, method, torque_kind, torque, kp, kd, target, target_qd, lower, upper, threads = None))]
#[allow(clippy::too_many_arguments)]
fn _simulate<'py>(
    py: Python<'py>,
    model: &Bound<'py, NumericModel>,
    q0: PyReadonlyArrayDyn<'py, f64>,
    qd0: PyReadonlyArrayDyn<'py, f64>,
    dt: f64,
    steps: usize,
    stride: usize,
    method: &str,
    torque_kind: &str,
    torque: PyReadonlyArrayDyn<'py, f64>,
    kp: PyReadonlyArrayDyn<'py, f64>,
    kd: PyReadonlyArrayDyn<'py, f64>,
    target: PyReadonlyArrayDyn<'py, f64>,
    target_qd: PyReadonlyArrayDyn<'py, f64>,
    lower: PyReadonlyArrayDyn<'py, f64>,
    upper: PyReadonlyArrayDyn<'py, f64>,
    threads: Option<i64>,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let threads = thread_arg(threads)?;
        let m = &model.get().model;
        let n = m.nv;
        let rows = q0.shape().first().copied().unwrap_or(0);
        let method = match method {
            "rk4" => Method::Rk4,
            "euler" => Method::SemiImplicitEuler,
            other => return Err(PyValueError::new_err(format!("method: unknown '{other}'"))),
        };
        if !(dt.is_finite() && dt > 0.0) || stride == 0 {
            return Err(PyValueError::new_err(format!("dt = {dt}, stride = {stride}: need dt > 0 finite, stride >= 1")));
        }
        let settings = Settings { method, dt, steps, stride };
        let q0 = data(&q0, "q0", &[rows, n])?;
        let qd0 = data(&qd0, "qd0", &[rows, n])?;
        let lower = data(&lower, "lower", &[n])?;
        let upper = data(&upper, "upper", &[n])?;
        let gains = || -> PyResult<_> {
            Ok((data(&kp, "kp", &[n])?, data(&kd, "kd", &[n])?, data(&target, "target", &[rows, n])?, data(&target_qd, "target_qd", &[rows, n])?))
        };
        let input = match torque_kind {
            "zero" => Input::Zero,
            "constant" => Input::Constant(data(&torque, "torque", &[rows, n])?),
            "series" => Input::Series { tau: data(&torque, "torque", &[steps, n])?, shared: true },
            "series-per-state" => Input::Series { tau: data(&torque, "torque", &[rows, steps, n])?, shared: false },
            "pd" | "pd-gravity" => {
                let (kp, kd, target, target_qd) = gains()?;
                Input::Pd { kp, kd, target, target_qd, gravity_compensation: torque_kind == "pd-gravity" }
            }
            "computed-torque" => {
                let (kp, kd, target, target_qd) = gains()?;
                Input::ComputedTorque { kp, kd, target, target_qd }
            }
            other => return Err(PyValueError::new_err(format!("torque_kind: unknown '{other}'"))),
        };
        if matches!(input, Input::Series { .. }) && steps == 0 {
            return Err(PyValueError::new_err("a torque series needs at least one step"));
        }
        let s = settings.samples();
        let f = |dims: &[usize]| PyArrayDyn::<f64>::zeros(py, dims, false);
        let i = |dims: &[usize]| PyArrayDyn::<i64>::zeros(py, dims, false);
        let (q, qd, qdd, tau) = (f(&[rows, s, n]), f(&[rows, s, n]), f(&[rows, s, n]), f(&[rows, s, n]));
        let (q_final, qd_final) = (f(&[rows, n]), f(&[rows, n]));
        let (limit_step, limit_joint, nonfinite_step) = (i(&[rows]), i(&[rows]), i(&[rows]));
        {
            // SAFETY: fresh arrays, not visible to Python until returned.
            let out = unsafe {
                Outputs {
                    q: q.as_slice_mut().expect("fresh"),
                    qd: qd.as_slice_mut().expect("fresh"),
                    qdd: qdd.as_slice_mut().expect("fresh"),
                    tau: tau.as_slice_mut().expect("fresh"),
                    q_final: q_final.as_slice_mut().expect("fresh"),
                    qd_final: qd_final.as_slice_mut().expect("fresh"),
                    limit_step: limit_step.as_slice_mut().expect("fresh"),
                    limit_joint: limit_joint.as_slice_mut().expect("fresh"),
                    nonfinite_step: nonfinite_step.as_slice_mut().expect("fresh"),
                }
            };
            py.detach(|| integrate::simulate(m, q0, qd0, input, settings, lower, upper, out, threads));
        }
        let d = PyDict::new(py);
        d.set_item("q", q)?;
        d.set_item("qd", qd)?;
        d.set_item("qdd", qdd)?;
        d.set_item("tau", tau)?;
        d.set_item("q_final", q_final)?;
        d.set_item("qd_final", qd_final)?;
        d.set_item("limit_step", limit_step)?;
        d.set_item("limit_joint", limit_joint)?;
        d.set_item("nonfinite_step", nonfinite_step)?;
        Ok(d)
    })
}

/// Register this file's functions in the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(_simulate, m)?)
}
