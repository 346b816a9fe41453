//! Campaign statistics: moments, percentiles with distribution-free
//! confidence intervals, Wilks tolerance bounds, exceedance probabilities
//! with Clopper–Pearson intervals, Spearman correlations with Fisher-z
//! intervals and Sobol sensitivities with bootstrap intervals.
//!
//! After a Monte Carlo campaign every quantity of interest (QoI, e.g.
//! `peak_pressure_pa`) is a column of `f64` values, one per instance. Diverged
//! instances are excluded by the caller; missing values inside a column are
//! encoded as NaN and are skipped here, with every result reporting `n`, the
//! number of values actually used. The functions in this module are pure and
//! never panic: degenerate inputs (empty columns, constant columns, mismatched
//! lengths, invalid confidence levels) produce NaN rather than an error, so a
//! single bad QoI never aborts the statistics of a whole campaign.
//!
//! Results are laid out as tidy [`StatRow`]s
//! `(quantity, statistic, threshold, value, ci_low, ci_high, n)`, the row
//! format of `statistics.parquet`.

mod beta;
mod bootstrap;
mod paired;
mod quantile;
mod sensitivity;
mod summary;
mod tolerance;

pub use paired::{
    finite_quantile, newcombe_paired, newcombe_unpaired, paired_differences, wilson, Estimate,
    PairedDifferences, PairedTable,
};
pub use quantile::{is_constant, quantile_interval, quantile_interval_min_n};
pub use sensitivity::{
    sobol_analysis, sobol_indices, spearman, spearman_interval, SobolAnalysis, SobolEstimate,
    SobolIndices, SobolOptions,
};
pub use summary::{
    clopper_pearson, describe, exceedance, percentile, Direction, Exceedance, StatRow, PERCENTILES,
};
pub use tolerance::{tolerance_bound, wilks_min_samples, Side, Tolerance};
