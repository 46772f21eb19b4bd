//! Helpers shared by the integration tests.
#![allow(clippy::needless_range_loop)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// Path relative to the repository root.
pub fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// Runs the `shipcast` binary; returns (success, stdout, stderr).
/// A simulated log with the configuration and system that made it.
pub struct SimLog {
    pub cfg: shipcast::shell::config::ShipcastConfig,
    pub sys: shipcast::hydro::VesselSystem,
    pub records: Vec<(f64, shipcast::shell::replay::Record)>,
}

/// `secs` simulated seconds of `config/<config>` (whose `[system] file` must be `system`, relative to
/// `config/`, made absolute in a copy in scratch dir `name`) with its text replaced (each (from, to)
/// of `edits` must be found once), recorded and read back.
pub fn simulated_with(name: &str, config: &str, system: &str, secs: f64, edits: &[(&str, &str)]) -> SimLog {
    let dir = scratch_dir(name);
    let mut text = std::fs::read_to_string(repo(&format!("config/{config}"))).unwrap();
    for (from, to) in edits {
        assert_eq!(text.matches(from).count(), 1, "config/{config}: {from:?} once");
        text = text.replace(from, to);
    }
    let text = absolute_paths(&text, system);
    let cfg_path = dir.join("shipcast.toml");
    std::fs::write(&cfg_path, text).unwrap();
    let path = dir.join("sim.mcap");
    simulate_to(&cfg_path, &path, secs);
    SimLog {
        cfg: shipcast::shell::config::load(&cfg_path).unwrap(),
        sys: shipcast::shell::files::load_system(&repo(&format!("config/{system}")))
            .unwrap()
            .system,
        records: shipcast::shell::replay::read(&path).unwrap().records,
    }
}

/// Edits of `config/shipcast.toml` (for [`simulated_with`]) that make its synthetic sea a twin
/// experiment: the truth the forecaster's own model (damping 1.2 x), a radar disc seen whole without
/// shadowing or bound waves, IMUs that do not drift. For tests of a pipeline (a slip of time, frame
/// or pose shows in the correlation), not of skill: the shipped sensors are the sea-state matrix's (docs/skill.md).
pub const TWIN_SEA: [(&str, &str); 7] = [
    ("truth_system = \"vessels/", "# truth_system = \"vessels/"),
    ("bound_waves = true ", "bound_waves = false "),
    ("blind_radius_m = 200.0 ", "blind_radius_m = 0.0 "),
    (
        "masked_sector_deg = [160.0, 200.0]",
        "# masked_sector_deg = [160.0, 200.0]",
    ),
    ("antenna_height_m = 30.0 ", "antenna_height_m = 0.0 "),
    // [simulate.imu]'s (the [estimator]'s own drift_m and drift_rad say what the daemon assumes)
    (
        "drift_m = 0.02                              # standard deviation (",
        "drift_m = 0.0 # (",
    ),
    (
        "drift_rad = 0.0003                          # standard deviation (",
        "drift_rad = 0.0 # (",
    ),
];

/// [`TWIN_SEA`] for `config/one-ship.toml` (its sensors at the defaults).
pub const ONE_SHIP_TWIN_SEA: [(&str, &str); 3] = [
    ("truth_system = \"vessels/ship/truth/system.toml\"\n", ""),
    ("[simulate.sea]\n", "[simulate.sea]\nbound_waves = false\n"),
    (
        "[simulate.radar]\n",
        "[simulate.imu]\ndrift_m = 0.0\ndrift_rad = 0.0\n\n[simulate.radar]\nblind_radius_m = 0.0\nantenna_height_m = 0.0\n",
    ),
];

/// A shipped config's text with its `[system] file` (which must be `system`, relative to `config/`)
/// and its `[simulate] truth_system` made absolute, for a copy elsewhere.
pub fn absolute_paths(text: &str, system: &str) -> String {
    let file = format!("file = \"{system}\"");
    assert!(text.contains(&file), "the config does not say {file}");
    text.replace(
        &file,
        &format!("file = \"{}\"", repo(&format!("config/{system}")).display()),
    )
    .replace(
        "truth_system = \"vessels/",
        &format!("truth_system = \"{}/", repo("config/vessels").display()),
    )
}

