//! The `layered` right-hand side: the column's sources (wall boundary layer, draws, film
//! exchange, stirring), its neighbour exchanges and remap, and the film's evaporation under the
//! ullage (module docs of [`super`]).

use super::Profile;
use crate::fluids::HELIUM;
use crate::lanes::{c, math, Real};
use crate::model::boundary::{self, BoundaryFlows};
use crate::model::boundary_layer;
use crate::model::derive::{self, Derived, Drive};
use crate::model::nodes::{self, Fluxes, NodeFits};
use crate::model::params::Params;
use crate::model::state::*;
use crate::model::thermal;
use crate::model::wave_mixing;
use crate::model::Group;
use std::f64::consts::PI;

/// The enthalpy carried by `flow_kg_s` (kg/s, upward positive) across a boundary: the lower
/// layer's `h_below` going up, the upper's `h_above` coming down (J/kg → W).
fn upwind<T: Real>(flow_kg_s: T, h_below: T, h_above: T) -> T {
    flow_kg_s.max_c(0.0) * h_below + flow_kg_s.min_c(0.0) * h_above
}

/// Sources of each layer: mass (kg/s) and energy (W).
struct Sources<T> {
    mass: [T; NL_MAX],
    energy: [T; NL_MAX],
}

/// The wetted wall's heat and its boundary layer over the column.
struct Wall<'a, T> {
    /// Top of each layer above the tank bottom, m.
    z_top: &'a [T; NL_MAX],
    /// Wall perimeter there, m.
    perimeter: &'a [T; NL_MAX],
    /// Wall heat into each layer's band, W.
    q_band: &'a [T; NL_MAX],
    /// Wall temperature above the liquid's mass-mean temperature (≥ 0), K.
    dtw_k: T,
    /// Axial acceleration, m/s².
    a_ax: T,
    /// `layered.detrain_width_k`, K.
    detrain_width_k: T,
}

/// The wall boundary layer (module docs of [`boundary_layer`]): walking up the wetted bands, the
/// layer entrains liquid to its correlation's flow, takes the band's wall heat up to what its
/// mass can hold at the wall's excess temperature (the rest heats the band's layer directly: a
/// weak or absent boundary layer, as in low gravity, leaves the heat where it enters), and gives
/// its liquid to a layer once it is no lighter than the layer over it, all of it to the top
/// layer. (Not to the film: the film is the conduction layer under the interface, which the
/// boundary layer's liquid, of the order of the whole column per hour at 1 g, would swamp.)
/// Returns the boundary layer's flow into the top layer, kg/s.
fn boundary_layer_sources<T: Real>(
    prof: &Profile<T>,
    h_flow: &[T; NL_MAX],
    fits: &[NodeFits<T>; NL_MAX],
    liq: &thermal::ConvectionProps<T>,
    wall: &Wall<'_, T>,
    src: &mut Sources<T>,
) -> T {
    let top = prof.n - 1;
    let (mut bl_m, mut bl_e, mut origin) = (c::<T>(0.0), c::<T>(0.0), c::<T>(0.0));
    for k in 0..prof.n {
        let x = wall.z_top[k] - origin;
        let target = wall.perimeter[k]
            * boundary_layer::mass_flow_per_perimeter(liq, wall.a_ax, wall.dtw_k, x);
        let entrained = (target - bl_m).max_c(0.0);
        bl_m += entrained;
        bl_e += entrained * h_flow[k];
        let room = (bl_m * (h_flow[k] + fits[k].dh_dt * wall.dtw_k) - bl_e).max_c(0.0);
        let carried = wall.q_band[k].max_c(0.0).min(room);
        bl_e += carried;
        let share = if k == top {
            c(1.0)
        } else {
            let h_bl = bl_e / bl_m.max_c(1.0e-30);
            ((h_flow[k + 1] - h_bl) / (fits[k].dh_dt * wall.detrain_width_k) + 0.5)
                .clamp_c(0.0, 1.0)
        };
        let (out_m, out_e) = (share * bl_m, share * bl_e);
        src.mass[k] += out_m - entrained;
        src.energy[k] += out_e - entrained * h_flow[k] + (wall.q_band[k] - carried);
        if k == top {
            return out_m;
        }
        bl_m -= out_m;
        bl_e -= out_e;
        // A boundary layer that gave its liquid away starts again from this height.
        origin += share * (wall.z_top[k] - origin);
    }
    c(0.0)
}

