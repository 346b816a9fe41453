//! What crosses the tank boundary and the vehicle motion, shared by every thermal level:
//! pressurant inflow, relief venting, engine draw, slosh and flight derivatives (MODEL.md §5, §7, §8).

use super::derive::{Derived, Drive};
use super::flight::{self, G0};
use super::params::{Fidelity, Params};
use super::state::*;
use super::thermal;
use super::Group;
use crate::fluids::HELIUM;
use crate::lanes::{c, math, Mask, Real};

/// Flows through the tank boundary at one instant, kg/s.
#[derive(Clone, Copy, Debug, Default)]
pub struct BoundaryFlows<T = f64> {
    /// Pressurant admitted (helium, or vapour when autogenous).
    pub press_kg_s: T,
    /// Ullage mixture vented.
    pub vent_kg_s: T,
    /// Vapour mass fraction of the ullage (and of the vented gas).
    pub y_vapor: T,
    /// Engine draw from this tank.
    pub out_kg_s: T,
}

impl<T: Real> BoundaryFlows<T> {
    /// Lane `i`.
    pub fn lane(&self, i: usize) -> BoundaryFlows {
        BoundaryFlows {
            press_kg_s: self.press_kg_s.lane(i),
            vent_kg_s: self.vent_kg_s.lane(i),
            y_vapor: self.y_vapor.lane(i),
            out_kg_s: self.out_kg_s.lane(i),
        }
    }
}

/// Pressurant PD flow, relief flow and engine draw. Each is evaluated only when some lane needs
/// it and applies in the lanes that do.
pub fn boundary_flows<T: Real>(
    g: Group<'_>,
    s: &State<T>,
    d: &Drive<T>,
    x: &Derived<T>,
) -> BoundaryFlows<T> {
    let f = g.shared().fluid.props();
    let m_u = s[M_V] + s[M_G];
    let y_v = T::select(m_u.gt(c(0.0)), s[M_V] / m_u, c(1.0));
    let mut b = BoundaryFlows {
        y_vapor: y_v,
        ..Default::default()
    };
    if g.shared().pressurization.is_some() && d.pressurize.any() {
        let ps = |h: fn(&super::params::Pressurization) -> f64| {
            g.get::<T>(move |p| p.pressurization.as_ref().map_or(0.0, h))
        };
        let (setpoint, tau) = (ps(|q| q.setpoint_pa), ps(|q| q.derivative_filter_s));
        let (kp, kd) = (ps(|q| q.kp_kg_per_s_pa), ps(|q| q.kd_kg_per_pa));
        let (max_flow, bottle) = (ps(|q| q.max_flow_kg_per_s), ps(|q| q.bottle_mass_kg));
        let e = setpoint - x.p_ullage_pa;
        let e_dot = -(x.p_ullage_pa - s[P_FILT]) / tau;
        // Gain schedule (`GainSchedule`): both gains times V_u / V_ref where a lane schedules
        // them (V_ref > 0), else times 1 (exact: the fixed regulator's bits are unchanged).
        let v_ref = ps(|q| q.gain_schedule.reference_or_zero_m3());
        let scheduled = v_ref.gt(c(0.0));
        let pd = kp * e + kd * e_dot;
        let pd = if scheduled.any() {
            pd * T::select(scheduled, x.v_ullage_m3 / v_ref, c(1.0))
        } else {
            pd
        };
        let demand = pd.max_c(0.0).min(max_flow);
        // The flow fades to zero over the last 0.1 % of the bottle instead of stopping abruptly.
        let left = bottle - s[PRESS_IN];
        let fade = (left / (bottle * 1.0e-3 + 1.0e-9)).clamp_c(0.0, 1.0);
        b.press_kg_s = T::select(d.pressurize, demand * fade, c(0.0));
    }
    if g.shared().relief.is_some() && d.valve_open.any() {
        let rv = f.r_specific_j_per_kg_k();
        let rg = HELIUM.r_specific_j_per_kg_k();
        let vapour = y_v.rsub(1.0);
        let r_mix = y_v * rv + vapour * rg;
        let cv_v = f.vapor_ideal(x.t_ullage_k).1;
        let cp = y_v * (cv_v + rv) + vapour * HELIUM.cp_j_per_kg_k;
        let cv = y_v * cv_v + vapour * HELIUM.cv_j_per_kg_k;
        let back = flight::ambient_pressure(s[ALT]);
        let area: T = g.get(|p| p.relief.map_or(0.0, |r| r.flow_area_m2));
        let vent = thermal::orifice_flow(area, x.p_ullage_pa, back, x.t_ullage_k, r_mix, cp / cv);
        b.vent_kg_s = T::select(d.valve_open, vent, c(0.0));
    }
    if d.burning.any() {
        let isp: T = g.get(|p| p.feed.isp_s);
        let frac: T = g.get(|p| p.feed.propellant_fraction);
        let engine = d.thrust_n / (isp * G0);
        // Starve smoothly over the last gram-scale sliver rather than drawing a negative mass.
        let m_l = x.m_liquid_kg;
        let avail = (m_l / (m_l.max_c(1.0) * 1.0e-6 + 1.0e-3)).clamp_c(0.0, 1.0);
        b.out_kg_s = T::select(d.burning, engine * frac * avail, c(0.0));
    }
    b
}

