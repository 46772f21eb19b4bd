//! The model error learnt from past forecasts checked against the motion that followed.

/// The leads at which past forecasts are checked against the motion that followed, s (those within
/// the forecast's length): the model error is learnt as a function of lead.
pub const CHECK_LEADS_S: [f64; 13] = [
    0.0, 5.0, 10.0, 20.0, 30.0, 45.0, 60.0, 75.0, 90.0, 105.0, 120.0, 180.0, 300.0,
];
/// The prior model error (`forecast.model_error`) holds up to this lead and grows in proportion
/// beyond it, as a phase error does (an inversion's frequency error): until the daemon has checked
/// its forecasts at a lead, it does not take them for better than that, s.
pub const PRIOR_LEAD_S: f64 = 30.0;
/// Checks averaged over: the model error follows the sea over about this many forecasts.
pub const CHECK_MEMORY: f64 = 600.0;
/// Checks at a lead before its estimate replaces the configured prior.
pub const CHECK_MIN: usize = 60;
/// The band's scale is learnt so that this share of the checks falls inside [-1.645, 1.645] band
/// widths: the published 90 % band covers nine checks in ten whatever the errors' distribution.
pub const BAND_QUANTILE: f64 = 0.9;
/// The standard normal's two-sided 90 % quantile.
pub(super) const Z90: f64 = 1.6448536269514722;
/// The band's learnt scale stays within these (a few odd checks do not collapse or blow it up).
pub(super) const BAND_SCALE_LIMITS: (f64, f64) = (0.5, 3.0);

/// The learnt model error's own uncertainty is told by batch means: the checks at a lead are
/// averaged in batches of this many (longer than a check's squared error stays correlated with the
/// next ones': 10-60 forecasts a second apart in the two-ship demo's default sea) ...
pub(super) const BATCH_CHECKS: usize = 60;
/// ... the last this many batches kept (the [`CHECK_MEMORY`] checks the estimate follows).
pub(super) const BATCHES: usize = (CHECK_MEMORY as usize) / BATCH_CHECKS;
/// The trusted span judges the learnt model error this many of its standard errors above the
/// estimate (one-sided, 84 %): a span opens where the error is known to be small, not where a
/// noisy estimate of it happens to read small (with 600 checks correlated over tens of them the
/// estimate's own spread is 25-45 % of it).
pub const SPAN_CONFIDENCE_Z: f64 = 1.0;

/// The smallest model error the estimate gives (a forecast is never taken as perfect).
pub(super) const MIN_MODEL_ERROR: f64 = 0.02;
/// A series' measured motion counts (judges the span, floors the model error) only where its variance
/// is this many times the sensor's noise variance; its forecast's error is learnt either way (a model
/// that moves a quiet series has an error the prior, a fraction of the model's motion, would miss).
pub(super) const MIN_SIGNAL_TO_NOISE: f64 = 9.0;

/// A forecast waiting to be checked: at each check lead (the first `values.len()` of
/// [`CHECK_LEADS_S`]), its values there and the variance of the waves it did not know.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub(super) struct Pending {
    issue_s: f64,
    dt_s: f64,
    /// The next check lead to do.
    next: usize,
    /// [lead][series]
    values: Vec<Vec<f64>>,
    unknown_var: Vec<Vec<f64>>,
    /// The band before its learnt scale, with the check's own error: what a check's error is
    /// measured in.
    raw_sigma: Vec<Vec<f64>>,
    /// Per series, the variance of what the estimate the forecast started from and the one it is
    /// checked against differ by beside the motion (the estimator's own error; the sensor's noise
    /// where not given).
    check_var: Vec<f64>,
}

