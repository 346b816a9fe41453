// Heat-transfer and flow closures in f32 (src/model/thermal.rs, boundary.rs): convection
// correlations, the stiff blend, interfacial evaporation coefficients, orifice and boundary flows.

// ---------------------------------------------------------------- closures (thermal.rs)

struct Conv {
    k: f32,
    mu: f32,
    rho: f32,
    cp: f32,
    beta: f32,
}

fn liquid_props(t: f32) -> Conv {
    let rho = fl_rho_l(t);
    return Conv(fl_k_l(t), fl_mu_l(t), rho, fl_cp_l(t), -fl_drho_l_dt(t) / rho);
}

/// cp_v: the vapour's ideal-gas c_p0 at the ullage temperature (nodes.rs::gas_props).
fn gas_props(s: ptr<function, St>, x: Derived, cp_v: f32) -> Conv {
    let m = x.m_v + (*s)[M_G];
    let y = select(1.0, x.m_v / m, m > 0.0);
    let t = x.t_u;
    return Conv(
        y * fl_k_v(t) + (1.0 - y) * he_k(t),
        y * fl_mu_v(t) + (1.0 - y) * he_mu(t),
        m / x.v_u,
        y * cp_v + (1.0 - y) * HE.cp,
        1.0 / t,
    );
}

/// (Ra, Pr); Ra is formed as a product of powers so that f32 never overflows on L³.
fn rayleigh(p: Conv, accel: f32, dt_k: f32, length: f32) -> vec2<f32> {
    let nu = p.mu / p.rho;
    let alpha = p.k / (p.rho * p.cp);
    let ra = max(accel, 0.0) * abs(p.beta) * abs(dt_k) / (nu * alpha) * length * length * length;
    return vec2<f32>(ra, nu / alpha);
}

fn h_vertical_wall(p: Conv, accel: f32, dt_k: f32, length_m: f32) -> f32 {
    let length = max(length_m, 1.0e-3);
    let rp = rayleigh(p, accel, dt_k, length);
    let f = pow(1.0 + pow(0.492 / rp.y, 9.0 / 16.0), 8.0 / 27.0);
    let nu = 0.825 + 0.387 * pow(rp.x, 1.0 / 6.0) / f;
    return nu * nu * p.k / length;
}

fn h_stable_interface(p: Conv, accel: f32, dt_k: f32, length_m: f32) -> f32 {
    let length = max(length_m, 1.0e-3);
    let rp = rayleigh(p, accel, dt_k, length);
    return (1.0 + 0.27 * pow(rp.x, 0.25)) * p.k / length;
}

fn h_unstable_interface(p: Conv, accel: f32, dt_unstable_k: f32, length_m: f32) -> f32 {
    let length = max(length_m, 1.0e-3);
    let rp = rayleigh(p, accel, max(dt_unstable_k, 0.0), length);
    // A stable pair has Ra = 0 and pow(0, 1/3) = 0 (thermal::h_unstable_interface): no pow.
    if (rp.x == 0.0) {
        return 0.0 * p.k / length;
    }
    return 0.15 * pow(rp.x, 1.0 / 3.0) * p.k / length;
}

/// Weights (a, w) of a stiff relaxation's rate K (a Δ + w h F) at z = h K J: a = S5(z)/S6(z),
/// w = z^5/S6(z), S_n = 1 + z + … + z^n, evaluated in 1/z beyond z = 1 (thermal::stiff_blend).
fn stiff_blend(z: f32) -> vec2<f32> {
    let big = z > 1.0;
    let v = select(z, 1.0 / z, big);
    var s_lo = 1.0;
    var v_lo = 1.0;
    for (var i = 1u; i < STIFF_BLEND_ORDER; i += 1u) {
        s_lo = s_lo * v + 1.0;
        v_lo = v_lo * v;
    }
    let s_hi = s_lo + v_lo * v;
    return vec2<f32>(s_lo / s_hi * select(1.0, v, big), select(v_lo, v, big) / s_hi);
}

