//! The algorithms, one per file. Each takes the model, a workspace and the state,
//! and writes into caller-provided output slices (no allocation).
//!
//! Conventions: `q`, `qd`, `qdd`, `tau` have length `model.nv` (movable joints in
//! tree order); matrices are row-major; spatial vectors `[angular; linear]` inside.

pub mod aba;
pub mod coriolis;
pub mod crba;
pub mod energy;
pub mod jacobian;
pub mod kinematics;
pub mod regressor;
pub mod rnea;

pub use aba::aba;
pub use coriolis::coriolis_matrix;
pub use crba::crba;
pub use energy::{kinetic_energy, potential_energy};
pub use jacobian::jacobian;
pub use kinematics::forward_kinematics;
pub use regressor::{regressor, regressor_columns};
pub use rnea::{bias, gravity, rnea};
