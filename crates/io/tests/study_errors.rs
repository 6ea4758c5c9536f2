//! Bad study files give an error naming the file, the line and column, the key and what is
//! expected; never a panic, never a silently wrong model.

use stickslip_io::study::Study;

/// A valid 2-DOF study; each test breaks one line of it.
const GOOD: &str = r#"[model]
dofs = ["a", "b"]
mass = [[2.0, 0.0], [0.0, 1.0]]
stiffness = [[3.0e4, -1.0e4], [-1.0e4, 1.0e4]]

[damping]
alpha = 2.0

[[load]]
name = "push"
dof = "a"

[[joint]]
name = "j1"
law = "jenkins"
between = ["a", "b"]
stiffness = 1.0e4
replaces_stiffness = true
threshold = 5.0

[excitation]
levels = [1.0, 2.0]

[sweep]
start_hz = 10.0
end_hz = 30.0
"#;

/// `GOOD` with `from` replaced by `to` (which must occur once).
fn broken(from: &str, to: &str) -> String {
    assert_eq!(GOOD.matches(from).count(), 1, "{from:?} must occur once in GOOD");
    GOOD.replace(from, to)
}

fn parse_error(text: &str) -> String {
    Study::parse(text, "study.toml").expect_err("the study must be rejected").to_string()
}

fn build_error(text: &str) -> String {
    let study = Study::parse(text, "study.toml").expect("the study parses");
    study.build_model().expect_err("the model must be rejected").to_string()
}

#[test]
fn the_good_study_builds() {
    let (model, excitation, outputs) = Study::parse(GOOD, "study.toml").unwrap().build_model().unwrap();
    assert_eq!(model.elements.len(), 1);
    // `between` acts on the relative displacement U_a − U_b.
    assert_eq!(model.elements[0].directions, vec![vec![1.0, -1.0]]);
    assert_eq!(excitation.levels_n, vec![1.0, 2.0]);
    // No [[output]]: every DOF of a small model is reported.
    assert_eq!(outputs.len(), 2);
}

#[test]
fn malformed_toml_names_line_and_column() {
    let msg = parse_error(&broken("[damping]", "[damping"));
    assert!(msg.starts_with("study.toml:6:9: "), "{msg}");
}

#[test]
fn unknown_key_lists_the_valid_keys() {
    let msg = parse_error(&broken("threshold = 5.0", "threshhold = 5.0"));
    assert!(msg.starts_with("study.toml:19:1: [[joint]]: unknown field"), "{msg}");
    assert!(msg.contains("unknown field `threshhold`") && msg.contains("`threshold`"), "{msg}");
}

#[test]
fn wrong_type_says_what_is_expected() {
    let msg = parse_error(&broken("levels = [1.0, 2.0]", "levels = \"high\""));
    assert!(msg.starts_with("study.toml:22:10: ") && msg.contains("expected a sequence"), "{msg}");
}

#[test]
fn missing_section_is_named() {
    let msg = parse_error(&GOOD.replace("[sweep]\nstart_hz = 10.0\nend_hz = 30.0\n", ""));
    assert!(msg.contains("missing field `sweep`"), "{msg}");
}

#[test]
fn wrong_matrix_size_is_rejected() {
    let msg = parse_error(&broken("[-1.0e4, 1.0e4]]", "[-1.0e4, 1.0e4, 0.0]]"));
    assert_eq!(msg, "study.toml:4:13: [model]: stiffness row 2 has 3 values, expected 2 (one per DOF)");
    let msg = parse_error(&broken("mass = [[2.0, 0.0], [0.0, 1.0]]", "mass = [2.0]"));
    assert_eq!(msg, "study.toml:3:8: [model]: mass has 1 diagonal values, expected 2 (one per DOF)");
}

#[test]
fn non_symmetric_stiffness_is_rejected() {
    let msg = build_error(&broken("[-1.0e4, 1.0e4]]", "[-1.1e4, 1.0e4]]"));
    assert!(msg.starts_with("study.toml:4:13: [model]: K (stiffness) is not symmetric"), "{msg}");
}

