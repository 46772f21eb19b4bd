//! Regular-wave runs of the time-domain model and the steady state fitted from them: the time-domain
//! motion RAO (pure).
//!
//! A run starts from rest with the wave force ramped in over `ramp_s` (R(t) = (1 - cos(pi t / T_r)) / 2).
//! The response is then fitted over successive windows of whole length T_w by least squares on
//! {exp(+-i w_e t) for each frequency, 1, t, t^2} (the polynomial absorbs the drift of DOFs without
//! restoring). The steady state is taken as reached, and the run stops, when the fitted amplitudes of two
//! consecutive windows differ by less than `tolerance` times the largest amplitude: the transient that
//! remains is then below that level. A linear model runs every frequency at once (multi-sine, unit
//! amplitude each: superposition holds); a model with quadratic damping runs one frequency at a time.

use super::model::TimeModel;
use super::stepper::Stepper;
use super::{Error, ForecastRequest, Forecaster, Result};
use crate::radiation::history::Memory;
use crate::waves::{WaveComponent, encounter_frequency, wave_number};
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::f64::consts::PI;

/// Options of the steady-state runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RegularOptions {
    /// Settling tolerance (fraction of the largest amplitude). Default 5e-4.
    pub tolerance: f64,
    /// Give up after this much simulated time, s. Default 20000 s.
    pub max_time_s: f64,
}

impl Default for RegularOptions {
    fn default() -> Self {
        RegularOptions {
            tolerance: 5e-4,
            max_time_s: 20_000.0,
        }
    }
}

/// The time-domain RAO at one heading.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeRao {
    /// `rao[f][mode]`: complex amplitude per metre of wave, every mode (inactive zero), exp(+i w_e t).
    pub rao: Vec<Vec<Complex64>>,
    /// Simulated time when the steady state was accepted, s.
    pub settled_s: f64,
}

/// Time-domain RAO of `model` at `heading_rad` for absolute frequencies `omegas_rad_s`.
pub fn time_domain_rao(
    model: &TimeModel,
    heading_rad: f64,
    omegas_rad_s: &[f64],
    opts: RegularOptions,
) -> Result<TimeRao> {
    if omegas_rad_s.is_empty() {
        return Ok(TimeRao {
            rao: vec![],
            settled_s: 0.0,
        });
    }
    if !model.is_nonlinear() {
        return run(model, heading_rad, omegas_rad_s, opts);
    }
    let mut out = TimeRao {
        rao: vec![],
        settled_s: 0.0,
    };
    for w in omegas_rad_s {
        let r = run(model, heading_rad, std::slice::from_ref(w), opts)?;
        out.rao.extend(r.rao);
        out.settled_s = out.settled_s.max(r.settled_s);
    }
    Ok(out)
}

