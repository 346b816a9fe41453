// Tank geometry in f32, one function per `Tank` method of src/geometry.rs (same clamping:
// heights to [0, H], volumes to [0, V]). The kernel assigns TANK once per invocation; every
// per-tank number comes from it (see src/gpu/props.rs). Depths below the top are formed as
// (H_hi - z) + H_lo and volumes below the top as (V_hi - v) + V_lo, so they stay accurate
// where the Rust f64 subtraction would cancel in f32.

var<private> TANK: GpuTank;

// 2 pi and the f32 machine epsilon (mathematical constants of the cap solver).
const GEO_TAU: f32 = 6.2831855;
const GEO_F32_EPS: f32 = 1.1920929e-7;
// Iteration cap of the cap-fraction Newton solver (a few suffice from the Viete root).
const GEO_NEWTON_ITER: i32 = 16;

fn tank_radius() -> f32 {
    return TANK.radius;
}

fn tank_height() -> f32 {
    return TANK.height_hi;
}

fn tank_volume() -> f32 {
    return TANK.volume_hi;
}

fn tank_wall_area() -> f32 {
    return TANK.wall_area;
}

// Height clamped to >= 0 (NaN -> 0); the upper clamp is folded into tank_top_depth.
fn tank_clamp_low(z: f32) -> f32 {
    return select(0.0, z, z > 0.0);
}

// Depth H - z (m) below the top, >= 0, without f32 cancellation.
fn tank_top_depth(z: f32) -> f32 {
    return max((TANK.height_hi - z) + TANK.height_lo, 0.0);
}

// Distance (m) from the nearest pole of a domed tank, capped at a.
fn tank_dome_depth(z: f32) -> f32 {
    if z <= TANK.a {
        return z;
    }
    if z < TANK.z_top_cyl {
        return TANK.a;
    }
    return tank_top_depth(z);
}

// Dome cap volume (m3) of depth w (m): V_dome t^2 (3 - t) / 2, t = w / a.
fn tank_cap_volume(w: f32) -> f32 {
    let t = clamp(w / TANK.a, 0.0, 1.0);
    return 0.5 * TANK.dome_volume * t * t * (3.0 - t);
}

// sqrt(c^2 + e s^2) (m) at depth w below a pole, from positive terms only.
fn tank_zone_integrand(w: f32) -> f32 {
    if TANK.e >= 0.0 {
        let s = TANK.a - w;
        return sqrt(TANK.c * TANK.c + TANK.e * s * s);
    }
    return sqrt(TANK.a * TANK.a - TANK.e * w * (2.0 * TANK.a - w));
}

// atanh(sqrt(z)) / sqrt(z) = sum_n z^n / (2n + 1), and atan(sqrt(-z)) / sqrt(-z) for z < 0;
// 11 terms, truncation < 2e-10 for |z| <= tan^2(pi/8) = 0.172, where it is used.
fn tank_atanh_series(z: f32) -> f32 {
    return 1.0 + z * (1.0 / 3.0 + z * (1.0 / 5.0 + z * (1.0 / 7.0 + z * (1.0 / 9.0 + z * (1.0 / 11.0
        + z * (1.0 / 13.0 + z * (1.0 / 15.0 + z * (1.0 / 17.0 + z * (1.0 / 19.0 + z / 21.0)))))))));
}

// asinh(x) / x for x >= 0: below 1 as 2 atanh(y) / x with y = tanh(asinh(x) / 2) <= 0.414,
// which avoids log near 1 (GPU log is only accurate in absolute terms there); above 1 by log.
fn tank_asinh_over_x(x: f32) -> f32 {
    let s = 1.0 + sqrt(1.0 + x * x);
    if x < 1.0 {
        let y = x / s;
        return 2.0 / s * tank_atanh_series(y * y);
    }
    return log(x + sqrt(1.0 + x * x)) / x;
}