/// The model error each series shows against lead, learnt from past forecasts checked against the
/// motion that followed: at each of [`CHECK_LEADS_S`], the squared error less what the waves the
/// forecast did not know and the motion sensor's own noise explain, averaged over the last
/// [`CHECK_MEMORY`] checks (until [`CHECK_MIN`] of them, a configured fraction of the motion
/// instead); and the motion's own variance, as measured. It takes in what a wave-by-wave account
/// leaves out: the model's own error, the inversion's frequency error that grows with lead, the
/// initial state's. Pure: forecasts and measurements in, variances out.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ModelError {
    prior: f64,
    n_series: usize,
    /// Per series, the variance of the measurement's noise (the band is for the motion, not the
    /// sensor's reading of it).
    noise_var: Vec<f64>,
    pending: std::collections::VecDeque<Pending>,
    /// [lead][series]: running mean of error^2 less what is explained.
    excess: Vec<Vec<f64>>,
    /// [lead][series]: the last [`CHECK_MEMORY`] checks' errors over their unscaled band.
    normalized: Vec<Vec<std::collections::VecDeque<f64>>>,
    /// Checks done at each lead.
    checks: Vec<usize>,
    /// Per series, running mean and mean square of the measured motion (at the checks of the first
    /// lead), and how many.
    mean: Vec<f64>,
    square: Vec<f64>,
    samples: usize,
    /// [lead][series]: the sum of error^2 less what is explained over the open batch of checks, and
    /// the means of the last closed batches ([`BATCH_CHECKS`] each), newest last.
    batch_sum: Vec<Vec<f64>>,
    batch_means: Vec<Vec<std::collections::VecDeque<f64>>>,
}

/// The model error of each series against lead, and the motion's measured variance.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelErrorCurve {
    pub lead_s: Vec<f64>,
    /// `var[series][lead]`, m^2 or rad^2 (NaN: not learnt, the prior's fraction of the motion).
    pub var: Vec<Vec<f64>>,
    /// The fraction of a series' motion standard deviation taken where nothing is learnt.
    pub prior: f64,
    /// Per series, the motion's measured variance (NaN: not yet known).
    pub motion_var: Vec<f64>,
    /// Per series, the motion sensor's noise variance: no band is narrower (a motion buried in the
    /// noise is forecast from a start the noise has moved).
    pub noise_var: Vec<f64>,
    /// `scale[series][lead]`: the band's factor that makes [`BAND_QUANTILE`] of the checks fall
    /// inside its 90 % (NaN: not learnt, 1).
    pub scale: Vec<Vec<f64>>,
    /// `var_se[series][lead]`: the standard error of `var` (batch means of the checks; one batch
    /// alone: `var` itself), m^2 or rad^2 (NaN: not learnt, 0).
    pub var_se: Vec<Vec<f64>>,
    /// The span trusts no lead past this one, s: the model error has been learnt at every check lead
    /// up to it (0: at none yet, the prior alone, which no forecast has been checked against).
    pub checked_to_s: f64,
}

impl ModelErrorCurve {
    /// Nothing learnt: `fraction` of each series' motion.
    pub fn prior(fraction: f64, n_series: usize) -> ModelErrorCurve {
        ModelErrorCurve {
            lead_s: vec![0.0],
            var: vec![vec![f64::NAN]; n_series],
            prior: fraction,
            motion_var: vec![f64::NAN; n_series],
            noise_var: vec![0.0; n_series],
            scale: vec![vec![f64::NAN]; n_series],
            var_se: vec![vec![f64::NAN]; n_series],
            checked_to_s: 0.0,
        }
    }

    /// Series i's model error variance at `lead_s` (the band at lead 0 is the start's,
    /// [`crate::band::start_sigma`]), its model's motion variance being
    /// `model_motion_var`: linear between the check leads, constant beyond them; never below the
    /// sensor's noise.
    pub fn at(&self, i: usize, lead_s: f64, model_motion_var: f64) -> f64 {
        let noise = self.noise_var.get(i).copied().unwrap_or(0.0);
        self.learnt_at(i, lead_s, model_motion_var).max(noise)
    }

    /// Series i's learnt model error variance at `lead_s` (NaN: the prior), its model's motion
    /// variance being `model_motion_var`, with no floor.
    pub fn learnt_at(&self, i: usize, lead_s: f64, model_motion_var: f64) -> f64 {
        let grown = self.prior * (lead_s / PRIOR_LEAD_S).max(1.0);
        let prior = grown * grown * model_motion_var;
        along_leads(&self.lead_s, self.var.get(i), lead_s, prior)
    }

