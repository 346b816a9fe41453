// The physics of one tank instance in f32, one instance per invocation: the WGSL mirror of
// src/model/ (derive.rs, homogeneous.rs, nodes.rs, boundary.rs, thermal.rs, slosh.rs, flight.rs)
// and of the step loop in src/simulate.rs. Change one, change both; tests/gpu_parity.rs checks.
//
// Prepended by the host: the generated constants, the state type St and struct declarations (src/gpu/params.rs,
// src/gpu/props.rs) and shaders/fluids.wgsl, shaders/geometry.wgsl (FL, HE, TANK, fl_*, tank_*).
//
// Precision: the state is carried as f32 hi + lo words and every Runge–Kutta increment is added
// with Kahan compensation, so slow integrals (wall energy over hours, vented mass) lose nothing
// to the f32 word; the right-hand side itself is evaluated in f32 from the hi word.

@group(0) @binding(0) var<storage, read> params: array<GpuParams>;
@group(0) @binding(1) var<storage, read> phases: array<GpuPhase>;
@group(0) @binding(2) var<storage, read> tables: array<f32>;
@group(0) @binding(3) var<storage, read> fluid: array<GpuFluid>;
@group(0) @binding(4) var<storage, read> gas: array<GpuGas>;
@group(0) @binding(5) var<storage, read_write> results: array<GpuResult>;
@group(0) @binding(6) var<storage, read> control: GpuControl;
@group(0) @binding(7) var<storage, read_write> phase_results: array<GpuPhaseResult>;

var<private> P: GpuParams;
// Index of the current phase's record in phase_results (instance × phase).
var<private> PHASE_SLOT: u32;

// ---------------------------------------------------------------- trajectory (flight.rs)

struct Drive {
    thrust_n: f32,
    burning: bool,
    flying: bool,
    gamma_rad: f32,
    gravity: f32,
    a_lat: f32,
    a_ax_extra: f32,
    pressurize: bool,
    valve_open: bool,
}

fn table_interp(ph: GpuPhase, col: u32, t: f32) -> f32 {
    let n = ph.table_len;
    if (n == 0u) {
        return 0.0;
    }
    let b = ph.table_start;
    if (t <= tables[3u * b]) {
        return tables[3u * b + col];
    }
    if (t >= tables[3u * (b + n - 1u)]) {
        return tables[3u * (b + n - 1u) + col];
    }
    // First row with time > t (the CPU's partition_point).
    var lo = 0u;
    var hi = n;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (tables[3u * (b + mid)] <= t) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    let i1 = b + lo;
    let i0 = i1 - 1u;
    let x0 = tables[3u * i0];
    let x1 = tables[3u * i1];
    let y0 = tables[3u * i0 + col];
    let y1 = tables[3u * i1 + col];
    return y0 + (y1 - y0) * (t - x0) / (x1 - x0);
}

const TAU: f32 = 6.283185307179586;
const PI: f32 = 3.141592653589793;

/// Lateral excitation and extra axial acceleration at phase time t.
fn excitation(ph: GpuPhase, t: f32) -> vec2<f32> {
    let e = ph.exc;
    switch ph.exc_kind {
        case EXC_STEP: {
            return vec2<f32>(select(0.0, e[0], t >= e[1]), 0.0);
        }
        case EXC_RAMP: {
            return vec2<f32>(e[0] * clamp((t - e[1]) / e[2], 0.0, 1.0), 0.0);
        }
        case EXC_SINE: {
            // The phase in cycles, reduced before the multiply by 2π.
            let cyc = fract(e[1] * t);
            return vec2<f32>(e[0] * sin(TAU * cyc + e[2]), 0.0);
        }
        case EXC_SWEEP: {
            let tc = clamp(t, 0.0, e[3]);
            let rate = (e[2] - e[1]) / e[3];
            let cyc = fract(e[1] * tc + 0.5 * rate * tc * tc) + fract(e[2] * (t - tc));
            return vec2<f32>(e[0] * sin(TAU * cyc), 0.0);
        }
        case EXC_GUST: {
            let tau = t - e[1];
            if (tau >= 0.0 && tau <= e[2]) {
                return vec2<f32>(0.5 * e[0] * (1.0 - cos(TAU * tau / e[2])), 0.0);
            }
            return vec2<f32>(0.0, 0.0);
        }
        case EXC_TABLE: {
            return vec2<f32>(table_interp(ph, 1u, t), table_interp(ph, 2u, t));
        }
        default: {
            return vec2<f32>(0.0, 0.0);
        }
    }
}

fn phase_drive(ph: GpuPhase, t: f32, valve_open: bool) -> Drive {
    let a = excitation(ph, t);
    let burning = ph.kind == PHASE_BURN;
    var d: Drive;
    d.thrust_n = select(0.0, ph.thrust_n, burning);
    d.burning = burning;
    d.flying = ph.kind != PHASE_HOLD;
    d.gamma_rad = ph.gamma_rad;
    d.gravity = ph.gravity;
    d.a_lat = a.x;
    d.a_ax_extra = a.y;
    d.pressurize = ph.pressurize != 0u;
    d.valve_open = valve_open;
    return d;
}

