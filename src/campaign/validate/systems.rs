//! The vehicle's systems around the tank: pressurization (regulator and pressurant), relief
//! valve, engine and feed line, and the vehicle itself, with ranges and the cross-field rules
//! between them (a relief valve above MEOP, a regulator set above the crack).

use super::{composition, number, Checker};
use crate::campaign::raw::{RawCampaign, RawPressurization};
use crate::campaign::CampaignError;
use crate::fluids::Fluid;
use crate::model::flight::{Phase, PhaseKind, G0};
use crate::model::params::{Feed, GainSchedule, Pressurization, Relief, Vehicle};
use crate::model::DEPLETION_RESIDUAL_FRACTION;

/// `[pressurization]`, if there is one, for propellant `fluid` in a tank of `tank_volume_m3`
/// (m³) filled to `fill_fraction`.
pub(super) fn pressurization(
    c: &Checker,
    raw: &RawCampaign,
    fluid: Fluid,
    tank_volume_m3: f64,
    fill_fraction: f64,
) -> Result<Option<Pressurization>, CampaignError> {
    raw.pressurization
        .as_ref()
        .map(|ps| -> Result<_, CampaignError> {
            Ok(Pressurization {
                setpoint_pa: c.positive("pressurization.setpoint_pa", ps.setpoint_pa, 1.0e8)?,
                kp_kg_per_s_pa: c.range(
                    "pressurization.kp_kg_per_s_pa",
                    ps.kp_kg_per_s_pa,
                    0.0,
                    1.0,
                )?,
                kd_kg_per_pa: c.opt_range(
                    "pressurization.kd_kg_per_pa",
                    ps.kd_kg_per_pa,
                    0.0,
                    0.0,
                    10.0,
                )?,
                derivative_filter_s: c.opt_range(
                    "pressurization.derivative_filter_s",
                    ps.derivative_filter_s,
                    1.0,
                    1.0e-3,
                    1.0e4,
                )?,
                max_flow_kg_per_s: c.positive(
                    "pressurization.max_flow_kg_per_s",
                    ps.max_flow_kg_per_s,
                    1.0e3,
                )?,
                gas_temperature_k: c.range(
                    "pressurization.gas_temperature_k",
                    ps.gas_temperature_k,
                    4.0,
                    600.0,
                )?,
                bottle_mass_kg: c.range(
                    "pressurization.bottle_mass_kg",
                    ps.bottle_mass_kg,
                    0.0,
                    1.0e5,
                )?,
                gain_schedule: gain_schedule(c, ps, tank_volume_m3, fill_fraction)?,
                // Last: its check reads the setpoint and inlet temperature validated above.
                gas: composition::pressurant_gas(c, fluid, ps)?,
            })
        })
        .transpose()
}

/// Smallest reference ullage of the gain schedule, as a share of the tank volume: a reference
/// of 1e-300 m³ multiplied the gains by 1e300 (found by a user's attack).
pub const MIN_SCHEDULE_REFERENCE_SHARE: f64 = 1.0e-4;

/// `pressurization.gain_schedule` (`"fixed"` by default, or `"ullage_volume"`) and its reference
/// ullage `schedule_reference_ullage_m3` in [[`MIN_SCHEDULE_REFERENCE_SHARE`]·V_tank, V_tank], by
/// default the initial ullage (1 − fill_fraction)·V_tank (at least that floor); the reference is
/// refused beside fixed gains, which never read it.
fn gain_schedule(
    c: &Checker,
    ps: &RawPressurization,
    tank_volume_m3: f64,
    fill_fraction: f64,
) -> Result<GainSchedule, CampaignError> {
    const REFERENCE: &str = "pressurization.schedule_reference_ullage_m3";
    match ps.gain_schedule.as_deref().unwrap_or("fixed") {
        "fixed" => match ps.schedule_reference_ullage_m3 {
            None => Ok(GainSchedule::Fixed),
            Some(v) => Err(c.err(
                REFERENCE,
                number(v),
                "no reference ullage with pressurization.gain_schedule = \"fixed\" (it scales \
                 the gains only with \"ullage_volume\")",
            )),
        },
        "ullage_volume" => {
            let reference_m3 = match ps.schedule_reference_ullage_m3 {
                Some(v) => c.range(
                    REFERENCE,
                    v,
                    MIN_SCHEDULE_REFERENCE_SHARE * tank_volume_m3,
                    tank_volume_m3,
                )?,
                None => ((1.0 - fill_fraction) * tank_volume_m3)
                    .max(MIN_SCHEDULE_REFERENCE_SHARE * tank_volume_m3),
            };
            Ok(GainSchedule::UllageVolume { reference_m3 })
        }
        other => Err(c.err(
            "pressurization.gain_schedule",
            other,
            "fixed | ullage_volume",
        )),
    }
}

