//! MODEL.md §10: mass to 1e-9 and energy to 1e-6 relative on every level and shipped campaign.

mod common;
use common::{load, CAMPAIGNS, LEVELS};
use cryoslosh::simulate::simulate;

#[test]
fn mass_and_energy_close_on_every_campaign_and_level() {
    for name in CAMPAIGNS {
        for level in LEVELS {
            let c = load(name, &[&format!("campaign.fidelity={level}")]);
            let q = simulate(&c, &c.params, None);
            assert!(
                !q.diverged,
                "{name}/{level} diverged: {:?}",
                q.diverged_reason
            );
            eprintln!(
                "{name:16} {level:12} mass {:.2e} energy {:.2e}",
                q.mass_error_rel, q.energy_error_rel
            );
            assert!(
                q.mass_error_rel < 1e-9,
                "{name}/{level}: mass error {:e}",
                q.mass_error_rel
            );
            assert!(
                q.energy_error_rel < 1e-6,
                "{name}/{level}: energy error {:e}",
                q.energy_error_rel
            );
        }
    }
}

#[test]
fn relief_venting_is_conservative_and_counted() {
    // The LCH4 coast vents: vented mass must be positive and the closure must still hold.
    let c = load("lch4_coast", &[]);
    let q = simulate(&c, &c.params, None);
    assert!(
        q.vented_kg > 0.1,
        "expected venting, got {} kg",
        q.vented_kg
    );
    assert!(q.peak_pressure_pa < 1.01 * c.params.relief.unwrap().crack_pa);
    assert!(q.mass_error_rel < 1e-9 && q.energy_error_rel < 1e-6);
}

#[test]
fn slosh_volume_coupling_work_is_accounted() {
    // Paper coupling I (ullage volume follows sin θ): its P dV work enters the energy ledger.
    let c = load("lox_ascent", &["slosh.volume_coupling_m3=0.05"]);
    let q = simulate(&c, &c.params, None);
    assert!(!q.diverged);
    assert!(
        q.mass_error_rel < 1e-9 && q.energy_error_rel < 1e-6,
        "{q:?}"
    );
}

/// The gain-scheduled regulator (`pressurization.gain_schedule`) on every level, through a burn
/// whose ullage grows: the pressurant it admits is in the ledgers like the fixed regulator's.
#[test]
fn scheduled_regulator_closes_mass_and_energy_on_every_level() {
    for level in LEVELS {
        let fid = format!("campaign.fidelity={level}");
        let c = load(
            "lox_ascent",
            &[&fid, "pressurization.gain_schedule=ullage_volume"],
        );
        let q = simulate(&c, &c.params, None);
        assert!(!q.diverged, "{level}: {:?}", q.diverged_reason);
        assert!(
            q.mass_error_rel < 1e-9 && q.energy_error_rel < 1e-6,
            "{level}: {q:?}"
        );
    }
}

