// The `layered` level in f32 (src/model/column/, src/model/boundary_layer.rs): the lumped
// levels' surface film over a column of P.layers layers with fixed mass shares P.layer_w, their
// enthalpies in slots COL + k. Only in the kernel built for the level (gpu::engine::
// kernel_source); the other kernels leave out this file and every `LAYERED{` block.

// The column at the state being evaluated (column::Profile), bottom (k = 0) to top: masses (kg),
// specific enthalpies (J/kg), temperatures (K), densities (kg/m³), volumes (m³). Set by
// derive_column, read by rhs_column in the same evaluation.
var<private> CM: array<f32, NL_MAX>;
var<private> CH: array<f32, NL_MAX>;
var<private> CT: array<f32, NL_MAX>;
var<private> CRHO: array<f32, NL_MAX>;
var<private> CV: array<f32, NL_MAX>;

/// Number of layers.
fn layers() -> u32 {
    return clamp(P.layers, 1u, NL_MAX);
}

/// The column's profile into CM..CV (column::profile); a column merged into the film (M_B = 0)
/// has the film's enthalpy in every massless layer.
fn column_profile(s: ptr<function, St>) {
    let n = layers();
    let gone = (*s)[M_B] <= 0.0;
    let h_film = (*s)[H_S] / max((*s)[M_S], 1.0e-12);
    let m_col = max((*s)[M_B], 1.0e-12);
    for (var k = 0u; k < n; k++) {
        let m = m_col * P.layer_w[k];
        let h = select((*s)[COL + k] / m, h_film, gone);
        let t = fl_t_from_h_l(h);
        let rho = fl_rho_l(t);
        CM[k] = m;
        CH[k] = h;
        CT[k] = t;
        CRHO[k] = rho;
        CV[k] = select(m / rho, 0.0, gone);
    }
}

/// The `layered` level's derived state (column::derive_column): the film is the warm layer, the
/// bottom layer the bulk (the outlet), the film both once the column has merged into it.
fn derive_column(s: ptr<function, St>, d: Drive) -> Derived {
    column_profile(s);
    var x: Derived;
    let t_film = fl_t_from_h_l((*s)[H_S] / max((*s)[M_S], 1.0e-12));
    let rho_film = fl_rho_l(t_film);
    let gone = (*s)[M_B] <= 0.0;
    x.t_s = t_film;
    x.t_b = select(CT[0], t_film, gone);
    x.rho_s = rho_film;
    x.rho_b = select(CRHO[0], rho_film, gone);
    x.v_s = (*s)[M_S] / rho_film;
    x.m_l = (*s)[M_S] + (*s)[M_B];
    var v_col = 0.0;
    var lo = t_film;
    var hi = t_film;
    for (var k = 0u; k < layers(); k++) {
        v_col += CV[k];
        lo = min(lo, CT[k]);
        hi = max(hi, CT[k]);
    }
    x.v_b = v_col;
    x.t_lmin = lo;
    x.t_lmax = hi;
    finish_nodes(s, d, &x, fl_mu_l(x.t_b) / x.rho_b);
    return x;
}

/// Mass flow per unit perimeter of the wall boundary layer, kg/(m·s), `x_m` above its start
/// for a wall `dt_k` warmer than the liquid `p` under `accel` (boundary_layer::
/// mass_flow_per_perimeter): the larger of Squire's laminar and Eckert & Jackson's turbulent
/// integral solutions; 0 without a warmer wall or height.
fn bl_mass_flow(p: Conv, accel: f32, dt_k: f32, x_m: f32) -> f32 {
    let nu = p.mu / p.rho;
    let pr = nu * p.rho * p.cp / p.k;
    let x = max(x_m, 0.0);
    let gr = max(accel, 0.0) * abs(p.beta) * max(dt_k, 0.0) * (x * x * x) / (nu * nu);
    if (!(gr > 0.0)) {
        return 0.0;
    }
    let ln_gr = log(gr);
    let laminar = exp(ln_gr * 0.25) * BL_LAMINAR_COEFFICIENT / (sqrt(pr) * sqrt(sqrt(pr + 0.952)));
    let damp = pow(pr, 2.0 / 3.0) * 0.494 + 1.0;
    let turbulent = exp(ln_gr * 0.4 - log(pr) * (8.0 / 15.0) - log(damp) * 0.4) * BL_TURBULENT_COEFFICIENT;
    return p.rho * nu * max(laminar, turbulent);
}

