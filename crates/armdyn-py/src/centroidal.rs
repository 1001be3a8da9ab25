//! Bindings of the centroidal quantities (`armdyn_core::algo::centroidal`): module-level
//! functions taking the NumericModel first (called by `python/armdyn/centroidal.py`, which
//! documents them), for a floating base (Pinocchio's arrays, the quaternion checked as in
//! `floating.rs`) or a fixed one; and the methods `forward_kinematics`, `jacobian`,
//! `kinetic_energy` and `potential_energy` of a floating model dispatch to the world-frame
//! ones here (`algo::floating_kinematics`). One state or a batch `(N, ...)`, as everywhere.

use crate::floating::finite;
use crate::{scalar_if_0d, NumericModel};
use armdyn_core::algo::centroidal;
use armdyn_core::algo::floating_kinematics as fk;
use armdyn_core::batch_centroidal::rows;
use armdyn_core::{Data, Model};
use numpy::PyArrayDyn;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

type Out<'py> = PyResult<Bound<'py, PyArrayDyn<f64>>>;

impl NumericModel {
    /// `(nq, nv)`: the lengths of q and v.
    pub(crate) fn widths(&self) -> (usize, usize) {
        let (qb, vb) = fk::base_widths(self.floating);
        (self.model.nq + qb, self.model.nv + vb)
    }

    /// `Err(ValueError)` when no body that moves has mass (the centre of mass is undefined).
    fn require_mass(&self, what: &str) -> PyResult<()> {
        let m = &self.model;
        let mass: f64 = m.inertia.iter().map(|i| i.m).sum::<f64>() + if self.floating { m.base_inertia.m } else { 0.0 };
        if mass > 0.0 {
            return Ok(());
        }
        Err(PyValueError::new_err(format!(
            "{what}: '{}' has no mass{}, so no centre of mass",
            self.name,
            if self.floating {
                ""
            } else {
                " in its moving links (a fixed base and the links welded to it do not count)"
            }
        )))
    }

    /// `f(model, data, row args, row out)` on one state or each state of a batch (the
    /// arguments `(name, object, width)` checked as `floating_op` checks them), into a
    /// fresh array of shape `out_shape` per state; a result not finite is an error.
    fn world_op<'py, const K: usize>(
        &self,
        py: Python<'py>,
        args: [(&str, &Bound<'py, PyAny>, usize); K],
        out_shape: &[usize],
        threads: Option<i64>,
        f: impl Fn(&Model, &mut Data<f64>, [&[f64]; K], &mut [f64]) + Sync + Send + Copy,
    ) -> Out<'py> {
        let widths = args.map(|(_, _, w)| w);
        let per_row = out_shape.iter().product::<usize>();
        let out = self.floating_op(
            py,
            args,
            out_shape,
            threads,
            |d, ins, o| f(&self.model, d, ins, o),
            move |m, ins, o, t| rows(m, ins, widths, o, per_row, t, move |d, a, o| f(m, d, a, o)),
        )?;
        finite(out)
    }
}

/// Centre of mass (3,) or (N, 3), world frame.
#[pyfunction]
#[pyo3(signature = (model, q, threads = None))]
fn center_of_mass<'py>(py: Python<'py>, model: &NumericModel, q: &Bound<'py, PyAny>, threads: Option<i64>) -> Out<'py> {
    model.require_mass("center_of_mass")?;
    let (nq, fl) = (model.widths().0, model.floating);
    model.world_op(py, [("q", q, nq)], &[3], threads, move |m, d, [q], o| {
        centroidal::center_of_mass(m, d, q, fl, o);
    })
}

/// Jacobian of the centre of mass (3, nv) or (N, 3, nv), world axes.
#[pyfunction]
#[pyo3(signature = (model, q, threads = None))]
fn com_jacobian<'py>(py: Python<'py>, model: &NumericModel, q: &Bound<'py, PyAny>, threads: Option<i64>) -> Out<'py> {
    model.require_mass("com_jacobian")?;
    let ((nq, nv), fl) = (model.widths(), model.floating);
    model.world_op(py, [("q", q, nq)], &[3, nv], threads, move |m, d, [q], o| {
        centroidal::com_jacobian(m, d, q, fl, o);
    })
}

/// Centroidal momentum matrix A_G (6, nv) or (N, 6, nv).
#[pyfunction]
#[pyo3(signature = (model, q, threads = None))]
fn centroidal_map<'py>(py: Python<'py>, model: &NumericModel, q: &Bound<'py, PyAny>, threads: Option<i64>) -> Out<'py> {
    model.require_mass("centroidal_momentum_matrix")?;
    let ((nq, nv), fl) = (model.widths(), model.floating);
    model.world_op(py, [("q", q, nq)], &[6, nv], threads, move |m, d, [q], o| {
        centroidal::centroidal_map(m, d, q, fl, o);
    })
}

