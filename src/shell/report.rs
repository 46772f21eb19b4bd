//! `shipcast db check`'s report: what a system file and its database hold, what the checks found
//! ([`crate::radiation::check`]), the state-space model the time domain runs, each radiation model's floor
//! against the database's frequency domain, and the warnings. [`DbCheck::new`] computes it from a loaded
//! system; its `Display` is the text `db check` prints (the binary adds the total time).
//!
//! Shell-side library module: it reads no file (the caller loads the system) and times only the
//! state-space fit, for the report.

use crate::hydro::external::ConnectionKind;
use crate::hydro::system::{AInfSource, Passivity, TailChoice};
use crate::hydro::{Dof, VesselSystem, mode_label};
use crate::radiation::check::{self, CheckReport};
use crate::radiation::irf::{self, PairError};
use crate::radiation::memory;
use crate::radiation::statespace::ModalModel;
use crate::rao::FrequencySolver;
use crate::rom::{RadiationMethod, RomOptions, TimeModel, floor};
use crate::shell::files::Loaded;
use std::f64::consts::PI;
use std::fmt;
use std::path::Path;

/// `db check` warns when a radiation model's floor is off the database's frequency domain by more than
/// this fraction of a curve's peak: the bar for the time domain against the frequency domain.
pub const FLOOR_WARNING: f64 = 0.01;
/// `db check` warns when the database's A or B had to be repaired (made symmetric, or B made positive
/// semi-definite) by more than this fraction of a coupling's scale: beyond 1 % a sensitive RAO (the
/// pair's beam-sea lighter yaw) moves by several per cent, a database problem.
pub const REPAIR_WARNING: f64 = 0.01;

/// The pairs of the Kramers-Kronig table shown without `--all-pairs`.
const PAIRS_SHOWN: usize = 8;

/// `db check`'s report of one system (see the module doc).
pub struct DbCheck<'a> {
    loaded: &'a Loaded,
    path: &'a Path,
    all_pairs: bool,
    check: CheckReport,
    state_space: StateSpace,
    floor_omegas: Vec<f64>,
    floors: Vec<(&'static str, FloorLine)>,
    warnings: Vec<String>,
}

/// The state-space model as `db check` reports it.
enum StateSpace {
    Fitted(Box<StateSpaceFit>),
    NotBuilt,
    NoFit(String),
}

/// The numbers of the state-space fit's line and its zero-frequency damping.
struct StateSpaceFit {
    fit_pairs: usize,
    fit_error: f64,
    full_order: usize,
    real_order: usize,
    modes: usize,
    next_hankel: f64,
    first_hankel: f64,
    fitted_s: f64,
    damping_error: f64,
    added_mass_error: f64,
    cover: f64,
    drift: DriftDrag,
}

/// What `db check` says of the state-space model's damping at zero frequency: the largest over a DOF's
/// peak damping, and the shortest time constant (M + A_inf)_ii / K_ii(0) of a DOF without restoring
/// (a steady drift, which radiation does not damp, slowed down by the model).
struct DriftDrag {
    /// (K_ii(0) in per cent of the DOF's peak damping, the DOF, K_ii(0) SI).
    largest: Option<(f64, String, f64)>,
    /// (time constant s, the DOF).
    free: Option<(f64, String)>,
}

/// One radiation model's floor line.
enum FloorLine {
    /// The worst curve error: fraction of the curve's peak, state, heading index, frequency index.
    Worst {
        fraction: f64,
        state: usize,
        heading: usize,
        omega: usize,
    },
    NoResponse,
    NoFrequencyDomain(String),
    Unavailable(String),
}

