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
use crate::waves::observe::{Grid, GridFrame, GridOptions, ScanFit, from_scans_after};
use crate::waves::sea::{SeaState, realize_all};
use crate::waves::window::{MIN_WINDOW_SCANS, regrid, window_scans};
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
    /// The most snapshots the processor's window holds (>= 2 tells opposite directions apart): it takes
    /// as many as its blind zone needs (`waves::window::window_scans`).
    pub snapshots: usize,
    /// Frequency band the processor keeps, rad/s.
    pub omega_min_rad_s: f64,
    pub omega_max_rad_s: f64,
    /// No echo within this range of the antenna, m (0: none).
    pub blind_radius_m: f64,
    /// A sector the superstructure masks: relative bearings from, to (deg clockwise from the bow).
    pub masked_sector_deg: Option<(f64, f64)>,
    /// The antenna's height above the mean water level, m: a cell is shadowed (no echo) where a crest
    /// nearer the antenna rises above the line of sight to it (0: no shadowing).
    pub antenna_height_m: f64,
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
    /// Drift: a bias that wanders (first-order Gauss-Markov, per DOF) with this standard deviation of
    /// translations (m) and rotations (rad), and this correlation time (s).
    pub drift_m: f64,
    pub drift_rad: f64,
    pub drift_time_s: f64,
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
    /// The radar sees the sea's second-order bound waves as well (the vessels feel the linear sea).
    pub bound_waves: bool,
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

/// The radar processor's map re-centres on the ship (to the nearest whole cell, its earlier snapshots
/// moved onto the new grid) when the ship is this fraction of the radar's range from the map's centre.
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
    /// The radar's newest snapshots of one map (at most `radar.snapshots`), and how many of the newest
    /// the processor's next inversion takes (`waves::window::window_scans` of its last field).
    grids: Vec<Grid>,
    window: usize,
    /// The processor's last window's fit, which its next starts from.
    fit: Option<ScanFit>,
    /// Reference points of the bodies in the system frame, m.
    body_xy_m: Vec<[f64; 2]>,
    /// The radar map's centre, earth frame, m.
    map_centre_m: Option<[f64; 2]>,
    /// The sea's mean wavenumber (at its mean frequency), rad/m: the bound waves' narrow-band scale.
    mean_wavenumber_rad_m: f64,
    /// Each vessel's IMU drift now (6 DOF), and when it was last drawn.
    drift: Vec<[f64; 6]>,
    drift_time_s: Option<f64>,
}

