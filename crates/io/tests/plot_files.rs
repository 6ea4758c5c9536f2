//! Plots are written as non-empty PNG and SVG files with their legends.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use num_complex::Complex64;
use stickslip_core::elements::{Element, Jenkins};
use stickslip_io::output::{ElementRecord, LevelResult, OutputRecord, PointRecord};
use stickslip_io::plot::{
    plot_comparison, plot_frf, plot_frf_phases, plot_frf_set, plot_frfs, plot_harmonics, plot_hysteresis,
    plot_level_details, plot_slider_velocity, plot_time_records, MeasuredCurve,
};
use stickslip_io::records::{Channel, FrfCurve, FrfSet, TimeRecords};
use stickslip_io::study::PlotFormat;

fn scratch_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("stickslip-io-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A linear oscillator's FRF (the shapes the plots must show) with softer, more damped
/// resonances at higher levels, and a Jenkins loop at one point.
fn levels() -> Vec<LevelResult> {
    let n_t = 300;
    [(100.0, 2.24e7, 0.01), (1000.0, 1.9e7, 0.03), (10000.0, 1.45e7, 0.06)]
        .iter()
        .map(|&(level_n, k, zeta)| {
            let points = (0..=200)
                .map(|i| {
                    let f = 150.0 + i as f64;
                    let w = 2.0 * PI * f;
                    let wn = (k / 10.0f64).sqrt();
                    let h = 1.0 / ((k - 10.0 * w * w).powi(2) + (2.0 * zeta * wn * 10.0 * w).powi(2)).sqrt();
                    let harmonics = (0..=7).map(|k| (h * level_n / (1.0 + k as f64).powi(3), 0.1 * k as f64)).collect();
                    let (loop_u, loop_force, slider_velocity) = jenkins_loop(h * level_n, w, n_t);
                    PointRecord {
                        frequency_hz: f,
                        iterations: 2,
                        residual: 1e-10,
                        outputs: vec![OutputRecord {
                            name: "mass".into(),
                            disp_frf: h,
                            accel_frf: w * w * h,
                            peak: h * level_n,
                            harmonics,
                            ..Default::default()
                        }],
                        elements: vec![ElementRecord {
                            name: "joint".into(),
                            energy_j: 0.0,
                            stick_fraction: 1.0,
                            loop_u,
                            loop_force,
                            slider_velocity,
                        }],
                        input_energy_j: 0.0,
                        viscous_energy_j: 0.0,
                        stability: None,
                    }
                })
                .collect();
            LevelResult { level_n, points, peaks: vec![], bifurcations: vec![] }
        })
        .collect()
}

/// Displacement, force and slider velocity of a Jenkins element (k = 8.11e6 N/m, F_c = 1000 N)
/// under u = a cos θ, second period of the march.
fn jenkins_loop(a: f64, w: f64, n_t: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let law = Jenkins::new(8.11e6, 1000.0).unwrap();
    let mut state = [0.0];
    let (mut u, mut f, mut v) = (Vec::new(), Vec::new(), Vec::new());
    for period in 0..2 {
        for j in 0..n_t {
            let theta = 2.0 * PI * j as f64 / n_t as f64;
            let before = state[0];
            let mut g = [0.0];
            law.update(&[a * theta.cos()], &[0.0], &mut state, &mut g, None);
            if period == 1 {
                u.push(a * theta.cos());
                f.push(g[0]);
                v.push((state[0] - before) * w * n_t as f64 / (2.0 * PI));
            }
        }
    }
    (u, f, v)
}

fn assert_png(path: &Path) {
    let bytes = std::fs::read(path).unwrap();
    assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "{} is not a PNG", path.display());
    // A 1000x650 chart with curves and text compresses to tens of kB; an empty white image
    // to well under 10 kB.
    assert!(bytes.len() > 10_000, "{} is only {} bytes", path.display(), bytes.len());
}

