//! Recorded logs and replay (issue 7): a simulated log read by an off-the-shelf reader in Python,
//! replayed through the daemon's engine deterministically, skill against lead time, damaged logs.

use crate::util::{repo, scratch_dir, shipcast};
use std::path::{Path, PathBuf};

fn config(dir: &Path) -> PathBuf {
    let text = format!(
        r#"
[system]
file = "{}"
[forecast]
horizon_s = 120.0
memory_s = 60.0
[simulate]
damping_factor = 1.2
seed = 5
[simulate.sea]
towards_deg = 270.0
components = 120
[simulate.radar]
radius_m = 1000.0
cells = 128
"#,
        repo("config/vessels/ship/system.toml").display()
    );
    let p = dir.join("shipcast.toml");
    std::fs::write(&p, text).unwrap();
    p
}

/// A simulated log of `secs` seconds (model error 1.2 x damping, radar disc 1 km).
fn simulated_log(dir: &Path, secs: u32) -> (PathBuf, PathBuf) {
    let cfg = config(dir);
    let log = dir.join("sim.mcap");
    let (ok, _, err) = shipcast(&[
        "simulate",
        "--config",
        cfg.to_str().unwrap(),
        "--record",
        log.to_str().unwrap(),
        "--duration",
        &secs.to_string(),
    ]);
    assert!(ok, "{err}");
    (cfg, log)
}

#[test]
fn replay_is_deterministic_and_skill_falls_past_the_horizon() {
    let dir = scratch_dir("replay-skill");
    let (cfg, log) = simulated_log(&dir, 600);
    let run = |name: &str| -> (serde_json::Value, Vec<shipcast::replay::ForecastRecord>) {
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
        assert!(rep.join("skill.csv").exists() && rep.join("skill.svg").exists());
        let forecasts: Vec<shipcast::replay::ForecastRecord> = shipcast::replay::read(&out)
            .unwrap()
            .records
            .into_iter()
            .filter_map(|(_, r)| match r {
                shipcast::replay::Record::Forecast(f) => Some(f),
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
    // the horizon of a 1 km disc for Tp 9 s: about 1000 / 11.6 = 86 s (shipcast horizon)
    eprintln!(
        "heave correlation at 30 / 60 / 110 s: {:.3} / {:.3} / {:.3}; pitch {:.3} / {:.3} / {:.3}",
        corr("heave", 30.0),
        corr("heave", 60.0),
        corr("heave", 110.0),
        corr("pitch", 30.0),
        corr("pitch", 60.0),
        corr("pitch", 110.0)
    );
    assert!(corr("heave", 30.0) > 0.9 && corr("pitch", 30.0) > 0.9);
    assert!(corr("heave", 110.0) < corr("heave", 30.0) - 0.2);
}

#[test]
fn python_lists_the_channels_and_decodes_a_message_of_each() {
    let have = std::process::Command::new("python3")
        .args(["-c", "import mcap"])
        .status();
    assert!(
        have.is_ok_and(|s| s.success()),
        "python3 with the mcap package is needed: python3 -m pip install -r tools/replay/requirements.txt"
    );
    let dir = scratch_dir("replay-python");
    let (_, log) = simulated_log(&dir, 30);
    let out = std::process::Command::new("python3")
        .args([
            repo("tools/replay/list_log.py").to_str().unwrap(),
            log.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let channels: Vec<serde_json::Value> = text.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    let topics: Vec<&str> = channels.iter().map(|c| c["topic"].as_str().unwrap()).collect();
    assert_eq!(topics, ["/motion", "/waves", "/truth"]);
    assert_eq!(channels[0]["first"]["x"].as_array().unwrap().len(), 6);
    assert!(channels[1]["first"]["radius_m"].as_f64().unwrap() > 0.0);
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
        meta.insert("shipcast_schema_version".to_string(), "2".to_string());
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
        err.contains("schema version 2") && err.contains("upgrade shipcast"),
        "{err}"
    );
}
