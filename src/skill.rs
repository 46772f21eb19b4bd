//! Forecast skill against what happened (pure): per series (vessel DOF or point) and lead time, the
//! correlation, the normalized RMS error (RMS error / standard deviation of the measurement), the
//! surface similarity parameter SSP = |f - m| / (|f| + |m|) (0 perfect, 1 no skill) and the bias
//! (mean of f - m), and the band's coverage: the fraction of the measurement inside the forecast's
//! published 90 % band (f +- 1.645 sigma, sigma the forecast's standard deviation), and its
//! spread-skill ratio: the RMS of sigma over the RMS error of the same pairs (1 when the band is as
//! wide as the errors are; above 1 a band wider than it need be, below 1 too narrow). Leads are the
//! forecast's own steps, binned to `lead_step_s`.
//!
//! Inputs: forecasts as (issue time t0, dt, values at t0 + k dt) and the measured series as samples
//! (time, value) sorted by time; the measurement is interpolated linearly at each valid time and pairs
//! without a measurement on both sides are skipped.

/// One forecast of one series.
#[derive(Debug, Clone, Copy)]
pub struct SeriesForecast<'a> {
    pub t0_s: f64,
    pub dt_s: f64,
    pub values: &'a [f64],
    /// The band's standard deviation at each value (empty: none).
    pub sigma: &'a [f64],
}

/// Half-width of the 90 % band in standard deviations (two-sided normal quantile).
pub const Z_90: f64 = 1.644_853_626_951_472_2;

/// Skill of one series against lead time.
#[derive(Debug, Clone, PartialEq)]
pub struct Skill {
    pub lead_s: Vec<f64>,
    pub correlation: Vec<f64>,
    pub nrmse: Vec<f64>,
    pub ssp: Vec<f64>,
    pub bias: Vec<f64>,
    /// Pairs behind each lead.
    pub count: Vec<usize>,
    /// Fraction of the measurement inside the 90 % band at each lead (NaN: no forecast had a band).
    pub coverage_90: Vec<f64>,
    /// RMS of the band's standard deviation over the RMS error of the pairs with a band, at each
    /// lead (NaN: no band, or no error).
    pub spread_skill: Vec<f64>,
}

/// Linear interpolation in a sorted (time, value) series; None outside it.
pub fn interpolate(measured: &[(f64, f64)], t: f64) -> Option<f64> {
    let i = measured.partition_point(|(tm, _)| *tm <= t);
    if i == 0 || i >= measured.len() {
        return None;
    }
    let (t0, x0) = measured[i - 1];
    let (t1, x1) = measured[i];
    if t1 <= t0 {
        return Some(x0);
    }
    Some(x0 + (x1 - x0) * (t - t0) / (t1 - t0))
}

/// Pearson correlation of two equally long series (NaN when either is constant or empty).
pub fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len()) as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    sab / (saa * sbb).sqrt()
}

