//! WAMIT output file readers: `.1` (added mass and damping), `.3`/`.2`/`.3fk`/`.3sc` (excitation),
//! `.hst` (hydrostatic restoring). Pure: they read from any `BufRead`; `file` is only a label for errors.
//!
//! Formats (WAMIT v7 manual, section 4; shipcast DESIGN.md section 1). ULEN = L, rho and g come from the
//! system file. Periods are assumed (WAMIT's default IPEROUT = 1), in seconds.
//! - `.1`:  `PER I J Abar [Bbar]`, A = rho L^k Abar, B = rho w L^k Bbar, k = 3 / 4 / 5 for
//!   translation-translation / mixed / rotation-rotation. PER = -1 is w = 0, PER = 0 is w = infinity
//!   (those rows carry no Bbar). Pairs absent from the file are zero.
//! - `.3`:  `PER BETA I |X| phase_deg Re Im`, X = rho g L^m (Re + i Im) per metre of wave amplitude,
//!   m = 2 for forces, 3 for moments, BETA in degrees; exp(+i w t).
//! - `.hst`: `I J Cbar`, C = rho g L^k Cbar, k = 2 / 3 / 4.
//!
//! Files written by WAMIT start with a one-line text header; files written by other tools often have
//! none: a first line whose first field is not a number is taken as the header.
//! Rows may come in any order; frequencies are returned sorted ascending.
//!
//! Completeness: WAMIT omits a pair (I, J) or a mode I only when it is zero at every frequency, so every
//! positive period of a `.1` file lists the same pairs (the union over its positive periods; PER = -1 / 0
//! rows may list another set), and every (period, heading) of a `.3` file the same modes. A period or
//! heading missing some is an error naming the file, the period and the first missing pair or mode (a
//! file cut short).
//!
//! Physical bounds ([`EntryBounds`], from the system file's masses): WAMIT's own scaling with the body's
//! length l = (m / rho)^(1/3) (m its mass; the geometric mean of the two bodies' for a coupling entry) in
//! place of ULEN makes every coefficient of a floating body of order one: |A_ij| <= F rho l^k,
//! |B_ij| <= F rho l^k max(w, sqrt(g / l)), |C_ij| <= F rho g l^k (k as above), |X_i| <= F rho g l^m, with
//! F = [`ENTRY_FACTOR`]. An entry beyond is an error naming the file and line: such a value is a corrupt
//! file, not a hull, and it would stall the solvers (an SVD of a matrix spanning 300 decades).

use super::{Error, Result};
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::io::BufRead;

/// Dimensional scaling of WAMIT's non-dimensional values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scaling {
    /// Water density, kg/m^3.
    pub rho: f64,
    /// Gravitational acceleration, m/s^2.
    pub g: f64,
    /// WAMIT's length scale ULEN, m.
    pub ulen: f64,
}

impl Scaling {
    fn is_rot(mode0: usize) -> bool {
        mode0 % 6 >= 3
    }
    /// Exponent of L for a radiation pair (3, 4, 5).
    fn k_rad(i0: usize, j0: usize) -> i32 {
        3 + Self::is_rot(i0) as i32 + Self::is_rot(j0) as i32
    }
    fn k_hst(i0: usize, j0: usize) -> i32 {
        2 + Self::is_rot(i0) as i32 + Self::is_rot(j0) as i32
    }
    fn m_exc(i0: usize) -> i32 {
        2 + Self::is_rot(i0) as i32
    }
}

/// How far beyond the scale of its body a database entry may be (see the module doc): a 100 m square
/// barge of 0.1 m draft has pitch restoring about 1e3 rho g l^4, the most extreme hull in sight.
pub const ENTRY_FACTOR: f64 = 1.0e4;

/// The physical bounds of database entries: each mode's body length l = (m / rho)^(1/3), m.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EntryBounds {
    length_m: Vec<f64>,
}

impl EntryBounds {
    /// No bounds (every finite value is accepted).
    pub fn none() -> EntryBounds {
        EntryBounds::default()
    }

