//! The Harmony deck a run writes (`model.inp`) keeps the screws' moment stiffness in a form
//! CalculiX honours: each screw reference is a `*RIGID BODY` with a `ROT NODE`, and the
//! rotational components of the screw connectors are springs on the rotation nodes' DOFs 1-3.
//! Read back, the deck gives the model built in memory; CalculiX 2.20 finds the same modes
//! (`reference/harmony_coarse.freq`, from the deck this test writes, see `regenerate.sh`).

use std::path::PathBuf;

use stickslip_fe::assembly::FeModel;
use stickslip_fe::eigen::{solve, to_sparse, EigenOptions};
use stickslip_fe::harmony::{Configuration, Design};
use stickslip_fe::mesh::{inp, inp_writer};

/// Modes compared (the deck's `*FREQUENCY`).
const MODES: usize = 20;

fn frequencies(fe: &FeModel) -> Vec<f64> {
    let (k, m) = (to_sparse(&fe.model.stiffness).into_owned(), to_sparse(&fe.model.mass).into_owned());
    solve(&k, &m, &EigenOptions { count: MODES, ..Default::default() }).expect("modes").modes.frequencies_hz()
}

#[test]
fn coarse_deck_keeps_the_screw_moment_stiffness_for_calculix_and_reads_back_to_the_same_modes() {
    let mut mesh = Design::refined(0.5).build(Configuration::Assembly).expect("the default design");
    mesh.modes_requested = Some(MODES);
    let deck = inp_writer::to_string(&mesh).unwrap();
    let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("harmony_coarse.inp");
    std::fs::write(&path, &deck).unwrap();
    // 16 screw references (two screws, blade and body side, four blades) and the shaker, whose
    // rotations are held: the references whose rotations the deck names.
    assert_eq!(deck.matches("\n*RIGID BODY,").count(), 17, "rigid bodies in {}", path.display());
    assert!(!deck.contains("CalculiX 2.20 springs act on translations only"), "a rotational spring CalculiX ignores");

    let read = inp::read(&path).unwrap_or_else(|e| panic!("{e}"));
    let ids = |m: &stickslip_fe::mesh::Mesh| m.nodes.iter().map(|n| n.id).collect::<Vec<_>>();
    assert!(ids(&read) == ids(&mesh), "the rotation nodes leave the mesh read back");
    let (original, read) = (FeModel::assemble(mesh).unwrap(), FeModel::assemble(read).unwrap());
    assert_eq!(original.model.dofs, read.model.dofs, "DOF labels");
    let (ours, back) = (frequencies(&original), frequencies(&read));
    // The deck rounds some coordinates below 1e-3 to 15-16 digits (see `inp_writer`), and the
    // first mode (2.7 Hz, the structure on the shaker's spring) lies far below the 1e10 N/m
    // joints' stiffness: measured 3e-8 between the two on that mode.
    for (r, (a, b)) in ours.iter().zip(&back).enumerate() {
        assert!((a / b - 1.0).abs() < 1e-6, "mode {}: {a} Hz in memory, {b} Hz read back", r + 1);
    }

    let reference = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("reference/harmony_coarse.freq");
    let calculix: Vec<f64> = std::fs::read_to_string(&reference)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split_whitespace().nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(calculix.len(), MODES, "{}", reference.display());
    let mut worst = 0.0f64;
    for (r, (f, c)) in ours.iter().zip(&calculix).enumerate() {
        let d = (f / c - 1.0).abs();
        worst = worst.max(d);
        assert!(d < 1e-4, "mode {}: {f} Hz here vs CalculiX {c} Hz", r + 1);
    }
    println!(
        "{MODES} modes, {:.2}..{:.1} Hz: worst relative difference to CalculiX {worst:.1e}",
        ours[0],
        ours[MODES - 1]
    );
}
