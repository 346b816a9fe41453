//! Right-hand side of the `lumped` and `two_mode` levels: ullage, stratified layer, bulk liquid,
//! dry and wetted wall (MODEL.md §4, §6). Keep in sync with `shaders/` once the GPU mirror exists.
//!
//! Fluxes are written once and applied with opposite signs to the two nodes they connect, so
//! mass and energy are conserved by construction.

use super::boundary::{self, BoundaryFlows};
use super::derive::{Derived, Drive};
use super::params::Params;
use super::state::*;
use super::thermal::{self, ConvectionProps};
use crate::fluids::HELIUM;
use std::f64::consts::PI;

/// Interfacial and internal fluxes, for the output and the tests.
#[derive(Clone, Copy, Debug, Default)]
pub struct Fluxes {
    /// Net evaporation (negative: condensation), kg/s.
    pub evap_kg_s: f64,
    /// Growth of the warm layer by entrainment of bulk liquid, kg/s.
    pub strat_kg_s: f64,
    /// Slosh mixing exchange, kg/s each way.
    pub mix_kg_s: f64,
    /// Heat from the wetted wall into the liquid, W.
    pub q_wall_liquid_w: f64,
    /// Heat from the dry wall into the ullage, W.
    pub q_wall_ullage_w: f64,
    /// Heat from the ullage into the layer, W.
    pub q_ullage_layer_w: f64,
    pub boundary: BoundaryFlows,
    /// Lateral slosh force on the tank, N.
    pub slosh_force_n: f64,
}

/// The saturated-liquid fits one liquid node needs, evaluated once per right-hand side.
#[derive(Clone, Copy, Debug)]
pub(super) struct NodeFits {
    /// Temperature, K.
    pub t: f64,
    /// Density, kg/m³.
    pub rho: f64,
    /// Specific heat, J/(kg·K).
    pub cp: f64,
    /// dρ/dT, kg/(m³·K).
    pub drho_dt: f64,
    /// Specific enthalpy, J/kg.
    pub h: f64,
}

impl NodeFits {
    /// The fits at `t`, with the density `rho` the caller already has.
    pub(super) fn at(p: &Params, t: f64, rho: f64) -> NodeFits {
        let f = p.fluid.props();
        NodeFits {
            t,
            rho,
            cp: f.cp_l_j_per_kg_k(t),
            drho_dt: f.drho_l_dt(t),
            h: f.h_l_j_per_kg(t),
        }
    }

    /// Liquid properties for convection.
    pub(super) fn convection(&self, p: &Params) -> ConvectionProps {
        let f = p.fluid.props();
        ConvectionProps {
            k: f.k_l_w_per_m_k(self.t),
            mu: f.mu_l_pa_s(self.t),
            rho: self.rho,
            cp: self.cp,
            beta: -self.drho_dt / self.rho,
        }
    }
}

/// Liquid properties for convection at temperature `t`.
pub(super) fn liquid_props(p: &Params, t: f64) -> ConvectionProps {
    let rho = p.fluid.props().rho_l_kg_per_m3(t);
    NodeFits::at(p, t, rho).convection(p)
}

/// Ullage-gas properties at the ullage temperature: mass-fraction-weighted vapour and helium
/// transport properties (a mixing rule adequate for a convection estimate), ideal-gas β = 1/T.
pub(super) fn gas_props(p: &Params, s: &State, x: &Derived) -> ConvectionProps {
    let f = p.fluid.props();
    let m = x.m_vapor_kg + s[M_G];
    let y = if m > 0.0 { x.m_vapor_kg / m } else { 1.0 };
    let t = x.t_ullage_k;
    let ((k_v, mu_v), (k_g, mu_g)) = (f.vapor_transport(t), HELIUM.transport(t));
    ConvectionProps {
        k: y * k_v + (1.0 - y) * k_g,
        mu: y * mu_v + (1.0 - y) * mu_g,
        rho: m / x.v_ullage_m3,
        cp: y * f.cp_vapor_j_per_kg_k + (1.0 - y) * HELIUM.cp_j_per_kg_k,
        beta: 1.0 / t,
    }
}

