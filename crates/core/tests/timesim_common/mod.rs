//! Models and closed forms shared by the time-integration tests.
#![allow(dead_code)]

use faer::linalg::solvers::Solve;
use faer::{c64, Mat};
use stickslip_core::elements::{Element, Jenkins};
use stickslip_core::model::{relative_direction, Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel};

/// Table 6 (paper Section 4.4, /work/shared/reference/table6-jenkins.toml): 1-DOF.
pub const MASS: f64 = 10.0;
pub const K_TOTAL: f64 = 2.24e7;
pub const K_JENKINS: f64 = 8.11e6;
pub const DAMPING: f64 = 350.0;
pub const F_COULOMB: f64 = 1000.0;
pub const F_EXCIT: f64 = 1000.0;

/// The Table 6 1-DOF model in the paper's form (Eq. 11): K holds the total stuck stiffness
/// and the Jenkins element replaces its part `k_jenkins`.
pub fn table6() -> NonlinearModel {
    table6_with(Damping::Matrix(Matrix::Dense(Mat::from_fn(1, 1, |_, _| DAMPING))))
}

/// Table 6 with its damping written as `damping` (e.g. α M, the same 350 N·s/m in modal form).
pub fn table6_with(damping: Damping) -> NonlinearModel {
    let linear = LinearModel::new(
        Matrix::Dense(Mat::from_fn(1, 1, |_, _| MASS)),
        Matrix::Dense(Mat::from_fn(1, 1, |_, _| K_TOTAL)),
        damping,
        vec![DofLabel::named("x")],
        vec![],
    )
    .unwrap();
    let law = Jenkins::replacing_stiffness(K_JENKINS, F_COULOMB).unwrap();
    NonlinearModel::new(
        linear,
        vec![ElementSite { name: "joint".into(), law: Box::new(law), directions: vec![vec![1.0]] }],
    )
    .unwrap()
}

/// A fixed-free chain of `n` masses `m` joined by springs `k` (the first to the ground), with
/// Rayleigh damping `alpha M + beta K` and the given elements `(law, dof i, dof j or ground)`.
pub fn chain(
    n: usize,
    m: f64,
    k: f64,
    alpha: f64,
    beta: f64,
    elements: Vec<(Box<dyn Element>, usize, Option<usize>)>,
) -> NonlinearModel {
    let mass = Mat::from_fn(n, n, |i, j| if i == j { m } else { 0.0 });
    let stiff = Mat::from_fn(n, n, |i, j| {
        if i == j {
            if i + 1 < n {
                2.0 * k
            } else {
                k
            }
        } else if i.abs_diff(j) == 1 {
            -k
        } else {
            0.0
        }
    });
    let linear = LinearModel::new(
        Matrix::Dense(mass),
        Matrix::Dense(stiff),
        Damping::Rayleigh { alpha, beta },
        (0..n).map(|i| DofLabel::named(format!("x{i}"))).collect(),
        vec![],
    )
    .unwrap();
    let sites = elements
        .into_iter()
        .enumerate()
        .map(|(e, (law, i, j))| ElementSite {
            name: format!("joint{e}"),
            law,
            directions: vec![relative_direction(n, i, j)],
        })
        .collect();
    NonlinearModel::new(linear, sites).unwrap()
}

/// Exact harmonic response `(K − Ω² M + iΩ D)⁻¹ F` of the linear part, D given dense.
pub fn harmonic_response(model: &LinearModel, d: &Mat<f64>, omega: f64, load: &[f64]) -> Vec<c64> {
    discrete_response(model, d, load, |_| {
        (c64::new(omega * omega, 0.0), c64::new(0.0, omega), c64::new(1.0, 0.0), c64::new(1.0, 0.0))
    })
}

/// Steady response of a linear model under a general per-sample transfer: given the
/// coefficients `(a, v, w, e)` of `M·(a U)·(−1) ...`, solves `(w (K + v D) − a M) U = e F`.
/// (`a = Ω², v = iΩ, w = e = 1` is the exact response.)
pub fn discrete_response(
    model: &LinearModel,
    d: &Mat<f64>,
    load: &[f64],
    coefficients: impl Fn(()) -> (c64, c64, c64, c64),
) -> Vec<c64> {
    let (a2, v, w, e) = coefficients(());
    let n = model.n_dofs();
    let m = model.mass.to_dense();
    let k = model.stiffness.to_dense();
    let a = Mat::<c64>::from_fn(n, n, |i, j| w * (c64::new(k[(i, j)], 0.0) + v * d[(i, j)]) - a2 * m[(i, j)]);
    let rhs = Mat::<c64>::from_fn(n, 1, |i, _| e * load[i]);
    let x = a.partial_piv_lu().solve(&rhs);
    (0..n).map(|i| x[(i, 0)]).collect()
}

