//! Binding of `armdyn_core::algo::integrate::simulate` as `armdyn._core._simulate`.
//!
//! Low level: `python/armdyn/simulate.py` validates and broadcasts the arguments, and
//! documents them; here every array must already have its exact shape (checked again,
//! a mismatch is a `ValueError`). The GIL is released while integrating.
//!
//! Ctrl-C: a long run integrates on a worker thread while this (the Python) thread waits
//! in slices of [`SIGNAL_POLL`] with the GIL released, re-acquiring it between slices only
//! to run Python's signal handlers (`Python::check_signals`). On a `KeyboardInterrupt`
//! (or any exception a handler raises) the worker's stop flag is set, the worker ends
//! within [`integrate::STOP_POLL`] steps, and the exception is returned with no result.

use super::{guard, thread_arg, NumericModel};
use armdyn_core::algo::integrate::{self, Input, Method, Outputs, Settings};
use armdyn_core::algo::integrate_floating;
use armdyn_core::algo::manifold::Manifold;
use numpy::{PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::Duration;

/// How often a waiting run looks at Python's signals.
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// Runs with fewer `rows * steps * nv` than this (a few milliseconds at most) integrate on
/// the calling thread: a worker thread is not worth its start-up there.
const INLINE_WORK: usize = 100_000;

/// Set when the worker ends, also by a panic (the guard's drop), so the wait always ends.
struct Done<'a>(&'a (Mutex<bool>, Condvar));

impl Drop for Done<'_> {
    fn drop(&mut self) {
        *self.0 .0.lock().unwrap_or_else(|e| e.into_inner()) = true;
        self.0 .1.notify_all();
    }
}

/// Run `work(stop)` on a worker thread, polling Python's signal handlers meanwhile;
/// an exception from a handler sets `stop`, waits for the worker and is returned.
fn interruptible<F: FnOnce(&AtomicBool) + Send>(py: Python<'_>, work: F) -> PyResult<()> {
    let stop = AtomicBool::new(false);
    let done = (Mutex::new(false), Condvar::new());
    // true once the worker has ended (waits at most `timeout`)
    let wait = |timeout: Duration| {
        let guard = done.0.lock().unwrap_or_else(|e| e.into_inner());
        let (guard, _) = done.1.wait_timeout_while(guard, timeout, |d| !*d).unwrap_or_else(|e| e.into_inner());
        *guard
    };
    std::thread::scope(|scope| {
        let (stop, done) = (&stop, &done);
        scope.spawn(move || {
            let _done = Done(done);
            work(stop);
        });
        loop {
            if py.detach(|| wait(SIGNAL_POLL)) {
                return Ok(()); // finished (a panic is re-raised by the scope)
            }
            if let Err(err) = py.check_signals() {
                stop.store(true, Ordering::Relaxed);
                while !py.detach(|| wait(Duration::from_secs(3600))) {}
                return Err(err);
            }
        }
    })
}

/// The data of a C-contiguous read-only array, with its shape checked.
fn data<'a>(a: &'a PyReadonlyArrayDyn<'_, f64>, name: &str, shape: &[usize]) -> PyResult<&'a [f64]> {
    if a.shape() != shape {
        return Err(PyValueError::new_err(format!("{name}: shape {:?}, expected {shape:?}", a.shape())));
    }
    a.as_slice().map_err(|_| PyValueError::new_err(format!("{name}: not C-contiguous")))
}

