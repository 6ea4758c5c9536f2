//! Folds and branch points of the shipped examples as a run finds them: from the
//! continuation's tangent and determinants at every sweep, with or without stability.

use std::path::PathBuf;

use stickslip_core::continuation::Silent;
use stickslip_io::analysis::run_level;
use stickslip_io::output::LevelResult;
use stickslip_io::study::Study;

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name).join("study.toml")
}

/// Every level of `study`, swept.
fn levels(study: &Study) -> Vec<LevelResult> {
    let (model, excitation, outputs) = study.build_model().unwrap();
    excitation
        .levels_n
        .iter()
        .map(|&level| {
            let started = std::time::Instant::now();
            let run = run_level(study, &model, &excitation, &outputs, level, &mut Silent).unwrap();
            let whole = started.elapsed().as_secs_f64();
            assert!(run.is_complete(), "{level} N: {:?}", run.termination);
            // Each stage's wall clock measured (the report's timings): every stage takes some
            // time, and the stages are disjoint parts of the level.
            let s = run.seconds;
            assert!([s.sweep, s.peaks, s.bifurcations].iter().all(|t| *t > 0.0), "{s:?}");
            assert!(s.sweep + s.peaks + s.bifurcations <= whole, "{s:?} in {whole} s");
            run.result
        })
        .collect()
}

#[test]
fn the_duffing_example_has_its_two_folds_with_or_without_stability() {
    let with = Study::load(example("duffing")).unwrap();
    assert!(with.hbm.stability);
    let mut without = with.clone();
    without.hbm.stability = false;
    let (with, without) = (levels(&with), levels(&without));
    // 1 N does not fold; 5 N does, twice (the example's comment).
    assert!(with[0].bifurcations.is_empty());
    let kinds: Vec<&str> = with[1].bifurcations.iter().map(|b| b.kind.as_str()).collect();
    assert_eq!(kinds, ["fold", "fold"]);
    assert!(with[1].bifurcations.iter().all(|b| b.located && b.exponent_im == 0.0));
    // Between the folds the points are unstable, stable outside: the stable flag changes
    // at each fold and nowhere else.
    let changes: Vec<usize> = with[1]
        .points
        .windows(2)
        .enumerate()
        .filter(|(_, w)| w[0].stability.unwrap().stable != w[1].stability.unwrap().stable)
        .map(|(i, _)| i)
        .collect();
    assert_eq!(changes.len(), 2);
    // The same folds, bit for bit, without the stability: the branch and its test functions do
    // not depend on it.
    for (a, b) in with.iter().zip(&without) {
        assert_eq!(a.bifurcations, b.bifurcations);
        assert!(b.points.iter().all(|p| p.stability.is_none()));
    }
}

#[test]
fn the_friction_examples_have_no_fold_and_no_branch_point() {
    // The 1-DOF Table 6 system with the stability: every point stable (Hill finds no crossing)
    // and no fold or branch point from the tangent either.
    let mut one = Study::load(example("jenkins-1dof")).unwrap();
    one.hbm.stability = true;
    for level in levels(&one) {
        assert!(level.points.iter().all(|p| p.stability.unwrap().stable), "{} N", level.level_n);
        assert_eq!(level.bifurcations, [], "{} N", level.level_n);
    }
    // The 2-DOF one (a damping matrix, taken by Hill's method in modal coordinates): its
    // branches go forwards in frequency at every step, every point is stable, and none is found.
    let mut two = Study::load(example("jenkins-2dof")).unwrap();
    two.hbm.stability = true;
    for level in levels(&two) {
        assert!(level.points.windows(2).all(|w| w[1].frequency_hz > w[0].frequency_hz), "{} N", level.level_n);
        assert!(level.points.iter().all(|p| p.stability.unwrap().stable), "{} N", level.level_n);
        assert_eq!(level.bifurcations, [], "{} N", level.level_n);
    }
}

/// Krack & Gross's forced two-DOF oscillator with cubic springs and dampers on its springs (a
/// general damping matrix), NLvib's `twoDOFoscillator_cubicSpring`, as the shipped example.
fn krack_gross() -> String {
    std::fs::read_to_string(example("two-dof-neimark-sacker")).unwrap()
}

#[test]
fn a_run_with_a_damping_matrix_lists_the_published_neimark_sacker_bifurcations() {
    // The crossings located to round-off by shooting (bench/peer/nlvib_neimark_sacker.py), in
    // Hz; the core test `stability_published_neimark_sacker.rs` compares them with NLvib's run.
    let shooting = [1.112_711_239, 1.195_736_669].map(|w: f64| w / std::f64::consts::TAU);
    let study = Study::parse(&krack_gross(), "study.toml").unwrap();
    let level = &levels(&study)[0];
    let ns: Vec<_> = level.bifurcations.iter().filter(|b| b.kind == "Neimark-Sacker").collect();
    assert_eq!(ns.len(), 2, "{:?}", level.bifurcations);
    for (b, f) in ns.iter().zip(shooting) {
        // As in the core test (measured 1e-10): the run's own steps, the same location.
        assert!(b.located && (b.frequency_hz - f).abs() <= 1e-8 * f, "{} Hz against {f}", b.frequency_hz);
        assert!(b.exponent_im > 0.0);
    }
    let folds = level.bifurcations.iter().filter(|b| b.kind == "fold").count();
    assert_eq!(folds, 2, "{:?}", level.bifurcations);
}

#[test]
fn a_run_says_when_hill_leaves_out_modes_of_a_model_with_a_damping_matrix() {
    let run = |text: &str| {
        let study = Study::parse(text, "study.toml").unwrap();
        let (model, excitation, outputs) = study.build_model().unwrap();
        run_level(&study, &model, &excitation, &outputs, 0.11, &mut Silent).unwrap().note
    };
    // Every mode kept (both below (N + 1) times the band's top): nothing to say.
    assert_eq!(run(&krack_gross()), None);
    // A third mass on a stiff spring to the first: its mode (~100 rad/s) lies above the 11.2
    // rad/s Hill's method keeps.
    let three = krack_gross()
        .replace(r#"dofs = ["x1", "x2"]"#, r#"dofs = ["x1", "x2", "x3"]"#)
        .replace("mass = [1.0, 0.05] ", "mass = [1.0, 0.05, 1.0] ")
        .replace(
            "stiffness = [[1.0453, -0.0453], [-0.0453, 0.0453]] ",
            "stiffness = [[10001.0453, -0.0453, -1e4], [-0.0453, 0.0453, 0.0], [-1e4, 0.0, 1e4]] ",
        )
        .replace(
            "matrix = [[0.015, -0.013], [-0.013, 0.013]] ",
            "matrix = [[0.015, -0.013, 0.0], [-0.013, 0.013, 0.0], [0.0, 0.0, 0.0]] ",
        );
    let note = run(&three).expect("a note");
    assert!(note.contains("keeps 2 of the model's 3 modes") && note.contains("approximate"), "{note}");
}