#[test]
fn indefinite_mass_is_rejected() {
    // Eigenvalues 3 and -1: symmetric, not positive definite.
    let msg = build_error(&broken("mass = [[2.0, 0.0], [0.0, 1.0]]", "mass = [[1.0, 2.0], [2.0, 1.0]]"));
    assert!(msg.starts_with("study.toml:3:8: [model]: the mass matrix is not positive definite"), "{msg}");
}

#[test]
fn negative_threshold_is_rejected() {
    let msg = parse_error(&broken("threshold = 5.0", "threshold = -3"));
    assert_eq!(msg, "study.toml:19:13: [[joint]] \"j1\": threshold must be > 0 N, got -3");
}

#[test]
fn empty_band_is_rejected() {
    let msg = parse_error(&broken("end_hz = 30.0", "end_hz = 10.0"));
    assert!(msg.starts_with("study.toml:26:10: [sweep]: empty band"), "{msg}");
}

#[test]
fn unknown_dof_names_the_known_ones() {
    let msg = build_error(&broken("between = [\"a\", \"b\"]", "between = [\"a\", \"c\"]"));
    assert_eq!(msg, "study.toml:16:11: [[joint]] \"j1\": no DOF named \"c\" in the model (DOFs are: a, b)");
}

#[test]
fn parameter_of_another_law_is_rejected() {
    let msg = parse_error(&broken("threshold = 5.0", "threshold = 5.0\nk3 = 1.0"));
    assert!(msg.starts_with("study.toml:20:6: [[joint]] \"j1\": `k3` is not a parameter of law \"jenkins\""), "{msg}");
}

#[test]
fn too_few_samples_for_the_harmonics() {
    let msg = parse_error(&format!("{GOOD}\n[harmonic_balance]\nharmonics = 7\nsamples = 14\n"));
    assert!(msg.contains("samples must be >= 2 harmonics + 1 = 15"), "{msg}");
}

#[test]
fn missing_matrix_file_names_the_file() {
    let text = GOOD
        .replace("mass = [[2.0, 0.0], [0.0, 1.0]]", "mass_file = \"no-such-mass.mtx\"")
        .replace("stiffness = [[3.0e4, -1.0e4], [-1.0e4, 1.0e4]]", "stiffness_file = \"k.mtx\"");
    let msg = build_error(&text);
    assert!(msg.contains("[model] mass_file") && msg.contains("no-such-mass.mtx"), "{msg}");
}

#[test]
fn replacing_more_stiffness_than_the_model_has_is_rejected() {
    // Without `stiffness`, the joint replaces all of the stiffness along e_a − e_b (Eq. 7),
    // including part of a's spring to the ground, which leaves K − k V Vᵀ indefinite.
    let msg = build_error(&broken("stiffness = 1.0e4\nreplaces_stiffness = true\n", ""));
    assert!(
        msg.starts_with("study.toml:16:11: [[joint]] \"j1\": with the joints \"j1\" (1.5e4 N/m) slipping"),
        "{msg}"
    );
    assert!(msg.contains("negative eigenvalue"), "{msg}");
}

#[test]
fn paper_form_stiffness_along_a_relative_direction() {
    // Two DOFs, each with 2e4 N/m to the ground, 1e4 N/m between them. Moving them apart by u
    // symmetrically (U = ±u/2, the unit direction of Eq. 7 scaled) stores
    // ½ (2·2e4·(u/2)² + 1e4·u²) = ½ (2e4) u²: the joint replaces k = 2e4 N/m on u = U_a − U_b.
    let text =
        broken("stiffness = [[3.0e4, -1.0e4], [-1.0e4, 1.0e4]]", "stiffness = [[3.0e4, -1.0e4], [-1.0e4, 3.0e4]]")
            .replace("stiffness = 1.0e4\nreplaces_stiffness = true\n", "");
    let (model, _, _) = Study::parse(&text, "study.toml").unwrap().build_model().unwrap();
    let law = &model.elements[0].law;
    let (mut state, mut g) = (vec![0.0; law.n_state()], [0.0]);
    // Gross slip: g = F_c − k u, exact in binary for these values.
    law.update(&[1.0], &[0.0], &mut state, &mut g, None);
    assert_eq!(g[0], 5.0 - 2.0e4);
}