/// The jet mixer (`[mixer]`) on every level, off in the coast: its pump heat is in the energy
/// ledger (`E_PUMP`) exactly as the power times the phases it runs in, and the closure holds
/// with it (integrated here step by step from the initial state, and through `simulate`).
#[test]
fn jet_mixer_adds_exactly_its_pump_heat_on_every_level() {
    use cryoslosh::model::derive::Drive;
    use cryoslosh::model::state::{energy_invariant, E_PUMP};
    use cryoslosh::model::{rk4_step, Group};
    use cryoslosh::simulate::{energy_scale, initial_state};
    let heat_w = 50.0;
    for level in LEVELS {
        let c = load(
            "lh2_upper_stage",
            &[
                &format!("campaign.fidelity={level}"),
                "mixer.pump_flow_m3_s=0.01",
                "mixer.nozzle_diameter_m=0.1",
                &format!("mixer.pump_heat_w={heat_w}"),
                "phases.coast.mixer=false",
            ],
        );
        let p = &c.params;
        let s0 = initial_state(&c, p);
        let mut s = s0;
        let mut on_s = 0.0;
        for ph in &c.phases {
            let (n, dt) = ph.steps();
            for k in 0..n {
                let drive = |t: f64| Drive::of_phase(ph, t, Default::default());
                rk4_step(Group::one(p), drive, &mut s, k as f64 * dt, dt, None);
            }
            if ph.mixer {
                on_s += ph.duration_s;
            }
        }
        assert_eq!(on_s, 720.0);
        let expected = heat_w * on_s;
        let pump_err = (s[E_PUMP] - expected).abs() / expected;
        let closure = (energy_invariant(&s) - energy_invariant(&s0)).abs() / energy_scale(&s0, &s);
        eprintln!(
            "{level:12} E_PUMP {:.3} J (expected {expected} J, rel {pump_err:.1e}), closure {closure:.1e}",
            s[E_PUMP]
        );
        assert!(pump_err < 1e-12, "{level}: E_PUMP {} J", s[E_PUMP]);
        assert!(closure < 1e-6, "{level}: closure {closure:e}");
        let q = simulate(&c, p, None);
        assert!(!q.diverged, "{level}: {:?}", q.diverged_reason);
        assert!(
            q.mass_error_rel < 1e-9 && q.energy_error_rel < 1e-6,
            "{level}: {q:?}"
        );
    }
}

/// The thermodynamic vent system (`[tvs]`) held on for two hours of the shipped coast on every
/// level: the vented mass is the J-T flow times the time (`VENT_TVS`), each kilogram carries
/// h_g(T_jt) out (`E_VENT`, the liquid staying warmer than T_jt), the pump heat is in `E_PUMP`,
/// and mass and energy close.
#[test]
fn tvs_vents_its_flow_at_the_vapour_enthalpy_on_every_level() {
    use cryoslosh::model::derive::{Drive, Switches};
    use cryoslosh::model::state::{energy_invariant, mass_invariant, E_PUMP, E_VENT, VENT_TVS};
    use cryoslosh::model::{rk4_step, Group};
    use cryoslosh::simulate::{energy_scale, initial_state};
    for level in LEVELS {
        let c = load(
            "lh2_tvs_coast",
            &[
                &format!("campaign.fidelity={level}"),
                "phases.0.duration_s=7200",
            ],
        );
        let p = &c.params;
        let tvs = p.tvs.unwrap();
        let s0 = initial_state(&c, p);
        let mut s = s0;
        let ph = &c.phases[0];
        let dt = 10.0;
        let on = Switches {
            relief: false,
            tvs: true,
        };
        for k in 0..720 {
            let drive = |t: f64| Drive::of_phase(ph, t, on);
            rk4_step(Group::one(p), drive, &mut s, k as f64 * dt, dt, None);
        }
        let vented = tvs.jt_flow_kg_s * 7200.0;
        let carried = tvs.vent_enthalpy_j_per_kg * s[VENT_TVS];
        let pump = tvs.pump_heat_w * 7200.0;
        let mass = (mass_invariant(&s) - mass_invariant(&s0)).abs() / mass_invariant(&s0);
        let closure = (energy_invariant(&s) - energy_invariant(&s0)).abs() / energy_scale(&s0, &s);
        eprintln!(
            "{level:12} VENT_TVS {:.6} kg (flow × time {vented:.6}), E_VENT {:.1} J (h_g × m {carried:.1}), E_PUMP {:.1} J, mass {mass:.1e}, energy {closure:.1e}",
            s[VENT_TVS], s[E_VENT], s[E_PUMP]
        );
        assert!((s[VENT_TVS] - vented).abs() <= 1e-12 * vented, "{level}");
        assert!((s[E_VENT] - carried).abs() <= 1e-12 * carried, "{level}");
        assert!((s[E_PUMP] - pump).abs() <= 1e-12 * pump, "{level}");
        assert!(mass < 1e-13, "{level}: mass {mass:e}");
        assert!(closure < 1e-12, "{level}: closure {closure:e}");
    }
}
