//! Truncated Fourier series and the alternating frequency/time passage (paper Eqs. 13, 15).
//!
//! # Conventions (the one place they are written down)
//!
//! A periodic signal of fundamental circular frequency Ω is, with θ = Ωt,
//!
//! ```text
//! x(θ) = c0 + Σ_{k=1..N} ( c_k cos kθ + s_k sin kθ )
//! ```
//!
//! and its **coefficient vector** is `[c0, c1, s1, c2, s2, ..., cN, sN]` (length `2N+1`). The
//! paper orders each pair (sin, cos) (`[B0 A1 B1 ...]`, Eq. 15); stickslip orders (cos, sin).
//! Coefficient index of `cos kθ` is `2k−1`, of `sin kθ` is `2k` (k ≥ 1).
//!
//! For several DOFs the coefficients are stored **coefficient-major**: entry `j·n + i` is
//! coefficient `j` of DOF `i` (a column-major `n × (2N+1)` matrix, one column per coefficient),
//! so the linear operator of Eq. 17 is block diagonal in pairs of columns.
//!
//! Time samples are `θ_j = 2π j / n_t`, `j = 0..n_t`. Complex amplitude of harmonic k is
//! `X_k = c_k − i s_k`, so that `x = c0 + Re Σ X_k e^{ikθ}`.

use multiversion::multiversion;
use std::sync::Arc;

use faer::Mat;
use realfft::num_complex::Complex;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};

/// Index of the cosine coefficient of harmonic `k ≥ 1` in a coefficient vector.
#[inline]
pub fn cos_index(k: usize) -> usize {
    2 * k - 1
}

/// Index of the sine coefficient of harmonic `k ≥ 1` in a coefficient vector.
#[inline]
pub fn sin_index(k: usize) -> usize {
    2 * k
}

/// Is the harmonic of Fourier coefficient `c` (0; cos 1, sin 1; cos 2, ...) even?
pub fn coefficient_is_even(c: usize) -> bool {
    c.div_ceil(2).is_multiple_of(2)
}

/// Errors building a Fourier plan.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum FourierError {
    #[error("{n_samples} time samples cannot resolve {n_harmonics} harmonics without aliasing: use at least {min} samples per period (paper: 300 for N = 7)")]
    TooFewSamples { n_harmonics: usize, n_samples: usize, min: usize },
    #[error("the number of harmonics must be at least 1, got 0")]
    NoHarmonics,
}

/// Planned real FFTs and the synthesis/projection matrices for `N` harmonics and `n_t` samples.
///
/// Built once per (N, n_t) and shared (`Send + Sync`, `&self` evaluation); temporaries live in
/// a caller-owned [`AftScratch`] so that evaluation never allocates.
pub struct AftPlan {
    n_harmonics: usize,
    n_samples: usize,
    forward: Arc<dyn RealToComplex<f64>>,
    inverse: Arc<dyn ComplexToReal<f64>>,
    /// `E[(j, c)]`: value at sample j of basis function c (`n_t × (2N+1)`), x = E X.
    synthesis: Mat<f64>,
    /// `E'[(j, c)]`: θ-derivative of basis function c at sample j, dx/dθ = E' X.
    synthesis_derivative: Mat<f64>,
    /// `Eᵀ` and `E'ᵀ` (`(2N+1) × n_t`): the basis at sample j as one contiguous column, for
    /// sample-by-sample loops.
    basis_at_sample: Mat<f64>,
    basis_derivative_at_sample: Mat<f64>,
    /// `P[(c, j)]`: weight of sample j in coefficient c (`(2N+1) × n_t`), X = P x (exact for
    /// band-limited signals, the DFT projection otherwise). `P E = I`.
    projection: Mat<f64>,
    /// Running sums of `P`'s columns (`(2N+1) × (n_t+1)`): column j is `Σ_{i<j} P[(·, i)]`,
    /// so that a stretch of samples is summed by one difference ([`Self::projection_sum`]).
    projection_prefix: Mat<f64>,
    /// Running sums of `cos mθ_j` and `sin mθ_j`, m = 0..=2N (`(2N+1) × (n_t+1)` each, column
    /// j summing the samples before j): a stretch's Fourier sums by one difference
    /// ([`Self::add_fourier_sums`]).
    cos_prefix: Mat<f64>,
    sin_prefix: Mat<f64>,
    /// For an even `n_t`, the coefficients of the odd harmonics (cos k, sin k for k = 1, 3, ...)
    /// and, one contiguous row of `n_t/2` samples each: their basis on the first half period
    /// and their projection weights from it (`4/n_t` times the basis: a half-wave symmetric
    /// signal, `x(θ + π) = −x(θ)`, has both halves' terms alike). Empty for an odd `n_t`.
    odd_coeffs: Vec<usize>,
    half_synthesis: Vec<f64>,
    half_projection: Vec<f64>,
}