fn air_density(h: f32) -> f32 {
    return RHO_SEA_LEVEL * exp(-max(h, 0.0) / SCALE_HEIGHT_M);
}

fn ambient_pressure(h: f32) -> f32 {
    return P_SEA_LEVEL_PA * exp(-max(h, 0.0) / SCALE_HEIGHT_M);
}

fn gravity(h: f32) -> f32 {
    let r = EARTH_RADIUS_M / (EARTH_RADIUS_M + max(h, 0.0));
    return G0 * r * r;
}

// ---------------------------------------------------------------- slosh analog (slosh.rs)

struct Slosh {
    mass: vec2<f32>,
    length: vec2<f32>,
    omega: vec2<f32>,
    zeta: f32,
}

/// (mass ratio, length ratio, ω² R / a) of mode n at depth ratio h/R.
fn mode_shape(xi: f32, h_over_r: f32) -> vec3<f32> {
    let hr = max(h_over_r, MIN_DEPTH_RATIO);
    let th = tanh(xi * hr);
    return vec3<f32>(2.0 * th / (xi * (xi * xi - 1.0) * hr), 1.0 / (xi * th), xi * th);
}

fn wall_damping(nu: f32, r: f32, a_ax: f32, h_over_r: f32) -> f32 {
    let hr = max(h_over_r, MIN_DEPTH_RATIO);
    let x = 1.84 * hr;
    let shape = 1.0 + (0.318 / sinh(x)) * (1.0 + (1.0 - hr) / cosh(x));
    return (4.98 / (2.0 * PI)) * sqrt(nu) * pow(r, -0.75) * pow(max(a_ax, MIN_AXIAL_ACCEL), -0.25)
        * shape;
}

fn baffle_damping(r: f32, z_surface: f32) -> f32 {
    if (P.baffle_count == 0u || P.baffle_width_m <= 0.0) {
        return 0.0;
    }
    let w = min(P.baffle_width_m / r, 1.0);
    let alpha = w * (2.0 - w);
    var sum = 0.0;
    for (var k = 0u; k < P.baffle_count; k++) {
        let depth = z_surface - (P.baffle_top_m - f32(k) * P.baffle_spacing_m);
        if (depth >= 0.0) {
            sum += exp(-4.6 * depth / r);
        }
    }
    return 2.83 * sqrt(P.baffle_wave_m / r) * sum * pow(alpha, 1.5);
}

// ---------------------------------------------------------------- derived state (derive.rs)

struct Derived {
    t_u: f32,
    t_s: f32,
    t_b: f32,
    t_wd: f32,
    t_ww: f32,
    rho_s: f32,
    rho_b: f32,
    v_s: f32,
    v_b: f32,
    v_u: f32,
    level: f32,
    a_i: f32,
    wet: f32,
    wet_slope: f32,
    m_v: f32,
    m_l: f32,
    p_v: f32,
    p_u: f32,
    a_ax: f32,
    mass: f32,
    drag: f32,
    sl: Slosh,
}

fn wetted_fraction(z: f32) -> f32 {
    return clamp(tank_wetted_area(z) / tank_wall_area(), MIN_WALL_SHARE, 1.0 - MIN_WALL_SHARE);
}

fn wetted_fraction_slope(z: f32) -> f32 {
    let raw = tank_wetted_area(z) / tank_wall_area();
    if (raw <= MIN_WALL_SHARE || raw >= 1.0 - MIN_WALL_SHARE) {
        return 0.0;
    }
    return tank_wetted_area_slope(z) / tank_wall_area();
}

fn wall_temperatures(s: ptr<function, St>, wet: f32) -> vec2<f32> {
    let mc = P.wall_areal_mass * tank_wall_area() * P.wall_cp;
    return vec2<f32>((*s)[E_WD] / (mc * (1.0 - wet)), (*s)[E_WW] / (mc * wet));
}

fn fill_level(x: ptr<function, Derived>, v_liquid: f32) {
    let z = tank_liquid_height(v_liquid);
    let r = tank_radius();
    (*x).level = z;
    (*x).a_i = max(tank_interface_area(z), 1.0e-6 * r * r);
    (*x).wet = wetted_fraction(z);
    (*x).wet_slope = wetted_fraction_slope(z);
}

fn slosh_params(v_liquid: f32, m_liquid: f32, z: f32, a_ax: f32, nu: f32) -> Slosh {
    let r = max(tank_surface_radius(z), 0.05 * tank_radius());
    let h = v_liquid / (PI * r * r);
    let hr = h / r;
    let zeta = wall_damping(nu, r, a_ax, hr) + baffle_damping(r, z) + P.extra_damping;
    let m0 = mode_shape(XI_0, hr);
    let m1 = mode_shape(XI_1, hr);
    var out: Slosh;
    out.mass = vec2<f32>(m0.x, m1.x) * m_liquid;
    out.length = vec2<f32>(m0.y, m1.y) * r;
    out.omega = sqrt(vec2<f32>(m0.z, m1.z) * a_ax / r);
    out.zeta = zeta;
    return out;
}

