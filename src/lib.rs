//! shipcast: real-time motion forecasts for one or more ships, from a Cummins reduced-order model driven
//! by a measured phase-resolved wave field (see README.md, ARCHITECTURE.md and DESIGN.md).
//!
//! Functional core (pure: no IO, no clocks, no async): the database [`hydro`], [`radiation`], the
//! frequency domain [`rao`], [`waves`], the time-domain model [`rom`], the forecast's band [`band`], the
//! daemon's decisions [`engine`], the configuration's values [`settings`], the simulated truth [`sim`],
//! scoring [`skill`] and [`operation`], the console's state [`console`]. Imperative shell: [`shell`]
//! (the daemon's loop, iceoryx2, logs, replay, the link, files) and the `shipcast` binary.

// Index loops read like the matrix formulas they implement (i, j, k as in the equations).
#![allow(clippy::needless_range_loop)]

pub mod band;
pub mod console;
pub mod engine;
pub mod hydro;
pub mod operation;
pub mod radiation;
pub mod rao;
pub mod rom;
pub mod settings;
pub mod shell;
pub mod sim;
pub mod skill;
pub mod tuning;
pub mod waves;
