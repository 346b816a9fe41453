// The right-hand sides in f32 (src/model/nodes.rs; the homogeneous level's too): node rates,
// the stiff evaporation, wall and motion rates.

// ---------------------------------------------------------------- nodes.rs

/// (wetted-wall ↔ liquid, dry-wall ↔ gas) coefficients: the campaign's, or Churchill–Chu.
fn wall_coefficients(x: Derived, liq: Conv, gas: Conv, t_liquid: f32, t_gas: f32) -> vec2<f32> {
    var h_wl = P.h_wall_liquid;
    if ((P.flags & FLAG_H_WALL_LIQUID) == 0u) {
        h_wl = h_vertical_wall(liq, x.a_ax, x.t_ww - t_liquid, x.level);
    }
    var h_wu = P.h_wall_ullage;
    if ((P.flags & FLAG_H_WALL_ULLAGE) == 0u) {
        h_wu = h_vertical_wall(gas, x.a_ax, x.t_wd - t_gas, tank_height() - x.level);
    }
    return vec2<f32>(h_wl, h_wu);
}

/// (dH/dt, dV/dt) of a liquid node doing P dV work on the ullage.
fn liquid_node_rates(p_pa: f32, flux_w: f32, dm: f32, t: f32, rho: f32) -> vec2<f32> {
    let beta = -fl_drho_l_dt(t) / (rho * rho * fl_dh_l_dt(t));
    let h = fl_h_l(t);
    let dh = (flux_w - p_pa * dm / rho + p_pa * beta * h * dm) / (1.0 + p_pa * beta);
    return vec2<f32>(dh, dm / rho + beta * (dh - h * dm));
}

/// (K, Δp) of the interfacial evaporation (nodes::evaporation_driving).
fn evaporation_driving(s: ptr<function, St>, x: Derived, h_mass: f32) -> vec2<f32> {
    let t_s = x.t_s;
    let rv = fl_r_specific();
    var k_kin = P.evap_coeff;
    if ((P.flags & FLAG_EVAP_COEFF) == 0u) {
        k_kin = schrage_coefficient(x.a_i, P.accommodation, FL.molar_mass, t_s);
    }
    let moles_v = (*s)[M_V] / FL.molar_mass;
    let moles_g = (*s)[M_G] / HE.molar_mass;
    let x_he = moles_g / max(moles_v + moles_g, 1.0e-30);
    let diffusion = x_he * rv * x.t_u / max(h_mass * x.a_i, 1.0e-30);
    let k = 1.0 / (1.0 / k_kin + diffusion);
    return vec2<f32>(k, fl_psat_pa(t_s) - x.p_v);
}

/// What the slots evaporation moves depend on, besides the evaporation rate (nodes::rhs `tail`).
struct EvapTail {
    q_ws: f32,
    q_us: f32,
    q_sb: f32,
    q_wu: f32,
    m_strat: f32,
    out_s: f32,
    mix_w: f32,
    /// The pump heat's layer share once the bulk has merged into it, W.
    q_pump_s: f32,
    /// The TVS's draw from the layer (kg/s) and the enthalpy it leaves with (J/kg).
    tvs_s: f32,
    h_tvs_s: f32,
    h_ls: f32,
    /// What the layer's draws carry (its enthalpy plus the flow work P/ρ) and what its growth
    /// brings from below (the bulk's or the top layer's likewise), J/kg (nodes::rhs).
    hf_s: f32,
    h_grow: f32,
    h_fg: f32,
    h_vap_gas: f32,
    /// Real-gas vapour at the ullage state: u_v, rho_v and the chain-rule slopes.
    u_vap: f32,
    rho_v: f32,
    du_res_drho: f32,
    dp_dt: f32,
    dp_drho: f32,
    /// dU_u/dT_u at constant masses and volume.
    c_u: f32,
    vent: f32,
    y: f32,
    press: f32,
    /// The share of it that is vapour (autogenous), kg/s.
    press_v: f32,
    h_press: f32,
    h_u: f32,
    pu: f32,
    dv_b: f32,
    dv_slosh: f32,
    t_s: f32,
    rho_s: f32,
    /// dh_l/dT and dP_sat/dT at T_s, evaluated once per right-hand side.
    dh_dt_s: f32,
    dpsat_dt: f32,
}