    /// The standard error of series i's learnt model error variance at `lead_s`: linear between the
    /// check leads, constant beyond them, 0 where not learnt.
    pub fn var_se_at(&self, i: usize, lead_s: f64) -> f64 {
        along_leads(&self.lead_s, self.var_se.get(i), lead_s, 0.0)
    }

    /// Series i's band scale at `lead_s`: linear between the check leads, constant beyond them, 1 where
    /// not learnt.
    pub fn scale_at(&self, i: usize, lead_s: f64) -> f64 {
        along_leads(&self.lead_s, self.scale.get(i), lead_s, 1.0)
    }

    /// Series i's motion standard deviation: measured, else the model's.
    pub fn motion_sigma(&self, i: usize, model_sigma: f64) -> f64 {
        self.motion_var
            .get(i)
            .filter(|v| v.is_finite())
            .map_or(model_sigma, |v| v.sqrt())
    }
}

/// The share of the learnt model error in the band's variance
/// at `lead_s`: none at lead 0, where the band is the start's ([`start_sigma`]), all
/// from the first later check lead on, linear between.
pub(super) fn after_start(lead_s: f64) -> f64 {
    (lead_s / CHECK_LEADS_S[1]).clamp(0.0, 1.0)
}

/// A learnt curve (`values` at each of `leads_s`, NaN or missing: `fallback`) at `lead_s`: linear
/// between the leads, constant beyond them.
pub(super) fn along_leads(leads_s: &[f64], values: Option<&Vec<f64>>, lead_s: f64, fallback: f64) -> f64 {
    let Some(f) = values else {
        return fallback;
    };
    let v = |j: usize| f.get(j).copied().filter(|x| x.is_finite()).unwrap_or(fallback);
    let j = leads_s.partition_point(|x| *x <= lead_s);
    if j == 0 {
        return v(0);
    }
    if j >= leads_s.len() {
        return v(leads_s.len() - 1);
    }
    let a = (lead_s - leads_s[j - 1]) / (leads_s[j] - leads_s[j - 1]);
    v(j - 1) + a * (v(j) - v(j - 1))
}

impl ModelError {
    /// A prior fraction for every series, and each series' measurement noise variance (its length is
    /// the number of series).
    pub fn new(prior: f64, noise_var: Vec<f64>) -> ModelError {
        let n_series = noise_var.len();
        ModelError {
            prior,
            n_series,
            noise_var,
            pending: Default::default(),
            excess: vec![vec![0.0; n_series]; CHECK_LEADS_S.len()],
            normalized: vec![vec![Default::default(); n_series]; CHECK_LEADS_S.len()],
            checks: vec![0; CHECK_LEADS_S.len()],
            mean: vec![0.0; n_series],
            square: vec![0.0; n_series],
            samples: 0,
            batch_sum: vec![vec![0.0; n_series]; CHECK_LEADS_S.len()],
            batch_means: vec![vec![Default::default(); n_series]; CHECK_LEADS_S.len()],
        }
    }

    /// Per series, the variance of the measurement's noise.
    pub fn noise_var(&self) -> &[f64] {
        &self.noise_var
    }

    /// Checks done so far at each of [`CHECK_LEADS_S`].
    pub fn checks(&self) -> &[usize] {
        &self.checks
    }

