//! Helpers shared by the integration tests: shipped campaigns and levels.
#![allow(dead_code, reason = "each test binary uses a different subset")]

use cryoslosh::campaign::Campaign;
use std::path::PathBuf;

/// Every shipped campaign.
pub const CAMPAIGNS: [&str; 5] = [
    "lh2_upper_stage",
    "lox_ascent",
    "lch4_coast",
    "mhtb_selfpress",
    "aydelott_sphere",
];

/// The physics levels implemented so far.
pub const LEVELS: [&str; 3] = ["homogeneous", "lumped", "two_mode"];

/// Path of a shipped campaign.
pub fn campaign_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("campaigns")
        .join(format!("{name}.toml"))
}

/// Load a shipped campaign with overrides, panicking with the error text on failure.
pub fn load(name: &str, overrides: &[&str]) -> Campaign {
    let sets: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    Campaign::load(&campaign_path(name), &sets).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Path of a validation CSV in ../shared/validation, if the shared folder is beside the repo.
pub fn validation_csv(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/validation")
        .join(name)
}