fn motion(s: ptr<function, St>, d: Drive, x: ptr<function, Derived>, nu_liquid: f32) {
    let m_tank = (*x).m_l + (*s)[M_V] + (*s)[M_G];
    let other_used = (*s)[OUT] * (1.0 / P.propellant_fraction - 1.0);
    let mass = max(P.dry_mass_kg + m_tank - other_used, 1.0);
    let v = (*s)[VEL];
    let drag = 0.5 * air_density((*s)[ALT]) * v * abs(v) * P.drag_area_m2;
    var a = 0.0;
    if (d.flying) {
        a = (d.thrust_n - drag) / mass;
    }
    (*x).mass = mass;
    (*x).drag = drag;
    (*x).a_ax = max(a + d.gravity + d.a_ax_extra, MIN_AXIAL_ACCEL);
    let v_l = (*x).v_s + (*x).v_b;
    let a_total = sqrt((*x).a_ax * (*x).a_ax + d.a_lat * d.a_lat);
    (*x).sl = slosh_params(v_l, (*x).m_l, (*x).level, a_total, nu_liquid);
}

fn slosh_angle(s: ptr<function, St>, sl: Slosh) -> f32 {
    if (P.fidelity == FID_TWO_MODE) {
        return atan((*s)[Q1] / sl.length.x);
    }
    return (*s)[Q1];
}

fn derive_nodes(s: ptr<function, St>, d: Drive) -> Derived {
    var x: Derived;
    let m_s = max((*s)[M_S], 1.0e-12);
    let m_b = max((*s)[M_B], 1.0e-12);
    x.t_s = fl_t_from_h_l((*s)[H_S] / m_s);
    x.t_b = select(fl_t_from_h_l((*s)[H_B] / m_b), x.t_s, (*s)[M_B] <= 0.0);
    x.rho_s = fl_rho_l(x.t_s);
    x.rho_b = fl_rho_l(x.t_b);
    x.v_s = (*s)[M_S] / x.rho_s;
    x.v_b = (*s)[M_B] / x.rho_b;
    x.m_l = (*s)[M_S] + (*s)[M_B];
    let v_l = x.v_s + x.v_b;
    fill_level(&x, v_l);
    let nu = fl_mu_l(x.t_b) / x.rho_b;
    motion(s, d, &x, nu);
    x.v_u = tank_volume() - v_l + P.coupling_volume_m3 * sin(slosh_angle(s, x.sl));
    let heat_cap = (*s)[M_V] * FL.cv_vapor + (*s)[M_G] * HE.cv;
    x.t_u = ((*s)[U_U] - (*s)[M_V] * FL.vapor_offset) / heat_cap;
    x.m_v = (*s)[M_V];
    x.p_v = (*s)[M_V] * fl_r_specific() * x.t_u / x.v_u;
    x.p_u = x.p_v + (*s)[M_G] * he_r_specific() * x.t_u / x.v_u;
    let tw = wall_temperatures(s, x.wet);
    x.t_wd = tw.x;
    x.t_ww = tw.y;
    return x;
}

// ---------------------------------------------------------------- homogeneous level

fn vapor_mass(m_p: f32, t: f32) -> f32 {
    let rho_v = fl_psat_pa(t) / (fl_r_specific() * t);
    let rho_l = fl_rho_l(t);
    return clamp(rho_v * (tank_volume() - m_p / rho_l) / (1.0 - rho_v / rho_l), 0.0, m_p);
}

fn fluid_energy(m_p: f32, m_g: f32, t: f32) -> f32 {
    let m_v = vapor_mass(m_p, t);
    let u_v = FL.cv_vapor * t + FL.vapor_offset;
    return (m_p - m_v) * fl_h_l(t) + m_v * u_v + m_g * HE.cv * t;
}

/// Newton on E(T) = e. The f32 slope is a central difference over ±1 mK (the CPU's ±1e-6 T
/// would be rounding noise in f32); the root is the same.
fn homogeneous_temperature(m_p: f32, m_g: f32, e: f32) -> f32 {
    let lo = FL.t_min_hi;
    let hi = FL.t_max;
    var t = clamp(fl_t_from_h_l(e / m_p), lo, hi);
    for (var it = 0u; it < 8u; it++) {
        let h = 1.0e-3;
        let r = fluid_energy(m_p, m_g, t) - e;
        let slope = (fluid_energy(m_p, m_g, t + h) - fluid_energy(m_p, m_g, t - h)) / (2.0 * h);
        t = clamp(t - r / slope, lo, hi);
    }
    return t;
}