/// `shipcast simulate --config CFG --record LOG --duration SECS`, which must succeed.
pub fn simulate_to(cfg: &Path, log: &Path, secs: f64) {
    simulate_to_with(cfg, log, secs, &[]);
}

/// [`simulate_to`] with `extra` arguments (`--truth CSV`).
pub fn simulate_to_with(cfg: &Path, log: &Path, secs: f64, extra: &[&str]) {
    let secs = secs.to_string();
    let mut args = vec![
        "simulate",
        "--config",
        cfg.to_str().unwrap(),
        "--record",
        log.to_str().unwrap(),
        "--duration",
        &secs,
    ];
    args.extend_from_slice(extra);
    let (ok, _, err) = shipcast(&args);
    assert!(ok, "{err}");
}

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
/// Curves below this fraction of their mode's largest peak (sway in head seas) are judged against that
/// largest peak, as in `rom::floor`.
const SMALL_CURVE: f64 = 0.1;

/// (mode, heading in mdeg, omega in micro rad/s) of a row.
fn rao_key(r: &RaoRow) -> (usize, i64, i64) {
    (
        r.mode,
        (r.heading_deg * 1000.0).round() as i64,
        (r.omega * 1e6).round() as i64,
    )
}

/// Worst |test - reference| over the rows of the reference with omega in `band`, relative to the peak of
/// its (mode, heading) curve over the whole reference (small curves to their mode's largest), with where.
pub fn rao_worst(test: &[RaoRow], reference: &[RaoRow], band: std::ops::RangeInclusive<f64>) -> (f64, String) {
    use std::collections::HashMap;
    let test: HashMap<_, _> = test.iter().map(|r| (rao_key(r), *r)).collect();
    let mut curve_peak: HashMap<(usize, i64), f64> = HashMap::new();
    let mut mode_peak: HashMap<usize, f64> = HashMap::new();
    for r in reference {
        let (m, h, _) = rao_key(r);
        let p = curve_peak.entry((m, h)).or_default();
        *p = p.max(r.amplitude);
        let q = mode_peak.entry(m).or_default();
        *q = q.max(r.amplitude);
    }
    let mut out = (0.0, String::new());
    for r in reference.iter().filter(|r| band.contains(&r.omega)) {
        let (m, h, _) = rao_key(r);
        let t = test.get(&rao_key(r)).unwrap_or_else(|| panic!("no row for {r:?}"));
        let peak = curve_peak[&(m, h)];
        let scale = if peak >= SMALL_CURVE * mode_peak[&m] {
            peak
        } else {
            mode_peak[&m]
        };
        let ((ar, ai), (br, bi)) = (t.complex(), r.complex());
        let e = (ar - br).hypot(ai - bi) / scale;
        if e > out.0 {
            out = (e, format!("mode {m}, heading {} deg, {} rad/s", r.heading_deg, r.omega));
        }
    }
    out
}

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

/// The median of `v` (the upper of the two middle values when even); NaN when `v` is empty, so that any
/// bound asserted on it fails.
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// A fresh scratch directory under the system's temp dir, unique per test.
pub fn scratch_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("shipcast-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("scratch dir");
    d
}

