//! One period of motion at many points, from records synchronised on the excitation phase (the
//! scanning-vibrometer "video" of paper Fig. 9).
//!
//! Each point is measured separately, each record with the excitation reference; the harmonics
//! of each point extracted on the reference phase ([`super::harmonics`], one block per record,
//! steady state assumed as in the paper) share one phase origin, so evaluating all of them at
//! the same phases θ_j = 2π j / n_frames gives the frames of one common period.

use super::SignalError;
use crate::hbm::fourier::{basis, cos_index, sin_index};

/// `frames[j][i]`: value of point `i` (coefficient vector `[c0, c1, s1, ...]`) at phase
/// `2π j / n_frames`. Points may have different numbers of harmonics.
pub fn frames(points: &[Vec<f64>], n_frames: usize) -> Result<Vec<Vec<f64>>, SignalError> {
    if n_frames == 0 {
        return Err(SignalError::NoFrames);
    }
    Ok((0..n_frames)
        .map(|j| {
            let theta = 2.0 * std::f64::consts::PI * j as f64 / n_frames as f64;
            points.iter().map(|c| c.iter().enumerate().map(|(m, v)| v * basis(m, theta)).sum()).collect()
        })
        .collect())
}

/// Harmonics of the time integral of a signal of fundamental `omega_rad_s` (velocity →
/// displacement, as for the vibrometer's velocities of Fig. 22): `∫ (c cos kθ + s sin kθ) dt =
/// (c sin kθ − s cos kθ) / (kΩ)`. The mean, undetermined, is set to zero.
pub fn integrate(coeffs: &[f64], omega_rad_s: f64) -> Result<Vec<f64>, SignalError> {
    if !(omega_rad_s.is_finite() && omega_rad_s > 0.0) {
        return Err(SignalError::NotPositive { what: "the circular frequency (rad/s)", value: omega_rad_s });
    }
    let mut out = vec![0.0; coeffs.len()];
    for k in 1..=(coeffs.len() - 1) / 2 {
        let kw = k as f64 * omega_rad_s;
        out[cos_index(k)] = -coeffs[sin_index(k)] / kw;
        out[sin_index(k)] = coeffs[cos_index(k)] / kw;
    }
    Ok(out)
}
