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
use super::Group;
use crate::fluids::HELIUM;
use crate::geometry::TankLanes;
use crate::lanes::{c, math, Mask, Real};
use std::f64::consts::PI;

/// Interfacial and internal fluxes, for the output and the tests.
#[derive(Clone, Copy, Debug, Default)]
pub struct Fluxes<T = f64> {
    /// Net evaporation (negative: condensation), kg/s.
    pub evap_kg_s: T,
    /// Relaxation rate of the interface pressure difference under evaporation, K·J, 1/s: its
    /// inverse is the physical time the evaporation takes to follow a change (milliseconds).
    pub evap_relaxation_per_s: T,
    /// Growth of the warm layer by entrainment of bulk liquid (conduction penetration and slosh
    /// mixing), kg/s.
    pub strat_kg_s: T,
    /// Layer ↔ bulk exchange by the jet mixer and the TVS spray, kg/s each way.
    pub mix_kg_s: T,
    /// Liquid the wall boundary layer brings to the top of the column, kg/s (`layered`; 0 on
    /// the other levels).
    pub boundary_layer_kg_s: T,
    /// Heat from the wetted wall into the liquid, W.
    pub q_wall_liquid_w: T,
    /// Heat from the dry wall into the ullage, W.
    pub q_wall_ullage_w: T,
    /// Heat from the ullage into the layer, W.
    pub q_ullage_layer_w: T,
    pub boundary: BoundaryFlows<T>,
    /// Lateral slosh force on the tank, N.
    pub slosh_force_n: T,
}

impl<T: Real> Fluxes<T> {
    /// Lane `i`.
    pub fn lane(&self, i: usize) -> Fluxes {
        Fluxes {
            evap_kg_s: self.evap_kg_s.lane(i),
            evap_relaxation_per_s: self.evap_relaxation_per_s.lane(i),
            strat_kg_s: self.strat_kg_s.lane(i),
            mix_kg_s: self.mix_kg_s.lane(i),
            boundary_layer_kg_s: self.boundary_layer_kg_s.lane(i),
            q_wall_liquid_w: self.q_wall_liquid_w.lane(i),
            q_wall_ullage_w: self.q_wall_ullage_w.lane(i),
            q_ullage_layer_w: self.q_ullage_layer_w.lane(i),
            boundary: self.boundary.lane(i),
            slosh_force_n: self.slosh_force_n.lane(i),
        }
    }
}

/// The saturated-liquid fits one liquid node needs, evaluated once per right-hand side.
#[derive(Clone, Copy, Debug)]
pub(super) struct NodeFits<T> {
    /// Temperature, K.
    pub t: T,
    /// Density, kg/m³.
    pub rho: T,
    /// Specific heat c_p,l, J/(kg·K) (convection and diffusivity).
    pub cp: T,
    /// Slope of the node's enthalpy h_l(T) along saturation, J/(kg·K): what turns an enthalpy
    /// rate into a temperature rate consistently with `derive` (T from h_l).
    pub dh_dt: T,
    /// dρ/dT, kg/(m³·K).
    pub drho_dt: T,
    /// Specific enthalpy, J/kg.
    pub h: T,
}

impl<T: Real> NodeFits<T> {
    /// The fits at `t`, with the density `rho` the caller already has.
    pub(super) fn at(g: Group<'_>, t: T, rho: T) -> NodeFits<T> {
        let f = g.shared().fluid.props();
        NodeFits {
            t,
            rho,
            cp: f.cp_l_j_per_kg_k(t),
            dh_dt: f.dh_l_dt(t),
            drho_dt: f.drho_l_dt(t),
            h: f.h_l_j_per_kg(t),
        }
    }

