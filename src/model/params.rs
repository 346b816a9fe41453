//! The validated, resolved inputs of one tank instance: what the physics reads, in SI units.
//!
//! Produced by `campaign::validate` (ranges checked, defaults resolved); nothing downstream
//! re-validates. Every field states its unit; defaults and sources live in the campaign docs.

use crate::fluids::Fluid;
use crate::geometry::Tank;

/// Physics level (MODEL.md §1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fidelity {
    /// One saturated liquid node in equilibrium with a saturated ullage.
    Homogeneous,
    /// Ullage, stratified layer, bulk and wall nodes; nonlinear pendulum slosh.
    Lumped,
    /// The lumped thermal nodes with two spring–mass–damper slosh modes.
    TwoMode,
    /// A resolved liquid column of N layers with a wall boundary layer (`model::column`), and the
    /// two-mode slosh analog.
    Layered,
}

impl Fidelity {
    /// Campaign spelling.
    pub fn name(self) -> &'static str {
        match self {
            Fidelity::Homogeneous => "homogeneous",
            Fidelity::Lumped => "lumped",
            Fidelity::TwoMode => "two_mode",
            Fidelity::Layered => "layered",
        }
    }

    /// Whether the level's slosh analog is the two spring–mass–damper modes (`two_mode`,
    /// `layered`) rather than the pendulum (`lumped`) or none (`homogeneous`).
    pub fn two_mode_slosh(self) -> bool {
        matches!(self, Fidelity::TwoMode | Fidelity::Layered)
    }
}

/// The liquid column of the `layered` level (`model::column`, docs/PHYSICS.md 2.8).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layered {
    /// Number of layers N, in [1, `state::NL_MAX`].
    pub layers: u32,
    /// Ratio of each layer's mass to that of the layer above it, in [1, 2]: 1 is a uniform grid,
    /// above 1 the cells are finer towards the interface, where the gradients are.
    pub stretch: f64,
    /// Width of the wall boundary layer's neutral-buoyancy detrainment, K, in [1e-6, 1]
    /// (`column::DETRAIN_WIDTH_K` by default): a numerical smoothing, reported in the
    /// sensitivity table of docs/VALIDATION.md.
    pub detrain_width_k: f64,
}

/// Ring baffles (Miles 1958 damping, MODEL.md §5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Baffles {
    /// Number of rings (0 = none).
    pub count: u32,
    /// Radial ring width W, m.
    pub width_m: f64,
    /// Axial spacing between rings, m.
    pub spacing_m: f64,
    /// Height of the top ring above the tank bottom, m; lower rings sit `spacing_m` apart below it.
    pub top_height_m: f64,
    /// Wave amplitude at the wall η used by Miles' formula, m.
    pub wave_amplitude_m: f64,
}

/// Heat-transfer closures. `None` means "use the documented correlation".
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeatTransfer {
    /// Interfacial evaporation coefficient K, kg/(s·Pa); `None`: Schrage kinetic theory.
    pub evaporation_coefficient_kg_per_s_pa: Option<f64>,
    /// Schrage accommodation coefficient σ (0, 1].
    pub accommodation: f64,
    /// Ullage ↔ interface coefficient h_us, W/(m²·K).
    pub h_us_w_per_m2_k: Option<f64>,
    /// Layer ↔ bulk base coefficient h_0, W/(m²·K).
    pub h_sb_w_per_m2_k: Option<f64>,
    /// Dry wall ↔ ullage coefficient, W/(m²·K).
    pub h_wall_ullage_w_per_m2_k: Option<f64>,
    /// Wetted wall ↔ liquid coefficient, W/(m²·K).
    pub h_wall_liquid_w_per_m2_k: Option<f64>,
}

/// Growth and mixing of the warm surface layer (MODEL.md §4 ṁ_strat, §6.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stratification {
    /// Initial layer thickness, m.
    pub initial_thickness_m: f64,
    /// Multiplier on the molecular thermal diffusivity for the layer's penetration growth, –.
    pub diffusivity_factor: f64,
    /// Share of the bulk's wall heat that the wall boundary layer lifts into the surface layer
    /// (Tellep & Harper 1963); 0 is the paper's contact-area model, –.
    pub wall_heat_to_layer: f64,
    /// Initial temperature of the layer, K, in [fluid T_min, T_sat(P_ullage)]; resolved default:
    /// saturation at the initial vapour partial pressure (the liquid temperature exactly when
    /// that pressure is P_sat(T_l), today's default composition).
    pub initial_temperature_k: f64,
}

