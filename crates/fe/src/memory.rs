//! Resident memory at stage boundaries, for finding where a large model's peak lies: with the
//! environment variable `STICKSLIP_MEMORY` set, each stage boundary prints the current and
//! peak resident set (`VmRSS`, `VmHWM` of `/proc/self/status`, Linux) to stderr. Off by
//! default so that normal output carries no measurement noise; reading the file costs ~20 µs.
//!
//! Also the channel through which the factor's size, known from the symbolic analysis, is
//! reported before the numeric factorisation allocates it ([`set_notes`]): a library does not
//! print on its own, the command line decides where notes go.
use std::sync::OnceLock;

static NOTES: OnceLock<fn(&str)> = OnceLock::new();

/// Where notes of the solvers go (e.g. the factor's estimated size before factorising); set
/// once, by the program. Without it, notes are dropped.
pub fn set_notes(sink: fn(&str)) {
    let _ = NOTES.set(sink);
}

/// A note for the user (see [`set_notes`]).
pub(crate) fn note(text: &str) {
    if let Some(sink) = NOTES.get() {
        sink(text);
    }
}

fn wanted() -> bool {
    static WANTED: OnceLock<bool> = OnceLock::new();
    *WANTED.get_or_init(|| std::env::var_os("STICKSLIP_MEMORY").is_some())
}

/// `(VmRSS, VmHWM)` in bytes, `None` where `/proc/self/status` cannot be read.
pub fn resident() -> Option<(u64, u64)> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let field = |name: &str| -> Option<u64> {
        let kb: u64 =
            status.lines().find_map(|l| l.strip_prefix(name))?.trim().trim_end_matches("kB").trim().parse().ok()?;
        Some(kb * 1024)
    };
    Some((field("VmRSS:")?, field("VmHWM:")?))
}

/// Print the resident and peak memory after `stage` when `STICKSLIP_MEMORY` is set, in GB as
/// BENCHMARKS.md gives `/usr/bin/time -v`'s maximum resident set (its kB / 10⁶, kB of 1024
/// bytes), so that the two compare.
pub fn stage(stage: &str) {
    if !wanted() {
        return;
    }
    if let Some((rss, hwm)) = resident() {
        let gb = |bytes: u64| bytes as f64 / 1024.0 / 1e6;
        eprintln!("memory after {stage}: resident {:.3} GB, peak {:.3} GB", gb(rss), gb(hwm));
    }
}
