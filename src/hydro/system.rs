//! The system file (`system.toml`, DESIGN.md section 3) and the assembled [`VesselSystem`].
//!
//! Pure: [`SystemSpec::from_toml`] takes the file's text and a label for errors; the shell reads files.
//! Every key is checked: unknown keys are errors, values are validated with messages that name the key.
//!
//! Units: position m (BEM global frame); mass kg; centre_of_gravity m relative to the body's reference
//! point (`position`); radii_of_gyration m about the centre of gravity (x, y, z axes); mass_matrix about
//! the reference point (kg, kg m, kg m^2); linear damping N s/m, N s, N m s/rad by DOF pair; quadratic
//! damping N s^2/m^2 ... (force per velocity squared); speed_damping (B_U) per m/s and speed_restoring
//! (C_UQ) per (m/s)^2 of forward speed.

use super::db::HydroDb;
use super::external::{self, External};
use super::wamit::{Excitation, Radiation};
use super::{Dof, Error, Result};
use nalgebra::{DMatrix, Matrix3, Matrix6, Vector3};
use serde::Deserialize;

/// The damping tail beyond the database's last frequency ([`crate::radiation::irf::DampingTail`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum TailChoice {
    /// Fitted so the added mass implied by K matches the database's A(w) with its A_inf (the default; the
    /// cubic tail when the database has no PER = 0 rows).
    #[default]
    Fitted,
    /// B_N (w_N/w)^3.
    Cubic,
}

/// What the time-domain models do with a damping B(w) that is not positive semi-definite (a BEM's
/// irregular frequencies, coarse panels): `irf.passivity`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Passivity {
    /// Negative eigenvalues set to zero at each frequency (the smallest change that makes B passive;
    /// [`crate::radiation::irf::passive_damping`]), the default: a passive K can never make a stable hull
    /// unstable.
    #[default]
    Project,
    /// B as the database has it; the model is refused when its free motion grows
    /// ([`crate::rom::TimeModel::new`]).
    None,
}

/// How A_inf is obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AInfSource {
    /// The database's PER = 0 rows (an error if absent).
    Database,
    /// Ogilvie's relation, A_inf = A(w) + (1/w) int K(t) sin(w t) dt, averaged over the database
    /// frequencies: consistent with the damping as the database samples it.
    Ogilvie,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
enum DepthSpec {
    Word(String),
    Metres(f64),
}

/// One `[[database]]` entry: a WAMIT file set computed at a forward speed.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SpeedDatabaseFile {
    speed_m_s: f64,
    wamit: String,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SystemFile {
    wamit: String,
    /// Databases at forward speeds (A and B against the encounter frequency, X against the wave
    /// frequency); `wamit` is the one at zero speed.
    #[serde(default)]
    database: Vec<SpeedDatabaseFile>,
    #[serde(default = "one")]
    ulen: f64,
    rho: f64,
    g: f64,
    water_depth: DepthSpec,
    #[serde(default = "yes")]
    hydrodynamic_coupling: bool,
    /// Complete a 0-180 deg database by port-starboard symmetry (default: when every body is on the x
    /// axis; see [`super::db`]).
    port_starboard_symmetric: Option<bool>,
    a_inf: Option<AInfSource>,
    irf: Option<IrfFile>,
    /// System-level linear damping entries `[mode_i, mode_j, value]`, WAMIT mode numbers 1..6N.
    #[serde(default)]
    linear_damping_entries: Vec<[f64; 3]>,
    /// System-level linear stiffness entries `[mode_i, mode_j, value]`.
    #[serde(default)]
    linear_stiffness_entries: Vec<[f64; 3]>,
    body: Vec<BodyFile>,
    #[serde(default)]
    connection: Vec<external::ConnectionFile>,
    #[serde(default)]
    tank: Vec<external::TankFile>,
    #[serde(default)]
    point: Vec<external::PointFile>,
    #[serde(default)]
    relative_motion: Vec<external::RelativeFile>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct IrfFile {
    dt_s: Option<f64>,
    duration_s: Option<f64>,
    tail: Option<TailChoice>,
    passivity: Option<Passivity>,
}

fn one() -> f64 {
    1.0
}
fn yes() -> bool {
    true
}

/// A 6 x 6 matrix, or its diagonal as 6 numbers.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
enum MatrixOrDiagonal {
    Matrix(Box<[[f64; 6]; 6]>),
    Diagonal([f64; 6]),
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct BodyFile {
    name: String,
    position: [f64; 3],
    mass_matrix: Option<[[f64; 6]; 6]>,
    mass: Option<f64>,
    centre_of_gravity: Option<[f64; 3]>,
    radii_of_gyration: Option<[f64; 3]>,
    linear_damping: Option<[[f64; 6]; 6]>,
    linear_stiffness: Option<[[f64; 6]; 6]>,
    quadratic_damping: Option<MatrixOrDiagonal>,
    speed_damping: Option<[[f64; 6]; 6]>,
    speed_restoring: Option<[[f64; 6]; 6]>,
    active_dofs: Option<Vec<String>>,
}

/// Impulse-response options (see [`crate::radiation::irf`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IrfOptions {
    /// Time step of the sampled K(t), s. Default 0.05 s.
    pub dt_s: f64,
    /// Memory length, s. Default: pi / (smallest frequency spacing), clamped to 30..600 s.
    pub duration_s: Option<f64>,
    /// The damping tail beyond the database's last frequency.
    pub tail: TailChoice,
    /// What an indefinite B(w) becomes.
    pub passivity: Passivity,
    /// Whether the system file said `passivity` (else the choice is made by the floors,
    /// [`crate::rom::passivity::choose`]).
    pub passivity_given: bool,
}

impl Default for IrfOptions {
    fn default() -> Self {
        IrfOptions {
            dt_s: 0.05,
            duration_s: None,
            tail: TailChoice::Fitted,
            passivity: Passivity::Project,
            passivity_given: false,
        }
    }
}

/// One vessel as the system file describes it.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    pub name: String,
    /// Reference point in the BEM global frame, m.
    pub position_m: Vector3<f64>,
    /// Rigid-body mass matrix about the reference point.
    pub mass: Matrix6<f64>,
    /// Added to B_lin.
    pub linear_damping: Matrix6<f64>,
    /// External linear stiffness (a linearized mooring, a PTO spring), added to C.
    pub linear_stiffness: Matrix6<f64>,
    /// B_Q in B_Q |x'| x'.
    pub quadratic_damping: Matrix6<f64>,
    /// B_U in B_U U x' (damping per m/s of forward speed).
    pub speed_damping: Matrix6<f64>,
    /// C_UQ in C_UQ U^2 x (restoring per (m/s)^2 of forward speed).
    pub speed_restoring: Matrix6<f64>,
    /// Which of surge..yaw are free.
    pub active: [bool; 6],
}

