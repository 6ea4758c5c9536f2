//! Models from a mesh (assembled by stickslip-fe) and their reduction (paper Section 3.3).

use std::fmt::Write as _;
use std::path::PathBuf;

use stickslip_io::study::Study;

fn scratch_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("stickslip-io-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A steel bar of 4 unit hexahedra along z, clamped at z = 0; node set TIP at z = 4.
/// Node `4 layer + c + 1` is corner c of layer `layer`.
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
    s.push_str("*NSET, NSET=BASE\n1, 2, 3, 4\n*NSET, NSET=TIP\n17, 18, 19, 20\n");
    s.push_str("*MATERIAL, NAME=STEEL\n*ELASTIC\n210e9, 0.3\n*DENSITY\n7800.\n");
    s.push_str("*SOLID SECTION, ELSET=BAR, MATERIAL=STEEL\n*BOUNDARY\nBASE, 1, 3\n");
    s
}

const REST: &str = r#"
[damping]
alpha = 5.0

[[load]]
name = "tip"
dof = "17.1"

[[joint]]
name = "contact"
law = "jenkins"
dof = "18.1"
stiffness = 1.0e8
threshold = 100.0

[excitation]
levels = [10.0]

[sweep]
start_hz = 50.0
end_hz = 150.0

[[output]]
name = "tip_x"
dof = "19.1"
"#;

fn lowest_hz(model: &stickslip_core::model::LinearModel, n: usize) -> Vec<f64> {
    model.dense_modes().unwrap().frequencies_hz()[..n].to_vec()
}

