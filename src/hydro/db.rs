//! The hydrodynamic database in SI units, and its interpolation over frequency and heading.
//!
//! Interpolation is linear in w for A and B, and bilinear in (w, beta) on the real and imaginary parts of X
//! (never on amplitude and phase, which wrap and misbehave near zeros). Headings that cover the circle
//! (the gap across 360 deg no larger than the largest gap between stored headings) interpolate across
//! 360 deg; otherwise a heading outside the stored range is an error, as is a frequency outside
//! [w_min, w_max]: the database is never extrapolated.

use super::wamit::{Excitation, Radiation};
use super::{Error, Result};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// Radiation, excitation and restoring of a 6N-mode system, SI units, exp(+i w t).
#[derive(Debug, Clone)]
pub struct HydroDb {
    pub n_modes: usize,
    /// Radiation frequencies, rad/s, ascending, finite and positive.
    pub omega_rad_s: Vec<f64>,
    pub added_mass: Vec<DMatrix<f64>>,
    pub damping: Vec<DMatrix<f64>>,
    pub added_mass_inf: Option<DMatrix<f64>>,
    pub added_mass_zero: Option<DMatrix<f64>>,
    /// Excitation frequencies, rad/s, ascending.
    pub exc_omega_rad_s: Vec<f64>,
    /// Headings, rad, in [0, 2 pi), ascending.
    pub heading_rad: Vec<f64>,
    /// X[(iw * n_headings + ib) * n_modes + i], N (or N m) per metre of wave amplitude.
    pub excitation: Vec<Complex64>,
    /// Linear restoring C, 6N x 6N.
    pub restoring: DMatrix<f64>,
}

/// Index of the segment holding `x` in ascending `xs` and the weight of its right end.
pub(crate) fn bracket(xs: &[f64], x: f64) -> Option<(usize, f64)> {
    let n = xs.len();
    if n == 0 || !x.is_finite() || x < xs[0] || x > xs[n - 1] {
        return None;
    }
    if n == 1 {
        return Some((0, 0.0));
    }
    let i = xs.partition_point(|v| *v <= x).clamp(1, n - 1) - 1;
    let w = (x - xs[i]) / (xs[i + 1] - xs[i]);
    Some((i, w.clamp(0.0, 1.0)))
}

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

