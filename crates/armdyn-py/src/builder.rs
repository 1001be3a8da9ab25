//! `armdyn._core.ModelBuilder`: a robot's numeric model built joint by joint, as
//! Pinocchio's `addJoint` / `appendBodyToJoint`, then compiled into a [`NumericModel`].
//!
//! ```python
//! b = ModelBuilder("arm", gravity=[0, 0, -9.81], base="base")
//! k = b.add_joint("shoulder", parent="base", child="upper", kind="revolute",
//!                 rotation=R, xyz=p, axis=[0, 0, 1])
//! b.append_body(k, mass=2.0, com=[0, 0, 0.1], inertia=I)
//! model = b.build()
//! ```
//!
//! Every argument is checked where it is given, naming the joint: a parent link not yet
//! added, a duplicate link, a wrong number of coordinate names, a second body on a
//! joint. The numbers themselves are checked by the core's `Model::new` at `build`, which
//! names the joint too. A builder pickles as the calls that made it (a model on a Dask
//! worker is rebuilt from them).

use crate::free_root::free_rooted;
use crate::{guard, inert_bodies, NumericModel, Scratch};
use armdyn_core::{JointDynamics, JointSpec, JointType, Model};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use std::collections::HashMap;
use std::sync::Mutex;

type M3 = [[f64; 3]; 3];
type V3 = [f64; 3];

/// A body: mass, centre of mass (3, link frame) and inertia about it (3x3, link axes).
type Body = (f64, V3, M3);

/// One `add_joint` call, with the body appended to it.
#[derive(Clone, Debug)]
struct JointRecord {
    name: String,
    parent: String,
    child: String,
    kind: String,
    rotation: M3,
    xyz: V3,
    axis: V3,
    coordinates: Vec<String>,
    /// `[armature, viscous, coulomb, offset]` on each of the joint's velocity coordinates.
    dynamics: Option<[f64; 4]>,
    body: Option<Body>,
}

/// The joint kinds, by the names `armdyn.model` gives them (`model/joints.py`).
fn joint_type(kind: &str) -> Option<JointType> {
    Some(match kind {
        "revolute" | "continuous" => JointType::Revolute,
        "prismatic" => JointType::Prismatic,
        "fixed" => JointType::Fixed,
        "spherical" => JointType::Spherical,
        "planar" => JointType::Planar,
        "floating" => JointType::Free,
        _ => return None,
    })
}

/// Builds a [`NumericModel`] joint by joint (module docs).
#[pyclass(name = "ModelBuilder", module = "armdyn._core")]
#[derive(Clone, Debug)]
pub struct ModelBuilder {
    name: String,
    gravity: V3,
    base: String,
    floating: bool,
    base_body: Option<Body>,
    joints: Vec<JointRecord>,
}

impl ModelBuilder {
    fn error(&self, joint: &str, message: String) -> PyErr {
        PyValueError::new_err(format!("robot '{}', joint '{joint}': {message}", self.name))
    }

    fn has_link(&self, link: &str) -> bool {
        link == self.base || self.joints.iter().any(|j| j.child == link)
    }
}

#[pymethods]
impl ModelBuilder {
    /// A robot `name` with gravity (3, base frame) whose base link is `base`; `floating`:
    /// the base is a free body (Pinocchio's free-flyer root joint).
    #[new]
    #[pyo3(signature = (name, gravity, base, floating = false))]
    fn new(name: String, gravity: V3, base: String, floating: bool) -> Self {
        ModelBuilder { name, gravity, base, floating, base_body: None, joints: vec![] }
    }

    /// The base link's body: mass, centre of mass (3) and inertia about it (3x3), base
    /// frame. A fixed base only counts its potential energy (a constant).
    #[pyo3(signature = (mass, com, inertia))]
    fn set_base_body(&mut self, mass: f64, com: V3, inertia: M3) {
        self.base_body = Some((mass, com, inertia));
    }

