//! Dispersion sampling: scalar input distributions sampled by inverse CDF, sampling designs
//! (plain Monte Carlo, Latin hypercube, Owen-scrambled Sobol, Saltelli) and Gaussian-copula
//! correlated pairs.
//!
//! # Contract
//!
//! The unit sample of instance `i`, dimension `d` depends only on
//! `(design, seed, n, i, d, k_inputs)` — see [`unit_sample`] — never on threads, chunking or
//! sharding, so any instance of a campaign can be regenerated on its own. Every distribution maps
//! a unit value `u ∈ (0, 1)` through its inverse CDF ([`Distribution::quantile`]), so every design
//! feeds every distribution the same way, and the stratification of a design carries over to the
//! sampled physical values.
//!
//! Nothing here allocates per sample or panics; invalid parameters are reported by
//! [`Distribution::validate`], which callers run once when a campaign is loaded.

mod design;
mod distribution;

pub use design::{saltelli_layout, unit_sample, Design, SaltelliRow, MAX_SOBOL_DIMS};
pub use distribution::{correlate, Distribution, DistributionError};