fn run(model: &TimeModel, heading_rad: f64, omegas: &[f64], opts: RegularOptions) -> Result<TimeRao> {
    let dt = model.opts.dt_s;
    let we: Vec<f64> = omegas
        .iter()
        .map(|w| {
            encounter_frequency(
                *w,
                wave_number(*w, model.g_m_s2, model.water_depth_m),
                model.opts.speed_m_s,
                heading_rad,
            )
        })
        .collect();
    let wmin = we.iter().map(|w| w.abs()).fold(f64::INFINITY, f64::min);
    if wmin.is_nan() || wmin <= 1e-6 {
        return Err(Error::Input(
            "a frequency meets the vessel at zero encounter frequency: no steady state".into(),
        ));
    }
    let mut sorted: Vec<f64> = we.iter().map(|w| w.abs()).collect();
    sorted.sort_by(f64::total_cmp);
    let min_gap = sorted.windows(2).map(|p| p[1] - p[0]).fold(f64::INFINITY, f64::min);
    if min_gap < 1e-9 {
        return Err(Error::Input(
            "two frequencies meet the vessel at the same encounter frequency".into(),
        ));
    }
    let period = 2.0 * PI / wmin;
    let ramp_s = (2.0 * period).max(100.0);
    let window_s = (3.0 * period)
        .max(if min_gap.is_finite() {
            2.0 * 2.0 * PI / min_gap
        } else {
            0.0
        })
        .max(60.0);
    let wsteps = (window_s / dt).ceil() as usize;
    let max_steps = (opts.max_time_s / dt).ceil() as usize;
    let waves: Vec<WaveComponent> = omegas
        .iter()
        .map(|w| WaveComponent {
            omega_rad_s: *w,
            heading_rad,
            amplitude_m: Complex64::new(1.0, 0.0),
        })
        .collect();
    let ramp_steps = (ramp_s / dt).ceil() as usize;
    // Run for a limited time and double it while the steady state is not reached: the force and the
    // stepper's memory are sized for what is simulated, not for `max_time_s`. The trajectory up to a
    // limit is the same whatever the limit, so the result does not depend on the doubling.
    let mut limit = (ramp_steps + 4 * wsteps).min(max_steps);
    loop {
        if let Some(rao) = run_until(model, &waves, &we, ramp_s, ramp_steps, wsteps, limit, opts.tolerance)? {
            return Ok(rao);
        }
        if limit >= max_steps {
            return Err(Error::Input(format!(
                "no steady state within {} s (tolerance {})",
                opts.max_time_s, opts.tolerance
            )));
        }
        limit = (2 * limit).min(max_steps);
    }
}

/// One run from rest of at most `limit` steps; None when the steady state is not reached by then.
#[allow(clippy::too_many_arguments)]
fn run_until(
    model: &TimeModel,
    waves: &[WaveComponent],
    we: &[f64],
    ramp_s: f64,
    ramp_steps: usize,
    wsteps: usize,
    limit: usize,
    tolerance: f64,
) -> Result<Option<TimeRao>> {
    let n = model.n();
    let dt = model.opts.dt_s;
    // the wave force, from the forecaster's own code path
    let mut fc = Forecaster::new();
    let memory = Memory::new(model);
    let zeros = vec![0.0; n];
    let force = fc.force_for(
        model,
        &ForecastRequest {
            x0: &zeros,
            v0: &zeros,
            memory: &memory,
            waves,
            length_s: limit as f64 * dt,
            ramp_s,
            drift_velocity: None,
            track: None,
        },
    )?;
    if fc.skipped() > 0 {
        return Err(Error::Input(format!(
            "frequency or heading outside the database ({} of {} components)",
            fc.skipped(),
            waves.len()
        )));
    }
    let mut st = Stepper::new();
    st.start(model, &zeros, &zeros, &memory, limit, &force[..n])?;
    let mut record = vec![0.0; wsteps * n];
    let mut prev: Option<Vec<Vec<Complex64>>> = None;
    let mut k = 0;
    while k < ramp_steps.min(limit) {
        k += 1;
        st.step(model, &force[k * n..(k + 1) * n], &zeros)?;
    }
    while k + wsteps <= limit {
        let start = k + 1;
        for r in 0..wsteps {
            k += 1;
            st.step(model, &force[k * n..(k + 1) * n], &zeros)?;
            record[r * n..(r + 1) * n].copy_from_slice(&st.x);
        }
        let fit = fit_window(&record, n, we, start as f64 * dt, dt, wsteps);
        if let Some(p) = &prev {
            let peak = fit.iter().flatten().map(|c| c.norm()).fold(0.0, f64::max);
            let change = fit
                .iter()
                .flatten()
                .zip(p.iter().flatten())
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max);
            tracing::debug!(t_s = k as f64 * dt, change, peak, "regular-wave window");
            if change <= tolerance * peak.max(f64::MIN_POSITIVE) {
                let rao = fit
                    .into_iter()
                    .map(|act| {
                        let mut all = vec![Complex64::default(); model.n_modes];
                        for (r, &i) in model.active.iter().enumerate() {
                            all[i] = act[r];
                        }
                        all
                    })
                    .collect();
                return Ok(Some(TimeRao {
                    rao,
                    settled_s: k as f64 * dt,
                }));
            }
        }
        prev = Some(fit);
    }
    Ok(None)
}