/// Slosh and flight derivatives into `ds`; returns the lateral slosh force on the tank, N.
pub fn motion_rates<T: Real>(
    g: Group<'_>,
    s: &State<T>,
    d: &Drive<T>,
    x: &Derived<T>,
    ds: &mut State<T>,
) -> T {
    let sl = &x.slosh;
    let force = match g.shared().fidelity {
        Fidelity::Homogeneous => c(0.0),
        Fidelity::Lumped => {
            let (th, w) = (s[Q1], s[Q1D]);
            let (l, om, ze) = (sl.length_m[0], sl.omega[0], sl.zeta[0]);
            let (sin, cos) = (math::sin(th), math::cos(th));
            let acc = -(x.a_ax / l) * sin - ze * 2.0 * om * w - (d.a_lat / l) * cos;
            ds[Q1] = w;
            ds[Q1D] = acc;
            // Force of the pendulum on the tank: −m_1 (ẍ + a_lat) with x = L sin θ (MODEL.md §5).
            -sl.mass_kg[0] * (l * (acc * cos - w * w * sin) + d.a_lat)
        }
        Fidelity::TwoMode | Fidelity::Layered => {
            let mut force = c(0.0);
            for (n, (q, qd)) in [(Q1, Q1D), (Q2, Q2D)].into_iter().enumerate() {
                let (om, ze) = (sl.omega[n], sl.zeta[n]);
                let acc = -om * om * s[q] - ze * 2.0 * om * s[qd] - d.a_lat;
                ds[q] = s[qd];
                ds[qd] = acc;
                force -= sl.mass_kg[n] * (acc + d.a_lat);
            }
            force
        }
    };
    if d.flying.any() {
        let gravity = flight::gravity(s[ALT]);
        let sin_gamma = math::sin(d.gamma_rad);
        let dv = (d.thrust_n - x.drag_n) / x.vehicle_mass_kg - gravity * sin_gamma;
        ds[VEL] = T::select(d.flying, dv, ds[VEL]);
        ds[ALT] = T::select(d.flying, s[VEL] * sin_gamma, ds[ALT]);
    }
    if g.shared().pressurization.is_some() {
        let tau: T = g.get(|p| p.pressurization.map_or(1.0, |q| q.derivative_filter_s));
        ds[P_FILT] = (x.p_ullage_pa - s[P_FILT]) / tau;
    }
    force
}

/// Slosh speed used by the mixing couplings, rad/s: |θ̇| or Σ |ẋ_n| / L_n (MODEL.md §6.2).
pub fn slosh_speed<T: Real>(g: Group<'_>, s: &State<T>, x: &Derived<T>) -> T {
    match g.shared().fidelity {
        Fidelity::Homogeneous => c(0.0),
        Fidelity::Lumped => s[Q1D].abs(),
        Fidelity::TwoMode | Fidelity::Layered => {
            s[Q1D].abs() / x.slosh.length_m[0] + s[Q2D].abs() / x.slosh.length_m[1]
        }
    }
}

