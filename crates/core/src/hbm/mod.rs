//! Harmonic balance (paper Section 4.1-4.2), in parts:
//!
//! - **the linear part** ([`receptance`]): the model's dynamic flexibility seen from the
//!   nonlinear directions, harmonic by harmonic, with its derivatives with respect to the
//!   frequency and to added damping (`α M + β K`) and a mode left out when a formulation keeps
//!   it as an unknown ([`ModalReceptance::matrix_with`]);
//! - **the nonlinear parts**: the elements' forces by AFT ([`joint_forces`], [`element_aft`]),
//!   or, for rigid contacts, DLFT ([`dlft`]);
//! - **the formulations**, each a continuation problem: the forced response condensed on the
//!   joints ([`condensed`], continued in Ω or the level by [`sweep`]), the damped nonlinear
//!   mode ([`mod@nonlinear_mode`]), the uncondensed balance ([`full`]).
//!
//! The force levels of a study share the linear part and the Fourier plan
//! ([`CondensedHbm::share_linear_part`]). What a point's results and stability need is read
//! from the evaluation that converged there, handed to the continuation's observers
//! ([`crate::continuation::PointObserver`]): [`crate::post::point_result`],
//! [`stability_at_last_evaluation`].
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
    floquet_bifurcations, folds_and_branch_points, stability_at, stability_at_last_evaluation,
    stability_by_eigenproblems, Bifurcation, BifurcationKind, BranchStabilityError, CrossingKind, UnstableCounts,
};
pub use condensed::{CondensedHbm, HbmError, HbmSettings, Jacobians};
pub use element_aft::{AftError, ElementAft};
pub use fourier::{AftPlan, AftScratch, FourierError};
pub use full::FullHbm;
pub use nonlinear_mode::{
    nonlinear_mode, Backbone, BackbonePoint, BackboneSingularPoint, NegativeDamping, NonlinearMode, NonlinearModeError,
    NonlinearModeSettings,
};
pub use receptance::{HarmonicReceptance, LinearParameter, LinearVariation, ModalReceptance, Receptance};
pub use stability::{Hill, HillSettings, Refined, Stability, StabilityError};
pub use sweep::{off_resonance, sweep_frequency, sweep_level, FrequencySweep, LevelSweep, SweepError};
