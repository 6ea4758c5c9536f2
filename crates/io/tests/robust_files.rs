//! Damaged inputs and non-finite results (issue 9): readers refuse non-finite samples and
//! unordered abscissas, writers refuse to write NaN or infinity, plot axes stay finite.

use std::path::PathBuf;

use num_complex::Complex64;
use stickslip_io::output::{write_frf_csv, write_frf_npz, write_point_csv, LevelResult, OutputRecord, PointRecord};
use stickslip_io::plot::{linear_axis, log_axis};
use stickslip_io::records::{self, FrfCurve, FrfSet};
use stickslip_io::uff::{self, Dataset58, Encoding};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("stickslip-robust-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn uff_readers_refuse_non_finite_values_and_unordered_frequencies() {
    let frf = Dataset58::frf("tip", "m/N", vec![10.0, 20.0, 30.0], vec![Complex64::new(1.0, 0.5); 3]);
    let text = String::from_utf8(uff::to_bytes(&[frf], Encoding::Ascii).unwrap()).unwrap();
    let data_line = text.lines().position(|l| l.contains("1.00000E+01")).unwrap() + 1;
    let nan = text.replacen("  1.000000000000E+00", "                 NaN", 1);
    let e = uff::parse(nan.as_bytes(), "nan.uff").unwrap_err().to_string();
    assert!(e.starts_with(&format!("nan.uff:{data_line}: `NaN` (columns 14-33) is not a finite number")), "{e}");
    let unordered = text.replacen("2.00000E+01", "5.00000E+00", 1);
    let e = uff::parse(unordered.as_bytes(), "order.uff").unwrap_err().to_string();
    assert!(
        e.starts_with(&format!("order.uff:{}: abscissa value 5 of point 2 does not increase on 10", data_line + 1)),
        "{e}"
    );
    // Binary: a NaN ordinate and a point count of 2^62 (once an overflow in the byte count).
    let mut d = Dataset58::time_record("force", "N", 1e-3, vec![1.0, 2.0, 3.0]);
    d.abscissa = uff::Abscissa::Even { min: 0.0, increment: 1e-3 };
    let mut bytes = uff::to_bytes(&[d], Encoding::Binary).unwrap();
    let at = bytes.windows(8).rposition(|w| w == 2.0f64.to_le_bytes()).unwrap();
    bytes[at..at + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    let e = uff::parse(&bytes, "bin.uff").unwrap_err().to_string();
    assert!(e.contains("bin.uff:") && e.contains("value 2 of the binary data (point 2) is NaN"), "{e}");
    let text = String::from_utf8_lossy(&bytes).into_owned();
    let record7 = text.lines().find(|l| l.starts_with("         4         3")).unwrap().to_string();
    let huge = record7.replacen("         4         3", "         44611686018427387904", 1);
    let bytes = String::from_utf8_lossy(
        &uff::to_bytes(&[Dataset58::time_record("f", "N", 1e-3, vec![1.0])], Encoding::Binary).unwrap(),
    )
    .replacen(&record7.replacen("         3", "         1", 1), &huge, 1);
    let _ = uff::parse(bytes.as_bytes(), "huge.uff"); // no overflow, no abort
                                                      // Time records from UFF: the even increment must advance.
    let mut d = Dataset58::time_record("force", "N", 0.0, vec![1.0, 2.0]);
    d.abscissa = uff::Abscissa::Even { min: 0.0, increment: 0.0 };
    let text = String::from_utf8(uff::to_bytes(&[d], Encoding::Ascii).unwrap()).unwrap();
    let e = uff::parse(text.as_bytes(), "dt.uff").unwrap_err().to_string();
    assert!(e.starts_with("dt.uff:9: abscissa increment 0 of 2 points: it must be > 0"), "{e}");
}

#[test]
fn writers_refuse_non_finite_values_naming_the_quantity_and_where() {
    let dir = scratch("writers");
    let point = |f: f64, disp: f64| PointRecord {
        frequency_hz: f,
        iterations: 3,
        residual: 1e-9,
        outputs: vec![OutputRecord {
            name: "tip".into(),
            disp_frf: disp,
            accel_frf: 1.0,
            peak: 1.0,
            harmonics: vec![(0.0, 0.0), (1.0, 0.1)],
            disp: vec![1.0, f64::INFINITY],
            vel: vec![0.0, 1.0],
        }],
        elements: vec![],
        input_energy_j: 0.0,
        viscous_energy_j: 0.0,
        stability: None,
    };
    let levels = vec![LevelResult {
        level_n: 10.0,
        points: vec![point(5.0, 1e-6), point(6.0, f64::NAN)],
        peaks: vec![],
        bifurcations: vec![],
    }];
    for (name, result) in [
        ("frf.csv", write_frf_csv(&dir.join("frf.csv"), &levels)),
        ("frf.npz", write_frf_npz(&dir.join("frf.npz"), &levels)),
    ] {
        let e = result.unwrap_err().to_string();
        assert!(
            e.contains(name)
                && e.contains("column `tip_disp_frf_m_per_N` is NaN at level 10 N, point at 6 Hz: refusing to write"),
            "{e}"
        );
        assert!(!dir.join(name).exists(), "{name} written");
    }
    let e = write_point_csv(&dir.join("p.csv"), &levels[0].points[0]).unwrap_err().to_string();
    assert!(e.contains("series `tip_disp_m` is inf at sample 1 of the point at 5 Hz"), "{e}");
    let set = FrfSet {
        source: "s".into(),
        level_n: Some(1.0),
        frequency_hz: vec![1.0, 2.0],
        curves: vec![FrfCurve {
            name: "tip".into(),
            unit: "m_per_N".into(),
            values: vec![Complex64::new(1.0, 0.0), Complex64::new(f64::NAN, 0.0)],
            has_phase: true,
        }],
    };
    let e = records::write_frf_csv(&dir.join("m.csv"), std::slice::from_ref(&set)).unwrap_err().to_string();
    assert!(e.contains("m.csv: the real part of FRF `tip` is NaN at level 1 N, 2 Hz"), "{e}");
    let e = uff::to_bytes(&records::frf_set_to_uff(&set), Encoding::Ascii).unwrap_err().to_string();
    assert!(e.contains("dataset `tip`: ordinate of point 2 is NaN+0i: refusing to write"), "{e}");
    let e = records::write_table(&dir.join("t.csv"), &["a".into(), "b".into()], &[vec![1.0, f64::NEG_INFINITY]])
        .unwrap_err()
        .to_string();
    assert!(e.contains("t.csv: column `b` is -inf at data row 1"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn plot_axes_are_finite_whatever_the_finite_data() {
    for (lo, hi) in [(1e-300, 1e308), (1e308, 1e308), (f64::MIN_POSITIVE, f64::MAX), (5e-324, 5e-324)] {
        let r = log_axis(lo, hi);
        assert!(r.start > 0.0 && r.end.is_finite() && r.start < r.end, "{lo} {hi}: {r:?}");
        assert!((r.end / r.start).log10() < 32.0, "{lo} {hi}: {r:?}");
    }
    for (lo, hi) in [(-1e308, 1e308), (1e20, 1e20 + 16384.0), (0.0, 0.0), (f64::MAX, f64::MAX), (-5.0, -5.0)] {
        let r = linear_axis(lo, hi);
        assert!(
            r.start.is_finite() && r.end.is_finite() && r.end - r.start >= 1e-9 * r.start.abs().max(r.end.abs()),
            "{lo} {hi}: {r:?}"
        );
    }
}
