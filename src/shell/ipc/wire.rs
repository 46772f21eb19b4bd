//! The iceoryx2 wire types: what goes over shared memory, field by field (schema version 1; the
//! forecast's 2, the status's 4, the link's 1).
//!
//! Every payload is `#[repr(C)]` with a stable type name, so a C, C++ or Python subscriber can declare
//! the same layout (`tools/console/subscriber.py` does it with ctypes). Units SI; times are seconds on
//! the sensors' clock (the data clock: UNIX seconds for live sensors); frames as in DESIGN.md section 1
//! (earth: x east, y north; directions counterclockwise from east, travel-to; body: x forward, y port,
//! z up; DOFs surge, sway, heave, roll, pitch, yaw). A reader checks `schema_version` first and refuses
//! what it does not know.
//!
//! Services (names `<prefix>/<kind>`, each paired with an event service of the same name that is
//! notified after every send):
//! - `motion`: [`MotionSample`], one per IMU sample, any vessel.
//! - `navigation`: [`NavigationSample`], one per GNSS/gyro fix, any vessel (its own rate, 1-10 Hz).
//! - `elevation`: a slice of f32 with an [`ElevationHeader`]: one radar scan, `n_x * n_y` elevations (m)
//!   row by row (`values[iy * n_x + ix]`), NaN where the cell is not valid (blind zone, shadow, a
//!   masked sector, beyond the range). The daemon inverts a sequence of scans into a field itself.
//! - `waves`: a slice of f64 with a [`WaveHeader`] (schema version [`WAVES_SCHEMA_VERSION`]): 4 values
//!   per component: omega (rad/s), direction (rad, earth), Re and Im of the complex amplitude (m) at
//!   the header's reference point and time; then, if the header says so, the radar's coverage: the
//!   farthest point observed in each of `n_sectors` sectors of direction (m).
//! - `forecast`: a slice of f64 with a [`ForecastHeader`]: series-major, series s = 6 v + d (vessel v,
//!   DOF d), `steps + 1` displacements each at t = issue_time_s + k dt_s (m or rad); then as many
//!   standard deviations, same order (the forecast's band: `crate::band`). Schema version
//!   [`FORECAST_SCHEMA_VERSION`].
//! - `status`: [`Status`].
//! - `link`: [`LinkStatus`], from `shipcast link` (the ship-to-ship link), when one runs.

pub use crate::engine::message::*;
use crate::waves::field::FlatHeader;
use iceoryx2::prelude::*;

/// Header of a radar elevation scan (the processor's phase-resolved map). 64 bytes.
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[type_name("shipcast_ElevationHeader_v1")]
#[repr(C)]
pub struct ElevationHeader {
    pub schema_version: u32,
    /// Cells along the grid's x and y axes.
    pub n_x: u32,
    pub n_y: u32,
    pub reserved: u32,
    /// Scan time, s (data clock).
    pub time_s: f64,
    /// Centre of cell (0, 0) in the site's tangent plane, m east and m north.
    pub origin_east_m: f64,
    pub origin_north_m: f64,
    /// Cell spacing along the grid's x and y axes, m.
    pub spacing_x_m: f64,
    pub spacing_y_m: f64,
    /// Compass direction of the grid's +x axis, deg clockwise from true north (90: x east, y north).
    pub orientation_deg: f64,
}

/// The largest radar grid the daemon takes: cells along each axis (a 1024 x 1024 scan is 4 MB).
pub const MAX_GRID_CELLS: u32 = 1024;

/// Header of a wave-field sample. 80 bytes; `schema_version` = [`WAVES_SCHEMA_VERSION`].
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[type_name("shipcast_WaveHeader_v2")]
#[repr(C)]
pub struct WaveHeader {
    pub schema_version: u32,
    /// Number of components (4 f64 each in the payload).
    pub n_components: u32,
    /// Observation time the amplitudes refer to, s.
    pub time_s: f64,
    /// Reference point of the amplitudes, earth frame, m.
    pub ref_east_m: f64,
    pub ref_north_m: f64,
    /// Radius of the observed disc around the reference point, m (0: unknown, treated as everywhere;
    /// negative: a wave probe at the reference point).
    pub radius_m: f64,
    /// Water depth, m (0: infinite).
    pub depth_m: f64,
    pub g_m_s2: f64,
    /// A wave probe's fitted record, s (0: not said, or not a probe).
    pub window_s: f64,
    /// A radar's blind zone: nothing within this of the reference point was observed, m (0: none).
    pub inner_m: f64,
    /// A radar's coverage: the payload's last `n_sectors` values (after the components) are the
    /// farthest point observed in each of as many equal sectors of direction from the reference
    /// point, m (sector j spans j..j+1 times 360 / n_sectors deg, counterclockwise from east: what
    /// shadowing and a masked sector left). 0: the disc of `radius_m` (beyond `inner_m`). At most
    /// 3600.
    pub n_sectors: u32,
    pub reserved: u32,
}

impl WaveHeader {
    /// The header of a field of `n_components` components (this schema version), its coverage in
    /// `n_sectors` sectors after them.
    pub fn of(n_components: usize, n_sectors: usize, h: &FlatHeader) -> WaveHeader {
        WaveHeader {
            schema_version: WAVES_SCHEMA_VERSION,
            n_components: n_components as u32,
            time_s: h.time_s,
            ref_east_m: h.reference_m[0],
            ref_north_m: h.reference_m[1],
            radius_m: h.radius_m,
            depth_m: h.depth_m,
            g_m_s2: h.g_m_s2,
            window_s: h.window_s,
            inner_m: h.inner_m,
            n_sectors: n_sectors as u32,
            reserved: 0,
        }
    }

    /// The field's header numbers, with its coverage in [`crate::waves::field::COVERAGE_SECTORS`].
    pub fn flat(&self, ranges_m: Option<[f64; crate::waves::field::COVERAGE_SECTORS]>) -> FlatHeader {
        FlatHeader {
            time_s: self.time_s,
            reference_m: [self.ref_east_m, self.ref_north_m],
            radius_m: self.radius_m,
            depth_m: self.depth_m,
            g_m_s2: self.g_m_s2,
            window_s: self.window_s,
            inner_m: self.inner_m,
            ranges_m,
        }
    }
}

/// Marks the engine's messages for iceoryx2, with their stable type names.
macro_rules! zero_copy_send {
    ($($t:ident),*) => {$(
        // SAFETY: the message is `#[repr(C)]` of plain numbers and arrays of them, with no pointers
        // or references; its layout is the one `layouts_are_what_the_docs_say` checks.
        unsafe impl ZeroCopySend for $t {
            unsafe fn type_name() -> &'static str {
                $t::TYPE_NAME
            }
        }
    )*};
}

zero_copy_send!(MotionSample, NavigationSample, ForecastHeader, Status, LinkStatus);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layouts_are_what_the_docs_say() {
        assert_eq!(std::mem::size_of::<ElevationHeader>(), 64);
        assert_eq!(std::mem::size_of::<WaveHeader>(), 80);
    }
}