// The column's sources (column::rhs Sources): mass (kg/s) and energy (W) per layer.
var<private> SRC_M: array<f32, NL_MAX>;
var<private> SRC_E: array<f32, NL_MAX>;
// The column's geometry at this evaluation: top of each layer (m), wall perimeter there (m),
// wall heat into its band (W), section (m², floored) and wall radius (m).
var<private> Z_TOP: array<f32, NL_MAX>;
var<private> PERIM: array<f32, NL_MAX>;
var<private> Q_BAND: array<f32, NL_MAX>;
var<private> SECTION: array<f32, NL_MAX>;
var<private> WALL_R: array<f32, NL_MAX>;

/// What liquid carries when it leaves layer `k` for good: its enthalpy plus the flow work
/// `pu` / ρ (column::rhs `h_flow`).
fn flow_enthalpy(k: u32, pu: f32) -> f32 {
    return CH[k] + pu / CRHO[k];
}

/// The wall boundary layer walking up the wetted bands (column::rhs boundary_layer_sources):
/// entrains to its correlation's flow, carries the band's heat up to what its mass holds at the
/// wall's excess `dtw` (K), gives its liquid to a layer once no lighter than the layer above
/// (all of it to the top one). Adds to SRC_M / SRC_E.
fn boundary_layer_sources(liq: Conv, dtw: f32, a_ax: f32, pu: f32) {
    let n = layers();
    let top = n - 1u;
    var bl_m = 0.0;
    var bl_e = 0.0;
    var origin = 0.0;
    for (var k = 0u; k < n; k++) {
        let dh_dt = fl_dh_l_dt(CT[k]);
        let x = Z_TOP[k] - origin;
        let wanted = PERIM[k] * bl_mass_flow(liq, a_ax, dtw, x);
        let entrained = max(wanted - bl_m, 0.0);
        bl_m += entrained;
        let h_k = flow_enthalpy(k, pu);
        bl_e += entrained * h_k;
        let room = max(bl_m * (h_k + dh_dt * dtw) - bl_e, 0.0);
        let carried = min(max(Q_BAND[k], 0.0), room);
        bl_e += carried;
        var share = 1.0;
        if (k != top) {
            let h_bl = bl_e / max(bl_m, 1.0e-30);
            share = clamp((flow_enthalpy(k + 1u, pu) - h_bl) / (dh_dt * P.detrain_width_k) + 0.5, 0.0, 1.0);
        }
        let out_m = share * bl_m;
        let out_e = share * bl_e;
        SRC_M[k] += out_m - entrained;
        SRC_E[k] += out_e - entrained * h_k + (Q_BAND[k] - carried);
        bl_m -= out_m;
        bl_e -= out_e;
        origin += share * (Z_TOP[k] - origin);
    }
}

