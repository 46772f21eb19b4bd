//! Recorded logs (shell): MCAP files of JSON messages, their record types, the recorder and the reader.
//! The daemon ([`crate::shell::daemon`]) records with it; [`crate::shell::replay`] reads logs back and feeds them
//! through the daemon's engine.
//!
//! Why MCAP: chunked, indexed, compressed (zstd), self-describing (each channel names its schema), with
//! off-the-shelf readers in Python, C++, Go, TypeScript (`pip install mcap`, Foxglove); a file cut short
//! is readable up to its last complete chunk. Messages are JSON (encoding `json`) so any tool can read
//! them without shipcast; numbers are written with shortest round-trip formatting, so a replay sees bit
//! for bit the values that were recorded. Every channel's schema is a JSON Schema (draft 2020-12,
//! encoding `jsonschema`) generated from the record types below, so Foxglove and other tools see the
//! field names, units and descriptions.
//!
//! Log time = the data clock in UNIX nanoseconds: the sample's stamp for the simulator and `import`,
//! the engine's clock (UNIX-anchored, monotonic) for the daemon's recording; publish time = log time.
//! Each file carries a metadata record `shipcast` ([`LogInfo`]: vessel names, system file, shipcast
//! version, configuration digest, log schema version).
//!
//! Channels (each with channel metadata `shipcast_schema_version` = [`LOG_SCHEMA_VERSION`]):
//! - `/motion` (`shipcast.Motion`): `{"vessel", "time_s", "x": [6], "v": [6]}` (measured; body-frame
//!   surge..yaw, m and rad)
//! - `/waves` (`shipcast.Waves`): `{"time_s", "ref_east_m", "ref_north_m", "radius_m", "depth_m",
//!   "g_m_s2", "window_s", "inner_m", "coverage_ranges_m": [...], "components": [[omega_rad_s,
//!   direction_rad, re_m, im_m], ...]}` (earth frame, as on the wire; a radar's blind zone and
//!   coverage, absent from logs before version 5 and for a field without them)
//! - `/truth` (`shipcast.Motion`): like `/motion`, the simulator's true motion (absent from real logs)
//! - `/forecast` (`shipcast.Forecast`): `{"issue_time_s", "dt_s", "steps", "flags", "wave_time_s",
//!   "motion_time_s", "compute_ms", "horizon_s": [..], "trusted_from_s": [..], "series_horizon_s":
//!   [..], "series_trusted_from_s": [..], "values": [...], "sigma": [...]}` (series-major as on the
//!   wire; `trusted_from_s` and `sigma`, the band's standard deviations, absent from logs before
//!   version 4; each series' own span, before version 6)
//! - `/navigation` (`shipcast.Navigation`): `{"vessel", "time_s", "east_m", "north_m", "heading_deg",
//!   "sog_m_s", "cog_deg", "stw_m_s", "rot_deg_s", "valid"}` (as on the wire: compass degrees,
//!   rate of turn positive to starboard; absent from logs before version 3)
//! - `/tick` (`shipcast.Tick`): `{"clock_s"}`, a cadence tick of a recording daemon
//! - `/elevation` (`foxglove.Grid`): a radar scan as the daemon received it on `<prefix>/elevation`
//!   (frame `earth`, the grid's corner and turn in `pose`, one FLOAT32 field `elevation_m`, NaN where a
//!   cell is not valid); replay inverts the scans as the daemon does
//! - `/radar` (`foxglove.Grid`, Foxglove's well-known schema): the simulated radar's elevation snapshot
//!   (frame `earth`: x east, y north, m; one FLOAT32 field `elevation_m`, NaN where the radar does not
//!   see), one per
//!   `simulate.radar.record_grid_every` scans; replay does not read it
//!
//! Version 1 logs (before JSON Schemas, metadata and `/radar`; the simulator's log times from 0) are
//! read as they are.

use crate::engine::message::{ForecastHeader, MotionSample, NavigationSample, SCHEMA_VERSION};
use crate::waves::field::{FlatHeader, WaveField, coverage_from_sectors};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::{BufWriter, Seek, Write};
use std::path::Path;

