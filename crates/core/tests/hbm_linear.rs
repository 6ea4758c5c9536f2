//! Without slip the harmonic balance is the linear FRF (K − Ω²M + iΩD)⁻¹F, for any N.
mod hbm_support;

use faer::linalg::solvers::Solve;
use faer::{c64, Mat};
use hbm_support::*;
use stickslip_core::elements::{Element, Jenkins};
use stickslip_core::hbm::fourier::{cos_index, sin_index};
use stickslip_core::hbm::{CondensedHbm, FullHbm, HbmSettings, Jacobians};
use stickslip_core::model::{relative_direction, Damping, NonlinearModel};
use stickslip_core::post::{evaluate_point, OutputSelector};

const N: usize = 6;

fn damped_models() -> Vec<(&'static str, NonlinearModel)> {
    let dmat = dense(N, |i, j| {
        if i == j {
            30.0 + i as f64
        } else if i.abs_diff(j) == 1 {
            -10.0
        } else {
            0.0
        }
    });
    [
        ("rayleigh", Damping::Rayleigh { alpha: 20.0, beta: 2e-6 }),
        ("modal", Damping::Modal { ratios: vec![0.01, 0.02, 0.015] }),
        ("matrix", Damping::Matrix(dmat)),
    ]
    .into_iter()
    .map(|(name, d)| {
        // A paper-form Jenkins that never slips (threshold 1e9 N) is exactly the stuck model.
        let law: Box<dyn Element> = Box::new(Jenkins::replacing_stiffness(5e5, 1e9).unwrap());
        (name, chain(N, d, vec![("joint", law, relative_direction(N, 1, Some(2)))]))
    })
    .collect()
}

/// (K − Ω²M + iΩD)⁻¹ F by a dense complex solve.
fn exact_frf(model: &NonlinearModel, omega: f64, force: &[f64]) -> Vec<c64> {
    let lin = &model.linear;
    let modes = if lin.damping.is_modal() { Some(lin.dense_modes().unwrap()) } else { None };
    let (m, k, d) = (lin.mass.to_dense(), lin.stiffness.to_dense(), lin.damping_dense(modes.as_ref()));
    let z = Mat::from_fn(N, N, |i, j| c64::new(k[(i, j)] - omega * omega * m[(i, j)], omega * d[(i, j)]));
    let f = Mat::from_fn(N, 1, |i, _| c64::new(force[i], 0.0));
    let u = z.partial_piv_lu().solve(&f);
    (0..N).map(|i| u[(i, 0)]).collect()
}

#[test]
fn condensed_balance_without_slip_is_the_linear_frf() {
    let mut force = vec![0.0; N];
    force[N - 1] = 1.0;
    let outputs: Vec<OutputSelector> =
        (0..N).map(|i| OutputSelector { name: format!("x{i}"), vector: relative_direction(N, i, None) }).collect();
    for (name, model) in damped_models() {
        let modes = model.linear.dense_modes().unwrap();
        for &harmonics in &[1, 3, 7] {
            let mut hbm = CondensedHbm::new(&model, &force, HbmSettings { harmonics, samples: 64 }).unwrap();
            // Below, at and beyond the first resonance.
            for &scale in &[0.5, 0.99, 1.0, 2.21, 2.99] {
                let omega = scale * modes.omega[0];
                let level = 250.0;
                let x0 = vec![0.0; hbm.dimension()];
                let (x, _) = hbm.solve(omega, level, &x0, 1e-14, 10).unwrap();
                let p = evaluate_point(&mut hbm, &x, omega, level, &outputs).unwrap();
                let exact = exact_frf(&model, omega, &force);
                let scale_u = exact.iter().fold(0.0f64, |m, u| m.max(u.norm())) * level;
                for (o, e) in p.outputs.iter().zip(&exact) {
                    let got = c64::new(o.coeffs[cos_index(1)], -o.coeffs[sin_index(1)]);
                    let err = (got - e * level).norm() / scale_u;
                    assert!(err < 1e-9, "{name} N={harmonics} Ω={omega:.1}: {} off by {err:.2e}", o.name);
                    // No other harmonic is excited.
                    for c in (0..o.coeffs.len()).filter(|&c| c != cos_index(1) && c != sin_index(1)) {
                        assert!(o.coeffs[c].abs() < 1e-12 * scale_u, "{name} coefficient {c}");
                    }
                }
                assert!(p.energy_balance_error().abs() < 1e-9, "{name}: {:.2e}", p.energy_balance_error());
            }
        }
    }
}

