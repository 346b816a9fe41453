//! Autogenous pressurization and the initial ullage composition: a tank pressurized with its own
//! vapour, or holding a warm pure-vapour ullage, used to be inexpressible (the ullage was always
//! helium plus vapour saturated at the liquid temperature). These pin the new keys' meaning:
//! the initial state matches them, every level conserves with them, an autogenous burn holds the
//! pressure with no helium, and bad values exit 2 naming the key.

mod common;
use common::{load, LEVELS};
use cryoslosh::campaign::Campaign;
use cryoslosh::fluids::Fluid;
use cryoslosh::model::derive::{derive, Drive};
use cryoslosh::model::state::{M_G, M_S, PRESS_IN};
use cryoslosh::model::Group;
use cryoslosh::simulate::{initial_state, simulate, History};
use std::path::PathBuf;
use std::process::Command;

/// A closed LN2 sphere at 246.5 kPa over 77.6 K liquid: P_sat(77.6 K) ≈ 104 kPa, so the default
/// composition would be 104 kPa vapour + 142 kPa helium; `helium` sets the helium partial
/// pressure (pure vapour needs an ullage above T_sat(246.5 kPa) ≈ 89 K: 100 K here).
fn ln2_closed(level: &str, extra: &str) -> String {
    format!(
        r#"
[campaign]
name = "ln2_warm_vapour"
fidelity = "{level}"
integrator = "dopri5"
dt_s = 1.0
output_interval_s = 60.0
instances = 1

[tank]
shape = "sphere"
radius_m = 1.0
heat_leak_w = 60.0
meop_pa = 1000000.0

[propellant]
fluid = "LN2"
fill_fraction = 0.7
temperature_k = 77.6

[ullage]
pressure_pa = 246500.0
temperature_k = 100.0
{extra}

[[phases]]
name = "hold"
kind = "hold"
duration_s = 1800.0
"#
    )
}

fn scratch_file(name: &str, text: &str) -> PathBuf {
    let d = common::scratch_in("autogenous", name);
    let p = d.join(format!("{name}.toml"));
    std::fs::write(&p, text).unwrap();
    p
}

fn from_text(name: &str, text: &str, sets: &[&str]) -> Campaign {
    let path = scratch_file(name, text);
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let c = Campaign::load(&path, &sets).unwrap_or_else(|e| panic!("{name}: {e}"));
    // Loaded whole: the scratch copy is not read again.
    std::fs::remove_dir_all(path.parent().unwrap()).ok();
    c
}

#[test]
fn warm_pure_vapour_ullage_conserves_on_every_level() {
    for level in LEVELS {
        let c = from_text(
            &format!("pure-{level}"),
            &ln2_closed(level, "helium_partial_pressure_pa = 0.0"),
            &[],
        );
        let mut h = History::default();
        let q = simulate(&c, &c.params, Some(&mut h));
        eprintln!(
            "{level:12} mass {:.2e} energy {:.2e} final {:.0} Pa",
            q.mass_error_rel, q.energy_error_rel, q.final_pressure_pa
        );
        assert!(!q.diverged, "{level}: {:?}", q.diverged_reason);
        assert!(
            q.mass_error_rel < 1e-9,
            "{level}: mass {:e}",
            q.mass_error_rel
        );
        assert!(
            q.energy_error_rel < 1e-6,
            "{level}: energy {:e}",
            q.energy_error_rel
        );
        let helium = h.column("helium_mass_kg").unwrap();
        assert!(helium.iter().all(|&m| m == 0.0), "{level}: helium appeared");
        assert!(q.boiloff_kg.is_finite() && q.final_pressure_pa.is_finite());
    }
}

#[test]
fn initial_state_matches_the_composition_keys() {
    let f = Fluid::Ln2.props();
    let t_sat = f.tsat_k(246_500.0);
    for (extra, p_he, t_layer) in [
        ("helium_partial_pressure_pa = 0.0", 0.0, t_sat),
        (
            "helium_partial_pressure_pa = 46500.0",
            46_500.0,
            f.tsat_k(200_000.0),
        ),
        (
            "helium_partial_pressure_pa = 0.0\n[stratification]\ninitial_temperature_k = 80.0",
            0.0,
            80.0,
        ),
        // Default: vapour saturated at the liquid, helium the rest, layer at the liquid.
        ("", 246_500.0 - f.psat_pa(77.6), 77.6),
    ] {
        let c = from_text("init", &ln2_closed("lumped", extra), &[]);
        let p = &c.params;
        assert!(
            (p.ullage_helium_partial_pressure_pa - p_he).abs() < 1e-6,
            "{extra}"
        );
        assert!(
            (p.stratification.initial_temperature_k - t_layer).abs() < 1e-9,
            "{extra}: layer {} K, expected {t_layer} K",
            p.stratification.initial_temperature_k
        );
        let s = initial_state(&c, p);
        let x = derive(
            Group::one(p),
            &s,
            &Drive::of_phase(&c.phases[0], 0.0, Default::default()),
        );
        assert!(
            (x.p_ullage_pa - 246_500.0).abs() < 1e-6 * 246_500.0,
            "{extra}: total {} Pa",
            x.p_ullage_pa
        );
        let helium = x.p_ullage_pa - x.p_vapor_pa;
        assert!(
            (helium - p_he).abs() < 1e-6 * 246_500.0,
            "{extra}: helium {helium} Pa, expected {p_he}"
        );
        assert!(
            (x.t_layer_k - t_layer).abs() < 1e-6,
            "{extra}: {}",
            x.t_layer_k
        );
        assert!((x.t_bulk_k - 77.6).abs() < 1e-6);
        assert!((x.t_ullage_k - 100.0).abs() < 1e-6);
        assert!(s[M_S] > 0.0 && (s[M_G] == 0.0) == (p_he == 0.0));
    }
}

