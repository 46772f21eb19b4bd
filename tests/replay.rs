//! Recorded logs and replay (issue 7): a simulated log read by an off-the-shelf reader in Python,
//! replayed through the daemon's engine deterministically, skill against lead time, damaged logs.

use crate::util::{absolute_paths, repo, scratch_dir, shipcast, simulate_to};
use std::path::{Path, PathBuf};

/// The simulated logs' data clock at the start (2025-06-15 UTC): fixed, so logs are reproducible.
const START_UNIX_S: f64 = 1_750_000_000.0;

/// The README's skill-report config (`config/one-ship.toml`), copied into `dir` with its system path
/// made absolute and the data clock's start fixed.
fn config(dir: &Path) -> PathBuf {
    let text = absolute_paths(
        &std::fs::read_to_string(repo("config/one-ship.toml")).unwrap(),
        "vessels/ship/system.toml",
    )
    .replace(
        "[simulate]\n",
        &format!("[simulate]\nstart_unix_s = {START_UNIX_S:?}\n"),
    );
    assert!(text.contains("start_unix_s"));
    assert!(text.contains(&*repo("config/vessels").to_string_lossy()));
    let p = dir.join("shipcast.toml");
    std::fs::write(&p, text).unwrap();
    p
}

/// A simulated log of `secs` seconds (model error 1.2 x damping, radar disc 1 km).
fn simulated_log(dir: &Path, secs: u32) -> (PathBuf, PathBuf) {
    let cfg = config(dir);
    let log = dir.join("sim.mcap");
    simulate_to(&cfg, &log, secs as f64);
    (cfg, log)
}

/// The default plot's forecast, s from the log's start: the 600 s log's middle one, 300 s with 50 s of margin.
const MIDDLE_FORECAST_S: std::ops::Range<f64> = 250.0..350.0;
/// Correlation at 120 s lead at least this below 60 s's: a clear fall past the radar's reach, not scatter.
const MIN_SKILL_DROP_PAST_REACH: f64 = 0.2;