    /// The bounds of bodies of these masses (kg), in the system file's order (6 modes each).
    pub fn from_masses(rho: f64, masses_kg: &[f64]) -> EntryBounds {
        EntryBounds {
            length_m: masses_kg
                .iter()
                .flat_map(|m| std::iter::repeat_n((m / rho).cbrt(), 6))
                .collect(),
        }
    }

    /// The length scale of a pair of modes, when bounded.
    fn length(&self, i0: usize, j0: usize) -> Option<f64> {
        let (a, b) = (self.length_m.get(i0)?, self.length_m.get(j0)?);
        let l = (a * b).sqrt();
        (l.is_finite() && l > 0.0).then_some(l)
    }
}

/// The error of an entry beyond its bound.
fn beyond(file: &str, line: usize, what: &str, raw: f64, value: f64, bound: f64, l: f64) -> Error {
    Error::Parse {
        file: file.into(),
        line,
        msg: format!(
            "{what} = {raw:?} makes {value:.3e}, beyond the physical bound {bound:.3e} ({ENTRY_FACTOR:e} times the scale of a body of length (m / rho)^(1/3) = {l:.3} m): a corrupt entry?"
        ),
    }
}

/// Radiation coefficients from a `.1` file, dimensional (kg, kg m, kg m^2; N s/m, ...).
#[derive(Debug, Clone, PartialEq)]
pub struct Radiation {
    /// Finite, positive frequencies, rad/s, ascending.
    pub omega_rad_s: Vec<f64>,
    /// A(w) per frequency, n_modes x n_modes, row = force mode i, column = motion mode j.
    pub added_mass: Vec<DMatrix<f64>>,
    /// B(w) per frequency.
    pub damping: Vec<DMatrix<f64>>,
    /// A at w = 0 (PER = -1), when present.
    pub added_mass_zero: Option<DMatrix<f64>>,
    /// A at w = infinity (PER = 0), when present.
    pub added_mass_inf: Option<DMatrix<f64>>,
}

/// Excitation force from a `.3`-type file, dimensional, per metre of wave amplitude, exp(+i w t).
#[derive(Debug, Clone, PartialEq)]
pub struct Excitation {
    /// Frequencies, rad/s, ascending.
    pub omega_rad_s: Vec<f64>,
    /// Headings, deg, ascending as they appear sorted; the same at every frequency.
    pub heading_deg: Vec<f64>,
    /// X[(iw * n_headings + ib) * n_modes + i].
    pub values: Vec<Complex64>,
    pub n_modes: usize,
}

impl Excitation {
    pub fn at(&self, iw: usize, ib: usize, mode0: usize) -> Complex64 {
        self.values[(iw * self.heading_deg.len() + ib) * self.n_modes + mode0]
    }
}

/// One data line: its number and fields. Skips blank lines and the optional text header.
fn data_lines<R: BufRead>(reader: R, file: &str) -> Result<Vec<(usize, Vec<String>)>> {
    let mut out = Vec::new();
    for (n, line) in reader.lines().enumerate() {
        let lineno = n + 1;
        let line = line.map_err(|e| Error::Parse {
            file: file.to_string(),
            line: lineno,
            msg: format!("cannot read line: {e}"),
        })?;
        let fields: Vec<String> = line.split_whitespace().map(str::to_string).collect();
        if fields.is_empty() {
            continue;
        }
        if lineno == 1 && fields[0].parse::<f64>().is_err() {
            continue; // WAMIT's one-line header
        }
        out.push((lineno, fields));
    }
    if out.is_empty() {
        return Err(Error::Invalid {
            file: file.to_string(),
            msg: "no data lines".into(),
        });
    }
    Ok(out)
}

fn field_f64(file: &str, line: usize, fields: &[String], col: usize, what: &str) -> Result<f64> {
    let s = &fields[col];
    let v: f64 = s.parse().map_err(|_| Error::Parse {
        file: file.into(),
        line,
        msg: format!("column {} ({what}): expected a number, found `{s}`", col + 1),
    })?;
    if !v.is_finite() {
        return Err(Error::Parse {
            file: file.into(),
            line,
            msg: format!("column {} ({what}): not a finite number: `{s}`", col + 1),
        });
    }
    Ok(v)
}

