//! A Duffing oscillator through the harmonic balance and the continuation: the fold of the
//! hardening peak is passed, and the branch matches the first-order closed form.
mod duffing_common;

use duffing_common::{duffing, C, F, K, K3, M};
use stickslip_core::continuation::{Options, Silent, TerminationReason};
use stickslip_core::hbm::fourier::{cos_index, sin_index};
use stickslip_core::hbm::{sweep_frequency, CondensedHbm, HbmSettings};

#[test]
fn duffing_fold_is_passed_and_the_branch_matches_the_closed_form_and_backbone() {
    let model = duffing();
    // N = 1 and 16 samples: u³ has harmonics 1 and 3 only, which 16 samples separate exactly,
    // so this is the first-order balance whose closed form is below.
    let mut hbm = CondensedHbm::new(&model, &[1.0], HbmSettings { harmonics: 1, samples: 16 }).unwrap();
    let branch = sweep_frequency(&mut hbm, F, 50.0, 250.0, &Options::default(), &mut Silent).unwrap();
    assert_eq!(branch.termination, TerminationReason::ReachedEnd);
    // The fold: Ω decreases along part of the branch.
    let backwards = branch.points.windows(2).filter(|w| w[1].lambda < w[0].lambda).count();
    assert!(backwards > 0, "the branch never turned back");
    let mut peak = (0.0, 0.0);
    for p in &branch.points {
        let a = p.x[cos_index(1)].hypot(p.x[sin_index(1)]);
        let w = p.lambda;
        // [(k − mΩ² + ¾k3A²)² + (cΩ)²] A² = F²
        let lhs = ((K - M * w * w + 0.75 * K3 * a * a).powi(2) + (C * w).powi(2)) * a * a;
        assert!((lhs.sqrt() - F).abs() < 1e-8 * F, "Ω = {w}: {} vs {F}", lhs.sqrt());
        if a > peak.1 {
            peak = (w, a);
        }
    }
    // At the peak, the response sits on the backbone Ω² = (k + ¾ k3 A²)/m up to the damping:
    // the peak's offset from the backbone is O(ζ²) ~ 1e-4 relative here, and its amplitude is
    // F/(cΩ) to the same order; the largest point is within a continuation step of the true
    // peak. Measured: 2.7e-4 off the backbone, 4.9e-4 off F/(cΩ); asserted to 2e-3.
    let backbone = ((K + 0.75 * K3 * peak.1 * peak.1) / M).sqrt();
    assert!((peak.0 - backbone).abs() / backbone < 2e-3, "peak at {} vs backbone {backbone}", peak.0);
    assert!((peak.1 - F / (C * peak.0)).abs() / peak.1 < 2e-3, "peak amplitude {}", peak.1);
}
