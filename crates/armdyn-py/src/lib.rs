//! `armdyn._core`: thin Python bindings of armdyn-core.
//!
//! One class, `NumericModel`: built once from a robot's numeric description, joint by
//! joint (`ModelBuilder`, `builder.rs`; `python/armdyn/numeric/` is the user-facing API
//! and documents every function), holding the immutable model and a workspace for single
//! calls.
//!
//! Every method takes one state `(n,)` or a batch `(N, n)` of float64 (anything else is
//! converted once with `numpy.ascontiguousarray`) and answers in the same shape. Shape
//! errors and NaN/inf raise `ValueError` naming the argument. Batches run on `threads`
//! threads (None = all cores) with the GIL released. A Rust panic becomes a
//! `RuntimeError`, never a crash.
//!
//! One state is the latency-bound case (a 6-joint rnea is 300 ns of arithmetic): a plain
//! float64 `(n,)` ndarray is read in place (`plain_state`), the GIL is kept, and the
//! result goes into an array of an earlier call that nobody holds any more (`OutputPool`).

use armdyn_core::{algo, batch, Model};
use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::{PyFloatingPointError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyFloat, PyString};
use std::collections::HashMap;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Mutex;

mod args;
mod builder;
mod centroidal;
mod derivatives;
mod floating;
mod floating_derivatives;
mod free_root;
mod regressor;
mod scratch;
mod simulate;

pub(crate) use args::*;
pub(crate) use builder::ModelBuilder;
pub(crate) use scratch::*;

/// Run `f`, turning a Rust panic into a Python `RuntimeError`.
fn guard<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|payload| {
        let msg = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        Err(PyRuntimeError::new_err(format!("armdyn internal error (please report): {msg}")))
    })
}

/// A robot's dynamics model compiled for numeric evaluation (see armdyn.numeric).
#[pyclass(name = "NumericModel", module = "armdyn._core", frozen)]
pub struct NumericModel {
    model: Model,
    scratch: Mutex<Scratch>,
    name: String,
    link_names: Vec<String>,
    link_index: HashMap<String, usize>,
    coordinate_names: Vec<String>,
    /// What built it, for pickling (`__reduce__`).
    builder: ModelBuilder,
    /// Movable joints whose whole subtree has no mass and no inertia: M is singular
    /// and `aba` refuses (it would divide by zero).
    inert_joints: Vec<String>,
    /// Whether the base floats (a free-flyer root joint, `floating.rs`): rnea, crba and
    /// aba (and the kinematics and energies) then take Pinocchio's floating-base arrays, and
    /// every other method refuses.
    floating: bool,
    /// For a floating base, the same robot hung from the world on a free joint
    /// (`free_root.rs`): what the Coriolis matrix, `jacobian_dot` and the regressor run on.
    free_root: Option<Model>,
}

/// Bodies (= movable joints, by coordinate index) whose subtree, themselves included,
/// has zero spatial inertia. Parents precede children, so one backward pass suffices.
pub(crate) fn inert_bodies(model: &Model) -> Vec<usize> {
    let mut inert: Vec<bool> = model.inertia.iter().map(|i| *i == Default::default()).collect();
    for i in (0..model.nv).rev() {
        if let Some(p) = model.parent[i] {
            inert[p] &= inert[i];
        }
    }
    (0..model.nv).filter(|&i| inert[i]).collect()
}

impl NumericModel {
    /// Index of a link given by name or index.
    fn link_arg(&self, link: &Bound<'_, PyAny>) -> PyResult<usize> {
        if let Ok(s) = link.cast::<PyString>() {
            let s = s.to_str()?;
            return self.link_index.get(s).copied().ok_or_else(|| {
                PyValueError::new_err(format!("link: no link named '{s}' (links: {})", self.link_names.join(", ")))
            });
        }
        match link.extract::<i64>() {
            Ok(k) if k >= 0 && (k as usize) < self.model.nlinks() => Ok(k as usize),
            Ok(k) => Err(PyValueError::new_err(format!("link: index {k} out of range 0..{}", self.model.nlinks()))),
            Err(_) => Err(PyValueError::new_err("link: expected a link name or index")),
        }
    }

