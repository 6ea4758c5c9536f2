//! Synchronous harmonic extraction on synthetic multi-harmonic signals with noise.
mod signal_util;

use std::f64::consts::PI;

use signal_util::Gaussian;
use stickslip_core::signal::harmonics::{complex_harmonic, extract, SyncOptions};
use stickslip_core::signal::period;

/// Mean and harmonics (k, amplitude, phase) of the synthetic response, phases relative to the
/// excitation `cos θ`.
const MEAN: f64 = 0.1;
const HARMONICS: [(usize, f64, f64); 4] = [(1, 1.0, 0.3), (2, 0.0, 0.0), (3, 0.05, -1.0), (5, 0.02, 2.0)];
const N: usize = 5;

fn true_coeffs() -> Vec<f64> {
    let mut c = vec![0.0; 2 * N + 1];
    c[0] = MEAN;
    for (k, a, p) in HARMONICS {
        c[2 * k - 1] = a * p.cos();
        c[2 * k] = -a * p.sin();
    }
    c
}

/// Reference `cos θ(t)` and response of phase θ(t) = 2π (f0 t + ½ ḟ t²) + θ0, plus white noise σ
/// on the response only (the excitation reference is the generator's clean signal).
fn record(f0: f64, sweep_rate: f64, fs: f64, duration: f64, sigma: f64, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let theta0 = 1.234; // an arbitrary record start: results must not depend on it
    let n = (duration * fs) as usize;
    let mut noise = Gaussian::new(seed);
    let mut reference = Vec::with_capacity(n);
    let mut response = Vec::with_capacity(n);
    for j in 0..n {
        let t = j as f64 / fs;
        let th = 2.0 * PI * (f0 * t + 0.5 * sweep_rate * t * t) + theta0;
        reference.push(th.cos());
        let y: f64 = MEAN + HARMONICS.iter().map(|&(k, a, p)| a * (k as f64 * th + p).cos()).sum::<f64>();
        response.push(y + sigma * noise.sample());
    }
    (reference, response)
}

/// RMS over blocks and over the 2N+1 coefficients of the extraction error.
fn rms_error(blocks: &[stickslip_core::signal::harmonics::Block]) -> f64 {
    let truth = true_coeffs();
    let mut sum = 0.0;
    let mut count = 0;
    for b in blocks {
        for (got, exact) in b.responses[0].iter().zip(&truth).skip(1) {
            sum += (got - exact).powi(2);
            count += 1;
        }
    }
    (sum / count as f64).sqrt()
}

#[test]
fn per_cycle_extraction_error_matches_least_squares_noise_prediction() {
    // 97.3 Hz at 10 kHz: 102.8 samples per cycle, a non-integer number (no DFT bin alignment).
    let (fs, f0, sigma) = (10_000.0, 97.3, 0.01);
    let (reference, response) = record(f0, 0.0, fs, 2.0, sigma, 1);
    let blocks = extract(&reference, &[("y", &response)], fs, &SyncOptions::per_cycle(N)).unwrap();
    assert!(blocks.len() > 150, "{} cycles", blocks.len());
    // Least squares on a nearly orthogonal basis over n samples: each c_k, s_k (k ≥ 1) has
    // standard deviation σ √(2/n).
    let n = fs / f0;
    let expected = sigma * (2.0 / n).sqrt();
    let got = rms_error(&blocks);
    assert!(got < 3.0 * expected && got > expected / 3.0, "rms error {got:.3e}, expected {expected:.3e}");
    // The frequency from the reference cycles: zero-crossing interpolation error of a clean
    // cosine is below 1e-5 of a cycle per crossing.
    for b in &blocks {
        assert!((b.frequency_hz - f0).abs() < 1e-3, "{} Hz", b.frequency_hz);
    }
}

#[test]
fn block_averaging_reduces_the_error_as_one_over_root_samples() {
    let (fs, f0, sigma) = (10_000.0, 97.3, 0.05);
    let (reference, response) = record(f0, 0.0, fs, 4.0, sigma, 2);
    let options = SyncOptions { n_harmonics: N, cycles_per_block: 20, skip_cycles: 3 };
    let blocks = extract(&reference, &[("y", &response)], fs, &options).unwrap();
    let n = 20.0 * fs / f0;
    let expected = sigma * (2.0 / n).sqrt();
    let got = rms_error(&blocks);
    assert!(got < 3.0 * expected && got > expected / 3.0, "rms error {got:.3e}, expected {expected:.3e}");
}

