//! The synthetic sea (pure): a true sea, the true motion of the vessels computed by the ROM (optionally
//! with model error), and what the sensors would report: a radar processor's wave field over a disc
//! around the ship (gridded snapshots with noise inverted by [`crate::waves::observe`]) and IMU samples
//! with noise and bias. The shell (`shipcast simulate`) paces it in real time and publishes or records.
//!
//! Frames (DESIGN.md section 1): the earth frame is x east, y north. The system's seakeeping frame
//! starts at `origin_m` with its x axis along `heading_rad` (counterclockwise from east) and follows
//! the [`Track`] (forward speed along its heading, a steady turn from a given time); the true motion is
//! the ROM's oscillation about that frame, forced along the track ([`Forecaster::from_rest_on`]).
//! Navigation (position and heading of each vessel's reference point, speed and course over ground,
//! rate of turn) is the frame's pose plus the vessel's own surge, sway and yaw. Times are seconds from
//! the start of the simulation (the shell adds the data clock's start, `simulate.start_unix_s`).

use crate::hydro::VesselSystem;
use crate::rom::{self, Forecast, Forecaster, RomOptions, TimeModel, Track};
use crate::waves::field::{Region, WaveField};
use crate::waves::observe::{Grid, GridFrame, GridOptions, from_grids};
use crate::waves::sea::{SeaState, realize_all};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The simulated processor publishes the largest components holding this share of the inverted
/// field's variance (one per wavenumber bin otherwise: thousands, mostly noise).
pub const PROCESSOR_VARIANCE_KEPT: f64 = 0.995;

/// The radar and its processor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RadarSpec {
    /// Range: the observed disc around the system origin, m.
    pub radius_m: f64,
    /// Cells across the disc's diameter (the grid is cells x cells).
    pub cells: usize,
    /// Time between snapshots, s.
    pub period_s: f64,
    /// Elevation noise (standard deviation), m.
    pub noise_m: f64,
    /// Snapshots per inversion (>= 2 tells opposite directions apart).
    pub snapshots: usize,
    /// Frequency band the processor keeps, rad/s.
    pub omega_min_rad_s: f64,
    pub omega_max_rad_s: f64,
    /// No echo within this range of the antenna, m (0: none).
    pub blind_radius_m: f64,
    /// A sector the superstructure masks: relative bearings from, to (deg clockwise from the bow).
    pub masked_sector_deg: Option<(f64, f64)>,
}

/// The motion sensors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuSpec {
    pub rate_hz: f64,
    /// Noise (standard deviation) of translations (m) and rotations (rad); velocities get the noise
    /// times the rate / 10.
    pub noise_m: f64,
    pub noise_rad: f64,
    /// Constant bias added to every translation (m) and rotation (rad).
    pub bias_m: f64,
    pub bias_rad: f64,
}

/// The navigation sensors (a GNSS and a gyro compass).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavSpec {
    /// Samples per second (0: no navigation stream).
    pub rate_hz: f64,
    /// Heading noise (standard deviation), rad.
    pub heading_noise_rad: f64,
    /// Position noise (standard deviation, each axis), m.
    pub position_noise_m: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub struct SimSpec {
    /// The true sea: directions counterclockwise from east (travel-to).
    pub seas: Vec<SeaState>,
    pub radar: RadarSpec,
    pub imu: ImuSpec,
    pub duration_s: f64,
    /// Ramp of the true wave force at the start, s.
    pub ramp_s: f64,
    /// The seakeeping frame's heading at the start (its +x, counterclockwise from east), rad.
    pub heading_rad: f64,
    /// The system origin's earth position at the start, m.
    pub origin_m: [f64; 2],
    /// The frame's track from the start: speed, turn.
    pub track: Track,
    pub navigation: NavSpec,
    /// Model error: the true vessels' linear damping is this factor times the model's.
    pub damping_factor: f64,
    pub seed: u64,
}

/// One IMU/navigation sample (the shell turns it into the wire type).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuSample {
    pub vessel: usize,
    pub time_s: f64,
    pub x: [f64; 6],
    pub v: [f64; 6],
}

