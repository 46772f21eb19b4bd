//! Measured wave data turned into a [`WaveField`] (pure): gridded elevation snapshots (a wave radar
//! processor's output) and a wave-probe record. Conventions as in [`super::field`].
//!
//! Grids: each snapshot is 2-D Fourier transformed; for every wavenumber bin k of one half-plane the
//! frequency is fixed by the dispersion relation, w = w(|k|), so the bin's complex value over the
//! snapshots is c(t) = P exp(+i w t) + Q exp(-i w t): P is a wave travelling along -k, Q one along +k.
//! With two or more snapshots P and Q are fitted by least squares (a 3-D transform evaluated on the
//! dispersion shell: energy off the shell, noise and the radar's artefacts, is rejected, and opposite
//! travelling waves are told apart); with one snapshot the direction is taken from a mean-direction
//! hint (the half-plane facing it). Bins outside the wavenumber band are left out.
//!
//! Radar scans ([`from_scans`]): snapshots whose cells may be invalid (NaN: the blind zone around the
//! antenna, cells shadowed behind crests, a sector masked by the superstructure, beyond the range),
//! on a grid that may be turned in the earth frame. Each snapshot's invalid cells are filled from the
//! field fitted to the valid ones ([`fill`]: what the older scans saw of the water in the blind zone
//! now), and the field's region is what the cells valid in any snapshot covered
//! ([`Region::Coverage`]).
//!
//! Probe: the record's FFT (the seed paper's method), long-crested along a given direction, amplitudes
//! referred to the probe and the record's last sample.

use super::field::{COVERAGE_SECTORS, Error, FieldComponent, Region, Result, WaveField, coverage_sector_of};
use num_complex::Complex64;
use rustfft::{FftDirection, FftPlanner};
use std::f64::consts::PI;

pub mod fill;
use fill::masked_fit;
pub use fill::{FILL_PASSES, ScanFit};

/// One gridded elevation snapshot: `values[iy * x_m.len() + ix]` at `(x_m[ix], y_m[iy])`, earth frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    pub x_m: Vec<f64>,
    pub y_m: Vec<f64>,
    pub time_s: f64,
    pub values: Vec<f64>,
}

/// Options of the grid inversion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridOptions {
    pub g_m_s2: f64,
    pub depth_m: Option<f64>,
    /// Frequency band kept, rad/s.
    pub omega_min_rad_s: f64,
    pub omega_max_rad_s: f64,
    /// Direction the waves travel to (earth frame), needed with a single snapshot.
    pub mean_direction_rad: Option<f64>,
    /// The radar's view: the field's region (default: the grid's inscribed disc).
    pub region: Option<Region>,
}

fn uniform_spacing(v: &[f64], name: &str, snap: usize) -> Result<f64> {
    if v.len() < 4 {
        return Err(Error::Invalid(format!(
            "snapshot {snap}: {name} has {} points: at least 4 are needed",
            v.len()
        )));
    }
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(Error::Invalid(format!("snapshot {snap}: {name}[{i}] is not finite")));
    }
    let d = (v[v.len() - 1] - v[0]) / (v.len() - 1) as f64;
    if d <= 0.0 {
        return Err(Error::Invalid(format!("snapshot {snap}: {name} must increase")));
    }
    for i in 1..v.len() {
        let step = v[i] - v[i - 1];
        if (step - d).abs() > 1e-6 * d {
            return Err(Error::Invalid(format!(
                "snapshot {snap}: the grid is not uniform: {name}[{i}] - {name}[{}] = {step} m, the mean spacing is {d} m",
                i - 1
            )));
        }
    }
    Ok(d)
}

/// Turns one or more snapshots of the same grid into a field referred to the grid's centre and the last
/// snapshot's time.
pub fn from_grids(grids: &[Grid], opts: &GridOptions) -> Result<WaveField> {
    let lattice = Lattice::of(grids, opts)?;
    let fits = lattice.fit(grids, &spectra_2d(grids, lattice.nx, lattice.ny), opts);
    lattice.field(grids, &fits, opts)
}