    /// Liquid properties for convection.
    pub(super) fn convection(&self, g: Group<'_>) -> ConvectionProps<T> {
        let f = g.shared().fluid.props();
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
pub(super) fn liquid_props<T: Real>(g: Group<'_>, t: T) -> ConvectionProps<T> {
    let rho = g.shared().fluid.props().rho_l_kg_per_m3(t);
    NodeFits::at(g, t, rho).convection(g)
}

/// Ullage-gas properties at the ullage temperature: mass-fraction-weighted vapour and helium
/// transport properties (a mixing rule adequate for a convection estimate), ideal-gas β = 1/T.
/// `cp_vapor` is the vapour's ideal-gas `c_p⁰` at the ullage temperature, J/(kg K).
pub(super) fn gas_props<T: Real>(
    g: Group<'_>,
    s: &State<T>,
    x: &Derived<T>,
    cp_vapor: T,
) -> ConvectionProps<T> {
    let f = g.shared().fluid.props();
    let m = x.m_vapor_kg + s[M_G];
    let y = T::select(m.gt(c(0.0)), x.m_vapor_kg / m, c(1.0));
    let t = x.t_ullage_k;
    let (k_v, mu_v) = f.vapor_transport(t);
    // An ullage without helium in every lane (self-pressurization) has y = 1 exactly: helium's
    // properties are weighted by 0, so they are not evaluated (the same bits, a logarithm and two
    // exponentials fewer).
    let (k_g, mu_g) = if s[M_G].is_zero().all() {
        (c(0.0), c(0.0))
    } else {
        HELIUM.transport(t)
    };
    let he = y.rsub(1.0);
    ConvectionProps {
        k: y * k_v + he * k_g,
        mu: y * mu_v + he * mu_g,
        rho: m / x.v_ullage_m3,
        cp: y * cp_vapor + he * HELIUM.cp_j_per_kg_k,
        beta: t.rdiv(1.0),
    }
}

/// A closure coefficient: the campaign's constant in every lane when it sets one (lanes agree
/// on whether it does), else the correlation.
pub(super) fn closure<T: Real>(
    g: Group<'_>,
    pick: impl Fn(&super::params::HeatTransfer) -> Option<f64>,
    correlation: impl FnOnce() -> T,
) -> T {
    match pick(&g.shared().heat_transfer) {
        Some(_) => g.get(|p| pick(&p.heat_transfer).unwrap_or(0.0)),
        None => correlation(),
    }
}

/// Wetted-wall ↔ liquid and dry-wall ↔ gas coefficients, W/(m²·K): the campaign's constants, or
/// Churchill–Chu on the wetted and dry heights with the liquid at `t_liquid`, the gas at `t_gas`.
pub(super) fn wall_coefficients<T: Real>(
    g: Group<'_>,
    x: &Derived<T>,
    liq: &ConvectionProps<T>,
    gas: &ConvectionProps<T>,
    t_liquid: T,
    t_gas: T,
) -> (T, T) {
    let h_wl = closure(
        g,
        |h| h.h_wall_liquid_w_per_m2_k,
        || thermal::h_vertical_wall(liq, x.a_ax, x.t_wall_wet_k - t_liquid, x.level_m),
    );
    let h_wu = closure(
        g,
        |h| h.h_wall_ullage_w_per_m2_k,
        || {
            let height: T = g.get(|p| p.tank.height_m());
            thermal::h_vertical_wall(gas, x.a_ax, x.t_wall_dry_k - t_gas, height - x.level_m)
        },
    );
    (h_wl, h_wu)
}

/// Enthalpy change of a liquid node whose own volume change does work P dV on the ullage:
/// solves dH = F − P dV with dV = ṁ/ρ + β (dH − ṁ h), β = −ρ'/(ρ² dh_l/dT). Returns (dH/dt, dV/dt).
pub(super) fn liquid_node_rates<T: Real>(p_pa: T, flux_w: T, dm: T, n: &NodeFits<T>) -> (T, T) {
    let (rho, h) = (n.rho, n.h);
    // β and 1/ρ from one reciprocal, 1/(ρ² dh_l/dT): two divides where there were four.
    let q = (rho * rho * n.dh_dt).rdiv(1.0);
    let beta = -n.drho_dt * q;
    let inv_rho = rho * n.dh_dt * q;
    let dh = (flux_w - p_pa * dm * inv_rho + p_pa * beta * h * dm) / (p_pa * beta + 1.0);
    (dh, dm * inv_rho + beta * (dh - h * dm))
}

/// Time derivative of the state at one instant. `dt` is the step the integrator is taking: the
/// stiff evaporation and wall exchange are blended towards implicit over it where the step does
/// not resolve them (see [`implicit_evaporation`]). `tank`: each lane's tank ([`Group::tank`]).
pub fn rhs<T: Real>(
    (g, tank): (Group<'_>, &TankLanes<T>),
    s: &State<T>,
    d: &Drive<T>,
    x: &Derived<T>,
    dt: T,
    ds: &mut State<T>,
    out: &mut Fluxes<T>,
) {
    let p0 = g.shared();
    let f = p0.fluid.props();
    let off = vapor_energy_offset(p0.fluid);
    let (t_u, t_s, t_b) = (x.t_ullage_k, x.t_layer_k, x.t_bulk_k);
    // Real-gas vapour at the ullage state (`fluids::vapor`): its energy, enthalpy and the
    // derivatives the evaporation's chain rule needs, as `derive::ullage_temperature` left them
    // at the same (T_u, ρ_v).
    let rho_v = s[M_V] / x.v_ullage_m3;
    let vapor = x.ullage_vapor.state;
    let rv = f.r_specific_j_per_kg_k();
    let (u0, cv0) = (x.ullage_vapor.u0_j_per_kg, x.ullage_vapor.cv0_j_per_kg_k);
    let u_vap = u0 + off + vapor.u_res_j_per_kg;
    // Ullage heat capacity at constant volume: real-gas vapour and ideal helium.
    let cv_g = HELIUM.cv_j_per_kg_k;
    let heat_cap = s[M_V] * (vapor.du_res_dt + cv0) + s[M_G] * cv_g;
    let a_i = x.interface_area_m2;
    let r_surf = tank.surface_radius_m(x.level_m).max_c(1.0e-3);
    let a_tot = tank.wall_area_m2();
    let dry_share = x.wetted_share.rsub(1.0);
    let (a_wet, a_dry) = (a_tot * x.wetted_share, a_tot * dry_share);
    let speed = boundary::slosh_speed(g, s, x);
    let enhancement: T = g.get(|p| p.coupling.h_enhancement_w_per_m2_k_s);

    // Wall heat transfer (Churchill–Chu on each wetted and dry height).
    let (bulk, layer) = (
        NodeFits::at(g, t_b, x.rho_bulk),
        NodeFits::at(g, t_s, x.rho_layer),
    );
    let liq = bulk.convection(g);
    let gas = gas_props(g, s, x, cv0 + rv);
    let (h_wl, h_wu) = wall_coefficients(g, x, &liq, &gas, t_b, t_u);
    // The wetted wall passes its heat into the liquid with a uniform flux; each liquid node takes
    // the share of the wetted band it touches (MODEL.md §4): the layer the band between the
    // interface and its own depth, the bulk the rest. A single wall node at the bulk temperature
    // must not cool the warmer layer through that band, hence the flux split, not h (T_w − T_s).
    let c_wall: T = g.get(Params::wall_heat_capacity_j_per_k);
    // Once the bulk is merged into the layer the wetted wall feeds the layer alone.
    let bulk_gone = s[M_B].le(c(0.0));
    let c_bulk = T::select(bulk_gone, s[M_S], s[M_B]).max_c(1.0e-9) * liq.cp;
    let env = super::insulation::wall_heat(g, d, x);
    let q_wl = thermal::wall_exchange(
        h_wl * a_wet,
        dt,
        c_wall * x.wetted_share,
        c_bulk,
        x.t_wall_wet_k - t_b,
        env.warming_wet_k_s,
    );
    let depth = x.v_layer_m3 / a_i;
    let a_below = tank.wetted_area_m2(x.level_m - depth);
    let a_ws = (a_wet - a_below).max_c(0.0).min(a_wet);
    let contact = a_ws / a_wet.max_c(1.0e-12);
    // Optionally the wall boundary layer lifts part of the bulk's share to the surface.
    let lift: T = g.get(|p| p.stratification.wall_heat_to_layer);
    let to_layer = T::select(bulk_gone, c(1.0), contact + lift * contact.rsub(1.0));
    let (q_ws, q_wb) = (to_layer * q_wl, to_layer.rsub(1.0) * q_wl);
    let q_wu = thermal::wall_exchange(
        h_wu * a_dry,
        dt,
        c_wall * dry_share,
        heat_cap,
        x.t_wall_dry_k - t_u,
        env.warming_dry_k_s,
    );

    // Interface: ullage ↔ layer (stable, warm gas over cold liquid) and layer ↔ bulk.
    let h_us = closure(
        g,
        |h| h.h_us_w_per_m2_k,
        || thermal::h_stable_interface(&gas, x.a_ax, t_u - t_s, r_surf * 0.5),
    ) + enhancement * speed;
    // The ullage ↔ layer exchange relaxes at h_us A_i (1/C_u + 1/C_s): its step average keeps it
    // stable at any step (coupling II at k_h = 1e6 under a resonant slosh gave z ≈ 6 in 0.01 s
    // RK4 steps of the 43 L LN2 tank and diverged; `thermal::stiff_blend`).
    let z_us = dt * h_us * a_i * (heat_cap.rdiv(1.0) + (s[M_S].max_c(1.0e-9) * layer.cp).rdiv(1.0));
    let q_us = thermal::stiff_blend(z_us).0 * h_us * a_i * (t_u - t_s);
    // Stable (warm layer on top): conduction is carried by the layer's penetration growth, so the
    // base coefficient is 0 unless set. Unstable (a layer cooled below the bulk by evaporation
    // into helium): the dense layer overturns, Lloyd & Moran's unstable-plate correlation.
    let h_sb = closure(g, |h| h.h_sb_w_per_m2_k, || c::<T>(0.0))
        + thermal::h_unstable_interface(&liq, x.a_ax, t_b - t_s, r_surf * 0.5)
        + enhancement * speed;
    let q_sb = h_sb * a_i * (t_s - t_b);

    // Layer growth by conduction penetration: δ² = (π/4) α_eff t reproduces the surface
    // temperature of a semi-infinite liquid under constant flux (Carslaw & Jaeger §2.9), so
    // dm_s/dt = ρ A π α_eff / (8 δ), δ = m_s / (ρ A). Needs bulk liquid to entrain. Slosh
    // mixing (coupling III, `wave_mixing`) adds the wave's eddy diffusivity at the layer's base
    // to α_eff: the wave deepens the mixed layer.
    let factor: T = g.get(|p| p.stratification.diffusivity_factor);
    let delta = (s[M_S] / (x.rho_layer * a_i)).max_c(1.0e-6);
    let eddy = super::wave_mixing::eddy_diffusivity(&super::wave_mixing::waves(g, s, x), delta);
    let alpha = factor * f.k_l_w_per_m_k(t_s) / (x.rho_layer * layer.cp) + eddy;
    // The bulk fades out of strat, mixing and the draw over its last share of the liquid, the
    // share below which it merges into the layer.
    let bulk_left =
        (s[M_B] / ((s[M_B] + s[M_S]) * super::BULK_MERGE_FRACTION + 1.0e-9)).clamp_c(0.0, 1.0);
    let m_strat = x.rho_layer * a_i * PI * alpha / (delta * 8.0) * bulk_left;
    // The jet mixer (`model::mixer`): equal masses both ways at ṁ_jet = (m_s m_b / (m_s + m_b))
    // / τ, so that ṁ_jet (1/m_s + 1/m_b) = 1/τ; its pump heat enters the liquid.
    let (jet_per_s, q_mixer) = super::mixer::lanes(g, d);
    let m_b = s[M_B].max_c(0.0);
    let m_jet = jet_per_s * s[M_S] * m_b / (s[M_S] + m_b).max_c(1.0e-9) * bulk_left;
    // The thermodynamic vent system (`model::tvs`): the spray returns the layer's share of the
    // recirculated liquid, ρ_b Q m_s / (m_s + m_b), exchanged with equal bulk mass.
    let tvs = super::tvs::lanes(g, d);
    let m_spray = tvs.pump_flow_m3_s * bulk.rho * s[M_S] / (s[M_S] + m_b).max_c(1.0e-9) * bulk_left;
    let m_mix = m_jet + m_spray;
    let q_pump = q_mixer + tvs.pump_heat_w;
    // Layer ↔ bulk exchange (mixing and interface conduction) as the two-node relaxation it is:
    // the difference relaxes at G (1/m_s + 1/m_b), G = ṁ_mix + h_sb A_i / c_p, and the step
    // average a(z) of `thermal::stiff_blend` keeps it stable where a small bulk is exchanged
    // within a step. The TVS spray (0.14 kg/s) exchanged the last 0.4 kg of bulk of the MHTB tank
    // at 2 % fill every 3 s; under 10 s RK4 steps T_b oscillated and the instance diverged.
    let exchange_kg_s = m_mix + h_sb * a_i / liq.cp;
    let z = dt * exchange_kg_s * (s[M_S].max_c(1.0e-9).rdiv(1.0) + m_b.max_c(1.0e-9).rdiv(1.0));
    let (damp, _) = thermal::stiff_blend(z);
    let q_sb = damp * q_sb;

    let b = boundary::boundary_flows(g, s, d, x);
    // Gas-side mass-transfer coefficient by the heat/mass analogy (Le ≈ 1): h_m = h / (ρ c_p).
    let h_mass_m_s = h_us / (gas.rho * gas.cp);
    let h_fg = f.h_fg_j_per_kg(t_s);
    let (k_evap, dp) = evaporation_driving(g, s, x, h_mass_m_s);
    // Engine draws from the bulk, then from the layer once the bulk is gone; so does the TVS,
    // whose flow leaves at h_g(T_jt) where its node is warmer than T_jt.
    let (out_b, out_s) = (b.out_kg_s * bulk_left, b.out_kg_s * bulk_left.rsub(1.0));
    let (tvs_b, tvs_s) = (
        tvs.vent_kg_s * bulk_left,
        tvs.vent_kg_s * bulk_left.rsub(1.0),
    );

    let (h_ls, h_lb) = (layer.h, bulk.h);
    let h_vap_gas = u_vap + vapor.z * rv * t_u;
    let y = b.y_vapor;
    let h_u = y * h_vap_gas + y.rsub(1.0) * HELIUM.cp_j_per_kg_k * t_u;
    let h_press = boundary::pressurant_inlet_enthalpy(g, x.p_ullage_pa);
    // Autogenous pressurant is vapour: it enters M_V (in `tail`), helium enters M_G.
    let press_v = b.press_kg_s * boundary::pressurant_vapor_share::<T>(g);
    let pu = x.p_ullage_pa;
    // What liquid carries when it leaves a node for good (the layer's growth from the bulk, the
    // engine's draw): its enthalpy plus the flow work P/ρ, which the node's own P dV work
    // (`liquid_node_rates`) pays as its volume shrinks. Without it the liquid left behind gained
    // P/ρ per kilogram (a closed LH2 tank at uniform saturation and no heat cooled its layer and
    // warmed its bulk; a drained one warmed). Equal-mass exchanges carry the enthalpy difference.
    let (hf_s, hf_b) = (h_ls + pu / layer.rho, h_lb + pu / bulk.rho);

    // Slots evaporation does not move.
    ds[M_G] = b.press_kg_s - press_v - b.vent_kg_s * y.rsub(1.0);
    ds[M_B] = -m_strat - out_b - tvs_b;
    let mix_w = damp * m_mix * (h_ls - h_lb);
    // The pump heat goes with the bulk, into the layer once the bulk has merged into it.
    let (q_pump_b, q_pump_s) = (q_pump * bulk_left, q_pump * bulk_left.rsub(1.0));
    let (h_tvs_b, h_tvs_s) = (
        tvs.leaving_enthalpy(bulk.t, h_lb),
        tvs.leaving_enthalpy(layer.t, h_ls),
    );
    let f_b = q_wb + q_sb - m_strat * hf_b + mix_w - out_b * hf_b + q_pump_b - tvs_b * h_tvs_b;
    let (dh_b, dv_b) = liquid_node_rates(pu, f_b, ds[M_B], &bulk);
    ds[H_B] = dh_b;
    let force = boundary::motion_rates(g, s, d, x, ds);
    let angle = super::derive::slosh_angle(g, s, &x.slosh);
    let c_v: T = g.get(|p| p.coupling.volume_m3);
    let dv_slosh = c_v * math::cos(angle) * boundary::slosh_angle_rate(g, s, x);

    // The slots evaporation moves, at evaporation rate m: [dm_v, dm_s, dH_s, dU_u, dV_s]. The
    // liquid's expansion work arrives in the ullage; the slosh volume term is external.
    let tail = |m: T| -> [T; 5] {
        // Evaporating liquid carries h_l + h_fg at T_s; condensing vapour leaves at the gas
        // enthalpy.
        let e_evap = m.max_c(0.0) * (h_ls + h_fg) + m.min_c(0.0) * h_vap_gas;
        let dm_v = m + press_v - b.vent_kg_s * y;
        let dm_s = -m + m_strat - out_s - tvs_s;
        let f_s = q_ws + q_us - q_sb - e_evap + m_strat * hf_b - mix_w - out_s * hf_s + q_pump_s
            - tvs_s * h_tvs_s;
        let (dh_s, dv_s) = liquid_node_rates(pu, f_s, dm_s, &layer);
        let du_u = q_wu - q_us + e_evap + b.press_kg_s * h_press - b.vent_kg_s * h_u
            + pu * (dv_s + dv_b)
            - pu * dv_slosh;
        [dm_v, dm_s, dh_s, du_u, dv_s]
    };
    // d(P_sat(T_s) − P_v)/dt along those rates, by the chain rule through `derive_nodes`:
    // T_s from H_s/m_s; ρ_v = m_v/V_u; T_u from U_u = m_v u_v(T_u, ρ_v) + m_g c_v,He T_u;
    // P_v = P(T_u, ρ_v) of the real gas.
    let dpsat_dt = f.psat_and_slope(t_s).1;
    let dm_g = ds[M_G];
    let dp_rate = |r: [T; 5]| -> T {
        let dt_s = (r[2] - h_ls * r[1]) / (s[M_S].max_c(1.0e-9) * layer.dh_dt);
        let dv_u = dv_slosh - r[4] - dv_b;
        let drho = (r[0] - rho_v * dv_u) / x.v_ullage_m3;
        let dt_u = (r[3] - r[0] * u_vap - s[M_V] * vapor.du_res_drho * drho - dm_g * cv_g * t_u)
            / heat_cap;
        let dp_v = vapor.dp_dt * dt_u + vapor.dp_drho * drho;
        dpsat_dt * dt_s - dp_v
    };
    let (m_evap, evap_relaxation) = implicit_evaporation(k_evap, dp, dt, &tail, &dp_rate);

    let [dm_v, dm_s, dh_s, du_u, dv_s] = tail(m_evap);
    ds[M_V] = dm_v;
    ds[M_S] = dm_s;
    ds[H_S] = dh_s;
    ds[U_U] = du_u;

    boundary::wall_rates(g, tank, x, &env, q_wl, q_wu, dv_s + dv_b, ds);
    boundary::boundary_ledger(&b, h_press, h_u, out_s * hf_s + out_b * hf_b, ds);
    ds[E_WORK] = -pu * dv_slosh;
    ds[E_PUMP] = q_pump;
    ds[VENT_TVS] = tvs.vent_kg_s;
    ds[E_VENT] += tvs_b * h_tvs_b + tvs_s * h_tvs_s;

    // Written field by field into the caller's buffer: a returned `Fluxes` of lanes (2.5 KB)
    // was copied into place on every right-hand side.
    out.evap_kg_s = m_evap;
    out.evap_relaxation_per_s = evap_relaxation;
    out.strat_kg_s = m_strat;
    out.mix_kg_s = m_mix;
    out.boundary_layer_kg_s = c(0.0);
    out.q_wall_liquid_w = q_wl;
    out.q_wall_ullage_w = q_wu;
    out.q_ullage_layer_w = q_us;
    out.boundary = b;
    out.slosh_force_n = force;
}

/// Interfacial evaporation ṁ = K (P_sat(T_s) − P_v) (MODEL.md §4, [fix]: vapour partial pressure):
/// returns (K, Δp), K in kg/(s·Pa), Δp = P_sat(T_s) − P_v in Pa.
///
/// K is the Schrage kinetic coefficient in series with gas-side diffusion through the helium:
/// 1/K = 1/K_kin + x_He R_v T_u / (h_m A), with h_m the gas-side mass-transfer coefficient and
/// x_He the helium mole fraction (Stefan flow: no diffusion resistance in pure vapour). Without
/// it, evaporation into a helium ullage runs at the kinetic limit and freezes the surface.
pub fn evaporation_driving<T: Real>(
    g: Group<'_>,
    s: &State<T>,
    x: &Derived<T>,
    h_mass_m_s: T,
) -> (T, T) {
    let f = g.shared().fluid.props();
    let t_s = x.t_layer_k;
    let rv = f.r_specific_j_per_kg_k();
    let k_kin = closure(
        g,
        |h| h.evaporation_coefficient_kg_per_s_pa,
        || {
            let sigma: T = g.get(|p| p.heat_transfer.accommodation);
            thermal::schrage_coefficient(x.interface_area_m2, sigma, f.molar_mass_kg_per_mol, t_s)
        },
    );
    let moles_v = s[M_V] / f.molar_mass_kg_per_mol;
    let moles_g = s[M_G] / HELIUM.molar_mass_kg_per_mol;
    let x_he = moles_g / (moles_v + moles_g).max_c(1.0e-300);
    let diffusion = x_he * rv * x.t_ullage_k / (h_mass_m_s * x.interface_area_m2).max_c(1.0e-300);
    let k = (k_kin.rdiv(1.0) + diffusion).rdiv(1.0);
    (k, f.psat_pa(t_s) - x.p_vapor_pa)
}

/// The evaporation rate over a step of length `dt`, stiff in the interface pressure difference
/// Δp, and its relaxation rate K·J, 1/s.
///
/// A realistic K relaxes P_v onto P_sat(T_s) in milliseconds: dΔp/dt = F − J ṁ, with F the rate
/// at which every other flux moves Δp and J = −∂(dΔp/dt)/∂ṁ. The rate is
/// ṁ = K (a Δp + w dt F) with the weights of [`thermal::stiff_blend`] at z = dt K J: K Δp to
/// O(z⁶) where the step resolves the relaxation (evaporation into helium relaxes in minutes),
/// implicit Euler's K (Δp + dt F)/(1 + dt K J) where it does not (pure vapour: milliseconds);
/// stable at any K, and — because F is in it — the physical quasi-steady Δp = F / (K J) at any
/// step. (Without F the quasi-steady Δp is (1 + dt K J) times the physical one, a
/// step-dependent pressure offset that an embedded error estimate cannot see.) F and J come
/// from `dp_rate` applied to the node rates `tail(ṁ)`, which are affine in ṁ on each side of 0
/// (evaporation and condensation carry different enthalpies), so J has a value on each side:
/// ṁ = max(ṁ(J₊), 0) + min(ṁ(J₋), 0), continuous where the sign changes (the rate's zero
/// depends on J once a ≠ w).
pub(super) fn implicit_evaporation<T: Real>(
    k: T,
    dp: T,
    dt: T,
    tail: &impl Fn(T) -> [T; 5],
    dp_rate: &impl Fn([T; 5]) -> T,
) -> (T, T) {
    let forcing = dp_rate(tail(c(0.0)));
    let j_evap = (forcing - dp_rate(tail(c(1.0)))).max_c(0.0);
    let j_cond = (dp_rate(tail(c(-1.0))) - forcing).max_c(0.0);
    let rate = |j: T| {
        let (a, w) = thermal::stiff_blend(dt * k * j);
        k * (a * dp + w * dt * forcing)
    };
    let m = rate(j_evap).max_c(0.0) + rate(j_cond).min_c(0.0);
    (m, k * T::select(m.ge(c(0.0)), j_evap, j_cond))
}
