//! `[model.harmony]` keys of the body and blade geometry (docs/study-file.md): taken into the
//! design, and refused naming the key when they cannot be.

use std::path::PathBuf;

use stickslip_io::study::{ModelSpec, Study};

fn example() -> String {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/harmony/study.toml");
    std::fs::read_to_string(path).unwrap()
}

/// The example with `keys` added to its `[model.harmony]`.
fn with_keys(keys: &str) -> Result<Study, String> {
    let text = example().replacen("[model.harmony]\n", &format!("[model.harmony]\n{keys}\n"), 1);
    Study::parse(&text, "study.toml").map_err(|e| e.to_string())
}

#[test]
fn geometry_keys_reach_the_design() {
    let study =
        with_keys("blade_rise = 0.0\nscrew_radii = [0.1, 0.13]\nbody_flange_radius = 0.15\ntop_disk_thickness = 0.009")
            .unwrap();
    let ModelSpec::Harmony { design, .. } = &study.model else { panic!("a Harmony model") };
    assert_eq!(design.variant.blade_rise, 0.0);
    assert_eq!(design.screw_radii, [0.1, 0.13]);
    assert_eq!(design.variant.body_flange_radius, Some(0.15));
    assert_eq!(design.variant.top_disk_thickness, Some(0.009));
    // The defaults are the calibrated design's (docs/harmony.md).
    let ModelSpec::Harmony { design, .. } = with_keys("").unwrap().model else { panic!("a Harmony model") };
    assert_eq!(design.variant.blade_rise, 0.0145);
}

#[test]
fn geometry_keys_that_cannot_be_built_are_refused_naming_the_key() {
    for (keys, expected) in [
        ("screw_radii = [0.1]", "screw_radii must give 2 radii"),
        ("screw_radii = [0.1, nan]", "screw_radii[1] must be a finite number"),
        ("blade_rise = -0.01", "blade_rise"),
        ("body_flange_radius = 0.0", "body_flange_radius"),
        ("top_disk_thickness = -1.0", "top_disk_thickness"),
        // Beyond the bottom ring's inner radius, checked with the other dimensions.
        ("body_flange_radius = 0.19", "body_flange_radius"),
        // A screw zone off the blade (its root is at 78 mm from the axis).
        ("screw_radii = [0.05, 0.115]", "screw_radii[0]"),
        ("screw_radii = [0.1, 0.115]", "screw zones (radius 0.01 m) overlap"),
        // Blades standing up above the envelope's top.
        ("blade_rise = 0.5", "above the envelope"),
    ] {
        let message = with_keys(keys).map(|_| ()).unwrap_err();
        println!("{keys}: {message}");
        assert!(message.starts_with("study.toml:"), "{keys}: {message}");
        assert!(message.contains("[model.harmony]") && message.contains(expected), "{keys}: {message}");
    }
}

#[test]
fn a_refinement_beyond_memory_is_refused_with_its_estimate_before_meshing() {
    let text = example().replace("refinement = 1.0", "refinement = 4.0");
    let message = Study::parse(&text, "study.toml").map(|_| ()).unwrap_err().to_string();
    println!("{message}");
    assert!(message.starts_with("study.toml:") && message.contains("[model.harmony]"), "{message}");
    // The estimate, in DOFs and GiB, and what to change.
    assert!(message.contains("refinement 4 would make about") && message.contains("GiB"), "{message}");
    assert!(message.contains("lower `refinement`"), "{message}");
}

#[test]
fn a_joint_on_a_node_outside_the_mesh_is_refused_before_the_modes() {
    // The coarse mesh, with blade 2's contact on a node the mesh does not have.
    let text = example()
        .replace("refinement = 1.0", "refinement = 0.5")
        .replace("between = [\"12.3\", \"22.3\"]", "between = [\"12.3\", \"99999.3\"]");
    let study = Study::parse(&text, "study.toml").unwrap();
    let mut stages = Vec::new();
    let message = study.build_model_timed(&mut stages).map(|_| ()).unwrap_err().to_string();
    println!("{message}");
    assert!(message.contains("[[joint]] \"blade2\"") && message.contains("99999.3"), "{message}");
    // Refused after the mesh and its assembly, before the modes and the reduction.
    let names: Vec<&str> = stages.iter().map(|(s, _)| s.as_str()).collect();
    assert_eq!(names, ["mesh", "assembly"], "{message}");
}
