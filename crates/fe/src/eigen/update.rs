//! Shift-invert of a stiffness changed by a few rank-one terms, from the factorisation of the
//! unchanged one (Sherman-Morrison-Woodbury): the modes of the structure with its joints
//! released (Zucca & Epureanu, the paper's ref. [30]), `K − Σ_j k_j d_j d_jᵀ`, without a second
//! factorisation of a model of hundreds of thousands of DOFs.
//!
//! With `A = K − σM`, `U = [d_j]`, `C = diag(k_j)`:
//! `(A − U C Uᵀ)⁻¹ = A⁻¹ + A⁻¹ U S⁻¹ Uᵀ A⁻¹`, `S = C⁻¹ − Uᵀ A⁻¹ U` (r × r), and by Haynsworth's
//! inertia additivity the eigenvalues below σ number those of A plus the negative eigenvalues
//! of S (C is positive). For a stiff connector `S` is a difference of two nearly equal
//! compliances (1/k_j and the compliance across the connector): on Harmony's 1e10 N/m contacts
//! it keeps ~1e-3 of 1/k_j, three of sixteen digits lost; the modes' true residuals with the
//! released stiffness are checked by the solver as for any other operator.
use faer::{Mat, MatMut};
use stickslip_core::model::symmetric_eigen;

use super::{EigenError, ShiftInvert, ShiftedFactor};

/// `(K − σM − Σ_j k_j d_j d_jᵀ)⁻¹` from the factorisation of `K − σM`.
pub struct LowRankUpdate<'a> {
    base: &'a ShiftedFactor,
    /// The directions `d_j`, one per column.
    u: Mat<f64>,
    /// The `k_j`.
    stiffness: Vec<f64>,
    /// `A⁻¹ U`.
    a_inv_u: Mat<f64>,
    /// `S⁻¹`.
    s_inv: Mat<f64>,
    below: usize,
}

impl<'a> LowRankUpdate<'a> {
    /// The update removing `stiffness[j] d_j d_jᵀ` (`directions` column j) from the factored
    /// matrix. Errors (`Singular`) when the changed matrix is singular to working precision
    /// (the release opens a mechanism at σ): factorise `K − Σ k_j d_j d_jᵀ` at another shift.
    pub fn new(base: &'a ShiftedFactor, directions: Mat<f64>, stiffness: &[f64]) -> Result<Self, EigenError> {
        let r = directions.ncols();
        assert!(
            directions.nrows() == base.n() && stiffness.len() == r,
            "expected {} rows and {r} stiffnesses, got {} and {}",
            base.n(),
            directions.nrows(),
            stiffness.len()
        );
        let mut a_inv_u = directions.clone();
        base.solve_in_place(a_inv_u.as_mut());
        let uau = directions.transpose() * &a_inv_u;
        let s = Mat::<f64>::from_fn(r, r, |i, j| {
            let c_inv = if i == j { 1.0 / stiffness[i] } else { 0.0 };
            c_inv - 0.5 * (uau[(i, j)] + uau[(j, i)])
        });
        let singular = || EigenError::Singular { shift: base.shift(), dof: None };
        let (mu, q) = symmetric_eigen(s.as_ref()).ok_or_else(singular)?;
        // An eigenvalue of S at round-off of the compliances 1/k_j: S is singular, and so is
        // the changed matrix.
        let scale = stiffness.iter().map(|k| 1.0 / k).fold(0.0, f64::max);
        if mu.iter().any(|m| m.is_nan() || m.abs() <= 1e-10 * scale) {
            return Err(singular());
        }
        let s_inv = Mat::<f64>::from_fn(r, r, |i, j| (0..r).map(|l| q[(i, l)] * q[(j, l)] / mu[l]).sum());
        let below = base.eigenvalues_below_shift() + mu.iter().filter(|m| **m < 0.0).count();
        Ok(LowRankUpdate { base, u: directions, stiffness: stiffness.to_vec(), a_inv_u, s_inv, below })
    }
}

impl LowRankUpdate<'_> {
    /// The directions `d_j` (columns) and the stiffnesses `k_j` removed.
    pub fn terms(&self) -> (faer::MatRef<'_, f64>, &[f64]) {
        (self.u.as_ref(), &self.stiffness)
    }
}

impl ShiftInvert for LowRankUpdate<'_> {
    fn shift(&self) -> f64 {
        self.base.shift()
    }

    fn eigenvalues_below_shift(&self) -> usize {
        self.below
    }

    fn solve_in_place(&self, mut rhs: MatMut<'_, f64>) {
        use faer::reborrow::{Reborrow, ReborrowMut};
        self.base.solve_in_place(rhs.rb_mut());
        let y = &self.s_inv * (self.u.transpose() * rhs.rb());
        // rhs += A⁻¹U y, accumulated in place (no n × b temporary).
        faer::linalg::matmul::matmul(
            rhs.rb_mut(),
            faer::Accum::Add,
            self.a_inv_u.as_ref(),
            y.as_ref(),
            1.0,
            faer::Par::Seq,
        );
    }
}
