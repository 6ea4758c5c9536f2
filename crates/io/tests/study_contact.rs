//! Contact joints in study files (`law = "contact2d"` / `"contact3d"`): directions from DOF
//! pairs, parameters, and an error naming the key and what is expected for each bad input.

use stickslip_io::study::Study;

/// Two bodies of three DOFs each (a and b, x y z), a 3-D contact between them and a 2-D
/// contact of b against the ground.
const GOOD: &str = r#"[model]
dofs = ["ax", "ay", "az", "bx", "by", "bz"]
mass = [[1.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 2.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 2.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 2.0]]
stiffness = [[1.0e6, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 1.0e6, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0e6, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0e6, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 1.0e6, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 1.0e6]]

[damping]
alpha = 2.0

[[load]]
name = "push"
dof = "ax"

[[joint]]
name = "pad"
law = "contact3d"
tangential = [["ax", "bx"], ["ay", "by"]]
normal = ["bz", "az"]
preload = 300.0
normal_stiffness = 2.0e6
tangential_stiffness = 1.0e6
friction = 0.3

[[joint]]
name = "foot"
law = "contact2d"
tangential = [["bx"]]
normal = ["bz"]
preload = 100.0
normal_stiffness = 5.0e5
tangential_stiffness = 4.0e5
friction = 0.5

[excitation]
levels = [1.0]

[sweep]
start_hz = 100.0
end_hz = 200.0
"#;

fn broken(from: &str, to: &str) -> String {
    assert_eq!(GOOD.matches(from).count(), 1, "{from:?} must occur once in GOOD");
    GOOD.replace(from, to)
}

fn parse_error(text: &str) -> String {
    Study::parse(text, "study.toml").expect_err("the study must be rejected").to_string()
}

#[test]
fn contacts_build_with_their_directions_tangential_first() {
    let (model, _, _) = Study::parse(GOOD, "study.toml").unwrap().build_model().unwrap();
    let (pad, foot) = (&model.elements[0], &model.elements[1]);
    assert_eq!(pad.law.kind(), "contact3d");
    assert_eq!(pad.law.n_dirs(), 3);
    // Pairs are U_a − U_b, unnormalised; a single name is that DOF against the ground.
    assert_eq!(pad.directions[0], vec![1.0, 0.0, 0.0, -1.0, 0.0, 0.0]);
    assert_eq!(pad.directions[1], vec![0.0, 1.0, 0.0, 0.0, -1.0, 0.0]);
    assert_eq!(pad.directions[2], vec![0.0, 0.0, -1.0, 0.0, 0.0, 1.0]);
    assert_eq!(foot.law.kind(), "contact2d");
    assert_eq!(foot.directions, vec![vec![0.0, 0.0, 0.0, 1.0, 0.0, 0.0], vec![0.0, 0.0, 0.0, 0.0, 0.0, 1.0]]);
    // Parameters reach the law: at rest the 3-D contact sticks with the spring k_t and k_n, and
    // opens (restoring force −N0) when pulled apart by more than N0/k_n = 1.5e-4 m.
    let (mut g, mut w) = ([0.0; 3], [0.0; 2]);
    pad.law.update(&[1e-5, 0.0, -2e-4], &[0.0; 3], &mut w, &mut g, None);
    assert_eq!(g, [0.0, 0.0, -300.0]);
    pad.law.update(&[1e-5, 0.0, 1e-5], &[0.0; 3], &mut w, &mut g, None);
    assert!((g[0] - 0.0).abs() < 1e-9 && (g[2] - 20.0).abs() < 1e-9, "{g:?}");
}

#[test]
fn bad_contact_inputs_name_the_key_and_what_is_expected() {
    let cases = [
        (broken("normal_stiffness = 2.0e6", "normal_stiffness = 0.0"), "normal_stiffness must be > 0 N/m, got 0"),
        (
            broken("normal_stiffness = 5.0e5", "normal_stiffness = -5.0e5"),
            "normal_stiffness must be > 0 N/m, got -500000",
        ),
        (
            broken("friction = 0.3", "friction = 12.0"),
            "friction must lie in [0, 10] (a coefficient, not a force), got 12",
        ),
        (broken("friction = 0.5", "friction = -0.1"), "friction must lie in [0, 10]"),
        (
            broken("preload = 300.0", "preload = -50.0"),
            "preload must be > 0 N, got -50: the contact would be open at rest",
        ),
        (broken("preload = 100.0", "preload = 0.0"), "the contact would be open at rest"),
        (
            broken("tangential = [[\"bx\"]]", "tangential = [[\"bx\"], [\"by\"]]"),
            "law \"contact2d\" needs 1 tangential direction(s), got 2",
        ),
        (
            broken("tangential = [[\"ax\", \"bx\"], [\"ay\", \"by\"]]", "tangential = [[\"ax\", \"bx\"]]"),
            "law \"contact3d\" needs 2 tangential direction(s), got 1",
        ),
        (
            broken("normal = [\"bz\", \"az\"]", "normal = [\"bz\", \"bz\"]"),
            "each direction of `normal` is [\"a\", \"b\"]",
        ),
        (broken("normal = [\"bz\"]\n", ""), "law \"contact2d\" needs `normal`"),
        (broken("friction = 0.5\n", ""), "law \"contact2d\" needs `friction`"),
        (
            broken("normal = [\"bz\"]", "normal = [\"bz\"]\nthreshold = 3.0"),
            "`threshold` is not a parameter of law \"contact2d\"",
        ),
        (broken("tangential = [[\"bx\"]]", "between = [\"ax\", \"bx\"]"), "a contact is placed by `tangential"),
    ];
    for (text, expected) in cases {
        let msg = parse_error(&text);
        assert!(msg.contains(expected), "expected {expected:?} in: {msg}");
        assert!(msg.contains("[[joint]]"), "the joint is not named: {msg}");
    }
    // An unknown DOF is found when the model is built, and named.
    let study = Study::parse(&broken("normal = [\"bz\"]", "normal = [\"cz\"]"), "study.toml").unwrap();
    let msg = study.build_model().expect_err("unknown DOF").to_string();
    assert!(msg.contains("cz"), "{msg}");
}
