//! The thermodynamic vent system of `[tvs]` (issue 17, the paper's §9 "active pressure
//! control"; docs/PHYSICS.md 2.7): the MHTB's spray-bar device, which holds the tank pressure in
//! a band without settling the propellant.
//!
//! **The device.** A recirculation pump draws liquid from the tank and returns it through a
//! spray bar along the tank axis. A small share of the liquid is throttled through a
//! Joule–Thomson valve to a low pressure, where it boils at T_jt = T_sat(P_jt), colder than the
//! bulk; it flows through a heat exchanger against the recirculated stream, leaves as vapour
//! and is vented overboard. The vented mass carries away its latent heat: per kilogram the tank
//! loses h_g(T_jt) = h_l(T_jt) + h_fg(T_jt), where a plain vent of liquid would take only its
//! own enthalpy. Hastings et al., "Spray bar zero-gravity vent system for on-orbit liquid
//! hydrogen storage", NASA/TM-2003-212926 (18 m³ MHTB, 90/50/25 % fill, 20 and 50 W heat
//! leak): the pressure held in a 7 kPa band.
//!
//! **Control.** Hysteresis like the relief valve: the TVS starts when the ullage pressure
//! reaches `band_upper_pa` and stops when it falls to `band_lower_pa`; the integrator locates
//! both switches (`simulate::adaptive`) and counts the cycles. A phase may switch it off
//! (`phases.N.tvs`).
//!
//! **In the nodes.** While on, the J-T flow is drawn from the bulk (from the layer once the
//! bulk has merged into it) and leaves at h_g(T_jt) when the node it comes from is at least
//! [`EXCHANGER_PINCH_K`] warmer than T_jt — the exchanger is taken as sized to evaporate the
//! whole J-T flow, as the MHTB's was; the vapour's superheat in the exchanger is neglected (it
//! would remove a few per cent more) — at the node's own enthalpy at or below T_jt (nothing to
//! cool), and linearly between (the share of the flow the exchanger can evaporate).
//! The spray returns the recirculated liquid along the whole column: the layer's share of it,
//! ρ_b Q m_s / (m_s + m_b), is exchanged with equal bulk mass, destratifying the liquid as the
//! jet mixer does (`model::mixer`). The pump's heat enters the liquid (the `E_PUMP` ledger).
//! Not modelled: the spray's direct cooling of the ullage (at low fill the MHTB's spray bar
//! condensed vapour in the ullage), and the J-T valve's flow falling with the tank pressure
//! (the flow is fixed while on). The vented mass is the `VENT_TVS` slot, its energy is in
//! `E_VENT`. The homogeneous level, one well-mixed fluid, takes the vent and the pump heat.

use super::derive::Drive;
use super::params::Params;
use super::Group;
use crate::lanes::{c, Mask, Real};

/// The thermodynamic vent system of one instance (`[tvs]`), validated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tvs {
    /// Ullage pressure at or above which the TVS starts, Pa.
    pub band_upper_pa: f64,
    /// Ullage pressure at or below which it stops, Pa; below `band_upper_pa`.
    pub band_lower_pa: f64,
    /// Mass flow through the J-T valve while the TVS runs, kg/s, in (0, 10].
    pub jt_flow_kg_s: f64,
    /// Pressure downstream of the J-T valve, Pa: at least the fit's lowest saturation pressure
    /// and below `band_lower_pa`.
    pub jt_outlet_pa: f64,
    /// Recirculation (spray-bar) pump flow, m³/s, in [0, 10].
    pub pump_flow_m3_s: f64,
    /// Heat the pump dissipates in the propellant while it runs, W, in [0, 1e5].
    pub pump_heat_w: f64,
    /// T_jt = T_sat(`jt_outlet_pa`), K (derived at validation).
    pub jt_temperature_k: f64,
    /// h_g(T_jt) = h_l(T_jt) + h_fg(T_jt), J/kg on the fits' reference (derived at validation):
    /// the enthalpy the vented vapour leaves with.
    pub vent_enthalpy_j_per_kg: f64,
}

