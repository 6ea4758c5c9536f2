//! Harmonic balance (paper Section 4.1-4.2).
pub mod condensed;
pub mod dlft;
pub mod element_aft;
pub mod fourier;
pub mod full;
pub mod receptance;
pub mod sweep;

pub use condensed::{CondensedHbm, HbmError, HbmSettings, Jacobians};
pub use element_aft::{AftError, ElementAft};
pub use fourier::{AftPlan, AftScratch, FourierError};
pub use full::FullHbm;
pub use receptance::Receptance;
pub use sweep::{sweep_frequency, sweep_level, FrequencySweep, LevelSweep, SweepError};
