//! UFF 58 files we write, ASCII and binary, real and complex, even and uneven abscissa, single
//! and double precision, read back by our reader; malformed files give errors naming the line.
//!
//! With `STICKSLIP_UFF_OUT=DIR` the written files are kept in DIR with `expected.csv` (what pyuff
//! must read from each), for `scripts/check_uff_pyuff.sh`.
use std::path::PathBuf;

use num_complex::Complex64;
use stickslip_io::uff::{self, Abscissa, Dataset58, Encoding, Ordinate, Precision, UffError};

/// The 16 combinations of encoding, ordinate, spacing and precision, on 23 points (not a
/// multiple of any line's field count, so partial last lines are exercised).
fn cases() -> Vec<(String, Encoding, Dataset58)> {
    let n = 23;
    let x: Vec<f64> = (0..n).map(|i| 10.0 + 0.5 * i as f64 + 0.01 * (i * i) as f64).collect();
    let real: Vec<f64> = (0..n).map(|i| (0.37 * i as f64).sin() * 10f64.powi(i % 7 - 3)).collect();
    let complex: Vec<Complex64> =
        real.iter().enumerate().map(|(i, &r)| Complex64::new(r, -0.3 * r + i as f64 * 1e-3)).collect();
    let mut out = Vec::new();
    for (enc, enc_name) in [(Encoding::Ascii, "ascii"), (Encoding::Binary, "binary")] {
        for precision in [Precision::Single, Precision::Double] {
            for even in [true, false] {
                for is_complex in [false, true] {
                    let name = format!(
                        "{enc_name}_{}_{}_{}",
                        if is_complex { "complex" } else { "real" },
                        if even { "even" } else { "uneven" },
                        if precision == Precision::Single { "single" } else { "double" }
                    );
                    let mut d = if is_complex {
                        Dataset58::frf(&name, "m/s^2", x.clone(), complex.clone())
                    } else {
                        Dataset58::time_record(&name, "m/s^2", 1e-4, real.clone())
                    };
                    d.precision = precision;
                    d.abscissa = if even {
                        Abscissa::Even { min: 0.25, increment: 1.5e-3 }
                    } else {
                        Abscissa::Uneven(x.clone())
                    };
                    d.response_node = 12;
                    d.response_direction = 3;
                    d.reference_node = 1;
                    d.reference_direction = -3;
                    out.push((name, enc, d));
                }
            }
        }
    }
    out
}

/// Relative accuracy of what a format stores: ASCII E13.5 keeps 6 significant digits (half a
/// unit of the last: 5e-6), E20.12 13 digits (5e-13), binary single an f32 (6e-8), binary double
/// everything. The abscissa of uneven double ASCII records is E13.5 by the standard.
fn tolerances(enc: Encoding, p: Precision) -> (f64, f64) {
    match (enc, p) {
        (Encoding::Ascii, Precision::Single) => (5e-6, 5e-6),
        (Encoding::Ascii, Precision::Double) => (5e-13, 5e-6),
        (Encoding::Binary, Precision::Single) => (6e-8, 6e-8),
        (Encoding::Binary, Precision::Double) => (0.0, 0.0),
    }
}