    /// What has been learnt.
    pub fn curve(&self) -> ModelErrorCurve {
        let var: Vec<Vec<f64>> = (0..self.n_series)
            .map(|i| {
                (0..CHECK_LEADS_S.len())
                    .map(|j| {
                        if self.checks[j] < CHECK_MIN {
                            return f64::NAN;
                        }
                        // lead 0's checks learn no model error (the band there is the start's)
                        if j == 0 {
                            return f64::NAN;
                        }
                        // never below MIN_MODEL_ERROR of the motion (where it stands out of the
                        // noise: a quiet series' error is learnt all the same)
                        let motion = self.motion_var(i);
                        let floor = if motion.is_nan() {
                            0.0
                        } else {
                            MIN_MODEL_ERROR * MIN_MODEL_ERROR * motion
                        };
                        self.excess[j][i].max(floor)
                    })
                    .collect()
            })
            .collect();
        let scale = (0..self.n_series)
            .map(|i| {
                (0..CHECK_LEADS_S.len())
                    .map(|j| {
                        let z = &self.normalized[j][i];
                        if z.len() < CHECK_MIN {
                            return f64::NAN;
                        }
                        // the BAND_QUANTILE order statistic (a selection, not a sort: once per forecast)
                        let mut z: Vec<f64> = z.iter().copied().collect();
                        let k = ((BAND_QUANTILE * z.len() as f64).ceil() as usize).clamp(1, z.len()) - 1;
                        let q = *z.select_nth_unstable_by(k, f64::total_cmp).1;
                        (q / Z90).clamp(BAND_SCALE_LIMITS.0, BAND_SCALE_LIMITS.1)
                    })
                    .collect()
            })
            .collect();
        // the standard error of each learnt variance: the spread of its batch means over the root
        // of their number (errors correlated over less than a batch leave the batches independent)
        let var_se = var
            .iter()
            .enumerate()
            .map(|(i, row)| {
                row.iter()
                    .enumerate()
                    .map(|(j, v)| {
                        let means = &self.batch_means[j][i];
                        let nb = means.len() as f64;
                        if v.is_nan() || nb < 2.0 {
                            return *v;
                        }
                        let mean = means.iter().sum::<f64>() / nb;
                        let square = means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (nb - 1.0);
                        (square / nb).sqrt()
                    })
                    .collect()
            })
            .collect();
        let checked_to_s = (1..CHECK_LEADS_S.len())
            .take_while(|&j| self.checks[j] >= CHECK_MIN)
            .last()
            .map_or(0.0, |j| CHECK_LEADS_S[j]);
        ModelErrorCurve {
            lead_s: CHECK_LEADS_S.to_vec(),
            var,
            var_se,
            checked_to_s,
            scale,
            prior: self.prior,
            motion_var: (0..self.n_series).map(|i| self.motion_var(i)).collect(),
            noise_var: self.noise_var.clone(),
        }
    }

    /// Series i's measured motion variance, less the sensor's noise (NaN before [`CHECK_MIN`], or
    /// when it is below [`MIN_SIGNAL_TO_NOISE`] times the noise).
    fn motion_var(&self, i: usize) -> f64 {
        let total = self.square[i] - self.mean[i] * self.mean[i];
        if self.samples < CHECK_MIN || total < MIN_SIGNAL_TO_NOISE * self.noise_var[i] {
            return f64::NAN;
        }
        total - self.noise_var[i]
    }

    /// A forecast issued at `issue_s` (values and standard deviations series-major, `steps + 1` each,
    /// step `dt_s`), each series' motion standard deviation by the model, the model error it was
    /// made with, and `errors`: each series' start error variance (the band's floor: as
    /// [`crate::band::SpreadOptions::start_var`]) and estimate error variance (what a check against a later
    /// estimate differs by beside the motion); missing, the sensor's noise.
    pub fn record(
        &mut self,
        issue_s: f64,
        dt_s: f64,
        spread: (&[f64], &[f64]),
        model_motion_sigma: &[f64],
        used: &ModelErrorCurve,
        errors: (&[f64], &[f64]),
    ) {
        let (values, sigma) = spread;
        let (start_var, check_var) = errors;
        let ns = self.n_series;
        if !(dt_s > 0.0 && issue_s.is_finite())
            || model_motion_sigma.len() != ns
            || sigma.len() != values.len()
            || ns == 0
        {
            return;
        }
        let n = values.len() / ns;
        let given = |v: &[f64], i: usize| {
            v.get(i)
                .copied()
                .filter(|v| v.is_finite() && *v >= 0.0)
                .unwrap_or(self.noise_var[i])
        };
        let check_var: Vec<f64> = (0..ns).map(|i| given(check_var, i)).collect();
        let floor_var: Vec<f64> = (0..ns).map(|i| given(start_var, i)).collect();
        let mut p = Pending {
            issue_s,
            dt_s,
            next: 0,
            values: vec![],
            unknown_var: vec![],
            raw_sigma: vec![],
            check_var,
        };
        for &lead in &CHECK_LEADS_S {
            let k = (lead / dt_s).round() as usize;
            if k >= n {
                break;
            }
            p.values.push((0..ns).map(|i| values[i * n + k]).collect());
            // the band as published is the unscaled one times the scale it was made with (at the
            // check leads past 0; at lead 0 it is the start's, and its checks learn no model error)
            let raw: Vec<f64> = (0..ns)
                .map(|i| {
                    if lead > 0.0 {
                        sigma[i * n + k] / used.scale_at(i, lead)
                    } else {
                        f64::NAN
                    }
                })
                .collect();
            p.unknown_var.push(
                (0..ns)
                    .map(|i| {
                        // the learnt model error, or the band's floor (the start's error: a band on it
                        // is taken for no unknown waves)
                        let learnt = used.learnt_at(i, lead, model_motion_sigma[i] * model_motion_sigma[i]);
                        let floor = learnt.max(floor_var[i] / used.scale_at(i, lead).powi(2));
                        (raw[i].powi(2) - floor).max(0.0)
                    })
                    .collect(),
            );
            p.raw_sigma.push(
                (0..ns)
                    .map(|i| (raw[i].powi(2) + if lead > 0.0 { p.check_var[i] } else { 0.0 }).sqrt())
                    .collect(),
            );
        }
        if !p.values.is_empty() {
            self.pending.push_back(p);
        }
    }