/// A sequence of snapshots on one uniform grid, checked: its size, its extent and where it lies.
struct Lattice {
    nx: usize,
    ny: usize,
    /// The grid's extent along x and y (cells times spacing), m.
    l_m: [f64; 2],
    /// The grid's centre and its first cell, m.
    centre_m: [f64; 2],
    origin_m: [f64; 2],
    /// The last snapshot's time, which the fit refers to, s.
    t_ref_s: f64,
}

/// One wavenumber bin's fit: its complex values over the snapshots are P exp(+i w (t - t_ref)) +
/// Q exp(-i w (t - t_ref)).
#[derive(Debug, Clone, PartialEq)]
struct BinFit {
    /// The bin's index in a snapshot's spectrum.
    index: usize,
    k_rad_m: [f64; 2],
    omega_rad_s: f64,
    p: Complex64,
    q: Complex64,
}

impl Lattice {
    /// The lattice of `grids`, refused with the snapshot and the axis when it is not one uniform grid
    /// sampled at increasing times, or when `opts` cannot invert it.
    fn of(grids: &[Grid], opts: &GridOptions) -> Result<Lattice> {
        let Some(first) = grids.first() else {
            return Err(Error::Invalid("no grid snapshot given".into()));
        };
        if !(opts.omega_min_rad_s > 0.0 && opts.omega_max_rad_s > opts.omega_min_rad_s) {
            return Err(Error::Invalid(format!(
                "frequency band {}..{} rad/s: must be positive and increasing",
                opts.omega_min_rad_s, opts.omega_max_rad_s
            )));
        }
        let (nx, ny) = (first.x_m.len(), first.y_m.len());
        let dx = uniform_spacing(&first.x_m, "x_m", 0)?;
        let dy = uniform_spacing(&first.y_m, "y_m", 0)?;
        check_snapshots(grids, nx, ny)?;
        if grids.len() == 1 && opts.mean_direction_rad.is_none() {
            return Err(Error::Invalid(
                "a single snapshot cannot tell opposite directions apart: give the mean direction or a sequence".into(),
            ));
        }
        Ok(Lattice {
            nx,
            ny,
            l_m: [dx * nx as f64, dy * ny as f64],
            centre_m: [
                0.5 * (first.x_m[0] + first.x_m[nx - 1]),
                0.5 * (first.y_m[0] + first.y_m[ny - 1]),
            ],
            origin_m: [first.x_m[0], first.y_m[0]],
            t_ref_s: grids[grids.len() - 1].time_s,
        })
    }

    /// Every bin of one half-plane inside the band fitted from the snapshots' `spectra`; the mean and
    /// the Nyquist lines (their direction is ambiguous), and the bins `separate` cannot split, left out.
    fn fit(&self, grids: &[Grid], spectra: &[Vec<Complex64>], opts: &GridOptions) -> Vec<BinFit> {
        let (nx, ny) = (self.nx, self.ny);
        let omega_of = |k: f64| match opts.depth_m {
            Some(h) => (opts.g_m_s2 * k * (k * h).tanh()).sqrt(),
            None => (opts.g_m_s2 * k).sqrt(),
        };
        let mut fits = vec![];
        for iy in 0..ny {
            for ix in 0..nx {
                let (mx, my) = (signed(ix, nx), signed(iy, ny));
                if (my < 0 || (my == 0 && mx <= 0)) || (nx % 2 == 0 && ix == nx / 2) || (ny % 2 == 0 && iy == ny / 2) {
                    continue;
                }
                let (kx, ky) = (2.0 * PI * mx as f64 / self.l_m[0], 2.0 * PI * my as f64 / self.l_m[1]);
                let w = omega_of(kx.hypot(ky));
                if w < opts.omega_min_rad_s || w > opts.omega_max_rad_s {
                    continue;
                }
                let index = iy * nx + ix;
                let c: Vec<Complex64> = spectra.iter().map(|s| s[index]).collect();
                let Some((p, q)) = separate(grids, &c, w, self.t_ref_s, opts.mean_direction_rad, [kx, ky]) else {
                    continue;
                };
                fits.push(BinFit {
                    index,
                    k_rad_m: [kx, ky],
                    omega_rad_s: w,
                    p,
                    q,
                });
            }
        }
        fits
    }

