//! The UFF 58 sample files of pyuff read with the values pyuff 2.5.8 reads
//! (tests/data/uff/summary_pyuff_2.5.8.txt: number of points, first/last abscissa, first/last
//! ordinate, sum of the ordinate).
use std::path::PathBuf;

use num_complex::Complex64;
use stickslip_io::uff::{self, Ordinate, Precision, UffError, UffWarning};

fn sample(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/uff").join(name)
}

/// Values of the summary for one real dataset.
struct Expected {
    file: &'static str,
    function_type: i32,
    precision: Precision,
    len: usize,
    x_first: f64,
    x_last: f64,
    first: f64,
    last: f64,
    sum: f64,
    id1: &'static str,
}

// Both read the same decimal or binary values into f64 and differ only in summation order:
// 1e-12 relative to the sum of |values| bounds the rounding of ~1e5 additions.
fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-12 * scale
}

fn check_real(e: &Expected) {
    let f = uff::read(&sample(e.file)).unwrap();
    assert_eq!(f.datasets.len(), 1, "{}", e.file);
    let d = &f.datasets[0];
    assert_eq!(d.function_type, e.function_type, "{}", e.file);
    assert_eq!(d.precision, e.precision, "{}", e.file);
    assert_eq!(d.ids[0], e.id1, "{}", e.file);
    let Ordinate::Real(v) = &d.ordinate else { panic!("{}: expected real data", e.file) };
    assert_eq!(v.len(), e.len, "{}", e.file);
    let x = d.x();
    // The abscissa is min + i·inc computed the same way: equal to the last bit or two.
    assert!((x[0] - e.x_first).abs() <= 1e-15 * e.x_last.abs(), "{}: x0 {}", e.file, x[0]);
    assert!((x[x.len() - 1] - e.x_last).abs() <= 1e-14 * e.x_last.abs(), "{}: x-1 {}", e.file, x[x.len() - 1]);
    // First and last values: the same decimal (or binary) number, read exactly.
    assert_eq!(v[0], e.first, "{}", e.file);
    assert_eq!(v[v.len() - 1], e.last, "{}", e.file);
    let abs_sum: f64 = v.iter().map(|a| a.abs()).sum();
    let sum: f64 = v.iter().sum();
    assert!(close(sum, e.sum, abs_sum), "{}: sum {sum} vs {}", e.file, e.sum);
}

#[test]
fn ascii_single_precision_time_record() {
    check_real(&Expected {
        file: "Sample_UFF58_ascii.uff",
        function_type: 1,
        precision: Precision::Single,
        len: 79292,
        x_first: 0.0,
        x_last: 1.2098855108,
        first: -0.0147553,
        last: -0.00431469,
        sum: 5.715039728042096,
        id1: "Mic 01.0Scalar",
    });
}

#[test]
fn binary_single_precision_time_record() {
    check_real(&Expected {
        file: "Sample_UFF58b_bin.uff",
        function_type: 1,
        precision: Precision::Single,
        len: 79292,
        x_first: 0.0,
        x_last: 1.2098855108,
        first: -0.014755260199308395,
        last: -0.004314688965678215,
        sum: 5.715040058740556,
        id1: "Mic 01.0Scalar",
    });
}

#[test]
fn binary_double_precision_time_record() {
    check_real(&Expected {
        file: "binary8byte.uff",
        function_type: 1,
        precision: Precision::Double,
        len: 250,
        x_first: 0.0,
        x_last: 2.49,
        first: 0.0,
        last: 0.3090193569660187,
        sum: 6.313748425276373,
        id1: "NONE",
    });
    let d = &uff::read(&sample("binary8byte.uff")).unwrap().datasets[0];
    assert_eq!((d.response_node, d.response_direction), (1, 0));
    assert_eq!(d.response_entity, "sine 5 Hz");
}

#[test]
fn partly_filled_last_line() {
    check_real(&Expected {
        file: "time-history-not-all-columns-filled.uff",
        function_type: 1,
        precision: Precision::Single,
        len: 13,
        x_first: 0.0,
        x_last: 0.0006000000000000001,
        first: -3.81956,
        last: -5.84096,
        sum: -47.70822999999999,
        id1: "1x : m/s²",
    });
}

#[test]
fn truncated_record_reads_what_is_there_and_warns() {
    check_real(&Expected {
        file: "dataset_milestone_in_header.uff",
        function_type: 1,
        precision: Precision::Single,
        len: 42,
        x_first: 1.11858e-05,
        x_last: 0.000811965,
        first: -0.00673633,
        last: 0.00539653,
        sum: -0.04821587846,
        id1: "M.REDON   [.../20EH0456 2017-12-06 Creteil Wet50C 14mm TorqueJLR 36V BIPO1/1 :1]",
    });
    let f = uff::read(&sample("dataset_milestone_in_header.uff")).unwrap();
    assert_eq!(f.warnings, vec![UffWarning::PointCount { line: 1, declared: 2508876, found: 42 }]);
    assert_eq!((f.datasets[0].reference_node, f.datasets[0].reference_direction), (-1, 0));
}

fn check_complex(
    file: &str,
    function_type: i32,
    len: usize,
    x_last: f64,
    first: Complex64,
    last: Complex64,
    sum: Complex64,
) {
    let f = uff::read(&sample(file)).unwrap();
    let d = &f.datasets[0];
    assert_eq!(d.function_type, function_type, "{file}");
    let Ordinate::Complex(v) = &d.ordinate else { panic!("{file}: expected complex data") };
    assert_eq!(v.len(), len, "{file}");
    let x = d.x();
    assert_eq!(x[0], 0.0);
    assert!((x[len - 1] - x_last).abs() <= 1e-15 * x_last, "{file}: {}", x[len - 1]);
    assert_eq!(v[0], first, "{file}");
    assert_eq!(v[len - 1], last, "{file}");
    let s: Complex64 = v.iter().sum();
    let scale: f64 = v.iter().map(|z| z.norm()).sum();
    assert!((s - sum).norm() <= 1e-12 * scale, "{file}: sum {s} vs {sum}");
}

#[test]
fn complex_frf_with_non_ascii_header() {
    check_complex(
        "non_ascii_header.uff",
        4,
        6,
        0.9765649999999999,
        Complex64::new(0.407994, 0.0),
        Complex64::new(3.75037, 2.93363),
        Complex64::new(2.0227436, 4.748306915000001),
    );
    let d = &uff::read(&sample("non_ascii_header.uff")).unwrap().datasets[0];
    assert_eq!(d.ids[0], "ref6_23_Mar");
    assert_eq!(d.abscissa_axis.units, "Hz");
}

#[test]
fn complex_uneven_power_spectral_density() {
    check_complex(
        "sample_dataset58_psd.uff",
        9,
        3201,
        3200.0,
        Complex64::new(0.0, 0.0),
        Complex64::new(2.634827e-10, 0.0),
        Complex64::new(0.31306925539025443, 0.0),
    );
}

#[test]
fn a_file_without_dataset_58_names_the_types_it_holds() {
    let e = uff::read(&sample("heat_engine_housing.uff")).unwrap_err();
    match &e {
        UffError::NoDataset58 { found, .. } => assert_eq!(found, &vec![151, 164, 2411, 2412, 2414]),
        other => panic!("expected NoDataset58, got {other:?}"),
    }
    let msg = e.to_string();
    assert!(msg.contains("heat_engine_housing.uff") && msg.contains("dataset 58"), "{msg}");
}
