//! shipcast: real-time motion forecasts for one or more ships, from a Cummins reduced-order model driven
//! by a measured phase-resolved wave field (see README.md, ARCHITECTURE.md and DESIGN.md).
//!
//! Functional core (pure, no IO, no clocks, no async): [`hydro`], [`rao`], [`rom`], [`waves`], [`sim`], [`skill`], [`operation`], [`console`].
//! Imperative shell: [`files`] and [`scenario`] (reading from disk), [`report`] (`db check`'s report), [`ipc`] (iceoryx2 ports), [`record`] (MCAP logs), [`replay`] (logs through the daemon), [`process`] (children),
//! [`service`] (the daemon) and the `shipcast` binary.

// Index loops read like the matrix formulas they implement (i, j, k as in the equations).
#![allow(clippy::needless_range_loop)]

pub mod band;
pub mod console;
pub mod engine;
pub mod files;
pub mod hydro;
pub mod ipc;
pub mod link;
pub mod operation;
pub mod process;
pub mod radiation;
pub mod rao;
pub mod record;
pub mod replay;
pub mod report;
pub mod rom;
pub mod scenario;
pub mod service;
pub mod sim;
pub mod skill;
pub mod waves;
