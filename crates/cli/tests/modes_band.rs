//! `stickslip modes --band F1:F2`: every mode in a frequency band, against `--count` on the
//! same deck; an empty band, bad ends and `--band` with `--count`.
mod common;
use std::fmt::Write as _;

use common::{columns, scratch, stickslip};

/// A free steel bar of 8 hexahedra (2 × 1 × 4 cells of 0.1 m cubes, no boundary condition:
/// 6 rigid-body modes first).
fn bar_inp() -> String {
    let (nx, ny, nz) = (2, 1, 4);
    let id = |i: usize, j: usize, k: usize| 1 + i + (nx + 1) * (j + (ny + 1) * k);
    let mut s = String::from("*NODE\n");
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                writeln!(s, "{}, {}, {}, {}", id(i, j, k), 0.1 * i as f64, 0.1 * j as f64, 0.1 * k as f64).unwrap();
            }
        }
    }
    s.push_str("*ELEMENT, TYPE=C3D8, ELSET=BAR\n");
    let mut e = 0;
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                e += 1;
                let n = [
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ];
                writeln!(s, "{e}, {}", n.map(|x| x.to_string()).join(", ")).unwrap();
            }
        }
    }
    s.push_str("*MATERIAL, NAME=STEEL\n*ELASTIC\n210e9, 0.3\n*DENSITY\n7800.\n");
    s.push_str("*SOLID SECTION, ELSET=BAR, MATERIAL=STEEL\n");
    s
}

fn run(dir: &std::path::Path, out: &str, options: &[&str]) -> std::process::Output {
    stickslip().arg("modes").arg(dir.join("bar.inp")).args(options).arg("--out").arg(dir.join(out)).output().unwrap()
}

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn band_gives_every_mode_in_it_and_no_other() {
    let dir = scratch("modes-band");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("bar.inp"), bar_inp()).unwrap();
    let o = run(&dir, "all", &["--count", "40"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let all = columns(&dir.join("all/modes.csv"))["frequency_hz"].clone();
    assert_eq!(all.len(), 40);
    // Band ends halfway between distinct frequencies.
    let gap = |mut i: usize| {
        while all[i + 1] - all[i] < 1e-6 * all[i + 1] {
            i += 1;
        }
        0.5 * (all[i] + all[i + 1])
    };
    for (lo, hi) in [(0.0, gap(20)), (gap(10), gap(35)), (gap(6), gap(7))] {
        let o = run(&dir, "band", &["--band", &format!("{lo}:{hi}")]);
        assert!(o.status.success(), "{}", stderr(&o));
        let got = columns(&dir.join("band/modes.csv"));
        let expected: Vec<f64> = all.iter().copied().filter(|f| *f >= lo && *f <= hi).collect();
        assert_eq!(got["frequency_hz"].len(), expected.len(), "band {lo}:{hi}: {:?}", got["frequency_hz"]);
        for (g, e) in got["frequency_hz"].iter().zip(&expected) {
            // Rigid-body modes at round-off (~1e-4 Hz) in both; elastic ones to 1e-9.
            if *e < 1.0 {
                assert!(*g < 1.0, "band {lo}:{hi}: rigid-body mode at {g} Hz");
            } else {
                assert!((g - e).abs() <= 1e-9 * e, "band {lo}:{hi}: {g} vs {e} Hz");
            }
        }
        assert!(got["residual"].iter().all(|r| *r < 1e-6), "{:?}", got["residual"]);
    }
    // A band between two modes: an empty table and a message, not an error.
    let (a, b) = (all[20], all[21]);
    assert!(b > a * 1.001);
    let o = run(&dir, "empty", &["--band", &format!("{}:{}", a + 0.3 * (b - a), a + 0.6 * (b - a))]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("no mode between"), "{}", stderr(&o));
    let text = std::fs::read_to_string(dir.join("empty/modes.csv")).unwrap();
    assert_eq!(text.lines().count(), 1, "{text}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_bands_are_refused_naming_the_option() {
    let dir = scratch("modes-band-bad");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("bar.inp"), bar_inp()).unwrap();
    for (band, says) in [
        ("-10:100", "--band -10:100: the lower end is negative"),
        ("300:100", "--band 300:100: the ends are reversed"),
        ("0:inf", "--band 0:inf: the ends must be finite"),
        ("nan:100", "--band nan:100: the ends must be finite"),
        ("100", "--band 100: expected two frequencies in Hz, F1:F2"),
    ] {
        let o = run(&dir, "bad", &["--band", band]);
        assert!(!o.status.success(), "{band} accepted");
        assert!(stderr(&o).contains(says), "{band}: {}", stderr(&o));
    }
    for other in [["--count", "5"], ["--shift", "100"]] {
        let o = run(&dir, "bad", &["--band", "0:100", other[0], other[1]]);
        assert!(!o.status.success(), "--band with {} accepted", other[0]);
        let msg = stderr(&o);
        assert!(msg.contains("--band") && msg.contains(other[0]) && msg.contains("cannot be used with"), "{msg}");
    }
    assert!(!dir.join("bad/modes.csv").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
