//! The campaign TOML as written: serde structs with `deny_unknown_fields`, every field optional
//! where a documented default exists. Units are in the names; `campaigns/*.toml` document each.

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawCampaign {
    pub campaign: RawRun,
    pub tank: RawTank,
    pub propellant: RawPropellant,
    pub ullage: RawUllage,
    #[serde(default)]
    pub heat_transfer: RawHeatTransfer,
    #[serde(default)]
    pub stratification: RawStratification,
    /// `[layered]`: the column of `campaign.fidelity = "layered"`.
    pub layered: Option<RawLayered>,
    #[serde(default)]
    pub slosh: RawSlosh,
    pub pressurization: Option<RawPressurization>,
    pub relief: Option<RawRelief>,
    pub insulation: Option<RawInsulation>,
    pub mixer: Option<RawMixer>,
    pub tvs: Option<RawTvs>,
    #[serde(default)]
    pub engine: RawEngine,
    #[serde(default)]
    pub feed: RawFeed,
    #[serde(default)]
    pub vehicle: RawVehicle,
    pub phases: Vec<RawPhase>,
    pub dispersions: Option<super::dispersion::RawDispersions>,
    pub statistics: Option<super::statistics::RawStatistics>,
    /// `[[variants]]`: read and checked by `variants::extract`.
    pub variants: Option<Vec<toml::Table>>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawRun {
    pub name: Option<String>,
    pub fidelity: Option<String>,
    pub dt_s: Option<f64>,
    pub output_interval_s: Option<f64>,
    pub instances: Option<u64>,
    pub seed: Option<u64>,
    pub integrator: Option<String>,
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
    pub max_step_s: Option<f64>,
    pub allow_coarse_step: Option<bool>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawTank {
    pub shape: String,
    pub radius_m: f64,
    pub cylinder_length_m: Option<f64>,
    pub dome_ratio: Option<f64>,
    /// Required without `[insulation]`; ignored with it.
    pub heat_leak_w: Option<f64>,
    pub wall_areal_mass_kg_per_m2: Option<f64>,
    pub wall_cp_j_per_kg_k: Option<f64>,
    pub dry_wall_temperature_k: Option<f64>,
    pub meop_pa: f64,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawPropellant {
    pub fluid: String,
    pub fill_fraction: f64,
    pub temperature_k: Option<f64>,
    pub subcooling_k: Option<f64>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawUllage {
    pub pressure_pa: f64,
    pub temperature_k: Option<f64>,
    pub helium_partial_pressure_pa: Option<f64>,
}

#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawHeatTransfer {
    pub evaporation_coefficient_kg_per_s_pa: Option<f64>,
    pub accommodation_coefficient: Option<f64>,
    pub h_ullage_interface_w_per_m2_k: Option<f64>,
    pub h_layer_bulk_w_per_m2_k: Option<f64>,
    pub h_wall_ullage_w_per_m2_k: Option<f64>,
    pub h_wall_liquid_w_per_m2_k: Option<f64>,
}

#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawStratification {
    pub initial_thickness_m: Option<f64>,
    pub diffusivity_factor: Option<f64>,
    pub wall_heat_to_layer: Option<f64>,
    pub initial_temperature_k: Option<f64>,
}

#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawLayered {
    pub layers: Option<u32>,
    pub stretch: Option<f64>,
    pub detrain_width_k: Option<f64>,
}

#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawSlosh {
    pub baffle_count: Option<u32>,
    pub baffle_width_m: Option<f64>,
    pub baffle_spacing_m: Option<f64>,
    pub baffle_top_height_m: Option<f64>,
    pub wave_amplitude_m: Option<f64>,
    pub extra_damping_ratio: Option<f64>,
    pub volume_coupling_m3: Option<f64>,
    pub heat_transfer_enhancement_w_per_m2_k_s: Option<f64>,
    pub mixing_coefficient: Option<f64>,
    pub initial_angle_rad: Option<f64>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawPressurization {
    pub gas: Option<String>,
    pub setpoint_pa: f64,
    pub kp_kg_per_s_pa: f64,
    pub kd_kg_per_pa: Option<f64>,
    pub derivative_filter_s: Option<f64>,
    pub max_flow_kg_per_s: f64,
    pub gas_temperature_k: f64,
    pub bottle_mass_kg: f64,
    pub gain_schedule: Option<String>,
    pub schedule_reference_ullage_m3: Option<f64>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawRelief {
    pub crack_pa: f64,
    pub reseat_pa: f64,
    pub flow_area_m2: f64,
    /// The crack pressure may lie above MEOP (a deliberate proof-test or off-nominal study).
    pub crack_above_meop: Option<bool>,
}

#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawInsulation {
    pub foam_thickness_m: Option<f64>,
    pub foam_conductivity_w_per_m_k: Option<f64>,
    pub mli_layers: Option<f64>,
    pub mli_layer_density_per_cm: Option<f64>,
    pub mli_interstitial_pressure_torr: Option<f64>,
    pub mli_shield_emissivity: Option<f64>,
    pub mli_degradation_factor: Option<f64>,
    pub ground_ambient_temperature_k: Option<f64>,
    pub ground_convection_w_per_m2_k: Option<f64>,
    pub space_sink_temperature_k: Option<f64>,
    pub space_incident_flux_w_per_m2: Option<f64>,
    pub outer_emissivity: Option<f64>,
    pub outer_absorptivity: Option<f64>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawMixer {
    /// Required; optional here so that `--set` can build the section a key at a time (the
    /// validation names a missing one).
    pub pump_flow_m3_s: Option<f64>,
    pub nozzle_diameter_m: Option<f64>,
    pub pump_heat_w: Option<f64>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawTvs {
    /// Required; optional here so that `--set` can build the section a key at a time (the
    /// validation names a missing one).
    pub band_upper_pa: Option<f64>,
    pub band_lower_pa: Option<f64>,
    pub jt_flow_kg_s: Option<f64>,
    pub jt_outlet_pa: Option<f64>,
    /// Default 0 (no recirculation pump).
    pub pump_flow_m3_s: Option<f64>,
    /// Default 0.
    pub pump_heat_w: Option<f64>,
}

#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawEngine {
    pub isp_s: Option<f64>,
    pub propellant_fraction: Option<f64>,
}

#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawFeed {
    pub line_height_m: Option<f64>,
    pub line_loss_pa: Option<f64>,
    pub line_velocity_m_s: Option<f64>,
    pub npsh_required_m: Option<f64>,
}

#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawVehicle {
    pub dry_mass_kg: Option<f64>,
    pub drag_area_m2: Option<f64>,
    pub initial_velocity_m_s: Option<f64>,
    pub initial_altitude_m: Option<f64>,
    pub slosh_lever_arm_m: Option<f64>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawPhase {
    pub name: Option<String>,
    pub kind: String,
    pub duration_s: f64,
    pub dt_s: Option<f64>,
    pub max_step_s: Option<f64>,
    pub thrust_n: Option<f64>,
    pub flight_path_angle_deg: Option<f64>,
    pub gravity_m_s2: Option<f64>,
    pub pressurize: Option<bool>,
    pub environment: Option<String>,
    /// Whether the `[mixer]` runs in this phase (default true).
    pub mixer: Option<bool>,
    /// Whether the `[tvs]` may run in this phase (default true).
    pub tvs: Option<bool>,
    pub excitation: Option<RawExcitation>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawExcitation {
    pub kind: String,
    pub amplitude_m_s2: Option<f64>,
    pub frequency_hz: Option<f64>,
    pub phase_rad: Option<f64>,
    pub start_s: Option<f64>,
    pub duration_s: Option<f64>,
    pub f_start_hz: Option<f64>,
    pub f_end_hz: Option<f64>,
    pub file: Option<String>,
}
