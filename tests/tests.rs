//! shipcast's integration tests: one binary, one module per subject. Validation modules are named for
//! the outside source they check against (Capytaine, WEC-Sim); every tolerance is a named constant with
//! a one-line reason.

mod util;

mod bad_input;
mod capytaine_barge;
mod capytaine_barge_speeds;
mod capytaine_close_pair;
mod capytaine_demo;
mod capytaine_messy_pair;
mod capytaine_offset_box;
mod cli;
mod console;
mod core_purity;
mod daemon;
mod external_models;
mod forecast_cli;
mod indep_barge_probe;
mod kramers_kronig;
#[cfg(feature = "link")]
mod link;
mod reach;
mod replay;
mod rom;
mod sim_truth;
mod tidy;
mod trust;
mod tuning;
mod two_ship_demo;
mod underway;
mod warm_start;
mod waves_fields;
mod wecsim_rm3;
mod wecsim_rm3_3dof;
