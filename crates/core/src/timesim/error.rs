use crate::model::ModelError;

/// What went wrong in a time integration, said so that the user knows what to change.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum TimesimError {
    #[error("the time step must be a finite number > 0 s, got {0}")]
    InvalidStep(f64),
    #[error("{steps_per_period} steps per period are too few for harmonic {harmonics}: use at least {min} (10 steps per period of the highest harmonic keep Newmark's period error there below 3.3 %)")]
    TooFewSteps { steps_per_period: usize, harmonics: usize, min: usize },
    #[error("the mass matrix is singular or not positive definite, so the initial acceleration M⁻¹(F − D U̇ − K U − V g) does not exist: give every DOF mass or condense massless DOFs out")]
    SingularMass,
    #[error("the effective matrix M/(βh²) + (1+α)(γ/(βh) D + K) is not positive definite: M, D and K must be symmetric with M positive definite and D, K positive semi-definite")]
    EffectiveNotPositiveDefinite,
    #[error("{what} has length {len}, expected {expected}")]
    WrongLength { what: String, len: usize, expected: usize },
    #[error("DOF index {index} is out of range (the model has {n_dofs} DOFs)")]
    DofOutOfRange { index: usize, n_dofs: usize },
    #[error("the element equations did not converge at t = {time:.6e} s after {iterations} Newton iterations (residual {residual:.3e} m): reduce the time step")]
    NewtonFailed { time: f64, iterations: usize, residual: f64 },
    #[error("no periodic steady state after {periods} periods at {frequency_hz} Hz: periodicity {criterion:.3e} > tolerance {tolerance:.3e}; raise max_periods, loosen the tolerance, or check that the response is not quasi-periodic")]
    NotPeriodic { frequency_hz: f64, periods: usize, criterion: f64, tolerance: f64 },
    #[error("the response became non-finite at t = {time:.6e} s: the model is unstable or the step too large")]
    Diverged { time: f64 },
    #[error("{0}")]
    Invalid(String),
    #[error(transparent)]
    Model(#[from] ModelError),
}
