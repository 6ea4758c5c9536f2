//! stickslip-core: the nonlinear heart of stickslip.
//!
//! The chain of Claeys et al. (MSSP 2016), from a linear model to a branch of periodic
//! solutions: [`model`] (the linear model, Eq. 6) → [`elements`] (friction joints and other
//! local nonlinearities, Eqs. 7-11) → [`hbm`] (harmonic balance with AFT and condensation,
//! Eqs. 13-29) → [`continuation`] (pseudo-arclength, Eqs. 31-32) → [`post`] (FRFs, harmonics,
//! stick-slip velocity Eq. 33, energy). [`timesim`] integrates Eq. 12 in time as an independent
//! check; [`signal`] turns time records into what the paper compares.
// Numerical kernels index vectors and matrices by the indices of their equations (harmonic k,
// direction i, mode r); iterator rewrites of those loops read worse.
#![allow(clippy::needless_range_loop)]

pub mod continuation;
pub mod elements;
pub mod hbm;
pub mod model;
pub mod post;
pub mod signal;
pub mod timesim;