/// One navigation fix of a vessel (core units: the shell writes compass degrees on the wire).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavFix {
    pub vessel: usize,
    pub time_s: f64,
    /// Earth position of the vessel's reference point, m.
    pub position_m: [f64; 2],
    /// Heading of the vessel's +x, counterclockwise from east, rad.
    pub heading_rad: f64,
    /// Speed over ground (>= 0), m/s, and its course, counterclockwise from east, rad.
    pub speed_m_s: f64,
    pub course_rad: f64,
    /// Speed through the water along the heading, m/s (negative astern).
    pub stw_m_s: f64,
    /// Rate of turn, counterclockwise positive, rad/s.
    pub turn_rate_rad_s: f64,
}

/// The truth's wave force along a turning track is computed in pieces of at most this heading change,
/// rad (0.1 deg: 20 times finer than a forecast's [`crate::rom::forecast::TURN_PIECE_RAD`], so that the
/// truth is not the forecaster's approximation).
pub const TRUTH_PIECE_RAD: f64 = 0.1 * std::f64::consts::PI / 180.0;

/// The radar processor's map re-centres on the ship when the ship is this fraction of the radar's
/// range from the map's centre (its snapshots must share one grid: the inversion starts over).
pub const MAP_RECENTRE_FRACTION: f64 = 0.1;

/// The simulation: truth computed once, sensors sampled on demand.
pub struct Simulation {
    pub spec: SimSpec,
    /// The true sea in the earth frame, reference the origin at t = 0.
    pub sea: WaveField,
    /// The true motion of every state from t = 0 at the model's dt.
    pub truth: Forecast,
    pub n_bodies: usize,
    rng: ChaCha8Rng,
    grids: Vec<Grid>,
    /// Reference points of the bodies in the system frame, m.
    body_xy_m: Vec<[f64; 2]>,
    /// The radar map's centre, earth frame, m.
    map_centre_m: Option<[f64; 2]>,
}

impl Simulation {
    /// Realizes the sea and computes the true motion (the system's own model, damping scaled).
    pub fn new(sys: &VesselSystem, opts: RomOptions, spec: SimSpec) -> rom::Result<Simulation> {
        // the database at the track's speed, as the daemon's model takes it
        let mut truth_sys = sys.at_speed(spec.track.speed_m_s)?;
        for b in truth_sys.spec.bodies.iter_mut() {
            b.linear_damping *= spec.damping_factor;
        }
        spec.track.validate()?;
        let model = TimeModel::new(
            &truth_sys,
            RomOptions {
                speed_m_s: spec.track.speed_m_s,
                ..opts
            },
        )?;
        let sea = WaveField::from_components(
            &realize_all(&spec.seas),
            sys.spec.g_m_s2,
            sys.spec.water_depth_m,
            Region::Everywhere,
        );
        let waves = sea.for_vessel(spec.origin_m, spec.heading_rad, 0.0);
        let truth = Forecaster::new()
            .from_rest_on(&model, &waves, spec.duration_s, spec.ramp_s, Some(spec.track))?
            .clone();
        Ok(Simulation {
            n_bodies: sys.spec.bodies.len(),
            body_xy_m: sys.spec.reference_points_xy_m(),
            map_centre_m: None,
            rng: ChaCha8Rng::seed_from_u64(spec.seed ^ 0x5eed),
            sea,
            truth,
            spec,
            grids: vec![],
        })
    }

    /// True displacement of state `i` at time t (linear between steps; 0 before the start).
    pub fn true_x(&self, t_s: f64, i: usize) -> f64 {
        interp(&self.truth, &self.truth.x, t_s, i)
    }

    fn true_v(&self, t_s: f64, i: usize) -> f64 {
        interp(&self.truth, &self.truth.v, t_s, i)
    }

