//! The hydrodynamic database in SI units, and its interpolation over frequency and heading.
//!
//! Interpolation is linear in w for A and B. X is interpolated on its real and imaginary parts (never on
//! amplitude and phase, which wrap and misbehave near zeros), referred first to each body's own reference
//! point ([`HydroDb::set_bodies`]): a multi-body database refers every body's excitation to the global
//! origin, where a body at r_b turns it by exp(-i k r_b . e_beta) between stored headings (k r_b = 40 rad
//! for a body 40 m out at 2.5 rad/s); referred to the body the values vary with heading as the hull does.
//! Linear in w, cubic in beta (Lagrange through the two stored headings either side, or the nearest four
//! inside the range at its ends), then turned back to the global origin at the query's k and heading.
//! Headings that cover the circle (the gap across 360 deg no larger than the largest gap between stored
//! headings) interpolate across 360 deg. A database over 0-180 deg only (or 180-360) of a system whose
//! bodies all lie on its x axis is completed by port-starboard symmetry: X at -beta is X at beta with
//! sway, roll and yaw negated (system file `port_starboard_symmetric`, default: when that holds). A
//! heading outside what is stored (or mirrored) is an error, as is a frequency outside [w_min, w_max]: the
//! database is never extrapolated.
//!
//! Conventions: exp(+i w t); a wave eta = Re{a exp(i(w t - k (x cos b + y sin b)))}, b the direction the
//! waves travel to, counterclockwise from +x (DESIGN.md section 1).

use super::wamit::{Excitation, Radiation};
use super::{Error, Result};
use crate::waves::wave_number;
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
    /// X referred to each body's reference point, same layout as `excitation` ([`Self::set_bodies`]).
    referred: Vec<Complex64>,
    /// Each body's reference point (x, y) in the database's frame, m (empty: all at the origin).
    body_origin_m: Vec<[f64; 2]>,
    /// For the wave number of the referral: g, m/s^2, and the depth (None: deep water), m.
    g_m_s2: f64,
    depth_m: Option<f64>,
    /// The headings of (pi, 2 pi) (or (0, pi)) were made by port-starboard symmetry.
    pub mirrored: bool,
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