impl<'a> DbCheck<'a> {
    /// Runs every check on `loaded` (read from `path`); `all_pairs` shows the whole Kramers-Kronig table.
    pub fn new(loaded: &'a Loaded, path: &'a Path, all_pairs: bool) -> DbCheck<'a> {
        let sys = &loaded.system;
        let db = &sys.db;
        let check = check::check(sys);
        let mut warnings = sys.warnings.clone();
        // the models the time domain runs, on the system file's IRF grid: the state-space fit's report,
        // then each method's floor against the database's frequency domain
        let t_fit = std::time::Instant::now();
        let model_opts = |radiation| RomOptions {
            dt_s: sys.spec.irf.dt_s,
            radiation,
            ..RomOptions::default()
        };
        let ss_model = TimeModel::new(sys, model_opts(RadiationMethod::StateSpace));
        let state_space = match &ss_model {
            Ok(m) => match m.kernel.modal_model() {
                Some(ss) => StateSpace::Fitted(Box::new(state_space_fit(sys, m, ss, t_fit))),
                None => StateSpace::NotBuilt,
            },
            Err(e) => StateSpace::NoFit(e.to_string()),
        };
        let (lo, hi) = db.omega_range();
        let omegas: Vec<f64> = db
            .omega_rad_s
            .iter()
            .copied()
            .filter(|x| *x >= lo && *x <= hi)
            .collect();
        let fd = FrequencySolver::new(sys).table(&omegas, &db.heading_rad);
        let mut floors = vec![];
        // where the database's damping is indefinite, the convolution's floor with the other choice of
        // `irf.passivity` too (the state space's fit is too slow to make twice)
        let mut models = vec![
            (
                "convolution",
                TimeModel::new(sys, model_opts(RadiationMethod::Convolution)),
                true,
            ),
            ("state space", ss_model, true),
        ];
        if check.passivity_repair.frequencies > 0 {
            let (choice, name) = match sys.spec.irf.passivity {
                Passivity::Project => (Passivity::None, "convolution, irf.passivity = \"none\""),
                Passivity::None => (Passivity::Project, "convolution, irf.passivity = \"project\""),
            };
            let mut other = sys.clone();
            other.spec.irf.passivity = choice;
            models.push((
                name,
                TimeModel::new(&other, model_opts(RadiationMethod::Convolution)),
                false,
            ));
        }
        for (name, model, warn) in models {
            let floor = model.and_then(|m| floor::implied_table(&m, &omegas, &db.heading_rad));
            let line = match (&fd, floor) {
                (Ok(fd), Ok(floor)) => match floor::worst_curve_error(&floor, fd) {
                    Some(e) => {
                        if warn && e.fraction > FLOOR_WARNING {
                            warnings.push(floor_warning(sys, name, e.fraction, e.state, omegas[e.omega]));
                        }
                        FloorLine::Worst {
                            fraction: e.fraction,
                            state: e.state,
                            heading: e.heading,
                            omega: e.omega,
                        }
                    }
                    None => FloorLine::NoResponse,
                },
                (Err(e), _) => FloorLine::NoFrequencyDomain(e.to_string()),
                (_, Err(e)) => FloorLine::Unavailable(e.to_string()),
            };
            floors.push((name, line));
        }
        warnings.extend(database_warnings(sys, &check));
        DbCheck {
            loaded,
            path,
            all_pairs,
            check,
            state_space,
            floor_omegas: omegas,
            floors,
            warnings,
        }
    }

    /// The warnings, in the order the report prints them.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }
}

/// The state-space line's numbers of the model `m` with radiation `ss`, its fit timed from `t_fit`.
fn state_space_fit(sys: &VesselSystem, m: &TimeModel, ss: &ModalModel, t_fit: std::time::Instant) -> StateSpaceFit {
    let mem = memory::state_space_memory(sys, memory::memory_duration_s(sys));
    let (eb, ea) = check::state_space_errors(sys, ss, &memory::model_a_inf(sys, &mem.irf), &mem.tail);
    let n_hsv = ss.hankel.len().min(ss.real_order() + 1);
    StateSpaceFit {
        fit_pairs: ss.fit_pairs,
        fit_error: ss.fit_error,
        full_order: ss.full_order,
        real_order: ss.real_order(),
        modes: ss.modes(),
        next_hankel: ss.hankel.get(n_hsv.saturating_sub(1)).copied().unwrap_or(0.0),
        first_hankel: ss.hankel.first().copied().unwrap_or(0.0),
        fitted_s: t_fit.elapsed().as_secs_f64(),
        damping_error: eb,
        added_mass_error: ea,
        cover: ss.cover,
        drift: drift_drag(sys, m, ss),
    }
}