impl std::fmt::Debug for AftPlan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AftPlan").field("n_harmonics", &self.n_harmonics).field("n_samples", &self.n_samples).finish()
    }
}

/// Caller-owned temporaries of an [`AftPlan`].
pub struct AftScratch {
    spectrum: Vec<Complex<f64>>,
    fft_scratch: Vec<Complex<f64>>,
    time: Vec<f64>,
}

impl AftPlan {
    /// Plan for `n_harmonics` harmonics and `n_samples` samples per period; `n_samples` must
    /// exceed `2 n_harmonics` so that harmonic N is resolved.
    pub fn new(n_harmonics: usize, n_samples: usize) -> Result<Self, FourierError> {
        if n_harmonics == 0 {
            return Err(FourierError::NoHarmonics);
        }
        let min = 2 * n_harmonics + 1;
        if n_samples < min {
            return Err(FourierError::TooFewSamples { n_harmonics, n_samples, min });
        }
        let mut planner = RealFftPlanner::<f64>::new();
        let forward = planner.plan_fft_forward(n_samples);
        let inverse = planner.plan_fft_inverse(n_samples);
        let nc = 2 * n_harmonics + 1;
        let dtheta = 2.0 * std::f64::consts::PI / n_samples as f64;
        let synthesis = Mat::from_fn(n_samples, nc, |j, c| basis(c, j as f64 * dtheta));
        let synthesis_derivative = Mat::from_fn(n_samples, nc, |j, c| basis_derivative(c, j as f64 * dtheta));
        let projection = Mat::from_fn(nc, n_samples, |c, j| {
            let w = if c == 0 { 1.0 } else { 2.0 };
            w / n_samples as f64 * basis(c, j as f64 * dtheta)
        });
        let projection_prefix = running_sums(nc, n_samples, |c, j| projection[(c, j)]);
        // mθ_j reduced to the period first: exact angles for every m.
        let angle = |m: usize, j: usize| ((m * j) % n_samples) as f64 * dtheta;
        let cos_prefix = running_sums(2 * n_harmonics + 1, n_samples, |m, j| angle(m, j).cos());
        let sin_prefix = running_sums(2 * n_harmonics + 1, n_samples, |m, j| angle(m, j).sin());
        let basis_at_sample = synthesis.transpose().to_owned();
        let basis_derivative_at_sample = synthesis_derivative.transpose().to_owned();
        let half = n_samples / 2;
        let odd_coeffs: Vec<usize> = match n_samples % 2 {
            0 => (1..nc).filter(|&c| !coefficient_is_even(c)).collect(),
            _ => Vec::new(),
        };
        let half_synthesis: Vec<f64> =
            odd_coeffs.iter().flat_map(|&c| (0..half).map(move |j| basis(c, j as f64 * dtheta))).collect();
        let half_projection = half_synthesis.iter().map(|b| 4.0 / n_samples as f64 * b).collect();
        Ok(AftPlan {
            n_harmonics,
            n_samples,
            forward,
            inverse,
            synthesis,
            synthesis_derivative,
            basis_at_sample,
            basis_derivative_at_sample,
            projection,
            projection_prefix,
            odd_coeffs,
            half_synthesis,
            half_projection,
            cos_prefix,
            sin_prefix,
        })
    }

    pub fn n_harmonics(&self) -> usize {
        self.n_harmonics
    }

