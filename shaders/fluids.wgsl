// Propellant and helium properties in f32, one function per `FluidProps` / `GasProps` method of
// src/fluids/mod.rs (same clamping and continuation). The kernel assigns FL and HE once per
// invocation; every per-fluid number comes from them (see src/gpu/props.rs).

var<private> FL: GpuFluid;
var<private> HE: GpuGas;

// Iteration cap of the bracketed Newton solvers fl_tsat_k and fl_t_from_h_l (a few suffice).
const FL_NEWTON_ITER: i32 = 16;
// Newton steps below this (in x, |x| <= 1) are accepted as converged: a few f32 ulps.
const FL_NEWTON_TOL: f32 = 2e-7;

// Horner evaluation of sum c_i x^i.
fn fl_poly(c: array<f32, 8>, x: f32) -> f32 {
    return c[0] + x * (c[1] + x * (c[2] + x * (c[3] + x * (c[4] + x * (c[5] + x * (c[6] + x * c[7]))))));
}

// Normalised temperature x = (T - T_mid) / T_half, unclamped (T_mid carried as hi + lo).
fn fl_x(t: f32) -> f32 {
    return ((t - FL.t_mid_hi) - FL.t_mid_lo) * FL.inv_t_half;
}

// Normalised temperature clamped to [-1, 1].
fn fl_x_clamped(t: f32) -> f32 {
    return clamp(fl_x(t), -1.0, 1.0);
}

// Temperature (K) from a normalised temperature.
fn fl_t_of(x: f32) -> f32 {
    return FL.t_mid_hi + (FL.t_mid_lo + FL.t_half * x);
}

// (ln P_sat, d ln P_sat / dx), continued linearly outside [-1, 1], before the limit.
fn fl_ln_psat_and_slope(t: f32) -> vec2<f32> {
    let x = fl_x(t);
    if x < -1.0 {
        return vec2<f32>(FL.ln_psat_lo + FL.ln_psat_slope_lo * (x + 1.0), FL.ln_psat_slope_lo);
    }
    if x > 1.0 {
        return vec2<f32>(FL.ln_psat_hi + FL.ln_psat_slope_hi * (x - 1.0), FL.ln_psat_slope_hi);
    }
    return vec2<f32>(fl_poly(FL.ln_psat, x), fl_poly(FL.ln_psat_d, x));
}

// y_ref (T / t_ref)^n with T clamped to [t_min, t_max].
fn fl_power_law(y_ref: f32, t_ref: f32, n: f32, t_min: f32, t_max: f32, t: f32) -> f32 {
    return y_ref * pow(clamp(t, t_min, t_max) / t_ref, n);
}

// Specific gas constant R_u / M of the vapour, J/(kg K).
fn fl_r_specific() -> f32 {
    return FL.r_specific;
}

// Saturation pressure (Pa) at t (K); |ln P| limited so the result is a finite normal f32.
fn fl_psat_pa(t: f32) -> f32 {
    let l = fl_ln_psat_and_slope(t);
    return exp(clamp(l.x, -FL.ln_p_limit, FL.ln_p_limit));
}

// dP_sat/dT (Pa/K) at t (K), consistent with fl_psat_pa; 0 where the limit is active.
fn fl_dpsat_dt(t: f32) -> f32 {
    let l = fl_ln_psat_and_slope(t);
    if abs(l.x) > FL.ln_p_limit {
        return 0.0;
    }
    return exp(l.x) * l.y * FL.inv_t_half;
}

