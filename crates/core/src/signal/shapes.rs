//! Correlation of shape vectors: DAC (paper Eq. 2) and MAC.

use num_complex::Complex64;

use super::SignalError;

/// Deformation shape correlation of paper Eq. 2, in percent, between a measured and a computed
/// real shape (same points, same order):
/// `DAC = 100 |ψ_expᵀ ψ_fem|² / (|ψ_femᵀ ψ_fem| |ψ_expᵀ ψ_exp|)`.
pub fn dac(experimental: &[f64], numerical: &[f64]) -> Result<f64, SignalError> {
    if experimental.len() != numerical.len() {
        return Err(SignalError::ShapeLength { left: experimental.len(), right: numerical.len() });
    }
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let ee = dot(experimental, experimental);
    let ff = dot(numerical, numerical);
    if ee == 0.0 || ff == 0.0 {
        return Err(SignalError::ZeroShape);
    }
    Ok(100.0 * dot(experimental, numerical).powi(2) / (ff * ee))
}

/// Modal assurance criterion between complex shapes, in [0, 1]:
/// `MAC = |ψ_aᴴ ψ_b|² / ((ψ_aᴴ ψ_a)(ψ_bᴴ ψ_b))` (the Hermitian form, so that a shape and the same
/// shape times any complex scalar correlate to 1). For real shapes `MAC = DAC / 100`.
pub fn mac(a: &[Complex64], b: &[Complex64]) -> Result<f64, SignalError> {
    if a.len() != b.len() {
        return Err(SignalError::ShapeLength { left: a.len(), right: b.len() });
    }
    let aa: f64 = a.iter().map(|z| z.norm_sqr()).sum();
    let bb: f64 = b.iter().map(|z| z.norm_sqr()).sum();
    if aa == 0.0 || bb == 0.0 {
        return Err(SignalError::ZeroShape);
    }
    let ab: Complex64 = a.iter().zip(b).map(|(x, y)| x.conj() * y).sum();
    Ok(ab.norm_sqr() / (aa * bb))
}