fn field_mode(file: &str, line: usize, fields: &[String], col: usize, n_modes: usize) -> Result<usize> {
    let s = &fields[col];
    let v: i64 = s.parse().map_err(|_| Error::Parse {
        file: file.into(),
        line,
        msg: format!("column {}: expected a mode number 1..{n_modes}, found `{s}`", col + 1),
    })?;
    if v < 1 || v as usize > n_modes {
        return Err(Error::Parse {
            file: file.into(),
            line,
            msg: format!(
                "column {}: mode {v} is outside 1..{n_modes} (6 per body, {} bodies in the system file)",
                col + 1,
                n_modes / 6
            ),
        });
    }
    Ok(v as usize - 1)
}

fn check_count(file: &str, line: usize, fields: &[String], allowed: &[usize], layout: &str) -> Result<()> {
    if allowed.contains(&fields.len()) {
        Ok(())
    } else {
        Err(Error::Parse {
            file: file.into(),
            line,
            msg: format!(
                "expected `{layout}` ({} fields), found {} fields",
                allowed_str(allowed),
                fields.len()
            ),
        })
    }
}

fn allowed_str(allowed: &[usize]) -> String {
    allowed.iter().map(|a| a.to_string()).collect::<Vec<_>>().join(" or ")
}

/// Period (s) to frequency (rad/s): PER = -1 is 0, PER = 0 is infinity.
fn per_to_omega(file: &str, line: usize, per: f64) -> Result<f64> {
    if per == -1.0 {
        Ok(0.0)
    } else if per == 0.0 {
        Ok(f64::INFINITY)
    } else if per > 0.0 {
        Ok(2.0 * PI / per)
    } else {
        Err(Error::Parse {
            file: file.into(),
            line,
            msg: format!("period {per}: expected a positive period, 0 (infinite frequency) or -1 (zero frequency)"),
        })
    }
}

/// Rows of one period of a `.1` file: omega, A, B, which (i, j) were seen, first line.
type RadiationRows = (f64, DMatrix<f64>, DMatrix<f64>, Vec<bool>, usize);
/// Rows of one period of a `.3` file: omega, first line, heading bits -> (heading, per-mode values).
type ExcitationRows = (f64, usize, BTreeMap<u64, (f64, Vec<Option<Complex64>>)>);

/// Reads a `.1` file for `n_modes` = 6N modes.
pub fn read_radiation<R: BufRead>(reader: R, file: &str, n_modes: usize, s: Scaling) -> Result<Radiation> {
    read_radiation_bounded(reader, file, n_modes, s, &EntryBounds::none())
}

/// [`read_radiation`] with every entry within `bounds`.
pub fn read_radiation_bounded<R: BufRead>(
    reader: R,
    file: &str,
    n_modes: usize,
    s: Scaling,
    bounds: &EntryBounds,
) -> Result<Radiation> {
    let by_per = radiation_rows(reader, file, n_modes, s, bounds)?;
    radiation_complete(file, n_modes, &by_per)?;
    let mut rad = Radiation {
        omega_rad_s: vec![],
        added_mass: vec![],
        damping: vec![],
        added_mass_zero: None,
        added_mass_inf: None,
    };
    let mut rows: Vec<_> = by_per.into_values().collect();
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (omega, a, b, _, _) in rows {
        if omega == 0.0 {
            rad.added_mass_zero = Some(a);
        } else if omega.is_infinite() {
            rad.added_mass_inf = Some(a);
        } else {
            rad.omega_rad_s.push(omega);
            rad.added_mass.push(a);
            rad.damping.push(b);
        }
    }
    if rad.omega_rad_s.is_empty() {
        return Err(Error::Invalid {
            file: file.into(),
            msg: "no finite frequency in the file (only PER = -1 / 0 rows)".into(),
        });
    }
    Ok(rad)
}