/// The ullage side of EvapTail, alike for the lumped film and the `layered` one: the real-gas
/// vapour at the ullage state (its `vapor` state, energy `u_vap` and the ullage's heat capacity
/// `c_gas`), the boundary flows' enthalpies and the film's saturation slopes. The caller sets
/// the liquid side (heats, draws, the film's and the liquid below's enthalpies and volume rates).
fn ullage_tail(s: ptr<function, St>, x: Derived, b: Bnd, vapor: VaporState, u_vap: f32, c_gas: f32) -> EvapTail {
    var c: EvapTail;
    let t_u = x.t_u;
    let t_s = x.t_s;
    c.h_fg = fl_h_fg(t_s);
    c.h_vap_gas = u_vap + vapor.z * fl_r_specific() * t_u;
    c.u_vap = u_vap;
    c.rho_v = (*s)[M_V] / x.v_u;
    c.du_res_drho = vapor.du_res_drho;
    c.dp_dt = vapor.dp_dt;
    c.dp_drho = vapor.dp_drho;
    c.c_u = c_gas;
    c.vent = b.vent;
    c.y = b.y;
    c.press = b.press;
    c.press_v = b.press * pressurant_vapor_share();
    c.h_press = pressurant_inlet_enthalpy(x.p_u);
    c.h_u = b.y * c.h_vap_gas + (1.0 - b.y) * HE.cp * t_u;
    c.pu = x.p_u;
    c.t_s = t_s;
    c.rho_s = x.rho_s;
    c.dh_dt_s = fl_dh_l_dt(t_s);
    c.dpsat_dt = fl_dpsat_dt(t_s);
    return c;
}

/// [dm_v, dm_s, dH_s, dU_u, dV_s] at evaporation rate m.
fn evap_tail(c: EvapTail, m: f32) -> array<f32, 5> {
    let e_evap = max(m, 0.0) * (c.h_ls + c.h_fg) + min(m, 0.0) * c.h_vap_gas;
    let dm_v = m + c.press_v - c.vent * c.y;
    let dm_s = -m + c.m_strat - c.out_s - c.tvs_s;
    let f_s = c.q_ws + c.q_us - c.q_sb - e_evap + c.m_strat * c.h_grow - c.mix_w - c.out_s * c.hf_s
        + c.q_pump_s - c.tvs_s * c.h_tvs_s;
    let rs = liquid_node_rates(c.pu, f_s, dm_s, c.t_s, c.rho_s);
    let du_u = c.q_wu - c.q_us + e_evap + c.press * c.h_press - c.vent * c.h_u
        + c.pu * (rs.y + c.dv_b) - c.pu * c.dv_slosh;
    return array<f32, 5>(dm_v, dm_s, rs.x, du_u, rs.y);
}

/// d(P_sat(T_s) − P_v)/dt along the rates r of evap_tail (chain rule through derive_nodes).
fn evap_dp_rate(s: ptr<function, St>, x: Derived, c: EvapTail, r: array<f32, 5>, dm_g: f32) -> f32 {
    let dt_s = (r[2] - c.h_ls * r[1]) / (max((*s)[M_S], 1.0e-9) * c.dh_dt_s);
    let dv_u = c.dv_slosh - r[4] - c.dv_b;
    let drho = (r[0] - c.rho_v * dv_u) / x.v_u;
    let dt_u = (r[3] - r[0] * c.u_vap - (*s)[M_V] * c.du_res_drho * drho - dm_g * HE.cv * x.t_u) / c.c_u;
    let dp_v = c.dp_dt * dt_u + c.dp_drho * drho;
    return c.dpsat_dt * dt_s - dp_v;
}

/// The stiff evaporation rate of one side's J (nodes::implicit_evaporation).
fn evap_rate(kd: vec2<f32>, dt: f32, forcing: f32, j: f32) -> f32 {
    let aw = stiff_blend(dt * kd.x * j);
    return kd.x * (aw.x * kd.y + aw.y * dt * forcing);
}

/// The stiff evaporation rate with its forcing, J on each side (nodes::implicit_evaporation).
fn implicit_evaporation(s: ptr<function, St>, x: Derived, c: EvapTail, kd: vec2<f32>, dt: f32, dm_g: f32) -> f32 {
    let forcing = evap_dp_rate(s, x, c, evap_tail(c, 0.0), dm_g);
    let j_evap = max(forcing - evap_dp_rate(s, x, c, evap_tail(c, 1.0), dm_g), 0.0);
    let j_cond = max(evap_dp_rate(s, x, c, evap_tail(c, -1.0), dm_g) - forcing, 0.0);
    let m = max(evap_rate(kd, dt, forcing, j_evap), 0.0) + min(evap_rate(kd, dt, forcing, j_cond), 0.0);
    EVAP_RELAX = kd.x * select(j_cond, j_evap, m >= 0.0);
    return m;
}

