//! Import of external recordings (pure: text in, records out): motion time series and wave-probe
//! records in CSV, so a model test or a sea trial can be replayed and scored without writing code
//! (`shipcast import`, which writes them as a log).
//!
//! Layout (a header row naming the columns, in any order; lines starting with `#` are comments;
//! times in seconds on one clock for every file):
//!
//! Motion, one row per sample of one vessel:
//!   `time_s, vessel, surge_m, sway_m, heave_m, roll_deg, pitch_deg, yaw_deg`
//!   and optionally the velocities `surge_m_s, sway_m_s, heave_m_s, roll_deg_s, pitch_deg_s,
//!   yaw_deg_s` (all six or none: without them they are central differences of the displacements).
//!   `vessel` is the body's name in the system file or its 0-based index. Displacements about the mean
//!   position, body frame, DOF conventions of DESIGN.md section 1 (rotations in degrees here).
//!
//! Wave probe, one row per sample, evenly spaced:
//!   `time_s, elevation_m` and optionally `east_m, north_m` (the probe's position in the earth frame,
//!   constant; default the site origin) and `towards_deg` (compass direction the waves travel to,
//!   constant; or given on the command line). A probe sees a long-crested sea: every `period_s` a
//!   field is fitted to the last `window_s` of the record ([`crate::waves::observe::from_probe`]).

use crate::hydro::Dof;
use crate::shell::record::{MotionRecord, WavesRecord};
use crate::waves::field::heading_from_compass_deg;
use crate::waves::observe::from_probe;

/// A wave-probe record as read.
#[derive(Debug, Clone, PartialEq)]
pub struct ProbeRecord {
    pub time_s: Vec<f64>,
    pub elevation_m: Vec<f64>,
    pub position_m: [f64; 2],
    /// Compass degrees the waves travel to, if the file says.
    pub towards_deg: Option<f64>,
}

/// How probe records become fields.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeOptions {
    pub period_s: f64,
    pub window_s: f64,
    pub band_rad_s: (f64, f64),
    pub g_m_s2: f64,
    pub depth_m: Option<f64>,
    /// Used when the file has no `towards_deg` column.
    pub towards_deg: Option<f64>,
}

/// The rows of a CSV text: the header's column indices by name, and each data row with its line.
struct Table {
    columns: Vec<String>,
    rows: Vec<(usize, Vec<String>)>,
}

fn table(text: &str, file: &str) -> Result<Table, String> {
    let mut r = csv::ReaderBuilder::new()
        .has_headers(false)
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .flexible(true)
        .from_reader(text.as_bytes());
    let mut columns: Option<Vec<String>> = None;
    let mut rows = vec![];
    for rec in r.records() {
        let rec = rec.map_err(|e| format!("{file}: {e}"))?;
        let line = rec.position().map_or(0, |p| p.line() as usize);
        let fields: Vec<String> = rec.iter().map(|s| s.to_string()).collect();
        if fields.iter().all(|f| f.is_empty()) {
            continue;
        }
        match &columns {
            None => columns = Some(fields),
            Some(c) if fields.len() != c.len() => {
                return Err(format!(
                    "{file}:{line}: {} fields, the header has {}",
                    fields.len(),
                    c.len()
                ));
            }
            Some(_) => rows.push((line, fields)),
        }
    }
    let columns = columns.ok_or_else(|| format!("{file}: no header row"))?;
    Ok(Table { columns, rows })
}

impl Table {
    fn col(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }

    fn need(&self, name: &str, file: &str) -> Result<usize, String> {
        self.col(name).ok_or_else(|| {
            format!(
                "{file}: no column \"{name}\" (the header has: {})",
                self.columns.join(", ")
            )
        })
    }

    fn num(&self, row: usize, col: usize, file: &str) -> Result<f64, String> {
        let (line, f) = &self.rows[row];
        let v: f64 = f[col]
            .parse()
            .map_err(|_| format!("{file}:{line}: {}: \"{}\" is not a number", self.columns[col], f[col]))?;
        if !v.is_finite() {
            return Err(format!("{file}:{line}: {}: {v} is not finite", self.columns[col]));
        }
        Ok(v)
    }
}

