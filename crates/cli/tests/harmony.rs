//! The Harmony example end to end at the coarse refinement (element size 60 mm, ~31k DOFs,
//! reduced to 103 DOFs + 34 free modes + 12 released modes): the paper's trends (Section 5.1-5.2).
mod common;
use common::{browser, repo, scratch, stickslip};

/// Column `name` of the FRF table.
fn column(header: &[String], name: &str) -> usize {
    header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name}"))
}

#[test]
fn harmony_softens_and_flattens_with_the_level_while_friction_dissipates() {
    let dir = scratch("harmony");
    std::fs::create_dir_all(&dir).unwrap();
    let study = std::fs::read_to_string(repo().join("examples/harmony/study.toml")).unwrap();
    let study = study
        .replace("refinement = 1.0", "refinement = 0.5")
        .replace("levels = [70.0, 1070.0, 1875.0, 2910.0, 6000.0, 10000.0]", "levels = [70.0, 1875.0, 2910.0]")
        .replace("start_hz = 300.0", "start_hz = 290.0")
        .replace("end_hz = 170.0", "end_hz = 200.0")
        .replace("time_data = 10", "time_data = \"none\"")
        + "\n[[output]]\nname = \"shaker\"\ndof = \"1.3\"\n";
    assert!(study.contains("refinement = 0.5") && study.contains("levels = [70.0, 1875.0, 2910.0]"));
    let path = dir.join("study.toml");
    std::fs::write(&path, study).unwrap();
    let out = dir.join("out");
    let status = stickslip().args(["run", "--quiet", "--out"]).arg(&out).arg(&path).status().unwrap();
    assert!(status.success());
    // The report (Deliver 7): every figure of the run embedded and shown by a headless
    // browser, without a script or console error.
    let report = out.join("report.html");
    let html = std::fs::read_to_string(&report).unwrap();
    let figures: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".png"))
        .collect();
    // Per output (5) the FRF and its phase, per level (3) and output the harmonics, and the
    // snapshot's velocities (no time data: no loops).
    assert_eq!(figures.len(), 5 * 2 + 3 * 5 + 1, "{figures:?}");
    assert_eq!(html.matches("<img src=\"data:image/png;base64,").count(), figures.len());
    for section in ["<h2>Model</h2>", "<h2>Peaks</h2>", "<h2>Harmonics</h2>", "<h2>Timings</h2>"] {
        assert!(html.contains(section), "the report has no {section}");
    }
    if let Some(browser) = browser::required_browser() {
        let dom = browser::dump_dom(&browser, &report, &dir.join("browser-profile"));
        let all = format!("{}/{}", figures.len(), figures.len());
        assert_eq!(browser::body_attribute(&dom, "data-figures").as_deref(), Some(all.as_str()), "figures shown");
        assert_eq!(browser::body_attribute(&dom, "data-errors").as_deref(), Some("0"), "script or console errors");
    }
    // The generated mesh is written for CalculiX/Abaqus and Gmsh (round trips: fe's
    // mesh_writers tests).
    let deck = std::fs::read_to_string(out.join("model.inp")).unwrap();
    assert!(deck.contains("*NODE") && deck.contains("*COUPLING") && deck.contains("*ELEMENT, TYPE=C3D20"));
    // The screws' moment springs act on the rotation nodes of rigid bodies, as CalculiX takes them.
    assert!(deck.contains("ROT NODE=") && !deck.contains("springs act on translations only"));
    let msh = std::fs::read_to_string(out.join("model.msh")).unwrap();
    assert!(msh.starts_with("$MeshFormat\n4.1") && msh.contains("ACCELEROMETERS"));
    let table = std::fs::read_to_string(out.join("frf.csv")).unwrap();
    let mut lines = table.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    let (level, freq) = (column(&header, "level_N"), column(&header, "frequency_Hz"));
    let disp = column(&header, "body_top_disp_frf_m_per_N");
    let h1 = column(&header, "body_top_h1_amp_m");
    let odd: Vec<usize> = [3, 5, 7].iter().map(|k| column(&header, &format!("body_top_h{k}_amp_m"))).collect();
    let stick: Vec<usize> = (1..=4).map(|i| column(&header, &format!("blade{i}_stick_fraction"))).collect();
    let energy: Vec<usize> = (1..=4).map(|i| column(&header, &format!("blade{i}_energy_J"))).collect();
    let (sh_amp, sh_phase) = (column(&header, "shaker_h1_amp_m"), column(&header, "shaker_h1_phase_rad"));
    let (input_energy, viscous) = (column(&header, "input_energy_J"), column(&header, "viscous_energy_J"));
    let residual = column(&header, "residual_rel");
    let mut stuck_points = 0;
    let mut worst_balance = 0.0f64;

    let mut peaks = Vec::new();
    for lv in [70.0, 1875.0, 2910.0] {
        let pts: Vec<&Vec<f64>> = rows.iter().filter(|r| r[level] == lv).collect();
        assert!(pts.len() > 20, "level {lv}: {} points", pts.len());
        assert_eq!(pts[0][freq], 290.0);
        assert!((pts[pts.len() - 1][freq] - 200.0).abs() < 1e-9, "level {lv} did not cross the band");
        let peak = pts.iter().max_by(|a, b| a[disp].total_cmp(&b[disp])).unwrap();
        peaks.push((peak[freq], peak[disp]));
        for p in &pts {
            let stuck = stick.iter().all(|&c| p[c] == 1.0);
            // Harmonics 3, 5, 7 come from friction only (Fig. 21): below 1e-3 of the first
            // harmonic where every blade sticks (a linear response has none: round-off only).
            let ratio = odd.iter().map(|&c| p[c]).fold(0.0, f64::max) / p[h1];
            if stuck {
                assert!(ratio < 1e-3, "level {lv}, {} Hz: stuck, yet h3-7/h1 = {ratio:e}", p[freq]);
                assert!(energy.iter().all(|&c| p[c].abs() < 1e-9), "stuck blades dissipate");
                stuck_points += 1;
            }
            // Energy per cycle: the shaker's input −π F A sin φ (x = A cos(Ωt + φ) under
            // F cos Ωt), computed here from the shaker's own first harmonic, is the input
            // written by the run (the force acts on the shaker alone: equal to round-off) ...
            let input = -std::f64::consts::PI * lv * p[sh_amp] * p[sh_phase].sin();
            assert!(
                (p[input_energy] / input - 1.0).abs() < 1e-9,
                "{} Hz: input {} J, {input} J",
                p[freq],
                p[input_energy]
            );
            // ... and balances the friction and the viscous dissipation. The defect is the work
            // of the balance's residual: Newton stops at ‖R‖ ≤ 1e-14 m on the joints'
            // directions here (the floor of docs/study-file.md: stuck 1e10 N/m joints move by
            // ~1e-9 m), whose work against joint forces of ~1e2-1e3 N is ~1e-7 of the input at
            // 70 N. Measured at most 4.4e-8 over the three levels; asserted 1e-6.
            let friction: f64 = energy.iter().map(|&c| p[c]).sum();
            assert!(
                friction >= -1e-12 && p[viscous] > 0.0,
                "{} Hz: friction {friction} J, viscous {} J",
                p[freq],
                p[viscous]
            );
            let balance = (input - friction - p[viscous]) / input;
            assert!(
                balance.abs() < 1e-6,
                "level {lv}, {} Hz: energy balance {balance:e} (residual {:e})",
                p[freq],
                p[residual]
            );
            worst_balance = worst_balance.max(balance.abs());
        }
        if lv == 2910.0 {
            // Friction acts at the resonance: the blades stick only part of the period, and
            // the odd harmonics rise above 1e-3 of the first.
            let at_peak = stick.iter().map(|&c| peak[c]).fold(1.0, f64::min);
            assert!(at_peak < 0.9, "stick fraction at the 2910 N peak: {at_peak}");
            let ratio = odd.iter().map(|&c| peak[c]).fold(0.0, f64::max) / peak[h1];
            assert!(ratio > 1e-3, "h3-7/h1 at the 2910 N peak: {ratio:e}");
        }
    }
    // The check of stuck points above ran: at 70 N the blades stick across the band.
    assert!(stuck_points > 20, "{stuck_points} points with every blade stuck");
    println!("energy balance at every point within {worst_balance:.1e} of the input; {stuck_points} stuck points");
    // Section 5.1: the resonance falls and the peak flattens as the level rises.
    assert!(peaks[0].0 > peaks[1].0 && peaks[1].0 > peaks[2].0, "peak frequencies {peaks:?}");
    assert!(peaks[0].1 > 1.5 * peaks[1].1 && peaks[1].1 > peaks[2].1, "peak FRFs {peaks:?}");

    // Figs. 22-23 (the example's [[snapshot]], 238 Hz and 3420 N): the blade top P (11.3)
    // alternates between following its envelope contact B (21.3) and slipping past it, twice
    // a period, faster than B moves. Stuck 0.17 of the period here, 0.20 at the default
    // refinement (the paper's Fig. 9 shows slip in 5 of 9 frames).
    let snapshot = std::fs::read_to_string(out.join("snapshot0.csv")).unwrap();
    let mut lines = snapshot.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    let (p, b) = (column(&header, "blade1_11.3_vel_m_s"), column(&header, "blade1_21.3_vel_m_s"));
    let stuck = rows.iter().filter(|r| r[p] == r[b]).count() as f64 / rows.len() as f64;
    assert!((0.1..0.8).contains(&stuck), "blade 1 sticks {stuck} of the period at 238 Hz, 3420 N");
    let slips = rows.windows(2).filter(|w| (w[0][p] == w[0][b]) && (w[1][p] != w[1][b])).count();
    assert!(slips >= 2, "{slips} slip phases a period");
    let b_peak = rows.iter().map(|r| r[b].abs()).fold(0.0, f64::max);
    let relative = rows.iter().map(|r| (r[p] - r[b]).abs()).fold(0.0, f64::max);
    assert!(relative > b_peak, "slip velocity {relative} m/s, contact velocity {b_peak} m/s");
    assert!(out.join("snapshot0_blade1.png").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// The FRF of the body top along a run's branch: (frequency Hz, |X₁|/F) in branch order.
fn body_top_frf(out: &std::path::Path) -> Vec<(f64, f64)> {
    let table = std::fs::read_to_string(out.join("frf.csv")).unwrap();
    let mut lines = table.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let (freq, disp) = (column(&header, "frequency_Hz"), column(&header, "body_top_disp_frf_m_per_N"));
    lines
        .map(|l| {
            let row: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
            (row[freq], row[disp])
        })
        .collect()
}

#[test]
fn the_10000_n_branch_is_resumed_past_the_corner_where_the_blades_stick_again() {
    // At the coarse refinement the 10000 N sweep down the band stops after 204.353 Hz (and
    // again after 202.687 Hz): the blades' stick fraction jumps there, and every step and leap
    // from the last point fails. The branch is resumed: started again further down, followed
    // back to the stop, where it arrives at the same solution.
    let dir = scratch("harmony-resumed");
    std::fs::create_dir_all(&dir).unwrap();
    let example = std::fs::read_to_string(repo().join("examples/harmony/study.toml")).unwrap();
    let coarse = example
        .replace("refinement = 1.0", "refinement = 0.5")
        .replace("levels = [70.0, 1070.0, 1875.0, 2910.0, 6000.0, 10000.0]", "levels = [10000.0]")
        .replace("time_data = 10", "time_data = \"none\"");
    assert!(coarse.contains("refinement = 0.5") && coarse.contains("levels = [10000.0]"));
    let run = |name: &str, study: &str| {
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, study).unwrap();
        let out = dir.join(name);
        let output = stickslip()
            .args(["run", "--quiet", "--no-plots", "--no-report", "--threads", "1", "--out"])
            .arg(&out)
            .arg(&path)
            .output()
            .unwrap();
        assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
        (out, String::from_utf8_lossy(&output.stderr).into_owned())
    };
    let (down, said) = run("down", &coarse);
    let stop: f64 = said
        .split("the continuation stopped after ")
        .nth(1)
        .and_then(|rest| rest.split(" Hz").next())
        .and_then(|f| f.parse().ok())
        .unwrap_or_else(|| panic!("no stop in {said}"));
    assert!((stop - 204.353).abs() < 0.01 && said.contains("was resumed"), "{said}");
    let branch = body_top_frf(&down);
    assert_eq!(branch.last().unwrap().0, 170.0, "the band is crossed");
    // The all-slip asymptote (Section 5.1: "an asymptotic resonance at 190 Hz", the blades
    // slipping freely): the located peak of the body top lies just above the resonance of this
    // mesh with the contacts released, 198.1 Hz (crates/fe/tests/harmony_model.rs), far below
    // the stuck one at 250.0 Hz. Measured 199.88 Hz (+0.9 %); asserted within 3 % above.
    let peaks = std::fs::read_to_string(down.join("peaks.csv")).unwrap();
    let body_top: Vec<&str> = peaks.lines().find(|l| l.contains(",body_top,")).unwrap().split(',').collect();
    let peak_hz: f64 = body_top[2].parse().unwrap();
    assert!(body_top[5] == "1" && (198.1..198.1 * 1.03).contains(&peak_hz), "10000 N peak at {peak_hz} Hz");

    // Independently, the branch swept up through the corner from 1.5 Hz below it, in steps of
    // at most 0.002 Hz: the resumed branch lies on it. Here the blades stick for one time
    // sample or none, alternately every ~0.12 Hz: the FRF is a sawtooth of corners ~0.5 %
    // high, and the arc without stick reaches past the corner where the upward sweep takes the
    // one-sample stick (they overlap by ~0.001 Hz at the stop: the sampled branch folds there,
    // which is why every step failed). The points within 0.01 Hz of the stop are left out;
    // elsewhere the FRF interpolated linearly between the reference's points matches: measured
    // 1e-7, asserted 1e-4; another branch would differ at first order.
    let (from, to) = (stop - 1.5, stop + 1.0);
    let up = coarse
        .replace("start_hz = 300.0", &format!("start_hz = {from:.3}"))
        .replace("end_hz = 170.0", &format!("end_hz = {to:.3}"))
        + "\n[continuation]\nmax_step_hz = 0.002\n";
    let up = up.replace("[sweep]", "[sweep]\nstep_hz = 0.002");
    let (up, _) = run("up", &up);
    let reference = body_top_frf(&up);
    let mut compared = 0;
    let mut worst = 0.0f64;
    for &(f, frf) in branch.iter().filter(|p| p.0 > from + 0.05 && p.0 < to - 0.05 && (p.0 - stop).abs() > 0.01) {
        let j = reference.partition_point(|r| r.0 < f);
        let ((f0, a0), (f1, a1)) = (reference[j - 1], reference[j]);
        let interpolated = a0 + (a1 - a0) * (f - f0) / (f1 - f0);
        assert!((frf / interpolated - 1.0).abs() < 1e-4, "{f} Hz: {frf} against {interpolated}");
        worst = worst.max((frf / interpolated - 1.0).abs());
        compared += 1;
    }
    println!("{compared} points compared around the stop at {stop} Hz: at most {worst:.1e} apart");
    assert!(compared >= 5, "{compared} points compared around the stop");
}
