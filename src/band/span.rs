//! One forecast's band and trusted span, from the waves it knows at each lead and the learnt model
//! error.

use super::*;
use crate::waves::WaveComponent;

/// Error variance of a component the forecast carries where it is not known, in units of its own
/// response variance: the forecast's guess and the sea's unobserved part are independent.
pub const UNKNOWN_ERROR_FACTOR: f64 = 2.0;

/// A component unknown from a forecast's start (a radar's blind zone, waves from where nothing was
/// observed) errs by nothing at lead 0, where the measured state holds the response to every wave
/// before it: the error its unknown force makes is the response to a force switched on then, which
/// builds up as (1 - exp(-t / tau))^2 of its whole (tau the response's group delay: at a resonance the
/// decay time of its amplitude, 47 s for a roll at 5 % of critical and 0.43 rad/s). Taken as a linear
/// ramp over this many tau, which leaves out the same area (1.5 tau).
pub const ONSET_DELAY_TIMES: f64 = 3.0;

/// The longest group delay of a response counted, s (a resonance with 1 % of critical damping at
/// 1.6 rad/s; beyond, the delay is a phase jump where the response vanishes, not a memory).
pub const MAX_GROUP_DELAY_S: f64 = 60.0;

/// The response standard deviation below which heave (m), roll and pitch (rad) do not decide the
/// trusted span: 1 cm, 0.1 deg (below what a motion sensor tells apart from its noise).
pub const SIGNIFICANT: [f64; 3] = [0.01, 0.001_745, 0.001_745];

/// The same per DOF (surge, sway, heave, roll, pitch, yaw), for each series' own span: an expected
/// error within `forecast.trusted_nrmse` of this is trusted however little the series moves (pitch in
/// beam seas is known to be nearly still).
pub const SIGNIFICANT_DOF: [f64; 6] = [0.01, 0.01, 0.01, 0.001_745, 0.001_745, 0.001_745];

/// What decides a band's width and the trusted span.
#[derive(Debug, Clone, PartialEq)]
pub struct SpreadOptions {
    /// Model error of each series against lead, as a fraction of its standard deviation
    /// ([`ModelError`]).
    pub model_error: ModelErrorCurve,
    /// The expected normalized RMS error up to which a lead is trusted (`forecast.trusted_nrmse`).
    pub trusted_nrmse: f64,
    /// Per series, the variance of the random part of the error of the state the forecast starts from
    /// (the estimator's own, the sensor's drift it leaves, what is unknown of the sensor's bias:
    /// `estimator::Estimator::start_var`, `service`), m^2 or rad^2; missing: the sensor's noise
    /// ([`ModelErrorCurve::noise_var`]). No band is narrower, at any lead.
    pub start_var: Vec<f64>,
    /// Per series, the expected error of the start (truth less forecast: the part of a measured mean
    /// the forecast leaves out as the sensor's bias that is more likely heel), m or rad; missing: 0.
    pub start_offset: Vec<f64>,
    /// Per series and step (series-major, `steps + 1` each), the variance a coupled vessel's unknown
    /// start adds ([`super::coupled_var`]); empty: none.
    pub coupled_var: Vec<f64>,
}

/// A forecast's band and trusted span.
#[derive(Debug, Clone, PartialEq)]
pub struct Spread {
    /// Standard deviation of every series at every step, series-major (6 per vessel, m or rad).
    pub sigma: Vec<f64>,
    /// Per vessel, the first and the last lead of the trusted span, s (both 0: not trusted at all):
    /// where every DOF that moves enough to matter is trusted.
    pub from_s: Vec<f64>,
    pub to_s: Vec<f64>,
    /// Per series (6 per vessel), the first and the last lead of its own trusted span, s (both 0: not
    /// trusted at all): its expected error within `trusted_nrmse` of its motion, or of
    /// [`SIGNIFICANT_DOF`] when it moves less.
    pub series_from_s: Vec<f64>,
    pub series_to_s: Vec<f64>,
    /// Per series, the response's own standard deviation, m or rad.
    pub motion_sigma: Vec<f64>,
}

