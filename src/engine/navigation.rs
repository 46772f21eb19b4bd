//! Each vessel's navigation (pure): the fixes of its GNSS and gyro compass, judged, kept over a short
//! window, and turned into the pose of the seakeeping frame at a forecast's start.
//!
//! Conventions: the wire's compass angles (degrees clockwise from true north) and rate of turn
//! (positive to starboard) are converted here, once, on arrival ([`Fix::of`]) to the earth frame of
//! DESIGN.md section 1: x east, y north, angles counterclockwise from east in radians, turning to port
//! positive. Headings are unwrapped as they arrive, so a turn through north is continuous.
//!
//! The pose at t0 is a least-squares straight line through the window's fixes, per value (heading,
//! east, north), evaluated at t0: the wave-frequency yaw and sway in the fixes average out and a steady
//! turn is followed without lag (the rate of turn is the heading's slope; a wire rate of turn is
//! checked but not used: it carries the wave-frequency yaw rate). Fixes spanning less than
//! [`MIN_TREND_SHARE`] of the window give no rate of turn, and positions moved by the mean velocity. The forward speed is the mean speed through the water where the
//! sensor gives it, else the mean speed over ground projected on the heading (no current known).

use super::message::{NavigationSample, nav_valid};
use crate::waves::field::heading_from_compass_deg;
use std::collections::VecDeque;
use std::f64::consts::TAU;

/// The fastest speed a navigation fix may report, m/s (50 knots).
pub const MAX_SPEED_M_S: f64 = 25.0;
/// The fastest rate of turn a fix may report, deg/s (a ship's, with room).
pub const MAX_TURN_DEG_S: f64 = 30.0;
/// The fixes must span this share of the window for their trend (rate of turn, the position's line)
/// to be used.
pub const MIN_TREND_SHARE: f64 = 0.5;
/// Fixes kept beyond the fitting window, s.
const KEEP_MARGIN_S: f64 = 5.0;

/// One fix, in the earth frame.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Fix {
    pub time_s: f64,
    /// Reference point, m east and north.
    pub position_m: [f64; 2],
    /// Heading of the vessel's +x, counterclockwise from east, rad (unwrapped against the fix before).
    pub heading_rad: f64,
    /// Velocity over ground, m/s, east and north.
    pub velocity_m_s: [f64; 2],
    /// Speed through the water, m/s, when given.
    pub stw_m_s: Option<f64>,
}

/// Why a fix was refused.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NavRefusal {
    NonFinite,
    /// Beyond what a ship does: speed, rate of turn, heading (which field).
    Implausible(&'static str),
    /// Older than (or as old as) the newest fix kept.
    Late,
}

impl Fix {
    /// A wire sample in the earth frame; None for a value that is not finite or not plausible.
    pub fn of(s: &NavigationSample) -> Result<Fix, NavRefusal> {
        let stw = (s.valid & nav_valid::STW != 0).then_some(s.stw_m_s);
        let rot = (s.valid & nav_valid::ROT != 0).then_some(s.rot_deg_s);
        let values = [s.time_s, s.east_m, s.north_m, s.heading_deg, s.sog_m_s, s.cog_deg];
        if values
            .iter()
            .chain(stw.iter())
            .chain(rot.iter())
            .any(|v| !v.is_finite())
        {
            return Err(NavRefusal::NonFinite);
        }
        if !(0.0..=MAX_SPEED_M_S).contains(&s.sog_m_s) || stw.is_some_and(|v| v.abs() > MAX_SPEED_M_S) {
            return Err(NavRefusal::Implausible("speed"));
        }
        if rot.is_some_and(|r| r.abs() > MAX_TURN_DEG_S) {
            return Err(NavRefusal::Implausible("rate of turn"));
        }
        if s.heading_deg.abs() > 720.0 || s.cog_deg.abs() > 720.0 {
            return Err(NavRefusal::Implausible("heading or course"));
        }
        let cog = heading_from_compass_deg(s.cog_deg);
        Ok(Fix {
            time_s: s.time_s,
            position_m: [s.east_m, s.north_m],
            heading_rad: heading_from_compass_deg(s.heading_deg),
            velocity_m_s: [s.sog_m_s * cog.cos(), s.sog_m_s * cog.sin()],
            stw_m_s: stw,
        })
    }
}

