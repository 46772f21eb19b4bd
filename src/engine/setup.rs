//! What a configuration and a vessel system make of the engine: the model's options, the memory and
//! history wanted, the vessels' positions, each vessel's estimator, and the limits of the wire.

use super::*;
use crate::rom::{RadiationMethod, RomOptions};
use crate::waves::field::heading_from_compass_deg;

/// The model options a configuration asks for, for this system: the step is `forecast.dt_s`, or when
/// that is not set the one chosen from the system's natural periods ([`crate::rom::step`]).
pub fn rom_options(cfg: &ShipcastConfig, sys: &VesselSystem) -> RomOptions {
    options_at(
        cfg,
        cfg.forecast
            .dt_s
            .unwrap_or_else(|| crate::rom::step::default_step(sys).dt_s),
    )
}

/// The solver step in words: the configured one, or the one chosen and why.
pub fn describe_step(cfg: &ShipcastConfig, sys: &VesselSystem) -> String {
    match cfg.forecast.dt_s {
        Some(dt) => format!("{dt} s (forecast.dt_s)"),
        None => crate::rom::step::default_step(sys).describe(sys),
    }
}

/// The model options of a configuration at step `dt_s`.
pub fn options_at(cfg: &ShipcastConfig, dt_s: f64) -> RomOptions {
    RomOptions {
        dt_s,
        radiation: if cfg.forecast.radiation == "state-space" {
            RadiationMethod::StateSpace
        } else {
            RadiationMethod::Convolution
        },
        memory_s: cfg.forecast.memory_s,
        ..RomOptions::default()
    }
}

/// With the state-space radiation (whose modal states carry the memory), the measured history each
/// forecast starts from when `forecast.memory_s` is not set, s.
pub const STATE_SPACE_HISTORY_S: f64 = 120.0;

/// How much measured motion a forecast wants behind it, s: the radiation memory (convolution) or the
/// history the modal states are started from (state space). Until the history is this long, forecasts
/// carry `history_short` (the missing past taken as at rest).
pub fn history_wanted_s(cfg: &ShipcastConfig, sys: &VesselSystem) -> f64 {
    match (cfg.forecast.memory_s, cfg.forecast.radiation.as_str()) {
        (Some(m), _) => m,
        (None, "state-space") => STATE_SPACE_HISTORY_S,
        (None, _) => crate::radiation::memory::memory_duration_s(sys),
    }
}

/// Earth position (east, north) of each body's reference point and the system's heading (rad,
/// counterclockwise from east).
pub fn vessel_positions(cfg: &ShipcastConfig, sys: &VesselSystem) -> (Vec<[f64; 2]>, f64) {
    let h = heading_from_compass_deg(cfg.site.heading_deg);
    let (s, c) = h.sin_cos();
    let o = [cfg.site.origin_east_m, cfg.site.origin_north_m];
    let pos = sys
        .spec
        .bodies
        .iter()
        .map(|b| {
            let (x, y) = (b.position_m.x, b.position_m.y);
            [o[0] + c * x - s * y, o[1] + s * x + c * y]
        })
        .collect();
    (pos, h)
}

