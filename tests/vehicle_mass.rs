//! A restart stretched past the oxidizer on board (`lh2_upper_stage`, restart 2000 s) drove the
//! vehicle's mass to its 1 kg floor, 853 m/s² and then NaN in a `bulk_merged` event: such a
//! campaign is now refused naming `vehicle.dry_mass_kg` and the bound, and a tank run dry
//! inside the bound ends as an outcome.

mod common;
use common::{campaign_path, check_shipped, cryoslosh_at};

#[test]
fn a_burn_longer_than_the_other_propellants_on_board_is_refused_naming_the_dry_mass() {
    let o = check_shipped("lh2_upper_stage", &["phases.restart.duration_s=1000"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("vehicle.dry_mass_kg = 22000"), "{err}");
    // Independently: 110 kN at I_sp 450 s for 400 + 1000 s, 84.62 % of it not this tank's
    // (5367 kg of LH2 drawn, less than the 6.6 t loaded, so the burns bind).
    let engine_kg = 110_000.0 / (450.0 * 9.806_65) * 1400.0;
    let other_kg = engine_kg * (1.0 - 0.1538);
    let printed: f64 = err
        .split("at least ")
        .nth(1)
        .and_then(|s| s.split(" kg").next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no bound in {err}"));
    assert!(
        printed >= other_kg && printed < other_kg * 1.001,
        "{printed} vs {other_kg}"
    );
}

#[test]
fn a_tank_run_dry_inside_the_bound_is_depleted_not_diverged() {
    let camp = campaign_path("lh2_upper_stage");
    let out =
        std::env::temp_dir().join(format!("cryoslosh-vehicle-{}.parquet", std::process::id()));
    let o = cryoslosh_at(
        &[
            "simulate",
            camp.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--set",
            "pressurization.setpoint_pa=185000",
            "--set",
            "phases.restart.duration_s=640",
            "--set",
            "propellant.fill_fraction=0.3",
        ],
        None,
    );
    let _ = std::fs::remove_file(&out);
    let text = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(text.contains("DEPLETED"), "{text}");
    assert!(
        !text.contains("DIVERGED") && !text.contains("NaN"),
        "{text}"
    );
}