#[test]
fn a_vector_of_the_wrong_length_is_rejected() {
    let msg = build_error(&broken("between = [\"a\", \"b\"]", "vector = [1.0, 0.0, 0.0]"));
    assert_eq!(msg, "study.toml:16:10: [[joint]] \"j1\": vector has 3 values, expected 2 (one per DOF of the model)");
}

#[test]
fn names_must_suit_column_names() {
    let msg = parse_error(&broken("name = \"j1\"", "name = \"j 1,x\""));
    assert!(
        msg.starts_with("study.toml:14:8: [[joint]]: name \"j 1,x\" must be non-empty and use only ASCII"),
        "{msg}"
    );
}

#[test]
fn several_loads_need_the_excitation_to_name_one() {
    let text = broken("[excitation]", "[[load]]\nname = \"pull\"\ndof = \"b\"\n\n[excitation]");
    let msg = parse_error(&text);
    assert!(msg.contains("[excitation]: say which [[load]] excites the structure"), "{msg}");
    let msg = parse_error(&text.replace("levels = [1.0, 2.0]", "load = \"shove\"\nlevels = [1.0, 2.0]"));
    assert!(msg.contains("no [[load]] named \"shove\" (loads are: push, pull)"), "{msg}");
}

#[test]
fn harmonic_balance_sizes_are_bounded() {
    // A mistyped size would otherwise allocate the AFT's arrays until the memory runs out.
    let hbm = |key: &str| GOOD.to_string() + &format!("\n[harmonic_balance]\n{key}\n");
    let msg = parse_error(&hbm("samples = 100000000"));
    assert!(msg.contains("[harmonic_balance]: samples must be at most 16384, got 100000000"), "{msg}");
    assert!(msg.starts_with("study.toml:29:11: "), "{msg}");
    let msg = parse_error(&hbm("harmonics = 5000"));
    assert!(msg.contains("harmonics must be at most 100, got 5000"), "{msg}");
    let msg = parse_error(&hbm("max_iterations = 1000000000"));
    assert!(msg.contains("max_iterations must be at most 10000"), "{msg}");
    // The largest accepted sizes parse.
    assert!(Study::parse(&hbm("harmonics = 100\nsamples = 16384"), "study.toml").is_ok());
}

#[test]
fn a_snapshot_needs_a_positive_frequency_and_level() {
    let msg = parse_error(&format!("{GOOD}\n[[snapshot]]\nfrequency_hz = -238.0\nlevel = 3420.0\n"));
    assert!(msg.starts_with("study.toml:29:16: [[snapshot]]: frequency_hz must be > 0 Hz"), "{msg}");
    assert!(msg.contains("-238"), "{msg}");
    let msg = parse_error(&format!("{GOOD}\n[[snapshot]]\nfrequency_hz = 238.0\n"));
    // The error points at the section's header line.
    assert_eq!(msg, "study.toml:28:1: missing field `level`");
    let study = Study::parse(&format!("{GOOD}\n[[snapshot]]\nfrequency_hz = 238.0\nlevel = 3420.0\n"), "study.toml");
    let snapshots = study.unwrap().snapshots;
    assert_eq!((snapshots.len(), snapshots[0].frequency_hz, snapshots[0].level), (1, 238.0, 3420.0));
}

#[test]
fn stability_is_accepted_with_a_damping_matrix_as_with_proportional_damping() {
    // Hill's method takes a general damping matrix in modal coordinates (docs/stability.md).
    let text = broken("alpha = 2.0", "matrix = [[2.0, 0.0], [0.0, 1.0]]") + "\n[harmonic_balance]\nstability = true\n";
    assert!(Study::parse(&text, "study.toml").unwrap().hbm.stability);
    let ok = GOOD.to_string() + "\n[harmonic_balance]\nstability = true\n";
    assert!(Study::parse(&ok, "study.toml").unwrap().hbm.stability);
}