/// The validated system file, before the database is attached.
#[derive(Debug, Clone, PartialEq)]
pub struct SystemSpec {
    /// Stem of the WAMIT files, relative to the system file: the database at zero speed.
    pub wamit_stem: String,
    /// `[[database]]`: (forward speed, m/s; stem) of databases at other speeds, speeds ascending and
    /// positive (an entry at speed 0 must name `wamit` itself and is left out here).
    pub speed_databases: Vec<(f64, String)>,
    pub ulen_m: f64,
    pub rho_kg_m3: f64,
    pub g_m_s2: f64,
    /// None = infinite depth.
    pub water_depth_m: Option<f64>,
    pub hydrodynamic_coupling: bool,
    /// `port_starboard_symmetric` (None: decided by the geometry, [`HydroDb::set_bodies`]).
    pub port_starboard_symmetric: Option<bool>,
    pub a_inf: Option<AInfSource>,
    pub irf: IrfOptions,
    pub bodies: Vec<Body>,
    /// 6N x 6N, added to B_lin.
    pub extra_damping: DMatrix<f64>,
    /// 6N x 6N, added to C.
    pub extra_stiffness: DMatrix<f64>,
    /// Connections, tanks, points of interest ([`super::external`]).
    pub external: External,
}

impl SystemSpec {
    pub fn n_modes(&self) -> usize {
        6 * self.bodies.len()
    }

    /// Each body's reference point (x, y) in the system's frame, m.
    pub fn reference_points_xy_m(&self) -> Vec<[f64; 2]> {
        self.bodies.iter().map(|b| [b.position_m.x, b.position_m.y]).collect()
    }

