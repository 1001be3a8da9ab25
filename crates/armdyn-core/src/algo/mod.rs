//! The algorithms, one per file. Each takes the model, a workspace and the state,
//! and writes into caller-provided output slices (no allocation).
//!
//! Conventions: `q`, `qd`, `qdd`, `tau` have length `model.nv` (movable joints in
//! tree order); matrices are row-major; spatial vectors `[angular; linear]` inside.

pub mod aba;
pub mod aba_derivatives;
pub mod centroidal;
pub mod coriolis;
pub mod crba;
pub mod energy;
pub mod external;
pub mod floating;
pub mod floating_kinematics;
pub mod floating_derivatives;
pub mod gravity_derivatives;
pub mod integrate;
pub mod integrate_floating;
pub mod jacobian;
pub mod jacobian_dot;
pub mod kinematics;
pub mod ltdl;
pub mod manifold;
pub mod minverse;
pub mod multi_derivatives;
pub mod regressor;
pub mod rnea;
pub mod rnea_derivatives;
pub mod tangent_derivatives;

pub use aba::aba;
pub use coriolis::coriolis_matrix;
pub use crba::crba;
pub use energy::{kinetic_energy, potential_energy};
pub use jacobian::jacobian;
pub use kinematics::forward_kinematics;
pub use regressor::{regressor, regressor_columns};
pub use rnea::{bias, gravity, rnea};
pub use aba_derivatives::aba_derivatives;
pub use floating::{aba_floating, crba_floating, rnea_floating};
pub use floating_derivatives::{aba_derivatives_floating, minverse_floating, rnea_derivatives_floating};
pub use external::{aba_ext, generalized_forces, rnea_ext, ExternalForces, ForceFrame};
pub use gravity_derivatives::gravity_derivatives;
pub use jacobian_dot::jacobian_dot;
pub use minverse::minverse;
pub use rnea_derivatives::rnea_derivatives;
