//! The corrector does not allocate: between two evaluations of the problem within one Newton
//! solve no memory is allocated (the bordered system is factored in place on buffers allocated
//! once per branch). Counted by a global allocator, in its own test binary.

use faer::MatMut;
use stickslip_core::continuation::{continue_branch, Options, Predictor, Problem, ProblemError, Silent};

mod allocation_counter;
use allocation_counter::allocations;

/// First-order harmonic balance of a Duffing oscillator (see continuation_duffing.rs) that
/// records the allocation count at every evaluation, in a buffer reserved beforehand.
struct Duffing {
    counts: Vec<usize>,
}

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
        assert!(self.counts.len() < self.counts.capacity(), "reserve more for the record");
        self.counts.push(allocations());
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

#[test]
fn newton_iterations_do_not_allocate() {
    for predictor in [Predictor::Secant, Predictor::Tangent, Predictor::Lagrange] {
        let mut problem = Duffing { counts: Vec::with_capacity(100_000) };
        let options = Options { predictor, ..Options::default() };
        let branch = continue_branch(&mut problem, &[0.13, 0.003], 0.5, 2.5, &options, &mut Silent).unwrap();
        let intervals = problem.counts.windows(2).count();
        let allocating = problem.counts.windows(2).filter(|w| w[1] != w[0]).count();
        let iterations: usize = branch.points.iter().map(|p| p.iterations).sum();
        // Memory is allocated only to store an accepted point (its x, the growing list): at most
        // once between consecutive evaluations per point, never between Newton iterations.
        assert!(
            allocating <= branch.points.len(),
            "{predictor:?}: {allocating} of {intervals} intervals between evaluations allocated, {} points",
            branch.points.len()
        );
        assert!(iterations > 2 * branch.points.len(), "{predictor:?}: the Newton iterations dominate the count");
    }
}
