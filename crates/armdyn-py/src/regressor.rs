//! `armdyn._core.regressor`: the joint torque regressor of a NumericModel (see
//! armdyn-core's `algo::regressor` for the columns; `armdyn.numeric.regressor` is the
//! user-facing API).

use crate::NumericModel;
use armdyn_core::{algo, batch};
use numpy::PyArrayDyn;
use pyo3::prelude::*;

/// Y (n, P) for one state, (N, n, P) for a batch, `P = 10 (nlinks - 1) + 4 n`:
/// per link `[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]` (about the link frame's
/// origin), then per movable joint `[qdd, qd, sign(qd), 1]`.
#[pyfunction]
#[pyo3(signature = (model, q, qd, qdd, threads = None))]
pub fn regressor<'py>(
    py: Python<'py>,
    model: &NumericModel,
    q: &Bound<'py, PyAny>,
    qd: &Bound<'py, PyAny>,
    qdd: &Bound<'py, PyAny>,
    threads: Option<i64>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if model.floating {
        return model.regressor_free_root(py, q, qd, qdd, threads);
    }
    let n = model.model.nv;
    let cols = algo::regressor_columns(&model.model);
    model.vector_op(
        py,
        [("q", q), ("qd", qd), ("qdd", qdd)],
        &[n, cols],
        threads,
        |m, s, [q, qd, qdd], o| algo::regressor(m, &mut s.data, q, qd, qdd, o),
        batch::regressor,
    )
}

/// The number of regressor columns of `model`.
#[pyfunction]
pub fn regressor_columns(model: &NumericModel) -> usize {
    let dropped = if model.floating { crate::free_root::ROOT_JOINT_COLUMNS } else { 0 };
    algo::regressor_columns(model.whole()) - dropped
}
