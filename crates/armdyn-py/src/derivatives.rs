//! Bindings of the derivative algorithms, M^-1, jacobian_dot and the external-force
//! variants of rnea/aba: module-level functions taking the NumericModel first (called by
//! `python/armdyn/numeric/`, which documents them). Same rules as the methods in
//! `lib.rs`: one state `(n,)` or a batch `(N, n)`, ValueError naming the argument.

use crate::{as_f64, guard, is_c_contiguous_aligned, new_array, slice, thread_arg, NumericModel, Scratch, Shape};
use armdyn_core::algo::{self, ExternalForces, ForceFrame};
use armdyn_core::{batch_derivatives as bd, Model};
use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

pub(crate) fn parse_frame(frame: &str) -> PyResult<ForceFrame> {
    match frame {
        "local" => Ok(ForceFrame::Local),
        "world" => Ok(ForceFrame::World),
        other => Err(PyValueError::new_err(format!("frame: expected 'local' or 'world', got '{other}'"))),
    }
}

/// `f_ext` converted and checked against the states' shape: (nlinks, 6) for one state,
/// (N, nlinks, 6) for N states, finite.
pub(crate) fn check_f_ext<'py>(
    m: &NumericModel,
    obj: &Bound<'py, PyAny>,
    shape: Shape,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let a = as_f64(obj, "f_ext")?;
    let nl = m.model.nlinks();
    let ok = match (shape, a.shape()) {
        (Shape::Single, [l, 6]) => *l == nl,
        (Shape::Batch(rows), [r, l, 6]) => *r == rows && *l == nl,
        _ => false,
    };
    if !ok {
        let want = match shape {
            Shape::Single => format!("({nl}, 6)"),
            Shape::Batch(rows) => format!("({rows}, {nl}, 6)"),
        };
        return Err(PyValueError::new_err(format!(
            "f_ext: expected shape {want} (one wrench [fx, fy, fz, nx, ny, nz] per link, links in link_names order: {}), got {:?}",
            m.link_names.join(", "),
            a.shape()
        )));
    }
    // SAFETY: read-only, GIL held.
    let values = unsafe { slice(&a) };
    if let Some(k) = values.iter().position(|x| !x.is_finite()) {
        let (row, rest) = (k / (6 * nl), k % (6 * nl));
        let (link, c) = (rest / 6, rest % 6);
        let at = match shape {
            Shape::Single => format!("f_ext[{link}, {c}]"),
            Shape::Batch(_) => format!("f_ext[{row}, {link}, {c}]"),
        };
        return Err(PyValueError::new_err(format!(
            "f_ext contains NaN or inf (at {at}, link '{}')",
            m.link_names[link]
        )));
    }
    Ok(a)
}

type Ext<'a> = Option<(&'a [f64], ForceFrame)>;

/// The byte range of a C-contiguous array's data.
fn memory(a: &Bound<'_, PyArrayDyn<f64>>) -> std::ops::Range<usize> {
    let start = a.data() as usize;
    start..start + a.len() * std::mem::size_of::<f64>()
}

/// `out=`: the caller's `R` arrays (one array when `R` is 1, else a tuple or list of `R`),
/// checked: float64, C-contiguous, aligned, writeable, of shape `dims`, sharing no
/// memory with `inputs` (name, array) nor with each other. Nothing is written here.
pub(crate) fn outputs_given<'py, const R: usize>(
    out: &Bound<'py, PyAny>,
    dims: &[usize],
    inputs: &[(&str, &Bound<'py, PyArrayDyn<f64>>)],
) -> PyResult<[Bound<'py, PyArrayDyn<f64>>; R]> {
    let items: Vec<Bound<'py, PyAny>> = if R == 1 && out.cast::<numpy::PyUntypedArray>().is_ok() {
        vec![out.clone()]
    } else if out.is_instance_of::<PyTuple>() || out.is_instance_of::<pyo3::types::PyList>() {
        out.try_iter()?.collect::<PyResult<_>>()?
    } else {
        return Err(PyValueError::new_err(format!(
            "out: expected {}, got {}",
            if R == 1 { "a numpy array" } else { "a tuple of numpy arrays" },
            out.get_type().name()?
        )));
    };
    if items.len() != R {
        return Err(PyValueError::new_err(format!("out: expected {R} arrays, got {}", items.len())));
    }
    let name = |k: usize| {
        if R == 1 {
            "out".to_string()
        } else {
            format!("out[{k}]")
        }
    };
    let mut arrays = Vec::with_capacity(R);
    for (k, item) in items.iter().enumerate() {
        let a = item.cast::<PyArrayDyn<f64>>().map_err(|_| {
            PyValueError::new_err(format!("{}: expected a float64 numpy array, got {}", name(k), describe(item)))
        })?;
        if a.shape() != dims {
            return Err(PyValueError::new_err(format!("{}: expected shape {dims:?}, got {:?}", name(k), a.shape())));
        }
        if !is_c_contiguous_aligned(a) {
            return Err(PyValueError::new_err(format!("{}: must be C-contiguous and aligned", name(k))));
        }
        if a.try_readwrite().is_err() {
            // (not writeable; or borrowed mutably by Rust code elsewhere)
            return Err(PyValueError::new_err(format!("{}: is read-only", name(k))));
        }
        let r = memory(a);
        let overlaps =
            |o: &std::ops::Range<usize>| !r.is_empty() && !o.is_empty() && r.start < o.end && o.start < r.end;
        if let Some((what, _)) = inputs.iter().find(|(_, i)| overlaps(&memory(i))) {
            return Err(PyValueError::new_err(format!("{}: shares memory with {what}", name(k))));
        }
        if let Some(j) = arrays.iter().position(|o: &Bound<'py, PyArrayDyn<f64>>| overlaps(&memory(o))) {
            return Err(PyValueError::new_err(format!("{}: shares memory with {}", name(k), name(j))));
        }
        arrays.push(a.clone());
    }
    Ok(arrays.try_into().unwrap_or_else(|_| unreachable!("R arrays checked above")))
}

