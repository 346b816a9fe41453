//! The initial ullage composition, the layer's initial temperature and the pressurant gas:
//! keys that depend on one another (helium + vapour = ullage pressure, vapour no denser than
//! saturation at the ullage temperature), checked together so the message names both.

use super::{number, Checker};
use crate::campaign::raw::{RawPressurization, RawStratification, RawUllage};
use crate::campaign::CampaignError;
use crate::fluids::Fluid;
use crate::model::params::PressurantGas;
use crate::model::state::{
    default_helium_pressure_pa, default_layer_temperature_k, vapor_partial_pressure_pa,
};

/// The resolved initial composition: helium partial pressure, Pa, and the layer's initial
/// temperature, K.
pub(super) struct Composition {
    pub helium_partial_pressure_pa: f64,
    pub layer_temperature_k: f64,
}

/// `ullage.helium_partial_pressure_pa` in [0, P_u] (default P_u − min(P_sat(T_l), P_u)); the
/// vapour partial pressure P_u − P_He at most P_sat(T_u) (more would be supersaturated vapour);
/// `stratification.initial_temperature_k` in [T_min, T_sat(P_u)] (default T_sat(P_u − P_He)).
pub(super) fn composition(
    c: &Checker,
    fluid: Fluid,
    ullage: &RawUllage,
    strat: &RawStratification,
    (p_ullage_pa, t_liquid_k, t_ullage_k): (f64, f64, f64),
) -> Result<Composition, CampaignError> {
    let f = fluid.props();
    let helium_key = "ullage.helium_partial_pressure_pa";
    let p_he = c.opt_range(
        helium_key,
        ullage.helium_partial_pressure_pa,
        default_helium_pressure_pa(fluid, p_ullage_pa, t_liquid_k),
        0.0,
        p_ullage_pa,
    )?;
    let p_v = vapor_partial_pressure_pa(fluid, p_ullage_pa, p_he, t_liquid_k);
    // The surface layer saturates the vapour: above P_sat(t_max) it would have to leave the
    // fluid's fitted range at the first step (issue 13's attack: LOX, pure vapour at 4 MPa).
    let p_v_max = f.psat_pa(f.t_max_k);
    if p_v > p_v_max * (1.0 + 1.0e-12) {
        return Err(c.err(
            helium_key,
            number(p_he),
            format!(
                "at least {} Pa: the vapour partial pressure ullage.pressure_pa − {helium_key} = {} Pa \
                 is above {} Pa, P_sat at {} K, the top of {}'s property fits (0.93 T_crit); add \
                 helium or lower ullage.pressure_pa",
                number(p_ullage_pa - p_v_max),
                number(p_v),
                number(p_v_max),
                number(f.t_max_k),
                fluid.name()
            ),
        ));
    }
    if t_ullage_k < f.t_max_k {
        let p_sat_u = f.psat_pa(t_ullage_k);
        if p_v > p_sat_u * (1.0 + 1.0e-12) {
            return Err(c.err(
                helium_key,
                number(p_he),
                format!(
                    "at least {} Pa: the vapour partial pressure ullage.pressure_pa − {helium_key} = {} Pa \
                     would exceed P_sat = {} Pa at ullage.temperature_k = {} K (supersaturated \
                     vapour; warm the ullage or add helium)",
                    number(p_ullage_pa - p_sat_u),
                    number(p_v),
                    number(p_sat_u),
                    number(t_ullage_k)
                ),
            ));
        }
    }
    let t_sat_u = f.tsat_k(p_ullage_pa.min(f.psat_pa(f.t_max_k)));
    let layer = c.opt_range(
        "stratification.initial_temperature_k",
        strat.initial_temperature_k,
        default_layer_temperature_k(fluid, t_liquid_k, p_v).min(t_sat_u),
        f.t_min_k,
        t_sat_u,
    )?;
    Ok(Composition {
        helium_partial_pressure_pa: p_he,
        layer_temperature_k: layer,
    })
}

/// `pressurization.gas`: helium (default) or autogenous. Autogenous vapour must enter no colder
/// than saturation at the setpoint, or it would be supersaturated as it arrives.
pub(super) fn pressurant_gas(
    c: &Checker,
    fluid: Fluid,
    ps: &RawPressurization,
) -> Result<PressurantGas, CampaignError> {
    let gas = match ps.gas.as_deref().unwrap_or("helium") {
        "helium" => PressurantGas::Helium,
        "autogenous" => PressurantGas::Autogenous,
        other => return Err(c.err("pressurization.gas", other, "helium | autogenous")),
    };
    if gas == PressurantGas::Autogenous {
        let f = fluid.props();
        // Saturation at the setpoint must lie inside the fits for the inlet bound below to hold.
        let p_max = f.psat_pa(f.t_max_k);
        if ps.setpoint_pa > p_max {
            return Err(c.err(
                "pressurization.setpoint_pa",
                number(ps.setpoint_pa),
                format!(
                    "at most {} Pa with pressurization.gas = \"autogenous\": P_sat at {} K, the top \
                     of {}'s property fits (0.93 T_crit)",
                    number(p_max),
                    number(f.t_max_k),
                    fluid.name()
                ),
            ));
        }
        let t_sat = f.tsat_k(
            ps.setpoint_pa
                .clamp(f.psat_pa(f.t_min_k), f.psat_pa(f.t_max_k)),
        );
        c.range(
            "pressurization.gas_temperature_k",
            ps.gas_temperature_k,
            t_sat,
            600.0,
        )
        .map_err(|_| {
            c.err(
                "pressurization.gas_temperature_k",
                number(ps.gas_temperature_k),
                format!(
                    "a finite number in [{}, 600] with pressurization.gas = \"autogenous\": \
                     {} vapour below T_sat at pressurization.setpoint_pa = {} Pa condenses",
                    number(t_sat),
                    fluid.name(),
                    number(ps.setpoint_pa)
                ),
            )
        })?;
    }
    Ok(gas)
}