/// Motion samples from a CSV text (`file` names it in errors), vessels named as in `vessels`; sorted
/// by time per vessel, SI units (m, rad).
pub fn motion_csv(text: &str, file: &str, vessels: &[String]) -> Result<Vec<MotionRecord>, String> {
    let t = table(text, file)?;
    let ct = t.need("time_s", file)?;
    let cv = t.need("vessel", file)?;
    // the columns: each DOF's output name (`surge_m` .. `yaw_deg`) and its rate (`surge_m_s` .. `yaw_deg_s`)
    let x_cols = Dof::ALL.map(Dof::output_name);
    let v_cols = Dof::ALL.map(|d| format!("{}_s", d.output_name()));
    let cx: Vec<usize> = x_cols.iter().map(|c| t.need(c, file)).collect::<Result<_, _>>()?;
    let given: Vec<Option<usize>> = v_cols.iter().map(|c| t.col(c)).collect();
    let cvel: Option<Vec<usize>> = match given.iter().filter(|c| c.is_some()).count() {
        0 => None,
        6 => Some(given.into_iter().flatten().collect()),
        _ => {
            return Err(format!(
                "{file}: give all six velocity columns ({}) or none",
                v_cols.join(", ")
            ));
        }
    };
    let mut out: Vec<Vec<MotionRecord>> = vec![vec![]; vessels.len()];
    for r in 0..t.rows.len() {
        let (line, f) = &t.rows[r];
        let name = &f[cv];
        let vessel = vessels
            .iter()
            .position(|v| v == name)
            .or_else(|| name.parse::<usize>().ok().filter(|i| *i < vessels.len()))
            .ok_or_else(|| {
                format!(
                    "{file}:{line}: vessel \"{name}\" is not in the system (one of {})",
                    vessels.join(", ")
                )
            })?;
        let mut x = [0.0; 6];
        let mut v = [0.0; 6];
        for d in 0..6 {
            let s = if d >= 3 { std::f64::consts::PI / 180.0 } else { 1.0 };
            x[d] = t.num(r, cx[d], file)? * s;
            if let Some(c) = &cvel {
                v[d] = t.num(r, c[d], file)? * s;
            }
        }
        out[vessel].push(MotionRecord {
            vessel: vessel as u32,
            time_s: t.num(r, ct, file)?,
            x,
            v,
        });
    }
    for s in &mut out {
        s.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
        if let Some(w) = s.windows(2).find(|w| w[1].time_s == w[0].time_s) {
            return Err(format!(
                "{file}: vessel {} has two samples at {} s",
                w[0].vessel, w[0].time_s
            ));
        }
        if cvel.is_none() {
            differentiate(s);
        }
    }
    Ok(out.into_iter().flatten().collect())
}

/// Velocities by central differences (one-sided at the ends) of the displacements.
fn differentiate(s: &mut [MotionRecord]) {
    let n = s.len();
    if n < 2 {
        return;
    }
    for k in 0..n {
        let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
        let dt = s[b].time_s - s[a].time_s;
        for d in 0..6 {
            s[k].v[d] = (s[b].x[d] - s[a].x[d]) / dt;
        }
    }
}

/// A wave-probe record from a CSV text.
pub fn probe_csv(text: &str, file: &str) -> Result<ProbeRecord, String> {
    let t = table(text, file)?;
    let ct = t.need("time_s", file)?;
    let ce = t.need("elevation_m", file)?;
    let constant = |name: &str| -> Result<Option<f64>, String> {
        let Some(c) = t.col(name) else { return Ok(None) };
        let mut first = None;
        for r in 0..t.rows.len() {
            let v = t.num(r, c, file)?;
            match first {
                None => first = Some(v),
                Some(f) if f != v => {
                    return Err(format!(
                        "{file}:{}: {name} changes ({f} then {v}): a probe stays put",
                        t.rows[r].0
                    ));
                }
                _ => {}
            }
        }
        Ok(first)
    };
    let east = constant("east_m")?.unwrap_or(0.0);
    let north = constant("north_m")?.unwrap_or(0.0);
    let towards_deg = constant("towards_deg")?;
    let mut time_s = Vec::with_capacity(t.rows.len());
    let mut elevation_m = Vec::with_capacity(t.rows.len());
    for r in 0..t.rows.len() {
        time_s.push(t.num(r, ct, file)?);
        elevation_m.push(t.num(r, ce, file)?);
    }
    if time_s.len() < 8 {
        return Err(format!("{file}: {} samples: at least 8 are needed", time_s.len()));
    }
    let dt = (time_s[time_s.len() - 1] - time_s[0]) / (time_s.len() - 1) as f64;
    for (k, w) in time_s.windows(2).enumerate() {
        if !(dt > 0.0 && ((w[1] - w[0]) - dt).abs() <= 0.01 * dt) {
            return Err(format!(
                "{file}:{}: samples must be evenly spaced ({dt} s), found a step of {} s",
                t.rows[k + 1].0,
                w[1] - w[0]
            ));
        }
    }
    Ok(ProbeRecord {
        time_s,
        elevation_m,
        position_m: [east, north],
        towards_deg,
    })
}