fn drift_drag(sys: &VesselSystem, m: &TimeModel, ss: &ModalModel) -> DriftDrag {
    let k0 = ss.zero_frequency_damping();
    let largest = (0..k0.len()).max_by(|&a, &b| (k0[a] / ss.scale[a]).abs().total_cmp(&(k0[b] / ss.scale[b]).abs()));
    let free = (0..k0.len())
        .filter(|&i| m.stiffness_linearized[(i, i)] == 0.0 && k0[i] > 0.0)
        .map(|i| (i, m.mass[(i, i)] / k0[i]))
        .min_by(|a, b| a.1.total_cmp(&b.1));
    DriftDrag {
        largest: largest.map(|i| (100.0 * k0[i] / ss.scale[i], mode_label(sys, m.active[i]), k0[i])),
        free: free.map(|(i, t)| (t, mode_label(sys, m.active[i]))),
    }
}

fn floor_warning(sys: &VesselSystem, name: &str, fraction: f64, state: usize, omega_rad_s: f64) -> String {
    let why = if name == "convolution" {
        "the database's A, B and A_inf are not Kramers-Kronig consistent enough there (see the table above: frequency resolution, range, panels)"
    } else {
        "the fit's error adds to the database's inconsistency (compare the convolution's floor)"
    };
    format!(
        "the {name} model's floor is {:.2} % of a curve's peak off the database's frequency domain ({} at {:.4} rad/s): no time step brings the time domain closer; {why}",
        100.0 * fraction,
        mode_label(sys, state),
        omega_rad_s
    )
}

/// The warnings on the database itself: negative damping, asymmetry and the passivity repair beyond
/// [`REPAIR_WARNING`].
fn database_warnings(sys: &VesselSystem, report: &CheckReport) -> Vec<String> {
    let db = &sys.db;
    let w = &db.omega_rad_s;
    let mut warnings = vec![];
    for (i, ws) in &report.negative_damping {
        let peak = db.damping.iter().map(|b| b[(*i, *i)]).fold(0.0, f64::max);
        let (k, low) = db
            .damping
            .iter()
            .enumerate()
            .map(|(k, b)| (k, b[(*i, *i)]))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((0, 0.0));
        warnings.push(format!(
            "negative diagonal damping B({0},{0}) ({1}) at {2} frequencies in {3:.4}..{4:.4} rad/s, lowest {5:.4e} at {6:.4} rad/s ({7:.3} % of its peak): irregular frequencies, panels too coarse or numerical noise",
            i + 1,
            mode_label(sys, *i),
            ws.len(),
            ws[0],
            ws[ws.len() - 1],
            low,
            w[k],
            100.0 * low.abs() / peak.max(f64::MIN_POSITIVE)
        ));
    }
    // a coupling whose two BEM estimates differ by more than 1 % of its scale moves a sensitive RAO
    let asym = report.asymmetry_added_mass.max(report.asymmetry_damping);
    if asym > REPAIR_WARNING {
        warnings.push(format!(
            "A(w) or B(w) unsymmetric by up to {:.2} % of sqrt(X_ii X_jj): the two BEM estimates of a coupling disagree (panels too coarse?); a passive time-domain model follows only the symmetric part (tools/bem/make_db.py writes it)",
            100.0 * asym
        ));
    }
    let repair = &report.passivity_repair;
    if repair.largest > REPAIR_WARNING {
        warnings.push(format!(
            "B(w) far from positive semi-definite (up to {:.2} % of sqrt(peak B_ii peak B_jj) removed at {:.4} rad/s): the BEM radiates negative power there (irregular frequencies, panels too coarse?); the time-domain models see the repaired damping, the frequency domain the database's",
            100.0 * repair.largest,
            w[repair.at]
        ));
    }
    warnings
}

