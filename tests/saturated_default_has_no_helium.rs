//! A liquid saturated at the ullage pressure (no temperature given) used to start with 2.9e-11 Pa of helium on MHTB, the fits' P_sat(T_sat(P)) residue, so the helium paths ran for nothing.

mod common;
use common::load;
use cryoslosh::model::derive::{derive, Drive};
use cryoslosh::model::state::{default_helium_pressure_pa, M_G};
use cryoslosh::model::Group;
use cryoslosh::simulate::initial_state;

/// MHTB (LH2 saturated at 111.5 kPa) and the same tank with `subcooling_k = 0`: no helium in
/// the parameters or the state, the stated pressure as vapour, the layer at the liquid.
#[test]
fn saturated_default_ullage_holds_no_helium() {
    for sets in [vec![], vec!["propellant.subcooling_k=0"]] {
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
    assert_eq!(default_helium_pressure_pa(fluid, psat, t), 0.0);
}
