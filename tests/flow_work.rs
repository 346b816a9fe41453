//! Liquid leaving a node carried its enthalpy without the flow work P/ρ, which the node's P dV term had paid: an isolated tank at uniform saturation drifted away from equilibrium and a drained bulk warmed (found by a new-user attack, 2026-12-02).

mod common;
use common::{load, LEVELS};
use cryoslosh::simulate::{simulate, History};

fn column<'a>(h: &'a History, name: &str) -> &'a [f64] {
    h.column(name)
        .unwrap_or_else(|| panic!("no history column {name}"))
}

/// The MHTB tank at 90 % fill, saturated at its lock-up pressure throughout, with no heat
/// leak: nothing may move. Before, the layer's growth from the bulk moved P/ρ per kilogram
/// from layer to bulk and the pressure fell by 463 Pa in ten minutes (ullage 12 mK colder).
#[test]
fn a_closed_saturated_tank_without_heat_stays_in_equilibrium() {
    for level in LEVELS {
        let c = load(
            "mhtb_selfpress",
            &[
                &format!("campaign.fidelity={level}"),
                "tank.heat_leak_w=0",
                "phases.lockup.duration_s=600",
            ],
        );
        let mut h = History::default();
        let s = simulate(&c, &c.params, Some(&mut h));
        assert!(!s.diverged, "{level}: diverged");
        let p = column(&h, "pressure_pa");
        let drift = p.iter().map(|v| (v - p[0]).abs()).fold(0.0, f64::max);
        assert!(
            drift < 1.0e-3,
            "{level}: pressure drifted {drift} Pa from {}",
            p[0]
        );
        for name in ["ullage_temp_k", "layer_temp_k", "bulk_temp_k"] {
            let t = column(&h, name);
            let drift = t.iter().map(|v| (v - t[0]).abs()).fold(0.0, f64::max);
            assert!(drift < 1.0e-6, "{level}: {name} drifted {drift} K");
        }
    }
}

/// The LH2 upper stage with no heat leak: its burns draw 2300 kg of 6630 from the bulk. The
/// bulk keeps its temperature (what warms it, 1 mK, is the layer above it, heated by the
/// warm pressurant); before, it kept the draw's flow work and ended 136 mK warmer.
#[test]
fn a_tank_drained_without_heat_keeps_its_bulk_temperature() {
    for level in ["lumped", "layered"] {
        let c = load(
            "lh2_upper_stage",
            &[&format!("campaign.fidelity={level}"), "tank.heat_leak_w=0"],
        );
        let mut h = History::default();
        let s = simulate(&c, &c.params, Some(&mut h));
        assert!(!s.diverged, "{level}: diverged");
        assert!(
            s.propellant_drawn_kg > 2000.0,
            "{level}: drew {} kg",
            s.propellant_drawn_kg
        );
        let t = column(&h, "bulk_temp_k");
        let rise = t.last().unwrap() - t[0];
        assert!(
            rise.abs() < 5.0e-3,
            "{level}: the bulk warmed {rise} K while draining"
        );
    }
}
