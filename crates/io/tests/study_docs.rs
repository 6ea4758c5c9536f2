//! docs/study-file.md documents every key the parser accepts: the list of valid keys is taken
//! from the parser itself (its "unknown field" message), so a new key without documentation
//! fails here.

use stickslip_io::study::Study;

const MINIMAL: &str = "[model]\ndofs = [\"a\"]\nmass = [1.0]\nstiffness = [1.0]\n[[load]]\nname = \"p\"\ndof = \"a\"\n\
                       [excitation]\nlevels = [1.0]\n[sweep]\nstart_hz = 1.0\nend_hz = 2.0\n";

/// The keys the parser accepts in `section` (e.g. "[model]", "[[joint]]").
fn valid_keys(section: &str) -> Vec<String> {
    let header = format!("{section}\n");
    let text = if MINIMAL.contains(&header) && !section.starts_with("[[") {
        // A table may appear once: put the unknown key into the existing one.
        MINIMAL.replace(&header, &format!("{header}no_such_key_anywhere = 1\n"))
    } else {
        format!("{MINIMAL}{header}no_such_key_anywhere = 1\n")
    };
    let msg = Study::parse(&text, "study.toml").unwrap_err().to_string();
    let list = msg.split("expected").nth(1).unwrap_or_else(|| panic!("no key list in {msg:?}"));
    // "`a`, `b`, `c`" or "`a` or `b`": the keys are the quoted words.
    list.split('`').skip(1).step_by(2).map(String::from).collect()
}

#[test]
fn every_key_is_documented() {
    let docs = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/study-file.md")).unwrap();
    let sections = [
        "[model]",
        "[model.material]",
        "[model.harmony]",
        "[reduction]",
        "[damping]",
        "[[load]]",
        "[[joint]]",
        "[[patch]]",
        "[excitation]",
        "[sweep]",
        "[harmonic_balance]",
        "[continuation]",
        "[[output]]",
        "[output_options]",
        "[nonlinear_mode]",
    ];
    let mut checked = 0;
    for section in sections {
        assert!(docs.contains(&format!("## `{section}`")), "section {section} is not documented");
        for key in valid_keys(section) {
            assert!(docs.contains(&format!("| `{key}` |")), "{section} {key} is not documented");
            checked += 1;
        }
    }
    // [model.harmony]: 12 keys, [[patch]]: 10; 54 + 10 = 64 keys today: the test must see them all.
    assert!(checked >= 64, "only {checked} keys found");
}
