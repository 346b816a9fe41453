//! cryoslosh: Monte Carlo dispersion engine for cryogenic propellant tanks — thermal
//! stratification, slosh, pressurization, venting and suction margin (see MODEL.md).
//!
//! The CLI (`src/main.rs`) adds nothing this library cannot do: load a [`campaign::Campaign`],
//! [`simulate::simulate`] an instance, write its history with [`history::write_history`].

pub mod campaign;
pub mod fluids;
pub mod geometry;
pub mod history;
pub mod model;
pub mod output;
pub mod simulate;

/// Crate version, recorded in every output file.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