/// The version of the log format this shipcast writes (channel metadata `shipcast_schema_version`);
/// it reads this and every older one. What each version added: 2, JSON Schemas, UNIX log times, the
/// `shipcast` metadata record, `/radar`; 3, `/navigation`, `/elevation`; 4, a forecast's `sigma` and
/// `trusted_from_s`, a wave field's `window_s`; 5, a wave field's `inner_m` and `coverage_ranges_m`;
/// 6, a forecast's `series_horizon_s` and `series_trusted_from_s`, a radar field's `window_s`.
pub const LOG_SCHEMA_VERSION: u32 = 6;

/// A vessel's motion sample (measured on `/motion`, true on `/truth`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(title = "shipcast.Motion")]
pub struct MotionRecord {
    /// Index of the vessel in the system file (the `shipcast` metadata's `vessels` names them).
    pub vessel: u32,
    /// The sample's stamp, UNIX seconds.
    pub time_s: f64,
    /// Displacement, body frame: surge, sway, heave (m), roll, pitch, yaw (rad).
    pub x: [f64; 6],
    /// Velocity, body frame: m/s and rad/s (0 on `/truth`).
    pub v: [f64; 6],
}

/// A vessel's navigation fix, as on the wire (`ipc::wire::NavigationSample`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(title = "shipcast.Navigation")]
pub struct NavigationRecord {
    /// Index of the vessel in the system file.
    pub vessel: u32,
    /// The fix's stamp, UNIX seconds.
    pub time_s: f64,
    /// Position of the vessel's reference point, site tangent plane, m east.
    pub east_m: f64,
    /// ... m north.
    pub north_m: f64,
    /// True heading, deg clockwise from north.
    pub heading_deg: f64,
    /// Speed over ground, m/s.
    pub sog_m_s: f64,
    /// Course over ground, deg clockwise from north.
    pub cog_deg: f64,
    /// Speed through the water, m/s (valid bit 1).
    pub stw_m_s: f64,
    /// Rate of turn, deg/s, positive to starboard (valid bit 2).
    pub rot_deg_s: f64,
    /// Which optional values are given (`ipc::wire::nav_valid`).
    pub valid: u32,
}

impl NavigationRecord {
    pub fn of(n: &NavigationSample) -> NavigationRecord {
        NavigationRecord {
            vessel: n.vessel,
            time_s: n.time_s,
            east_m: n.east_m,
            north_m: n.north_m,
            heading_deg: n.heading_deg,
            sog_m_s: n.sog_m_s,
            cog_deg: n.cog_deg,
            stw_m_s: n.stw_m_s,
            rot_deg_s: n.rot_deg_s,
            valid: n.valid,
        }
    }

    pub fn to_wire(&self) -> NavigationSample {
        NavigationSample {
            schema_version: SCHEMA_VERSION,
            vessel: self.vessel,
            time_s: self.time_s,
            east_m: self.east_m,
            north_m: self.north_m,
            heading_deg: self.heading_deg,
            sog_m_s: self.sog_m_s,
            cog_deg: self.cog_deg,
            stw_m_s: self.stw_m_s,
            rot_deg_s: self.rot_deg_s,
            valid: self.valid,
            reserved: 0,
        }
    }
}