// Saturation temperature (K) at p (Pa): bracketed Newton on the ln P_sat polynomial from the
// Clausius-Clapeyron guess; clamps to [t_min, t_max] outside [P_sat(t_min), P_sat(t_max)].
fn fl_tsat_k(p: f32) -> f32 {
    let t_min = FL.t_min_hi + FL.t_min_lo;
    if p <= 0.0 {
        return t_min;
    }
    let ln_p = log(p);
    if ln_p <= FL.ln_psat_lo {
        return t_min;
    }
    if ln_p >= FL.ln_psat_hi {
        return FL.t_max;
    }
    let frac = (ln_p - FL.ln_psat_lo) / (FL.ln_psat_hi - FL.ln_psat_lo);
    let inv_t = (1.0 - frac) / t_min + frac / FL.t_max;
    var x = fl_x_clamped(1.0 / inv_t);
    var lo = -1.0;
    var hi = 1.0;
    for (var i = 0; i < FL_NEWTON_ITER; i++) {
        let f = fl_poly(FL.ln_psat, x) - ln_p;
        if f == 0.0 {
            break;
        }
        if f > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        let x_newton = x - f / fl_poly(FL.ln_psat_d, x);
        if abs(x_newton - x) <= FL_NEWTON_TOL {
            x = clamp(x_newton, -1.0, 1.0);
            break;
        }
        x = select(0.5 * (lo + hi), x_newton, x_newton > lo && x_newton < hi);
    }
    return fl_t_of(x);
}

// Saturated-liquid density (kg/m3) at t (K), clamped outside the range.
fn fl_rho_l(t: f32) -> f32 {
    return fl_poly(FL.rho_l, fl_x_clamped(t));
}

// d rho_l / dT (kg/(m3 K)) at t (K); 0 outside the range.
fn fl_drho_l_dt(t: f32) -> f32 {
    let x = fl_x(t);
    if x < -1.0 || x > 1.0 {
        return 0.0;
    }
    return fl_poly(FL.rho_l_d, x) * FL.inv_t_half;
}

// Saturated-liquid c_p (J/(kg K)) at t (K), clamped outside the range.
fn fl_cp_l(t: f32) -> f32 {
    return fl_poly(FL.cp_l, fl_x_clamped(t));
}

// Slope of the saturated-liquid enthalpy dh_l/dT (J/(kg K)) at t (K), clamped outside the range.
fn fl_dh_l_dt(t: f32) -> f32 {
    return fl_poly(FL.dh_l_sat, fl_x_clamped(t));
}

// Saturated-liquid enthalpy (J/kg, 0 at t_min) at t (K): (T - t_min) times the mean dh_l/dT over
// [t_min, T], continued linearly with the end-point slope outside the range.
fn fl_h_l(t: f32) -> f32 {
    let d = (t - FL.t_min_hi) - FL.t_min_lo;
    if d <= 0.0 {
        return FL.dh_l_lo * d;
    }
    if t >= FL.t_max {
        return FL.h_l_max + FL.dh_l_hi * (t - FL.t_max);
    }
    return d * fl_poly(FL.h_l_mean, fl_x_clamped(t));
}

// Temperature (K) with liquid enthalpy h (J/kg): inverse of fl_h_l by bracketed Newton on
// d = T - t_min in [0, t_max - t_min].
fn fl_t_from_h_l(h: f32) -> f32 {
    if h <= 0.0 {
        return FL.t_min_hi + (FL.t_min_lo + h / FL.dh_l_lo);
    }
    if h >= FL.h_l_max {
        return FL.t_max + (h - FL.h_l_max) / FL.dh_l_hi;
    }
    var d = clamp(h / FL.h_l_max * FL.t_span, 0.0, FL.t_span);
    var lo = 0.0;
    var hi = FL.t_span;
    for (var i = 0; i < FL_NEWTON_ITER; i++) {
        let x = d * FL.inv_t_half - 1.0;
        let f = d * fl_poly(FL.h_l_mean, x) - h;
        if f == 0.0 {
            break;
        }
        if f > 0.0 {
            hi = d;
        } else {
            lo = d;
        }
        let d_newton = d - f / fl_poly(FL.dh_l_sat, x);
        if abs(d_newton - d) <= FL_NEWTON_TOL * FL.t_half {
            d = clamp(d_newton, 0.0, FL.t_span);
            break;
        }
        d = select(0.5 * (lo + hi), d_newton, d_newton > lo && d_newton < hi);
    }
    return FL.t_min_hi + (FL.t_min_lo + d);
}

