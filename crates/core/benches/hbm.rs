//! Harmonic balance benchmarks (figures in BENCHMARKS.md): whole sweeps at the sizes of the
//! paper and the cost of one Newton iteration as q and N grow. Medians of repeated runs, one
//! thread. Run: `cargo bench -p stickslip-core --bench hbm` (add `-- quick` for fewer repeats).
use std::time::Instant;

use faer::linalg::solvers::Solve;
use faer::Mat;
use stickslip_core::continuation::{Options, Silent, TerminationReason};
use stickslip_core::elements::{Contact, Element, Jenkins};
use stickslip_core::hbm::{stability_at, sweep_frequency, CondensedHbm, HbmSettings, Hill, HillSettings, Jacobians};
use stickslip_core::model::{
    relative_direction, stiffness_along, Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel,
};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

fn dense(n: usize, f: impl Fn(usize, usize) -> f64) -> Matrix {
    Matrix::Dense(Mat::from_fn(n, n, f))
}

/// Table 6 1-DOF (/work/shared/reference/table6-jenkins.toml), paper form.
fn table6() -> NonlinearModel {
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

struct SweepFigures {
    seconds: f64,
    points: usize,
    iterations: usize,
    complete: bool,
}

fn sweep(model: &NonlinearModel, force_dof: usize, level: f64, band_hz: (f64, f64), options: &Options) -> SweepFigures {
    let mut force = vec![0.0; model.linear.n_dofs()];
    force[force_dof] = 1.0;
    let start = Instant::now();
    let mut hbm = CondensedHbm::new(model, &force, HbmSettings { harmonics: 7, samples: 300 }).unwrap();
    let branch =
        sweep_frequency(&mut hbm, level, TWO_PI * band_hz.0, TWO_PI * band_hz.1, options, &mut Silent).unwrap();
    SweepFigures {
        seconds: start.elapsed().as_secs_f64(),
        points: branch.points.len(),
        iterations: branch.points.iter().map(|p| p.iterations).sum(),
        complete: branch.termination == TerminationReason::ReachedEnd,
    }
}

fn repeat(runs: usize, mut f: impl FnMut() -> SweepFigures) -> SweepFigures {
    let mut all: Vec<SweepFigures> = (0..runs).map(|_| f()).collect();
    all.sort_by(|a, b| a.seconds.partial_cmp(&b.seconds).unwrap());
    all.swap_remove(runs / 2)
}

fn print_sweep(name: &str, f: &SweepFigures) {
    println!(
        "{name:<44} {:>9.3} ms/sweep {:>5} points {:>8.1} us/point {:>5.2} Newton it/point{}",
        f.seconds * 1e3,
        f.points,
        f.seconds * 1e6 / f.points as f64,
        f.iterations as f64 / f.points as f64,
        if f.complete { "" } else { "  (branch did not reach the end)" }
    );
}

/// One Newton iteration of the condensed balance: residual + Jacobian + LU solve.
fn newton_iteration_seconds(q: usize, harmonics: usize, runs: usize) -> f64 {
    let n = (2 * q + 10).max(40);
    let model = chain_with_joints(n, q, true);
    let mut force = vec![0.0; n];
    force[n - 1] = 1.0;
    let mut hbm = CondensedHbm::new(&model, &force, HbmSettings { harmonics, samples: 300 }).unwrap();
    let dim = hbm.dimension();
    let omega = TWO_PI * 230.0;
    // A slipping state: the linear response at a level where the joints slip.
    let x = hbm.linear_solution(omega, 3000.0);
    let mut r = vec![0.0; dim];
    let mut jac = Mat::zeros(dim, dim);
    let mut times = Vec::new();
    for _ in 0..runs {
        let t = Instant::now();
        hbm.evaluate(&x, omega, 3000.0, &mut r, Some(Jacobians { dx: jac.as_mut(), domega: None, dlevel: None }))
            .unwrap();
        let dx = jac.partial_piv_lu().solve(Mat::from_fn(dim, 1, |i, _| r[i]));
        std::hint::black_box(dx);
        times.push(t.elapsed().as_secs_f64());
    }
    median(times)
}

/// One Newton iteration with `c` 3-D contacts (q = 3c directions) on a grounded chain of
/// 3c + 10 DOFs, each contact on three neighbouring relative motions (two tangential, one
/// normal); returns (residual + Jacobian, LU solve) in seconds. The state is the linear
/// response at a level where the contacts stick, slip and open over the period.
fn newton_iteration_contact_seconds(c: usize, harmonics: usize, runs: usize) -> (f64, f64) {
    let n = 3 * c + 10;
    let linear = chain_with_joints(n, 0, true).linear;
    let sites = (0..c)
        .map(|e| {
            let i = 3 * e + 5;
            let law: Box<dyn Element> = Box::new(Contact::new_3d(2e7, 4e7, 0.5, 200.0).unwrap());
            let directions = (0..3).map(|a| relative_direction(n, i + a, Some(i + a + 1))).collect();
            ElementSite { name: format!("contact{e}"), law, directions }
        })
        .collect();
    let model = NonlinearModel::new(linear, sites).unwrap();
    let mut force = vec![0.0; n];
    force[n - 1] = 1.0;
    let mut hbm = CondensedHbm::new(&model, &force, HbmSettings { harmonics, samples: 300 }).unwrap();
    let dim = hbm.dimension();
    let omega = TWO_PI * 230.0;
    let x = hbm.linear_solution(omega, 3000.0);
    let mut r = vec![0.0; dim];
    let mut jac = Mat::zeros(dim, dim);
    let (mut eval, mut solve) = (Vec::new(), Vec::new());
    for _ in 0..runs {
        let t = Instant::now();
        hbm.evaluate(&x, omega, 3000.0, &mut r, Some(Jacobians { dx: jac.as_mut(), domega: None, dlevel: None }))
            .unwrap();
        eval.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let dx = jac.partial_piv_lu().solve(Mat::from_fn(dim, 1, |i, _| r[i]));
        std::hint::black_box(dx);
        solve.push(t.elapsed().as_secs_f64());
    }
    (median(eval), median(solve))
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "quick");
    // Optional filters: `table6`, `paper`, `cost`, `contact`, `stability` (default: all).
    let wanted = |name: &str| {
        let filters: Vec<&String> =
            args.iter().filter(|a| ["table6", "paper", "cost", "contact", "stability"].contains(&a.as_str())).collect();
        filters.is_empty() || filters.iter().any(|f| *f == name)
    };
    let runs = if quick { 3 } else { 11 };
    faer::set_global_parallelism(faer::Par::Seq);
    println!("stickslip harmonic balance benchmarks: N = 7, 300 samples, one thread, median of {runs} runs");

    let options = Options::default();
    if wanted("table6") {
        let t6 = table6();
        let f = repeat(runs, || sweep(&t6, 0, 1000.0, (150.0, 350.0), &options));
        print_sweep("Table 6 1-DOF, 1000 N, 150-350 Hz", &f);
        // The same sweep at a fixed density of 1 point per Hz-ish: a smaller largest step.
        let dense_options = Options { max_step: 0.005, initial_step: 0.005, ..Options::default() };
        let f = repeat(runs, || sweep(&t6, 0, 1000.0, (150.0, 350.0), &dense_options));
        print_sweep("Table 6 1-DOF, 1000 N, max step 1/200 band", &f);
    }
    if wanted("paper") {
        let paper = chain_with_joints(137, 4, false);
        let levels = [70.0, 1070.0, 1875.0, 2910.0, 6000.0, 10000.0];
        let mut total = 0.0;
        for &level in &levels {
            let f = repeat(runs.min(5), || sweep(&paper, 136, level, (170.0, 300.0), &options));
            total += f.seconds;
            print_sweep(&format!("137 DOFs, q = 4, {level} N, 170-300 Hz"), &f);
        }
        println!("{:<44} {:>9.3} ms for the 6 levels", "137 DOFs, q = 4, all levels", total * 1e3);
    }
    if wanted("stability") {
        // Hill's method on every point of a paper-size sweep (2910 N, where the joints slip):
        // the sweep alone, then the stability of each of its points (one evaluation of the
        // joints' Jacobian and the Hill eigenproblem, with the sliders' memory refined).
        let paper = chain_with_joints(137, 4, false);
        let mut force = vec![0.0; 137];
        force[136] = 1.0;
        let mut hbm = CondensedHbm::new(&paper, &force, HbmSettings { harmonics: 7, samples: 300 }).unwrap();
        let start = Instant::now();
        let branch = sweep_frequency(&mut hbm, 2910.0, TWO_PI * 170.0, TWO_PI * 300.0, &options, &mut Silent).unwrap();
        let sweep_seconds = start.elapsed().as_secs_f64();
        let hill = Hill::new(hbm.receptance(), HillSettings::for_band(7, TWO_PI * 300.0)).unwrap();
        let mut per_point = Vec::new();
        let mut unstable = 0;
        for p in branch.points.iter().step_by((branch.points.len() / 20).max(1)) {
            let start = Instant::now();
            let s = stability_at(&mut hbm, &hill, &p.x, p.lambda).unwrap();
            per_point.push(start.elapsed().as_secs_f64());
            unstable += usize::from(!s.is_stable(1e-9 * p.lambda));
        }
        let point = median(per_point.clone());
        println!(
            "137 DOFs, q = 4, 2910 N: sweep {:.1} ms for {} points; stability {:.1} ms/point with {} modes kept \
             ({} of {} sampled points unstable): {:.0}x the sweep's cost per point",
            sweep_seconds * 1e3,
            branch.points.len(),
            point * 1e3,
            hill.n_modes(),
            unstable,
            per_point.len(),
            point / (sweep_seconds / branch.points.len() as f64)
        );
    }
    if wanted("contact") {
        println!("cost of one Newton iteration with 3-D contacts (residual + Jacobian | LU), 300 samples:");
        for &harmonics in &[3, 7] {
            for &c in &[2, 8, 32, 100] {
                let q = 3 * c;
                let dim = (2 * harmonics + 1) * q;
                let reps = if dim > 2000 {
                    1
                } else if dim > 500 {
                    3
                } else {
                    runs
                };
                let (e, l) = newton_iteration_contact_seconds(c, harmonics, reps);
                println!(
                    "  N = {harmonics:>2}, q = {q:>3} ({dim:>5} unknowns): {:>10.3} ms + {:>10.3} ms",
                    e * 1e3,
                    l * 1e3
                );
            }
        }
    }
    if !wanted("cost") {
        return;
    }

    println!("cost of one Newton iteration (residual + Jacobian + LU), 300 samples:");
    for &harmonics in &[7, 15] {
        for &q in &[4, 16, 64, 256] {
            let dim = (2 * harmonics + 1) * q;
            let reps = if dim > 2000 {
                1
            } else if dim > 500 {
                3
            } else {
                runs
            };
            let s = newton_iteration_seconds(q, harmonics, reps);
            println!("  N = {harmonics:>2}, q = {q:>3} ({dim:>5} unknowns): {:>10.3} ms", s * 1e3);
        }
    }
}