fn derive_homogeneous(s: ptr<function, St>, d: Drive) -> Derived {
    let m_p = (*s)[M_B];
    let m_g = (*s)[M_G];
    let t = homogeneous_temperature(m_p, m_g, (*s)[H_B]);
    let m_v = vapor_mass(m_p, t);
    let rho = fl_rho_l(t);
    var x: Derived;
    x.t_u = t;
    x.t_s = t;
    x.t_b = t;
    x.rho_s = rho;
    x.rho_b = rho;
    x.v_s = 0.0;
    x.v_b = (m_p - m_v) / rho;
    x.m_v = m_v;
    x.m_l = m_p - m_v;
    fill_level(&x, x.v_b);
    x.v_u = tank_volume() - x.v_b;
    x.p_v = fl_psat_pa(t);
    x.p_u = x.p_v + m_g * he_r_specific() * t / x.v_u;
    let tw = wall_temperatures(s, x.wet);
    x.t_wd = tw.x;
    x.t_ww = tw.y;
    motion(s, d, &x, fl_mu_l(t) / rho);
    return x;
}

fn derive_state(s: ptr<function, St>, d: Drive) -> Derived {
    if (P.fidelity == FID_HOMOGENEOUS) {
        return derive_homogeneous(s, d);
    }
    return derive_nodes(s, d);
}

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