// asin(d) / d for the angle theta = asin(d) in [0, pi/2) given cos_d = cos(theta) (from positive
// terms): theta = 4 atan(tan(theta / 4)), tan(theta / 4) <= 0.414, so no atan2/asin is needed.
fn tank_asin_over_x(d: f32, cos_d: f32) -> f32 {
    let t = d / (1.0 + cos_d);
    let s = 1.0 + sqrt(1.0 + t * t);
    let t4 = t / s;
    return 4.0 * tank_atanh_series(-t4 * t4) / ((1.0 + cos_d) * s);
}

// Wall area (m2) of a dome zone of depth w (m) from the pole, in the cancellation-free
// difference form of geometry.rs.
fn tank_zone_area(w_in: f32) -> f32 {
    let a = TANK.a;
    let w = clamp(w_in, 0.0, a);
    if w <= 0.0 {
        return 0.0;
    }
    let s1 = a - w;
    let s2 = a;
    let big1 = tank_zone_integrand(w);
    let big2 = a;
    let c2 = TANK.c * TANK.c;
    let ds2 = w * (2.0 * a - w);
    let term1 = (c2 + TANK.e * (s1 * s1 + s2 * s2)) / (s2 * big2 + s1 * big1);
    let cross = s2 * big1 + s1 * big2;
    let d = TANK.sqrt_abs_e * ds2 / cross;
    var g: f32;
    if TANK.e > 0.0 {
        g = tank_asinh_over_x(d);
    } else {
        // cos(asin x2 - asin x1) = (S1 S2 + |e| s1 s2) / c^2, a sum of positive terms.
        g = tank_asin_over_x(d, (big1 * big2 + abs(TANK.e) * s1 * s2) / c2);
    }
    let term2 = c2 * g / cross;
    let integral = 0.5 * ds2 * (term1 + term2);
    return 2.0 * TANK.pi_over_k2 * integral;
}

// Solves t^2 (3 - t) = q for t in [0, 1]: Newton from the Viete root, bisection-safeguarded
// in [sqrt(q/3), sqrt(q/2)], at most GEO_NEWTON_ITER steps.
fn tank_solve_cap_fraction(q: f32) -> f32 {
    if !(q > 0.0) {
        return 0.0;
    }
    if q >= 2.0 {
        return 1.0;
    }
    var lo = sqrt(q / 3.0);
    var hi = min(sqrt(q / 2.0), 1.0);
    let theta = (GEO_TAU - acos(clamp(0.5 * q - 1.0, -1.0, 1.0))) / 3.0;
    let guess = 1.0 - 2.0 * cos(theta);
    var t = select(0.5 * (lo + hi), guess, guess > lo && guess < hi);
    for (var i = 0; i < GEO_NEWTON_ITER; i++) {
        let f = t * t * (3.0 - t) - q;
        if f > 0.0 {
            hi = t;
        } else if f < 0.0 {
            lo = t;
        } else {
            return t;
        }
        let fp = 3.0 * t * (2.0 - t);
        let newton = t - f / fp;
        // Checked before the bracket test: in f32 a converged step can land on the bracket end.
        if abs(newton - t) <= 2.0 * GEO_F32_EPS * t {
            return clamp(newton, lo, hi);
        }
        t = select(0.5 * (lo + hi), newton, newton > lo && newton < hi);
        if hi - lo <= GEO_F32_EPS * hi {
            return t;
        }
    }
    return t;
}

// Liquid volume (m3) below the free surface at height z (m).
fn tank_liquid_volume(z_in: f32) -> f32 {
    let z = tank_clamp_low(z_in);
    if TANK.domed == 0u {
        return TANK.disc_area * min(z, TANK.height_hi);
    }
    if z <= TANK.a {
        return tank_cap_volume(z);
    }
    if z < TANK.z_top_cyl {
        return TANK.dome_volume + TANK.disc_area * (z - TANK.a);
    }
    return (TANK.volume_hi - tank_cap_volume(tank_top_depth(z))) + TANK.volume_lo;
}

