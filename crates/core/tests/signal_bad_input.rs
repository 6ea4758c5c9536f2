//! Bad input to the signal processing: a clear error that says what to change.
use std::f64::consts::PI;

use stickslip_core::signal::harmonics::{extract, SyncOptions};
use stickslip_core::signal::SignalError;

fn sine(f: f64, fs: f64, n: usize) -> Vec<f64> {
    (0..n).map(|j| (2.0 * PI * f * j as f64 / fs).cos()).collect()
}

#[test]
fn records_of_unequal_length_are_refused_naming_the_channel() {
    let r = sine(100.0, 10_000.0, 5000);
    let y = sine(100.0, 10_000.0, 4999);
    let e = extract(&r, &[("accel_top", &y)], 10_000.0, &SyncOptions::per_cycle(3)).unwrap_err();
    assert_eq!(e, SignalError::UnequalLength { channel: "accel_top".into(), len: 4999, reference_len: 5000 });
    assert!(e.to_string().contains("accel_top") && e.to_string().contains("same length"));
}

#[test]
fn harmonic_above_nyquist_says_how_many_harmonics_fit() {
    // 100 Hz at 1 kHz: Nyquist 500 Hz, harmonic 5 is 500 Hz → at most 4 harmonics.
    let r = sine(100.0, 1000.0, 2000);
    let e = extract(&r, &[("y", &r)], 1000.0, &SyncOptions::per_cycle(5)).unwrap_err();
    match &e {
        SignalError::Aliasing { max_harmonics, .. } => assert_eq!(*max_harmonics, 4),
        other => panic!("expected Aliasing, got {other:?}"),
    }
    assert!(e.to_string().contains("at most 4 harmonics"), "{e}");
    assert!(extract(&r, &[("y", &r)], 1000.0, &SyncOptions::per_cycle(4)).is_ok());
}

#[test]
fn a_reference_without_cycles_is_refused() {
    let flat = vec![1.0; 1000];
    let e = extract(&flat, &[], 1000.0, &SyncOptions::per_cycle(1)).unwrap_err();
    assert!(matches!(e, SignalError::TooFewCycles { .. }), "{e:?}");
    assert!(e.to_string().contains("reference channel"));
    let r = sine(10.0, 1000.0, 1000);
    let e = extract(&r, &[], 1000.0, &SyncOptions::whole_record(1, 50)).unwrap_err();
    assert!(matches!(e, SignalError::TooFewCycles { .. }), "{e:?}");
    assert!(extract(&r, &[], 0.0, &SyncOptions::per_cycle(1)).is_err());
    assert_eq!(extract(&r, &[], 1000.0, &SyncOptions::per_cycle(0)).unwrap_err(), SignalError::NoHarmonics);
}

#[test]
fn a_cycle_with_fewer_samples_than_coefficients_is_refused() {
    // 10.5 samples per cycle: harmonic 5 is below Nyquist (5 < 5.25), but some cycles hold 10
    // samples for 11 coefficients; per-cycle fitting is impossible, two cycles per block work.
    let fs = 1050.0;
    let r = sine(100.0, fs, 2100);
    let e = extract(&r, &[("y", &r)], fs, &SyncOptions::per_cycle(5)).unwrap_err();
    assert!(matches!(e, SignalError::TooFewSamples { samples: 10, coefficients: 11, .. }), "{e:?}");
    assert!(e.to_string().contains("more cycles per block"), "{e}");
    let two = SyncOptions { n_harmonics: 5, cycles_per_block: 2, skip_cycles: 0 };
    assert!(extract(&r, &[("y", &r)], fs, &two).is_ok());
}
