//! The `homogeneous` level: liquid, vapour and helium in thermal equilibrium at one temperature,
//! the vapour saturated (MODEL.md §1, §4). The classic baseline whose closed-tank pressure-rise
//! rate has a closed form (tested in `tests/homogeneous.rs`).
//!
//! Conserved slots: `M_B` holds all propellant (liquid + vapour), `H_B` the energy of all fluid,
//! `M_G` the helium. The temperature is the root of E(T) = `H_B`, with the vapour mass fixed by
//! saturation and the tank volume.

use super::boundary;
use super::derive::{fill_level, motion, wall_temperatures, Derived, Drive};
use super::params::Params;
use super::state::*;
use super::thermal;
use crate::fluids::HELIUM;

/// Vapour mass at temperature `t` when `m_p` of propellant fills `v_tank` in equilibrium:
/// m_v = ρ_v (V − m_p/ρ_l) / (1 − ρ_v/ρ_l), ρ_v = P_sat/(R_v T) (ideal gas, as in the ullage).
fn vapor_mass(p: &Params, m_p: f64, t: f64) -> f64 {
    let f = p.fluid.props();
    let rho_v = f.psat_pa(t) / (f.r_specific_j_per_kg_k() * t);
    let rho_l = f.rho_l_kg_per_m3(t);
    (rho_v * (p.tank.volume_m3() - m_p / rho_l) / (1.0 - rho_v / rho_l)).clamp(0.0, m_p)
}

/// Energy of all fluid at equilibrium temperature `t`, J: liquid m_l h_l(T), vapour
/// m_v (c_v,v T + offset) and helium m_g c_v,He T — the same references as the lumped nodes.
pub fn fluid_energy(p: &Params, m_p: f64, m_g: f64, t: f64) -> f64 {
    let f = p.fluid.props();
    let m_v = vapor_mass(p, m_p, t);
    let u_v = f.cv_vapor_j_per_kg_k * t + vapor_enthalpy_offset(p.fluid);
    (m_p - m_v) * f.h_l_j_per_kg(t) + m_v * u_v + m_g * HELIUM.cv_j_per_kg_k * t
}

/// Equilibrium temperature for the conserved propellant mass, helium mass and fluid energy:
/// Newton on E(T) with a secant-free analytic-enough central difference, started from the
/// all-liquid temperature, bracketed to the fluid's range.
pub fn temperature(p: &Params, m_p: f64, m_g: f64, e: f64) -> f64 {
    let f = p.fluid.props();
    let (lo, hi) = (f.t_min_k, f.t_max_k);
    let mut t = p.fluid.t_from_h_l_k(e / m_p).clamp(lo, hi);
    for _ in 0..40 {
        let h = 1.0e-6 * t;
        let r = fluid_energy(p, m_p, m_g, t) - e;
        let slope =
            (fluid_energy(p, m_p, m_g, t + h) - fluid_energy(p, m_p, m_g, t - h)) / (2.0 * h);
        let step = r / slope;
        t = (t - step).clamp(lo, hi);
        if step.abs() <= 1.0e-13 * t {
            break;
        }
    }
    t
}

/// Derived quantities of the equilibrium state.
pub fn derive(p: &Params, s: &State, d: &Drive) -> Derived {
    let f = p.fluid.props();
    let (m_p, m_g) = (s[M_B], s[M_G]);
    let t = temperature(p, m_p, m_g, s[H_B]);
    let m_v = vapor_mass(p, m_p, t);
    let rho = f.rho_l_kg_per_m3(t);
    let mut out = Derived {
        t_ullage_k: t,
        t_layer_k: t,
        t_bulk_k: t,
        rho_layer: rho,
        rho_bulk: rho,
        v_bulk_m3: (m_p - m_v) / rho,
        m_vapor_kg: m_v,
        m_liquid_kg: m_p - m_v,
        ..Default::default()
    };
    let v_l = out.v_bulk_m3;
    fill_level(p, &mut out, v_l);
    out.v_ullage_m3 = p.tank.volume_m3() - out.v_bulk_m3;
    out.p_vapor_pa = f.psat_pa(t);
    out.p_ullage_pa = out.p_vapor_pa + m_g * HELIUM.r_specific_j_per_kg_k() * t / out.v_ullage_m3;
    let (twd, tww) = wall_temperatures(p, s, out.wetted_share);
    out.t_wall_dry_k = twd;
    out.t_wall_wet_k = tww;
    motion(p, s, d, &mut out, f.mu_l_pa_s(t) / rho);
    out
}

/// Right-hand side of the equilibrium node: wall heat, helium, venting and outflow.
pub fn rhs(
    p: &Params,
    s: &State,
    d: &Drive,
    x: &Derived,
    dt: f64,
    ds: &mut State,
) -> boundary::BoundaryFlows {
    let f = p.fluid.props();
    let t = x.t_bulk_k;
    let a_tot = p.tank.wall_area_m2();
    let (a_wet, a_dry) = (a_tot * x.wetted_share, a_tot * (1.0 - x.wetted_share));
    let rho = x.rho_bulk;
    let liq = super::nodes::liquid_props(p, t);
    let gas = super::nodes::gas_props(p, s, x);
    let m_u = x.m_vapor_kg + s[M_G];
    let (h_wl, h_wu) = super::nodes::wall_coefficients(p, x, &liq, &gas, t, t);
    // The fluid's heat capacity is far larger than a wall node's: the wall side limits the step.
    let c_wall = p.wall_areal_mass_kg_per_m2 * a_tot * p.wall_cp_j_per_kg_k;
    let c_fluid = x.m_liquid_kg * liq.cp + m_u * f.cv_vapor_j_per_kg_k;
    let ua_wl = thermal::limited_conductance(h_wl * a_wet, dt, c_wall * x.wetted_share, c_fluid);
    let ua_wu =
        thermal::limited_conductance(h_wu * a_dry, dt, c_wall * (1.0 - x.wetted_share), c_fluid);
    let q_wl = ua_wl * (x.t_wall_wet_k - t);
    let q_wu = ua_wu * (x.t_wall_dry_k - t);

    // The M_V slot is unused here; the ullage composition comes from the equilibrium.
    let mut sv = *s;
    sv[M_V] = x.m_vapor_kg;
    let b = boundary::boundary_flows(p, &sv, d, x);
    let h_v = f.cp_vapor_j_per_kg_k * t + vapor_enthalpy_offset(p.fluid);
    let h_u = b.y_vapor * h_v + (1.0 - b.y_vapor) * HELIUM.cp_j_per_kg_k * t;
    let h_l = f.h_l_j_per_kg(t);
    let h_press = boundary::helium_inlet_enthalpy(p);

    ds[M_B] = -b.out_kg_s - b.vent_kg_s * b.y_vapor;
    ds[M_G] = b.press_kg_s - b.vent_kg_s * (1.0 - b.y_vapor);
    ds[H_B] = q_wl + q_wu + b.press_kg_s * h_press - b.vent_kg_s * h_u - b.out_kg_s * h_l;
    boundary::motion_rates(p, s, d, x, ds);

    // Level motion for the wall hand-over (vapour share neglected).
    boundary::wall_rates(p, x, q_wl, q_wu, ds[M_B] / rho, ds);
    boundary::boundary_ledger(&b, h_press, h_u, b.out_kg_s * h_l, ds);
    b
}