    /// Parses and validates a system file's text; `file` labels errors.
    pub fn from_toml(text: &str, file: &str) -> Result<SystemSpec> {
        let raw: SystemFile = toml::from_str(text).map_err(|e| {
            let (line, col) = e.span().map(|sp| line_col(text, sp.start)).unwrap_or((0, 0));
            Error::Parse {
                file: file.into(),
                line,
                msg: format!("column {col}: {}", e.message()),
            }
        })?;
        let key = |k: &str, msg: String| Error::Key {
            file: file.into(),
            key: k.into(),
            msg,
        };
        for (k, v) in [("ulen", raw.ulen), ("rho", raw.rho), ("g", raw.g)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(key(k, format!("must be a positive number, found {v}")));
            }
        }
        if raw.wamit.trim().is_empty() {
            return Err(key("wamit", "must name the stem of the WAMIT files".into()));
        }
        let speed_databases = speed_databases(&raw).map_err(|(k, msg)| key(&k, msg))?;
        let water_depth_m = water_depth(&raw.water_depth).map_err(|msg| key("water_depth", msg))?;
        let irf = irf_options(raw.irf.as_ref()).map_err(|(k, msg)| key(k, msg))?;
        if raw.body.is_empty() {
            return Err(key("body", "at least one [[body]] is needed".into()));
        }
        let mut bodies = Vec::new();
        for (k, b) in raw.body.iter().enumerate() {
            let at = |field: &str| format!("body[{k}].{field}");
            let body = parse_body(b, k).map_err(|(field, msg)| key(&at(&field), msg))?;
            if bodies.iter().any(|o: &Body| o.name == body.name) {
                return Err(key(&at("name"), format!("`{}` is used by another body", body.name)));
            }
            bodies.push(body);
        }
        let n = 6 * bodies.len();
        let extra = |name: &str, entries: &[[f64; 3]]| {
            extra_entries(entries, n).map_err(|(e, msg)| key(&format!("{name}[{e}]"), msg))
        };
        let extra_damping = extra("linear_damping_entries", &raw.linear_damping_entries)?;
        let extra_stiffness = extra("linear_stiffness_entries", &raw.linear_stiffness_entries)?;
        let names: Vec<String> = bodies.iter().map(|b| b.name.clone()).collect();
        let positions = bodies.iter().map(|b| b.position_m).collect();
        let external = external::parse_external(
            &raw.connection,
            &raw.tank,
            &raw.point,
            &raw.relative_motion,
            &names,
            positions,
            raw.g,
        )
        .map_err(|(k, msg)| key(&k, msg))?;
        Ok(SystemSpec {
            wamit_stem: raw.wamit,
            speed_databases,
            ulen_m: raw.ulen,
            rho_kg_m3: raw.rho,
            g_m_s2: raw.g,
            water_depth_m,
            hydrodynamic_coupling: raw.hydrodynamic_coupling,
            port_starboard_symmetric: raw.port_starboard_symmetric,
            a_inf: raw.a_inf,
            irf,
            bodies,
            extra_damping,
            extra_stiffness,
            external,
        })
    }
}

/// The databases at forward speed of a system file (speed 0 is `wamit` itself), in increasing order;
/// an error is (key, message).
fn speed_databases(raw: &SystemFile) -> std::result::Result<Vec<(f64, String)>, (String, String)> {
    let mut speed_databases: Vec<(f64, String)> = vec![];
    for (i, d) in raw.database.iter().enumerate() {
        let at = format!("database[{i}]");
        if !(d.speed_m_s.is_finite() && d.speed_m_s >= 0.0 && d.speed_m_s <= MAX_DATABASE_SPEED_M_S) {
            return Err((
                format!("{at}.speed_m_s"),
                format!("must be in [0, {MAX_DATABASE_SPEED_M_S}] m/s, found {}", d.speed_m_s),
            ));
        }
        if d.wamit.trim().is_empty() {
            return Err((format!("{at}.wamit"), "must name the stem of the WAMIT files".into()));
        }
        if d.speed_m_s == 0.0 {
            if d.wamit != raw.wamit {
                return Err((
                    format!("{at}.wamit"),
                    format!(
                        "the database at speed 0 is `wamit` (\"{}\"), found \"{}\"",
                        raw.wamit, d.wamit
                    ),
                ));
            }
            continue;
        }
        if speed_databases.last().is_some_and(|(u, _)| *u >= d.speed_m_s) {
            return Err((
                format!("{at}.speed_m_s"),
                "the databases' speeds must be listed in increasing order, each once".into(),
            ));
        }
        speed_databases.push((d.speed_m_s, d.wamit.clone()));
    }
    Ok(speed_databases)
}

/// `water_depth`: "infinite" (None) or positive metres.
fn water_depth(spec: &DepthSpec) -> std::result::Result<Option<f64>, String> {
    Ok(match spec {
        DepthSpec::Word(w) if w == "infinite" => None,
        DepthSpec::Word(w) => return Err(format!("expected \"infinite\" or metres, found \"{w}\"")),
        DepthSpec::Metres(d) if d.is_finite() && *d > 0.0 => Some(*d),
        DepthSpec::Metres(d) => return Err(format!("must be positive, found {d}")),
    })
}

/// The `[irf]` table over the defaults; an error is (key, message).
fn irf_options(f: Option<&IrfFile>) -> std::result::Result<IrfOptions, (&'static str, String)> {
    let mut irf = IrfOptions::default();
    if let Some(f) = f {
        if let Some(dt) = f.dt_s {
            crate::radiation::irf::check_dt(dt).map_err(|e| ("irf.dt_s", e.to_string()))?;
            irf.dt_s = dt;
        }
        if let Some(d) = f.duration_s {
            if !(1.0..=3600.0).contains(&d) {
                return Err(("irf.duration_s", format!("must be in [1, 3600] s, found {d}")));
            }
            irf.duration_s = Some(d);
        }
        if let Some(p) = f.passivity {
            irf.passivity = p;
            irf.passivity_given = true;
        }
        if let Some(t) = f.tail {
            irf.tail = t;
        }
    }
    Ok(irf)
}

