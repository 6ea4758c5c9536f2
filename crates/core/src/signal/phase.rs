//! Excitation phase from the reference channel.
//!
//! Each excitation cycle is bracketed by two consecutive upward zero crossings of the reference
//! (mean removed), located by linear interpolation between samples. Within a cycle the phase is
//! taken linear in time, which is exact for a stepped sine and, for a sweep of rate ḟ, wrong by at
//! most ḟ/(8 f²) cycles (10 Hz/s at 200 Hz: 3e-5 cycle), far below any measurement error.
//!
//! Zero crossings rather than a Hilbert (quadrature) demodulation: they need no FFT of the whole
//! record, have no end effects, give the instantaneous frequency cycle by cycle directly, and are
//! insensitive to the reference amplitude (the force drops at resonance in shaker tests). A
//! hysteresis of 20 % of the reference RMS rejects noise-induced double crossings; any constant
//! phase bias of the crossings is removed later by referring all phases to the reference's own
//! fundamental (see [`super::harmonics`]).

use std::f64::consts::PI;

use super::SignalError;

/// One excitation cycle: the times of two consecutive upward zero crossings of the reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cycle {
    pub start_s: f64,
    pub end_s: f64,
}

impl Cycle {
    /// Frequency of the cycle, 1 / duration, in Hz.
    pub fn frequency_hz(&self) -> f64 {
        1.0 / (self.end_s - self.start_s)
    }

    /// Excitation phase θ at time `t` (s), with the reference ≈ cos θ: its upward zero crossing
    /// is at θ = −π/2.
    #[inline]
    pub fn phase_at(&self, t: f64) -> f64 {
        -0.5 * PI + 2.0 * PI * (t - self.start_s) / (self.end_s - self.start_s)
    }
}

/// Fraction of the reference RMS the signal must fall below before the next upward crossing
/// counts (hysteresis against noise).
const HYSTERESIS: f64 = 0.2;

/// The complete excitation cycles of a reference sampled at `sample_rate_hz` (time of sample j
/// is j / fs). Needs at least one complete cycle.
pub fn reference_cycles(reference: &[f64], sample_rate_hz: f64) -> Result<Vec<Cycle>, SignalError> {
    if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
        return Err(SignalError::BadSampleRate(sample_rate_hz));
    }
    let n = reference.len().max(1) as f64;
    let mean = reference.iter().sum::<f64>() / n;
    let rms = (reference.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt();
    let threshold = HYSTERESIS * rms;
    let mut crossings = Vec::new();
    let mut armed = false;
    for j in 1..reference.len() {
        let (a, b) = (reference[j - 1] - mean, reference[j] - mean);
        if a < -threshold {
            armed = true;
        }
        if armed && a < 0.0 && b >= 0.0 {
            // Linear interpolation of the crossing between samples j-1 and j.
            let frac = a / (a - b);
            crossings.push((j as f64 - 1.0 + frac) / sample_rate_hz);
            armed = false;
        }
    }
    if crossings.len() < 2 {
        return Err(SignalError::TooFewCycles { crossings: crossings.len(), needed: 1 });
    }
    Ok(crossings.windows(2).map(|w| Cycle { start_s: w[0], end_s: w[1] }).collect())
}