// Saturated-vapour density (kg/m^3) at t (K), clamped outside the range.
fn fl_rho_v_sat(t: f32) -> f32 {
    return exp(fl_poly(FL.ln_rho_v, fl_x_clamped(t)));
}

// (B_k, B_k', B_k'') of density power k at y = tau - 1, written out (no loop).
fn fl_virial_b(o: i32, y: f32) -> vec3<f32> {
    let c0 = FL.virial[o];
    let c1 = FL.virial[o + 1];
    let c2 = FL.virial[o + 2];
    let c3 = FL.virial[o + 3];
    let c4 = FL.virial[o + 4];
    let c5 = FL.virial[o + 5];
    let b = c0 + y * (c1 + y * (c2 + y * (c3 + y * (c4 + y * c5))));
    let b1 = c1 + y * (2.0 * c2 + y * (3.0 * c3 + y * (4.0 * c4 + y * 5.0 * c5)));
    let b2 = 2.0 * c2 + y * (6.0 * c3 + y * (12.0 * c4 + y * 20.0 * c5));
    return vec3<f32>(b, b1, b2);
}

// The real-gas vapour at (t, rho) with the derivatives an ullage node needs
// (FluidProps::vapor_state): Z, u_res (J/kg), its T and rho slopes, P and its T and rho slopes.
struct VaporState {
    z: f32,
    u_res: f32,
    du_res_dt: f32,
    du_res_drho: f32,
    p: f32,
    dp_dt: f32,
    dp_drho: f32,
}

fn fl_vapor_state(t_in: f32, rho: f32) -> VaporState {
    let t = max(t_in, 1.0);
    let tau = FL.t_crit / t;
    let y = tau - 1.0;
    let r = rho * FL.inv_rho_crit;
    let b4 = fl_virial_b(18, y);
    let b3 = fl_virial_b(12, y);
    let b2 = fl_virial_b(6, y);
    let b1 = fl_virial_b(0, y);
    // Horner in r: sums of r^k B_k, k r^k B_k, r^k B_k'/k, r^(k-1) B_k', r^k B_k''/k.
    let z = (((b4.x * r + b3.x) * r + b2.x) * r + b1.x) * r;
    let kz = (((4.0 * b4.x * r + 3.0 * b3.x) * r + 2.0 * b2.x) * r + b1.x) * r;
    let u = (((0.25 * b4.y * r + b3.y / 3.0) * r + 0.5 * b2.y) * r + b1.y) * r;
    let s1 = ((b4.y * r + b3.y) * r + b2.y) * r + b1.y;
    let u2 = (((0.25 * b4.z * r + b3.z / 3.0) * r + 0.5 * b2.z) * r + b1.z) * r;
    let rs = fl_r_specific();
    let rtc = rs * FL.t_crit;
    var v: VaporState;
    v.z = 1.0 + z;
    v.u_res = u * rtc;
    v.du_res_dt = -(tau / t) * u2 * rtc;
    v.du_res_drho = s1 * rtc * FL.inv_rho_crit;
    v.p = rho * rs * t * v.z;
    v.dp_dt = rho * rs * (v.z - tau * s1 * r);
    v.dp_drho = rs * t * (kz + v.z);
    return v;
}

