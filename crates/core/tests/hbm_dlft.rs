//! DLFT (rigid unilateral contact with friction) against the penalty contact with growing
//! stiffness, on the 2-DOF model of timesim_contact.rs made rigid.
use faer::linalg::solvers::Solve;
use faer::Mat;
use stickslip_core::elements::Contact;
use stickslip_core::hbm::dlft::{DlftHbm, RigidContact};
use stickslip_core::hbm::fourier::{cos_index, sin_index};
use stickslip_core::hbm::{AftPlan, CondensedHbm, HbmSettings, Jacobians};
use stickslip_core::model::{relative_direction, Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

/// x (tangential) and y (normal approach), 1 kg and 1e6 N/m each, 20 N·s/m; forced in phase,
/// 40 N on x and 60 N on y. Rigidly held at rest, the normal load N0 + 60 cos Ωt (N0 = 50 N)
/// opens the contact around cos Ωt = −1, and the tangential reaction reaches μN (μ = 0.4)
/// before that: stick, slip and separation in every period.
fn linear() -> LinearModel {
    let diag = |v: [f64; 2]| Matrix::Dense(Mat::from_fn(2, 2, |i, j| if i == j { v[i] } else { 0.0 }));
    LinearModel::new(
        diag([1.0, 1.0]),
        diag([1e6, 1e6]),
        Damping::Matrix(diag([20.0, 20.0])),
        vec![DofLabel::named("x"), DofLabel::named("y")],
        vec![],
    )
    .unwrap()
}

const FORCE: [f64; 2] = [40.0, 60.0];
const MU: f64 = 0.4;
const N0: f64 = 50.0;

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|a| a * a).sum::<f64>().sqrt()
}

#[test]
fn penalty_contact_converges_to_dlft_as_its_stiffness_grows() {
    let settings = HbmSettings { harmonics: 7, samples: 512 };
    let nc = 2 * settings.harmonics + 1;
    let omega = TWO_PI * 120.0;
    let contacts = [RigidContact {
        name: "c".into(),
        directions: vec![relative_direction(2, 0, None), relative_direction(2, 1, None)],
        friction: MU,
        preload: N0,
    }];
    let lin = linear();
    let eps = DlftHbm::default_epsilon(&lin, &contacts, &FORCE, omega).unwrap();
    let mut solutions: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    for factor in [1.0, 3.0] {
        let mut dlft = DlftHbm::new(&lin, &contacts, &FORCE, settings, factor * eps).unwrap();
        let x0 = solutions.last().map_or_else(|| vec![1e-9; dlft.dimension()], |s| s.0.clone());
        let (x, it) = dlft.solve(omega, 1.0, &x0, 1e-12, 100).unwrap();
        println!("DLFT ε = {:.3e}: {it} iterations, |x| = {:.4e}", factor * eps, norm(&x));
        solutions.push((x, dlft.contact_forces().to_vec()));
    }
    let (x_dlft, lambda) = &solutions[0];
    let de = norm(&solutions[1].0.iter().zip(x_dlft).map(|(a, b)| a - b).collect::<Vec<_>>()) / norm(x_dlft);
    println!("DLFT: ε × 10 changes the solution by {de:.2e}");
    // The regime: the normal force (N − N0 harmonics → samples) reaches −N0 (open) and the
    // tangential force μN somewhere.
    let plan = AftPlan::new(settings.harmonics, settings.samples).unwrap();
    let mut scratch = plan.scratch();
    let (mut tn, mut tt) = (vec![0.0; 512], vec![0.0; 512]);
    let pick = |a: usize| (0..nc).map(|c| lambda[c * 2 + a]).collect::<Vec<_>>();
    plan.synthesize(&pick(0), &mut tt, &mut scratch);
    plan.synthesize(&pick(1), &mut tn, &mut scratch);
    let open = tn.iter().filter(|g| **g + N0 < 0.05 * N0).count();
    println!("open (N < 5 % N0) on {open}/512 samples");
    assert!(open > 0, "the contact never opens");

    let mut errors = Vec::new();
    for k in [1e7, 1e8, 1e9] {
        let site = ElementSite {
            name: "c".into(),
            law: Box::new(Contact::new_2d(k, k, MU, N0).unwrap()),
            directions: vec![relative_direction(2, 0, None), relative_direction(2, 1, None)],
        };
        let model = NonlinearModel::new(linear(), vec![site]).unwrap();
        let mut hbm = CondensedHbm::new(&model, &FORCE, settings).unwrap();
        let x = damped_newton(&mut hbm, omega, 1.0, x_dlft);
        let diff: Vec<f64> = x.iter().zip(x_dlft).map(|(a, b)| a - b).collect();
        let e = norm(&diff) / norm(x_dlft);
        let h1 = |v: &[f64]| v[cos_index(1) * 2].hypot(v[sin_index(1) * 2]);
        println!(
            "penalty k = {k:.0e}: |x − x_DLFT|/|x_DLFT| = {e:.3e}, harmonic 1 of x {:.5e} vs {:.5e}",
            h1(&x),
            h1(x_dlft)
        );
        errors.push(e);
    }
    println!("{errors:?}");
    // The penalty solution approaches the rigid one as 1/k: ×10 in k divides the gap by ~10.
    assert!(errors[2] < errors[1] / 5.0 && errors[1] < errors[0] / 5.0, "{errors:?}");
    assert!(errors[2] < 1e-2, "{errors:?}");
    assert!(de < 1e-6, "ε changes the DLFT solution by {de:.2e}");
}

/// Newton on the penalty balance with the step halved while it does not reduce ‖R‖: a stiff
/// unilateral contact makes the residual kink at every sample's open/close switch, where full
/// steps cycle.
fn damped_newton(hbm: &mut CondensedHbm<'_>, omega: f64, level: f64, x0: &[f64]) -> Vec<f64> {
    let n = hbm.dimension();
    let (mut x, mut trial) = (x0.to_vec(), x0.to_vec());
    let (mut r, mut jac) = (vec![0.0; n], Mat::zeros(n, n));
    for _ in 0..200 {
        hbm.evaluate(&x, omega, level, &mut r, Some(Jacobians { dx: jac.as_mut(), domega: None, dlevel: None }))
            .unwrap();
        let r_norm = norm(&r);
        if r_norm <= 1e-12 * norm(&x) {
            return x;
        }
        let dx = jac.partial_piv_lu().solve(Mat::from_fn(n, 1, |i, _| r[i]));
        let mut step = 1.0;
        for _ in 0..12 {
            for i in 0..n {
                trial[i] = x[i] - step * dx[(i, 0)];
            }
            hbm.evaluate(&trial, omega, level, &mut r, None).unwrap();
            if norm(&r) < r_norm {
                break;
            }
            step *= 0.5;
        }
        x.copy_from_slice(&trial);
    }
    panic!("penalty balance not converged at level {level}: {:.2e}", norm(&r) / norm(&x));
}