/// An `n` x `n` matrix of `[i, j, value]` entries (WAMIT mode numbers 1..n, summed); an error is (the
/// entry's index, message).
fn extra_entries(entries: &[[f64; 3]], n: usize) -> std::result::Result<DMatrix<f64>, (usize, String)> {
    let mut m = DMatrix::zeros(n, n);
    for (e, [i, j, v]) in entries.iter().enumerate() {
        for idx in [i, j] {
            if idx.fract() != 0.0 || *idx < 1.0 || *idx > n as f64 {
                return Err((
                    e,
                    format!("mode {idx} is outside 1..{n} (WAMIT mode numbers of {} bodies)", n / 6),
                ));
            }
        }
        if !v.is_finite() {
            return Err((e, format!("value {v} is not finite")));
        }
        m[(*i as usize - 1, *j as usize - 1)] += v;
    }
    Ok(m)
}

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rfind('\n').map(|p| offset - p).unwrap_or(offset + 1);
    (line, col)
}

type FieldErr = (String, String);

fn finite_matrix(m: &[[f64; 6]; 6], field: &str) -> std::result::Result<Matrix6<f64>, FieldErr> {
    let mut out = Matrix6::zeros();
    for i in 0..6 {
        for j in 0..6 {
            if !m[i][j].is_finite() {
                return Err((
                    format!("{field}[{i}][{j}]"),
                    format!("not a finite number: {}", m[i][j]),
                ));
            }
            out[(i, j)] = m[i][j];
        }
    }
    Ok(out)
}

/// Rigid-body mass matrix about the reference point from mass, centre of gravity (relative to the
/// reference point) and radii of gyration about the centre of gravity (principal axes along x, y, z).
/// `[m I, -m [r]x; m [r]x, I_G + m (|r|^2 I - r r^T)]`, `[r]x` the cross-product matrix of r.
pub fn mass_matrix_from_properties(mass_kg: f64, cog_m: Vector3<f64>, radii_m: Vector3<f64>) -> Matrix6<f64> {
    let skew = cog_m.cross_matrix();
    let ig = Matrix3::from_diagonal(&radii_m.map(|r| mass_kg * r * r));
    let io = ig + (Matrix3::identity() * cog_m.norm_squared() - cog_m * cog_m.transpose()) * mass_kg;
    let mut m = Matrix6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(Matrix3::identity() * mass_kg));
    m.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-skew * mass_kg));
    m.fixed_view_mut::<3, 3>(3, 0).copy_from(&(skew * mass_kg));
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(&io);
    m
}

/// A body's mass matrix about its reference point, from `mass_matrix` or from mass, centre of gravity
/// and radii of gyration: symmetric and positive definite.
fn body_mass(b: &BodyFile) -> std::result::Result<Matrix6<f64>, FieldErr> {
    let err = |f: &str, m: String| (f.to_string(), m);
    let props = (b.mass, b.centre_of_gravity, b.radii_of_gyration);
    let mass = match (&b.mass_matrix, props) {
        (Some(m), (None, None, None)) => finite_matrix(m, "mass_matrix")?,
        (None, (Some(m), Some(cog), Some(r))) => {
            if !(m.is_finite() && m > 0.0) {
                return Err(err("mass", format!("must be a positive mass in kg, found {m}")));
            }
            if cog.iter().any(|v| !v.is_finite()) {
                return Err(err("centre_of_gravity", "must be three finite numbers (m)".into()));
            }
            if r.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
                return Err(err(
                    "radii_of_gyration",
                    format!("must be three positive numbers (m), found {r:?}"),
                ));
            }
            mass_matrix_from_properties(m, Vector3::from(cog), Vector3::from(r))
        }
        (Some(_), _) => {
            return Err(err(
                "mass_matrix",
                "give either mass_matrix or mass + centre_of_gravity + radii_of_gyration, not both".into(),
            ));
        }
        (None, _) => {
            return Err(err(
                "mass",
                "give either mass_matrix, or all of mass, centre_of_gravity and radii_of_gyration".into(),
            ));
        }
    };
    let scale = mass.diagonal().amax().max(f64::MIN_POSITIVE);
    let asym = (mass - mass.transpose()).amax();
    if asym > 1e-9 * scale {
        return Err(err(
            "mass_matrix",
            format!("is not symmetric (largest |M_ij - M_ji| = {asym:.6e})"),
        ));
    }
    if mass.cholesky().is_none() {
        return Err(err("mass_matrix", "is not positive definite".into()));
    }
    Ok(mass)
}