const PI: f64 = std::f64::consts::PI;
const TWO_PI: f64 = 2.0 * PI;

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
            referred: excitation.clone(),
            excitation,
            restoring,
            body_origin_m: vec![],
            g_m_s2: 9.81,
            depth_m: None,
            mirrored: false,
        })
    }

    /// Refers the excitation to each body's reference point (`origins_m`, x and y in the database's
    /// frame, one per body; g and depth for the wave number), and completes a half circle of headings by
    /// port-starboard symmetry where `mirror` says so (None: when every body lies on the x axis and the
    /// stored headings are within 0-180 or 180-360 deg, and do not cover the circle). Err: `mirror =
    /// Some(true)` where the symmetry cannot hold.
    pub fn set_bodies(
        &mut self,
        origins_m: &[[f64; 2]],
        g_m_s2: f64,
        depth_m: Option<f64>,
        mirror: Option<bool>,
    ) -> std::result::Result<(), String> {
        if origins_m.len() * 6 != self.n_modes {
            // the system's own check names that mismatch; nothing is referred
            return Ok(());
        }
        self.body_origin_m = origins_m.to_vec();
        self.g_m_s2 = g_m_s2;
        self.depth_m = depth_m;
        let (n, nb) = (self.n_modes, self.heading_rad.len());
        for (iw, &w) in self.exc_omega_rad_s.iter().enumerate() {
            let k = wave_number(w, g_m_s2, depth_m);
            for (ib, &b) in self.heading_rad.iter().enumerate() {
                for i in 0..n {
                    let at = (iw * nb + ib) * n + i;
                    self.referred[at] = self.excitation[at] * self.turn(i, k, b).conj();
                }
            }
        }
        let on_axis = origins_m.iter().all(|o| o[1].abs() <= 1e-6);
        let h = &self.heading_rad;
        let eps = 1e-9;
        let half = (h.iter().all(|&b| b <= PI + eps) || h.iter().all(|&b| b >= PI - eps || b <= eps))
            && !self.headings_cover_circle();
        match mirror {
            Some(true) if !on_axis => {
                return Err("port-starboard symmetry needs every body on the x axis (position y = 0)".into());
            }
            Some(true) if !half => {
                return Err(
                    "port-starboard symmetry needs the database's headings within 0-180 (or 180-360) deg, not covering the circle"
                        .into(),
                );
            }
            Some(false) => return Ok(()),
            _ if !(on_axis && half) => return Ok(()),
            _ => {}
        }
        self.mirror();
        Ok(())
    }

    /// exp(-i k r_b . e_beta) of the body owning mode `i`: the wave phase at its reference point.
    fn turn(&self, i: usize, k: f64, heading_rad: f64) -> Complex64 {
        match self.body_origin_m.get(i / 6) {
            Some(o) => {
                let (s, c) = heading_rad.sin_cos();
                Complex64::from_polar(1.0, -k * (o[0] * c + o[1] * s))
            }
            None => Complex64::new(1.0, 0.0),
        }
    }

    /// Adds the mirror image -beta of every stored heading strictly between 0 and pi (or pi and 2 pi),
    /// with sway, roll and yaw negated.
    fn mirror(&mut self) {
        let (n, nb) = (self.n_modes, self.heading_rad.len());
        let eps = 1e-9;
        let mut all: Vec<(f64, usize, bool)> = self
            .heading_rad
            .iter()
            .enumerate()
            .map(|(i, &b)| (b, i, false))
            .collect();
        for (i, &b) in self.heading_rad.iter().enumerate() {
            if b > eps && (b - PI).abs() > eps {
                all.push(((TWO_PI - b).rem_euclid(TWO_PI), i, true));
            }
        }
        all.sort_by(|a, b| a.0.total_cmp(&b.0));
        let sign = |i: usize| if matches!(i % 6, 1 | 3 | 5) { -1.0 } else { 1.0 };
        let pick = |src: &[Complex64]| {
            let mut out = Vec::with_capacity(self.exc_omega_rad_s.len() * all.len() * n);
            for iw in 0..self.exc_omega_rad_s.len() {
                for &(_, ib, mirrored) in &all {
                    out.extend((0..n).map(|i| {
                        let v = src[(iw * nb + ib) * n + i];
                        if mirrored { v * sign(i) } else { v }
                    }));
                }
            }
            out
        };
        self.excitation = pick(&self.excitation);
        self.referred = pick(&self.referred);
        self.heading_rad = all.iter().map(|a| a.0).collect();
        self.mirrored = true;
    }

    /// The database at forward speed `speed_m_s` from databases at several speeds (speed, database;
    /// speeds ascending), all on the same grids and prepared alike (coupling, body referral, symmetry).
    /// A(w_e) and B(w_e) are quadratic in the speed through three consecutive speeds around it, the
    /// farthest of them as near as can be (Capytaine's
    /// forward-speed radiation is exactly quadratic in U at a given encounter frequency; linear between
    /// the two when only two are given); X(w, beta) is linear between the two speeds either side (at a
    /// given wave frequency the encounter frequency moves with U, and a quadratic overshoots as often
    /// as it helps). A_inf, A(0) and C are the first database's. Never extrapolated: a speed outside
    /// the databases' is an error.
    pub fn interpolate_speed(dbs: &[(f64, &HydroDb)], speed_m_s: f64) -> Result<HydroDb> {
        let (Some(first), Some(last)) = (dbs.first(), dbs.last()) else {
            return Err(Error::OutOfRange("no database to interpolate in speed".into()));
        };
        if !(speed_m_s.is_finite() && speed_m_s >= first.0 - 1e-12 && speed_m_s <= last.0 + 1e-12) {
            return Err(Error::OutOfRange(format!(
                "forward speed {speed_m_s} m/s is outside the databases' speeds {}..{} m/s",
                first.0, last.0
            )));
        }
        let base = first.1;
        for (u, d) in dbs {
            let same = |a: &[f64], b: &[f64]| {
                a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-9 * x.abs().max(1.0))
            };
            let what = if d.n_modes != base.n_modes {
                Some("modes")
            } else if !same(&d.omega_rad_s, &base.omega_rad_s) {
                Some("radiation frequencies")
            } else if !same(&d.exc_omega_rad_s, &base.exc_omega_rad_s) {
                Some("excitation frequencies")
            } else if !same(&d.heading_rad, &base.heading_rad) {
                Some("headings")
            } else {
                None
            };
            if let Some(what) = what {
                return Err(Error::OutOfRange(format!(
                    "the database at {u} m/s has other {what} than the one at {} m/s: databases interpolated in speed must share their grids",
                    first.0
                )));
            }
        }
        if dbs.windows(2).any(|w| w[1].0 <= w[0].0 || w[1].0.is_nan()) {
            return Err(Error::OutOfRange(
                "the databases' speeds must increase: each speed once".into(),
            ));
        }
        if dbs.len() == 1 {
            return Ok(base.clone());
        }
        let speed_m_s = speed_m_s.clamp(first.0, last.0);
        // the bracketing pair (linear) and the three nearest speeds (quadratic)
        let hi = dbs
            .iter()
            .position(|(u, _)| *u >= speed_m_s)
            .unwrap_or(dbs.len() - 1)
            .max(1);
        let lo = hi - 1;
        let t = (speed_m_s - dbs[lo].0) / (dbs[hi].0 - dbs[lo].0);
        let linear = [(lo, 1.0 - t), (hi, t)];
        let quadratic: Vec<(usize, f64)> = if dbs.len() < 3 {
            linear.to_vec()
        } else {
            // the window of three consecutive speeds around the speed whose farthest speed is nearest
            let start = (0..=dbs.len() - 3)
                .filter(|&i| dbs[i].0 <= speed_m_s && speed_m_s <= dbs[i + 2].0)
                .min_by(|&i, &j| {
                    let reach = |i: usize| (speed_m_s - dbs[i].0).max(dbs[i + 2].0 - speed_m_s);
                    reach(i).total_cmp(&reach(j))
                })
                .unwrap_or(dbs.len() - 3);
            let idx = [start, start + 1, start + 2];
            idx.iter()
                .map(|&i| {
                    let w = idx
                        .iter()
                        .filter(|&&j| j != i)
                        .map(|&j| (speed_m_s - dbs[j].0) / (dbs[i].0 - dbs[j].0))
                        .product::<f64>();
                    (i, w)
                })
                .collect()
        };
        let mut out = base.clone();
        for (k, (a, b)) in out.added_mass.iter_mut().zip(out.damping.iter_mut()).enumerate() {
            *a = quadratic.iter().map(|&(i, w)| &dbs[i].1.added_mass[k] * w).sum();
            *b = quadratic.iter().map(|&(i, w)| &dbs[i].1.damping[k] * w).sum();
        }
        for (k, x) in out.excitation.iter_mut().enumerate() {
            *x = linear.iter().map(|&(i, w)| dbs[i].1.excitation[k] * w).sum();
        }
        for (k, x) in out.referred.iter_mut().enumerate() {
            *x = linear.iter().map(|&(i, w)| dbs[i].1.referred[k] * w).sum();
        }
        Ok(out)
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

    /// The stored headings a heading is interpolated from and their weights: the Lagrange cubic through
    /// the two either side and one beyond each (wrapping where the headings cover the circle; the nearest
    /// four inside the range at its ends; fewer where fewer are stored). Unused slots have weight 0.
    fn heading_stencil(&self, heading_rad: f64) -> Result<([usize; 4], [f64; 4])> {
        let h = &self.heading_rad;
        let nb = h.len();
        let b = heading_rad.rem_euclid(TWO_PI);
        let near = |x: f64, y: f64| {
            let d = (x - y).rem_euclid(TWO_PI);
            d.min(TWO_PI - d) < 1e-9
        };
        if let Some(i) = h.iter().position(|&x| near(x, b)) {
            return Ok(([i, i, i, i], [1.0, 0.0, 0.0, 0.0]));
        }
        let circle = self.headings_cover_circle();
        // the segment [lo, lo + 1] (indices, possibly past the end on a circle) holding b, unwrapped
        let (lo, b) = if let Some((i, _)) = bracket(h, b) {
            (i as isize, b)
        } else if circle {
            let last = nb - 1;
            (last as isize, if b < h[0] { b + TWO_PI } else { b })
        } else {
            return Err(self.outside(heading_rad));
        };
        // unwrapped angle of index j (any integer on a circle)
        let angle = |j: isize| {
            let m = j.rem_euclid(nb as isize) as usize;
            h[m] + TWO_PI * j.div_euclid(nb as isize) as f64
        };
        let count = nb.min(4) as isize;
        let mut first = lo - (count - 1) / 2;
        if !circle {
            first = first.clamp(0, nb as isize - count);
        }
        let (mut idx, mut wts) = ([0usize; 4], [0.0; 4]);
        for a in 0..count {
            let ja = first + a;
            let mut w = 1.0;
            for c in 0..count {
                if c != a {
                    let jc = first + c;
                    w *= (b - angle(jc)) / (angle(ja) - angle(jc));
                }
            }
            idx[a as usize] = ja.rem_euclid(nb as isize) as usize;
            wts[a as usize] = w;
        }
        Ok((idx, wts))
    }

    fn outside(&self, heading_rad: f64) -> Error {
        let h = &self.heading_rad;
        Error::OutOfRange(format!(
            "heading {:.3} deg is outside the database's headings {:?} deg",
            heading_rad.to_degrees(),
            h.iter()
                .map(|x| (x.to_degrees() * 1e6).round() / 1e6)
                .collect::<Vec<_>>()
        ))
    }

    /// X(w, beta): linear in w, cubic in beta, on the values referred to each body (module docs).
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
        let (idx, wts) = self.heading_stencil(heading_rad)?;
        let n = self.n_modes;
        let nb = self.heading_rad.len();
        let k = wave_number(omega_rad_s, self.g_m_s2, self.depth_m);
        let at = |w: usize, i: usize| -> Complex64 {
            idx.iter()
                .zip(&wts)
                .filter(|(_, w)| **w != 0.0)
                .map(|(&b, &wt)| self.referred[(w * nb + b) * n + i] * wt)
                .sum()
        };
        for (i, o) in out.iter_mut().enumerate().take(n) {
            *o = (at(iw, i) * (1.0 - ww) + at(jw, i) * ww) * self.turn(i, k, heading_rad);
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

    /// A database of `headings_deg` at w = 0.5, 1.0 whose X is `f(heading_rad, w, mode)`.
    fn db_of(headings_deg: &[f64], f: impl Fn(f64, f64, usize) -> Complex64) -> HydroDb {
        let mut d = db(headings_deg.to_vec());
        let nb = d.heading_rad.len();
        for (iw, w) in [0.5, 1.0].into_iter().enumerate() {
            for ib in 0..nb {
                for i in 0..6 {
                    d.excitation[(iw * nb + ib) * 6 + i] = f(d.heading_rad[ib], w, i);
                }
            }
        }
        d.referred = d.excitation.clone();
        d
    }

    #[test]
    fn headings_wrap_when_they_cover_the_circle() {
        let d = db(vec![-90.0, 0.0, 90.0, 180.0]); // -90 is stored as 270
        assert!(d.headings_cover_circle());
        let hs: Vec<f64> = (0..12).map(|k| 30.0 * k as f64).collect();
        let d = db_of(&hs, |b, _, _| Complex64::new(b.cos(), b.sin()));
        // the cubic through 30 deg steps: its error on cos and sin is h^4 max|f(4)| / 24 (9/16), 2e-3
        for q in [45.0f64, 345.0, 5.0, 359.0] {
            let x = d.excitation_at(0.5, q.to_radians()).unwrap();
            let want = Complex64::from_polar(1.0, q.to_radians());
            assert!((x[0] - want).norm() < 3e-3, "{q}: {} vs {want}", x[0]);
        }
    }

    #[test]
    fn the_cubic_is_exact_on_cubics_to_the_ends_of_a_partial_range() {
        let p = |b: f64| 1.0 + 2.0 * b - 0.5 * b * b + 0.3 * b * b * b;
        let hs = [0.0, 20.0, 45.0, 60.0, 90.0, 130.0, 150.0, 180.0];
        let d = db_of(&hs, |b, w, i| Complex64::new(p(b) * w, i as f64));
        for q in [1.0f64, 10.0, 50.0, 100.0, 170.0, 179.5] {
            let b = q.to_radians();
            let x = d.excitation_at(0.75, b).unwrap();
            assert!((x[0].re - 0.75 * p(b)).abs() < 1e-9, "{q}: {}", x[0]);
            assert!((x[4].im - 4.0).abs() < 1e-9);
        }
        assert!(
            d.excitation_at(0.75, 181f64.to_radians()).is_err(),
            "never extrapolated"
        );
    }

    #[test]
    fn excitation_of_a_body_away_from_the_origin_is_interpolated_referred_to_it() {
        // a body at (40, 10) m whose own excitation is the same at every heading: referred to the
        // origin it turns by k r . e_beta, 2 rad between stored headings 30 deg apart near beam seas
        // at 1 rad/s
        let (g, r) = (9.81, [40.0, 10.0]);
        let global = |b: f64, w: f64| {
            let k = w * w / g;
            Complex64::from_polar(1.0, -k * (r[0] * b.cos() + r[1] * b.sin()))
        };
        let hs: Vec<f64> = (0..12).map(|k| 30.0 * k as f64).collect();
        let mut d = db_of(&hs, |b, w, _| global(b, w));
        d.set_bodies(&[r], g, None, None).unwrap();
        assert!(!d.mirrored, "a body off the x axis");
        for q in [15.0f64, 100.0, 250.0] {
            let b = q.to_radians();
            // at a stored frequency: exact (the referred values are constant)
            let x = d.excitation_at(1.0, b).unwrap();
            assert!(
                (x[2] - global(b, 1.0)).norm() < 1e-9,
                "{q}: {} vs {}",
                x[2],
                global(b, 1.0)
            );
        }
        // unreferred, the same interpolation is off by far more
        let mut raw = db_of(&hs, |b, w, _| global(b, w));
        raw.set_bodies(&[[0.0, 0.0]], g, None, None).unwrap();
        let b = 105f64.to_radians();
        let off = (raw.excitation_at(1.0, b).unwrap()[2] - global(b, 1.0)).norm();
        assert!(off > 0.05, "{off}");
    }

    #[test]
    fn a_half_circle_is_completed_by_port_starboard_symmetry() {
        let hs: Vec<f64> = (0..=12).map(|k| 15.0 * k as f64).collect();
        // a symmetric hull's sway, roll and yaw vanish in head and following seas
        let f = |b: f64, _: f64, i: usize| match i {
            1 | 3 | 5 => Complex64::new(b.sin(), 2.0 * b.sin() * (1 + i) as f64),
            _ => Complex64::new(b.cos() + i as f64, (2.0 * b).cos()),
        };
        let mut d = db_of(&hs, f);
        d.set_bodies(&[[40.0, 0.0]], 9.81, None, None).unwrap();
        assert!(d.mirrored && d.headings_cover_circle());
        assert_eq!(d.heading_rad.len(), 24);
        for q in [200.0f64, 300.0, 352.5] {
            let (x, m) = (
                d.excitation_at(1.0, q.to_radians()).unwrap(),
                d.excitation_at(1.0, (360.0 - q).to_radians()).unwrap(),
            );
            for i in 0..6 {
                let s = if matches!(i, 1 | 3 | 5) { -1.0 } else { 1.0 };
                assert!((x[i] - m[i] * s).norm() < 1e-9, "{q} mode {i}: {} vs {}", x[i], m[i]);
            }
        }
        // not for a body off the axis, nor when the file says no; refused when it insists
        let mut off = db_of(&hs, f);
        off.set_bodies(&[[40.0, 3.0]], 9.81, None, None).unwrap();
        assert!(!off.mirrored && off.excitation_at(1.0, 4.0).is_err());
        let mut no = db_of(&hs, f);
        no.set_bodies(&[[40.0, 0.0]], 9.81, None, Some(false)).unwrap();
        assert!(!no.mirrored);
        assert!(
            db_of(&hs, f)
                .set_bodies(&[[40.0, 3.0]], 9.81, None, Some(true))
                .is_err()
        );
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