/// Reads a `.3`-type file (`.3`, `.2`, `.3fk`, `.3sc`) for `n_modes` modes.
pub fn read_excitation<R: BufRead>(reader: R, file: &str, n_modes: usize, s: Scaling) -> Result<Excitation> {
    read_excitation_bounded(reader, file, n_modes, s, &EntryBounds::none())
}

/// [`read_excitation`] with every entry within `bounds`.
pub fn read_excitation_bounded<R: BufRead>(
    reader: R,
    file: &str,
    n_modes: usize,
    s: Scaling,
    bounds: &EntryBounds,
) -> Result<Excitation> {
    let by_per = excitation_rows(reader, file, n_modes, s, bounds)?;
    excitation_complete(file, n_modes, &by_per)?;
    let mut pers: Vec<_> = by_per.into_values().collect();
    pers.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut headings: Option<Vec<f64>> = None;
    let mut exc = Excitation {
        omega_rad_s: vec![],
        heading_deg: vec![],
        values: vec![],
        n_modes,
    };
    for (omega, first_line, hmap) in pers {
        let mut hs: Vec<(f64, Vec<Option<Complex64>>)> = hmap.into_values().collect();
        hs.sort_by(|a, b| a.0.total_cmp(&b.0));
        let these: Vec<f64> = hs.iter().map(|h| h.0).collect();
        match &headings {
            None => headings = Some(these.clone()),
            Some(h0) if *h0 != these => {
                return Err(Error::Invalid {
                    file: file.into(),
                    msg: format!(
                        "period {:.6} s (first at line {first_line}) has headings {these:?} deg, but the first period has {h0:?}: every period must have the same headings",
                        2.0 * PI / omega
                    ),
                });
            }
            _ => {}
        }
        exc.omega_rad_s.push(omega);
        for (_, vals) in hs {
            // modes absent from the file are zero (WAMIT omits modes it did not solve)
            exc.values.extend(vals.into_iter().map(|v| v.unwrap_or_default()));
        }
    }
    exc.heading_deg = headings.unwrap_or_default();
    Ok(exc)
}

/// The `.1` file's rows by period, each entry scaled to SI and checked against `bounds`.
fn radiation_rows<R: BufRead>(
    reader: R,
    file: &str,
    n_modes: usize,
    s: Scaling,
    bounds: &EntryBounds,
) -> Result<BTreeMap<u64, RadiationRows>> {
    // key: period bits (the same period prints identically on every row of a frequency)
    let mut by_per: BTreeMap<u64, RadiationRows> = BTreeMap::new();
    for (line, f) in data_lines(reader, file)? {
        check_count(file, line, &f, &[4, 5], "PER I J Abar [Bbar]")?;
        let per = field_f64(file, line, &f, 0, "PER")?;
        let omega = per_to_omega(file, line, per)?;
        let i = field_mode(file, line, &f, 1, n_modes)?;
        let j = field_mode(file, line, &f, 2, n_modes)?;
        let abar = field_f64(file, line, &f, 3, "Abar")?;
        let finite = omega.is_finite() && omega > 0.0;
        if finite && f.len() != 5 {
            return Err(Error::Parse {
                file: file.into(),
                line,
                msg: format!("period {per} s: expected `PER I J Abar Bbar` (5 fields), found 4"),
            });
        }
        let bbar = if f.len() == 5 {
            field_f64(file, line, &f, 4, "Bbar")?
        } else {
            0.0
        };
        let entry = by_per.entry(per.to_bits()).or_insert_with(|| {
            (
                omega,
                DMatrix::zeros(n_modes, n_modes),
                DMatrix::zeros(n_modes, n_modes),
                vec![false; n_modes * n_modes],
                line,
            )
        });
        if entry.3[i * n_modes + j] {
            return Err(Error::Parse {
                file: file.into(),
                line,
                msg: format!("duplicate entry for period {per} s, modes {} {}", i + 1, j + 1),
            });
        }
        entry.3[i * n_modes + j] = true;
        let k = Scaling::k_rad(i, j);
        entry.1[(i, j)] = s.rho * s.ulen.powi(k) * abar;
        if finite {
            entry.2[(i, j)] = s.rho * omega * s.ulen.powi(k) * bbar;
        }
        if let Some(l) = bounds.length(i, j) {
            let a_max = ENTRY_FACTOR * s.rho * l.powi(k);
            if entry.1[(i, j)].abs() > a_max {
                return Err(beyond(file, line, "column 4 (Abar)", abar, entry.1[(i, j)], a_max, l));
            }
            let b_max = a_max * omega.max((s.g / l).sqrt());
            if finite && entry.2[(i, j)].abs() > b_max {
                return Err(beyond(file, line, "column 5 (Bbar)", bbar, entry.2[(i, j)], b_max, l));
            }
        }
    }
    Ok(by_per)
}