fn svg(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.starts_with("<svg"), "{} is not an SVG", path.display());
    text
}

#[test]
fn frf_plots_have_one_curve_per_level_and_a_legend() {
    let dir = scratch_dir("plot-frf");
    let levels = levels();
    plot_frf(&dir.join("frf.png"), &levels, "mass").unwrap();
    assert_png(&dir.join("frf.png"));
    let files = plot_frfs(&dir, &levels, PlotFormat::Svg).unwrap();
    assert_eq!(files, [dir.join("frf_mass.svg")]);
    let text = svg(&files[0]);
    for label in ["100 N", "1000 N", "10000 N", "Frequency (Hz)"] {
        assert!(text.contains(label), "missing {label:?}");
    }
    // Curves and legend marks are the only lines drawn 2 px wide.
    assert_eq!(text.matches("stroke-width=\"2\"").count(), 3 + 3, "3 curves and 3 legend marks");
    let msg = plot_frf(&dir.join("frf.png"), &levels, "tip").unwrap_err().to_string();
    assert_eq!(msg, "no output named \"tip\" (outputs are: mass)");
    let msg = plot_frf(&dir.join("frf.pdf"), &levels, "mass").unwrap_err().to_string();
    assert!(msg.ends_with("the plot file name must end in .png or .svg"), "{msg}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn harmonics_hysteresis_and_slider_velocity_plots_are_written() {
    let dir = scratch_dir("plot-more");
    let levels = levels();
    plot_harmonics(&dir.join("harmonics.png"), &levels[2], "mass").unwrap();
    assert_png(&dir.join("harmonics.png"));
    plot_harmonics(&dir.join("harmonics.svg"), &levels[2], "mass").unwrap();
    assert!(svg(&dir.join("harmonics.svg")).contains("harmonic 7"));
    // The harmonics span decades: the log axis labels its decades only (1e-7, not 2e-7).
    let text = svg(&dir.join("harmonics.svg"));
    let labels: Vec<&str> = text.lines().map(str::trim).filter(|l| l.len() < 8 && l.contains("e-")).collect();
    assert!(labels.iter().any(|l| l.starts_with("1e-")), "no decade label in {labels:?}");
    assert!(labels.iter().all(|l| l.starts_with("1e-")), "a label between decades in {labels:?}");
    let point = &levels[2].points[88];
    plot_hysteresis(&dir.join("loop.png"), 1000.0, point, "joint").unwrap();
    assert_png(&dir.join("loop.png"));
    plot_slider_velocity(&dir.join("slider.svg"), 1000.0, point, "joint").unwrap();
    assert!(svg(&dir.join("slider.svg")).contains("Time (ms)"));
    // The level is in the title of every detail plot.
    assert!(svg(&dir.join("slider.svg")).contains("1000 N"));
    if std::env::var_os("STICKSLIP_KEEP_PLOTS").is_none() {
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn level_details_plot_the_resonance_point() {
    let dir = scratch_dir("plot-details");
    let files = plot_level_details(&dir, &levels(), PlotFormat::Svg).unwrap();
    let names: Vec<_> = files.iter().map(|f| f.file_name().unwrap().to_str().unwrap().to_string()).collect();
    assert_eq!(names.len(), 3 * 3);
    assert_eq!(names[..3], ["harmonics_level0_mass.svg", "loop_level0_joint.svg", "slider_level0_joint.svg"]);
    // Level 2 (k = 1.45e7 N/m, 10 kg, ζ = 0.06): the displacement FRF peaks at
    // sqrt(k/m) sqrt(1 − 2ζ²)/2π = 190.96 Hz, so at 191 Hz on the 1 Hz grid.
    let text = std::fs::read_to_string(dir.join("loop_level2_joint.svg")).unwrap();
    assert!(text.contains("at 191.0000 Hz"), "the loop is not at the resonance");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn round_off_harmonics_do_not_stretch_the_log_axis() {
    let dir = scratch_dir("plot-roundoff");
    let mut level = levels().remove(2);
    for p in &mut level.points {
        // An even harmonic of a symmetric response: round-off, ~1e-20 of the first.
        p.outputs[0].harmonics[2].0 = 1e-25;
    }
    plot_harmonics(&dir.join("h.svg"), &level, "mass").unwrap();
    let text = std::fs::read_to_string(dir.join("h.svg")).unwrap();
    // The other harmonics span 1e-6..1e-3 m; an axis stretched to 1e-25 would label the
    // decades 1e-2x. Labels are written on their own line.
    assert!(text.contains("\n1e-4\n"), "expected labels missing");
    assert!(!text.contains("\n1e-2"), "the axis reaches the round-off");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn phase_plots_stand_beside_the_amplitude_plots() {
    let dir = scratch_dir("plot-phase");
    let files = plot_frf_phases(&dir, &levels(), PlotFormat::Svg).unwrap();
    assert_eq!(files, [dir.join("frf_phase_mass.svg")]);
    let text = svg(&files[0]);
    for label in ["Phase of mass", "Phase (degrees)", "100 N", "10000 N"] {
        assert!(text.contains(label), "missing {label:?}");
    }
    assert_eq!(text.matches("stroke-width=\"2\"").count(), 3 + 3, "3 curves and 3 legend marks");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn extracted_frfs_are_plotted_per_unit_and_time_records_per_quantity() {
    let dir = scratch_dir("plot-extract");
    let f: Vec<f64> = (0..20).map(|i| 100.0 + i as f64).collect();
    let curve = |name: &str, unit: &str, has_phase: bool| FrfCurve {
        name: name.into(),
        unit: unit.into(),
        values: f.iter().map(|x| Complex64::from_polar(1e-5 * x, -0.01 * x)).collect(),
        has_phase,
    };
    let set = FrfSet {
        source: "memory".into(),
        level_n: Some(2.0),
        frequency_hz: f.clone(),
        curves: vec![curve("tip", "m_per_N", true), curve("mid", "m_per_N", true), curve("tip", "m_s2_per_N", false)],
    };
    let files = plot_frf_set(&dir, "frf", &set, PlotFormat::Svg).unwrap();
    // An amplitude plot per unit; a phase plot where there is a phase (not for the
    // amplitude-only acceleration).
    let names: Vec<_> = files.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
    assert_eq!(names, ["frf_amp_m_per_N.svg", "frf_phase_m_per_N.svg", "frf_amp_m_s2_per_N.svg"]);
    let text = svg(&files[0]);
    assert!(text.contains("m / N") && text.contains("at 2.0000 N"), "axis in m / N, the level in the title");
    assert_eq!(svg(&files[1]).matches("stroke-width=\"2\"").count(), 2 + 2, "tip and mid, and their legend marks");

    let records = TimeRecords {
        source: "memory".into(),
        start_s: 0.0,
        sample_rate_hz: 1000.0,
        channels: vec![
            Channel {
                name: "force".into(),
                unit: "N".into(),
                values: (0..100).map(|j| (0.1 * j as f64).cos()).collect(),
            },
            Channel {
                name: "tip".into(),
                unit: "m".into(),
                values: (0..100).map(|j| 1e-5 * (0.1 * j as f64).sin()).collect(),
            },
        ],
    };
    plot_time_records(&dir.join("t.svg"), "steady state", &records, "m").unwrap();
    let text = svg(&dir.join("t.svg"));
    assert!(text.contains("Displacement (m)") && text.contains("Time (s)"));
    assert_eq!(text.matches("stroke-width=\"2\"").count(), 1 + 1, "the tip only, not the force");
    let msg = plot_time_records(&dir.join("v.svg"), "t", &records, "m_s").unwrap_err().to_string();
    assert_eq!(msg, "memory: no channel in m_s to plot (the units are [\"N\", \"m\"])");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn measured_markers_are_drawn_over_the_simulated_line() {
    let dir = scratch_dir("plot-compare");
    let f: Vec<f64> = (0..50).map(|i| 100.0 + i as f64).collect();
    let a: Vec<f64> = f.iter().map(|x| 1.0 / (1.0 + ((x - 125.0) / 3.0).powi(2))).collect();
    let measured = [MeasuredCurve { label: "test".into(), frequency_hz: f.clone(), amplitude: a.clone() }];
    let path = dir.join("c.svg");
    plot_comparison(&path, "tip at 2 N", "m_s2_per_N", &(f, a), &measured).unwrap();
    let text = svg(&path);
    // In SVG what comes later is drawn on top: every marker after the simulated line.
    let line = text.find("<polyline").expect("the simulated line");
    let first_marker = text.find("<circle").expect("markers");
    assert!(first_marker > line, "markers drawn under the line");
    // 50 filled markers, 50 rings, 1 legend marker.
    assert_eq!(text.matches("<circle").count(), 101);
    assert!(text.contains("m/s² / N"), "the unit on the axis");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn unstable_stretches_are_drawn_dashed_and_bifurcations_marked() {
    use stickslip_io::output::{BifurcationRecord, PointStability};
    let dir = scratch_dir("plot-unstable");
    let mut levels = levels();
    // The middle level unstable between 240 and 260 Hz, with a fold at each end.
    let unstable = |f: f64| (240.0..=260.0).contains(&f);
    for p in &mut levels[1].points {
        let stable = !unstable(p.frequency_hz);
        p.stability = Some(PointStability { stable, exponent_re: if stable { -1.0 } else { 1.0 }, exponent_im: 0.0 });
    }
    for f in [240.0, 260.0] {
        // On the curve: the point's harmonics (its |X₁| is (|X₁|/F) × F).
        let point = &levels[1].points.iter().find(|p| p.frequency_hz == f).unwrap().outputs[0];
        let harmonics = point.harmonics.clone();
        levels[1].bifurcations.push(BifurcationRecord {
            level_n: 1000.0,
            kind: "fold".into(),
            frequency_hz: f,
            harmonics: vec![("mass".into(), harmonics)],
            exponent_im: 0.0,
            located: true,
        });
    }
    let amplitude = plot_frfs(&dir, &levels, PlotFormat::Svg).unwrap();
    let phase = plot_frf_phases(&dir, &levels, PlotFormat::Svg).unwrap();
    for path in [&amplitude[0], &phase[0]] {
        let text = svg(path);
        // Solid, a curve is one polyline; dashed, the stretch is drawn as 8 px dashes with
        // 6 px gaps: many more lines of the curves' width than the 3 + 3 of stable curves.
        let wide = text.matches("stroke-width=\"2\"").count();
        assert!(wide > 3 + 3 + 5, "{}: {wide} lines 2 px wide, no dashes", path.display());
    }
    for path in [&amplitude[0], &phase[0]] {
        let text = svg(path);
        assert!(text.contains("dashed: unstable"), "{}: the title says what dashes mean", path.display());
        // A marker is a ring of radius 5 with its kind's symbol beside it.
        assert_eq!(text.matches("<circle").count(), 2, "{}: the two folds marked", path.display());
        assert!(text.contains("r=\"5\"") && text.contains("LP"), "{}: the folds' rings and symbol", path.display());
    }
    // Without stability, the same curves are solid.
    let stable = scratch_dir("plot-stable");
    let text = svg(&plot_frfs(&stable, &self::levels(), PlotFormat::Svg).unwrap()[0]);
    assert_eq!(text.matches("stroke-width=\"2\"").count(), 3 + 3);
    assert!(!text.contains("dashed"));
    std::fs::remove_dir_all(&dir).unwrap();
    std::fs::remove_dir_all(&stable).unwrap();
}
