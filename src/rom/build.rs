//! Building a time-domain model (pure): [`TimeModel::new`] assembles it (`model.rs`) and, where the
//! database's damping is used as it is (`irf.passivity = "none"`), runs its free motion to refuse one
//! whose radiation memory creates energy.

use super::forecast::{ForecastRequest, Forecaster};
use super::model::{FREE_MOTION_GROWTH, Kernel, RomOptions, TimeModel};
use super::{Error, Result};
use crate::hydro::VesselSystem;
use crate::radiation::history::Memory;

impl TimeModel {
    /// The time-domain model of `sys` over its active DOFs with `opts`.
    pub fn new(sys: &VesselSystem, opts: RomOptions) -> Result<TimeModel> {
        let model = TimeModel::assemble(sys, opts)?;
        if sys.spec.irf.passivity == crate::hydro::system::Passivity::None {
            model.check_free_motion()?;
        }
        Ok(model)
    }

    /// With the database's damping used as it is (`irf.passivity = "none"`), a radiation memory that
    /// creates energy can make the free motion grow. From a small velocity on every active state, no
    /// waves, over the memory's length (at least 60 s): Err when the energy (v^T M v + x^T C x) / 2 over
    /// the run's last quarter exceeds [`FREE_MOTION_GROWTH`] times its start.
    fn check_free_motion(&self) -> Result<()> {
        let n = self.n();
        let v0: Vec<f64> = (0..n).map(|r| 0.01 / (1.0 + r as f64)).collect();
        let x0 = vec![0.0; n];
        let memory = Memory::new(self);
        let memory_s = match &self.kernel {
            Kernel::Convolution { taps, .. } => *taps as f64 * self.opts.dt_s,
            Kernel::StateSpace { .. } => 300.0,
        };
        let length_s = memory_s.clamp(60.0, 600.0);
        let mut fc = Forecaster::new();
        let req = ForecastRequest {
            x0: &x0,
            v0: &v0,
            memory: &memory,
            waves: &[],
            length_s,
            ramp_s: 0.0,
            drift_velocity: None,
            track: None,
        };
        let refuse = |why: String| {
            Error::Input(format!(
                "irf.passivity = \"none\": {why}: the database's damping creates energy (not positive semi-definite); use passivity = \"project\""
            ))
        };
        let f = fc
            .forecast(self, &req)
            .map_err(|e| refuse(format!("the free motion diverged ({e})")))?;
        let energy = |k: usize| {
            let (mut e, nm) = (0.0, self.n_modes);
            for (r, &i) in self.active.iter().enumerate() {
                for (c, &j) in self.active.iter().enumerate() {
                    e += 0.5 * self.mass[(r, c)] * f.v[k * nm + i] * f.v[k * nm + j];
                    e += 0.5 * self.stiffness_linearized[(r, c)] * f.x[k * nm + i] * f.x[k * nm + j];
                }
            }
            e
        };
        let start = energy(0);
        let late = (3 * f.steps / 4..=f.steps).map(energy).fold(0.0, f64::max);
        if late.is_nan() || late > FREE_MOTION_GROWTH * start {
            return Err(refuse(format!(
                "the free motion's energy grew {:.3e} times in {length_s:.0} s",
                late / start
            )));
        }
        Ok(())
    }
}
