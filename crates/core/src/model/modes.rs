use faer::{Mat, MatRef, Side};

use super::{Damping, LinearModel, Matrix, ModelError};

/// Undamped modes of `(K, M)`: `K φ_r = ω_r² M φ_r`, mass-normalised (`Φᵀ M Φ = I`), in
/// increasing frequency order.
#[derive(Clone, Debug)]
pub struct Modes {
    /// Circular frequencies ω_r in rad/s.
    pub omega: Vec<f64>,
    /// Mode shapes, one column per mode.
    pub shapes: Mat<f64>,
}

impl Modes {
    /// Frequencies in Hz.
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.omega.iter().map(|w| w / (2.0 * std::f64::consts::PI)).collect()
    }
}

impl LinearModel {
    /// All modes of the model by a dense generalised symmetric eigensolution: `M = L Lᵀ`
    /// (Cholesky), `L⁻¹ K L⁻ᵀ = Q Λ Qᵀ`, `Φ = L⁻ᵀ Q`. Meant for reduced or small models (the
    /// cost is O(n³)); FE-size models go through the sparse eigensolver of `stickslip-fe`.
    ///
    /// Errors when M is not positive definite or K has a non-positive eigenvalue (a rigid-body
    /// motion, which makes the static harmonic of the balance singular).
    pub fn dense_modes(&self) -> Result<Modes, ModelError> {
        let n = self.n_dofs();
        let m = self.mass.to_dense();
        let k = self.stiffness.to_dense();
        let llt = m.llt(Side::Lower).map_err(|_| ModelError::MassNotPositiveDefinite)?;
        // A = L⁻¹ K L⁻ᵀ: solve L X = K, then L Aᵀ = Xᵀ (A symmetric).
        let l = llt.L();
        let mut x = k.clone();
        faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, x.as_mut(), faer::Par::Seq);
        let mut a = x.transpose().to_owned();
        faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, a.as_mut(), faer::Par::Seq);
        // Symmetrise round-off before the symmetric eigensolver.
        let a = Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
        let (mut lambda, q) = symmetric_eigen(a.as_ref())
            .ok_or_else(|| ModelError::Invalid("the eigensolver of (K, M) did not converge to round-off".into()))?;
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| lambda[a].total_cmp(&lambda[b]));
        lambda = order.iter().map(|&i| lambda[i]).collect();
        let scale = lambda.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        if let Some(&lowest) = lambda.first() {
            // Eigenvalues below round-off of the largest are rigid-body modes.
            if lowest <= 1e-12 * scale {
                return Err(ModelError::StiffnessNotPositiveDefinite { lowest });
            }
        }
        let mut shapes = Mat::from_fn(n, n, |i, r| q[(i, order[r])]);
        faer::linalg::triangular_solve::solve_upper_triangular_in_place(l.transpose(), shapes.as_mut(), faer::Par::Seq);
        let (relative, r) = worst_residual(&k, &m, &lambda, &shapes);
        if relative > RESIDUAL_TOLERANCE {
            return Err(ModelError::Invalid(format!(
                "the dense eigensolution of (K, M) is inaccurate for mode {} ({:.4} Hz): residual {relative:.2e}; reduce the model or check its conditioning",
                r + 1,
                lambda[r].sqrt() / (2.0 * std::f64::consts::PI)
            )));
        }
        Ok(Modes { omega: lambda.iter().map(|l| l.sqrt()).collect(), shapes })
    }
}