/// Lumped / two_mode right-hand side into ds; returns the lateral slosh force.
fn rhs_nodes(s: ptr<function, St>, d: Drive, x: Derived, dt: f32, ds: ptr<function, St>) -> f32 {
    let t_u = x.t_u;
    let t_s = x.t_s;
    let t_b = x.t_b;
    let a_i = x.a_i;
    let r_surf = max(tank_surface_radius(x.level), 1.0e-3);
    let a_tot = tank_wall_area();
    let a_wet = a_tot * x.wet;
    let a_dry = a_tot * (1.0 - x.wet);
    let speed = slosh_speed(s, x);

    // Real-gas vapour at the ullage state (nodes.rs::closure): ideal part, residual part and
    // the ullage's heat capacity at constant volume.
    let rho_v = (*s)[M_V] / x.v_u;
    let vapor = fl_vapor_state(t_u, rho_v);
    let ideal = fl_vapor_ideal(t_u);
    let u_vap = ideal.x + FL.vapor_offset + vapor.u_res;
    let c_gas = (*s)[M_V] * (ideal.y + vapor.du_res_dt) + (*s)[M_G] * HE.cv;

    let liq = liquid_props(t_b);
    let gas = gas_props(s, x, ideal.y + fl_r_specific());
    let h_w = wall_coefficients(x, liq, gas, t_b, t_u);
    let h_wl = h_w.x;
    let h_wu = h_w.y;
    let c_wall = P.wall_areal_mass * a_tot * P.wall_cp;
    let bulk_gone = (*s)[M_B] <= 0.0;
    let c_bulk = max(select((*s)[M_B], (*s)[M_S], bulk_gone), 1.0e-9) * liq.cp;
    let env = wall_heat(d, x);
    let q_wl = wall_exchange(h_wl * a_wet, dt, c_wall * x.wet, c_bulk, x.t_ww - t_b, env.warming_wet);
    let depth = x.v_s / a_i;
    let a_ws = clamp(a_wet - tank_wetted_area(x.level - depth), 0.0, a_wet);
    let contact = a_ws / max(a_wet, 1.0e-12);
    let to_layer = select(contact + P.wall_heat_to_layer * (1.0 - contact), 1.0, bulk_gone);
    let q_ws = to_layer * q_wl;
    let q_wb = (1.0 - to_layer) * q_wl;
    let q_wu = wall_exchange(h_wu * a_dry, dt, c_wall * (1.0 - x.wet), c_gas, x.t_wd - t_u, env.warming_dry);

    var h_us = P.h_us;
    if ((P.flags & FLAG_H_US) == 0u) {
        h_us = h_stable_interface(gas, x.a_ax, t_u - t_s, 0.5 * r_surf);
    }
    h_us += P.coupling_h * speed;
    // Ullage ↔ layer exchange, stable at any step (nodes.rs::rhs).
    let z_us = dt * h_us * a_i * (1.0 / c_gas + 1.0 / (max((*s)[M_S], 1.0e-9) * fl_cp_l(t_s)));
    let q_us = stiff_blend(z_us).x * h_us * a_i * (t_u - t_s);
    var h_sb0 = 0.0;
    if ((P.flags & FLAG_H_SB) != 0u) {
        h_sb0 = P.h_sb;
    }
    let h_sb = h_sb0 + h_unstable_interface(liq, x.a_ax, t_b - t_s, 0.5 * r_surf) + P.coupling_h * speed;
    let q_sb_raw = h_sb * a_i * (t_s - t_b);

    // Penetration growth; slosh mixing (coupling III) adds the wave's eddy diffusivity at the
    // layer's base (nodes::rhs).
    let delta = max((*s)[M_S] / (x.rho_s * a_i), 1.0e-6);
    let alpha = P.diffusivity_factor * fl_k_l(t_s) / (x.rho_s * fl_cp_l(t_s)) + eddy_diffusivity(slosh_waves(s, x), delta);
    let bulk_left = clamp((*s)[M_B] / (BULK_MERGE_FRACTION * ((*s)[M_B] + (*s)[M_S]) + 1.0e-9), 0.0, 1.0);
    let m_strat = x.rho_s * a_i * PI * alpha / (8.0 * delta) * bulk_left;
    // The jet mixer (nodes::rhs): ṁ_jet = (m_s m_b / (m_s + m_b)) / τ each way, and its heat.
    let jet = jet_mixer(d);
    let m_b = max((*s)[M_B], 0.0);
    let m_jet = jet.x * (*s)[M_S] * m_b / max((*s)[M_S] + m_b, 1.0e-9) * bulk_left;
    // The TVS's spray (model::tvs): the layer's share of the recirculated liquid each way.
    let tv = tvs_flows(d);
    let m_spray = tv.pump_m3_s * x.rho_b * (*s)[M_S] / max((*s)[M_S] + m_b, 1.0e-9) * bulk_left;
    let m_mix = m_jet + m_spray;
    let q_pump = jet.y + tv.pump_heat_w;
    // Layer ↔ bulk exchange as a two-node relaxation, stable at any step (nodes.rs::rhs).
    let z = dt * (m_mix + h_sb * a_i / liq.cp) * (1.0 / max((*s)[M_S], 1.0e-9) + 1.0 / max(m_b, 1.0e-9));
    let damp = stiff_blend(z).x;

    let b = boundary_flows(s, d, x);
    let h_mass = h_us / (gas.rho * gas.cp);
    let kd = evaporation_driving(s, x, h_mass);
    let out_b = b.out * bulk_left;
    let out_s = b.out * (1.0 - bulk_left);
    let tvs_b = tv.vent * bulk_left;
    let tvs_s = tv.vent * (1.0 - bulk_left);

    let h_ls = fl_h_l(t_s);
    let h_lb = fl_h_l(t_b);
    var c = ullage_tail(s, x, b, vapor, u_vap, c_gas);
    let pu = x.p_u;
    // What liquid carries when it leaves a node for good: enthalpy plus flow work (nodes::rhs).
    let hf_s = h_ls + pu / x.rho_s;
    let hf_b = h_lb + pu / x.rho_b;

    (*ds)[M_G] = b.press - c.press_v - b.vent * (1.0 - b.y);
    (*ds)[M_B] = -m_strat - out_b - tvs_b;
    let mix_w = damp * m_mix * (h_ls - h_lb);
    let q_pump_b = q_pump * bulk_left;
    let h_tvs_b = tvs_leaving_enthalpy(tv, t_b, h_lb);
    let h_tvs_s = tvs_leaving_enthalpy(tv, t_s, h_ls);
    let q_sb = damp * q_sb_raw;
    let f_b = q_wb + q_sb - m_strat * hf_b + mix_w - out_b * hf_b + q_pump_b - tvs_b * h_tvs_b;
    let rb = liquid_node_rates(pu, f_b, (*ds)[M_B], t_b, x.rho_b);
    (*ds)[H_B] = rb.x;
    let force = motion_rates(s, d, x, ds);
    let angle = slosh_angle(s, x.sl);
    let dv_slosh = P.coupling_volume_m3 * cos(angle) * slosh_angle_rate(s, x);

    c.q_ws = q_ws;
    c.q_us = q_us;
    c.q_sb = q_sb;
    c.q_wu = q_wu;
    c.m_strat = m_strat;
    c.out_s = out_s;
    c.mix_w = mix_w;
    c.q_pump_s = q_pump * (1.0 - bulk_left);
    c.tvs_s = tvs_s;
    c.h_tvs_s = h_tvs_s;
    c.h_ls = h_ls;
    c.hf_s = hf_s;
    c.h_grow = hf_b;
    c.dv_b = rb.y;
    c.dv_slosh = dv_slosh;
    let m_evap = implicit_evaporation(s, x, c, kd, dt, (*ds)[M_G]);
    EVAP_RATE = m_evap;
    let r = evap_tail(c, m_evap);
    (*ds)[M_V] = r[0];
    (*ds)[M_S] = r[1];
    (*ds)[H_S] = r[2];
    (*ds)[U_U] = r[3];
    let rs = vec2<f32>(r[2], r[4]);

    wall_rates(x, env, q_wl, q_wu, rs.y + rb.y, ds);
    boundary_ledger(b, c.h_press, c.h_u, out_s * hf_s + out_b * hf_b, ds);
    (*ds)[E_WORK] = -pu * dv_slosh;
    (*ds)[E_PUMP] = q_pump;
    (*ds)[VENT_TVS] = tv.vent;
    (*ds)[E_VENT] += tvs_b * h_tvs_b + tvs_s * h_tvs_s;
    return force;
}

