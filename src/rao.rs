//! The linear frequency-domain solver: motion RAOs of the whole system (pure).
//!
//!   Xi(w, beta) = [-w^2 (M + A(w)) + i w (B(w) + B_lin) + C]^-1 X(w, beta)
//!
//! restricted to the active DOFs (the others are held at zero). Conventions (DESIGN.md section 1): the
//! 6N-vector Xi is for exp(+i w t) and a unit-amplitude wave whose crest is at the database origin at
//! t = 0; |Xi_i| is in m/m for translations and rad/m for rotations. A(w), B(w) and X(w, beta) are
//! interpolated by [`crate::hydro::HydroDb`]. Quadratic damping does not enter (it has no linear
//! frequency-domain form); zero forward speed. External models enter as the system file gives them:
//! tanks (one state each after the 6N modes), linear connections, and the nonlinear connections
//! linearized at equilibrium (their tangent stiffness by central differences).

use crate::hydro::{Error, Result, VesselSystem};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// The system matrices that do not depend on frequency, gathered once for many solves.
#[derive(Debug, Clone)]
pub struct FrequencySolver<'a> {
    sys: &'a VesselSystem,
    mass: DMatrix<f64>,
    damping: DMatrix<f64>,
    stiffness: DMatrix<f64>,
    active: Vec<usize>,
}

impl<'a> FrequencySolver<'a> {
    pub fn new(sys: &'a VesselSystem) -> Self {
        let terms = sys.linear_terms();
        FrequencySolver {
            sys,
            mass: terms.mass,
            damping: terms.damping,
            stiffness: terms.stiffness + sys.spec.external.nonlinear_tangent(sys.n_states()),
            active: sys.active_states(),
        }
    }

    /// Motion RAO of every state (6N modes then the tanks; inactive ones zero) at `omega_rad_s` and `heading_rad`.
    pub fn rao(&self, omega_rad_s: f64, heading_rad: f64) -> Result<DVector<Complex64>> {
        if !(omega_rad_s.is_finite() && omega_rad_s > 0.0) {
            return Err(Error::OutOfRange(format!(
                "frequency {omega_rad_s} rad/s: must be positive"
            )));
        }
        let (a, b) = self.sys.db.radiation_at(omega_rad_s)?;
        let x = self.sys.db.excitation_at(omega_rad_s, heading_rad)?;
        let w = omega_rad_s;
        let act = &self.active;
        let na = act.len();
        let nm = self.sys.n_modes();
        let hydro = |m: &DMatrix<f64>, i: usize, j: usize| if i < nm && j < nm { m[(i, j)] } else { 0.0 };
        let z = DMatrix::from_fn(na, na, |r, c| {
            let (i, j) = (act[r], act[c]);
            Complex64::new(
                -w * w * (self.mass[(i, j)] + hydro(&a, i, j)) + self.stiffness[(i, j)],
                w * (hydro(&b, i, j) + self.damping[(i, j)]),
            )
        });
        let rhs = DVector::from_fn(na, |r, _| if act[r] < nm { x[act[r]] } else { Complex64::default() });
        let sol = z
            .lu()
            .solve(&rhs)
            .ok_or_else(|| Error::OutOfRange(format!("the equations of motion are singular at {w} rad/s")))?;
        let mut out = DVector::from_element(self.sys.n_states(), Complex64::default());
        for (r, &i) in act.iter().enumerate() {
            out[i] = sol[r];
        }
        Ok(out)
    }

    /// [`FrequencySolver::rao`] at every heading and frequency: `table[heading][omega][state]` (the
    /// layout of [`crate::rom::floor::RaoTable`]). An error names the heading and frequency.
    pub fn table(&self, omegas_rad_s: &[f64], headings_rad: &[f64]) -> Result<Vec<Vec<Vec<Complex64>>>> {
        headings_rad
            .iter()
            .map(|&h| {
                omegas_rad_s
                    .iter()
                    .map(|&w| {
                        self.rao(w, h).map(|x| x.iter().copied().collect()).map_err(|e| {
                            Error::OutOfRange(format!("omega {w} rad/s, heading {} deg: {e}", h.to_degrees()))
                        })
                    })
                    .collect()
            })
            .collect()
    }
}
