//! Harmony's blade contacts as contact patches (`examples/harmony/study-patches.toml`, the
//! generator's `tip_contact = "patch"`) against the paper's connector and Jenkins element
//! (`examples/harmony/study.toml`), at the coarse refinement (element size 60 mm) and the
//! paper's lowest level, 70 N, where every contact sticks: the patches pair up, the static
//! pre-step gives each blade the paper's slip threshold μ N0 = F_Coulomb = 290 N (Section 5),
//! and the stuck resonance is the connector model's to the tolerance the stiffness difference
//! allows (docs/contact-patches.md, "Harmony's blade contacts").

use std::path::PathBuf;

use stickslip_core::continuation::Silent;
use stickslip_io::analysis::run_level;
use stickslip_io::study::{Excitation, NonlinearModel, OutputSpec, Study};

fn example(name: &str) -> String {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/harmony").join(name);
    std::fs::read_to_string(path).unwrap()
}

/// `text` with each replacement applied (each must apply once).
fn edited(text: &str, edits: &[(&str, &str)]) -> String {
    edits.iter().fold(text.to_string(), |t, (from, to)| {
        assert_eq!(t.matches(from).count(), 1, "{from:?}");
        t.replace(from, to)
    })
}

/// The preload N0 of a contact law that replaces its stiffnesses: wide open (u_n = −h), its
/// restoring normal force is g_n = −N0 + k_n h, so N0 = g_n(−2h) − 2 g_n(−h). h = 1 cm opens every
/// pair (k_n h ≥ 3e3 N against N0 ≤ 100 N) with a round-off of k_n h × 1e-16.
fn contact_preload(law: &dyn stickslip_core::elements::Element) -> f64 {
    let d = law.n_dirs();
    let g_open = |h: f64| {
        let (mut u, mut g, mut w) = ([0.0; 3], [0.0; 3], [0.0; 2]);
        u[d - 1] = -h;
        law.update(&u[..d], &[0.0; 3][..d], &mut w[..d - 1], &mut g[..d], None);
        g[d - 1]
    };
    g_open(2e-2) - 2.0 * g_open(1e-2)
}

/// The body top's stuck resonance (Hz) at 70 N, between 260 and 235 Hz.
fn stuck_peak(study: &Study, built: &(NonlinearModel, Excitation, Vec<OutputSpec>)) -> f64 {
    let (model, excitation, outputs) = built;
    let run = run_level(study, model, excitation, outputs, 70.0, &mut Silent).unwrap();
    assert!(run.is_complete(), "{}", run.ending());
    for p in &run.result.points {
        assert!(p.elements.iter().all(|e| e.stick_fraction == 1.0), "{} Hz: a contact slips at 70 N", p.frequency_hz);
    }
    let peak = run.result.peaks.iter().find(|p| p.output == "body_top").expect("a body top peak");
    assert!(peak.located, "{peak:?}");
    peak.frequency_hz
}

/// Largest relative difference of the stuck resonances, patches against connector.
const TOLERANCE: f64 = 0.01;

const COARSE_LOW: [(&str, &str); 3] = [
    ("levels = [70.0, 1070.0]", "levels = [70.0]"),
    ("start_hz = 255.0", "start_hz = 260.0"),
    ("end_hz = 228.0", "end_hz = 235.0"),
];

#[test]
fn harmony_blade_patches_pair_up_carry_the_papers_threshold_and_stick_near_the_connectors_resonance() {
    let patches = edited(&example("study-patches.toml"), &COARSE_LOW);
    let study = Study::parse(&patches, "study-patches.toml").unwrap();
    let built = study.build_model().unwrap();
    let model = &built.0;
    let friction = 0.5;
    for blade in 1..=4 {
        let prefix = format!("blade{blade}-");
        let pairs: Vec<_> = model.elements.iter().filter(|e| e.name.starts_with(&prefix)).collect();
        // Hex20, the tip two cells across and one through the thickness: 13 nodes a face.
        assert_eq!(pairs.len(), 13, "blade {blade}");
        assert!(pairs.iter().all(|e| e.law.kind() == "contact3d"));
        let n0: Vec<f64> = pairs.iter().map(|e| contact_preload(e.law.as_ref())).collect();
        let total: f64 = n0.iter().sum();
        println!(
            "blade {blade}: N0 from {:.2} to {:.2} N, {total:.10} N in all",
            n0.iter().copied().fold(f64::INFINITY, f64::min),
            n0.iter().copied().fold(0.0, f64::max)
        );
        assert!(n0.iter().all(|&n| n > 0.0));
        assert!((friction * total - 290.0).abs() < 1e-9 * 290.0, "blade {blade}: μ N0 = {} N", friction * total);
    }
    assert_eq!(model.elements.len(), 52);

    // The connector model of the same design: the patch study's geometry keys (its flat blades).
    let geometry: String = example("study-patches.toml")
        .split("[model.harmony]\n")
        .nth(1)
        .and_then(|rest| rest.split("\n\n").next())
        .expect("the patch study's [model.harmony]")
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("refinement") && !l.starts_with("tip_contact"))
        .map(|l| format!("{l}\n"))
        .collect();
    assert!(geometry.contains("blade_rise = 0.0"), "{geometry}");
    let connector_text = edited(
        &example("study.toml"),
        &[
            ("refinement = 1.0", &format!("refinement = 0.5\n{geometry}")),
            ("levels = [70.0, 1070.0, 1875.0, 2910.0, 6000.0, 10000.0]", "levels = [70.0]"),
            ("start_hz = 300.0", "start_hz = 260.0"),
            ("end_hz = 170.0", "end_hz = 235.0"),
        ],
    );
    let connector = Study::parse(&connector_text, "study.toml").unwrap();
    let f_patch = stuck_peak(&study, &built);
    let f_connector = stuck_peak(&connector, &connector.build_model().unwrap());
    println!("stuck resonance at 70 N: patches {f_patch:.3} Hz, connector {f_connector:.3} Hz");
    // Both have the connector's 1e10 N/m tangentially; they differ in what holds the tip's
    // rotation (the patch's normal stiffness times the face's second moment, 145 N m/rad,
    // against nothing) and in the wall (elastic under the patch, a rigid zone under the
    // connector), and the patch mesh is cut at more angles. Measured +0.11 %; ten times the
    // normal stiffness restrains the rotation enough to move the peak by +3.4 % or more
    // (docs/contact-patches.md): 1 % admits the first and refuses the second.
    let relative = (f_patch - f_connector).abs() / f_connector;
    assert!(relative < TOLERANCE, "patches {f_patch} Hz against the connector's {f_connector} Hz");
}

#[test]
fn a_tip_contact_other_than_connector_or_patch_is_refused_naming_the_key_and_the_values() {
    let text = edited(&example("study-patches.toml"), &[("tip_contact = \"patch\"\n", "tip_contact = \"glued\"\n")]);
    let message = Study::parse(&text, "study-patches.toml").map(|_| ()).unwrap_err().to_string();
    println!("{message}");
    assert!(message.starts_with("study-patches.toml:"), "{message}");
    assert!(message.contains("[model.harmony]"), "{message}");
    assert!(message.contains("tip_contact must be \"connector\" or \"patch\", got \"glued\""), "{message}");
}