#[test]
fn autogenous_burn_holds_pressure_with_vapour_only() {
    for level in LEVELS {
        let c = load(
            "methalox_autogenous",
            &[&format!("campaign.fidelity={level}")],
        );
        let mut h = History::default();
        let q = simulate(&c, &c.params, Some(&mut h));
        assert!(!q.diverged, "{level}: {:?}", q.diverged_reason);
        assert!(
            q.mass_error_rel < 1e-9 && q.energy_error_rel < 1e-6,
            "{level}: {q:?}"
        );
        let col = |n: &str| h.column(n).unwrap().to_vec();
        let (p, he) = (col("pressure_pa"), col("helium_mass_kg"));
        assert!(
            he.iter().all(|&m| m == 0.0),
            "{level}: helium in the ullage"
        );
        assert!(
            q.pressurant_used_kg > 1.0,
            "{level}: {}",
            q.pressurant_used_kg
        );
        assert!(
            q.propellant_drawn_kg > 10_000.0,
            "{level}: {}",
            q.propellant_drawn_kg
        );
        let setpoint = c.params.pressurization.unwrap().setpoint_pa;
        let (lo, hi) = p
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
        eprintln!(
            "{level:12} pressurant {:.1} kg, drawn {:.0} kg, boil-off {:.2} kg, pressure {lo:.0}–{hi:.0} Pa, mass {:.1e} energy {:.1e}",
            q.pressurant_used_kg, q.propellant_drawn_kg, q.boiloff_kg, q.mass_error_rel, q.energy_error_rel
        );
        if level == "homogeneous" {
            // An equilibrium tank cannot hold vapour above P_sat(T): the warm vapour condenses
            // into the 112 K liquid and the pressure stays near P_sat (docs/PHYSICS.md §10).
            assert!(hi < 0.6 * setpoint, "{level}: {hi} Pa");
            continue;
        }
        // The PD regulator holds the setpoint with vapour alone while the engine drains the
        // tank (its proportional droop is ≈2 %; the 0.03 rad wave at 83 s deepens the warm layer
        // by the wave's eddy diffusivity and the pressure dips 3.7 % on `lumped`, PHYSICS 6.4).
        assert!(!q.pressurant_exhausted, "{level}");
        assert!(
            lo > 0.95 * setpoint && hi < 1.01 * setpoint,
            "{level}: pressure {lo}–{hi} Pa against {setpoint} Pa"
        );
    }
}

#[test]
fn autogenous_pressurant_runs_out() {
    // A 5 kg budget cannot hold the pressure through the burn: the outcome still fires, and the
    // pressurant slot stops at the budget.
    let c = load("methalox_autogenous", &["pressurization.bottle_mass_kg=5"]);
    let q = simulate(&c, &c.params, None);
    assert!(q.pressurant_exhausted, "{q:?}");
    // The flow fades over the supply's last 0.1 %; a step may overrun it by a rounding-sized sliver.
    assert!(
        q.pressurant_used_kg <= 5.0 * (1.0 + 1e-3),
        "{}",
        q.pressurant_used_kg
    );
    assert!(q.mass_error_rel < 1e-9 && q.energy_error_rel < 1e-6);
}

#[test]
fn autogenous_inflow_is_vapour_not_helium() {
    // The same campaign with helium: helium appears in M_G; autogenous leaves M_G at zero and
    // books the inflow in PRESS_IN.
    let c = load("methalox_autogenous", &["pressurization.gas=helium"]);
    let mut h = History::default();
    let q = simulate(&c, &c.params, Some(&mut h));
    let he = h.column("helium_mass_kg").unwrap();
    assert!(
        he.last().copied().unwrap_or(0.0) > 1.0,
        "no helium admitted"
    );
    assert!((he.last().unwrap() - q.pressurant_used_kg).abs() < 1e-6 * q.pressurant_used_kg);
    let c = load("methalox_autogenous", &[]);
    let s0 = initial_state(&c, &c.params);
    assert_eq!(s0[M_G], 0.0);
    assert_eq!(s0[PRESS_IN], 0.0);
}

