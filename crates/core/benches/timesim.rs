//! Time-integration benchmark: steps per second on the Table 6 1-DOF model and on a 137-DOF
//! model with 4 Jenkins elements, and the time to a converged steady state at one frequency
//! against one harmonic-balance point. Prints medians over repeated runs.
//!
//! `cargo bench -p stickslip-core --bench timesim`

use std::time::{Duration, Instant};

use faer::Mat;
use stickslip_core::elements::Jenkins;
use stickslip_core::hbm::{CondensedHbm, HbmSettings};
use stickslip_core::model::{relative_direction, Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel};
use stickslip_core::timesim::{steady_state, Integrator, Scheme, SteadyState, SteadyStateOptions};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;
const REPEATS: usize = 7;

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

/// Table 6 (paper Section 4.4): 1 DOF, Jenkins element in the paper's form.
fn table6() -> (NonlinearModel, Vec<f64>) {
    let one = |x: f64| Matrix::Dense(Mat::from_fn(1, 1, |_, _| x));
    let linear =
        LinearModel::new(one(10.0), one(2.24e7), Damping::Matrix(one(350.0)), vec![DofLabel::named("x")], vec![])
            .unwrap();
    let law = Jenkins::replacing_stiffness(8.11e6, 1000.0).unwrap();
    let site = ElementSite { name: "joint".into(), law: Box::new(law), directions: vec![vec![1.0]] };
    (NonlinearModel::new(linear, vec![site]).unwrap(), vec![1000.0])
}

/// A fixed-free chain of 137 masses, first mode at 238 Hz, 0.5 % Rayleigh (mass) damping at
/// that mode; the four springs nearest the clamp (the most strained in mode 1) are Jenkins
/// joints in the paper's form, slipping at 60 % of their stuck force under the tip load used.
fn chain137() -> (NonlinearModel, Vec<f64>) {
    let n = 137;
    let m = 0.05;
    // Fixed-free chain: ω1 = 2 √(k/m) sin(π / (2(2n+1))).
    let omega1 = TWO_PI * 238.0;
    let s = (std::f64::consts::PI / (2.0 * (2 * n + 1) as f64)).sin();
    let k = m * (omega1 / (2.0 * s)).powi(2);
    let mass = Mat::from_fn(n, n, |i, j| if i == j { m } else { 0.0 });
    let stiff = Mat::from_fn(n, n, |i, j| {
        if i == j {
            if i + 1 < n {
                2.0 * k
            } else {
                k
            }
        } else if i.abs_diff(j) == 1 {
            -k
        } else {
            0.0
        }
    });
    let linear = LinearModel::new(
        Matrix::Dense(mass),
        Matrix::Dense(stiff),
        Damping::Rayleigh { alpha: 2.0 * 0.005 * omega1, beta: 0.0 },
        (0..n).map(|i| DofLabel::named(format!("x{i}"))).collect(),
        vec![],
    )
    .unwrap();
    let tip = 1.0;
    // Static tip load F puts F on every spring; at resonance the amplification is ~100, so
    // thresholds of 30 F make the joints slip over part of the cycle.
    let sites = (0..4)
        .map(|e| ElementSite {
            name: format!("joint{e}"),
            law: Box::new(Jenkins::replacing_stiffness(k, 30.0 * tip).unwrap()),
            directions: vec![relative_direction(n, e, if e == 0 { None } else { Some(e - 1) })],
        })
        .collect();
    let mut load = vec![0.0; n];
    load[n - 1] = tip;
    (NonlinearModel::new(linear, sites).unwrap(), load)
}

/// The same chain with `n` DOFs stored sparse (first mode kept at 238 Hz), for the sparse
/// Cholesky path.
fn sparse_chain(n: usize) -> (NonlinearModel, Vec<f64>) {
    use faer::sparse::{SparseColMat, Triplet};
    let m = 0.05;
    let omega1 = TWO_PI * 238.0;
    let s = (std::f64::consts::PI / (2.0 * (2 * n + 1) as f64)).sin();
    let k = m * (omega1 / (2.0 * s)).powi(2);
    let mut kt = Vec::new();
    for i in 0..n {
        kt.push(Triplet::new(i, i, if i + 1 < n { 2.0 * k } else { k }));
        if i + 1 < n {
            kt.push(Triplet::new(i, i + 1, -k));
            kt.push(Triplet::new(i + 1, i, -k));
        }
    }
    let mt: Vec<_> = (0..n).map(|i| Triplet::new(i, i, m)).collect();
    let linear = LinearModel::new(
        Matrix::Sparse(SparseColMat::try_new_from_triplets(n, n, &mt).unwrap()),
        Matrix::Sparse(SparseColMat::try_new_from_triplets(n, n, &kt).unwrap()),
        Damping::Rayleigh { alpha: 2.0 * 0.005 * omega1, beta: 0.0 },
        (0..n).map(|i| DofLabel::named(format!("x{i}"))).collect(),
        vec![],
    )
    .unwrap();
    let sites = (0..4)
        .map(|e| ElementSite {
            name: format!("joint{e}"),
            law: Box::new(Jenkins::replacing_stiffness(k, 30.0).unwrap()),
            directions: vec![relative_direction(n, e, if e == 0 { None } else { Some(e - 1) })],
        })
        .collect();
    let mut load = vec![0.0; n];
    load[n - 1] = 1.0;
    (NonlinearModel::new(linear, sites).unwrap(), load)
}

