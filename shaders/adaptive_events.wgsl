// Along an accepted Dormand–Prince step (`shaders/adaptive.wgsl`, the mirror of
// src/simulate/adaptive.rs): the quantities whose extremes are observed between step ends and
// the parabola through them, the relief valve's and the TVS's switching functions, their root
// on the dense output, and the first step after a switch or a phase start. Change one, change
// both; tests/gpu_parity.rs checks.

/// The quantities whose extremes are observed between step ends (adaptive::observe_probe):
/// pressure, −pressure, −cavitation margin, |slosh angle|, |slosh force|. The margin counts only
/// while the engine draws: [`dp_drawing`] zeroes it otherwise.
fn dp_extremes(s: ptr<function, St>, ev: Eval) -> array<f32, 5> {
    let margin = -cavitation_margin(s, ev.x).x;
    return array<f32, 5>(ev.x.p_u, -ev.x.p_u, margin, abs(slosh_angle(s, ev.x.sl)), abs(ev.force));
}

/// `q` with the margin zeroed unless the engine draws.
fn dp_drawing(q: array<f32, 5>, burning: bool) -> array<f32, 5> {
    var out = q;
    if (!burning) {
        out[2] = 0.0;
    }
    return out;
}

/// Abscissa of the vertex of the parabola through three points (adaptive::parabola_vertex).
fn dp_vertex(a: vec2<f32>, b: vec2<f32>, c: vec2<f32>) -> f32 {
    let p = b.x - a.x;
    let q = b.x - c.x;
    let fa = b.y - c.y;
    let fc = b.y - a.y;
    let den = p * fa - q * fc;
    if (den == 0.0) {
        return b.x;
    }
    return b.x - 0.5 * (p * p * fa - q * q * fc) / den;
}

/// The relief valve's switching function (P_u − P_crack while closed, P_reseat − P_u while open).
fn dp_switch(p_u: f32, open: bool) -> f32 {
    return select(p_u - P.relief_crack_pa, P.relief_reseat_pa - p_u, open);
}

/// The TVS's switching function (model::tvs::switching: P_u − P_upper while off, P_lower − P_u
/// while on).
fn tvs_switch(p_u: f32, on: bool) -> f32 {
    return select(p_u - P.tvs_upper_pa, P.tvs_lower_pa - p_u, on);
}

/// Switching function `kind` (0: the relief valve, open = `open`; 1: the TVS, on = TVS_ON).
fn any_switch(kind: u32, p_u: f32, open: bool) -> f32 {
    if (kind == 1u) {
        return tvs_switch(p_u, TVS_ON);
    }
    return dp_switch(p_u, open);
}

/// The step fraction in [lo.x, hi.x] where switching function `kind` crosses zero, g(lo) < 0 ≤
/// g(hi): Illinois regula falsi on the dense output (adaptive::locate), to f32's resolution,
/// then the root's check: it is a switch only where |g| ≤ 1e-3 `band_pa` there (`band_pa` the
/// crack or the TVS's upper pressure). A root at or after `before` is discarded unchecked (an
/// earlier switch cuts the step). Returns the root, or 2.0 for none. One
/// `derive_state` call site for the iterations and the check: NIR inlines every call.
fn dp_locate(hi_s: ptr<function, St>, ph: GpuPhase, t0: f32, h: f32, lo_in: vec2<f32>, hi_in: vec2<f32>, open: bool, kind: u32, before: f32, band_pa: f32, r: ptr<function, GpuResult>) -> f32 {
    var lo = lo_in;
    var hi = hi_in;
    var side = 0;
    // Forty rounds at most, then the check (round 40 at the latest).
    for (var it = 0u; it <= 40u; it++) {
        let checking = it == 40u || hi.x - lo.x <= 1.0e-6;
        var th = hi.x;
        if (checking) {
            if (!(th < before)) {
                return 2.0;
            }
        } else {
            th = (lo.x * hi.y - hi.x * lo.y) / (hi.y - lo.y);
            if (!(th > lo.x && th < hi.x)) {
                th = 0.5 * (lo.x + hi.x);
            }
        }
        var y = dp_dense(hi_s, th);
        let x = derive_state(&y, phase_drive(ph, t0 + th * h, open));
        (*r).evaluations += 1u;
        let v = any_switch(kind, x.p_u, open);
        if (checking) {
            return select(2.0, th, abs(v) <= 1.0e-3 * band_pa);
        }
        if (v >= 0.0) {
            hi = vec2<f32>(th, v);
            if (side == 1) {
                lo.y *= 0.5;
            }
            side = 1;
        } else {
            lo = vec2<f32>(th, v);
            if (side == -1) {
                hi.y *= 0.5;
            }
            side = -1;
        }
    }
    return 2.0;
}

/// The first step after a discontinuity: the interface's relaxation time (adaptive::restart_step).
fn dp_restart(ev: Eval) -> f32 {
    return select(3.4e38, 1.0 / ev.relax, ev.relax > 0.0);
}
