//! Phase-resolved wave fields in the earth frame (pure).
//!
//! Conventions (DESIGN.md section 1): earth frame x east, y north (local ENU tangent plane), m; a
//! direction is where the waves travel to, counterclockwise from east, rad. A component is
//! eta(p, t) = Re{ a exp(i(w (t - t_ref) - k d . (p - p_ref))) }, d = (cos dir, sin dir), k from the
//! dispersion relation at the field's depth; `a` is the complex amplitude at the reference point at the
//! reference time. A vessel's heading here is the direction of its +x axis, counterclockwise from east
//! (compass headings are converted at the edges: [`heading_from_compass_deg`]).

use super::{WaveComponent, wave_number};
use num_complex::Complex64;

/// Errors of wave-field inputs: the message names the field, cell or sample.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    #[error("{0}")]
    Invalid(String),
}

pub type Result<T> = std::result::Result<T, Error>;

/// One directional component of a field (earth frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldComponent {
    /// Absolute frequency, rad/s (> 0).
    pub omega_rad_s: f64,
    /// Direction of travel, counterclockwise from east, rad.
    pub direction_rad: f64,
    /// Complex amplitude at the field's reference point and time, m.
    pub amplitude_m: Complex64,
}

/// Where a field was observed.
#[derive(Debug, Clone, Copy, PartialEq)]
// one region a field: a box would be an allocation per field for nothing, and it keeps the type Copy
#[allow(clippy::large_enum_variant)]
pub enum Region {
    /// Known everywhere (a synthetic sea, a list of components without a region).
    Everywhere,
    /// A disc (a radar's view), earth frame.
    Disc { centre_m: [f64; 2], radius_m: f64 },
    /// A point (a wave probe) whose record of `window_s` seconds up to the field's time was fitted
    /// (0: not said).
    Point { at_m: [f64; 2], window_s: f64 },
    /// What a radar's valid cells covered, seen from `centre_m` (earth frame): in each of
    /// [`COVERAGE_SECTORS`] equal sectors of direction (sector j spans j..j+1 times 360 / sectors deg,
    /// counterclockwise from east), the farthest valid cell, m (0: nothing seen that way); nothing
    /// within `inner_m` of the centre was seen (a radar's blind zone). The field was fitted to scans
    /// from `window_s` before its time up to it (0: one scan, or not said): water that has moved into
    /// the blind zone since was seen by an earlier scan of the window.
    Coverage {
        centre_m: [f64; 2],
        inner_m: f64,
        ranges_m: [f64; COVERAGE_SECTORS],
        window_s: f64,
    },
}

/// Sectors of a [`Region::Coverage`] (5 deg each).
pub const COVERAGE_SECTORS: usize = 72;

impl Region {
    /// Whether an earth point is inside the observed region (a point region: never).
    pub fn contains(&self, p: [f64; 2]) -> bool {
        match self {
            Region::Everywhere => true,
            Region::Disc { centre_m, radius_m } => (p[0] - centre_m[0]).hypot(p[1] - centre_m[1]) <= *radius_m,
            Region::Point { .. } => false,
            Region::Coverage {
                centre_m,
                inner_m,
                ranges_m,
                ..
            } => {
                // squared distances and a polynomial bearing, the bearing only where the distance
                // allows: the known leads' march asks this millions of times a forecast
                // (`horizon::known_leads`)
                let (dx, dy) = (p[0] - centre_m[0], p[1] - centre_m[1]);
                let r2 = dx * dx + dy * dy;
                if r2 < inner_m * inner_m {
                    return false;
                }
                let range = ranges_m[coverage_sector_of(dx, dy)];
                r2 <= range * range
            }
        }
    }
}

/// The [`Region::Coverage`] sector of the direction of `(dx, dy)` (east, north), by
/// [`bearing_rad`]: what a coverage is built and asked with.
pub fn coverage_sector_of(dx: f64, dy: f64) -> usize {
    let b = bearing_rad(dx, dy);
    let f = if b < 0.0 { b + std::f64::consts::TAU } else { b } / std::f64::consts::TAU;
    ((f * COVERAGE_SECTORS as f64) as usize).min(COVERAGE_SECTORS - 1)
}

