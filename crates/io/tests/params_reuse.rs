//! A parameter study builds the linear model and its reduction once while the varied keys
//! leave them unchanged, and its results are those of samples built from scratch.

use std::path::PathBuf;

use stickslip_io::params::{ParamStudy, SampleOutcome, SampleRunner, Vary};

/// A 6-mass chain grounded at both ends, reduced (enriched: the joint that replaces the
/// spring between masses 3 and 4 is released) to 3 retained DOFs and 2 modes; a Jenkins
/// joint replaces that spring, Rayleigh damping, two force levels.
const CHAIN: &str = r#"
[model]
dofs = ["a", "b", "c", "d", "e", "f"]
mass = [1.0, 1.2, 0.8, 1.1, 0.9, 1.3]
stiffness = [[ 2.0e6, -1.0e6,  0.0,    0.0,    0.0,    0.0],
             [-1.0e6,  2.0e6, -1.0e6,  0.0,    0.0,    0.0],
             [ 0.0,   -1.0e6,  2.0e6, -1.0e6,  0.0,    0.0],
             [ 0.0,    0.0,   -1.0e6,  2.0e6, -1.0e6,  0.0],
             [ 0.0,    0.0,    0.0,   -1.0e6,  2.0e6, -1.0e6],
             [ 0.0,    0.0,    0.0,    0.0,   -1.0e6,  2.0e6]]

[reduction]
method = "enriched"
retain = ["a", "c", "d"]
modes = 2
release_modes = 1

[damping]
alpha = 20.0

[[load]]
name = "shaker"
dof = "a"

[[joint]]
name = "j"
law = "jenkins"
between = ["c", "d"]
stiffness = 1.0e6
replaces_stiffness = true
threshold = 40.0

[excitation]
load = "shaker"
levels = [20.0, 60.0]

[sweep]
start_hz = 60.0
end_hz = 180.0

[harmonic_balance]
harmonics = 3
samples = 64

[[output]]
name = "a"
dof = "a"
"#;

fn study(varies: &[&str], samples: Option<usize>) -> ParamStudy {
    let varies: Vec<Vary> = varies.iter().map(|v| Vary::parse(v).unwrap()).collect();
    let table: toml::Table = toml::from_str(CHAIN).unwrap();
    ParamStudy::new(table, PathBuf::from("chain.toml"), &varies, samples, 5).unwrap()
}

/// Runs every sample through one runner (reuse) and each from scratch; returns the number of
/// linear models the runner built.
fn compare(p: &ParamStudy) -> usize {
    let mut runner = SampleRunner::new(p);
    let reused: Vec<SampleOutcome> = (0..p.samples.len()).map(|i| runner.run(i, None, true)).collect();
    for (i, r) in reused.iter().enumerate() {
        let fresh = p.run_sample(i, None, true);
        assert_eq!(r.error, None, "sample {i}");
        assert_eq!(fresh.error, None, "sample {i}");
        assert_eq!(r.rows.len(), 2, "sample {i}: {:?}", r.error);
        // The same model is built from the same numbers in the same order: results agree to
        // round-off, asked at 1e-12 relative (every value, every point of every curve).
        let close = |a: f64, b: f64, what: &str| {
            assert!((a - b).abs() <= 1e-12 * a.abs().max(b.abs()), "sample {i}, {what}: {a:e} (reused) vs {b:e}");
        };
        for (a, b) in r.rows.iter().zip(&fresh.rows) {
            close(a.peak_frequency_hz, b.peak_frequency_hz, "peak frequency");
            close(a.peak_amplitude_m, b.peak_amplitude_m, "peak amplitude");
            close(a.peak_energy_j, b.peak_energy_j, "peak energy");
            assert_eq!((a.points, a.complete), (b.points, b.complete), "sample {i}");
            assert!(a.points > 10 && a.complete, "sample {i}: a whole branch, {} points", a.points);
        }
        for (la, lb) in r.levels.as_ref().unwrap().iter().zip(fresh.levels.as_ref().unwrap()) {
            assert_eq!(la.points.len(), lb.points.len());
            for (pa, pb) in la.points.iter().zip(&lb.points) {
                close(pa.frequency_hz, pb.frequency_hz, "frequency");
                for (oa, ob) in pa.outputs.iter().zip(&pb.outputs) {
                    for (ha, hb) in oa.harmonics.iter().zip(&ob.harmonics) {
                        close(ha.0, hb.0, "harmonic amplitude");
                    }
                }
            }
        }
    }
    runner.builds
}

#[test]
fn keys_on_top_of_the_linear_model_reuse_it_with_the_same_results() {
    // Threshold, Rayleigh damping and a force level: one reduction for the 6 samples.
    let p = study(&["joint.j.threshold=20:60", "damping.alpha=5:40", "excitation.levels[1]=40:80"], Some(6));
    assert_eq!(compare(&p), 1);
}

#[test]
fn keys_of_the_linear_model_or_of_the_released_joints_rebuild_it() {
    // A mass changes the model; the replaced stiffness of a released joint changes the
    // enriched basis: each new value is a new build (grid, one key varying: 3 values).
    let p = study(&["model.mass[1]=1.0,1.2,1.4"], None);
    assert_eq!(compare(&p), 3);
    let p = study(&["joint.j.stiffness=0.5e6,0.8e6,1.0e6"], None);
    assert_eq!(compare(&p), 3);
    // The threshold varying fastest in a grid: a build per stiffness value only.
    let p = study(&["joint.j.stiffness=0.5e6,1.0e6", "joint.j.threshold=30,50"], None);
    assert_eq!(compare(&p), 2);
}

/// The coarse Harmony model (refinement 0.5, enriched reduction): two thresholds on one
/// reduction equal two builds from scratch. Minutes on a shared 2-core machine: run with
/// `cargo test -p stickslip-io --test params_reuse -- --ignored`.
#[test]
#[ignore]
fn the_coarse_harmony_reuses_its_reduction_with_the_same_results() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/harmony/study.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("refinement = 1.0"), "the example's refinement line changed");
    let mut table: toml::Table = toml::from_str(&text.replace("refinement = 1.0", "refinement = 0.5")).unwrap();
    // Two of the paper's levels, one below and one above the joints' first slip.
    table["excitation"]["levels"] = toml::Value::Array(vec![70.0.into(), 1875.0.into()]);
    let varies = [Vary::parse("joint.blade1.threshold=250,330").unwrap()];
    let p = ParamStudy::new(table, &path, &varies, None, 0).unwrap();
    assert_eq!(compare(&p), 1);
}
