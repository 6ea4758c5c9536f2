//! Nonlinear modes of models with a damping matrix that is not diagonal in the undamped modes
//! (a dashpot across the structure, as measured damping matrices are): the condensed modes
//! are coupled to the target by `Φᵀ D Φ`. Checked against the diagonal path (a proportional
//! matrix), the quadratic eigenproblem of the linear limit, central differences and the energy
//! balance.
mod hbm_support;

use faer::{c64, Mat};
use hbm_support::*;
use stickslip_core::continuation::{Options, Silent, TerminationReason};
use stickslip_core::elements::{Element, Jenkins};
use stickslip_core::hbm::{
    nonlinear_mode, Backbone, HbmSettings, NegativeDamping, NonlinearMode, NonlinearModeSettings,
};
use stickslip_core::model::{Damping, Matrix, NonlinearModel};

const ALPHA: f64 = 3.0;
const BETA: f64 = 2.0e-5;

fn settings(negative_damping: NegativeDamping) -> NonlinearModeSettings {
    NonlinearModeSettings { mode: 0, hbm: HbmSettings { harmonics: 5, samples: 256 }, negative_damping }
}

/// Three masses, two Jenkins joints (to the ground, and between masses 1 and 2), with damping
/// `damping` built from the chain's M and K.
fn chain3(damping: impl Fn(&Mat<f64>, &Mat<f64>) -> Damping) -> NonlinearModel {
    let elements = || -> Vec<(&str, Box<dyn Element>, Vec<f64>)> {
        vec![
            ("ground", Box::new(Jenkins::replacing_stiffness(3.0e5, 40.0).unwrap()), vec![1.0, 0.0, 0.0]),
            ("link", Box::new(Jenkins::replacing_stiffness(2.0e5, 28.0).unwrap()), vec![0.0, 1.0, -1.0]),
        ]
    };
    let probe = chain(3, Damping::None, elements());
    let (m, k) = (probe.linear.mass.to_dense(), probe.linear.stiffness.to_dense());
    chain(3, damping(&m, &k), elements())
}

/// Rayleigh damping written out as a matrix: the coupled path with a C that is diagonal.
fn rayleigh_matrix(m: &Mat<f64>, k: &Mat<f64>) -> Damping {
    Damping::Matrix(Matrix::Dense(Mat::from_fn(3, 3, |i, j| ALPHA * m[(i, j)] + BETA * k[(i, j)])))
}

/// Rayleigh damping plus a dashpot of 60 N·s/m between masses 0 and 2: `Φᵀ D Φ` is full
/// (its off-diagonal entries measured up to 40 % of the diagonal ones).
fn dashpot_across(m: &Mat<f64>, k: &Mat<f64>) -> Damping {
    let c = 60.0;
    let dashpot = |i: usize, j: usize| match (i, j) {
        (0, 0) | (2, 2) => c,
        (0, 2) | (2, 0) => -c,
        _ => 0.0,
    };
    Damping::Matrix(Matrix::Dense(Mat::from_fn(3, 3, |i, j| ALPHA * m[(i, j)] + BETA * k[(i, j)] + dashpot(i, j))))
}

fn backbone(model: &NonlinearModel, negative_damping: NegativeDamping) -> Backbone {
    nonlinear_mode(model, &settings(negative_damping), 1e-5, 1e-2, &[], &Options::default(), &mut Silent).unwrap()
}

/// ln a, Ω and ζ of a backbone's points.
fn curves(b: &Backbone) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    (
        b.points.iter().map(|p| p.amplitude.ln()).collect(),
        b.points.iter().map(|p| p.omega).collect(),
        b.points.iter().map(|p| p.damping_ratio()).collect(),
    )
}

fn interpolate(xs: &[f64], ys: &[f64], x0: f64) -> f64 {
    let i = xs.windows(2).position(|w| w[0] <= x0 && x0 <= w[1]).expect("inside the backbone");
    let t = (x0 - xs[i]) / (xs[i + 1] - xs[i]);
    ys[i] + t * (ys[i + 1] - ys[i])
}

#[test]
fn a_proportional_damping_matrix_gives_the_rayleigh_backbone() {
    // The same damping, once as Rayleigh (the modal sum) and once as a matrix (the coupled
    // path: a complex LU of the other modes per harmonic, C diagonal only up to round-off).
    for negative_damping in [NegativeDamping::MassProportional, NegativeDamping::TargetMode] {
        let modal = backbone(&chain3(|_, _| Damping::Rayleigh { alpha: ALPHA, beta: BETA }), negative_damping);
        let matrix = backbone(&chain3(rayleigh_matrix), negative_damping);
        assert_eq!(modal.termination, TerminationReason::ReachedEnd);
        assert_eq!(matrix.termination, TerminationReason::ReachedEnd);
        let (la, wa, za) = curves(&modal);
        let (mut ew, mut ez) = (0.0f64, 0.0f64);
        for p in &matrix.points {
            let l = p.amplitude.ln().clamp(la[0], la[la.len() - 1]);
            ew = ew.max((p.omega / interpolate(&la, &wa, l) - 1.0).abs());
            ez = ez.max((p.damping_ratio() / interpolate(&la, &za, l) - 1.0).abs());
        }
        eprintln!(
            "{negative_damping:?}: {} and {} points, frequency {ew:.2e}, ζ {ez:.2e}",
            modal.points.len(),
            matrix.points.len()
        );
        // Both solve one balance and take the same steps (30 points each): the difference is
        // round-off, measured 2.2e-16 in frequency and 1.4e-15 in ζ. Asserted 1e-9: a coupled
        // path wrong by a part in a billion fails.
        assert_eq!(modal.points.len(), matrix.points.len());
        assert!(ew < 1e-9 && ez < 1e-9, "{negative_damping:?}: {ew:e} {ez:e}");
        assert!((matrix.linear_omega / modal.linear_omega - 1.0).abs() < 1e-12);
    }
}