/// Eigenvalues (in no particular order) and orthonormal eigenvectors of the symmetric `s`
/// (pass it symmetrised), checked: `‖S u_i − θ_i u_i‖ ≤ 1e-12 ‖S‖` for every pair, the
/// backward error of a stable symmetric eigensolver. `None` when that is not reached.
///
/// faer 0.24's `self_adjoint_eigen` (divide and conquer from 128 rows) can return inaccurate
/// eigenpairs: 8e-10 of ‖S‖ on the 137-DOF chain of the benchmarks, eigenvectors with a
/// residual of 0.44 on a 144-DOF hex20 cantilever, a negative eigenvalue of the positive
/// definite `L⁻¹ K L⁻ᵀ` of the 627-DOF example blade, `‖S u − θ u‖ / |θ|` of 4e-6 on the
/// Rayleigh-Ritz matrices of the block Lanczos (which stalled its thick restarts). The QR
/// algorithm, tried first up to `QR_UP_TO` (256) rows, gives 5e-15 on the chain. When the check
/// fails the pairs are recomputed by divide and conquer (up to that size), then from the SVD: for symmetric S,
/// `S = U Σ Vᵀ` with `v_i = ±u_i`, the eigenvalue being `σ_i (u_i · v_i)`.
pub fn symmetric_eigen(s: MatRef<'_, f64>) -> Option<(Vec<f64>, Mat<f64>)> {
    let n = s.nrows();
    // Up to `QR_UP_TO` rows the QR algorithm on the tridiagonal matrix first (faster there,
    // and accurate where divide and conquer was not), then divide and conquer; above, divide
    // and conquer alone (faer's QR left mode 1 of the 627-DOF example blade 1.6e-9 from the
    // Lanczos' where the SVD that follows agrees to 1e-10).
    let methods: &[Tridiagonal] = if n <= QR_UP_TO {
        &[Tridiagonal::Qr, Tridiagonal::DivideAndConquer]
    } else {
        &[Tridiagonal::DivideAndConquer]
    };
    for &method in methods {
        if let Some((theta, u)) = tridiagonal_eigen(s, method) {
            if eigenpairs_accurate(s, &theta, u.as_ref()) {
                return Some((theta, u));
            }
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
    eigenpairs_accurate(s, &theta, u.as_ref()).then_some((theta, u))
}

/// Rows up to which [`symmetric_eigen`] tries the QR algorithm first: measured faster than
/// divide and conquer at 137 rows (3.4 against 5.4 ms, one core), slower at 300 (20.5
/// against 17.1 ms).
const QR_UP_TO: usize = 256;

/// How faer diagonalises the tridiagonal matrix of a symmetric eigensolution.
#[derive(Clone, Copy)]
enum Tridiagonal {
    Qr,
    DivideAndConquer,
}

/// faer's symmetric eigensolver with the tridiagonal matrix diagonalised by `method` (faer's
/// default is divide and conquer from 128 rows).
fn tridiagonal_eigen(s: MatRef<'_, f64>, method: Tridiagonal) -> Option<(Vec<f64>, Mat<f64>)> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::evd::{self_adjoint_evd, self_adjoint_evd_scratch, ComputeEigenvectors, SelfAdjointEvdParams};
    let n = s.nrows();
    let par = faer::get_global_parallelism();
    let recursion_threshold = match method {
        Tridiagonal::Qr => usize::MAX,
        Tridiagonal::DivideAndConquer => 128,
    };
    let params = SelfAdjointEvdParams { recursion_threshold, ..faer::Auto::<f64>::auto() };
    let mut u = Mat::<f64>::zeros(n, n);
    let mut theta = faer::diag::Diag::<f64>::zeros(n);
    let mut scratch = MemBuffer::new(self_adjoint_evd_scratch::<f64>(n, ComputeEigenvectors::Yes, par, params.into()));
    self_adjoint_evd(s, theta.as_mut(), Some(u.as_mut()), par, MemStack::new(&mut scratch), params.into()).ok()?;
    Some(((0..n).map(|i| theta[i]).collect(), u))
}

fn eigenpairs_accurate(s: MatRef<'_, f64>, theta: &[f64], u: MatRef<'_, f64>) -> bool {
    let n = s.nrows();
    let norm = theta.iter().fold(0.0f64, |a, t| a.max(t.abs()));
    let su = s * u;
    let tolerance = 1e-12 * norm.max(f64::MIN_POSITIVE);
    (0..n).all(|c| {
        let r2: f64 = (0..n).map(|r| (su[(r, c)] - theta[c] * u[(r, c)]).powi(2)).sum();
        r2.sqrt() <= tolerance && theta[c].is_finite()
    })
}

/// Relative residual ‖Kφ − ω²Mφ‖ / ‖|K||φ|‖ accepted for a mode. A sound solution gives ~1e-14
/// on well-conditioned models and ~1e-8 on stiff chains (1e9 N/m links); a wrong eigenvector
/// gives 1e-5 to 1 (seen with faer 0.24's symmetric eigensolver).
const RESIDUAL_TOLERANCE: f64 = 1e-6;

/// Largest relative residual over the modes, and the mode where it is. The residual is
/// measured against ‖|K||φ|‖, the size of the terms that cancel in Kφ, which is the round-off
/// scale of the product itself: where light, stiffly held DOFs are kept (the nodes of a
/// contact patch), a low mode's Kφ cancels terms up to λ_max/λ_r times larger, and even its
/// exact shape would show a residual of ε λ_max/λ_r relative to ‖Kφ‖ (1e-5 for the 2.7 Hz
/// shaker mode of Harmony with its blade-tip patches). Where nothing cancels the two measures
/// are the same.
fn worst_residual(k: &Mat<f64>, m: &Mat<f64>, lambda: &[f64], shapes: &Mat<f64>) -> (f64, usize) {
    let kphi = k * shapes;
    let mphi = m * shapes;
    let n = k.nrows();
    let terms =
        Mat::from_fn(n, n, |i, j| k[(i, j)].abs()) * Mat::from_fn(n, shapes.ncols(), |i, r| shapes[(i, r)].abs());
    let mut worst = (0.0f64, 0);
    for r in 0..lambda.len() {
        let (mut res, mut norm) = (0.0f64, 0.0f64);
        for i in 0..n {
            res += (kphi[(i, r)] - lambda[r] * mphi[(i, r)]).powi(2);
            norm += terms[(i, r)].powi(2);
        }
        let relative = (res / norm).sqrt();
        if relative > worst.0 {
            worst = (relative, r);
        }
    }
    worst
}

impl super::NonlinearModel {
    /// The model in the coordinates of all its undamped modes, `U = Φ η` with `modes` from
    /// [`LinearModel::dense_modes`]: `M = I`, `K = diag(ω_r²)`, loads `Φᵀ f`, application
    /// vectors `Φᵀ v`, damping `Φᵀ D Φ` (diagonal for Rayleigh and modal damping, dense for a
    /// general matrix). Every response in physical coordinates is `Φ η`. The harmonic balance
    /// and the Newmark family are invariant under this change of coordinates; a time step of
    /// a diagonal model costs O(n q) instead of the O(n²) of a dense reduced model, which is
    /// what makes long swept sines affordable (10⁶-10⁷ steps).
    ///
    /// Errors when `modes` is not a full set (one mode per DOF).
    pub fn into_modal(self, modes: &Modes) -> Result<super::NonlinearModel, ModelError> {
        let n = self.linear.n_dofs();
        if modes.shapes.nrows() != n || modes.shapes.ncols() != n || modes.omega.len() != n {
            return Err(ModelError::Invalid(format!(
                "modal coordinates need all {n} modes of the model, got {} of length {}",
                modes.shapes.ncols(),
                modes.shapes.nrows()
            )));
        }
        let phi = &modes.shapes;
        let project = |v: &[f64]| -> Vec<f64> { (0..n).map(|r| (0..n).map(|i| phi[(i, r)] * v[i]).sum()).collect() };
        let lin = &self.linear;
        let damping = match &lin.damping {
            Damping::None => Damping::None,
            // Φᵀ (αM + βK) Φ = αI + β diag(ω²): the same law in the new coordinates.
            Damping::Rayleigh { alpha, beta } => Damping::Rayleigh { alpha: *alpha, beta: *beta },
            Damping::Modal { .. } => {
                let c: Vec<f64> =
                    (0..n).map(|r| lin.damping.modal_coefficient(r, modes.omega[r]).unwrap_or(0.0)).collect();
                Damping::Matrix(Matrix::from_diagonal(&c))
            }
            Damping::Matrix(d) => {
                let d = d.to_dense();
                let pdp = phi.transpose() * &d * phi;
                Damping::Matrix(Matrix::Dense(Mat::from_fn(n, n, |i, j| 0.5 * (pdp[(i, j)] + pdp[(j, i)]))))
            }
        };
        let stiffness: Vec<f64> = modes.omega.iter().map(|w| w * w).collect();
        let linear = LinearModel {
            mass: Matrix::from_diagonal(&vec![1.0; n]),
            stiffness: Matrix::from_diagonal(&stiffness),
            damping,
            dofs: (0..n).map(super::DofLabel::modal).collect(),
            loads: lin
                .loads
                .iter()
                .map(|l| super::NamedVector { name: l.name.clone(), values: project(&l.values) })
                .collect(),
        };
        let elements = self
            .elements
            .into_iter()
            .map(|e| super::ElementSite {
                directions: e.directions.iter().map(|v| project(v)).collect(),
                name: e.name,
                law: e.law,
            })
            .collect();
        super::NonlinearModel::new(linear, elements)
    }
}

#[cfg(test)]
mod tests {
    use faer::Mat;

    /// The benchmarks' 137-DOF fixed-free chain (`K / m`, tridiagonal), where faer's divide and
    /// conquer left 8e-10 of ‖S‖: the QR algorithm, tried first at this size, passes the
    /// round-off check alone, and its eigenvalues are the closed form
    /// `λ_j = 2 k/m (1 − cos((2j − 1)π/(2n + 1)))` to 1e-13 of the largest (round-off of a
    /// stable eigensolver, measured 2e-15).
    #[test]
    fn the_qr_algorithm_solves_the_stiff_chain_to_round_off() {
        let (n, k, m) = (137, 1.0e8, 0.5);
        let s = Mat::from_fn(n, n, |i, j| {
            let v = if i == j {
                if i + 1 < n {
                    2.0 * k
                } else {
                    k
                }
            } else if i.abs_diff(j) == 1 {
                -k
            } else {
                0.0
            };
            v / m
        });
        let (mut theta, u) = super::tridiagonal_eigen(s.as_ref(), super::Tridiagonal::Qr).unwrap();
        assert!(super::eigenpairs_accurate(s.as_ref(), &theta, u.as_ref()));
        theta.sort_by(f64::total_cmp);
        let pi = std::f64::consts::PI;
        let exact: Vec<f64> =
            (1..=n).map(|j| 2.0 * k / m * (1.0 - ((2 * j - 1) as f64 * pi / (2 * n + 1) as f64).cos())).collect();
        let largest = exact[n - 1];
        let worst = theta.iter().zip(&exact).map(|(a, b)| (a - b).abs() / largest).fold(0.0, f64::max);
        assert!(worst <= 1e-13, "eigenvalues {worst:.1e} of the largest from the closed form");
    }

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