impl fmt::Display for DbCheck<'_> {
    fn fmt(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.write_system(out)?;
        external_summary(out, &self.loaded.system)?;
        self.write_radiation(out)?;
        self.write_kramers_kronig(out)?;
        self.write_models(out)?;
        for n in &self.loaded.notes {
            writeln!(out, "note: {n}")?;
        }
        if self.warnings.is_empty() {
            writeln!(out, "warnings: none")?;
        } else {
            writeln!(out, "warnings: {}", self.warnings.len())?;
            for wmsg in &self.warnings {
                writeln!(out, "  WARNING: {wmsg}")?;
            }
        }
        Ok(())
    }
}

impl DbCheck<'_> {
    /// The files read, the constants, the bodies and the database's grids.
    fn write_system(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sys = &self.loaded.system;
        let db = &sys.db;
        writeln!(out, "system: {}", self.path.display())?;
        for f in &self.loaded.files[1..] {
            writeln!(out, "  read {}", f.display())?;
        }
        let depth = sys
            .spec
            .water_depth_m
            .map(|d| format!("{d} m"))
            .unwrap_or("infinite".into());
        writeln!(
            out,
            "rho = {} kg/m^3, g = {} m/s^2, ULEN = {} m, water depth {depth}, hydrodynamic coupling {}",
            sys.spec.rho_kg_m3,
            sys.spec.g_m_s2,
            sys.spec.ulen_m,
            if sys.spec.hydrodynamic_coupling {
                "on"
            } else {
                "off (own 6x6 blocks only)"
            }
        )?;
        if !sys.speed_dbs.is_empty() {
            let speeds: Vec<String> = std::iter::once(0.0)
                .chain(sys.speed_dbs.iter().map(|(u, _)| *u))
                .map(|u| format!("{u}"))
                .collect();
            writeln!(
                out,
                "databases at forward speeds {} m/s: A and B (against the encounter frequency) quadratic in the speed, X linear; the checks below are of the zero-speed one",
                speeds.join(", ")
            )?;
        }
        writeln!(out, "bodies: {} ({} modes)", sys.spec.bodies.len(), sys.n_modes())?;
        for (k, b) in sys.spec.bodies.iter().enumerate() {
            let active: Vec<&str> = (0..6).filter(|j| b.active[*j]).map(|j| Dof::ALL[j].name()).collect();
            writeln!(
                out,
                "  {k}: {} at ({:.3}, {:.3}, {:.3}) m, mass {:.6e} kg, modes {}..{}, active: {}",
                b.name,
                b.position_m.x,
                b.position_m.y,
                b.position_m.z,
                b.mass[(0, 0)],
                6 * k + 1,
                6 * k + 6,
                active.join(" ")
            )?;
        }
        let w = &db.omega_rad_s;
        let min_dw = w.windows(2).map(|p| p[1] - p[0]).fold(f64::INFINITY, f64::min);
        let max_dw = w.windows(2).map(|p| p[1] - p[0]).fold(0.0, f64::max);
        let present = |x: bool| if x { "present" } else { "absent" };
        writeln!(
            out,
            "radiation: {} frequencies {:.4}..{:.4} rad/s (spacing {:.4}..{:.4} rad/s), A(0) {}, A_inf {}",
            w.len(),
            w[0],
            w[w.len() - 1],
            min_dw,
            max_dw,
            present(db.added_mass_zero.is_some()),
            present(db.added_mass_inf.is_some()),
        )?;
        let hd: Vec<String> = db
            .heading_rad
            .iter()
            .map(|h| format!("{:.1}", h.to_degrees()))
            .collect();
        writeln!(
            out,
            "excitation: {} frequencies {:.4}..{:.4} rad/s, {} headings [{}] deg{}",
            db.exc_omega_rad_s.len(),
            db.exc_omega_rad_s[0],
            db.exc_omega_rad_s[db.exc_omega_rad_s.len() - 1],
            db.heading_rad.len(),
            hd.join(", "),
            match (db.mirrored, db.headings_cover_circle()) {
                (true, _) => {
                    " (full circle: those over 180-360 deg, or 0-180, by port-starboard symmetry; port_starboard_symmetric = false turns it off); interpolated referred to each body's position, cubic in heading"
                }
                (false, true) => " (full circle); interpolated referred to each body's position, cubic in heading",
                (false, false) => "; interpolated referred to each body's position, cubic in heading",
            }
        )
    }

    /// Natural periods, the impulse response and its tail, A_inf, asymmetry and passivity.
    fn write_radiation(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sys = &self.loaded.system;
        let report = &self.check;
        let w = &sys.db.omega_rad_s;
        writeln!(
            out,
            "natural periods (undamped, diagonal terms: lowest w with C = w^2 (M + A(w))):"
        )?;
        for (i, t) in &report.natural_periods_s {
            writeln!(
                out,
                "  {:<20} T = {:8.3} s  (omega = {:.4} rad/s)",
                mode_label(sys, *i),
                t,
                2.0 * PI / t
            )?;
        }
        writeln!(
            out,
            "default solver step (the daemon's forecast.dt_s and rao --dt when not set): {}",
            crate::rom::step::default_step(sys).describe(sys)
        )?;
        writeln!(
            out,
            "impulse response: dt = {} s, memory {:.1} s, the database's damping; beyond w_N = {:.4} rad/s B_ij = B_N,ij (w_N/w)^((p_i + p_j)/2) + D_ij [(w_N/w)^{} - (w_N/w)^{}]",
            report.irf.dt_s,
            report.irf.duration_s(),
            w[w.len() - 1],
            irf::TAIL_FAR_POWER,
            irf::TAIL_POWER,
        )?;
        match report.tail_fit_residuals {
            Some((cubic, fitted)) => writeln!(
                out,
                "  fitted to the database's A(w) and A_inf (p = [{}], largest D_ii / B_N,ii {:.3}): worst added-mass residual in band {:.3} % with the cubic tail (p = 3, D = 0), {:.3} % fitted",
                report
                    .tail
                    .near_power
                    .iter()
                    .map(|p| format!("{p}"))
                    .collect::<Vec<_>>()
                    .join(" "),
                report.tail.far_ratio(),
                100.0 * cubic,
                100.0 * fitted
            )?,
            None => writeln!(
                out,
                "  p = 3, D = 0 (the cubic tail: {})",
                if sys.spec.irf.tail == TailChoice::Cubic {
                    "irf.tail = \"cubic\""
                } else {
                    "the database has no A_inf to fit it to"
                }
            )?,
        }
        writeln!(
            out,
            "A_inf used: {}",
            match report.a_inf_source {
                AInfSource::Database => "the database's (PER = 0)",
                AInfSource::Ogilvie => "Ogilvie's estimate (median over w)",
            }
        )?;
        writeln!(
            out,
            "asymmetry (reciprocity makes A and B symmetric): largest |X_ij - X_ji| / sqrt(X_ii X_jj) {:.3} % in A, {:.3} % in B{}",
            100.0 * report.asymmetry_added_mass,
            100.0 * report.asymmetry_damping,
            if report.asymmetry_added_mass.max(report.asymmetry_damping) > 0.0 {
                " (the state-space model uses the symmetric parts)"
            } else {
                ""
            }
        )?;
        let repair = &report.passivity_repair;
        if repair.frequencies == 0 {
            writeln!(
                out,
                "passivity (radiated power >= 0 makes B positive semi-definite): B(w) is, at every frequency"
            )
        } else {
            writeln!(
                out,
                "passivity (radiated power >= 0 makes B positive semi-definite): B(w) indefinite at {} of {} frequencies; {}, largest change {:.4} % of sqrt(peak B_ii peak B_jj) at {:.4} rad/s",
                repair.frequencies,
                w.len(),
                match self.loaded.system.spec.irf.passivity {
                    Passivity::Project =>
                        "the models use it with the negative eigenvalues set to zero (irf.passivity = \"project\")",
                    Passivity::None =>
                        "the models use it as it is (irf.passivity = \"none\"; the projection would change it)",
                },
                100.0 * repair.largest,
                w[repair.at]
            )?;
            match &self.loaded.passivity {
                Some(c) => writeln!(
                    out,
                    "  chosen by the in-band floor of each choice (convolution models): {}; taken: \"{}\" (the lowest; `irf.passivity` in the system file overrides)",
                    crate::shell::files::describe_floors(c),
                    crate::rom::passivity::name(c.taken)
                ),
                None => writeln!(out, "  irf.passivity as the system file says"),
            }
        }
    }

    /// The Kramers-Kronig summary and the worst pairs (every pair with `all_pairs`).
    fn write_kramers_kronig(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sys = &self.loaded.system;
        let report = &self.check;
        let w = &sys.db.omega_rad_s;
        let mut kk = report.kk.clone();
        kk.sort_by(|a, b| b.added_mass_band.total_cmp(&a.added_mass_band));
        let worst = |f: fn(&PairError) -> f64| kk.iter().map(f).fold(0.0, f64::max);
        let band = irf::KK_BAND_FRACTION * w[w.len() - 1];
        writeln!(
            out,
            "Kramers-Kronig (A, B rebuilt from K; error / sqrt(scale_ii scale_jj)): worst A {:.3} % up to {band:.3} rad/s, {:.3} % over all; worst B {:.3} %",
            100.0 * worst(|e| e.added_mass_band),
            100.0 * worst(|e| e.added_mass),
            100.0 * worst(|e| e.damping)
        )?;
        let og_band = report.kk_ogilvie.iter().map(|e| e.added_mass_band).fold(0.0, f64::max);
        writeln!(
            out,
            "  with Ogilvie's A_inf instead: worst A {:.3} % up to {band:.3} rad/s",
            100.0 * og_band
        )?;
        let shown = if self.all_pairs {
            kk.len()
        } else {
            kk.len().min(PAIRS_SHOWN)
        };
        for e in &kk[..shown] {
            writeln!(
                out,
                "  {:>2} {:>2} {:<16} {:<16} A {:7.3} % in band, {:7.3} % all (at {:.3} rad/s)  B {:7.3} %  Ogilvie A_inf spread {:7.3} %",
                e.i + 1,
                e.j + 1,
                mode_label(sys, e.i),
                mode_label(sys, e.j),
                100.0 * e.added_mass_band,
                100.0 * e.added_mass,
                e.added_mass_at_rad_s,
                100.0 * e.damping,
                100.0 * e.a_inf_spread
            )?;
        }
        if shown < kk.len() {
            writeln!(out, "  ... {} more pairs (--all-pairs)", kk.len() - shown)?;
        }
        Ok(())
    }

    /// The state-space fit and each radiation model's floor.
    fn write_models(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sys = &self.loaded.system;
        match &self.state_space {
            StateSpace::Fitted(s) => {
                writeln!(
                    out,
                    "state-space radiation (active DOFs): vector fit with {} pole pairs (largest scaled error {:.3} %), {} states balanced-truncated to {} ({} modes; next Hankel singular value {:.2e} of {:.2e}), fitted in {:.2} s; damping error {:.3} %, added mass error {:.3} % (largest, scaled); passivity cover {:.4} % of the peak damping",
                    s.fit_pairs,
                    100.0 * s.fit_error,
                    s.full_order,
                    s.real_order,
                    s.modes,
                    s.next_hankel,
                    s.first_hankel,
                    s.fitted_s,
                    100.0 * s.damping_error,
                    100.0 * s.added_mass_error,
                    100.0 * s.cover
                )?;
                writeln!(out, "  {}", s.drift)?;
            }
            StateSpace::NotBuilt => writeln!(out, "state-space radiation: not built")?,
            StateSpace::NoFit(e) => writeln!(out, "state-space radiation: no fit: {e}")?,
        }
        writeln!(
            out,
            "time-domain floor (the frequency-domain solve with the A(w), B(w) each radiation model implies: what a time-domain run converges to as dt -> 0) against the database's frequency domain; worst |difference| / curve peak, every mode and heading:"
        )?;
        for (name, floor) in &self.floors {
            match floor {
                FloorLine::Worst {
                    fraction,
                    state,
                    heading,
                    omega,
                } => writeln!(
                    out,
                    "  {name:<12} {:.3} % ({}, heading {:.1} deg, {:.4} rad/s)",
                    100.0 * fraction,
                    mode_label(sys, *state),
                    sys.db.heading_rad[*heading].to_degrees(),
                    self.floor_omegas[*omega]
                )?,
                FloorLine::NoResponse => writeln!(out, "  {name:<12} no response to compare")?,
                FloorLine::NoFrequencyDomain(e) => writeln!(out, "  {name:<12} no frequency-domain solve: {e}")?,
                FloorLine::Unavailable(e) => writeln!(out, "  {name:<12} no floor: {e}")?,
            }
        }
        Ok(())
    }
}

