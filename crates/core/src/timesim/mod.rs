//! Direct time integration of the equation of motion with local nonlinearities (paper Eq. 12),
//!
//! ```text
//! M Ü + D U̇ + K U + Σ_e V_e g_e(u_e, u̇_e, history) = F(t),
//! ```
//!
//! an independent check of the harmonic balance and the generator of virtual experiments
//! (fixed-frequency steady states and swept sines, as on the shaker of Sections 2 and 5).
//!
//! * [`Integrator`]: one implicit step of Newmark average acceleration or HHT-α. The linear
//!   part is factorised once per step size; the elements enter through their `q` application
//!   directions only, by an exact condensation of the step equations onto `z = Vᵀ U` and Newton
//!   iterations on a `q × q` system with the elements' consistent tangent.
//! * [`steady_state`]: run a harmonic excitation until periodic (stated criterion) and return
//!   one period of records and the energy balance of that period.
//! * [`swept_sine`]: linear sweep at a given rate in Hz/s, up or down, with per-cycle
//!   first-harmonic amplitudes of the recorded DOFs.

// Step loops run over several arrays of the same length by index, as the equations read.
#![allow(clippy::needless_range_loop)]

mod error;
mod integrator;
mod operator;
mod records;
mod steady;
mod sweep;

pub use error::TimesimError;
pub use integrator::{EnergyTally, Integrator, Scheme, State};
pub use records::{CycleEnergy, ElementRecords, Records};
pub use steady::{steady_state, SteadyState, SteadyStateOptions};
pub use sweep::{swept_sine, SlowBand, SweepCycle, SweepOptions, SweepRecord, SweepSchedule};