/// The estimator of vessel `b`: the configured sensor and gate, bounds from the body and the
/// database, the bandwidth from the database's highest frequency, the bias on the DOFs with
/// hydrostatic restoring.
pub fn estimator_spec(cfg: &ShipcastConfig, sys: &VesselSystem, model: &TimeModel, b: usize) -> estimator::Spec {
    let e = &cfg.estimator;
    let (omega_min, omega_max) = model.db.omega_range();
    let mut spec = estimator::Spec {
        method: e.method,
        noise_x: [e.noise_m, e.noise_m, e.noise_m, e.noise_rad, e.noise_rad, e.noise_rad],
        noise_v: [
            e.velocity_noise_m_s,
            e.velocity_noise_m_s,
            e.velocity_noise_m_s,
            e.velocity_noise_rad_s,
            e.velocity_noise_rad_s,
            e.velocity_noise_rad_s,
        ],
        q: [0.0; 6],
        bounds: estimator::Bounds::from_system(
            &sys.spec.bodies[b].mass,
            sys.spec.g_m_s2,
            e.max_acceleration_g,
            omega_min,
        ),
        restored: [false; 6],
        learned: [false; 6],
        bias_time_s: e.bias_time_s,
        drift: [e.drift_m, e.drift_m, e.drift_m, e.drift_rad, e.drift_rad, e.drift_rad],
        drift_time_s: e.drift_time_s,
        gate_sigma: e.gate_sigma,
        reset_samples: e.reset_samples as usize,
    };
    for d in 0..6 {
        spec.q[d] = estimator::Spec::process_noise(spec.noise_x[d], estimator::BANDWIDTH_FACTOR * omega_max);
        if (2..5).contains(&d)
            && let Some(row) = model.active.iter().position(|&i| i == 6 * b + d)
        {
            spec.restored[d] = model.stiffness[(row, row)] > 0.0;
            spec.learned[d] = spec.restored[d] && !MEASURED_MEAN_DOFS.contains(&d);
        }
    }
    spec
}

/// The daemon (and a replay of its log) forecasts at most [`MAX_VESSELS`] vessels: the forecast and
/// status payloads carry no more.
pub fn fits_the_wire(sys: &VesselSystem) -> Result<(), String> {
    let n = sys.spec.bodies.len();
    if n > MAX_VESSELS {
        return Err(format!(
            "the system file has {n} vessels: the daemon's forecasts and status carry at most {MAX_VESSELS}"
        ));
    }
    Ok(())
}

/// The daemon pings systemd's watchdog once per forecast period: a `WatchdogSec` shorter than two periods
/// would have systemd kill a healthy daemon. `watchdog_s` is the unit's interval (None: no watchdog).
pub fn watchdog_fits(period_s: f64, watchdog_s: Option<f64>) -> Result<(), String> {
    match watchdog_s {
        Some(w) if 2.0 * period_s > w => Err(format!(
            "forecast.period_s = {period_s} s, but the unit's WatchdogSec is {w} s: the daemon pings the watchdog once \
             a period, so WatchdogSec must be at least twice forecast.period_s ({} s)",
            2.0 * period_s
        )),
        _ => Ok(()),
    }
}

/// A coupling term counts when it is this share of the geometric mean of the two diagonal terms it
/// joins: hulls far apart keep BEM round-off between them.
const COUPLING_SHARE: f64 = 1e-6;

/// Which vessels the model couples, transitively (each with itself): a connection between them, or
/// inertia, damping or stiffness between their rows. A vessel's bad start reaches every vessel
/// coupled to it.
pub fn coupled_vessels(model: &TimeModel, n_bodies: usize) -> Vec<Vec<bool>> {
    let mut c = vec![vec![false; n_bodies]; n_bodies];
    for (b, row) in c.iter_mut().enumerate() {
        row[b] = true;
    }
    let body = |row: usize| Some(model.active[row] / 6).filter(|b| *b < n_bodies && model.active[row] < 6 * n_bodies);
    for m in [&model.mass, &model.damping, &model.stiffness_linearized] {
        for i in 0..m.nrows() {
            for j in 0..m.ncols() {
                let (Some(a), Some(b)) = (body(i), body(j)) else {
                    continue;
                };
                let scale = (m[(i, i)] * m[(j, j)]).abs().sqrt();
                if a != b && m[(i, j)].abs() > COUPLING_SHARE * scale {
                    (c[a][b], c[b][a]) = (true, true);
                }
            }
        }
    }
    if let Some(ext) = &model.external {
        for conn in &ext.connections {
            if let (Some(a), Some(b)) = (conn.a.body, conn.b.body)
                && a < n_bodies
                && b < n_bodies
            {
                (c[a][b], c[b][a]) = (true, true);
            }
        }
    }
    // transitively: a chain of three hulls carries a bad start end to end
    for k in 0..n_bodies {
        for i in 0..n_bodies {
            for j in 0..n_bodies {
                if c[i][k] && c[k][j] {
                    c[i][j] = true;
                }
            }
        }
    }
    c
}