/// Slosh–thermal coupling constants (MODEL.md §6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coupling {
    /// Ullage volume amplitude c_V of coupling I, m³ (0 for a rigid tank).
    pub volume_m3: f64,
    /// Heat-transfer enhancement k_h of coupling II, W/(m²·K) per rad/s.
    pub h_enhancement_w_per_m2_k_s: f64,
    /// Constant c_mix of coupling III, the wave-induced eddy diffusivity
    /// D = c_mix Σ |x_n| |ẋ_n| e^(−2 ξ_n d / R) (`model::wave_mixing`), dimensionless.
    pub mixing: f64,
}

/// What the pressurization system admits (MODEL.md §7).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PressurantGas {
    /// Helium from a bottle: it enters the helium slot `M_G` with h = c_p,He T_in.
    Helium,
    /// The propellant's own vapour (GH2, GOX, GCH4, GN2 tapped from the engine or a heat
    /// exchanger): it enters the vapour slot `M_V` (the homogeneous level: `M_B`) with the
    /// ullage vapour's enthalpy at the inlet temperature, h = c_p,v T_in + offset.
    Autogenous,
}

impl PressurantGas {
    /// Campaign spelling.
    pub fn name(self) -> &'static str {
        match self {
            PressurantGas::Helium => "helium",
            PressurantGas::Autogenous => "autogenous",
        }
    }
}

/// How the regulator's gains follow the tank state (`pressurization.gain_schedule`).
///
/// For the ullage gas dP/dm ≈ R T / V_u: a kilogram of pressurant raises the pressure of a small
/// ullage more than that of a large one. With fixed gains the loop gain (R T / V_u)·k_p — the
/// inverse of the closed-loop time constant V_u / (k_p R T) — falls as the ullage grows during a
/// burn (sluggish, under-damped late) and is too hot at a high fill. Scaling both gains with
/// V_u / V_ref holds the loop gain at its value for the reference ullage V_ref.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GainSchedule {
    /// k_p and k_d as written (`"fixed"`, the default).
    Fixed,
    /// k_p·V_u/V_ref and k_d·V_u/V_ref with V_u the current ullage volume (`"ullage_volume"`).
    UllageVolume {
        /// The reference ullage volume V_ref, m³ (`schedule_reference_ullage_m3`; default the
        /// initial ullage (1 − fill_fraction)·V_tank).
        reference_m3: f64,
    },
}

impl GainSchedule {
    /// Campaign spelling.
    pub fn name(self) -> &'static str {
        match self {
            GainSchedule::Fixed => "fixed",
            GainSchedule::UllageVolume { .. } => "ullage_volume",
        }
    }

    /// The reference ullage volume, m³, as a per-lane number: 0 selects the fixed gains (so
    /// that instances with either schedule share a lane group).
    pub fn reference_or_zero_m3(self) -> f64 {
        match self {
            GainSchedule::Fixed => 0.0,
            GainSchedule::UllageVolume { reference_m3 } => reference_m3,
        }
    }
}

/// PD pressurization with a finite supply of helium or of autogenous vapour (MODEL.md §7).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pressurization {
    /// The gas admitted (default helium).
    pub gas: PressurantGas,
    /// Regulated ullage pressure P_ref, Pa.
    pub setpoint_pa: f64,
    /// Proportional gain, kg/(s·Pa).
    pub kp_kg_per_s_pa: f64,
    /// Derivative gain, kg/Pa.
    pub kd_kg_per_pa: f64,
    /// Derivative filter time constant, s.
    pub derivative_filter_s: f64,
    /// Maximum flow, kg/s.
    pub max_flow_kg_per_s: f64,
    /// Inlet gas temperature, K.
    pub gas_temperature_k: f64,
    /// Usable pressurant mass, kg: the helium bottle, or the autogenous gas budget.
    pub bottle_mass_kg: f64,
    /// Whether k_p and k_d are fixed or scaled with the ullage volume.
    pub gain_schedule: GainSchedule,
}

