//! Models shared by the harmonic balance tests.
#![allow(dead_code)]

use faer::Mat;
use stickslip_core::elements::{Element, Jenkins};
use stickslip_core::model::{Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel};

pub const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

/// Table 6 (/work/shared/reference/table6-jenkins.toml).
pub const MASS: f64 = 10.0;
pub const K_TOTAL: f64 = 2.24e7;
pub const K_JENKINS: f64 = 8.11e6;
pub const DAMPING: f64 = 350.0;
pub const F_COULOMB: f64 = 1000.0;
pub const F_EXCIT: f64 = 1000.0;

pub fn dense(n: usize, f: impl Fn(usize, usize) -> f64) -> Matrix {
    Matrix::Dense(Mat::from_fn(n, n, f))
}

/// The 1-DOF system of Fig. 15 (left) in the paper's form: K holds the total stuck stiffness,
/// the Jenkins element replaces its part k_J. The dashpot is `D = (d/M) M`, Rayleigh, unless
/// `damping_matrix` asks for the same D as an explicit matrix (direct receptance path).
pub fn table6_1dof(threshold: f64, damping_matrix: bool) -> NonlinearModel {
    let damping = if damping_matrix {
        Damping::Matrix(dense(1, |_, _| DAMPING))
    } else {
        Damping::Rayleigh { alpha: DAMPING / MASS, beta: 0.0 }
    };
    let linear =
        LinearModel::new(dense(1, |_, _| MASS), dense(1, |_, _| K_TOTAL), damping, vec![DofLabel::named("M")], vec![])
            .unwrap();
    let law: Box<dyn Element> = Box::new(Jenkins::replacing_stiffness(K_JENKINS, threshold).unwrap());
    NonlinearModel::new(linear, vec![ElementSite { name: "slider".into(), law, directions: vec![vec![1.0]] }]).unwrap()
}

/// A chain of `n` masses with springs between neighbours and to the ground at both ends,
/// plus the given elements placed by (name, law, application vector).
pub fn chain(n: usize, damping: Damping, elements: Vec<(&str, Box<dyn Element>, Vec<f64>)>) -> NonlinearModel {
    let mass = dense(n, |i, j| if i == j { 1.0 + 0.1 * i as f64 } else { 0.0 });
    let k = 1.0e6;
    let stiffness = dense(n, |i, j| {
        if i == j {
            2.0 * k * (1.0 + 0.05 * i as f64)
        } else if i.abs_diff(j) == 1 {
            -k * (1.0 + 0.05 * i.min(j) as f64)
        } else {
            0.0
        }
    });
    // Make K symmetric and diagonally dominant (springs to ground at both ends and mild grading).
    let kd = stiffness.to_dense();
    let stiffness = dense(n, |i, j| 0.5 * (kd[(i, j)] + kd[(j, i)]));
    let linear =
        LinearModel::new(mass, stiffness, damping, (0..n).map(|i| DofLabel::named(format!("x{i}"))).collect(), vec![])
            .unwrap();
    let sites = elements
        .into_iter()
        .map(|(name, law, v)| ElementSite { name: name.into(), law, directions: vec![v] })
        .collect();
    NonlinearModel::new(linear, sites).unwrap()
}

/// Jenkins describing function (first harmonic of the force for u = A cos θ,
/// /work/shared/reference/jenkins-closed-form.md): complex stiffness ν = (a1 − i b1)/A.
pub fn jenkins_describing_function(k: f64, fc: f64, a: f64) -> (f64, f64) {
    if k * a <= fc {
        return (k, 0.0);
    }
    let th = (1.0 - 2.0 * fc / (k * a)).acos();
    let re = k / std::f64::consts::PI * (th - th.sin() * th.cos());
    let im = 4.0 * fc / (std::f64::consts::PI * a) * (1.0 - fc / (k * a));
    (re, im)
}

