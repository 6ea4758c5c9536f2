//! Resonance peaks of an FRF amplitude curve: frequency and amplitude, for comparing measured and
//! simulated FRFs (paper Section 5.1: peak shift and flattening with the force level).
//!
//! A sample is a peak if it is a local maximum whose prominence (height above the higher of the
//! two lowest points separating it from higher samples, or from the ends) is at least a given
//! fraction of the curve's maximum: noise ripples on a measured swept-sine FRF have small
//! prominence and are ignored. The peak is refined by the parabola through the three samples
//! around it (on a smooth peak sampled at step h, the vertex error is O(h²) of the peak width).

/// One resonance peak.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Peak {
    pub frequency_hz: f64,
    pub amplitude: f64,
    /// Index of the highest sample.
    pub index: usize,
}

/// Peaks of `amplitude(frequency)` (samples in sweep order) with prominence at least
/// `min_prominence` × the maximum amplitude, in order of frequency.
pub fn peaks(frequency_hz: &[f64], amplitude: &[f64], min_prominence: f64) -> Vec<Peak> {
    let n = amplitude.len().min(frequency_hz.len());
    let a = &amplitude[..n];
    let max = a.iter().copied().fold(0.0, f64::max);
    let mut out = Vec::new();
    // Interior samples only: a maximum at an end of the band (or a start-up transient) is not a
    // resonance peak.
    for i in 1..n.saturating_sub(1) {
        if !(a[i - 1] < a[i] && a[i + 1] <= a[i]) {
            continue;
        }
        let base = |range: &mut dyn Iterator<Item = usize>| {
            let mut low = a[i];
            for j in range {
                if a[j] > a[i] {
                    break;
                }
                low = low.min(a[j]);
            }
            low
        };
        let left = base(&mut (0..i).rev());
        let right = base(&mut (i + 1..n));
        if a[i] - left.max(right) < min_prominence * max {
            continue;
        }
        out.push(refine(frequency_hz, a, i));
    }
    out.sort_by(|p, q| p.frequency_hz.total_cmp(&q.frequency_hz));
    out
}

/// Vertex of the parabola through samples i−1, i, i+1 (0 < i < n−1).
fn refine(f: &[f64], a: &[f64], i: usize) -> Peak {
    let (x0, x1, x2) = (f[i - 1], f[i], f[i + 1]);
    let (y0, y1, y2) = (a[i - 1], a[i], a[i + 1]);
    let d01 = (y1 - y0) / (x1 - x0);
    let d12 = (y2 - y1) / (x2 - x1);
    let curvature = (d12 - d01) / (x2 - x0);
    if curvature >= 0.0 || !curvature.is_finite() {
        return Peak { frequency_hz: x1, amplitude: y1, index: i };
    }
    // y = y1 + d (x − x1) + c (x − x1)²  with d the slope at x1 of the parabola.
    let slope = d01 + curvature * (x1 - x0);
    let dx = -slope / (2.0 * curvature);
    if dx.abs() > (x2 - x0).abs() {
        return Peak { frequency_hz: x1, amplitude: y1, index: i };
    }
    Peak { frequency_hz: x1 + dx, amplitude: y1 + slope * dx + curvature * dx * dx, index: i }
}