/// Wetted-wall ↔ liquid and dry-wall ↔ gas coefficients, W/(m²·K): the campaign's constants, or
/// Churchill–Chu on the wetted and dry heights with the liquid at `t_liquid`, the gas at `t_gas`.
pub(super) fn wall_coefficients(
    p: &Params,
    x: &Derived,
    liq: &ConvectionProps,
    gas: &ConvectionProps,
    t_liquid: f64,
    t_gas: f64,
) -> (f64, f64) {
    let ht = &p.heat_transfer;
    let h_wl = ht.h_wall_liquid_w_per_m2_k.unwrap_or_else(|| {
        thermal::h_vertical_wall(liq, x.a_ax, x.t_wall_wet_k - t_liquid, x.level_m)
    });
    let h_wu = ht.h_wall_ullage_w_per_m2_k.unwrap_or_else(|| {
        thermal::h_vertical_wall(
            gas,
            x.a_ax,
            x.t_wall_dry_k - t_gas,
            p.tank.height_m() - x.level_m,
        )
    });
    (h_wl, h_wu)
}

/// Enthalpy change of a liquid node whose own volume change does work P dV on the ullage:
/// solves dH = F − P dV with dV = ṁ/ρ + β (dH − ṁ h), β = −ρ'/(ρ² c_p). Returns (dH/dt, dV/dt).
fn liquid_node_rates(p_pa: f64, flux_w: f64, dm: f64, n: &NodeFits) -> (f64, f64) {
    let (rho, h) = (n.rho, n.h);
    let beta = -n.drho_dt / (rho * rho * n.cp);
    let dh = (flux_w - p_pa * dm / rho + p_pa * beta * h * dm) / (1.0 + p_pa * beta);
    (dh, dm / rho + beta * (dh - h * dm))
}