impl Tvs {
    /// The TVS with its derived fields for propellant fits `f`.
    pub fn new(
        f: &crate::fluids::FluidProps,
        (band_upper_pa, band_lower_pa): (f64, f64),
        (jt_flow_kg_s, jt_outlet_pa): (f64, f64),
        (pump_flow_m3_s, pump_heat_w): (f64, f64),
    ) -> Tvs {
        let t = f.tsat_k(jt_outlet_pa);
        Tvs {
            band_upper_pa,
            band_lower_pa,
            jt_flow_kg_s,
            jt_outlet_pa,
            pump_flow_m3_s,
            pump_heat_w,
            jt_temperature_k: t,
            vent_enthalpy_j_per_kg: f.h_l_j_per_kg(t) + f.h_fg_j_per_kg(t),
        }
    }
}

/// What the TVS does in each lane at one instant; zero where the campaign has no `[tvs]` or the
/// TVS is off.
#[derive(Clone, Copy, Debug, Default)]
pub struct TvsFlows<T> {
    /// J-T flow vented, kg/s.
    pub vent_kg_s: T,
    /// Recirculation flow, m³/s.
    pub pump_flow_m3_s: T,
    /// Pump heat into the liquid, W.
    pub pump_heat_w: T,
    /// T_jt, K (where on; 0 elsewhere).
    pub jt_temperature_k: T,
    /// h_g(T_jt), J/kg.
    pub vent_enthalpy_j_per_kg: T,
}

/// Temperature difference, K, across which the exchanger goes from evaporating nothing (liquid
/// at T_jt) to evaporating the whole J-T flow: a finite exchanger needs a driving difference,
/// and a step from h_l to h_g at T = T_jt made the bulk chatter on it (87 852 steps where 1 102
/// did, found by a user's attack).
pub const EXCHANGER_PINCH_K: f64 = 0.5;

impl<T: Real> TvsFlows<T> {
    /// The enthalpy the J-T flow leaves with when drawn from liquid at `t_k` (K) with specific
    /// enthalpy `h_j_per_kg` (J/kg): h_g(T_jt) where the liquid is at least
    /// [`EXCHANGER_PINCH_K`] warmer than T_jt, its own h at or below T_jt, linear between (the
    /// evaporated share of the flow).
    pub fn leaving_enthalpy(&self, t_k: T, h_j_per_kg: T) -> T {
        let share = ((t_k - self.jt_temperature_k) * (1.0 / EXCHANGER_PINCH_K)).clamp_c(0.0, 1.0);
        h_j_per_kg + share * (self.vent_enthalpy_j_per_kg - h_j_per_kg)
    }
}

/// The TVS flows of each lane under drive `d` (`nodes::rhs`, `homogeneous::rhs`).
pub(super) fn lanes<T: Real>(g: Group<'_>, d: &Drive<T>) -> TvsFlows<T> {
    if g.shared().tvs.is_none() || !d.tvs_on.any() {
        return TvsFlows::default();
    }
    let on = d.tvs_on;
    let get = |f: fn(&Tvs) -> f64| -> T {
        T::select(on, g.get(|p| p.tvs.as_ref().map_or(0.0, f)), c(0.0))
    };
    TvsFlows {
        vent_kg_s: get(|t| t.jt_flow_kg_s),
        pump_flow_m3_s: get(|t| t.pump_flow_m3_s),
        pump_heat_w: get(|t| t.pump_heat_w),
        jt_temperature_k: get(|t| t.jt_temperature_k),
        vent_enthalpy_j_per_kg: get(|t| t.vent_enthalpy_j_per_kg),
    }
}

/// The TVS's hysteresis in each lane: on at or above the band's upper pressure, off at or below
/// its lower one, in between as it was; off where the phase switches it off (`enabled`) or the
/// campaign has no `[tvs]`.
pub fn update<T: Real>(g: Group<'_>, pressure_pa: T, on: T::Mask, enabled: T::Mask) -> T::Mask {
    if g.shared().tvs.is_none() {
        return T::Mask::splat(false);
    }
    let upper: T = g.get(|p| p.tvs.map_or(0.0, |t| t.band_upper_pa));
    let lower: T = g.get(|p| p.tvs.map_or(0.0, |t| t.band_lower_pa));
    enabled & (pressure_pa.ge(upper) | (!pressure_pa.le(lower) & on))
}

/// The switching function of instance `p`'s TVS in state `on` at ullage pressure `pressure_pa`
/// (Pa): P − P_upper while off, P_lower − P while on; the TVS switches where it reaches 0.
pub fn switching(p: &Params, on: bool, pressure_pa: f64) -> f64 {
    let t = p.tvs.expect("a TVS switch needs a [tvs]");
    if on {
        t.band_lower_pa - pressure_pa
    } else {
        pressure_pa - t.band_upper_pa
    }
}
