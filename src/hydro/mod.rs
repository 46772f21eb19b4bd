//! The vessel system and its hydrodynamic database (pure: values in, values out, no IO).
//!
//! Owns: the WAMIT readers ([`wamit`]), the system file ([`system`]), the assembled database with its
//! interpolation over frequency and heading ([`db`]) and the external models ([`external`]). What the
//! database's radiation makes (impulse responses, A_inf, the state-space fit, the checks) is
//! [`crate::radiation`]'s.
//!
//! Conventions (DESIGN.md section 1, contracts):
//! - SI units: m, s, kg, N, rad. Degrees only where a name says `_deg`.
//! - Body frame: x forward, y to port, z up, origin at the body's WAMIT reference point.
//! - DOF order per vessel: surge, sway, heave, roll, pitch, yaw; vessel k owns indices 6k..6k+5
//!   (0-based), i.e. WAMIT modes 6k+1..6k+6.
//! - Complex amplitudes are for exp(+i w t) (WAMIT's convention). A wave heading beta is the direction the
//!   wave travels to, counterclockwise from +x (180 deg = head seas).
//! - Excitation X(w, beta) is the force per metre of wave amplitude referred to the wave phase at the
//!   database's global origin.

pub mod db;
pub mod external;
pub mod system;
pub mod wamit;

pub use db::HydroDb;
pub use system::{Body, VesselSystem};

/// Degrees of freedom of one vessel, in DESIGN.md order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dof {
    Surge,
    Sway,
    Heave,
    Roll,
    Pitch,
    Yaw,
}

impl Dof {
    pub const ALL: [Dof; 6] = [Dof::Surge, Dof::Sway, Dof::Heave, Dof::Roll, Dof::Pitch, Dof::Yaw];

    /// The one table of DOF names, in [`Dof::ALL`]'s order: the name in system files, channels and
    /// labels, and the output column's name with the unit its values are written in.
    const TABLE: [(&'static str, &'static str); 6] = [
        ("surge", "surge_m"),
        ("sway", "sway_m"),
        ("heave", "heave_m"),
        ("roll", "roll_deg"),
        ("pitch", "pitch_deg"),
        ("yaw", "yaw_deg"),
    ];

    /// The names of [`Dof::ALL`]: `surge` .. `yaw`.
    pub const NAMES: [&'static str; 6] = {
        let t = Dof::TABLE;
        [t[0].0, t[1].0, t[2].0, t[3].0, t[4].0, t[5].0]
    };

    /// Lower-case name as used in system files and outputs.
    pub fn name(self) -> &'static str {
        Dof::TABLE[self.index()].0
    }

    pub fn from_name(name: &str) -> Option<Dof> {
        Dof::ALL.into_iter().find(|d| d.name() == name.to_ascii_lowercase())
    }

    /// Index 0..5 within a vessel.
    pub fn index(self) -> usize {
        self as usize
    }

    /// Name with the unit its values are written in by CSV and JSON outputs (`surge_m` .. `yaw_deg`):
    /// the edges speak degrees (DESIGN.md section 1), the core radians.
    pub fn output_name(self) -> &'static str {
        Dof::TABLE[self.index()].1
    }

    /// A value in the core's unit (m or rad) in the unit of [`Dof::output_name`] (m or deg).
    pub fn to_output(self, si: f64) -> f64 {
        if self.is_rotation() { si.to_degrees() } else { si }
    }

    /// Translations are in m, rotations in rad.
    pub fn is_rotation(self) -> bool {
        self.index() >= 3
    }

    /// The DOF of a 0-based global index (6k + j).
    pub fn of_index(global: usize) -> Dof {
        Dof::ALL[global % 6]
    }
}

/// `carrier.heave` style label of a 0-based global mode index.
pub fn mode_label(sys: &VesselSystem, i: usize) -> String {
    if i >= sys.n_modes() {
        let k = i - sys.n_modes();
        let name = sys.spec.external.tank_names.get(k).map(|s| s.as_str()).unwrap_or("?");
        return format!("{name}.tank_angle");
    }
    let body = sys.spec.bodies.get(i / 6).map(|b| b.name.as_str()).unwrap_or("?");
    format!("{body}.{}", Dof::of_index(i).name())
}

/// The output column of state `i` with its unit (`carrier.heave_m`, `carrier.roll_deg`,
/// `<tank>.tank_angle_deg`), as CSV and JSON outputs write it; [`output_value`] converts the value.
pub fn output_label(sys: &VesselSystem, i: usize) -> String {
    if i >= sys.n_modes() {
        return format!("{}_deg", mode_label(sys, i));
    }
    let body = sys.spec.bodies.get(i / 6).map(|b| b.name.as_str()).unwrap_or("?");
    format!("{body}.{}", Dof::of_index(i).output_name())
}

/// State `i`'s value (m or rad) in the unit of its [`output_label`] (m or deg; a tank angle in deg).
pub fn output_value(sys: &VesselSystem, i: usize, si: f64) -> f64 {
    if i >= sys.n_modes() {
        si.to_degrees()
    } else {
        Dof::of_index(i).to_output(si)
    }
}

/// Errors from reading or validating a vessel system and its database. Each names where the problem is
/// (file, line, key) and what was expected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A line of a data file could not be read.
    #[error("{file}:{line}: {msg}")]
    Parse { file: String, line: usize, msg: String },
    /// A key of the system file is missing, unknown or has an invalid value.
    #[error("{file}: {key}: {msg}")]
    Key { file: String, key: String, msg: String },
    /// The data are readable but inconsistent or unusable.
    #[error("{file}: {msg}")]
    Invalid { file: String, msg: String },
    /// A request outside what the database covers (frequency, heading, speed).
    #[error("{0}")]
    OutOfRange(String),
}

pub type Result<T> = std::result::Result<T, Error>;
