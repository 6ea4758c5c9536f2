//! The linear model of an assembly: `M Ü + D U̇ + K U = F` (paper Eq. 6), whatever it came from
//! (inline matrices, an FE mesh, an imported file or a reduction).

mod damping;
mod dof;
mod linear;
mod matrix;
mod modes;
mod nonlinear;

pub use damping::Damping;
pub use dof::DofLabel;
pub use linear::{LinearModel, ModelError, NamedVector};
pub use matrix::Matrix;
pub use modes::{symmetric_eigen, Modes};
pub use nonlinear::{relative_direction, stiffness_along, ElementSite, NonlinearModel, RigidContact};
