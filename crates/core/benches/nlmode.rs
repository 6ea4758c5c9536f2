//! Nonlinear mode benchmark (figure in BENCHMARKS.md): a backbone over four decades of
//! modal amplitude at the paper's size (137 DOFs, 4 paper-form Jenkins joints, N = 7, 300
//! samples), by the extended periodic motion concept. Median of repeated runs, one thread.
//! Run: `cargo bench -p stickslip-core --bench nlmode` (add `-- quick` for fewer repeats).
mod common;

use std::time::Instant;

use common::chain_with_joints;
use faer::Mat;
use stickslip_core::continuation::{Options, Silent};
use stickslip_core::hbm::{nonlinear_mode, HbmSettings, NegativeDamping, NonlinearModeSettings};
use stickslip_core::model::{Damping, Matrix};

fn main() {
    let quick = std::env::args().any(|a| a == "quick");
    let runs = if quick || std::env::args().any(|a| a == "damping-matrix") { 3 } else { 11 };
    faer::set_global_parallelism(faer::Par::Seq);
    println!("stickslip nonlinear mode benchmark: N = 7, 300 samples, one thread, median of {runs} runs");
    let mass = std::env::args().any(|a| a == "mass");
    let negative_damping = if mass { NegativeDamping::MassProportional } else { NegativeDamping::TargetMode };
    // `damping-matrix`: the 137-DOF chain's D = αM written as a matrix with a dashpot added
    // across it (DOF 10 to DOF 70, 20 N·s/m), so that Φᵀ D Φ is full and the balance takes the
    // coupled path (one complex LU of the other 136 modes per harmonic and evaluation).
    let coupled = std::env::args().any(|a| a == "damping-matrix");
    for n in if coupled { vec![137] } else { vec![137, 149] } {
        let mut model = chain_with_joints(n, 4, false);
        if coupled {
            let Damping::Rayleigh { alpha, .. } = model.linear.damping else {
                unreachable!("the chain's damping is αM")
            };
            let mass = model.linear.mass.to_dense();
            let dashpot = |i: usize, j: usize| match (i, j) {
                (10, 10) | (70, 70) => 20.0,
                (10, 70) | (70, 10) => -20.0,
                _ => 0.0,
            };
            model.linear.damping =
                Damping::Matrix(Matrix::Dense(Mat::from_fn(n, n, |i, j| alpha * mass[(i, j)] + dashpot(i, j))));
        }
        let settings =
            NonlinearModeSettings { mode: 0, hbm: HbmSettings { harmonics: 7, samples: 300 }, negative_damping };
        // Four decades, from the stuck mode to joints slipping over most of the cycle. The
        // negative damping acts on the target mode only: with D = αM, −ξM would leave the 136
        // other modes undamped, some near a harmonic of the mode (see NegativeDamping).
        let (a0, a1) = (1e-5, 1e-1);
        // The continuation's default steps (at most 1/20 of the range, 0.2 decade), and the
        // study's (at most 1/20 decade: `stickslip run`/`nlmode` draw smoother curves), both at
        // the study's default tolerance (1e-8 of the order-one scaled residuals).
        for (steps, options) in [
            ("default steps", Options { rtol: 1e-8, ..Options::default() }),
            ("1/20-decade steps", Options { rtol: 1e-8, max_step: 0.0125, initial_step: 0.01, ..Options::default() }),
        ] {
            let mut times = Vec::new();
            let mut last = None;
            for _ in 0..runs {
                let t = Instant::now();
                let b = nonlinear_mode(&model, &settings, a0, a1, &[], &options, &mut Silent).unwrap();
                times.push(t.elapsed().as_secs_f64());
                last = Some(b);
            }
            times.sort_by(f64::total_cmp);
            let b = last.unwrap();
            let branch = b.branch.as_ref().unwrap();
            let iterations: usize = branch.points.iter().map(|p| p.iterations).sum();
            let (p0, p1) = (&b.points[0], b.points.last().unwrap());
            let stick = p1.stick_fraction.iter().cloned().fold(f64::INFINITY, f64::min);
            println!(
            "{n} DOFs, q = 4, modal amplitude {a0:e}-{a1:e}, {steps}: {:>8.3} ms/backbone {:>4} points {:>7.1} us/point {:.2} Newton it/point; \
             {:.3} -> {:.3} Hz, damping ratio {:.4} -> {:.4} (max {:.4}), least stick fraction at the end {stick:.2}, {} folds or branch points; {}",
            times[runs / 2] * 1e3,
            b.points.len(),
            times[runs / 2] * 1e6 / b.points.len() as f64,
            iterations as f64 / b.points.len() as f64,
            p0.frequency_hz(),
            p1.frequency_hz(),
            p0.damping_ratio(),
            p1.damping_ratio(),
            b.points.iter().map(|p| p.damping_ratio()).fold(0.0, f64::max),
            b.singular_points.len(),
            b.termination
        );
        }
    }
}
