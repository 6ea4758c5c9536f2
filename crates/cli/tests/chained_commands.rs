//! Commands that chain: each consumes the previous one's files as written.
mod common;
use common::{repo, scratch, stickslip};

/// CSV columns by name.
fn columns(path: &std::path::Path) -> std::collections::HashMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let names: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    for l in lines {
        for (c, v) in cols.iter_mut().zip(l.split(',')) {
            c.push(v.parse().unwrap());
        }
    }
    names.into_iter().zip(cols).collect()
}

#[test]
fn reduce_then_run_on_the_reduced_matrices_gives_the_study_with_its_own_reduction() {
    // The blade example reduces its mesh inside the study ([reduction]); here `reduce` writes
    // M.mtx, K.mtx and dofs.csv, and a study reads them as they are (dofs.csv as its
    // dof_file). The same reduction, the same joints: the same FRF, to the round trip of the
    // matrix files (shortest round-trip decimals: exact) and the solver's tolerance.
    let dir = scratch("chain");
    std::fs::create_dir_all(&dir).unwrap();
    let example = repo().join("examples/blade-joint");
    let status = stickslip()
        .args(["reduce", "--retain", "TOP_BLADE,MID", "--modes", "8", "--method", "free", "--out"])
        .arg(dir.join("reduced"))
        .arg(example.join("blade.inp"))
        .status()
        .unwrap();
    assert!(status.success());
    let original = std::fs::read_to_string(example.join("study.toml")).unwrap();
    // The same study on the matrix files, without its [reduction] section.
    let mut chained = Vec::new();
    let mut in_reduction = false;
    for line in original.lines() {
        if line.starts_with('[') {
            in_reduction = line == "[reduction]";
        }
        match line {
            _ if in_reduction => {}
            "mesh = \"blade.inp\"" => chained.extend([
                "mass_file = \"reduced/M.mtx\"",
                "stiffness_file = \"reduced/K.mtx\"",
                "dof_file = \"reduced/dofs.csv\"",
            ]),
            "time_data = 20" => chained.push("time_data = \"none\""),
            _ => chained.push(line),
        }
    }
    let chained = chained.join("\n");
    assert!(!chained.contains("[reduction]") && chained.contains("dof_file"));
    std::fs::write(dir.join("chained.toml"), &chained).unwrap();
    std::fs::write(dir.join("original.toml"), original.replace("time_data = 20", "time_data = \"none\"")).unwrap();
    std::fs::copy(example.join("blade.inp"), dir.join("blade.inp")).unwrap();
    for name in ["original", "chained"] {
        let status = stickslip()
            .args(["run", "--quiet", "--no-report", "--no-plots", "--out"])
            .arg(dir.join(name))
            .arg(dir.join(format!("{name}.toml")))
            .status()
            .unwrap();
        assert!(status.success(), "{name}");
    }
    let (a, b) = (columns(&dir.join("original/frf.csv")), columns(&dir.join("chained/frf.csv")));
    assert_eq!(a["frequency_Hz"].len(), b["frequency_Hz"].len());
    for col in ["frequency_Hz", "tip_disp_frf_m_per_N", "mid_disp_frf_m_per_N", "contact_energy_J"] {
        for (x, y) in a[col].iter().zip(&b[col]) {
            assert!((x - y).abs() <= 1e-9 * x.abs().max(1e-300), "{col}: {x:e} vs {y:e}");
        }
    }
}
