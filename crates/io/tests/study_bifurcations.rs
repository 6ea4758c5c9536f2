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