/// The seakeeping frame's pose at a time, from a vessel's navigation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Heading of the vessel's +x, counterclockwise from east, rad.
    pub heading_rad: f64,
    /// Its reference point, m east and north.
    pub position_m: [f64; 2],
    /// Rate of turn, rad/s, counterclockwise (to port) positive.
    pub turn_rate_rad_s: f64,
    /// Forward speed through the water along the heading, m/s.
    pub speed_m_s: f64,
    /// Velocity over ground, m/s, east and north.
    pub velocity_m_s: [f64; 2],
}

/// One vessel's recent fixes.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct NavTrack {
    fixes: VecDeque<Fix>,
    /// Whether any fix was ever taken.
    seen: bool,
}

impl NavTrack {
    /// Takes a fix (its heading unwrapped against the one before); keeps `window_s` (and a margin) of
    /// them. Refuses late and duplicate fixes.
    pub fn push(&mut self, s: &NavigationSample, window_s: f64) -> Result<(), NavRefusal> {
        let mut f = Fix::of(s)?;
        if let Some(last) = self.fixes.back() {
            if f.time_s <= last.time_s {
                return Err(NavRefusal::Late);
            }
            f.heading_rad += TAU * ((last.heading_rad - f.heading_rad) / TAU).round();
        }
        self.fixes.push_back(f);
        self.seen = true;
        while self
            .fixes
            .front()
            .is_some_and(|o| o.time_s < f.time_s - window_s - KEEP_MARGIN_S)
        {
            self.fixes.pop_front();
        }
        Ok(())
    }

    /// Forgets the fixes (a clock step): the next fix starts the track again.
    pub fn restart(&mut self) {
        self.fixes.clear();
    }

    pub fn seen(&self) -> bool {
        self.seen
    }

    pub fn newest_time_s(&self) -> Option<f64> {
        self.fixes.back().map(|f| f.time_s)
    }

    /// The pose at `t0_s` from the fixes of the last `window_s` before the newest: a least-squares
    /// line per value, evaluated at t0 (a single fix: its values, not turning). None without fixes.
    pub fn pose_at(&self, t0_s: f64, window_s: f64) -> Option<Pose> {
        let newest = self.newest_time_s()?;
        let used: Vec<&Fix> = self.fixes.iter().filter(|f| f.time_s >= newest - window_s).collect();
        let n = used.len() as f64;
        let tm = used.iter().map(|f| f.time_s).sum::<f64>() / n;
        let stt: f64 = used.iter().map(|f| (f.time_s - tm).powi(2)).sum();
        // fixes spanning less than half the window give no trend: a few fixes would turn their yaw
        // noise into a rate of turn the forecast would follow for minutes
        let span = newest - used[0].time_s;
        let trend = span >= MIN_TREND_SHARE * window_s && stt > 0.0;
        let velocity = [
            used.iter().map(|f| f.velocity_m_s[0]).sum::<f64>() / n,
            used.iter().map(|f| f.velocity_m_s[1]).sum::<f64>() / n,
        ];
        // a line through the fixes, at t0 (without a trend: their mean, moved at `drift` to t0)
        let line = |value: &dyn Fn(&Fix) -> f64, drift: f64| -> (f64, f64) {
            let mean = used.iter().map(|f| value(f)).sum::<f64>() / n;
            let slope = if trend {
                used.iter().map(|f| (f.time_s - tm) * (value(f) - mean)).sum::<f64>() / stt
            } else {
                drift
            };
            (mean + slope * (t0_s - tm), slope)
        };
        let (heading, rate) = line(&|f| f.heading_rad, 0.0);
        let (east, _) = line(&|f| f.position_m[0], velocity[0]);
        let (north, _) = line(&|f| f.position_m[1], velocity[1]);
        let stw: Vec<f64> = used.iter().filter_map(|f| f.stw_m_s).collect();
        // each fix's velocity along its own heading (the mean velocity lags a turning heading)
        let speed = if stw.is_empty() {
            used.iter()
                .map(|f| f.velocity_m_s[0] * f.heading_rad.cos() + f.velocity_m_s[1] * f.heading_rad.sin())
                .sum::<f64>()
                / n
        } else {
            stw.iter().sum::<f64>() / stw.len() as f64
        };
        Some(Pose {
            heading_rad: heading,
            position_m: [east, north],
            turn_rate_rad_s: rate,
            speed_m_s: speed,
            velocity_m_s: velocity,
        })
    }
}