    pub fn n_samples(&self) -> usize {
        self.n_samples
    }

    /// Length of a coefficient vector, `2N + 1`.
    pub fn n_coeffs(&self) -> usize {
        2 * self.n_harmonics + 1
    }

    /// Synthesis matrix `E` (`n_t × (2N+1)`): `x_j = Σ_c E[(j,c)] X_c`.
    pub fn synthesis(&self) -> &Mat<f64> {
        &self.synthesis
    }

    /// Derivative synthesis matrix `E'` (`n_t × (2N+1)`): `dx/dθ(θ_j) = Σ_c E'[(j,c)] X_c`.
    pub fn synthesis_derivative_matrix(&self) -> &Mat<f64> {
        &self.synthesis_derivative
    }

    /// The basis functions at sample `j`: row j of `E`, contiguous.
    pub fn basis_at(&self, j: usize) -> &[f64] {
        self.basis_at_sample.col_as_slice(j)
    }

    /// Their θ-derivatives at sample `j`: row j of `E'`, contiguous.
    pub fn basis_derivative_at(&self, j: usize) -> &[f64] {
        self.basis_derivative_at_sample.col_as_slice(j)
    }

    /// The weights of sample `j` in every coefficient: column j of `P`, contiguous.
    pub fn projection_at(&self, j: usize) -> &[f64] {
        self.projection.col_as_slice(j)
    }

    /// `Σ P[(·, j)]` over the `count ≤ n_t` samples from `first` on, wrapping past the period's
    /// end, into `sum` (length `2N+1`): two or three columns of the running sums instead of
    /// `count` columns (a stuck slider's Jacobian sums `P` over each stick phase). Equal to the
    /// direct sum to round-off of the running sums' size (`|Σ P| ≤ 2`, so ~1e-16 absolute).
    pub fn projection_sum(&self, first: usize, count: usize, sum: &mut [f64]) {
        sum.fill(0.0);
        self.add_stretch(&self.projection_prefix, first, count, sum);
    }

    /// Add `Σ cos mθ_j` and `Σ sin mθ_j` over the `count ≤ n_t` samples from `first` on,
    /// wrapping past the period's end, to `cos_sums[m]` and `sin_sums[m]`, m up to their length
    /// (at most 2N + 1): the Fourier sums of a stretch of constant weight (a slider's stick
    /// phase) without a transform. Exact to ~1 ulp of `n_t` per stretch.
    pub fn add_fourier_sums(&self, first: usize, count: usize, cos_sums: &mut [f64], sin_sums: &mut [f64]) {
        self.add_stretch(&self.cos_prefix, first, count, cos_sums);
        self.add_stretch(&self.sin_prefix, first, count, sin_sums);
    }

    /// Add to `sums` the stretch of `count` samples from `first` on (wrapping) of the sequences
    /// whose running sums are `prefix`: one difference of two columns, or three columns.
    fn add_stretch(&self, prefix: &Mat<f64>, first: usize, count: usize, sums: &mut [f64]) {
        let nt = self.n_samples;
        debug_assert!(first < nt && count <= nt);
        let at = |j: usize| prefix.col_as_slice(j);
        let end = first + count;
        if end <= nt {
            for ((s, a), b) in sums.iter_mut().zip(at(end)).zip(at(first)) {
                *s += a - b;
            }
        } else {
            for (((s, a), b), c) in sums.iter_mut().zip(at(nt)).zip(at(first)).zip(at(end - nt)) {
                *s += (a - b) + c;
            }
        }
    }

    /// Projection matrix `P` (`(2N+1) × n_t`): `X_c = Σ_j P[(c,j)] x_j`.
    pub fn projection(&self) -> &Mat<f64> {
        &self.projection
    }

    /// Do [`Self::synthesize_half_wave`] and [`Self::analyze_half_wave`] apply (an even number
    /// of samples, so that θ + π is a sample)?
    pub fn has_half_wave(&self) -> bool {
        !self.odd_coeffs.is_empty()
    }