    /// Run `f` with the single-call workspace (a fresh one if another thread holds it).
    fn with_scratch<R>(&self, f: impl FnOnce(&mut Scratch) -> R) -> R {
        match self.scratch.try_lock() {
            Ok(mut s) => f(&mut s),
            Err(std::sync::TryLockError::Poisoned(p)) => f(&mut p.into_inner()),
            Err(std::sync::TryLockError::WouldBlock) => f(&mut Scratch::new(&self.model)),
        }
    }

    /// The shared body of the `(n,) -> (n,)` style methods whose batch path is a
    /// lane kernel: `single(data, args, out)` or `batched(model, args, out, threads)`.
    /// [`Self::vector_op_unchecked`], then a `FloatingPointError` if the result holds NaN or
    /// inf: the inputs were checked finite, so that is an overflow (qd = 1e300 squared in the
    /// velocity products). Checked here, in a few nanoseconds, rather than in Python (a
    /// microsecond on a 6x6 matrix, longer than the algorithm).
    fn vector_op<'py, const K: usize>(
        &self,
        py: Python<'py>,
        args: [(&str, &Bound<'py, PyAny>); K],
        out_shape: &[usize],
        threads: Option<i64>,
        single: impl FnOnce(&Model, &mut Scratch, [&[f64]; K], &mut [f64]),
        batched: impl FnOnce(&Model, [&[f64]; K], &mut [f64], Option<usize>) + Send,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let out = self.vector_op_unchecked(py, args, out_shape, threads, single, batched)?;
        // SAFETY: `out` is ours and not yet returned.
        if all_finite(unsafe { slice(&out) }) {
            Ok(out)
        } else {
            Err(PyFloatingPointError::new_err("the result is not finite: an overflow from finite inputs"))
        }
    }

    fn vector_op_unchecked<'py, const K: usize>(
        &self,
        py: Python<'py>,
        args: [(&str, &Bound<'py, PyAny>); K],
        out_shape: &[usize],
        threads: Option<i64>,
        single: impl FnOnce(&Model, &mut Scratch, [&[f64]; K], &mut [f64]),
        batched: impl FnOnce(&Model, [&[f64]; K], &mut [f64], Option<usize>) + Send,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guard(|| {
            self.fixed_base_only()?;
            let threads = thread_arg(threads)?;
            // the common call, one plain float64 state: read in place, no conversion objects
            // SAFETY: inputs read-only and `out` fresh, GIL held throughout.
            let plain = !self.model.has_multi();
            if let Some(ins) = plain.then(|| unsafe { plain_states(py, self.model.nv, &args) }).flatten() {
                return Ok(self.with_scratch(|s| {
                    let out = s.output(py, out_shape);
                    // SAFETY: `out` (C-contiguous, of `out_shape`) is fresh or pooled and free:
                    // nothing else refers to its data while `single` writes every element.
                    let o = unsafe { std::slice::from_raw_parts_mut(out.data(), out.len()) };
                    single(&self.model, s, ins, o);
                    out
                }));
            }
            let (shape, arrays) = self.joint_states(args)?;
            match shape {
                Shape::Single => {
                    let out = new_array(py, out_shape);
                    // SAFETY: inputs read-only and `out` fresh, GIL held throughout.
                    let ins: [&[f64]; K] = std::array::from_fn(|k| unsafe { slice(&arrays[k]) });
                    let o = unsafe { out.as_slice_mut().expect("fresh array") };
                    self.with_scratch(|s| single(&self.model, s, ins, o));
                    Ok(out)
                }
                Shape::Batch(rows) => {
                    let dims: Vec<usize> = std::iter::once(rows).chain(out_shape.iter().copied()).collect();
                    let out = new_array(py, &dims);
                    let readonly: Vec<_> = arrays.iter().map(|a| a.readonly()).collect();
                    let ins: [&[f64]; K] = std::array::from_fn(|k| readonly[k].as_slice().expect("contiguous"));
                    // SAFETY: `out` is fresh and not visible to Python until returned.
                    let o = unsafe { out.as_slice_mut().expect("fresh array") };
                    let model = &self.model;
                    py.detach(|| batched(model, ins, o, threads));
                    Ok(out)
                }
            }
        })
    }
}

#[pymethods]
impl NumericModel {
    /// Number of movable joints.
    #[getter]
    fn dof(&self) -> usize {
        self.model.nv
    }
    /// Whether the base floats (a free-flyer root joint).
    #[getter]
    fn floating(&self) -> bool {
        self.floating
    }
    /// Length of q: the joints' configuration (a quaternion or planar pair counting 4), 7
    /// more for a floating base.
    #[getter]
    fn nq(&self) -> usize {
        self.widths().0
    }
    /// Length of v (qd, qdd, tau): dof (the joints' velocity coordinates), 6 more for a
    /// floating base.
    #[getter]
    fn nv(&self) -> usize {
        self.widths().1
    }
    /// Number of link frames (base included).
    #[getter]
    fn nlinks(&self) -> usize {
        self.model.nlinks()
    }
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }
    /// Link names, base first (the order of forward_kinematics).
    #[getter]
    fn link_names(&self) -> Vec<String> {
        self.link_names.clone()
    }
    /// Names of the movable joints (the order of q).
    #[getter]
    fn coordinate_names(&self) -> Vec<String> {
        self.coordinate_names.clone()
    }
    /// Gravity (3,) in the base frame.
    #[getter]
    fn gravity(&self) -> [f64; 3] {
        self.model.gravity.to_array()
    }
    /// The model itself, so that `obj._numeric_model` is the compiled model for a
    /// Robot (where it is cached) and for a NumericModel alike.
    #[getter(_numeric_model)]
    fn compiled_self(slf: Bound<'_, Self>) -> Bound<'_, Self> {
        slf
    }

    /// Pickling rebuilds the model from its builder (so it travels to other processes,
    /// e.g. Dask workers: friction and rotor inertia included).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (ModelBuilder,))> {
        let build = slf.py().import("armdyn._core")?.getattr("_build")?;
        Ok((build, (slf.get().builder.clone(),)))
    }

    fn __repr__(&self) -> String {
        let base = if self.floating { ", floating" } else { "" };
        format!("NumericModel({:?}, dof={}, nlinks={}{base})", self.name, self.model.nv, self.model.nlinks())
    }

    /// Inverse dynamics tau = M qdd + C qd + g. q, qd, qdd: (n,) or (N, n).
    #[pyo3(signature = (q, qd, qdd, threads = None))]
    fn rnea<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: &Bound<'py, PyAny>,
        qdd: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        if self.floating {
            return self.rnea_floating(py, q, qd, qdd, threads);
        }
        self.vector_op(
            py,
            [("q", q), ("qd", qd), ("qdd", qdd)],
            &[self.model.nv],
            threads,
            |m, s, [q, qd, qdd], o| algo::rnea(m, &mut s.data, q, qd, qdd, o),
            batch::rnea,
        )
    }

