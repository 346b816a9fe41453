// The first two slosh modes of TANK: the f32 mirror of model::slosh::tank_modes, mode_shape
// and domed_modes (src/model/slosh.rs); change both. Cylinders by the SP-106 closed form,
// domed tanks (capsule, sphere) from the slosh tables at the start of the kernel's `tables`
// storage buffer (gpu::props::slosh_table_f32, placed by gpu::params::Tables; the kernel
// declares the binding). Prepended by the host: the SLOSH_* constants
// (src/gpu/props.rs::slosh_table_wgsl), GpuTank and TANK.

struct SloshNodes {
    i: vec4<u32>,
    w: vec4<f32>,
}

// Catmull-Rom nodes and weights at grid coordinate x (clamped to [0, n - 1]); the end
// intervals use a ghost node extended linearly from the last two.
fn slosh_catmull_rom(n: u32, x_in: f32) -> SloshNodes {
    let x = clamp(select(0.0, x_in, x_in == x_in), 0.0, f32(n - 1u));
    let i = min(u32(floor(x)), n - 2u);
    let t = x - f32(i);
    let t2 = t * t;
    let t3 = t2 * t;
    var w = vec4<f32>(0.5 * (-t3 + 2.0 * t2 - t), 0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t), 0.5 * (t3 - t2));
    var idx = vec4<u32>(max(i, 1u) - 1u, i, i + 1u, min(i + 2u, n - 1u));
    if i == 0u {
        w = vec4<f32>(0.0, w.y + 2.0 * w.x, w.z - w.x, w.w);
    }
    if i + 2u > n - 1u {
        w = vec4<f32>(w.x, w.y - w.w, w.z + 2.0 * w.w, 0.0);
    }
    var out: SloshNodes;
    out.i = idx;
    out.w = w;
    return out;
}

// One table column (nodes of 4 values from `base`) at grid coordinate x, Catmull-Rom.
fn slosh_column(base: u32, n: u32, x: f32) -> vec4<f32> {
    let c = slosh_catmull_rom(n, x);
    var out = vec4<f32>(0.0);
    for (var j = 0u; j < 4u; j++) {
        let o = base + 4u * c.i[j];
        out += c.w[j] * vec4<f32>(tables[o], tables[o + 1u], tables[o + 2u], tables[o + 3u]);
    }
    return out;
}

// (omega^2 R/a, m_n/m_l) of a flat-bottom cylinder's mode with root xi at depth ratio h/R.
fn slosh_cylinder_mode(xi: f32, h_over_r: f32) -> vec2<f32> {
    let hr = max(h_over_r, SLOSH_MIN_DEPTH_RATIO);
    let th = tanh(xi * hr);
    return vec2<f32>(xi * th, 2.0 * th / (xi * (xi * xi - 1.0) * hr));
}

// (omega_1^2 R/a, m_1/m_l, omega_2^2 R/a, m_2/m_l) of TANK with the free surface at z (m) above
// the bottom over v (m3) of liquid; R the tank radius.
fn tank_slosh_modes(z: f32, v: f32) -> vec4<f32> {
    if TANK.domed == 1u {
        return slosh_domed_modes(z, v);
    }
    let hr = v / (TANK.disc_area * TANK.radius);
    return vec4<f32>(slosh_cylinder_mode(SLOSH_XI_0, hr), slosh_cylinder_mode(SLOSH_XI_1, hr));
}

// tank_slosh_modes of a domed TANK, from the tables.
fn slosh_domed_modes(z: f32, v: f32) -> vec4<f32> {
    let r = TANK.radius;
    let k = TANK.k;
    let l = TANK.length / r;
    let zr = max(z / r, 0.0);
    let vr = max(v / (r * r * r), 1.0e-30);
    let kx = clamp((log2(k) - SLOSH_LOG2K_0) / SLOSH_LOG2K_STEP, 0.0, f32(SLOSH_NK - 1u));
    let ki = min(u32(floor(kx)), SLOSH_NK - 2u);
    let kt = kx - f32(ki);
    if zr <= k {
        let x = sqrt(zr / k) * f32(SLOSH_N_SIGMA - 1u);
        let n = SLOSH_N_SIGMA;
        return (1.0 - kt) * slosh_column(4u * ki * n, n, x) + kt * slosh_column(4u * (ki + 1u) * n, n, x);
    }
    if zr < k + l {
        let x = sqrt((zr - k) / SLOSH_BARREL_H_MAX) * f32(SLOSH_N_BARREL - 1u);
        let n = SLOSH_N_BARREL;
        let q = (1.0 - kt) * slosh_column(SLOSH_BARREL_AT + 4u * ki * n, n, x)
            + kt * slosh_column(SLOSH_BARREL_AT + 4u * (ki + 1u) * n, n, x);
        return q * vec4<f32>(1.0, 1.0 / vr, 1.0, 1.0 / vr);
    }
    let u = min((zr - k - l) / k, 1.0);
    let rs = max(sqrt(max(1.0 - u * u, 0.0)), SLOSH_RS_MIN);
    let x = u / SLOSH_TOP_U_MAX * f32(SLOSH_N_TOP - 1u);
    let bx = clamp(exp(-SLOSH_BETA_RATE * l) * f32(SLOSH_N_BETA - 1u), 0.0, f32(SLOSH_N_BETA - 1u));
    let bi = min(u32(floor(bx)), SLOSH_N_BETA - 2u);
    let bt = bx - f32(bi);
    let n = SLOSH_N_TOP;
    var q = vec4<f32>(0.0);
    for (var a = 0u; a < 2u; a++) {
        let wk = select(1.0 - kt, kt, a == 1u);
        for (var b = 0u; b < 2u; b++) {
            let wb = select(1.0 - bt, bt, b == 1u);
            let base = SLOSH_TOP_AT + 4u * n * ((bi + b) + SLOSH_N_BETA * (ki + a));
            q += wk * wb * slosh_column(base, n, x);
        }
    }
    let m = rs * rs * rs / vr;
    return q * vec4<f32>(1.0 / rs, m, 1.0 / rs, m);
}
