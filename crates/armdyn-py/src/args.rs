//! The arguments of the bindings: arrays converted (or read in place) and checked, the
//! threads argument, fresh result arrays. Every method of `NumericModel` reads its
//! arrays through these, so shapes, NaN/inf and dtypes are refused in one way.

use armdyn_core::batch;
use numpy::{npyffi, Element, PyArray, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use std::sync::OnceLock;

/// Whether the array's data can be used as a `&[f64]` in place: C-contiguous and 8-byte
/// aligned (arrays received over a network can be C-contiguous but unaligned).
pub(crate) fn is_c_contiguous_aligned(a: &Bound<'_, PyArrayDyn<f64>>) -> bool {
    a.is_c_contiguous() && (a.data() as usize) % std::mem::align_of::<f64>() == 0
}

/// `obj` as a C-contiguous float64 array: as is when it already is one (no copy),
/// else converted once by `numpy.ascontiguousarray(obj, dtype=float64)`.
///
/// Only real numbers are converted: arrays of floats or integers, or object arrays
/// whose every element is a `numbers.Real` other than `bool`. Complex, boolean,
/// string, bytes, datetime and structured arrays are refused with a `ValueError`
/// naming the argument (NumPy would silently drop an imaginary part, read `True` as
/// 1.0 and parse `"1.5"`).
pub(crate) fn as_f64<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if let Ok(a) = obj.cast::<PyArrayDyn<f64>>() {
        // (aligned too: arrays received over a network, e.g. Dask results, can be
        // C-contiguous but not 8-byte aligned, and rust-numpy then gives no slice)
        if is_c_contiguous_aligned(&a) {
            return Ok(a.clone());
        }
        // an unaligned one: ascontiguousarray would return it as is, so copy it
        if a.is_c_contiguous() {
            let copy = a.call_method0("copy")?;
            return Ok(copy.cast_into::<PyArrayDyn<f64>>()?);
        }
    }
    static ASCONTIGUOUS: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    static ASARRAY: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    static REAL: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    let py = obj.py();
    let unreadable = |e: PyErr| PyValueError::new_err(format!("{name}: cannot be read as a float64 array ({e})"));
    let arr = ASARRAY.import(py, "numpy", "asarray")?.call1((obj,)).map_err(unreadable)?;
    let dtype = arr.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    let refuse = |what: String| Err(PyValueError::new_err(format!("{name}: expected real numbers, got {what}")));
    match kind.as_str() {
        "f" | "i" | "u" => {}
        "O" => {
            let real = REAL.import(py, "numbers", "Real")?;
            for x in arr.call_method0("ravel")?.try_iter()? {
                let x = x?;
                if x.is_instance_of::<pyo3::types::PyBool>() || !x.is_instance(real)? {
                    return refuse(format!("an element of type {}", x.get_type().name()?));
                }
            }
        }
        _ => return refuse(format!("an array of dtype {}", dtype.str()?)),
    }
    let conv = ASCONTIGUOUS.import(py, "numpy", "ascontiguousarray")?;
    let float64 = py.import("numpy")?.getattr("float64")?;
    let converted = conv.call1((arr, float64)).map_err(unreadable)?;
    Ok(converted.cast_into::<PyArrayDyn<f64>>()?)
}

/// The data of a C-contiguous array.
///
/// SAFETY (callers): the array is not written while the slice lives. Our inputs are
/// only read, and our outputs are fresh arrays nobody else has seen; Python code could
/// only write them concurrently if the user does so from another thread during a
/// batch (with the GIL released), as with NumPy's own GIL-free functions.
pub(crate) unsafe fn slice<'a>(a: &'a Bound<'_, PyArrayDyn<f64>>) -> &'a [f64] {
    unsafe { a.as_slice().expect("C-contiguous") }
}

/// The ndarray type and the native float64 descriptor, read once: what a single state
/// usually is, recognised by two pointer comparisons.
pub(crate) fn ndarray_and_f64(py: Python<'_>) -> (*mut pyo3::ffi::PyTypeObject, *mut npyffi::PyArray_Descr) {
    static POINTERS: OnceLock<(usize, usize)> = OnceLock::new();
    let &(array_type, f64_descr) = POINTERS.get_or_init(|| {
        // SAFETY: NumPy's C API, loaded by rust-numpy on first use, with the GIL held.
        let array_type = unsafe { npyffi::get_type_object(py, npyffi::NpyTypes::PyArray_Type) } as usize;
        // the builtin descriptor is a singleton NumPy keeps for its lifetime (`get_dtype`
        // holds a reference only for this call)
        (array_type, f64::get_dtype(py).as_dtype_ptr() as usize)
    });
    (array_type as *mut _, f64_descr as *mut _)
}

