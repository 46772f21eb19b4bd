//! The synthetic sea (pure): a true sea, the true motion of the vessels computed by the ROM (optionally
//! with model error), and what the sensors would report: a radar processor's wave field over a disc
//! around the ship (gridded snapshots with noise inverted by [`crate::waves::observe`]) and IMU samples
//! with noise and bias. The shell (`shipcast simulate`) paces it in real time and publishes or records.
//!
//! Frames (DESIGN.md section 1): the earth frame is x east, y north; the vessels keep station (zero
//! speed) with the system's x axis along `heading_rad` (counterclockwise from east) and the system's
//! origin at `origin_m`. Times are seconds from the start of the simulation (the shell adds the data
//! clock's start, `simulate.start_unix_s`).

use crate::hydro::VesselSystem;
use crate::rom::{self, Forecast, Forecaster, RomOptions, TimeModel};
use crate::waves::field::{Region, WaveField};
use crate::waves::observe::{Grid, GridOptions, from_grids};
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

#[derive(Debug, Clone, PartialEq)]
pub struct SimSpec {
    /// The true sea: directions counterclockwise from east (travel-to).
    pub seas: Vec<SeaState>,
    pub radar: RadarSpec,
    pub imu: ImuSpec,
    pub duration_s: f64,
    /// Ramp of the true wave force at the start, s.
    pub ramp_s: f64,
    pub heading_rad: f64,
    pub origin_m: [f64; 2],
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
}

impl Simulation {
    /// Realizes the sea and computes the true motion (the system's own model, damping scaled).
    pub fn new(sys: &VesselSystem, opts: RomOptions, spec: SimSpec) -> rom::Result<Simulation> {
        let mut truth_sys = sys.clone();
        for b in truth_sys.spec.bodies.iter_mut() {
            b.linear_damping *= spec.damping_factor;
        }
        let model = TimeModel::new(&truth_sys, opts)?;
        let sea = WaveField::from_components(
            &realize_all(&spec.seas),
            sys.spec.g_m_s2,
            sys.spec.water_depth_m,
            Region::Everywhere,
        );
        let waves = sea.for_vessel(spec.origin_m, spec.heading_rad, 0.0);
        let truth = Forecaster::new()
            .from_rest(&model, &waves, spec.duration_s, spec.ramp_s)?
            .clone();
        Ok(Simulation {
            n_bodies: sys.spec.bodies.len(),
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
        let o = self.spec.origin_m;
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
        for (p, v) in pts.iter().zip(values.iter_mut()) {
            if (p[0] - o[0]).hypot(p[1] - o[1]) > r.radius_m {
                *v = 0.0;
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
        from_grids(&self.grids, &opts)
            .ok()
            .map(|f| f.pruned(PROCESSOR_VARIANCE_KEPT))
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