/// Integrate `q0`, `qd0` (N, nv) for `steps` steps of `dt`; see armdyn.simulate.
///
/// A floating-base model or one with joints of several coordinates
/// (`algo::integrate_floating`): `q0`, `q`, `q_final` have the model's `nq` columns
/// (7 more with a floating base), `qd0`, the torques and the other outputs `nv` (6
/// more); lower, upper stay (dof,); the controllers' kp, kd, target_qd are (nv,) and
/// (N, nv), target (N, nq), at those widths (a floating base's rows are not actuated).
///
/// torque_kind: "zero", "constant" (torque (N, nv)), "series" (torque (steps, nv)),
/// "series-per-state" (torque (N, steps, nv)), "pd", "pd-gravity", "computed-torque"
/// (kp, kd (nv,), target, target_qd (N, nv)). lower, upper: (nv,). Returns a dict of
/// q, qd, qdd, tau (N, S, nv), work (N, S) (of the torque since the start), q_final, qd_final (N, nv), limit_step, limit_joint,
/// nonfinite_step, nonfinite_joint (N,) int64 (a state's samples after its
/// nonfinite_step are not written). Ctrl-C during a long run raises KeyboardInterrupt
/// within about 0.1 s (see the module docstring).
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
        let floating = model.get().floating;
        // a configuration that is not flat: a floating base or joints of several coordinates
        let manifold = floating || m.has_multi();
        let n = m.nv;
        // the widths of q and of v (qd, qdd, tau): a floating base adds its 7 and 6
        let (nq, nv) = if floating { (m.nq + 7, n + 6) } else { (m.nq, n) };
        let rows = q0.shape().first().copied().unwrap_or(0);
        let method = match method {
            "rk4" => Method::Rk4,
            "euler" => Method::SemiImplicitEuler,
            other => return Err(PyValueError::new_err(format!("method: unknown '{other}'"))),
        };
        if !(dt.is_finite() && dt > 0.0) || stride == 0 {
            return Err(PyValueError::new_err(format!(
                "dt = {dt}, stride = {stride}: need dt > 0 finite, stride >= 1"
            )));
        }
        let settings = Settings { method, dt, steps, stride };
        let q0 = data(&q0, "q0", &[rows, nq])?;
        let qd0 = data(&qd0, "qd0", &[rows, nv])?;
        if manifold {
            model.get().check_unit_blocks(q0)?;
        }
        let lower = data(&lower, "lower", &[n])?;
        let upper = data(&upper, "upper", &[n])?;
        let gains = || -> PyResult<_> {
            Ok((
                data(&kp, "kp", &[nv])?,
                data(&kd, "kd", &[nv])?,
                data(&target, "target", &[rows, nq])?,
                data(&target_qd, "target_qd", &[rows, nv])?,
            ))
        };
        let input = match torque_kind {
            "zero" => Input::Zero,
            "constant" => Input::Constant(data(&torque, "torque", &[rows, nv])?),
            "series" => Input::Series { tau: data(&torque, "torque", &[steps, nv])?, shared: true },
            "series-per-state" => Input::Series { tau: data(&torque, "torque", &[rows, steps, nv])?, shared: false },
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
        if manifold {
            if let Input::Pd { target, .. } | Input::ComputedTorque { target, .. } = input {
                model.get().check_unit_blocks(target)?;
            }
        }
        if matches!(input, Input::Series { .. }) && steps == 0 {
            return Err(PyValueError::new_err("a torque series needs at least one step"));
        }
        let s = settings.samples();
        let f = |dims: &[usize]| PyArrayDyn::<f64>::zeros(py, dims, false);
        let i = |dims: &[usize]| PyArrayDyn::<i64>::zeros(py, dims, false);
        let (q, qd, qdd, tau) = (f(&[rows, s, nq]), f(&[rows, s, nv]), f(&[rows, s, nv]), f(&[rows, s, nv]));
        let (q_final, qd_final) = (f(&[rows, nq]), f(&[rows, nv]));
        let work = f(&[rows, s]);
        let (limit_step, limit_joint, nonfinite_step, nonfinite_joint) =
            (i(&[rows]), i(&[rows]), i(&[rows]), i(&[rows]));
        {
            // SAFETY: fresh arrays, not visible to Python until returned.
            let out = unsafe {
                Outputs {
                    q: q.as_slice_mut().expect("fresh"),
                    work: work.as_slice_mut().expect("fresh"),
                    qd: qd.as_slice_mut().expect("fresh"),
                    qdd: qdd.as_slice_mut().expect("fresh"),
                    tau: tau.as_slice_mut().expect("fresh"),
                    q_final: q_final.as_slice_mut().expect("fresh"),
                    qd_final: qd_final.as_slice_mut().expect("fresh"),
                    limit_step: limit_step.as_slice_mut().expect("fresh"),
                    limit_joint: limit_joint.as_slice_mut().expect("fresh"),
                    nonfinite_step: nonfinite_step.as_slice_mut().expect("fresh"),
                    nonfinite_joint: nonfinite_joint.as_slice_mut().expect("fresh"),
                }
            };
            let run = |stop: &AtomicBool| {
                if manifold {
                    let f = integrate_floating::simulate_manifold_until;
                    f(m, floating, q0, qd0, input, settings, lower, upper, out, threads, stop);
                } else {
                    integrate::simulate_until(m, q0, qd0, input, settings, lower, upper, out, threads, stop);
                }
            };
            if rows.saturating_mul(steps).saturating_mul(nv.max(1)) < INLINE_WORK {
                py.detach(|| run(&AtomicBool::new(false)));
            } else {
                interruptible(py, run)?;
            }
        }
        let d = PyDict::new(py);
        d.set_item("q", q)?;
        d.set_item("qd", qd)?;
        d.set_item("qdd", qdd)?;
        d.set_item("tau", tau)?;
        d.set_item("work", work)?;
        d.set_item("q_final", q_final)?;
        d.set_item("qd_final", qd_final)?;
        d.set_item("limit_step", limit_step)?;
        d.set_item("limit_joint", limit_joint)?;
        d.set_item("nonfinite_step", nonfinite_step)?;
        d.set_item("nonfinite_joint", nonfinite_joint)?;
        Ok(d)
    })
}