/// Time derivative of the state at one instant. `dt` is the step the integrator is taking: the
/// stiff evaporation term is rate-limited to it (linearly implicit, see [`evaporation`]).
pub fn rhs(p: &Params, s: &State, d: &Drive, x: &Derived, dt: f64, ds: &mut State) -> Fluxes {
    let f = p.fluid.props();
    let ht = &p.heat_transfer;
    let off = vapor_enthalpy_offset(p.fluid);
    let (t_u, t_s, t_b) = (x.t_ullage_k, x.t_layer_k, x.t_bulk_k);
    let a_i = x.interface_area_m2;
    let r_surf = p.tank.surface_radius_m(x.level_m).max(1.0e-3);
    let a_tot = p.tank.wall_area_m2();
    let (a_wet, a_dry) = (a_tot * x.wetted_share, a_tot * (1.0 - x.wetted_share));
    let speed = boundary::slosh_speed(p, s, x);

    // Wall heat transfer (Churchill–Chu on each wetted and dry height).
    let (bulk, layer) = (
        NodeFits::at(p, t_b, x.rho_bulk),
        NodeFits::at(p, t_s, x.rho_layer),
    );
    let liq = bulk.convection(p);
    let gas = gas_props(p, s, x);
    let (h_wl, h_wu) = wall_coefficients(p, x, &liq, &gas, t_b, t_u);
    // The wetted wall passes its heat into the liquid with a uniform flux; each liquid node takes
    // the share of the wetted band it touches (MODEL.md §4): the layer the band between the
    // interface and its own depth, the bulk the rest. A single wall node at the bulk temperature
    // must not cool the warmer layer through that band, hence the flux split, not h (T_w − T_s).
    let c_wall = p.wall_areal_mass_kg_per_m2 * a_tot * p.wall_cp_j_per_kg_k;
    let c_bulk = s[M_B].max(1.0e-9) * liq.cp;
    let c_gas = s[M_V] * f.cv_vapor_j_per_kg_k + s[M_G] * HELIUM.cv_j_per_kg_k;
    let ua_wl = thermal::limited_conductance(h_wl * a_wet, dt, c_wall * x.wetted_share, c_bulk);
    let q_wl = ua_wl * (x.t_wall_wet_k - t_b);
    let depth = x.v_layer_m3 / a_i;
    let a_ws = (a_wet - p.tank.wetted_area_m2(x.level_m - depth)).clamp(0.0, a_wet);
    let contact = a_ws / a_wet.max(1.0e-12);
    // Optionally the wall boundary layer lifts part of the bulk's share to the surface.
    let to_layer = contact + p.stratification.wall_heat_to_layer * (1.0 - contact);
    let (q_ws, q_wb) = (to_layer * q_wl, (1.0 - to_layer) * q_wl);
    let ua_wu =
        thermal::limited_conductance(h_wu * a_dry, dt, c_wall * (1.0 - x.wetted_share), c_gas);
    let q_wu = ua_wu * (x.t_wall_dry_k - t_u);

    // Interface: ullage ↔ layer (stable, warm gas over cold liquid) and layer ↔ bulk.
    let h_us = ht
        .h_us_w_per_m2_k
        .unwrap_or_else(|| thermal::h_stable_interface(&gas, x.a_ax, t_u - t_s, 0.5 * r_surf))
        + p.coupling.h_enhancement_w_per_m2_k_s * speed;
    let q_us = h_us * a_i * (t_u - t_s);
    // Stable (warm layer on top): conduction is carried by the layer's penetration growth, so the
    // base coefficient is 0 unless set. Unstable (a layer cooled below the bulk by evaporation
    // into helium): the dense layer overturns, Lloyd & Moran's unstable-plate correlation.
    let h_sb = ht.h_sb_w_per_m2_k.unwrap_or(0.0)
        + thermal::h_unstable_interface(&liq, x.a_ax, t_b - t_s, 0.5 * r_surf)
        + p.coupling.h_enhancement_w_per_m2_k_s * speed;
    let q_sb = h_sb * a_i * (t_s - t_b);

    // Layer growth by conduction penetration: δ² = (π/4) α_eff t reproduces the surface
    // temperature of a semi-infinite liquid under constant flux (Carslaw & Jaeger §2.9), so
    // dm_s/dt = ρ A π α_eff / (8 δ), δ = m_s / (ρ A). Needs bulk liquid to entrain.
    let alpha =
        p.stratification.diffusivity_factor * f.k_l_w_per_m_k(t_s) / (x.rho_layer * layer.cp);
    let delta = (s[M_S] / (x.rho_layer * a_i)).max(1.0e-6);
    let bulk_left = (s[M_B] / (1.0e-4 * (s[M_B] + s[M_S]) + 1.0e-9)).clamp(0.0, 1.0);
    let m_strat = x.rho_layer * a_i * PI * alpha / (8.0 * delta) * bulk_left;
    let m_mix = p.coupling.mixing * s[M_S] * speed * bulk_left;

    let b = boundary::boundary_flows(p, s, d, x);
    // Gas-side mass-transfer coefficient by the heat/mass analogy (Le ≈ 1): h_m = h / (ρ c_p).
    let h_mass_m_s = h_us / (gas.rho * gas.cp);
    let h_fg = f.h_fg_j_per_kg(t_s);
    let m_evap = evaporation(p, s, x, dt, h_mass_m_s, layer.cp, h_fg);
    // Engine draws from the bulk, then from the layer once the bulk is gone.
    let (out_b, out_s) = (b.out_kg_s * bulk_left, b.out_kg_s * (1.0 - bulk_left));

    let (h_ls, h_lb) = (layer.h, bulk.h);
    let h_vap_gas = f.cp_vapor_j_per_kg_k * t_u + off;
    // Evaporating liquid carries h_l + h_fg at T_s; condensing vapour leaves at the gas enthalpy.
    let e_evap = m_evap.max(0.0) * (h_ls + h_fg) + m_evap.min(0.0) * h_vap_gas;
    let y = b.y_vapor;
    let h_u = y * h_vap_gas + (1.0 - y) * HELIUM.cp_j_per_kg_k * t_u;
    let h_press = boundary::helium_inlet_enthalpy(p);

    // Mass.
    ds[M_V] = m_evap - b.vent_kg_s * y;
    ds[M_G] = b.press_kg_s - b.vent_kg_s * (1.0 - y);
    ds[M_S] = -m_evap + m_strat - out_s;
    ds[M_B] = -m_strat - out_b;

    // Liquid energy with the work of its own expansion.
    let mix_w = m_mix * (h_ls - h_lb);
    let f_s = q_ws + q_us - q_sb - e_evap + m_strat * h_lb - mix_w - out_s * h_ls;
    let f_b = q_wb + q_sb - m_strat * h_lb + mix_w - out_b * h_lb;
    let pu = x.p_ullage_pa;
    let (dh_s, dv_s) = liquid_node_rates(pu, f_s, ds[M_S], &layer);
    let (dh_b, dv_b) = liquid_node_rates(pu, f_b, ds[M_B], &bulk);
    ds[H_S] = dh_s;
    ds[H_B] = dh_b;

    // Ullage energy: the liquid's expansion work arrives here; the slosh volume term is external.
    let force = boundary::motion_rates(p, s, d, x, ds);
    let angle = super::derive::slosh_angle(p, s, &x.slosh);
    let dv_slosh = p.coupling.volume_m3 * angle.cos() * boundary::slosh_angle_rate(p, s, x);
    ds[U_U] = q_wu - q_us + e_evap + b.press_kg_s * h_press - b.vent_kg_s * h_u
        + pu * (dv_s + dv_b)
        - pu * dv_slosh;

    boundary::wall_rates(p, x, q_wl, q_wu, dv_s + dv_b, ds);
    boundary::boundary_ledger(&b, h_press, h_u, out_s * h_ls + out_b * h_lb, ds);
    ds[E_WORK] = -pu * dv_slosh;

    Fluxes {
        evap_kg_s: m_evap,
        strat_kg_s: m_strat,
        mix_kg_s: m_mix,
        q_wall_liquid_w: q_wl,
        q_wall_ullage_w: q_wu,
        q_ullage_layer_w: q_us,
        boundary: b,
        slosh_force_n: force,
    }
}