/// Solutions of the 1-DOF Jenkins oscillator by the describing function (the N = 1 balance
/// solved in closed form up to a scalar root): |k − k_J + ν(A) − MΩ² + i(Ωd + ν_i(A))| A = F.
/// Every root on 1e-8..1 m (log scan + bisection), each as (A, c1, s1) with x = c1 cos + s1 sin.
pub fn describing_function_solutions(omega: f64, fc: f64) -> Vec<(f64, f64, f64)> {
    let z = |a: f64| {
        let (nr, ni) = jenkins_describing_function(K_JENKINS, fc, a);
        (K_TOTAL - K_JENKINS + nr - MASS * omega * omega, omega * DAMPING + ni)
    };
    let phi = |a: f64| {
        let (re, im) = z(a);
        re.hypot(im) * a - F_EXCIT
    };
    let grid: Vec<f64> = (0..=4000).map(|i| 1e-8 * 10f64.powf(8.0 * i as f64 / 4000.0)).collect();
    let mut roots = Vec::new();
    for w in grid.windows(2) {
        let (mut lo, mut hi) = (w[0], w[1]);
        if phi(lo) * phi(hi) > 0.0 {
            continue;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if phi(lo) * phi(mid) <= 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let a = 0.5 * (lo + hi);
        // X = F / Z(A): c1 − i s1 = F (re − i im) / |Z|².
        let (re, im) = z(a);
        let d = re * re + im * im;
        roots.push((a, F_EXCIT * re / d, F_EXCIT * im / d));
    }
    roots
}

pub fn norm(v: &[f64]) -> f64 {
    v.iter().map(|a| a * a).sum::<f64>().sqrt()
}

/// Relative distance between the full (2N+1)n balance's solution and `recovered`, the full
/// unknowns recovered from a condensed solution (Eq. 27): Newton on the full balance from
/// `recovered` perturbed by 1 %, asserted converged (‖R‖ < 1e-9 of the level).
pub fn full_balance_distance(
    model: &NonlinearModel,
    force: &[f64],
    settings: stickslip_core::hbm::HbmSettings,
    omega: f64,
    level: f64,
    recovered: &[f64],
    max_iterations: usize,
) -> f64 {
    use faer::linalg::solvers::Solve;
    let mut full = stickslip_core::hbm::FullHbm::new(model, force, settings).unwrap();
    let dim = full.dimension();
    let mut x: Vec<f64> = recovered.iter().map(|v| v * 1.01).collect();
    let mut r = vec![0.0; dim];
    let mut j = Mat::zeros(dim, dim);
    for _ in 0..max_iterations {
        full.evaluate(&x, omega, level, &mut r, Some(j.as_mut())).unwrap();
        let dx = j.partial_piv_lu().solve(Mat::from_fn(dim, 1, |i, _| r[i]));
        for i in 0..dim {
            x[i] -= dx[(i, 0)];
        }
        if norm(&(0..dim).map(|i| dx[(i, 0)]).collect::<Vec<_>>()) < 1e-15 * norm(&x) {
            break;
        }
    }
    full.evaluate(&x, omega, level, &mut r, None).unwrap();
    assert!(norm(&r) < 1e-9 * level, "full balance not converged: {:.2e}", norm(&r));
    let diff: Vec<f64> = x.iter().zip(recovered).map(|(a, b)| a - b).collect();
    norm(&diff) / norm(&x)
}

/// The worst difference between the analytic Jacobian of `problem` at `(y, λ)` (the unknowns'
/// columns, then the λ-column) and central differences of step `h`, with the largest entry of
/// the analytic Jacobian: `(worst, largest)`.
pub fn jacobian_against_central_differences<P: stickslip_core::continuation::Problem>(
    problem: &mut P,
    y: &[f64],
    lambda: f64,
    h: f64,
) -> (f64, f64) {
    let n = problem.dimension();
    let (mut r, mut jac, mut dl) = (vec![0.0; n], Mat::zeros(n, n), vec![0.0; n]);
    problem.evaluate(y, lambda, &mut r, Some((jac.as_mut(), &mut dl))).unwrap();
    let largest = (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).fold(0.0f64, |m, (i, j)| m.max(jac[(i, j)].abs()));
    let (mut rp, mut rm) = (vec![0.0; n], vec![0.0; n]);
    let mut worst = 0.0f64;
    for j in 0..=n {
        let (mut yp, mut ym) = (y.to_vec(), y.to_vec());
        let (mut lp, mut lm) = (lambda, lambda);
        if j < n {
            yp[j] += h;
            ym[j] -= h;
        } else {
            lp += h;
            lm -= h;
        }
        problem.evaluate(&yp, lp, &mut rp, None).unwrap();
        problem.evaluate(&ym, lm, &mut rm, None).unwrap();
        for i in 0..n {
            let fd = (rp[i] - rm[i]) / (2.0 * h);
            let an = if j < n { jac[(i, j)] } else { dl[i] };
            worst = worst.max((fd - an).abs());
        }
    }
    (worst, largest)
}
