// The derived state of one instance in f32 (src/model/derive.rs, homogeneous.rs): temperatures,
// volumes, level, slosh parameters from the conserved state. Part of the kernel after model.wgsl.

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
    // LAYERED{
    /// Coldest and warmest liquid (every layer of the column), K: the validity check's range.
    t_lmin: f32,
    t_lmax: f32,
    // }LAYERED
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

// Modal masses, lengths and frequencies of the tank's own shape: the closed form for a
// cylinder, the generated tables for a domed tank (shaders/slosh_modes.wgsl). The damping
// correlations (cylinder) take the equivalent cylinder: free-surface radius, depth V / (pi r^2).
fn slosh_params(v_liquid: f32, m_liquid: f32, z: f32, a_ax: f32, nu: f32) -> Slosh {
    let radius = tank_radius();
    let r = max(tank_surface_radius(z), SLOSH_RS_MIN * radius);
    let hr = v_liquid / (PI * r * r) / r;
    let zeta = wall_damping(nu, r, a_ax, hr) + baffle_damping(r, z) + P.extra_damping;
    let q = tank_slosh_modes(z, v_liquid);
    let w2 = q.xz;
    let mr = q.yw;
    var out: Slosh;
    out.mass = mr * m_liquid;
    out.length = radius / w2;
    out.omega = sqrt(w2 * a_ax / radius);
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
    if (SLOSH_UNREAD && slosh_at_rest(s, d)) {
        // derive::SloshParams::at_rest: every slosh term of the rates is then a zero of the same
        // sign as with the modes (an angle, a rate and a force of 0 times a finite factor).
        (*x).sl = Slosh(vec2<f32>(0.0), vec2<f32>(1.0), vec2<f32>(0.0), 0.0);
    } else {
        (*x).sl = slosh_params(v_l, (*x).m_l, (*x).level, a_total, nu_liquid);
    }
}

/// The analog rests and nothing pushes it (derive::slosh_at_rest): no lateral acceleration, the
/// angles and rates 0 (a NaN is not).
fn slosh_at_rest(s: ptr<function, St>, d: Drive) -> bool {
    let still = (*s)[Q1] == 0.0 && (*s)[Q1D] == 0.0 && (*s)[Q2] == 0.0 && (*s)[Q2D] == 0.0;
    return d.a_lat == 0.0 && still;
}

/// The level carries the two-mode slosh analog (Fidelity::two_mode_slosh): two_mode, layered.
fn two_mode_slosh() -> bool {
    return P.fidelity == FID_TWO_MODE || P.fidelity == FID_LAYERED;
}

fn slosh_angle(s: ptr<function, St>, sl: Slosh) -> f32 {
    if (two_mode_slosh()) {
        return atan((*s)[Q1] / sl.length.x);
    }
    return (*s)[Q1];
}

/// The second mode's equivalent angle atan(|x_2| / L_2) (derive::mode2_angle); 0 but two_mode.
fn mode2_angle(s: ptr<function, St>, sl: Slosh) -> f32 {
    if (two_mode_slosh()) {
        return atan(abs((*s)[Q2]) / sl.length.y);
    }
    return 0.0;
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
    finish_nodes(s, d, &x, fl_mu_l(x.t_b) / x.rho_b);
    return x;
}

/// What the node levels derive alike once their liquid is known (derive::finish_nodes): level,
/// flight and slosh, the ullage's volume, temperature and pressures, the walls' temperatures.
/// `nu`: the liquid's kinematic viscosity at the outlet, m²/s.
fn finish_nodes(s: ptr<function, St>, d: Drive, xp: ptr<function, Derived>, nu: f32) {
    var x = *xp;
    let v_l = x.v_s + x.v_b;
    fill_level(&x, v_l);
    motion(s, d, &x, nu);
    x.v_u = tank_volume() - v_l + P.coupling_volume_m3 * sin(slosh_angle(s, x.sl));
    let rho_v = (*s)[M_V] / x.v_u;
    x.t_u = ullage_temperature((*s)[M_V], (*s)[M_G], (*s)[U_U], rho_v);
    x.m_v = (*s)[M_V];
    x.p_v = fl_vapor_state(x.t_u, rho_v).p;
    x.p_u = x.p_v + (*s)[M_G] * he_r_specific() * x.t_u / x.v_u;
    let tw = wall_temperatures(s, x.wet);
    x.t_wd = tw.x;
    x.t_ww = tw.y;
    *xp = x;
}