    /// Forward dynamics qdd = M^-1 (tau - C qd - g). q, qd, tau: (n,) or (N, n).
    #[pyo3(signature = (q, qd, tau, threads = None))]
    fn aba<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: &Bound<'py, PyAny>,
        tau: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        if self.floating {
            return self.aba_floating(py, q, qd, tau, threads);
        }
        if !self.inert_joints.is_empty() {
            let names: Vec<String> = self.inert_joints.iter().map(|n| format!("'{n}'")).collect();
            return Err(PyValueError::new_err(format!(
                "aba: the joint-space inertia matrix of '{}' is singular: joints [{}] move no mass or \
                 inertia (links without inertia?), so their accelerations are undetermined",
                self.name,
                names.join(", ")
            )));
        }
        let out = self.vector_op_unchecked(
            py,
            [("q", q), ("qd", qd), ("tau", tau)],
            &[self.model.nv],
            threads,
            |m, s, [q, qd, tau], o| algo::aba(m, &mut s.data, q, qd, tau, o),
            batch::aba,
        )?;
        // finite inputs (checked) give a finite result unless M is singular at this state
        // (e.g. a revolute joint whose subtree's mass all lies on its axis)
        // SAFETY: `out` is ours and not yet returned.
        let values = unsafe { slice(&out) };
        if !all_finite(values) {
            let k = values.iter().position(|x| !x.is_finite()).unwrap_or(0);
            let n = self.model.nv.max(1);
            let at = if out.ndim() == 1 { String::new() } else { format!(" (row {} of the batch)", k / n) };
            return Err(PyValueError::new_err(format!(
                "aba: the joint-space inertia matrix of '{}' is singular at this state{at} (e.g. a \
                 subtree's mass all on a joint's axis): no finite acceleration",
                self.name
            )));
        }
        Ok(out)
    }

    /// Joint-space inertia matrix M (n, n) (or (N, n, n)).
    #[pyo3(signature = (q, threads = None))]
    fn crba<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        if self.floating {
            return self.crba_floating(py, q, threads);
        }
        let n = self.model.nv;
        self.vector_op(py, [("q", q)], &[n, n], threads, |m, s, [q], o| algo::crba(m, &mut s.data, q, o), batch::crba)
    }

    /// Gravity torques g(q) = rnea(q, 0, 0).
    #[pyo3(signature = (q, threads = None))]
    fn gravity_torques<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        self.vector_op(
            py,
            [("q", q)],
            &[self.model.nv],
            threads,
            |m, s, [q], o| algo::gravity(m, &mut s.data, q, o),
            batch::gravity,
        )
    }

    /// Nonlinear effects h = C qd + g = rnea(q, qd, 0).
    #[pyo3(signature = (q, qd, threads = None))]
    fn bias<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        self.vector_op(
            py,
            [("q", q), ("qd", qd)],
            &[self.model.nv],
            threads,
            |m, s, [q, qd], o| algo::bias(m, &mut s.data, q, qd, o),
            batch::bias,
        )
    }

    /// The Christoffel-consistent Coriolis matrix C (n, n) (or (N, n, n)).
    #[pyo3(signature = (q, qd, threads = None))]
    fn coriolis_matrix<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        if self.floating {
            return self.coriolis_free_root(py, q, qd, threads);
        }
        let n = self.model.nv;
        self.vector_op(
            py,
            [("q", q), ("qd", qd)],
            &[n, n],
            threads,
            |m, s, [q, qd], o| algo::coriolis_matrix(m, &mut s.data, &mut s.coriolis, q, qd, o),
            |m, [q, qd], o, t| batch::coriolis_matrix(m, q, qd, o, t),
        )
    }

    /// Kinetic energy 1/2 qd^T M qd: a float (or (N,)).
    #[pyo3(signature = (q, qd, threads = None))]
    fn kinetic_energy<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        if self.floating {
            return self.kinetic_energy_floating(py, q, qd, threads);
        }
        let out = self.vector_op(
            py,
            [("q", q), ("qd", qd)],
            &[],
            threads,
            |m, s, [q, qd], o| o[0] = algo::kinetic_energy(m, &mut s.data, q, qd),
            |m, [q, qd], o, t| batch::kinetic_energy(m, q, qd, o, t),
        )?;
        scalar_if_0d(out)
    }

    /// Potential energy -sum m_i g . p_ci: a float (or (N,)).
    #[pyo3(signature = (q, threads = None))]
    fn potential_energy<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        if self.floating {
            return self.potential_energy_floating(py, q, threads);
        }
        let out = self.vector_op(
            py,
            [("q", q)],
            &[],
            threads,
            |m, s, [q], o| o[0] = algo::potential_energy(m, &mut s.data, q),
            |m, [q], o, t| batch::potential_energy(m, q, o, t),
        )?;
        scalar_if_0d(out)
    }

    /// Poses of all link frames in the base frame: (nlinks, 4, 4) (or (N, nlinks, 4, 4)).
    #[pyo3(signature = (q, threads = None))]
    fn forward_kinematics<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        if self.floating {
            return self.forward_kinematics_floating(py, q, threads);
        }
        self.vector_op(
            py,
            [("q", q)],
            &[self.model.nlinks(), 4, 4],
            threads,
            |m, s, [q], o| algo::forward_kinematics(m, &mut s.data, q, o),
            |m, [q], o, t| batch::forward_kinematics(m, q, o, t),
        )
    }

    /// Geometric Jacobian (6, n) (or (N, 6, n)) of link `link` (name or index in
    /// link_names), rows [v; w] in base-frame axes.
    #[pyo3(signature = (q, link, threads = None))]
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        link: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let index = self.link_arg(link)?;
        if self.floating {
            return self.jacobian_floating(py, q, index, threads);
        }
        self.vector_op(
            py,
            [("q", q)],
            &[6, self.model.nv],
            threads,
            |m, s, [q], o| algo::jacobian(m, &mut s.data, q, index, o),
            |m, [q], o, t| batch::jacobian(m, q, index, o, t),
        )
    }
}

