//! Harmonic balance (paper Section 4.1-4.2).
pub mod bifurcation;
pub mod condensed;
pub mod dlft;
pub mod element_aft;
pub mod fourier;
pub mod full;
pub mod joint_forces;
pub mod nonlinear_mode;
pub mod receptance;
pub mod stability;
pub mod structured;
pub mod sweep;

pub use bifurcation::{
    bifurcations, stability_at, stability_at_last_evaluation, stability_by_eigenproblems, Bifurcation, BifurcationKind,
    BranchStabilityError,
};
pub use condensed::{CondensedHbm, HbmError, HbmSettings, Jacobians};
pub use element_aft::{AftError, ElementAft};
pub use fourier::{AftPlan, AftScratch, FourierError};
pub use full::FullHbm;
pub use nonlinear_mode::{
    nonlinear_mode, Backbone, BackbonePoint, NegativeDamping, NonlinearMode, NonlinearModeError, NonlinearModeSettings,
};
pub use receptance::{HarmonicReceptance, LinearParameter, LinearVariation, ModalReceptance, Receptance};
pub use stability::{Hill, HillSettings, Refined, Stability, StabilityError};
pub use sweep::{off_resonance, sweep_frequency, sweep_level, FrequencySweep, LevelSweep, SweepError};
