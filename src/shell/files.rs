//! Shell: reads a system file and its WAMIT database from disk and hands the text to the pure readers.
//! (Logs are `record`'s, configurations `config`'s.)

use crate::hydro::system::SystemSpec;
use crate::hydro::wamit::{self, Scaling};
use crate::hydro::{self, VesselSystem};
use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

/// Errors of the file layer: the file that could not be opened, or what the reader found in it.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The OS error is part of the message, not a source: printed once.
    #[error("{}: {err}", path.display())]
    Io { path: PathBuf, err: std::io::Error },
    #[error(transparent)]
    Hydro(#[from] hydro::Error),
}

fn open(path: &Path) -> Result<BufReader<File>, Error> {
    File::open(path).map(BufReader::new).map_err(|err| Error::Io {
        path: path.to_path_buf(),
        err,
    })
}

/// A loaded system, with notes on the optional files found beside it.
#[derive(Debug, Clone)]
pub struct Loaded {
    pub system: VesselSystem,
    /// The files read, in order.
    pub files: Vec<PathBuf>,
    /// Observations on optional files (e.g. `.3fk + .3sc` against `.3`).
    pub notes: Vec<String>,
    /// The choice of `irf.passivity` by the floors, where the file left it unsaid and the damping is
    /// indefinite ([`crate::rom::passivity`]; already applied to `system`).
    pub passivity: Option<crate::rom::passivity::PassivityChoice>,
}

/// Loads `system.toml` and the WAMIT files it names (`.1`, `.3` or else `.2`, `.hst`; `.3fk` and
/// `.3sc` when present are read and checked against the total excitation).
pub fn load_system(path: &Path) -> Result<Loaded, Error> {
    let text = std::fs::read_to_string(path).map_err(|err| Error::Io {
        path: path.to_path_buf(),
        err,
    })?;
    let spec = SystemSpec::from_toml(&text, &path.display().to_string())?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let stem = dir.join(&spec.wamit_stem);
    let with_ext = |ext: &str| PathBuf::from(format!("{}.{ext}", stem.display()));
    let n = spec.n_modes();
    let s = Scaling {
        rho: spec.rho_kg_m3,
        g: spec.g_m_s2,
        ulen: spec.ulen_m,
    };
    let bounds = wamit::EntryBounds::from_masses(
        spec.rho_kg_m3,
        &spec.bodies.iter().map(|b| b.mass[(0, 0)]).collect::<Vec<_>>(),
    );
    let mut files = vec![path.to_path_buf()];
    let p1 = with_ext("1");
    let rad = wamit::read_radiation_bounded(open(&p1)?, &p1.display().to_string(), n, s, &bounds)?;
    files.push(p1);
    let p3 = if with_ext("3").exists() || !with_ext("2").exists() {
        with_ext("3")
    } else {
        with_ext("2")
    };
    let exc = wamit::read_excitation_bounded(open(&p3)?, &p3.display().to_string(), n, s, &bounds)?;
    files.push(p3.clone());
    let phst = with_ext("hst");
    let hst = wamit::read_hydrostatics_bounded(open(&phst)?, &phst.display().to_string(), n, s, &bounds)?;
    files.push(phst);
    let mut notes = vec![];
    let (pfk, psc) = (with_ext("3fk"), with_ext("3sc"));
    if pfk.exists() && psc.exists() {
        let fk = wamit::read_excitation_bounded(open(&pfk)?, &pfk.display().to_string(), n, s, &bounds)?;
        let sc = wamit::read_excitation_bounded(open(&psc)?, &psc.display().to_string(), n, s, &bounds)?;
        notes.push(match wamit::sum_mismatch(&fk, &sc, &exc) {
            Some(e) => format!(
                "Froude-Krylov + scattering ({}, {}) against the total: largest difference {:.3e} of the largest |X|",
                pfk.display(),
                psc.display(),
                e
            ),
            None => {
                "Froude-Krylov and scattering files do not share the total's frequencies and headings: not compared"
                    .into()
            }
        });
        files.push(pfk);
        files.push(psc);
    }
    let label = stem.display().to_string();
    let speeds = spec.speed_databases.clone();
    let mut system = VesselSystem::assemble(spec, rad, exc, hst, &label)?;
    for (u, stem) in speeds {
        let stem = dir.join(&stem);
        let with_ext = |ext: &str| PathBuf::from(format!("{}.{ext}", stem.display()));
        let (p1, p3, phst) = (with_ext("1"), with_ext("3"), with_ext("hst"));
        let rad = wamit::read_radiation_bounded(open(&p1)?, &p1.display().to_string(), n, s, &bounds)?;
        let exc = wamit::read_excitation_bounded(open(&p3)?, &p3.display().to_string(), n, s, &bounds)?;
        let hst = wamit::read_hydrostatics_bounded(open(&phst)?, &phst.display().to_string(), n, s, &bounds)?;
        system.add_speed_database(u, rad, exc, hst, &stem.display().to_string())?;
        files.extend([p1, p3, phst]);
    }
    let passivity = crate::rom::passivity::choose(&system);
    if let Some(c) = &passivity {
        system.spec.irf.passivity = c.taken;
        tracing::info!(
            "{}: its damping is indefinite at some frequencies; irf.passivity = \"{}\", the lowest in-band floor ({})",
            path.display(),
            crate::rom::passivity::name(c.taken),
            describe_floors(c)
        );
    }
    Ok(Loaded {
        system,
        files,
        notes,
        passivity,
    })
}

/// Each passivity choice's floor, for the log and `db check`.
pub fn describe_floors(c: &crate::rom::passivity::PassivityChoice) -> String {
    c.floors
        .iter()
        .map(|(p, f)| {
            let n = crate::rom::passivity::name(*p);
            match f {
                Ok(f) => format!("{n}: {:.2} %", 100.0 * f),
                Err(e) => format!("{n}: none ({e})"),
            }
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// Reads a CSV or text file whole (for the CLI's own inputs).
pub fn read_text(path: &Path) -> Result<String, Error> {
    std::fs::read_to_string(path).map_err(|err| Error::Io {
        path: path.to_path_buf(),
        err,
    })
}