#[test]
fn the_linear_limit_is_an_undamped_eigenvalue_of_the_shifted_system() {
    // With every joint stuck, EPMC's periodic motion is an eigenvector of
    // λ² M + λ (D − ξ S) + K with λ = iΩ exactly (S = M, or M φ φᵀ M on the target only).
    // Checked on the first-order companion matrix's spectrum, computed independently (dense
    // eigenvalues of a 6 × 6 matrix): one eigenvalue lies on the imaginary axis at Ω.
    let model = chain3(dashpot_across);
    let (m, k) = (model.linear.mass.to_dense(), model.linear.stiffness.to_dense());
    let Damping::Matrix(d) = &model.linear.damping else { unreachable!() };
    let d = d.to_dense();
    let modes = model.linear.dense_modes().unwrap();
    for negative_damping in [NegativeDamping::MassProportional, NegativeDamping::TargetMode] {
        let problem = NonlinearMode::new(&model, &settings(negative_damping)).unwrap();
        let (omega, xi) = problem.linear_limit();
        let phi = modes.shapes.col(0);
        let mphi: Vec<f64> = (0..3).map(|i| (0..3).map(|j| m[(i, j)] * phi[j]).sum()).collect();
        let s = |i: usize, j: usize| match negative_damping {
            NegativeDamping::MassProportional => m[(i, j)],
            NegativeDamping::TargetMode => mphi[i] * mphi[j],
        };
        // A = [0 I; −M⁻¹K −M⁻¹(D − ξS)]: M is diagonal here.
        let a = Mat::from_fn(6, 6, |i, j| match (i < 3, j < 3) {
            (true, true) => 0.0,
            (true, false) => f64::from(j - 3 == i),
            (false, true) => -k[(i - 3, j)] / m[(i - 3, i - 3)],
            (false, false) => -(d[(i - 3, j - 3)] - xi * s(i - 3, j - 3)) / m[(i - 3, i - 3)],
        });
        let eigenvalues: Vec<c64> = a.eigenvalues().unwrap();
        let nearest = eigenvalues.iter().map(|l| (*l - c64::new(0.0, omega)).norm()).fold(f64::INFINITY, f64::min);
        // The undamped mode's own (ω_*, c_*) is off by the coupling (measured 3.0e-7 in the
        // damping ratio, 3.3e-8 in frequency): 300 times the tolerance below, so the test
        // tells the linear limit from the undamped mode.
        let off = (problem.linear_omega() / omega - 1.0)
            .abs()
            .max((problem.linear_damping_ratio() / (xi / (2.0 * omega)) - 1.0).abs());
        eprintln!("{negative_damping:?}: Ω = {omega:.9} rad/s, ξ = {xi:.6} 1/s; nearest eigenvalue {nearest:.2e} rad/s; undamped mode {off:.2e} off");
        // Newton on z_1(Ω, ξ) = 0 to 1e-15; the eigenvalues to round-off of a matrix of norm
        // ~ω²: asserted 1e-9 of Ω.
        assert!(nearest < 1e-9 * omega, "{negative_damping:?}: {nearest:e}");
        assert!(off > 1e-7, "the dashpot should move the linear limit: {off:e}");
    }
}

#[test]
fn jacobian_matches_central_differences_with_a_damping_matrix() {
    let model = chain3(dashpot_across);
    for negative_damping in [NegativeDamping::MassProportional, NegativeDamping::TargetMode] {
        let mut p = NonlinearMode::new(&model, &settings(negative_damping)).unwrap();
        let mut y = p.linear_guess();
        for (i, v) in y.iter_mut().enumerate() {
            *v += 0.01 * (i as f64 * 1.7).sin();
        }
        let (worst, scale) = jacobian_against_central_differences(&mut p, &y, -3.7, 1e-6);
        eprintln!(
            "{negative_damping:?}: worst |analytic − central difference| {:.2e} of the largest entry",
            worst / scale
        );
        // As the diagonal path's test: central differences with h = 1e-6 on a piecewise-smooth
        // AFT (no stick/slip switch within ±h at this point); asserted 1e-6.
        assert!(worst < 1e-6 * scale, "{negative_damping:?}: {:e}", worst / scale);
    }
}

#[test]
fn energy_balances_with_a_damping_matrix() {
    // The work of −ξ S U̇ equals the viscous (full Φᵀ D Φ) and friction dissipation of the
    // recovered motion at every point, joints slipping over part of the cycle.
    let model = chain3(dashpot_across);
    for negative_damping in [NegativeDamping::MassProportional, NegativeDamping::TargetMode] {
        let b = backbone(&model, negative_damping);
        assert_eq!(b.termination, TerminationReason::ReachedEnd, "{negative_damping:?}");
        let last = b.points.last().unwrap();
        assert!(last.stick_fraction.iter().any(|&f| f < 0.9), "{:?}", last.stick_fraction);
        let worst = b.points.iter().map(|p| (p.energy_per_cycle / p.supplied_energy - 1.0).abs()).fold(0.0, f64::max);
        eprintln!(
            "{negative_damping:?}: {} points, ζ {:.4} → up to {:.4}, energy balance {worst:.2e}",
            b.points.len(),
            b.linear_damping_ratio,
            b.points.iter().map(|p| p.damping_ratio()).fold(0.0, f64::max)
        );
        assert!(worst < 1e-8, "{negative_damping:?}: {worst:e}");
        // The first point is the linear limit, not the undamped mode's (ω_*, c_*).
        let first = &b.points[0];
        assert!((first.omega / b.linear_omega - 1.0).abs() < 1e-9);
    }
}