/// The band and span of a forecast of `steps` steps of `dt_s` from `waves` (relative to the vessels'
/// frame, as the forecast takes them); `known[b][c]` is the span of leads (s, from the forecast's
/// start) over which component c is known at vessel b; `speed_m_s` along the vessels' +x gives the
/// encounter frequency.
#[allow(clippy::too_many_arguments)]
pub fn spread(
    table: &ResponseTable,
    waves: &[WaveComponent],
    known: &[Vec<[f64; 2]>],
    n_bodies: usize,
    speed_m_s: f64,
    g_m_s2: f64,
    depth_m: Option<f64>,
    steps: usize,
    dt_s: f64,
    opts: &SpreadOptions,
) -> Spread {
    let n = steps + 1;
    let n_series = 6 * n_bodies;
    let sea = Sea {
        speed_m_s,
        g_m_s2,
        depth_m,
    };
    let (total, diff, slope) = unknown_variance(table, waves, known, n_bodies, &sea, n, dt_s);
    let (sigma, span_sigma) = band_sigma(&total, &diff, &slope, n, dt_s, opts);
    let motion_sigma: Vec<f64> = total.iter().map(|t| t.sqrt()).collect();
    // the span judges the expected error against the motion as measured where it is known (a
    // linearized model may not move as the vessel does)
    let judged: Vec<f64> = (0..n_series)
        .map(|i| opts.model_error.motion_sigma(i, motion_sigma[i]))
        .collect();
    let mut from_s = vec![0.0; n_bodies];
    let mut to_s = vec![0.0; n_bodies];
    for b in 0..n_bodies {
        let decisive: Vec<usize> = (0..3)
            .filter(|&j| judged[6 * b + 2 + j] >= SIGNIFICANT[j])
            .map(|j| 6 * b + 2 + j)
            .collect();
        let trusted = |k: usize| {
            decisive
                .iter()
                .all(|&i| span_sigma[i * n + k] <= opts.trusted_nrmse * judged[i])
        };
        if let Some((first, last)) = longest_run((0..=n.saturating_sub(1)).map(trusted)) {
            from_s[b] = first as f64 * dt_s;
            to_s[b] = last as f64 * dt_s;
        }
    }
    let (series_from_s, series_to_s) = (0..n_series)
        .map(|i| {
            let allowed = opts.trusted_nrmse * judged[i].max(SIGNIFICANT_DOF[i % 6]);
            longest_run((0..n).map(|k| span_sigma[i * n + k] <= allowed))
                .map_or((0.0, 0.0), |(first, last)| (first as f64 * dt_s, last as f64 * dt_s))
        })
        .unzip();
    Spread {
        sigma,
        from_s,
        to_s,
        series_from_s,
        series_to_s,
        motion_sigma,
    }
}

/// The sea's numbers the band needs: the speed along the vessels' +x (m/s, for the encounter
/// frequency), gravity (m/s^2) and the depth (m; None: deep).
pub(super) struct Sea {
    speed_m_s: f64,
    g_m_s2: f64,
    depth_m: Option<f64>,
}

/// Per series: the total response variance, and difference arrays over the `n` steps of the variance
/// left unknown, a constant part and a part proportional to the step (the ramps).
#[allow(clippy::type_complexity)]
pub(super) fn unknown_variance(
    table: &ResponseTable,
    waves: &[WaveComponent],
    known: &[Vec<[f64; 2]>],
    n_bodies: usize,
    sea: &Sea,
    n: usize,
    dt_s: f64,
) -> (Vec<f64>, Vec<Vec<f64>>, Vec<Vec<f64>>) {
    let n_series = 6 * n_bodies;
    // per series: the total response variance, and difference arrays of the unknown variance, a
    // constant part and a part proportional to the step (the ramps)
    let mut total = vec![0.0; n_series];
    let mut diff = vec![vec![0.0; n + 1]; n_series];
    let mut slope = vec![vec![0.0; n + 1]; n_series];
    let mut g2 = vec![0.0; table.n_modes];
    let mut delay = vec![0.0; table.n_modes];
    let step = |t: f64| -> usize {
        if t.is_nan() || t <= 0.0 {
            0
        } else {
            ((t / dt_s).ceil() as usize).min(n)
        }
    };
    for (c, w) in waves.iter().enumerate() {
        let v = 0.5 * w.amplitude_m.norm_sqr();
        if !(v.is_finite() && v > 0.0) {
            continue;
        }
        let k = crate::waves::wave_number(w.omega_rad_s, sea.g_m_s2, sea.depth_m);
        let we = (w.omega_rad_s - k * sea.speed_m_s * w.heading_rad.cos()).abs();
        table.gain2_into(we, w.heading_rad, &mut g2, &mut delay);
        for b in 0..n_bodies.min(table.n_modes / 6) {
            let [s, e] = known.get(b).and_then(|k| k.get(c)).copied().unwrap_or([0.0, 0.0]);
            for d in 0..6 {
                let i = 6 * b + d;
                let vr = v * g2[i];
                if vr.is_nan() || vr <= 0.0 {
                    continue;
                }
                // known over steps ks..ke (exclusive), unknown before and after; never known: unknown
                // from the start (ks = ke = n)
                let ks = step(s);
                let ke = if e.is_finite() {
                    step(e + 1e-9 * dt_s).max(ks)
                } else {
                    n
                };
                let (ks, ke) = if e > s && ke > ks { (ks, ke) } else { (n, n) };
                total[i] += vr;
                let u = UNKNOWN_ERROR_FACTOR * vr;
                // unknown from the start: the error builds up over ko steps, then whole until ks
                let ko = ((ONSET_DELAY_TIMES * delay[i] / dt_s).round() as usize).min(n);
                let built = if ko > 0 { u * (ks.min(ko) as f64 / ko as f64) } else { u };
                if ko > 0 {
                    let rate = u / ko as f64;
                    slope[i][0] += rate;
                    slope[i][ks.min(ko)] -= rate;
                }
                if ko < ks {
                    diff[i][ko] += u;
                    diff[i][ks] -= u;
                }
                // unknown again after the span
                diff[i][ke] += u;
                diff[i][n] -= u;
                // a start after the forecast's own rings on over kr steps, from what it had built up
                // to nothing: built (1 - (k - ks) / kr) over ks..ks + kr
                let kr = if ks > 0 && ks < n {
                    ((delay[i] / dt_s).round() as usize).min(ke - ks)
                } else {
                    0
                };
                if kr > 0 && built > 0.0 {
                    let rate = built / kr as f64;
                    diff[i][ks] += built + rate * ks as f64;
                    diff[i][ks + kr] -= built + rate * ks as f64;
                    slope[i][ks] -= rate;
                    slope[i][ks + kr] += rate;
                }
            }
        }
    }
    (total, diff, slope)
}