/// What the TVS does in this phase (model::tvs::lanes): zero without `[tvs]` or while off.
struct TvsFlows {
    vent: f32,
    pump_m3_s: f32,
    pump_heat_w: f32,
    t_jt: f32,
    h_vent: f32,
}

/// The enthalpy the J-T flow leaves with from liquid at `t` with enthalpy `h` (TvsFlows::
/// leaving_enthalpy): h_g(T_jt) at least EXCHANGER_PINCH_K above T_jt, h at T_jt, linear
/// between.
fn tvs_leaving_enthalpy(tv: TvsFlows, t: f32, h: f32) -> f32 {
    let share = clamp((t - tv.t_jt) * (1.0 / EXCHANGER_PINCH_K), 0.0, 1.0);
    return h + share * (tv.h_vent - h);
}

fn tvs_flows(d: Drive) -> TvsFlows {
    var t: TvsFlows;
    if ((P.flags & FLAG_TVS) == 0u || !d.tvs_on) {
        return t;
    }
    t.vent = P.tvs_flow_kg_s;
    t.pump_m3_s = P.tvs_pump_m3_s;
    t.pump_heat_w = P.tvs_pump_heat_w;
    t.t_jt = P.tvs_t_jt_k;
    t.h_vent = P.tvs_h_vent;
    return t;
}

