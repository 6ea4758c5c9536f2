//! Harmonic balance benchmarks (figures in BENCHMARKS.md): whole sweeps at the sizes of the
//! paper and the cost of one Newton iteration as q and N grow. Medians of repeated runs, one
//! thread. Run: `cargo bench -p stickslip-core --bench hbm` (add `-- quick` for fewer repeats).
mod common;

use std::time::Instant;

use common::{chain_with_joints, table6};
use faer::linalg::solvers::Solve;
use faer::Mat;
use stickslip_core::continuation::{
    Accepted, Options, PivotedLu, PointObserver, Problem, Silent, TerminationReason, TestFunctions,
};
use stickslip_core::elements::{Contact, Element};
use stickslip_core::hbm::receptance::HarmonicReceptance;
use stickslip_core::hbm::{
    folds_and_branch_points, stability_at, stability_by_eigenproblems, sweep_frequency, CondensedHbm, ElementAft,
    FrequencySweep, HbmSettings, Hill, HillSettings, Jacobians,
};
use stickslip_core::model::{relative_direction, ElementSite, NonlinearModel};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
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

/// Takes the test functions of folds and branch points of every accepted point: exact, or
/// estimated from the corrector's last factorisation where it can (as a run does).
#[derive(Default)]
struct TakeTestFunctions(Vec<Option<TestFunctions>>, bool);