    /// The IMU samples of every vessel at time t.
    pub fn imu(&mut self, t_s: f64) -> Vec<ImuSample> {
        let s = self.spec.imu;
        (0..self.n_bodies)
            .map(|b| {
                let mut x = [0.0; 6];
                let mut v = [0.0; 6];
                for d in 0..6 {
                    let (noise, bias) = if d < 3 {
                        (s.noise_m, s.bias_m)
                    } else {
                        (s.noise_rad, s.bias_rad)
                    };
                    x[d] = self.true_x(t_s, 6 * b + d) + bias + noise * gauss(&mut self.rng);
                    v[d] = self.true_v(t_s, 6 * b + d) + 0.1 * noise * s.rate_hz * gauss(&mut self.rng);
                }
                ImuSample {
                    vessel: b,
                    time_s: t_s,
                    x,
                    v,
                }
            })
            .collect()
    }

    /// The seakeeping frame's earth heading (rad, counterclockwise from east) and origin (m) at `t_s`.
    pub fn pose(&self, t_s: f64) -> (f64, [f64; 2]) {
        let (psi, p) = self.spec.track.pose(t_s.max(0.0));
        let h = self.spec.heading_rad;
        let (s, c) = h.sin_cos();
        let o = self.spec.origin_m;
        (h + psi, [o[0] + c * p[0] - s * p[1], o[1] + s * p[0] + c * p[1]])
    }

    /// The navigation fixes of every vessel at `t_s`: the frame's pose plus the vessel's own surge, sway
    /// and yaw, with the sensors' noise.
    pub fn navigation(&mut self, t_s: f64) -> Vec<NavFix> {
        let nav = self.spec.navigation;
        let tr = self.spec.track;
        let (h, o) = self.pose(t_s);
        let turning = tr.turn_rate_rad_s != 0.0 && t_s > tr.turn_start_s;
        let rate = if turning { tr.turn_rate_rad_s } else { 0.0 };
        (0..self.n_bodies)
            .map(|b| {
                let xy = self.body_xy_m[b];
                let (surge, sway, yaw) = (
                    self.true_x(t_s, 6 * b),
                    self.true_x(t_s, 6 * b + 1),
                    self.true_x(t_s, 6 * b + 5),
                );
                let (x, y) = (xy[0] + surge, xy[1] + sway);
                let (s, c) = h.sin_cos();
                let noise = [
                    nav.position_noise_m * gauss(&mut self.rng),
                    nav.position_noise_m * gauss(&mut self.rng),
                    nav.heading_noise_rad * gauss(&mut self.rng),
                ];
                NavFix {
                    vessel: b,
                    time_s: t_s,
                    position_m: [o[0] + c * x - s * y + noise[0], o[1] + s * x + c * y + noise[1]],
                    heading_rad: h + yaw + noise[2],
                    speed_m_s: tr.speed_m_s.abs(),
                    course_rad: if tr.speed_m_s < 0.0 {
                        h + std::f64::consts::PI
                    } else {
                        h
                    },
                    stw_m_s: tr.speed_m_s,
                    turn_rate_rad_s: rate + self.true_v(t_s, 6 * b + 5),
                }
            })
            .collect()
    }

    /// The radar's newest snapshot (elevation, m, on its grid), if any.
    pub fn last_grid(&self) -> Option<&Grid> {
        self.grids.last()
    }

