//! The forced Duffing oscillator shared by the harmonic balance and stability tests:
//! `M ẍ + C ẋ + K x + K3 x³ = F cos Ωt`.
#![allow(dead_code)]

use faer::Mat;
use stickslip_core::elements::{CubicSpring, Element};
use stickslip_core::model::{Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel};

pub const M: f64 = 1.0;
pub const K: f64 = 1.0e4;
pub const C: f64 = 2.0; // ζ = 0.01
pub const K3: f64 = 1.0e7;
pub const F: f64 = 5.0;

pub fn duffing() -> NonlinearModel {
    let linear = LinearModel::new(
        Matrix::Dense(Mat::from_fn(1, 1, |_, _| M)),
        Matrix::Dense(Mat::from_fn(1, 1, |_, _| K)),
        Damping::Rayleigh { alpha: C / M, beta: 0.0 },
        vec![DofLabel::named("x")],
        vec![],
    )
    .unwrap();
    let law: Box<dyn Element> = Box::new(CubicSpring::new(K3).unwrap());
    NonlinearModel::new(linear, vec![ElementSite { name: "k3".into(), law, directions: vec![vec![1.0]] }]).unwrap()
}
