// The physics of one tank instance in f32, one instance per invocation: the WGSL mirror of
// src/model/. This file: the bindings and per-invocation globals, the trajectory (flight.rs) and
// the slosh analog's damping (slosh.rs; its modes are shaders/slosh_modes.wgsl in the property
// library). Then derive.wgsl (derive.rs, homogeneous.rs), closures.wgsl
// (thermal.rs, boundary.rs; insulation.wgsl before it: insulation.rs), rhs.wgsl (nodes.rs), column.wgsl
// (model/column/, the `layered` level's kernel only), observe.wgsl (model/mod.rs and the
// observation in src/simulate/), and the stepping loop (rk4.wgsl or adaptive.wgsl). Change one,
// change both; tests/gpu_parity.rs checks.
//
// Prepended by the host: the generated constants, the state type St and struct declarations (src/gpu/params.rs,
// src/gpu/props.rs) and shaders/fluids.wgsl, shaders/geometry.wgsl, shaders/slosh_modes.wgsl (FL, HE,
// TANK, fl_*, tank_*, tank_slosh_modes). `tables` starts with the slosh tables (gpu::params::Tables).
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
    space: bool,
    mixing: bool,
    tvs_on: bool,
}

/// The thermodynamic vent system runs (model::tvs): the invocation's switch state, loaded from
/// and saved to the result record by the kernels, read by every drive.
var<private> TVS_ON: bool;

/// Nothing reads this evaluation's slosh modes but the rates, and the phase has no lateral
/// excitation (derive::Drive::slosh_modes_unread): set by the RK4 kernel for its stages and
/// cleared after them; false (the modes evaluated) everywhere else, the adaptive kernel's step
/// bound among them.
var<private> SLOSH_UNREAD: bool;

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
    d.space = ph.space != 0u;
    d.mixing = ph.mixer != 0u;
    d.tvs_on = TVS_ON && ph.tvs != 0u;
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