/// The shortest default window of a probe's fit, s.
pub const MIN_PROBE_WINDOW_S: f64 = 120.0;
/// The default window's margin beyond the slowest group's travel, s: a few peak periods, so that the
/// fit resolves that group's frequency from what passed the probe around it.
pub const PROBE_WINDOW_MARGIN_S: f64 = 30.0;

/// The default window of a probe's fit: the waves that reach the farthest vessel over the next
/// seconds passed the probe as long ago as the along-wave distance over their group velocity, the
/// slowest (the band's highest frequency) longest: that travel and [`PROBE_WINDOW_MARGIN_S`], at least
/// [`MIN_PROBE_WINDOW_S`] (and that for a probe down-wave of every vessel, where it tells nothing).
pub fn default_probe_window_s(
    probe_m: [f64; 2],
    towards_deg: f64,
    vessels_m: &[[f64; 2]],
    band_rad_s: (f64, f64),
    g_m_s2: f64,
    depth_m: Option<f64>,
) -> f64 {
    let d = heading_from_compass_deg(towards_deg);
    let (s, c) = d.sin_cos();
    let along = vessels_m
        .iter()
        .map(|v| c * (v[0] - probe_m[0]) + s * (v[1] - probe_m[1]))
        .fold(0.0f64, f64::max);
    let cg = crate::waves::field::group_velocity(band_rad_s.1, g_m_s2, depth_m);
    if !(along > 0.0 && cg > 0.0) {
        return MIN_PROBE_WINDOW_S;
    }
    (along / cg + PROBE_WINDOW_MARGIN_S).max(MIN_PROBE_WINDOW_S)
}

