//! Signal processing of time records, simulated or measured (paper Sections 2 and 5).
//!
//! - [`phase`]: the excitation phase θ(t) and instantaneous frequency from the reference channel
//!   (upward zero crossings, one cycle at a time).
//! - [`harmonics`]: per-cycle (or per-block) synchronous least-squares extraction of harmonics
//!   0..N of every response on the reference phase (the multi-harmonic comparison of Section 5.2).
//! - [`frf`]: FRFs from stepped-sine and swept-sine records, and the identification of the
//!   excitation level from an off-resonance response (Eq. 1).
//! - [`peaks`]: resonance peaks of an FRF amplitude curve (frequency and amplitude).
//! - [`shapes`]: DAC (Eq. 2) and MAC between shape vectors.
//! - [`antialias`]: the anti-aliasing low-pass of a data acquisition system, for records
//!   sampled from a simulation as a test system samples them.
//! - [`period`]: one period of motion at many points from records synchronised on the excitation
//!   phase, sampled at regular phase steps (the vibrometry "video" of Fig. 9).
//!
//! Harmonics follow the Fourier convention of [`crate::hbm::fourier`]: `[c0, c1, s1, ..., cN, sN]`
//! with θ = Ωt, and phases are measured from the reference's fundamental, taken as `cos θ` (the
//! excitation `F cos Ωt` of Eq. 12), so measured and simulated harmonics compare directly.

pub mod antialias;
pub mod frf;
pub mod harmonics;
pub mod peaks;
pub mod period;
pub mod phase;
pub mod shapes;

/// Errors of signal processing. Each says what to change.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SignalError {
    #[error("the sample rate must be positive and finite, got {0} Hz")]
    BadSampleRate(f64),
    #[error("channel `{channel}` has {len} samples but the reference has {reference_len}: records must be sampled together (same length and clock)")]
    UnequalLength { channel: String, len: usize, reference_len: usize },
    #[error("the reference crosses zero upwards {crossings} times: at least {needed} complete excitation cycles are needed (record longer, or check that the reference channel is the excitation signal)")]
    TooFewCycles { crossings: usize, needed: usize },
    #[error("harmonic {n_harmonics} of {frequency_hz:.4} Hz is {alias_hz:.4} Hz, above the Nyquist frequency {nyquist_hz:.4} Hz of the {sample_rate_hz} Hz sampling: use at most {max_harmonics} harmonics or sample faster than {needed_rate_hz:.1} Hz")]
    Aliasing {
        n_harmonics: usize,
        frequency_hz: f64,
        alias_hz: f64,
        nyquist_hz: f64,
        sample_rate_hz: f64,
        max_harmonics: usize,
        needed_rate_hz: f64,
    },
    #[error("the block starting at {time_s:.6} s holds {samples} samples, fewer than the {coefficients} coefficients of harmonics 0..N: use fewer harmonics, more cycles per block, or sample faster")]
    TooFewSamples { time_s: f64, samples: usize, coefficients: usize },
    #[error("the number of harmonics must be at least 1, got 0")]
    NoHarmonics,
    #[error("the number of cycles per block must be at least 1, got 0")]
    EmptyBlock,
    #[error("the reference fundamental is zero in the block starting at {time_s:.6} s: phases and FRFs cannot be referred to it (check the reference channel)")]
    ZeroReference { time_s: f64 },
    #[error("shape vectors have lengths {left} and {right}: they must list the same points in the same order")]
    ShapeLength { left: usize, right: usize },
    #[error("a shape vector is zero: DAC/MAC are undefined")]
    ZeroShape,
    #[error("{what} must be positive and finite, got {value}")]
    NotPositive { what: &'static str, value: f64 },
    #[error("frequency {frequency_hz} Hz is outside the measured range [{min_hz}, {max_hz}] Hz: choose an identification frequency inside both records")]
    FrequencyOutOfRange { frequency_hz: f64, min_hz: f64, max_hz: f64 },
    #[error("the number of frames must be at least 1, got 0")]
    NoFrames,
    #[error("{0}")]
    Invalid(String),
}