/// `dy.atan2(dx)` within 2e-6 rad (a minimax polynomial of atan on [0, 1], by octant), several times
/// cheaper than libm's: a coverage's sectors are 5 deg wide, so a point can change sector only
/// within 2e-6 rad of a sector's edge, and the coverage is built with the same function
/// ([`coverage_sector_of`]). (0, 0): 0.
pub fn bearing_rad(dx: f64, dy: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI};
    let (ax, ay) = (dx.abs(), dy.abs());
    let (lo, hi) = if ay > ax { (ax, ay) } else { (ay, ax) };
    if hi == 0.0 {
        return 0.0;
    }
    let a = lo / hi;
    let s = a * a;
    let mut r = a
        * (0.99997726 + s * (-0.33262347 + s * (0.19354346 + s * (-0.11643287 + s * (0.05265332 + s * -0.01172120)))));
    if ay > ax {
        r = FRAC_PI_2 - r;
    }
    if dx < 0.0 {
        r = PI - r;
    }
    if dy < 0.0 { -r } else { r }
}

/// A phase-resolved wave field.
#[derive(Debug, Clone, PartialEq)]
pub struct WaveField {
    pub components: Vec<FieldComponent>,
    /// Reference point of the amplitudes, earth frame, m.
    pub reference_m: [f64; 2],
    /// Reference time of the amplitudes (the observation time), s on the sensors' clock.
    pub time_s: f64,
    pub g_m_s2: f64,
    /// None = infinite depth.
    pub depth_m: Option<f64>,
    pub region: Region,
}

/// A field's header numbers in the flat layout shared by the wire (`ipc::wire::WaveHeader`) and the
/// log (`record::WavesRecord`); the components travel as rows `[omega_rad_s, direction_rad, re, im]`.
/// Radius 0 = no region known (read back as [`Region::Everywhere`]); a negative radius = a wave probe
/// at the reference point ([`Region::Point`]; a probe's field is referred to its point); depth 0 =
/// infinite. `window_s`: a probe's fitted record, or a radar's window of scans, s (0: not said, or one
/// scan). A radar's view
/// ([`Region::Coverage`], seen from the reference point): `inner_m` its blind zone (0: none) and
/// `ranges_m` the farthest point seen per sector (None: the disc of `radius_m`, less the blind zone),
/// `radius_m` then the farthest of them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlatHeader {
    pub time_s: f64,
    pub reference_m: [f64; 2],
    pub radius_m: f64,
    pub depth_m: f64,
    pub g_m_s2: f64,
    pub window_s: f64,
    pub inner_m: f64,
    pub ranges_m: Option<[f64; COVERAGE_SECTORS]>,
}

/// The most sectors a coverage may be given in on the wire or in a log (a tenth of a degree each).
pub const MAX_GIVEN_SECTORS: usize = 3600;

/// A coverage given as the farthest point seen in each of `given.len()` equal sectors of direction
/// (sector i spans i..i+1 times 360 / n deg, counterclockwise from east; m), in
/// [`COVERAGE_SECTORS`] sectors: each the nearest of the given sectors it overlaps (what was seen
/// all across it). None for none given; an error names the first range that is not a finite number
/// >= 0, or too many sectors.
pub fn coverage_from_sectors(given: &[f64]) -> Result<Option<[f64; COVERAGE_SECTORS]>> {
    let n = given.len();
    if n == 0 {
        return Ok(None);
    }
    if n > MAX_GIVEN_SECTORS {
        return Err(Error::Invalid(format!(
            "coverage in {n} sectors: at most {MAX_GIVEN_SECTORS}"
        )));
    }
    check_ranges(given)?;
    Ok(Some(std::array::from_fn(|j| {
        // the given sectors overlapping [j, j + 1) of ours, in units of theirs (exact where n is a
        // multiple of COVERAGE_SECTORS or a divisor)
        let scale = n as f64 / COVERAGE_SECTORS as f64;
        let lo = ((j as f64 * scale) + 1e-9).floor() as usize;
        let hi = (((j + 1) as f64 * scale) - 1e-9).ceil() as usize;
        given[lo.min(n - 1)..hi.clamp(lo.min(n - 1) + 1, n)]
            .iter()
            .fold(f64::INFINITY, |m, r| m.min(*r))
    })))
}

