//! Harmonic balance (paper Section 4.1-4.2).
pub mod fourier;

pub use fourier::{AftPlan, AftScratch, FourierError};