/// A 0-d result as a Python float, else the array.
fn scalar_if_0d(a: Bound<'_, PyArrayDyn<f64>>) -> PyResult<Bound<'_, PyAny>> {
    if a.ndim() == 0 {
        // SAFETY: a fresh 0-d array holds one element.
        let x = unsafe { slice(&a) }[0];
        Ok(PyFloat::new(a.py(), x).into_any())
    } else {
        Ok(a.into_any())
    }
}

/// Panic on purpose (inside a batch call, with the GIL released, when `in_batch`), to
/// test that panics surface as RuntimeError. Not part of the API.
#[pyfunction]
#[pyo3(signature = (in_batch = false))]
fn _test_panic(py: Python<'_>, in_batch: bool) -> PyResult<()> {
    guard(|| {
        if in_batch {
            let mut out = vec![0.0; 1000];
            let model = Model::new(&[], [0.0; 3]).expect("empty model");
            // rows of width 0 with a non-empty output: the batch driver's size check fails
            py.detach(|| batch::crba(&model, [&[]], &mut out, Some(2)));
        }
        panic!("deliberate test panic")
    })
}

/// The SIMD kernels batches run with on this CPU: "avx512" (8 states per step),
/// "avx2" (4) or "baseline" (4; SSE2 on x86-64). The environment variable ARMDYN_SIMD
/// (read once) caps them.
#[pyfunction]
fn simd_kernels() -> &'static str {
    match batch::kernels() {
        batch::Kernels::Avx512 => "avx512",
        batch::Kernels::Avx2 => "avx2",
        batch::Kernels::Baseline => "baseline",
    }
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<NumericModel>()?;
    m.add_class::<ModelBuilder>()?;
    m.add_function(wrap_pyfunction!(builder::_build, m)?)?;
    m.add_function(wrap_pyfunction!(_test_panic, m)?)?;
    m.add_function(wrap_pyfunction!(simd_kernels, m)?)?;
    derivatives::register(m)?;
    m.add_function(wrap_pyfunction!(regressor::regressor, m)?)?;
    m.add_function(wrap_pyfunction!(regressor::regressor_columns, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    simulate::register(m)?;
    centroidal::register(m)?;
    Ok(())
}