    /// The field of `fits`: each bin's two waves, amplitudes referred to the grid's centre.
    fn field(&self, grids: &[Grid], fits: &[BinFit], opts: &GridOptions) -> Result<WaveField> {
        let n = (self.nx * self.ny) as f64;
        let (centre, origin) = (self.centre_m, self.origin_m);
        let mut comps = vec![];
        for b in fits {
            let [kx, ky] = b.k_rad_m;
            // amplitudes at the grid origin, then at the centre
            for (coef, sign, conj) in [(b.p, -1.0, false), (b.q, 1.0, true)] {
                if coef.norm() == 0.0 {
                    continue;
                }
                let mut a = coef * (2.0 / n);
                if conj {
                    a = a.conj();
                }
                let (dxk, dyk) = (sign * kx, sign * ky);
                let shift = dxk * (centre[0] - origin[0]) + dyk * (centre[1] - origin[1]);
                comps.push(FieldComponent {
                    omega_rad_s: b.omega_rad_s,
                    direction_rad: dyk.atan2(dxk),
                    amplitude_m: a * Complex64::from_polar(1.0, -shift),
                });
            }
        }
        let region = opts.region.unwrap_or(Region::Disc {
            centre_m: centre,
            radius_m: 0.5 * self.l_m[0].min(self.l_m[1]),
        });
        let f = WaveField {
            components: comps,
            reference_m: centre,
            time_s: grids[grids.len() - 1].time_s,
            g_m_s2: opts.g_m_s2,
            depth_m: opts.depth_m,
            region,
        };
        f.validate()?;
        Ok(f)
    }
}

/// Where a radar scan's grid lies in the earth frame: its snapshots' `x_m` and `y_m` are along the
/// grid's own axes from `origin_m` (earth, m), its +x axis turned `orientation_rad` counterclockwise
/// from east.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridFrame {
    pub origin_m: [f64; 2],
    pub orientation_rad: f64,
}

impl GridFrame {
    /// The earth point of grid coordinates (x, y).
    pub fn to_earth(&self, x: f64, y: f64) -> [f64; 2] {
        let (s, c) = self.orientation_rad.sin_cos();
        [self.origin_m[0] + c * x - s * y, self.origin_m[1] + s * x + c * y]
    }
}

/// A wavenumber bin whose snapshots' phases leave the least-squares separation of the two directions
/// this ill-conditioned (its determinant at most this share of the largest, n^2) is left out: near
/// w = pi / (scan period) every scan sees the bin at the same phase, and the fit would amplify the
/// noise by 1 / sqrt(share) and more (3 scans 2 s apart: the bins within about 0.1 rad/s of 1.57 rad/s).
pub const SEPARATION_FLOOR: f64 = 0.1;

/// The least share of each snapshot's cells that must be valid.
pub const MIN_VALID_SHARE: f64 = 0.05;

/// A field from radar scans with invalid (NaN) cells on a grid in `frame` ([`from_grids`] of the scans,
/// the invalid cells filled from the fit to the valid ones by [`FILL_PASSES`] passes ([`fill`]); the
/// region what the valid cells covered, seen from the grid's centre; directions and reference point
/// turned into the earth frame).
pub fn from_scans(grids: &[Grid], frame: GridFrame, opts: &GridOptions) -> Result<WaveField> {
    from_scans_after(grids, frame, opts, None).map(|(f, _)| f)
}

