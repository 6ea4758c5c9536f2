//! The maximum of a quantity along a branch, located between the sampled points
//! (`continuation::maximise_along`), against closed forms: the resonance peak of a linear
//! oscillator, and the peak of a hardening Duffing oscillator, which lies next to a fold.
use faer::MatMut;
use stickslip_core::continuation::{
    continue_branch, maximise_along, Bracket, Options, Point, Problem, ProblemError, Silent, TerminationReason,
};

/// One-harmonic balance of `m ẍ + c ẋ + k x + k3 x³ = F cos Ωt`, `x = a cos Ωt + b sin Ωt`,
/// λ = Ω: `(k − mΩ² + ¾ k3 A²) a + cΩ b = F`, `(k − mΩ² + ¾ k3 A²) b − cΩ a = 0`.
struct Oscillator {
    m: f64,
    c: f64,
    k: f64,
    k3: f64,
    f: f64,
}

impl Problem for Oscillator {
    fn dimension(&self) -> usize {
        2
    }
    fn evaluate(
        &mut self,
        x: &[f64],
        w: f64,
        r: &mut [f64],
        jacobian: Option<(MatMut<'_, f64>, &mut [f64])>,
    ) -> Result<(), ProblemError> {
        let (a, b) = (x[0], x[1]);
        let kappa = self.k - self.m * w * w + 0.75 * self.k3 * (a * a + b * b);
        r[0] = kappa * a + self.c * w * b - self.f;
        r[1] = kappa * b - self.c * w * a;
        if let Some((mut j, dl)) = jacobian {
            let g = 1.5 * self.k3;
            j[(0, 0)] = kappa + g * a * a;
            j[(0, 1)] = g * a * b + self.c * w;
            j[(1, 0)] = g * a * b - self.c * w;
            j[(1, 1)] = kappa + g * b * b;
            dl[0] = -2.0 * self.m * w * a + self.c * b;
            dl[1] = -2.0 * self.m * w * b - self.c * a;
        }
        Ok(())
    }
}

fn amplitude(x: &[f64]) -> f64 {
    x[0].hypot(x[1])
}

/// The branch from `w0` to `w1` at default steps, and the maximum located around its largest
/// sampled amplitude.
fn located_peak(p: &mut Oscillator, w0: f64, w1: f64) -> (Point, stickslip_core::continuation::Extremum) {
    let guess = [p.f / (p.k - p.m * w0 * w0), 0.0];
    let branch = continue_branch(p, &guess, w0, w1, &Options::default(), &mut Silent).unwrap();
    assert_eq!(branch.termination, TerminationReason::ReachedEnd);
    let pts = &branch.points;
    let i = (0..pts.len()).max_by(|&i, &j| amplitude(&pts[i].x).total_cmp(&amplitude(&pts[j].x))).unwrap();
    assert!(i > 0 && i + 1 < pts.len());
    let found = maximise_along(p, [&pts[i - 1], &pts[i], &pts[i + 1]], 1e-9, |_, x, _| Ok(amplitude(x))).unwrap();
    (pts[i].clone(), found)
}

#[test]
fn the_peak_of_a_linear_oscillator_is_located_at_its_closed_form() {
    // ζ = 2 %: the displacement peak is at ω_n √(1 − 2ζ²), of height F / (2ζ k √(1 − ζ²)).
    let (m, wn, zeta, f) = (2.0, 2.0 * std::f64::consts::PI * 100.0, 0.02, 10.0);
    let k = m * wn * wn;
    let mut p = Oscillator { m, c: 2.0 * zeta * m * wn, k, k3: 0.0, f };
    let (sampled, found) = located_peak(&mut p, 0.5 * wn, 1.5 * wn);
    let (w_peak, a_peak) = (wn * (1.0 - 2.0 * zeta * zeta).sqrt(), f / (2.0 * zeta * k * (1.0 - zeta * zeta).sqrt()));
    // The sampled maximum is off by the point density, the located one by round-off: a peak is
    // flat (A − A_peak ∝ (Ω − Ω_peak)²), so 1e-9 on s gives ~1e-9 of the bracket in Ω and
    // 1e-13 in A.
    assert!((sampled.lambda - w_peak).abs() > 1e-5 * w_peak, "the default steps happen to hit the peak");
    assert!((found.lambda - w_peak).abs() < 1e-9 * w_peak, "{} vs {w_peak}", found.lambda);
    assert!((found.value - a_peak).abs() < 1e-12 * a_peak, "{} vs {a_peak}", found.value);
    // The middle point, the scan (16 lattice points or more) and the arc's steps.
    assert!(found.solves < 50, "{} solves", found.solves);
}

#[test]
fn the_peak_of_a_hardening_duffing_oscillator_next_to_its_fold_is_located() {
    // Along the branch the amplitude is largest where the two frequencies of one amplitude
    // merge: with κ = k + ¾ k3 A², A² = 4m²F² / (4mκc² − c⁴) (discriminant of the quadratic in
    // Ω² of F² = A²[(κ − mΩ²)² + c²Ω²]), at mΩ² = κ − c²/(2m). Solved by fixed point.
    let (m, k, c, k3, f) = (1.0, 1.0e4, 2.0, 5.0e7, 2.0);
    let mut p = Oscillator { m, c, k, k3, f };
    let mut a2 = 1e-4;
    for _ in 0..200 {
        let kappa = k + 0.75 * k3 * a2;
        a2 = 4.0 * m * m * f * f / (4.0 * m * kappa * c * c - c.powi(4));
    }
    let kappa = k + 0.75 * k3 * a2;
    let w_peak = ((kappa - c * c / (2.0 * m)) / m).sqrt();
    let (_, found) = located_peak(&mut p, 50.0, 400.0);
    // The peak is the branch's point of horizontal tangent in A, a hair before the fold: the
    // bracket's hyperplanes cross the branch there transversally.
    assert!((found.value - a2.sqrt()).abs() < 1e-10 * a2.sqrt(), "{} vs {}", found.value, a2.sqrt());
    assert!((found.lambda - w_peak).abs() < 1e-6 * w_peak, "{} vs {w_peak}", found.lambda);
}

/// ω_n and ζ of [`resonance_at_default_steps`].
const WN: f64 = 2.0 * std::f64::consts::PI * 100.0;
const ZETA: f64 = 0.02;

/// A linear oscillator (2 kg, 100 Hz, ζ = 2 %, 10 N) swept over 50-150 Hz at default steps:
/// the problem, its points and the index of the largest sampled amplitude.
fn resonance_at_default_steps() -> (Oscillator, Vec<Point>, usize) {
    let (m, f) = (2.0, 10.0);
    let mut p = Oscillator { m, c: 2.0 * ZETA * m * WN, k: m * WN * WN, k3: 0.0, f };
    let guess = [f / (p.k - m * 0.25 * WN * WN), 0.0];
    let branch = continue_branch(&mut p, &guess, 0.5 * WN, 1.5 * WN, &Options::default(), &mut Silent).unwrap();
    let pts = branch.points;
    let i = (0..pts.len()).max_by(|&i, &j| amplitude(&pts[i].x).total_cmp(&amplitude(&pts[j].x))).unwrap();
    (p, pts, i)
}

#[test]
fn quantities_maximised_in_one_bracket_share_its_points_and_find_what_each_finds_alone() {
    // Two outputs of one resonance: the displacement amplitude A, and the velocity Ω A, which
    // peaks a little higher, at ω_n exactly against ω_n √(1 − 2ζ²); then the power A², which
    // peaks where A does.
    let (mut p, pts, i) = resonance_at_default_steps();
    let wn = WN;
    let bracket = [&pts[i - 1], &pts[i], &pts[i + 1]];
    let velocity = |_: &mut Oscillator, x: &[f64], w: f64| Ok(w * amplitude(x));
    let power = |_: &mut Oscillator, x: &[f64], _: f64| Ok(amplitude(x).powi(2));
    let alone = [
        maximise_along(&mut p, bracket, 1e-9, |_, x, _| Ok(amplitude(x))).unwrap(),
        maximise_along(&mut p, bracket, 1e-9, velocity).unwrap(),
        maximise_along(&mut p, bracket, 1e-9, power).unwrap(),
    ];
    let mut shared = Bracket::new(&mut p, bracket).unwrap();
    let found = [
        shared.maximise(&mut p, 1e-9, |_, x, _| Ok(amplitude(x))).unwrap(),
        shared.maximise(&mut p, 1e-9, velocity).unwrap(),
        shared.maximise(&mut p, 1e-9, power).unwrap(),
    ];
    // The same searches on the same points, solved to round-off from other guesses, so the
    // arcs' steps may differ by round-off: λ equal to the search's tolerance (1e-9 of the bracket's
    // chord, itself ~10 % of λ: 1e-10, asserted 1e-9), the value to round-off (the peak is
    // flat: 1e-12 asserted).
    for (s, a) in found.iter().zip(&alone) {
        assert!((s.lambda / a.lambda - 1.0).abs() < 1e-9, "{} vs {}", s.lambda, a.lambda);
        assert!((s.value / a.value - 1.0).abs() < 1e-12, "{} vs {}", s.value, a.value);
    }
    assert!((found[1].lambda - wn).abs() < 1e-9 * wn, "{} vs {wn}", found[1].lambda);
    assert!((found[0].lambda - found[1].lambda).abs() > 1e-4 * wn);
    // Each later search solved only the lattice points outside the earlier windows and its own
    // arc steps: the power's window is the amplitude's, so its search solved only its arc's
    // steps (to 1e-9, at most ~20), against a scan besides alone (each side of the vertex down
    // the flank to two points DROP below the best: 5 points at least, 9 here).
    assert_eq!(found[0].solves, alone[0].solves);
    assert!(found[1].solves < alone[1].solves, "{} solves shared, {} alone", found[1].solves, alone[1].solves);
    assert!(
        found[2].solves <= 20 && alone[2].solves >= found[2].solves + 5,
        "{} shared, {} alone",
        found[2].solves,
        alone[2].solves
    );
}

#[test]
fn a_spike_found_by_another_quantity_of_the_bracket_is_refined_for_this_one() {
    // Two quantities of one bracket: the amplitude A, and B, a smooth hump near the bracket's
    // start plus a spike at A's peak far narrower than the scan's lattice (a friction arc
    // that one output's window misses and another's finds: Harmony's envelope contact and
    // envelope top at 6000 N). Alone, B's search sees only the hump; after A's search, the
    // points solved at A's peak show the spike, which B's search then refines.
    let (mut p, pts, i) = resonance_at_default_steps();
    let (wn, zeta) = (WN, ZETA);
    let bracket = [&pts[i - 1], &pts[i], &pts[i + 1]];
    let w_peak = wn * (1.0 - 2.0 * zeta * zeta).sqrt();
    let (w0, span) = (pts[i - 1].lambda, pts[i + 1].lambda - pts[i - 1].lambda);
    // The spike: 1e-5 of the bracket wide, 500 times narrower than the lattice.
    let width = 1e-5 * span;
    let b = move |_: &mut Oscillator, _: &[f64], w: f64| {
        let hump = 1.0 - ((w - (w0 + 0.05 * span)) / span).powi(2);
        Ok(hump + 0.5 * (-((w - w_peak) / width).powi(2)).exp())
    };
    let alone = maximise_along(&mut p, bracket, 1e-9, b).unwrap();
    assert!(alone.value < 1.01, "the scan alone found the spike: {}", alone.value);
    let mut shared = Bracket::new(&mut p, bracket).unwrap();
    let a = shared.maximise(&mut p, 1e-9, |_, x, _| Ok(amplitude(x))).unwrap();
    assert!((a.lambda - w_peak).abs() < 1e-9 * w_peak, "{} vs {w_peak}", a.lambda);
    let found = shared.maximise(&mut p, 1e-9, b).unwrap();
    // The spike's top: the hump there plus 0.5, where the hump's slope (2e-6 of the spike's
    // curvature) moves it by ~1e-12 of the bracket: the value to 1e-9 (the search's tolerance of
    // 1e-9 on the chord, on a spike 1e-5 of it wide, gives (1e-4)² of its height).
    let hump_at_peak = 1.0 - ((w_peak - (w0 + 0.05 * span)) / span).powi(2);
    assert!((found.value - (hump_at_peak + 0.5)).abs() < 1e-9, "{} vs {}", found.value, hump_at_peak + 0.5);
    assert!((found.lambda - w_peak).abs() < 1e-3 * width, "{} vs {w_peak}", found.lambda);
}

#[test]
fn a_side_that_rises_towards_a_higher_top_is_scanned_beyond_its_low_points() {
    // A quantity of λ alone whose bracket misleads the envelope's parabola: the first end is
    // nearly as high as the middle point (1e-4 below it), the last end far lower (1e-2), so
    // the vertex lies between the first end and the middle, at ~0.26 of the bracket. The
    // quantity dips 2.7e-3 below the middle at 0.15, then rises through the middle to a top
    // 2.3e-3 above it at 0.8, and falls steeply to the last end. The scan from the vertex
    // towards the middle meets points more than twice the candidate threshold below the best,
    // but rising: they are not the flank of the peak, and the top beyond them is found.
    // Harmony's 2910 N level showed this (the envelope's peak was located 0.29 % low, on the
    // middle point; a grid of fixed-frequency solves confirms the top found now). Stopping
    // a side after two low points, rising or not, fails this.
    let (mut p, pts, i) = resonance_at_default_steps();
    let (l0, lm, l1) = (pts[i - 1].lambda, pts[i].lambda, pts[i + 1].lambda);
    let um = (lm - l0) / (l1 - l0);
    // Piecewise linear through knots (u, g), u the place on the bracket in λ.
    let rising = |u: f64| -2e-3 + 5e-3 * (u - 0.15) / 0.65;
    let gm = rising(um);
    let knots = [(0.0, gm - 1e-4), (0.15, -2e-3), (0.8, 3e-3), (1.0, gm - 1e-2)];
    let q = move |w: f64| {
        let u = (w - l0) / (l1 - l0);
        let k = knots.windows(2).position(|k| u <= k[1].0).unwrap_or(2);
        let ((ua, ga), (ub, gb)) = (knots[k], knots[k + 1]);
        1.0 + ga + (gb - ga) * (u - ua) / (ub - ua) - gm
    };
    assert!(um > 0.35 && um < 0.65, "the middle point at {um}");
    assert!((q(lm) - 1.0).abs() < 1e-15 && q(l0) < q(lm) && q(l1) < q(lm));
    let top = q(l0 + 0.8 * (l1 - l0));
    let found = maximise_along(&mut p, [&pts[i - 1], &pts[i], &pts[i + 1]], 1e-5, |_, _, w| Ok(q(w))).unwrap();
    // The top is a corner between straight sides: located to the tolerance on s (1e-5 of the
    // bracket) times the steeper side's slope (~6e-2 per unit of s), ~6e-7; asserted 1e-6.
    assert!((found.value - top).abs() < 1e-6, "{} against the top {top}", found.value);
}