/// The values of `obj` in place when it is the plain case of one state: exactly a
/// `numpy.ndarray` (no subclass) of native float64, C-contiguous and aligned, of shape
/// `(n,)`, every value finite. None for anything else, which the general path
/// ([`states`]) converts or refuses with a message naming what is wrong.
///
/// SAFETY (callers): the GIL is held and the array is not written while the slice lives.
pub(crate) unsafe fn plain_state<'a>(py: Python<'_>, obj: &'a Bound<'_, PyAny>, n: usize) -> Option<&'a [f64]> {
    let (array_type, f64_descr) = ndarray_and_f64(py);
    let p = obj.as_ptr();
    unsafe {
        if pyo3::ffi::Py_TYPE(p) != array_type {
            return None;
        }
        let a = &(*(p as *const npyffi::PyArrayObject)).fields;
        let wanted = npyffi::NPY_ARRAY_C_CONTIGUOUS | npyffi::NPY_ARRAY_ALIGNED;
        if a.nd != 1 || *a.dimensions != n as npyffi::npy_intp || a.descr != f64_descr || a.flags & wanted != wanted {
            return None;
        }
        let values = std::slice::from_raw_parts(a.data as *const f64, n);
        all_finite(values).then_some(values)
    }
}

/// [`plain_state`] for every argument, or None if any is not plain.
///
/// SAFETY: as [`plain_state`].
pub(crate) unsafe fn plain_states<'a, 'py, const K: usize>(
    py: Python<'py>,
    n: usize,
    args: &'a [(&str, &Bound<'py, PyAny>); K],
) -> Option<[&'a [f64]; K]> {
    let mut out: [&[f64]; K] = [&[]; K];
    for (slot, (_, obj)) in out.iter_mut().zip(args) {
        *slot = unsafe { plain_state(py, obj, n) }?;
    }
    Some(out)
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Shape {
    /// One state, `(n,)`.
    Single,
    /// `N` states, `(N, n)`.
    Batch(usize),
}

/// Convert and check state arguments `(name, object)`: each `(n,)` or `(N, n)`, all of
/// the same shape, finite.
pub(crate) fn states<'py, const K: usize>(
    n: usize,
    args: [(&str, &Bound<'py, PyAny>); K],
) -> PyResult<(Shape, [Bound<'py, PyArrayDyn<f64>>; K])> {
    // (no Vec: a single-state call is timed per call, and an allocation shows)
    let mut converted = args.map(|(name, obj)| as_f64(obj, name));
    if let Some(k) = converted.iter().position(|r| r.is_err()) {
        return Err(std::mem::replace(&mut converted[k], Err(PyRuntimeError::new_err(""))).err().expect("an error"));
    }
    let arrays: [Bound<'py, PyArrayDyn<f64>>; K] = converted.map(|r| r.expect("checked above"));
    let mut shape = None;
    for ((name, _), a) in args.iter().zip(&arrays) {
        let s = match a.shape() {
            [m] if *m == n => Shape::Single,
            [rows, m] if *m == n => Shape::Batch(*rows),
            other => {
                return Err(PyValueError::new_err(format!(
                    "{name}: expected shape ({n},) for one state or (N, {n}) for a batch, got {other:?}"
                )))
            }
        };
        match shape {
            None => shape = Some(s),
            Some(s0) if s0 != s => {
                return Err(PyValueError::new_err(format!(
                    "{name}: shape {:?} does not match {}'s {:?}",
                    a.shape(),
                    args[0].0,
                    arrays[0].shape()
                )))
            }
            _ => {}
        }
        // SAFETY: read-only, GIL held.
        let values = unsafe { slice(a) };
        if !all_finite(values) {
            let k = values.iter().position(|x| !x.is_finite()).unwrap_or(0);
            let at = match s {
                Shape::Single => format!("[{k}]"),
                Shape::Batch(_) => format!("[{}, {}]", k / n.max(1), k % n.max(1)),
            };
            return Err(PyValueError::new_err(format!("{name} contains NaN or inf (at {name}{at})")));
        }
    }
    Ok((shape.expect("at least one argument"), arrays))
}

/// Whether no element is NaN or inf: `x - x` is 0 for finite `x` and NaN otherwise;
/// eight independent sums let the loop vectorise (no early exit).
#[allow(clippy::eq_op)]
pub(crate) fn all_finite(values: &[f64]) -> bool {
    let mut acc = [0.0f64; 8];
    let chunks = values.chunks_exact(8);
    let rest = chunks.remainder();
    for c in chunks {
        for k in 0..8 {
            acc[k] += c[k] - c[k];
        }
    }
    acc.iter().chain(rest).all(|x| (x - x) == 0.0)
}

/// A fresh uninitialised float64 array of shape `dims`.
pub(crate) fn new_array<'py>(py: Python<'py>, dims: &[usize]) -> Bound<'py, PyArrayDyn<f64>> {
    // SAFETY: every element is written before the array is returned to Python.
    unsafe { PyArray::<f64, _>::new(py, dims, false) }
}

/// `threads` as given from Python: None (all cores) or a count in `1..=MAX_THREADS`.
pub(crate) fn thread_arg(threads: Option<i64>) -> PyResult<Option<usize>> {
    match threads {
        None => Ok(None),
        Some(k) if k >= 1 && k as u64 <= batch::MAX_THREADS as u64 => Ok(Some(k as usize)),
        Some(k) => Err(PyValueError::new_err(format!(
            "threads must be None or an integer from 1 to {}, got {k}",
            batch::MAX_THREADS
        ))),
    }
}