impl<P: Problem + ?Sized> PointObserver<P> for TakeTestFunctions {
    fn on_accepted(&mut self, accepted: &mut Accepted<'_, P>) {
        let taken = if self.1 { accepted.test_functions_estimate() } else { accepted.test_functions() };
        self.0.push(taken.ok().flatten().cloned());
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

/// One Newton iteration on the patch at the linear response of `level` at 340 Hz: residual,
/// Jacobian factored by structure and solved (median of `runs`), the same with the dense LU
/// (once, skipped in `quick` runs), and the number of directions that couple harmonics.
fn patch_newton_iteration(
    model: &NonlinearModel,
    force: &[f64],
    level: f64,
    quick: bool,
    runs: usize,
) -> (f64, Option<f64>, usize) {
    let mut hbm = CondensedHbm::new(model, force, HbmSettings { harmonics: 7, samples: 300 }).unwrap();
    let dim = hbm.dimension();
    let omega = TWO_PI * 340.0;
    let x = hbm.linear_solution(omega, level);
    let mut r = vec![0.0; dim];
    let mut times = Vec::new();
    for _ in 0..runs {
        let t = Instant::now();
        hbm.evaluate_factored(&x, omega, level, &mut r, None, None).unwrap();
        assert!(hbm.solve_factored(&mut r));
        times.push(t.elapsed().as_secs_f64());
    }
    let coupled = hbm.structured_jacobian().unwrap().coupled_directions();
    let dense = (!quick).then(|| {
        let t = Instant::now();
        let mut jac = Mat::zeros(dim, dim);
        hbm.evaluate(&x, omega, level, &mut r, Some(Jacobians { dx: jac.as_mut(), domega: None, dlevel: None }))
            .unwrap();
        std::hint::black_box(jac.partial_piv_lu().solve(Mat::from_fn(dim, 1, |i, _| r[i])));
        t.elapsed().as_secs_f64()
    });
    (median(times), dense, coupled)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "quick");
    // Optional filters: `table6`, `paper`, `profile`, `cost`, `contact`, `stability`, `folds`,
    // `patch` (default: all).
    let wanted = |name: &str| {
        let filters: Vec<&String> = args
            .iter()
            .filter(|a| {
                ["table6", "paper", "profile", "cost", "contact", "stability", "folds", "patch"].contains(&a.as_str())
            })
            .collect();
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
        // As `stickslip run` sweeps a study's levels: the set-up (the model's modes) once, each
        // level on a balance sharing it.
        let mut force = vec![0.0; 137];
        force[136] = 1.0;
        let mut shared: Vec<f64> = (0..runs.min(5))
            .map(|_| {
                let start = Instant::now();
                let hbm = CondensedHbm::new(&paper, &force, HbmSettings { harmonics: 7, samples: 300 }).unwrap();
                for &level in &levels {
                    let mut level_hbm = hbm.share_linear_part();
                    let (w0, w1) = (TWO_PI * 170.0, TWO_PI * 300.0);
                    sweep_frequency(&mut level_hbm, level, w0, w1, &options, &mut Silent).unwrap();
                }
                start.elapsed().as_secs_f64()
            })
            .collect();
        shared.sort_by(f64::total_cmp);
        let t = shared[shared.len() / 2];
        println!(
            "{:<44} {:>9.3} ms for the 6 levels, {:.3} ms per level",
            "137 DOFs, q = 4, set-up shared by the levels",
            t * 1e3,
            t * 1e3 / levels.len() as f64
        );
    }
    if wanted("profile") {
        // Where a paper-size level's time goes (2910 N, where the joints slip): the calls the
        // continuation made per point, and each kind of call timed alone at the branch's own
        // points (median over the points of repeated timings).
        let paper = chain_with_joints(137, 4, false);
        let mut force = vec![0.0; 137];
        force[136] = 1.0;
        let settings = HbmSettings { harmonics: 7, samples: 300 };
        let timed = |f: &mut dyn FnMut()| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        };
        let setup = median(
            (0..runs)
                .map(|_| {
                    timed(&mut || drop(std::hint::black_box(CondensedHbm::new(&paper, &force, settings).unwrap())))
                })
                .collect(),
        );
        let mut hbm = CondensedHbm::new(&paper, &force, settings).unwrap();
        let sweeps: Vec<f64> = (0..runs)
            .map(|_| {
                timed(&mut || {
                    sweep_frequency(&mut hbm, 2910.0, TWO_PI * 170.0, TWO_PI * 300.0, &options, &mut Silent).unwrap();
                })
            })
            .collect();
        let sweep_seconds = median(sweeps);
        let branch = sweep_frequency(&mut hbm, 2910.0, TWO_PI * 170.0, TWO_PI * 300.0, &options, &mut Silent).unwrap();
        let points = branch.points.len() as f64;
        // The corrector evaluates residuals and completes to Jacobians those it does not
        // accept (`CondensedHbm::complete_jacobian`, every joint a slider).
        assert!(hbm.completes_jacobian());
        let (residuals, jacobians, factorizations) = (
            branch.calls.residuals as f64 / points,
            branch.calls.jacobians as f64 / points,
            branch.calls.factorizations as f64 / points,
        );
        // Each call alone at every point of the branch, as the balance makes it: with the even
        // harmonics pinned (sliders), the AFT over half a period, the odd harmonics' receptance
        // and Jacobian, and the odd block's LU alone.
        let pinned = hbm.pins_even_harmonics();
        let (dim, q) = (hbm.dimension(), hbm.n_directions());
        let plan = hbm.plan();
        let mut afts: Vec<ElementAft> = paper.elements.iter().map(|e| ElementAft::new(e.law.as_ref(), plan)).collect();
        let nc = plan.n_coeffs();
        let receptance = hbm.receptance();
        let mut harmonic: Vec<HarmonicReceptance> = (0..7).map(|_| HarmonicReceptance::new(q)).collect();
        let (mut u, mut g, mut block, mut dgdw) = (vec![0.0; nc], vec![0.0; nc], Mat::zeros(nc, nc), vec![0.0; nc]);
        // The AFT of the 4 joints without Jacobian, then (`complete`) their Jacobians from it.
        let mut aft_alone = |x: &[f64], omega: f64, complete: bool| {
            for (e, (site, aft)) in paper.elements.iter().zip(&mut afts).enumerate() {
                for c in 0..nc {
                    u[c] = x[c * q + e];
                }
                aft.evaluate_with_symmetry(site.law.as_ref(), plan, omega, &u, &mut g, None, pinned).unwrap();
                if complete {
                    assert!(aft.complete_slider_jacobian(plan, block.as_mut(), &mut dgdw, pinned));
                }
            }
        };
        // The receptance at the 7 harmonics for a residual (with the matrices H_k where the
        // residual makes them, `Receptance::prefers_matrix`), then (`complete`) the matrices
        // H_k if it did not.
        let matrices_in_residual = receptance.prefers_matrix();
        let mut receptance_alone = |omega: f64, complete: bool| {
            for (k, hr) in harmonic.iter_mut().enumerate().filter(|(k, _)| !pinned || k % 2 == 0) {
                let w = (k + 1) as f64 * omega;
                match (k, matrices_in_residual) {
                    (0, false) => receptance.evaluate(w, hr),
                    (0, true) => receptance.evaluate_matrix(w, hr),
                    _ => receptance.evaluate_unforced(w, hr, matrices_in_residual),
                }
                if complete && !matrices_in_residual {
                    receptance.complete_matrix(w, hr);
                }
            }
        };
        let repeat_at = |f: &mut dyn FnMut()| median((0..5).map(|_| timed(f)).collect());
        let mut t = [Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new()];
        for p in &branch.points {
            t[0].push(repeat_at(&mut || aft_alone(&p.x, p.lambda, false)));
            t[1].push(repeat_at(&mut || aft_alone(&p.x, p.lambda, true)));
            t[2].push(repeat_at(&mut || receptance_alone(p.lambda, false)));
            t[3].push(repeat_at(&mut || receptance_alone(p.lambda, true)));
        }
        let mut r = vec![0.0; dim];
        let mut jac = Mat::zeros(dim, dim);
        let mut dw = vec![0.0; dim];
        let mut blocks = Vec::new();
        let (mut residual_t, mut jacobian_t) = (Vec::new(), Vec::new());
        for p in &branch.points {
            residual_t.push(repeat_at(&mut || hbm.evaluate(&p.x, p.lambda, 2910.0, &mut r, None).unwrap()));
            jacobian_t.push(repeat_at(&mut || {
                hbm.evaluate(&p.x, p.lambda, 2910.0, &mut r, None).unwrap();
                assert!(hbm.complete_jacobian(jac.as_mut(), Some(&mut dw), None));
            }));
            // The bordered (n+1) system of the corrector, factored and solved: whole, or where
            // the Jacobian splits into even and odd harmonics (as here), the even block and
            // the odd one bordered (the corrector's own triangular solves are faster still).
            let bordered_of = |rows: &[usize]| {
                let m = rows.len();
                Mat::from_fn(m + 1, m + 1, |i, j| match (i < m, j < m) {
                    (true, true) => jac[(rows[i], rows[j])],
                    (true, false) => dw[rows[i]],
                    _ => 1.0,
                })
            };
            let split = hbm.decoupled_unknowns().map(<[usize]>::to_vec);
            let identity = hbm.decoupled_block_is_identity();
            blocks = match &split {
                None => vec![dim + 1],
                Some(even) if identity => vec![dim - even.len() + 1],
                Some(even) => vec![even.len(), dim - even.len() + 1],
            };
            let systems: Vec<(Mat<f64>, Mat<f64>)> = match &split {
                None => vec![bordered_of(&(0..dim).collect::<Vec<_>>())],
                Some(even) => {
                    let odd: Vec<usize> = (0..dim).filter(|i| even.binary_search(i).is_err()).collect();
                    let mut block = bordered_of(even);
                    block = block.subrows(0, even.len()).subcols(0, even.len()).to_owned();
                    match identity {
                        true => vec![bordered_of(&odd)],
                        false => vec![block, bordered_of(&odd)],
                    }
                }
            }
            .into_iter()
            .map(|a| {
                let rhs = Mat::from_fn(a.nrows(), 1, |i, _| r[i.min(dim - 1)]);
                (a, rhs)
            })
            .collect();
            // The corrector's own LU and solves.
            let mut lus: Vec<(PivotedLu, Vec<f64>)> = systems
                .iter()
                .map(|(a, rhs)| (PivotedLu::new(a.nrows()), (0..rhs.nrows()).map(|i| rhs[(i, 0)]).collect()))
                .collect();
            t[4].push(repeat_at(&mut || {
                for ((a, _), (lu, rhs)) in systems.iter().zip(&mut lus) {
                    lu.factor(a.as_ref());
                    let mut x = rhs.clone();
                    lu.solve(&mut x);
                    std::hint::black_box(&x);
                }
            }));
        }
        let us = |v: Vec<f64>| median(v) * 1e6;
        let [aft_r, aft_j, rec_r, rec_j, lu] = t.map(us);
        let res = us(residual_t);
        // Completions by difference: the residual, then the residual and its completion.
        let jcb = us(jacobian_t) - res;
        let (aft_j, rec_j) = (aft_j - aft_r, rec_j - rec_r);
        let accounted = jacobians * jcb + residuals * res + factorizations * lu;
        let per_point = sweep_seconds * 1e6 / points;
        println!(
            "profile, 137 DOFs, q = 4, 2910 N, 170-300 Hz: {} points, sweep {:.2} ms ({:.1} us/point), set-up \
             (modes, receptance) {:.2} ms",
            branch.points.len(),
            sweep_seconds * 1e3,
            per_point,
            setup * 1e3
        );
        println!(
            "  per point: {residuals:.2} residuals, {jacobians:.2} completed to Jacobians, {factorizations:.2} \
             bordered LU solves"
        );
        let (made_in_residual, made_in_completion) = if matrices_in_residual {
            (" with the matrices H_k", String::new())
        } else {
            ("", format!("matrices H_k {rec_j:.1}, "))
        };
        let (over, harmonics) = match pinned {
            true => (" over half a period (even harmonics pinned)", "the 4 odd harmonics"),
            false => ("", "7 harmonics"),
        };
        println!(
            "  residual   {res:>6.1} us: AFT of the 4 joints{over} {aft_r:.1}, receptance at {harmonics}\
             {made_in_residual} {rec_r:.1}, products H_k G_k {:.1}",
            res - aft_r - rec_r
        );
        println!(
            "  completion {jcb:>6.1} us: sliders' Jacobians {aft_j:.1}, {made_in_completion}{dim} x {dim} assembly \
             and dR/dOmega {:.1}",
            jcb - aft_j - rec_j
        );
        let sizes: Vec<String> = blocks.iter().map(|m| format!("{m} x {m}")).collect();
        println!("  bordered LU ({}) and solve {lu:.1} us", sizes.join(" and "));
        println!(
            "  accounted per point {accounted:.1} us ({:.1} residuals, {:.1} completions, {:.1} LU) of {per_point:.1} \
             us measured (the rest: the continuation's own work, colder caches and, on a loaded machine, \
             waiting for a core)",
            residuals * res,
            jacobians * jcb,
            factorizations * lu
        );
    }
    if wanted("stability") {
        // Hill's method on every point of a paper-size sweep (2910 N, where the joints slip):
        // the sweep alone; the stability of each point computed in full, by the reference (the
        // sliders' memory refined by a complex eigenproblem per fixed-point step, Hill's matrix
        // whole) on 20 of them and as a run does it (split into even and odd harmonics, Newton's
        // refinement) on all.
        let paper = chain_with_joints(137, 4, false);
        let mut force = vec![0.0; 137];
        force[136] = 1.0;
        let mut hbm = CondensedHbm::new(&paper, &force, HbmSettings { harmonics: 7, samples: 300 }).unwrap();
        let mut sweeps = Vec::new();
        let mut branch = None;
        for _ in 0..runs.min(5) {
            let start = Instant::now();
            let b = sweep_frequency(&mut hbm, 2910.0, TWO_PI * 170.0, TWO_PI * 300.0, &options, &mut Silent).unwrap();
            sweeps.push(start.elapsed().as_secs_f64());
            branch = Some(b);
        }
        let branch = branch.unwrap();
        let sweep_seconds = median(sweeps);
        let n = branch.points.len();
        let hill = Hill::new(hbm.receptance(), HillSettings::for_band(7, TWO_PI * 300.0)).unwrap();
        let whole = hill.clone().without_symmetry();
        let mut reference = Vec::new();
        for p in branch.points.iter().step_by((n / 20).max(1)) {
            let start = Instant::now();
            std::hint::black_box(stability_by_eigenproblems(&mut hbm, &whole, &p.x, p.lambda).unwrap());
            reference.push(start.elapsed().as_secs_f64());
        }
        let mut full = Vec::new();
        let mut full_total = 0.0;
        let mut unstable = 0;
        for p in &branch.points {
            let start = Instant::now();
            let s = stability_at(&mut hbm, &hill, &p.x, p.lambda).unwrap();
            full.push(start.elapsed().as_secs_f64());
            full_total += full.last().unwrap();
            unstable += usize::from(!s.is_stable(1e-9 * p.lambda));
        }
        let (mut jacobian, mut spectrum, mut whole_spectrum) = (Vec::new(), Vec::new(), Vec::new());
        for p in &branch.points {
            let start = Instant::now();
            let jac = hbm.element_force_jacobian(&p.x, p.lambda).unwrap();
            jacobian.push(start.elapsed().as_secs_f64());
            let start = Instant::now();
            std::hint::black_box(hill.exponents(p.lambda, jac.as_ref()).unwrap());
            spectrum.push(start.elapsed().as_secs_f64());
            let start = Instant::now();
            std::hint::black_box(whole.exponents(p.lambda, jac.as_ref()).unwrap());
            whole_spectrum.push(start.elapsed().as_secs_f64());
        }
        let (reference, full, jacobian) = (median(reference), median(full), median(jacobian));
        let (spectrum, whole_spectrum) = (median(spectrum), median(whole_spectrum));
        let total: f64 = full_total;
        println!(
            "137 DOFs, q = 4, 2910 N: sweep {:.1} ms for {n} points ({:.3} ms/point), {} modes kept, {unstable} points unstable",
            sweep_seconds * 1e3,
            sweep_seconds * 1e3 / n as f64,
            hill.n_modes(),
        );
        println!(
            "  stability per point: reference {:.2} ms, now {:.2} ms (of which the joints' Jacobian {:.3} ms, \
             the periodic spectrum {:.2} ms, {:.2} ms unsplit)",
            reference * 1e3,
            full * 1e3,
            jacobian * 1e3,
            spectrum * 1e3,
            whole_spectrum * 1e3
        );
        println!(
            "  stability of the {n} points: {:.1} ms, {:.0} % of the sweep",
            total * 1e3,
            100.0 * total / sweep_seconds
        );
    }
    if wanted("folds") {
        // The test functions of folds and branch points (tangent and determinants) at every
        // point of a paper-size sweep (2910 N, where the joints slip): the sweep with a silent
        // observer and with one that asks every accepted point for them, run in turn; then
        // their search for sign changes along the branch.
        let paper = chain_with_joints(137, 4, false);
        let mut force = vec![0.0; 137];
        force[136] = 1.0;
        let mut hbm = CondensedHbm::new(&paper, &force, HbmSettings { harmonics: 7, samples: 300 }).unwrap();
        let (w0, w1) = (TWO_PI * 170.0, TWO_PI * 300.0);
        let (mut silent, mut exact, mut estimated) = (Vec::new(), Vec::new(), Vec::new());
        let mut taken = (Vec::new(), TakeTestFunctions::default());
        for _ in 0..runs {
            let start = Instant::now();
            std::hint::black_box(sweep_frequency(&mut hbm, 2910.0, w0, w1, &options, &mut Silent).unwrap());
            silent.push(start.elapsed().as_secs_f64());
            let mut tests = TakeTestFunctions::default();
            let start = Instant::now();
            std::hint::black_box(sweep_frequency(&mut hbm, 2910.0, w0, w1, &options, &mut tests).unwrap());
            exact.push(start.elapsed().as_secs_f64());
            let mut tests = TakeTestFunctions(Vec::new(), true);
            let start = Instant::now();
            let branch = sweep_frequency(&mut hbm, 2910.0, w0, w1, &options, &mut tests).unwrap();
            estimated.push(start.elapsed().as_secs_f64());
            taken = (branch.points, tests);
        }
        let (points, tests) = taken;
        let start = Instant::now();
        let found =
            folds_and_branch_points(&mut FrequencySweep { hbm: &mut hbm, level: 2910.0 }, &points, &tests.0, 1e-10);
        let search = start.elapsed().as_secs_f64();
        let (silent, exact, estimated) = (median(silent), median(exact), median(estimated));
        let per_point = |t: f64| (t - silent) * 1e6 / points.len() as f64;
        println!(
            "137 DOFs, q = 4, 2910 N: sweep {:.2} ms, with the test functions of its {} points: exact {:.2} ms \
             (+{:.1} %, {:.1} us/point), from the corrector's last factorisation {:.2} ms (+{:.1} %, {:.1} us/point); \
             their search {:.3} ms, {} found",
            silent * 1e3,
            points.len(),
            exact * 1e3,
            100.0 * (exact / silent - 1.0),
            per_point(exact),
            estimated * 1e3,
            100.0 * (estimated / silent - 1.0),
            per_point(estimated),
            search * 1e3,
            found.len()
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
    if wanted("patch") {
        // A 10 × 10 patch of 3-D contacts (q = 300), N = 7: one Newton iteration solved by
        // structure at levels where more and more of the patch slips, against the dense LU;
        // then whole sweeps through the patch's resonance.
        println!("contact patch 10 x 10 (q = 300), N = 7, 300 samples: one Newton iteration at 340 Hz");
        let (model, force) = common::contact_patch(10);
        for &level in &[100.0, 2000.0, 6000.0, 20000.0, 100000.0] {
            let (structured, dense, coupled) = patch_newton_iteration(&model, &force, level, quick, runs.min(5));
            println!(
                "  linear response of {level:>6} N: {coupled:>3} of 300 directions slip or open; by structure \
                 {:>8.1} ms, dense {}",
                structured * 1e3,
                dense.map_or("not run".into(), |d| format!("{:.1} ms", d * 1e3)),
            );
        }
        for &level in &[200.0, 1000.0, 3000.0] {
            let start = Instant::now();
            let mut hbm = CondensedHbm::new(&model, &force, HbmSettings { harmonics: 7, samples: 300 }).unwrap();
            let branch =
                sweep_frequency(&mut hbm, level, TWO_PI * 250.0, TWO_PI * 450.0, &options, &mut Silent).unwrap();
            let iterations: usize = branch.points.iter().map(|p| p.iterations).sum();
            let seconds = start.elapsed().as_secs_f64();
            println!(
                "  sweep 250-450 Hz at {level:>5} N: {:>6.2} s, {} points, {} Newton iterations ({:.0} ms each){}",
                seconds,
                branch.points.len(),
                iterations,
                seconds * 1e3 / iterations.max(1) as f64,
                if branch.termination == TerminationReason::ReachedEnd { "" } else { " (did not reach the end)" }
            );
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
