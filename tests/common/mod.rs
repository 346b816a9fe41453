//! Helpers shared by the integration tests: shipped campaigns and levels.
#![allow(dead_code, reason = "each test binary uses a different subset")]

use cryoslosh::campaign::Campaign;
use cryoslosh::fluids::Fluid;
use cryoslosh::model::state::vapor_energy_offset;
use std::path::PathBuf;

pub mod fixture;
pub mod gpu;
pub mod parity;
pub mod report;

/// Every shipped campaign.
pub const CAMPAIGNS: [&str; 7] = [
    "lh2_upper_stage",
    "lox_ascent",
    "lch4_coast",
    "mhtb_selfpress",
    "aydelott_sphere",
    "methalox_autogenous",
    "ln2_slosh_destratification",
];

/// The physics levels (MODEL.md §1).
pub const LEVELS: [&str; 4] = ["homogeneous", "lumped", "two_mode", "layered"];

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

/// Every shipped campaign at every level under both integrators, loaded with `overrides` after
/// the level and integrator: `f("name/level/integrator", campaign)`.
pub fn each_campaign_level_integrator(overrides: &[&str], mut f: impl FnMut(&str, Campaign)) {
    for name in CAMPAIGNS {
        for level in LEVELS {
            for integrator in ["rk4", "dopri5"] {
                let level_set = format!("campaign.fidelity={level}");
                let integrator_set = format!("campaign.integrator={integrator}");
                let mut sets = vec![level_set.as_str(), integrator_set.as_str()];
                sets.extend_from_slice(overrides);
                f(&format!("{name}/{level}/{integrator}"), load(name, &sets));
            }
        }
    }
}

/// Path of a validation CSV in ../shared/validation, if the shared folder is beside the repo.
pub fn validation_csv(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/validation")
        .join(name)
}

/// du/dT of the saturated two-phase mixture at temperature t, J/(kg·K), at fixed specific volume
/// v (m³/kg): u(T) = u_l + x (u_v − u_l), x = (v − v_l)/(v_v − v_l), written from the property
/// fits (u_l = h_l − P_sat/ρ_l, v_v = 1/ρ_v,sat, u_v = u⁰(T) + offset + u_res) and differenced
/// over ±1 mK, independently of the model's Newton solve and state layout.
pub fn mixture_du_dt(fluid: Fluid, v: f64, t: f64) -> f64 {
    let f = fluid.props();
    let u = |t: f64| {
        let (vl, vv) = (1.0 / f.rho_l_kg_per_m3(t), 1.0 / f.rho_v_sat_kg_per_m3(t));
        let x = (v - vl) / (vv - vl);
        let ul = f.h_l_j_per_kg(t) - f.psat_pa(t) * vl;
        let uv =
            f.vapor_ideal(t).0 + vapor_energy_offset(fluid) + f.vapor_u_res_j_per_kg(t, 1.0 / vv);
        ul + x * (uv - ul)
    };
    let h = 1e-3;
    (u(t - 2.0 * h) - 8.0 * u(t - h) + 8.0 * u(t + h) - u(t + 2.0 * h)) / (12.0 * h)
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

/// Integrate `campaigns` as one lane group (`simulate_lanes`) and assert that each lane's summary
/// is bit for bit the one of that instance integrated alone (`what` names the case in a
/// failure); returns the lanes' summaries.
pub fn lanes_equal_one_at_a_time(
    campaigns: &[Campaign],
    what: &str,
) -> Vec<cryoslosh::simulate::Summary> {
    use cryoslosh::simulate::{simulate, simulate_lanes};
    let members: Vec<_> = campaigns.iter().map(|c| (c, &c.params)).collect();
    let lanes = simulate_lanes(&members);
    assert_eq!(lanes.len(), campaigns.len(), "{what}");
    for (i, (c, lane)) in campaigns.iter().zip(&lanes).enumerate() {
        let one = simulate(c, &c.params, None);
        assert_eq!(format!("{lane:?}"), format!("{one:?}"), "{what}: lane {i}");
    }
    lanes
}

/// `cryoslosh check` of shipped campaign `name` with `--set` overrides `sets`.
pub fn check_shipped(name: &str, sets: &[&str]) -> std::process::Output {
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_cryoslosh"));
    cmd.arg("check").arg(campaign_path(name));
    for s in sets {
        cmd.args(["--set", s]);
    }
    cmd.output().unwrap()
}
