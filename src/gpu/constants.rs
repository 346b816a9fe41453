//! Every number the WGSL kernel shares with the CPU model, emitted as WGSL `const`s from the
//! Rust definitions (state slots, flags, diverged reasons, physical constants, thresholds), so
//! that the shaders never hold a copy that could drift.

use super::params::{exc, fidelity_code, flag, kernel_slots, phase_code, DIVERGED_REASONS};
use crate::fluids::R_UNIVERSAL;
use crate::model::flight::PhaseKind;
use crate::model::flight::{EARTH_RADIUS_M, G0, P_SEA_LEVEL_PA, RHO_SEA_LEVEL, SCALE_HEIGHT_M};
use crate::model::params::Fidelity;
use crate::model::slosh::MIN_AXIAL_ACCEL;
use crate::model::state;

/// WGSL `const` declarations of every number the kernel shares with the CPU model, for the
/// kernel of the `layered` level (its state type St holds the column's slots) or of the others.
pub fn constants_wgsl(layered: bool) -> String {
    let slots = kernel_slots(layered);
    let mut s = format!("alias St = array<f32, {slots}>;\n");
    let mut u = |name: &str, v: u32| s += &format!("const {name}: u32 = {v}u;\n");
    u("NS", slots as u32);
    u("COL", state::COL as u32);
    u("NL_MAX", state::NL_MAX as u32);
    for (name, v) in [
        ("M_V", state::M_V),
        ("M_G", state::M_G),
        ("U_U", state::U_U),
        ("M_S", state::M_S),
        ("H_S", state::H_S),
        ("M_B", state::M_B),
        ("H_B", state::H_B),
        ("E_WD", state::E_WD),
        ("E_WW", state::E_WW),
        ("Q1", state::Q1),
        ("Q1D", state::Q1D),
        ("Q2", state::Q2),
        ("Q2D", state::Q2D),
        ("VEL", state::VEL),
        ("ALT", state::ALT),
        ("P_FILT", state::P_FILT),
        ("VENT_V", state::VENT_V),
        ("VENT_G", state::VENT_G),
        ("OUT", state::OUT),
        ("PRESS_IN", state::PRESS_IN),
        ("E_ENV", state::E_ENV),
        ("E_PRESS", state::E_PRESS),
        ("E_VENT", state::E_VENT),
        ("E_OUT", state::E_OUT),
        ("E_WORK", state::E_WORK),
        ("E_PUMP", state::E_PUMP),
        ("VENT_TVS", state::VENT_TVS),
    ] {
        u(name, v as u32);
    }
    for (name, v) in [
        ("FLAG_EVAP_COEFF", flag::EVAP_COEFF),
        ("FLAG_H_US", flag::H_US),
        ("FLAG_H_SB", flag::H_SB),
        ("FLAG_H_WALL_ULLAGE", flag::H_WALL_ULLAGE),
        ("FLAG_H_WALL_LIQUID", flag::H_WALL_LIQUID),
        ("FLAG_PRESSURIZATION", flag::PRESSURIZATION),
        ("FLAG_RELIEF", flag::RELIEF),
        ("FLAG_AUTOGENOUS", flag::AUTOGENOUS),
        ("FLAG_INSULATION", flag::INSULATION),
        ("FLAG_MLI", flag::MLI),
        ("FLAG_MIXER", flag::MIXER),
        ("FLAG_TVS", flag::TVS),
        (
            "INSULATION_OUTER_ITERATIONS",
            crate::model::insulation::OUTER_ITERATIONS,
        ),
        (
            "INSULATION_INNER_ITERATIONS",
            crate::model::insulation::INNER_ITERATIONS,
        ),
        (
            "INSULATION_FOAM_ITERATIONS",
            crate::model::insulation::FOAM_ITERATIONS,
        ),
        ("EXC_NONE", exc::NONE),
        ("EXC_STEP", exc::STEP),
        ("EXC_RAMP", exc::RAMP),
        ("EXC_SINE", exc::SINE),
        ("EXC_SWEEP", exc::SWEEP),
        ("EXC_GUST", exc::GUST),
        ("EXC_TABLE", exc::TABLE),
        ("FID_HOMOGENEOUS", fidelity_code(Fidelity::Homogeneous)),
        ("FID_LUMPED", fidelity_code(Fidelity::Lumped)),
        ("FID_TWO_MODE", fidelity_code(Fidelity::TwoMode)),
        ("FID_LAYERED", fidelity_code(Fidelity::Layered)),
        ("PHASE_HOLD", phase_code(PhaseKind::Hold)),
        ("PHASE_BURN", phase_code(PhaseKind::Burn)),
        ("PHASE_COAST", phase_code(PhaseKind::Coast)),
        ("DIVERGED_STEP_SIZE", (DIVERGED_REASONS.len() - 1) as u32),
        (
            "STIFF_BLEND_ORDER",
            crate::model::thermal::STIFF_BLEND_ORDER,
        ),
    ] {
        u(name, v);
    }
    for (name, v) in [
        ("G0", G0),
        ("P_SEA_LEVEL_PA", P_SEA_LEVEL_PA),
        ("RHO_SEA_LEVEL", RHO_SEA_LEVEL),
        ("SCALE_HEIGHT_M", SCALE_HEIGHT_M),
        ("EARTH_RADIUS_M", EARTH_RADIUS_M),
        ("MIN_AXIAL_ACCEL", MIN_AXIAL_ACCEL),
        ("R_UNIVERSAL", R_UNIVERSAL),
        ("MIN_WALL_SHARE", crate::model::derive::MIN_WALL_SHARE),
        ("MIN_DEPTH_RATIO", crate::model::slosh::MIN_DEPTH_RATIO),
        ("BULK_MERGE_FRACTION", crate::model::BULK_MERGE_FRACTION),
        ("EXCHANGER_PINCH_K", crate::model::tvs::EXCHANGER_PINCH_K),
        ("BULK_MERGE_DRAIN_S", crate::model::BULK_MERGE_DRAIN_S),
        ("SLOSH_BOND_MIN", crate::simulate::SLOSH_BOND_MIN),
        ("SLOSH_ANGLE_MAX_RAD", crate::simulate::SLOSH_ANGLE_MAX_RAD),
        (
            "DEPLETION_RESIDUAL_FRACTION",
            crate::simulate::DEPLETION_RESIDUAL_FRACTION,
        ),
        (
            "PRESSURANT_EMPTY_FRACTION",
            crate::simulate::PRESSURANT_EMPTY_FRACTION,
        ),
        (
            "ADAPTIVE_STEPS_PER_PERIOD",
            crate::simulate::adaptive::ADAPTIVE_STEPS_PER_PERIOD,
        ),
        (
            "MIN_STEP_FRACTION",
            crate::simulate::adaptive::MIN_STEP_FRACTION,
        ),
        ("DOPRI_ERROR_ORDER", crate::model::dopri::ERROR_ORDER),
        (
            "MIN_INSULATION_TEMPERATURE_K",
            crate::model::insulation::MIN_INSULATION_TEMPERATURE_K,
        ),
        (
            "MLI_RADIATION_EXPONENT",
            crate::model::insulation::MLI_RADIATION_EXPONENT,
        ),
        (
            "MLI_GAS_EXPONENT",
            crate::model::insulation::MLI_GAS_EXPONENT,
        ),
        (
            "BL_LAMINAR_COEFFICIENT",
            crate::model::boundary_layer::LAMINAR_COEFFICIENT,
        ),
        (
            "BL_TURBULENT_COEFFICIENT",
            crate::model::boundary_layer::TURBULENT_COEFFICIENT,
        ),
    ] {
        s += &format!("const {name}: f32 = {v:e};\n");
    }
    s
}