// Liquid height (m) holding the volume v (m3), clamped to [0, V].
fn tank_liquid_height(v_in: f32) -> f32 {
    let v = tank_clamp_low(v_in);
    // V - v, accurate near the top.
    let dv = (TANK.volume_hi - v) + TANK.volume_lo;
    if dv <= 0.0 {
        return TANK.height_hi;
    }
    if TANK.domed == 0u {
        return min(v / TANK.disc_area, TANK.height_hi);
    }
    if v <= TANK.dome_volume {
        return TANK.a * tank_solve_cap_fraction(2.0 * v / TANK.dome_volume);
    }
    if dv > TANK.dome_volume {
        let z = TANK.a + (v - TANK.dome_volume) / TANK.disc_area;
        return min(max(z, TANK.a), TANK.z_top_cyl);
    }
    let w = TANK.a * tank_solve_cap_fraction(2.0 * dv / TANK.dome_volume);
    return max((TANK.height_hi - w) + TANK.height_lo, 0.0);
}

// Radius (m) of the free surface at height z (m); 0 at the poles of a domed tank.
fn tank_surface_radius(z: f32) -> f32 {
    if TANK.domed == 0u {
        return TANK.radius;
    }
    let w = tank_dome_depth(tank_clamp_low(z));
    if w >= TANK.a {
        return TANK.radius;
    }
    return sqrt(w * (2.0 * TANK.a - w)) / TANK.k;
}

// Area (m2) of the flat liquid-vapour interface at height z (m).
fn tank_interface_area(z: f32) -> f32 {
    if TANK.domed == 0u {
        return TANK.disc_area;
    }
    let w = tank_dome_depth(tank_clamp_low(z));
    if w >= TANK.a {
        return TANK.disc_area;
    }
    return TANK.pi_over_k2 * w * (2.0 * TANK.a - w);
}

// Wall area (m2) below height z (m), bottom included; a cylinder's top disc counts only when
// full.
fn tank_wetted_area(z_in: f32) -> f32 {
    let z = tank_clamp_low(z_in);
    if TANK.domed == 0u {
        if tank_top_depth(z) <= 0.0 {
            return TANK.wall_area;
        }
        return TANK.disc_area + TANK.two_pi_r * z;
    }
    if z <= TANK.a {
        return tank_zone_area(z);
    }
    if z < TANK.z_top_cyl {
        return TANK.dome_area + TANK.two_pi_r * (z - TANK.a);
    }
    return max(TANK.wall_area - tank_zone_area(tank_top_depth(z)), 0.0);
}

// Wall area (m2) above height z (m), wall_area - wetted_area, formed from the depth below the
// top so that it keeps full f32 accuracy as it goes to 0.
fn tank_dry_area(z_in: f32) -> f32 {
    let z = tank_clamp_low(z_in);
    let w = tank_top_depth(z);
    if TANK.domed == 0u {
        if w <= 0.0 {
            return 0.0;
        }
        return TANK.disc_area + TANK.two_pi_r * w;
    }
    if z <= TANK.a {
        return max(TANK.wall_area - tank_zone_area(z), 0.0);
    }
    if z < TANK.z_top_cyl {
        return TANK.dome_area + TANK.two_pi_r * (TANK.z_top_cyl - z);
    }
    return min(tank_zone_area(w), TANK.wall_area);
}

// d(wetted area)/dz (m): 2 pi r sqrt(1 + r'^2); 2 pi R / k at a pole, 2 pi R on a cylinder.
fn tank_wetted_area_slope(z: f32) -> f32 {
    if TANK.domed == 0u {
        return TANK.two_pi_r;
    }
    let w = tank_dome_depth(tank_clamp_low(z));
    if w >= TANK.a {
        return TANK.two_pi_r;
    }
    return 2.0 * TANK.pi_over_k2 * tank_zone_integrand(w);
}

// Horizontal cross-section (m2) at height z (m), equal to the interface area.
fn tank_cross_section_area(z: f32) -> f32 {
    return tank_interface_area(z);
}