/// Rate of the slosh angle, rad/s, for the coupling-I work term.
pub fn slosh_angle_rate<T: Real>(g: Group<'_>, s: &State<T>, x: &Derived<T>) -> T {
    match g.shared().fidelity {
        Fidelity::TwoMode | Fidelity::Layered => {
            let l = x.slosh.length_m[0];
            let r = s[Q1] / l;
            s[Q1D] / l / (r * r + 1.0)
        }
        _ => s[Q1D],
    }
}

/// Wall node rates: the heat from outside (`env`, [`super::insulation::wall_heat`]), less the
/// heat each node passes to the fluid (`q_wet_w` into the liquid, `q_dry_w` into the ullage),
/// plus the hand-over of wall mass and its energy as the waterline moves with the liquid volume
/// rate `dv_liquid_m3_s`.
#[expect(
    clippy::too_many_arguments,
    reason = "the wall's inputs, each a lane value"
)]
pub fn wall_rates<T: Real>(
    g: Group<'_>,
    tank: &crate::geometry::TankLanes<T>,
    x: &Derived<T>,
    env: &super::insulation::WallHeat<T>,
    q_wet_w: T,
    q_dry_w: T,
    dv_liquid_m3_s: T,
    ds: &mut State<T>,
) {
    let section = tank.interface_area_m2(x.level_m);
    let dz = dv_liquid_m3_s / section.max_c(1.0e-9);
    let m_wall: T = g.get(Params::wall_mass_kg);
    let cp_wall: T = g.get(|p| p.wall_cp_j_per_kg_k);
    let dshare = x.wetted_share_slope * dz;
    let t_moving = T::select(dshare.lt(c(0.0)), x.t_wall_wet_k, x.t_wall_dry_k);
    let handover = m_wall * dshare * cp_wall * t_moving;
    ds[E_WD] = env.dry_w - q_dry_w - handover;
    ds[E_WW] = env.wet_w - q_wet_w + handover;
    ds[E_ENV] = env.total_w;
}

/// The ledger of what crossed the tank boundary: vented species, drawn propellant, pressurant in,
/// and their energies (`h_u` the ullage enthalpy, `e_out_w` the enthalpy flow of the draw).
pub fn boundary_ledger<T: Real>(
    b: &BoundaryFlows<T>,
    h_press: T,
    h_u: T,
    e_out_w: T,
    ds: &mut State<T>,
) {
    ds[VENT_V] = b.vent_kg_s * b.y_vapor;
    ds[VENT_G] = b.vent_kg_s * b.y_vapor.rsub(1.0);
    ds[OUT] = b.out_kg_s;
    ds[PRESS_IN] = b.press_kg_s;
    ds[E_PRESS] = b.press_kg_s * h_press;
    ds[E_VENT] = b.vent_kg_s * h_u;
    ds[E_OUT] = e_out_w;
}

/// Pressurant enthalpy at the inlet temperature, J/kg, entering at the ullage pressure
/// `p_ullage_pa` (Pa): helium c_p,He T_in, or for autogenous pressurization the real-gas vapour
/// u⁰(T_in) + R T_in + offset + h_res(T_in, P) on the ullage's reference (so that the `E_PRESS`
/// ledger closes the energy balance; `h_res` from
/// [`crate::fluids::FluidProps::vapor_h_res_at_tp`]).
pub fn pressurant_inlet_enthalpy<T: Real>(g: Group<'_>, p_ullage_pa: T) -> T {
    let t_in: T = g.get(|p| p.pressurization.map_or(0.0, |ps| ps.gas_temperature_k));
    let helium = t_in * HELIUM.cp_j_per_kg_k;
    let autogenous = pressurant_vapor_share::<T>(g).gt(c(0.0));
    if !autogenous.any() {
        return helium;
    }
    let fluid = g.shared().fluid;
    let f = fluid.props();
    let (u0, _) = f.vapor_ideal(t_in);
    let h_res = f.vapor_h_res_at_tp(t_in, p_ullage_pa);
    let vapour = u0 + t_in * f.r_specific_j_per_kg_k() + vapor_energy_offset(fluid) + h_res;
    T::select(autogenous, vapour, helium)
}

/// Share of the pressurant flow that enters as propellant vapour (1 autogenous, 0 helium), per
/// lane.
pub fn pressurant_vapor_share<T: Real>(g: Group<'_>) -> T {
    g.get(Params::pressurant_vapor_share)
}