    /// Samples of the half-wave symmetric signal of the odd harmonics of `coeffs` (the even
    /// ones are not read): the first half period by direct sums of the N/2 odd harmonics, the
    /// second its negative, `x_{j+n_t/2} = −x_j` exactly. For N ≪ n_t a quarter of the
    /// operations of the whole sums and fewer than an inverse FFT, which has no form for half
    /// a spectrum (written here for that reason). Needs [`Self::has_half_wave`].
    pub fn synthesize_half_wave(&self, coeffs: &[f64], samples: &mut [f64]) {
        assert!(self.has_half_wave(), "half-wave synthesis needs an even number of samples");
        assert_eq!(samples.len(), self.n_samples, "expected {} samples, got {}", self.n_samples, samples.len());
        let (first, second) = samples.split_at_mut(self.n_samples / 2);
        half_synthesize(&self.half_synthesis, &self.odd_coeffs, coeffs, first);
        for (b, a) in second.iter_mut().zip(first.iter()) {
            *b = -*a;
        }
    }

    /// The coefficients of a half-wave symmetric signal from its first half period (the
    /// second is not read): the odd harmonics by the DFT's sums, twice those of the first
    /// half; the even ones, which such a signal does not have, zero. The counterpart of
    /// [`Self::synthesize_half_wave`].
    pub fn analyze_half_wave(&self, samples: &[f64], coeffs: &mut [f64]) {
        assert!(self.has_half_wave(), "half-wave analysis needs an even number of samples");
        assert_eq!(coeffs.len(), self.n_coeffs(), "expected {} coefficients, got {}", self.n_coeffs(), coeffs.len());
        coeffs.fill(0.0);
        half_analyze(&self.half_projection, &self.odd_coeffs, &samples[..self.n_samples / 2], coeffs);
    }

    /// Temporaries for [`synthesize`](Self::synthesize) and [`analyze`](Self::analyze).
    pub fn scratch(&self) -> AftScratch {
        let len = self.forward.get_scratch_len().max(self.inverse.get_scratch_len());
        AftScratch {
            spectrum: vec![Complex::new(0.0, 0.0); self.n_samples / 2 + 1],
            fft_scratch: vec![Complex::new(0.0, 0.0); len],
            time: vec![0.0; self.n_samples],
        }
    }

    /// Time samples `x(θ_j)` of the coefficient vector `coeffs` (inverse DFT of Eq. 15).
    pub fn synthesize(&self, coeffs: &[f64], samples: &mut [f64], scratch: &mut AftScratch) {
        self.synthesize_scaled(coeffs, samples, scratch, 0)
    }

    /// Samples of `dx/dθ` (multiply by Ω for the time derivative).
    pub fn synthesize_derivative(&self, coeffs: &[f64], samples: &mut [f64], scratch: &mut AftScratch) {
        self.synthesize_scaled(coeffs, samples, scratch, 1)
    }

    fn synthesize_scaled(&self, coeffs: &[f64], samples: &mut [f64], scratch: &mut AftScratch, derivative: u32) {
        assert_eq!(coeffs.len(), self.n_coeffs(), "expected {} coefficients, got {}", self.n_coeffs(), coeffs.len());
        assert_eq!(samples.len(), self.n_samples, "expected {} samples, got {}", self.n_samples, samples.len());
        let spec = &mut scratch.spectrum;
        spec.iter_mut().for_each(|z| *z = Complex::new(0.0, 0.0));
        spec[0] = Complex::new(if derivative == 0 { coeffs[0] } else { 0.0 }, 0.0);
        for k in 1..=self.n_harmonics {
            // X_k = c_k − i s_k; the c2r transform sums X_0 + 2 Re Σ Y_k e^{ikθ}, so Y_k = X_k/2.
            let z = Complex::new(coeffs[cos_index(k)], -coeffs[sin_index(k)]) * 0.5;
            // d/dθ multiplies harmonic k by ik.
            spec[k] = if derivative == 0 { z } else { z * Complex::new(0.0, k as f64) };
        }
        if self.n_samples.is_multiple_of(2) {
            // The Nyquist bin must be real for the c2r transform; it is zero here since N < n_t/2.
            let last = spec.len() - 1;
            spec[last].im = 0.0;
        }
        self.inverse
            .process_with_scratch(spec, samples, &mut scratch.fft_scratch)
            .expect("buffer sizes are fixed by the plan");
    }

