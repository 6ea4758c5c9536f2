//! Fuzz-style mutations of valid sample inputs for the reader property tests (shared by the
//! `fuzz_*` tests of stickslip-io and stickslip-fe): byte flips, truncation, line duplication
//! and deletion, numbers replaced by huge, NaN or negative values, words overwritten with
//! extreme binary values, random bytes inserted.
//!
//! `STICKSLIP_FUZZ_CASES` sets the number of cases per reader (default [`DEFAULT_CASES`]).
#![allow(dead_code)]

use std::time::{Duration, Instant};

use proptest::prelude::*;
use proptest::test_runner::{Config, FileFailurePersistence};

/// Cases per reader when `STICKSLIP_FUZZ_CASES` is not set: the whole suite stays well under
/// two minutes in the dev profile.
pub const DEFAULT_CASES: u32 = 3000;

/// Longest a reader may take on one small input.
pub const CASE_TIME_LIMIT: Duration = Duration::from_secs(5);

/// The proptest configuration of a fuzz target (the count printed, so that a log shows it).
pub fn config(target: &str) -> Config {
    let cases = std::env::var("STICKSLIP_FUZZ_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(DEFAULT_CASES);
    show(&format!("fuzz {target}: {cases} cases (set STICKSLIP_FUZZ_CASES for more)"));
    Config {
        cases,
        // Failures are reported with the input; no regression files are written beside the tests.
        failure_persistence: Some(Box::new(FileFailurePersistence::Off)),
        ..Config::default()
    }
}

/// Text that replaces a number: beyond every range, not finite, negative, or wrapping.
const NUMBERS: [&str; 16] = [
    "1e308",
    "-1e308",
    "1e999",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "-1",
    "0",
    "18446744073709551615",
    "9223372036854775807",
    "-9223372036854775808",
    "4294967307",
    "1e-320",
    "999999999999",
    "1.5D+400",
];

/// Eight-byte words written over binary data.
const WORDS: [u64; 8] = [
    u64::MAX,
    1 << 62,
    1 << 32,
    0x7ff8_0000_0000_0000, // NaN
    0x7ff0_0000_0000_0000, // inf
    0xfff0_0000_0000_0000, // -inf
    0,
    0x8000_0000_0000_0000,
];

#[derive(Clone, Debug)]
pub enum Mutation {
    FlipBit { at: usize, bit: u8 },
    Truncate { at: usize },
    DuplicateLine { line: usize },
    DeleteLine { line: usize },
    ReplaceNumber { which: usize, with: usize },
    OverwriteWord { at: usize, word: usize, four: bool },
    Insert { at: usize, bytes: Vec<u8> },
}

pub fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        3 => (any::<usize>(), 0u8..8).prop_map(|(at, bit)| Mutation::FlipBit { at, bit }),
        1 => any::<usize>().prop_map(|at| Mutation::Truncate { at }),
        2 => any::<usize>().prop_map(|line| Mutation::DuplicateLine { line }),
        2 => any::<usize>().prop_map(|line| Mutation::DeleteLine { line }),
        4 => (any::<usize>(), 0..NUMBERS.len()).prop_map(|(which, with)| Mutation::ReplaceNumber { which, with }),
        2 => (any::<usize>(), 0..WORDS.len(), any::<bool>()).prop_map(|(at, word, four)| Mutation::OverwriteWord { at, word, four }),
        1 => (any::<usize>(), proptest::collection::vec(any::<u8>(), 1..8)).prop_map(|(at, bytes)| Mutation::Insert { at, bytes }),
    ]
}

/// A seed index and one to four mutations.
pub fn case(seeds: usize) -> impl Strategy<Value = (usize, Vec<Mutation>)> {
    (0..seeds, proptest::collection::vec(mutation(), 1..5))
}

/// Byte ranges `[start, end)` of the lines of `b` (terminator included).
fn lines(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, &c) in b.iter().enumerate() {
        if c == b'\n' {
            out.push((start, i + 1));
            start = i + 1;
        }
    }
    if start < b.len() {
        out.push((start, b.len()));
    }
    out
}