fn parse_body(b: &BodyFile, k: usize) -> std::result::Result<Body, FieldErr> {
    let err = |f: &str, m: String| (f.to_string(), m);
    if b.name.trim().is_empty() {
        return Err(err("name", format!("body {k} needs a non-empty name")));
    }
    if b.position.iter().any(|v| !v.is_finite()) {
        return Err(err("position", "must be three finite numbers (m)".into()));
    }
    let mass = body_mass(b)?;
    let linear_damping = match &b.linear_damping {
        Some(m) => finite_matrix(m, "linear_damping")?,
        None => Matrix6::zeros(),
    };
    let optional = |m: &Option<[[f64; 6]; 6]>, field: &str| match m {
        Some(m) => finite_matrix(m, field),
        None => Ok(Matrix6::zeros()),
    };
    let quadratic_damping = match &b.quadratic_damping {
        Some(MatrixOrDiagonal::Matrix(m)) => finite_matrix(m.as_ref(), "quadratic_damping")?,
        Some(MatrixOrDiagonal::Diagonal(d)) => {
            let mut m = [[0.0; 6]; 6];
            for i in 0..6 {
                m[i][i] = d[i];
            }
            finite_matrix(&m, "quadratic_damping")?
        }
        None => Matrix6::zeros(),
    };
    let linear_stiffness = optional(&b.linear_stiffness, "linear_stiffness")?;
    for (m, field) in [
        (&linear_damping, "linear_damping"),
        (&quadratic_damping, "quadratic_damping"),
        (&linear_stiffness, "linear_stiffness"),
    ] {
        if let Some(i) = (0..6).find(|&i| m[(i, i)] < 0.0) {
            return Err(err(
                field,
                format!(
                    "diagonal entry {i} ({}) is negative: {} (it would feed energy in)",
                    Dof::ALL[i].name(),
                    m[(i, i)]
                ),
            ));
        }
    }
    let speed_damping = optional(&b.speed_damping, "speed_damping")?;
    let speed_restoring = optional(&b.speed_restoring, "speed_restoring")?;
    let mut active = [true; 6];
    if let Some(list) = &b.active_dofs {
        active = [false; 6];
        for name in list {
            let dof = Dof::from_name(name).ok_or_else(|| {
                err(
                    "active_dofs",
                    format!("unknown DOF `{name}`: expected surge, sway, heave, roll, pitch or yaw"),
                )
            })?;
            active[dof.index()] = true;
        }
    }
    Ok(Body {
        name: b.name.clone(),
        position_m: Vector3::from(b.position),
        mass,
        linear_damping,
        linear_stiffness,
        quadratic_damping,
        speed_damping,
        speed_restoring,
        active,
    })
}

/// Linear terms over every state (see [`VesselSystem::linear_terms`]).
#[derive(Debug, Clone)]
pub struct LinearTerms {
    pub mass: DMatrix<f64>,
    pub damping: DMatrix<f64>,
    pub stiffness: DMatrix<f64>,
}

/// The fastest forward speed a `[[database]]` may be computed at, m/s (the model's own bound).
pub const MAX_DATABASE_SPEED_M_S: f64 = 25.0;

/// A vessel system: bodies, their hydrodynamic database and system-level terms, ready for the solvers.
/// The coupling switch is already applied: with `hydrodynamic_coupling = false` every 6x6 block between
/// two different bodies of A(w), B(w), A_inf and C is zero.
#[derive(Debug, Clone)]
pub struct VesselSystem {
    pub spec: SystemSpec,
    pub db: HydroDb,
    /// Databases at forward speeds (speed, m/s, ascending and positive), prepared like `db` (coupling
    /// switch, body referral); `db` is the one at zero speed. [`VesselSystem::at_speed`] interpolates.
    pub speed_dbs: Vec<(f64, HydroDb)>,
    /// Warnings found while assembling (shown by `shipcast db check`).
    pub warnings: Vec<String>,
}

impl VesselSystem {
    /// Adds a database at a forward speed (`[[database]]`), prepared as the zero-speed one is (the
    /// coupling switch, each body's referral, port-starboard symmetry); `file` labels errors.
    pub fn add_speed_database(
        &mut self,
        speed_m_s: f64,
        rad: Radiation,
        exc: Excitation,
        restoring: DMatrix<f64>,
        file: &str,
    ) -> Result<()> {
        let mut db = HydroDb::new(rad, exc, restoring, file)?;
        if !self.spec.hydrodynamic_coupling {
            db.decouple();
        }
        let origins = self.spec.reference_points_xy_m();
        db.set_bodies(
            &origins,
            self.spec.g_m_s2,
            self.spec.water_depth_m,
            self.spec.port_starboard_symmetric,
        )
        .map_err(|msg| Error::Key {
            file: file.into(),
            key: "port_starboard_symmetric".into(),
            msg,
        })?;
        // the same grids as the zero-speed database, checked now rather than at the first forecast
        HydroDb::interpolate_speed(&[(0.0, &self.db), (speed_m_s, &db)], speed_m_s).map_err(|e| Error::Invalid {
            file: file.into(),
            msg: e.to_string(),
        })?;
        self.speed_dbs.push((speed_m_s, db));
        Ok(())
    }