/// [`from_scans`] started from the fit of the window before (`prior`, from the same lattice, the
/// grid's origin moved by whole cells at most): the scans' unseen cells are filled from it and fitted
/// once, which tracks the fit to the seen cells as the window slides at a pass's cost. Without a prior
/// (or one from another lattice) the window is fitted with [`FILL_PASSES`] passes. Also returns this
/// window's fit, for the next.
pub fn from_scans_after(
    grids: &[Grid],
    frame: GridFrame,
    opts: &GridOptions,
    prior: Option<&ScanFit>,
) -> Result<(WaveField, ScanFit)> {
    let Some(first) = grids.first() else {
        return Err(Error::Invalid("no radar scan given".into()));
    };
    let (nx, ny) = (first.x_m.len(), first.y_m.len());
    if grids.iter().any(|g| g.values.len() != nx * ny) {
        return Err(Error::Invalid(format!(
            "a scan's values do not fill its {nx} x {ny} grid"
        )));
    }
    for (s, g) in grids.iter().enumerate() {
        let share = g.values.iter().filter(|v| v.is_finite()).count() as f64 / (nx * ny).max(1) as f64;
        if share < MIN_VALID_SHARE {
            return Err(Error::Invalid(format!(
                "snapshot {s}: {:.1} % of its cells are valid: at least {:.0} % are needed",
                100.0 * share,
                100.0 * MIN_VALID_SHARE
            )));
        }
    }
    // each snapshot's own invalid cells are zero (shadows move with the crests: the cells valid in
    // every snapshot are fewer than any one scan's)
    let valid: Vec<bool> = (0..nx * ny)
        .map(|i| grids.iter().any(|g| g.values[i].is_finite()))
        .collect();
    let zeroed: Vec<Grid> = grids
        .iter()
        .map(|g| Grid {
            values: g.values.iter().map(|v| if v.is_finite() { *v } else { 0.0 }).collect(),
            ..g.clone()
        })
        .collect();
    let (local, fit) = masked_fit(
        &zeroed,
        grids,
        frame,
        &GridOptions {
            mean_direction_rad: opts.mean_direction_rad.map(|d| d - frame.orientation_rad),
            region: None,
            ..*opts
        },
        prior,
    )?;
    // the coverage, seen from the grid's centre
    let centre_local = local.reference_m;
    let centre = frame.to_earth(centre_local[0], centre_local[1]);
    let mut ranges_m = [0.0f64; COVERAGE_SECTORS];
    let mut nearest_m = f64::INFINITY;
    // the grid's coarser spacing (from_grids has checked it is uniform and increasing)
    let cell_m = [&first.x_m, &first.y_m]
        .iter()
        .map(|v| (v[v.len() - 1] - v[0]) / (v.len() - 1).max(1) as f64)
        .fold(0.0f64, f64::max);
    for iy in 0..ny {
        for ix in 0..nx {
            if !valid[iy * nx + ix] {
                continue;
            }
            let p = frame.to_earth(first.x_m[ix], first.y_m[iy]);
            let (dx, dy) = (p[0] - centre[0], p[1] - centre[1]);
            let j = coverage_sector_of(dx, dy);
            ranges_m[j] = ranges_m[j].max(dx.hypot(dy));
            nearest_m = nearest_m.min(dx.hypot(dy));
        }
    }
    let f = WaveField {
        components: local
            .components
            .iter()
            .map(|c| FieldComponent {
                direction_rad: c.direction_rad + frame.orientation_rad,
                ..*c
            })
            .collect(),
        reference_m: centre,
        region: Region::Coverage {
            centre_m: centre,
            // the blind zone: to the nearest valid cell, less half a cell's diagonal (a grid without
            // one has none)
            inner_m: (nearest_m - 0.5 * cell_m * std::f64::consts::SQRT_2).max(0.0),
            ranges_m,
            window_s: grids.last().map_or(0.0, |g| g.time_s) - first.time_s,
        },
        ..local
    };
    f.validate()?;
    Ok((f, fit))
}

/// Every snapshot on the first one's grid, with `nx` x `ny` finite values, at finite increasing times.
fn check_snapshots(grids: &[Grid], nx: usize, ny: usize) -> Result<()> {
    let first = &grids[0];
    for (s, g) in grids.iter().enumerate() {
        if g.x_m != first.x_m || g.y_m != first.y_m {
            return Err(Error::Invalid(format!(
                "snapshot {s}: a different grid from snapshot 0"
            )));
        }
        if g.values.len() != nx * ny {
            return Err(Error::Invalid(format!(
                "snapshot {s}: {} values for a {nx} x {ny} grid",
                g.values.len()
            )));
        }
        if let Some(i) = g.values.iter().position(|v| !v.is_finite()) {
            return Err(Error::Invalid(format!(
                "snapshot {s}: cell (ix {}, iy {}) is not finite ({})",
                i % nx,
                i / nx,
                g.values[i]
            )));
        }
        if !g.time_s.is_finite() || (s > 0 && g.time_s <= grids[s - 1].time_s) {
            return Err(Error::Invalid(format!(
                "snapshot {s}: times must be finite and increasing"
            )));
        }
    }
    Ok(())
}

