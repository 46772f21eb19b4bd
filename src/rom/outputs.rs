//! What a forecast implies beyond the DOF motions (pure): the displacement, velocity and acceleration
//! of the system file's points of interest, the relative motions between points, and the force in
//! every connection, step by step. Conventions as in [`crate::hydro::external`]: global axes, m, m/s,
//! m/s^2, N; relative motion = point_a - point_b.

use super::forecast::Forecast;
use crate::hydro::external::External;

/// Named series on the forecast's time grid: `values[k * names.len() + c]`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Derived {
    pub names: Vec<String>,
    pub values: Vec<f64>,
}

impl Derived {
    pub fn at(&self, k: usize, c: usize) -> f64 {
        self.values[k * self.names.len() + c]
    }

    /// Column index of a series by name.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }
}

/// Points (x, y, z, vx, vy, vz, ax, ay, az each), then relative motions (same), then connection
/// forces (`name.force`).
pub fn derived(ext: &External, f: &Forecast) -> Derived {
    let mut names = vec![];
    let pts: Vec<&str> = ext
        .points
        .iter()
        .map(|p| p.name.as_str())
        .chain(ext.relative_motions.iter().map(|r| r.name.as_str()))
        .collect();
    for p in &pts {
        for q in ["x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az"] {
            names.push(format!("{p}.{q}"));
        }
    }
    names.extend(ext.connections.iter().map(|c| format!("{}.force", c.name)));
    let nm = f.n_modes;
    let mut values = Vec::with_capacity((f.steps + 1) * names.len());
    let (mut px, mut pv, mut pa, mut cf) = (vec![], vec![], vec![], vec![]);
    for k in 0..=f.steps {
        let (x, v, a) = (
            &f.x[k * nm..(k + 1) * nm],
            &f.v[k * nm..(k + 1) * nm],
            &f.a[k * nm..(k + 1) * nm],
        );
        ext.point_outputs(x, &mut px);
        ext.point_outputs(v, &mut pv);
        ext.point_outputs(a, &mut pa);
        for p in 0..pts.len() {
            values.extend_from_slice(&px[3 * p..3 * p + 3]);
            values.extend_from_slice(&pv[3 * p..3 * p + 3]);
            values.extend_from_slice(&pa[3 * p..3 * p + 3]);
        }
        ext.connection_forces(x, v, &mut cf);
        values.extend_from_slice(&cf);
    }
    Derived { names, values }
}
