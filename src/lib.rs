//! cryoslosh: Monte Carlo dispersion engine for cryogenic propellant tanks — thermal
//! stratification, slosh, pressurization, venting and suction margin (see MODEL.md).
//!
//! The CLI (`src/main.rs`) adds nothing this library cannot do: load a [`campaign::Campaign`],
//! [`simulate::simulate`] an instance, write its history with [`history::write_history`], or run
//! a dispersion campaign with [`montecarlo::run`] on an [`engine::Backend`].

pub mod campaign;
pub mod engine;
pub mod fluids;
pub mod geometry;
pub mod gpu;
pub mod history;
pub mod lanes;
pub mod model;
pub mod montecarlo;
pub mod output;
pub mod report;
pub mod runner;
pub mod sampling;
pub mod simulate;
pub mod stats;

/// Crate version, recorded in every output file.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
