//! armdyn-core: rigid-body dynamics of robot arms in Featherstone's spatial algebra.
//!
//! * [`Model`] — immutable, built once from a description ([`JointSpec`]s in tree
//!   order), shareable across threads. Fixed joints are merged into their movable
//!   ancestor's body; their frames are kept for kinematics.
//! * [`Data`] — a per-thread workspace, allocated once per model; the algorithms
//!   allocate nothing.
//! * [`algo`] — one algorithm per file: `rnea`, `crba`, `aba`, `gravity`, `bias`,
//!   `coriolis_matrix`, energies, `jacobian`, `forward_kinematics`; `floating`: the
//!   RNEA, CRBA and ABA with a floating base (Pinocchio's free-flyer arrays);
//!   `floating_kinematics` and `centroidal`: world-frame poses, Jacobians, energies,
//!   centre of mass and centroidal momentum, for a floating base or a fixed one.
//! * [`batch`] — many states (rows of `(N, n)` arrays), rayon over chunks of rows,
//!   4 or 8 states per SIMD step for `rnea`, `aba`, `crba`, `gravity`, `bias`;
//!   [`batch_centroidal`] for the world-frame and centroidal quantities.
//!
//! Conventions: SI units; `M(q) qdd + C(q, qd) qd + g(q) = tau`; spatial vectors
//! `[angular; linear]`; matrices row-major.

// Index loops over bodies read like the book's `for i = 1 to N_B`.
#![allow(clippy::needless_range_loop)]

pub mod algo;
pub mod batch;
pub mod batch_centroidal;
pub mod batch_derivatives;
pub mod data;
pub mod deriv_data;
pub mod dual;
pub mod joint;
pub mod joint_multi;
pub mod model;
pub mod real;
pub mod spatial;

pub use data::Data;
pub use deriv_data::DerivData;
pub use model::{JointDynamics, JointSpec, JointType, Model, ModelError};
pub use real::{F64x4, F64x8, Real};
