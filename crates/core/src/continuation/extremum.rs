//! The largest value of a quantity along a branch, located between the points the continuation
//! sampled: a resonance peak, whatever the point density.
//!
//! The three points around the largest sampled value bracket the maximum. Between the outer
//! two, the branch is parametrised by `s ∈ [0, 1]` along their chord `c` in scaled variables
//! (as the continuation's, Eq. 31): the point at `s` solves
//!
//! ```text
//! R(x, λ) = 0,      cᵀ (z − z_before − s c) = 0
//! ```
//!
//! the corrector of Eq. 32 on the hyperplane orthogonal to the chord, so that a fold inside the
//! bracket (a hardening peak) is parametrised as well as a plain peak. The quantity is scanned
//! at a few values of `s` (a friction peak has several local maxima, see below), then maximised
//! around the best, on each arc near the top, by a search that follows the corners where a
//! friction peak's arcs meet (the lines of their sides) and, on smooth tops, parabolas, with
//! Brent's safeguards (Brent 1973, ch. 5). It is written here rather than taken from `argmin`,
//! whose solver framework is far more than one bounded scalar search needs, and which has no
//! search for corners.

use std::collections::BTreeMap;

use super::linear::Workspace;
use super::{Point, Problem, ProblemError};

/// A point of the bracket: its scaled variables, and the bound on Newton's next update where
/// it was accepted (0: converged to round-off).
struct Solved {
    z: Vec<f64>,
    precision: f64,
}

/// The located maximum.
#[derive(Clone, Debug, PartialEq)]
pub struct Extremum {
    pub x: Vec<f64>,
    pub lambda: f64,
    /// Where on the chord between the bracket's ends (0 at the first, 1 at the last).
    pub s: f64,
    /// The quantity there.
    pub value: f64,
    /// Points solved on the branch to locate it (not counting those shared with an earlier
    /// search of the same [`Bracket`]).
    pub solves: usize,
}

/// 1 − 1/φ: the golden-section step.
const GOLDEN: f64 = 0.381_966_011_250_105_1;
/// Points solved at most to refine one arc.
const MAX_ARC_STEPS: usize = 60;
/// The best point of an arc and its two neighbours on one side are aligned, a side of a corner,
/// where the slopes of their two segments differ by at most this fraction: a few per cent along
/// a friction peak's side, ~100 % around a smooth top.
const ALIGNED: f64 = 0.25;
/// The best point's neighbours are lopsided when one lies this many times further than the
/// other: the parabola of the arc search is then taken on the near side
/// ([`next_arc_point`]).
const ASYMMETRIC: f64 = 4.0;
/// A point solved for another quantity of the bracket shows an arc this quantity's search
/// missed where it is higher than all this quantity's own points by more than this fraction.
const MISSED_ARC: f64 = 1e-7;
/// Newton iterations allowed for one point of the bracket.
const MAX_ITERATIONS: usize = 30;
/// Spacing of the scan on the bracket's chord (1 = the whole bracket, two continuation steps),
/// and the half-width of the scanned window beyond the envelope's vertex and the middle point.
/// The arcs of a friction peak (see [`Bracket::maximise`]) are ~0.1 of the bracket wide at the
/// default steps (Table 6, 300 samples), so the lattice puts several points on each; Harmony's
/// four joints make some narrower, and its highest arc lay up to 0.15 from the vertex (a
/// narrower window missed it by 1e-4, a coarser lattice by 2e-5). The window is widened while
/// the best point is at one of its ends.
const SCAN_SPACING: f64 = 0.02;
const WINDOW: f64 = 0.15;
/// Points solved within this distance start a new one (two lattice spacings and a half: the
/// scan's neighbours, the arcs' steps).
const NEAR: f64 = 2.5 * SCAN_SPACING;
/// A point is converged when its residual is at most this fraction of its unknowns' norm
/// (`R = x − λ u_F + H G` is a difference of terms of the size of x: ~1000 ulps of them).
const ROUND_OFF: f64 = 1e-13;
/// The scanned arcs that are maximised: those whose best scanned point is within this fraction
/// of the best. The tops of a friction peak's arcs differ by 1e-5 to 1e-4 near the maximum, a
/// scanned point is below its arc's top by up to ~4e-5 (Table 6 at 100 N).
const CANDIDATE: f64 = 2e-4;
/// A point of the scan is accepted once Newton's next update would move it by at most this
/// (scaled variables: of the bracket's x and λ spans), the arcs' points once it would move them
/// by 1e-4 of the search's tolerance if that is less (the same at the tolerance of 1e-5 that
/// peaks are located to). A value then errs by ~1e-10 of itself (measured against round-off on
/// Table 6), far below the 1e-5 by which arcs differ and the ~1e-8 a corner's slope gives over
/// the tolerance; the solve saves the Jacobian and evaluation that would only polish it (most
/// of the scan's points on Table 6). The located point itself is converged to round-off.
const SCAN_PRECISION: f64 = 1e-9;
/// CANDIDATE is for the roughest tops seen (the arcs of Table 6 and Harmony). A top whose
/// scanned values are smooth needs less: its arcs' tops lie within the scan's ripple of their
/// envelope, so the threshold follows the ripple measured on the lattice ([`ripple`]),
/// RIPPLE_MARGIN times it, down to CANDIDATE_FLOOR: a thousand times the precision of the
/// located values (~1e-8 at the tolerance of 1e-5). A side of the scan stops after two
/// consecutive points fall to more than twice the threshold below the best, so that an arc
/// whose top is within the threshold of the best is never left out.
const RIPPLE_MARGIN: f64 = 8.0;
const CANDIDATE_FLOOR: f64 = 1e-5;

/// Locate the maximum of `quantity(problem, x, λ)` along the branch of `problem` between
/// `before` and `after`, given `middle`, a converged point between them where the quantity is
/// at least as large as at both. `tolerance` is on `s` (1 = the bracket's chord); the point
/// found is converged to round-off (Newton until the scaled update stops decreasing).
pub fn maximise_along<P: Problem>(
    problem: &mut P,
    bracket: [&Point; 3],
    tolerance: f64,
    quantity: impl FnMut(&mut P, &[f64], f64) -> Result<f64, ProblemError>,
) -> Result<Extremum, ProblemError> {
    Bracket::new(problem, bracket)?.maximise(problem, tolerance, quantity)
}

/// The branch between three of its points, where several quantities may be maximised in turn
/// ([`Bracket::maximise`]): the outputs of a structure that peak between the same two points
/// share the points solved there. The scan of each maximum lies on one lattice of `s` (spacing
/// `SCAN_SPACING`), so the scans of quantities whose vertices are near each other solve
/// mostly the same points, once.
pub struct Bracket {
    z0: Vec<f64>,
    zm: Vec<f64>,
    z1: Vec<f64>,
    /// `s` of the middle point.
    sm: f64,
    path: ChordPath,
    /// Points solved so far, by `s` (bit pattern: lattice points are computed identically):
    /// `None` where the branch could not be solved.
    solved: BTreeMap<u64, Option<Solved>>,
    /// Points solved on the branch so far.
    pub solves: usize,
}

