//! Recorded logs (shell): MCAP files of JSON messages, and replay through the daemon's own engine.
//!
//! Why MCAP: chunked, indexed, compressed (zstd), self-describing (each channel names its schema), with
//! off-the-shelf readers in Python, C++, Go, TypeScript (`pip install mcap`, Foxglove); a file cut short
//! is readable up to its last complete chunk. Messages are JSON (encoding `json`, JSON-schema schemas) so
//! any tool can read them without shipcast; numbers are written with shortest round-trip formatting, so
//! a replay sees bit-for-bit the values that were recorded. Log time = the data clock in nanoseconds.
//!
//! Channels (each with channel metadata `shipcast_schema_version`):
//! - `/motion`: `{"vessel", "time_s", "x": [6], "v": [6]}` (measured; body-frame surge..yaw, m and rad)
//! - `/waves`: `{"time_s", "ref_east_m", "ref_north_m", "radius_m", "depth_m", "g_m_s2",
//!   "components": [[omega_rad_s, direction_rad, re_m, im_m], ...]}` (earth frame, as on the wire)
//! - `/truth`: like `/motion`, the simulator's true motion (absent from real logs)
//! - `/forecast`: `{"issue_time_s", "dt_s", "steps", "flags", "wave_time_s", "motion_time_s",
//!   "compute_ms", "horizon_s": [..], "values": [...]}` (series-major as on the wire)

use crate::ipc::wire::{ForecastHeader, MotionSample, SCHEMA_VERSION};
use crate::waves::field::{FlatHeader, WaveField};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::{BufWriter, Seek, Write};
use std::path::Path;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MotionRecord {
    pub vessel: u32,
    pub time_s: f64,
    pub x: [f64; 6],
    pub v: [f64; 6],
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WavesRecord {
    pub time_s: f64,
    pub ref_east_m: f64,
    pub ref_north_m: f64,
    pub radius_m: f64,
    pub depth_m: f64,
    pub g_m_s2: f64,
    pub components: Vec<[f64; 4]>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ForecastRecord {
    pub issue_time_s: f64,
    pub dt_s: f64,
    pub steps: u32,
    pub flags: u32,
    pub wave_time_s: f64,
    pub motion_time_s: f64,
    pub compute_ms: f64,
    pub horizon_s: Vec<f64>,
    pub values: Vec<f64>,
}

impl MotionRecord {
    pub fn to_wire(&self) -> MotionSample {
        MotionSample {
            schema_version: SCHEMA_VERSION,
            vessel: self.vessel,
            time_s: self.time_s,
            x: self.x,
            v: self.v,
        }
    }
}

impl WavesRecord {
    pub fn of(f: &WaveField) -> WavesRecord {
        let h = f.flat_header();
        WavesRecord {
            time_s: h.time_s,
            ref_east_m: h.reference_m[0],
            ref_north_m: h.reference_m[1],
            radius_m: h.radius_m,
            depth_m: h.depth_m,
            g_m_s2: h.g_m_s2,
            components: f.flat_rows().collect(),
        }
    }

    pub fn field(&self) -> Result<WaveField, String> {
        let h = FlatHeader {
            time_s: self.time_s,
            reference_m: [self.ref_east_m, self.ref_north_m],
            radius_m: self.radius_m,
            depth_m: self.depth_m,
            g_m_s2: self.g_m_s2,
        };
        WaveField::from_flat(h, self.components.iter().copied()).map_err(|e| e.to_string())
    }
}

impl ForecastRecord {
    pub fn of(h: &ForecastHeader, values: &[f64]) -> ForecastRecord {
        ForecastRecord {
            issue_time_s: h.issue_time_s,
            dt_s: h.dt_s,
            steps: h.steps,
            flags: h.flags,
            wave_time_s: h.wave_time_s,
            motion_time_s: h.motion_time_s,
            compute_ms: h.compute_ms,
            horizon_s: h.horizon_s[..h.n_vessels as usize].to_vec(),
            values: values.to_vec(),
        }
    }
}

/// A log being written.
pub struct Recorder<W: Write + Seek> {
    w: mcap::Writer<W>,
    channels: BTreeMap<&'static str, u16>,
    seq: u32,
    /// Message bytes written so far (before compression).
    pub bytes: u64,
}

/// The daemon's recording: `shipcast-<n>.mcap` files in a directory, a new one past a size.
pub struct RotatingRecorder {
    dir: std::path::PathBuf,
    rotate_bytes: u64,
    /// Log seconds per file (None: by size only).
    rotate_s: Option<f64>,
    /// Log time of the current file's first message.
    file_start_s: Option<f64>,
    index: u32,
    current: Option<Recorder<BufWriter<std::fs::File>>>,
}

impl RotatingRecorder {
    /// Files `dir/shipcast-<unix time>-NNNN.mcap`, a new one past `rotate_mb` MB of messages or, when
    /// given, `rotate_s` seconds of log time.
    pub fn new(dir: &Path, rotate_mb: f64, rotate_s: Option<f64>) -> Result<Self, Error> {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let stamp = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_secs())
            .unwrap_or(0);
        let mut r = RotatingRecorder {
            dir: dir.join(format!("shipcast-{stamp}")),
            rotate_bytes: (rotate_mb * 1e6) as u64,
            rotate_s,
            file_start_s: None,
            index: 0,
            current: None,
        };
        r.open()?;
        Ok(r)
    }

    fn open(&mut self) -> Result<(), Error> {
        let p = std::path::PathBuf::from(format!("{}-{:04}.mcap", self.dir.display(), self.index));
        self.current = Some(Recorder::create(&p)?);
        self.index += 1;
        Ok(())
    }

    /// Starts a new file if the current one is full or long enough (before a message at `time_s`).
    fn rotate_if_due(&mut self, time_s: f64) -> Result<(), Error> {
        let too_long = match (self.rotate_s, self.file_start_s) {
            (Some(r), Some(t0)) => time_s - t0 >= r,
            _ => false,
        };
        if (too_long || self.current.as_ref().is_some_and(|c| c.bytes > self.rotate_bytes))
            && let Some(c) = self.current.take()
        {
            c.finish()?;
            self.open()?;
            self.file_start_s = None;
        }
        if self.file_start_s.is_none() {
            self.file_start_s = Some(time_s);
        }
        Ok(())
    }

    pub fn write<T: Serialize>(&mut self, topic: &'static str, time_s: f64, msg: &T) -> Result<(), Error> {
        self.rotate_if_due(time_s)?;
        match self.current.as_mut() {
            Some(c) => c.write(topic, time_s, msg),
            None => Ok(()),
        }
    }

    /// Writes a record on its channel.
    pub fn record(&mut self, t: f64, r: &Record) -> Result<(), Error> {
        self.rotate_if_due(t)?;
        match self.current.as_mut() {
            Some(c) => c.record(t, r),
            None => Ok(()),
        }
    }

    pub fn finish(mut self) -> Result<(), Error> {
        match self.current.take() {
            Some(c) => c.finish(),
            None => Ok(()),
        }
    }
}

pub type Error = Box<dyn std::error::Error + Send + Sync>;

pub mod import;

const TOPICS: [(&str, &str); 5] = [
    ("/motion", "shipcast.Motion"),
    ("/waves", "shipcast.Waves"),
    ("/truth", "shipcast.Motion"),
    ("/forecast", "shipcast.Forecast"),
    ("/tick", "shipcast.Tick"),
];

/// A cadence tick of a recording daemon (its engine clock is the log time).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TickRecord {
    pub clock_s: f64,
}

