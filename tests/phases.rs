//! Per-phase quantities of interest (issue 11): each phase's amounts add up to the mission's and
//! its extremes bound the mission's on every shipped campaign and level under both integrators;
//! a phase's pressure rise in a closed tank matches the closed-form rate; phases an instance
//! never entered are nulls in instances.parquet; phase names are unique column suffixes.

mod common;
use common::{campaign_path, each_campaign_level_integrator, mixture_du_dt};
use cryoslosh::campaign::Campaign;
use cryoslosh::montecarlo::table;
use cryoslosh::simulate::{simulate, History, Summary};
use std::path::Path;
use std::process::Command;

/// |a − b| within `rel` of the larger magnitude (and of `floor`).
fn close(a: f64, b: f64, rel: f64, floor: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(floor)
}

fn check_phases_against_mission(what: &str, q: &Summary, n_phases: usize) {
    assert!(!q.diverged, "{what}: {:?}", q.diverged_reason);
    assert_eq!(q.phases.len(), n_phases, "{what}: phases entered");
    let sum = |f: fn(&cryoslosh::simulate::PhaseSummary) -> f64| q.phases.iter().map(f).sum();
    let (boiloff, vented): (f64, f64) = (sum(|p| p.boiloff_kg), sum(|p| p.vented_kg));
    // The amounts are differences of the same cumulative values the mission's are: they add
    // up to rounding of the cumulative magnitude.
    assert!(
        close(boiloff, q.boiloff_kg, 1e-9, 1e-6),
        "{what}: phases boil off {boiloff} kg, the mission {} kg",
        q.boiloff_kg
    );
    assert!(
        close(vented, q.vented_kg, 1e-9, 1e-6),
        "{what}: phases vent {vented} kg, the mission {} kg",
        q.vented_kg
    );
    let max = |f: fn(&cryoslosh::simulate::PhaseSummary) -> f64| {
        q.phases.iter().map(f).fold(f64::NEG_INFINITY, f64::max)
    };
    let min_p = q
        .phases
        .iter()
        .map(|p| p.min_pressure_pa)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(max(|p| p.peak_pressure_pa), q.peak_pressure_pa, "{what}");
    assert_eq!(min_p, q.min_pressure_pa, "{what}");
    assert_eq!(
        max(|p| p.max_slosh_angle_rad),
        q.max_slosh_angle_rad,
        "{what}"
    );
    let margins: Vec<f64> = q
        .phases
        .iter()
        .filter_map(|p| p.min_cavitation_margin_m)
        .collect();
    assert_eq!(
        margins.iter().copied().reduce(f64::min),
        q.min_cavitation_margin_m,
        "{what}"
    );
    for p in &q.phases {
        assert!(p.pressure_rise_pa() >= 0.0, "{what}: {}", p.name);
        assert!(
            p.min_pressure_pa <= p.start_pressure_pa,
            "{what}: {}",
            p.name
        );
    }
}

#[test]
fn phase_amounts_add_up_to_the_mission_and_extremes_bound_it() {
    each_campaign_level_integrator(&[], |what, c| {
        let q = simulate(&c, &c.params, None);
        check_phases_against_mission(what, &q, c.phases.len());
    });
}

/// A closed homogeneous LN2 sphere held in two phases: each phase's pressure rise is the
/// closed-form dP/dt = P_sat'(T) Q / (M du/dT + C_wall) (as in tests/homogeneous.rs) integrated
/// over the phase by the trapezoidal rule on its start and end temperatures.
#[test]
fn closed_tank_pressure_rise_per_phase_matches_closed_form() {
    let q_w = 200.0;
    let text = format!(
        "[campaign]\nfidelity = \"homogeneous\"\noutput_interval_s = 10.0\n[tank]\nshape = \"sphere\"\nradius_m = 0.8\nheat_leak_w = {q_w}\nwall_areal_mass_kg_per_m2 = 0.01\nmeop_pa = 1.0e7\n[propellant]\nfluid = \"LN2\"\nfill_fraction = 0.6\n[ullage]\npressure_pa = 101325.0\n[[phases]]\nname = \"first\"\nkind = \"hold\"\nduration_s = 1800.0\ndt_s = 1.0\n[[phases]]\nname = \"second\"\nkind = \"hold\"\nduration_s = 1800.0\ndt_s = 1.0\n"
    );
    let c = Campaign::from_text(Path::new("two_holds.toml"), &text, &[]).unwrap();
    let mut h = History::default();
    let q = simulate(&c, &c.params, Some(&mut h));
    check_phases_against_mission("two holds", &q, 2);
    let f = c.params.fluid;
    let (t, tb) = (
        h.column("time_s").unwrap(),
        h.column("bulk_temp_k").unwrap(),
    );
    let total_mass = h.column("liquid_mass_kg").unwrap()[0] + h.column("vapor_mass_kg").unwrap()[0];
    let v = c.params.tank.volume_m3() / total_mass;
    let wall = c.params.wall_areal_mass_kg_per_m2
        * c.params.tank.wall_area_m2()
        * c.params.wall_cp_j_per_kg_k;
    let rate = |temp: f64| {
        f.props().dpsat_dt_pa_per_k(temp) * q_w / (total_mass * mixture_du_dt(f, v, temp) + wall)
    };
    // The second phase: the wall has settled into tracking the fluid (the first phase's start
    // carries the wall's initial transient, which the closed form leaves out).
    let (t0, t1) = (1800.0, 3600.0);
    let at = |time: f64| t.iter().position(|&x| (x - time).abs() < 1e-6).unwrap();
    let closed_form = 0.5 * (rate(tb[at(t0)]) + rate(tb[at(t1)])) * (t1 - t0);
    let rise = q.phases[1].pressure_rise_pa();
    eprintln!("second hold: rise {rise:.3} Pa, closed form {closed_form:.3} Pa");
    assert!(
        close(rise, closed_form, 1e-4, 0.0),
        "{rise} vs {closed_form}"
    );
    assert_eq!(q.phases[1].start_pressure_pa, q.phases[0].peak_pressure_pa);
}