impl Bracket {
    pub fn new<P: Problem>(problem: &mut P, [before, middle, after]: [&Point; 3]) -> Result<Self, ProblemError> {
        // Scaled variables z = [x/s_x, λ/s_λ], λ by its span: the chord has comparable x and
        // λ parts.
        let lambda_scale = (after.lambda - before.lambda).abs().max(1e-12 * middle.lambda.abs()).max(f64::MIN_POSITIVE);
        Self::scaled(problem, [before, middle, after], lambda_scale)
    }

    /// The branch between three points around a fold, where λ turns back: λ scaled by its own
    /// magnitude, so that the chord lies along x and its hyperplanes cross the fold
    /// transversally (λ's span, as [`Self::new`] scales it, would make them hyperplanes of
    /// nearly constant λ, which meet the branch twice near a fold or not at all).
    pub fn across_fold<P: Problem>(problem: &mut P, points: [&Point; 3]) -> Result<Self, ProblemError> {
        let lambda_scale = points.iter().map(|p| p.lambda.abs()).fold(f64::MIN_POSITIVE, f64::max);
        Self::scaled(problem, points, lambda_scale)
    }

    fn scaled<P: Problem>(
        problem: &mut P,
        [before, middle, after]: [&Point; 3],
        lambda_scale: f64,
    ) -> Result<Self, ProblemError> {
        let x_scale = [before, middle, after]
            .iter()
            .map(|p| p.x.iter().map(|v| v * v).sum::<f64>().sqrt())
            .fold(f64::MIN_POSITIVE, f64::max);
        let scaled = |p: &Point| -> Vec<f64> {
            p.x.iter().map(|v| v / x_scale).chain(std::iter::once(p.lambda / lambda_scale)).collect()
        };
        let (z0, zm, z1) = (scaled(before), scaled(middle), scaled(after));
        let chord: Vec<f64> = z1.iter().zip(&z0).map(|(b, a)| b - a).collect();
        let chord2: f64 = chord.iter().map(|c| c * c).sum();
        let sm = chord.iter().zip(zm.iter().zip(&z0)).map(|(c, (m, a))| c * (m - a)).sum::<f64>() / chord2;
        if !(sm > 0.0 && sm < 1.0) {
            return Err(ProblemError::new(format!("the middle point (s = {sm}) is not between the bracket's ends")));
        }
        let path = ChordPath::new(problem, &z0, &z1, x_scale, lambda_scale);
        // The middle point is the continuation's, converged to its tolerance (1e-10 of the
        // residual scale by default): as good as a scan's point, and its own value.
        let solved = BTreeMap::from([(sm.to_bits(), Some(Solved { z: zm.clone(), precision: SCAN_PRECISION }))]);
        Ok(Bracket { z0, zm, z1, sm, path, solved, solves: 0 })
    }

    /// `s` of the bracket's middle point on the chord between its ends.
    pub fn middle(&self) -> f64 {
        self.sm
    }

    /// The point at `s` (scaled) and its precision, solved once to `precision` (0: to
    /// round-off; see [`ChordPath::solve`]), further if asked for more later: from the line through the nearest points solved on either side, or
    /// the two nearest on one side, if they are near (the scan's neighbours, the arcs' steps: one
    /// or two Newton iterations), else from the parabola through the three points. `None` if
    /// it cannot be solved there.
    fn point<P: Problem>(
        &mut self,
        problem: &mut P,
        s: f64,
        precision: f64,
    ) -> Result<Option<(&[f64], f64)>, ProblemError> {
        let key = s.to_bits();
        let wanted = |p: &Option<Solved>| p.as_ref().is_some_and(|p| p.precision > precision);
        if let Some(Some(point)) = self.solved.get_mut(&key).filter(|p| wanted(p)) {
            // Wanted more precise than it was solved: Newton goes on from it.
            self.solves += 1;
            let mut z = std::mem::take(&mut point.z);
            let solved = self.path.solve(problem, s, &mut z, precision)?;
            self.solved.insert(key, solved.map(|exact| Solved { z, precision: if exact { 0.0 } else { precision } }));
        }
        if !self.solved.contains_key(&key) {
            let n = self.path.n;
            let mut z = vec![0.0; n + 1];
            // The nearest points solved on either side (keys of positive `s` sort as `s`).
            let near = |t: f64| (s - t).abs() <= NEAR;
            let below: Vec<(f64, &Vec<f64>)> = self
                .solved
                .range(..key)
                .rev()
                .filter_map(|(k, p)| Some((f64::from_bits(*k), &p.as_ref()?.z)))
                .take_while(|(t, _)| near(*t))
                .take(2)
                .collect();
            let above: Vec<(f64, &Vec<f64>)> = self
                .solved
                .range(key..)
                .filter_map(|(k, p)| Some((f64::from_bits(*k), &p.as_ref()?.z)))
                .take_while(|(t, _)| near(*t))
                .take(2)
                .collect();
            // Between two solved points, the line through them; else the line through the two
            // nearest on one side; else a shift along the chord from the one nearest; else
            // the parabola through the bracket's three points.
            let line = match (below.first(), above.first()) {
                (Some(a), Some(b)) => Some((*a, *b)),
                _ => below.get(1).map(|b| (below[0], *b)).or_else(|| above.get(1).map(|b| (above[0], *b))),
            };
            match (line, below.first().or(above.first())) {
                (Some(((s1, z1), (s0, z0))), _) => {
                    let t = (s - s1) / (s1 - s0);
                    for i in 0..=n {
                        z[i] = z1[i] + t * (z1[i] - z0[i]);
                    }
                }
                (None, Some((s1, z1))) => {
                    for i in 0..=n {
                        z[i] = z1[i] + (s - s1) * self.path.chord[i];
                    }
                }
                (None, None) => {
                    let sm = self.sm;
                    let (l0, lm, l1) =
                        ((s - sm) * (s - 1.0) / sm, s * (s - 1.0) / (sm * (sm - 1.0)), s * (s - sm) / (1.0 - sm));
                    for i in 0..=n {
                        z[i] = l0 * self.z0[i] + lm * self.zm[i] + l1 * self.z1[i];
                    }
                }
            }
            self.solves += 1;
            let solved = self.path.solve(problem, s, &mut z, precision)?;
            self.solved.insert(key, solved.map(|exact| Solved { z, precision: if exact { 0.0 } else { precision } }));
        }
        Ok(self.solved[&key].as_ref().map(|p| (p.z.as_slice(), p.precision)))
    }

