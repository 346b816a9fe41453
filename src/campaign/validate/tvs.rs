//! `[tvs]`: the thermodynamic vent system (`model::tvs`, docs/PHYSICS.md 2.7) with its ranges,
//! the rules that tie its band to the relief valve and the regulator, and the per-phase `tvs`
//! switches.

use super::{number, Checker};
use crate::campaign::raw::{RawCampaign, RawPhase};
use crate::campaign::{CampaignError, Integrator};
use crate::fluids::Fluid;
use crate::model::flight::Phase;
use crate::model::params::{Fidelity, Pressurization, Relief};
use crate::model::tvs::Tvs;

/// Largest pump heat the TVS's recirculation pump may dissipate in the propellant, W.
pub const MAX_PUMP_HEAT_W: f64 = 1.0e5;

/// Most fixed RK4 steps per spray exchange time V_l / Q a campaign may ask for (as
/// `validate::mixer::MIN_STEPS_PER_EXCHANGE_TIME`).
pub const MIN_STEPS_PER_SPRAY_TIME: f64 = 2.0;

/// Narrowest band the TVS may hold, as a share of `band_upper_pa`: a pressure transducer's
/// accuracy (0.1 % of reading). A 1 Pa band started the TVS 39 000 times in a day (found by a
/// user's attack); the step count and the history grow without bound as the band closes.
pub const MIN_BAND_SHARE: f64 = 1.0e-3;

/// Validate `[tvs]` (`None` when the campaign has none) for propellant `fluid` with initial
/// liquid temperature `t_liquid_k` (K), against the relief valve `relief` (the band must lie
/// below its crack) and `tank.meop_pa` = `meop_pa` (Pa).
pub(super) fn tvs(
    c: &Checker,
    raw: &RawCampaign,
    fluid: Fluid,
    (t_liquid_k, meop_pa): (f64, f64),
    relief: Option<&Relief>,
) -> Result<Option<Tvs>, CampaignError> {
    let Some(r) = raw.tvs.as_ref() else {
        return Ok(None);
    };
    let required = |key: &str, v: Option<f64>| {
        v.ok_or_else(|| c.err(key, "(missing)", "a value: every [tvs] needs it"))
    };
    let f = fluid.props();
    let upper = required("tvs.band_upper_pa", r.band_upper_pa)?;
    let upper = c.positive("tvs.band_upper_pa", upper, 1.0e8)?;
    if upper > meop_pa {
        return Err(c.err(
            "tvs.band_upper_pa",
            number(upper),
            format!("at most tank.meop_pa = {}", number(meop_pa)),
        ));
    }
    if let Some(rv) = relief {
        if upper >= rv.crack_pa {
            return Err(c.err(
                "tvs.band_upper_pa",
                number(upper),
                format!(
                    "below relief.crack_pa = {} (the valve would vent before the TVS starts)",
                    number(rv.crack_pa)
                ),
            ));
        }
    }
    // The J-T outlet boils at T_sat(P_jt): inside the fits, below the band, and colder than
    // the liquid it is to cool.
    let p_min = f.psat_pa(f.t_min_k).ceil();
    let lower_in = required("tvs.band_lower_pa", r.band_lower_pa)?;
    let widest = upper * (1.0 - MIN_BAND_SHARE);
    if !(lower_in.is_finite() && lower_in > p_min && lower_in <= widest) {
        return Err(c.err(
            "tvs.band_lower_pa",
            number(lower_in),
            format!(
                "a finite number in ({}, {}]: above the J-T outlet's lowest pressure and at \
                 least {} % below tvs.band_upper_pa = {}",
                number(p_min),
                number(widest),
                100.0 * MIN_BAND_SHARE,
                number(upper)
            ),
        ));
    }
    let outlet = required("tvs.jt_outlet_pa", r.jt_outlet_pa)?;
    let liquid_psat = f.psat_pa(t_liquid_k);
    let below = lower_in.min(liquid_psat);
    if !(outlet.is_finite() && outlet >= p_min && outlet < below) {
        return Err(c.err(
            "tvs.jt_outlet_pa",
            number(outlet),
            format!(
                "a finite number in [{}, {}): at least the fits' lowest saturation pressure, \
                 below tvs.band_lower_pa = {} and below P_sat = {} Pa of the initial liquid \
                 (the vented flow must boil colder than the liquid it cools)",
                number(p_min),
                number(below),
                number(lower_in),
                number(liquid_psat.round())
            ),
        ));
    }
    let flow = c.positive(
        "tvs.jt_flow_kg_s",
        required("tvs.jt_flow_kg_s", r.jt_flow_kg_s)?,
        10.0,
    )?;
    let pump_flow = c.opt_range("tvs.pump_flow_m3_s", r.pump_flow_m3_s, 0.0, 0.0, 10.0)?;
    let pump_heat = c.opt_range("tvs.pump_heat_w", r.pump_heat_w, 0.0, 0.0, MAX_PUMP_HEAT_W)?;
    Ok(Some(Tvs::new(
        f,
        (upper, lower_in),
        (flow, outlet),
        (pump_flow, pump_heat),
    )))
}