fn gas_props(s: ptr<function, St>, x: Derived) -> Conv {
    let m = x.m_v + (*s)[M_G];
    let y = select(1.0, x.m_v / m, m > 0.0);
    let t = x.t_u;
    return Conv(
        y * fl_k_v(t) + (1.0 - y) * he_k(t),
        y * fl_mu_v(t) + (1.0 - y) * he_mu(t),
        m / x.v_u,
        y * FL.cp_vapor + (1.0 - y) * HE.cp,
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
        let demand = clamp(P.press_kp * e + P.press_kd * e_dot, 0.0, P.press_max_flow);
        let left = P.press_bottle_kg - (*s)[PRESS_IN];
        let fade = clamp(left / (1.0e-3 * P.press_bottle_kg + 1.0e-9), 0.0, 1.0);
        b.press = demand * fade;
    }
    if ((P.flags & FLAG_RELIEF) != 0u && d.valve_open) {
        let rv = fl_r_specific();
        let rg = he_r_specific();
        let r_mix = y * rv + (1.0 - y) * rg;
        let cp = y * FL.cp_vapor + (1.0 - y) * HE.cp;
        let cv = y * FL.cv_vapor + (1.0 - y) * HE.cv;
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
    } else if (P.fidelity == FID_TWO_MODE) {
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
    if (P.fidelity == FID_TWO_MODE) {
        return abs((*s)[Q1D]) / x.sl.length.x + abs((*s)[Q2D]) / x.sl.length.y;
    }
    return 0.0;
}

fn slosh_angle_rate(s: ptr<function, St>, x: Derived) -> f32 {
    if (P.fidelity == FID_TWO_MODE) {
        let l = x.sl.length.x;
        let r = (*s)[Q1] / l;
        return (*s)[Q1D] / l / (1.0 + r * r);
    }
    return (*s)[Q1D];
}

fn wall_rates(x: Derived, q_wet: f32, q_dry: f32, dv_liquid: f32, ds: ptr<function, St>) {
    let dz = dv_liquid / max(tank_cross_section_area(x.level), 1.0e-9);
    let m_wall = P.wall_areal_mass * tank_wall_area();
    let dshare = x.wet_slope * dz;
    let t_moving = select(x.t_wd, x.t_ww, dshare < 0.0);
    let handover = m_wall * dshare * P.wall_cp * t_moving;
    let q_env = P.heat_leak_w;
    (*ds)[E_WD] = q_env * (1.0 - x.wet) - q_dry - handover;
    (*ds)[E_WW] = q_env * x.wet - q_wet + handover;
    (*ds)[E_ENV] = q_env;
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

fn helium_inlet_enthalpy() -> f32 {
    if ((P.flags & FLAG_PRESSURIZATION) != 0u) {
        return HE.cp * P.press_gas_t;
    }
    return 0.0;
}

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
    let beta = -fl_drho_l_dt(t) / (rho * rho * fl_cp_l(t));
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
    h_ls: f32,
    h_lb: f32,
    h_fg: f32,
    h_vap_gas: f32,
    vent: f32,
    y: f32,
    press: f32,
    h_press: f32,
    h_u: f32,
    pu: f32,
    dv_b: f32,
    dv_slosh: f32,
    t_s: f32,
    rho_s: f32,
    /// c_p,l and dP_sat/dT at T_s, evaluated once per right-hand side.
    cp_s: f32,
    dpsat_dt: f32,
}

/// [dm_v, dm_s, dH_s, dU_u, dV_s] at evaporation rate m.
fn evap_tail(c: EvapTail, m: f32) -> array<f32, 5> {
    let e_evap = max(m, 0.0) * (c.h_ls + c.h_fg) + min(m, 0.0) * c.h_vap_gas;
    let dm_v = m - c.vent * c.y;
    let dm_s = -m + c.m_strat - c.out_s;
    let f_s = c.q_ws + c.q_us - c.q_sb - e_evap + c.m_strat * c.h_lb - c.mix_w - c.out_s * c.h_ls;
    let rs = liquid_node_rates(c.pu, f_s, dm_s, c.t_s, c.rho_s);
    let du_u = c.q_wu - c.q_us + e_evap + c.press * c.h_press - c.vent * c.h_u
        + c.pu * (rs.y + c.dv_b) - c.pu * c.dv_slosh;
    return array<f32, 5>(dm_v, dm_s, rs.x, du_u, rs.y);
}

/// d(P_sat(T_s) − P_v)/dt along the rates r of evap_tail (chain rule through derive_nodes).
fn evap_dp_rate(s: ptr<function, St>, x: Derived, c: EvapTail, r: array<f32, 5>, dm_g: f32) -> f32 {
    let heat_cap = (*s)[M_V] * FL.cv_vapor + (*s)[M_G] * HE.cv;
    let dt_s = (r[2] - c.h_ls * r[1]) / (max((*s)[M_S], 1.0e-9) * c.cp_s);
    let dt_u = (r[3] - r[0] * FL.vapor_offset - x.t_u * (r[0] * FL.cv_vapor + dm_g * HE.cv)) / heat_cap;
    let dv_u = c.dv_slosh - r[4] - c.dv_b;
    let dp_v = ((r[0] * x.t_u + (*s)[M_V] * dt_u) * fl_r_specific() - x.p_v * dv_u) / x.v_u;
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

    let liq = liquid_props(t_b);
    let gas = gas_props(s, x);
    let h_w = wall_coefficients(x, liq, gas, t_b, t_u);
    let h_wl = h_w.x;
    let h_wu = h_w.y;
    let c_wall = P.wall_areal_mass * a_tot * P.wall_cp;
    let bulk_gone = (*s)[M_B] <= 0.0;
    let c_bulk = max(select((*s)[M_B], (*s)[M_S], bulk_gone), 1.0e-9) * liq.cp;
    let c_gas = (*s)[M_V] * FL.cv_vapor + (*s)[M_G] * HE.cv;
    let warming = P.heat_leak_w / c_wall;
    let q_wl = wall_exchange(h_wl * a_wet, dt, c_wall * x.wet, c_bulk, x.t_ww - t_b, warming);
    let depth = x.v_s / a_i;
    let a_ws = clamp(a_wet - tank_wetted_area(x.level - depth), 0.0, a_wet);
    let contact = a_ws / max(a_wet, 1.0e-12);
    let to_layer = select(contact + P.wall_heat_to_layer * (1.0 - contact), 1.0, bulk_gone);
    let q_ws = to_layer * q_wl;
    let q_wb = (1.0 - to_layer) * q_wl;
    let q_wu = wall_exchange(h_wu * a_dry, dt, c_wall * (1.0 - x.wet), c_gas, x.t_wd - t_u, warming);

    var h_us = P.h_us;
    if ((P.flags & FLAG_H_US) == 0u) {
        h_us = h_stable_interface(gas, x.a_ax, t_u - t_s, 0.5 * r_surf);
    }
    h_us += P.coupling_h * speed;
    let q_us = h_us * a_i * (t_u - t_s);
    var h_sb0 = 0.0;
    if ((P.flags & FLAG_H_SB) != 0u) {
        h_sb0 = P.h_sb;
    }
    let h_sb = h_sb0 + h_unstable_interface(liq, x.a_ax, t_b - t_s, 0.5 * r_surf) + P.coupling_h * speed;
    let q_sb = h_sb * a_i * (t_s - t_b);

    let alpha = P.diffusivity_factor * fl_k_l(t_s) / (x.rho_s * fl_cp_l(t_s));
    let delta = max((*s)[M_S] / (x.rho_s * a_i), 1.0e-6);
    let bulk_left = clamp((*s)[M_B] / (BULK_MERGE_FRACTION * ((*s)[M_B] + (*s)[M_S]) + 1.0e-9), 0.0, 1.0);
    let m_strat = x.rho_s * a_i * PI * alpha / (8.0 * delta) * bulk_left;
    let m_mix = P.coupling_mixing * (*s)[M_S] * speed * bulk_left;

    let b = boundary_flows(s, d, x);
    let h_mass = h_us / (gas.rho * gas.cp);
    let kd = evaporation_driving(s, x, h_mass);
    let out_b = b.out * bulk_left;
    let out_s = b.out * (1.0 - bulk_left);

    let h_ls = fl_h_l(t_s);
    let h_lb = fl_h_l(t_b);
    let h_vap_gas = FL.cp_vapor * t_u + FL.vapor_offset;
    let y = b.y;
    let h_u = y * h_vap_gas + (1.0 - y) * HE.cp * t_u;
    let h_press = helium_inlet_enthalpy();
    let pu = x.p_u;

    (*ds)[M_G] = b.press - b.vent * (1.0 - y);
    (*ds)[M_B] = -m_strat - out_b;
    let mix_w = m_mix * (h_ls - h_lb);
    let f_b = q_wb + q_sb - m_strat * h_lb + mix_w - out_b * h_lb;
    let rb = liquid_node_rates(pu, f_b, (*ds)[M_B], t_b, x.rho_b);
    (*ds)[H_B] = rb.x;
    let force = motion_rates(s, d, x, ds);
    let angle = slosh_angle(s, x.sl);
    let dv_slosh = P.coupling_volume_m3 * cos(angle) * slosh_angle_rate(s, x);

    var c: EvapTail;
    c.q_ws = q_ws;
    c.q_us = q_us;
    c.q_sb = q_sb;
    c.q_wu = q_wu;
    c.m_strat = m_strat;
    c.out_s = out_s;
    c.mix_w = mix_w;
    c.h_ls = h_ls;
    c.h_lb = h_lb;
    c.h_fg = fl_h_fg(t_s);
    c.h_vap_gas = h_vap_gas;
    c.vent = b.vent;
    c.y = y;
    c.press = b.press;
    c.h_press = h_press;
    c.h_u = h_u;
    c.pu = pu;
    c.dv_b = rb.y;
    c.dv_slosh = dv_slosh;
    c.t_s = t_s;
    c.rho_s = x.rho_s;
    c.cp_s = fl_cp_l(t_s);
    c.dpsat_dt = fl_dpsat_dt(t_s);
    let m_evap = implicit_evaporation(s, x, c, kd, dt, (*ds)[M_G]);
    EVAP_RATE = m_evap;
    let r = evap_tail(c, m_evap);
    (*ds)[M_V] = r[0];
    (*ds)[M_S] = r[1];
    (*ds)[H_S] = r[2];
    (*ds)[U_U] = r[3];
    let rs = vec2<f32>(r[2], r[4]);

    wall_rates(x, q_wl, q_wu, rs.y + rb.y, ds);
    boundary_ledger(b, h_press, h_u, out_s * h_ls + out_b * h_lb, ds);
    (*ds)[E_WORK] = -pu * dv_slosh;
    return force;
}

/// Homogeneous right-hand side into ds; returns the slosh force (none at this level).
fn rhs_homogeneous(s: ptr<function, St>, d: Drive, x: Derived, dt: f32, ds: ptr<function, St>) -> f32 {
    let t = x.t_b;
    let a_tot = tank_wall_area();
    let a_wet = a_tot * x.wet;
    let a_dry = a_tot * (1.0 - x.wet);
    let rho = x.rho_b;
    let liq = liquid_props(t);
    let gas = gas_props(s, x);
    let m_u = x.m_v + (*s)[M_G];
    let h_w = wall_coefficients(x, liq, gas, t, t);
    let h_wl = h_w.x;
    let h_wu = h_w.y;
    let c_wall = P.wall_areal_mass * a_tot * P.wall_cp;
    let c_fluid = x.m_l * liq.cp + m_u * FL.cv_vapor;
    let warming = P.heat_leak_w / c_wall;
    let q_wl = wall_exchange(h_wl * a_wet, dt, c_wall * x.wet, c_fluid, x.t_ww - t, warming);
    let q_wu = wall_exchange(h_wu * a_dry, dt, c_wall * (1.0 - x.wet), c_fluid, x.t_wd - t, warming);

    var sv = *s;
    sv[M_V] = x.m_v;
    let b = boundary_flows(&sv, d, x);
    let h_v = FL.cp_vapor * t + FL.vapor_offset;
    let h_u = b.y * h_v + (1.0 - b.y) * HE.cp * t;
    let h_l = fl_h_l(t);
    let h_press = helium_inlet_enthalpy();

    (*ds)[M_B] = -b.out - b.vent * b.y;
    (*ds)[M_G] = b.press - b.vent * (1.0 - b.y);
    (*ds)[H_B] = q_wl + q_wu + b.press * h_press - b.vent * h_u - b.out * h_l;
    let force = motion_rates(s, d, x, ds);
    wall_rates(x, q_wl, q_wu, (*ds)[M_B] / rho, ds);
    boundary_ledger(b, h_press, h_u, b.out * h_l, ds);
    return force;
}

// ---------------------------------------------------------------- mod.rs, simulate.rs

struct Eval {
    x: Derived,
    ds: St,
    force: f32,
    /// Interfacial evaporation rate, kg/s, and its relaxation rate K·J, 1/s (0 at the
    /// homogeneous level; error control and its restart step use them).
    evap: f32,
    relax: f32,
}

// Set by the lumped right-hand side for evaluate's Eval (nodes::Fluxes::evap_kg_s,
// evap_relaxation_per_s).
var<private> EVAP_RATE: f32;
var<private> EVAP_RELAX: f32;

fn evaluate(s: ptr<function, St>, d: Drive, dt: f32) -> Eval {
    var ev: Eval;
    ev.x = derive_state(s, d);
    var ds: St;
    for (var i = 0u; i < NS; i++) {
        ds[i] = 0.0;
    }
    EVAP_RATE = 0.0;
    EVAP_RELAX = 0.0;
    if (P.fidelity == FID_HOMOGENEOUS) {
        ev.force = rhs_homogeneous(s, d, ev.x, dt, &ds);
    } else {
        ev.force = rhs_nodes(s, d, ev.x, dt, &ds);
    }
    ev.ds = ds;
    ev.evap = EVAP_RATE;
    ev.relax = EVAP_RELAX;
    return ev;
}

fn rates_at(s: ptr<function, St>, a: f32, k: ptr<function, St>, d: Drive, dt: f32) -> St {
    var y: St;
    for (var i = 0u; i < NS; i++) {
        y[i] = (*s)[i] + a * (*k)[i];
    }
    return evaluate(&y, d, dt).ds;
}

fn not_finite(v: f32) -> bool {
    return (bitcast<u32>(v) & 0x7f800000u) == 0x7f800000u;
}

/// Which check failed (an index into DIVERGED_REASONS) and the offending value; 0 if none.
fn check_state(s: ptr<function, St>, x: Derived) -> vec2<f32> {
    for (var i = 0u; i < NS; i++) {
        if (not_finite((*s)[i])) {
            return vec2<f32>(1.0, f32(i));
        }
    }
    var v = array<f32, 7>(x.p_u, x.v_u, x.t_u, x.t_s, x.t_b, x.t_wd, x.t_ww);
    var lo = array<f32, 7>(0.0, 0.0, 1.0, FL.t_min_hi - 2.0, FL.t_min_hi - 2.0, 1.0, 1.0);
    var hi = array<f32, 7>(10.0 * FL.p_crit, 3.4e38, 2000.0, FL.t_max + 2.0, FL.t_max + 2.0, 2000.0, 2000.0);
    for (var i = 0u; i < 7u; i++) {
        if (not_finite(v[i]) || !(v[i] > lo[i] && v[i] < hi[i])) {
            return vec2<f32>(f32(2u + i), v[i]);
        }
    }
    let scale = 1.0e-9 * max(abs((*s)[M_B] + (*s)[M_S]), 1.0);
    if ((*s)[M_V] < -scale) {
        return vec2<f32>(9.0, (*s)[M_V]);
    }
    if ((*s)[M_G] < -scale) {
        return vec2<f32>(10.0, (*s)[M_G]);
    }
    if ((*s)[M_S] < -scale) {
        return vec2<f32>(11.0, (*s)[M_S]);
    }
    if ((*s)[M_B] < -scale) {
        return vec2<f32>(11.0, (*s)[M_B]);
    }
    return vec2<f32>(0.0, 0.0);
}

fn cavitation_margin(s: ptr<function, St>, x: Derived) -> vec2<f32> {
    let bulk_gone = (*s)[M_B] <= BULK_MERGE_FRACTION * ((*s)[M_B] + (*s)[M_S]);
    let rho = select(x.rho_b, x.rho_s, bulk_gone);
    let t_out = select(x.t_b, x.t_s, bulk_gone);
    let head = x.p_u + rho * x.a_ax * (x.level + P.line_height_m) - P.line_loss_pa
        - 0.5 * rho * P.line_velocity_m_s * P.line_velocity_m_s - fl_psat_pa(t_out);
    let margin = head / (rho * G0) - P.npsh_required_m;
    return vec2<f32>(margin, margin * rho * G0);
}

fn observe(r: ptr<function, GpuResult>, s: ptr<function, St>, t: f32, ev: Eval, d: Drive) {
    let pu = ev.x.p_u;
    if (pu > (*r).peak_pressure_pa) {
        // A later peak within f32 rounding of the first is the same peak (simulate::observe).
        if (pu > (*r).peak_pressure_pa + 1.0e-6 * abs((*r).peak_pressure_pa)) {
            (*r).peak_pressure_time_s = t;
        }
        (*r).peak_pressure_pa = pu;
    }
    if (pu < (*r).min_pressure_pa) {
        (*r).min_pressure_pa = pu;
        (*r).min_pressure_time_s = t;
    }
    var ph = phase_results[PHASE_SLOT];
    if (d.burning) {
        let m = cavitation_margin(s, ev.x);
        if ((*r).drew == 0u || m.x < (*r).min_margin_m) {
            (*r).drew = 1u;
            (*r).min_margin_m = m.x;
            (*r).min_margin_pa = m.y;
            (*r).min_margin_time_s = t;
        }
        if (ph.drew == 0u || m.x < ph.min_margin_m) {
            ph.drew = 1u;
            ph.min_margin_m = m.x;
        }
    }
    let angle = abs(slosh_angle(s, ev.x.sl));
    (*r).last_angle_rad = angle;
    (*r).max_slosh_angle_rad = max((*r).max_slosh_angle_rad, angle);
    let force = abs(ev.force);
    (*r).peak_slosh_force_n = max((*r).peak_slosh_force_n, force);
    (*r).peak_slosh_moment_n_m = max((*r).peak_slosh_moment_n_m, force * abs(P.lever_arm_m));
    ph.peak_pressure_pa = max(ph.peak_pressure_pa, pu);
    ph.min_pressure_pa = min(ph.min_pressure_pa, pu);
    ph.max_slosh_angle_rad = max(ph.max_slosh_angle_rad, angle);
    phase_results[PHASE_SLOT] = ph;
}

/// Phase record `slot` starts from the last observed state (hi + lo words) of `r`
/// (simulate::qoi::Tracker::enter_phase): its start pressure, slosh angle, vapour mass and vented
/// slots.
fn enter_phase(slot: u32, r: ptr<function, GpuResult>, hi: ptr<function, St>, lo: ptr<function, St>) {
    var ph: GpuPhaseResult;
    ph.entered = 1u;
    ph.start_pressure_pa = (*r).p_ullage_pa;
    ph.peak_pressure_pa = (*r).p_ullage_pa;
    ph.min_pressure_pa = (*r).p_ullage_pa;
    ph.max_slosh_angle_rad = (*r).last_angle_rad;
    if (P.fidelity == FID_HOMOGENEOUS) {
        ph.m_vapor_hi = (*r).m_vapor_kg;
    } else {
        ph.m_vapor_hi = (*hi)[M_V];
        ph.m_vapor_lo = (*lo)[M_V];
    }
    ph.vent_v_hi = (*hi)[VENT_V];
    ph.vent_v_lo = (*lo)[VENT_V];
    ph.vent_g_hi = (*hi)[VENT_G];
    ph.vent_g_lo = (*lo)[VENT_G];
    phase_results[slot] = ph;
}

fn update_valve(pressure: f32, open: bool) -> bool {
    if ((P.flags & FLAG_RELIEF) == 0u) {
        return false;
    }
    if (pressure >= P.relief_crack_pa) {
        return true;
    }
    if (pressure <= P.relief_reseat_pa) {
        return false;
    }
    return open;
}

/// Move slot `src` into slot `dst` on the hi + lo words, keeping the rounding in lo.
fn absorb(hi: ptr<function, St>, lo: ptr<function, St>, dst: u32, src: u32) {
    let t = ((*hi)[dst] + (*hi)[src]) * control.one;
    let err = (*hi)[src] - (t - (*hi)[dst]);
    (*lo)[dst] = (*lo)[dst] + (*lo)[src] + err;
    (*hi)[dst] = t;
    (*hi)[src] = 0.0;
    (*lo)[src] = 0.0;
}

/// Merge a nearly empty bulk node into the layer (model::merge_empty_bulk). True if it merged.
fn merge_empty_bulk(hi: ptr<function, St>, lo: ptr<function, St>) -> bool {
    let m_b = (*hi)[M_B] + (*lo)[M_B];
    let m_s = (*hi)[M_S] + (*lo)[M_S];
    if (P.fidelity == FID_HOMOGENEOUS || m_b <= 0.0 || m_b > BULK_MERGE_FRACTION * (m_b + m_s)) {
        return false;
    }
    absorb(hi, lo, M_S, M_B);
    absorb(hi, lo, H_S, H_B);
    return true;
}

/// Accumulate the time the slosh analog spends outside its range (LaneRun::slosh_validity).
fn slosh_validity(r: ptr<function, GpuResult>, s: ptr<function, St>, dt: f32, ev: Eval, d: Drive) {
    if (P.fidelity == FID_HOMOGENEOUS) {
        return;
    }
    let a = sqrt(ev.x.a_ax * ev.x.a_ax + d.a_lat * d.a_lat);
    let sigma = P.sigma0 * pow(max(1.0 - ev.x.t_s / P.sigma_tc, 0.0), P.sigma_exp);
    let bond = ev.x.rho_b * a * TANK.radius * TANK.radius / sigma;
    if (bond < SLOSH_BOND_MIN || abs(slosh_angle(s, ev.x.sl)) > SLOSH_ANGLE_MAX_RAD) {
        (*r).slosh_out = 1u;
        (*r).slosh_out_time_s += dt;
    }
}

/// The fraction of a step where values a → b cross `level`, linearly (simulate::crossing).
fn crossing(a: f32, b: f32, level: f32) -> f32 {
    if (a == b) {
        return 1.0;
    }
    return clamp((a - level) / (a - b), 0.0, 1.0);
}

/// Outcomes of the step from t0 to t1 ending at evaluation ev (LaneRun::outcomes): the bottle
/// running out (first time), and the tank running dry. True when it ran dry.
fn outcomes(r: ptr<function, GpuResult>, press0: f32, press1: f32, t0: f32, t1: f32, ev: Eval) -> bool {
    if ((P.flags & FLAG_PRESSURIZATION) != 0u && (*r).exhausted == 0u) {
        let empty = P.press_bottle_kg * (1.0 - PRESSURANT_EMPTY_FRACTION);
        if (press1 >= empty) {
            (*r).exhausted = 1u;
            (*r).exhausted_time_s = t0 + crossing(press0, press1, empty) * (t1 - t0);
        }
    }
    let residual = (*r).m_liquid0_kg * DEPLETION_RESIDUAL_FRACTION;
    if (!(ev.x.m_l <= residual)) {
        return false;
    }
    (*r).depleted = 1u;
    (*r).depleted_time_s = t0 + crossing((*r).m_liquid_kg, ev.x.m_l, residual) * (t1 - t0);
    return true;
}

fn save_last(r: ptr<function, GpuResult>, x: Derived) {
    (*r).m_vapor_kg = x.m_v;
    (*r).t_layer_k = x.t_s;
    (*r).t_bulk_k = x.t_b;
    (*r).p_ullage_pa = x.p_u;
    (*r).m_liquid_kg = x.m_l;
}