    /// The maximum of `quantity(problem, x, λ)` between the bracket's ends, to `tolerance` on
    /// `s`. `solves` of the result counts the points solved for it: not those an earlier search
    /// of this bracket solved already.
    pub fn maximise<P: Problem>(
        &mut self,
        problem: &mut P,
        tolerance: f64,
        mut quantity: impl FnMut(&mut P, &[f64], f64) -> Result<f64, ProblemError>,
    ) -> Result<Extremum, ProblemError> {
        let n = self.path.n;
        let (x_scale, lambda_scale, sm) = (self.path.x_scale, self.path.lambda_scale, self.sm);
        let solved_before = self.solves;
        // At the bracket's ends, the continuation's points as they are: they only place the
        // envelope's vertex.
        let mut at_end = |z: &[f64]| {
            let x: Vec<f64> = z[..n].iter().map(|v| v * x_scale).collect();
            quantity(problem, &x, z[n] * lambda_scale)
        };
        let (f0, f1) = (at_end(&self.z0)?, at_end(&self.z1)?);
        // The quantity at s, kept by `s` with the precision of its point.
        let mut values: BTreeMap<u64, (f64, f64)> = BTreeMap::new();
        let mut value_at = |bracket: &mut Bracket,
                            problem: &mut P,
                            values: &mut BTreeMap<u64, (f64, f64)>,
                            s: f64,
                            precision: f64|
         -> Result<f64, ProblemError> {
            let Some((z, precision)) = bracket.point(problem, s, precision)? else {
                // A point that cannot be solved is not the maximum (recorded so: a best point
                // that fails to converge further gives way to the next).
                values.insert(s.to_bits(), (f64::NEG_INFINITY, 0.0));
                return Ok(f64::NEG_INFINITY);
            };
            let x: Vec<f64> = z[..n].iter().map(|v| v * x_scale).collect();
            let value = quantity(problem, &x, z[n] * lambda_scale)?;
            values.insert(s.to_bits(), (value, precision));
            Ok(value)
        };

        // A friction peak is a chain of smooth arcs joined at corners: the slip instants move
        // in steps of one time sample as the phase turns through the resonance. Each arc has
        // its own local maximum, within ~1e-5 of the others near the top. The three sampled
        // points place the envelope's vertex (a parabola through them); a scan on a lattice
        // finer than the arcs around it finds the arcs near the top, and `next_arc_point` the
        // maximum of each arc whose scanned best is near the best (the highest is kept).
        let fm = value_at(self, problem, &mut values, sm, SCAN_PRECISION)?;
        // Vertex of the parabola through (0, f0), (sm, fm), (1, f1).
        let (d0, d1) = (sm * (fm - f1), (sm - 1.0) * (fm - f0));
        let denominator = d0 - d1;
        let vertex = if denominator != 0.0 && denominator.is_finite() {
            (sm - 0.5 * (sm * d0 - (sm - 1.0) * d1) / denominator).clamp(0.0, 1.0)
        } else {
            sm
        };
        let mut samples: Vec<(f64, f64)> = vec![(0.0, f64::NEG_INFINITY), (sm, fm), (1.0, f64::NEG_INFINITY)];
        let lattice = |k: i64| k as f64 * SCAN_SPACING;
        // The window spans the vertex and the middle point: on a friction peak, whose top is a
        // chain of arcs rather than a parabola, the highest arc may lie near either.
        let (mut first, mut last) = (
            ((vertex.min(sm) - WINDOW) / SCAN_SPACING).ceil() as i64,
            ((vertex.max(sm) + WINDOW) / SCAN_SPACING).floor() as i64,
        );
        // Scanned outward from the vertex, each side until the window's end or until two
        // consecutive points fall to more than twice the candidate threshold below the best:
        // the peak's flank, where no arc can rise to within the threshold of the top.
        let centre = ((vertex / SCAN_SPACING).round() as i64).clamp(first, last);
        let mut top = fm;
        // The scanned values by lattice index, for the ripple.
        let mut scanned: BTreeMap<i64, f64> = BTreeMap::new();
        for side in [1i64, -1] {
            let (mut low, mut previous) = (0, f64::INFINITY);
            let mut k = if side == 1 { centre } else { centre - 1 };
            while (first..=last).contains(&k) && low < 2 {
                if lattice(k) > 0.0 && lattice(k) < 1.0 {
                    let value = value_at(self, problem, &mut values, lattice(k), SCAN_PRECISION)?;
                    samples.push((lattice(k), value));
                    scanned.insert(k, value);
                    top = top.max(value);
                    // Low and falling: a side that rises towards a best point beyond it (the
                    // middle one, where the vertex was off) goes on.
                    let drop = 2.0 * candidate(&scanned, top);
                    low = if value < top - drop * top.abs() && value < previous { low + 1 } else { 0 };
                    previous = value;
                }
                k += side;
            }
            // The window ends where this side's scan stopped.
            if side == 1 {
                last = k - side;
            } else {
                first = k - side;
            }
        }
        // Widened while the best scanned point is at an end of the window: the vertex of the
        // sampled parabola was off (a peak far from symmetric).
        loop {
            samples.sort_by(|a, b| a.0.total_cmp(&b.0));
            let best = (1..samples.len() - 1).max_by(|&a, &b| samples[a].1.total_cmp(&samples[b].1)).expect("interior");
            let k = if samples[best].0 == lattice(first) && lattice(first - 1) > 0.0 {
                first -= 1;
                first
            } else if samples[best].0 == lattice(last) && lattice(last + 1) < 1.0 {
                last += 1;
                last
            } else {
                break;
            };
            let value = value_at(self, problem, &mut values, lattice(k), SCAN_PRECISION)?;
            samples.push((lattice(k), value));
            scanned.insert(k, value);
        }
        let top = samples.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
        let candidate = candidate(&scanned, top);
        if top.is_finite() {
            // The arcs near the top: scanned points higher than their scanned neighbours (an
            // end of the window is not, the bracket's ends are not scanned), within the threshold
            // of the best, highest first.
            let mut candidates: Vec<usize> = (1..samples.len() - 1)
                .filter(|&j| {
                    let (before, here, after) = (samples[j - 1].1, samples[j].1, samples[j + 1].1);
                    before.is_finite()
                        && after.is_finite()
                        && here >= before
                        && here >= after
                        && here >= top - candidate * top.abs()
                })
                .collect();
            candidates.sort_by(|&a, &b| samples[b].1.total_cmp(&samples[a].1));
            // The arcs' points to a precision far below the tolerance, so that their comparisons are
            // those of points converged to round-off.
            let refined = (1e-4 * tolerance).min(SCAN_PRECISION);
            for j in candidates {
                let (a, b) = (samples[j - 1].0, samples[j + 1].0);
                for _ in 0..MAX_ARC_STEPS {
                    let Some(s) = next_arc_point(&values, a, b, tolerance) else { break };
                    value_at(self, problem, &mut values, s, refined)?;
                }
            }
            // The points solved for the bracket's other quantities (their scans and arcs) cost
            // no solve here. One higher than all this quantity's own points by more than the
            // precision a corner is located to (~2e-8 of the value: its slope times the
            // tolerance) lies on an arc this quantity's window missed (a narrow spike: Harmony's
            // envelope contact at 6000 N, 2e-5 above the arc its window found, beside the
            // envelope top's); that arc is refined too. The others' points are left out of
            // this quantity's values otherwise.
            let own = values.values().map(|v| v.0).fold(f64::NEG_INFINITY, f64::max);
            let earlier: Vec<(f64, f64)> = self
                .solved
                .iter()
                .filter(|(key, _)| !values.contains_key(key))
                .filter_map(|(key, point)| Some((f64::from_bits(*key), point.as_ref()?.precision)))
                .collect();
            let mut higher = (f64::NAN, own + MISSED_ARC * own.abs());
            for &(s, precision) in &earlier {
                let value = value_at(self, problem, &mut values, s, precision)?;
                if value > higher.1 {
                    higher = (s, value);
                }
            }
            // Between its nearest points on either side (the other quantity's).
            let around = (!higher.0.is_nan()).then(|| {
                let a = values.range(..higher.0.to_bits()).next_back().map_or(0.0, |(k, _)| f64::from_bits(*k));
                let b = values.range(higher.0.to_bits()..).nth(1).map_or(1.0, |(k, _)| f64::from_bits(*k));
                (a, b)
            });
            for (s, _) in earlier {
                if around.is_none_or(|(a, b)| s < a || s > b) {
                    values.remove(&s.to_bits());
                }
            }
            if let Some((a, b)) = around {
                for _ in 0..MAX_ARC_STEPS {
                    let Some(s) = next_arc_point(&values, a, b, tolerance) else { break };
                    value_at(self, problem, &mut values, s, refined)?;
                }
            }
        }
        // The best point, converged to round-off (a scan's point is solved further if it is
        // the best, and may then be overtaken).
        let (value, s) = loop {
            let Some((&key, &(value, precision))) = values.iter().max_by(|a, b| a.1 .0.total_cmp(&b.1 .0)) else {
                break (f64::NEG_INFINITY, sm);
            };
            if precision == 0.0 || !value.is_finite() {
                break (value, f64::from_bits(key));
            }
            value_at(self, problem, &mut values, f64::from_bits(key), 0.0)?;
        };
        if !value.is_finite() {
            return Err(ProblemError::new("no point of the bracket could be solved"));
        }
        let best_z = &self.solved[&s.to_bits()].as_ref().expect("the best point was solved").z;
        Ok(Extremum {
            x: best_z[..n].iter().map(|v| v * x_scale).collect(),
            lambda: best_z[n] * lambda_scale,
            s,
            value,
            solves: self.solves - solved_before,
        })
    }
}