/// A short description of a Python object for error messages: its type, and a numpy
/// array's dtype.
fn describe(obj: &Bound<'_, PyAny>) -> String {
    match obj.cast::<numpy::PyUntypedArray>() {
        Ok(a) => format!("an array of dtype {}", a.dtype()),
        Err(_) => obj.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "?".into()),
    }
}

/// The shared body: check the states (and `f_ext`), then run `single` on the model's
/// workspace or `batched` with the GIL released, into `R` outputs of shape `out_shape`
/// (with a leading N for batches): fresh arrays, or the caller's `out` (checked by
/// [`outputs_given`]; reused buffers spare a batch the first-touch page faults of fresh
/// ones, which cost as much as a tenth to a fifth of the time of a large batch).
#[allow(clippy::too_many_arguments)]
fn run<'py, const K: usize, const R: usize>(
    m: &NumericModel,
    py: Python<'py>,
    args: [(&str, &Bound<'py, PyAny>); K],
    f_ext: Option<&Bound<'py, PyAny>>,
    frame: &str,
    out_shape: &[usize],
    threads: Option<i64>,
    out: Option<&Bound<'py, PyAny>>,
    single: impl FnOnce(&Model, &mut Scratch, [&[f64]; K], Ext<'_>, [&mut [f64]; R]),
    batched: impl FnOnce(&Model, [&[f64]; K], Ext<'_>, [&mut [f64]; R], Option<usize>) + Send,
) -> PyResult<[Bound<'py, PyArrayDyn<f64>>; R]> {
    guard(|| {
        m.fixed_base_only()?;
        let threads = thread_arg(threads)?;
        let frame = parse_frame(frame)?;
        let (shape, arrays) = m.joint_states(args)?;
        let ext_arr = f_ext.map(|f| check_f_ext(m, f, shape)).transpose()?;
        // the output shape, with a leading N for a batch (a stack buffer: no allocation per call)
        let mut buf = [0usize; 4];
        let dims: &[usize] = match shape {
            Shape::Single => {
                buf[..out_shape.len()].copy_from_slice(out_shape);
                &buf[..out_shape.len()]
            }
            Shape::Batch(rows) => {
                buf[0] = rows;
                buf[1..=out_shape.len()].copy_from_slice(out_shape);
                &buf[..=out_shape.len()]
            }
        };
        let outs: [Bound<'py, PyArrayDyn<f64>>; R] = match out {
            None => std::array::from_fn(|_| new_array(py, dims)),
            Some(o) => {
                let mut inputs: Vec<(&str, &Bound<'py, PyArrayDyn<f64>>)> =
                    args.iter().map(|(name, _)| *name).zip(arrays.iter()).collect();
                if let Some(e) = ext_arr.as_ref() {
                    inputs.push(("f_ext", e));
                }
                outputs_given(o, dims, &inputs)?
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
                let ext = ext_arr.as_ref().map(|a| (unsafe { slice(a) }, frame));
                m.with_scratch(|s| single(&m.model, s, ins, ext, os));
            }
            Shape::Batch(_) => {
                let readonly: Vec<_> = arrays.iter().map(|a| a.readonly()).collect();
                let ins: [&[f64]; K] = std::array::from_fn(|k| readonly[k].as_slice().expect("contiguous"));
                let ext_ro = ext_arr.as_ref().map(|a| a.readonly());
                let ext = ext_ro.as_ref().map(|a| (a.as_slice().expect("contiguous"), frame));
                let model = &m.model;
                py.detach(|| batched(model, ins, ext, os, threads));
            }
        }
        Ok(outs)
    })
}

fn ext_forces(e: Ext<'_>) -> Option<ExternalForces<'_, f64>> {
    e.map(|(wrenches, frame)| ExternalForces { wrenches, frame })
}

/// Defines `fn $name(py, model, q, threads, out)` returning the (n, n) (or (N, n, n))
/// output of `$algo` / `$batch` on a compiled model; the attributes given first (e.g.
/// `#[pyfunction]`) are passed on.
macro_rules! matrix_of_q {
    ($(#[$attr:meta])* $name:ident, $algo:path, $batch:path $(, floating = $floating:path)? $(, one_dof = $one:literal)?) => {
        $(#[$attr])*
        fn $name<'py>(
            py: Python<'py>,
            model: &Bound<'py, NumericModel>,
            q: &Bound<'py, PyAny>,
            threads: Option<i64>,
            out: Option<&Bound<'py, PyAny>>,
        ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
            let m = model.get();
            $(if $one {
                m.one_dof_only(stringify!($name))?;
            })?
            $(if m.floating {
                return $floating(m, py, q, threads, out);
            })?
            let n = m.model.nv;
            let [o] = run(
                m,
                py,
                [("q", q)],
                None,
                "local",
                &[n, n],
                threads,
                out,
                |md, s, [q], _, [o]| {
                    let (data, deriv) = s.deriv(md);
                    $algo(md, data, deriv, q, o)
                },
                |md, [q], _, [o], t| $batch(md, q, o, t),
            )?;
            Ok(o)
        }
    };
}

/// Defines the entry `#[pyfunction] $name(model, q, qd, $third, f_ext=None,
/// frame="local", threads=None, out=None)` returning the tuple of the three (n, n) (or
/// (N, n, n)) outputs of `$algo` (one state) / `$batch` (a batch) on a compiled model.
/// `armdyn.numeric` documents the entries and decides which robots they run for (a
/// Robot's cached NumericModel; mimic joints and a Robot's f_ext are handled there): its
/// common call, no f_ext, passes every argument by position.
macro_rules! derivatives_entry {
    ($(#[$doc:meta])* $name:ident, $third:ident, $algo:path, $batch:path, floating = $floating:path) => {
        $(#[$doc])*
        #[pyfunction]
        #[pyo3(signature = (model, q, qd, $third, f_ext = None, frame = "local", threads = None, out = None))]
        #[allow(clippy::too_many_arguments)]
        fn $name<'py>(
            py: Python<'py>,
            model: &Bound<'py, NumericModel>,
            q: &Bound<'py, PyAny>,
            qd: &Bound<'py, PyAny>,
            $third: &Bound<'py, PyAny>,
            f_ext: Option<&Bound<'py, PyAny>>,
            frame: &str,
            threads: Option<i64>,
            out: Option<&Bound<'py, PyAny>>,
        ) -> PyResult<Bound<'py, PyTuple>> {
            let m = model.get();
            if m.model.has_multi() {
                let rnea = stringify!($name) == "rnea_derivatives";
                return crate::floating_derivatives::tangent(m, py, rnea, q, qd, $third, f_ext, frame, threads, out);
            }
            if m.floating {
                return $floating(m, py, q, qd, $third, f_ext, frame, threads, out);
            }
            let n = m.model.nv;
            let o = run(
                m,
                py,
                [("q", q), ("qd", qd), (stringify!($third), $third)],
                f_ext,
                frame,
                &[n, n],
                threads,
                out,
                |md, s, [a, b, c], e, [o0, o1, o2]| {
                    let (data, deriv) = s.deriv(md);
                    $algo(md, data, deriv, a, b, c, ext_forces(e).as_ref(), o0, o1, o2)
                },
                |md, a, e, o, t| $batch(md, a, e, o, t),
            )?;
            PyTuple::new(py, o)
        }
    };
}

derivatives_entry!(
    /// ``(dtau_dq, dtau_dqd, M)`` of a NumericModel, each (n, n) or (N, n, n): the entry
    /// of ``armdyn.numeric.rnea_derivatives`` (documented there).
    rnea_derivatives, qdd, algo::rnea_derivatives, bd::rnea_derivatives,
    floating = crate::floating_derivatives::rnea_derivatives
);
derivatives_entry!(
    /// ``(dqdd_dq, dqdd_dqd, Minv)`` of a NumericModel, each (n, n) or (N, n, n): the entry
    /// of ``armdyn.numeric.aba_derivatives`` (documented there).
    aba_derivatives, tau, algo::aba_derivatives, bd::aba_derivatives,
    floating = crate::floating_derivatives::aba_derivatives
);

matrix_of_q!(
    /// M(q)^-1 of a NumericModel, (n, n) or (N, n, n): the entry of
    /// ``armdyn.numeric.minverse`` (documented there).
    #[pyfunction]
    #[pyo3(signature = (model, q, threads = None, out = None))]
    minverse, algo::minverse, bd::minverse, floating = crate::floating_derivatives::minverse
);

matrix_of_q!(
    /// dg/dq, (n, n) or (N, n, n).
    #[pyfunction]
    #[pyo3(signature = (model, q, threads = None, out = None))]
    gravity_derivatives, algo::gravity_derivatives, bd::gravity_derivatives, one_dof = true
);

/// dJ/dt of link `link`'s Jacobian, (6, n) or (N, 6, n).
#[pyfunction]
#[pyo3(signature = (model, q, qd, link, threads = None))]
fn jacobian_dot<'py>(
    py: Python<'py>,
    model: &Bound<'py, NumericModel>,
    q: &Bound<'py, PyAny>,
    qd: &Bound<'py, PyAny>,
    link: &Bound<'py, PyAny>,
    threads: Option<i64>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let m = model.get();
    let index = m.link_arg(link)?;
    if m.floating {
        return m.jacobian_dot_free_root(py, q, qd, index, threads);
    }
    let [o] = run(
        m,
        py,
        [("q", q), ("qd", qd)],
        None,
        "local",
        &[6, m.model.nv],
        threads,
        None,
        |md, s, [q, qd], _, [o]| algo::jacobian_dot(md, &mut s.data, q, qd, index, o),
        |md, [q, qd], _, [o], t| bd::jacobian_dot(md, q, qd, index, o, t),
    )?;
    Ok(o)
}

/// Defines `#[pyfunction] $name(model, q, qd, $third, f_ext, frame="local",
/// threads=None)` returning the (n,) (or (N, n)) output of `$algo` / `$batch`: rnea and
/// aba with external wrenches.
macro_rules! with_wrenches {
    ($(#[$doc:meta])* $name:ident, $third:ident, $algo:path, $batch:path) => {
        $(#[$doc])*
        #[pyfunction]
        #[pyo3(signature = (model, q, qd, $third, f_ext, frame = "local", threads = None))]
        #[allow(clippy::too_many_arguments)]
        fn $name<'py>(
            py: Python<'py>,
            model: &Bound<'py, NumericModel>,
            q: &Bound<'py, PyAny>,
            qd: &Bound<'py, PyAny>,
            $third: &Bound<'py, PyAny>,
            f_ext: &Bound<'py, PyAny>,
            frame: &str,
            threads: Option<i64>,
        ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
            let m = model.get();
            let [o] = run(
                m,
                py,
                [("q", q), ("qd", qd), (stringify!($third), $third)],
                Some(f_ext),
                frame,
                &[m.model.nv],
                threads,
                None,
                |md, s, [a, b, c], e, [o]| {
                    let e = ext_forces(e).expect("f_ext");
                    let (data, deriv) = s.deriv(md);
                    $algo(md, data, deriv, a, b, c, &e, o)
                },
                |md, a, e, [o], t| $batch(md, a, e.expect("f_ext"), o, t),
            )?;
            Ok(o)
        }
    };
}

with_wrenches!(
    /// rnea with external wrenches, (n,) or (N, n).
    rnea_ext, qdd, algo::rnea_ext, bd::rnea_ext
);
with_wrenches!(
    /// aba with external wrenches, (n,) or (N, n).
    aba_ext, tau, algo::aba_ext, bd::aba_ext
);

/// Register the functions above in the `_core` module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(rnea_derivatives, m)?)?;
    m.add_function(wrap_pyfunction!(aba_derivatives, m)?)?;
    m.add_function(wrap_pyfunction!(minverse, m)?)?;
    m.add_function(wrap_pyfunction!(gravity_derivatives, m)?)?;
    m.add_function(wrap_pyfunction!(jacobian_dot, m)?)?;
    m.add_function(wrap_pyfunction!(rnea_ext, m)?)?;
    m.add_function(wrap_pyfunction!(aba_ext, m)?)?;
    Ok(())
}
