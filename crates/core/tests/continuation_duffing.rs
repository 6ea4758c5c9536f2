//! First-order harmonic balance of a Duffing oscillator, m ẍ + c ẋ + k x + k₃ x³ = F cos Ωt,
//! written algebraically with x = a cos Ωt + b sin Ωt (the first harmonic of x³ is
//! ¾A²(a cos + b sin), A² = a² + b²):
//!
//! ```text
//! (k − mΩ² + ¾k₃A²) a + cΩ b − F = 0
//! (k − mΩ² + ¾k₃A²) b − cΩ a     = 0
//! ```
//!
//! continued in Ω across the hysteretic peak of the hardening oscillator, in both directions.
//! Independent checks: the closed-form frequency-response equation
//! [(k − mΩ² + ¾k₃A²)² + (cΩ)²] A² = F², and the peak against the backbone Ω² = (k + ¾k₃A²)/m.

use faer::MatMut;
use stickslip_core::continuation::{
    continue_branch, Branch, Options, Point, Predictor, Problem, ProblemError, Silent, TerminationReason,
};

#[derive(Clone, Copy)]
struct Duffing {
    m: f64,
    c: f64,
    k: f64,
    k3: f64,
    f: f64,
}

const DUFFING: Duffing = Duffing { m: 1.0, c: 0.05, k: 1.0, k3: 1.0, f: 0.1 };

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
        let Duffing { m, c, k, k3, f } = *self;
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

impl Duffing {
    /// The linear solution (k₃ = 0) at Ω: the natural first guess.
    fn linear_guess(&self, omega: f64) -> [f64; 2] {
        let re = self.k - self.m * omega * omega;
        let im = self.c * omega;
        let d = re * re + im * im;
        [self.f * re / d, self.f * im / d]
    }

    /// Relative error of the closed-form frequency-response equation at (Ω, A).
    fn response_equation_error(&self, omega: f64, amplitude: f64) -> f64 {
        let stiffness = self.k - self.m * omega * omega + 0.75 * self.k3 * amplitude * amplitude;
        let lhs = (stiffness * stiffness + (self.c * omega).powi(2)) * amplitude * amplitude;
        (lhs - self.f * self.f).abs() / (self.f * self.f)
    }

    /// Exact peak of the response curve. On the curve G(Ω, A) = 0, dA/dΩ = 0 means ∂G/∂Ω = 0:
    /// −4mΩ (k − mΩ² + ¾k₃A²) + 2c²Ω = 0, i.e. k − mΩ² + ¾k₃A² = c²/(2m). So the peak lies below
    /// the backbone by Ω_bb² − Ω_peak² = c²/(2m²), and A² (c⁴/(4m²) + c²Ω²) = F² there: one
    /// monotone equation in A, solved by bisection.
    fn peak(&self) -> (f64, f64) {
        let Duffing { m, c, k, k3, f } = *self;
        let omega2 = |a: f64| (k + 0.75 * k3 * a * a - c * c / (2.0 * m)) / m;
        let g = |a: f64| a * a * (c.powi(4) / (4.0 * m * m) + c * c * omega2(a)) - f * f;
        let (mut lo, mut hi) = (0.0, f / (c * (k / m).sqrt()));
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if g(mid) > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let a = 0.5 * (lo + hi);
        (omega2(a).sqrt(), a)
    }
}

fn amplitude(p: &Point) -> f64 {
    p.x[0].hypot(p.x[1])
}

fn sweep(from: f64, to: f64, options: &Options) -> Branch {
    let mut problem = DUFFING;
    continue_branch(&mut problem, &DUFFING.linear_guess(from), from, to, options, &mut Silent).expect("valid input")
}

/// Peak of the branch: the quadratic through the largest-amplitude point and its neighbours,
/// parametrised by the cumulative chord in (a, b, Ω), maximised.
fn interpolated_peak(points: &[Point]) -> (f64, f64) {
    let j = (1..points.len() - 1).max_by(|&i, &k| amplitude(&points[i]).total_cmp(&amplitude(&points[k]))).unwrap();
    let chord = |p: &Point, q: &Point| (p.x[0] - q.x[0]).hypot(p.x[1] - q.x[1]).hypot(p.lambda - q.lambda);
    let s = [-chord(&points[j - 1], &points[j]), 0.0, chord(&points[j], &points[j + 1])];
    let quadratic = |v: [f64; 3]| {
        // v(s) = v1 + d1 s + d2 s², through the three samples.
        let d0 = (v[1] - v[0]) / (s[1] - s[0]);
        let d1 = (v[2] - v[1]) / (s[2] - s[1]);
        let d2 = (d1 - d0) / (s[2] - s[0]);
        let slope = d0 + d2 * (s[1] - s[0]);
        (v[1], slope, d2)
    };
    let amp = quadratic([amplitude(&points[j - 1]), amplitude(&points[j]), amplitude(&points[j + 1])]);
    let om = quadratic([points[j - 1].lambda, points[j].lambda, points[j + 1].lambda]);
    let s_star = -amp.1 / (2.0 * amp.2);
    (om.0 + om.1 * s_star + om.2 * s_star * s_star, amp.0 + amp.1 * s_star + amp.2 * s_star * s_star)
}