/// Skill at leads 0, step, 2 step, ... up to `max_lead_s`.
pub fn score(forecasts: &[SeriesForecast], measured: &[(f64, f64)], lead_step_s: f64, max_lead_s: f64) -> Skill {
    let nl = (max_lead_s / lead_step_s).floor() as usize + 1;
    let mut pairs: Vec<Vec<(f64, f64)>> = vec![vec![]; nl];
    // per lead: pairs with a band, and of them those inside it; their sum of sigma^2 and of error^2
    let mut covered = vec![(0usize, 0usize); nl];
    let mut spread = vec![(0.0f64, 0.0f64); nl];
    for f in forecasts {
        for (l, p) in pairs.iter_mut().enumerate() {
            let lead = l as f64 * lead_step_s;
            let k = (lead / f.dt_s).round() as usize;
            let (Some(v), Some(m)) = (f.values.get(k), interpolate(measured, f.t0_s + k as f64 * f.dt_s)) else {
                continue;
            };
            if v.is_finite() && m.is_finite() {
                p.push((*v, m));
                if let Some(s) = f.sigma.get(k).filter(|s| s.is_finite()) {
                    covered[l].0 += 1;
                    covered[l].1 += usize::from((m - v).abs() <= Z_90 * s);
                    spread[l].0 += s * s;
                    spread[l].1 += (m - v) * (m - v);
                }
            }
        }
    }
    let mut s = Skill {
        lead_s: (0..nl).map(|l| l as f64 * lead_step_s).collect(),
        correlation: vec![],
        nrmse: vec![],
        ssp: vec![],
        bias: vec![],
        count: vec![],
        coverage_90: covered
            .iter()
            .map(|(n, inside)| if *n > 0 { *inside as f64 / *n as f64 } else { f64::NAN })
            .collect(),
        spread_skill: spread
            .iter()
            .map(|(s2, e2)| if *e2 > 0.0 { (s2 / e2).sqrt() } else { f64::NAN })
            .collect(),
    };
    for p in &pairs {
        let n = p.len() as f64;
        s.count.push(p.len());
        if p.len() < 2 {
            for v in [&mut s.correlation, &mut s.nrmse, &mut s.ssp, &mut s.bias] {
                v.push(f64::NAN);
            }
            continue;
        }
        let mf = p.iter().map(|q| q.0).sum::<f64>() / n;
        let mm = p.iter().map(|q| q.1).sum::<f64>() / n;
        let (mut sfm, mut sff, mut smm, mut e2, mut f2, mut m2) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for (f, m) in p {
            sfm += (f - mf) * (m - mm);
            sff += (f - mf) * (f - mf);
            smm += (m - mm) * (m - mm);
            e2 += (f - m) * (f - m);
            f2 += f * f;
            m2 += m * m;
        }
        s.correlation.push(sfm / (sff * smm).sqrt());
        s.nrmse.push((e2 / n).sqrt() / (smm / n).sqrt());
        s.ssp.push(e2.sqrt() / (f2.sqrt() + m2.sqrt()));
        s.bias.push(mf - mm);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_perfect_forecast_scores_perfectly_and_a_delayed_one_loses_skill_with_lead() {
        let truth = |t: f64| (0.7 * t).sin();
        let measured: Vec<(f64, f64)> = (0..4000).map(|k| (k as f64 * 0.1, truth(k as f64 * 0.1))).collect();
        let perfect: Vec<Vec<f64>> = (0..20)
            .map(|j| (0..=300).map(|k| truth(10.0 * j as f64 + k as f64 * 0.1)).collect())
            .collect();
        // forecasts issued every 10 s at dt 0.1 s
        let score_all = |runs: &[Vec<f64>]| {
            let fs: Vec<SeriesForecast> = runs
                .iter()
                .enumerate()
                .map(|(j, v)| SeriesForecast {
                    t0_s: 10.0 * j as f64,
                    dt_s: 0.1,
                    values: v,
                    sigma: &[],
                })
                .collect();
            score(&fs, &measured, 5.0, 30.0)
        };
        let s = score_all(&perfect);
        assert_eq!(s.lead_s.len(), 7);
        for l in 0..7 {
            assert!((s.correlation[l] - 1.0).abs() < 1e-4, "{:?}", s.correlation);
            assert!(s.nrmse[l] < 1e-2 && s.ssp[l] < 1e-2 && s.bias[l].abs() < 1e-2);
        }
        // a forecast whose phase drifts with lead (wrong frequency): correlation falls
        let drift: Vec<Vec<f64>> = (0..20)
            .map(|j| {
                (0..=300)
                    .map(|k| {
                        let t = 10.0 * j as f64 + k as f64 * 0.1;
                        (0.7 * t + 0.05 * k as f64 * 0.1).sin()
                    })
                    .collect()
            })
            .collect();
        let s = score_all(&drift);
        assert!(s.correlation[0] > 0.999 && s.correlation[6] < s.correlation[1]);
        assert!(s.nrmse[6] > s.nrmse[1]);
        assert!(s.coverage_90.iter().all(|c| c.is_nan()));
        assert!(s.spread_skill.iter().all(|c| c.is_nan()));
    }

    #[test]
    fn coverage_counts_the_measurement_inside_the_band() {
        // forecasts of 0 with sigma 1 against a measurement that is +-1 (inside) or +-2 (outside)
        let measured: Vec<(f64, f64)> = (0..1000)
            .map(|k| (k as f64, if k % 4 == 0 { 2.0 } else { -1.0 }))
            .collect();
        let zeros = vec![0.0; 11];
        let ones = vec![1.0; 11];
        let fs: Vec<SeriesForecast> = (0..100)
            .map(|j| SeriesForecast {
                t0_s: 5.0 * j as f64,
                dt_s: 1.0,
                values: &zeros,
                sigma: &ones,
            })
            .collect();
        let s = score(&fs, &measured, 1.0, 10.0);
        // three quarters of the samples are inside 1.645 sigma
        for c in &s.coverage_90 {
            assert!((c - 0.75).abs() < 0.03, "{:?}", s.coverage_90);
        }
        // errors 2 and 1 (one in four, three in four): RMS error sqrt(7 / 4), sigma 1
        for r in &s.spread_skill {
            assert!((r - (4.0f64 / 7.0).sqrt()).abs() < 0.03, "{:?}", s.spread_skill);
        }
    }
}