    /// Coefficients of the first N harmonics of the samples (DFT of Eq. 15).
    pub fn analyze(&self, samples: &[f64], coeffs: &mut [f64], scratch: &mut AftScratch) {
        assert_eq!(coeffs.len(), self.n_coeffs(), "expected {} coefficients, got {}", self.n_coeffs(), coeffs.len());
        assert_eq!(samples.len(), self.n_samples, "expected {} samples, got {}", self.n_samples, samples.len());
        scratch.time.copy_from_slice(samples);
        self.forward
            .process_with_scratch(&mut scratch.time, &mut scratch.spectrum, &mut scratch.fft_scratch)
            .expect("buffer sizes are fixed by the plan");
        let scale = 1.0 / self.n_samples as f64;
        coeffs[0] = scratch.spectrum[0].re * scale;
        for k in 1..=self.n_harmonics {
            let z = scratch.spectrum[k];
            coeffs[cos_index(k)] = 2.0 * z.re * scale;
            coeffs[sin_index(k)] = -2.0 * z.im * scale;
        }
    }
}

/// `out = Σ_o coeffs[odd[o]] table[o]` (rows of `out.len()`), row after row so that the loop
/// over the samples vectorises.
#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn half_synthesize(table: &[f64], odd: &[usize], coeffs: &[f64], out: &mut [f64]) {
    let half = out.len();
    out.fill(0.0);
    for (row, &c) in table.chunks_exact(half).zip(odd) {
        let x = coeffs[c];
        for (o, b) in out.iter_mut().zip(row) {
            *o += x * b;
        }
    }
}

/// `coeffs[odd[o]] = table[o] · samples`, each on four partial sums so that it vectorises.
#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn half_analyze(table: &[f64], odd: &[usize], samples: &[f64], coeffs: &mut [f64]) {
    let half = samples.len();
    for (row, &c) in table.chunks_exact(half).zip(odd) {
        let mut sums = [0.0; 4];
        let (rows, values) = (row.chunks_exact(4), samples.chunks_exact(4));
        let tail: f64 = rows.remainder().iter().zip(values.remainder()).map(|(a, b)| a * b).sum();
        for (r, v) in rows.zip(values) {
            for l in 0..4 {
                sums[l] += r[l] * v[l];
            }
        }
        coeffs[c] = (sums[0] + sums[1]) + (sums[2] + sums[3]) + tail;
    }
}

/// Running sums of `rows` sequences of `n` values, `value(row, j)`: column j of the result
/// (`rows × (n+1)`) sums the values before j. Compensated (Neumaier): each column is the exact
/// sum rounded once, so a stretch's sum (a difference of two) errs by ~2 ulp of the sums'
/// size, not by the error of n additions.
fn running_sums(rows: usize, n: usize, value: impl Fn(usize, usize) -> f64) -> Mat<f64> {
    let mut prefix = Mat::zeros(rows, n + 1);
    for r in 0..rows {
        let (mut sum, mut compensation) = (0.0f64, 0.0f64);
        for j in 0..n {
            let x = value(r, j);
            let t = sum + x;
            compensation += if sum.abs() >= x.abs() { (sum - t) + x } else { (x - t) + sum };
            sum = t;
            prefix[(r, j + 1)] = sum + compensation;
        }
    }
    prefix
}

/// Basis function c at angle θ: 1, cos θ, sin θ, cos 2θ, ...
#[inline]
pub fn basis(c: usize, theta: f64) -> f64 {
    if c == 0 {
        1.0
    } else {
        let k = c.div_ceil(2) as f64;
        if c % 2 == 1 {
            (k * theta).cos()
        } else {
            (k * theta).sin()
        }
    }
}

/// θ-derivative of basis function c: 0, −sin θ, cos θ, −2 sin 2θ, ...
#[inline]
pub fn basis_derivative(c: usize, theta: f64) -> f64 {
    if c == 0 {
        0.0
    } else {
        let k = c.div_ceil(2) as f64;
        if c % 2 == 1 {
            -k * (k * theta).sin()
        } else {
            k * (k * theta).cos()
        }
    }
}