impl Recorder<BufWriter<std::fs::File>> {
    pub fn create(path: &Path) -> Result<Self, Error> {
        let f = std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
        Recorder::new(BufWriter::new(f))
    }
}

impl<W: Write + Seek> Recorder<W> {
    pub fn new(w: W) -> Result<Self, Error> {
        let mut w = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Zstd))
            .chunk_size(Some(1 << 20))
            .profile("shipcast")
            .create(w)?;
        let mut channels = BTreeMap::new();
        let mut meta = BTreeMap::new();
        meta.insert("shipcast_schema_version".to_string(), SCHEMA_VERSION.to_string());
        for (topic, schema) in TOPICS {
            let sid = w.add_schema(schema, "jsonschema", br#"{"type":"object"}"#)?;
            channels.insert(topic, w.add_channel(sid, topic, "json", &meta)?);
        }
        Ok(Recorder {
            w,
            channels,
            seq: 0,
            bytes: 0,
        })
    }

    /// Writes a record on its channel.
    pub fn record(&mut self, t: f64, r: &Record) -> Result<(), Error> {
        match r {
            Record::Motion(m) => self.write("/motion", t, m),
            Record::Waves(w) => self.write("/waves", t, w),
            Record::Truth(m) => self.write("/truth", t, m),
            Record::Forecast(f) => self.write("/forecast", t, f),
            Record::Tick(k) => self.write("/tick", t, k),
        }
    }

    pub fn write<T: Serialize>(&mut self, topic: &'static str, time_s: f64, msg: &T) -> Result<(), Error> {
        let id = *self
            .channels
            .get(topic)
            .ok_or_else(|| format!("unknown topic {topic}"))?;
        let data = serde_json::to_vec(msg)?;
        self.bytes += data.len() as u64;
        let t = (time_s.max(0.0) * 1e9) as u64;
        self.seq += 1;
        self.w.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: id,
                sequence: self.seq,
                log_time: t,
                publish_time: t,
            },
            &data,
        )?;
        Ok(())
    }

    pub fn finish(mut self) -> Result<(), Error> {
        self.w.finish()?;
        Ok(())
    }
}

/// What a log holds, in log-time order.
#[derive(Debug, Clone)]
pub enum Record {
    Motion(MotionRecord),
    Waves(WavesRecord),
    Truth(MotionRecord),
    Forecast(ForecastRecord),
    Tick(TickRecord),
}

