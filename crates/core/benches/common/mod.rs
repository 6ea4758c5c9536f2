//! Models shared by the harmonic balance benchmarks: dense matrices, the Table 6 oscillator and
//! the paper-size chain with joints.
#![allow(dead_code)]

use faer::Mat;
use stickslip_core::elements::{Element, Jenkins};
use stickslip_core::model::{
    relative_direction, stiffness_along, Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel,
};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

pub fn dense(n: usize, f: impl Fn(usize, usize) -> f64) -> Matrix {
    Matrix::Dense(Mat::from_fn(n, n, f))
}

/// Table 6 1-DOF (/work/shared/reference/table6-jenkins.toml), paper form.
pub fn table6() -> NonlinearModel {
    let linear = LinearModel::new(
        dense(1, |_, _| 10.0),
        dense(1, |_, _| 2.24e7),
        Damping::Rayleigh { alpha: 35.0, beta: 0.0 },
        vec![DofLabel::named("M")],
        vec![],
    )
    .unwrap();
    let law: Box<dyn Element> = Box::new(Jenkins::replacing_stiffness(8.11e6, 1000.0).unwrap());
    NonlinearModel::new(linear, vec![ElementSite { name: "joint".into(), law, directions: vec![vec![1.0]] }]).unwrap()
}

/// A chain of `n` masses (0.5 kg, 68 kg in all for n = 137, about Harmony's) grounded at DOF 0,
/// its stiffness scaled so that the first mode is at 238 Hz (Harmony's first vertical mode),
/// damping D = αM with 1 % at that mode, and `q` Jenkins joints in the paper's form, each on the
/// normalised relative motion of a pair of neighbours (Eqs. 7-8) and replacing 40 % of that
/// spring, threshold 290 N (the paper's updated F_Coulomb).
pub fn chain_with_joints(n: usize, q: usize, grounded: bool) -> NonlinearModel {
    let kc = 1.0e8;
    let k = |i: usize, j: usize| {
        if i == j {
            // Springs to the ground at every DOF keep long chains well conditioned.
            let ground = if grounded { kc } else { 0.0 };
            ground + if i + 1 < n { 2.0 * kc } else { kc }
        } else if i.abs_diff(j) == 1 {
            -kc
        } else {
            0.0
        }
    };
    let probe = LinearModel::new(
        dense(n, |i, j| if i == j { 0.5 } else { 0.0 }),
        dense(n, k),
        Damping::None,
        labels(n),
        vec![],
    )
    .unwrap();
    let w1 = probe.dense_modes().unwrap().omega[0];
    let scale = (TWO_PI * 238.0 / w1).powi(2);
    let alpha = 2.0 * 0.01 * TWO_PI * 238.0;
    let linear = LinearModel::new(
        dense(n, |i, j| if i == j { 0.5 } else { 0.0 }),
        dense(n, |i, j| scale * k(i, j)),
        Damping::Rayleigh { alpha, beta: 0.0 },
        labels(n),
        vec![],
    )
    .unwrap();
    let sites = (0..q)
        .map(|e| {
            let i = (e + 1) * (n - 1) / (q + 1);
            let mut v = relative_direction(n, i, Some(i + 1));
            v.iter_mut().for_each(|x| *x /= std::f64::consts::SQRT_2);
            // 40 % of the spring between i and i+1: k_J = 0.4 Vᵀ K_spring V with V normalised.
            let kj = 0.4 * stiffness_along(&linear, &v).min(2.0 * scale * kc);
            let law: Box<dyn Element> = Box::new(Jenkins::replacing_stiffness(kj, 290.0).unwrap());
            ElementSite { name: format!("joint{e}"), law, directions: vec![v] }
        })
        .collect();
    NonlinearModel::new(linear, sites).unwrap()
}

pub fn labels(n: usize) -> Vec<DofLabel> {
    (0..n).map(|i| DofLabel::named(format!("x{i}"))).collect()
}