/// Energy each layer gains from its neighbours (column::neighbour_exchange): conduction at
/// `conductivity` (W/(m·K)), Lloyd & Moran overturning, the wave-induced eddy diffusivity
/// Σ c_mix |x_n| |ẋ_n| e^(−2 ξ_n d / R) (`waves`: amplitudes (m²/s) and decay rates (1/m) of the
/// two modes), each blended over the step as a two-node relaxation. Adds to SRC_E.
fn neighbour_exchange(liq: Conv, level: f32, conductivity: f32, a_ax: f32, waves: vec4<f32>, dt: f32) {
    let n = layers();
    for (var k = 0u; k + 1u < n; k++) {
        var z_below = 0.0;
        if (k > 0u) {
            z_below = Z_TOP[k - 1u];
        }
        let gap = max((Z_TOP[k + 1u] - z_below) * 0.5, 1.0e-6);
        let area = SECTION[k];
        let depth = max(level - Z_TOP[k], 0.0);
        let overturn = h_unstable_interface(liq, a_ax, CT[k] - CT[k + 1u], WALL_R[k] * 0.5);
        let eddy = eddy_diffusivity(waves, depth);
        let rho_pair = (CRHO[k] + CRHO[k + 1u]) * 0.5;
        let cp = liq.cp;
        let g_kg_s = (rho_pair * eddy + conductivity / cp) * area / gap + overturn * area / cp;
        let z = dt * g_kg_s * (1.0 / CM[k] + 1.0 / CM[k + 1u]);
        let q = stiff_blend(z).x * g_kg_s * (CH[k] - CH[k + 1u]);
        SRC_E[k] -= q;
        SRC_E[k + 1u] += q;
    }
}

/// The enthalpy carried by `flow` (kg/s, upward positive) across a boundary, upwind (W).
fn upwind(flow: f32, h_below: f32, h_above: f32) -> f32 {
    return max(flow, 0.0) * h_below + min(flow, 0.0) * h_above;
}

