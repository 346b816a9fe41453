//! Helpers shared by the integration tests: shipped campaigns and levels.
#![allow(dead_code, reason = "each test binary uses a different subset")]

use cryoslosh::campaign::Campaign;
use cryoslosh::fluids::Fluid;
use cryoslosh::model::state::vapor_enthalpy_offset;
use std::path::PathBuf;

/// Every shipped campaign.
pub const CAMPAIGNS: [&str; 6] = [
    "lh2_upper_stage",
    "lox_ascent",
    "lch4_coast",
    "mhtb_selfpress",
    "aydelott_sphere",
    "methalox_autogenous",
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

/// du/dT of the saturated two-phase mixture at temperature t, J/(kg·K), per the closed form.
pub fn mixture_du_dt(fluid: Fluid, v: f64, t: f64) -> f64 {
    let f = fluid.props();
    let r = f.r_specific_j_per_kg_k();
    let (p, dp) = (f.psat_pa(t), f.dpsat_dt_pa_per_k(t));
    let rho = f.rho_l_kg_per_m3(t);
    let (vl, dvl) = (1.0 / rho, -f.drho_l_dt(t) / (rho * rho));
    let (vv, dvv) = (r * t / p, r / p - r * t * dp / (p * p));
    let x = (v - vl) / (vv - vl);
    let dx = (-dvl * (vv - vl) - (v - vl) * (dvv - dvl)) / ((vv - vl) * (vv - vl));
    let ul = f.h_l_j_per_kg(t);
    let uv = f.cv_vapor_j_per_kg_k * t + vapor_enthalpy_offset(fluid);
    f.cp_l_j_per_kg_k(t) + dx * (uv - ul) + x * (f.cv_vapor_j_per_kg_k - f.cp_l_j_per_kg_k(t))
}

/// Whether `python3` can import `modules` (e.g. "pyarrow, polars"); panics instead of skipping
/// when CI requires Python (`CRYOSLOSH_REQUIRE_PYTHON`).
pub fn python_with(modules: &str) -> bool {
    let have = std::process::Command::new("python3")
        .args(["-c", &format!("import {modules}")])
        .status()
        .is_ok_and(|s| s.success());
    if !have {
        assert!(
            std::env::var_os("CRYOSLOSH_REQUIRE_PYTHON").is_none(),
            "python3 with {modules} is required"
        );
        eprintln!("skipped: python3 with {modules} not available");
    }
    have
}

/// A fresh scratch directory for test binary `tag`'s case `name` (removed first if a previous
/// run left it).
pub fn scratch_in(tag: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cryoslosh-{tag}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Run the cryoslosh binary with `args`, killed at `failpoint` (the `CRYOSLOSH_FAILPOINT` test
/// hook) when one is given.
pub fn cryoslosh_at(args: &[&str], failpoint: Option<&str>) -> std::process::Output {
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_cryoslosh"));
    cmd.args(args);
    match failpoint {
        Some(f) => cmd.env("CRYOSLOSH_FAILPOINT", f),
        None => cmd.env_remove("CRYOSLOSH_FAILPOINT"),
    };
    cmd.output().unwrap()
}