/// Wall-to-fluid heat over a step, stiff in ΔT with the wall's own warming rate `warming`
/// (heat leak / wall heat capacity, K/s; thermal::wall_exchange).
fn wall_exchange(ua: f32, dt: f32, c_wall: f32, c_fluid: f32, dtemp: f32, warming: f32) -> f32 {
    let aw = stiff_blend(dt * ua * (1.0 / c_wall + 1.0 / c_fluid));
    return ua * (aw.x * dtemp + aw.y * dt * warming);
}

fn schrage_coefficient(area: f32, sigma: f32, molar_mass: f32, t: f32) -> f32 {
    return area * 2.0 * sigma / (2.0 - sigma) * sqrt(molar_mass / (2.0 * PI * R_UNIVERSAL * t));
}

fn orifice_flow(area: f32, p_up: f32, p_down: f32, t: f32, r: f32, g: f32) -> f32 {
    if (p_up <= p_down || p_up <= 0.0) {
        return 0.0;
    }
    let pr_crit = pow(2.0 / (g + 1.0), g / (g - 1.0));
    let pr = max(p_down / p_up, pr_crit);
    let flux = sqrt(max(2.0 * g / ((g - 1.0) * r * t) * (pow(pr, 2.0 / g) - pow(pr, (g + 1.0) / g)), 0.0));
    return area * p_up * flux;
}

// ---------------------------------------------------------------- boundary.rs

struct Bnd {
    press: f32,
    vent: f32,
    y: f32,
    out: f32,
}

fn boundary_flows(s: ptr<function, St>, d: Drive, x: Derived) -> Bnd {
    let m_u = (*s)[M_V] + (*s)[M_G];
    let y = select(1.0, (*s)[M_V] / m_u, m_u > 0.0);
    var b = Bnd(0.0, 0.0, y, 0.0);
    if ((P.flags & FLAG_PRESSURIZATION) != 0u && d.pressurize) {
        let e = P.press_setpoint_pa - x.p_u;
        let e_dot = -(x.p_u - (*s)[P_FILT]) / P.press_filter_s;
        // Gain schedule: both gains times V_u / V_ref where V_ref > 0, else fixed.
        let v_ref = P.press_schedule_ref_m3;
        let gain = select(1.0, x.v_u / v_ref, v_ref > 0.0);
        let demand = clamp((P.press_kp * e + P.press_kd * e_dot) * gain, 0.0, P.press_max_flow);
        let left = P.press_bottle_kg - (*s)[PRESS_IN];
        let fade = clamp(left / (1.0e-3 * P.press_bottle_kg + 1.0e-9), 0.0, 1.0);
        b.press = demand * fade;
    }
    if ((P.flags & FLAG_RELIEF) != 0u && d.valve_open) {
        let rv = fl_r_specific();
        let rg = he_r_specific();
        let r_mix = y * rv + (1.0 - y) * rg;
        let cv_v = fl_vapor_ideal(x.t_u).y;
        let cp = y * (cv_v + rv) + (1.0 - y) * HE.cp;
        let cv = y * cv_v + (1.0 - y) * HE.cv;
        let back = ambient_pressure((*s)[ALT]);
        b.vent = orifice_flow(P.relief_area_m2, x.p_u, back, x.t_u, r_mix, cp / cv);
    }
    if (d.burning) {
        let engine = d.thrust_n / (P.isp_s * G0);
        let avail = clamp(x.m_l / (1.0e-6 * max(x.m_l, 1.0) + 1.0e-3), 0.0, 1.0);
        b.out = engine * P.propellant_fraction * avail;
    }
    return b;
}