/// The fields a probe record gives: one every `period_s`, fitted to the last `window_s` of samples.
pub fn probe_fields(p: &ProbeRecord, o: &ProbeOptions, file: &str) -> Result<Vec<WavesRecord>, String> {
    let towards = p
        .towards_deg
        .or(o.towards_deg)
        .ok_or_else(|| format!("{file}: no towards_deg column: give the wave direction (--towards-deg)"))?;
    let direction = heading_from_compass_deg(towards);
    let dt = (p.time_s[p.time_s.len() - 1] - p.time_s[0]) / (p.time_s.len() - 1) as f64;
    let per_window = ((o.window_s / dt).round() as usize).max(8);
    let mut out = vec![];
    let mut t = p.time_s[0] + o.window_s;
    let end = p.time_s[p.time_s.len() - 1];
    while t <= end + 1e-9 {
        let last = p.time_s.partition_point(|x| *x <= t + 1e-9);
        let first = last.saturating_sub(per_window);
        let f = from_probe(
            &p.elevation_m[first..last],
            dt,
            p.time_s[last - 1],
            p.position_m,
            direction,
            o.band_rad_s,
            o.g_m_s2,
            o.depth_m,
        )
        .map_err(|e| format!("{file}: at {t} s: {e}"))?;
        out.push(WavesRecord::of(&f));
        t += o.period_s;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ships() -> Vec<String> {
        vec!["carrier".into(), "lighter".into()]
    }

    #[test]
    fn motion_columns_in_any_order_with_names_or_indices_and_differentiated() {
        let text = "# a model test\nvessel,time_s,heave_m,surge_m,sway_m,roll_deg,pitch_deg,yaw_deg\n\
                    carrier,0.0,0.0,0,0,0,0,0\ncarrier,1.0,1.0,0,0,90,0,0\n1,0.5,0.2,0,0,0,0,0\ncarrier,2.0,4.0,0,0,0,0,0\n";
        let m = motion_csv(text, "m.csv", &ships()).unwrap();
        assert_eq!(m.len(), 4);
        let c: Vec<&MotionRecord> = m.iter().filter(|r| r.vessel == 0).collect();
        assert_eq!(c[1].x[2], 1.0);
        assert!((c[1].x[3] - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert_eq!(c[1].v[2], 2.0); // (4 - 0) / 2
        assert_eq!(c[0].v[2], 1.0); // one-sided
        assert_eq!(m.iter().filter(|r| r.vessel == 1).count(), 1);
    }

    #[test]
    fn motion_errors_name_file_line_and_column() {
        let h = "time_s,vessel,surge_m,sway_m,heave_m,roll_deg,pitch_deg,yaw_deg\n";
        let e = motion_csv(&format!("{h}0,carrier,0,0,x,0,0,0\n"), "m.csv", &ships()).unwrap_err();
        assert_eq!(e, "m.csv:2: heave_m: \"x\" is not a number");
        let e = motion_csv(&format!("{h}0,tug,0,0,0,0,0,0\n"), "m.csv", &ships()).unwrap_err();
        assert!(e.starts_with("m.csv:2: vessel \"tug\" is not in the system"), "{e}");
        let e = motion_csv("time_s,vessel,heave_m\n", "m.csv", &ships()).unwrap_err();
        assert!(e.starts_with("m.csv: no column \"surge_m\""), "{e}");
        let e = motion_csv(&format!("{h}0,carrier,0,0\n"), "m.csv", &ships()).unwrap_err();
        assert_eq!(e, "m.csv:2: 4 fields, the header has 8");
        let e = motion_csv(&h.replace('\n', ",heave_m_s\n"), "m.csv", &ships()).unwrap_err();
        assert!(e.contains("all six velocity columns"), "{e}");
    }

    #[test]
    fn a_probe_record_gives_a_field_every_period_that_reproduces_it() {
        let (w, a) = (0.6f64, 1.2f64);
        let mut text = String::from("time_s,elevation_m,east_m,north_m,towards_deg\n");
        for k in 0..=2400 {
            let t = 0.1 * k as f64;
            text.push_str(&format!("{t},{},500,0,270\n", a * (w * t).cos()));
        }
        let p = probe_csv(&text, "p.csv").unwrap();
        assert_eq!(p.position_m, [500.0, 0.0]);
        let o = ProbeOptions {
            period_s: 2.0,
            window_s: 2.0 * std::f64::consts::PI / w * 10.0,
            band_rad_s: (0.2, 2.0),
            g_m_s2: 9.81,
            depth_m: None,
            towards_deg: None,
        };
        let fields = probe_fields(&p, &o, "p.csv").unwrap();
        assert_eq!(fields.len(), ((240.0 - o.window_s) / 2.0).floor() as usize + 1);
        let f = fields.last().unwrap().field().unwrap();
        let eta = f.elevation_at([500.0, 0.0], 240.0);
        assert!((eta - a * (w * 240.0).cos()).abs() < 0.02 * a, "{eta}");
        let e = probe_csv("time_s,elevation_m\n0,0\n1,0\n3,0\n4,0\n5,0\n6,0\n7,0\n8,0\n", "p.csv").unwrap_err();
        assert!(e.contains("samples must be evenly spaced"), "{e}");
    }

    /// Was: the window was 120 s whatever the probe's distance, so a probe 600 m up-wave fitted none
    /// of the short waves that reach the vessel in the next minute (they passed it 190 s ago).
    #[test]
    fn the_default_window_follows_the_probe_distance() {
        let band = (0.25, 1.6);
        let cg = crate::waves::field::group_velocity(1.6, 9.81, None);
        // waves to the west (270), the probe 600 m east of the vessel: up-wave
        let w = default_probe_window_s([600.0, 0.0], 270.0, &[[0.0, 0.0]], band, 9.81, None);
        assert!(
            (w - (600.0 / cg + PROBE_WINDOW_MARGIN_S)).abs() < 1e-9 && w > 190.0,
            "{w}"
        );
        // the farthest of two vessels decides
        let w2 = default_probe_window_s([600.0, 0.0], 270.0, &[[0.0, 0.0], [-100.0, 50.0]], band, 9.81, None);
        assert!((w2 - (700.0 / cg + PROBE_WINDOW_MARGIN_S)).abs() < 1e-9, "{w2}");
        // close by, or down-wave: the shortest window
        assert_eq!(
            default_probe_window_s([50.0, 0.0], 270.0, &[[0.0, 0.0]], band, 9.81, None),
            MIN_PROBE_WINDOW_S
        );
        assert_eq!(
            default_probe_window_s([600.0, 0.0], 90.0, &[[0.0, 0.0]], band, 9.81, None),
            MIN_PROBE_WINDOW_S
        );
    }
}
