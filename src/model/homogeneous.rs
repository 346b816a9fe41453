//! The `homogeneous` level: liquid, vapour and helium in thermal equilibrium at one temperature,
//! the vapour saturated (MODEL.md §1, §4). The classic baseline whose closed-tank pressure-rise
//! rate is checked against CoolProp's two-phase equilibrium (`tests/homogeneous.rs`).
//!
//! Conserved slots: `M_B` holds all propellant (liquid + vapour), `H_B` the internal energy of
//! all fluid, `M_G` the helium. The temperature is the root of E(T) = `H_B`, with the vapour mass
//! fixed by saturation and the tank volume. Real fluid throughout: the saturated-vapour density is
//! CoolProp's (fit `ln ρ_v`, not P_sat/(RT)), the vapour energy carries the virial form's
//! residual (`fluids::vapor`), and the liquid holds internal energy `u_l = h_l − P_sat/ρ_l` from
//! the saturated-liquid enthalpy. Helium is an ideal gas filling the same volume.

use super::boundary;
use super::derive::{fill_level, motion, wall_temperatures, Derived, Drive};
use super::params::Params;
use super::state::*;
use super::thermal;
use super::Group;
use crate::fluids::HELIUM;
use crate::lanes::{c, Mask, Real};

/// Vapour mass at temperature `t` when `m_p` of propellant fills `v_tank` in equilibrium:
/// m_v = ρ_v (V − m_p/ρ_l) / (1 − ρ_v/ρ_l), ρ_v the saturated-vapour density.
fn vapor_mass<T: Real>(g: Group<'_>, m_p: T, t: T) -> T {
    let f = g.shared().fluid.props();
    vapor_mass_at(g, m_p, f.rho_v_sat_kg_per_m3(t), f.rho_l_kg_per_m3(t))
}

/// [`vapor_mass`] from the saturated densities `rho_v`, `rho_l` (kg/m³) the caller already has.
fn vapor_mass_at<T: Real>(g: Group<'_>, m_p: T, rho_v: T, rho_l: T) -> T {
    let v_tank: T = g.get(|p| p.tank.volume_m3());
    (rho_v * (v_tank - m_p / rho_l) / (rho_v / rho_l).rsub(1.0))
        .max_c(0.0)
        .min(m_p)
}

/// Internal energy of all fluid at equilibrium temperature `t`, J: liquid m_l u_l(T), saturated
/// vapour m_v u_v(T) ([`saturated_vapor`]) and helium m_g c_v,He T. Each fit is evaluated once
/// (the Newton solve of [`temperature`] calls this three times per step).
pub fn fluid_energy<T: Real>(g: Group<'_>, m_p: T, m_g: T, t: T) -> T {
    let f = g.shared().fluid.props();
    let (rho_v, u_v, _) = saturated_vapor(g, t);
    let rho_l = f.rho_l_kg_per_m3(t);
    let m_v = vapor_mass_at(g, m_p, rho_v, rho_l);
    let u_l = f.h_l_j_per_kg(t) - f.psat_pa(t) / rho_l;
    (m_p - m_v) * u_l + m_v * u_v + m_g * HELIUM.cv_j_per_kg_k * t
}

/// Saturated vapour at `t`: (ρ_v kg/m³, u_v J/kg, h_v J/kg). u_v = u⁰(T) + offset + u_res(T, ρ_v)
/// with the offset of [`vapor_energy_offset`], so h_v − h_l = h_fg at the normal boiling
/// point and, through the fits, within 1e-3 of h_fg along the whole saturation line.
pub fn saturated_vapor<T: Real>(g: Group<'_>, t: T) -> (T, T, T) {
    let fluid = g.shared().fluid;
    let f = fluid.props();
    let rho_v = f.rho_v_sat_kg_per_m3(t);
    let (z, u_res) = f.vapor_z_u_res(t, rho_v);
    let rt = t * f.r_specific_j_per_kg_k();
    let u_v = f.vapor_ideal(t).0 + vapor_energy_offset(fluid) + u_res * rt;
    (rho_v, u_v, u_v + z * rt)
}

