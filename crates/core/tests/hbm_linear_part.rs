//! The linear part of the harmonic balance with its parameter derivatives
//! ([`ModalReceptance::matrix_with`]): the receptance of the model with damping `α M + β K`
//! added equals a direct solve of `Vᵀ Z(ω)⁻¹ V` with that damping matrix (an independent
//! method: one complex LU of the dense dynamic stiffness), and its derivatives with respect to
//! ω, α and β equal central differences.
#[path = "../benches/common/mod.rs"]
mod common;

use faer::{c64, Mat};
use stickslip_core::hbm::{HarmonicReceptance, LinearParameter, LinearVariation, Receptance};
use stickslip_core::model::{Damping, LinearModel, Matrix};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;
const PARAMETERS: [LinearParameter; 3] =
    [LinearParameter::Frequency, LinearParameter::MassDamping, LinearParameter::StiffnessDamping];

/// The paper-like chain of 20 DOFs (first mode 238 Hz, D = αM) and its 4 joint directions.
fn chain() -> (LinearModel, Vec<Vec<f64>>) {
    let model = common::chain_with_joints(20, 4, false);
    let directions = model.application_vectors().cloned().collect();
    (model.linear, directions)
}

fn largest(m: &Mat<c64>) -> f64 {
    m.col_iter().flat_map(|c| c.iter().map(|v| v.norm()).collect::<Vec<_>>()).fold(0.0, f64::max)
}

fn distance(a: &Mat<c64>, b: &Mat<c64>) -> f64 {
    let d = Mat::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)] - b[(i, j)]);
    largest(&d) / largest(b)
}

fn matrix_with(receptance: &Receptance, omega: f64, variation: &LinearVariation) -> (Mat<c64>, [Mat<c64>; 3]) {
    let Receptance::Modal(modal) = receptance else { panic!("modal damping") };
    let q = receptance.n_directions();
    let mut h = Mat::zeros(q, q);
    let mut d = [Mat::zeros(q, q), Mat::zeros(q, q), Mat::zeros(q, q)];
    let [d0, d1, d2] = &mut d;
    modal.matrix_with(omega, variation, &PARAMETERS, h.as_mut(), &mut [d0.as_mut(), d1.as_mut(), d2.as_mut()]);
    (h, d)
}

#[test]
fn added_damping_equals_a_direct_solve_with_that_damping_matrix() {
    let (model, directions) = chain();
    let dirs: Vec<&[f64]> = directions.iter().map(|v| v.as_slice()).collect();
    let n = model.n_dofs();
    let receptance = Receptance::new(&model, &dirs, &vec![0.0; n]).unwrap();
    let Damping::Rayleigh { alpha, beta } = model.damping else { panic!("Rayleigh") };
    let (added_alpha, added_beta) = (-0.7 * alpha, 2e-6);
    let variation = LinearVariation { mass_damping: added_alpha, stiffness_damping: added_beta, without_mode: None };
    // D = (α + Δα) M + (β + Δβ) K as a matrix: the direct receptance, one LU per frequency.
    let (m, k) = (model.mass.to_dense(), model.stiffness.to_dense());
    let d = Mat::from_fn(n, n, |i, j| (alpha + added_alpha) * m[(i, j)] + (beta + added_beta) * k[(i, j)]);
    let direct_model = LinearModel::new(
        Matrix::Dense(m.clone()),
        Matrix::Dense(k.clone()),
        Damping::Matrix(Matrix::Dense(d)),
        model.dofs.clone(),
        vec![],
    )
    .unwrap();
    let direct = Receptance::new(&direct_model, &dirs, &vec![0.0; n]).unwrap();
    assert!(matches!(direct, Receptance::Direct(_)));
    let mut worst: f64 = 0.0;
    // Off resonance and at the first resonance, where the damping decides the value.
    for hz in [50.0, 238.0, 700.0, 2100.0] {
        let omega = TWO_PI * hz;
        let (h, _) = matrix_with(&receptance, omega, &variation);
        let mut hr = HarmonicReceptance::new(dirs.len());
        direct.evaluate_matrix(omega, &mut hr);
        worst = worst.max(distance(&h, &hr.h));
    }
    // Two exact representations of one matrix: the LU of a 20 × 20 dynamic stiffness (condition
    // ~1e4 near resonance) against the modal sum, each to round-off: measured 8e-13.
    assert!(worst <= 1e-11, "modal with added damping against direct: {worst:e}");
}