/// Every positive period of a `.1` file lists the pairs the others list (else the file was cut short).
fn radiation_complete(file: &str, n_modes: usize, by_per: &BTreeMap<u64, RadiationRows>) -> Result<()> {
    // every positive period lists the pairs the others list
    let mut union = vec![false; n_modes * n_modes];
    for (omega, _, _, seen, _) in by_per.values() {
        if omega.is_finite() && *omega > 0.0 {
            union.iter_mut().zip(seen).for_each(|(u, s)| *u |= *s);
        }
    }
    let mut periods: Vec<(&u64, &RadiationRows)> = by_per.iter().collect();
    periods.sort_by_key(|(_, r)| r.4);
    for (per, (omega, _, _, seen, first)) in periods {
        if !(omega.is_finite() && *omega > 0.0) {
            continue;
        }
        if let Some(p) = (0..n_modes * n_modes).find(|&p| union[p] && !seen[p]) {
            return Err(Error::Invalid {
                file: file.into(),
                msg: format!(
                    "period {} s (first at line {first}) has no entry for modes {} {}, which other periods have: is the file cut short?",
                    f64::from_bits(*per),
                    p / n_modes + 1,
                    p % n_modes + 1
                ),
            });
        }
    }
    Ok(())
}

/// The `.3` file's rows by period and heading, each entry scaled to SI and checked against `bounds`.
fn excitation_rows<R: BufRead>(
    reader: R,
    file: &str,
    n_modes: usize,
    s: Scaling,
    bounds: &EntryBounds,
) -> Result<BTreeMap<u64, ExcitationRows>> {
    // period bits -> heading bits -> values
    let mut by_per: BTreeMap<u64, ExcitationRows> = BTreeMap::new();
    for (line, f) in data_lines(reader, file)? {
        check_count(file, line, &f, &[7], "PER BETA I |X| phase Re Im")?;
        let per = field_f64(file, line, &f, 0, "PER")?;
        let omega = per_to_omega(file, line, per)?;
        if !(omega.is_finite() && omega > 0.0) {
            return Err(Error::Parse {
                file: file.into(),
                line,
                msg: format!("period {per}: excitation needs a finite, positive period"),
            });
        }
        let beta = field_f64(file, line, &f, 1, "BETA (deg)")?;
        let i = field_mode(file, line, &f, 2, n_modes)?;
        let _mag = field_f64(file, line, &f, 3, "|X|")?;
        let _ph = field_f64(file, line, &f, 4, "phase (deg)")?;
        let re = field_f64(file, line, &f, 5, "Re X")?;
        let im = field_f64(file, line, &f, 6, "Im X")?;
        let scale = s.rho * s.g * s.ulen.powi(Scaling::m_exc(i));
        let per_entry = by_per
            .entry(per.to_bits())
            .or_insert_with(|| (omega, line, BTreeMap::new()));
        let h = per_entry
            .2
            .entry(beta.to_bits())
            .or_insert_with(|| (beta, vec![None; n_modes]));
        if h.1[i].is_some() {
            return Err(Error::Parse {
                file: file.into(),
                line,
                msg: format!("duplicate entry for period {per} s, heading {beta} deg, mode {}", i + 1),
            });
        }
        let x = Complex64::new(re, im) * scale;
        if let Some(l) = bounds.length(i, i) {
            let x_max = ENTRY_FACTOR * s.rho * s.g * l.powi(Scaling::m_exc(i));
            if x.norm() > x_max {
                let raw = if re.abs() >= im.abs() { re } else { im };
                let what = if re.abs() >= im.abs() {
                    "column 6 (Re X)"
                } else {
                    "column 7 (Im X)"
                };
                return Err(beyond(file, line, what, raw, x.norm(), x_max, l));
            }
        }
        h.1[i] = Some(x);
    }
    Ok(by_per)
}

