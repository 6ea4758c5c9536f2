//! Result files read back give the numbers written, bit for bit.

use std::path::PathBuf;

use stickslip_io::study::PlotFormat;

use stickslip_io::output::{
    frf_columns, frf_row, harmonics_from_coefficients, write_frf_csv, write_frf_npz, write_results, write_time_data,
    ElementRecord, LevelResult, OutputRecord, PointRecord, PointStability,
};

fn scratch_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("stickslip-io-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Awkward numbers: not representable in few decimals, tiny, huge, negative.
fn value(seed: usize) -> f64 {
    let x = (seed as f64 + 1.0) * std::f64::consts::PI / 7.0;
    x.sin() * 10f64.powi((seed % 17) as i32 - 8) / 3.0
}

fn point(f: f64, seed: usize, n_t: usize) -> PointRecord {
    let harmonics = harmonics_from_coefficients(&(0..15).map(|i| value(seed + i)).collect::<Vec<_>>());
    let series = |s: usize| (0..n_t).map(|j| value(s + j)).collect::<Vec<f64>>();
    PointRecord {
        frequency_hz: f,
        iterations: seed % 5,
        residual: value(seed).abs(),
        outputs: vec![
            OutputRecord {
                name: "mass".into(),
                disp_frf: value(seed + 1),
                accel_frf: value(seed + 2),
                peak: value(seed + 3),
                harmonics: harmonics.clone(),
                disp: series(seed),
                vel: series(seed + 1),
            },
            OutputRecord { name: "slider-P".into(), harmonics, ..Default::default() },
        ],
        elements: vec![ElementRecord {
            name: "joint_1".into(),
            energy_j: value(seed + 4),
            stick_fraction: 0.25,
            loop_u: series(seed + 2),
            loop_force: series(seed + 3),
            slider_velocity: series(seed + 4),
        }],
        input_energy_j: value(seed + 7),
        viscous_energy_j: value(seed + 8),
        stability: Some(PointStability {
            stable: seed.is_multiple_of(2),
            exponent_re: value(seed + 5),
            exponent_im: value(seed + 6),
        }),
    }
}

fn levels(n_t: usize) -> Vec<LevelResult> {
    vec![
        LevelResult {
            level_n: 100.0,
            points: (0..5).map(|i| point(150.0 + i as f64 * 0.1, i, n_t)).collect(),
            peaks: vec![],
            bifurcations: vec![],
        },
        LevelResult {
            level_n: 1000.0,
            points: (0..3).map(|i| point(350.0 - i as f64 / 3.0, 40 + i, 0)).collect(),
            peaks: vec![],
            bifurcations: vec![],
        },
    ]
}

fn read_csv(path: &std::path::Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines.map(|l| l.split(',').map(|v| v.parse::<f64>().unwrap()).collect()).collect();
    (header, rows)
}

#[test]
fn harmonics_are_amplitude_and_phase_of_cosines() {
    // c cos θ + s sin θ with c = 3, s = −4 is 5 cos(θ + atan2(4, 3)): exact up to round-off.
    let h = harmonics_from_coefficients(&[-0.5, 3.0, -4.0]);
    assert_eq!(h[0], (-0.5, 0.0));
    assert!((h[1].0 - 5.0).abs() < 1e-15 && (h[1].1 - 4f64.atan2(3.0)).abs() < 1e-15);
}

#[test]
fn frf_csv_reads_back_exactly() {
    let dir = scratch_dir("csv");
    let levels = levels(0);
    write_frf_csv(&dir.join("frf.csv"), &levels).unwrap();
    let (header, rows) = read_csv(&dir.join("frf.csv"));
    assert_eq!(&header[..4], ["level_N", "frequency_Hz", "newton_iterations", "residual_rel"]);
    assert_eq!(&header[4..7], ["mass_disp_frf_m_per_N", "mass_accel_frf_m_s2_per_N", "mass_peak_m"]);
    assert_eq!(&header[7..9], ["mass_h0_amp_m", "mass_h0_phase_rad"]);
    assert_eq!(
        &header[header.len() - 6..],
        [
            "joint_1_stick_fraction",
            "input_energy_J",
            "viscous_energy_J",
            "stable",
            "floquet_re_per_s",
            "floquet_im_rad_per_s"
        ]
    );
    // 4 + per output 3 + 2 (N+1) with N = 7, + 2 per element, + 2 energies, + 3 for the
    // stability.
    assert_eq!(header.len(), 4 + 2 * (3 + 16) + 2 + 2 + 3);
    assert_eq!(header, frf_columns(&levels[0].points[0]));
    assert_eq!(rows.len(), 8);
    let mut r = 0;
    for l in &levels {
        for p in &l.points {
            let row = &rows[r];
            assert_eq!(row[0], l.level_n);
            assert_eq!(row[1], p.frequency_hz);
            assert_eq!(row[2], p.iterations as f64);
            assert_eq!(row[3], p.residual);
            assert_eq!(row[4], p.outputs[0].disp_frf);
            assert_eq!(row[7 + 2 * 5], p.outputs[0].harmonics[5].0);
            assert_eq!(row[7 + 2 * 5 + 1], p.outputs[0].harmonics[5].1);
            assert_eq!(row[header.len() - 7], p.elements[0].energy_j);
            assert_eq!(row[header.len() - 5..header.len() - 3], [p.input_energy_j, p.viscous_energy_j]);
            let stability = p.stability.unwrap();
            assert_eq!(
                row[header.len() - 3..],
                [f64::from(u8::from(stability.stable)), stability.exponent_re, stability.exponent_im]
            );
            r += 1;
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn points_of_different_shape_are_refused() {
    let dir = scratch_dir("csv-shape");
    let mut levels = levels(0);
    levels[1].points[2].outputs[0].harmonics.pop();
    let msg = write_frf_csv(&dir.join("frf.csv"), &levels).unwrap_err().to_string();
    assert!(msg.starts_with("level 1000 N, point at"), "{msg}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn time_data_reads_back_exactly() {
    let dir = scratch_dir("time");
    let n_t = 300;
    let levels = levels(n_t);
    // Only the first level's points carry time data.
    assert_eq!(write_time_data(&dir, &levels).unwrap(), 5);
    let (header, rows) = read_csv(&dir.join("points/level0_point3.csv"));
    assert_eq!(
        header,
        [
            "theta_rad",
            "time_s",
            "mass_disp_m",
            "mass_vel_m_s",
            "joint_1_u_m",
            "joint_1_force_N",
            "joint_1_slider_vel_m_s"
        ]
    );
    assert_eq!(rows.len(), n_t);
    let p = &levels[0].points[3];
    for (j, row) in rows.iter().enumerate() {
        let theta = 2.0 * std::f64::consts::PI * j as f64 / n_t as f64;
        assert_eq!(row[0], theta);
        assert_eq!(row[1], theta / (2.0 * std::f64::consts::PI * p.frequency_hz));
        assert_eq!(row[2], p.outputs[0].disp[j]);
        assert_eq!(row[6], p.elements[0].slider_velocity[j]);
    }
    assert!(!dir.join("points/level1_point0.csv").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn frf_npz_reads_back_exactly() {
    let dir = scratch_dir("npz");
    let levels = levels(0);
    let path = dir.join("frf.npz");
    write_frf_npz(&path, &levels).unwrap();
    let mut npz = npyz::npz::NpzArchive::open(&path).unwrap();
    let read = |npz: &mut npyz::npz::NpzArchive<_>, name: &str| {
        let arr = npz.by_name(name).unwrap().unwrap_or_else(|| panic!("array {name} missing"));
        let shape = arr.shape().to_vec();
        (shape, arr.into_vec::<f64>().unwrap())
    };
    let (shape, level) = read(&mut npz, "level_N");
    assert_eq!(shape, [8]);
    assert_eq!(level, [100.0, 100.0, 100.0, 100.0, 100.0, 1000.0, 1000.0, 1000.0]);
    let (_, f) = read(&mut npz, "frequency_Hz");
    assert_eq!(f[6], levels[1].points[1].frequency_hz);
    let (_, e) = read(&mut npz, "joint_1_energy_J");
    assert_eq!(e[2], levels[0].points[2].elements[0].energy_j);
    let (shape, amps) = read(&mut npz, "slider-P_harmonics_amp_m");
    assert_eq!(shape, [8, 8]);
    // Row-major (C order), as numpy reads it: row 6 = level 1, point 1.
    assert_eq!(amps[6 * 8 + 3], levels[1].points[1].outputs[1].harmonics[3].0);
    let (_, h3) = read(&mut npz, "slider-P_h3_amp_m");
    assert_eq!(h3[6], amps[6 * 8 + 3]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Every array of `frf.npz`, as `numpy.load` sees it: float64, C order, its shape, the header
/// numpy writes, and every value equal to the table's, bit for bit.
#[test]
fn frf_npz_holds_every_column_and_harmonic_exactly_in_numpy_format() {
    use std::io::Read as _;
    let dir = scratch_dir("npz-all");
    let levels = levels(0);
    let path = dir.join("frf.npz");
    write_frf_npz(&path, &levels).unwrap();
    let columns = frf_columns(&levels[0].points[0]);
    let rows: Vec<Vec<f64>> = levels.iter().flat_map(|l| l.points.iter().map(move |p| frf_row(l.level_n, p))).collect();
    let points: Vec<&PointRecord> = levels.iter().flat_map(|l| &l.points).collect();

    let mut zip = npyz::zip::ZipArchive::new(std::fs::File::open(&path).unwrap()).unwrap();
    let mut names: Vec<String> = zip.file_names().map(String::from).collect();
    names.sort();
    let mut expected: Vec<String> = columns.iter().map(|c| format!("{c}.npy")).collect();
    for out in ["mass", "slider-P"] {
        expected.extend([format!("{out}_harmonics_amp_m.npy"), format!("{out}_harmonics_phase_rad.npy")]);
    }
    expected.sort();
    assert_eq!(names, expected);
    // The header as numpy writes it (format 1.0, the dict padded with spaces to a multiple of 16).
    let mut bytes = Vec::new();
    zip.by_name("level_N.npy").unwrap().read_to_end(&mut bytes).unwrap();
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
    assert_eq!((10 + header_len) % 16, 0);
    let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
    assert_eq!(header.trim_end(), "{'descr': '<f8', 'fortran_order': False, 'shape': (8, ), }");
    assert!(header.ends_with('\n'));
    assert_eq!(bytes.len(), 10 + header_len + 8 * 8);

    let mut npz = npyz::npz::NpzArchive::open(&path).unwrap();
    let mut read = |name: &str| {
        let arr = npz.by_name(name).unwrap().unwrap_or_else(|| panic!("array {name} missing"));
        assert_eq!(arr.dtype(), npyz::DType::Plain("<f8".parse().unwrap()), "{name}");
        assert_eq!(arr.order(), npyz::Order::C, "{name}");
        let shape = arr.shape().to_vec();
        (shape, arr.into_vec::<f64>().unwrap())
    };
    for (c, name) in columns.iter().enumerate() {
        let (shape, values) = read(name);
        assert_eq!(shape, [rows.len() as u64], "{name}");
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&values), bits(&rows.iter().map(|r| r[c]).collect::<Vec<_>>()), "{name}");
    }
    for (o, out) in ["mass", "slider-P"].iter().enumerate() {
        let (shape, amps) = read(&format!("{out}_harmonics_amp_m"));
        let (phase_shape, phases) = read(&format!("{out}_harmonics_phase_rad"));
        assert_eq!(shape, [8, 8]);
        assert_eq!(phase_shape, [8, 8]);
        let harmonics: Vec<(f64, f64)> = points.iter().flat_map(|p| p.outputs[o].harmonics.iter().copied()).collect();
        assert_eq!(amps, harmonics.iter().map(|h| h.0).collect::<Vec<_>>());
        assert_eq!(phases, harmonics.iter().map(|h| h.1).collect::<Vec<_>>());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The archive's bytes depend on the results alone: its entries carry the zip format's first
/// date (1980-01-01), not the time of the run, so two runs' files compare byte for byte.
#[test]
fn frf_npz_entries_are_dated_1980_so_the_same_results_make_the_same_bytes() {
    let dir = scratch_dir("npz-dated");
    let levels = levels(16);
    let path = dir.join("frf.npz");
    write_frf_npz(&path, &levels).unwrap();
    let mut zip = npyz::zip::ZipArchive::new(std::fs::File::open(&path).unwrap()).unwrap();
    assert!(zip.len() > 10, "{} entries", zip.len());
    for i in 0..zip.len() {
        let entry = zip.by_index(i).unwrap();
        let t = entry.last_modified();
        let date = (t.year(), t.month(), t.day(), t.hour(), t.minute(), t.second());
        assert_eq!(date, (1980, 1, 1, 0, 0, 0), "{}", entry.name());
    }
    drop(zip);
    let first = std::fs::read(&path).unwrap();
    write_frf_npz(&path, &levels).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), first);
}

#[test]
fn an_empty_sweep_writes_an_empty_npz() {
    let dir = scratch_dir("npz-empty");
    let path = dir.join("frf.npz");
    write_frf_npz(&path, &[]).unwrap();
    let zip = npyz::zip::ZipArchive::new(std::fs::File::open(&path).unwrap()).unwrap();
    assert_eq!(zip.len(), 0);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn write_results_writes_table_arrays_time_data_and_plots() {
    let dir = scratch_dir("all").join("run");
    let files = write_results(&dir, &levels(64), Some(PlotFormat::Svg)).unwrap();
    let names: Vec<_> = files.iter().map(|f| f.file_name().unwrap().to_str().unwrap().to_string()).collect();
    assert_eq!(
        names[..8],
        [
            "frf.csv",
            "frf.npz",
            "peaks.csv",
            "bifurcations.csv",
            "frf_mass.svg",
            "frf_slider-P.svg",
            "frf_phase_mass.svg",
            "frf_phase_slider-P.svg"
        ]
    );
    // Harmonics of 2 outputs at 2 levels; loop and slider velocity where time data exist.
    assert_eq!(names.len(), 8 + 2 * 2 + 2);
    // Stability known, no bifurcation given: the header alone.
    let bifurcations = std::fs::read_to_string(dir.join("bifurcations.csv")).unwrap();
    assert_eq!(bifurcations, "level_N,kind,frequency_Hz,located,floquet_im_rad_per_s,mass_amp_m,slider-P_amp_m\n");
    // The time data files, as `time_data_files` lists them for a run's list of its files.
    let listed = stickslip_io::output::time_data_files(&dir, &levels(64));
    assert_eq!(listed.len(), 5);
    assert!(listed.iter().all(|f| f.starts_with(dir.join("points")) && f.exists()), "{listed:?}");
    // No located peaks given: the largest sampled point per level and output, marked 0.
    let peaks = std::fs::read_to_string(dir.join("peaks.csv")).unwrap();
    assert_eq!(peaks.lines().count(), 1 + 2 * 2);
    assert!(peaks.lines().skip(1).all(|l| l.ends_with(",0")), "{peaks}");
    assert!(names.contains(&"loop_level0_joint_1.svg".to_string()));
    assert!(files.iter().all(|f| std::fs::metadata(f).unwrap().len() > 0));
    // 5 points of level 0 carry time data (level 1 was built without).
    assert_eq!(std::fs::read_dir(dir.join("points")).unwrap().count(), 5);
    if std::env::var_os("STICKSLIP_KEEP_PLOTS").is_none() {
        std::fs::remove_dir_all(dir.parent().unwrap()).unwrap();
    }
}

#[test]
fn time_series_of_different_lengths_are_refused() {
    let dir = scratch_dir("time-len");
    let mut p = point(200.0, 3, 16);
    p.elements[0].slider_velocity.pop();
    let msg = stickslip_io::output::write_point_csv(&dir.join("p.csv"), &p).unwrap_err().to_string();
    assert!(msg.ends_with("p.csv: series joint_1_slider_vel_m_s has 15 samples, others 16"), "{msg}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_run_removes_what_its_previous_run_wrote_and_nothing_else() {
    use stickslip_io::output::{manifest_path, replace_previous_run};
    let dir = std::env::temp_dir().join(format!("stickslip-io-manifest-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("points")).unwrap();
    let write = |name: &str| {
        std::fs::write(dir.join(name), name).unwrap();
        dir.join(name)
    };
    // The user's notes, and another command's file.
    write("notes.txt");
    write("compare_level0_tip_disp.svg");
    // First run: four files, one in a sub-folder.
    let first: Vec<PathBuf> =
        ["frf.csv", "frf_tip.svg", "frf_level3.svg", "points/level3_point0.csv"].map(write).to_vec();
    assert!(replace_previous_run(&dir, "run", &first).unwrap().is_empty(), "nothing listed yet");
    assert_eq!(
        std::fs::read_to_string(manifest_path(&dir, "run")).unwrap(),
        "frf.csv\nfrf_tip.svg\nfrf_level3.svg\npoints/level3_point0.csv\n"
    );
    // Second run, fewer levels: two of the old files are not written again.
    let second: Vec<PathBuf> = ["frf.csv", "frf_tip.svg"].map(write).to_vec();
    let mut removed = replace_previous_run(&dir, "run", &second).unwrap();
    removed.sort();
    assert_eq!(removed, [dir.join("frf_level3.svg"), dir.join("points/level3_point0.csv")]);
    assert!(!dir.join("points").exists(), "the emptied sub-folder goes too");
    for kept in ["notes.txt", "compare_level0_tip_disp.svg", "frf.csv", "frf_tip.svg"] {
        assert!(dir.join(kept).exists(), "{kept} was removed");
    }
    // A list edited to point outside the folder removes nothing there.
    let outside = dir.with_extension("outside");
    std::fs::write(&outside, "x").unwrap();
    let escaped = format!("../{}\n/etc/hostname\n", outside.file_name().unwrap().to_string_lossy());
    std::fs::write(manifest_path(&dir, "run"), escaped).unwrap();
    assert!(replace_previous_run(&dir, "run", &second).unwrap().is_empty());
    assert!(outside.exists());
    std::fs::remove_file(&outside).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
}