impl HydroDb {
    /// Assembles the database from the WAMIT readers' output. `file` labels errors.
    pub fn new(rad: Radiation, exc: Excitation, restoring: DMatrix<f64>, file: &str) -> Result<HydroDb> {
        let n = exc.n_modes;
        if exc.omega_rad_s.is_empty() || exc.heading_deg.is_empty() {
            return Err(Error::Invalid {
                file: file.into(),
                msg: "the excitation file holds no frequency or no heading".into(),
            });
        }
        // headings to [0, 2 pi), sorted, duplicates (e.g. 0 and 360) dropped
        let nb = exc.heading_deg.len();
        let mut order: Vec<(f64, usize)> = exc
            .heading_deg
            .iter()
            .enumerate()
            .map(|(i, h)| (h.to_radians().rem_euclid(TWO_PI), i))
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0));
        order.dedup_by(|b, a| (b.0 - a.0).abs() < 1e-9 || (TWO_PI - b.0 + a.0).abs() < 1e-9);
        if let (Some(first), Some(last)) = (order.first().copied(), order.last().copied())
            && order.len() > 1
            && (TWO_PI - last.0 + first.0).abs() < 1e-9
        {
            order.pop();
        }
        let heading_rad: Vec<f64> = order.iter().map(|o| o.0).collect();
        let mut excitation = Vec::with_capacity(exc.omega_rad_s.len() * heading_rad.len() * n);
        for iw in 0..exc.omega_rad_s.len() {
            for &(_, ib) in &order {
                debug_assert!(ib < nb);
                excitation.extend((0..n).map(|i| exc.at(iw, ib, i)));
            }
        }
        Ok(HydroDb {
            n_modes: n,
            omega_rad_s: rad.omega_rad_s,
            added_mass: rad.added_mass,
            damping: rad.damping,
            added_mass_inf: rad.added_mass_inf,
            added_mass_zero: rad.added_mass_zero,
            exc_omega_rad_s: exc.omega_rad_s,
            heading_rad,
            excitation,
            restoring,
        })
    }

    /// Zeroes every 6x6 block coupling two different bodies (`hydrodynamic_coupling = false`).
    pub fn decouple(&mut self) {
        let mask = |m: &mut DMatrix<f64>| {
            for i in 0..m.nrows() {
                for j in 0..m.ncols() {
                    if i / 6 != j / 6 {
                        m[(i, j)] = 0.0;
                    }
                }
            }
        };
        self.added_mass.iter_mut().for_each(mask);
        self.damping.iter_mut().for_each(mask);
        if let Some(a) = self.added_mass_inf.as_mut() {
            mask(a)
        }
        if let Some(a) = self.added_mass_zero.as_mut() {
            mask(a)
        }
        mask(&mut self.restoring);
    }

    /// Frequency range covered by both radiation and excitation, rad/s.
    pub fn omega_range(&self) -> (f64, f64) {
        let lo = self.omega_rad_s[0].max(self.exc_omega_rad_s[0]);
        let hi = self.omega_rad_s[self.omega_rad_s.len() - 1].min(self.exc_omega_rad_s[self.exc_omega_rad_s.len() - 1]);
        (lo, hi)
    }

    /// A(w) and B(w), linearly interpolated.
    pub fn radiation_at(&self, omega_rad_s: f64) -> Result<(DMatrix<f64>, DMatrix<f64>)> {
        let (i, w) = bracket(&self.omega_rad_s, omega_rad_s).ok_or_else(|| {
            Error::OutOfRange(format!(
                "frequency {omega_rad_s} rad/s is outside the database's radiation range {:.4}..{:.4} rad/s",
                self.omega_rad_s[0],
                self.omega_rad_s[self.omega_rad_s.len() - 1]
            ))
        })?;
        let j = (i + 1).min(self.omega_rad_s.len() - 1);
        let a = &self.added_mass[i] * (1.0 - w) + &self.added_mass[j] * w;
        let b = &self.damping[i] * (1.0 - w) + &self.damping[j] * w;
        Ok((a, b))
    }

    /// Whether the stored headings cover the circle (interpolation may wrap across 360 deg).
    pub fn headings_cover_circle(&self) -> bool {
        let h = &self.heading_rad;
        if h.len() < 3 {
            return false;
        }
        let max_gap = h.windows(2).map(|p| p[1] - p[0]).fold(0.0, f64::max);
        TWO_PI - h[h.len() - 1] + h[0] <= max_gap + 1e-9
    }

    /// The two stored headings around `heading_rad` and the weight of the second.
    fn heading_bracket(&self, heading_rad: f64) -> Result<(usize, usize, f64)> {
        let h = &self.heading_rad;
        let b = heading_rad.rem_euclid(TWO_PI);
        let near = |x: f64, y: f64| {
            let d = (x - y).rem_euclid(TWO_PI);
            d.min(TWO_PI - d) < 1e-9
        };
        if let Some(i) = h.iter().position(|&x| near(x, b)) {
            return Ok((i, i, 0.0));
        }
        if let Some((i, w)) = bracket(h, b) {
            return Ok((i, (i + 1).min(h.len() - 1), w));
        }
        if self.headings_cover_circle() {
            let last = h.len() - 1;
            let span = TWO_PI - h[last] + h[0];
            let d = (b - h[last]).rem_euclid(TWO_PI);
            return Ok((last, 0, d / span));
        }
        Err(Error::OutOfRange(format!(
            "heading {:.3} deg is outside the database's headings {:?} deg",
            heading_rad.to_degrees(),
            h.iter()
                .map(|x| (x.to_degrees() * 1e6).round() / 1e6)
                .collect::<Vec<_>>()
        )))
    }

    /// X(w, beta), bilinear in (w, beta) on real and imaginary parts.
    pub fn excitation_at(&self, omega_rad_s: f64, heading_rad: f64) -> Result<DVector<Complex64>> {
        let mut out = DVector::from_element(self.n_modes, Complex64::default());
        self.excitation_into(omega_rad_s, heading_rad, out.as_mut_slice())?;
        Ok(out)
    }

    /// As [`Self::excitation_at`], into `out` (length n_modes): no allocation.
    pub fn excitation_into(&self, omega_rad_s: f64, heading_rad: f64, out: &mut [Complex64]) -> Result<()> {
        let ws = &self.exc_omega_rad_s;
        let (iw, ww) = bracket(ws, omega_rad_s).ok_or_else(|| {
            Error::OutOfRange(format!(
                "frequency {omega_rad_s} rad/s is outside the database's excitation range {:.4}..{:.4} rad/s",
                ws[0],
                ws[ws.len() - 1]
            ))
        })?;
        let jw = (iw + 1).min(ws.len() - 1);
        let (ib, jb, wb) = self.heading_bracket(heading_rad)?;
        let n = self.n_modes;
        let nb = self.heading_rad.len();
        let at = |w: usize, b: usize, i: usize| self.excitation[(w * nb + b) * n + i];
        for (i, o) in out.iter_mut().enumerate().take(n) {
            *o = (at(iw, ib, i) * (1.0 - wb) + at(iw, jb, i) * wb) * (1.0 - ww)
                + (at(jw, ib, i) * (1.0 - wb) + at(jw, jb, i) * wb) * ww;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn db(headings_deg: Vec<f64>) -> HydroDb {
        let n = 6;
        let nb = headings_deg.len();
        let rad = Radiation {
            omega_rad_s: vec![0.5, 1.0],
            added_mass: vec![DMatrix::identity(n, n), DMatrix::identity(n, n) * 3.0],
            damping: vec![DMatrix::zeros(n, n), DMatrix::identity(n, n)],
            added_mass_zero: None,
            added_mass_inf: None,
        };
        let mut values = vec![];
        for iw in 0..2 {
            for &h in &headings_deg {
                for i in 0..n {
                    values.push(Complex64::new(h + iw as f64 * 1000.0, i as f64));
                }
            }
        }
        let exc = Excitation {
            omega_rad_s: vec![0.5, 1.0],
            heading_deg: headings_deg,
            values,
            n_modes: n,
        };
        assert_eq!(exc.values.len(), 2 * nb * n);
        HydroDb::new(rad, exc, DMatrix::zeros(n, n), "t").unwrap()
    }

    #[test]
    fn radiation_interpolates_linearly_and_refuses_extrapolation() {
        let d = db(vec![0.0, 90.0]);
        let (a, b) = d.radiation_at(0.75).unwrap();
        assert!((a[(0, 0)] - 2.0).abs() < 1e-12);
        assert!((b[(0, 0)] - 0.5).abs() < 1e-12);
        assert!(d.radiation_at(1.2).is_err());
        assert!(d.radiation_at(f64::NAN).is_err());
    }

    #[test]
    fn headings_wrap_when_they_cover_the_circle() {
        let d = db(vec![-90.0, 0.0, 90.0, 180.0]); // -90 is stored as 270
        assert!(d.headings_cover_circle());
        let x = d.excitation_at(0.5, 315f64.to_radians()).unwrap();
        // halfway between 270 (value -90) and 0 (value 0)
        assert!((x[0].re - (-45.0)).abs() < 1e-9, "{}", x[0]);
        let x = d.excitation_at(0.75, 45f64.to_radians()).unwrap();
        assert!((x[0].re - (45.0 + 500.0)).abs() < 1e-9, "{}", x[0]);
        assert!((x[3].im - 3.0).abs() < 1e-12);
    }

    #[test]
    fn partial_headings_do_not_wrap() {
        let d = db(vec![0.0, 90.0, 180.0]);
        assert!(!d.headings_cover_circle());
        assert!(d.excitation_at(0.5, 270f64.to_radians()).is_err());
        assert!(d.excitation_at(0.5, 180f64.to_radians()).is_ok());
        let one = db(vec![0.0]);
        assert!(one.excitation_at(0.5, 0.0).is_ok());
        assert!(one.excitation_at(0.5, 0.1).is_err());
    }
}