/// Relief valve with hysteresis, venting the ullage mixture through an orifice.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Relief {
    /// Cracking (opening) pressure, Pa.
    pub crack_pa: f64,
    /// Reseat (closing) pressure, Pa; below `crack_pa`.
    pub reseat_pa: f64,
    /// Effective flow area C_d·A, m².
    pub flow_area_m2: f64,
}

/// Engine draw and feed line (MODEL.md §7, §9).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Feed {
    /// Engine specific impulse, s.
    pub isp_s: f64,
    /// This tank's share of the engine mass flow, –.
    pub propellant_fraction: f64,
    /// Feed-line drop from the tank outlet to the pump inlet, m.
    pub line_height_m: f64,
    /// Frictional line loss, Pa.
    pub line_loss_pa: f64,
    /// Line velocity, m/s.
    pub line_velocity_m_s: f64,
    /// Required NPSH of the pump, m.
    pub npsh_required_m: f64,
}

/// 1-D vehicle for the flight state (MODEL.md §8).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vehicle {
    /// Vehicle mass without this tank's propellant, kg (includes the other propellant at start).
    pub dry_mass_kg: f64,
    /// Drag coefficient × reference area, m².
    pub drag_area_m2: f64,
    /// Initial velocity, m/s.
    pub initial_velocity_m_s: f64,
    /// Initial altitude, m.
    pub initial_altitude_m: f64,
    /// Lever arm from the vehicle centre of mass to the slosh hinge, m (moment = F_x · arm).
    pub slosh_lever_arm_m: f64,
}

/// The insulation of `[insulation]` and the surroundings it faces (docs/PHYSICS.md 2.5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Insulation {
    /// Spray-on foam on the wall, if any.
    pub foam: Option<super::insulation::Foam>,
    /// Multilayer blanket over the foam (or the bare wall), if any.
    pub mli: Option<super::insulation::Mli>,
    /// Ground: air and surrounding-surface temperature, K.
    pub ground_ambient_temperature_k: f64,
    /// Ground: convection coefficient to the outer surface, W/(m²·K).
    pub ground_convection_w_per_m2_k: f64,
    /// Space: radiation sink temperature, K.
    pub space_sink_temperature_k: f64,
    /// Space: solar, albedo and planetary flux incident on the outer surface, averaged over the
    /// insulated area, W/m².
    pub space_incident_flux_w_per_m2: f64,
    /// Outer surface hemispherical emissivity, –.
    pub outer_emissivity: f64,
    /// Outer surface absorptivity for the incident flux, –.
    pub outer_absorptivity: f64,
}

impl Insulation {
    /// The stack of one instance (f64).
    pub fn stack(&self) -> super::insulation::Stack {
        super::insulation::Stack {
            foam_resistance_m2_k_per_w: self.foam.map_or(0.0, |f| f.resistance_m2_k_per_w()),
            mli: self.mli.map(|m| m.coefficients()),
        }
    }

    /// The surroundings in `env` (f64).
    pub fn surroundings(&self, env: super::flight::Environment) -> super::insulation::Surroundings {
        let space = env == super::flight::Environment::Space;
        let t = if space {
            self.space_sink_temperature_k
        } else {
            self.ground_ambient_temperature_k
        };
        super::insulation::Surroundings {
            h_w_per_m2_k: if space {
                0.0
            } else {
                self.ground_convection_w_per_m2_k
            },
            t_air_k: t,
            t_rad4_k4: t * t * (t * t),
            absorbed_w_per_m2: if space {
                self.outer_absorptivity * self.space_incident_flux_w_per_m2
            } else {
                0.0
            },
            eps_sigma: self.outer_emissivity * super::insulation::STEFAN_BOLTZMANN,
        }
    }

    /// The steady leak into a wall at `t_wall_k` (K) in `env`: the same solution the
    /// integration uses.
    pub fn leak(&self, env: super::flight::Environment, t_wall_k: f64) -> super::insulation::Leak {
        super::insulation::leak(&self.stack(), &self.surroundings(env), t_wall_k)
    }
}

