// Heat leak through the tank's insulation in f32: the WGSL mirror of src/model/insulation.rs
// (foam and multilayer blanket in series, the outer surface's steady balance with the ground or
// space surroundings). Pure functions of their arguments, so tests/gpu_insulation.rs evaluates them
// against the Rust ones; closures.wgsl (wall_heat) feeds them the instance's parameters. The
// constants (iteration counts, exponents, floor temperature) are generated from the Rust ones
// (src/gpu/params.rs). Change one, change both.

struct MliCoeffs {
    // D C_s N̄^2.63 / (N_s + 1), D C_r ε / N_s, D C_g P / N_s
    solid: f32,
    radiation: f32,
    gas: f32,
}

struct Surroundings {
    h: f32,
    t_air: f32,
    t_rad4: f32,
    absorbed: f32,
    eps_sigma: f32,
}

struct InsLeak {
    q: f32,
    t_outer: f32,
    t_interface: f32,
}

/// Modified Lockheed flux from the warm face at t_hot to the cold face at t_cold (W/m²) and its
/// partial derivatives by t_hot and t_cold (insulation::mli_flux).
fn mli_flux(k: MliCoeffs, t_hot: f32, t_cold: f32) -> vec3<f32> {
    let th = max(t_hot, MIN_INSULATION_TEMPERATURE_K);
    let tc = max(t_cold, MIN_INSULATION_TEMPERATURE_K);
    let ln_h = log(th);
    let ln_c = log(tc);
    let tm = (th + tc) * 0.5;
    let f = (800.0 - tm) * 7.0e-6 + log(tm) * 0.0228 + 0.017;
    let df = 0.0228 / tm - 7.0e-6;
    let rh = exp(ln_h * MLI_RADIATION_EXPONENT);
    let rc = exp(ln_c * MLI_RADIATION_EXPONENT);
    let gh = exp(ln_h * MLI_GAS_EXPONENT);
    let gc = exp(ln_c * MLI_GAS_EXPONENT);
    let dt = th - tc;
    let q = k.solid * f * dt + k.radiation * (rh - rc) + k.gas * (gh - gc);
    let half_slope = df * dt * 0.5;
    let dq_dh = k.solid * (f + half_slope) + k.radiation * MLI_RADIATION_EXPONENT * rh / th
        + k.gas * MLI_GAS_EXPONENT * gh / th;
    let dq_dc = k.solid * (half_slope - f) - k.radiation * MLI_RADIATION_EXPONENT * rc / tc
        - k.gas * MLI_GAS_EXPONENT * gc / tc;
    return vec3<f32>(q, select(dq_dh, 0.0, t_hot < MIN_INSULATION_TEMPERATURE_K),
        select(dq_dc, 0.0, t_cold < MIN_INSULATION_TEMPERATURE_K));
}

/// What the surroundings deliver to the outer surface at t (W/m²) and its slope.
fn surroundings_flux(e: Surroundings, t: f32) -> vec2<f32> {
    let t2 = t * t;
    let g = e.h * (e.t_air - t) + e.eps_sigma * (e.t_rad4 - t2 * t2) + e.absorbed;
    let slope = -(e.h + e.eps_sigma * t2 * t * 4.0);
    return vec2<f32>(g, slope);
}

/// One safeguarded Newton step on a monotone residual r at x (insulation::safeguarded); the
/// bracket is narrowed in place.
fn ins_safeguarded(x: f32, r: f32, slope: f32, increasing: bool, lo: ptr<function, f32>, hi: ptr<function, f32>) -> f32 {
    var above = r < 0.0;
    if (increasing) {
        above = r > 0.0;
    }
    *hi = select(*hi, x, above);
    *lo = select(x, *lo, above);
    let next = x - r / slope;
    let inside = next >= *lo && next <= *hi;
    return select((*lo + *hi) * 0.5, next, inside);
}

/// Outer temperature at which the surroundings deliver q, and the slope there.
fn ins_outer_temperature(e: Surroundings, q: f32, t_lo: f32, t_hi: f32) -> vec2<f32> {
    let excess = e.absorbed - q;
    let a = e.t_air + excess / max(e.h, 1.0e-30);
    let b = sqrt(sqrt(max(e.t_rad4 + excess / e.eps_sigma, 0.0)));
    let t_rad = sqrt(sqrt(e.t_rad4));
    var t = min(max(min(max(a, t_rad), max(e.t_air, b)), t_lo), t_hi);
    for (var i = 0u; i < INSULATION_INNER_ITERATIONS; i++) {
        let g = surroundings_flux(e, t);
        t = min(max(t - (g.x - q) / min(g.y, -1.0e-12), t_lo), t_hi);
    }
    return vec2<f32>(t, surroundings_flux(e, t).y);
}

/// Steady flux into a wall at t_wall through foam of resistance r_foam (0: none) and, when
/// has_mli, the blanket k, from the surroundings e (insulation::leak).
fn insulation_leak(has_mli: bool, r_foam: f32, k: MliCoeffs, e: Surroundings, t_wall: f32) -> InsLeak {
    let t_eq = sqrt(sqrt(e.t_rad4 + e.absorbed / e.eps_sigma));
    let t_lo = min(min(t_wall, e.t_air), t_eq);
    let t_hi = max(max(t_wall, e.t_air), t_eq);
    var out: InsLeak;
    if (!has_mli) {
        let conductance = 1.0 / r_foam;
        var lo = t_lo;
        var hi = t_hi;
        var t = t_hi;
        for (var i = 0u; i < INSULATION_FOAM_ITERATIONS; i++) {
            let g = surroundings_flux(e, t);
            let r = conductance * (t - t_wall) - g.x;
            t = ins_safeguarded(t, r, conductance - g.y, true, &lo, &hi);
        }
        out.q = conductance * (t - t_wall);
        out.t_outer = t;
        out.t_interface = t;
        return out;
    }
    var lo = surroundings_flux(e, t_hi).x;
    var hi = surroundings_flux(e, t_lo).x;
    let bare = mli_flux(k, t_hi, t_wall).x;
    let foam_cap = (t_hi - t_wall) / max(r_foam, 1.0e-30);
    var q = min(max(min(bare, foam_cap), lo), hi);
    for (var i = 0u; i < INSULATION_OUTER_ITERATIONS; i++) {
        let o = ins_outer_temperature(e, q, t_lo, t_hi);
        let m = mli_flux(k, o.x, t_wall + r_foam * q);
        let dr = m.y / min(o.y, -1.0e-12) + m.z * r_foam - 1.0;
        q = ins_safeguarded(q, m.x - q, dr, false, &lo, &hi);
    }
    out.q = q;
    out.t_outer = ins_outer_temperature(e, q, t_lo, t_hi).x;
    out.t_interface = t_wall + r_foam * q;
    return out;
}
