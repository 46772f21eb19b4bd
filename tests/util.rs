//! Helpers shared by the integration tests.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Path relative to the repository root.
pub fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// Runs the `shipcast` binary; returns (success, stdout, stderr).
pub fn shipcast(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_shipcast"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the shipcast binary runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// One row of an RAO CSV (`omega,heading_deg,mode,amplitude,phase_deg`).
#[derive(Debug, Clone, Copy)]
pub struct RaoRow {
    pub omega: f64,
    pub heading_deg: f64,
    pub mode: usize,
    pub amplitude: f64,
    pub phase_deg: f64,
}

impl RaoRow {
    pub fn complex(&self) -> (f64, f64) {
        let p = self.phase_deg.to_radians();
        (self.amplitude * p.cos(), self.amplitude * p.sin())
    }
}

/// Parses an RAO CSV, checking its header.
pub fn parse_rao_csv(text: &str) -> Vec<RaoRow> {
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("omega,heading_deg,mode,amplitude,phase_deg"),
        "RAO CSV header"
    );
    lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), 5, "RAO CSV row `{l}`");
            RaoRow {
                omega: f[0].parse().unwrap(),
                heading_deg: f[1].parse().unwrap(),
                mode: f[2].parse().unwrap(),
                amplitude: f[3].parse().unwrap(),
                phase_deg: f[4].parse().unwrap(),
            }
        })
        .collect()
}