fn motion_rates(s: ptr<function, St>, d: Drive, x: Derived, ds: ptr<function, St>) -> f32 {
    let sl = x.sl;
    var force = 0.0;
    if (P.fidelity == FID_LUMPED) {
        let th = (*s)[Q1];
        let w = (*s)[Q1D];
        let l = sl.length.x;
        let om = sl.omega.x;
        let acc = -(x.a_ax / l) * sin(th) - 2.0 * sl.zeta * om * w - (d.a_lat / l) * cos(th);
        (*ds)[Q1] = w;
        (*ds)[Q1D] = acc;
        force = -sl.mass.x * (l * (acc * cos(th) - w * w * sin(th)) + d.a_lat);
    } else if (two_mode_slosh()) {
        let om = sl.omega;
        let acc1 = -om.x * om.x * (*s)[Q1] - 2.0 * sl.zeta * om.x * (*s)[Q1D] - d.a_lat;
        let acc2 = -om.y * om.y * (*s)[Q2] - 2.0 * sl.zeta * om.y * (*s)[Q2D] - d.a_lat;
        (*ds)[Q1] = (*s)[Q1D];
        (*ds)[Q1D] = acc1;
        (*ds)[Q2] = (*s)[Q2D];
        (*ds)[Q2D] = acc2;
        force = -sl.mass.x * (acc1 + d.a_lat) - sl.mass.y * (acc2 + d.a_lat);
    }
    if (d.flying) {
        let g = gravity((*s)[ALT]);
        (*ds)[VEL] = (d.thrust_n - x.drag) / x.mass - g * sin(d.gamma_rad);
        (*ds)[ALT] = (*s)[VEL] * sin(d.gamma_rad);
    }
    if ((P.flags & FLAG_PRESSURIZATION) != 0u) {
        (*ds)[P_FILT] = (x.p_u - (*s)[P_FILT]) / P.press_filter_s;
    }
    return force;
}

fn slosh_speed(s: ptr<function, St>, x: Derived) -> f32 {
    if (P.fidelity == FID_LUMPED) {
        return abs((*s)[Q1D]);
    }
    if (two_mode_slosh()) {
        return abs((*s)[Q1D]) / x.sl.length.x + abs((*s)[Q2D]) / x.sl.length.y;
    }
    return 0.0;
}

/// The waves that stir the liquid (model::wave_mixing::waves): per mode c_mix |x_n| |ẋ_n| (m²/s)
/// and ξ_n / R (1/m), packed (x, y) for mode 1 and (z, w) for mode 2; x = L θ on `lumped`.
fn slosh_waves(s: ptr<function, St>, x: Derived) -> vec4<f32> {
    let radius = tank_radius();
    if (P.fidelity == FID_LUMPED) {
        let l = x.sl.length.x;
        let a1 = P.coupling_mixing * abs(l * (*s)[Q1]) * abs(l * (*s)[Q1D]);
        return vec4<f32>(a1, SLOSH_XI_0 / radius, 0.0, 0.0);
    }
    if (two_mode_slosh()) {
        return vec4<f32>(
            P.coupling_mixing * abs((*s)[Q1]) * abs((*s)[Q1D]),
            SLOSH_XI_0 / radius,
            P.coupling_mixing * abs((*s)[Q2]) * abs((*s)[Q2D]),
            SLOSH_XI_1 / radius,
        );
    }
    return vec4<f32>(0.0);
}

/// The eddy diffusivity Σ c_mix |x_n| |ẋ_n| e^(−2 ξ_n d / R) at `depth` (m) below the surface,
/// m²/s (model::wave_mixing::eddy_diffusivity).
fn eddy_diffusivity(waves: vec4<f32>, depth: f32) -> f32 {
    return waves.x * exp(depth * waves.y * -2.0) + waves.z * exp(depth * waves.w * -2.0);
}

fn slosh_angle_rate(s: ptr<function, St>, x: Derived) -> f32 {
    if (two_mode_slosh()) {
        let l = x.sl.length.x;
        let r = (*s)[Q1] / l;
        return (*s)[Q1D] / l / (1.0 + r * r);
    }
    return (*s)[Q1D];
}

/// Heat into each wall node from outside (insulation::WallHeat): dry and wetted (W), their
/// total (W), and each over its node's heat capacity (K/s).
struct WallHeat {
    dry: f32,
    wet: f32,
    total: f32,
    warming_dry: f32,
    warming_wet: f32,
}

