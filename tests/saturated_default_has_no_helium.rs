//! A liquid saturated at the ullage pressure (no temperature given) used to start with 2.9e-11 Pa of helium on MHTB, the fits' P_sat(T_sat(P)) residue, so the helium paths ran for nothing.

mod common;
use common::{load, LEVELS};
use cryoslosh::fluids::Fluid;
use cryoslosh::model::derive::{derive, Drive};
use cryoslosh::model::state::{default_helium_pressure_pa, M_G, SATURATED_RESIDUE};
use cryoslosh::model::Group;
use cryoslosh::simulate::initial_state;

/// MHTB (LH2 saturated at 111.5 kPa) and the same tank with `subcooling_k = 0`, at every level:
/// no helium in the parameters or the state, the stated pressure as vapour, the layer at the
/// liquid.
#[test]
fn saturated_default_ullage_holds_no_helium() {
    for (level, subcooling) in LEVELS
        .iter()
        .flat_map(|l| [(l, ""), (l, "propellant.subcooling_k=0")])
    {
        let fidelity = format!("campaign.fidelity={level}");
        let sets: Vec<&str> = [fidelity.as_str(), subcooling]
            .into_iter()
            .filter(|s| !s.is_empty())
            .collect();
        let c = load("mhtb_selfpress", &sets);
        let p = &c.params;
        assert_eq!(p.ullage_helium_partial_pressure_pa, 0.0, "{sets:?}");
        let s = initial_state(&c, p);
        assert_eq!(s[M_G], 0.0, "{sets:?}");
        let x = derive(
            Group::one(p),
            &s,
            &Drive::of_phase(&c.phases[0], 0.0, Default::default()),
        );
        assert!(
            (x.p_ullage_pa / p.ullage_pressure_pa - 1.0).abs() < 1e-12,
            "{sets:?}: {} Pa",
            x.p_ullage_pa
        );
        assert_eq!(x.p_ullage_pa, x.p_vapor_pa, "{sets:?}");
        assert_eq!(
            p.stratification.initial_temperature_k,
            p.liquid_temperature_k
        );
    }
}

/// The residue rule keeps real helium: one kelvin of subcooling leaves kilopascals of it, and a
/// difference just above 1e-13 P_u is kept as given.
#[test]
fn subcooled_default_keeps_its_helium() {
    let c = load("mhtb_selfpress", &["propellant.subcooling_k=1"]);
    let p = &c.params;
    assert!(
        p.ullage_helium_partial_pressure_pa > 1.0e4,
        "{}",
        p.ullage_helium_partial_pressure_pa
    );
    let s = initial_state(&c, p);
    assert!(s[M_G] > 0.0);
    let fluid = p.fluid;
    let t = p.liquid_temperature_k;
    let psat = fluid.props().psat_pa(t);
    let just_above = psat * (1.0 + 2.0e-13);
    assert!(default_helium_pressure_pa(fluid, just_above, t) > 0.0);
    // Half the residue share above P_sat: helium before, none now.
    assert_eq!(
        default_helium_pressure_pa(fluid, psat * (1.0 + 0.5e-13), t),
        0.0
    );
}

/// The residue share holds on every fluid's saturated range: a liquid at T_sat(P) gets no helium
/// at 400 log-spaced pressures from P_sat at the fits' lowest temperature to P_sat at their
/// highest, so that `SATURATED_RESIDUE` is larger than the round trip P_sat(T_sat(P)) everywhere.
#[test]
fn saturation_round_trip_is_within_the_residue_share_on_every_fluid() {
    for fluid in Fluid::ALL {
        let f = fluid.props();
        let (lo, hi) = (f.psat_pa(f.t_min_k).ln(), f.psat_pa(f.t_max_k).ln());
        let mut worst = 0.0_f64;
        for k in 0..400 {
            let p = (lo + (hi - lo) * k as f64 / 399.0)
                .exp()
                .min(f.psat_pa(f.t_max_k));
            let t = f.tsat_k(p);
            worst = worst.max((p - f.psat_pa(t)) / p);
            assert_eq!(
                default_helium_pressure_pa(fluid, p, t),
                0.0,
                "{}: {p} Pa, T_sat {t} K, P_sat(T_sat) {} Pa",
                fluid.name(),
                f.psat_pa(t)
            );
        }
        assert!(worst < SATURATED_RESIDUE, "{}: {worst}", fluid.name());
    }
}
