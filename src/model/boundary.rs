//! What crosses the tank boundary and the vehicle motion, shared by every thermal level:
//! helium inflow, relief venting, engine draw, slosh and flight derivatives (MODEL.md §5, §7, §8).

use super::derive::{Derived, Drive};
use super::flight::{self, G0};
use super::params::{Fidelity, Params};
use super::state::*;
use super::thermal;
use crate::fluids::HELIUM;

/// Flows through the tank boundary at one instant, kg/s.
#[derive(Clone, Copy, Debug, Default)]
pub struct BoundaryFlows {
    /// Helium admitted.
    pub press_kg_s: f64,
    /// Ullage mixture vented.
    pub vent_kg_s: f64,
    /// Vapour mass fraction of the ullage (and of the vented gas).
    pub y_vapor: f64,
    /// Engine draw from this tank.
    pub out_kg_s: f64,
}

/// Helium PD flow, relief flow and engine draw.
pub fn boundary_flows(p: &Params, s: &State, d: &Drive, x: &Derived) -> BoundaryFlows {
    let f = p.fluid.props();
    let m_u = s[M_V] + s[M_G];
    let y_v = if m_u > 0.0 { s[M_V] / m_u } else { 1.0 };
    let mut b = BoundaryFlows {
        y_vapor: y_v,
        ..Default::default()
    };
    if let Some(ps) = p.pressurization.filter(|_| d.pressurize) {
        let e = ps.setpoint_pa - x.p_ullage_pa;
        let e_dot = -(x.p_ullage_pa - s[P_FILT]) / ps.derivative_filter_s;
        let demand =
            (ps.kp_kg_per_s_pa * e + ps.kd_kg_per_pa * e_dot).clamp(0.0, ps.max_flow_kg_per_s);
        // The flow fades to zero over the last 0.1 % of the bottle instead of stopping abruptly.
        let left = ps.bottle_mass_kg - s[PRESS_IN];
        let fade = (left / (1.0e-3 * ps.bottle_mass_kg + 1.0e-9)).clamp(0.0, 1.0);
        b.press_kg_s = demand * fade;
    }
    if let Some(r) = p.relief.filter(|_| d.valve_open) {
        let rv = f.r_specific_j_per_kg_k();
        let rg = HELIUM.r_specific_j_per_kg_k();
        let r_mix = y_v * rv + (1.0 - y_v) * rg;
        let cp = y_v * f.cp_vapor_j_per_kg_k + (1.0 - y_v) * HELIUM.cp_j_per_kg_k;
        let cv = y_v * f.cv_vapor_j_per_kg_k + (1.0 - y_v) * HELIUM.cv_j_per_kg_k;
        let back = flight::ambient_pressure(s[ALT]);
        b.vent_kg_s = thermal::orifice_flow(
            r.flow_area_m2,
            x.p_ullage_pa,
            back,
            x.t_ullage_k,
            r_mix,
            cp / cv,
        );
    }
    if d.burning {
        let engine = d.thrust_n / (p.feed.isp_s * G0);
        // Starve smoothly over the last gram-scale sliver rather than drawing a negative mass.
        let avail = (x.m_liquid_kg / (1.0e-6 * x.m_liquid_kg.max(1.0) + 1.0e-3)).clamp(0.0, 1.0);
        b.out_kg_s = engine * p.feed.propellant_fraction * avail;
    }
    b
}