#[test]
fn replay_is_deterministic_and_skill_falls_past_the_horizon() {
    let dir = scratch_dir("replay-skill");
    let (cfg, log) = simulated_log(&dir, 600);
    let run = |name: &str| -> (serde_json::Value, Vec<shipcast::shell::record::ForecastRecord>) {
        let rep = dir.join(name);
        let out = dir.join(format!("{name}.mcap"));
        let (ok, stdout, err) = shipcast(&[
            "replay",
            log.to_str().unwrap(),
            "--config",
            cfg.to_str().unwrap(),
            "--max",
            "--report",
            rep.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{err}");
        assert!(stdout.contains("skill.json"));
        eprintln!("{}", err.lines().last().unwrap_or(""));
        let j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(rep.join("skill.json")).unwrap()).unwrap();
        assert!(rep.join("skill.csv").exists());
        // every plot as SVG (labelled axes, legend) and as a PNG that decodes
        let plot_ok = |svg: &Path, labels: &[&str]| {
            let text = std::fs::read_to_string(svg).unwrap();
            for l in labels {
                assert!(text.contains(l), "{} lacks {l:?}", svg.display());
            }
            let png = svg.with_extension("png");
            let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap()));
            let mut r = dec.read_info().unwrap();
            let mut buf = vec![0; r.output_buffer_size()];
            let info = r.next_frame(&mut buf).unwrap();
            assert!(
                info.width >= 800 && info.height >= 600,
                "{}: {}x{}",
                png.display(),
                info.width,
                info.height
            );
        };
        plot_ok(
            &rep.join("skill.svg"),
            &[
                "lead time (s)",
                "correlation (forecast, truth)",
                "NRMSE (RMS error / truth std)",
                "carrier heave",
            ],
        );
        // a simulation's forecasts are scored against its true motion
        assert_eq!(j["reference"], "truth");
        // operator windows (default channels: heave 1 m, roll 2 deg) against the simulation's truth
        let w: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(rep.join("windows.json")).unwrap()).unwrap();
        assert_eq!(w["reference"], "truth");
        assert!(w["forecasts_scored"].as_u64().unwrap() > 400, "{w}");
        assert!(stdout.contains("operator windows"), "{stdout}");
        // the middle forecast of a 600 s log against what followed
        let svg = std::fs::read_dir(&rep)
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| {
                let n = p.file_name().unwrap().to_string_lossy();
                n.starts_with("forecast-") && n.ends_with(".svg")
            })
            .expect("a forecast-<t>.svg");
        let t: f64 = svg.file_stem().unwrap().to_string_lossy()["forecast-".len()..]
            .parse()
            .unwrap();
        assert!(MIDDLE_FORECAST_S.contains(&t), "{t}");
        plot_ok(
            &svg,
            &[
                "lead time (s)",
                "carrier.heave (m)",
                "carrier.roll (deg)",
                "truth motion",
                "forecast (trusted)",
                "limits ±1 m",
                "trusted horizon",
            ],
        );
        let forecasts: Vec<shipcast::shell::record::ForecastRecord> = shipcast::shell::record::read(&out)
            .unwrap()
            .records
            .into_iter()
            .filter_map(|(_, r)| match r {
                shipcast::shell::record::Record::Forecast(f) => Some(f),
                _ => None,
            })
            .collect();
        (j, forecasts)
    };
    let (a, fa) = run("a");
    let (_, fb) = run("b");
    // the same log gives the same forecasts, bit for bit
    assert!(fa.len() > 500);
    assert!(fa == fb, "replays differ");
    let lead: Vec<f64> = a["lead_s"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let corr = |dof: &str, l: f64| {
        let i = lead.iter().position(|x| *x == l).unwrap();
        a["vessels"]["carrier"][dof]["correlation"][i].as_f64().unwrap()
    };
    // the truth is another model of the hull and the radar a real one's (blind zone, shadowing, bound
    // waves): skill as at sea, not a twin's
    eprintln!(
        "heave correlation at 30 / 60 / 110 s: {:.3} / {:.3} / {:.3}; pitch {:.3} / {:.3} / {:.3}",
        corr("heave", 30.0),
        corr("heave", 60.0),
        corr("heave", 110.0),
        corr("pitch", 30.0),
        corr("pitch", 60.0),
        corr("pitch", 110.0)
    );
    for dof in ["heave", "pitch"] {
        assert!(
            corr(dof, 60.0) > MIN_SEA_CORRELATION,
            "{dof} at 60 s: {}",
            corr(dof, 60.0)
        );
        assert!(
            corr(dof, 30.0) < MAX_SEA_CORRELATION,
            "{dof} at 30 s: {}: a twin's",
            corr(dof, 30.0)
        );
        assert!(
            corr(dof, 120.0) < corr(dof, 60.0) - MIN_SKILL_DROP_PAST_REACH,
            "{dof}: skill falls past the radar's reach"
        );
    }
    // the band: the truth inside the published 90 % band about nine times in ten at every lead, for
    // the motions of this head sea (its roll is a few hundredths of a degree); the span, where one is
    // published, only where the forecast's error is what it says
    for dof in ["heave", "pitch"] {
        for (i, l) in lead.iter().enumerate().filter(|(_, l)| **l > 0.0) {
            let c = a["vessels"]["carrier"][dof]["coverage_90"][i].as_f64().unwrap();
            assert!(SHORT_LOG_COVERAGE.contains(&c), "{dof} at {l} s: coverage_90 {c}");
        }
    }
    // at lead 0 the band is the start's own error, neither the sensor's noise (the estimate is
    // better than one sample) nor the sensor's drift the checks count as error
    for dof in ["heave", "pitch"] {
        let c = a["vessels"]["carrier"][dof]["coverage_90"][0].as_f64().unwrap();
        eprintln!("{dof} at lead 0: coverage_90 {c:.2}");
        assert!(START_COVERAGE.contains(&c), "{dof} at lead 0: coverage_90 {c}");
    }
    let (from, to) = (
        a["trusted_from_s"]["carrier"].as_f64().unwrap(),
        a["trusted_horizon_s"]["carrier"].as_f64().unwrap(),
    );
    eprintln!("median trusted span {from:.0}-{to:.0} s");
    for dof in ["heave", "pitch"] {
        for (i, l) in lead
            .iter()
            .enumerate()
            .filter(|(_, l)| **l >= from && **l <= to && to > 0.0)
        {
            let e = a["vessels"]["carrier"][dof]["nrmse"][i].as_f64().unwrap();
            assert!(e <= SHORT_LOG_SPAN_NRMSE, "{dof} at {l} s, inside the span: NRMSE {e}");
        }
    }
}