/// What the column's neighbour exchanges need (per lane; arrays per layer, bottom to top).
pub struct Exchange<'a, T> {
    pub prof: &'a Profile<T>,
    /// Top of each layer above the tank bottom, m.
    pub z_top: &'a [T; NL_MAX],
    /// Horizontal section of the tank there, m² (floored).
    pub section: &'a [T; NL_MAX],
    /// Wall radius there, m: the overturning correlation's length is half of it.
    pub wall_radius: &'a [T; NL_MAX],
    /// Liquid level, m.
    pub level_m: T,
    /// Effective conductivity k · `stratification.diffusivity_factor`, W/(m·K).
    pub conductivity: T,
    /// Liquid properties for the overturning correlation; its c_p turns the conductive and
    /// convective fluxes into mass exchanges.
    pub liquid: &'a thermal::ConvectionProps<T>,
    /// Axial acceleration, m/s².
    pub a_ax: T,
    /// Per slosh mode: c_mix |x_n| |ẋ_n| (m²/s) and its decay rate with depth ξ_n / R (1/m).
    pub waves: [(T, T); 2],
    /// The integrator's step, s.
    pub dt: T,
}

/// Energy each layer gains from its neighbours, W, added to `energy`. Through each boundary k
/// (between layers k and k + 1, Δz the distance between their centres, A the section there) the
/// layers exchange a mass G (kg/s each way) carrying their enthalpy difference:
///
/// G = (ρ D + k_eff / c_p) A / Δz + h_LM A / c_p,
///
/// conduction at the effective conductivity; Lloyd & Moran's unstable-plate coefficient h_LM
/// (0 unless the lower layer is warmer); the wave-induced eddy diffusivity
/// D = Σ_n c_mix |x_n| |ẋ_n| e^(−2 ξ_n d / R) at depth d below the surface (the form of Qiao et
/// al. 2004's wave mixing B = α l u, amplitude times orbital velocity, each decaying with depth
/// as the mode does). Each exchange is blended over the step as the two-node relaxation it is
/// (`thermal::stiff_blend` at z = dt G (1/m_k + 1/m_(k+1))).
pub fn neighbour_exchange<T: Real>(e: &Exchange<'_, T>, energy: &mut [T; NL_MAX]) {
    let prof = e.prof;
    for k in 0..prof.n - 1 {
        let z_below = if k == 0 { c(0.0) } else { e.z_top[k - 1] };
        let gap = ((e.z_top[k + 1] - z_below) * 0.5).max_c(1.0e-6);
        let area = e.section[k];
        let depth = (e.level_m - e.z_top[k]).max_c(0.0);
        let overturn = thermal::h_unstable_interface(
            e.liquid,
            e.a_ax,
            prof.t[k] - prof.t[k + 1],
            e.wall_radius[k] * 0.5,
        );
        let eddy = wave_mixing::eddy_diffusivity(&e.waves, depth);
        let rho_pair = (prof.rho[k] + prof.rho[k + 1]) * 0.5;
        let cp = e.liquid.cp;
        let g_kg_s = (rho_pair * eddy + e.conductivity / cp) * area / gap + overturn * area / cp;
        let z = e.dt * g_kg_s * (prof.m[k].rdiv(1.0) + prof.m[k + 1].rdiv(1.0));
        let q = thermal::stiff_blend(z).0 * g_kg_s * (prof.h[k] - prof.h[k + 1]);
        energy[k] -= q;
        energy[k + 1] += q;
    }
}