/// A wire sample from a fix in the earth frame (the simulator's, and tests'): compass degrees, rate of
/// turn positive to starboard, speed through the water as given.
pub fn to_wire(vessel: u32, time_s: f64, fix: &crate::sim::NavFix) -> NavigationSample {
    let compass = |rad: f64| (90.0 - rad.to_degrees()).rem_euclid(360.0);
    NavigationSample {
        schema_version: super::message::SCHEMA_VERSION,
        vessel,
        time_s,
        east_m: fix.position_m[0],
        north_m: fix.position_m[1],
        heading_deg: compass(fix.heading_rad),
        sog_m_s: fix.speed_m_s,
        cog_deg: compass(fix.course_rad),
        stw_m_s: fix.stw_m_s,
        rot_deg_s: -fix.turn_rate_rad_s.to_degrees(),
        valid: nav_valid::STW | nav_valid::ROT,
        reserved: 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t: f64, heading_deg: f64, east: f64, north: f64) -> NavigationSample {
        NavigationSample {
            schema_version: 1,
            vessel: 0,
            time_s: t,
            east_m: east,
            north_m: north,
            heading_deg,
            sog_m_s: 3.0,
            cog_deg: heading_deg,
            ..NavigationSample::default()
        }
    }

    #[test]
    fn compass_angles_become_counterclockwise_from_east() {
        let f = Fix::of(&sample(0.0, 0.0, 0.0, 0.0)).unwrap();
        assert!((f.heading_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        // heading north at 3 m/s: velocity (0, 3)
        assert!(f.velocity_m_s[0].abs() < 1e-12 && (f.velocity_m_s[1] - 3.0).abs() < 1e-12);
    }

    #[test]
    fn a_steady_turn_through_north_is_followed_without_lag() {
        // turning to starboard at 0.2 deg/s through north: compass 350 -> 10 deg
        let mut tr = NavTrack::default();
        for k in 0..=100 {
            let t = k as f64;
            let c = (350.0 + 0.2 * t).rem_euclid(360.0);
            tr.push(&sample(t, c, 0.0, 0.0), 30.0).unwrap();
        }
        let p = tr.pose_at(101.0, 30.0).unwrap();
        let want = heading_from_compass_deg(350.0 + 0.2 * 101.0);
        let d = (p.heading_rad - want + std::f64::consts::PI).rem_euclid(TAU) - std::f64::consts::PI;
        assert!(d.abs() < 1e-9, "{d}");
        // to starboard is clockwise: a negative counterclockwise rate
        assert!(
            (p.turn_rate_rad_s + 0.2f64.to_radians()).abs() < 1e-12,
            "{}",
            p.turn_rate_rad_s
        );
        assert!((p.speed_m_s - 3.0).abs() < 1e-3);
    }

    /// Was: two fixes 1 s apart, their heading 1 deg apart from wave-frequency yaw, gave a rate of turn
    /// of 1 deg/s that a forecast would follow for minutes.
    #[test]
    fn a_few_fixes_give_no_rate_of_turn() {
        let mut tr = NavTrack::default();
        tr.push(&sample(0.0, 90.0, 0.0, 0.0), 30.0).unwrap();
        tr.push(&sample(1.0, 91.0, 0.0, 3.0), 30.0).unwrap();
        let p = tr.pose_at(1.5, 30.0).unwrap();
        assert_eq!(p.turn_rate_rad_s, 0.0);
        // the mean heading, and the mean position moved by the velocity over ground
        assert!((p.heading_rad - heading_from_compass_deg(90.5)).abs() < 1e-12);
        assert!((p.position_m[0] - 3.0).abs() < 1e-3, "{:?}", p.position_m);
    }

    #[test]
    fn bad_fixes_are_refused() {
        let mut tr = NavTrack::default();
        let mut s = sample(1.0, 10.0, 0.0, 0.0);
        s.east_m = f64::NAN;
        assert_eq!(tr.push(&s, 30.0), Err(NavRefusal::NonFinite));
        let mut s = sample(1.0, 10.0, 0.0, 0.0);
        s.sog_m_s = 80.0;
        assert!(matches!(tr.push(&s, 30.0), Err(NavRefusal::Implausible(_))));
        tr.push(&sample(1.0, 10.0, 0.0, 0.0), 30.0).unwrap();
        assert_eq!(tr.push(&sample(1.0, 10.0, 0.0, 0.0), 30.0), Err(NavRefusal::Late));
        assert!(tr.seen());
    }
}