    /// The system at forward speed `speed_m_s`: its database interpolated between the databases at
    /// several speeds ([`HydroDb::interpolate_speed`]; `|speed|`, astern taken as ahead). Without
    /// databases at other speeds, the system as it is (the zero-speed database at every speed).
    pub fn at_speed(&self, speed_m_s: f64) -> Result<VesselSystem> {
        if self.speed_dbs.is_empty() {
            return Ok(self.clone());
        }
        let dbs: Vec<(f64, &HydroDb)> = std::iter::once((0.0, &self.db))
            .chain(self.speed_dbs.iter().map(|(u, d)| (*u, d)))
            .collect();
        let db = HydroDb::interpolate_speed(&dbs, speed_m_s.abs())?;
        Ok(VesselSystem {
            spec: self.spec.clone(),
            db,
            speed_dbs: vec![],
            warnings: self.warnings.clone(),
        })
    }

    /// Attaches the WAMIT data to a validated system file; `file` labels errors (the WAMIT stem).
    pub fn assemble(
        spec: SystemSpec,
        rad: Radiation,
        exc: Excitation,
        restoring: DMatrix<f64>,
        file: &str,
    ) -> Result<VesselSystem> {
        let mut db = HydroDb::new(rad, exc, restoring, file)?;
        let memory_s = spec
            .irf
            .duration_s
            .unwrap_or_else(|| crate::radiation::irf::default_duration_s(&db));
        crate::radiation::irf::check_grid(spec.irf.dt_s, memory_s).map_err(|e| Error::Key {
            file: file.into(),
            key: "irf".into(),
            msg: e.to_string(),
        })?;
        let mut warnings = vec![];
        if !spec.hydrodynamic_coupling {
            db.decouple();
        }
        let origins = spec.reference_points_xy_m();
        db.set_bodies(&origins, spec.g_m_s2, spec.water_depth_m, spec.port_starboard_symmetric)
            .map_err(|msg| Error::Key {
                file: file.into(),
                key: "port_starboard_symmetric".into(),
                msg,
            })?;
        if spec.a_inf == Some(AInfSource::Database) && db.added_mass_inf.is_none() {
            return Err(Error::Invalid {
                file: file.into(),
                msg: "a_inf = \"database\" but the .1 file has no PER = 0 (infinite-frequency) rows".into(),
            });
        }
        if db.added_mass_inf.is_none() {
            warnings.push(
                "no infinite-frequency added mass (PER = 0) in the database: A_inf estimated by Ogilvie's relation"
                    .into(),
            );
        }
        let c = &db.restoring;
        let asym = (c - c.transpose()).amax();
        if asym > 1e-6 * c.amax() {
            warnings.push(format!("the restoring matrix is not symmetric (largest |C_ij - C_ji| = {asym:.4e}): is the body in equilibrium?"));
        }
        let sys = VesselSystem {
            spec,
            db,
            speed_dbs: vec![],
            warnings,
        };
        // a tank's free-surface effect must leave the roll restoring positive
        let c = sys.stiffness();
        for (k, t) in sys.spec.external.tanks.iter().enumerate() {
            let r = 6 * t.body + 3;
            let left = c[(r, r)] - t.c_t4 * t.c_t4 / t.c_tt;
            if left <= 0.0 {
                return Err(Error::Key {
                    file: file.into(),
                    key: format!("tank[{k}]"),
                    msg: format!(
                        "the tank's free-surface effect c_t4^2 / c_tt = {:.4e} N m exceeds the roll restoring {:.4e} N m of `{}`: the ship would capsize",
                        t.c_t4 * t.c_t4 / t.c_tt,
                        c[(r, r)],
                        sys.spec.bodies[t.body].name
                    ),
                });
            }
        }
        Ok(sys)
    }

    pub fn n_modes(&self) -> usize {
        self.spec.n_modes()
    }

    /// Global mass matrix M (6N x 6N, block diagonal).
    pub fn mass_matrix(&self) -> DMatrix<f64> {
        self.block_diag(|b| &b.mass)
    }

    /// B_lin: the bodies' linear damping plus system-level entries.
    pub fn linear_damping(&self) -> DMatrix<f64> {
        self.block_diag(|b| &b.linear_damping) + &self.spec.extra_damping
    }