/// Per series and step, the band's standard deviation and the expected RMS error the span judges.
pub(super) fn band_sigma(
    total: &[f64],
    diff: &[Vec<f64>],
    slope: &[Vec<f64>],
    n: usize,
    dt_s: f64,
    opts: &SpreadOptions,
) -> (Vec<f64>, Vec<f64>) {
    let n_series = total.len();
    let mut sigma = Vec::with_capacity(n_series * n);
    // the expected RMS error the span judges: unscaled, the learnt model error SPAN_CONFIDENCE_Z
    // standard errors up
    let mut span_sigma = Vec::with_capacity(n_series * n);
    for i in 0..n_series {
        let noise_var = opts.model_error.noise_var.get(i).copied().unwrap_or(0.0);
        let start0 = opts
            .start_var
            .get(i)
            .copied()
            .filter(|v| v.is_finite())
            .unwrap_or(noise_var)
            .max(0.0);
        let offset0 = opts
            .start_offset
            .get(i)
            .copied()
            .filter(|o| o.is_finite())
            .unwrap_or(0.0);
        let sigma0 = start_sigma(offset0, start0);
        let (mut acc, mut rate) = (0.0, 0.0);
        for (k, (dk, dr)) in diff[i][..n].iter().zip(&slope[i][..n]).enumerate() {
            let lead_s = k as f64 * dt_s;
            acc += dk;
            rate += dr;
            // the model error as learnt from the first later check lead on; before it, the
            // variance runs linearly from the start's band to that
            let learnt_lead_s = lead_s.max(CHECK_LEADS_S[1]);
            let floor = opts.model_error.learnt_at(i, learnt_lead_s, total[i]);
            let scale = opts.model_error.scale_at(i, learnt_lead_s);
            // never narrower than the start's own random error (a forecast is no surer than its
            // start; the checks against the measured motion cannot resolve less than its noise)
            let unknown = (acc + rate * k as f64).max(0.0);
            let learnt = ((unknown + floor) * scale * scale).max(start0);
            let r = after_start(lead_s);
            let coupled = opts.coupled_var.get(i * n + k).copied().unwrap_or(0.0);
            let var = r * learnt + (1.0 - r) * sigma0 * sigma0 + coupled;
            sigma.push(var.sqrt());
            // the span judges the error's expected mean square, not the band: the band's scale
            // makes it hold nine checks in ten (narrow-band errors, a resonant roll's, have their
            // 90 % quantile at 1.4 RMS, not 1.645: a band of 0.85 RMS); and the learnt model error
            // as it may be, not as estimated; and nothing past the leads it has been checked at
            let se = opts.model_error.var_se_at(i, learnt_lead_s);
            let mean_square = (unknown + floor + SPAN_CONFIDENCE_Z * se).max(start0);
            span_sigma.push(if learnt_lead_s <= opts.model_error.checked_to_s {
                (r * mean_square + (1.0 - r) * sigma0 * sigma0 + coupled).sqrt()
            } else {
                f64::INFINITY
            });
        }
    }
    (sigma, span_sigma)
}

/// The first and last index of the longest run of `true` (the earliest of equal ones), if any.
pub(super) fn longest_run(flags: impl Iterator<Item = bool>) -> Option<(usize, usize)> {
    let mut best: Option<(usize, usize)> = None;
    let mut start = None;
    for (k, ok) in flags.chain(std::iter::once(false)).enumerate() {
        match (ok, start) {
            (true, None) => start = Some(k),
            (false, Some(s)) => {
                if best.is_none_or(|(f, l)| k - 1 - s > l - f) {
                    best = Some((s, k - 1));
                }
                start = None;
            }
            _ => {}
        }
    }
    best
}
