//! stickslip-fe: from a mesh to a (reduced) linear model (paper Section 3.1-3.3).
//!
//! Meshes in ([`mesh`]), finite elements and sparse assembly ([`assembly`]), the sparse
//! eigensolver ([`eigen`]) and the reductions ([`reduction`]: Craig-Bampton, the paper's
//! free-mode variant Eqs. 3-5, slipped-joint enrichment) and node-to-node contact patches
//! between conforming surfaces ([`patch`]).
pub mod assembly;
pub mod eigen;
pub mod element;
pub mod harmony;
pub mod memory;
pub mod mesh;
pub mod patch;
pub mod reduction;
