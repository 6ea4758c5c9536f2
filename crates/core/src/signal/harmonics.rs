//! Synchronous extraction of harmonics 0..N of responses on the excitation phase.
//!
//! For each block of `cycles_per_block` consecutive reference cycles ([`super::phase`]), the
//! samples `y_j` of every response are fitted in the least-squares sense by
//! `y(θ) = c0 + Σ_k (c_k cos kθ + s_k sin kθ)` at their own phases θ_j (one QR of the basis per
//! block, all channels as right-hand sides). Least squares rather than a DFT because a cycle
//! holds a non-integer number of samples that changes from cycle to cycle in a sweep: the fit on
//! the exact phases has no leakage, and for white noise of standard deviation σ over n samples
//! each coefficient c_k, s_k (k ≥ 1) has standard deviation σ √(2/n).
//!
//! Per-cycle blocks follow a sweep; longer blocks average noise (a stepped-sine record is one
//! block). The reference itself is fitted too, and every harmonic k is rotated by `−k φ_ref`,
//! φ_ref the phase of the reference's fundamental, so that the reference becomes a pure
//! `|R1| cos θ`: phases are those of the paper's excitation `F cos Ωt` (Eq. 12) and do not depend
//! on where the zero crossings were detected.

use faer::linalg::solvers::SolveLstsq;
use faer::Mat;
use num_complex::Complex64;

use super::phase::{reference_cycles, Cycle};
use super::SignalError;
use crate::hbm::fourier::{basis, cos_index, sin_index};

/// How records are cut into blocks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SyncOptions {
    /// Highest harmonic N extracted (≥ 1).
    pub n_harmonics: usize,
    /// Reference cycles per block; `usize::MAX` puts all remaining cycles in one block. An
    /// incomplete last block is dropped (all blocks average the same number of cycles).
    pub cycles_per_block: usize,
    /// Cycles dropped at the start of the record (transient).
    pub skip_cycles: usize,
}

impl SyncOptions {
    /// One block per excitation cycle (swept sine).
    pub fn per_cycle(n_harmonics: usize) -> Self {
        SyncOptions { n_harmonics, cycles_per_block: 1, skip_cycles: 0 }
    }

    /// One block of every cycle after the first `skip_cycles` (stepped sine, stationary record).
    pub fn whole_record(n_harmonics: usize, skip_cycles: usize) -> Self {
        SyncOptions { n_harmonics, cycles_per_block: usize::MAX, skip_cycles }
    }
}

/// Harmonics of the reference and of every response over one block of cycles.
#[derive(Debug, Clone, PartialEq)]
pub struct Block {
    pub start_s: f64,
    pub end_s: f64,
    /// Mean frequency of the block: cycles / duration, Hz.
    pub frequency_hz: f64,
    /// Coefficients `[c0, c1, s1, ..., cN, sN]` of the reference (s1 = 0, c1 = |R1| > 0).
    pub reference: Vec<f64>,
    /// Coefficients of each response, in the order given.
    pub responses: Vec<Vec<f64>>,
}

impl Block {
    /// Complex amplitude `X_k = c_k − i s_k` of harmonic `k ≥ 1` of response `r`.
    pub fn harmonic(&self, r: usize, k: usize) -> Complex64 {
        complex_harmonic(&self.responses[r], k)
    }
}

/// Complex amplitude `c_k − i s_k` of harmonic `k ≥ 1` of a coefficient vector.
pub fn complex_harmonic(coeffs: &[f64], k: usize) -> Complex64 {
    Complex64::new(coeffs[cos_index(k)], -coeffs[sin_index(k)])
}

/// Check that harmonic N of the fastest cycle lies below the Nyquist frequency.
fn check_aliasing(n_harmonics: usize, max_frequency_hz: f64, sample_rate_hz: f64) -> Result<(), SignalError> {
    let nyquist_hz = 0.5 * sample_rate_hz;
    let alias_hz = n_harmonics as f64 * max_frequency_hz;
    if alias_hz >= nyquist_hz {
        let max_harmonics = ((nyquist_hz / max_frequency_hz).ceil() as usize).saturating_sub(1);
        return Err(SignalError::Aliasing {
            n_harmonics,
            frequency_hz: max_frequency_hz,
            alias_hz,
            nyquist_hz,
            sample_rate_hz,
            max_harmonics,
            needed_rate_hz: 2.0 * alias_hz,
        });
    }
    Ok(())
}