#[test]
fn swept_sine_harmonics_follow_the_reference_phase() {
    // 1 Hz/s (the paper's rate in the friction range): the linear phase within a cycle is wrong by
    // at most ḟ/(8f²) = 1e-5 cycle, negligible against the noise error σ√(2/n) = 1.4e-3.
    let (fs, f0, sigma) = (10_000.0, 95.0, 0.01);
    let (reference, response) = record(f0, 1.0, fs, 6.0, sigma, 3);
    let blocks = extract(&reference, &[("y", &response)], fs, &SyncOptions::per_cycle(N)).unwrap();
    let n = fs / 98.0;
    let expected = sigma * (2.0 / n).sqrt();
    let got = rms_error(&blocks);
    assert!(got < 3.0 * expected && got > expected / 3.0, "rms error {got:.3e}, expected {expected:.3e}");
    // Each block's frequency is the sweep's instantaneous frequency at the block's middle
    // (exact for a linear sweep), to the zero-crossing interpolation error.
    for b in &blocks {
        let f_mid = f0 + 0.5 * (b.start_s + b.end_s);
        assert!((b.frequency_hz - f_mid).abs() < 2e-3, "{} vs {f_mid} Hz", b.frequency_hz);
    }
}

#[test]
fn reference_becomes_a_pure_cosine_of_its_amplitude() {
    let fs = 8_000.0;
    let n = 16_000;
    let reference: Vec<f64> = (0..n).map(|j| 3.0 * (2.0 * PI * 50.0 * j as f64 / fs - 0.7).cos() + 0.4).collect();
    let blocks = extract(&reference, &[], fs, &SyncOptions::whole_record(3, 1)).unwrap();
    let r = &blocks[0].reference;
    // Noise-free and band-limited: the fit is exact to rounding (1e-9 of the amplitude).
    let h1 = complex_harmonic(r, 1);
    assert!((h1.re - 3.0).abs() < 1e-9 && h1.im.abs() < 1e-9, "{h1}");
    assert!((r[0] - 0.4).abs() < 1e-9);
}

#[test]
fn period_frames_reassemble_points_recorded_at_different_times() {
    // Three points, each recorded separately with its own reference (the scanning vibrometer): the
    // motion of point i is a_i cos(θ + φ_i) + b_i cos(3θ), θ the excitation phase. Each record
    // starts at a different excitation phase; the frames must show the common period.
    let (fs, f) = (20_000.0, 210.0);
    let points = [(1.0, 0.0, 0.1), (0.5, 1.0, -0.2), (2.0, -2.5, 0.3)];
    let mut coeffs = Vec::new();
    for (i, &(a, phi, b)) in points.iter().enumerate() {
        let start = 0.37 * i as f64 + 0.1;
        let th = |j: usize| 2.0 * PI * f * j as f64 / fs + start;
        let reference: Vec<f64> = (0..4000).map(|j| th(j).cos()).collect();
        let v: Vec<f64> = (0..4000).map(|j| a * (th(j) + phi).cos() + b * (3.0 * th(j)).cos()).collect();
        let blocks = extract(&reference, &[("v", &v)], fs, &SyncOptions::whole_record(3, 0)).unwrap();
        coeffs.push(blocks[0].responses[0].clone());
    }
    let frames = period::frames(&coeffs, 9).unwrap();
    for (j, frame) in frames.iter().enumerate() {
        let th = 2.0 * PI * j as f64 / 9.0;
        for (i, &(a, phi, b)) in points.iter().enumerate() {
            let exact = a * (th + phi).cos() + b * (3.0 * th).cos();
            // Noise-free fit: exact to the zero-crossing interpolation error (~1e-6 rad).
            assert!((frame[i] - exact).abs() < 1e-5, "frame {j} point {i}: {} vs {exact}", frame[i]);
        }
    }
    // Velocity a cos θ → displacement a sin θ / Ω.
    let d = period::integrate(&[0.0, 2.0, 0.0], 10.0).unwrap();
    assert_eq!(d, vec![0.0, -0.0, 0.2]);
}

#[test]
fn reference_noise_enters_through_the_reference_fit_only() {
    // A noisy reference (σ_r = 1 % of its amplitude) and a clean response of unit fundamental.
    // The zero-crossing jitter shifts each cycle's phase origin, but the rotation onto the
    // reference's own fitted fundamental removes that shift; what remains is the noise of that
    // fit, σ_r √(2/n) in phase (rad) per cycle of n samples, i.e. in h1 for a unit amplitude.
    let (fs, f, sigma_r) = (10_000.0, 97.3, 0.01);
    let mut noise = Gaussian::new(5);
    let n = 20_000;
    let th = |j: usize| 2.0 * PI * f * j as f64 / fs;
    let reference: Vec<f64> = (0..n).map(|j| th(j).cos() + sigma_r * noise.sample()).collect();
    let response: Vec<f64> = (0..n).map(|j| (th(j) + 0.3).cos()).collect();
    let blocks = extract(&reference, &[("y", &response)], fs, &SyncOptions::per_cycle(3)).unwrap();
    let exact = num_complex::Complex64::from_polar(1.0, 0.3);
    let rms = (blocks.iter().map(|b| (b.harmonic(0, 1) - exact).norm_sqr()).sum::<f64>() / blocks.len() as f64).sqrt();
    let expected = sigma_r * (2.0 * f / fs).sqrt();
    assert!(rms < 3.0 * expected && rms > expected / 3.0, "rms error {rms:.3e}, expected {expected:.3e}");
}