#[test]
fn written_files_read_back_within_the_precision_of_their_format() {
    let keep = std::env::var_os("STICKSLIP_UFF_OUT").map(PathBuf::from);
    let dir =
        keep.clone().unwrap_or_else(|| std::env::temp_dir().join(format!("stickslip-uff-{}", std::process::id())));
    std::fs::create_dir_all(&dir).unwrap();
    let mut expected =
        String::from("file,binary,precision,num_pts,x_first,x_last,first_re,first_im,last_re,last_im,sum_re,sum_im\n");
    for (name, enc, d) in cases() {
        let path = dir.join(format!("{name}.uff"));
        uff::write(&path, std::slice::from_ref(&d), enc).unwrap();
        let back = uff::read(&path).unwrap();
        assert!(back.warnings.is_empty() && back.skipped.is_empty(), "{name}");
        let r = &back.datasets[0];
        assert_eq!(r.len(), d.len(), "{name}");
        assert_eq!(r.precision, d.precision, "{name}");
        assert_eq!((r.function_type, r.ids[0].as_str()), (d.function_type, name.as_str()));
        assert_eq!((r.response_node, r.response_direction, r.reference_node, r.reference_direction), (12, 3, 1, -3));
        assert_eq!(r.ordinate_axis.units, "m/s^2");
        let (tol_y, tol_x) = tolerances(enc, d.precision);
        for (a, b) in r.x().iter().zip(d.x()) {
            assert!((a - b).abs() <= tol_x * b.abs(), "{name}: x {a} vs {b}");
        }
        let as_complex = |o: &Ordinate| match o {
            Ordinate::Real(v) => v.iter().map(|&x| Complex64::new(x, 0.0)).collect::<Vec<_>>(),
            Ordinate::Complex(v) => v.clone(),
        };
        assert_eq!(matches!(r.ordinate, Ordinate::Complex(_)), matches!(d.ordinate, Ordinate::Complex(_)), "{name}");
        let (got, want) = (as_complex(&r.ordinate), as_complex(&d.ordinate));
        for (a, b) in got.iter().zip(&want) {
            assert!((a.re - b.re).abs() <= tol_y * b.re.abs(), "{name}: {a} vs {b}");
            assert!((a.im - b.im).abs() <= tol_y * b.im.abs(), "{name}: {a} vs {b}");
        }
        let x = r.x();
        let sum: Complex64 = got.iter().sum();
        expected.push_str(&format!(
            "{name}.uff,{},{},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}\n",
            u8::from(enc == Encoding::Binary),
            if d.precision == Precision::Single { "single" } else { "double" },
            r.len(),
            x[0],
            x[x.len() - 1],
            got[0].re,
            got[0].im,
            got[got.len() - 1].re,
            got[got.len() - 1].im,
            sum.re,
            sum.im
        ));
    }
    // Several datasets in one file, mixed types, read back in order.
    let all: Vec<Dataset58> = cases().into_iter().filter(|c| c.1 == Encoding::Ascii).map(|c| c.2).collect();
    let bytes = uff::to_bytes(&all, Encoding::Ascii).unwrap();
    let back = uff::parse(&bytes, "several.uff").unwrap();
    assert_eq!(back.datasets.len(), all.len());
    for (a, b) in back.datasets.iter().zip(&all) {
        assert_eq!(a.ids[0], b.ids[0]);
    }
    if keep.is_some() {
        std::fs::write(dir.join("expected.csv"), expected).unwrap();
    } else {
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

fn header(code: &str, points: &str) -> String {
    format!(
        "    -1\n    58\nname\nNONE\nNONE\nNONE\nNONE\n    1         0    0         0 NONE               0   0 NONE               0   0\n{code:>10}{points:>10}         1  0.00000E+00  1.00000E-03  0.00000E+00\n        17    0    0    0 Time                 s\n         1    0    0    0 a                    m/s^2\n         0    0    0    0 NONE                 NONE\n         0    0    0    0 NONE                 NONE\n"
    )
}

#[test]
fn malformed_files_give_errors_naming_file_and_line() {
    // Unknown ordinate data type.
    let text = header("3", "2") + "  1.00000E+00  2.00000E+00\n    -1\n";
    let e = uff::parse(text.as_bytes(), "bad.uff").unwrap_err();
    assert!(matches!(e, UffError::OrdinateType { line: 9, code: 3, .. }), "{e:?}");
    assert!(e.to_string().starts_with("bad.uff:9:"), "{e}");
    // A value that is not a number.
    let text = header("2", "2") + "  1.00000E+00  2.0000xE+00\n    -1\n";
    let e = uff::parse(text.as_bytes(), "bad.uff").unwrap_err();
    assert!(e.to_string().contains("bad.uff:14:") && e.to_string().contains("2.0000xE+00"), "{e}");
    // Not UFF at all.
    let e = uff::parse(b"time_s,a_m\n0,1\n", "notuff.csv").unwrap_err();
    assert!(e.to_string().contains("notuff.csv:1:") && e.to_string().contains("-1"), "{e}");
    // Binary data shorter than the point count says.
    let d = Dataset58::time_record("a", "m", 1e-3, vec![1.0, 2.0, 3.0]);
    let mut bytes = uff::to_bytes(&[d], Encoding::Binary).unwrap();
    let text = String::from_utf8_lossy(&bytes).into_owned();
    let at = text.find("         3         1").unwrap();
    bytes[at + 9] = b'4';
    let e = uff::parse(&bytes, "short.uff").unwrap_err();
    assert!(e.to_string().contains("short.uff:") && e.to_string().contains("4 points"), "{e}");
    // An unclosed dataset.
    let text = header("2", "2") + "  1.00000E+00  2.00000E+00\n";
    assert!(uff::parse(text.as_bytes(), "open.uff").unwrap_err().to_string().contains("not closed"));
}
