//! Parameter studies on the Table 6 example: keys, designs, the samples' studies, shard
//! tables and their merge.

use std::path::PathBuf;

use stickslip_io::params::files::{merge, write_shard, Shard};
use stickslip_io::params::{ParamStudy, Vary};
use stickslip_io::study::Study;

fn example() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/jenkins-1dof/study.toml")
}

fn table() -> toml::Table {
    toml::from_str(&std::fs::read_to_string(example()).unwrap()).unwrap()
}

fn study(varies: &[&str], samples: Option<usize>) -> Result<ParamStudy, String> {
    let varies: Vec<Vary> =
        varies.iter().map(|v| Vary::parse(v).map_err(|e| e.to_string())).collect::<Result<_, _>>()?;
    ParamStudy::new(table(), example(), &varies, samples, 3).map_err(|e| e.to_string())
}

#[test]
fn a_sample_is_the_study_with_its_values_written_at_the_keys() {
    let p = study(&["joint.joint.threshold=800,1200", "excitation.levels[1]=500,600", "damping.alpha=20:30:2"], None)
        .unwrap();
    assert_eq!(p.samples.len(), 8);
    let s = Study::from_table(&p.sample_table(&p.samples[5]).unwrap(), example()).unwrap();
    // Sample 5 of the grid (last key fastest): threshold 1200, level 500, alpha 30.
    assert_eq!(p.samples[5], vec![1200.0, 500.0, 30.0]);
    match &s.joints[0].law {
        stickslip_io::study::LawSpec::Jenkins { threshold, .. } => assert_eq!(*threshold, 1200.0),
        other => panic!("expected a Jenkins joint, got {other:?}"),
    }
    assert_eq!(s.excitation.levels, vec![100.0, 500.0, 3000.0, 10000.0]);
    assert!(matches!(s.damping, stickslip_io::study::DampingSpec::Rayleigh { alpha, .. } if alpha == 30.0));
}

#[test]
fn keys_that_are_missing_or_not_numbers_and_refused_values_are_named() {
    let cases = [
        ("joint.blade9.threshold=1:2", "--vary joint.blade9.threshold: `joint` has no table named \"blade9\" (names: \"joint\")"),
        ("output.mass.dof=1:2", "--vary output.mass.dof: holds a string \"M\", not a number"),
        ("excitation.levels[9]=1:2", "--vary excitation.levels[9]: index 9 is out of range: the list has 4 value(s)"),
        ("reduction.modes=1:2", "--vary reduction.modes: the study has no `reduction`"),
        (
            "joint.joint.threshold=-1:2",
            "--vary joint.joint.threshold: the value -1 is not accepted: [[joint]] \"joint\": threshold must be > 0 N, got -1",
        ),
        ("damping.alpah=1:2", "--vary damping.alpah: the value 1 is not accepted: [damping]: unknown field `alpah`"),
    ];
    for (spec, expected) in cases {
        let e = study(&[spec], Some(4)).unwrap_err();
        assert!(e.starts_with(expected), "{spec}: got {e}");
    }
}

#[test]
fn an_integer_key_takes_rounded_samples_and_a_missing_key_of_a_section_is_added() {
    let p = study(&["harmonic_balance.harmonics=3:7", "damping.beta=0:1e-6"], Some(5)).unwrap();
    for row in &p.samples {
        assert_eq!(row[0], row[0].round());
        assert!((3.0..=7.0).contains(&row[0]) && (0.0..=1e-6).contains(&row[1]));
        let s = Study::from_table(&p.sample_table(row).unwrap(), example()).unwrap();
        assert_eq!(s.hbm.harmonics as f64, row[0]);
    }
}

#[test]
fn shards_merge_into_the_table_of_the_whole_and_refuse_mixing() {
    let p = study(&["joint.joint.threshold=800:1200"], Some(5)).unwrap();
    // Outcomes made by hand (no solve): a failed sample with a quote and a line break.
    let outcome = |i: usize| stickslip_io::params::SampleOutcome {
        index: i,
        values: p.samples[i].clone(),
        rows: Vec::new(),
        levels: None,
        error: Some(format!("sample {i}: \"bad\"\nsecond line")),
    };
    let dir = std::env::temp_dir().join(format!("stickslip-params-{}", std::process::id()));
    let (whole, parts) = (dir.join("whole"), dir.join("parts"));
    std::fs::create_dir_all(&whole).unwrap();
    std::fs::create_dir_all(&parts).unwrap();
    write_shard(&whole, &p, Shard { index: 1, count: 1 }, &(0..5).map(outcome).collect::<Vec<_>>()).unwrap();
    let shards = [Shard::parse("1/2").unwrap(), Shard::parse("2/2").unwrap()];
    assert_eq!((shards[0].range(5), shards[1].range(5)), (0..2, 2..5));
    write_shard(&parts, &p, shards[1], &shards[1].range(5).map(outcome).collect::<Vec<_>>()).unwrap();
    let e = merge(&parts).unwrap_err().to_string();
    assert!(e.ends_with("1 of 2 shard(s) missing: shard-1-of-2.csv"), "{e}");
    write_shard(&parts, &p, shards[0], &shards[0].range(5).map(outcome).collect::<Vec<_>>()).unwrap();
    assert_eq!(merge(&whole).unwrap().1, 5);
    assert_eq!(merge(&parts).unwrap().1, 5);
    let read = |d: &PathBuf| std::fs::read_to_string(d.join("samples.csv")).unwrap();
    assert_eq!(read(&whole), read(&parts));
    // Another design (another seed) in the same folder is refused.
    let other =
        ParamStudy::new(table(), example(), &[Vary::parse("joint.joint.threshold=800:1200").unwrap()], Some(5), 4)
            .unwrap();
    write_shard(&parts, &other, Shard { index: 1, count: 2 }, &[]).unwrap();
    let e = merge(&parts).unwrap_err().to_string();
    assert!(e.contains("refusing to mix them"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