/// `GOOD` with its Jenkins joint replaced by a rigid 2-D contact of a (tangential) and b
/// (normal) against the ground, solved by DLFT.
fn dlft() -> String {
    let contact =
        "name = \"pad\"\nlaw = \"contact2d\"\ntangential = [[\"a\"]]\nnormal = [\"b\"]\nfriction = 0.3\npreload = 10.0";
    let jenkins = "name = \"j1\"\nlaw = \"jenkins\"\nbetween = [\"a\", \"b\"]\nstiffness = 1.0e4\nreplaces_stiffness = true\nthreshold = 5.0";
    assert_eq!(GOOD.matches(jenkins).count(), 1);
    GOOD.replace(jenkins, contact) + "\n[harmonic_balance]\ncontact_method = \"dlft\"\n"
}

/// `study.toml:LINE:` of the first line of `text` that contains `needle`.
fn at_line(text: &str, needle: &str) -> String {
    let line = text.lines().position(|l| l.contains(needle)).expect("needle in text") + 1;
    format!("study.toml:{line}:")
}

#[test]
fn a_dlft_study_builds_rigid_contacts_sampled_at_2n_plus_1() {
    let study = Study::parse(&dlft(), "study.toml").unwrap();
    // Collocation by default (7 harmonics, 15 samples): the DLFT solution is then free of ε.
    assert_eq!((study.hbm.harmonics, study.hbm.samples), (7, 15));
    let (model, _, _) = study.build_model().unwrap();
    assert!(model.elements.is_empty());
    let contact = &model.rigid_contacts[0];
    assert_eq!((contact.name.as_str(), contact.friction, contact.preload), ("pad", 0.3, 10.0));
    assert_eq!(contact.directions, vec![vec![1.0, 0.0], vec![0.0, 1.0]]);
    // 2N + 1 written out is accepted.
    let text = dlft().replace("contact_method = \"dlft\"", "contact_method = \"dlft\"\nharmonics = 3\nsamples = 7");
    assert_eq!(Study::parse(&text, "study.toml").unwrap().hbm.samples, 7);
}

#[test]
fn dlft_with_another_law_names_the_joint_the_key_and_what_is_expected() {
    // The Jenkins joint of GOOD next to the rigid contact.
    let jenkins = "[[joint]]\nname = \"j1\"\nlaw = \"jenkins\"\nbetween = [\"a\", \"b\"]\nthreshold = 5.0\n\n";
    let text = dlft().replace("[excitation]", &format!("{jenkins}[excitation]"));
    let msg = parse_error(&text);
    println!("{msg}");
    assert!(msg.starts_with(&at_line(&text, "law = \"jenkins\"")), "{msg}");
    assert!(
        msg.contains("[[joint]] \"j1\": law \"jenkins\" cannot be mixed with rigid contacts")
            && msg.contains("[harmonic_balance] contact_method = \"dlft\"")
            && msg.contains("every [[joint]] must be law = \"contact2d\" or \"contact3d\""),
        "{msg}"
    );
}