/// The jet mixer's exchange rate 1/τ (1/s) and pump heat (W) in this phase: zero without
/// `[mixer]` or where the phase turns it off (model::mixer::lanes).
fn jet_mixer(d: Drive) -> vec2<f32> {
    if ((P.flags & FLAG_MIXER) == 0u || !d.mixing) {
        return vec2<f32>(0.0, 0.0);
    }
    return vec2<f32>(P.mixer_rate_per_s, P.mixer_heat_w);
}

/// Homogeneous right-hand side into ds; returns the slosh force (none at this level).
fn rhs_homogeneous(s: ptr<function, St>, d: Drive, x: Derived, dt: f32, ds: ptr<function, St>) -> f32 {
    let t = x.t_b;
    let a_tot = tank_wall_area();
    let a_wet = a_tot * x.wet;
    let a_dry = a_tot * (1.0 - x.wet);
    let rho = x.rho_b;
    let liq = liquid_props(t);
    let cv_vapor = fl_vapor_ideal(t).y;
    let gas = gas_props(s, x, cv_vapor + fl_r_specific());
    let m_u = x.m_v + (*s)[M_G];
    let h_w = wall_coefficients(x, liq, gas, t, t);
    let h_wl = h_w.x;
    let h_wu = h_w.y;
    let c_wall = P.wall_areal_mass * a_tot * P.wall_cp;
    let c_fluid = x.m_l * liq.cp + m_u * cv_vapor;
    let env = wall_heat(d, x);
    let q_wl = wall_exchange(h_wl * a_wet, dt, c_wall * x.wet, c_fluid, x.t_ww - t, env.warming_wet);
    let q_wu = wall_exchange(h_wu * a_dry, dt, c_wall * (1.0 - x.wet), c_fluid, x.t_wd - t, env.warming_dry);

    var sv = *s;
    sv[M_V] = x.m_v;
    let b = boundary_flows(&sv, d, x);
    let h_v = saturated_vapor(t).z;
    let h_u = b.y * h_v + (1.0 - b.y) * HE.cp * t;
    let h_l = fl_h_l(t);
    let h_press = pressurant_inlet_enthalpy(x.p_u);
    let press_v = b.press * pressurant_vapor_share();

    // The TVS draws liquid that leaves at h_g(T_jt) (homogeneous::rhs).
    let tv = tvs_flows(d);
    let h_tvs = tvs_leaving_enthalpy(tv, t, h_l);
    (*ds)[M_B] = press_v - b.out - b.vent * b.y - tv.vent;
    (*ds)[M_G] = b.press - press_v - b.vent * (1.0 - b.y);
    // The mixer's and the spray pump's heat only: no stratification to destroy.
    let q_pump = jet_mixer(d).y + tv.pump_heat_w;
    (*ds)[H_B] = q_wl + q_wu + b.press * h_press - b.vent * h_u - b.out * h_l + q_pump - tv.vent * h_tvs;
    (*ds)[E_PUMP] = q_pump;
    let force = motion_rates(s, d, x, ds);
    wall_rates(x, env, q_wl, q_wu, (*ds)[M_B] / rho, ds);
    boundary_ledger(b, h_press, h_u, b.out * h_l, ds);
    (*ds)[VENT_TVS] = tv.vent;
    (*ds)[E_VENT] += tv.vent * h_tvs;
    return force;
}
