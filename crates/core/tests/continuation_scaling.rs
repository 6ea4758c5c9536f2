//! Automatic scaling (Eq. 31's α is never the user's job): the same Duffing oscillator written
//! in units where x ~ 1e-5 m, Ω ~ 1e3 rad/s and forces ~ 1e3 N is continued exactly as in unit
//! magnitudes; and coarse steps near folds are cut back rather than accepted.

use faer::MatMut;
use stickslip_core::continuation::{
    continue_branch, Branch, Options, Point, Predictor, Problem, ProblemError, Silent, TerminationReason,
};

/// First-order harmonic balance of m ẍ + c ẋ + k x + k₃ x³ = F cos Ωt (see continuation_duffing.rs),
/// with unknowns, frequency and residual expressed in units `x_unit`, `omega_unit`, `force_unit`.
struct Duffing {
    x_unit: f64,
    omega_unit: f64,
    force_unit: f64,
}

const M: f64 = 1.0;
const C: f64 = 0.05;
const K: f64 = 1.0;
const K3: f64 = 1.0;
const F: f64 = 0.1;

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
        let (a, b, w) = (x[0] / self.x_unit, x[1] / self.x_unit, omega / self.omega_unit);
        let stiffness = K - M * w * w + 0.75 * K3 * (a * a + b * b);
        let fu = self.force_unit;
        residual[0] = fu * (stiffness * a + C * w * b - F);
        residual[1] = fu * (stiffness * b - C * w * a);
        if let Some((mut jx, dw)) = jacobian {
            let cx = fu / self.x_unit;
            jx[(0, 0)] = cx * (stiffness + 1.5 * K3 * a * a);
            jx[(0, 1)] = cx * (1.5 * K3 * a * b + C * w);
            jx[(1, 0)] = cx * (1.5 * K3 * a * b - C * w);
            jx[(1, 1)] = cx * (stiffness + 1.5 * K3 * b * b);
            let cw = fu / self.omega_unit;
            dw[0] = cw * (-2.0 * M * w * a + C * b);
            dw[1] = cw * (-2.0 * M * w * b - C * a);
        }
        Ok(())
    }
}

fn sweep(x_unit: f64, omega_unit: f64, force_unit: f64, options: &Options) -> Branch {
    let mut problem = Duffing { x_unit, omega_unit, force_unit };
    // Linear solution at the start, in the problem's units.
    let w = 0.5;
    let (re, im) = (K - M * w * w, C * w);
    let d = re * re + im * im;
    let guess = [x_unit * F * re / d, x_unit * F * im / d];
    continue_branch(&mut problem, &guess, 0.5 * omega_unit, 2.5 * omega_unit, options, &mut Silent).unwrap()
}

#[test]
fn the_branch_does_not_depend_on_the_units() {
    for predictor in [Predictor::Secant, Predictor::Tangent, Predictor::Lagrange] {
        let options = Options { predictor, ..Options::default() };
        let unit = sweep(1.0, 1.0, 1.0, &options);
        let physical = sweep(1e-5, 1e3, 1e3, &options);
        assert_eq!(unit.termination, TerminationReason::ReachedEnd);
        assert_eq!(physical.termination, TerminationReason::ReachedEnd);
        // Scaled variables and residuals are identical up to rounding, so every decision (step,
        // acceptance, iteration count) is the same: the same points in other units.
        assert_eq!(unit.points.len(), physical.points.len(), "{predictor:?}");
        for (p, q) in unit.points.iter().zip(&physical.points) {
            assert_eq!(p.iterations, q.iterations, "{predictor:?}");
            // Steps are exact products of growth factors, except the last, a computed distance.
            assert!((p.step - q.step).abs() <= 1e-12 * p.step, "{predictor:?}");
            // Only rounding differs (unit conversions are not exact in binary): observed 2e-14
            // relative at most, amplified by the conditioning near the folds; 1e-12 checks that
            // no decision differed (a different step or iteration would differ by ≥ 1e-10).
            assert!((q.lambda / 1e3 - p.lambda).abs() <= 1e-12 * p.lambda, "{predictor:?}");
            let amplitude = |v: &Point, unit: f64| v.x[0].hypot(v.x[1]) / unit;
            assert!((amplitude(q, 1e-5) - amplitude(p, 1.0)).abs() <= 1e-12 * amplitude(p, 1.0), "{predictor:?}");
        }
    }
}

#[test]
fn coarse_steps_near_folds_are_cut_back_and_the_folds_still_passed() {
    // Steps of up to 0.8 of the band: far too coarse for the peak. The angle and distance checks
    // must cut them back; every point still lies on the curve and both folds are passed.
    for predictor in [Predictor::Secant, Predictor::Tangent, Predictor::Lagrange] {
        let options = Options { predictor, initial_step: 0.2, max_step: 0.8, ..Options::default() };
        let branch = sweep(1.0, 1.0, 1.0, &options);
        assert_eq!(branch.termination, TerminationReason::ReachedEnd, "{predictor:?}");
        let rejected: usize = branch.points.iter().map(|p| p.rejected).sum();
        assert!(rejected > 0, "{predictor:?}: coarse steps must be rejected somewhere");
        let steps: Vec<f64> = branch.points.windows(2).map(|w| w[1].lambda - w[0].lambda).collect();
        let folds = steps.windows(2).filter(|w| w[0] * w[1] < 0.0).count();
        assert_eq!(folds, 2, "{predictor:?}");
        // The peak (closed form 1.31808, see continuation_duffing.rs) is approached by the
        // branch: the largest amplitude is within 5 % even with these steps.
        let top = branch.points.iter().map(|p| p.x[0].hypot(p.x[1])).fold(0.0, f64::max);
        assert!(top > 0.95 * 1.318080 && top <= 1.318081, "{predictor:?}: peak {top}");
    }
}