/// Every (period, heading) of a `.3` file lists the modes the others list (else the file was cut
/// short).
fn excitation_complete(file: &str, n_modes: usize, by_per: &BTreeMap<u64, ExcitationRows>) -> Result<()> {
    // every (period, heading) lists the modes the others list
    let mut union = vec![false; n_modes];
    for (_, _, hmap) in by_per.values() {
        for (_, vals) in hmap.values() {
            union.iter_mut().zip(vals).for_each(|(u, v)| *u |= v.is_some());
        }
    }
    let mut periods: Vec<(&u64, &ExcitationRows)> = by_per.iter().collect();
    periods.sort_by_key(|(_, r)| r.1);
    for (per, (_, first, hmap)) in periods {
        for (beta, vals) in hmap.values() {
            if let Some(m) = (0..n_modes).find(|&m| union[m] && vals[m].is_none()) {
                return Err(Error::Invalid {
                    file: file.into(),
                    msg: format!(
                        "period {} s (first at line {first}), heading {beta} deg has no entry for mode {}, which other periods and headings have: is the file cut short?",
                        f64::from_bits(*per),
                        m + 1
                    ),
                });
            }
        }
    }
    Ok(())
}

/// Reads a `.hst` file: the linear restoring matrix (N/m, N, N m/rad ...).
pub fn read_hydrostatics<R: BufRead>(reader: R, file: &str, n_modes: usize, s: Scaling) -> Result<DMatrix<f64>> {
    read_hydrostatics_bounded(reader, file, n_modes, s, &EntryBounds::none())
}

/// [`read_hydrostatics`] with every entry within `bounds`.
pub fn read_hydrostatics_bounded<R: BufRead>(
    reader: R,
    file: &str,
    n_modes: usize,
    s: Scaling,
    bounds: &EntryBounds,
) -> Result<DMatrix<f64>> {
    let mut c = DMatrix::zeros(n_modes, n_modes);
    let mut seen = vec![false; n_modes * n_modes];
    for (line, f) in data_lines(reader, file)? {
        check_count(file, line, &f, &[3], "I J Cbar")?;
        let i = field_mode(file, line, &f, 0, n_modes)?;
        let j = field_mode(file, line, &f, 1, n_modes)?;
        let cbar = field_f64(file, line, &f, 2, "Cbar")?;
        if seen[i * n_modes + j] {
            return Err(Error::Parse {
                file: file.into(),
                line,
                msg: format!("duplicate entry for modes {} {}", i + 1, j + 1),
            });
        }
        seen[i * n_modes + j] = true;
        c[(i, j)] = s.rho * s.g * s.ulen.powi(Scaling::k_hst(i, j)) * cbar;
        if let Some(l) = bounds.length(i, j) {
            let c_max = ENTRY_FACTOR * s.rho * s.g * l.powi(Scaling::k_hst(i, j));
            if c[(i, j)].abs() > c_max {
                return Err(beyond(file, line, "column 3 (Cbar)", cbar, c[(i, j)], c_max, l));
            }
        }
    }
    Ok(c)
}