/// How far beyond the fitted range (K) the equilibrium temperature is still solved: a state whose
/// energy lies past the range then shows a bulk temperature out of range, which `simulate` reports
/// as a divergence (it allows 2 K), instead of a temperature pinned at the end of the range while
/// heat or vented latent heat silently vanishes (issue 13's attack: 20 kW into a LOX tank at
/// 3.27 MPa left P frozen at P_sat(t_max)).
pub const RANGE_MARGIN_K: f64 = 3.0;

/// Iteration cap of [`temperature`] (Newton steps plus bisections).
const MAX_ITER: usize = 80;

/// Equilibrium temperature for the conserved propellant mass, helium mass and fluid energy:
/// Newton on E(T) (increasing in T) with a central-difference slope, safeguarded by bisection on
/// the bracket [t_min − 3 K, t_max + 3 K] that each evaluation narrows; started from the
/// all-liquid temperature. The bracket makes it converge from any start: at low fills most of the
/// energy is in the vapour and that start lies far above the root (issue 13's attack: at 10 % fill
/// the unguarded Newton stuck at t_max and flashed the load to vapour). A lane stops moving once
/// its Newton step, or its bracket, is below 1e-13 T.
pub fn temperature<T: Real>(g: Group<'_>, m_p: T, m_g: T, e: T) -> T {
    let fluid = g.shared().fluid;
    let f = fluid.props();
    let mut lo = T::splat(f.t_min_k - RANGE_MARGIN_K);
    let mut hi = T::splat(f.t_max_k + RANGE_MARGIN_K);
    let mut t = fluid.t_from_h_l_k(e / m_p).clamp_c(f.t_min_k, f.t_max_k);
    let mut done = T::Mask::splat(false);
    for _ in 0..MAX_ITER {
        let h = t * 1.0e-6;
        let r = fluid_energy(g, m_p, m_g, t) - e;
        let slope =
            (fluid_energy(g, m_p, m_g, t + h) - fluid_energy(g, m_p, m_g, t - h)) / (h * 2.0);
        let moving = !done;
        hi = T::select(moving & r.gt(c(0.0)), t, hi);
        lo = T::select(moving & r.lt(c(0.0)), t, lo);
        let newton = t - r / slope;
        let inside = newton.gt(lo) & newton.lt(hi) & slope.gt(c(0.0));
        let converged = inside & (newton - t).abs().le(t * 1.0e-13);
        let bracketed = (hi - lo).le(t * 1.0e-13);
        let next = T::select(inside, newton, (lo + hi) * 0.5);
        t = T::select(done, t, next);
        done = done | converged | bracketed | r.is(|v| v == 0.0 || v.is_nan());
        if done.all() {
            break;
        }
    }
    t
}

/// Derived quantities of the equilibrium state.
pub fn derive<T: Real>(g: Group<'_>, s: &State<T>, d: &Drive<T>) -> Derived<T> {
    let f = g.shared().fluid.props();
    let (m_p, m_g) = (s[M_B], s[M_G]);
    let t = temperature(g, m_p, m_g, s[H_B]);
    let m_v = vapor_mass(g, m_p, t);
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
    let tank = g.tank();
    fill_level(g, &tank, &mut out, v_l);
    let v_tank: T = g.get(|p| p.tank.volume_m3());
    out.v_ullage_m3 = v_tank - out.v_bulk_m3;
    out.p_vapor_pa = f.psat_pa(t);
    out.p_ullage_pa = out.p_vapor_pa + m_g * HELIUM.r_specific_j_per_kg_k() * t / out.v_ullage_m3;
    let (twd, tww) = wall_temperatures(g, s, out.wetted_share);
    out.t_wall_dry_k = twd;
    out.t_wall_wet_k = tww;
    motion(g, &tank, s, d, &mut out, move || f.mu_l_pa_s(t) / rho);
    out
}

