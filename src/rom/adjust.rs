//! A built model adjusted in place of a rebuild: added diagonal damping (linear and quadratic) and
//! stiffness on chosen active rows, as in-situ tuning identifies them (pure). The radiation memory,
//! the mass and the excitation are the built model's; the step's matrices are recomputed.
//!
//! Units: a row's linear damping N s/m or N m s/rad, quadratic N s^2/m^2 or N m s^2/rad^2, stiffness
//! N/m or N m/rad (DESIGN.md section 1: SI, DOF order surge..yaw per vessel).

use nalgebra::DMatrix;

use super::{Error, Result, TimeModel};

/// What is added to one active row's diagonal.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RowChange {
    /// Index into the model's active states (`TimeModel::active`).
    pub row: usize,
    pub damping: f64,
    pub quadratic: f64,
    pub stiffness: f64,
}

impl TimeModel {
    /// This model with `changes` added to its diagonal damping, quadratic damping and stiffness (the
    /// linearized stiffness too). An error when a row is out of range, a change is not finite, or the
    /// step's matrix becomes singular.
    pub fn adjusted(&self, changes: &[RowChange]) -> Result<TimeModel> {
        let n = self.n();
        let mut m = self.clone();
        let mut bdc = from_columns(&self.cols_bdc, self.n_pad, n, 2 * n);
        for c in changes {
            if c.row >= n || ![c.damping, c.quadratic, c.stiffness].iter().all(|v| v.is_finite()) {
                return Err(Error::Input(format!(
                    "a model adjustment of row {} is out of range or not finite",
                    c.row
                )));
            }
            let r = c.row;
            m.damping[(r, r)] += c.damping;
            m.stiffness[(r, r)] += c.stiffness;
            m.stiffness_linearized[(r, r)] += c.stiffness;
            bdc[(r, r)] += c.damping;
            bdc[(r, n + r)] += c.stiffness;
            if c.quadratic != 0.0 {
                let q = m.quadratic.get_or_insert_with(|| DMatrix::zeros(n, n));
                q[(r, r)] += c.quadratic;
            }
        }
        let dt = self.opts.dt_s;
        let b_total = bdc.columns(0, n).into_owned();
        let c_total = bdc.columns(n, n).into_owned();
        let s = &self.mass + b_total * (dt / 2.0) + c_total * (self.opts.beta * dt * dt);
        let s_inv = s
            .try_inverse()
            .ok_or_else(|| Error::Input("the adjusted model's implicit step matrix is singular".into()))?;
        m.cols_bdc = super::dense::columns(&bdc);
        m.cols_s_inv = super::dense::columns(&s_inv);
        Ok(m)
    }
}

/// The matrix `rows` x `cols` stored by [`super::dense::columns`] with columns padded to `np`.
fn from_columns(data: &[f64], np: usize, rows: usize, cols: usize) -> DMatrix<f64> {
    DMatrix::from_fn(rows, cols, |r, c| data[c * np + r])
}