/// The fixed heat leak shared by area, or with [insulation] the steady flux at each wall node's
/// temperature times its share of the wall area (insulation::wall_heat).
fn wall_heat(d: Drive, x: Derived) -> WallHeat {
    let c_wall = P.wall_areal_mass * tank_wall_area() * P.wall_cp;
    var w: WallHeat;
    if ((P.flags & FLAG_INSULATION) == 0u) {
        let q = P.heat_leak_w;
        w.dry = q * (1.0 - x.wet);
        w.wet = q * x.wet;
        w.total = q;
        w.warming_dry = q / c_wall;
        w.warming_wet = q / c_wall;
        return w;
    }
    var k: MliCoeffs;
    k.solid = P.ins_mli_solid;
    k.radiation = P.ins_mli_radiation;
    k.gas = P.ins_mli_gas;
    var e: Surroundings;
    let t_rad = select(P.ins_ground_t, P.ins_space_t, d.space);
    let t_rad2 = t_rad * t_rad;
    e.h = select(P.ins_ground_h, 0.0, d.space);
    e.t_air = t_rad;
    e.t_rad4 = t_rad2 * t_rad2;
    e.absorbed = select(0.0, P.ins_space_absorbed, d.space);
    e.eps_sigma = P.ins_eps_sigma;
    let has_mli = (P.flags & FLAG_MLI) != 0u;
    let area = tank_wall_area();
    let dry = insulation_leak(has_mli, P.ins_foam_resistance, k, e, x.t_wd).q * area;
    let wet = insulation_leak(has_mli, P.ins_foam_resistance, k, e, x.t_ww).q * area;
    w.dry = dry * (1.0 - x.wet);
    w.wet = wet * x.wet;
    w.total = w.dry + w.wet;
    w.warming_dry = dry / c_wall;
    w.warming_wet = wet / c_wall;
    return w;
}

fn wall_rates(x: Derived, env: WallHeat, q_wet: f32, q_dry: f32, dv_liquid: f32, ds: ptr<function, St>) {
    let dz = dv_liquid / max(tank_cross_section_area(x.level), 1.0e-9);
    let m_wall = P.wall_areal_mass * tank_wall_area();
    let dshare = x.wet_slope * dz;
    let t_moving = select(x.t_wd, x.t_ww, dshare < 0.0);
    let handover = m_wall * dshare * P.wall_cp * t_moving;
    (*ds)[E_WD] = env.dry - q_dry - handover;
    (*ds)[E_WW] = env.wet - q_wet + handover;
    (*ds)[E_ENV] = env.total;
}

fn boundary_ledger(b: Bnd, h_press: f32, h_u: f32, e_out: f32, ds: ptr<function, St>) {
    (*ds)[VENT_V] = b.vent * b.y;
    (*ds)[VENT_G] = b.vent * (1.0 - b.y);
    (*ds)[OUT] = b.out;
    (*ds)[PRESS_IN] = b.press;
    (*ds)[E_PRESS] = b.press * h_press;
    (*ds)[E_VENT] = b.vent * h_u;
    (*ds)[E_OUT] = e_out;
}

/// Pressurant enthalpy at the inlet temperature entering at the ullage pressure p_u, J/kg
/// (boundary::pressurant_inlet_enthalpy): helium, or the propellant's real-gas vapour on the
/// ullage's reference when autogenous.
fn pressurant_inlet_enthalpy(p_u: f32) -> f32 {
    if ((P.flags & FLAG_PRESSURIZATION) == 0u) {
        return 0.0;
    }
    if ((P.flags & FLAG_AUTOGENOUS) != 0u) {
        let t_in = P.press_gas_t;
        let u0 = fl_vapor_ideal(t_in).x;
        return u0 + t_in * fl_r_specific() + FL.vapor_offset + fl_vapor_h_res_at_tp(t_in, p_u);
    }
    return HE.cp * P.press_gas_t;
}

/// Share of the pressurant flow that is propellant vapour (boundary::pressurant_vapor_share).
fn pressurant_vapor_share() -> f32 {
    return select(0.0, 1.0, (P.flags & FLAG_AUTOGENOUS) != 0u);
}
