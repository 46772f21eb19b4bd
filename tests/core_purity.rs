//! The functional core stays pure: no async runtime, IPC, files, network or clocks in the numeric
//! modules (ARCHITECTURE.md, "Invariants"). A tidy test in the rust-analyzer manner.

use crate::util::repo;
use std::path::{Path, PathBuf};

/// The core: the database, frequency-domain solver, and (as they arrive) waves, ROM and scoring.
const CORE: &[&str] = &[
    "src/hydro",
    "src/rao.rs",
    "src/waves",
    "src/rom",
    "src/skill.rs",
    "src/sim.rs",
    "src/service/estimator.rs",
    "src/service/clock.rs",
    "src/operation.rs",
    "src/console",
];
const FORBIDDEN: &[&str] = &[
    "tokio",
    "iceoryx2",
    "std::fs",
    "std::net",
    "std::time",
    "Instant",
    "SystemTime",
    "File::",
    "std::env",
    "std::process",
    "std::thread",
    "crossterm",
];

fn rust_files(p: &Path, out: &mut Vec<PathBuf>) {
    if p.is_file() && p.extension().is_some_and(|e| e == "rs") {
        out.push(p.to_path_buf());
    } else if p.is_dir() {
        for e in std::fs::read_dir(p).unwrap() {
            rust_files(&e.unwrap().path(), out);
        }
    }
}

/// Forbidden names in a source text, ignoring `//` comments.
fn violations(text: &str) -> Vec<(usize, &'static str)> {
    let mut v = vec![];
    for (n, line) in text.lines().enumerate() {
        let code = line.split("//").next().unwrap_or("");
        for f in FORBIDDEN {
            if code.contains(f) {
                v.push((n + 1, *f));
            }
        }
    }
    v
}

#[test]
fn the_scanner_finds_what_it_looks_for() {
    assert_eq!(
        violations("use std::fs::File;\n// tokio in a comment is fine"),
        vec![(1, "std::fs")]
    );
    assert!(violations("let t = std::time::Instant::now();").len() >= 2);
}

#[test]
fn core_modules_do_no_io_and_read_no_clock() {
    let mut files = vec![];
    for c in CORE {
        rust_files(&repo(c), &mut files);
    }
    assert!(files.len() >= 6, "the core was found: {files:?}");
    let mut bad = vec![];
    for f in &files {
        for (line, what) in violations(&std::fs::read_to_string(f).unwrap()) {
            bad.push(format!("{}:{line}: `{what}`", f.display()));
        }
    }
    assert!(
        bad.is_empty(),
        "the functional core must stay pure:\n{}",
        bad.join("\n")
    );
}
