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
