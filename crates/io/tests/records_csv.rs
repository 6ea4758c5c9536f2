//! Time records and measured FRFs as CSV, and their exchange with UFF 58.
use std::path::PathBuf;

use num_complex::Complex64;
use stickslip_io::records::{
    self, frf_set_to_uff, frf_sets_from_uff, time_records_from_uff, time_records_to_uff, Channel, FrfCurve, FrfSet,
    RecordsError, TimeRecords,
};
use stickslip_io::uff::{self, Encoding};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("stickslip-records-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn sample_records() -> TimeRecords {
    let n = 50;
    TimeRecords {
        source: "memory".into(),
        start_s: 0.0,
        sample_rate_hz: 2048.0,
        channels: vec![
            Channel {
                name: "force".into(),
                unit: "N".into(),
                values: (0..n).map(|j| (0.1 * j as f64).cos()).collect(),
            },
            Channel {
                name: "top".into(),
                unit: "m_s2".into(),
                values: (0..n).map(|j| 1e-3 / (1.0 + j as f64)).collect(),
            },
        ],
    }
}

#[test]
fn time_records_round_trip_through_csv_exactly() {
    let r = sample_records();
    let path = scratch("records.csv");
    records::write_time_csv(&path, &r).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.starts_with("time_s,force_N,top_m_s2\n"), "{text}");
    let back = records::read_time_csv(&path).unwrap();
    // Shortest round-trip formatting: values come back bit for bit; the rate from the time
    // column to the rounding of the times (1e-12 relative).
    assert_eq!(back.channels, r.channels);
    assert!((back.sample_rate_hz - 2048.0).abs() < 1e-9);
    assert_eq!(back.channel("top").unwrap().unit, "m_s2");
    assert_eq!(back.channel("top_m_s2").unwrap().name, "top");
}

#[test]
fn time_records_round_trip_through_uff() {
    let r = sample_records();
    for enc in [Encoding::Ascii, Encoding::Binary] {
        let bytes = uff::to_bytes(&time_records_to_uff(&r), enc).unwrap();
        let back = time_records_from_uff(&uff::parse(&bytes, "r.uff").unwrap().datasets, "r.uff").unwrap();
        assert_eq!(back.channels.len(), 2);
        assert_eq!((back.channels[1].name.as_str(), back.channels[1].unit.as_str()), ("top", "m_s2"));
        // ASCII E20.12 keeps 13 digits (5e-13 relative); binary doubles are exact. The rate
        // passes through E13.5 (the increment 1/2048 = 4.8828125e-4 → 4.88281E-04: 5e-6).
        for (a, b) in back.channels[1].values.iter().zip(&r.channels[1].values) {
            assert!((a - b).abs() <= 5e-13 * b.abs());
        }
        assert!((back.sample_rate_hz - 2048.0).abs() < 5e-6 * 2048.0);
    }
}

#[test]
fn measured_frfs_of_several_levels_in_one_file() {
    let set = |level: f64, k: f64| FrfSet {
        source: String::new(),
        level_n: Some(level),
        frequency_hz: vec![200.0, 210.0, 220.0],
        curves: vec![FrfCurve {
            name: "top".into(),
            unit: "m_s2_per_N".into(),
            values: vec![Complex64::new(k, 0.5), Complex64::new(2.0 * k, -1.0), Complex64::new(0.5, k)],
            has_phase: true,
        }],
    };
    let sets = vec![set(70.0, 1.0), set(2910.0, 0.3)];
    let path = scratch("frf.csv");
    records::write_frf_csv(&path, &sets).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.starts_with("level_N,frequency_Hz,top_amp_m_s2_per_N,top_phase_rad\n"), "{text}");
    let back = records::read_frf_csv(&path).unwrap();
    assert_eq!(back.len(), 2);
    for (a, b) in back.iter().zip(&sets) {
        assert_eq!(a.level_n, b.level_n);
        assert_eq!(a.frequency_hz, b.frequency_hz);
        // Through amplitude and phase: 2 ulp-level rounding, 1e-15 relative.
        for (x, y) in a.curves[0].values.iter().zip(&b.curves[0].values) {
            assert!((x - y).norm() <= 1e-15 * y.norm() * 4.0, "{x} vs {y}");
        }
    }
    // And through UFF (complex FRF, listed frequencies).
    let bytes = uff::to_bytes(&frf_set_to_uff(&sets[1]), Encoding::Binary).unwrap();
    let from_uff = frf_sets_from_uff(&uff::parse(&bytes, "f.uff").unwrap().datasets, "f.uff");
    assert_eq!(from_uff[0].curves[0].values, sets[1].curves[0].values);
    assert_eq!(from_uff[0].curves[0].unit, "m_s2_per_N");
    assert_eq!(from_uff[0].frequency_hz, sets[1].frequency_hz);
    assert_eq!(from_uff[0].level_n, Some(2910.0));
}

