//! Commands that chain: each consumes the previous one's files as written.
mod common;
use common::{browser, columns, repo, scratch, stickslip};

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
    let chained = on_reduced_matrices(&original);
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

/// The blade study on the files `reduce` writes into `reduced/` (M.mtx, K.mtx, dofs.csv as
/// its dof_file), without its [reduction] section and without time data.
fn on_reduced_matrices(original: &str) -> String {
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
    chained
}

/// `stickslip` run with `args`; its output, when it succeeds.
fn ok<A: AsRef<std::ffi::OsStr>>(args: &[A]) -> std::process::Output {
    let out = stickslip().args(args).output().unwrap();
    let shown: Vec<_> = args.iter().map(|a| a.as_ref().to_string_lossy().into_owned()).collect();
    assert!(out.status.success(), "stickslip {shown:?} failed:\n{}", String::from_utf8_lossy(&out.stderr));
    out
}

/// The `frequency_Hz` of `output`'s row at `level` in a `peaks.csv` written by `run`.
fn located_peak(path: &std::path::Path, output: &str, level: f64) -> f64 {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|c| *c == name).unwrap();
    let (l, o, f) = (col("level_N"), col("output"), col("frequency_Hz"));
    lines
        .map(|line| line.split(',').collect::<Vec<_>>())
        .find(|row| row[o] == output && row[l].parse::<f64>().unwrap() == level)
        .map(|row| row[f].parse().unwrap())
        .unwrap_or_else(|| panic!("{}: no peak of {output} at {level} N", path.display()))
}

