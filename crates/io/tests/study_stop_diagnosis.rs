//! A branch that stops because its solutions are not isolated says so: a mass held by a
//! friction joint alone (the joint in the paper's form replaces the only stiffness there is)
//! has no fixed mean position once the joint slips during the cycle, since the slip resets its
//! anchor. The condensed balance's harmonic-0 equation `x₀ + H(0) G₀ = 0` is then
//! `(mean friction force)/k = 0` whatever x₀: its Jacobian has the mean as null vector, and no
//! continuation step can be taken. The level says so where it says why the branch stopped.

use stickslip_core::continuation::{Silent, TerminationReason};
use stickslip_io::analysis::run_level;
use stickslip_io::study::Study;

const HELD_BY_FRICTION: &str = r#"
[model]
dofs = ["M"]
mass = [[1.0]]
stiffness = [[1.0e6]]

[damping]
alpha = 10.0

[[load]]
name = "shaker"
dof = "M"

[[joint]]
name = "support"
law = "jenkins"
dof = "M"
stiffness = 1.0e6
replaces_stiffness = true
threshold = 10.0

[excitation]
load = "shaker"
levels = [5.0]

[sweep]
start_hz = 100.0
end_hz = 250.0

[harmonic_balance]
harmonics = 5
samples = 128

[[output]]
name = "mass"
dof = "M"
"#;

fn note_at(text: &str, level: f64) -> (TerminationReason, Option<String>) {
    let study = Study::parse(text, "study.toml").unwrap();
    let (model, excitation, outputs) = study.build_model().unwrap();
    let run = run_level(&study, &model, &excitation, &outputs, level, &mut Silent).unwrap();
    // The reason users read (the run's summary, Python's `ending`, the report) carries the
    // diagnosis in place of the general advice on steps and samples.
    let ending = run.ending();
    match &run.diagnosis {
        Some(d) => assert!(ending.ends_with(d.as_str()) && !ending.contains("min_step_hz, more"), "{ending}"),
        None => assert!(!ending.contains("singular value"), "{ending}"),
    }
    (run.termination, run.diagnosis)
}

#[test]
fn a_mass_held_by_a_slipping_joint_alone_is_diagnosed() {
    let (termination, note) = note_at(HELD_BY_FRICTION, 5.0);
    assert!(matches!(termination, TerminationReason::StepTooSmall { .. }), "{termination:?}");
    let note = note.expect("a diagnosis of the stop");
    assert!(note.contains("Jacobian is singular"), "{note}");
    assert!(note.contains("mean (harmonic 0)"), "{note}");
    // The mean is an exact null vector (the harmonic-0 row and column vanish): the singular
    // value is round-off, far below the 1e-10 the diagnosis requires.
    let ratio: f64 = note.split("smallest singular value ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    assert!(ratio <= 1e-14, "{note}");
}

#[test]
fn the_same_mass_also_held_by_a_spring_crosses_the_band_without_a_note() {
    // A spring of 20 % of the joint's stiffness that the joint does not replace fixes the mean.
    let held = HELD_BY_FRICTION.replace("stiffness = [[1.0e6]]", "stiffness = [[1.2e6]]");
    let (termination, note) = note_at(&held, 5.0);
    assert_eq!(termination, TerminationReason::ReachedEnd);
    assert_eq!(note, None);
}