/// Right-hand side of the equilibrium node: wall heat, pressurant, venting and outflow.
pub fn rhs<T: Real>(
    g: Group<'_>,
    s: &State<T>,
    d: &Drive<T>,
    x: &Derived<T>,
    dt: T,
    ds: &mut State<T>,
) -> boundary::BoundaryFlows<T> {
    let fluid = g.shared().fluid;
    let f = fluid.props();
    let t = x.t_bulk_k;
    let a_tot: T = g.get(|p| p.tank.wall_area_m2());
    let dry_share = x.wetted_share.rsub(1.0);
    let (a_wet, a_dry) = (a_tot * x.wetted_share, a_tot * dry_share);
    let rho = x.rho_bulk;
    let liq = super::nodes::liquid_props(g, t);
    let cv_vapor = f.vapor_ideal(t).1;
    let gas = super::nodes::gas_props(g, s, x, cv_vapor + f.r_specific_j_per_kg_k());
    let m_u = x.m_vapor_kg + s[M_G];
    let (h_wl, h_wu) = super::nodes::wall_coefficients(g, x, &liq, &gas, t, t);
    // The fluid's heat capacity is far larger than a wall node's: the wall side limits the step.
    let c_wall: T = g.get(Params::wall_heat_capacity_j_per_k);
    let c_fluid = x.m_liquid_kg * liq.cp + m_u * cv_vapor;
    let env = super::insulation::wall_heat(g, d, x);
    let exchange = |h: T, area: T, share: T, t_wall: T, warming: T| {
        thermal::wall_exchange(h * area, dt, c_wall * share, c_fluid, t_wall - t, warming)
    };
    let q_wl = exchange(
        h_wl,
        a_wet,
        x.wetted_share,
        x.t_wall_wet_k,
        env.warming_wet_k_s,
    );
    let q_wu = exchange(h_wu, a_dry, dry_share, x.t_wall_dry_k, env.warming_dry_k_s);

    // The M_V slot is unused here; the ullage composition comes from the equilibrium.
    let mut sv = *s;
    sv[M_V] = x.m_vapor_kg;
    let b = boundary::boundary_flows(g, &sv, d, x);
    let (_, _, h_v) = saturated_vapor(g, t);
    let h_u = b.y_vapor * h_v + b.y_vapor.rsub(1.0) * HELIUM.cp_j_per_kg_k * t;
    let h_l = f.h_l_j_per_kg(t);
    let h_press = boundary::pressurant_inlet_enthalpy(g, x.p_ullage_pa);
    // Autogenous pressurant is propellant: it joins M_B (the equilibrium decides its phase).
    let press_v = b.press_kg_s * boundary::pressurant_vapor_share::<T>(g);

    // The thermodynamic vent system draws liquid that leaves at h_g(T_jt) (`model::tvs`).
    let tvs = super::tvs::lanes(g, d);
    let h_tvs = tvs.leaving_enthalpy(t, h_l);
    ds[M_B] = press_v - b.out_kg_s - b.vent_kg_s * b.y_vapor - tvs.vent_kg_s;
    ds[M_G] = b.press_kg_s - press_v - b.vent_kg_s * b.y_vapor.rsub(1.0);
    // The jet mixer and the TVS's spray: one well-mixed fluid has no stratification to
    // destroy, so only their pump heat acts (`model::mixer`).
    let (_, q_mixer) = super::mixer::lanes(g, d);
    let q_pump = q_mixer + tvs.pump_heat_w;
    ds[H_B] = q_wl + q_wu + b.press_kg_s * h_press - b.vent_kg_s * h_u - b.out_kg_s * h_l + q_pump
        - tvs.vent_kg_s * h_tvs;
    ds[E_PUMP] = q_pump;
    boundary::motion_rates(g, s, d, x, ds);

    // Level motion for the wall hand-over (vapour share neglected).
    boundary::wall_rates(g, &g.tank(), x, &env, q_wl, q_wu, ds[M_B] / rho, ds);
    boundary::boundary_ledger(&b, h_press, h_u, b.out_kg_s * h_l, ds);
    ds[VENT_TVS] = tvs.vent_kg_s;
    ds[E_VENT] += tvs.vent_kg_s * h_tvs;
    b
}
