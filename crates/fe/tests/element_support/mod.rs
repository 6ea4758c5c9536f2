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

/// Lowest eigenvalue ω² of `(K, M)` outside the span of `deflate` (e.g. rigid-body motions),
/// by inverse iteration on a sparse Cholesky factor of `K + σ M` (σ ≥ 0 shifts a free
/// structure's zero eigenvalues away), the iterate kept M-orthogonal to `deflate`; returns the
/// Rayleigh quotient of the converged vector. Converges like `((λ1+σ)/(λ2+σ))^iterations`.
pub fn lowest_eigenvalue(model: &LinearModel, sigma: f64, deflate: &[Vec<f64>], iterations: usize) -> f64 {
    use stickslip_core::model::Matrix;
    let (Matrix::Sparse(k), Matrix::Sparse(m)) = (&model.stiffness, &model.mass) else {
        panic!("expected sparse K, M")
    };
    // M is stored without the zeros of K's pattern: the sum on the union of the two.
    let a = faer::sparse::ops::binary_op(k.as_ref(), m.as_ref(), |a, b| {
        a.copied().unwrap_or(0.0) + sigma * b.copied().unwrap_or(0.0)
    })
    .unwrap();
    let llt = a.sp_cholesky(Side::Lower).expect("K + σM positive definite");
    let n = model.n_dofs();
    // M-orthonormal deflation basis (Gram-Schmidt in the M inner product).
    let mut basis: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    let mut mv = vec![0.0; n];
    for v in deflate {
        let mut v = v.clone();
        for (b, mb) in &basis {
            let c: f64 = v.iter().zip(mb).map(|(x, y)| x * y).sum();
            v.iter_mut().zip(b).for_each(|(x, y)| *x -= c * y);
        }
        model.mass.mul_vec(&v, &mut mv);
        let norm = v.iter().zip(&mv).map(|(x, y)| x * y).sum::<f64>().sqrt();
        basis.push((v.iter().map(|x| x / norm).collect(), mv.iter().map(|x| x / norm).collect()));
    }
    let project = |x: &mut Vec<f64>| {
        for (b, mb) in &basis {
            let c: f64 = x.iter().zip(mb).map(|(p, q)| p * q).sum();
            x.iter_mut().zip(b).for_each(|(p, q)| *p -= c * q);
        }
    };
    let mut x: Vec<f64> = (0..n).map(|i| 1.0 + (i % 7) as f64 * 0.1).collect();
    project(&mut x);
    let mut mx = vec![0.0; n];
    let mut rhs = Mat::<f64>::zeros(n, 1);
    for _ in 0..iterations {
        model.mass.mul_vec(&x, &mut mx);
        for i in 0..n {
            rhs[(i, 0)] = mx[i];
        }
        llt.solve_in_place(rhs.as_mut());
        let norm = (0..n).map(|i| rhs[(i, 0)].powi(2)).sum::<f64>().sqrt();
        for i in 0..n {
            x[i] = rhs[(i, 0)] / norm;
        }
        project(&mut x);
    }
    model.stiffness.bilinear(&x, &x) / model.mass.bilinear(&x, &x)
}

/// All frequencies in Hz of a small model with positive definite K by a dense eigensolution
/// of `L⁻¹ M L⁻ᵀ` (`K = L Lᵀ`, eigenvalues 1/ω²): unlike `LinearModel::dense_modes` it accepts
/// a singular M (under-integrated C3D20R masses), whose zero eigenvalues are infinite
/// frequencies and are dropped.
pub fn dense_frequencies(model: &LinearModel) -> Vec<f64> {
    let k = model.stiffness.to_dense();
    let m = model.mass.to_dense();
    let llt = k.llt(Side::Lower).expect("K positive definite");
    let l = llt.L();
    let mut x = m.clone();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, x.as_mut(), faer::Par::Seq);
    let mut a = x.transpose().to_owned();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, a.as_mut(), faer::Par::Seq);
    let n = a.nrows();
    let a = Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    // Eigenvalues only: faer 0.24's `self_adjoint_eigen` (with vectors) returned a wrong lowest
    // eigenpair on a 270-DOF block (residual 1e-4 of |A|, frequency off by 8e-4), while
    // `self_adjoint_eigenvalues` and inverse iteration agree with CalculiX to 1e-9.
    let values = a.self_adjoint_eigenvalues(Side::Lower).expect("eigensolver");
    let top = values.iter().copied().fold(0.0f64, f64::max);
    let mut f: Vec<f64> = values
        .into_iter()
        .filter(|&mu| mu > 1e-13 * top)
        .map(|mu| (1.0 / mu).sqrt() / (2.0 * std::f64::consts::PI))
        .collect();
    f.sort_by(|a, b| a.partial_cmp(b).unwrap());
    f
}