/// Time derivative of the `layered` state. `dt` is the integrator's step (the stiff exchanges
/// are blended towards implicit over it, as on the lumped levels: `thermal::stiff_blend`).
#[expect(
    clippy::needless_range_loop,
    reason = "the column's passes read several arrays per layer and its neighbours"
)]
pub fn rhs<T: Real>(
    g: Group<'_>,
    s: &State<T>,
    d: &Drive<T>,
    x: &Derived<T>,
    prof: &Profile<T>,
    dt: T,
    ds: &mut State<T>,
) -> Fluxes<T> {
    let p0 = g.shared();
    let f = p0.fluid.props();
    let (n, top) = (prof.n, prof.n - 1);
    let (t_u, t_s) = (x.t_ullage_k, x.t_layer_k);
    let rho_v = s[M_V] / x.v_ullage_m3;
    let vapor = x.ullage_vapor.state;
    let rv = f.r_specific_j_per_kg_k();
    let (u0, cv0) = (x.ullage_vapor.u0_j_per_kg, x.ullage_vapor.cv0_j_per_kg_k);
    let u_vap = u0 + vapor_energy_offset(p0.fluid) + vapor.u_res_j_per_kg;
    let cv_g = HELIUM.cv_j_per_kg_k;
    let heat_cap = s[M_V] * (vapor.du_res_dt + cv0) + s[M_G] * cv_g;
    let a_i = x.interface_area_m2;
    let tank = g.tank();
    let r_surf = tank.surface_radius_m(x.level_m).max_c(1.0e-3);
    let a_tot = tank.wall_area_m2();
    let dry_share = x.wetted_share.rsub(1.0);
    let (a_wet, a_dry) = (a_tot * x.wetted_share, a_tot * dry_share);
    let speed = boundary::slosh_speed(g, s, x);
    let enhancement: T = g.get(|p| p.coupling.h_enhancement_w_per_m2_k_s);

    // The film and the layers: fits, and the liquid's mass-mean temperature and enthalpy.
    let film = NodeFits::at(g, t_s, x.rho_layer);
    let m_s = s[M_S].max_c(1.0e-9);
    let m_col = s[M_B].max_c(0.0);
    let m_liq = (s[M_S] + m_col).max_c(1.0e-9);
    let mut fits = [film; NL_MAX];
    let (mut mt, mut mh) = (s[M_S] * t_s, s[M_S] * film.h);
    for k in 0..n {
        fits[k] = NodeFits::at(g, prof.t[k], prof.rho[k]);
        let m_k = m_col * prof.w[k];
        mt += m_k * prof.t[k];
        mh += m_k * prof.h[k];
    }
    let (t_mean, h_mean) = (mt / m_liq, mh / m_liq);
    // What liquid carries when it leaves a layer or the film for good (boundary layer, remap,
    // the film's growth, the draws): its enthalpy plus the flow work P/ρ, which the node's own
    // P dV work pays as its volume shrinks (as `nodes::rhs`). Equal-mass exchanges (neighbours,
    // stirring) carry the enthalpy difference.
    let pu = x.p_ullage_pa;
    let mut h_flow = [c::<T>(0.0); NL_MAX];
    for k in 0..n {
        h_flow[k] = prof.h[k] + pu / prof.rho[k];
    }
    let h_flow_film = film.h + pu / film.rho;
    // The column fades out of the exchanges and the draw over its last share of the liquid, the
    // share below which it merges into the film (as the lumped levels' bulk).
    let bulk_left = (s[M_B] / ((s[M_B] + s[M_S]) * crate::model::BULK_MERGE_FRACTION + 1.0e-9))
        .clamp_c(0.0, 1.0);

    // Walls: one wetted and one dry node, as on the lumped levels, the wetted one against the
    // liquid's mass-mean temperature.
    let liq = nodes::liquid_props(g, t_mean);
    let gas = nodes::gas_props(g, s, x, cv0 + rv);
    let (h_wl, h_wu) = nodes::wall_coefficients(g, x, &liq, &gas, t_mean, t_u);
    let c_wall: T = g.get(Params::wall_heat_capacity_j_per_k);
    let env = crate::model::insulation::wall_heat(g, d, x);
    let q_wl = thermal::wall_exchange(
        h_wl * a_wet,
        dt,
        c_wall * x.wetted_share,
        m_liq * liq.cp,
        x.t_wall_wet_k - t_mean,
        env.warming_wet_k_s,
    );
    let q_wu = thermal::wall_exchange(
        h_wu * a_dry,
        dt,
        c_wall * dry_share,
        heat_cap,
        x.t_wall_dry_k - t_u,
        env.warming_dry_k_s,
    );

    // The column's geometry: the top of each layer, the wall's radius and the tank's section
    // there, the wall band each layer wets and the wall heat it takes (a uniform flux over the
    // wetted wall); the film takes the band above the column.
    let zero = [c::<T>(0.0); NL_MAX];
    let (mut z_top, mut perimeter, mut q_band) = (zero, zero, zero);
    let (mut section, mut wall_radius) = (zero, zero);
    let floor_area: T = g.get(|p| 1.0e-6 * p.tank.radius_m().powi(2));
    let wetted_total = tank.wetted_area_m2(x.level_m).max_c(1.0e-12);
    let (mut v_cum, mut below) = (c::<T>(0.0), c::<T>(0.0));
    for k in 0..n {
        v_cum += prof.v[k];
        z_top[k] = tank.liquid_height_m(v_cum);
        let radius_k = tank.surface_radius_m(z_top[k]);
        perimeter[k] = radius_k * (2.0 * PI);
        wall_radius[k] = radius_k.max_c(1.0e-3);
        section[k] = tank.interface_area_m2(z_top[k]).max(floor_area);
        let wetted = tank.wetted_area_m2(z_top[k]);
        q_band[k] = q_wl * ((wetted - below).max_c(0.0) / wetted_total);
        below = wetted;
    }
    let q_film_wall = q_wl * ((wetted_total - below).max_c(0.0) / wetted_total);

    let mut src = Sources {
        mass: zero,
        energy: zero,
    };
    let wall = Wall {
        z_top: &z_top,
        perimeter: &perimeter,
        q_band: &q_band,
        dtw_k: (x.t_wall_wet_k - t_mean).max_c(0.0),
        a_ax: x.a_ax,
        detrain_width_k: g.get(|p| p.layered.detrain_width_k),
    };
    let bl_top_kg_s = boundary_layer_sources(prof, &h_flow, &fits, &liq, &wall, &mut src);

    // Neighbour exchanges inside the column (`neighbour_exchange`).
    let factor: T = g.get(|p| p.stratification.diffusivity_factor);
    let waves = wave_mixing::waves(g, s, x);
    let exchange = Exchange {
        prof,
        z_top: &z_top,
        section: &section,
        wall_radius: &wall_radius,
        level_m: x.level_m,
        conductivity: liq.k * factor,
        liquid: &liq,
        a_ax: x.a_ax,
        waves,
        dt,
    };
    neighbour_exchange(&exchange, &mut src.energy);

    // Film ↔ top layer, with the lumped levels' closures: the film grows by conduction
    // penetration (δ² = (π/4) α_eff t, entraining the top layer; α_eff takes the wave's eddy
    // diffusivity at the film's base, coupling III), overturns when colder than it (Lloyd &
    // Moran), with the interface coefficient enhanced by k_h |speed| (coupling II).
    let t_top = prof.t[top];
    let h_sb = nodes::closure(g, |h| h.h_sb_w_per_m2_k, || c::<T>(0.0))
        + thermal::h_unstable_interface(&liq, x.a_ax, t_top - t_s, r_surf * 0.5)
        + enhancement * speed;
    let delta = (s[M_S] / (x.rho_layer * a_i)).max_c(1.0e-6);
    let alpha = factor * f.k_l_w_per_m_k(t_s) / (x.rho_layer * film.cp)
        + wave_mixing::eddy_diffusivity(&waves, delta);
    let m_strat = x.rho_layer * a_i * PI * alpha / (delta * 8.0) * bulk_left;
    let exchange = h_sb * a_i / liq.cp;
    let z = dt * exchange * (m_s.rdiv(1.0) + prof.m[top].max_c(1.0e-9).rdiv(1.0));
    let damp = thermal::stiff_blend(z).0;
    let q_sb = damp * h_sb * a_i * (t_s - t_top);
    src.mass[top] -= m_strat;
    src.energy[top] += q_sb - m_strat * h_flow[top];

    // The jet mixer and the thermodynamic vent's spray stir the whole liquid: the film and every
    // layer relax towards the mass-mean enthalpy at 1/τ (mixer) + ρ Q / m_l (spray turnover);
    // the pump heat goes with the mass.
    let (jet_per_s, q_mixer) = crate::model::mixer::lanes(g, d);
    let tvs = crate::model::tvs::lanes(g, d);
    let stir = jet_per_s + tvs.pump_flow_m3_s * prof.rho[0] / m_liq;
    let stir = thermal::stiff_blend(dt * stir).0 * stir;
    let q_pump = q_mixer + tvs.pump_heat_w;
    let pump_per_kg = q_pump / m_liq;
    for k in 0..n {
        let m_k = m_col * prof.w[k];
        src.energy[k] += (stir * (h_mean - prof.h[k]) + pump_per_kg) * m_k;
    }
    let film_stir = (stir * (h_mean - film.h) + pump_per_kg) * s[M_S];

    // The engine and the thermodynamic vent draw from the bottom layer, from the film once the
    // column is gone.
    let b: BoundaryFlows<T> = boundary::boundary_flows(g, s, d, x);
    let (out_b, out_s) = (b.out_kg_s * bulk_left, b.out_kg_s * bulk_left.rsub(1.0));
    let (tvs_b, tvs_s) = (
        tvs.vent_kg_s * bulk_left,
        tvs.vent_kg_s * bulk_left.rsub(1.0),
    );
    let (h_tvs_b, h_tvs_s) = (
        tvs.leaving_enthalpy(prof.t[0], prof.h[0]),
        tvs.leaving_enthalpy(t_s, film.h),
    );
    // The J-T flow leaves the bottom layer as the draw does; what its exchanger takes beyond
    // the liquid's flow enthalpy comes out of the recirculated stream, which the spray bar
    // returns along the column, so each layer gives its mass share (the lumped levels' bulk
    // gives it all). Taken from the bottom layer alone it sat 2 K under the lumped bulk on the
    // TVS coast, found by a user's attack.
    let q_exchanger = tvs_b * (h_tvs_b - h_flow[0]);
    src.mass[0] -= out_b + tvs_b;
    src.energy[0] -= (out_b + tvs_b) * h_flow[0];
    for k in 0..n {
        src.energy[k] -= q_exchanger * prof.w[k];
    }

    // The column's rates: the remap flux through each boundary from the mass balance, upwind.
    let mut dm_col = c::<T>(0.0);
    for k in 0..n {
        dm_col += src.mass[k];
    }
    let (mut dv_col, mut flow_in, mut energy_in) = (c::<T>(0.0), c::<T>(0.0), c::<T>(0.0));
    for k in 0..n {
        let dm_k = dm_col * prof.w[k];
        let (flow_out, energy_out) = if k == top {
            (c(0.0), c(0.0))
        } else {
            let up = flow_in + src.mass[k] - dm_k;
            (up, upwind(up, h_flow[k], h_flow[k + 1]))
        };
        let flux = src.energy[k] + energy_in - energy_out;
        let (dh_k, dv_k) = nodes::liquid_node_rates(x.p_ullage_pa, flux, dm_k, &fits[k]);
        ds[COL + k] = dh_k;
        dv_col += dv_k;
        flow_in = flow_out;
        energy_in = energy_out;
    }
    ds[M_B] = dm_col;

    // Interface: ullage ↔ film, blended over the step as on the lumped levels.
    let h_us = nodes::closure(
        g,
        |h| h.h_us_w_per_m2_k,
        || thermal::h_stable_interface(&gas, x.a_ax, t_u - t_s, r_surf * 0.5),
    ) + enhancement * speed;
    let z_us = dt * h_us * a_i * (heat_cap.rdiv(1.0) + (m_s * film.cp).rdiv(1.0));
    let q_us = thermal::stiff_blend(z_us).0 * h_us * a_i * (t_u - t_s);

    let h_mass_m_s = h_us / (gas.rho * gas.cp);
    let h_fg = f.h_fg_j_per_kg(t_s);
    let (k_evap, dp) = nodes::evaporation_driving(g, s, x, h_mass_m_s);
    let h_vap_gas = u_vap + vapor.z * rv * t_u;
    let y = b.y_vapor;
    let h_u = y * h_vap_gas + y.rsub(1.0) * HELIUM.cp_j_per_kg_k * t_u;
    let h_press = boundary::pressurant_inlet_enthalpy(g, x.p_ullage_pa);
    let press_v = b.press_kg_s * boundary::pressurant_vapor_share::<T>(g);

    ds[M_G] = b.press_kg_s - press_v - b.vent_kg_s * y.rsub(1.0);
    let force = boundary::motion_rates(g, s, d, x, ds);
    let angle = derive::slosh_angle(g, s, &x.slosh);
    let c_v: T = g.get(|p| p.coupling.volume_m3);
    let dv_slosh = c_v * math::cos(angle) * boundary::slosh_angle_rate(g, s, x);

    // The film's slots at evaporation rate m, as `nodes::rhs`: [dm_v, dm_s, dH_s, dU_u, dV_s].
    let film_mass = m_strat - out_s - tvs_s;
    let film_energy = q_film_wall + q_us - q_sb + m_strat * h_flow[top] + film_stir
        - out_s * h_flow_film
        - tvs_s * h_tvs_s;
    let tail = |m: T| -> [T; 5] {
        let e_evap = m.max_c(0.0) * (film.h + h_fg) + m.min_c(0.0) * h_vap_gas;
        let dm_v = m + press_v - b.vent_kg_s * y;
        let dm_s = film_mass - m;
        let (dh_s, dv_s) = nodes::liquid_node_rates(pu, film_energy - e_evap, dm_s, &film);
        let du_u = q_wu - q_us + e_evap + b.press_kg_s * h_press - b.vent_kg_s * h_u
            + pu * (dv_s + dv_col)
            - pu * dv_slosh;
        [dm_v, dm_s, dh_s, du_u, dv_s]
    };
    let dpsat_dt = f.psat_and_slope(t_s).1;
    let dm_g = ds[M_G];
    let dp_rate = |r: [T; 5]| -> T {
        let dt_s = (r[2] - film.h * r[1]) / (m_s * film.dh_dt);
        let dv_u = dv_slosh - r[4] - dv_col;
        let drho = (r[0] - rho_v * dv_u) / x.v_ullage_m3;
        let dt_u = (r[3] - r[0] * u_vap - s[M_V] * vapor.du_res_drho * drho - dm_g * cv_g * t_u)
            / heat_cap;
        let dp_v = vapor.dp_dt * dt_u + vapor.dp_drho * drho;
        dpsat_dt * dt_s - dp_v
    };
    let (m_evap, evap_relaxation) = nodes::implicit_evaporation(k_evap, dp, dt, &tail, &dp_rate);
    let [dm_v, dm_s, dh_s, du_u, dv_s] = tail(m_evap);
    ds[M_V] = dm_v;
    ds[M_S] = dm_s;
    ds[H_S] = dh_s;
    ds[U_U] = du_u;

    boundary::wall_rates(g, &tank, x, &env, q_wl, q_wu, dv_s + dv_col, ds);
    let e_out = out_b * h_flow[0] + out_s * h_flow_film;
    boundary::boundary_ledger(&b, h_press, h_u, e_out, ds);
    ds[E_WORK] = -pu * dv_slosh;
    ds[E_PUMP] = q_pump;
    ds[VENT_TVS] = tvs.vent_kg_s;
    ds[E_VENT] += tvs_b * h_tvs_b + tvs_s * h_tvs_s;

    Fluxes {
        evap_kg_s: m_evap,
        evap_relaxation_per_s: evap_relaxation,
        strat_kg_s: m_strat,
        mix_kg_s: c(0.0),
        boundary_layer_kg_s: bl_top_kg_s,
        q_wall_liquid_w: q_wl,
        q_wall_ullage_w: q_wu,
        q_ullage_layer_w: q_us,
        boundary: b,
        slosh_force_n: force,
    }
}