impl Simulation {
    /// Realizes the sea and computes the true motion: `truth`'s model of the same bodies if given (another
    /// database, other damping), else the forecaster's own `sys`; linear damping scaled by
    /// `spec.damping_factor`.
    pub fn new(
        sys: &VesselSystem,
        truth: Option<&VesselSystem>,
        opts: RomOptions,
        spec: SimSpec,
    ) -> rom::Result<Simulation> {
        let truth = truth.unwrap_or(sys);
        let names = |s: &VesselSystem| s.spec.bodies.iter().map(|b| b.name.clone()).collect::<Vec<_>>();
        if names(truth) != names(sys) {
            return Err(rom::Error::Input(format!(
                "the truth's bodies {:?} are not the model's {:?}",
                names(truth),
                names(sys)
            )));
        }
        // the database at the track's speed, as the daemon's model takes it
        let mut truth_sys = truth.at_speed(spec.track.speed_m_s)?;
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
        let components = realize_all(&spec.seas);
        let sea = WaveField::from_components(&components, sys.spec.g_m_s2, sys.spec.water_depth_m, Region::Everywhere);
        let waves = sea.for_vessel(spec.origin_m, spec.heading_rad, 0.0);
        let truth = Forecaster::new()
            .from_rest_on(&model, &waves, spec.duration_s, spec.ramp_s, Some(spec.track))?
            .clone();
        let energy: f64 = sea.components.iter().map(|c| c.amplitude_m.norm_sqr()).sum();
        let mean_omega = sea
            .components
            .iter()
            .map(|c| c.amplitude_m.norm_sqr() * c.omega_rad_s)
            .sum::<f64>()
            / energy.max(f64::MIN_POSITIVE);
        let window = spec.radar.snapshots.max(2);
        Ok(Simulation {
            mean_wavenumber_rad_m: if energy > 0.0 { sea.wave_number(mean_omega) } else { 0.0 },
            drift: vec![[0.0; 6]; sys.spec.bodies.len()],
            drift_time_s: None,
            n_bodies: sys.spec.bodies.len(),
            body_xy_m: sys.spec.reference_points_xy_m(),
            map_centre_m: None,
            rng: ChaCha8Rng::seed_from_u64(spec.seed ^ 0x5eed),
            sea,
            truth,
            spec,
            grids: vec![],
            fit: None,
            window,
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
        self.advance_drift(t_s);
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
                    x[d] = self.true_x(t_s, 6 * b + d) + bias + self.drift[b][d] + noise * gauss(&mut self.rng);
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

    /// Moves every IMU's drift on to `t_s` (first-order Gauss-Markov: exact in any step; drawn from its
    /// stationary distribution at the first sample).
    fn advance_drift(&mut self, t_s: f64) {
        let s = self.spec.imu;
        let keep = match self.drift_time_s {
            Some(t0) if s.drift_time_s > 0.0 => (-(t_s - t0).max(0.0) / s.drift_time_s).exp(),
            Some(_) => 1.0,
            None => 0.0,
        };
        let fresh = (1.0 - keep * keep).max(0.0).sqrt();
        for b in 0..self.n_bodies {
            for d in 0..6 {
                let sigma = if d < 3 { s.drift_m } else { s.drift_rad };
                self.drift[b][d] = keep * self.drift[b][d] + fresh * sigma * gauss(&mut self.rng);
            }
        }
        self.drift_time_s = Some(t_s);
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
        // the map follows the ship in steps of whole cells: its earlier snapshots are moved onto the
        // re-centred grid (the window goes on)
        let ship = self.pose(t_s).1;
        let o = match self.map_centre_m {
            Some(c) if (ship[0] - c[0]).hypot(ship[1] - c[1]) <= MAP_RECENTRE_FRACTION * r.radius_m => c,
            Some(c) => [
                c[0] + ((ship[0] - c[0]) / d).round() * d,
                c[1] + ((ship[1] - c[1]) / d).round() * d,
            ],
            None => ship,
        };
        let xs: Vec<f64> = (0..n).map(|i| o[0] - r.radius_m + (i as f64 + 0.5) * d).collect();
        let ys: Vec<f64> = (0..n).map(|i| o[1] - r.radius_m + (i as f64 + 0.5) * d).collect();
        if self.map_centre_m.is_some_and(|c| c != o) {
            let earth = GridFrame {
                origin_m: [0.0, 0.0],
                orientation_rad: 0.0,
            };
            self.grids = self
                .grids
                .iter()
                .filter_map(|g| regrid(g, earth, &xs, &ys, earth))
                .collect();
        }
        self.map_centre_m = Some(o);
        let mut pts = Vec::with_capacity(n * n);
        for y in &ys {
            for x in &xs {
                pts.push([*x, *y]);
            }
        }
        let mut values = vec![0.0; pts.len()];
        if r.antenna_height_m > 0.0 || self.spec.bound_waves {
            let mut analytic = vec![num_complex::Complex64::default(); pts.len()];
            self.sea.analytic_elevation(&pts, t_s, &mut analytic);
            let k = if self.spec.bound_waves {
                self.mean_wavenumber_rad_m
            } else {
                0.0
            };
            for (v, a) in values.iter_mut().zip(&analytic) {
                *v = bound_elevation(*a, k);
            }
        } else {
            self.sea.elevation(&pts, t_s, &mut values);
        }
        // cells the radar does not see are NaN: beyond its range, in its blind zone, in the sector
        // the superstructure masks (relative bearings clockwise from the bow, seen from the ship),
        // shadowed behind a crest nearer the antenna
        let (heading, ship) = self.pose(t_s);
        let shadowed = if r.antenna_height_m > 0.0 {
            shadow(&xs, &ys, &values, ship, r.antenna_height_m)
        } else {
            vec![false; values.len()]
        };
        for ((p, v), hidden) in pts.iter().zip(values.iter_mut()).zip(shadowed) {
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
            if range > r.radius_m || from_antenna < r.blind_radius_m || masked || hidden {
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
        let most = r.snapshots.max(2);
        if self.grids.len() > most {
            self.grids.remove(0);
        }
        if self.grids.len() < MIN_WINDOW_SCANS.min(most) {
            return None;
        }
        let opts = GridOptions {
            g_m_s2: self.sea.g_m_s2,
            depth_m: self.sea.depth_m,
            omega_min_rad_s: r.omega_min_rad_s,
            omega_max_rad_s: r.omega_max_rad_s,
            mean_direction_rad: None,
            region: None,
        };
        // the processor's own inversion of its window's newest scans, the cells it does not see filled
        // from its last window's fit; its region what they saw (the blind zone, a masked sector, the
        // window's length)
        let used = self.window.clamp(1, most).min(self.grids.len());
        let frame = GridFrame {
            origin_m: [0.0, 0.0],
            orientation_rad: 0.0,
        };
        let (f, fit) =
            from_scans_after(&self.grids[self.grids.len() - used..], frame, &opts, self.fit.as_ref()).ok()?;
        self.fit = Some(fit);
        let f = f.pruned(PROCESSOR_VARIANCE_KEPT);
        self.window = window_scans(&f, r.period_s, most);
        Some(f)
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

/// The elevation with the sea's second-order bound waves, from the linear sea's analytic signal
/// `a` (real part the elevation, imaginary part its Hilbert transform) and its mean wavenumber `k`:
/// Tayfun's narrow-band model (J. Geophys. Res. 85(C3), 1980), `eta + k/2 (eta^2 - eta_H^2)`, deep
/// water: one component of amplitude A gains Stokes' second harmonic, k A^2 / 2 cos 2 theta.
pub fn bound_elevation(a: num_complex::Complex64, k_rad_m: f64) -> f64 {
    a.re + 0.5 * k_rad_m * (a.re * a.re - a.im * a.im)
}

/// Which cells of a grid (`values[iy * xs.len() + ix]`, elevations, m) an antenna at `antenna_m`,
/// `height_m` above the mean level, cannot see: a crest between them rises above the line of sight
/// (geometric shadowing). The line is followed in half-cell steps through the bilinear surface; cells
/// within one cell of the antenna are seen.
pub fn shadow(xs: &[f64], ys: &[f64], values: &[f64], antenna_m: [f64; 2], height_m: f64) -> Vec<bool> {
    let (nx, ny) = (xs.len(), ys.len());
    if nx < 2 || ny < 2 || values.len() != nx * ny {
        return vec![false; values.len()];
    }
    let (dx, dy) = (
        (xs[nx - 1] - xs[0]) / (nx - 1) as f64,
        (ys[ny - 1] - ys[0]) / (ny - 1) as f64,
    );
    let cell = dx.min(dy);
    let at = |x: f64, y: f64| -> Option<f64> {
        let (u, v) = ((x - xs[0]) / dx, (y - ys[0]) / dy);
        if !(u >= 0.0 && v >= 0.0 && u <= (nx - 1) as f64 && v <= (ny - 1) as f64) {
            return None;
        }
        let (i, j) = ((u as usize).min(nx - 2), (v as usize).min(ny - 2));
        let (fu, fv) = (u - i as f64, v - j as f64);
        let z = |i: usize, j: usize| values[j * nx + i];
        let e = (1.0 - fv) * ((1.0 - fu) * z(i, j) + fu * z(i + 1, j))
            + fv * ((1.0 - fu) * z(i, j + 1) + fu * z(i + 1, j + 1));
        e.is_finite().then_some(e)
    };
    let mut out = vec![false; values.len()];
    for iy in 0..ny {
        for ix in 0..nx {
            let v = values[iy * nx + ix];
            let (ex, ey) = (xs[ix] - antenna_m[0], ys[iy] - antenna_m[1]);
            let range = ex.hypot(ey);
            if !v.is_finite() || range <= cell {
                continue;
            }
            // the slope of the line of sight to this cell, and of every point before it
            let slope = (v - height_m) / range;
            let steps = (2.0 * range / cell).floor() as usize;
            out[iy * nx + ix] = (2..steps).any(|s| {
                let f = 0.5 * s as f64 * cell / range;
                at(antenna_m[0] + f * ex, antenna_m[1] + f * ey).is_some_and(|e| (e - height_m) / (f * range) > slope)
            });
        }
    }
    out
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
pub(crate) fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = rng.random::<f64>().max(1e-300);
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_complex::Complex64;

    /// One component of amplitude A: the bound wave is Stokes' second harmonic, k A^2 / 2 cos 2 theta.
    #[test]
    fn bound_waves_of_one_component_are_stokes_second_order() {
        let (amp_m, k_rad_m) = (1.5, 0.05);
        for theta in [0.0, 0.4, 1.3, 2.9, 4.0] {
            let a = Complex64::from_polar(amp_m, theta);
            let stokes = amp_m * f64::cos(theta) + 0.5 * k_rad_m * amp_m * amp_m * f64::cos(2.0 * theta);
            assert!((bound_elevation(a, k_rad_m) - stokes).abs() < 1e-12, "theta {theta}");
        }
        // crests sharpen, troughs flatten
        assert!(bound_elevation(Complex64::new(1.0, 0.0), k_rad_m) > 1.0);
        assert!(bound_elevation(Complex64::new(-1.0, 0.0), k_rad_m) > -1.0);
    }

    fn grid(n: usize, d_m: f64) -> (Vec<f64>, Vec<f64>) {
        let c: Vec<f64> = (0..n).map(|i| (i as f64 - (n - 1) as f64 / 2.0) * d_m).collect();
        (c.clone(), c)
    }

    #[test]
    fn a_flat_sea_shadows_nothing_and_a_ridge_hides_what_is_behind_it() {
        let (xs, ys) = grid(41, 10.0);
        let flat = vec![0.0; xs.len() * ys.len()];
        assert!(shadow(&xs, &ys, &flat, [0.0, 0.0], 20.0).iter().all(|s| !s));
        // a 3 m ridge along x = 100 m: from 20 m up, the water just beyond it (down to 20 m x / 100 m - 20
        // ... ) is hidden; the ridge itself and the water before it are seen
        let ridge: Vec<f64> = (0..ys.len())
            .flat_map(|_| xs.iter().map(|x| if (*x - 100.0).abs() < 1.0 { 3.0 } else { 0.0 }))
            .collect();
        let hidden = shadow(&xs, &ys, &ridge, [0.0, 0.0], 20.0);
        let at = |x: f64, y: f64| {
            let ix = xs.iter().position(|v| (*v - x).abs() < 1e-9).unwrap();
            let iy = ys.iter().position(|v| (*v - y).abs() < 1e-9).unwrap();
            hidden[iy * xs.len() + ix]
        };
        assert!(!at(50.0, 0.0) && !at(100.0, 0.0), "before and on the ridge");
        assert!(at(110.0, 0.0) && at(110.0, 20.0), "just behind the ridge");
        // the line of sight over a 3 m ridge 100 m off from 20 m up meets the water 117.6 m off
        assert!(!at(130.0, 0.0), "far enough behind it");
        assert!(!at(-110.0, 0.0), "on the other side");
        // no shadowing from a mast higher than any crest close in
        assert!(shadow(&xs, &ys, &ridge, [0.0, 0.0], 1e6).iter().all(|s| !s));
    }
}