// The vapour's ideal-gas part at t (K) (FluidProps::vapor_ideal): (u0 J/kg on the fit's own
// reference, c_v0 J/(kg K)); c_v0 held outside [ideal_t_lo, ideal_t_hi]. Horner written out.
fn fl_vapor_ideal(t: f32) -> vec2<f32> {
    let tc = clamp(t, FL.ideal_t_lo, FL.ideal_t_hi);
    let s = sqrt(tc);
    let x = (s - FL.ideal_s_lo) * (2.0 * FL.ideal_inv_span) - 1.0;
    let q = FL.ideal[0] + x * (FL.ideal[1] + x * (FL.ideal[2] + x * (FL.ideal[3] + x * (FL.ideal[4] + x * (FL.ideal[5] + x * (FL.ideal[6] + x * (FL.ideal[7] + x * (FL.ideal[8] + x * (FL.ideal[9] + x * (FL.ideal[10] + x * (FL.ideal[11] + x * (FL.ideal[12] + x * (FL.ideal[13] + x * (FL.ideal[14] + x * (FL.ideal[15])))))))))))))));
    let dq = FL.ideal[1] + x * (2.0 * FL.ideal[2] + x * (3.0 * FL.ideal[3] + x * (4.0 * FL.ideal[4] + x * (5.0 * FL.ideal[5] + x * (6.0 * FL.ideal[6] + x * (7.0 * FL.ideal[7] + x * (8.0 * FL.ideal[8] + x * (9.0 * FL.ideal[9] + x * (10.0 * FL.ideal[10] + x * (11.0 * FL.ideal[11] + x * (12.0 * FL.ideal[12] + x * (13.0 * FL.ideal[13] + x * (14.0 * FL.ideal[14] + x * (15.0 * FL.ideal[15]))))))))))))));
    let cv = q + dq * s * FL.ideal_inv_span;
    let rs = fl_r_specific();
    return vec2<f32>((tc * q + cv * (t - tc)) * rs, cv * rs);
}

// Residual enthalpy h - h0 (J/kg) of the vapour at (t, p) (FluidProps::vapor_h_res_at_tp): at the
// density of two Newton steps on P = rho R T Z from the ideal gas (written out, no loop).
fn fl_vapor_h_res_at_tp(t: f32, p: f32) -> f32 {
    let rt = max(t, 1.0) * fl_r_specific();
    let rho0 = max(p, 0.0) / rt;
    let v0 = fl_vapor_state(t, rho0);
    let rho1 = max(rho0 - (v0.p - p) / max(v0.dp_drho, 0.1 * rt), 0.5 * rho0);
    let v1 = fl_vapor_state(t, rho1);
    let rho2 = max(rho1 - (v1.p - p) / max(v1.dp_drho, 0.1 * rt), 0.5 * rho1);
    let v = fl_vapor_state(t, rho2);
    return v.u_res + (v.z - 1.0) * rt;
}

// Latent heat (J/kg) at t (K), clamped outside the range.
fn fl_h_fg(t: f32) -> f32 {
    return fl_poly(FL.h_fg, fl_x_clamped(t));
}

// Saturated-liquid conductivity (W/(m K)) at t (K), clamped outside the range.
fn fl_k_l(t: f32) -> f32 {
    return fl_poly(FL.k_l, fl_x_clamped(t));
}

// Saturated-liquid viscosity (Pa s) at t (K), clamped outside the range.
fn fl_mu_l(t: f32) -> f32 {
    return exp(fl_poly(FL.ln_mu_l, fl_x_clamped(t)));
}

// Vapour conductivity (W/(m K)) at t (K): power law.
fn fl_k_v(t: f32) -> f32 {
    return fl_power_law(FL.k_vapor_ref, FL.vapor_t_ref, FL.k_vapor_exp, FL.power_t_min, FL.power_t_max, t);
}

// Vapour viscosity (Pa s) at t (K): power law.
fn fl_mu_v(t: f32) -> f32 {
    return fl_power_law(FL.mu_vapor_ref, FL.vapor_t_ref, FL.mu_vapor_exp, FL.power_t_min, FL.power_t_max, t);
}

// Helium specific gas constant R_u / M, J/(kg K).
fn he_r_specific() -> f32 {
    return HE.r_specific;
}

// Helium conductivity (W/(m K)) at t (K): power law.
fn he_k(t: f32) -> f32 {
    return fl_power_law(HE.k_ref, HE.t_ref, HE.k_exp, HE.power_t_min, HE.power_t_max, t);
}

// Helium viscosity (Pa s) at t (K): power law.
fn he_mu(t: f32) -> f32 {
    return fl_power_law(HE.mu_ref, HE.t_ref, HE.mu_exp, HE.power_t_min, HE.power_t_max, t);
}