#[test]
fn mesh_to_comparison_each_command_reading_the_previous_ones_files() {
    // The blade mesh reduced by `reduce`; `run` on the reduced matrices (the harmonic balance);
    // `timesim` on the same study at five frequencies around the located resonance (the
    // independent check: what a stepped-sine test records); `extract` on those records as
    // written; `compare` of what `extract` wrote against `run`'s frf.csv. No file is edited
    // between the steps.
    let dir = scratch("workflow");
    std::fs::create_dir_all(&dir).unwrap();
    let example = repo().join("examples/blade-joint");
    let path = |p: &str| dir.join(p).into_os_string();
    let s = |x: &str| std::ffi::OsString::from(x);
    let blade = example.join("blade.inp").into_os_string();
    ok(&[s("reduce"), s("--retain"), s("TOP_BLADE,MID"), s("--modes"), s("8"), s("--method"), s("free")]
        .into_iter()
        .chain([s("--out"), path("reduced"), blade])
        .collect::<Vec<_>>());
    // One force level, where the contact slips over the top of the resonance (396-408 Hz) and
    // sticks on its flanks. (At 2 N the third harmonic meets the second mode near 386 Hz, a dip
    // 0.5 Hz wide whose place the two methods' discretisations move apart.)
    let level = 0.5;
    let original = std::fs::read_to_string(example.join("study.toml")).unwrap();
    let study = on_reduced_matrices(&original).replace("levels = [0.5, 2.0, 5.0, 20.0]", "levels = [0.5]");
    assert!(study.contains("levels = [0.5]"));
    std::fs::write(dir.join("study.toml"), &study).unwrap();
    ok(&[s("run"), s("--quiet"), s("--out"), path("run"), path("study.toml")]);
    // The phase plot beside the amplitude plot of each output.
    for plot in ["frf_tip.png", "frf_phase_tip.png", "frf_phase_mid.png"] {
        assert!(dir.join("run").join(plot).exists(), "run wrote no {plot}");
    }
    let peak = located_peak(&dir.join("run/peaks.csv"), "tip", level);
    // Five points of the branch about the resonance, 1.5 % apart: the time integration runs at
    // their very frequencies (written in shortest round-trip form), so that no interpolation
    // between points enters the comparison.
    let run_frf = columns(&dir.join("run/frf.csv"));
    let nearest = |f: f64| {
        (0..run_frf["frequency_Hz"].len())
            .min_by(|&a, &b| (run_frf["frequency_Hz"][a] - f).abs().total_cmp(&(run_frf["frequency_Hz"][b] - f).abs()))
            .unwrap()
    };
    let rows: Vec<usize> = [0.97, 0.985, 1.0, 1.015, 1.03].iter().map(|r| nearest(r * peak)).collect();
    let frequencies: Vec<f64> = rows.iter().map(|&j| run_frf["frequency_Hz"][j]).collect();
    let list: Vec<String> = frequencies.iter().map(|f| f.to_string()).collect();
    ok(&[s("timesim"), s("--frequency"), s(&list.join(",")), s("--out"), path("timesim"), path("study.toml")]);
    let records: Vec<std::ffi::OsString> =
        list.iter().map(|f| path(&format!("timesim/timesim_{level}N_{f}Hz.csv"))).collect();
    for r in &records {
        assert!(std::path::Path::new(r).exists(), "timesim wrote no {r:?}");
    }
    // The steady state as written: --write-periods (4) copies of the converged period of 256
    // steps, sample for sample, and its plot.
    let record = columns(std::path::Path::new(&records[2]));
    assert_eq!(record["time_s"].len(), 4 * 256);
    assert!((0..3 * 256).all(|j| record["tip_m"][j] == record["tip_m"][j + 256]));
    assert!(dir.join(format!("timesim/timesim_{level}N_{}Hz.png", list[2])).exists());
    let mut extract = vec![s("extract"), s("--stepped"), s("--reference"), s("force"), s("--out"), path("extract")];
    extract.extend(records);
    ok(&extract);
    // Its FRFs plotted too, amplitude and phase per unit, as docs/outputs.md lists them.
    let plotted: Vec<String> = std::fs::read_dir(dir.join("extract"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".svg"))
        .collect();
    for kind in ["frf_amp_m_per_N.svg", "frf_phase_m_per_N.svg"] {
        assert!(plotted.iter().any(|name| name == kind), "extract drew no {kind}: {plotted:?}");
    }

    // The harmonic balance and the time integration agree at the five frequencies. The first
    // harmonic of the tip: the balance keeps 7 harmonics (what the 8th and above carry is out
    // of the first's balance, ~1e-3 of it for a Jenkins joint slipping part of the cycle); Newmark
    // at 256 steps per period lengthens the period by (2π/256)²/12 = 5e-5, an amplitude error
    // of up to 1/(2ζ) = 50 times that (2.5e-3) on the flanks of a 1 % damped resonance. 1 %
    // bounds both (2e-3 measured, on the stuck flanks); a wrong force normalisation, unit or
    // frequency is off by far more.
    let extracted = columns(&dir.join("extract/frf.csv"));
    assert_eq!(extracted["frequency_Hz"].len(), 5, "one row per record");
    assert!(extracted["level_N"].iter().all(|l| (l - level).abs() <= 1e-9 * level), "{:?}", extracted["level_N"]);
    for (i, &f) in extracted["frequency_Hz"].iter().enumerate() {
        // The frequency found from the force's zero crossings is the one asked.
        assert!((f - frequencies[i]).abs() <= 1e-6 * f, "{f} Hz for {} Hz", frequencies[i]);
        let disp = extracted["tip_amp_m_per_N"][i];
        let balance = run_frf["tip_disp_frf_m_per_N"][rows[i]];
        assert!((disp - balance).abs() <= 0.01 * balance, "{f} Hz: timesim {disp:e} m/N, balance {balance:e} m/N");
        // Velocity and acceleration FRFs are Ω and Ω² times the displacement's (first harmonic,
        // to the Newmark period error above).
        let omega = 2.0 * std::f64::consts::PI * f;
        for (column, power) in [("tip_amp_m_s_per_N", 1), ("tip_amp_m_s2_per_N", 2)] {
            let v = extracted[column][i] / omega.powi(power);
            assert!((v - disp).abs() <= 1e-3 * disp, "{column} at {f} Hz: {v:e} vs {disp:e}");
        }
    }
    // Each of the three tip FRFs and harmonics has its own phase column; no column is named
    // twice in either table.
    for (table, phase) in [("frf.csv", "tip_m_per_N_phase_rad"), ("harmonics.csv", "tip_m_s2_h3_phase_rad")] {
        let text = std::fs::read_to_string(dir.join("extract").join(table)).unwrap();
        let names: Vec<&str> = text.lines().next().unwrap().split(',').collect();
        for (i, n) in names.iter().enumerate() {
            assert!(!names[..i].contains(n), "{table}: column {n} twice in {names:?}");
        }
        assert!(names.contains(&phase) && !names.iter().any(|n| n.starts_with("frequency_h")), "{names:?}");
    }

    let out = ok(&[
        s("compare"),
        s("--measured"),
        path("extract/frf.csv"),
        s("--simulated"),
        path("run"),
        s("--out"),
        path("compare"),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("amp_err_%") && !stdout.contains("damp"), "{stdout}");
    // Displacement and acceleration on their own axes.
    for plot in ["compare_level0_tip_disp.svg", "compare_level0_tip_accel.svg"] {
        assert!(dir.join("compare").join(plot).exists(), "compare wrote no {plot}");
    }
    // The comparison joins the run's report: its plots embedded in a "Test comparison"
    // section, which a headless browser shows with the run's figures, without an error.
    assert!(stdout.contains("(its test comparison section)"), "{stdout}");
    let report = dir.join("run/report.html");
    let html = std::fs::read_to_string(&report).unwrap();
    assert_eq!(html.matches("<h2>Test comparison</h2>").count(), 1);
    for plot in ["compare_level0_tip_disp.svg", "compare_level0_tip_accel.svg"] {
        assert!(html.contains(&format!("<code>{plot}</code>")), "{plot} not in the report");
    }
    let images = html.matches("<img ").count();
    assert!(html.contains(&format!("data-expected-figures=\"{images}\"")), "figure count");
    if let Some(browser) = browser::required_browser() {
        let dom = browser::dump_dom(&browser, &report, &dir.join("browser-profile"));
        let all = format!("{images}/{images}");
        assert_eq!(browser::body_attribute(&dom, "data-figures").as_deref(), Some(all.as_str()), "figures shown");
        assert_eq!(browser::body_attribute(&dom, "data-errors").as_deref(), Some("0"), "script or console errors");
    }
    // The measured peak of the tip's displacement is the resonance `run` located: the middle
    // record sits on it, and the vertex of the parabola through three equally spaced records
    // whose middle one is highest lies within half their 1.5 % spacing of it (0.75 %; on this
    // flat-topped friction peak it lands 0.50 % away); the amplitudes agree as the FRFs do
    // above.
    let text = std::fs::read_to_string(dir.join("compare/peaks.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|c| *c == name).unwrap();
    let row: Vec<&str> = lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .find(|r| r[col("output")] == "tip" && r[col("unit")] == "m_per_N")
        .unwrap_or_else(|| panic!("no tip displacement peak in {text}"));
    let value = |name: &str| row[col(name)].parse::<f64>().unwrap();
    assert!((value("measured_frequency_Hz") - peak).abs() <= 0.0075 * peak, "{text}");
    assert!(value("amplitude_error_pct").abs() <= 1.0, "{text}");

    // The same folder, one frequency: the other records and plots of the previous timesim
    // go, the user's file stays.
    std::fs::write(dir.join("timesim/notes.txt"), "mine").unwrap();
    ok(&[s("timesim"), s("--frequency"), s(&list[2]), s("--out"), path("timesim"), path("study.toml")]);
    let mut left: Vec<String> = std::fs::read_dir(dir.join("timesim"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    let middle = format!("timesim_{level}N_{}Hz", list[2]);
    let mut expected = vec![
        format!("{middle}.csv"),
        format!("{middle}.png"),
        "notes.txt".to_string(),
        "timesim_files.txt".into(),
        "timesim_summary.csv".into(),
    ];
    expected.sort();
    assert_eq!(left, expected);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `params` lists its files per shard and `merge` its table, so that a smaller re-run into the
/// same folder removes the curves of the samples it no longer has.
#[test]
fn a_parameter_study_rerun_removes_the_curves_of_samples_it_no_longer_has() {
    let dir = scratch("params-files");
    let study = repo().join("examples/jenkins-1dof/study.toml");
    let run = |values: &str| {
        let out = stickslip()
            .args(["--threads", "1", "params", "--quiet", "--curves", "--vary"])
            .arg(format!("excitation.levels[0]={values}"))
            .arg(&study)
            .arg("--out")
            .arg(&dir)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    run("500,1000,1500");
    assert!(dir.join("curves/sample-2.csv").exists());
    let second = run("500,1000");
    assert!(!dir.join("curves/sample-2.csv").exists(), "{second}");
    assert!(dir.join("curves/sample-1.csv").exists());
    let list = std::fs::read_to_string(dir.join("params-shard-1-of-1_files.txt")).unwrap();
    assert_eq!(list.lines().count(), 3, "{list}");
    assert!(std::fs::read_to_string(dir.join("merge_files.txt")).unwrap().contains("samples.csv"));
    std::fs::remove_dir_all(&dir).unwrap();
}