/// The model's manifold (a floating base's first) and `a`, `b` (N, wa), (N, wb) checked.
fn manifold_rows<'a>(
    model: &Bound<'_, NumericModel>,
    a: &'a PyReadonlyArrayDyn<'_, f64>,
    b: &'a PyReadonlyArrayDyn<'_, f64>,
    names: [&str; 2],
    widths: impl Fn(&Manifold) -> (usize, usize),
) -> PyResult<(Manifold, &'a [f64], &'a [f64])> {
    let manifold = Manifold::new(&model.get().model, model.get().floating);
    let (wa, wb) = widths(&manifold);
    let rows = a.shape().first().copied().unwrap_or(0);
    Ok((manifold, data(a, names[0], &[rows, wa])?, data(b, names[1], &[rows, wb])?))
}

/// `q (+) xi` row by row (`q` (N, nq), `xi` (N, nv)): the step of the manifold
/// integrators (`algo::manifold`), for the Python-callable path of armdyn.simulate.
#[pyfunction]
fn _manifold_integrate<'py>(
    py: Python<'py>,
    model: &Bound<'py, NumericModel>,
    q: PyReadonlyArrayDyn<'py, f64>,
    xi: PyReadonlyArrayDyn<'py, f64>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    guard(|| {
        let (m, q, xi) = manifold_rows(model, &q, &xi, ["q", "xi"], |m| (m.nq, m.nv))?;
        let out = PyArrayDyn::<f64>::zeros(py, &[q.len() / m.nq.max(1), m.nq][..], false);
        // SAFETY: a fresh array, not visible to Python until returned.
        let o = unsafe { out.as_slice_mut().expect("fresh") };
        for ((q, xi), o) in q.chunks(m.nq).zip(xi.chunks(m.nv)).zip(o.chunks_mut(m.nq)) {
            m.integrate(q, xi, o);
        }
        Ok(out)
    })
}

/// RK-Munthe-Kaas's rate of the local coordinate, `dexp^-1_{-theta}(v)` to fourth order,
/// row by row (`theta`, `v` (N, nv); `algo::manifold::Manifold::local_rate`).
#[pyfunction]
fn _manifold_local_rate<'py>(
    py: Python<'py>,
    model: &Bound<'py, NumericModel>,
    theta: PyReadonlyArrayDyn<'py, f64>,
    v: PyReadonlyArrayDyn<'py, f64>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    guard(|| {
        let (m, theta, v) = manifold_rows(model, &theta, &v, ["theta", "v"], |m| (m.nv, m.nv))?;
        let out = PyArrayDyn::<f64>::zeros(py, &[theta.len() / m.nv.max(1), m.nv][..], false);
        // SAFETY: a fresh array, not visible to Python until returned.
        let o = unsafe { out.as_slice_mut().expect("fresh") };
        for ((t, v), o) in theta.chunks(m.nv).zip(v.chunks(m.nv)).zip(o.chunks_mut(m.nv)) {
            m.local_rate(t, v, o);
        }
        Ok(out)
    })
}

/// Register this file's functions in the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(_simulate, m)?)?;
    m.add_function(wrap_pyfunction!(_manifold_integrate, m)?)?;
    m.add_function(wrap_pyfunction!(_manifold_local_rate, m)?)
}