    /// Block-diagonal 6N x 6N matrix of a per-body 6x6 term.
    pub fn body_matrix(&self, f: impl Fn(&Body) -> &Matrix6<f64>) -> DMatrix<f64> {
        self.block_diag(f)
    }

    /// C: the database's restoring plus the bodies' external stiffness and system-level entries.
    pub fn stiffness(&self) -> DMatrix<f64> {
        &self.db.restoring + &self.spec.extra_stiffness + self.block_diag(|b| &b.linear_stiffness)
    }

    /// Number of states: the 6N body modes, then one per anti-roll tank.
    pub fn n_states(&self) -> usize {
        self.n_modes() + self.spec.external.tanks.len()
    }

    /// Active DOFs followed by every tank state (indices into the n_states vector).
    pub fn active_states(&self) -> Vec<usize> {
        let mut a = self.active_indices();
        a.extend(self.n_modes()..self.n_states());
        a
    }

    /// The speed-independent linear terms over every state (n_states x n_states): mass (rigid body +
    /// tanks), damping (B_lin + linear connections + tanks), stiffness (C + external + linear
    /// connections + tanks). Hydrodynamic terms (A, B, A_inf, K) are not included.
    pub fn linear_terms(&self) -> LinearTerms {
        let ns = self.n_states();
        let n = self.n_modes();
        let pad = |m: DMatrix<f64>| {
            let mut out = DMatrix::zeros(ns, ns);
            out.view_mut((0, 0), (n, n)).copy_from(&m);
            out
        };
        let ext = &self.spec.external;
        let [tm, tb, tc] = ext.tank_matrices(n);
        let (kc, cc) = ext.linear_matrices(ns);
        LinearTerms {
            mass: pad(self.mass_matrix()) + tm,
            damping: pad(self.linear_damping()) + tb + cc,
            stiffness: pad(self.stiffness()) + tc + kc,
        }
    }

    /// A hydrodynamic n_modes matrix padded with zeros to n_states.
    pub fn pad_states(&self, m: &DMatrix<f64>) -> DMatrix<f64> {
        let ns = self.n_states();
        let mut out = DMatrix::zeros(ns, ns);
        let n = m.nrows().min(ns);
        out.view_mut((0, 0), (n, n)).copy_from(&m.view((0, 0), (n, n)));
        out
    }

    /// Undamped natural periods of the active DOFs with positive restoring, from the diagonal terms:
    /// (global mode index, period s), each from the lowest frequency with C_ii = w^2 (M_ii + A_ii(w)).
    pub fn natural_periods_s(&self) -> Vec<(usize, f64)> {
        let db = &self.db;
        let mass = self.mass_matrix();
        let c = self.stiffness();
        let mut natural = vec![];
        for i in self.active_indices() {
            if c[(i, i)] <= 0.0 {
                continue;
            }
            // lowest root of f(w) = C_ii - w^2 (M_ii + A_ii(w)) over the database frequencies (A can swing
            // through gap resonances, so no fixed-point iteration); outside the range use A(w_min) / A_inf
            let f = |w: f64, a: f64| c[(i, i)] - w * w * (mass[(i, i)] + a);
            let ws = &db.omega_rad_s;
            let fs: Vec<f64> = ws.iter().zip(&db.added_mass).map(|(w, a)| f(*w, a[(i, i)])).collect();
            let w = if fs[0] <= 0.0 {
                (c[(i, i)] / (mass[(i, i)] + db.added_mass_zero.as_ref().unwrap_or(&db.added_mass[0])[(i, i)])).sqrt()
            } else if let Some(k) = fs.windows(2).position(|p| p[0] > 0.0 && p[1] <= 0.0) {
                ws[k] + (ws[k + 1] - ws[k]) * fs[k] / (fs[k] - fs[k + 1])
            } else {
                let a = db.added_mass_inf.as_ref().unwrap_or(&db.added_mass[ws.len() - 1])[(i, i)];
                (c[(i, i)] / (mass[(i, i)] + a)).sqrt()
            };
            if w.is_finite() && w > 0.0 {
                natural.push((i, 2.0 * std::f64::consts::PI / w));
            }
        }
        natural
    }

    /// Indices (0-based, global) of the active DOFs.
    pub fn active_indices(&self) -> Vec<usize> {
        self.spec
            .bodies
            .iter()
            .enumerate()
            .flat_map(|(k, b)| (0..6).filter(move |j| b.active[*j]).map(move |j| 6 * k + j))
            .collect()
    }

