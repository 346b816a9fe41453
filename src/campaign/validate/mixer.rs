//! `[mixer]`: the axial jet mixer (`model::mixer`, docs/PHYSICS.md 2.6) with its ranges, the
//! correlation's validity range (a turbulent jet) and the per-phase `mixer` switches.

use super::{number, Checker};
use crate::campaign::raw::{RawMixer, RawPhase};
use crate::campaign::{CampaignError, Integrator};
use crate::fluids::Fluid;
use crate::model::flight::Phase;
use crate::model::mixer::{Mixer, MIN_JET_REYNOLDS};
use crate::model::params::Fidelity;

/// Most fixed RK4 steps per exchange time constant τ a campaign may ask for: at dt = τ / 2 the
/// step's amplification of the layer–bulk difference is exp(−0.5) to 3e-4 relative (RK4's
/// error in e^{−z} at z = 0.5), far inside RK4's stability bound z < 2.79.
pub const MIN_STEPS_PER_EXCHANGE_TIME: f64 = 2.0;

/// Largest pump heat a `[mixer]` may dissipate in the propellant, W.
pub const MAX_PUMP_HEAT_W: f64 = 1.0e5;

/// `w` rounded up to four significant digits, for a bound printed in a message.
fn round_up(w: f64) -> f64 {
    if w <= 0.0 || !w.is_finite() {
        return w;
    }
    let scale = 10f64.powi(3 - w.log10().floor() as i32);
    (w * scale).ceil() / scale
}

/// Validate `[mixer]` (`None` when the campaign has none) for propellant `fluid` at the initial
/// liquid temperature `t_liquid_k` (K) in a tank of radius `radius_m` (m). `runs`: some phase
/// runs it (a mixer every phase switches off never uses the correlation, so its jet need not be
/// turbulent).
pub(super) fn mixer(
    c: &Checker,
    raw: Option<&RawMixer>,
    fluid: Fluid,
    (t_liquid_k, radius_m): (f64, f64),
    runs: bool,
) -> Result<Option<Mixer>, CampaignError> {
    let Some(r) = raw else {
        return Ok(None);
    };
    let required = |key: &str, v: Option<f64>| {
        v.ok_or_else(|| c.err(key, "(missing)", "a value: every [mixer] needs it"))
    };
    let flow_in = required("mixer.pump_flow_m3_s", r.pump_flow_m3_s)?;
    let nozzle_in = required("mixer.nozzle_diameter_m", r.nozzle_diameter_m)?;
    let heat = required("mixer.pump_heat_w", r.pump_heat_w)?;
    let flow = c.range("mixer.pump_flow_m3_s", flow_in, 0.0, 10.0)?;
    let nozzle = c.positive("mixer.nozzle_diameter_m", nozzle_in, radius_m)?;
    let partial = Mixer {
        pump_flow_m3_s: flow,
        nozzle_diameter_m: nozzle,
        pump_heat_w: 0.0,
    };
    let f = fluid.props();
    let (rho, mu) = (f.rho_l_kg_per_m3(t_liquid_k), f.mu_l_pa_s(t_liquid_k));
    // Fossett & Prosser's constant holds for a turbulent jet: a flow that makes a laminar jet
    // is outside the correlation (a dispersed sample there is rejected, not used).
    let re = partial.jet_reynolds(rho, mu);
    if runs && flow > 0.0 && re < MIN_JET_REYNOLDS {
        return Err(c.err(
            "mixer.pump_flow_m3_s",
            number(flow),
            format!(
                "0, or a turbulent jet: the jet Reynolds number ρ u_j d_j / μ = {} at the \
                 initial liquid temperature with mixer.nozzle_diameter_m = {} is below {} \
                 (the range of Fossett & Prosser's mixing-time correlation)",
                number((re * 10.0).round() / 10.0),
                number(nozzle),
                number(MIN_JET_REYNOLDS)
            ),
        ));
    }
    // The jet's kinetic power is dissipated in the liquid: the pump's heat cannot be less, so a
    // jet above the pump-heat ceiling is the flow's (or nozzle's) fault, not the heat's.
    let jet_w = partial.jet_power_w(rho);
    if jet_w > MAX_PUMP_HEAT_W {
        return Err(c.err(
            "mixer.pump_flow_m3_s",
            number(flow),
            format!(
                "a flow whose jet carries at most {} W (the ceiling of mixer.pump_heat_w): \
                 ½ ρ Q u_j² = {} W with mixer.nozzle_diameter_m = {}; lower the flow or widen \
                 the nozzle",
                number(MAX_PUMP_HEAT_W),
                number(round_up(jet_w)),
                number(nozzle)
            ),
        ));
    }
    if !(heat.is_finite() && heat >= jet_w && heat <= MAX_PUMP_HEAT_W) {
        return Err(c.err(
            "mixer.pump_heat_w",
            number(heat),
            format!(
                "a finite number in [{}, {}]: at least the jet's kinetic power ½ ρ Q u_j² \
                 (the liquid dissipates it) with this flow and nozzle",
                number(round_up(jet_w)),
                number(MAX_PUMP_HEAT_W)
            ),
        ));
    }
    Ok(Some(Mixer {
        pump_heat_w: heat,
        ..partial
    }))
}

/// The per-phase switches: `phases.N.mixer` only with a `[mixer]` section (it would be ignored
/// without a word), and a fixed RK4 step that resolves the exchange time constant τ in every
/// phase where the mixer runs (on the levels with a layer and a bulk). `tank_diameter_m` in m.
pub(super) fn phases(
    c: &Checker,
    mixer: Option<&Mixer>,
    raw: &[RawPhase],
    phases: &[Phase],
    integrator: Integrator,
    fidelity: Fidelity,
    tank_diameter_m: f64,
) -> Result<(), CampaignError> {
    let Some(m) = mixer else {
        return match raw.iter().position(|ph| ph.mixer.is_some()) {
            Some(i) => Err(c.err(
                &format!("phases.{i}.mixer"),
                raw[i].mixer.unwrap_or_default(),
                "no per-phase mixer switch without a [mixer] section",
            )),
            None => Ok(()),
        };
    };
    // The exchange acts between the layer and the bulk: the homogeneous level has neither and
    // takes only the pump heat, so its step need not resolve τ.
    if integrator != Integrator::Rk4 || fidelity == Fidelity::Homogeneous {
        return Ok(());
    }
    let tau = 1.0 / m.exchange_rate_per_s(tank_diameter_m);
    match phases
        .iter()
        .position(|ph| ph.mixer && ph.steps().1 * MIN_STEPS_PER_EXCHANGE_TIME > tau)
    {
        Some(i) => Err(c.err(
            "mixer.pump_flow_m3_s",
            number(m.pump_flow_m3_s),
            format!(
                "a flow whose exchange time constant τ = t_mix / ln 20 = {} s spans at least {} \
                 fixed steps of phases.{i} (dt {} s): lower the flow, shorten the phase's dt_s \
                 or use campaign.integrator = \"dopri5\"",
                number(tau),
                MIN_STEPS_PER_EXCHANGE_TIME,
                number(phases[i].steps().1)
            ),
        )),
        None => Ok(()),
    }
}