#[test]
fn full_balance_without_elements_is_the_linear_frf() {
    let mut force = vec![0.0; N];
    force[0] = 1.0;
    force[3] = -0.5;
    for (name, model) in damped_models() {
        let linear_only = NonlinearModel::new(model.linear.clone(), vec![]).unwrap();
        for &harmonics in &[1, 4] {
            let mut full = FullHbm::new(&linear_only, &force, HbmSettings { harmonics, samples: 32 }).unwrap();
            let n = full.dimension();
            let omega = 900.0;
            // Linear: one Newton step from zero is exact.
            let mut r = vec![0.0; n];
            let mut j = Mat::zeros(n, n);
            full.evaluate(&vec![0.0; n], omega, 1.0, &mut r, Some(j.as_mut())).unwrap();
            let x = j.partial_piv_lu().solve(Mat::from_fn(n, 1, |i, _| -r[i]));
            let exact = exact_frf(&model, omega, &force);
            let scale = exact.iter().fold(0.0f64, |m, u| m.max(u.norm()));
            for i in 0..N {
                let got = c64::new(x[(cos_index(1) * N + i, 0)], -x[(sin_index(1) * N + i, 0)]);
                assert!((got - exact[i]).norm() < 1e-10 * scale, "{name} N={harmonics} DOF {i}");
            }
        }
    }
}

#[test]
fn condensed_jacobian_equals_finite_differences() {
    // The Jacobian of the whole condensed residual (receptance × element AFT), in ∂x and ∂Ω, on
    // a slipping state of three elements (stick-slip for the Jenkins, velocity dependence for the
    // damper).
    use stickslip_core::elements::{CubicSpring, RegularizedCoulomb};
    let laws: Vec<(&str, Box<dyn Element>, Vec<f64>)> = vec![
        ("j1", Box::new(Jenkins::replacing_stiffness(5e5, 40.0).unwrap()), relative_direction(N, 1, Some(2))),
        ("c1", Box::new(RegularizedCoulomb::new(20.0, 1e-3).unwrap()), relative_direction(N, 3, None)),
        ("k3", Box::new(CubicSpring::new(1e13).unwrap()), relative_direction(N, 4, Some(5))),
    ];
    let model = chain(N, Damping::Rayleigh { alpha: 10.0, beta: 1e-6 }, laws);
    let mut force = vec![0.0; N];
    force[N - 1] = 1.0;
    let mut hbm = CondensedHbm::new(&model, &force, HbmSettings { harmonics: 3, samples: 256 }).unwrap();
    let n = hbm.dimension();
    let omega = 700.0;
    let x: Vec<f64> = (0..n).map(|i| 2e-4 * ((i as f64 * 1.3).sin() + if i < 9 { 0.5 } else { 0.0 })).collect();
    let mut r = vec![0.0; n];
    let mut jx = Mat::zeros(n, n);
    let mut jw = vec![0.0; n];
    let mut jl = vec![0.0; n];
    hbm.evaluate(
        &x,
        omega,
        300.0,
        &mut r,
        Some(Jacobians { dx: jx.as_mut(), domega: Some(&mut jw), dlevel: Some(&mut jl) }),
    )
    .unwrap();
    let (mut rp, mut rm) = (vec![0.0; n], vec![0.0; n]);
    let jscale = (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).fold(0.0f64, |m, (i, j)| m.max(jx[(i, j)].abs()));
    let h = 1e-10;
    for col in 0..n {
        let mut xp = x.clone();
        xp[col] += h;
        hbm.evaluate(&xp, omega, 300.0, &mut rp, None).unwrap();
        let mut xm = x.clone();
        xm[col] -= h;
        hbm.evaluate(&xm, omega, 300.0, &mut rm, None).unwrap();
        for row in 0..n {
            let fd = (rp[row] - rm[row]) / (2.0 * h);
            assert!((fd - jx[(row, col)]).abs() < 1e-5 * jscale, "∂R{row}/∂x{col}: {fd} vs {}", jx[(row, col)]);
        }
    }
    let hw = 1e-4;
    hbm.evaluate(&x, omega + hw, 300.0, &mut rp, None).unwrap();
    hbm.evaluate(&x, omega - hw, 300.0, &mut rm, None).unwrap();
    let wscale = norm(&jw);
    for row in 0..n {
        let fd = (rp[row] - rm[row]) / (2.0 * hw);
        assert!((fd - jw[row]).abs() < 1e-5 * wscale, "∂R{row}/∂Ω: {fd} vs {}", jw[row]);
    }
    hbm.evaluate(&x, omega, 301.0, &mut rp, None).unwrap();
    hbm.evaluate(&x, omega, 299.0, &mut rm, None).unwrap();
    for row in 0..n {
        let fd = (rp[row] - rm[row]) / 2.0;
        assert!((fd - jl[row]).abs() < 1e-9 * norm(&jl), "∂R{row}/∂λ");
    }
}