/// The LOX ascent burned for 200 s runs dry in the burn: a coast after it is never entered,
/// and its columns in instances.parquet are nulls while the burn's have values.
#[test]
fn phases_never_entered_are_nulls_in_the_instances_file() {
    let dir = std::env::temp_dir().join(format!("cryoslosh-phases-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string(campaign_path("lox_ascent")).unwrap()
        + "\n[[phases]]\nname = \"after\"\nkind = \"coast\"\nduration_s = 10.0\ndt_s = 0.02\n";
    let campaign = dir.join("lox_dry.toml");
    std::fs::write(&campaign, text).unwrap();
    let out = dir.join("run");
    let status = Command::new(env!("CARGO_BIN_EXE_cryoslosh"))
        .args([
            "run",
            campaign.to_str().unwrap(),
            "--instances",
            "8",
            "--out",
        ])
        .arg(&out)
        .args(["--set", "phases.ascent.duration_s=200"])
        .output()
        .unwrap();
    assert!(
        status.status.code().is_some_and(|c| c == 0 || c == 3),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let file = out.join("instances.parquet");
    let depleted = table::read_bool(&file, "depleted").unwrap();
    assert!(depleted.iter().all(|&d| d), "every instance runs dry");
    let names: Vec<String> = table::read_schema(&file)
        .unwrap()
        .into_iter()
        .map(|(n, _)| n)
        .collect();
    for (qoi, _) in table::PHASE_QOIS {
        for phase in ["pad", "ascent", "after"] {
            assert!(names.contains(&format!("{qoi}.{phase}")), "{qoi}.{phase}");
        }
        let after = table::read_f64(&file, &format!("{qoi}.after")).unwrap();
        assert!(after.iter().all(|v| v.is_nan()), "{qoi}.after: {after:?}");
    }
    for qoi in ["peak_pressure_pa", "boiloff_kg", "min_cavitation_margin_m"] {
        let ascent = table::read_f64(&file, &format!("{qoi}.ascent")).unwrap();
        assert!(
            ascent.iter().all(|v| v.is_finite()),
            "{qoi}.ascent: {ascent:?}"
        );
    }
    // The pad hold draws nothing: its cavitation margin is null, not zero.
    let pad = table::read_f64(&file, "min_cavitation_margin_m.pad").unwrap();
    assert!(pad.iter().all(|v| v.is_nan()));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn phase_names_must_be_unique_column_suffixes() {
    let base = std::fs::read_to_string(campaign_path("mhtb_selfpress")).unwrap();
    let long = format!(
        "\n[[phases]]\nname = \"{}\"\nkind = \"hold\"\nduration_s = 10.0\n",
        "a".repeat(65)
    );
    for (extra, key, why) in [
        (
            "\n[[phases]]\nname = \"lockup\"\nkind = \"hold\"\nduration_s = 10.0\n",
            "phases.1.name",
            "no other phase",
        ),
        (
            "\n[[phases]]\nname = \"a.b\"\nkind = \"hold\"\nduration_s = 10.0\n",
            "phases.1.name",
            "letters, digits",
        ),
        (
            "\n[[phases]]\nname = \"2\"\nkind = \"hold\"\nduration_s = 10.0\n",
            "phases.1.name",
            "not a number",
        ),
        (
            "\n[[phases]]\nname = \"-1e3\"\nkind = \"hold\"\nduration_s = 10.0\n",
            "phases.1.name",
            "not a number",
        ),
        (
            "\n[[phases]]\nname = \"LOCKUP\"\nkind = \"hold\"\nduration_s = 10.0\n",
            "phases.1.name",
            "ignoring case",
        ),
        (long.as_str(), "phases.1.name", "1 to 64"),
    ] {
        let err = Campaign::from_text(Path::new("x.toml"), &(base.clone() + extra), &[])
            .unwrap_err()
            .to_string();
        assert!(err.contains(key) && err.contains(why), "{err}");
    }
}