/// Every range of a coverage (m, per sector) a finite number >= 0; the error names the first that is
/// not by its sector.
fn check_ranges(ranges_m: &[f64]) -> Result<()> {
    match ranges_m.iter().position(|r| !(r.is_finite() && *r >= 0.0)) {
        Some(j) => Err(Error::Invalid(format!(
            "coverage sector {j}: range {} m must be a finite number >= 0",
            ranges_m[j]
        ))),
        None => Ok(()),
    }
}

/// Converts a compass heading (clockwise from north, degrees) to a direction counterclockwise from
/// east, radians.
pub fn heading_from_compass_deg(compass_deg: f64) -> f64 {
    (90.0 - compass_deg).to_radians()
}

impl WaveField {
    /// A field from components given in a frame whose x axis points east (a scenario's or a
    /// realization's: heading = direction), referred to the origin at t = 0.
    pub fn from_components(
        components: &[WaveComponent],
        g_m_s2: f64,
        depth_m: Option<f64>,
        region: Region,
    ) -> WaveField {
        WaveField {
            components: components
                .iter()
                .map(|c| FieldComponent {
                    omega_rad_s: c.omega_rad_s,
                    direction_rad: c.heading_rad,
                    amplitude_m: c.amplitude_m,
                })
                .collect(),
            reference_m: [0.0, 0.0],
            time_s: 0.0,
            g_m_s2,
            depth_m,
            region,
        }
    }

    /// Checks every component: positive finite frequency, finite direction and amplitude.
    /// The header numbers of the flat layout ([`FlatHeader`]). A point region travels as the
    /// reference point (a probe's field is referred to its probe: `observe::from_probe`).
    pub fn flat_header(&self) -> FlatHeader {
        let (inner_m, ranges_m) = match self.region {
            Region::Coverage { inner_m, ranges_m, .. } => (inner_m, Some(ranges_m)),
            _ => (0.0, None),
        };
        FlatHeader {
            time_s: self.time_s,
            reference_m: self.reference_m,
            radius_m: match self.region {
                Region::Disc { radius_m, .. } => radius_m,
                Region::Coverage { ranges_m, .. } => ranges_m.iter().fold(0.0, |m, r| m.max(*r)),
                Region::Point { .. } => -1.0,
                Region::Everywhere => 0.0,
            },
            depth_m: self.depth_m.unwrap_or(0.0),
            g_m_s2: self.g_m_s2,
            window_s: match self.region {
                Region::Point { window_s, .. } | Region::Coverage { window_s, .. } => window_s,
                _ => 0.0,
            },
            inner_m,
            ranges_m,
        }
    }