/// Interfacial evaporation ṁ = K (P_sat(T_s) − P_v) (MODEL.md §4, [fix]: vapour partial pressure).
///
/// K is the Schrage kinetic coefficient in series with gas-side diffusion through the helium:
/// 1/K = 1/K_kin + x_He R_v T_u / (h_m A), with h_m the gas-side mass-transfer coefficient and
/// x_He the helium mole fraction (Stefan flow: no diffusion resistance in pure vapour). Without
/// it, evaporation into a helium ullage runs at the kinetic limit and freezes the surface.
///
/// A realistic K relaxes P_v onto P_sat(T_s) in milliseconds. The rate is taken linearly implicit
/// over the step: ṁ = K Δp / (1 + dt K J), J = ∂(P_v − P_sat)/∂m = R_v T_u / V_u +
/// P_sat'(T_s) h_fg / (m_s c_p), which is K Δp when K dt J ≪ 1 and the one-step relaxation of Δp
/// when K dt J ≫ 1, keeping the explicit RK step stable at any K.
/// `cp_layer` and `h_fg` are the layer's c_p,l and latent heat at T_s.
pub fn evaporation(
    p: &Params,
    s: &State,
    x: &Derived,
    dt: f64,
    h_mass_m_s: f64,
    cp_layer: f64,
    h_fg: f64,
) -> f64 {
    let f = p.fluid.props();
    let t_s = x.t_layer_k;
    let rv = f.r_specific_j_per_kg_k();
    let k_kin = p
        .heat_transfer
        .evaporation_coefficient_kg_per_s_pa
        .unwrap_or_else(|| {
            thermal::schrage_coefficient(
                x.interface_area_m2,
                p.heat_transfer.accommodation,
                f.molar_mass_kg_per_mol,
                t_s,
            )
        });
    let moles_v = s[M_V] / f.molar_mass_kg_per_mol;
    let moles_g = s[M_G] / HELIUM.molar_mass_kg_per_mol;
    let x_he = moles_g / (moles_v + moles_g).max(1.0e-300);
    let diffusion = x_he * rv * x.t_ullage_k / (h_mass_m_s * x.interface_area_m2).max(1.0e-300);
    let k = 1.0 / (1.0 / k_kin + diffusion);
    let (psat, dpsat_dt) = f.psat_and_slope(t_s);
    let dp = psat - x.p_vapor_pa;
    let j = rv * x.t_ullage_k / x.v_ullage_m3 + dpsat_dt * h_fg / (s[M_S].max(1.0e-9) * cp_layer);
    k * dp / (1.0 + dt * k * j)
}