    /// A radar snapshot at time t; once enough snapshots are in, the processor's wave field (referred
    /// to the origin and t), else None.
    pub fn radar(&mut self, t_s: f64) -> Option<WaveField> {
        let r = self.spec.radar;
        let n = r.cells.max(8);
        let d = 2.0 * r.radius_m / n as f64;
        // the map follows the ship in steps: its snapshots share one grid until it re-centres
        let ship = self.pose(t_s).1;
        let o = match self.map_centre_m {
            Some(c) if (ship[0] - c[0]).hypot(ship[1] - c[1]) <= MAP_RECENTRE_FRACTION * r.radius_m => c,
            _ => {
                self.grids.clear();
                ship
            }
        };
        self.map_centre_m = Some(o);
        let xs: Vec<f64> = (0..n).map(|i| o[0] - r.radius_m + (i as f64 + 0.5) * d).collect();
        let ys: Vec<f64> = (0..n).map(|i| o[1] - r.radius_m + (i as f64 + 0.5) * d).collect();
        let mut pts = Vec::with_capacity(n * n);
        for y in &ys {
            for x in &xs {
                pts.push([*x, *y]);
            }
        }
        let mut values = vec![0.0; pts.len()];
        self.sea.elevation(&pts, t_s, &mut values);
        // cells the radar does not see are NaN: beyond its range, in its blind zone, in the sector
        // the superstructure masks (relative bearings clockwise from the bow, seen from the ship)
        let (heading, ship) = self.pose(t_s);
        for (p, v) in pts.iter().zip(values.iter_mut()) {
            let range = (p[0] - o[0]).hypot(p[1] - o[1]);
            let masked = r.masked_sector_deg.is_some_and(|(from, to)| {
                let (dx, dy) = (p[0] - ship[0], p[1] - ship[1]);
                let bearing = (heading - dy.atan2(dx)).to_degrees().rem_euclid(360.0);
                let (from, to) = (from.rem_euclid(360.0), to.rem_euclid(360.0));
                if from <= to {
                    (from..=to).contains(&bearing)
                } else {
                    bearing >= from || bearing <= to
                }
            });
            let from_antenna = (p[0] - ship[0]).hypot(p[1] - ship[1]);
            if range > r.radius_m || from_antenna < r.blind_radius_m || masked {
                *v = f64::NAN;
            } else {
                *v += r.noise_m * gauss(&mut self.rng);
            }
        }
        self.grids.push(Grid {
            x_m: xs,
            y_m: ys,
            time_s: t_s,
            values,
        });
        if self.grids.len() > r.snapshots.max(2) {
            self.grids.remove(0);
        }
        if self.grids.len() < r.snapshots.max(2) {
            return None;
        }
        let opts = GridOptions {
            g_m_s2: self.sea.g_m_s2,
            depth_m: self.sea.depth_m,
            omega_min_rad_s: r.omega_min_rad_s,
            omega_max_rad_s: r.omega_max_rad_s,
            mean_direction_rad: None,
            region: Some(Region::Disc {
                centre_m: o,
                radius_m: r.radius_m,
            }),
        };
        // the processor's own inversion: the cells it does not see taken as zero
        let zeroed: Vec<Grid> = self.grids.iter().map(zero_invalid).collect();
        from_grids(&zeroed, &opts)
            .ok()
            .map(|f| f.pruned(PROCESSOR_VARIANCE_KEPT))
    }

    /// The newest radar scan as a processor that publishes maps sends it: the grid along its axes from
    /// the corner cell, NaN where the radar does not see, and where the grid lies.
    pub fn last_scan(&self) -> Option<(Grid, GridFrame)> {
        let g = self.grids.last()?;
        Some((
            Grid {
                x_m: g.x_m.iter().map(|x| x - g.x_m[0]).collect(),
                y_m: g.y_m.iter().map(|y| y - g.y_m[0]).collect(),
                ..g.clone()
            },
            GridFrame {
                origin_m: [g.x_m[0], g.y_m[0]],
                orientation_rad: 0.0,
            },
        ))
    }
}

/// A grid with its NaN cells (not seen) set to zero.
pub fn zero_invalid(g: &Grid) -> Grid {
    Grid {
        values: g.values.iter().map(|v| if v.is_finite() { *v } else { 0.0 }).collect(),
        ..g.clone()
    }
}

fn interp(f: &Forecast, series: &[f64], t_s: f64, i: usize) -> f64 {
    if t_s <= 0.0 {
        return 0.0;
    }
    let u = t_s / f.dt_s;
    let k = (u.floor() as usize).min(f.steps.saturating_sub(1));
    let w = (u - k as f64).clamp(0.0, 1.0);
    let n = f.n_modes;
    series[k * n + i] * (1.0 - w) + series[(k + 1).min(f.steps) * n + i] * w
}

/// A standard normal draw (Box-Muller).
fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = rng.random::<f64>().max(1e-300);
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}