fn steps_per_second(model: &NonlinearModel, load: &[f64], steps: usize) -> (f64, Duration) {
    let f = 238.0;
    let p = 256;
    let h = 1.0 / (f * p as f64);
    let n = model.linear.n_dofs();
    let mut times = Vec::new();
    for _ in 0..REPEATS {
        let mut it = Integrator::new(model, Scheme::AverageAcceleration, h).unwrap();
        let mut state = it.start(0.0, &vec![0.0; n], &vec![0.0; n], load, 1.0).unwrap();
        let start = Instant::now();
        for k in 1..=steps {
            let e = (TWO_PI * f * k as f64 * h).cos();
            it.step(&mut state, load, e, e).unwrap();
        }
        times.push(start.elapsed());
        std::hint::black_box(&state);
    }
    let t = median(times);
    (steps as f64 / t.as_secs_f64(), t)
}

fn time_to_steady(model: &NonlinearModel, load: &[f64], f: f64) -> (Duration, SteadyState) {
    let mut result = None;
    let mut times = Vec::new();
    for _ in 0..REPEATS {
        let mut o = SteadyStateOptions::new(f, load.to_vec());
        o.steps_per_period = 512;
        o.tolerance = 1e-6;
        o.record_dofs = vec![0];
        let start = Instant::now();
        let s = steady_state(model, &o).unwrap();
        times.push(start.elapsed());
        result = Some(s);
    }
    (median(times), result.unwrap())
}

/// One HBM point (N = 7, 300 samples, the paper's settings) at the same frequency, Newton from
/// the stuck linear solution or, where that start is too far (at the stuck resonance), from
/// the harmonics of the time solution's element displacements.
fn hbm_point(
    model: &NonlinearModel,
    load: &[f64],
    f: f64,
    steady: &SteadyState,
) -> Option<(Duration, usize, &'static str)> {
    let mut times = Vec::new();
    let mut iterations = (0, "");
    for _ in 0..REPEATS {
        let mut start = Instant::now();
        let mut hbm = match CondensedHbm::new(model, load, HbmSettings { harmonics: 7, samples: 300 }) {
            Ok(h) => h,
            Err(e) => {
                println!("  HBM set-up: {e}");
                return None;
            }
        };
        let x0 = hbm.linear_solution(TWO_PI * f, 1.0);
        let (it, from) = match hbm.solve(TWO_PI * f, 1.0, &x0, 1e-10, 100) {
            Ok((_, it)) => (it, "the stuck solution"),
            Err(_) => {
                // Time only the successful solve.
                start = Instant::now();
                // Coefficient-major start: x[c·q + a] from the time records.
                let q = hbm.n_directions();
                let nc = hbm.plan().n_coeffs();
                let mut x0 = vec![0.0; nc * q];
                for a in 0..q {
                    let c = SteadyState::harmonics(&steady.records.elements.displacement[a], 7).ok()?;
                    for (k, v) in c.iter().enumerate() {
                        x0[k * q + a] = *v;
                    }
                }
                match hbm.solve(TWO_PI * f, 1.0, &x0, 1e-10, 100) {
                    Ok((_, it)) => (it, "the time solution"),
                    Err(e) => {
                        println!("  HBM from the time solution: {e}");
                        return None;
                    }
                }
            }
        };
        times.push(start.elapsed());
        iterations = (it, from);
    }
    Some((median(times), iterations.0, iterations.1))
}

fn main() {
    println!("time integration benchmark (median of {REPEATS} runs), average acceleration, 256 steps/period");
    let (model, load) = sparse_chain(20_000);
    let (rate, t) = steps_per_second(&model, &load, 2_000);
    println!("sparse chain 20000-DOF, q = 4: {rate:.3e} steps/s (2000 steps in {:.3} s)", t.as_secs_f64());
    for (name, (model, load), steps) in
        [("table6 1-DOF, q = 1", table6(), 200_000), ("chain 137-DOF, q = 4", chain137(), 20_000)]
    {
        let (rate, t) = steps_per_second(&model, &load, steps);
        println!("{name}: {rate:.3e} steps/s ({steps} steps in {:.3} s)", t.as_secs_f64());
        let f = 238.0;
        let (t_steady, s) = time_to_steady(&model, &load, f);
        println!(
            "{name}: steady state at {f} Hz (512 steps/period, periodicity 1e-6): {:.3} ms, {} periods",
            t_steady.as_secs_f64() * 1e3,
            s.periods
        );
        let slipping: Vec<f64> = s
            .records
            .elements
            .slider_velocity
            .iter()
            .map(|v| v.iter().filter(|x| **x != 0.0).count() as f64 / v.len() as f64)
            .collect();
        println!("{name}: fraction of the period each joint slips: {slipping:.2?}");
        match hbm_point(&model, &load, f, &s) {
            Some((t, it, from)) => println!(
                "{name}: one HBM point at {f} Hz (N = 7, 300 samples, from {from}): {:.3} ms, {it} Newton iterations",
                t.as_secs_f64() * 1e3
            ),
            None => println!("{name}: HBM point at {f} Hz did not converge"),
        }
    }
}
