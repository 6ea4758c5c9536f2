//! `[nonlinear_mode]`: validation errors naming the key, and the backbone of a study written
//! to `backbone.csv`.

use stickslip_core::continuation::{Silent, TerminationReason};
use stickslip_io::analysis::run_nonlinear_mode;
use stickslip_io::backbone::{backbone_columns, write_backbone_csv};
use stickslip_io::study::Study;

/// The Table 6 oscillator (examples/jenkins-1dof) with a backbone section.
const STUDY: &str = r#"[model]
dofs = ["M"]
mass = [[10.0]]
stiffness = [[2.24e7]]

[damping]
alpha = 35.0

[[load]]
name = "shaker"
dof = "M"

[[joint]]
name = "joint"
law = "jenkins"
dof = "M"
stiffness = 8.11e6
replaces_stiffness = true
threshold = 1000.0

[excitation]
levels = [1000.0]

[sweep]
start_hz = 150.0
end_hz = 350.0

[[output]]
name = "mass"
dof = "M"

[nonlinear_mode]
mode = 1
amplitude_start = 3.16e-5
amplitude_end = 3.16e-2
outputs = ["mass"]
"#;

fn error(from: &str, to: &str) -> String {
    assert_eq!(STUDY.matches(from).count(), 1, "{from:?}");
    Study::parse(&STUDY.replace(from, to), "study.toml").expect_err("rejected").to_string()
}

#[test]
fn bad_keys_are_named() {
    let e = error("mode = 1", "mode = 0");
    assert!(e.contains("[nonlinear_mode]: mode must be an integer >= 1"), "{e}");
    let e = error("amplitude_start = 3.16e-5", "amplitude_start = -1.0");
    assert!(e.contains("amplitude_start must be > 0"), "{e}");
    let e = error("amplitude_end = 3.16e-2", "amplitude_end = 1e-6");
    assert!(e.contains("amplitude_end must be larger than amplitude_start"), "{e}");
    let e = error("outputs = [\"mass\"]", "outputs = [\"nowhere\"]");
    assert!(e.contains("outputs names \"nowhere\""), "{e}");
    let e = error("outputs = [\"mass\"]", "negative_damping = \"all\"");
    assert!(e.contains("negative_damping must be"), "{e}");
    let e = error("outputs = [\"mass\"]", "amplitude = 3");
    assert!(e.contains("[nonlinear_mode]") && e.contains("amplitude"), "{e}");
    // The line and column of the key are given.
    assert!(error("mode = 1", "mode = 0").starts_with("study.toml:"));
}

#[test]
fn backbone_of_a_study_is_written() {
    let study = Study::parse(STUDY, "study.toml").unwrap();
    let (model, _, outputs) = study.build_model().unwrap();
    let (backbone, names) = run_nonlinear_mode(&study, &model, &outputs, &mut Silent).unwrap().unwrap();
    assert_eq!(backbone.termination, TerminationReason::ReachedEnd);
    assert_eq!(names, vec!["mass".to_string()]);
    let (first, last) = (&backbone.points[0], backbone.points.last().unwrap());
    // Stuck: the linear mode, √(2.24e7/10)/2π = 238.2 Hz, ζ = 35/(2ω).
    let w = (2.24e7f64 / 10.0).sqrt();
    assert!((first.omega / w - 1.0).abs() < 1e-8);
    assert!((first.damping_ratio() - 35.0 / (2.0 * w)).abs() < 1e-8);
    // Fully slipped at 1e-2 m: close to √((2.24e7 − 8.11e6)/10)/2π = 190.3 Hz.
    assert!((last.frequency_hz() - 190.3).abs() < 0.5, "{}", last.frequency_hz());
    // The output is the displacement, a/√M in harmonic 1.
    assert!((last.output_amplitude(0, 1) - 3.16e-2 / 10f64.sqrt()).abs() < 1e-12);

    let dir = std::env::temp_dir().join(format!("stickslip-backbone-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("backbone.csv");
    write_backbone_csv(&path, &backbone, &["joint".to_string()], &names, 7).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let header = text.lines().next().unwrap();
    assert_eq!(header, backbone_columns(&["joint".to_string()], &names, 7).join(","));
    assert!(header
        .starts_with("modal_amplitude_m_sqrtkg,frequency_Hz,damping_ratio,energy_per_cycle_J,joint_stick_fraction"));
    assert_eq!(text.lines().count(), backbone.points.len() + 1);
    // Shortest round-trip digits: the file reads back to the very doubles of the rows.
    let rows = stickslip_io::backbone::backbone_rows(&backbone, 1, 7);
    for (line, row) in text.lines().skip(1).zip(&rows) {
        let read: Vec<f64> = line.split(',').map(|v| v.parse().unwrap()).collect();
        assert_eq!(&read, row);
    }
    #[cfg(feature = "plot")]
    {
        let files = stickslip_io::plot::plot_backbone(&dir, &backbone, stickslip_io::study::PlotFormat::Svg).unwrap();
        assert!(files.iter().all(|f| std::fs::metadata(f).unwrap().len() > 1000));
    }
    std::fs::remove_dir_all(&dir).ok();
}
