//! `stickslip modes` on a Gmsh mesh: the material from the command line.
mod common;
use std::fmt::Write as _;

use common::{columns, scratch, stickslip};

/// A free steel bar of 4 unit hexahedra along z (no boundary condition: its 6 rigid-body
/// modes come first).
fn bar_inp() -> String {
    let mut s = String::from("*NODE\n");
    for layer in 0..5 {
        for (c, (x, y)) in [(0., 0.), (1., 0.), (1., 1.), (0., 1.)].iter().enumerate() {
            writeln!(s, "{}, {x}, {y}, {layer}.", 4 * layer + c + 1).unwrap();
        }
    }
    s.push_str("*ELEMENT, TYPE=C3D8, ELSET=BAR\n");
    for e in 0..4 {
        let n = |c: usize| 4 * e + c + 1;
        writeln!(s, "{}, {}, {}, {}, {}, {}, {}, {}, {}", e + 1, n(0), n(1), n(2), n(3), n(4), n(5), n(6), n(7))
            .unwrap();
    }
    s.push_str("*MATERIAL, NAME=STEEL\n*ELASTIC\n210e9, 0.3\n*DENSITY\n7800.\n");
    s.push_str("*SOLID SECTION, ELSET=BAR, MATERIAL=STEEL\n");
    s
}

/// The elastic modes' frequencies (Hz) of `modes.csv` in `dir`: those above 1 Hz (the rigid
/// ones come out at round-off, ~1e-4 Hz, and are left out).
fn elastic_hz(dir: &std::path::Path) -> Vec<f64> {
    columns(&dir.join("modes.csv"))["frequency_hz"].iter().copied().filter(|f| *f > 1.0).collect()
}

#[test]
fn modes_of_a_msh_take_the_material_from_the_command_line() {
    let dir = scratch("msh-modes");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("bar.inp"), bar_inp()).unwrap();
    let mesh = stickslip_fe::mesh::inp::parse(&bar_inp(), "bar.inp").unwrap();
    stickslip_fe::mesh::gmsh_writer::write(&mesh, dir.join("bar.msh")).unwrap();
    let modes = |model: &str, material: &[&str], out: &str| {
        stickslip()
            .args(["modes", "--count", "12", "--out"])
            .arg(dir.join(out))
            .arg(dir.join(model))
            .args(material)
            .output()
            .unwrap()
    };
    // Without a material: refused, naming the file and the options.
    let o = modes("bar.msh", &[], "none");
    let msg = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        msg.contains("bar.msh: a Gmsh mesh carries no material: give --young PA --poisson NU --density KG_M3"),
        "{msg}"
    );
    assert!(!dir.join("none/modes.csv").exists());
    // A bad value names its option.
    let o = modes("bar.msh", &["--young", "2.1e11", "--poisson", "0.5", "--density", "7800"], "bad");
    assert!(String::from_utf8_lossy(&o.stderr).contains("--poisson: Poisson's ratio must be in (-1, 0.5), got 0.5"));
    // The deck's steel given on the command line: the deck's modes, to the solver's round-off.
    let steel = ["--young", "210e9", "--poisson", "0.3", "--density", "7800"];
    for (model, material, out) in [("bar.inp", &[][..], "inp"), ("bar.msh", &steel[..], "msh")] {
        let o = modes(model, material, out);
        assert!(o.status.success(), "{model}: {}", String::from_utf8_lossy(&o.stderr));
    }
    let (inp, msh) = (elastic_hz(&dir.join("inp")), elastic_hz(&dir.join("msh")));
    assert_eq!(inp.len(), 6, "12 modes, 6 of them rigid: {inp:?}");
    for (a, b) in inp.iter().zip(&msh) {
        assert!((a - b).abs() <= 1e-8 * a, "{inp:?} vs {msh:?}");
    }
    // Twice the density: every frequency divided by √2 (ω² = k/m), so the density is used.
    let heavy = ["--young", "210e9", "--poisson", "0.3", "--density", "15600"];
    assert!(modes("bar.msh", &heavy, "heavy").status.success());
    for (a, b) in inp.iter().zip(&elastic_hz(&dir.join("heavy"))) {
        assert!((a / b - 2f64.sqrt()).abs() <= 1e-8, "{a} Hz / {b} Hz");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn fix_clamps_a_node_set_of_a_msh_as_a_boundary_of_the_deck_does() {
    let dir = scratch("msh-fix");
    std::fs::create_dir_all(&dir).unwrap();
    // The bar with its base (nodes 1-4) as a node set; the deck clamps it by *BOUNDARY.
    let free = format!("{}*NSET, NSET=BASE\n1, 2, 3, 4\n", bar_inp());
    let clamped = format!("{free}*BOUNDARY\nBASE, 1, 3\n");
    std::fs::write(dir.join("clamped.inp"), &clamped).unwrap();
    let mesh = stickslip_fe::mesh::inp::parse(&free, "bar.inp").unwrap();
    stickslip_fe::mesh::gmsh_writer::write(&mesh, dir.join("bar.msh")).unwrap();
    let steel = ["--young", "210e9", "--poisson", "0.3", "--density", "7800"];
    let modes = |model: &str, extra: &[&str], out: &str| {
        stickslip()
            .args(["modes", "--count", "6", "--out"])
            .arg(dir.join(out))
            .arg(dir.join(model))
            .args(extra)
            .output()
            .unwrap()
    };
    let o = modes("clamped.inp", &[], "inp");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let fix: Vec<&str> = steel.iter().copied().chain(["--fix", "base=1,2,3"]).collect();
    let o = modes("bar.msh", &fix, "msh");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let hz = |out: &str| columns(&dir.join(out).join("modes.csv"))["frequency_hz"].clone();
    let (inp, msh) = (hz("inp"), hz("msh"));
    // A clamped cantilever: no rigid-body mode (those come out at ~1e-4 Hz), its first bending
    // pair at 62.8 Hz; the same model twice, so equal to the solver's round-off (1e-8 asserted,
    // as above).
    assert!(inp[0] > 10.0, "{inp:?}");
    for (a, b) in inp.iter().zip(&msh) {
        assert!((a - b).abs() <= 1e-8 * a, "{inp:?} vs {msh:?}");
    }
    // Errors name the option, the set and what is expected.
    let bad = |arg: &str| {
        let args: Vec<&str> = steel.iter().copied().chain(["--fix", arg]).collect();
        let o = modes("bar.msh", &args, "bad");
        assert!(!o.status.success());
        String::from_utf8_lossy(&o.stderr).to_string()
    };
    let msg = bad("TOP=1,2,3");
    assert!(msg.contains("--fix TOP=1,2,3: no node set (physical group) `TOP` in") && msg.contains("BASE"), "{msg}");
    let msg = bad("BASE=1,7");
    assert!(msg.contains("--fix BASE=1,7: direction `7` is not one of 1..6"), "{msg}");
    let msg = bad("BASE");
    assert!(msg.contains("--fix BASE: expected SET=DIRECTIONS"), "{msg}");
    std::fs::remove_dir_all(&dir).unwrap();
}