/// A log read as far as it can be: the records, and a warning when it stopped early (truncated or
/// corrupt) or skipped messages.
pub struct Read {
    pub records: Vec<(f64, Record)>,
    pub warnings: Vec<String>,
}

/// Reads a log. A newer schema version is an error; a truncated or corrupt tail keeps every message
/// before it (with a warning); an undecodable message is skipped (counted in a warning).
pub fn read(path: &Path) -> Result<Read, Error> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = Read {
        records: vec![],
        warnings: vec![],
    };
    let stream = mcap::MessageStream::new_with_options(&bytes, mcap::read::Options::IgnoreEndMagic.into())
        .map_err(|e| format!("{}: not an MCAP log: {e}", path.display()))?;
    let mut skipped = 0usize;
    for m in stream {
        let m = match m {
            Ok(m) => m,
            Err(e) => {
                out.warnings.push(format!(
                    "{}: the log stops being readable after {} messages ({e}): using what came before",
                    path.display(),
                    out.records.len()
                ));
                break;
            }
        };
        if let Some(v) = m.channel.metadata.get("shipcast_schema_version") {
            let v: u32 = v.parse().unwrap_or(u32::MAX);
            if v > SCHEMA_VERSION {
                return Err(format!(
                    "{}: channel {} is schema version {v}; this shipcast reads up to {SCHEMA_VERSION}: upgrade shipcast",
                    path.display(),
                    m.channel.topic
                )
                .into());
            }
        }
        let t = m.log_time as f64 * 1e-9;
        let rec = match m.channel.topic.as_str() {
            "/motion" => serde_json::from_slice(&m.data).map(Record::Motion),
            "/truth" => serde_json::from_slice(&m.data).map(Record::Truth),
            "/waves" => serde_json::from_slice(&m.data).map(Record::Waves),
            "/forecast" => serde_json::from_slice(&m.data).map(Record::Forecast),
            "/tick" => serde_json::from_slice(&m.data).map(Record::Tick),
            _ => continue,
        };
        match rec {
            Ok(r) => out.records.push((t, r)),
            Err(_) => skipped += 1,
        }
    }
    if skipped > 0 {
        out.warnings.push(format!(
            "{}: {skipped} messages could not be decoded and were skipped",
            path.display()
        ));
    }
    Ok(out)
}

/// Feeds a log's inputs through the daemon's engine and computer on the log's clock, forecasts computed
/// inline (no overruns: replay is not real time). A log recorded by the daemon carries its ticks
/// (`/tick`, log time = the engine's clock): replay ticks exactly there and so takes every decision the
/// live daemon took; a log without ticks (the simulator's) is ticked every `period_s` of log time.
/// `on_output` sees every forecast and every tick's status; `pace` is called with each tick's log time
/// (the shell sleeps there for `--speed`, and publishes the inputs up to it).
pub fn drive(
    cfg: &crate::service::config::ShipcastConfig,
    sys: &crate::hydro::VesselSystem,
    records: &[(f64, Record)],
    mut pace: impl FnMut(f64),
    mut on_output: impl FnMut(crate::ipc::Output),
) -> Result<crate::service::Counters, Error> {
    use crate::ipc::{Input, Output};
    use crate::service::{Computer, Engine, rom_options};
    let model = crate::rom::TimeModel::new(sys, rom_options(cfg))?;
    let mut engine = Engine::new(cfg, sys, &model);
    let mut computer = Computer::new(model, sys.spec.bodies.len(), cfg.forecast.horizon_s);
    let period = cfg.forecast.period_s;
    let mut next_tick: Option<f64> = None;
    let mut tick = |at: f64, engine: &mut Engine, computer: &mut Computer| {
        pace(at);
        if let Some(job) = engine.tick(at) {
            let d = computer.run(job, || 0.0);
            if let Some(o @ Output::Forecast(..)) = engine.done(d) {
                on_output(o);
            }
        }
        on_output(Output::Status(engine.status(at, at, true)));
    };
    let recorded_ticks = records.iter().any(|(_, r)| matches!(r, Record::Tick(_)));
    for (t, r) in records {
        if recorded_ticks {
            if let Record::Tick(k) = r {
                tick(k.clock_s, &mut engine, &mut computer);
            }
        } else {
            let mut nt = next_tick.unwrap_or(*t);
            while nt <= *t {
                tick(nt, &mut engine, &mut computer);
                nt += period;
            }
            next_tick = Some(nt);
        }
        match r {
            Record::Motion(m) => engine.input(Input::Motion(m.to_wire()), *t),
            Record::Waves(w) => match w.field() {
                Ok(f) => engine.input(Input::Waves(f), *t),
                Err(e) => engine.input(Input::Rejected(e), *t),
            },
            Record::Truth(_) | Record::Forecast(_) | Record::Tick(_) => {}
        }
    }
    Ok(engine.counters.clone())
}