/// Largest |X_a + X_b - X_total| over the largest |X_total|, when the three share frequencies and
/// headings (a `.3fk` + `.3sc` pair against `.3`).
pub fn sum_mismatch(a: &Excitation, b: &Excitation, total: &Excitation) -> Option<f64> {
    let same = |x: &Excitation| x.omega_rad_s == total.omega_rad_s && x.heading_deg == total.heading_deg;
    if !(same(a) && same(b)) {
        return None;
    }
    let scale = total.values.iter().map(|v| v.norm()).fold(0.0, f64::max);
    let worst = a
        .values
        .iter()
        .zip(&b.values)
        .zip(&total.values)
        .map(|((x, y), t)| (x + y - t).norm())
        .fold(0.0, f64::max);
    Some(if scale > 0.0 { worst / scale } else { worst })
}

#[cfg(test)]
mod tests {
    use super::*;

    const S: Scaling = Scaling {
        rho: 1000.0,
        g: 9.81,
        ulen: 2.0,
    };

    #[test]
    fn radiation_scaling_order_and_limits() {
        let text = " WAMIT header line\n\
            6.0 3 3 2.0 4.0\n\
            6.0 4 4 1.0 1.0\n\
            6.0 3 5 1.0 0.5\n\
            -1.0 3 3 5.0\n\
            0.0 3 3 1.0\n\
            12.0 3 3 3.0 1.0\n\
            12.0 4 4 1.0 1.0\n\
            12.0 3 5 1.0 0.5\n";
        let r = read_radiation(text.as_bytes(), "t.1", 6, S).unwrap();
        let w1 = 2.0 * PI / 12.0;
        assert_eq!(r.omega_rad_s.len(), 2);
        assert!((r.omega_rad_s[0] - w1).abs() < 1e-12, "sorted ascending");
        assert_eq!(r.added_mass[0][(2, 2)], 1000.0 * 8.0 * 3.0);
        assert!((r.damping[0][(2, 2)] - 1000.0 * w1 * 8.0 * 1.0).abs() < 1e-9);
        assert_eq!(r.added_mass[0][(3, 3)], 1000.0 * 32.0 * 1.0, "rotation-rotation: L^5");
        assert_eq!(r.added_mass[0][(2, 4)], 1000.0 * 16.0 * 1.0, "mixed: L^4");
        assert_eq!(r.added_mass[0][(0, 0)], 0.0, "absent pairs are zero");
        assert_eq!(r.added_mass_zero.as_ref().unwrap()[(2, 2)], 5000.0 * 8.0);
        assert_eq!(r.added_mass_inf.as_ref().unwrap()[(2, 2)], 1000.0 * 8.0);
    }

    #[test]
    fn excitation_scaling_and_headings() {
        let text = "10.0 0.0 3 1 0 1.0 0.5\n10.0 90.0 3 1 0 2.0 0.0\n10.0 0.0 4 1 0 0.0 1.0\n\
                    10.0 90.0 4 0 0 0.0 0.0\n5.0 90.0 3 1 0 1.0 0.0\n5.0 0.0 3 1 0 1.0 0.0\n\
                    5.0 90.0 4 1 0 1.0 0.0\n5.0 0.0 4 1 0 1.0 0.0\n";
        let x = read_excitation(text.as_bytes(), "t.3", 6, S).unwrap();
        assert_eq!(x.heading_deg, vec![0.0, 90.0]);
        assert_eq!(x.omega_rad_s.len(), 2);
        // 10 s is the lower frequency: index 0
        assert_eq!(x.at(0, 0, 2), Complex64::new(1.0, 0.5) * 1000.0 * 9.81 * 4.0);
        assert_eq!(x.at(0, 0, 3), Complex64::new(0.0, 1.0) * 1000.0 * 9.81 * 8.0);
        assert_eq!(x.at(0, 1, 3), Complex64::default());
    }

    #[test]
    fn excitation_heading_mismatch_is_an_error() {
        let text = "10.0 0.0 3 1 0 1.0 0.5\n5.0 90.0 3 1 0 1.0 0.0\n";
        let e = read_excitation(text.as_bytes(), "t.3", 6, S).unwrap_err();
        assert!(e.to_string().contains("same headings"), "{e}");
    }