/// The 90 % band's coverage allowed on a 10-minute log: its first minutes use the configured prior
/// while the model error is learnt (docs/skill.md: the 30-minute figures). The lowest is pitch at 5 s
/// (measured 0.63): with the blind zone filled by the window of scans no wave is unknown there, and
/// the band is the prior's 0.15 of the motion where pitch errs by 0.18-0.23 until it is learnt.
const SHORT_LOG_COVERAGE: std::ops::RangeInclusive<f64> = 0.6..=1.0;
/// ... and at lead 0, where nothing is learnt from the prior: the Show's (measured 0.90 heave, 0.94
/// pitch; 0.93 and 0.98 when the band there was floored at the sensor's noise and learnt from checks
/// that counted heave's drift as error).
const START_COVERAGE: std::ops::RangeInclusive<f64> = 0.85..=0.95;
/// Inside the median published span, the error a 10-minute log allows: `forecast.trusted_nrmse` (0.6)
/// and the first minutes' forecasts, made with the prior.
const SHORT_LOG_SPAN_NRMSE: f64 = 0.75;
/// Heave and pitch correlation at 60 s lead in the realistic sea, at least: sea trials of radar-based
/// forecasts report 0.8-0.9 (Naaijen et al., OMAE 2016); measured 0.92 / 0.93 on this log (the radar's
/// window of scans fills its blind zone).
const MIN_SEA_CORRELATION: f64 = 0.7;
/// ... and at 30 s at most: the realistic sea's truth is another model of the hull and its radar
/// shadows and noise (measured 0.975 / 0.981), where the twin experiment (the truth the forecaster's
/// own model, a perfect radar disc) forecasts pitch at 1.00.
const MAX_SEA_CORRELATION: f64 = 0.995;

