//! Contact patches in study files (`[[patch]]`): node-to-node contacts between two node sets of a
//! mesh, preloaded by a pressure or by a static pre-step, kept by the reduction; the condensed
//! harmonic balance against the full one with a patch of 20 contact nodes; errors naming the
//! file, the key, the sets and the nodes.

#[path = "../../core/tests/hbm_support/mod.rs"]
mod hbm_support;

use std::path::PathBuf;

use stickslip_core::hbm::{CondensedHbm, HbmSettings};
use stickslip_core::model::relative_direction;
use stickslip_core::post::{evaluate_point, OutputSelector};
use stickslip_fe::element::SolidKind;
use stickslip_fe::mesh::lap_joint::LapJoint;
use stickslip_fe::mesh::Material;
use stickslip_io::study::Study;

/// The lap joint of steel plates 0.2 × 0.03 × 0.005 m, hex8, overlap 4 × 3 cells
/// (0.08 × 0.03 m): 20 contact nodes per side.
fn lap_joint_mesh(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("stickslip-io-patch-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let design = LapJoint {
        length: 0.2,
        width: 0.03,
        thickness: 0.005,
        cells_along: 10,
        overlap_cells: 4,
        cells_across: 3,
        cells_through: 1,
        kind: SolidKind::Hex8,
    };
    let mesh = design.build(Material { young: 2.1e11, poisson: 0.3, density: 7800.0 }).unwrap();
    stickslip_fe::mesh::inp_writer::write(&mesh, dir.join("lap.inp")).unwrap();
    dir
}

const OVERLAP_AREA: f64 = 0.08 * 0.03;

fn study_text(preload: &str, reduction: bool) -> String {
    study_with_law(preload, reduction, "contact3d")
}

/// `law` is "contact3d", or "contact2d" sliding along x (the plates' length).
fn study_with_law(preload: &str, reduction: bool, law: &str) -> String {
    let law = if law == "contact2d" { "\"contact2d\"\ntangential = [1.0, 0.0, 0.0]" } else { "\"contact3d\"" };
    let reduction = if reduction { "[reduction]\nmethod = \"cb\"\nretain = [\"TIP\"]\nmodes = 4\n" } else { "" };
    format!(
        r#"[model]
mesh = "lap.inp"
fixed = {{ CLAMP = [1, 2, 3] }}

{reduction}
[damping]
alpha = 20.0

[[load]]
name = "shaker"
dof = "{tip}.3"

[[patch]]
name = "lap"
between = ["A_CONTACT", "B_CONTACT"]
law = {law}
friction = 0.3
normal_stiffness_per_area = 1.0e12
tangential_stiffness_per_area = 5.0e11
{preload}

[excitation]
levels = [1.0]

[sweep]
start_hz = 50.0
end_hz = 150.0

[[output]]
name = "tip"
dof = "{tip}.3"
"#,
        tip = TIP_NODE
    )
}

/// Id of the TIP node of the mesh above: plate B's free end, (0.32, 0, 0.01) m.
const TIP_NODE: u64 = 131;

const PRESSURE: &str = "pressure = 2.0e6";
const BOLT: &str = r#"preload_forces = [{ set = "BOLT_TOP", force = [0.0, 0.0, -3000.0] }, { set = "BOLT_BOTTOM", force = [0.0, 0.0, 3000.0] }]"#;

const BOLT_APART: &str = r#"preload_forces = [{ set = "BOLT_TOP", force = [0.0, 0.0, 3000.0] }, { set = "BOLT_BOTTOM", force = [0.0, 0.0, -3000.0] }]"#;

fn load(dir: &std::path::Path, text: &str) -> Result<Study, String> {
    let path = dir.join("study.toml");
    std::fs::write(&path, text).unwrap();
    Study::load(&path).map_err(|e| e.to_string())
}