/// The 2-D FFT of each snapshot less its mean (rows, then columns).
fn spectra_2d(grids: &[Grid], nx: usize, ny: usize) -> Vec<Vec<Complex64>> {
    let n = (nx * ny) as f64;
    let fft = Fft2d::new(nx, ny, FftDirection::Forward);
    grids
        .iter()
        .map(|g| {
            let mean = g.values.iter().sum::<f64>() / n;
            let mut c: Vec<Complex64> = g.values.iter().map(|v| Complex64::new(v - mean, 0.0)).collect();
            fft.process(&mut c);
            c
        })
        .collect()
}

/// The signed wavenumber index of FFT bin `i` of `n` (0, 1 .. n / 2, then -(n - i)).
fn signed(i: usize, n: usize) -> i64 {
    if i <= n / 2 { i as i64 } else { i as i64 - n as i64 }
}

/// A 2-D FFT of `nx` x `ny` values stored by rows (unnormalized, as rustfft's).
struct Fft2d {
    nx: usize,
    ny: usize,
    rows: std::sync::Arc<dyn rustfft::Fft<f64>>,
    columns: std::sync::Arc<dyn rustfft::Fft<f64>>,
}

impl Fft2d {
    fn new(nx: usize, ny: usize, direction: FftDirection) -> Fft2d {
        let mut planner = FftPlanner::new();
        Fft2d {
            nx,
            ny,
            rows: planner.plan_fft(nx, direction),
            columns: planner.plan_fft(ny, direction),
        }
    }

    fn process(&self, c: &mut [Complex64]) {
        let (nx, ny) = (self.nx, self.ny);
        for row in c.chunks_exact_mut(nx) {
            self.rows.process(row);
        }
        let mut col = vec![Complex64::default(); ny];
        for ix in 0..nx {
            for iy in 0..ny {
                col[iy] = c[iy * nx + ix];
            }
            self.columns.process(&mut col);
            for iy in 0..ny {
                c[iy * nx + ix] = col[iy];
            }
        }
    }
}

/// The spectra `c` (one per snapshot) of wavenumber `k_rad_m` split into the waves travelling along it
/// and against it (P, Q) at frequency `w`, referred to `t_ref`: by the mean direction for one snapshot,
/// by least squares for a sequence; None when the snapshots cannot tell them apart.
fn separate(
    grids: &[Grid],
    c: &[Complex64],
    w: f64,
    t_ref: f64,
    mean_direction_rad: Option<f64>,
    k_rad_m: [f64; 2],
) -> Option<(Complex64, Complex64)> {
    let [kx, ky] = k_rad_m;
    if grids.len() == 1 {
        let d = mean_direction_rad.unwrap_or(0.0);
        if kx * d.cos() + ky * d.sin() >= 0.0 {
            Some((Complex64::default(), c[0]))
        } else {
            Some((c[0], Complex64::default()))
        }
    } else {
        // least squares: c_j = P e_j + Q conj(e_j), e_j = exp(i w (t_j - t_ref))
        let e: Vec<Complex64> = grids
            .iter()
            .map(|g| Complex64::from_polar(1.0, w * (g.time_s - t_ref)))
            .collect();
        let (mut a11, mut a12) = (0.0, Complex64::default());
        let (mut b1, mut b2) = (Complex64::default(), Complex64::default());
        for (ej, cj) in e.iter().zip(c) {
            a11 += 1.0;
            a12 += ej.conj() * ej.conj();
            b1 += ej.conj() * cj;
            b2 += ej * cj;
        }
        // [[a11, a12], [conj(a12), a11]] [P, Q] = [b1, b2]
        let det = a11 * a11 - a12.norm_sqr();
        if det <= SEPARATION_FLOOR * a11 * a11 {
            // the snapshots sample this frequency at (nearly) the same phase: no separation possible,
            // and a near-singular fit turns the noise into metres
            return None;
        }
        Some(((b1 * a11 - a12 * b2) / det, (b2 * a11 - a12.conj() * b1) / det))
    }
}

