//! Resonance peaks of FRF amplitude curves against closed forms.
mod signal_util;

use std::f64::consts::PI;

use signal_util::Gaussian;
use stickslip_core::signal::peaks::peaks;

/// |H| of m ẍ + c ẋ + k x = F for two oscillators in parallel (two well separated peaks).
fn two_modes(f: f64) -> f64 {
    let h = |fn_: f64, zeta: f64, m: f64| {
        let (w, wn) = (2.0 * PI * f, 2.0 * PI * fn_);
        1.0 / (m * ((wn * wn - w * w).powi(2) + (2.0 * zeta * wn * w).powi(2)).sqrt())
    };
    h(100.0, 0.02, 1.0) + h(250.0, 0.01, 2.0)
}

/// Exact peak of an SDOF displacement receptance: f_n √(1 − 2ζ²).
fn peak_frequency(fn_: f64, zeta: f64) -> f64 {
    fn_ * (1.0 - 2.0 * zeta * zeta).sqrt()
}

#[test]
fn peaks_of_two_modes_at_the_closed_form_frequencies() {
    let h = 0.25;
    let f: Vec<f64> = (0..1600).map(|i| 50.0 + h * i as f64).collect();
    let a: Vec<f64> = f.iter().map(|&x| two_modes(x)).collect();
    let p = peaks(&f, &a, 0.05);
    assert_eq!(p.len(), 2, "{p:?}");
    // The other mode's tail shifts each peak by its slope over the peak's curvature: below
    // 0.003 Hz here. The parabola through samples 0.25 Hz apart on peaks 4 and 5 Hz wide
    // (half-power bandwidths 2ζf_n) is off by O((h/width)²) of the width: < 0.02 Hz.
    assert!((p[0].frequency_hz - peak_frequency(100.0, 0.02)).abs() < 0.02, "{:?}", p[0]);
    assert!((p[1].frequency_hz - peak_frequency(250.0, 0.01)).abs() < 0.02, "{:?}", p[1]);
    // Amplitude: the parabola's vertex within 1 % of the sampled curve's true maximum.
    let exact = two_modes(peak_frequency(100.0, 0.02));
    assert!((p[0].amplitude - exact).abs() < 0.01 * exact, "{} vs {exact}", p[0].amplitude);
}

#[test]
fn noise_ripples_are_not_peaks() {
    let f: Vec<f64> = (0..1600).map(|i| 50.0 + 0.25 * i as f64).collect();
    let mut g = Gaussian::new(7);
    // 1 % multiplicative noise makes hundreds of local maxima; only the two modes are prominent
    // above 5 % of the maximum.
    let a: Vec<f64> = f.iter().map(|&x| two_modes(x) * (1.0 + 0.01 * g.sample())).collect();
    let p = peaks(&f, &a, 0.05);
    assert_eq!(p.len(), 2, "{p:?}");
    // Noise of 1 % moves the apparent maximum within the top 1 % of the peak: ±ζ f_n √0.02·2 ≈ ±0.6 Hz.
    assert!((p[0].frequency_hz - peak_frequency(100.0, 0.02)).abs() < 0.6, "{:?}", p[0]);
}

#[test]
fn a_maximum_at_the_band_end_is_not_a_peak() {
    // A sweep starting on the flank of a resonance (and its start-up transient) is highest at
    // the first sample: that is not a resonance.
    let f: Vec<f64> = (0..400).map(|i| 101.0 + 0.25 * i as f64).collect();
    let a: Vec<f64> = f.iter().map(|&x| two_modes(x)).collect();
    let p = peaks(&f, &a, 0.05);
    assert_eq!(p.len(), 0, "{p:?}");
}