    /// Add joint `name` from link `parent` (the base or an earlier joint's child) to the
    /// new link `child`: its placement `rotation` (3x3, axes as columns) and `xyz` (3) in
    /// the parent link's frame, its `kind` (revolute, continuous, prismatic, fixed,
    /// spherical, planar, floating), its unit `axis` (3, placement frame; 1-dof joints),
    /// the names of its velocity coordinates, and `dynamics` = `[armature, viscous,
    /// coulomb, offset]` acting on each of them. Returns the joint's index.
    #[pyo3(signature = (name, parent, child, kind, rotation, xyz, axis, coordinates, dynamics = None))]
    #[allow(clippy::too_many_arguments)]
    fn add_joint(
        &mut self,
        name: String,
        parent: String,
        child: String,
        kind: String,
        rotation: M3,
        xyz: V3,
        axis: V3,
        coordinates: Vec<String>,
        dynamics: Option<[f64; 4]>,
    ) -> PyResult<usize> {
        let Some(t) = joint_type(&kind) else {
            return Err(self.error(&name, format!("unknown kind '{kind}'")));
        };
        if !self.has_link(&parent) {
            return Err(
                self.error(&name, format!("parent link '{parent}' is not the base nor an earlier joint's child"))
            );
        }
        if self.has_link(&child) {
            return Err(self.error(&name, format!("child link '{child}' is already in the model")));
        }
        let nv = t.nv();
        if coordinates.len() != nv {
            return Err(
                self.error(&name, format!("a {kind} joint has {nv} coordinates, {} names given", coordinates.len()))
            );
        }
        self.joints.push(JointRecord {
            name,
            parent,
            child,
            kind,
            rotation,
            xyz,
            axis,
            coordinates,
            dynamics,
            body: None,
        });
        Ok(self.joints.len() - 1)
    }

    /// Give joint `joint`'s child link its body: mass, centre of mass (3) and inertia
    /// about it (3x3), in the link's frame. A link without one is massless.
    #[pyo3(signature = (joint, mass, com, inertia))]
    fn append_body(&mut self, joint: usize, mass: f64, com: V3, inertia: M3) -> PyResult<()> {
        let Some(record) = self.joints.get(joint) else {
            return Err(PyValueError::new_err(format!("robot '{}': no joint {joint}", self.name)));
        };
        if record.body.is_some() {
            return Err(self.error(&record.name.clone(), "its child link already has a body".into()));
        }
        self.joints[joint].body = Some((mass, com, inertia));
        Ok(())
    }

    /// The compiled model.
    fn build(&self) -> PyResult<NumericModel> {
        guard(|| self.compile())
    }

    /// Pickling replays the calls (`_from_calls`).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let b = slf.borrow();
        let joints: Vec<_> = b
            .joints
            .iter()
            .map(|j| {
                let call = (&j.name, &j.parent, &j.child, &j.kind, j.rotation, j.xyz, j.axis, &j.coordinates);
                (call, j.dynamics, j.body)
            })
            .collect();
        let args = (&b.name, b.gravity, &b.base, b.floating, b.base_body, joints).into_pyobject(py)?;
        Ok((slf.get_type().getattr("_from_calls")?, args))
    }

    /// The builder made by these calls (what `__reduce__` gives).
    #[staticmethod]
    #[allow(clippy::type_complexity)]
    fn _from_calls(
        name: String,
        gravity: V3,
        base: String,
        floating: bool,
        base_body: Option<Body>,
        joints: Vec<((String, String, String, String, M3, V3, V3, Vec<String>), Option<[f64; 4]>, Option<Body>)>,
    ) -> PyResult<Self> {
        let mut b = ModelBuilder::new(name, gravity, base, floating);
        b.base_body = base_body;
        for ((name, parent, child, kind, rotation, xyz, axis, coordinates), dynamics, body) in joints {
            let k = b.add_joint(name, parent, child, kind, rotation, xyz, axis, coordinates, dynamics)?;
            if let Some((mass, com, inertia)) = body {
                b.append_body(k, mass, com, inertia)?;
            }
        }
        Ok(b)
    }
}

