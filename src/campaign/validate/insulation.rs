//! `[insulation]`: foam and multilayer blanket and the surroundings they face, with ranges and
//! defaults (docs/PHYSICS.md 2.5). A key of a layer that is not there is refused rather than
//! ignored, and so is an empty stack.

use super::Checker;
use crate::campaign::raw::RawInsulation;
use crate::campaign::CampaignError;
use crate::model::insulation::{Foam, Mli, MLI_DEFAULT_EMISSIVITY};
use crate::model::params::Insulation;

/// Default effective foam conductivity, W/(m·K): the order of that of the polyisocyanurate
/// spray-on foams of cryogenic launcher tanks (NCFI 24-124, BX-265) between room temperature
/// and the tank; Barrios & Van Sciver, Cryogenics 55–56 (2013) 12–19, measured NCFI 24-124
/// from 20 K to 300 K, lower at cryogenic mean temperatures, so this is the warm end.
pub const DEFAULT_FOAM_CONDUCTIVITY_W_PER_M_K: f64 = 0.02;
/// Default interstitial pressure of the blanket, torr (high vacuum).
pub const DEFAULT_MLI_PRESSURE_TORR: f64 = 1.0e-6;
/// Default ground ambient temperature, K (20 °C).
pub const DEFAULT_GROUND_AMBIENT_K: f64 = 293.15;
/// Default ground convection coefficient, W/(m²·K): still air on a large vertical surface.
pub const DEFAULT_GROUND_CONVECTION_W_PER_M2_K: f64 = 5.0;
/// Default space sink temperature, K (the cosmic background).
pub const DEFAULT_SPACE_SINK_K: f64 = 2.725;
/// Default outer emissivity and absorptivity, –: a painted or bare foam surface. An
/// aluminized outer blanket layer is nearer ε ≈ 0.05; set both for the real surface.
pub const DEFAULT_OUTER_EMISSIVITY: f64 = 0.9;
/// See [`DEFAULT_OUTER_EMISSIVITY`].
pub const DEFAULT_OUTER_ABSORPTIVITY: f64 = 0.3;

/// Validate `[insulation]` (read from the section; `None` when the campaign has none).
pub(super) fn insulation(
    c: &Checker,
    raw: Option<&RawInsulation>,
) -> Result<Option<Insulation>, CampaignError> {
    let Some(r) = raw else {
        return Ok(None);
    };
    let key = |k: &str| format!("insulation.{k}");
    // A layer's parameters only with the layer itself.
    let unused = |present: bool, layer: &str, keys: &[(&str, bool)]| {
        keys.iter().find(|(_, set)| *set && !present).map(|(k, _)| {
            c.err(
                &key(k),
                "(set)",
                format!("only with insulation.{layer} (this layer is not in the stack)"),
            )
        })
    };
    if let Some(e) = unused(
        r.foam_thickness_m.is_some(),
        "foam_thickness_m",
        &[(
            "foam_conductivity_w_per_m_k",
            r.foam_conductivity_w_per_m_k.is_some(),
        )],
    ) {
        return Err(e);
    }
    if let Some(e) = unused(
        r.mli_layers.is_some(),
        "mli_layers",
        &[
            (
                "mli_layer_density_per_cm",
                r.mli_layer_density_per_cm.is_some(),
            ),
            (
                "mli_interstitial_pressure_torr",
                r.mli_interstitial_pressure_torr.is_some(),
            ),
            ("mli_shield_emissivity", r.mli_shield_emissivity.is_some()),
            ("mli_degradation_factor", r.mli_degradation_factor.is_some()),
        ],
    ) {
        return Err(e);
    }
    let foam = r
        .foam_thickness_m
        .map(|l| {
            Ok::<_, CampaignError>(Foam {
                thickness_m: c.positive(&key("foam_thickness_m"), l, 1.0)?,
                conductivity_w_per_m_k: c.opt_range(
                    &key("foam_conductivity_w_per_m_k"),
                    r.foam_conductivity_w_per_m_k,
                    DEFAULT_FOAM_CONDUCTIVITY_W_PER_M_K,
                    1.0e-4,
                    1.0,
                )?,
            })
        })
        .transpose()?;
    let mli = r
        .mli_layers
        .map(|n| {
            Ok::<_, CampaignError>(Mli {
                layers: c.range(&key("mli_layers"), n, 1.0, 1000.0)?,
                // Required with a blanket: the layer density sets both conduction terms.
                layer_density_per_cm: match r.mli_layer_density_per_cm {
                    Some(v) => c.range(&key("mli_layer_density_per_cm"), v, 1.0, 100.0)?,
                    None => {
                        return Err(c.err(
                            &key("mli_layer_density_per_cm"),
                            "(missing)",
                            "a layer density in [1, 100] layers/cm, required with mli_layers",
                        ))
                    }
                },
                interstitial_pressure_torr: c.opt_range(
                    &key("mli_interstitial_pressure_torr"),
                    r.mli_interstitial_pressure_torr,
                    DEFAULT_MLI_PRESSURE_TORR,
                    0.0,
                    1.0e-3,
                )?,
                shield_emissivity: c.opt_range(
                    &key("mli_shield_emissivity"),
                    r.mli_shield_emissivity,
                    MLI_DEFAULT_EMISSIVITY,
                    0.005,
                    0.5,
                )?,
                degradation_factor: c.opt_range(
                    &key("mli_degradation_factor"),
                    r.mli_degradation_factor,
                    1.0,
                    1.0,
                    100.0,
                )?,
            })
        })
        .transpose()?;
    if foam.is_none() && mli.is_none() {
        return Err(c.err(
            "insulation",
            "(no layer)",
            "insulation.foam_thickness_m and/or insulation.mli_layers",
        ));
    }
    Ok(Some(Insulation {
        foam,
        mli,
        ground_ambient_temperature_k: c.opt_range(
            &key("ground_ambient_temperature_k"),
            r.ground_ambient_temperature_k,
            DEFAULT_GROUND_AMBIENT_K,
            150.0,
            400.0,
        )?,
        ground_convection_w_per_m2_k: c.opt_range(
            &key("ground_convection_w_per_m2_k"),
            r.ground_convection_w_per_m2_k,
            DEFAULT_GROUND_CONVECTION_W_PER_M2_K,
            0.0,
            1000.0,
        )?,
        space_sink_temperature_k: c.opt_range(
            &key("space_sink_temperature_k"),
            r.space_sink_temperature_k,
            DEFAULT_SPACE_SINK_K,
            0.0,
            400.0,
        )?,
        space_incident_flux_w_per_m2: c.opt_range(
            &key("space_incident_flux_w_per_m2"),
            r.space_incident_flux_w_per_m2,
            0.0,
            0.0,
            1.0e4,
        )?,
        outer_emissivity: c.opt_range(
            &key("outer_emissivity"),
            r.outer_emissivity,
            DEFAULT_OUTER_EMISSIVITY,
            0.01,
            1.0,
        )?,
        outer_absorptivity: c.opt_range(
            &key("outer_absorptivity"),
            r.outer_absorptivity,
            DEFAULT_OUTER_ABSORPTIVITY,
            0.0,
            1.0,
        )?,
    }))
}