fn build_error(dir: &std::path::Path, text: &str) -> String {
    let study = load(dir, text).unwrap();
    match study.build_model() {
        Ok(_) => panic!("the study must be refused"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn tip_node_is_the_free_end_of_the_upper_plate() {
    let dir = lap_joint_mesh("tip");
    let mesh = stickslip_fe::mesh::inp::read(dir.join("lap.inp")).unwrap();
    let tip = mesh.node_set("TIP").unwrap()[0];
    assert_eq!(mesh.nodes[tip].id, TIP_NODE);
}

#[test]
fn a_pressure_patch_gives_one_contact_per_pair_scaled_by_its_area() {
    let dir = lap_joint_mesh("pressure");
    let study = load(&dir, &study_text(PRESSURE, false)).unwrap();
    let (model, _, _) = study.build_model().unwrap();
    assert_eq!(model.elements.len(), 20);
    let mut preload = 0.0;
    for e in &model.elements {
        assert!(e.name.starts_with("lap-"), "{}", e.name);
        assert_eq!(e.law.kind(), "contact3d");
        assert_eq!(e.directions.len(), 3);
        // The normal direction is (U_a − U_b)·z: +1 on the A node's z DOF, −1 on B's.
        let normal = &e.directions[2];
        let nonzero: Vec<f64> = normal.iter().copied().filter(|x| x.abs() > 1e-15).collect();
        assert_eq!(nonzero.len(), 2, "{}: {nonzero:?}", e.name);
        assert!((nonzero.iter().sum::<f64>()).abs() < 1e-15);
        preload += contact_preload(e.law.as_ref());
    }
    // Each pair carries p × its area: the total is p × the overlap.
    let exact = 2.0e6 * OVERLAP_AREA;
    assert!((preload - exact).abs() < 1e-9 * exact, "total preload {preload} N vs {exact} N");
}

/// The preload N0 of a contact law (2-D or 3-D) that replaces its stiffnesses: wide open
/// (u_n = −h), its restoring normal force is g_n = 0 − N0 − k_n u_n = −N0 + k_n h, so
/// N0 = g_n(−2h) − 2 g_n(−h). Round-off: k_n h (≤ 2e5 N) × 1e-16.
fn contact_preload(law: &dyn stickslip_core::elements::Element) -> f64 {
    let d = law.n_dirs();
    let g_open = |h: f64| {
        let (mut u, mut g, mut w) = ([0.0; 3], [0.0; 3], [0.0; 2]);
        u[d - 1] = -h;
        law.update(&u[..d], &[0.0; 3][..d], &mut w[..d - 1], &mut g[..d], None);
        g[d - 1]
    };
    g_open(2e-3) - 2.0 * g_open(1e-3)
}

#[test]
fn a_bolt_preload_from_the_static_pre_step_balances_the_bolt() {
    // Plate B is held by the contacts alone: their normal forces at rest sum to the bolt's
    // 3 kN; each is positive (all pressed).
    let dir = lap_joint_mesh("bolt");
    let study = load(&dir, &study_text(BOLT, true)).unwrap();
    let (model, _, _) = study.build_model().unwrap();
    let forces: Vec<f64> = model.elements.iter().map(|e| contact_preload(e.law.as_ref())).collect();
    let total: f64 = forces.iter().sum();
    println!("pair preloads {forces:.1?}");
    assert!((total - 3000.0).abs() < 1e-8 * 3000.0, "sum of preloads {total} N");
    assert!(forces.iter().all(|f| *f > 0.0));
    // The reduction keeps the 40 patch nodes' 120 DOFs and TIP's 3 as physical DOFs.
    let physical = model.linear.dofs.iter().filter(|d| d.node.is_some()).count();
    assert_eq!(physical, 123, "{:?}", &model.linear.dofs[..5]);

    // A bolt pulling the plates apart opens every pair: refused, naming the file, the patch
    // and the pairs.
    let message = build_error(&dir, &study_text(BOLT_APART, false));
    println!("{message}");
    assert!(message.contains("study.toml:") && message.contains("[[patch]] \"lap\""), "{message}");
    assert!(message.contains("20 pair(s) are not pressed together at rest"), "{message}");
}

#[test]
fn condensed_balance_equals_the_full_balance_with_a_20_node_patch() {
    let dir = lap_joint_mesh("condensed");
    // contact2d sliding along the plates: the slider of a 1-D path repeats its state after one
    // period, where a 2-D tangential path converges to its periodic regime geometrically.
    let study = load(&dir, &study_with_law(PRESSURE, true, "contact2d")).unwrap();
    let (model, excitation, _) = study.build_model().unwrap();
    let n = model.linear.n_dofs();
    // The first bending mode of the joint stuck and closed: K holds the contacts' stiffnesses.
    let stuck = model.linear.clone();
    let omega1 = stuck.dense_modes().unwrap().omega[0];
    println!("first stuck mode: {:.2} Hz", omega1 / hbm_support::TWO_PI);

    let settings = HbmSettings { harmonics: 3, samples: 64 };
    let omega = 0.9 * omega1;
    // 30 N at the tip: 11 of the 20 contacts slip over part of the cycle (microslip from the
    // overlap's ends inwards), the others stick.
    let level = 30.0;
    let mut cond = CondensedHbm::new(&model, &excitation.pattern, settings).unwrap();
    let x0 = cond.linear_solution(omega, level);
    let (xq, _) = cond.solve(omega, level, &x0, 1e-13, 80).unwrap();
    let outputs: Vec<OutputSelector> =
        (0..n).map(|i| OutputSelector { name: format!("q{i}"), vector: relative_direction(n, i, None) }).collect();
    let p = evaluate_point(&mut cond, &xq, omega, level, &outputs).unwrap();
    let slipping = p.elements.iter().filter(|e| e.stick_fraction < 0.99 && e.energy_per_cycle > 0.0).count();
    let stick: Vec<f64> = p.elements.iter().map(|e| e.stick_fraction).collect();
    println!("{slipping} of 20 contacts slip; stick fractions {stick:.2?}");
    assert!(slipping >= 8, "only {slipping} contacts slip: the test would check linear algebra");
    let nc = 2 * settings.harmonics + 1;
    let recovered: Vec<f64> = (0..nc * n).map(|idx| p.outputs[idx % n].coeffs[idx / n]).collect();
    // Both solve the same equations. The stiff contacts (k_n A up to 2e8 N/m against the
    // plates' bending) condition the full balance: measured 1.0e-9 to 2.2e-9 from run to run
    // (the reduction's modes differ in the last bits); bound 1e-8.
    let err = hbm_support::full_balance_distance(&model, &excitation.pattern, settings, omega, level, &recovered, 40);
    println!("condensed vs full, 20-node patch: {err:.2e}");
    assert!(err < 1e-8, "condensed vs full: {err:.2e}");
}

#[test]
fn bad_patches_are_refused_naming_the_key_the_sets_and_the_nodes() {
    let dir = lap_joint_mesh("errors");
    let good = study_text(PRESSURE, false);
    let parse = |from: &str, to: &str| {
        assert_eq!(good.matches(from).count(), 1, "{from:?} must occur once");
        load(&dir, &good.replace(from, to)).expect_err("the study must be refused")
    };
    for (from, to, expected) in [
        (
            "normal_stiffness_per_area = 1.0e12",
            "normal_stiffness_per_area = 0.0",
            "normal_stiffness_per_area must be > 0 N/m^3, got 0",
        ),
        (
            "normal_stiffness_per_area = 1.0e12",
            "normal_stiffness_per_area = -1.0e12",
            "normal_stiffness_per_area must be > 0 N/m^3",
        ),
        ("tangential_stiffness_per_area = 5.0e11", "", "needs `tangential_stiffness_per_area` (N/m^3)"),
        ("friction = 0.3", "friction = 12.0", "friction must lie in [0, 10]"),
        ("friction = 0.3", "friction = -0.1", "friction must lie in [0, 10]"),
        ("pressure = 2.0e6", "pressure = -1.0", "pressure must be > 0 Pa, got -1: the contact would be open at rest"),
        ("pressure = 2.0e6", "", "give the load at rest as exactly one of `pressure`"),
        ("pressure = 2.0e6", &format!("pressure = 2.0e6\n{BOLT}"), "exactly one of `pressure`"),
        ("law = \"contact3d\"", "law = \"contact2d\"", "law \"contact2d\" needs `tangential = [x, y, z]`"),
        ("law = \"contact3d\"", "law = \"jenkins\"", "law must be \"contact2d\" or \"contact3d\", got \"jenkins\""),
        (
            "between = [\"A_CONTACT\", \"B_CONTACT\"]",
            "between = [\"A_CONTACT\"]",
            "between must name two different node sets",
        ),
        (
            "pressure = 2.0e6",
            "pressure = 2.0e6\nnormal = [0.0, 0.0, 0.0]",
            "normal must be a direction [x, y, z], not zero",
        ),
        ("pressure = 2.0e6", "pressure = 2.0e6\nstiffness = 3.0", "unknown field `stiffness`"),
    ] {
        let message = parse(from, to).to_string();
        println!("{message}");
        assert!(message.starts_with(&dir.join("study.toml").display().to_string()), "{message}");
        assert!(message.contains("[[patch]]"), "{message}");
        assert!(message.contains(expected), "{to:?}: expected {expected:?} in {message}");
    }

    // Errors found on the mesh: sets that do not pair up (naming the nodes), an unknown set,
    // a bolt on an unknown set, a normal pointing into A.
    let mesh = stickslip_fe::mesh::inp::read(dir.join("lap.inp")).unwrap();
    for (from, to, expected) in [
        (
            "[\"A_CONTACT\", \"B_CONTACT\"]",
            "[\"A_CONTACT\", \"BOLT_TOP\"]",
            "do not pair up: 20 node(s) of \"A_CONTACT\"".to_string(),
        ),
        ("[\"A_CONTACT\", \"B_CONTACT\"]", "[\"A_CONTACT\", \"NOPE\"]", "no node set \"NOPE\" in the mesh".to_string()),
        (
            "pressure = 2.0e6",
            "pressure = 2.0e6\nnormal = [0.0, 0.0, -1.0]",
            "points into the body of \"A_CONTACT\"".to_string(),
        ),
        (
            "pressure = 2.0e6",
            "preload_forces = [{ set = \"BOLTS\", force = [0.0, 0.0, -1.0] }]",
            "preload_forces: no node set \"BOLTS\" in the mesh".to_string(),
        ),
    ] {
        let message = build_error(&dir, &good.replace(from, to));
        println!("{message}");
        assert!(message.contains("study.toml:") && message.contains("[[patch]] \"lap\""), "{message}");
        assert!(message.contains(&expected), "{to:?}: expected {expected:?} in {message}");
    }
    let unpaired = build_error(&dir, &good.replace("[\"A_CONTACT\", \"B_CONTACT\"]", "[\"A_CONTACT\", \"BOLT_TOP\"]"));
    let first = mesh.node_set("A_CONTACT").unwrap().iter().map(|&n| mesh.nodes[n].id).min().unwrap();
    assert!(unpaired.contains(&format!("nodes {first}, ")) && unpaired.contains("(20 in all)"), "{unpaired}");

    // A patch on a model given by matrices.
    let matrices = "[model]\ndofs = [\"a\"]\nmass = [1.0]\nstiffness = [1.0]\n\n[[load]]\nname = \"f\"\ndof = \"a\"\n\n[[patch]]\nname = \"p\"\nbetween = [\"A\", \"B\"]\nlaw = \"contact3d\"\nfriction = 0.3\nnormal_stiffness_per_area = 1.0\ntangential_stiffness_per_area = 1.0\npressure = 1.0\n\n[excitation]\nlevels = [1.0]\n\n[sweep]\nstart_hz = 1.0\nend_hz = 2.0\n";
    let message = load(&dir, matrices).unwrap_err();
    assert!(message.contains("the [model] must be a `mesh` or `harmony`"), "{message}");
}

#[test]
fn the_lap_joint_example_builds_its_patch_and_its_jenkins_simplification() {
    let examples = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/lap-joint");
    let (model, _, _) = Study::load(examples.join("study.toml")).unwrap().build_model().unwrap();
    assert_eq!(model.elements.len(), 29);
    assert!(model.elements.iter().all(|e| e.law.kind() == "contact2d"));
    // The bolt's 2 kN is carried by the pairs at rest.
    let preloads: Vec<f64> = model.elements.iter().map(|e| contact_preload(e.law.as_ref())).collect();
    let total: f64 = preloads.iter().sum();
    let (least, most) = preloads.iter().fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
    println!("lap joint example: preloads from {least:.1} to {most:.1} N, {total:.6} N in all");
    assert!((total - 2000.0).abs() < 1e-8 * 2000.0, "sum of preloads {total} N");
    let (jenkins, _, _) = Study::load(examples.join("study-jenkins.toml")).unwrap().build_model().unwrap();
    assert_eq!(jenkins.elements.len(), 1);
    assert_eq!(jenkins.elements[0].law.kind(), "jenkins");
}