/// Least-squares fit of x(t) = sum_j Re{X_j exp(i w_j t)} + c0 + c1 t + c2 t^2 over one window; returns X[j][dof].
fn fit_window(record: &[f64], n: usize, we: &[f64], t_start: f64, dt: f64, steps: usize) -> Vec<Vec<Complex64>> {
    let m = we.len();
    // exponentials (2m + 1, the constant included) and the polynomial trend tau, tau^2
    const POLY: usize = 2;
    let nb = 2 * m + 1 + POLY;
    // basis frequencies: +w_j, -w_j, 0 (constant); the last basis is the trend tau in [-1/2, 1/2)
    let freq = |a: usize| {
        if a < m {
            we[a]
        } else if a < 2 * m {
            -we[a - m]
        } else {
            0.0
        }
    };
    let tau = |k: usize| k as f64 / steps as f64 - 0.5;
    let geom = |theta: f64, t0: f64| -> Complex64 {
        // sum_{k < steps} exp(i theta' (t0 + k dt)) with theta' = theta (rad/s)
        let phase = Complex64::from_polar(1.0, theta * t0);
        let q = theta * dt;
        if (q / (2.0 * PI)).fract().abs() < 1e-12 || q.abs() < 1e-12 {
            return phase * steps as f64;
        }
        let num = Complex64::new(1.0, 0.0) - Complex64::from_polar(1.0, q * steps as f64);
        let den = Complex64::new(1.0, 0.0) - Complex64::from_polar(1.0, q);
        phase * num / den
    };
    let mut g = DMatrix::<Complex64>::zeros(nb, nb);
    for a in 0..2 * m + 1 {
        for b in 0..2 * m + 1 {
            g[(a, b)] = geom(freq(b) - freq(a), t_start);
        }
    }
    // trend rows/columns, numerically
    let poly = |p: usize, k: usize| tau(k).powi(p as i32 + 1);
    for p in 0..POLY {
        let col = 2 * m + 1 + p;
        for a in 0..2 * m + 1 {
            let mut s = Complex64::default();
            let (rot, mut z) = (
                Complex64::from_polar(1.0, -freq(a) * dt),
                Complex64::from_polar(1.0, -freq(a) * t_start),
            );
            for k in 0..steps {
                s += z * poly(p, k);
                z *= rot;
            }
            g[(a, col)] = s; // conj(phi_a) * tau^(p+1)
            g[(col, a)] = s.conj();
        }
        for q in 0..POLY {
            g[(col, 2 * m + 1 + q)] = Complex64::new((0..steps).map(|k| poly(p, k) * poly(q, k)).sum(), 0.0);
        }
    }
    // right-hand sides for every DOF
    let mut p = DMatrix::<Complex64>::zeros(nb, n);
    for a in 0..2 * m + 1 {
        let (rot, mut z) = (
            Complex64::from_polar(1.0, -freq(a) * dt),
            Complex64::from_polar(1.0, -freq(a) * t_start),
        );
        for k in 0..steps {
            let row = &record[k * n..(k + 1) * n];
            for (d, x) in row.iter().enumerate() {
                p[(a, d)] += z * x;
            }
            z *= rot;
        }
    }
    for q in 0..POLY {
        for k in 0..steps {
            let row = &record[k * n..(k + 1) * n];
            for (d, x) in row.iter().enumerate() {
                p[(2 * m + 1 + q, d)] += Complex64::new(poly(q, k) * x, 0.0);
            }
        }
    }
    let sol = g.lu().solve(&p).unwrap_or_else(|| DMatrix::zeros(nb, n));
    (0..m)
        .map(|j| (0..n).map(|d| sol[(j, d)] * 2.0).collect())
        .collect::<Vec<Vec<Complex64>>>()
}
