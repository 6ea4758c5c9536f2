//! The nonlinear mode's balance does not allocate: with damping diagonal in the modes (the
//! modal-sum path every reduced model with Rayleigh or modal damping takes), a residual and
//! Jacobian evaluation runs on buffers allocated when the problem is set up. Counted by a
//! global allocator, in its own test binary.

use faer::Mat;
use stickslip_core::continuation::Problem;
use stickslip_core::elements::{Element, Jenkins};
use stickslip_core::hbm::{HbmSettings, NegativeDamping, NonlinearMode, NonlinearModeSettings};
use stickslip_core::model::{Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel};

mod allocation_counter;
use allocation_counter::allocations;

/// A 3-DOF chain with Rayleigh damping and two Jenkins joints (to the ground, and between
/// masses 1 and 2).
fn chain3() -> NonlinearModel {
    let dense = |f: &dyn Fn(usize, usize) -> f64| Matrix::Dense(Mat::from_fn(3, 3, f));
    let k = 1.0e6;
    let stiffness = |i: usize, j: usize| match i.abs_diff(j) {
        0 => 2.0 * k,
        1 => -k,
        _ => 0.0,
    };
    let linear = LinearModel::new(
        dense(&|i, j| if i == j { 1.0 + 0.1 * i as f64 } else { 0.0 }),
        dense(&stiffness),
        Damping::Rayleigh { alpha: 3.0, beta: 2.0e-5 },
        (0..3).map(|i| DofLabel::named(format!("x{i}"))).collect(),
        vec![],
    )
    .unwrap();
    let site =
        |name: &str, law: Box<dyn Element>, v: Vec<f64>| ElementSite { name: name.into(), law, directions: vec![v] };
    let sites = vec![
        site("ground", Box::new(Jenkins::replacing_stiffness(3.0e5, 40.0).unwrap()), vec![1.0, 0.0, 0.0]),
        site("link", Box::new(Jenkins::replacing_stiffness(2.0e5, 28.0).unwrap()), vec![0.0, 1.0, -1.0]),
    ];
    NonlinearModel::new(linear, sites).unwrap()
}

#[test]
fn evaluations_of_the_balance_do_not_allocate() {
    let model = chain3();
    for negative_damping in [NegativeDamping::MassProportional, NegativeDamping::TargetMode] {
        let settings =
            NonlinearModeSettings { mode: 0, hbm: HbmSettings { harmonics: 5, samples: 256 }, negative_damping };
        let mut p = NonlinearMode::new(&model, &settings).unwrap();
        let n = p.dimension();
        let mut y = p.linear_guess();
        for (i, v) in y.iter_mut().enumerate() {
            *v += 0.01 * (i as f64 * 1.7).sin();
        }
        let (mut r, mut jac, mut dl) = (vec![0.0; n], Mat::zeros(n, n), vec![0.0; n]);
        // The joints slip at this point (a motion of 10^-3.7 m·√kg); a first evaluation may
        // size what it keeps.
        p.evaluate(&y, -3.7, &mut r, Some((jac.as_mut(), &mut dl))).unwrap();
        let before = allocations();
        for lambda in [-3.7, -3.6, -3.5] {
            p.evaluate(&y, lambda, &mut r, None).unwrap();
            p.evaluate(&y, lambda, &mut r, Some((jac.as_mut(), &mut dl))).unwrap();
        }
        assert_eq!(allocations() - before, 0, "{negative_damping:?}: six evaluations allocated");
    }
}