fn fold_count(points: &[Point]) -> usize {
    let steps: Vec<f64> = points.windows(2).map(|w| w[1].lambda - w[0].lambda).collect();
    steps.windows(2).filter(|w| w[0] * w[1] < 0.0).count()
}

#[test]
fn duffing_frequency_sweeps_follow_the_closed_form_response_through_both_folds() {
    let (omega_peak, amplitude_peak) = DUFFING.peak();
    for predictor in [Predictor::Secant, Predictor::Tangent, Predictor::Lagrange] {
        let options = Options { predictor, ..Options::default() };
        for (from, to) in [(0.5, 2.5), (2.5, 0.5)] {
            let branch = sweep(from, to, &options);
            let label = format!("{predictor:?} {from} → {to}");
            assert_eq!(branch.termination, TerminationReason::ReachedEnd, "{label}");
            assert_eq!(branch.points.last().unwrap().lambda, to, "{label}");
            assert_eq!(fold_count(&branch.points), 2, "{label}: both folds of the hysteretic peak");
            // Call counts of a point reached without rejection: one factorisation per Newton
            // iteration (plus the tangent at the previous point, always for the first point),
            // one residual per iterate plus at most one residual-only check, a Jacobian per
            // iteration (and at the solution unless it was skipped).
            for (i, p) in branch.points.iter().enumerate().take(branch.points.len() - 1).skip(1) {
                if p.rejected == 0 {
                    let tangent = usize::from(i == 1 || predictor == Predictor::Tangent);
                    assert_eq!(p.calls.factorizations, p.iterations + tangent, "{label} {p:?}");
                    assert!(p.calls.residuals == p.iterations + 1 || p.calls.residuals == p.iterations + 2, "{p:?}");
                    assert!(p.calls.jacobians >= p.iterations && p.calls.jacobians <= p.iterations + 1, "{p:?}");
                }
            }
            if predictor != Predictor::Tangent {
                assert!(branch.calls.jacobians < branch.calls.residuals, "{label}: Jacobians at solutions skipped");
            }
            for p in &branch.points {
                // The residual is below 1e-10·F: the response equation, quadratic in the
                // residual-perturbed force, holds to ~2e-10 relative; 1e-8 leaves margin.
                let mut residual = [0.0; 2];
                DUFFING.clone().evaluate(&p.x, p.lambda, &mut residual, None).unwrap();
                assert!(residual[0].hypot(residual[1]) <= 1e-10 * DUFFING.f, "{label}: {p:?}");
                let error = DUFFING.response_equation_error(p.lambda, amplitude(p));
                assert!(error < 1e-8, "{label}: response equation off by {error:e} at Ω = {}", p.lambda);
            }
            // The peak of the computed branch against the exact peak. The quadratic through
            // three points spaced by at most max_step = 0.05 (scaled) interpolates to O(h³):
            // observed 0.2-4e-7 relative over the six sweeps; 2e-6 leaves a factor 5.
            let (omega_star, amplitude_star) = interpolated_peak(&branch.points);
            assert!(
                (amplitude_star / amplitude_peak - 1.0).abs() < 2e-6,
                "{label}: peak amplitude {amplitude_star} vs {amplitude_peak}"
            );
            assert!((omega_star / omega_peak - 1.0).abs() < 2e-6, "{label}: peak Ω {omega_star} vs {omega_peak}");
            // Backbone: the peak sits below Ω_bb(A)² = (k + ¾k₃A²)/m by exactly c²/(2m²)
            // (see `peak`), 5.5e-4 of Ω² here, i.e. ΔΩ/Ω = ζ²ω₀²/Ω² with ζ = c/(2√(km)). An
            // error of 2e-6 on Ω² is 0.4 % of the offset (observed ≤ 0.17 %): 1 % checks it.
            let Duffing { m, c, k, k3, .. } = DUFFING;
            let backbone2 = (k + 0.75 * k3 * amplitude_star * amplitude_star) / m;
            let offset = backbone2 - omega_star * omega_star;
            let expected = c * c / (2.0 * m * m);
            assert!(
                (offset / expected - 1.0).abs() < 1e-2,
                "{label}: backbone offset {offset:e}, expected {expected:e}"
            );
        }
    }
}