/// `[relief]`, if there is one, checked against `tank.meop_pa` = `meop_pa` (Pa) and the
/// regulator's setpoint.
pub(super) fn relief(
    c: &Checker,
    raw: &RawCampaign,
    meop_pa: f64,
) -> Result<Option<Relief>, CampaignError> {
    raw.relief
        .as_ref()
        .map(|r| -> Result<_, CampaignError> {
            let crack = c.positive("relief.crack_pa", r.crack_pa, 1.0e8)?;
            // Cross-field rules: a valve that cracks above MEOP lets the tank pass it (allowed
            // only when stated); a regulator set above the crack vents its own pressurant.
            if crack > meop_pa && r.crack_above_meop != Some(true) {
                return Err(c.err(
                    "relief.crack_pa",
                    crack,
                    format!("at most tank.meop_pa = {meop_pa} (or relief.crack_above_meop = true)"),
                ));
            }
            if let Some(ps) = &raw.pressurization {
                if ps.setpoint_pa >= crack {
                    return Err(c.err(
                        "pressurization.setpoint_pa",
                        ps.setpoint_pa,
                        format!("below relief.crack_pa = {crack}"),
                    ));
                }
            }
            Ok(Relief {
                crack_pa: crack,
                reseat_pa: if r.reseat_pa < crack {
                    c.range("relief.reseat_pa", r.reseat_pa, 0.0, crack)?
                } else {
                    // A valve that reseats where it cracks would chatter every step.
                    return Err(c.err(
                        "relief.reseat_pa",
                        number(r.reseat_pa),
                        format!("below relief.crack_pa = {}", number(crack)),
                    ));
                },
                flow_area_m2: c.positive("relief.flow_area_m2", r.flow_area_m2, 10.0)?,
            })
        })
        .transpose()
}

/// `[engine]` and `[feed]`.
pub(super) fn feed(c: &Checker, raw: &RawCampaign) -> Result<Feed, CampaignError> {
    let fd = &raw.feed;
    Ok(Feed {
        isp_s: c.opt_range("engine.isp_s", raw.engine.isp_s, 450.0, 1.0, 1.0e4)?,
        propellant_fraction: c.opt_range(
            "engine.propellant_fraction",
            raw.engine.propellant_fraction,
            1.0,
            1.0e-3,
            1.0,
        )?,
        line_height_m: c.opt_range("feed.line_height_m", fd.line_height_m, 0.0, -100.0, 100.0)?,
        line_loss_pa: c.opt_range("feed.line_loss_pa", fd.line_loss_pa, 0.0, 0.0, 1.0e7)?,
        line_velocity_m_s: c.opt_range(
            "feed.line_velocity_m_s",
            fd.line_velocity_m_s,
            0.0,
            0.0,
            200.0,
        )?,
        npsh_required_m: c.opt_range(
            "feed.npsh_required_m",
            fd.npsh_required_m,
            0.0,
            0.0,
            1.0e4,
        )?,
    })
}

/// `[vehicle]`.
pub(super) fn vehicle(c: &Checker, raw: &RawCampaign) -> Result<Vehicle, CampaignError> {
    let v = &raw.vehicle;
    Ok(Vehicle {
        dry_mass_kg: c.opt_range("vehicle.dry_mass_kg", v.dry_mass_kg, 0.0, 0.0, 1.0e8)?,
        drag_area_m2: c.opt_range("vehicle.drag_area_m2", v.drag_area_m2, 0.0, 0.0, 1.0e4)?,
        initial_velocity_m_s: c.opt_range(
            "vehicle.initial_velocity_m_s",
            v.initial_velocity_m_s,
            0.0,
            -1.0e4,
            1.0e5,
        )?,
        initial_altitude_m: c.opt_range(
            "vehicle.initial_altitude_m",
            v.initial_altitude_m,
            0.0,
            0.0,
            1.0e9,
        )?,
        slosh_lever_arm_m: c.opt_range(
            "vehicle.slosh_lever_arm_m",
            v.slosh_lever_arm_m,
            0.0,
            -1.0e3,
            1.0e3,
        )?,
    })
}

/// The other propellants the burns draw before this tank can run dry,
/// min(Σ thrust/(I_sp g₀) · duration · f, (1 − r) m_l0) · (1 − f)/f over the burn phases (f:
/// `engine.propellant_fraction`, this tank's share of the engine flow; m_l0 the initial liquid
/// mass, `m_liquid0_kg`; r the residual at which it counts as dry,
/// [`DEPLETION_RESIDUAL_FRACTION`]), must fit in `vehicle.dry_mass_kg`, which holds them: a restart
/// stretched past the oxidizer on board left the vehicle at its 1 kg floor under 110 kN,
/// 853 m/s² and then NaN. A tank that runs dry first ends the instance (an outcome).
pub(super) fn other_propellants(
    c: &Checker,
    (feed, vehicle): (&Feed, &Vehicle),
    phases: &[Phase],
    m_liquid0_kg: f64,
) -> Result<(), CampaignError> {
    let f = feed.propellant_fraction;
    let tank_kg: f64 = phases
        .iter()
        .filter(|ph| ph.kind == PhaseKind::Burn)
        .map(|ph| ph.thrust_n / (feed.isp_s * G0) * ph.duration_s * f)
        .sum();
    let usable_kg = (1.0 - DEPLETION_RESIDUAL_FRACTION) * m_liquid0_kg;
    let other_kg = tank_kg.min(usable_kg) * (1.0 - f) / f;
    if other_kg > vehicle.dry_mass_kg {
        return Err(c.err(
            "vehicle.dry_mass_kg",
            number(vehicle.dry_mass_kg),
            format!(
                "at least {} kg: the burns draw that much of the other propellants \
                 (thrust/(engine.isp_s·g0) × duration × (1 − engine.propellant_fraction), \
                 until this tank runs dry), which the dry mass holds; shorten the burns or \
                 raise the dry mass",
                number((other_kg * 10.0).ceil() / 10.0)
            ),
        ));
    }
    Ok(())
}