/// The steady response of Newmark/HHT to `F cos Ωt` sampled at `t_n = n h`, from the
/// scheme's recurrences with `u_n = Re(U zⁿ)`, `z = e^{iΩh}`:
/// `U(z−1) = h V + h²((½−β) + βz) A`, `V(z−1) = h((1−γ) + γz) A`, and
/// `A + (1 + α − α/z)(D V + K U) = z^α F` (HHT writes the force at `t_{n+1} + αh`).
pub fn newmark_response(model: &LinearModel, d: &Mat<f64>, omega: f64, h: f64, alpha: f64, load: &[f64]) -> Vec<c64> {
    let beta = (1.0 - alpha) * (1.0 - alpha) / 4.0;
    let gamma = 0.5 - alpha;
    let z = c64::cis(omega * h);
    let one = c64::new(1.0, 0.0);
    // A = s_a U, V = s_v U.
    let ratio_av = (z - one) / (h * ((1.0 - gamma) * one + gamma * z)); // A = ratio_av V
    let s_v = (z - one) / (h * one + h * h * ((0.5 - beta) * one + beta * z) * ratio_av);
    let s_a = ratio_av * s_v;
    let weight = (1.0 + alpha) * one - alpha / z;
    let e = c64::cis(alpha * omega * h);
    discrete_response(model, d, load, |_| (-s_a, s_v, weight, e))
}

/// Jenkins first-harmonic coefficients under `u = a cos θ` (jenkins-closed-form.md):
/// `(k_eq a, b1)` with `f ≈ a1 cos θ + b1 sin θ`.
pub fn jenkins_first_harmonic(k: f64, fc: f64, a: f64) -> (f64, f64) {
    if k * a <= fc {
        return (k * a, 0.0);
    }
    let theta = (1.0 - 2.0 * fc / (k * a)).acos();
    let a1 = a * k / std::f64::consts::PI * (theta - theta.sin() * theta.cos());
    let b1 = -4.0 * fc / std::f64::consts::PI * (1.0 - fc / (k * a));
    (a1, b1)
}

/// Energy dissipated per cycle by a Jenkins element whose displacement has one maximum and one
/// minimum per cycle, half peak-to-peak `a` (Masing: the loop depends only on the extremes).
pub fn jenkins_dissipation(k: f64, fc: f64, a: f64) -> f64 {
    if k * a <= fc {
        0.0
    } else {
        4.0 * fc * (a - fc / k)
    }
}

/// Describing-function (N = 1 harmonic balance) amplitudes of the Table 6 1-DOF model at
/// circular frequency `omega`: every root `a` of
/// `[(K − k_J + a1/a − Ω²M)² + (ΩD − b1/a)²] a² = F²`, found on a fine logarithmic grid and
/// refined by bisection.
pub fn table6_describing_function(omega: f64) -> Vec<f64> {
    let residual = |a: f64| {
        let (a1, b1) = jenkins_first_harmonic(K_JENKINS, F_COULOMB, a);
        let re = (K_TOTAL - K_JENKINS - omega * omega * MASS) * a + a1;
        let im = omega * DAMPING * a - b1;
        re.hypot(im) - F_EXCIT
    };
    let mut roots = Vec::new();
    let (lo, hi, steps) = (1e-7f64, 1e-2f64, 20000);
    let mut prev = (lo, residual(lo));
    for i in 1..=steps {
        let a = lo * (hi / lo).powf(i as f64 / steps as f64);
        let r = residual(a);
        if r.signum() != prev.1.signum() {
            let (mut x0, mut x1) = (prev.0, a);
            for _ in 0..200 {
                let xm = 0.5 * (x0 + x1);
                if residual(xm).signum() == residual(x0).signum() {
                    x0 = xm;
                } else {
                    x1 = xm;
                }
            }
            roots.push(0.5 * (x0 + x1));
        }
        prev = (a, r);
    }
    roots
}