/// The threshold below the best scanned value within which an arc is refined (see
/// CANDIDATE; a side of the scan stops at twice it): RIPPLE_MARGIN times the ripple of the
/// scanned values, between CANDIDATE_FLOOR and CANDIDATE, and CANDIDATE until four
/// consecutive lattice points show the ripple.
fn candidate(scanned: &BTreeMap<i64, f64>, top: f64) -> f64 {
    ripple(scanned, top).map_or(CANDIDATE, |r| (RIPPLE_MARGIN * r).clamp(CANDIDATE_FLOOR, CANDIDATE))
}

/// The ripple of values on consecutive lattice points, relative to `top`: a quarter of the
/// largest third difference over four, which is the most a scanned point can lie below the
/// top of its arc. A corner between sides of slopes ±m, sampled every h, makes third
/// differences up to 2 m h, four times the m h / 2 by which the nearest lattice point can miss
/// the corner; a smooth top's are its third derivative times h³. `None` until four consecutive
/// points are known (or a value is not finite: a point that failed).
fn ripple(scanned: &BTreeMap<i64, f64>, top: f64) -> Option<f64> {
    if !(top.is_finite() && top != 0.0) {
        return None;
    }
    let mut window = [(i64::MIN, 0.0); 4];
    let mut largest: Option<f64> = None;
    for (&k, &v) in scanned {
        window.rotate_left(1);
        window[3] = (k, v);
        if window[0].0 == i64::MIN || window[3].0 - window[0].0 != 3 {
            continue;
        }
        let [a, b, c, d] = window.map(|p| p.1);
        let third = (d - 3.0 * c + 3.0 * b - a).abs();
        if !third.is_finite() {
            return None;
        }
        largest = Some(largest.map_or(third, |l: f64| l.max(third)));
    }
    largest.map(|l| 0.25 * l / top.abs())
}