    /// Checks every pending forecast at each of its check leads that `now_s` has passed, against
    /// `measured(t)`: every series' displacement at t (None: not measured, that check is skipped).
    pub fn observe(&mut self, now_s: f64, mut measured: impl FnMut(f64) -> Option<Vec<f64>>) {
        for p in &mut self.pending {
            while p.next < p.values.len() {
                let k = (CHECK_LEADS_S[p.next] / p.dt_s).round();
                let t = p.issue_s + k * p.dt_s;
                if t > now_s {
                    break;
                }
                let j = p.next;
                p.next += 1;
                let Some(x) = measured(t).filter(|x| x.len() == self.n_series && x.iter().all(|v| v.is_finite()))
                else {
                    continue;
                };
                self.checks[j] += 1;
                let w = 1.0 / (self.checks[j] as f64).min(CHECK_MEMORY);
                // at lead 0 the forecast is the estimate it is checked against: the band there is the
                // start's (`start_sigma`), and those checks learn only the motion's variance
                for (i, xi) in x.iter().enumerate().filter(|_| j > 0) {
                    let e2 = (xi - p.values[j][i]).powi(2);
                    // the estimate checked against errs by as much as the start's did
                    let noise = p.check_var[i];
                    let explained = p.unknown_var[j][i] + noise;
                    self.excess[j][i] += w * (e2 - explained - self.excess[j][i]);
                    self.batch_sum[j][i] += e2 - explained;
                    let band = p.raw_sigma[j][i];
                    if band > 0.0 && band.is_finite() {
                        let z = &mut self.normalized[j][i];
                        z.push_back(e2.sqrt() / band);
                        if z.len() > CHECK_MEMORY as usize {
                            z.pop_front();
                        }
                    }
                }
                if j > 0 && self.checks[j].is_multiple_of(BATCH_CHECKS) {
                    for i in 0..self.n_series {
                        let means = &mut self.batch_means[j][i];
                        means.push_back(self.batch_sum[j][i] / BATCH_CHECKS as f64);
                        if means.len() > BATCHES {
                            means.pop_front();
                        }
                        self.batch_sum[j][i] = 0.0;
                    }
                }
                if j == 0 {
                    self.samples += 1;
                    let w = 1.0 / (self.samples as f64).min(CHECK_MEMORY);
                    for (i, xi) in x.iter().enumerate() {
                        self.mean[i] += w * (xi - self.mean[i]);
                        self.square[i] += w * (xi * xi - self.square[i]);
                    }
                }
            }
        }
        while self.pending.front().is_some_and(|p| p.next >= p.values.len()) {
            self.pending.pop_front();
        }
    }
}