/// Slosh and flight derivatives into `ds`; returns the lateral slosh force on the tank, N.
pub fn motion_rates(p: &Params, s: &State, d: &Drive, x: &Derived, ds: &mut State) -> f64 {
    let sl = &x.slosh;
    let force = match p.fidelity {
        Fidelity::Homogeneous => 0.0,
        Fidelity::Lumped => {
            let (th, w) = (s[Q1], s[Q1D]);
            let (l, om, ze) = (sl.length_m[0], sl.omega[0], sl.zeta[0]);
            let acc = -(x.a_ax / l) * th.sin() - 2.0 * ze * om * w - (d.a_lat / l) * th.cos();
            ds[Q1] = w;
            ds[Q1D] = acc;
            // Force of the pendulum on the tank: −m_1 (ẍ + a_lat) with x = L sin θ (MODEL.md §5).
            -sl.mass_kg[0] * (l * (acc * th.cos() - w * w * th.sin()) + d.a_lat)
        }
        Fidelity::TwoMode => {
            let mut force = 0.0;
            for (n, (q, qd)) in [(Q1, Q1D), (Q2, Q2D)].into_iter().enumerate() {
                let (om, ze) = (sl.omega[n], sl.zeta[n]);
                let acc = -om * om * s[q] - 2.0 * ze * om * s[qd] - d.a_lat;
                ds[q] = s[qd];
                ds[qd] = acc;
                force -= sl.mass_kg[n] * (acc + d.a_lat);
            }
            force
        }
    };
    if d.flying {
        let g = flight::gravity(s[ALT]);
        ds[VEL] = (d.thrust_n - x.drag_n) / x.vehicle_mass_kg - g * d.gamma_rad.sin();
        ds[ALT] = s[VEL] * d.gamma_rad.sin();
    }
    if let Some(ps) = p.pressurization {
        ds[P_FILT] = (x.p_ullage_pa - s[P_FILT]) / ps.derivative_filter_s;
    }
    force
}

/// Slosh speed used by the mixing couplings, rad/s: |θ̇| or Σ |ẋ_n| / L_n (MODEL.md §6.2).
pub fn slosh_speed(p: &Params, s: &State, x: &Derived) -> f64 {
    match p.fidelity {
        Fidelity::Homogeneous => 0.0,
        Fidelity::Lumped => s[Q1D].abs(),
        Fidelity::TwoMode => {
            s[Q1D].abs() / x.slosh.length_m[0] + s[Q2D].abs() / x.slosh.length_m[1]
        }
    }
}

/// Rate of the slosh angle, rad/s, for the coupling-I work term.
pub fn slosh_angle_rate(p: &Params, s: &State, x: &Derived) -> f64 {
    match p.fidelity {
        Fidelity::TwoMode => {
            let l = x.slosh.length_m[0];
            let r = s[Q1] / l;
            s[Q1D] / l / (1.0 + r * r)
        }
        _ => s[Q1D],
    }
}

/// Wall node rates: the insulation heat by area share, less the heat each node passes to the
/// fluid (`q_wet_w` into the liquid, `q_dry_w` into the ullage), plus the hand-over of wall mass
/// and its energy as the waterline moves with the liquid volume rate `dv_liquid_m3_s`.
pub fn wall_rates(
    p: &Params,
    x: &Derived,
    q_wet_w: f64,
    q_dry_w: f64,
    dv_liquid_m3_s: f64,
    ds: &mut State,
) {
    let dz = dv_liquid_m3_s / p.tank.cross_section_area_m2(x.level_m).max(1.0e-9);
    let m_wall = p.wall_areal_mass_kg_per_m2 * p.tank.wall_area_m2();
    let dshare = x.wetted_share_slope * dz;
    let t_moving = if dshare < 0.0 {
        x.t_wall_wet_k
    } else {
        x.t_wall_dry_k
    };
    let handover = m_wall * dshare * p.wall_cp_j_per_kg_k * t_moving;
    let q_env = p.heat_leak_w;
    ds[E_WD] = q_env * (1.0 - x.wetted_share) - q_dry_w - handover;
    ds[E_WW] = q_env * x.wetted_share - q_wet_w + handover;
    ds[E_ENV] = q_env;
}

/// The ledger of what crossed the tank boundary: vented species, drawn propellant, helium in,
/// and their energies (`h_u` the ullage enthalpy, `e_out_w` the enthalpy flow of the draw).
pub fn boundary_ledger(b: &BoundaryFlows, h_press: f64, h_u: f64, e_out_w: f64, ds: &mut State) {
    ds[VENT_V] = b.vent_kg_s * b.y_vapor;
    ds[VENT_G] = b.vent_kg_s * (1.0 - b.y_vapor);
    ds[OUT] = b.out_kg_s;
    ds[PRESS_IN] = b.press_kg_s;
    ds[E_PRESS] = b.press_kg_s * h_press;
    ds[E_VENT] = b.vent_kg_s * h_u;
    ds[E_OUT] = e_out_w;
}

/// Helium enthalpy at the inlet temperature, J/kg.
pub fn helium_inlet_enthalpy(p: &Params) -> f64 {
    p.pressurization
        .map_or(0.0, |ps| HELIUM.cp_j_per_kg_k * ps.gas_temperature_k)
}