fn check(path: &std::path::Path, sets: &[&str]) -> (Option<i32>, String) {
    let mut args = vec!["check".to_string(), path.to_str().unwrap().to_string()];
    for s in sets {
        args.push("--set".into());
        args.push(s.to_string());
    }
    let o = Command::new(env!("CARGO_BIN_EXE_cryoslosh"))
        .args(&args)
        .output()
        .unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn bad_composition_and_pressurant_keys_exit_2_naming_them() {
    let ln2 = scratch_file("bad", &ln2_closed("lumped", ""));
    let methalox = common::campaign_path("methalox_autogenous");
    for (path, set, key) in [
        (
            &ln2,
            "ullage.helium_partial_pressure_pa=-1",
            "ullage.helium_partial_pressure_pa",
        ),
        (
            &ln2,
            "ullage.helium_partial_pressure_pa=300000",
            "ullage.helium_partial_pressure_pa",
        ),
        (
            &ln2,
            "ullage.helium_partial_pressure_pa=nan",
            "ullage.helium_partial_pressure_pa",
        ),
        // Pure vapour at 246.5 kPa and 80 K: P_sat(80 K) ≈ 137 kPa, supersaturated.
        (
            &ln2,
            "ullage.temperature_k=80",
            "ullage.helium_partial_pressure_pa",
        ),
        (
            &ln2,
            "stratification.initial_temperature_k=20",
            "stratification.initial_temperature_k",
        ),
        (
            &ln2,
            "stratification.initial_temperature_k=95",
            "stratification.initial_temperature_k",
        ),
        (
            &methalox,
            "pressurization.gas=\"argon\"",
            "pressurization.gas",
        ),
        (
            &methalox,
            "pressurization.gas_temperature_k=100",
            "pressurization.gas_temperature_k",
        ),
    ] {
        let sets: Vec<&str> = if path == &ln2 && set.starts_with("ullage.temperature_k") {
            vec!["ullage.helium_partial_pressure_pa=0", set]
        } else {
            vec![set]
        };
        let (code, err) = check(path, &sets);
        assert_eq!(code, Some(2), "{set}: {err}");
        assert!(err.contains(key), "{set}: {err}");
        assert!(
            err.contains(path.file_name().unwrap().to_str().unwrap()),
            "{set}: {err}"
        );
    }
    let (code, err) = check(
        &ln2,
        &[
            "ullage.helium_partial_pressure_pa=0",
            "ullage.temperature_k=80",
        ],
    );
    assert_eq!(code, Some(2));
    assert!(
        err.contains("supersaturated") && err.contains("ullage.temperature_k"),
        "{err}"
    );
    std::fs::remove_dir_all(ln2.parent().unwrap()).ok();
}

#[test]
fn composition_keys_are_dispersible() {
    // The shipped campaign disperses the helium partial pressure and the layer temperature;
    // each instance resolves them like the nominal.
    let c = load("methalox_autogenous", &[]);
    let keys: Vec<&str> = c
        .dispersions
        .inputs
        .iter()
        .map(|i| i.key.as_str())
        .collect();
    assert!(keys.contains(&"ullage.helium_partial_pressure_pa"));
    assert!(keys.contains(&"stratification.initial_temperature_k"));
    let i = c.instance(&[300.0, 2500.0, 120.0, 1.0e6]).unwrap();
    assert_eq!(i.params.ullage_helium_partial_pressure_pa, 2500.0);
    assert_eq!(i.params.stratification.initial_temperature_k, 120.0);
    assert_eq!(i.params.pressurization.unwrap().gas_temperature_k, 300.0);
}

#[test]
fn helium_and_autogenous_lanes_share_a_group_exactly() {
    // The pressurant gas is a per-lane share, not a group-wide switch: a lane group mixing
    // helium and autogenous members equals each run alone, bit for bit.
    use cryoslosh::lanes::WIDTH;
    use cryoslosh::simulate::simulate_lanes;
    let gases = ["pressurization.gas=helium", "pressurization.gas=autogenous"];
    let cs: Vec<Campaign> = (0..WIDTH)
        .map(|i| {
            load(
                "methalox_autogenous",
                &[gases[i % 2], "phases.burn.duration_s=60"],
            )
        })
        .collect();
    assert!(cs.iter().all(|c| cs[0].params.lane_compatible(&c.params)));
    let members: Vec<_> = cs.iter().map(|c| (c, &c.params)).collect();
    let grouped = simulate_lanes(&members);
    for (c, q) in cs.iter().zip(&grouped) {
        let alone = simulate(c, &c.params, None);
        assert_eq!(format!("{q:?}"), format!("{alone:?}"));
    }
    assert_ne!(format!("{:?}", grouped[0]), format!("{:?}", grouped[1]));
}