/// A phase-resolved wave field (the radar processor's, or fitted to a probe).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(title = "shipcast.Waves")]
pub struct WavesRecord {
    /// The field's reference time, UNIX seconds.
    pub time_s: f64,
    /// Reference point, earth frame, m east.
    pub ref_east_m: f64,
    /// Reference point, earth frame, m north.
    pub ref_north_m: f64,
    /// Radius of the observed disc, m (0: no region known; negative: a wave probe at the reference
    /// point; with `coverage_ranges_m`, the farthest of them).
    pub radius_m: f64,
    /// Water depth, m (0: deep water).
    pub depth_m: f64,
    /// Gravity, m/s2.
    pub g_m_s2: f64,
    /// A wave probe's fitted record, s (0 or absent: not said, or not a probe).
    #[serde(default)]
    pub window_s: f64,
    /// A radar's blind zone: nothing within this of the reference point was observed, m (0 or
    /// absent: none; before log version 5 not recorded).
    #[serde(default)]
    pub inner_m: f64,
    /// A radar's coverage: the farthest point observed in each of as many equal sectors of direction
    /// from the reference point (sector j spans j..j+1 times 360 / n deg, counterclockwise from
    /// east), m (absent: the disc of `radius_m`; before log version 5 not recorded).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub coverage_ranges_m: Vec<f64>,
    /// Components `[omega_rad_s, direction_rad (travel-to, counterclockwise from east), re_m, im_m]`.
    pub components: Vec<[f64; 4]>,
}

/// A forecast of every vessel DOF.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(title = "shipcast.Forecast")]
pub struct ForecastRecord {
    /// UNIX seconds (the motion's clock) of the forecast's first value.
    pub issue_time_s: f64,
    /// Step between values, s.
    pub dt_s: f64,
    /// Values per series minus one.
    pub steps: u32,
    /// Quality flags (`ipc::wire::flags`).
    pub flags: u32,
    /// Reference time of the wave field used, UNIX seconds.
    pub wave_time_s: f64,
    /// Stamp of the newest motion sample used, UNIX seconds.
    pub motion_time_s: f64,
    /// Compute time, ms.
    pub compute_ms: f64,
    /// End of the trusted span per vessel, s of lead.
    pub horizon_s: Vec<f64>,
    /// Start of the trusted span per vessel, s of lead (absent before log version 4: 0).
    #[serde(default)]
    pub trusted_from_s: Vec<f64>,
    /// Each series' own trusted span, s of lead: its end and its start (6 per vessel; absent
    /// before log version 6: the vessel's, [`ForecastRecord::series_span`]).
    #[serde(default)]
    pub series_horizon_s: Vec<f64>,
    #[serde(default)]
    pub series_trusted_from_s: Vec<f64>,
    /// Series-major: 6 series per vessel (surge..yaw, m and rad), `steps + 1` values each.
    pub values: Vec<f64>,
    /// The band: a standard deviation per value, same layout (absent before log version 4: empty).
    #[serde(default)]
    pub sigma: Vec<f64>,
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
            window_s: h.window_s,
            inner_m: h.inner_m,
            coverage_ranges_m: h.ranges_m.map_or(vec![], |r| r.to_vec()),
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
            window_s: self.window_s,
            inner_m: self.inner_m,
            ranges_m: coverage_from_sectors(&self.coverage_ranges_m).map_err(|e| e.to_string())?,
        };
        WaveField::from_flat(h, self.components.iter().copied()).map_err(|e| e.to_string())
    }
}

impl ForecastRecord {
    /// The record of a forecast as on the wire: `payload` holds the displacements, then the standard
    /// deviations (a payload without them records an empty band).
    pub fn of(h: &ForecastHeader, payload: &[f64]) -> ForecastRecord {
        let nv = (h.n_vessels as usize).min(h.horizon_s.len());
        let n = (h.steps as usize + 1) * 6 * nv;
        let (values, sigma) = if payload.len() >= 2 * n {
            (&payload[..n], &payload[n..2 * n])
        } else {
            (payload, &[][..])
        };
        ForecastRecord {
            issue_time_s: h.issue_time_s,
            dt_s: h.dt_s,
            steps: h.steps,
            flags: h.flags,
            wave_time_s: h.wave_time_s,
            motion_time_s: h.motion_time_s,
            compute_ms: h.compute_ms,
            horizon_s: h.horizon_s[..nv].to_vec(),
            trusted_from_s: h.trusted_from_s[..nv].to_vec(),
            series_horizon_s: h.series_horizon_s[..6 * nv].to_vec(),
            series_trusted_from_s: h.series_trusted_from_s[..6 * nv].to_vec(),
            values: values.to_vec(),
            sigma: sigma.to_vec(),
        }
    }