#[test]
fn a_mesh_builds_and_its_free_mode_reduction_keeps_the_lowest_modes() {
    let dir = scratch_dir("mesh");
    std::fs::write(dir.join("bar.inp"), bar_inp()).unwrap();
    std::fs::write(dir.join("full.toml"), format!("[model]\nmesh = \"bar.inp\"\n{REST}")).unwrap();
    let (full, excitation, outputs) = Study::load(dir.join("full.toml")).unwrap().build_model().unwrap();
    // 16 free nodes × 3 directions, named node.direction.
    assert_eq!(full.linear.n_dofs(), 48);
    let i = full.linear.dof_index("17.1").unwrap();
    assert_eq!(excitation.pattern[i], 1.0);
    assert_eq!(outputs[0].vector[full.linear.dof_index("19.1").unwrap()], 1.0);

    let reduced_study =
        format!("[model]\nmesh = \"bar.inp\"\n[reduction]\nmethod = \"free\"\nretain = [\"TIP\"]\nmodes = 4\n{REST}");
    std::fs::write(dir.join("reduced.toml"), reduced_study).unwrap();
    let (red, excitation, outputs) = Study::load(dir.join("reduced.toml")).unwrap().build_model().unwrap();
    // 4 tip nodes × 3 retained DOFs + 4 modes.
    assert_eq!(red.linear.n_dofs(), 16);
    assert_eq!(red.linear.dofs[0].name, "17.1");
    // The free-mode basis holds the 4 lowest free modes exactly: the reduced model has the
    // same 4 lowest frequencies, to the eigensolvers' accuracy (residual tolerance 1e-10 of the
    // Lanczos solver, eigenvalue error of its square; dense solver at round-off).
    let (f_full, f_red) = (lowest_hz(&full.linear, 4), lowest_hz(&red.linear, 4));
    for (a, b) in f_full.iter().zip(&f_red) {
        assert!((a - b).abs() < 1e-8 * a, "full {f_full:?} Hz, reduced {f_red:?} Hz");
    }
    // Retained DOFs project to unit vectors of the reduced model (constraint modes are the
    // identity on the retained DOFs and the dynamic vectors vanish there).
    let unit = |name: &str| {
        let k = red.linear.dof_index(name).unwrap();
        (0..16).map(|j| if j == k { 1.0 } else { 0.0 }).collect::<Vec<f64>>()
    };
    let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
    assert!(close(&excitation.pattern, &unit("17.1")), "{:?}", excitation.pattern);
    assert!(close(&red.elements[0].directions[0], &unit("18.1")));
    assert!(close(&outputs[0].vector, &unit("19.1")));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `modes_up_to_hz` keeps every mode up to the frequency, counted by the inertia of K − σM:
/// free modes of the whole bar for "free", fixed-interface modes for "cb"; with `modes` it is
/// refused, and so is a frequency below the first free mode or not > 0.
#[test]
fn modes_up_to_a_frequency_are_counted_not_guessed() {
    let dir = scratch_dir("mesh-up-to");
    std::fs::write(dir.join("bar.inp"), bar_inp()).unwrap();
    std::fs::write(dir.join("full.toml"), format!("[model]\nmesh = \"bar.inp\"\n{REST}")).unwrap();
    let (full, _, _) = Study::load(dir.join("full.toml")).unwrap().build_model().unwrap();
    let f = full.linear.dense_modes().unwrap().frequencies_hz();
    let study = |keys: &str| {
        let text =
            format!("[model]\nmesh = \"bar.inp\"\n[reduction]\nmethod = \"free\"\nretain = [\"TIP\"]\n{keys}\n{REST}");
        std::fs::write(dir.join("s.toml"), text).unwrap();
        Study::load(dir.join("s.toml")).and_then(|s| s.build_model())
    };
    // Halfway between the 5th free mode (or the last copy of it: the square bar's bending modes
    // are double) and the next: every mode up to there, 12 retained DOFs.
    let mut last = 4;
    while f[last + 1] - f[last] < 1e-6 * f[last + 1] {
        last += 1;
    }
    let (red, _, _) = study(&format!("modes_up_to_hz = {}", 0.5 * (f[last] + f[last + 1]))).unwrap();
    assert_eq!(red.linear.n_dofs(), 12 + last + 1, "{:?} Hz", &f[..last + 2]);
    let g = lowest_hz(&red.linear, last + 1);
    for (a, b) in f.iter().zip(&g) {
        assert!((a - b).abs() < 1e-8 * a, "full {:?} Hz, reduced {g:?} Hz", &f[..=last]);
    }
    let msg = |keys: &str| study(keys).unwrap_err().to_string();
    let e = msg("modes = 4\nmodes_up_to_hz = 1000.0");
    assert!(e.contains("[reduction]: give either `modes` (a number of modes) or `modes_up_to_hz`"), "{e}");
    let e = msg("modes_up_to_hz = -5.0");
    assert!(e.contains("[reduction]: modes_up_to_hz must be > 0 Hz, got -5"), "{e}");
    let e = msg("");
    assert!(e.contains("[reduction]: needs `modes` (a number of modes) or `modes_up_to_hz`"), "{e}");
    let e = msg(&format!("modes_up_to_hz = {}", 0.5 * f[0]));
    assert!(e.contains("modes_up_to_hz") && e.contains("has no mode up to"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_unknown_retained_set_is_named() {
    let dir = scratch_dir("mesh-retain");
    std::fs::write(dir.join("bar.inp"), bar_inp()).unwrap();
    let text =
        format!("[model]\nmesh = \"bar.inp\"\n[reduction]\nmethod = \"cb\"\nretain = [\"TOP\"]\nmodes = 2\n{REST}");
    std::fs::write(dir.join("study.toml"), text).unwrap();
    let msg = Study::load(dir.join("study.toml")).unwrap().build_model().unwrap_err().to_string();
    assert!(
        msg.contains(
            "study.toml:5:10: [reduction] retain (neither a node set of the mesh nor a DOF): no DOF named \"TOP\""
        ),
        "{msg}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_gmsh_mesh_needs_a_material() {
    let mesh = concat!(env!("CARGO_MANIFEST_DIR"), "/../fe/tests/data/box_hex8_binary.msh");
    let rest =
        "[[load]]\nname = \"p\"\ndof = \"1.3\"\n[excitation]\nlevels = [1.0]\n[sweep]\nstart_hz = 1.0\nend_hz = 2.0\n\
                [[output]]\nname = \"corner\"\ndof = \"1.3\"\n";
    let without = format!("[model]\nmesh = \"{mesh}\"\n{rest}");
    let msg = Study::parse(&without, "study.toml").unwrap().build_model().unwrap_err().to_string();
    assert!(msg.starts_with("study.toml:2:8: [model] mesh: element") && msg.contains("has no material"), "{msg}");
    let with =
        format!("[model]\nmesh = \"{mesh}\"\nmaterial = {{ young = 70e9, poisson = 0.33, density = 2700.0 }}\n{rest}");
    let (model, _, _) = Study::parse(&with, "study.toml").unwrap().build_model().unwrap();
    assert!(model.linear.n_dofs() > 0);
}

/// The bar of [`bar_inp`] as a Gmsh file (its node sets as physical groups; no material, no
/// boundary condition: a `.msh` holds neither).
fn bar_msh(dir: &std::path::Path) -> PathBuf {
    let mesh = stickslip_fe::mesh::inp::parse(&bar_inp(), "bar.inp").unwrap();
    let path = dir.join("bar.msh");
    stickslip_fe::mesh::gmsh_writer::write(&mesh, &path).unwrap();
    path
}

#[test]
fn a_msh_with_fixed_node_sets_is_the_deck_with_its_boundary() {
    // The deck fixes BASE (1-3) by *BOUNDARY and gives steel; the same mesh as .msh gets both
    // from the study. Same nodes, elements, material and fixed DOFs: the same M and K, so the
    // same modes to the eigensolver's round-off.
    let dir = scratch_dir("msh-fixed");
    std::fs::write(dir.join("bar.inp"), bar_inp()).unwrap();
    bar_msh(&dir);
    std::fs::write(dir.join("inp.toml"), format!("[model]\nmesh = \"bar.inp\"\n{REST}")).unwrap();
    let material = "material = { young = 210e9, poisson = 0.3, density = 7800.0 }";
    let msh = format!("[model]\nmesh = \"bar.msh\"\n{material}\nfixed = {{ BASE = [1, 2, 3] }}\n{REST}");
    std::fs::write(dir.join("msh.toml"), &msh).unwrap();
    let (from_inp, _, _) = Study::load(dir.join("inp.toml")).unwrap().build_model().unwrap();
    let (from_msh, _, _) = Study::load(dir.join("msh.toml")).unwrap().build_model().unwrap();
    assert_eq!(from_msh.linear.n_dofs(), 48, "16 free nodes x 3 directions");
    assert!(from_msh.linear.dof_index("1.1").is_err(), "node 1 of BASE is fixed");
    let (a, b) = (lowest_hz(&from_inp.linear, 4), lowest_hz(&from_msh.linear, 4));
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() <= 1e-9 * x, "{a:?} vs {b:?}");
    }
    // Only the x direction fixed: y and z of the 4 base nodes are free, 8 more DOFs.
    let (x_only, _, _) = Study::parse(&msh.replace("BASE = [1, 2, 3]", "BASE = [1]"), dir.join("x.toml"))
        .unwrap()
        .build_model()
        .unwrap();
    assert_eq!(x_only.linear.n_dofs(), 56);
}

#[test]
fn fixed_node_sets_say_what_is_wrong() {
    let dir = scratch_dir("msh-fixed-errors");
    bar_msh(&dir);
    let material = "material = { young = 210e9, poisson = 0.3, density = 7800.0 }";
    let study = |fixed: &str| format!("[model]\nmesh = \"bar.msh\"\n{material}\nfixed = {fixed}\n{REST}");
    let error = |fixed: &str| -> String {
        match Study::parse(&study(fixed), dir.join("s.toml")) {
            Err(e) => e.to_string(),
            Ok(s) => match s.build_model() {
                Err(e) => e.to_string(),
                Ok(_) => panic!("{fixed}: accepted"),
            },
        }
    };
    let cases = [
        ("{ BASE = [7] }", "[model] fixed.BASE: direction 7 is not one of 1..6"),
        ("{ BASE = [1, 1] }", "[model] fixed.BASE: direction 1 is given twice"),
        ("{ BASE = [] }", "[model] fixed.BASE: no direction"),
        ("{}", "[model] fixed: no node set given"),
        ("{ ROOT = [1] }", "[model] fixed.ROOT: no node set (physical group) `ROOT` in"),
    ];
    for (fixed, expected) in cases {
        let e = error(fixed);
        assert!(e.contains(expected), "{fixed}: {e}");
    }
    // The unknown set's message lists the sets there are.
    assert!(error("{ ROOT = [1] }").contains("\"BASE\""));
    // Matrices have no node sets.
    let on_matrices = "[model]\ndofs = [\"a\"]\nmass = [1.0]\nstiffness = [1.0]\nfixed = { BASE = [1] }\n";
    let e = Study::parse(&format!("{on_matrices}{}", &REST[REST.find("[excitation]").unwrap()..]), dir.join("m.toml"))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(e.contains("`fixed` goes with a `mesh`"), "{e}");
}