#[test]
fn without_the_variation_it_is_the_forced_balance_receptance() {
    let (model, directions) = chain();
    let dirs: Vec<&[f64]> = directions.iter().map(|v| v.as_slice()).collect();
    let receptance = Receptance::new(&model, &dirs, &vec![0.0; model.n_dofs()]).unwrap();
    let omega = TWO_PI * 241.0;
    let (h, [dh, _, _]) = matrix_with(&receptance, omega, &LinearVariation::default());
    let mut hr = HarmonicReceptance::new(dirs.len());
    receptance.evaluate_matrix(omega, &mut hr);
    // The same modal sums in another order (the forced balance's are vectorised by partial
    // sums): round-off, measured 2e-16; asserted 1e-13.
    assert!(distance(&h, &hr.h) <= 1e-13, "{:e}", distance(&h, &hr.h));
    let dh_forced = receptance.derivative_matrix(&hr);
    assert!(distance(&dh, &dh_forced) <= 1e-13, "{:e}", distance(&dh, &dh_forced));

    // Leaving a mode out removes exactly its term a_r a_rᵀ / den_r.
    let Receptance::Modal(modal) = &receptance else { panic!("modal") };
    let r = 0;
    let (h_rest, _) =
        matrix_with(&receptance, omega, &LinearVariation { without_mode: Some(r), ..LinearVariation::default() });
    let (w, c) = (modal.natural_frequencies()[r], modal.damping_coefficients()[r]);
    let den = c64::new(w * w - omega * omega, omega * c);
    let a = modal.participation();
    let added = Mat::from_fn(h.nrows(), h.ncols(), |i, j| h_rest[(i, j)] + a[(i, r)] * a[(j, r)] / den);
    // Near the first resonance the left-out term dominates: the sum cancels to round-off of it.
    assert!(distance(&added, &h) <= 1e-13, "{:e}", distance(&added, &h));
}

#[test]
fn parameter_derivatives_equal_central_differences() {
    let (model, directions) = chain();
    let dirs: Vec<&[f64]> = directions.iter().map(|v| v.as_slice()).collect();
    let receptance = Receptance::new(&model, &dirs, &vec![0.0; model.n_dofs()]).unwrap();
    let base = LinearVariation { mass_damping: -10.0, stiffness_damping: 1e-6, without_mode: Some(1) };
    for hz in [120.0, 236.0, 900.0] {
        let omega = TWO_PI * hz;
        let (_, derivatives) = matrix_with(&receptance, omega, &base);
        // Near a resonance H varies on the scale of its half-power width c/2 ≈ 10 rad/s (c =
        // α − 10 ≈ 20 1/s here), so the truncation of a central difference is ~(h/(c/2))²;
        // away from it the damping derivatives are small against H (|∂H/∂α| ~ ω/|den| |H|), so
        // the round-off ε|H|/(h |∂H/∂α|) asks for larger steps. 1.5e-3 rad/s in ω, 1e-3 1/s
        // in α and 1e-9 s in β (β ω_1² ≈ 2e-3 1/s): measured ≤ 1e-8; asserted 1e-7.
        let steps = [1e-6 * omega, 1e-3, 1e-9];
        for (p, (analytic, h)) in derivatives.iter().zip(steps).enumerate() {
            let shifted = |sign: f64| {
                let mut v = base;
                let mut w = omega;
                match p {
                    0 => w += sign * h,
                    1 => v.mass_damping += sign * h,
                    _ => v.stiffness_damping += sign * h,
                }
                matrix_with(&receptance, w, &v).0
            };
            let (plus, minus) = (shifted(1.0), shifted(-1.0));
            let numeric = Mat::from_fn(plus.nrows(), plus.ncols(), |i, j| (plus[(i, j)] - minus[(i, j)]) / (2.0 * h));
            let error = distance(analytic, &numeric);
            assert!(error <= 1e-7, "{hz} Hz, {:?}: {error:e}", PARAMETERS[p]);
        }
    }
}