/// Byte ranges of the numbers of `b`: runs of digits with signs, points and exponents.
fn numbers(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() {
            let mut start = i;
            if start > 0 && matches!(b[start - 1], b'-' | b'+' | b'.') {
                start -= 1;
            }
            while i < b.len() && (b[i].is_ascii_alphanumeric() || matches!(b[i], b'.' | b'+' | b'-')) {
                i += 1;
            }
            out.push((start, i));
        } else {
            i += 1;
        }
    }
    out
}

/// Apply `mutations` to `input`.
pub fn mutate(input: &[u8], mutations: &[Mutation]) -> Vec<u8> {
    let mut b = input.to_vec();
    for m in mutations {
        match m {
            Mutation::FlipBit { at, bit } if !b.is_empty() => {
                let n = b.len();
                b[at % n] ^= 1 << bit;
            }
            Mutation::Truncate { at } => b.truncate(at % (b.len() + 1)),
            Mutation::DuplicateLine { line } | Mutation::DeleteLine { line } => {
                let l = lines(&b);
                if l.is_empty() {
                    continue;
                }
                let (s, e) = l[line % l.len()];
                if matches!(m, Mutation::DeleteLine { .. }) {
                    b.drain(s..e);
                } else {
                    let copy = b[s..e].to_vec();
                    b.splice(e..e, copy);
                }
            }
            Mutation::ReplaceNumber { which, with } => {
                let n = numbers(&b);
                if n.is_empty() {
                    continue;
                }
                let (s, e) = n[which % n.len()];
                b.splice(s..e, NUMBERS[*with].bytes());
            }
            Mutation::OverwriteWord { at, word, four } => {
                let w = WORDS[*word].to_le_bytes();
                let len = if *four { 4 } else { 8 };
                if b.len() >= len {
                    let at = at % (b.len() - len + 1);
                    b[at..at + len].copy_from_slice(&w[8 - len..]);
                }
            }
            Mutation::Insert { at, bytes } => {
                let at = at % (b.len() + 1);
                b.splice(at..at, bytes.iter().copied());
            }
            _ => {}
        }
    }
    b
}

/// Run `read` on a mutated input, failing when it takes longer than [`CASE_TIME_LIMIT`].
pub fn timed<T>(what: &str, read: impl FnOnce() -> T) -> T {
    let start = Instant::now();
    let out = read();
    let took = start.elapsed();
    assert!(took < CASE_TIME_LIMIT, "{what}: the reader took {took:?}");
    out
}

/// Whether the `Debug` text of a value shows a non-finite float (`NaN`, `inf`, `-inf` as a
/// whole token: quoted names are not tokens of that form).
pub fn debug_has_non_finite(debug: &str) -> bool {
    debug
        .split(|c: char| c.is_whitespace() || matches!(c, ',' | '[' | ']' | '(' | ')' | '{' | '}' | ':'))
        .any(|t| matches!(t, "NaN" | "inf" | "-inf"))
}

/// Run `check` on mutations of `seeds`; a panic or a failed assertion fails the test with
/// the seed and the mutations.
pub fn fuzz(target: &str, seeds: &[Vec<u8>], check: impl Fn(usize, &[u8])) {
    let mut runner = proptest::test_runner::TestRunner::new(config(target));
    let started = Instant::now();
    runner
        .run(&case(seeds.len()), |(seed, mutations)| {
            let input = mutate(&seeds[seed], &mutations);
            timed(target, || check(seed, &input));
            Ok(())
        })
        .unwrap_or_else(|e| panic!("fuzz {target}: {e}"));
    show(&format!("fuzz {target}: {} cases done in {:.2} s", runner.config().cases, started.elapsed().as_secs_f64()));
}

/// A line on the test's standard error that `cargo test` shows: it captures what `eprintln!`
/// writes in a passing test, not what is written to the stream itself, and a log should show
/// each target's cases and time.
fn show(line: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "{line}");
}
