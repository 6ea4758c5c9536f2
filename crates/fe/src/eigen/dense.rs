//! Dense symmetric eigendecomposition of the small projected matrices (Rayleigh-Ritz), checked.
//!
//! faer 0.24's `self_adjoint_eigen` can return accurate eigenvalues with inaccurate
//! eigenvectors: measured on the Rayleigh-Ritz matrices of the block Lanczos (288 × 288),
//! `‖S u − θ u‖ / |θ|` of 4e-6 for wanted Ritz pairs, which after a thick restart left the
//! Ritz residuals stalled near 1e-8. Each decomposition is therefore checked and, when its
//! residual exceeds round-off, recomputed from the SVD (another algorithm): for symmetric S,
//! `S = U Σ Vᵀ` with `v_i = ±u_i`, the eigenvalue being `σ_i (u_i · v_i)`.
use faer::{Mat, MatRef, Side};

/// Eigenvalues (in no particular order) and orthonormal eigenvectors of the symmetric `s`
/// (only its lower triangle is read by the first attempt; pass it symmetrised). `None` when
/// neither algorithm converges to round-off.
pub(crate) fn symmetric_eigen(s: MatRef<'_, f64>) -> Option<(Vec<f64>, Mat<f64>)> {
    let n = s.nrows();
    if let Ok(evd) = s.self_adjoint_eigen(Side::Lower) {
        let theta: Vec<f64> = (0..n).map(|i| evd.S()[i]).collect();
        let u = evd.U().to_owned();
        if accurate(s, &theta, u.as_ref()) {
            return Some((theta, u));
        }
    }
    let svd = s.svd().ok()?;
    let (u, v) = (svd.U(), svd.V());
    let theta: Vec<f64> = (0..n)
        .map(|i| {
            let sign: f64 = (0..n).map(|r| u[(r, i)] * v[(r, i)]).sum();
            svd.S()[i] * sign.signum()
        })
        .collect();
    let u = u.to_owned();
    accurate(s, &theta, u.as_ref()).then_some((theta, u))
}

/// `‖S u_i − θ_i u_i‖ ≤ 1e-12 ‖S‖` for every pair (‖S‖ the largest |θ|): the backward error of
/// a stable symmetric eigensolver is a small multiple of n ε ‖S‖.
fn accurate(s: MatRef<'_, f64>, theta: &[f64], u: MatRef<'_, f64>) -> bool {
    let n = s.nrows();
    let norm = theta.iter().fold(0.0f64, |a, t| a.max(t.abs()));
    let su = s * u;
    let tolerance = 1e-12 * norm.max(f64::MIN_POSITIVE);
    (0..n).all(|c| {
        let r2: f64 = (0..n).map(|r| (su[(r, c)] - theta[c] * u[(r, c)]).powi(2)).sum();
        r2.sqrt() <= tolerance && theta[c].is_finite()
    })
}

#[cfg(test)]
mod tests {
    use faer::Mat;

    #[test]
    fn reproduces_a_known_spectrum() {
        // Q diag(λ) Qᵀ with Q a product of plane rotations: exact eigenpairs known.
        let n = 40;
        let lambda: Vec<f64> = (0..n).map(|i| if i % 7 == 3 { -(i as f64) } else { 1.0 / (1.0 + i as f64) }).collect();
        let mut q = Mat::<f64>::identity(n, n);
        for k in 0..n - 1 {
            let (c, s) = ((0.3 + k as f64).cos(), (0.3 + k as f64).sin());
            for r in 0..n {
                let (a, b) = (q[(r, k)], q[(r, k + 1)]);
                q[(r, k)] = c * a - s * b;
                q[(r, k + 1)] = s * a + c * b;
            }
        }
        let d = Mat::<f64>::from_fn(n, n, |i, j| if i == j { lambda[i] } else { 0.0 });
        let a = &q * &d * q.transpose();
        let a = Mat::<f64>::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
        let (mut theta, _) = super::symmetric_eigen(a.as_ref()).unwrap();
        let mut exact = lambda.clone();
        theta.sort_by(f64::total_cmp);
        exact.sort_by(f64::total_cmp);
        for (t, e) in theta.iter().zip(&exact) {
            // Backward-stable solvers: absolute error a few ε ‖A‖ (‖A‖ = 39 here).
            assert!((t - e).abs() < 1e-12, "{t} vs {e}");
        }
    }
}