// Ullage temperature from its energy with real-gas vapour (derive.rs::ullage_temperature):
// Newton from the root of the ideal gas linearised at the middle of the liquid range until the
// step is a few f32 ulps (at most 12 steps).
fn ullage_temperature(m_v: f32, m_g: f32, u: f32, rho_v: f32) -> f32 {
    let cv_g = m_g * HE.cv;
    var t = (u - m_v * FL.ideal_u_ref) / (m_v * FL.ideal_cv_ref + cv_g);
    for (var i = 0; i < 12; i++) {
        let v = fl_vapor_state(t, rho_v);
        let id = fl_vapor_ideal(t);
        let r = m_v * (id.x + FL.vapor_offset + v.u_res) + cv_g * t - u;
        let step = r / (m_v * (id.y + v.du_res_dt) + cv_g);
        t = t - step;
        if abs(step) <= 3e-7 * abs(t) {
            break;
        }
    }
    return t;
}

// ---------------------------------------------------------------- homogeneous level

fn vapor_mass(m_p: f32, t: f32) -> f32 {
    return vapor_mass_at(m_p, fl_rho_v_sat(t), fl_rho_l(t));
}

// vapor_mass from the saturated densities the caller already has.
fn vapor_mass_at(m_p: f32, rho_v: f32, rho_l: f32) -> f32 {
    return clamp(rho_v * (tank_volume() - m_p / rho_l) / (1.0 - rho_v / rho_l), 0.0, m_p);
}

// Saturated real-gas vapour at t: (rho_v, u_v, h_v) as homogeneous.rs::saturated_vapor.
fn saturated_vapor(t: f32) -> vec3<f32> {
    let rho_v = fl_rho_v_sat(t);
    let v = fl_vapor_state(t, rho_v);
    let u_v = fl_vapor_ideal(t).x + FL.vapor_offset + v.u_res;
    return vec3<f32>(rho_v, u_v, u_v + v.z * fl_r_specific() * t);
}

// Internal energy of all fluid at t: liquid u_l = h_l - P_sat/rho_l, saturated vapour, helium.
fn fluid_energy(m_p: f32, m_g: f32, t: f32) -> f32 {
    let sv = saturated_vapor(t);
    let rho_l = fl_rho_l(t);
    let m_v = vapor_mass_at(m_p, sv.x, rho_l);
    let u_l = fl_h_l(t) - fl_psat_pa(t) / rho_l;
    return (m_p - m_v) * u_l + m_v * sv.y + m_g * HE.cv * t;
}

/// Newton on E(T) = e safeguarded by bisection on [t_min - 3 K, t_max + 3 K]
/// (homogeneous.rs::temperature). The f32 slope is a central difference over ±1 mK (the CPU's
/// ±1e-6 T would be rounding noise in f32); the root is the same.
fn homogeneous_temperature(m_p: f32, m_g: f32, e: f32) -> f32 {
    var lo = FL.t_min_hi - 3.0;
    var hi = FL.t_max + 3.0;
    var t = clamp(fl_t_from_h_l(e / m_p), FL.t_min_hi, FL.t_max);
    for (var it = 0u; it < 32u; it++) {
        let h = 1.0e-3;
        let r = fluid_energy(m_p, m_g, t) - e;
        let slope = (fluid_energy(m_p, m_g, t + h) - fluid_energy(m_p, m_g, t - h)) / (2.0 * h);
        if r > 0.0 {
            hi = t;
        } else if r < 0.0 {
            lo = t;
        } else {
            break;
        }
        let newton = t - r / slope;
        let inside = newton > lo && newton < hi && slope > 0.0;
        let next = select(0.5 * (lo + hi), newton, inside);
        if (inside && abs(newton - t) <= 2e-7 * t) || hi - lo <= 2e-7 * t {
            t = next;
            break;
        }
        t = next;
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
    // LAYERED{
    if (P.fidelity == FID_LAYERED) {
        return derive_column(s, d);
    }
    // }LAYERED
    return derive_nodes(s, d);
}