#[test]
fn amplitude_only_frf_files_are_accepted() {
    let path = scratch("amp.csv");
    std::fs::write(&path, "frequency_Hz,base_amp_m_s2_per_N\n100,0.5\n110,0.75\n").unwrap();
    let sets = records::read_frf_csv(&path).unwrap();
    assert_eq!(sets.len(), 1);
    assert_eq!(sets[0].level_n, None);
    assert!(!sets[0].curves[0].has_phase);
    assert_eq!(sets[0].curves[0].values[1], Complex64::new(0.75, 0.0));
}

#[test]
fn bad_records_say_what_to_change() {
    let path = scratch("nonuniform.csv");
    std::fs::write(&path, "time_s,a_m\n0,1\n0.001,2\n0.0025,3\n0.003,4\n").unwrap();
    let e = records::read_time_csv(&path).unwrap_err();
    assert!(matches!(e, RecordsError::NonUniform { line: 4, .. }), "{e:?}");
    assert!(e.to_string().contains("nonuniform.csv:4") && e.to_string().contains("resample"), "{e}");

    let path = scratch("ragged.csv");
    std::fs::write(&path, "time_s,a_m,b_m\n0,1,2\n0.001,2\n").unwrap();
    let e = records::read_time_csv(&path).unwrap_err();
    assert!(e.to_string().contains("ragged.csv:3") && e.to_string().contains("2 fields"), "{e}");

    let path = scratch("notime.csv");
    std::fs::write(&path, "t,a_m\n0,1\n1,2\n").unwrap();
    assert!(records::read_time_csv(&path).unwrap_err().to_string().contains("`time_s`"));

    let r = sample_records();
    let e = r.channel("shaker").unwrap_err();
    assert!(e.to_string().contains("shaker") && e.to_string().contains("force_N"), "{e}");

    // UFF channels of unequal length cannot form one record set.
    let mut ds = time_records_to_uff(&r);
    if let uff::Ordinate::Real(v) = &mut ds[1].ordinate {
        v.pop();
    }
    let e = time_records_from_uff(&ds, "u.uff").unwrap_err();
    assert!(e.to_string().contains("49 samples") && e.to_string().contains("same sample rate and length"), "{e}");
}

#[test]
fn curves_sharing_a_name_keep_their_own_phase_columns() {
    // Displacement, velocity and acceleration FRFs of one output, as `extract` finds them in a
    // `timesim` record: once three columns were all named `tip_phase_rad`.
    let curve = |unit: &str, phase: f64| FrfCurve {
        name: "tip".into(),
        unit: unit.into(),
        values: vec![Complex64::from_polar(2.0, phase), Complex64::from_polar(3.0, phase)],
        has_phase: true,
    };
    let mid = FrfCurve { name: "mid".into(), ..curve("m_per_N", 0.25) };
    let set = FrfSet {
        source: String::new(),
        level_n: Some(2.0),
        frequency_hz: vec![100.0, 101.0],
        curves: vec![curve("m_per_N", -0.5), curve("m_s_per_N", 1.0), curve("m_s2_per_N", 2.5), mid],
    };
    let path = scratch("shared.csv");
    records::write_frf_csv(&path, std::slice::from_ref(&set)).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.starts_with(
            "level_N,frequency_Hz,tip_amp_m_per_N,tip_m_per_N_phase_rad,tip_amp_m_s_per_N,tip_m_s_per_N_phase_rad,\
             tip_amp_m_s2_per_N,tip_m_s2_per_N_phase_rad,mid_amp_m_per_N,mid_phase_rad\n"
        ),
        "{text}"
    );
    let back = records::read_frf_csv(&path).unwrap();
    for (a, b) in back[0].curves.iter().zip(&set.curves) {
        assert_eq!((&a.name, &a.unit, a.has_phase), (&b.name, &b.unit, true));
        // Each curve its own phase (-0.5, 1.0, 2.5, 0.25 rad), through amplitude and phase.
        for (x, y) in a.values.iter().zip(&b.values) {
            assert!((x - y).norm() <= 4e-15 * y.norm(), "{}: {x} vs {y}", a.unit);
        }
    }
    // One phase column for two curves of one name says which it is not.
    std::fs::write(&path, "frequency_Hz,tip_amp_m_per_N,tip_amp_m_s2_per_N,tip_phase_rad\n100,1,2,0.5\n").unwrap();
    let msg = records::read_frf_csv(&path).unwrap_err().to_string();
    assert!(msg.contains("`tip_phase_rad` is ambiguous") && msg.contains("`tip_m_per_N_phase_rad`"), "{msg}");
    // Two curves of one name and unit would write two columns alike.
    let twice = FrfSet { curves: vec![curve("m_per_N", 0.0), curve("m_per_N", 1.0)], ..set };
    let msg = records::write_frf_csv(&path, &[twice]).unwrap_err().to_string();
    assert!(msg.contains("two FRF curves named `tip` in m_per_N"), "{msg}");
}