    #[test]
    fn bad_lines_name_file_line_and_field() {
        let cases: [(&str, &str); 6] = [
            ("6.0 3 3\n", "t.1:1: expected `PER I J Abar [Bbar]`"),
            (
                "6.0 3 3 x 1.0\n",
                "t.1:1: column 4 (Abar): expected a number, found `x`",
            ),
            ("6.0 3 3 NaN 1.0\n", "t.1:1: column 4 (Abar): not a finite number"),
            ("6.0 3 13 1.0 1.0\n", "t.1:1: column 3: mode 13 is outside 1..12"),
            ("6.0 3 3 1.0 1.0\n6.0 3 3 1.0 1.0\n", "t.1:2: duplicate entry"),
            ("6.0 3 3 1.0\n", "t.1:1: period 6 s: expected `PER I J Abar Bbar`"),
        ];
        for (text, want) in cases {
            let e = read_radiation(text.as_bytes(), "t.1", 12, S).unwrap_err();
            assert!(e.to_string().starts_with(want), "`{e}` does not start with `{want}`");
        }
        let e = read_hydrostatics("1 1\n".as_bytes(), "t.hst", 6, S).unwrap_err();
        assert!(e.to_string().starts_with("t.hst:1: expected `I J Cbar`"), "{e}");
        let e = read_hydrostatics("".as_bytes(), "t.hst", 6, S).unwrap_err();
        assert!(e.to_string().contains("no data lines"), "{e}");
        let e = read_excitation("-2.0 0 1 1 0 1 0\n".as_bytes(), "t.3", 6, S).unwrap_err();
        assert!(e.to_string().contains("positive period"), "{e}");
    }

    #[test]
    fn a_period_missing_pairs_is_an_error() {
        let text = "6.0 3 3 1.0 1.0\n6.0 4 4 1.0 1.0\n12.0 3 3 1.0 1.0\n-1.0 3 3 1.0\n";
        let e = read_radiation(text.as_bytes(), "t.1", 6, S).unwrap_err().to_string();
        assert!(
            e.contains("period 12 s (first at line 3) has no entry for modes 4 4"),
            "{e}"
        );
        let text = "10.0 0.0 3 1 0 1.0 0.5\n10.0 0.0 4 1 0 1.0 0.5\n5.0 0.0 3 1 0 1.0 0.0\n";
        let e = read_excitation(text.as_bytes(), "t.3", 6, S).unwrap_err().to_string();
        assert!(
            e.contains("period 5 s (first at line 3), heading 0 deg has no entry for mode 4"),
            "{e}"
        );
    }

    #[test]
    fn entries_beyond_the_body_scale_name_file_and_line() {
        // a 1000 t body: l = 10 m at rho = 1000
        let b = EntryBounds::from_masses(1000.0, &[1.0e6]);
        let ok = "6.0 3 3 1.0 1.0\n";
        read_radiation_bounded(ok.as_bytes(), "t.1", 6, S, &b).unwrap();
        let e = read_radiation_bounded("6.0 3 3 1.0 1.0\n12.0 3 3 1e300 1.0\n".as_bytes(), "t.1", 6, S, &b)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.1:2: column 4 (Abar) = 1e300"), "{e}");
        let e = read_excitation_bounded("10.0 0.0 3 1 0 1e30 0.0\n".as_bytes(), "t.3", 6, S, &b)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.3:1: column 6 (Re X)"), "{e}");
        let e = read_hydrostatics_bounded("3 3 1e40\n".as_bytes(), "t.hst", 6, S, &b)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.hst:1: column 3 (Cbar)"), "{e}");
    }

    #[test]
    fn hydrostatics_scaling() {
        let c = read_hydrostatics("3 3 2.0\n4 4 1.0\n3 5 1.0\n".as_bytes(), "t.hst", 6, S).unwrap();
        assert_eq!(c[(2, 2)], 1000.0 * 9.81 * 4.0 * 2.0);
        assert_eq!(c[(3, 3)], 1000.0 * 9.81 * 16.0);
        assert_eq!(c[(2, 4)], 1000.0 * 9.81 * 8.0);
    }
}