    /// The components as flat rows `[omega_rad_s, direction_rad, re, im]`.
    pub fn flat_rows(&self) -> impl Iterator<Item = [f64; 4]> + '_ {
        self.components
            .iter()
            .map(|c| [c.omega_rad_s, c.direction_rad, c.amplitude_m.re, c.amplitude_m.im])
    }

    /// A field from the flat layout, validated (the inverse of [`Self::flat_header`] and
    /// [`Self::flat_rows`]; a coverage is seen from the reference point, and a disc with a blind zone
    /// or a window of scans is a coverage of that radius all round).
    pub fn from_flat(h: FlatHeader, rows: impl IntoIterator<Item = [f64; 4]>) -> Result<WaveField> {
        // a window that is not a positive finite number is not said
        let window_s = if h.window_s.is_finite() && h.window_s > 0.0 {
            h.window_s
        } else {
            0.0
        };
        let f = WaveField {
            components: rows
                .into_iter()
                .map(|c| FieldComponent {
                    omega_rad_s: c[0],
                    direction_rad: c[1],
                    amplitude_m: Complex64::new(c[2], c[3]),
                })
                .collect(),
            reference_m: h.reference_m,
            time_s: h.time_s,
            g_m_s2: h.g_m_s2,
            depth_m: (h.depth_m > 0.0).then_some(h.depth_m),
            region: if h.radius_m > 0.0 && (h.ranges_m.is_some() || h.inner_m != 0.0 || window_s > 0.0) {
                Region::Coverage {
                    centre_m: h.reference_m,
                    inner_m: h.inner_m,
                    ranges_m: h.ranges_m.unwrap_or([h.radius_m; COVERAGE_SECTORS]),
                    window_s,
                }
            } else if h.radius_m > 0.0 {
                Region::Disc {
                    centre_m: h.reference_m,
                    radius_m: h.radius_m,
                }
            } else if h.radius_m < 0.0 {
                Region::Point {
                    at_m: h.reference_m,
                    window_s,
                }
            } else {
                Region::Everywhere
            },
        };
        f.validate()?;
        Ok(f)
    }

    pub fn validate(&self) -> Result<()> {
        for (i, c) in self.components.iter().enumerate() {
            if !(c.omega_rad_s.is_finite() && c.omega_rad_s > 0.0) {
                return Err(Error::Invalid(format!(
                    "component {i}: frequency {} rad/s must be positive and finite",
                    c.omega_rad_s
                )));
            }
            if !(c.direction_rad.is_finite() && c.amplitude_m.re.is_finite() && c.amplitude_m.im.is_finite()) {
                return Err(Error::Invalid(format!(
                    "component {i}: direction and amplitude must be finite"
                )));
            }
        }
        if !(self.g_m_s2.is_finite() && self.g_m_s2 > 0.0) {
            return Err(Error::Invalid(format!("g = {}: must be positive", self.g_m_s2)));
        }
        if let Some(h) = self.depth_m
            && !(h.is_finite() && h > 0.0)
        {
            return Err(Error::Invalid(format!("depth {h} m: must be positive")));
        }
        if let Region::Coverage { inner_m, ranges_m, .. } = self.region {
            if !(inner_m.is_finite() && inner_m >= 0.0) {
                return Err(Error::Invalid(format!(
                    "blind zone {inner_m} m: must be a finite number >= 0"
                )));
            }
            check_ranges(&ranges_m)?;
        }
        Ok(())
    }

    /// Refuses a field used `now_s` when it is older than `max_age_s` (or from the future).
    pub fn check_age(&self, now_s: f64, max_age_s: f64) -> Result<()> {
        let age = now_s - self.time_s;
        if !(age.is_finite() && age <= max_age_s) {
            return Err(Error::Invalid(format!(
                "the wave field is {age:.1} s old (observed at {:.3} s, now {now_s:.3} s): beyond its validity of {max_age_s} s",
                self.time_s
            )));
        }
        if age < -1e-9 {
            return Err(Error::Invalid(format!(
                "the wave field is from the future: observed at {:.3} s, now {now_s:.3} s",
                self.time_s
            )));
        }
        Ok(())
    }

    /// Wave number of a component, rad/m.
    pub fn wave_number(&self, omega_rad_s: f64) -> f64 {
        wave_number(omega_rad_s, self.g_m_s2, self.depth_m)
    }

    /// Elevation at `points` (earth frame, m) at time `t_s`, into `out`.
    pub fn elevation(&self, points: &[[f64; 2]], t_s: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|e| *e = 0.0);
        self.each_term(points, t_s, |i, a0, cs, sn| {
            // Re{a0 exp(-i ph)}
            out[i] += a0.re * cs + a0.im * sn;
        });
    }

    /// The elevation's analytic signal at `points` and `t_s`: the elevation (real part) and its Hilbert
    /// transform (imaginary part: every component a quarter period on), into `out`.
    pub fn analytic_elevation(&self, points: &[[f64; 2]], t_s: f64, out: &mut [Complex64]) {
        out.iter_mut().for_each(|e| *e = Complex64::default());
        self.each_term(points, t_s, |i, a0, cs, sn| {
            // a0 exp(-i ph)
            out[i] += Complex64::new(a0.re * cs + a0.im * sn, a0.im * cs - a0.re * sn);
        });
    }

    /// Calls `f(point, a0, cos ph, sin ph)` for every component and point: a0 the component's complex
    /// amplitude at the reference point and `t_s`, ph its phase k . (p - reference).
    fn each_term(&self, points: &[[f64; 2]], t_s: f64, mut f: impl FnMut(usize, Complex64, f64, f64)) {
        let dt = t_s - self.time_s;
        for c in &self.components {
            let k = self.wave_number(c.omega_rad_s);
            let (s, co) = c.direction_rad.sin_cos();
            let (kx, ky) = (k * co, k * s);
            let a0 = c.amplitude_m * Complex64::from_polar(1.0, c.omega_rad_s * dt);
            for (i, p) in points.iter().enumerate() {
                let ph = kx * (p[0] - self.reference_m[0]) + ky * (p[1] - self.reference_m[1]);
                let (sn, cs) = ph.sin_cos();
                f(i, a0, cs, sn);
            }
        }
    }

    /// Elevation at one point and time.
    pub fn elevation_at(&self, p: [f64; 2], t_s: f64) -> f64 {
        let mut e = [0.0];
        self.elevation(&[p], t_s, &mut e);
        e[0]
    }

    /// The field in a vessel's seakeeping frame at t0: each component's heading relative to the
    /// vessel's +x and its amplitude at the vessel's origin (`position_m`, earth frame) at `t0_s`.
    pub fn for_vessel(&self, position_m: [f64; 2], heading_rad: f64, t0_s: f64) -> Vec<WaveComponent> {
        self.components
            .iter()
            .map(|c| {
                let k = self.wave_number(c.omega_rad_s);
                let (s, co) = c.direction_rad.sin_cos();
                let ph = k * (co * (position_m[0] - self.reference_m[0]) + s * (position_m[1] - self.reference_m[1]));
                WaveComponent {
                    omega_rad_s: c.omega_rad_s,
                    heading_rad: c.direction_rad - heading_rad,
                    amplitude_m: c.amplitude_m * Complex64::from_polar(1.0, c.omega_rad_s * (t0_s - self.time_s) - ph),
                }
            })
            .collect()
    }

    /// The largest components that together hold `fraction` of the variance (a radar inversion gives one
    /// per wavenumber bin, most of them noise: the forecast's cost is proportional to their number).
    pub fn pruned(&self, fraction: f64) -> WaveField {
        let mut idx: Vec<usize> = (0..self.components.len()).collect();
        idx.sort_by(|a, b| {
            self.components[*b]
                .amplitude_m
                .norm_sqr()
                .total_cmp(&self.components[*a].amplitude_m.norm_sqr())
        });
        let total = self.variance_m2();
        let mut acc = 0.0;
        let mut keep = vec![];
        for i in idx {
            if acc >= fraction * total {
                break;
            }
            acc += 0.5 * self.components[i].amplitude_m.norm_sqr();
            keep.push(self.components[i]);
        }
        WaveField {
            components: keep,
            ..self.clone()
        }
    }

    /// Variance sum |a|^2 / 2, m^2.
    pub fn variance_m2(&self) -> f64 {
        self.components.iter().map(|c| 0.5 * c.amplitude_m.norm_sqr()).sum()
    }
}

