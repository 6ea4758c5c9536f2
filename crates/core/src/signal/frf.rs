//! FRFs from stepped-sine and swept-sine records, and the excitation level from an
//! off-resonance response (paper Eq. 1).

use num_complex::Complex64;

use super::harmonics::{extract, Block, SyncOptions};
use super::SignalError;

/// What the response's fundamental is divided by.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Normalization {
    /// The reference's own fundamental (the reference is a force measurement, in N).
    ReferenceChannel,
    /// A known force amplitude in N (the shaker is driven at constant voltage and the level
    /// identified by Eq. 1, as in the paper); the reference then only gives the phase.
    Force { amplitude_n: f64 },
}

/// One FRF value: complex `Y1 / F` at a frequency.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrfPoint {
    pub frequency_hz: f64,
    pub value: Complex64,
}

/// FRF of response `response` from already extracted blocks: one point per block (per cycle for
/// a swept sine with [`SyncOptions::per_cycle`]).
pub fn frf_from_blocks(
    blocks: &[Block],
    response: usize,
    normalization: Normalization,
) -> Result<Vec<FrfPoint>, SignalError> {
    let force = |b: &Block| match normalization {
        // After the rotation of `extract`, the reference fundamental is real and positive.
        Normalization::ReferenceChannel => Ok(b.reference[1]),
        Normalization::Force { amplitude_n } if amplitude_n.is_finite() && amplitude_n > 0.0 => Ok(amplitude_n),
        Normalization::Force { amplitude_n } => {
            Err(SignalError::NotPositive { what: "the force amplitude (N)", value: amplitude_n })
        }
    };
    blocks
        .iter()
        .map(|b| Ok(FrfPoint { frequency_hz: b.frequency_hz, value: b.harmonic(response, 1) / force(b)? }))
        .collect()
}

/// One FRF point from a stepped-sine record (one excitation frequency): harmonics fitted over all
/// cycles after the first `skip_cycles` (the transient).
pub fn stepped_sine_point(
    reference: &[f64],
    response: &[f64],
    sample_rate_hz: f64,
    skip_cycles: usize,
    normalization: Normalization,
) -> Result<FrfPoint, SignalError> {
    let blocks =
        extract(reference, &[("response", response)], sample_rate_hz, &SyncOptions::whole_record(1, skip_cycles))?;
    Ok(frf_from_blocks(&blocks, 0, normalization)?[0])
}

/// FRF of a swept-sine record, one point per block of `cycles_per_block` cycles, the frequency of
/// each block from the reference.
pub fn swept_sine_frf(
    reference: &[f64],
    response: &[f64],
    sample_rate_hz: f64,
    cycles_per_block: usize,
    normalization: Normalization,
) -> Result<Vec<FrfPoint>, SignalError> {
    let options = SyncOptions { n_harmonics: 1, cycles_per_block, skip_cycles: 0 };
    let blocks = extract(reference, &[("response", response)], sample_rate_hz, &options)?;
    frf_from_blocks(&blocks, 0, normalization)
}

/// Excitation level identified from the response at an off-resonance frequency where the
/// structure is linear (paper Eq. 1):
/// `level = reference_level · response / reference_response`, where `reference_response` was
/// measured at the same frequency and point with the known `reference_level` (70 N in the paper,
/// responses at 100 Hz).
pub fn identify_force(reference_level_n: f64, reference_response: f64, response: f64) -> Result<f64, SignalError> {
    for (what, value) in [
        ("the reference excitation level (N)", reference_level_n),
        ("the response amplitude obtained with the reference level", reference_response),
        ("the response amplitude", response),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(SignalError::NotPositive { what, value });
        }
    }
    Ok(reference_level_n * response / reference_response)
}

/// Value at `frequency_hz` of a sampled curve (frequencies strictly increasing), by linear
/// interpolation; the frequency must lie inside the sampled range.
pub fn interpolate_at(frequencies_hz: &[f64], values: &[f64], frequency_hz: f64) -> Result<f64, SignalError> {
    let (min_hz, max_hz) = match (frequencies_hz.first(), frequencies_hz.last()) {
        (Some(&a), Some(&b)) => (a, b),
        _ => (f64::NAN, f64::NAN),
    };
    if !(frequency_hz >= min_hz && frequency_hz <= max_hz) {
        return Err(SignalError::FrequencyOutOfRange { frequency_hz, min_hz, max_hz });
    }
    let i = frequencies_hz.partition_point(|&f| f <= frequency_hz).clamp(1, frequencies_hz.len().max(2) - 1);
    if frequencies_hz.len() == 1 {
        return Ok(values[0]);
    }
    let (f0, f1) = (frequencies_hz[i - 1], frequencies_hz[i]);
    let w = (frequency_hz - f0) / (f1 - f0);
    Ok(values[i - 1] * (1.0 - w) + values[i] * w)
}