/// The per-phase switches: `phases.N.tvs` only with a `[tvs]` section; no regulator set at or
/// above the band's lower pressure in a phase where both run (the TVS would vent the
/// pressurant it admits and never stop); and a fixed RK4 step that resolves the spray's
/// exchange time V_l / Q (initial liquid volume `liquid_volume_m3`, m³) where the TVS runs on
/// the levels with a layer and a bulk.
pub(super) fn phases(
    c: &Checker,
    (tvs, pressurization): (Option<&Tvs>, Option<&Pressurization>),
    raw: &[RawPhase],
    phases: &[Phase],
    (integrator, fidelity): (Integrator, Fidelity),
    liquid_volume_m3: f64,
) -> Result<(), CampaignError> {
    let Some(t) = tvs else {
        return match raw.iter().position(|ph| ph.tvs.is_some()) {
            Some(i) => Err(c.err(
                &format!("phases.{i}.tvs"),
                raw[i].tvs.unwrap_or_default(),
                "no per-phase TVS switch without a [tvs] section",
            )),
            None => Ok(()),
        };
    };
    if let Some(ps) = pressurization {
        if let Some(i) = phases
            .iter()
            .position(|ph| ph.tvs && ph.pressurize && ps.setpoint_pa >= t.band_lower_pa)
        {
            return Err(c.err(
                "pressurization.setpoint_pa",
                number(ps.setpoint_pa),
                format!(
                    "below tvs.band_lower_pa = {} where both run (phases.{i}), or switch one of \
                     them off there (phases.{i}.pressurize or phases.{i}.tvs = false)",
                    number(t.band_lower_pa)
                ),
            ));
        }
    }
    if integrator != Integrator::Rk4 || fidelity == Fidelity::Homogeneous || t.pump_flow_m3_s <= 0.0
    {
        return Ok(());
    }
    let tau = liquid_volume_m3 / t.pump_flow_m3_s;
    match phases
        .iter()
        .position(|ph| ph.tvs && ph.steps().1 * MIN_STEPS_PER_SPRAY_TIME > tau)
    {
        Some(i) => Err(c.err(
            "tvs.pump_flow_m3_s",
            number(t.pump_flow_m3_s),
            format!(
                "a flow whose spray exchange time V_l / Q = {} s spans at least {} fixed steps \
                 of phases.{i} (dt {} s): lower the flow, shorten the phase's dt_s or use \
                 campaign.integrator = \"dopri5\"",
                number(tau),
                MIN_STEPS_PER_SPRAY_TIME,
                number(phases[i].steps().1)
            ),
        )),
        None => Ok(()),
    }
}