/// Amplitude and phase of harmonic `k ≥ 1` of a coefficient vector: `x_k = A cos(kθ + φ)`,
/// `A = |c_k − i s_k|`, `φ = arg(c_k − i s_k)` (so a pure sine has φ = −π/2).
pub fn amplitude_phase(coeffs: &[f64], k: usize) -> (f64, f64) {
    let c = coeffs[cos_index(k)];
    let s = coeffs[sin_index(k)];
    (c.hypot(s), (-s).atan2(c))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel_err(a: &[f64], b: &[f64]) -> f64 {
        let num: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt();
        let den: f64 = b.iter().map(|y| y * y).sum::<f64>().sqrt();
        num / den
    }

    /// The half-wave transforms equal the FFTs on a signal of odd harmonics (N = 7, 300 and 64
    /// samples): samples and coefficients within 5e-15 in norm (measured 1.1e-15: the FFT's
    /// error grows as ε log₂ n_t, ~8 ε at 300), the second half exactly the first's negative,
    /// the even coefficients exactly zero; and an odd number of samples has none.
    #[test]
    fn half_wave_transforms_equal_the_ffts_on_odd_harmonics() {
        for nt in [300, 64] {
            let plan = AftPlan::new(7, nt).unwrap();
            assert!(plan.has_half_wave());
            let mut scratch = plan.scratch();
            let coeffs: Vec<f64> = (0..15)
                .map(|c| if coefficient_is_even(c) { 0.0 } else { ((c * 7 + 3) % 11) as f64 * 0.1 - 0.45 })
                .collect();
            let (mut fft, mut half) = (vec![0.0; nt], vec![0.0; nt]);
            plan.synthesize(&coeffs, &mut fft, &mut scratch);
            plan.synthesize_half_wave(&coeffs, &mut half);
            assert!(rel_err(&half, &fft) <= 5e-15, "{:e}", rel_err(&half, &fft));
            assert!((0..nt / 2).all(|j| half[j + nt / 2] == -half[j]));
            let (mut back_fft, mut back_half) = (vec![0.0; 15], vec![0.0; 15]);
            plan.analyze(&half, &mut back_fft, &mut scratch);
            plan.analyze_half_wave(&half, &mut back_half);
            assert!(rel_err(&back_half, &coeffs) <= 5e-15, "{back_half:?}");
            assert!(rel_err(&back_fft, &back_half) <= 5e-15);
            assert!((0..15).filter(|&c| coefficient_is_even(c)).all(|c| back_half[c] == 0.0));
        }
        assert!(!AftPlan::new(7, 301).unwrap().has_half_wave());
    }

    #[test]
    fn synthesis_and_analysis_are_inverse_and_match_the_matrices() {
        // Odd and even sample counts, and the paper's 300.
        for &(n, nt) in &[(1, 3), (3, 8), (7, 300), (5, 31)] {
            let plan = AftPlan::new(n, nt).unwrap();
            let mut s = plan.scratch();
            let coeffs: Vec<f64> = (0..plan.n_coeffs()).map(|c| 0.3 + (c as f64 * 1.7).sin()).collect();
            let mut x = vec![0.0; nt];
            plan.synthesize(&coeffs, &mut x, &mut s);
            // Direct evaluation of the series.
            let direct: Vec<f64> = (0..nt)
                .map(|j| {
                    let th = 2.0 * std::f64::consts::PI * j as f64 / nt as f64;
                    (0..plan.n_coeffs()).map(|c| coeffs[c] * basis(c, th)).sum()
                })
                .collect();
            assert!(rel_err(&x, &direct) < 1e-13, "synthesis N={n} nt={nt}");
            let mut back = vec![0.0; plan.n_coeffs()];
            plan.analyze(&x, &mut back, &mut s);
            assert!(rel_err(&back, &coeffs) < 1e-13, "analysis N={n} nt={nt}");
            // P E = I.
            let pe = plan.projection() * plan.synthesis();
            for i in 0..plan.n_coeffs() {
                for j in 0..plan.n_coeffs() {
                    let expect = if i == j { 1.0 } else { 0.0 };
                    assert!((pe[(i, j)] - expect).abs() < 1e-13);
                }
            }
        }
    }

    #[test]
    fn derivative_of_a_known_series() {
        let plan = AftPlan::new(3, 64).unwrap();
        let mut s = plan.scratch();
        // x = 2 cos 2θ + 5 sin 3θ  →  x' = −4 sin 2θ + 15 cos 3θ.
        let mut c = vec![0.0; 7];
        c[cos_index(2)] = 2.0;
        c[sin_index(3)] = 5.0;
        let mut dx = vec![0.0; 64];
        plan.synthesize_derivative(&c, &mut dx, &mut s);
        for (j, v) in dx.iter().enumerate() {
            let th = 2.0 * std::f64::consts::PI * j as f64 / 64.0;
            let expect = -4.0 * (2.0 * th).sin() + 15.0 * (3.0 * th).cos();
            assert!((v - expect).abs() < 1e-12);
        }
        let (a, phi) = amplitude_phase(&c, 3);
        assert!((a - 5.0).abs() < 1e-15 && (phi + std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    }

    /// A stretch summed from the running sums equals the exact sum of its columns (a
    /// compensated sum here), wrapping or not, within the rounding of two running sums of size
    /// up to 1 and their difference: 4e-16 absolute.
    #[test]
    fn projection_sums_of_stretches_equal_the_direct_sums() {
        let plan = AftPlan::new(7, 300).unwrap();
        let nc = plan.n_coeffs();
        let mut sum = vec![0.0; nc];
        for (first, count) in [(0, 0), (0, 1), (0, 300), (17, 40), (250, 50), (250, 51), (299, 300), (123, 299)] {
            plan.projection_sum(first, count, &mut sum);
            for c in 0..nc {
                let (mut direct, mut compensation) = (0.0f64, 0.0f64);
                for i in 0..count {
                    let x = plan.projection()[(c, (first + i) % 300)];
                    let t = direct + x;
                    compensation += if direct.abs() >= x.abs() { (direct - t) + x } else { (x - t) + direct };
                    direct = t;
                }
                let direct = direct + compensation;
                assert!(
                    (sum[c] - direct).abs() <= 4e-16,
                    "({first}, {count}) coefficient {c}: {} against {direct}",
                    sum[c]
                );
            }
        }
    }

    /// A stretch's Fourier sums from the running sums equal the direct sums of cos mθ_j and
    /// sin mθ_j up to m = 2N, wrapping or not, to 1e-13 (sums of up to 300 terms of size 1).
    #[test]
    fn fourier_sums_of_stretches_equal_the_direct_sums() {
        let plan = AftPlan::new(7, 300).unwrap();
        let dtheta = 2.0 * std::f64::consts::PI / 300.0;
        for (first, count) in [(0, 0), (0, 1), (0, 300), (17, 40), (250, 51), (299, 300), (123, 299)] {
            let (mut c, mut s) = (vec![0.5; 15], vec![0.5; 15]);
            plan.add_fourier_sums(first, count, &mut c, &mut s);
            for m in 0..15 {
                let theta = |i: usize| m as f64 * ((first + i) % 300) as f64 * dtheta;
                let dc: f64 = (0..count).map(|i| theta(i).cos()).sum();
                let ds: f64 = (0..count).map(|i| theta(i).sin()).sum();
                assert!((c[m] - 0.5 - dc).abs() < 1e-13, "({first}, {count}) cos {m}: {} against {dc}", c[m] - 0.5);
                assert!((s[m] - 0.5 - ds).abs() < 1e-13, "({first}, {count}) sin {m}: {} against {ds}", s[m] - 0.5);
            }
        }
    }

    #[test]
    fn too_few_samples_is_an_error() {
        assert_eq!(
            AftPlan::new(7, 14).unwrap_err(),
            FourierError::TooFewSamples { n_harmonics: 7, n_samples: 14, min: 15 }
        );
    }
}
