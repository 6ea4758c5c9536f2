//! Continuation benchmark: the cost of the continuation itself (prediction, bordered LU solve,
//! step control) per converged point and per Newton iteration, on problems whose residual is
//! cheap so that the loop dominates: the first-order Duffing balance (n = 2) and a dense cubic
//! problem of the paper's condensed size (n = (2N+1)q = 60 for N = 7, q = 4) and larger.
//! Prints medians over repeated runs.
//!
//! `cargo bench -p stickslip-core --bench continuation`

use std::time::{Duration, Instant};

use faer::prelude::Solve;
use faer::{Mat, MatMut};
use stickslip_core::continuation::{continue_branch, Branch, Options, Predictor, Problem, ProblemError, Silent};

const REPEATS: usize = 9;

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

/// m ẍ + c ẋ + k x + k₃ x³ = F cos Ωt at first order, x = a cos + b sin; λ = Ω.
struct Duffing;

impl Problem for Duffing {
    fn dimension(&self) -> usize {
        2
    }
    fn evaluate(
        &mut self,
        x: &[f64],
        omega: f64,
        residual: &mut [f64],
        jacobian: Option<(MatMut<'_, f64>, &mut [f64])>,
    ) -> Result<(), ProblemError> {
        let (m, c, k, k3, f) = (1.0, 0.05, 1.0, 1.0, 0.1);
        let (a, b) = (x[0], x[1]);
        let stiffness = k - m * omega * omega + 0.75 * k3 * (a * a + b * b);
        residual[0] = stiffness * a + c * omega * b - f;
        residual[1] = stiffness * b - c * omega * a;
        if let Some((mut jx, dw)) = jacobian {
            jx[(0, 0)] = stiffness + 1.5 * k3 * a * a;
            jx[(0, 1)] = 1.5 * k3 * a * b + c * omega;
            jx[(1, 0)] = 1.5 * k3 * a * b - c * omega;
            jx[(1, 1)] = stiffness + 1.5 * k3 * b * b;
            dw[0] = -2.0 * m * omega * a + c * b;
            dw[1] = -2.0 * m * omega * b - c * a;
        }
        Ok(())
    }
}

/// R(x, λ) = A x + x³ − λ f (component-wise cube), A a fixed well-conditioned dense matrix:
/// a dense n×n Jacobian as the condensed harmonic balance has, at the cost of a mat-vec.
struct DenseCubic {
    a: Mat<f64>,
    f: Vec<f64>,
}

impl DenseCubic {
    fn new(n: usize) -> Self {
        let a =
            Mat::from_fn(n, n, |i, j| if i == j { 4.0 } else { ((i * 7 + j * 13) % 11) as f64 / (11.0 * n as f64) });
        DenseCubic { a, f: (0..n).map(|i| 1.0 + (i % 3) as f64).collect() }
    }
}

impl Problem for DenseCubic {
    fn dimension(&self) -> usize {
        self.f.len()
    }
    fn evaluate(
        &mut self,
        x: &[f64],
        lambda: f64,
        residual: &mut [f64],
        jacobian: Option<(MatMut<'_, f64>, &mut [f64])>,
    ) -> Result<(), ProblemError> {
        let n = x.len();
        for (i, r) in residual.iter_mut().enumerate() {
            let ax: f64 = x.iter().enumerate().map(|(j, xj)| self.a[(i, j)] * xj).sum();
            *r = ax + x[i].powi(3) - lambda * self.f[i];
        }
        if let Some((mut jx, dl)) = jacobian {
            for j in 0..n {
                for i in 0..n {
                    jx[(i, j)] = self.a[(i, j)];
                }
                jx[(j, j)] += 3.0 * x[j] * x[j];
                dl[j] = -self.f[j];
            }
        }
        Ok(())
    }
}

fn measure<P: Problem>(name: &str, mut make: impl FnMut() -> P, guess: &[f64], from: f64, to: f64, options: &Options) {
    let mut times = Vec::with_capacity(REPEATS);
    let mut branch: Option<Branch> = None;
    for _ in 0..REPEATS {
        let mut problem = make();
        let start = Instant::now();
        let b = continue_branch(&mut problem, guess, from, to, options, &mut Silent).expect("valid input");
        times.push(start.elapsed());
        branch = Some(b);
    }
    let branch = branch.expect("at least one run");
    let time = median(times).as_secs_f64();
    let points = branch.points.len();
    let iterations: usize = branch.points.iter().map(|p| p.iterations).sum();
    println!(
        "{name:<34} {points:>5} points {iterations:>5} Newton iterations {:>5} LU  {:>9.2} µs/point {:>8.2} µs/factorisation  (branch {:.3} ms, {:?})",
        branch.calls.factorizations,
        time / points as f64 * 1e6,
        time / branch.calls.factorizations as f64 * 1e6,
        time * 1e3,
        branch.termination
    );
}

/// Reference: one faer partial-pivot LU and solve of a dense (n+1)×(n+1) matrix, the bordered
/// system's size, without the continuation around it.
fn raw_lu(n: usize) {
    let size = n + 1;
    let a = Mat::from_fn(size, size, |i, j| if i == j { 4.0 } else { ((i * 7 + j * 13) % 11) as f64 / 11.0 });
    let rounds = 2000 / n.max(1) + 10;
    let mut times = Vec::with_capacity(REPEATS);
    for _ in 0..REPEATS {
        let start = Instant::now();
        for _ in 0..rounds {
            let lu = std::hint::black_box(&a).partial_piv_lu();
            let x = lu.solve(Mat::<f64>::ones(size, 1));
            std::hint::black_box(x);
        }
        times.push(start.elapsed() / rounds as u32);
    }
    println!(
        "{:<34} {:>9.2} µs per LU + solve (faer PartialPivLu, allocating)",
        format!("raw faer LU {size}×{size}"),
        median(times).as_secs_f64() * 1e6
    );
}

fn main() {
    println!("median of {REPEATS} runs; residuals are cheap, so the times are the continuation's own cost");
    for predictor in [Predictor::Secant, Predictor::Tangent, Predictor::Lagrange] {
        let options = Options { predictor, ..Options::default() };
        measure(&format!("Duffing n=2 {predictor:?}"), || Duffing, &[0.13, 0.003], 0.5, 2.5, &options);
    }
    for n in [60, 120, 240] {
        let options = Options::default();
        measure(&format!("dense cubic n={n} Secant"), || DenseCubic::new(n), &vec![0.0; n], 0.0, 20.0, &options);
        raw_lu(n);
    }
}
