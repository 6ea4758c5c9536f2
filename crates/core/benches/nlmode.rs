//! Nonlinear mode benchmark (figure in BENCHMARKS.md): a backbone over four decades of
//! modal amplitude at the paper's size (137 DOFs, 4 paper-form Jenkins joints, N = 7, 300
//! samples), by the extended periodic motion concept. Median of repeated runs, one thread.
//! Run: `cargo bench -p stickslip-core --bench nlmode` (add `-- quick` for fewer repeats).
use std::time::Instant;

use faer::Mat;
use stickslip_core::continuation::{Options, Silent};
use stickslip_core::elements::{Element, Jenkins};
use stickslip_core::hbm::{nonlinear_mode, HbmSettings, NegativeDamping, NonlinearModeSettings};
use stickslip_core::model::{
    relative_direction, stiffness_along, Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel,
};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

fn dense(n: usize, f: impl Fn(usize, usize) -> f64) -> Matrix {
    Matrix::Dense(Mat::from_fn(n, n, f))
}

/// A chain of `n` masses (0.5 kg, 68 kg in all for n = 137, about Harmony's) grounded at DOF 0,
/// its stiffness scaled so that the first mode is at 238 Hz (Harmony's first vertical mode),
/// damping D = αM with 1 % at that mode, and `q` Jenkins joints in the paper's form, each on the
/// normalised relative motion of a pair of neighbours (Eqs. 7-8) and replacing 40 % of that
/// spring, threshold 290 N (the paper's updated F_Coulomb).
fn chain_with_joints(n: usize, q: usize, grounded: bool) -> NonlinearModel {
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

fn labels(n: usize) -> Vec<DofLabel> {
    (0..n).map(|i| DofLabel::named(format!("x{i}"))).collect()
}

fn main() {
    let quick = std::env::args().any(|a| a == "quick");
    let runs = if quick { 3 } else { 11 };
    faer::set_global_parallelism(faer::Par::Seq);
    println!("stickslip nonlinear mode benchmark: N = 7, 300 samples, one thread, median of {runs} runs");
    for n in [137, 149] {
        let model = chain_with_joints(n, 4, false);
        let settings = NonlinearModeSettings {
            mode: 0,
            hbm: HbmSettings { harmonics: 7, samples: 300 },
            negative_damping: NegativeDamping::TargetMode,
        };
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
             {:.3} -> {:.3} Hz, damping ratio {:.4} -> {:.4} (max {:.4}), least stick fraction at the end {stick:.2}; {}",
            times[runs / 2] * 1e3,
            b.points.len(),
            times[runs / 2] * 1e6 / b.points.len() as f64,
            iterations as f64 / b.points.len() as f64,
            p0.frequency_hz(),
            p1.frequency_hz(),
            p0.damping_ratio(),
            p1.damping_ratio(),
            b.points.iter().map(|p| p.damping_ratio()).fold(0.0, f64::max),
            b.termination
        );
        }
    }
}