/// Locate a zero of `quantity(problem, x, λ)` along the branch of `problem` between two
/// converged points where it has opposite signs (a Floquet exponent crossing the imaginary
/// axis: a bifurcation). The branch between them is parametrised as in [`maximise_along`]; the
/// zero is bracketed by the Illinois variant of regula falsi (superlinear, and never leaves
/// the bracket), to `tolerance` on `s` (1 = the chord between the two points).
pub fn zero_along<P: Problem>(
    problem: &mut P,
    [before, after]: [&Point; 2],
    tolerance: f64,
    mut quantity: impl FnMut(&mut P, &[f64], f64) -> Result<f64, ProblemError>,
) -> Result<Extremum, ProblemError> {
    let n = problem.dimension();
    let x_scale =
        [before, after].iter().map(|p| p.x.iter().map(|v| v * v).sum::<f64>().sqrt()).fold(f64::MIN_POSITIVE, f64::max);
    // λ relative to itself (not to its change between the points, as for a peak): a crossing
    // may sit at a fold, where λ hardly changes while x does, and the hyperplanes orthogonal
    // to the chord must then cut the branch across x, once.
    let lambda_scale = before.lambda.abs().max(after.lambda.abs()).max(f64::MIN_POSITIVE);
    let scaled = |p: &Point| -> Vec<f64> {
        p.x.iter().map(|v| v / x_scale).chain(std::iter::once(p.lambda / lambda_scale)).collect()
    };
    let (z0, z1) = (scaled(before), scaled(after));
    let mut path = ChordPath::new(problem, &z0, &z1, x_scale, lambda_scale);
    let (mut a, mut b) = ((0.0, z0.clone()), (1.0, z1.clone()));
    let mut value = |problem: &mut P, z: &[f64]| {
        let x: Vec<f64> = z[..n].iter().map(|v| v * x_scale).collect();
        quantity(problem, &x, z[n] * lambda_scale)
    };
    let (mut fa, mut fb) = (value(problem, &a.1)?, value(problem, &b.1)?);
    if fa * fb > 0.0 || fa.is_nan() || fb.is_nan() {
        return Err(ProblemError::new(format!("no sign change between the two points ({fa} and {fb})")));
    }
    let mut solves = 0;
    let mut side = 0i8;
    let mut z = vec![0.0; n + 1];
    while (b.0 - a.0) > tolerance && solves < 100 {
        let s = if fa != fb { (a.0 * fb - b.0 * fa) / (fb - fa) } else { 0.5 * (a.0 + b.0) };
        // Keep the trial strictly inside the bracket, off its ends by a little of its width.
        let width = b.0 - a.0;
        let mut s = s.clamp(a.0 + 0.01 * width, b.0 - 0.01 * width);
        let mut solved = false;
        // Near a branch point the corrector's bordered matrix is nearly singular on every
        // hyperplane (∂R/∂z has rank n − 1 there) and Newton cannot resolve the branch from the
        // other one crossing it, which is as near: a trial that regula falsi puts there is
        // replaced by one an eighth of the bracket or more away from it, towards its farther end.
        let farther = if s - a.0 > b.0 - s { a.0 } else { b.0 };
        for trial in [s, s + 0.25 * (farther - s)] {
            s = trial;
            for i in 0..=n {
                let w = (s - a.0) / width;
                z[i] = (1.0 - w) * a.1[i] + w * b.1[i];
            }
            solves += 1;
            solved = path.solve(problem, s, &mut z, 0.0)?.is_some();
            if solved {
                break;
            }
        }
        if !solved {
            return Err(ProblemError::new(format!("the branch could not be solved at {s} of the bracket")));
        }
        let fs = value(problem, &z)?;
        if fs == 0.0 {
            a = (s, z.clone());
            b = (s, z.clone());
            break;
        }
        // Illinois: the end kept twice in a row has its value halved, so that both ends move.
        if fs * fb > 0.0 {
            b = (s, z.clone());
            fb = fs;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            a = (s, z.clone());
            fa = fs;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
    }
    // The end nearer the zero (the values may have been halved: compare them afresh).
    let ((sa, za), (sb, zb)) = (a, b);
    let (va, vb) = (value(problem, &za)?, value(problem, &zb)?);
    let (s, z, value) = if va.abs() <= vb.abs() { (sa, za, va) } else { (sb, zb, vb) };
    Ok(Extremum { x: z[..n].iter().map(|v| v * x_scale).collect(), lambda: z[n] * lambda_scale, s, value, solves })
}

/// Points of a branch between two of its points `z0` and `z1` (scaled, as the continuation's
/// variables), parametrised by `s` along their chord `c`: the point at `s` solves `R(x, λ) = 0`
/// with `cᵀ (z − z0 − s c) = 0` (the corrector of Eq. 32 on the hyperplane orthogonal to the
/// chord), so that a fold between them is parametrised as well as a plain arc.
struct ChordPath {
    n: usize,
    z0: Vec<f64>,
    chord: Vec<f64>,
    x_scale: f64,
    lambda_scale: f64,
    workspace: Workspace,
    x: Vec<f64>,
}

impl ChordPath {
    fn new<P: Problem>(problem: &mut P, z0: &[f64], z1: &[f64], x_scale: f64, lambda_scale: f64) -> Self {
        let n = problem.dimension();
        ChordPath {
            n,
            z0: z0.to_vec(),
            chord: z1.iter().zip(z0).map(|(b, a)| b - a).collect(),
            x_scale,
            lambda_scale,
            workspace: Workspace::new(problem),
            x: vec![0.0; n],
        }
    }

    /// Solve the point at `s` from the guess in `z`, into `z`: converged to round-off (Newton
    /// until the scaled update stops decreasing), or, if `early` is positive, once Newton's next
    /// update is at most `early`, left where it was last evaluated. `Some(true)` if converged
    /// to round-off, `Some(false)` if accepted early, `None` if it cannot be solved there.
    fn solve<P: Problem>(
        &mut self,
        problem: &mut P,
        s: f64,
        z: &mut [f64],
        early: f64,
    ) -> Result<Option<bool>, ProblemError> {
        let n = self.n;
        let target: Vec<f64> = self.z0.iter().zip(&self.chord).map(|(a, c)| a + s * c).collect();
        let mut last_step = f64::INFINITY;
        // Residuals relative to their change across the bracket, ‖∂R/∂λ‖ s_λ (set at the first
        // evaluation), so that the rows of the bordered matrix are of one magnitude.
        let mut residual_scale = 0.0;
        let lazy = self.workspace.lazy;
        for iteration in 0..MAX_ITERATIONS {
            for (xi, zi) in self.x.iter_mut().zip(z.iter()) {
                *xi = zi * self.x_scale;
            }
            let lambda = z[n] * self.lambda_scale;
            // A problem that completes residuals to Jacobians: the residual first, the Jacobian
            // only if the iterate is not converged.
            let evaluated = self.workspace.evaluate(problem, &self.x, lambda, !lazy || iteration == 0);
            // Converged to round-off: the residual is down to a thousand ulps of the unknowns.
            // A friction residual is piecewise affine in x, so one step from a guess on the
            // same arc lands there, and this saves the Jacobian and solve that would only
            // show a negligible update.
            if evaluated.is_ok() && iteration > 0 {
                let r = self.workspace.residual.iter().map(|v| v * v).sum::<f64>().sqrt();
                if r <= ROUND_OFF * self.x.iter().map(|v| v * v).sum::<f64>().sqrt() {
                    return Ok(Some(true));
                }
                // Before the Jacobian is completed here, the next update estimated with the
                // factors of the last one (a chord step: one back-substitution).
                let workspace = &mut self.workspace;
                if early > 0.0 && lazy && workspace.holds_bordered_factors() {
                    let constraint: f64 =
                        self.chord.iter().zip(z.iter().zip(&target)).map(|(c, (a, b))| c * (a - b)).sum();
                    for i in 0..n {
                        workspace.rhs[i] = -workspace.residual[i] / residual_scale;
                    }
                    workspace.rhs[n] = -constraint;
                    if workspace.solve_with_bordered_factors()
                        && workspace.rhs.iter().map(|d| d * d).sum::<f64>().sqrt() <= early
                    {
                        return Ok(Some(false));
                    }
                }
            }
            let evaluated = match evaluated {
                Ok(()) if lazy && iteration > 0 => self.workspace.complete(problem),
                other => other,
            };
            match evaluated {
                Ok(()) => {}
                // A law that fails on this iterate: the point cannot be solved, not the search.
                Err(e) if e.at_trial_iterate => return Ok(None),
                Err(e) => return Err(e),
            }
            let workspace = &mut self.workspace;
            if residual_scale == 0.0 {
                residual_scale = workspace.dr_dlambda.iter().map(|v| v * v).sum::<f64>().sqrt() * self.lambda_scale;
                if !(residual_scale.is_finite() && residual_scale > 0.0) {
                    residual_scale = 1.0;
                }
            }
            let constraint: f64 = self.chord.iter().zip(z.iter().zip(&target)).map(|(c, (a, b))| c * (a - b)).sum();
            for i in 0..n {
                workspace.rhs[i] = -workspace.residual[i] / residual_scale;
            }
            workspace.rhs[n] = -constraint;
            if !workspace.residual.iter().all(|r| r.is_finite())
                || !workspace.solve_bordered(problem, self.x_scale, self.lambda_scale, residual_scale, &self.chord)
            {
                return Ok(None);
            }
            let step = workspace.rhs.iter().map(|d| d * d).sum::<f64>().sqrt();
            // Accurate enough as it is, where it was evaluated.
            if step <= early {
                return Ok(Some(false));
            }
            for (zi, d) in z.iter_mut().zip(&workspace.rhs) {
                *zi += d;
            }
            // Converged to round-off: the update is negligible, or small and no longer shrinking.
            if step <= 1e-14 * (1.0 + z.iter().map(|v| v * v).sum::<f64>().sqrt()) || (step < 1e-8 && step >= last_step)
            {
                return Ok(Some(true));
            }
            last_step = step;
        }
        Ok(None)
    }
}

/// The next point to solve on the arc between `a` and `b` (scanned points of the bracket's
/// chord, `s`) whose maximum is sought, given the quantity's values so far by `s`; `None` once
/// the maximum is located: the points either side of the best are within twice the tolerance
/// of each other (Brent's criterion), or one is as high as the best to round-off.
///
/// The top of a friction peak's arc is mostly a corner: the slip instants move by one time
/// sample there, and the quantity rises and falls along two nearly straight sides (slopes of
/// ~±2e-3 of the value per unit of the chord on Table 6, changing by a few per cent along a
/// side). Where the best point and its two neighbours on one side are aligned, the next point
/// is where that side's line meets the line through the next two points on the other side: on
/// straight sides the corner itself, on curved ones a step or two from it; the steps then
/// land on either side of the corner and close the bracket. Elsewhere (a smooth top, or a
/// side that is not straight), the vertex of the parabola through the best point and its
/// neighbours (on the near side where they are lopsided, [`ASYMMETRIC`]); a step is at least the tolerance, and a golden-section step of the larger side
/// is taken where no model applies (Brent 1973, ch. 5, whose parabolas alone fit a corner
/// badly: 11-15 points a corner at a tolerance of 1e-5, against 4-6 here). Written here: a
/// bounded search over a cached, piecewise smooth function is what no optimisation crate
/// offers.
fn next_arc_point(values: &BTreeMap<u64, (f64, f64)>, a: f64, b: f64, tolerance: f64) -> Option<f64> {
    // The points solved so far, in order of `s` (keys of positive `s` sort as `s`).
    let points: Vec<(f64, f64)> =
        values.iter().map(|(k, v)| (f64::from_bits(*k), v.0)).filter(|p| p.1.is_finite()).collect();
    let inside = |p: &(f64, f64)| p.0 >= a && p.0 <= b;
    let k = (0..points.len()).filter(|&i| inside(&points[i])).max_by(|&i, &j| points[i].1.total_cmp(&points[j].1))?;
    // The best point at an end of the arc: the maximum is another arc's.
    if k == 0 || k + 1 == points.len() || !inside(&points[k - 1]) || !inside(&points[k + 1]) {
        return None;
    }
    let (lo, best, hi) = (points[k - 1], points[k], points[k + 1]);
    // Located to the tolerance; or to round-off, a neighbour within twice the tolerance as
    // high as the best (values that no longer tell the points apart).
    let level = |p: (f64, f64)| p.1 >= best.1 - 4.0 * f64::EPSILON * best.1.abs();
    if hi.0 - lo.0 <= 2.0 * tolerance
        || (level(lo) && best.0 - lo.0 <= 2.0 * tolerance)
        || (level(hi) && hi.0 - best.0 <= 2.0 * tolerance)
    {
        return None;
    }
    let slope = |p: (f64, f64), q: (f64, f64)| (q.1 - p.1) / (q.0 - p.0);
    let aligned = |p, q, r| {
        let (first, second) = (slope(p, q), slope(q, r));
        (first - second).abs() <= ALIGNED * first.abs().max(second.abs())
    };
    // Where the rising line through p and q meets the falling line through r and t, if
    // between `from` and `to` (or at the best point itself, to round-off), and the lines'
    // value there.
    let margin = 0.5 * tolerance;
    let corner = |p, q: (f64, f64), r: (f64, f64), t, from: f64, to: f64| -> Option<(f64, f64)> {
        let (rise, fall) = (slope(p, q), slope(r, t));
        let s = (r.1 - q.1 + rise * q.0 - fall * r.0) / (rise - fall);
        (rise > 0.0 && fall < 0.0 && s >= from - margin && s <= to + margin).then_some((s, q.1 + rise * (s - q.0)))
    };
    // Two points within 2.5 tolerances on one side of the best: the steps of one tolerance
    // went on rising that way, so the lines met at the best point without a corner there (a
    // side drawn across a hidden corner, on arcs narrower than the scan's spacing: Table 6's
    // two-DOF variant at 3000 N). A golden-section step then explores the larger side.
    let crowded = (k >= 2 && best.0 - points[k - 2].0 <= 2.5 * tolerance)
        || (k + 2 < points.len() && points[k + 2].0 - best.0 <= 2.5 * tolerance);
    let mut proposal = None;
    if !crowded && k >= 2 && k + 2 < points.len() {
        // The best point on the rising side, aligned with the two before it; or on the falling
        // side, aligned with the two after it. The higher corner is taken.
        let rising = aligned(points[k - 2], lo, best).then(|| corner(lo, best, hi, points[k + 2], best.0, hi.0));
        let falling = aligned(best, hi, points[k + 2]).then(|| corner(points[k - 2], lo, best, hi, lo.0, best.0));
        proposal =
            [rising.flatten(), falling.flatten()].into_iter().flatten().max_by(|x, y| x.1.total_cmp(&y.1)).map(|c| c.0);
    }
    if proposal.is_none() && !crowded {
        // The parabola through the best point and its neighbours, if concave: its vertex.
        let vertex = |p: (f64, f64), q: (f64, f64), r: (f64, f64)| {
            let (d_pq, d_qr) = (slope(p, q), slope(q, r));
            let curvature = (d_qr - d_pq) / (r.0 - p.0);
            let vertex = 0.5 * (p.0 + q.0) - d_pq / (2.0 * curvature);
            (curvature < 0.0 && vertex > lo.0 && vertex < hi.0).then_some(vertex)
        };
        // Where one neighbour lies more than ASYMMETRIC times further than the other, first
        // through the best point and the two nearest on the near side, if they span less than
        // half the far side (as Brent's parabola goes through the best points): across the far
        // side, a lopsided top (a steep fall beyond it) biases the vertex towards the best
        // point, and the steps crept to the top by ever smaller fractions of the way (a
        // smooth top of the lap joint took 21 solves, 11 now). Not from a neighbour a step of about
        // the tolerance away, whose slope to the best point near the top is round-off.
        let wide = |gap: f64| gap > 2.5 * tolerance;
        let near_side = if hi.0 - best.0 > ASYMMETRIC * (best.0 - lo.0) && wide(best.0 - lo.0) && k >= 2 {
            let p = points[k - 2];
            (inside(&p) && best.0 - p.0 < 0.5 * (hi.0 - best.0)).then(|| vertex(p, lo, best)).flatten()
        } else if best.0 - lo.0 > ASYMMETRIC * (hi.0 - best.0) && wide(hi.0 - best.0) && k + 2 < points.len() {
            let r = points[k + 2];
            (inside(&r) && r.0 - best.0 < 0.5 * (best.0 - lo.0)).then(|| vertex(best, hi, r)).flatten()
        } else {
            None
        };
        proposal = near_side.or_else(|| vertex(lo, best, hi));
    }
    // Within half the tolerance of a point solved (a step of exactly the tolerance is not).
    let near = |s: f64| values.keys().any(|key| (f64::from_bits(*key) - s).abs() < 0.5 * tolerance);
    if let Some(s) = proposal {
        // A step of at least the tolerance: towards the proposal, else away from it once that
        // side is closed to the tolerance.
        let steps = if (s - best.0).abs() < tolerance {
            let side = tolerance.copysign(s - best.0);
            [best.0 + side, best.0 - side]
        } else {
            [s, s]
        };
        if let Some(s) = steps.into_iter().find(|s| !near(*s) && *s > lo.0 && *s < hi.0) {
            return Some(s);
        }
    }
    // Golden section of the larger side.
    let s = if hi.0 - best.0 > best.0 - lo.0 {
        best.0 + GOLDEN * (hi.0 - best.0)
    } else {
        best.0 - GOLDEN * (best.0 - lo.0)
    };
    (!near(s)).then_some(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The arc search on `f` between `a` and `b` from the values at `initial` (a scan's points):
    /// the best point, its value and the points solved.
    fn search(f: impl Fn(f64) -> f64, [a, b]: [f64; 2], initial: &[f64], tolerance: f64) -> (f64, f64, usize) {
        let mut values: BTreeMap<u64, (f64, f64)> = initial.iter().map(|&s| (s.to_bits(), (f(s), 0.0))).collect();
        let mut steps = 0;
        while let Some(s) = next_arc_point(&values, a, b, tolerance) {
            assert!(s > a && s < b && steps < MAX_ARC_STEPS, "step {steps} at {s}");
            values.insert(s.to_bits(), (f(s), 0.0));
            steps += 1;
        }
        let (s, v) = values.iter().map(|(k, v)| (f64::from_bits(*k), v.0)).max_by(|x, y| x.1.total_cmp(&y.1)).unwrap();
        (s, v, steps)
    }

    /// The scan's lattice around `centre`.
    fn lattice(centre: f64) -> Vec<f64> {
        (-3..=3).map(|k| centre + k as f64 * SCAN_SPACING).collect()
    }

    #[test]
    fn the_candidate_threshold_follows_the_ripple_of_the_scan() {
        let scan = |f: &dyn Fn(f64) -> f64| -> BTreeMap<i64, f64> {
            (10..=30).map(|k| (k, f(k as f64 * SCAN_SPACING))).collect()
        };
        // A smooth top (the parabola of a resonance, 1e-3 of the value over the scan): third
        // differences vanish to round-off, the threshold is the floor.
        let smooth = scan(&|s| 1.0 - 0.01 * (s - 0.4) * (s - 0.4));
        assert!(ripple(&smooth, 1.0).unwrap() < 1e-15);
        assert_eq!(candidate(&smooth, 1.0), CANDIDATE_FLOOR);
        // The same top with arcs 0.1 wide whose corners dip 3e-5 below their tops (smaller
        // than Table 6's): the lattice's points nearest each top lie a tenth of an arc from
        // it, 0.2 of the depth below, and that is what the ripple measures. The threshold is
        // RIPPLE_MARGIN times it, above the floor.
        let depth = 3e-5;
        let rough = scan(&|s| {
            let phase = (s / 0.1).fract();
            1.0 - 0.01 * (s - 0.4) * (s - 0.4) - depth * (2.0 * (phase - 0.5).abs())
        });
        let r = ripple(&rough, 1.0).unwrap();
        assert!((r - 0.2 * depth).abs() < 1e-3 * depth, "ripple {r:e} for dips of {depth:e}");
        assert_eq!(candidate(&rough, 1.0), RIPPLE_MARGIN * r);
        // Arcs dipping 2e-4 (Table 6's scans show dips of 1e-4 at 1000 N) keep the threshold
        // of the roughest tops.
        let deep = scan(&|s| 1.0 - 2e-4 * (2.0 * ((s / 0.1).fract() - 0.5).abs()));
        assert_eq!(candidate(&deep, 1.0), CANDIDATE);
        // Fewer than four consecutive points, or a point that failed: no measure, the most
        // cautious threshold.
        let gappy: BTreeMap<i64, f64> = [(1, 1.0), (2, 1.0), (4, 1.0), (5, 1.0)].into();
        assert_eq!(candidate(&gappy, 1.0), CANDIDATE);
        let mut failed = smooth.clone();
        failed.insert(20, f64::NEG_INFINITY);
        assert_eq!(candidate(&failed, 1.0), CANDIDATE);
    }

    #[test]
    fn a_corner_with_straight_sides_is_located_in_one_step_and_bracketed_in_two() {
        // Sides of slopes +2e-3 and −1e-3 of the value per unit of s (Table 6 at 100 N), meeting
        // at 0.5037, between two lattice points: the lines through two points per side meet
        // there exactly (to round-off), so one step lands on it; two steps of one tolerance
        // either side then close the bracket.
        let corner = 0.5037;
        let f = |s: f64| 1.0 + if s < corner { 2e-3 * (s - corner) } else { -1e-3 * (s - corner) };
        let (s, v, steps) = search(f, [0.48, 0.52], &lattice(0.5), 1e-5);
        assert!((s - corner).abs() < 1e-12, "{s}");
        assert!((v - 1.0).abs() < 1e-15, "{v}");
        assert_eq!(steps, 3);
    }

    #[test]
    fn a_corner_between_curved_sides_is_located_in_a_few_steps() {
        // Concave sides whose slopes change by 5 % over a lattice spacing (a friction peak's:
        // a few per cent), meeting at 0.4963: located to the tolerance on s, where its value is
        // within the slope times the tolerance. Brent's method needed 11-15 points for such
        // corners at that tolerance (golden sections: the parabolas through a corner fit it
        // badly).
        let corner = 0.4963;
        let f = |s: f64| {
            let d = s - corner;
            1.0 + if d < 0.0 { 2e-3 * d - 2.5e-3 * d * d } else { -1.5e-3 * d - 2.5e-3 * d * d }
        };
        let (s, v, steps) = search(f, [0.48, 0.52], &lattice(0.5), 1e-5);
        assert!((s - corner).abs() <= 1e-5, "{s}");
        assert!(1.0 - v <= 2e-3 * 1e-5, "{v}");
        assert!(steps <= 5, "{steps} steps");
    }

    #[test]
    fn a_smooth_top_is_located_to_the_tolerance() {
        // A parabola: its vertex to the tolerance on s, as Brent's method locates it, in a
        // few parabolic steps and the two steps of one tolerance either side that close the
        // bracket.
        let top = 0.50731;
        let f = |s: f64| 1.0 - 3e-3 * (s - top) * (s - top);
        for tolerance in [1e-5, 1e-9] {
            let (s, _, steps) = search(f, [0.48, 0.52], &lattice(0.5), tolerance);
            assert!((s - top).abs() <= tolerance, "{s} at tolerance {tolerance:e}");
            assert!(steps <= 6, "{steps} steps at tolerance {tolerance:e}");
        }
    }

    #[test]
    fn the_search_stays_on_its_arc_of_a_chain_of_corners() {
        // A friction peak's top: corners every 0.103 of the chord on a parabolic envelope
        // (Table 6 at 100 N), the value falling by 2e-3 per unit of s after each corner and
        // rising at 2e-3 to the next. The search between two lattice points around one
        // corner finds that corner, not its neighbours'.
        let corners: Vec<f64> = (0..10).map(|i| 0.0475 + 0.103 * i as f64).collect();
        let envelope = |s: f64| 1.0 - 4e-4 * (s - 0.55) * (s - 0.55);
        let f = |s: f64| {
            let c = corners.iter().copied().min_by(|a, b| (a - s).abs().total_cmp(&(b - s).abs())).unwrap();
            envelope(c) - 2e-3 * (s - c).abs()
        };
        let scan = lattice(0.56);
        let (s, v, steps) = search(f, [scan[2], scan[4]], &scan, 1e-5);
        assert!((s - corners[5]).abs() < 1e-9, "{s}");
        assert!((v - envelope(corners[5])).abs() < 1e-14, "{v}");
        assert!(steps <= 3, "{steps} steps");
    }

    #[test]
    fn random_chains_of_corners_wider_than_two_lattice_spacings_are_located_to_their_slope_times_the_tolerance() {
        // 500 friction-like tops: corners every w ∈ [0.04, 0.12] of the chord on a parabolic
        // envelope, sides rising at 5e-4..1e-2 of the value per unit of s towards each corner
        // and falling at another such slope after it, each side curved by up to 3e-2 (random,
        // a fixed xorshift sequence). The search starts from a scan's lattice (every 0.02 over
        // ±0.24) on the arc of its best local maximum, as `maximise` does. On arcs at least two
        // spacings wide the arc holds one corner: found to the tolerance, its value to the
        // steepest slope times it (1e-2 × 1e-5 = 1e-7; 4.6e-8 measured at most), in 6.6 steps
        // on average where Brent's method took 13.3 (measured on the same tops outside the
        // code; the same misses as Brent on narrower arcs, where a lattice cannot tell arcs
        // apart).
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut uniform = |lo: f64, hi: f64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            lo + (hi - lo) * (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut total_steps = 0;
        for _ in 0..500 {
            let (w, up, down) = (uniform(0.04, 0.12), uniform(5e-4, 1e-2), uniform(5e-4, 1e-2));
            let (offset, curvature, centre) = (uniform(0.0, w), uniform(0.0, 3e-2), uniform(0.45, 0.55));
            let f = |s: f64| {
                let corner = offset + w * ((s - offset) / w).round();
                let d = s - corner;
                1.0 - 4e-4 * (corner - centre).powi(2) - if d < 0.0 { -up * d } else { down * d } - curvature * d * d
            };
            let scan: Vec<f64> = (-12..=12).map(|k| 0.5 + k as f64 * SCAN_SPACING).collect();
            let j = (1..scan.len() - 1)
                .filter(|&j| f(scan[j]) >= f(scan[j - 1]) && f(scan[j]) >= f(scan[j + 1]))
                .max_by(|&a, &b| f(scan[a]).total_cmp(&f(scan[b])))
                .unwrap();
            let (a, b) = (scan[j - 1], scan[j + 1]);
            let (_, v, steps) = search(f, [a, b], &scan, 1e-5);
            let top = (0..=20000).map(|i| f(a + (b - a) * i as f64 / 20000.0)).fold(f64::NEG_INFINITY, f64::max);
            // The dense grid's best is within 1e-2 × (b − a)/20000 = 2e-8 of the top.
            assert!(top - v <= 1e-7, "{} below, w = {w}", top - v);
            total_steps += steps;
        }
        assert!(total_steps <= 9 * 500, "{} steps on average", total_steps as f64 / 500.0);
    }

    #[test]
    fn a_lopsided_smooth_top_is_located_in_a_few_steps() {
        // A smooth top whose far side falls steeply (a cubic beyond the top: the lap joint's
        // second peak, top near 0.6913 of the chord, the scan's best at 0.70): the parabola
        // through the far neighbour puts each step short of the top, and the steps crept
        // there by ever smaller fractions of the way (19 steps for the top at 0.7031, 9 at
        // 0.6913). On the near side, a step or two, then the two of one tolerance that close
        // the bracket.
        for (top, quadratic, cubic) in
            [(0.6913, 1e-4, 5e-3), (0.6913, 1e-4, 2e-3), (0.695, 1e-4, 5e-3), (0.7031, 1e-4, 5e-3)]
        {
            let f = |s: f64| {
                let d = s - top;
                1.0 - quadratic * d * d - if d > 0.0 { cubic * d * d * d } else { 0.0 }
            };
            let scan = lattice(0.70);
            let (s, _, steps) = search(f, [scan[2], scan[4]], &scan, 1e-5);
            assert!((s - top).abs() <= 1e-5, "{s} for the top at {top}");
            assert!(steps <= 6, "{steps} steps for the top at {top}");
        }
    }
}