impl fmt::Display for DriftDrag {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "damping at zero frequency (radiation has none; balanced truncation loses the fit's K(0) = 0 and passivity enforcement makes it positive):"
        )?;
        if let Some((percent, dof, k0)) = &self.largest {
            write!(f, " largest {percent:.4} % of the peak damping ({dof}, {k0:.3e} SI)")?;
        }
        match &self.free {
            Some((t, dof)) => write!(
                f,
                "; a free drift slowed with time constant {t:.0} s at the shortest ({dof}, (M + A_inf) / K(0))"
            ),
            None => write!(f, "; no DOF without restoring is damped at zero frequency"),
        }
    }
}

/// The system file's external models: connections with their force at equilibrium, tanks, points and
/// relative motions (nothing without any).
fn external_summary(out: &mut fmt::Formatter<'_>, sys: &VesselSystem) -> fmt::Result {
    let ext = &sys.spec.external;
    let body = |b: Option<usize>| {
        b.map(|k| sys.spec.bodies[k].name.clone())
            .unwrap_or_else(|| "earth".into())
    };
    if ext.connections.is_empty() && ext.tanks.is_empty() && ext.points.is_empty() {
        return Ok(());
    }
    let n = sys.n_states();
    let zero = vec![0.0; n];
    let mut f = vec![];
    ext.connection_forces(&zero, &zero, &mut f);
    for (c, f0) in ext.connections.iter().zip(&f) {
        let kind = match &c.kind {
            ConnectionKind::SpringDamper { .. } => "spring-damper",
            ConnectionKind::Bushing { .. } => "bushing",
            ConnectionKind::MooringLine { .. } => "mooring line",
            ConnectionKind::Fender { .. } => "fender",
        };
        writeln!(
            out,
            "connection {}: {kind}, {} -> {}, force at equilibrium {:.4e} N",
            c.name,
            body(c.a.body),
            body(c.b.body),
            f0
        )?;
    }
    let mut net = vec![0.0; n];
    ext.nonlinear_force(&zero, &zero, &mut net);
    let worst = net.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if worst > 0.0 {
        writeln!(
            out,
            "  lines and fenders at equilibrium: largest net generalized force {worst:.4e} (taken as balanced by the mean loads; the model works about it)"
        )?;
    }
    for (t, name) in ext.tanks.iter().zip(&ext.tank_names) {
        writeln!(
            out,
            "tank {name} on {}: fluid natural frequency {:.4} rad/s (T = {:.2} s), a_tt {:.4e}, b_tt {:.4e}, c_tt {:.4e}, a_t4 {:.4e}, c_t4 {:.4e}",
            sys.spec.bodies[t.body].name,
            t.natural_frequency_rad_s(),
            2.0 * PI / t.natural_frequency_rad_s(),
            t.a_tt,
            t.b_tt,
            t.c_tt,
            t.a_t4,
            t.c_t4
        )?;
    }
    for p in &ext.points {
        writeln!(
            out,
            "point {} on {} at ({:.3}, {:.3}, {:.3}) m",
            p.name, sys.spec.bodies[p.body].name, p.point_m.x, p.point_m.y, p.point_m.z
        )?;
    }
    for r in &ext.relative_motions {
        writeln!(
            out,
            "relative motion {}: {} - {}",
            r.name, ext.points[r.a].name, ext.points[r.b].name
        )?;
    }
    Ok(())
}