/// A wave-probe record: `eta_m` sampled every `dt_s` up to `end_time_s` (the last sample), at
/// `position_m`, waves travelling along `direction_rad` (long-crested); frequencies outside the band
/// are left out.
#[allow(clippy::too_many_arguments)]
pub fn from_probe(
    eta_m: &[f64],
    dt_s: f64,
    end_time_s: f64,
    position_m: [f64; 2],
    direction_rad: f64,
    band_rad_s: (f64, f64),
    g_m_s2: f64,
    depth_m: Option<f64>,
) -> Result<WaveField> {
    if eta_m.len() < 8 {
        return Err(Error::Invalid(format!(
            "probe record has {} samples: at least 8 are needed",
            eta_m.len()
        )));
    }
    if !(dt_s.is_finite() && dt_s > 0.0) {
        return Err(Error::Invalid(format!(
            "probe sample interval {dt_s} s: must be positive"
        )));
    }
    if let Some(i) = eta_m.iter().position(|v| !v.is_finite()) {
        return Err(Error::Invalid(format!("probe sample {i} is not finite ({})", eta_m[i])));
    }
    if !(band_rad_s.0 > 0.0 && band_rad_s.1 > band_rad_s.0) {
        return Err(Error::Invalid(format!(
            "frequency band {}..{} rad/s: must be positive and increasing",
            band_rad_s.0, band_rad_s.1
        )));
    }
    let n = eta_m.len();
    let mean = eta_m.iter().sum::<f64>() / n as f64;
    let mut c: Vec<Complex64> = eta_m.iter().map(|v| Complex64::new(v - mean, 0.0)).collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut c);
    let span = n as f64 * dt_s;
    let t_last_rel = (n - 1) as f64 * dt_s;
    let mut comps = vec![];
    for (m, cm) in c.iter().enumerate().take(n.div_ceil(2)).skip(1) {
        let w = 2.0 * PI * m as f64 / span;
        if w < band_rad_s.0 || w > band_rad_s.1 {
            continue;
        }
        // eta_j = sum Re{a exp(i w j dt)}, a = 2 C_m / n; referred to the last sample
        let a = cm * (2.0 / n as f64) * Complex64::from_polar(1.0, w * t_last_rel);
        comps.push(FieldComponent {
            omega_rad_s: w,
            direction_rad,
            amplitude_m: a,
        });
    }
    let f = WaveField {
        components: comps,
        reference_m: position_m,
        time_s: end_time_s,
        g_m_s2,
        depth_m,
        region: Region::Point {
            at_m: position_m,
            window_s: n as f64 * dt_s,
        },
    };
    f.validate()?;
    Ok(f)
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(super) fn grid_of(field: &WaveField, n: usize, d: f64, t: f64) -> Grid {
        let x: Vec<f64> = (0..n).map(|i| -0.5 * d * n as f64 + d * i as f64).collect();
        let mut pts = Vec::with_capacity(n * n);
        for yy in &x {
            for xx in &x {
                pts.push([*xx, *yy]);
            }
        }
        let mut v = vec![0.0; pts.len()];
        field.elevation(&pts, t, &mut v);
        Grid {
            x_m: x.clone(),
            y_m: x,
            time_s: t,
            values: v,
        }
    }

    fn periodic_field(n: usize, d: f64) -> WaveField {
        // components exactly on the grid's wavenumber lattice, travelling in opposite directions
        let l = n as f64 * d;
        let k1 = 2.0 * PI * 8.0 / l;
        let k2 = 2.0 * PI * 11.0 / l;
        WaveField {
            components: vec![
                FieldComponent {
                    omega_rad_s: (9.81 * k1).sqrt(),
                    direction_rad: 0.0,
                    amplitude_m: Complex64::new(0.7, 0.2),
                },
                FieldComponent {
                    omega_rad_s: (9.81 * k2).sqrt(),
                    direction_rad: PI,
                    amplitude_m: Complex64::new(-0.3, 0.4),
                },
            ],
            reference_m: [0.0, 0.0],
            time_s: 0.0,
            g_m_s2: 9.81,
            depth_m: None,
            region: Region::Everywhere,
        }
    }

    #[test]
    fn a_sequence_separates_opposite_waves() {
        let (n, d) = (64, 10.0);
        let truth = periodic_field(n, d);
        let grids: Vec<Grid> = [0.0, 1.5, 3.0].iter().map(|t| grid_of(&truth, n, d, *t)).collect();
        let opts = GridOptions {
            g_m_s2: 9.81,
            depth_m: None,
            omega_min_rad_s: 0.1,
            omega_max_rad_s: 3.0,
            mean_direction_rad: None,
            region: None,
        };
        let f = from_grids(&grids, &opts).unwrap();
        let big: Vec<&FieldComponent> = f.components.iter().filter(|c| c.amplitude_m.norm() > 0.01).collect();
        assert_eq!(big.len(), 2, "{big:?}");
        for want in &truth.components {
            let got = big
                .iter()
                .find(|c| (c.omega_rad_s - want.omega_rad_s).abs() < 1e-9)
                .expect("component found");
            let dd = (got.direction_rad - want.direction_rad).rem_euclid(2.0 * PI);
            assert!(
                dd < 1e-9 || (2.0 * PI - dd) < 1e-9,
                "direction {} vs {}",
                got.direction_rad,
                want.direction_rad
            );
            // amplitude at the field's reference (the grid centre) and the last snapshot's time
            let k = want.omega_rad_s.powi(2) / 9.81;
            let ph = k * (want.direction_rad.cos() * f.reference_m[0] + want.direction_rad.sin() * f.reference_m[1]);
            let want_a = want.amplitude_m * Complex64::from_polar(1.0, want.omega_rad_s * 3.0 - ph);
            assert!(
                (got.amplitude_m - want_a).norm() < 1e-9,
                "{} vs {want_a}",
                got.amplitude_m
            );
        }
    }

    #[test]
    fn bad_grids_are_refused_with_the_cell() {
        let (n, d) = (16, 10.0);
        let truth = periodic_field(n, d);
        let opts = GridOptions {
            g_m_s2: 9.81,
            depth_m: None,
            omega_min_rad_s: 0.1,
            omega_max_rad_s: 3.0,
            mean_direction_rad: Some(0.0),
            region: None,
        };
        let mut g = grid_of(&truth, n, d, 0.0);
        g.values[3 * n + 5] = f64::NAN;
        let e = from_grids(std::slice::from_ref(&g), &opts).unwrap_err().to_string();
        assert!(e.contains("cell (ix 5, iy 3) is not finite"), "{e}");
        let mut g = grid_of(&truth, n, d, 0.0);
        g.x_m[7] += 1.0;
        let e = from_grids(&[g], &opts).unwrap_err().to_string();
        assert!(e.contains("not uniform") && e.contains("x_m[7]"), "{e}");
        let g = grid_of(&truth, n, d, 0.0);
        let e = from_grids(&[g.clone(), g], &opts).unwrap_err().to_string();
        assert!(e.contains("increasing"), "{e}");
    }

    #[test]
    fn probe_record_reproduces_itself() {
        let truth = periodic_field(64, 10.0);
        let dt = 0.5;
        let n = 512;
        let p = [30.0, -20.0];
        // a record that is periodic over its span: components on the FFT's frequency lattice
        let span = n as f64 * dt;
        let mut t = truth.clone();
        for (c, m) in t.components.iter_mut().zip([20.0, 31.0]) {
            c.omega_rad_s = 2.0 * PI * m / span;
            c.direction_rad = 0.4;
        }
        let eta: Vec<f64> = (0..n).map(|j| t.elevation_at(p, j as f64 * dt)).collect();
        let f = from_probe(&eta, dt, (n - 1) as f64 * dt, p, 0.4, (0.05, 3.0), 9.81, None).unwrap();
        for j in [0, 100, n - 1] {
            let tj = j as f64 * dt;
            assert!((f.elevation_at(p, tj) - eta[j]).abs() < 1e-9);
        }
        // downstream: the same field
        let q = [p[0] + 300.0 * 0.4f64.cos(), p[1] + 300.0 * 0.4f64.sin()];
        let tq = 200.0;
        assert!((f.elevation_at(q, tq) - t.elevation_at(q, tq)).abs() < 1e-9);
    }
}