/// Harmonics 0..N of each response (named, for error messages) on the phase of `reference`,
/// all sampled at `sample_rate_hz` from t = 0, block by block.
pub fn extract(
    reference: &[f64],
    responses: &[(&str, &[f64])],
    sample_rate_hz: f64,
    options: &SyncOptions,
) -> Result<Vec<Block>, SignalError> {
    if options.n_harmonics == 0 {
        return Err(SignalError::NoHarmonics);
    }
    if options.cycles_per_block == 0 {
        return Err(SignalError::EmptyBlock);
    }
    for (name, samples) in responses {
        if samples.len() != reference.len() {
            return Err(SignalError::UnequalLength {
                channel: name.to_string(),
                len: samples.len(),
                reference_len: reference.len(),
            });
        }
    }
    let cycles = reference_cycles(reference, sample_rate_hz)?;
    if cycles.len() <= options.skip_cycles {
        return Err(SignalError::TooFewCycles { crossings: cycles.len() + 1, needed: options.skip_cycles + 1 });
    }
    let cycles = &cycles[options.skip_cycles..];
    let max_frequency = cycles.iter().map(Cycle::frequency_hz).fold(0.0, f64::max);
    check_aliasing(options.n_harmonics, max_frequency, sample_rate_hz)?;

    let n_coeffs = 2 * options.n_harmonics + 1;
    let n_rhs = 1 + responses.len();
    let block_len = options.cycles_per_block.min(cycles.len());
    // Buffers sized for the longest block, reused for every block.
    let longest = cycles
        .chunks(block_len)
        .map(|b| ((b[b.len() - 1].end_s - b[0].start_s) * sample_rate_hz).ceil() as usize + 1)
        .max()
        .unwrap_or(0);
    let mut basis_mat = Mat::<f64>::zeros(longest, n_coeffs);
    let mut rhs = Mat::<f64>::zeros(longest, n_rhs);
    let mut blocks = Vec::with_capacity(cycles.len().div_ceil(block_len));
    for chunk in cycles.chunks(block_len) {
        if chunk.len() < block_len && !blocks.is_empty() {
            break; // an incomplete last block would mix averaging lengths
        }
        let mut n = 0;
        for cycle in chunk {
            let first = (cycle.start_s * sample_rate_hz).ceil() as usize;
            let mut j = first;
            while (j as f64) < cycle.end_s * sample_rate_hz && j < reference.len() {
                let theta = cycle.phase_at(j as f64 / sample_rate_hz);
                for c in 0..n_coeffs {
                    basis_mat[(n, c)] = basis(c, theta);
                }
                rhs[(n, 0)] = reference[j];
                for (r, (_, samples)) in responses.iter().enumerate() {
                    rhs[(n, r + 1)] = samples[j];
                }
                n += 1;
                j += 1;
            }
        }
        let start_s = chunk[0].start_s;
        let end_s = chunk[chunk.len() - 1].end_s;
        if n < n_coeffs {
            return Err(SignalError::TooFewSamples { time_s: start_s, samples: n, coefficients: n_coeffs });
        }
        let solution = basis_mat.as_ref().subrows(0, n).qr().solve_lstsq(rhs.as_ref().subrows(0, n));
        let coeffs = |col: usize| (0..n_coeffs).map(|c| solution[(c, col)]).collect::<Vec<f64>>();
        let mut reference_coeffs = coeffs(0);
        let r1 = complex_harmonic(&reference_coeffs, 1);
        if r1.norm() <= 1e-12 * reference_coeffs.iter().map(|c| c.abs()).fold(0.0, f64::max).max(f64::MIN_POSITIVE) {
            return Err(SignalError::ZeroReference { time_s: start_s });
        }
        let rotation = r1.conj() / r1.norm();
        rotate(&mut reference_coeffs, rotation);
        let responses = (1..n_rhs)
            .map(|col| {
                let mut c = coeffs(col);
                rotate(&mut c, rotation);
                c
            })
            .collect();
        blocks.push(Block {
            start_s,
            end_s,
            frequency_hz: chunk.len() as f64 / (end_s - start_s),
            reference: reference_coeffs,
            responses,
        });
    }
    Ok(blocks)
}

/// Multiply harmonic k by `rotation^k` (a unit complex number): a shift of the phase origin.
fn rotate(coeffs: &mut [f64], rotation: Complex64) {
    let n_harmonics = (coeffs.len() - 1) / 2;
    let mut factor = rotation;
    for k in 1..=n_harmonics {
        let x = complex_harmonic(coeffs, k) * factor;
        coeffs[cos_index(k)] = x.re;
        coeffs[sin_index(k)] = -x.im;
        factor *= rotation;
    }
}