    /// Series `i`'s trusted span (from, to), s of lead: its own, or in a log without them its
    /// vessel's ((0, 0): not trusted).
    pub fn series_span(&self, i: usize) -> (f64, f64) {
        match (self.series_trusted_from_s.get(i), self.series_horizon_s.get(i)) {
            (Some(f), Some(t)) => (*f, *t),
            _ => (
                self.trusted_from_s.get(i / 6).copied().unwrap_or(0.0),
                self.horizon_s.get(i / 6).copied().unwrap_or(0.0),
            ),
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
    info: LogInfo,
    current: Option<Recorder<BufWriter<std::fs::File>>>,
}

impl RotatingRecorder {
    /// Files `dir/shipcast-<unix time>-NNNN.mcap`, a new one past `rotate_mb` MB of messages or, when
    /// given, `rotate_s` seconds of log time.
    pub fn new(dir: &Path, rotate_mb: f64, rotate_s: Option<f64>, info: LogInfo) -> Result<Self, Error> {
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
            info,
            current: None,
        };
        r.open()?;
        Ok(r)
    }

    fn open(&mut self) -> Result<(), Error> {
        let p = std::path::PathBuf::from(format!("{}-{:04}.mcap", self.dir.display(), self.index));
        self.current = Some(Recorder::create(&p, &self.info)?);
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

/// The channels: topic, schema name, schema (JSON Schema of the record type).
fn topics() -> [(&'static str, &'static str, schemars::Schema); 8] {
    use schemars::schema_for;
    [
        ("/motion", "shipcast.Motion", schema_for!(MotionRecord)),
        ("/navigation", "shipcast.Navigation", schema_for!(NavigationRecord)),
        ("/waves", "shipcast.Waves", schema_for!(WavesRecord)),
        ("/truth", "shipcast.Motion", schema_for!(MotionRecord)),
        ("/forecast", "shipcast.Forecast", schema_for!(ForecastRecord)),
        ("/tick", "shipcast.Tick", schema_for!(TickRecord)),
        ("/radar", "foxglove.Grid", schema_for!(GridRecord)),
        ("/elevation", "foxglove.Grid", schema_for!(GridRecord)),
    ]
}

/// zstd level of the chunks, and their size before compression. The bulk of a simulated log is
/// `/waves` (the two-ship demo: ~7700 components a field every 2 s, 95 % of the bytes), whose random
/// mantissas compress little; level 9 on 4 MB chunks takes it 16 % below level 3 on 1 MB chunks, at
/// about 4x the CPU time (under 1 % of a core at the demo's data rate). A file cut short loses at most
/// its last chunk (about 40 s of the demo).
const ZSTD_LEVEL: u32 = 9;
const CHUNK_BYTES: u64 = 4 << 20;

/// Log time in nanoseconds of a time in seconds, rounded to the nanosecond (exact for UNIX times:
/// reading it back with [`seconds_of_log_time`] gives the same f64).
pub fn log_time_of_seconds(time_s: f64) -> u64 {
    let t = time_s.max(0.0);
    let sec = t.floor();
    (sec as u64)
        .saturating_mul(1_000_000_000)
        .saturating_add(((t - sec) * 1e9).round() as u64)
}

/// Seconds of a log time in nanoseconds (the nearest f64).
pub fn seconds_of_log_time(ns: u64) -> f64 {
    (ns / 1_000_000_000) as f64 + (ns % 1_000_000_000) as f64 * 1e-9
}

/// A cadence tick of a recording daemon (its engine clock is the log time).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(title = "shipcast.Tick")]
pub struct TickRecord {
    /// The engine's clock, UNIX seconds (monotonic from the wall clock at the daemon's start).
    pub clock_s: f64,
}

/// Foxglove's well-known `foxglove.Grid` message (JSON encoding): a 2D grid of packed cells.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(title = "foxglove.Grid", description = "A 2D grid of data")]
pub struct GridRecord {
    /// Timestamp of grid
    pub timestamp: FoxgloveTime,
    /// Frame of reference
    pub frame_id: String,
    /// Origin of grid's corner relative to frame of reference; grid is positioned in the x-y plane
    /// relative to this origin
    pub pose: FoxglovePose,
    /// Number of grid columns
    pub column_count: u32,
    /// Size of single grid cell along x and y axes, relative to `pose`
    pub cell_size: FoxgloveVector2,
    /// Number of bytes between rows in `data`
    pub row_stride: u32,
    /// Number of bytes between cells within a row in `data`
    pub cell_stride: u32,
    /// Fields in `data`
    pub fields: Vec<FoxglovePackedElementField>,
    /// Grid cell data (base64), interpreted using `fields`, in row-major (y-major) order
    #[schemars(extend("contentEncoding" = "base64"))]
    pub data: String,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(title = "time")]
pub struct FoxgloveTime {
    pub sec: u32,
    #[schemars(range(max = 999_999_999))]
    pub nsec: u32,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(title = "foxglove.Pose")]
pub struct FoxglovePose {
    pub position: FoxgloveVector3,
    pub orientation: FoxgloveQuaternion,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(title = "foxglove.Vector2")]
pub struct FoxgloveVector2 {
    pub x: f64,
    pub y: f64,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(title = "foxglove.Vector3")]
pub struct FoxgloveVector3 {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(title = "foxglove.Quaternion")]
pub struct FoxgloveQuaternion {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub w: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(title = "foxglove.PackedElementField")]
pub struct FoxglovePackedElementField {
    /// Name of the field
    pub name: String,
    /// Byte offset from start of data buffer
    pub offset: u32,
    /// Type of data in the field (`foxglove.NumericType`: 7 = FLOAT32, little-endian)
    #[serde(rename = "type")]
    pub kind: u32,
}

/// `foxglove.NumericType` FLOAT32.
const FOXGLOVE_FLOAT32: u32 = 7;

impl GridRecord {
    /// A radar scan (its grid's corner and turn in `pose`; NaN cells kept).
    pub fn of_scan(scan: &crate::engine::message::Scan) -> GridRecord {
        let g = &scan.grid;
        let local: Vec<f64> = g.x_m.iter().map(|x| x - g.x_m[0]).collect();
        let mut r = GridRecord::elevation(
            &local,
            &g.y_m.iter().map(|y| y - g.y_m[0]).collect::<Vec<_>>(),
            &g.values,
            g.time_s,
        );
        let corner = scan
            .frame
            .to_earth(g.x_m[0] - 0.5 * r.cell_size.x, g.y_m[0] - 0.5 * r.cell_size.y);
        let half = 0.5 * scan.frame.orientation_rad;
        r.pose = FoxglovePose {
            position: FoxgloveVector3 {
                x: corner[0],
                y: corner[1],
                z: 0.0,
            },
            orientation: FoxgloveQuaternion {
                x: 0.0,
                y: 0.0,
                z: half.sin(),
                w: half.cos(),
            },
        };
        r
    }

    /// The scan of a `/elevation` record (the inverse of [`Self::of_scan`]): one FLOAT32 field, a turn
    /// about z only.
    pub fn scan(&self) -> Result<crate::engine::message::Scan, String> {
        use base64::Engine;
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(&self.data)
            .map_err(|e| format!("elevation grid data: {e}"))?;
        let nx = self.column_count as usize;
        if nx < 4 || self.cell_stride != 4 || self.row_stride as usize != 4 * nx || bytes.len() % (4 * nx) != 0 {
            return Err(format!(
                "elevation grid of {nx} columns, cell stride {}, row stride {}, {} bytes: one FLOAT32 per cell expected",
                self.cell_stride,
                self.row_stride,
                bytes.len()
            ));
        }
        let ny = bytes.len() / (4 * nx);
        let q = &self.pose.orientation;
        let theta = 2.0 * q.z.atan2(q.w);
        let (dx, dy) = (self.cell_size.x, self.cell_size.y);
        let frame = crate::waves::observe::GridFrame {
            origin_m: [self.pose.position.x, self.pose.position.y],
            orientation_rad: theta,
        };
        let origin = frame.to_earth(0.5 * dx, 0.5 * dy);
        Ok(crate::engine::message::Scan {
            grid: crate::waves::observe::Grid {
                x_m: (0..nx).map(|i| i as f64 * dx).collect(),
                y_m: (0..ny).map(|i| i as f64 * dy).collect(),
                time_s: self.timestamp.sec as f64 + self.timestamp.nsec as f64 * 1e-9,
                values: bytes
                    .chunks_exact(4)
                    .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64)
                    .collect(),
            },
            frame: crate::waves::observe::GridFrame {
                origin_m: origin,
                orientation_rad: theta,
            },
        })
    }

    /// A grid of elevations (m) at cell centres `x_m` (east) by `y_m` (north), row-major by y, stamped
    /// `time_s` (UNIX seconds); the cells are stored as little-endian f32.
    pub fn elevation(x_m: &[f64], y_m: &[f64], values: &[f64], time_s: f64) -> GridRecord {
        use base64::Engine;
        let dx = if x_m.len() > 1 { x_m[1] - x_m[0] } else { 1.0 };
        let dy = if y_m.len() > 1 { y_m[1] - y_m[0] } else { 1.0 };
        let mut bytes = Vec::with_capacity(4 * values.len());
        for v in values {
            bytes.extend_from_slice(&(*v as f32).to_le_bytes());
        }
        let sec = time_s.max(0.0).floor();
        GridRecord {
            timestamp: FoxgloveTime {
                sec: sec as u32,
                nsec: (((time_s.max(0.0) - sec) * 1e9) as u32).min(999_999_999),
            },
            frame_id: "earth".into(),
            pose: FoxglovePose {
                position: FoxgloveVector3 {
                    x: x_m.first().copied().unwrap_or(0.0) - 0.5 * dx,
                    y: y_m.first().copied().unwrap_or(0.0) - 0.5 * dy,
                    z: 0.0,
                },
                orientation: FoxgloveQuaternion {
                    x: 0.0,
                    y: 0.0,
                    z: 0.0,
                    w: 1.0,
                },
            },
            column_count: x_m.len() as u32,
            cell_size: FoxgloveVector2 { x: dx, y: dy },
            row_stride: 4 * x_m.len() as u32,
            cell_stride: 4,
            fields: vec![FoxglovePackedElementField {
                name: "elevation_m".into(),
                offset: 0,
                kind: FOXGLOVE_FLOAT32,
            }],
            data: base64::engine::general_purpose::STANDARD.encode(bytes),
        }
    }
}

/// What a log says about where it came from: the `shipcast` metadata record.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LogInfo {
    /// Vessel names in the system file's order (the records' `vessel` indexes them).
    pub vessels: Vec<String>,
    /// The system file, as the configuration names it.
    pub system_file: String,
    /// A digest of the parsed configuration (FNV-1a 64 of its debug form): two logs with the same
    /// digest were made with the same settings.
    pub config_digest: String,
    /// What wrote the log: `simulate`, `daemon`, `replay`, `import`.
    pub writer: String,
}

impl LogInfo {
    /// The record of a log written by `writer` with the configuration `cfg` (its debug form is digested)
    /// naming the system file `system_file`, for the system `sys`.
    pub fn of(
        cfg: &impl std::fmt::Debug,
        system_file: &Path,
        sys: &crate::hydro::VesselSystem,
        writer: &str,
    ) -> LogInfo {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in format!("{cfg:?}").bytes() {
            h = (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
        LogInfo {
            vessels: sys.spec.bodies.iter().map(|b| b.name.clone()).collect(),
            system_file: system_file.display().to_string(),
            config_digest: format!("fnv1a64:{h:016x}"),
            writer: writer.into(),
        }
    }

    fn metadata(&self) -> BTreeMap<String, String> {
        let mut m = BTreeMap::new();
        m.insert("vessels".into(), serde_json::json!(self.vessels).to_string());
        m.insert("system_file".into(), self.system_file.clone());
        m.insert("shipcast_version".into(), env!("CARGO_PKG_VERSION").into());
        m.insert("config_digest".into(), self.config_digest.clone());
        m.insert("writer".into(), self.writer.clone());
        m.insert("log_schema_version".into(), LOG_SCHEMA_VERSION.to_string());
        m
    }
}

impl Recorder<BufWriter<std::fs::File>> {
    pub fn create(path: &Path, info: &LogInfo) -> Result<Self, Error> {
        let f = std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
        Recorder::new(BufWriter::new(f), info).map_err(|e| format!("{}: {e}", path.display()).into())
    }
}

impl<W: Write + Seek> Recorder<W> {
    pub fn new(w: W, info: &LogInfo) -> Result<Self, Error> {
        let mut w = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Zstd))
            .compression_level(ZSTD_LEVEL)
            // the daemon's forecasts own the cores: compress on the writing thread
            .compression_threads(0)
            .chunk_size(Some(CHUNK_BYTES))
            .profile("shipcast")
            .library(format!("shipcast {}", env!("CARGO_PKG_VERSION")))
            .create(w)?;
        w.write_metadata(&mcap::records::Metadata {
            name: "shipcast".into(),
            metadata: info.metadata(),
        })?;
        let mut channels = BTreeMap::new();
        let mut meta = BTreeMap::new();
        meta.insert("shipcast_schema_version".to_string(), LOG_SCHEMA_VERSION.to_string());
        let mut schema_ids: BTreeMap<&str, u16> = BTreeMap::new();
        for (topic, name, schema) in topics() {
            let sid = match schema_ids.get(name) {
                Some(id) => *id,
                None => {
                    let id = w.add_schema(name, "jsonschema", &serde_json::to_vec(&schema)?)?;
                    schema_ids.insert(name, id);
                    id
                }
            };
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
            Record::Navigation(n) => self.write("/navigation", t, n),
            Record::Elevation(g) => self.write("/elevation", t, g),
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
        let t = log_time_of_seconds(time_s);
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
    Navigation(NavigationRecord),
    /// A radar scan (`/elevation`).
    Elevation(Box<GridRecord>),
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

/// Reads a log. A newer schema version is an error; a truncated or corrupt tail (a chunk whose CRC
/// does not match) keeps every message before it (with a warning); an undecodable message is skipped
/// (counted in a warning).
pub fn read(path: &Path) -> Result<Read, Error> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = Read {
        records: vec![],
        warnings: vec![],
    };
    // a chunk whose CRC does not match is corrupt: its messages may decode to other numbers (a
    // compressed chunk's corrupted literals are other digits), so it ends the readable part
    let options = mcap::read::Options::IgnoreEndMagic | mcap::read::Options::ValidateChunkCrcs;
    let stream = mcap::MessageStream::new_with_options(&bytes, options)
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
        let version: u32 = match m.channel.metadata.get("shipcast_schema_version") {
            Some(v) => v.parse().unwrap_or(u32::MAX),
            None => 1,
        };
        if version > LOG_SCHEMA_VERSION {
            return Err(format!(
                "{}: channel {} is schema version {version}; this shipcast reads up to {LOG_SCHEMA_VERSION}: upgrade shipcast",
                path.display(),
                m.channel.topic
            )
            .into());
        }
        // version 1 logs were read this way (and their replays are reproduced bit for bit)
        let t = if version < 2 {
            m.log_time as f64 * 1e-9
        } else {
            seconds_of_log_time(m.log_time)
        };
        let rec = match m.channel.topic.as_str() {
            "/motion" => serde_json::from_slice(&m.data).map(Record::Motion),
            "/navigation" => serde_json::from_slice(&m.data).map(Record::Navigation),
            "/elevation" => serde_json::from_slice(&m.data).map(|g| Record::Elevation(Box::new(g))),
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
