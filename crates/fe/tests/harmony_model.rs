//! The generated Harmony-like assembly against the paper's figures (Tables 1, 3-5), at the
//! coarse refinement that CI affords (element size 60 mm, ~31k DOFs). The default refinement
//! (30 mm, ~66k DOFs) is calibrated to the paper; docs/harmony.md gives the mesh convergence.

use stickslip_fe::assembly::FeModel;
use stickslip_fe::eigen::{solve, to_sparse, EigenOptions};
use stickslip_fe::harmony::{self, Configuration, Design};
use stickslip_fe::mesh::structured::GenerateError;

/// Frequencies (Hz) of the axial modes among the lowest `count`: those where the top of the
/// central body (accelerometer 101) moves vertically more than a tenth of the most it does.
fn axial_modes(design: &Design, count: usize) -> (Vec<f64>, f64) {
    let mesh = design.build(Configuration::Assembly).expect("a buildable design");
    let fe = FeModel::assemble(mesh).expect("assembly");
    let (k, m) = (to_sparse(&fe.model.stiffness), to_sparse(&fe.model.mass));
    let (k, m) = (k.into_owned(), m.into_owned());
    let sol = solve(&k, &m, &EigenOptions { count, ..Default::default() }).expect("modes");
    let top = fe.dof(harmony::accelerometer(0), 3).expect("body top DOF");
    let amp: Vec<f64> = (0..count).map(|j| sol.modes.shapes[(top, j)].abs()).collect();
    let largest = amp.iter().copied().fold(0.0, f64::max);
    let f = sol.modes.frequencies_hz();
    // The first mode is the whole structure on the shaker's soft spring (~2.7 Hz).
    let axial = (1..count).filter(|&j| amp[j] > 0.1 * largest).map(|j| f[j]).collect();
    (axial, fe.solid_mass)
}

#[test]
fn coarse_assembly_has_the_paper_axial_modes_and_masses() {
    let design = Design::refined(0.5);
    let (stuck, mass) = axial_modes(&design, 16);
    // Table 1: 9.47 + 44.88 + 11.92 + 4 x 0.1086 kg; the parts' dimensions are set from these
    // masses on the exact geometry, the mesh differs by the arcs' quadratic interpolation.
    let table1 = 9.47 + 44.88 + 11.92 + 4.0 * 0.1086;
    assert!((mass - table1).abs() < 5e-3 * table1, "solid mass {mass} kg vs Table 1 {table1} kg");
    // Table 5: 237.6 Hz and 878.4 Hz. The coarse mesh is stiffer than the calibrated default
    // (measured: +3.8 % on the first mode, see docs/harmony.md): 5 % covers it, and a change
    // of the model that moves the mode by more than the mesh error fails.
    assert!(stuck.len() >= 2, "axial modes found: {stuck:?}");
    assert!((stuck[0] / 237.6 - 1.0).abs() < 0.05, "first axial mode {} Hz", stuck[0]);
    assert!((stuck[1] / 878.4 - 1.0).abs() < 0.05, "second axial mode {} Hz", stuck[1]);
    // All blades slipping (contact connectors released vertically): the paper's asymptote near
    // 190 Hz (Section 5.1); coarse mesh +4.9 %.
    let released = Design { contact_vertical_stiffness: 0.0, ..design };
    let (slipping, _) = axial_modes(&released, 6);
    assert!((slipping[0] / 190.0 - 1.0).abs() < 0.06, "all-slipping axial mode {} Hz", slipping[0]);
    assert!(slipping[0] < 0.9 * stuck[0]);
}

#[test]
fn paper_retained_set_has_103_dofs() {
    let mesh = Design::refined(0.5).build(Configuration::Assembly).unwrap();
    let fe = FeModel::assemble(mesh).unwrap();
    let count: usize = ["ACCELEROMETERS", "SHAKER", "BLADE_SCREWS", "CONTACT_ZONES"]
        .iter()
        .map(|s| fe.set_dofs(s).unwrap().len())
        .sum();
    // 10 tri-axial accelerometers, the shaker's vertical DOF, 3 reference nodes x 6 per blade.
    assert_eq!(count, 103);
    // The blade tips (Top_Blade) exist, with 6 DOFs, and are not in the retained sets.
    for i in 1..=4 {
        assert!(fe.dof(harmony::top_blade(i), 3).is_ok());
    }
}

#[test]
fn geometry_that_cannot_be_built_is_refused_naming_the_key() {
    let cases: Vec<(Design, &str)> = vec![
        (Design { diaphragm_thickness: -0.001, ..Design::default() }, "diaphragm_thickness"),
        (Design { base_radius: -0.2, ..Design::default() }, "base_radius"),
        (Design { diaphragm_thickness: 0.05, ..Design::default() }, "diaphragm_thickness"),
        (Design { blade_length: 0.3, ..Design::default() }, "blade_length"),
        (Design { blade_thickness: 0.2, ..Design::default() }, "blade"),
        (Design { element_size: f64::NAN, ..Design::default() }, "element_size"),
    ];
    for (design, key) in cases {
        match design.build(Configuration::Assembly) {
            Err(GenerateError::Geometry { msg, .. }) => assert!(msg.contains(key), "{key}: {msg}"),
            other => panic!("{key}: expected a geometry error, got {:?}", other.map(|m| m.nodes.len())),
        }
    }
}