/// A one-body WAMIT database with frequency-independent coefficients (rho = 1000, g = 9.81, L = 1):
/// added mass `a` and damping `b` (6 diagonal values, SI), restoring diagonal `c`, and an excitation
/// moment `roll_moment` N m per metre in roll for beam waves (heading 90 deg; -roll_moment at 270),
/// zero elsewhere. Frequencies 0.05..3.0 rad/s. Writes `dir/flat.{1,3,hst}`.
pub fn write_flat_database(dir: &Path, a: [f64; 6], b: [f64; 6], c: [f64; 6], roll_moment: f64) {
    let (rho, g) = (1000.0, 9.81);
    let k = |i: usize| if i < 3 { 3 } else { 5 };
    let mut one = String::new();
    one.push_str(&format!("{:e} {} {} {:e}\n", 0.0, 1, 1, a[0] / rho));
    for i in 1..6 {
        one.push_str(&format!("{:e} {} {} {:e}\n", 0.0, i + 1, i + 1, a[i] / rho));
    }
    let omegas: Vec<f64> = (1..=60).map(|s| 0.05 * s as f64).collect();
    for w in &omegas {
        let per = 2.0 * std::f64::consts::PI / w;
        for i in 0..6 {
            let scale = rho * 1f64.powi(k(i));
            one.push_str(&format!(
                "{per:e} {} {} {:e} {:e}\n",
                i + 1,
                i + 1,
                a[i] / scale,
                b[i] / (scale * w)
            ));
        }
    }
    std::fs::write(dir.join("flat.1"), one).unwrap();
    let mut three = String::new();
    for w in &omegas {
        let per = 2.0 * std::f64::consts::PI / w;
        for beta in [0.0, 90.0, 180.0, 270.0] {
            for i in 0..6 {
                let x = if i == 3 && beta == 90.0 {
                    roll_moment
                } else if i == 3 && beta == 270.0 {
                    -roll_moment
                } else {
                    0.0
                };
                let xb = x / (rho * g);
                let phase = if xb < 0.0 { 180.0 } else { 0.0 };
                three.push_str(&format!("{per:e} {beta} {} {:e} {phase} {:e} 0\n", i + 1, xb.abs(), xb));
            }
        }
    }
    std::fs::write(dir.join("flat.3"), three).unwrap();
    let mut hst = String::new();
    for i in 0..6 {
        for j in 0..6 {
            let v = if i == j { c[i] / (rho * g) } else { 0.0 };
            hst.push_str(&format!("{} {} {:e}\n", i + 1, j + 1, v));
        }
    }
    std::fs::write(dir.join("flat.hst"), hst).unwrap();
}

/// The Python interpreter of the tests' own virtual environment, with the pinned packages of
/// `tools/console/requirements.txt` and `tools/replay/requirements.txt` (iceoryx2, mcap). Made once,
/// under `target/tmp/py-venv`, with `python3 -m venv` and the venv's own pip (never the system's), and
/// made again when a requirements file changes. A file lock keeps two test processes from building it
/// at once. Panics with what is missing (python3, its venv module, PyPI) rather than skipping a test.
pub fn python() -> PathBuf {
    static PYTHON: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    PYTHON.get_or_init(make_venv).clone()
}

fn make_venv() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("py-venv");
    let reqs = [
        repo("tools/console/requirements.txt"),
        repo("tools/replay/requirements.txt"),
    ];
    let mut want = String::new();
    for r in &reqs {
        want.push_str(&std::fs::read_to_string(r).expect("requirements file"));
    }
    std::fs::create_dir_all(dir.parent().unwrap()).unwrap();
    let lock = std::fs::File::create(dir.with_extension("lock")).expect("venv lock file");
    lock.lock().expect("lock the venv");
    let stamp = dir.join("shipcast-requirements.txt");
    let python = dir.join("bin").join("python");
    if std::fs::read_to_string(&stamp).ok().as_deref() == Some(want.as_str()) && python.exists() {
        return python;
    }
    let _ = std::fs::remove_dir_all(&dir);
    let run = |cmd: &mut Command, what: &str| {
        let out = cmd.output().unwrap_or_else(|e| panic!("{what}: {e}"));
        assert!(
            out.status.success(),
            "{what} failed:\n{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    };
    run(
        Command::new("python3").args(["-m", "venv"]).arg(&dir),
        "python3 -m venv (Python 3 with its venv module is a prerequisite: README)",
    );
    let mut pip = Command::new(&python);
    pip.args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check"]);
    for r in &reqs {
        pip.arg("-r").arg(r);
    }
    run(
        &mut pip,
        "pip install of the tests' Python packages into target/tmp/py-venv",
    );
    std::fs::write(&stamp, want).unwrap();
    python
}