/// The `layered` right-hand side into ds (column::rhs); returns the lateral slosh force.
fn rhs_column(s: ptr<function, St>, d: Drive, x: Derived, dt: f32, ds: ptr<function, St>) -> f32 {
    let n = layers();
    let top = n - 1u;
    let t_u = x.t_u;
    let t_s = x.t_s;
    let rho_v = (*s)[M_V] / x.v_u;
    let vapor = fl_vapor_state(t_u, rho_v);
    let ideal = fl_vapor_ideal(t_u);
    let rv = fl_r_specific();
    let u_vap = ideal.x + FL.vapor_offset + vapor.u_res;
    let c_gas = (*s)[M_V] * (vapor.du_res_dt + ideal.y) + (*s)[M_G] * HE.cv;
    let a_i = x.a_i;
    let radius = tank_radius();
    let r_surf = max(tank_surface_radius(x.level), 1.0e-3);
    let a_tot = tank_wall_area();
    let a_wet = a_tot * x.wet;
    let a_dry = a_tot * (1.0 - x.wet);
    let speed = slosh_speed(s, x);

    // The film and the layers: the liquid's mass-mean temperature and enthalpy.
    let h_ls = fl_h_l(t_s);
    let cp_s = fl_cp_l(t_s);
    let m_s = max((*s)[M_S], 1.0e-9);
    let m_col = max((*s)[M_B], 0.0);
    let m_liq = max((*s)[M_S] + m_col, 1.0e-9);
    var mt = (*s)[M_S] * t_s;
    var mh = (*s)[M_S] * h_ls;
    for (var k = 0u; k < n; k++) {
        let m_k = m_col * P.layer_w[k];
        mt += m_k * CT[k];
        mh += m_k * CH[k];
        SRC_M[k] = 0.0;
        SRC_E[k] = 0.0;
    }
    let t_mean = mt / m_liq;
    let h_mean = mh / m_liq;
    let bulk_left = clamp((*s)[M_B] / (((*s)[M_B] + (*s)[M_S]) * BULK_MERGE_FRACTION + 1.0e-9), 0.0, 1.0);

    // Walls: one wetted node against the liquid's mass-mean temperature, one dry.
    let liq = liquid_props(t_mean);
    let gas = gas_props(s, x, ideal.y + rv);
    let h_w = wall_coefficients(x, liq, gas, t_mean, t_u);
    let c_wall = P.wall_areal_mass * a_tot * P.wall_cp;
    let env = wall_heat(d, x);
    let q_wl = wall_exchange(h_w.x * a_wet, dt, c_wall * x.wet, m_liq * liq.cp, x.t_ww - t_mean, env.warming_wet);
    let q_wu = wall_exchange(h_w.y * a_dry, dt, c_wall * (1.0 - x.wet), c_gas, x.t_wd - t_u, env.warming_dry);

    // The column's geometry and the wall heat into each layer's band; the film takes the rest.
    let floor_area = 1.0e-6 * radius * radius;
    let wetted_total = max(tank_wetted_area(x.level), 1.0e-12);
    var v_cum = 0.0;
    var below = 0.0;
    for (var k = 0u; k < n; k++) {
        v_cum += CV[k];
        Z_TOP[k] = tank_liquid_height(v_cum);
        let radius_k = tank_surface_radius(Z_TOP[k]);
        PERIM[k] = radius_k * TAU;
        WALL_R[k] = max(radius_k, 1.0e-3);
        SECTION[k] = max(tank_interface_area(Z_TOP[k]), floor_area);
        let wetted = tank_wetted_area(Z_TOP[k]);
        Q_BAND[k] = q_wl * (max(wetted - below, 0.0) / wetted_total);
        below = wetted;
    }
    let q_film_wall = q_wl * (max(wetted_total - below, 0.0) / wetted_total);

    let pu = x.p_u;
    let h_flow_film = h_ls + pu / x.rho_s;
    boundary_layer_sources(liq, max(x.t_ww - t_mean, 0.0), x.a_ax, pu);
    let waves = slosh_waves(s, x);
    neighbour_exchange(liq, x.level, liq.k * P.diffusivity_factor, x.a_ax, waves, dt);

    // Film ↔ top layer: penetration growth (conduction and the wave's eddy diffusivity),
    // overturning (column::rhs).
    let h_top = flow_enthalpy(top, pu);
    let t_top = CT[top];
    var h_sb0 = 0.0;
    if ((P.flags & FLAG_H_SB) != 0u) {
        h_sb0 = P.h_sb;
    }
    let h_sb = h_sb0 + h_unstable_interface(liq, x.a_ax, t_top - t_s, r_surf * 0.5) + P.coupling_h * speed;
    let delta = max((*s)[M_S] / (x.rho_s * a_i), 1.0e-6);
    let alpha = P.diffusivity_factor * fl_k_l(t_s) / (x.rho_s * cp_s) + eddy_diffusivity(waves, delta);
    let m_strat = x.rho_s * a_i * PI * alpha / (delta * 8.0) * bulk_left;
    let exchange = h_sb * a_i / liq.cp;
    let z = dt * exchange * (1.0 / m_s + 1.0 / max(CM[top], 1.0e-9));
    let damp = stiff_blend(z).x;
    let q_sb = damp * h_sb * a_i * (t_s - t_top);
    SRC_M[top] -= m_strat;
    SRC_E[top] += q_sb - m_strat * h_top;

    // The jet mixer and the TVS spray stir the whole liquid towards its mass-mean enthalpy.
    let jet = jet_mixer(d);
    let tv = tvs_flows(d);
    let stir_rate = jet.x + tv.pump_m3_s * CRHO[0] / m_liq;
    let stir = stiff_blend(dt * stir_rate).x * stir_rate;
    let q_pump = jet.y + tv.pump_heat_w;
    let pump_per_kg = q_pump / m_liq;
    for (var k = 0u; k < n; k++) {
        let m_k = m_col * P.layer_w[k];
        SRC_E[k] += (stir * (h_mean - CH[k]) + pump_per_kg) * m_k;
    }
    let film_stir = (stir * (h_mean - h_ls) + pump_per_kg) * (*s)[M_S];

    // The engine and the TVS draw from the bottom layer, from the film once the column is gone.
    let b = boundary_flows(s, d, x);
    let out_b = b.out * bulk_left;
    let out_s = b.out * (1.0 - bulk_left);
    let tvs_b = tv.vent * bulk_left;
    let tvs_s = tv.vent * (1.0 - bulk_left);
    let h_tvs_b = tvs_leaving_enthalpy(tv, CT[0], CH[0]);
    let h_tvs_s = tvs_leaving_enthalpy(tv, t_s, h_ls);
    // The J-T exchanger's heat comes out of the recirculated stream: each layer its mass share.
    let h_draw = flow_enthalpy(0u, pu);
    let q_exchanger = tvs_b * (h_tvs_b - h_draw);
    SRC_M[0] -= out_b + tvs_b;
    SRC_E[0] -= (out_b + tvs_b) * h_draw;
    for (var k = 0u; k < n; k++) {
        SRC_E[k] -= q_exchanger * P.layer_w[k];
    }

    // The column's rates: the remap flux through each boundary, upwind.
    var dm_col = 0.0;
    for (var k = 0u; k < n; k++) {
        dm_col += SRC_M[k];
    }
    var dv_col = 0.0;
    var flow_in = 0.0;
    var energy_in = 0.0;
    for (var k = 0u; k < n; k++) {
        let dm_k = dm_col * P.layer_w[k];
        var flow_out = 0.0;
        var energy_out = 0.0;
        if (k != top) {
            flow_out = flow_in + SRC_M[k] - dm_k;
            energy_out = upwind(flow_out, flow_enthalpy(k, pu), flow_enthalpy(k + 1u, pu));
        }
        let flux = SRC_E[k] + energy_in - energy_out;
        let r = liquid_node_rates(x.p_u, flux, dm_k, CT[k], CRHO[k]);
        (*ds)[COL + k] = r.x;
        dv_col += r.y;
        flow_in = flow_out;
        energy_in = energy_out;
    }
    (*ds)[M_B] = dm_col;

    // Interface: ullage ↔ film, blended over the step.
    var h_us = P.h_us;
    if ((P.flags & FLAG_H_US) == 0u) {
        h_us = h_stable_interface(gas, x.a_ax, t_u - t_s, 0.5 * r_surf);
    }
    h_us += P.coupling_h * speed;
    let z_us = dt * h_us * a_i * (1.0 / c_gas + 1.0 / (m_s * cp_s));
    let q_us = stiff_blend(z_us).x * h_us * a_i * (t_u - t_s);

    let kd = evaporation_driving(s, x, h_us / (gas.rho * gas.cp));
    var c = ullage_tail(s, x, b, vapor, u_vap, c_gas);

    (*ds)[M_G] = b.press - c.press_v - b.vent * (1.0 - b.y);
    let force = motion_rates(s, d, x, ds);
    let angle = slosh_angle(s, x.sl);
    let dv_slosh = P.coupling_volume_m3 * cos(angle) * slosh_angle_rate(s, x);

    // The film's slots at the evaporation rate (rhs.wgsl's evap_tail): the film's wall band,
    // the top layer's flow enthalpy for what it entrains, the stirring and pump heat as q_pump_s.
    c.q_ws = q_film_wall;
    c.q_us = q_us;
    c.q_sb = q_sb;
    c.q_wu = q_wu;
    c.m_strat = m_strat;
    c.out_s = out_s;
    c.mix_w = 0.0;
    c.q_pump_s = film_stir;
    c.tvs_s = tvs_s;
    c.h_tvs_s = h_tvs_s;
    c.h_ls = h_ls;
    c.hf_s = h_flow_film;
    c.h_grow = h_top;
    c.dv_b = dv_col;
    c.dv_slosh = dv_slosh;
    let m_evap = implicit_evaporation(s, x, c, kd, dt, (*ds)[M_G]);
    EVAP_RATE = m_evap;
    let r = evap_tail(c, m_evap);
    (*ds)[M_V] = r[0];
    (*ds)[M_S] = r[1];
    (*ds)[H_S] = r[2];
    (*ds)[U_U] = r[3];

    wall_rates(x, env, q_wl, q_wu, r[4] + dv_col, ds);
    boundary_ledger(b, c.h_press, c.h_u, out_b * flow_enthalpy(0u, pu) + out_s * h_flow_film, ds);
    (*ds)[E_WORK] = -pu * dv_slosh;
    (*ds)[E_PUMP] = q_pump;
    (*ds)[VENT_TVS] = tv.vent;
    (*ds)[E_VENT] += tvs_b * h_tvs_b + tvs_s * h_tvs_s;
    return force;
}