impl ModelBuilder {
    fn compile(&self) -> PyResult<NumericModel> {
        let child_index: HashMap<&str, usize> =
            self.joints.iter().enumerate().map(|(k, j)| (j.child.as_str(), k)).collect();
        let joints: Vec<JointSpec> = self
            .joints
            .iter()
            .map(|j| {
                let (mass, com, inertia) = j.body.unwrap_or((0.0, [0.0; 3], [[0.0; 3]; 3]));
                JointSpec {
                    parent: child_index.get(j.parent.as_str()).copied(),
                    jtype: joint_type(&j.kind).expect("checked by add_joint"),
                    rotation: j.rotation,
                    translation: j.xyz,
                    axis: j.axis,
                    mass,
                    com,
                    inertia,
                }
            })
            .collect();
        let named = |k: Option<usize>, message: &str| match k {
            Some(k) => {
                let j = &self.joints[k];
                PyValueError::new_err(format!(
                    "robot '{}', joint '{}' (link '{}'): {message}",
                    self.name, j.name, j.child
                ))
            }
            None => PyValueError::new_err(format!("robot '{}': {message}", self.name)),
        };
        let mut model = Model::new(&joints, self.gravity).map_err(|e| named(e.joint, &e.message))?;
        let (base_mass, base_com, base_inertia) = self.base_body.unwrap_or((0.0, [0.0; 3], [[0.0; 3]; 3]));
        if self.floating {
            model
                .add_base_inertia(base_mass, base_com, base_inertia)
                .map_err(|e| PyValueError::new_err(format!("link '{}': {}", self.base, e.message)))?;
        } else {
            if !(base_mass.is_finite() && base_com.iter().all(|x| x.is_finite())) {
                return Err(PyValueError::new_err(format!("link '{}': mass or com is not finite", self.base)));
            }
            model.add_base_mass(base_mass, base_com);
        }
        // each joint's friction and rotor inertia on each of its bodies (one per coordinate)
        let mut body = 0;
        for (k, j) in self.joints.iter().enumerate() {
            let n = j.coordinates.len();
            if let Some([armature, viscous, coulomb, offset]) = j.dynamics {
                for b in body..body + n {
                    model
                        .set_joint_dynamics(b, JointDynamics { armature, viscous, coulomb, offset })
                        .map_err(|e| named(Some(k), &e.message))?;
                }
            }
            body += n;
        }
        let free_root = match self.floating {
            true => Some(
                free_rooted(&joints, self.gravity, (base_mass, base_com, base_inertia), &model.joint_dynamics)
                    .map_err(|e| named(None, &format!("the free-rooted model: {e}")))?,
            ),
            false => None,
        };
        let link_names: Vec<String> =
            std::iter::once(self.base.clone()).chain(self.joints.iter().map(|j| j.child.clone())).collect();
        let coordinate_names: Vec<String> = self.joints.iter().flat_map(|j| j.coordinates.clone()).collect();
        let inert_joints = inert_bodies(&model).into_iter().map(|i| coordinate_names[i].clone()).collect();
        Ok(NumericModel {
            scratch: Mutex::new(Scratch::new(&model)),
            link_index: link_names.iter().enumerate().map(|(k, s)| (s.clone(), k)).collect(),
            model,
            name: self.name.clone(),
            link_names,
            coordinate_names,
            builder: self.clone(),
            inert_joints,
            floating: self.floating,
            free_root,
        })
    }
}

/// `builder.build()`, for unpickling a [`NumericModel`].
#[pyfunction]
pub(crate) fn _build(builder: &ModelBuilder) -> PyResult<NumericModel> {
    builder.build()
}
