//! The shipped example studies parse and build the models of paper Table 6.

use std::path::PathBuf;

use stickslip_io::study::{HbmSettings, Study};

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name).join("study.toml")
}

/// Force of element `e` of the model at displacement `u`, starting from the unloaded state.
fn element_force(model: &stickslip_core::model::NonlinearModel, e: usize, u: f64) -> f64 {
    let law = &model.elements[e].law;
    let mut state = vec![0.0; law.n_state()];
    let mut g = [0.0];
    law.update(&[u], &[0.0], &mut state, &mut g, None);
    g[0]
}

#[test]
fn table6_one_dof_builds_the_stuck_oscillator() {
    let study = Study::load(example("jenkins-1dof")).unwrap();
    assert_eq!(study.hbm, HbmSettings { harmonics: 7, samples: 300, ..HbmSettings::default() });
    assert_eq!((study.sweep.start_hz, study.sweep.end_hz), (150.0, 350.0));
    let (model, excitation, outputs) = study.build_model().unwrap();
    assert_eq!(excitation.levels_n, vec![100.0, 1000.0, 3000.0, 10000.0]);
    assert_eq!(excitation.pattern, vec![1.0]);
    assert_eq!(outputs.len(), 1);
    // Stuck natural frequency sqrt(k/M)/2π = 238.2 Hz (table6-jenkins.toml); the dense
    // eigensolver is accurate to round-off, the reference value is given to 4 digits.
    let f = model.linear.dense_modes().unwrap().frequencies_hz()[0];
    assert!((f - 238.2).abs() < 0.05, "stuck frequency {f} Hz");
    // D = αM with α = 35 1/s is the paper's d = 350 N·s/m.
    let d = model.linear.damping_dense(None);
    assert!((d[(0, 0)] - 350.0).abs() < 1e-9);
    // Paper form (Eq. 11): stuck, the element adds nothing to K (g = f − k_J u = 0); in gross
    // slip it gives F_c − k_J u. Exact arithmetic on these inputs: 1e-9 relative is round-off.
    assert_eq!(element_force(&model, 0, 1e-5), 0.0);
    let u = 1e-3;
    let expected = 1000.0 - 8.11e6 * u;
    assert!((element_force(&model, 0, u) - expected).abs() < 1e-9 * expected.abs());
}

#[test]
fn table6_two_dof_builds_the_slider_mass_and_hard_contact() {
    let study = Study::load(example("jenkins-2dof")).unwrap();
    let (model, excitation, outputs) = study.build_model().unwrap();
    assert_eq!(model.linear.n_dofs(), 2);
    assert_eq!(excitation.pattern, vec![1.0, 0.0]);
    assert_eq!(outputs.iter().map(|o| o.name.as_str()).collect::<Vec<_>>(), ["mass", "slider"]);
    assert_eq!(model.elements[0].directions, vec![vec![0.0, 1.0]]);
    // Without the contact, P (mass ratio 1e-4) only follows M, which then sees k − k_J to the
    // ground: the lower mode is sqrt((k − k_J)/M)/2π = 190.3 Hz up to O(m/M) = 1e-4 relative.
    let f = model.linear.dense_modes().unwrap().frequencies_hz()[0];
    assert!((f - 190.3).abs() < 0.1, "lowest frequency without contact {f} Hz");
    // The joint is standalone with k_hard: stuck force k_hard u below F_c / k_hard = 1 µm.
    let u = 5e-7;
    assert!((element_force(&model, 0, u) - 1e9 * u).abs() < 1e-9 * 1e9 * u);
    assert_eq!(element_force(&model, 0, 1e-3), 1000.0);
}