#[test]
fn python_lists_the_channels_and_decodes_a_message_of_each() {
    let python = crate::util::python();
    let dir = scratch_dir("replay-python");
    let (_, log) = simulated_log(&dir, 30);
    let out = std::process::Command::new(&python)
        .args([
            repo("tools/replay/list_log.py").to_str().unwrap(),
            log.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let lines: Vec<serde_json::Value> = text.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    let (meta, channels): (Vec<_>, Vec<_>) = lines.iter().partition(|l| l.get("metadata").is_some());
    let mut topics: Vec<&str> = channels.iter().map(|c| c["topic"].as_str().unwrap()).collect();
    topics.sort();
    assert_eq!(topics, ["/motion", "/navigation", "/radar", "/truth", "/waves"]);
    let channel = |t: &str| *channels.iter().find(|c| c["topic"] == t).unwrap();
    assert_eq!(channel("/motion")["first"]["x"].as_array().unwrap().len(), 6);
    assert!(channel("/waves")["first"]["radius_m"].as_f64().unwrap() > 0.0);
    assert!(channel("/navigation")["first"]["heading_deg"].as_f64().is_some());
    for c in &channels {
        // a real JSON Schema with field names, and log times on the UNIX clock (ISO dates compare as text)
        assert_eq!(c["schema_encoding"], "jsonschema", "{c}");
        let fields: Vec<&str> = c["fields"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f.as_str().unwrap())
            .collect();
        assert!(!fields.is_empty(), "{c}");
        let first = c["first"].as_object().unwrap();
        assert!(first.keys().all(|k| fields.contains(&k.as_str())), "{c}");
        assert!(c["first_log_time"].as_str().unwrap() > "2020-01-01", "{c}");
    }
    assert!(
        channel("/motion")["fields"]
            .as_array()
            .unwrap()
            .contains(&"time_s".into())
    );
    assert_eq!(channel("/radar")["schema"], "foxglove.Grid");
    assert_eq!(channel("/radar")["first"]["column_count"], 128);
    assert_eq!(meta.len(), 1, "{text}");
    assert_eq!(meta[0]["metadata"], "shipcast");
    assert_eq!(meta[0]["vessels"], "[\"carrier\"]");
    assert_eq!(meta[0]["writer"], "simulate");
    assert_eq!(meta[0]["shipcast_version"], env!("CARGO_PKG_VERSION"));
}

#[test]
fn damaged_logs_keep_what_is_readable_and_newer_schemas_are_refused() {
    let dir = scratch_dir("replay-damaged");
    let (cfg, log) = simulated_log(&dir, 120);
    let bytes = std::fs::read(&log).unwrap();
    // cut short (a crash or power loss)
    let cut = dir.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
    let (ok, _, err) = shipcast(&["replay", cut.to_str().unwrap(), "--config", cfg.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(
        err.contains("stops being readable after") && err.contains("forecasts"),
        "{err}"
    );
    // a corrupt chunk in the middle
    let mut bad = bytes.clone();
    let mid = bad.len() / 2;
    for b in &mut bad[mid..mid + 64] {
        *b ^= 0x5a;
    }
    let corrupt = dir.join("corrupt.mcap");
    std::fs::write(&corrupt, &bad).unwrap();
    let (ok, _, err) = shipcast(&["replay", corrupt.to_str().unwrap(), "--config", cfg.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(err.contains("warning"), "{err}");
    // a log from a newer schema
    let newer = dir.join("newer.mcap");
    {
        let f = std::io::BufWriter::new(std::fs::File::create(&newer).unwrap());
        let mut w = mcap::WriteOptions::new().create(f).unwrap();
        let sid = w.add_schema("shipcast.Motion", "jsonschema", b"{}").unwrap();
        let mut meta = std::collections::BTreeMap::new();
        let newer_version = shipcast::shell::record::LOG_SCHEMA_VERSION + 1;
        meta.insert("shipcast_schema_version".to_string(), newer_version.to_string());
        let ch = w.add_channel(sid, "/motion", "json", &meta).unwrap();
        w.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: ch,
                sequence: 1,
                log_time: 0,
                publish_time: 0,
            },
            b"{}",
        )
        .unwrap();
        w.finish().unwrap();
    }
    let (ok, _, err) = shipcast(&["replay", newer.to_str().unwrap(), "--config", cfg.to_str().unwrap()]);
    assert!(!ok);
    assert!(
        err.contains(&format!(
            "schema version {}",
            shipcast::shell::record::LOG_SCHEMA_VERSION + 1
        )) && err.contains("upgrade shipcast"),
        "{err}"
    );
}

/// Log time per rotated file, s: the recorder's rotation period, so every file spans less than this.
const ROTATE_EVERY_S: f64 = 10.0;

#[test]
fn logs_rotate_by_log_time_and_every_message_is_kept() {
    use shipcast::shell::record::{LogInfo, MotionRecord, Record, RotatingRecorder, read};
    let dir = scratch_dir("rotate-time");
    let mut r = RotatingRecorder::new(&dir, 1000.0, Some(ROTATE_EVERY_S), LogInfo::default()).unwrap();
    for k in 0..350 {
        let t = 0.1 * k as f64;
        let m = MotionRecord {
            vessel: 0,
            time_s: t,
            x: [t; 6],
            v: [0.0; 6],
        };
        r.record(t, &Record::Motion(m)).unwrap();
    }
    r.finish().unwrap();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    files.sort();
    assert_eq!(files.len(), 4, "{files:?}"); // 0-10, 10-20, 20-30, 30-35 s
    let mut times = vec![];
    for f in &files {
        let log = read(f).unwrap();
        assert!(log.warnings.is_empty());
        let t: Vec<f64> = log.records.iter().map(|(t, _)| *t).collect();
        assert!(t.last().unwrap() - t[0] < ROTATE_EVERY_S);
        times.extend(t);
    }
    assert_eq!(times.len(), 350);
    assert!(times.windows(2).all(|w| w[1] > w[0]));
}

/// Import bar: the imported motion equals the CSV's to this (degrees written with 12 digits).
const IMPORT_TOL: f64 = 1e-9;
/// A probe 400 m upwave of a ship in Tp 9 s long-crested seas: the heave forecast from it must still
/// correlate this well at 10 s lead (measured 0.915; a broken import or direction gives about 0).
const PROBE_MIN_CORRELATION_10S: f64 = 0.8;

#[test]
fn csv_recordings_import_and_replay_without_code() {
    use shipcast::shell::record::{Record, read};
    let dir = scratch_dir("import");
    let (cfg, log) = simulated_log(&dir, 400);
    let records = read(&log).unwrap().records;
    // the "trial data": the IMU motion as CSV, and a wave probe 400 m east (upwave: the sea travels
    // west) sampled at 2 Hz from the radar's fields
    let mut motion =
        String::from("# sea trial, ship motion\ntime_s,vessel,surge_m,sway_m,heave_m,roll_deg,pitch_deg,yaw_deg\n");
    let mut n_motion = 0;
    for (_, r) in &records {
        if let Record::Motion(m) = r {
            let x = m.x;
            motion.push_str(&format!(
                "{},carrier,{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e}\n",
                m.time_s,
                x[0],
                x[1],
                x[2],
                x[3].to_degrees(),
                x[4].to_degrees(),
                x[5].to_degrees()
            ));
            n_motion += 1;
        }
    }
    let fields: Vec<shipcast::waves::field::WaveField> = records
        .iter()
        .filter_map(|(_, r)| match r {
            Record::Waves(w) => Some(w.field().unwrap()),
            _ => None,
        })
        .collect();
    let mut probe = String::from("time_s,elevation_m,east_m,north_m,towards_deg\n");
    let mut t = fields[0].time_s;
    while t < START_UNIX_S + 400.0 {
        let f = fields.iter().rev().find(|f| f.time_s <= t).unwrap();
        probe.push_str(&format!("{t:.1},{:.6},400,0,270\n", f.elevation_at([400.0, 0.0], t)));
        t += 0.5;
    }
    std::fs::write(dir.join("motion.csv"), motion).unwrap();
    std::fs::write(dir.join("probe.csv"), probe).unwrap();
    let imported = dir.join("imported.mcap");
    let (ok, stdout, err) = shipcast(&[
        "import",
        "--config",
        cfg.to_str().unwrap(),
        "--motion",
        dir.join("motion.csv").to_str().unwrap(),
        "--probe",
        dir.join("probe.csv").to_str().unwrap(),
        "--out",
        imported.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    eprintln!("{err}{stdout}");
    let back = read(&imported).unwrap().records;
    let orig: Vec<_> = records
        .iter()
        .filter_map(|(_, r)| if let Record::Motion(m) = r { Some(m) } else { None })
        .collect();
    let got: Vec<_> = back
        .iter()
        .filter_map(|(_, r)| if let Record::Motion(m) = r { Some(m) } else { None })
        .collect();
    assert_eq!(got.len(), n_motion);
    for (a, b) in orig.iter().zip(&got) {
        assert_eq!(a.time_s, b.time_s);
        assert!(
            a.x.iter()
                .zip(&b.x)
                .all(|(p, q)| (p - q).abs() <= IMPORT_TOL * (1.0 + p.abs()))
        );
    }
    assert!(back.iter().filter(|(_, r)| matches!(r, Record::Waves(_))).count() > 100);
    // a probe's fields say they come from a point (their horizon is the travel time from it)
    let probe_field = back
        .iter()
        .find_map(|(_, r)| {
            if let Record::Waves(w) = r {
                Some(w.field().unwrap())
            } else {
                None
            }
        })
        .unwrap();
    // a probe, and the window its field was fitted to (the default follows its distance: at least 120 s)
    assert!(
        matches!(
            probe_field.region,
            shipcast::waves::field::Region::Point { at_m: [400.0, 0.0], window_s } if window_s >= 120.0
        ),
        "{:?}",
        probe_field.region
    );
    let rep = dir.join("report");
    let (ok, _, err) = shipcast(&[
        "replay",
        imported.to_str().unwrap(),
        "--config",
        cfg.to_str().unwrap(),
        "--report",
        rep.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(rep.join("skill.json")).unwrap()).unwrap();
    let lead: Vec<f64> = j["lead_s"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let i = lead.iter().position(|x| *x == 10.0).unwrap();
    let c = j["vessels"]["carrier"]["heave"]["correlation"][i].as_f64().unwrap();
    eprintln!("probe-driven heave correlation at 10 s lead: {c:.3}");
    assert!(c > PROBE_MIN_CORRELATION_10S, "{c}");
    // a bad file is named with its line
    std::fs::write(
        dir.join("bad.csv"),
        "time_s,vessel,surge_m,sway_m,heave_m,roll_deg,pitch_deg,yaw_deg\n0,carrier,0,0,nan?,0,0,0\n",
    )
    .unwrap();
    let (ok, _, err) = shipcast(&[
        "import",
        "--config",
        cfg.to_str().unwrap(),
        "--motion",
        dir.join("bad.csv").to_str().unwrap(),
        "--out",
        dir.join("x.mcap").to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("bad.csv:2: heave_m: \"nan?\" is not a number"),
        "{err}"
    );
}

#[test]
fn a_replay_publishes_for_a_console() {
    use shipcast::shell::ipc::{ForecastSubscriber, MotionSubscriber, Names, Received};
    use std::time::{Duration, Instant};
    let dir = scratch_dir("replay-publish");
    let (cfg, log) = simulated_log(&dir, 150);
    let prefix = format!("shipcast-test-{}-replay-publish", std::process::id());
    let names = Names { prefix: prefix.clone() };
    let fs = ForecastSubscriber::new(&names).unwrap();
    let ms = MotionSubscriber::new(&names).unwrap();
    let _replay = shipcast::shell::process::Interrupting(
        std::process::Command::new(env!("CARGO_BIN_EXE_shipcast"))
            .args(["replay", log.to_str().unwrap(), "--config", cfg.to_str().unwrap()])
            .args(["--speed", "10", &format!("--publish={prefix}")])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap(),
    );
    let (mut got, mut motion) = (vec![], vec![]);
    let t = Instant::now();
    let forecasts = |g: &Vec<Received>| g.iter().filter(|r| matches!(r, Received::Forecast(..))).count();
    while t.elapsed() < Duration::from_secs(30) && (forecasts(&got) < 5 || motion.is_empty()) {
        fs.wait(Duration::from_millis(200), &mut got).unwrap();
        ms.drain(&mut motion).unwrap();
    }
    assert!(forecasts(&got) >= 5, "{} forecasts", forecasts(&got));
    assert!(got.iter().any(|r| matches!(r, Received::Status(s) if s.running == 1)));
    assert!(!motion.is_empty());
}

/// A replay of the 40 s fixture log takes about a second; a replay that has not ended after this
/// long is spinning (the faults below ran for ever).
const REPLAY_DEADLINE: std::time::Duration = std::time::Duration::from_secs(120);

/// Runs `shipcast` as a child process; kills it and fails the test if it has not ended by `deadline`.
/// Returns (success, stdout, stderr).
fn shipcast_within(args: &[&str], deadline: std::time::Duration) -> (bool, String, String) {
    use std::io::Read;
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_shipcast"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("the shipcast binary runs");
    // drain the pipes on threads so a chatty child cannot block on a full pipe
    let mut so = child.stdout.take().unwrap();
    let mut se = child.stderr.take().unwrap();
    let out = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = so.read_to_string(&mut s);
        s
    });
    let err = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = se.read_to_string(&mut s);
        s
    });
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("shipcast {} did not end within {deadline:?}: killed", args.join(" "));
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    };
    (status.success(), out.join().unwrap(), err.join().unwrap())
}

/// The version-1 fixture log and its config (tests/data/replay-v1).
fn v1_fixture() -> (PathBuf, PathBuf) {
    (
        repo("tests/data/replay-v1/shipcast.toml"),
        repo("tests/data/replay-v1/sim.mcap"),
    )
}

/// Offsets of the Chunk records (opcode 0x06) of an MCAP file.
fn chunk_offsets(bytes: &[u8]) -> Vec<usize> {
    let mut at = 8; // magic
    let mut out = vec![];
    while at + 9 <= bytes.len() {
        let op = bytes[at];
        let len = u64::from_le_bytes(bytes[at + 1..at + 9].try_into().unwrap()) as usize;
        if op == 0x06 {
            out.push(at);
        }
        if op == 0x0f {
            break; // footer
        }
        at += 9 + len;
    }
    out
}

#[test]
fn a_corrupt_chunk_header_is_read_up_to_the_damage_in_bounded_time() {
    let dir = scratch_dir("replay-chunk-header");
    let (cfg, log) = v1_fixture();
    let mut bytes = std::fs::read(&log).unwrap();
    let chunks = chunk_offsets(&bytes);
    assert!(chunks.len() >= 2, "the fixture has {} chunks", chunks.len());
    // the last chunk's uncompressed size (after opcode, length, start and end times) off by 1000
    let at = chunks[chunks.len() - 1] + 1 + 8 + 16;
    let size = u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap());
    bytes[at..at + 8].copy_from_slice(&(size + 1000).to_le_bytes());
    let bad = dir.join("bad-chunk.mcap");
    std::fs::write(&bad, &bytes).unwrap();
    let (ok, _, err) = shipcast_within(
        &["replay", bad.to_str().unwrap(), "--config", cfg.to_str().unwrap()],
        REPLAY_DEADLINE,
    );
    assert!(ok, "{err}");
    assert!(err.contains("warning") && err.contains("bad-chunk.mcap"), "{err}");
    let forecasts: usize = err
        .split(" forecasts (")
        .next()
        .and_then(|s| s.rsplit(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or(0);
    assert!(forecasts > 0, "{err}");
}

#[test]
fn a_log_time_gap_replays_in_time_proportional_to_its_messages() {
    use shipcast::shell::record::{LogInfo, MotionRecord, Record, Recorder, read};
    let dir = scratch_dir("replay-gap");
    let (cfg, log) = v1_fixture();
    let mut records = read(&log).unwrap().records;
    // one absurd time: a motion sample in the year 2446 (log time 1.5e19 ns, near the largest an MCAP
    // log time can hold), a tick per second across the gap: 1.5e10 ticks
    let far = 1.5e10;
    records.push((
        far,
        Record::Motion(MotionRecord {
            vessel: 0,
            time_s: far,
            x: [0.0; 6],
            v: [0.0; 6],
        }),
    ));
    let gap = dir.join("gap.mcap");
    let mut rec = Recorder::create(&gap, &LogInfo::default()).unwrap();
    for (t, r) in &records {
        rec.record(*t, r).unwrap();
    }
    rec.finish().unwrap();
    let (ok, _, err) = shipcast_within(
        &["replay", gap.to_str().unwrap(), "--config", cfg.to_str().unwrap()],
        REPLAY_DEADLINE,
    );
    assert!(ok, "{err}");
}

#[test]
fn a_version_1_log_still_replays_to_the_same_forecasts() {
    use shipcast::shell::record::{ForecastRecord, Record, read};
    let dir = scratch_dir("replay-v1");
    let (cfg, log) = v1_fixture();
    let out = dir.join("replayed.mcap");
    let (ok, _, err) = shipcast_within(
        &[
            "replay",
            log.to_str().unwrap(),
            "--config",
            cfg.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        REPLAY_DEADLINE,
    );
    assert!(ok, "{err}");
    let forecasts = |p: &Path| -> Vec<ForecastRecord> {
        let r = read(p).unwrap();
        assert!(r.warnings.is_empty(), "{:?}", r.warnings);
        r.records
            .into_iter()
            .filter_map(|(_, r)| match r {
                Record::Forecast(f) => Some(f),
                _ => None,
            })
            .collect()
    };
    // the forecasts today's shipcast replays from it are those in forecasts.mcap, bit for bit (remade
    // with `shipcast replay sim.mcap --config shipcast.toml --out forecasts.mcap` only when the model
    // changes on purpose: last when the history's force was transformed at the run's length and the
    // estimator kept its smoothed states, which moved values by at most 6.7e-16 m of 0.32 m with the
    // same flags; before that for the flag model_error_unchecked)
    let (was, now) = (forecasts(&repo("tests/data/replay-v1/forecasts.mcap")), forecasts(&out));
    assert!(was.len() > 20, "{}", was.len());
    assert_eq!(was.len(), now.len());
    for (a, b) in was.iter().zip(&now) {
        assert_eq!(a.issue_time_s.to_bits(), b.issue_time_s.to_bits());
        assert_eq!(a.flags, b.flags);
        assert!(
            a.values.len() == b.values.len() && a.values.iter().zip(&b.values).all(|(x, y)| x.to_bits() == y.to_bits()),
            "the forecast at {} differs",
            a.issue_time_s
        );
    }
}
