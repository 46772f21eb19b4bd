//! Subcommands of the `shipcast` binary that have grown past a few lines (shell: wiring only).

pub mod console;
pub mod daemon;
pub mod horizon;
pub mod replay;
