//! Helpers shared by the element and assembly tests: deterministic perturbations, dense and
//! sparse eigen solutions of small models.
#![allow(dead_code)]

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use stickslip_core::model::LinearModel;

/// Deterministic pseudo-random numbers in [−1, 1] (a 64-bit LCG), so tests are reproducible.
pub struct Lcg(pub u64);

impl Lcg {
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// Lowest eigenvalue ω² of `(K, M)` by inverse iteration on a sparse Cholesky factor of K,
/// with the Rayleigh quotient of the converged vector. Converges like `(λ1/λ2)^iterations`.
pub fn lowest_eigenvalue(model: &LinearModel, iterations: usize) -> f64 {
    let stickslip_core::model::Matrix::Sparse(k) = &model.stiffness else { panic!("expected a sparse K") };
    let llt = k.sp_cholesky(Side::Lower).expect("K positive definite");
    let n = model.n_dofs();
    let mut x = Mat::<f64>::from_fn(n, 1, |i, _| 1.0 + (i % 7) as f64 * 0.1);
    let mut mx = vec![0.0; n];
    for _ in 0..iterations {
        let xv: Vec<f64> = (0..n).map(|i| x[(i, 0)]).collect();
        model.mass.mul_vec(&xv, &mut mx);
        let mut rhs = Mat::<f64>::from_fn(n, 1, |i, _| mx[i]);
        llt.solve_in_place(rhs.as_mut());
        let norm = (0..n).map(|i| rhs[(i, 0)].powi(2)).sum::<f64>().sqrt();
        x = Mat::from_fn(n, 1, |i, _| rhs[(i, 0)] / norm);
    }
    let xv: Vec<f64> = (0..n).map(|i| x[(i, 0)]).collect();
    model.stiffness.bilinear(&xv, &xv) / model.mass.bilinear(&xv, &xv)
}

/// All frequencies in Hz of a small model by the dense eigensolution.
pub fn dense_frequencies(model: &LinearModel) -> Vec<f64> {
    model.dense_modes().expect("dense modes").frequencies_hz()
}