/// Time derivative of the centroidal momentum matrix (6, nv) or (N, 6, nv).
#[pyfunction]
#[pyo3(signature = (model, q, v, threads = None))]
fn centroidal_map_rate<'py>(
    py: Python<'py>,
    model: &NumericModel,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    threads: Option<i64>,
) -> Out<'py> {
    model.require_mass("centroidal_momentum_matrix_rate")?;
    let ((nq, nv), fl) = (model.widths(), model.floating);
    model.world_op(py, [("q", q, nq), ("v", v, nv)], &[6, nv], threads, move |m, d, [q, v], o| {
        centroidal::centroidal_map_rate(m, d, q, v, fl, o);
    })
}

/// Centroidal momentum h_G (6,) or (N, 6).
#[pyfunction]
#[pyo3(signature = (model, q, v, threads = None))]
fn centroidal_momentum<'py>(
    py: Python<'py>,
    model: &NumericModel,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    threads: Option<i64>,
) -> Out<'py> {
    model.require_mass("centroidal_momentum")?;
    let ((nq, nv), fl) = (model.widths(), model.floating);
    model.world_op(py, [("q", q, nq), ("v", v, nv)], &[6], threads, move |m, d, [q, v], o| {
        centroidal::centroidal_momentum(m, d, q, v, fl, o);
    })
}

/// Rate of change of the centroidal momentum (6,) or (N, 6).
#[pyfunction]
#[pyo3(signature = (model, q, v, a, threads = None))]
fn centroidal_momentum_rate<'py>(
    py: Python<'py>,
    model: &NumericModel,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    a: &Bound<'py, PyAny>,
    threads: Option<i64>,
) -> Out<'py> {
    model.require_mass("centroidal_momentum_rate")?;
    let ((nq, nv), fl) = (model.widths(), model.floating);
    let args = [("q", q, nq), ("v", v, nv), ("a", a, nv)];
    model.world_op(py, args, &[6], threads, move |m, d, [q, v, a], o| {
        centroidal::centroidal_momentum_rate(m, d, q, v, a, fl, o);
    })
}

impl NumericModel {
    /// Poses of all link frames in the world frame (nlinks, 4, 4) or (N, nlinks, 4, 4):
    /// `forward_kinematics` of a floating model.
    pub(crate) fn forward_kinematics_floating<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> Out<'py> {
        let shape = [self.model.nlinks(), 4, 4];
        self.world_op(py, [("q", q, self.widths().0)], &shape, threads, |m, d, [q], o| {
            fk::forward_kinematics_world(m, d, q, true, o)
        })
    }

    /// Jacobian (6, nv) or (N, 6, nv) of link `index`, world axes: `jacobian` of a
    /// floating model.
    pub(crate) fn jacobian_floating<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        index: usize,
        threads: Option<i64>,
    ) -> Out<'py> {
        let (nq, nv) = self.widths();
        self.world_op(py, [("q", q, nq)], &[6, nv], threads, move |m, d, [q], o| {
            fk::jacobian_world(m, d, q, true, index, o)
        })
    }

    /// Kinetic energy 1/2 v^T M v, a float or (N,): `kinetic_energy` of a floating model.
    pub(crate) fn kinetic_energy_floating<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (nq, nv) = self.widths();
        let out = self.world_op(py, [("q", q, nq), ("qd", v, nv)], &[], threads, |m, d, [q, v], o| {
            o[0] = fk::kinetic_energy_world(m, d, q, v, true)
        })?;
        scalar_if_0d(out)
    }

    /// Potential energy, a float or (N,): `potential_energy` of a floating model.
    pub(crate) fn potential_energy_floating<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let out = self.world_op(py, [("q", q, self.widths().0)], &[], threads, |m, d, [q], o| {
            o[0] = fk::potential_energy_floating(m, d, q)
        })?;
        scalar_if_0d(out)
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(center_of_mass, m)?)?;
    m.add_function(wrap_pyfunction!(com_jacobian, m)?)?;
    m.add_function(wrap_pyfunction!(centroidal_map, m)?)?;
    m.add_function(wrap_pyfunction!(centroidal_momentum, m)?)?;
    m.add_function(wrap_pyfunction!(centroidal_momentum_rate, m)?)?;
    m.add_function(wrap_pyfunction!(centroidal_map_rate, m)?)?;
    Ok(())
}
