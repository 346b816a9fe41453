//! The axial jet mixer of `[mixer]` (issue 17; the paper's §9 "mixing device" against thermal
//! stratification; docs/PHYSICS.md 2.6): a pump that draws liquid and returns it through a
//! nozzle as a turbulent jet across the tank.
//!
//! **Correlation.** Fossett & Prosser, Proc. Instn Mech. Engrs 160 (1949),
//! doi:10.1243/PIME_PROC_1949_160_024_02 (its abstract): a free jet directed across a circular
//! tank mixes it completely in t_mix ≈ 8 D² / √(Q u_j) (D the tank diameter, m; Q the nozzle
//! flow, m³/s; u_j = 4 Q / (π d_j²) the nozzle velocity, m/s), i.e. 9.0 D² / (u_j d_j). The
//! correlation is for a turbulent jet: the jet Reynolds number Re_j = ρ_l u_j d_j / μ_l must be
//! at least [`MIN_JET_REYNOLDS`] (submerged jets in cylindrical vessels, "Submerged jets in
//! short cylindrical flow vessels", inlet Reynolds numbers 100–28 000, are fully turbulent
//! above Re ≈ 3000; below it the jet stays laminar over a length that grows as Re falls and
//! the constant no longer holds). `campaign::validate` refuses a nominal campaign outside that
//! range (exit 2) and rejects a dispersed instance that leaves it (`rejected_by`).
//!
//! **Mapping to the nodes.** "Complete" is read as the layer–bulk difference down to 5 %: the
//! mixer exchanges equal masses ṁ_mix between the stratified layer and the bulk, with
//! 1/τ = ṁ_mix (1/m_s + 1/m_b) and τ = t_mix / ln 20, so that in a closed, heat-free tank
//! h_s − h_b (and T_s − T_b to the variation of c_p) decays as exp(−t/τ) and reaches 5 % at
//! t_mix. The pump's heat enters the liquid (`nodes::rhs`, `homogeneous::rhs`).

use super::derive::Drive;
use super::params::Params;
use super::Group;
use crate::lanes::{c, Real};

/// Fossett & Prosser's constant in t_mix = C D² / √(Q u_j), –.
pub const FOSSETT_PROSSER: f64 = 8.0;

/// Lowest jet Reynolds number ρ_l u_j d_j / μ_l at which the correlation is used, –.
pub const MIN_JET_REYNOLDS: f64 = 3000.0;

/// What is left of the layer–bulk difference at t_mix: 5 %, so t_mix = τ ln 20.
pub const RESIDUAL_AT_MIXING_TIME: f64 = 0.05;

/// The jet mixer of one instance (`[mixer]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mixer {
    /// Volume flow through the nozzle Q, m³/s, in [0, 10]; 0: the pump moves no liquid (no
    /// exchange; its heat, if any, still enters the liquid).
    pub pump_flow_m3_s: f64,
    /// Nozzle diameter d_j, m, in (0, tank radius].
    pub nozzle_diameter_m: f64,
    /// Heat the pump and motor dissipate in the propellant while they run, W, in [0, 1e5]: at
    /// least the jet's kinetic power ½ ρ_l Q u_j² (which the liquid dissipates); a submerged
    /// pump dissipates its whole electric power.
    pub pump_heat_w: f64,
}

impl Mixer {
    /// Nozzle velocity u_j = 4 Q / (π d_j²), m/s.
    pub fn jet_velocity_m_s(&self) -> f64 {
        4.0 * self.pump_flow_m3_s / (std::f64::consts::PI * self.nozzle_diameter_m.powi(2))
    }

    /// Jet Reynolds number ρ u_j d_j / μ for liquid of density `rho_kg_m3` (kg/m³) and
    /// viscosity `mu_pa_s` (Pa·s), –.
    pub fn jet_reynolds(&self, rho_kg_m3: f64, mu_pa_s: f64) -> f64 {
        rho_kg_m3 * self.jet_velocity_m_s() * self.nozzle_diameter_m / mu_pa_s
    }

    /// Kinetic power of the jet ½ ρ Q u_j², W, for liquid of density `rho_kg_m3` (kg/m³).
    pub fn jet_power_w(&self, rho_kg_m3: f64) -> f64 {
        0.5 * rho_kg_m3 * self.pump_flow_m3_s * self.jet_velocity_m_s().powi(2)
    }

    /// Fossett & Prosser's mixing time 8 D² / √(Q u_j) in a tank of diameter
    /// `tank_diameter_m` (m), s (infinite without flow).
    pub fn mixing_time_s(&self, tank_diameter_m: f64) -> f64 {
        let qu = self.pump_flow_m3_s * self.jet_velocity_m_s();
        if qu > 0.0 {
            FOSSETT_PROSSER * tank_diameter_m.powi(2) / qu.sqrt()
        } else {
            f64::INFINITY
        }
    }

    /// 1/τ = ln(1/0.05) / t_mix, 1/s: the decay rate of the layer–bulk difference (0 without
    /// flow).
    pub fn exchange_rate_per_s(&self, tank_diameter_m: f64) -> f64 {
        (1.0 / RESIDUAL_AT_MIXING_TIME).ln() / self.mixing_time_s(tank_diameter_m)
    }
}

/// The mixer's exchange rate 1/τ of instance `p` (1/s; 0 without a mixer).
pub fn exchange_rate_per_s(p: &Params) -> f64 {
    p.mixer
        .map_or(0.0, |m| m.exchange_rate_per_s(2.0 * p.tank.radius_m()))
}

/// The pump heat of instance `p` while the mixer runs (W; 0 without a mixer).
pub fn pump_heat_w(p: &Params) -> f64 {
    p.mixer.map_or(0.0, |m| m.pump_heat_w)
}

/// The jet mixer's exchange rate 1/τ (1/s) and pump heat (W) in each lane: 0 where the
/// campaign has no `[mixer]` or the phase turns it off (`nodes::rhs`, `homogeneous::rhs`).
pub(super) fn lanes<T: Real>(g: Group<'_>, d: &Drive<T>) -> (T, T) {
    if g.shared().mixer.is_none() {
        return (c(0.0), c(0.0));
    }
    let rate: T = g.get(exchange_rate_per_s);
    let heat: T = g.get(pump_heat_w);
    (
        T::select(d.mixing, rate, c(0.0)),
        T::select(d.mixing, heat, c(0.0)),
    )
}