/// The same oscillator continued in the force level F at a fixed frequency above resonance,
/// from F = 0: the amplitude-force curve has two folds (the jump up of a hardening oscillator).
struct DuffingInForce {
    model: Duffing,
    omega: f64,
}

impl Problem for DuffingInForce {
    fn dimension(&self) -> usize {
        2
    }
    fn evaluate(
        &mut self,
        x: &[f64],
        force: f64,
        residual: &mut [f64],
        jacobian: Option<(MatMut<'_, f64>, &mut [f64])>,
    ) -> Result<(), ProblemError> {
        let mut model = Duffing { f: force, ..self.model };
        match jacobian {
            Some((jx, df)) => {
                let mut d_omega = [0.0; 2];
                model.evaluate(x, self.omega, residual, Some((jx, &mut d_omega)))?;
                df[0] = -1.0;
                df[1] = 0.0;
                Ok(())
            }
            None => model.evaluate(x, self.omega, residual, None),
        }
    }
}

#[test]
fn force_level_continuation_at_fixed_frequency_passes_the_jump_folds_from_zero_force() {
    // At Ω = 1.5 (k − mΩ² = −1.25), F(A) = A √((¾k₃A² − 1.25)² + (cΩ)²) rises to a local
    // maximum near A = 0.745 (F ≈ 0.62), falls to a minimum near A = 1.29 (F ≈ 0.097) and rises.
    let omega = 1.5;
    for (from, to, guess) in [(0.0, 1.0, [0.0, 0.0]), (1.0, 0.0, [-1.6, 0.0])] {
        let mut problem = DuffingInForce { model: DUFFING, omega };
        let branch = continue_branch(&mut problem, &guess, from, to, &Options::default(), &mut Silent).unwrap();
        let label = format!("F {from} → {to}");
        assert_eq!(branch.termination, TerminationReason::ReachedEnd, "{label}");
        assert_eq!(fold_count(&branch.points), 2, "{label}");
        let last = branch.points.last().unwrap();
        assert_eq!(last.lambda, to, "{label}");
        for p in &branch.points {
            // The residual tolerance is 1e-10 of ‖R(0, F = 1)‖ = 1 (the start has no force): the
            // response equation, F² = |Z|²A², then holds to ~2e-10 absolute; 1e-9 leaves margin.
            let a = amplitude(p);
            let stiffness = DUFFING.k - DUFFING.m * omega * omega + 0.75 * DUFFING.k3 * a * a;
            let error = ((stiffness * stiffness + (DUFFING.c * omega).powi(2)) * a * a - p.lambda * p.lambda).abs();
            assert!(error < 1e-9, "{label}: response equation off by {error:e} at F = {}", p.lambda);
        }
        // The lower fold is the local maximum of F(A) on the closed form (golden search on
        // [0.5, 1]). No point can pass it; the nearest point lies within half a step of it,
        // below it by the sagitta κ(h/2)²/2: observed 4-6e-4 relative with the default
        // max_step, so 2e-3 allows a 3× larger curvature or step before failing.
        let force_of = |a: f64| {
            let stiffness = DUFFING.k - DUFFING.m * omega * omega + 0.75 * DUFFING.k3 * a * a;
            a * (stiffness * stiffness + (DUFFING.c * omega).powi(2)).sqrt()
        };
        let (mut lo, mut hi) = (0.5, 1.0);
        let golden = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..100 {
            let (a1, a2) = (hi - golden * (hi - lo), lo + golden * (hi - lo));
            if force_of(a1) > force_of(a2) {
                hi = a2;
            } else {
                lo = a1;
            }
        }
        let fold = force_of(0.5 * (lo + hi));
        let f_max_lower = branch.points.iter().filter(|p| amplitude(p) < 1.0).map(|p| p.lambda).fold(0.0, f64::max);
        assert!(f_max_lower <= fold * (1.0 + 1e-9), "{label}: beyond the fold {fold}: {f_max_lower}");
        assert!(f_max_lower > fold * (1.0 - 2e-3), "{label}: fold {fold}, reached {f_max_lower}");
    }
}