#[test]
fn dlft_contact_inputs_name_the_key_and_what_is_expected() {
    let text = dlft();
    let cases = [
        ("preload = 10.0", "preload = 0.0", "[[joint]] \"pad\": preload must be > 0 N, got 0: the contact would be open at rest"),
        ("preload = 10.0", "preload = -5.0", "[[joint]] \"pad\": preload must be > 0 N, got -5"),
        ("friction = 0.3", "friction = 12.0", "[[joint]] \"pad\": friction must lie in [0, 10] (a coefficient, not a force), got 12"),
        ("friction = 0.3", "friction = -0.1", "[[joint]] \"pad\": friction must lie in [0, 10] (a coefficient, not a force), got -0.1"),
        (
            "preload = 10.0",
            "preload = 10.0\nnormal_stiffness = 1.0e9",
            "[[joint]] \"pad\": `normal_stiffness` does not apply with [harmonic_balance] contact_method = \"dlft\": the contact is rigid",
        ),
        (
            "preload = 10.0",
            "preload = 10.0\ntangential_stiffness = 1.0e9",
            "[[joint]] \"pad\": `tangential_stiffness` does not apply with [harmonic_balance] contact_method = \"dlft\"",
        ),
        (
            "contact_method = \"dlft\"",
            "contact_method = \"dlft\"\nsamples = 300",
            "[harmonic_balance]: with contact_method = \"dlft\", samples must be 2 harmonics + 1 = 15 (the default), got 300",
        ),
        (
            "contact_method = \"dlft\"",
            "contact_method = \"dlft\"\nstability = true",
            "[harmonic_balance]: stability = true is not available with contact_method = \"dlft\"",
        ),
        (
            "contact_method = \"dlft\"",
            "contact_method = \"rigid\"",
            "[harmonic_balance]: contact_method must be \"penalty\" (contacts with stiffness, the default) or \"dlft\" (rigid contacts), got \"rigid\"",
        ),
    ];
    for (from, to, expected) in cases {
        assert_eq!(text.matches(from).count(), 1, "{from:?}");
        let bad = text.replace(from, to);
        let msg = parse_error(&bad);
        // The error points at the offending key's line (the last line `to` writes).
        let key = to.lines().last().unwrap();
        assert!(msg.starts_with(&at_line(&bad, key)), "{msg}");
        assert!(msg.contains(expected), "{msg}\nexpected: {expected}");
    }
    // A penalty contact (the default method) still needs its stiffnesses.
    let penalty = text.replace("contact_method = \"dlft\"", "contact_method = \"penalty\"");
    let msg = parse_error(&penalty);
    assert!(msg.contains("[[joint]] \"pad\": law \"contact2d\" needs `normal_stiffness` N/m"), "{msg}");
}

#[test]
fn dlft_without_contacts_or_with_a_nonlinear_mode_is_refused() {
    // GOOD's Jenkins joint alone.
    let text = GOOD.to_string() + "\n[harmonic_balance]\ncontact_method = \"dlft\"\n";
    let msg = parse_error(&text);
    assert!(msg.contains("law \"jenkins\" cannot be mixed with rigid contacts"), "{msg}");
    // A contact patch (its contacts hold its parts through their stiffness).
    let text = r#"[model]
mesh = "plates.inp"

[[load]]
name = "shaker"
dof = "477.3"

[[patch]]
name = "lap"
between = ["A_CONTACT", "B_CONTACT"]
law = "contact3d"
friction = 0.3
normal_stiffness_per_area = 1.0e12
tangential_stiffness_per_area = 5.0e11
pressure = 1.0e6

[excitation]
levels = [1.0]

[sweep]
start_hz = 26.0
end_hz = 38.0

[harmonic_balance]
contact_method = "dlft"
"#;
    let msg = parse_error(text);
    assert!(msg.starts_with(&at_line(text, "[[patch]]")), "{msg}");
    assert!(msg.contains("[[patch]] \"lap\": patches are not solved with rigid contacts"), "{msg}");
    // No joint at all.
    let start = dlft().find("[[joint]]").unwrap();
    let end = dlft().find("[excitation]").unwrap();
    let text = format!("{}{}", &dlft()[..start], &dlft()[end..]);
    let msg = parse_error(&text);
    assert!(msg.starts_with(&at_line(&text, "contact_method")), "{msg}");
    assert!(msg.contains("solves rigid point contacts only, and the study has none"), "{msg}");
    let text = dlft() + "\n[nonlinear_mode]\nmode = 1\namplitude_start = 1e-6\namplitude_end = 1e-3\n";
    let msg = parse_error(&text);
    assert!(msg.contains("[nonlinear_mode]: not available with rigid contacts"), "{msg}");
}
