//! The anti-aliasing filter against the closed form of a digital Butterworth filter: the
//! bilinear transform prewarped at the cutoff maps the analog gain 1/√(1 + (Ω/Ω_c)^16) onto
//! `|H(f)| = 1 / √(1 + (tan(π f / f_s) / tan(π f_c / f_s))^16)`.

use stickslip_core::signal::antialias::AntiAliasFilter;

/// Steady-state gain at `f` (Hz): run a sine through the filter until the start transient has
/// died (the slowest pole decays in ~10/f_c s), then take the output amplitude over whole
/// periods by projection on sin and cos.
fn gain(fs: f64, fc: f64, f: f64) -> f64 {
    let mut filter = AntiAliasFilter::new(fs, fc).unwrap();
    let settle = (50.0 * fs / fc) as usize;
    let period = fs / f;
    let n = (200.0 * period).round() as usize;
    let (mut c, mut s) = (0.0, 0.0);
    let w = 2.0 * std::f64::consts::PI * f / fs;
    for k in 0..settle + n {
        let y = filter.run((w * k as f64).sin());
        if k >= settle {
            c += y * (w * k as f64).cos();
            s += y * (w * k as f64).sin();
        }
    }
    2.0 * c.hypot(s) / n as f64
}

fn closed_form(fs: f64, fc: f64, f: f64) -> f64 {
    let pi = std::f64::consts::PI;
    let r = (pi * f / fs).tan() / (pi * fc / fs).tan();
    1.0 / (1.0 + r.powi(16)).sqrt()
}

#[test]
fn butterworth_gain_matches_the_closed_form() {
    // The integration rate and cutoff of a Harmony virtual test: 38.4 kHz, 0.4 x 9.6 kHz.
    let (fs, fc) = (38_400.0, 3_840.0);
    for f in [100.0, 300.0, 2_100.0, 3_840.0, 7_000.0, 9_000.0] {
        let (g, exact) = (gain(fs, fc, f), closed_form(fs, fc, f));
        // The projection over 200 periods of a sampled sine is exact to ~1e-4 of the amplitude
        // (non-integer samples per period leave a partial-period leak of ~1/n).
        assert!((g - exact).abs() < 2e-4 + 1e-3 * exact, "{f} Hz: gain {g:.6} vs {exact:.6}");
    }
    // The passband of interest (harmonics 1-7 of 300 Hz) is flat: the FRFs of a test ratio
    // two channels filtered alike, harmonic amplitudes of one channel lose at most 1e-3.
    assert!(closed_form(fs, fc, 2_100.0) > 0.999);
    // What would fold onto the band from above half the output rate is cut by 46 dB or more.
    assert!(closed_form(fs, fc, 9_600.0 - 2_100.0) < 10f64.powf(-46.0 / 20.0));
}

#[test]
fn a_cutoff_above_nyquist_is_refused() {
    let e = AntiAliasFilter::new(1000.0, 600.0).unwrap_err().to_string();
    assert!(e.contains("half the sample rate"), "{e}");
    assert!(AntiAliasFilter::new(f64::NAN, 10.0).is_err());
}