    fn block_diag(&self, f: impl Fn(&Body) -> &Matrix6<f64>) -> DMatrix<f64> {
        let n = self.n_modes();
        let mut m = DMatrix::zeros(n, n);
        for (k, b) in self.spec.bodies.iter().enumerate() {
            m.view_mut((6 * k, 6 * k), (6, 6)).copy_from(f(b));
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
wamit = "pair"
rho = 1025.0
g = 9.81
water_depth = "infinite"

[[body]]
name = "a"
position = [0.0, 0.0, 0.0]
mass = 1.0e6
centre_of_gravity = [1.0, 0.0, 2.0]
radii_of_gyration = [5.0, 20.0, 21.0]
active_dofs = ["heave", "Roll", "pitch"]
"#;

    #[test]
    fn parses_and_builds_mass_matrix() {
        let s = SystemSpec::from_toml(GOOD, "s.toml").unwrap();
        let m = s.bodies[0].mass;
        assert_eq!(m[(0, 0)], 1.0e6);
        // surge force from pitch acceleration: m zg; heave force from pitch: -m xg
        assert_eq!(m[(0, 4)], 1.0e6 * 2.0);
        assert_eq!(m[(2, 4)], -1.0e6 * 1.0);
        assert!((m - m.transpose()).amax() == 0.0);
        // I_yy about the reference point: m (ky^2 + xg^2 + zg^2)
        assert_eq!(m[(4, 4)], 1.0e6 * (400.0 + 1.0 + 4.0));
        assert_eq!(s.bodies[0].active, [false, false, true, true, true, false]);
        assert!(s.hydrodynamic_coupling);
        assert_eq!(s.water_depth_m, None);
    }

    fn err_of(text: &str) -> String {
        SystemSpec::from_toml(text, "s.toml").unwrap_err().to_string()
    }

    #[test]
    fn unknown_key_is_an_error_with_its_line() {
        let e = err_of(&GOOD.replace("g = 9.81", "g = 9.81\ngravity = 9.8"));
        assert!(
            e.contains("s.toml:5: column 1:") && e.contains("unknown field `gravity`"),
            "{e}"
        );
        let e = err_of(&GOOD.replace("active_dofs", "actve_dofs"));
        assert!(e.contains("unknown field `actve_dofs`"), "{e}");
    }

    #[test]
    fn bad_values_name_the_key() {
        for (from, to, want) in [
            ("rho = 1025.0", "rho = -1.0", "s.toml: rho: must be a positive"),
            ("\"infinite\"", "\"deep\"", "water_depth: expected \"infinite\""),
            ("\"Roll\"", "\"rol\"", "body[0].active_dofs: unknown DOF `rol`"),
            ("mass = 1.0e6", "mass = 0.0", "body[0].mass: must be a positive mass"),
            ("[5.0, 20.0, 21.0]", "[5.0, -20.0, 21.0]", "body[0].radii_of_gyration"),
            ("mass = 1.0e6\n", "", "body[0].mass: give either mass_matrix"),
            ("rho = 1025.0", "rho = \"heavy\"", "s.toml:3: column 7: invalid type"),
        ] {
            let e = err_of(&GOOD.replace(from, to));
            assert!(e.contains(want), "`{e}` lacks `{want}`");
        }
    }

    #[test]
    fn mass_matrix_must_be_symmetric_positive_definite() {
        let base = GOOD
            .replace("mass = 1.0e6\n", "")
            .replace("centre_of_gravity = [1.0, 0.0, 2.0]\n", "")
            .replace("radii_of_gyration = [5.0, 20.0, 21.0]\n", "");
        let diag = |d: [f64; 6], extra: Option<(usize, usize, f64)>| {
            let mut rows = vec![];
            for i in 0..6 {
                let mut r = [0.0; 6];
                r[i] = d[i];
                if let Some((a, b, v)) = extra
                    && a == i
                {
                    r[b] = v;
                }
                rows.push(format!("{r:?}"));
            }
            base.replace(
                "active_dofs",
                &format!("mass_matrix = [{}]\nactive_dofs", rows.join(", ")),
            )
        };
        assert!(SystemSpec::from_toml(&diag([1.0; 6], None), "s").is_ok());
        let e = err_of(&diag([1.0; 6], Some((0, 4, 0.5))));
        assert!(e.contains("body[0].mass_matrix: is not symmetric"), "{e}");
        let e = err_of(&diag([1.0, 1.0, -1.0, 1.0, 1.0, 1.0], None));
        assert!(e.contains("body[0].mass_matrix: is not positive definite"), "{e}");
    }

    #[test]
    fn extra_entries_are_checked() {
        let t = GOOD.replace("water_depth", "linear_damping_entries = [[3, 9, 1.0]]\nwater_depth");
        let e = err_of(&t);
        assert!(e.contains("linear_damping_entries[0]: mode 9 is outside 1..6"), "{e}");
        let t = GOOD.replace("water_depth", "linear_damping_entries = [[3, 3, 2.0]]\nwater_depth");
        let s = SystemSpec::from_toml(&t, "s").unwrap();
        assert_eq!(s.extra_damping[(2, 2)], 2.0);
    }
}