/// Everything one instance needs apart from the phase list.
#[derive(Clone, Copy, Debug)]
pub struct Params {
    pub fidelity: Fidelity,
    pub fluid: Fluid,
    pub tank: Tank,
    /// Fixed heat leak through the insulation into the wall, W (unused with `insulation`).
    pub heat_leak_w: f64,
    /// Insulation and surroundings; `None`: the fixed `heat_leak_w`.
    pub insulation: Option<Insulation>,
    /// Wall mass per unit area, kg/m².
    pub wall_areal_mass_kg_per_m2: f64,
    /// Wall specific heat, J/(kg·K).
    pub wall_cp_j_per_kg_k: f64,
    /// Initial temperature of the dry (ullage-side) wall node, K, in [liquid temperature, 400];
    /// the wetted wall starts at the liquid temperature.
    pub dry_wall_temperature_k: f64,
    /// Maximum expected operating pressure (overpressure flag), Pa.
    pub meop_pa: f64,
    /// Initial liquid volume / tank volume.
    pub fill_fraction: f64,
    /// Initial liquid temperature, K.
    pub liquid_temperature_k: f64,
    /// Initial ullage pressure (vapour + helium), Pa.
    pub ullage_pressure_pa: f64,
    /// Initial helium partial pressure, Pa, in [0, `ullage_pressure_pa`]; the vapour holds the
    /// rest. Resolved default: `ullage_pressure_pa` − min(P_sat(T_l), `ullage_pressure_pa`).
    pub ullage_helium_partial_pressure_pa: f64,
    /// Initial ullage temperature, K.
    pub ullage_temperature_k: f64,
    pub heat_transfer: HeatTransfer,
    pub stratification: Stratification,
    pub coupling: Coupling,
    /// The column of the `layered` level (read only there).
    pub layered: Layered,
    pub baffles: Baffles,
    /// Additional slosh damping ratio (devices not modelled otherwise), –.
    pub extra_damping: f64,
    pub pressurization: Option<Pressurization>,
    pub relief: Option<Relief>,
    /// The jet mixer of `[mixer]`, if any (`model::mixer`).
    pub mixer: Option<super::mixer::Mixer>,
    /// The thermodynamic vent system of `[tvs]`, if any (`model::tvs`).
    pub tvs: Option<super::tvs::Tvs>,
    pub feed: Feed,
    pub vehicle: Vehicle,
}

impl Params {
    /// Mass of the tank wall, kg.
    pub fn wall_mass_kg(&self) -> f64 {
        self.wall_areal_mass_kg_per_m2 * self.tank.wall_area_m2()
    }

    /// Heat capacity of the tank wall, J/K.
    pub fn wall_heat_capacity_j_per_k(&self) -> f64 {
        self.wall_mass_kg() * self.wall_cp_j_per_kg_k
    }

    /// Share of the pressurant flow that is propellant vapour: 1 for autogenous, else 0.
    pub fn pressurant_vapor_share(&self) -> f64 {
        match self.pressurization.map(|ps| ps.gas) {
            Some(PressurantGas::Autogenous) => 1.0,
            _ => 0.0,
        }
    }

    /// Whether `other` can share a lane group with `self`: the same level, propellant and tank
    /// shape, and the same optional systems and closures present (their numbers may differ).
    pub fn lane_compatible(&self, other: &Params) -> bool {
        let (a, b) = (&self.heat_transfer, &other.heat_transfer);
        self.fidelity == other.fidelity
            && (self.fidelity != Fidelity::Layered || self.layered == other.layered)
            && self.fluid == other.fluid
            && self.tank.shape() == other.tank.shape()
            && self.pressurization.is_some() == other.pressurization.is_some()
            && self.relief.is_some() == other.relief.is_some()
            && self.mixer.is_some() == other.mixer.is_some()
            && self.tvs.is_some() == other.tvs.is_some()
            && self.insulation.map(|i| (i.foam.is_some(), i.mli.is_some()))
                == other
                    .insulation
                    .map(|i| (i.foam.is_some(), i.mli.is_some()))
            && a.evaporation_coefficient_kg_per_s_pa.is_some()
                == b.evaporation_coefficient_kg_per_s_pa.is_some()
            && a.h_us_w_per_m2_k.is_some() == b.h_us_w_per_m2_k.is_some()
            && a.h_sb_w_per_m2_k.is_some() == b.h_sb_w_per_m2_k.is_some()
            && a.h_wall_ullage_w_per_m2_k.is_some() == b.h_wall_ullage_w_per_m2_k.is_some()
            && a.h_wall_liquid_w_per_m2_k.is_some() == b.h_wall_liquid_w_per_m2_k.is_some()
    }
}