/// Group velocity of frequency w at depth h (None: deep), m/s.
pub fn group_velocity(omega_rad_s: f64, g_m_s2: f64, depth_m: Option<f64>) -> f64 {
    let k = wave_number(omega_rad_s, g_m_s2, depth_m);
    let c = omega_rad_s / k;
    match depth_m {
        Some(h) if k * h < 20.0 => {
            let kh = k * h;
            0.5 * c * (1.0 + 2.0 * kh / (2.0 * kh).sinh())
        }
        _ => 0.5 * c,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What the polynomial bearing may differ from libm's atan2 by, rad (its fit's error is 1.7e-6).
    const BEARING_TOLERANCE_RAD: f64 = 2e-6;

    #[test]
    fn the_bearing_is_atan2_to_its_tolerance_all_round() {
        let mut worst = 0.0f64;
        for k in 0..=7200 {
            let a = (k as f64 / 7200.0 - 0.5) * std::f64::consts::TAU;
            for r in [1e-3, 1.0, 2500.0] {
                let (dx, dy) = (r * a.cos(), r * a.sin());
                // the same direction either side of the branch cut at +-pi
                let d = (bearing_rad(dx, dy) - dy.atan2(dx)).rem_euclid(std::f64::consts::TAU);
                worst = worst.max(d.min(std::f64::consts::TAU - d));
            }
        }
        assert!(worst < BEARING_TOLERANCE_RAD, "worst {worst:e} rad");
        assert_eq!(bearing_rad(0.0, 0.0), 0.0);
        assert_eq!(coverage_sector_of(1.0, -1e-9), COVERAGE_SECTORS - 1);
        assert_eq!(coverage_sector_of(1.0, 0.0), 0);
    }
    use std::f64::consts::PI;

    fn field() -> WaveField {
        WaveField {
            components: vec![
                FieldComponent {
                    omega_rad_s: 0.6,
                    direction_rad: 0.3,
                    amplitude_m: Complex64::new(0.5, -0.2),
                },
                FieldComponent {
                    omega_rad_s: 0.9,
                    direction_rad: 2.0,
                    amplitude_m: Complex64::new(-0.1, 0.3),
                },
            ],
            reference_m: [100.0, -50.0],
            time_s: 1000.0,
            g_m_s2: 9.81,
            depth_m: Some(60.0),
            region: Region::Everywhere,
        }
    }

    #[test]
    fn the_flat_layout_keeps_every_region() {
        for region in [
            Region::Everywhere,
            Region::Disc {
                centre_m: [100.0, -50.0],
                radius_m: 800.0,
            },
            Region::Point {
                at_m: [100.0, -50.0],
                window_s: 120.0,
            },
            // a radar's view: a blind zone, a masked sector, shadows (not read back as the disc of
            // its farthest reach)
            Region::Coverage {
                centre_m: [100.0, -50.0],
                inner_m: 190.0,
                ranges_m: std::array::from_fn(|j| {
                    if (30..38).contains(&j) {
                        0.0
                    } else {
                        600.0 + 5.0 * j as f64
                    }
                }),
                window_s: 62.0,
            },
        ] {
            let f = WaveField { region, ..field() };
            let back = WaveField::from_flat(f.flat_header(), f.flat_rows()).unwrap();
            assert_eq!(back, f);
        }
    }

    #[test]
    fn a_coverage_given_in_other_sectors_keeps_only_what_was_seen_all_across_ours() {
        assert_eq!(coverage_from_sectors(&[]).unwrap(), None);
        // 36 sectors of 10 deg: each of ours (5 deg) inside one of them
        let coarse: Vec<f64> = (0..36).map(|i| 100.0 * i as f64).collect();
        let ours = coverage_from_sectors(&coarse).unwrap().unwrap();
        assert!((0..COVERAGE_SECTORS).all(|j| ours[j] == coarse[j / 2]), "{ours:?}");
        // 144 sectors of 2.5 deg: the nearer of the two in each of ours
        let fine: Vec<f64> = (0..144)
            .map(|i| if i % 2 == 0 { 500.0 } else { 300.0 + i as f64 })
            .collect();
        let ours = coverage_from_sectors(&fine).unwrap().unwrap();
        assert!(
            (0..COVERAGE_SECTORS).all(|j| ours[j] == 301.0 + 2.0 * j as f64),
            "{ours:?}"
        );
        // 7 sectors (51.4 deg): ours across a boundary takes the nearer
        let seven = [900.0, 100.0, 900.0, 900.0, 900.0, 900.0, 900.0];
        let ours = coverage_from_sectors(&seven).unwrap().unwrap();
        // our sector 10 spans 50-55 deg, across the boundary at 51.4 deg
        assert_eq!((ours[9], ours[10], ours[11]), (900.0, 100.0, 100.0));
        // 72: as given
        let same: Vec<f64> = (0..72).map(|i| i as f64).collect();
        assert_eq!(coverage_from_sectors(&same).unwrap().unwrap().to_vec(), same);
        for bad in [vec![f64::NAN; 72], vec![-1.0; 10], vec![1.0; MAX_GIVEN_SECTORS + 1]] {
            assert!(coverage_from_sectors(&bad).is_err());
        }
        let err = coverage_from_sectors(&[5.0, 5.0, f64::INFINITY])
            .unwrap_err()
            .to_string();
        assert!(err.contains("coverage sector 2"), "{err}");
    }

    #[test]
    fn a_disc_with_a_blind_zone_is_a_coverage_all_round() {
        let f = field();
        let h = FlatHeader {
            radius_m: 900.0,
            inner_m: 150.0,
            ..f.flat_header()
        };
        let back = WaveField::from_flat(h, f.flat_rows()).unwrap();
        assert_eq!(
            back.region,
            Region::Coverage {
                centre_m: f.reference_m,
                inner_m: 150.0,
                ranges_m: [900.0; COVERAGE_SECTORS],
                window_s: 0.0,
            }
        );
        let bad = FlatHeader { inner_m: -1.0, ..h };
        assert!(
            WaveField::from_flat(bad, f.flat_rows())
                .unwrap_err()
                .to_string()
                .contains("blind zone")
        );
    }

    #[test]
    fn elevation_is_the_analytic_sum() {
        let f = field();
        let p = [[350.0, 120.0], [-40.0, 10.0]];
        let t = 1012.5;
        let mut out = [0.0; 2];
        f.elevation(&p, t, &mut out);
        for (q, e) in p.iter().zip(out) {
            let mut want = 0.0;
            for c in &f.components {
                let k = wave_number(c.omega_rad_s, 9.81, Some(60.0));
                let ph = c.omega_rad_s * (t - 1000.0)
                    - k * ((q[0] - 100.0) * c.direction_rad.cos() + (q[1] + 50.0) * c.direction_rad.sin());
                want += (c.amplitude_m * Complex64::from_polar(1.0, ph)).re;
            }
            assert!((e - want).abs() < 1e-12, "{e} vs {want}");
        }
    }

    #[test]
    fn vessel_frame_gives_the_same_elevation_at_its_origin() {
        let f = field();
        let pos = [230.0, 75.0];
        let comps = f.for_vessel(pos, 1.1, 1005.0);
        // at the origin at t0 + 3 s: sum Re{a exp(i w 3)}
        let e: f64 = comps
            .iter()
            .map(|c| (c.amplitude_m * Complex64::from_polar(1.0, c.omega_rad_s * 3.0)).re)
            .sum();
        assert!((e - f.elevation_at(pos, 1008.0)).abs() < 1e-12);
        assert!((comps[0].heading_rad - (0.3 - 1.1)).abs() < 1e-15);
    }

    #[test]
    fn pruning_keeps_the_largest_components() {
        let f = field();
        let total = f.variance_m2();
        let p = f.pruned(0.5);
        assert_eq!(p.components.len(), 1);
        assert_eq!(p.components[0], f.components[0]);
        assert!(p.variance_m2() >= 0.5 * total);
        assert_eq!(f.pruned(1.0).components.len(), 2);
    }

    #[test]
    fn compass_conversion() {
        assert!((heading_from_compass_deg(0.0) - PI / 2.0).abs() < 1e-15); // north
        assert!(heading_from_compass_deg(90.0).abs() < 1e-15); // east
        assert!((heading_from_compass_deg(270.0) + PI).abs() < 1e-12); // west
    }

    #[test]
    fn group_velocity_limits() {
        assert!((group_velocity(0.5, 9.81, None) - 9.81 / (2.0 * 0.5)).abs() < 1e-12);
        // shallow: c_g -> sqrt(g h)
        let cg = group_velocity(0.02, 9.81, Some(10.0));
        assert!((cg - (98.1f64).sqrt()).abs() / cg < 1e-3);
    }

    #[test]
    fn bad_components_are_named() {
        let mut f = field();
        f.components[1].omega_rad_s = 0.0;
        assert!(f.validate().unwrap_err().to_string().contains("component 1"));
        let mut f = field();
        f.components[0].amplitude_m = Complex64::new(f64::NAN, 0.0);
        assert!(f.validate().is_err());
        let f = field();
        assert!(f.check_age(1020.0, 30.0).is_ok());
        let e = f.check_age(1042.0, 30.0).unwrap_err().to_string();
        assert!(e.contains("42.0 s old") && e.contains("validity of 30 s"), "{e}");
        assert!(f.check_age(990.0, 30.0).unwrap_err().to_string().contains("future"));
    }
}
