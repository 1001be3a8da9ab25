//! The workspaces of single calls: the core's `Data` and derivative scratch per model,
//! and the pool of result arrays nobody holds any more (`OutputPool`).

use crate::args::*;
use armdyn_core::algo::coriolis::CoriolisWork;
use armdyn_core::{Data, Model};
use numpy::{npyffi, PyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;

/// Workspaces for single calls.
pub(crate) struct Scratch {
    pub(crate) data: Data<f64>,
    pub(crate) coriolis: CoriolisWork,
    /// Built on the first derivative call: it holds nv x nv blocks and subtree lists
    /// (O(nv^2) memory), which a 10^4-joint model must not pay for rnea alone.
    pub(crate) deriv_work: Option<armdyn_core::DerivData<f64>>,
    /// Built on the first derivative call of a model with joints of several coordinates.
    pub(crate) multi_work: Option<armdyn_core::algo::multi_derivatives::MultiWork>,
    /// Small single-state results handed out before, for [`Scratch::output`].
    pub(crate) outputs: OutputPool,
}

/// Result arrays of single calls kept for reuse: allocating a NumPy array and freeing it
/// again costs about 45 ns, a fifth of a 6-joint crba. An array is reused only when
/// nothing but this pool refers to it (the caller dropped it) and it is still the plain
/// float64 array it was made as (see [`is_free`]); a caller never sees a result change.
pub(crate) struct OutputPool {
    arrays: [Option<Py<PyArrayDyn<f64>>>; OutputPool::SLOTS],
    next: usize,
}

impl OutputPool {
    /// Enough for a loop that keeps each result until the next call, for two output
    /// shapes (e.g. rnea's (n,) and crba's (n, n)).
    const SLOTS: usize = 4;
    /// Larger results are not kept (the pool holds its arrays while the model lives).
    const MAX_LEN: usize = 4096;
}

/// Whether the pooled array `a` may be written and handed out again as a fresh result of
/// shape `dims`: its only reference is the pool's and no weak reference or view exists,
/// and it is still an exact, writeable, C-contiguous, aligned float64 ndarray owning its
/// data with that shape (a caller could have reshaped it, or made it read-only, before
/// dropping it).
pub(crate) fn is_free(py: Python<'_>, a: &Bound<'_, PyArrayDyn<f64>>, dims: &[usize]) -> bool {
    let (array_type, f64_descr) = ndarray_and_f64(py);
    let p = a.as_ptr();
    // SAFETY: `p` is a live ndarray (the pool's reference), read with the GIL held.
    unsafe {
        if pyo3::ffi::Py_REFCNT(p) != 1 || pyo3::ffi::Py_TYPE(p) != array_type {
            return false;
        }
        let f = &(*(p as *const npyffi::PyArrayObject)).fields;
        let wanted = npyffi::NPY_ARRAY_C_CONTIGUOUS
            | npyffi::NPY_ARRAY_ALIGNED
            | npyffi::NPY_ARRAY_WRITEABLE
            | npyffi::NPY_ARRAY_OWNDATA;
        f.weakreflist.is_null()
            && f.base.is_null()
            && f.descr == f64_descr
            && f.flags & wanted == wanted
            && f.nd as usize == dims.len()
            && dims.iter().enumerate().all(|(k, &d)| *f.dimensions.add(k) == d as npyffi::npy_intp)
    }
}

impl Scratch {
    pub(crate) fn new(model: &Model) -> Self {
        Scratch {
            data: Data::new(model),
            coriolis: CoriolisWork::new(model),
            deriv_work: None,
            multi_work: None,
            outputs: OutputPool { arrays: Default::default(), next: 0 },
        }
    }

    /// An array of shape `dims` for a single call's result, every element to be written
    /// by the caller: a pooled one nobody holds any more, else a fresh one (pooled when
    /// small).
    pub(crate) fn output<'py>(&mut self, py: Python<'py>, dims: &[usize]) -> Bound<'py, PyArrayDyn<f64>> {
        let pool = &mut self.outputs;
        if let Some(a) = pool.arrays.iter().flatten().map(|a| a.bind(py)).find(|a| is_free(py, a, dims)) {
            return a.clone();
        }
        let fresh = new_array(py, dims);
        if fresh.len() <= OutputPool::MAX_LEN {
            pool.arrays[pool.next] = Some(fresh.clone().unbind());
            pool.next = (pool.next + 1) % OutputPool::SLOTS;
        }
        fresh
    }

    /// The derivative workspace and `data`, the workspace built on first use.
    pub(crate) fn deriv(&mut self, model: &Model) -> (&mut Data<f64>, &mut armdyn_core::DerivData<f64>) {
        let deriv = self.deriv_work.get_or_insert_with(|| armdyn_core::DerivData::new(model));
        (&mut self.data, deriv)
    }
}
