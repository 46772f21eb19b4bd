//! `shipcast horizon`: the predictable horizon of a radar disc for a sea state (a planning tool).

use anyhow::{Result, bail};
use clap::{Args, ValueEnum};
use shipcast::waves::G_STANDARD_M_S2;
use shipcast::waves::horizon::{self, PlanningSea, Spreading, UNKNOWN_FRACTION};
use std::io::Write;

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spectrum {
    /// JONSWAP, gamma 3.3.
    Jonswap,
    /// Pierson-Moskowitz.
    Pm,
}

#[derive(Args, Debug)]
pub struct HorizonArgs {
    /// Radius of the observed disc around the vessel (the radar's range), m.
    #[arg(long, allow_negative_numbers = true)]
    radius: f64,
    /// Peak period, s.
    #[arg(long, allow_negative_numbers = true)]
    tp: f64,
    /// Significant wave height, m (the horizon does not depend on it; reported).
    #[arg(long, allow_negative_numbers = true, default_value_t = 2.0)]
    hs: f64,
    #[arg(long, value_enum, default_value = "jonswap")]
    spectrum: Spectrum,
    /// cos-2s spreading exponent s (omit for long-crested waves; 0 for cos^2 spreading).
    #[arg(long, allow_negative_numbers = true)]
    spreading: Option<f64>,
    /// Mean wave heading relative to the vessel, deg: the direction the waves travel to,
    /// counterclockwise from the bow (180 = head seas).
    #[arg(long, allow_negative_numbers = true, default_value_t = 180.0)]
    heading: f64,
    /// Vessel speed along its heading, m/s.
    #[arg(long, allow_negative_numbers = true, default_value_t = 0.0)]
    speed: f64,
    /// Water depth, m (omit for deep water).
    #[arg(long, allow_negative_numbers = true)]
    depth: Option<f64>,
    /// Non-causal reach of the vessel's force RAO, s (taken off the waves' horizon).
    #[arg(long, allow_negative_numbers = true, default_value_t = 0.0)]
    noncausal: f64,
}

pub fn run(a: &HorizonArgs) -> Result<()> {
    for (name, v) in [("--radius", a.radius), ("--tp", a.tp), ("--hs", a.hs)] {
        if !(v.is_finite() && v > 0.0) {
            bail!("{name} {v}: must be a positive number");
        }
    }
    if !(a.heading.is_finite() && a.speed.is_finite() && a.speed >= 0.0) {
        bail!("--heading and --speed must be finite, --speed >= 0");
    }
    if !(a.noncausal.is_finite() && a.noncausal >= 0.0) {
        bail!("--noncausal {}: must be >= 0 s", a.noncausal);
    }
    if let Some(d) = a.depth
        && !(d.is_finite() && d > 0.0)
    {
        bail!("--depth {d}: must be positive");
    }
    let spreading = match a.spreading {
        None => Spreading::LongCrested,
        Some(0.0) => Spreading::Cos2,
        Some(s) if s.is_finite() && s > 0.0 => Spreading::Cos2s(s),
        Some(s) => bail!("--spreading {s}: must be >= 0"),
    };
    let sea = PlanningSea {
        hs_m: a.hs,
        tp_s: a.tp,
        gamma: match a.spectrum {
            Spectrum::Jonswap => 3.3,
            Spectrum::Pm => 1.0,
        },
        spreading,
        heading_rad: a.heading.to_radians(),
    };
    let g = G_STANDARD_M_S2;
    let h = horizon::of_sea(&sea, a.radius, a.speed, g, a.depth, a.noncausal);
    let mut out = std::io::stdout().lock();
    writeln!(
        out,
        "sea: {:?} Hs {} m, Tp {} s, {:?}, waves travelling to {} deg from the bow; vessel at {} m/s; depth {}",
        a.spectrum,
        a.hs,
        a.tp,
        spreading,
        a.heading,
        a.speed,
        a.depth.map(|d| format!("{d} m")).unwrap_or("infinite".into())
    )?;
    writeln!(
        out,
        "the radar sees a disc of {} m around the vessel at t0; a wave group reaching the vessel at lead time t was at (U - c_g d) t from it at t0",
        a.radius
    )?;
    writeln!(
        out,
        "the fastest groups leave first: at {:.1} s the parts of the sea never observed carry {:.1} % of its variance; the limit is set by {:.3} rad/s (T = {:.1} s, c_g = {:.2} m/s) travelling to {:.1} deg",
        h.wave_horizon_s,
        100.0 * UNKNOWN_FRACTION,
        h.limiting_omega_rad_s,
        2.0 * std::f64::consts::PI / h.limiting_omega_rad_s,
        h.limiting_group_velocity_m_s,
        h.limiting_direction_rad.to_degrees()
    )?;
    if a.speed == 0.0 {
        writeln!(
            out,
            "for a stationary vessel this is R / c_g,max = {:.0} / {:.2} = {:.1} s",
            a.radius,
            h.limiting_group_velocity_m_s,
            a.radius / h.limiting_group_velocity_m_s
        )?;
    }
    writeln!(
        out,
        "the force RAO's non-causal reach ({} s) comes off: the force is predictable up to {:.1} s ahead",
        a.noncausal, h.horizon_s
    )?;
    writeln!(out, "horizon_s={:.1}", h.horizon_s)?;
    Ok(())
}
