// Evaluation and observation in f32 (src/model/mod.rs, src/simulate/qoi.rs, the outcomes of
// src/simulate/mod.rs): evaluate, the state checks, cavitation margin, extremes and per-phase
// records, valve, bulk merge, slosh validity, outcomes.

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
    // LAYERED{
    } else if (P.fidelity == FID_LAYERED) {
        ev.force = rhs_column(s, d, ev.x, dt, &ds);
    // }LAYERED
    } else {
        ev.force = rhs_nodes(s, d, ev.x, dt, &ds);
    }
    ev.ds = ds;
    ev.evap = EVAP_RATE;
    ev.relax = EVAP_RELAX;
    return ev;
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
    // LAYERED{
    // Every layer of the column (the film and the bottom are checked above).
    if (P.fidelity == FID_LAYERED) {
        let t_lo = FL.t_min_hi - 2.0;
        let t_hi = FL.t_max + 2.0;
        if (not_finite(x.t_lmin) || !(x.t_lmin > t_lo && x.t_lmin < t_hi)) {
            return vec2<f32>(12.0, x.t_lmin);
        }
        if (not_finite(x.t_lmax) || !(x.t_lmax > t_lo && x.t_lmax < t_hi)) {
            return vec2<f32>(13.0, x.t_lmax);
        }
    }
    // }LAYERED
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
/// (simulate::qoi::Tracker::enter_phase): its start pressure, slosh angle, vapour mass, vented,
/// pressurant and TVS-vented slots.
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
    ph.press_in_hi = (*hi)[PRESS_IN];
    ph.press_in_lo = (*lo)[PRESS_IN];
    ph.vent_tvs_hi = (*hi)[VENT_TVS];
    ph.vent_tvs_lo = (*lo)[VENT_TVS];
    phase_results[slot] = ph;
    // The new phase may switch the TVS off, or let it start above its band.
    switch_tvs(r, phases[slot], (*r).p_ullage_pa);
}

/// The TVS's hysteresis (model::tvs::update) under the phase's switch `enabled`.
fn update_tvs(pressure: f32, on: bool, enabled: bool) -> bool {
    if ((P.flags & FLAG_TVS) == 0u || !enabled) {
        return false;
    }
    if (pressure >= P.tvs_upper_pa) {
        return true;
    }
    if (pressure <= P.tvs_lower_pa) {
        return false;
    }
    return on;
}

/// Update TVS_ON at ullage pressure `pressure` under phase `ph`, counting a start
/// (LaneRun::switch_tvs). Returns whether it switched.
fn switch_tvs(r: ptr<function, GpuResult>, ph: GpuPhase, pressure: f32) -> bool {
    let before = TVS_ON;
    TVS_ON = update_tvs(pressure, before, ph.tvs != 0u);
    if (TVS_ON && !before) {
        (*r).tvs_cycles += 1u;
    }
    return TVS_ON != before;
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

/// Merge a nearly empty bulk node into the layer (model::merge_empty_bulk): below its fade share,
/// or drawn by the step just taken (length `step_s`, from a bulk of `m_b_before`) at a rate that
/// empties it within `horizon_s`. True if it merged.
fn merge_empty_bulk(hi: ptr<function, St>, lo: ptr<function, St>, m_b_before: f32, step_s: f32, horizon_s: f32) -> bool {
    let m_b = (*hi)[M_B] + (*lo)[M_B];
    let m_s = (*hi)[M_S] + (*lo)[M_S];
    let taken = m_b_before - m_b;
    if (P.fidelity == FID_HOMOGENEOUS || m_b == 0.0 || !(abs(m_b) <= 3.0e38)
        || (m_b > BULK_MERGE_FRACTION * (m_b + m_s) && (step_s <= 0.0 || m_b * step_s >= horizon_s * taken))) {
        return false;
    }
    absorb(hi, lo, M_S, M_B);
    absorb(hi, lo, H_S, H_B);
    // LAYERED{
    // The column's enthalpy goes with its mass.
    for (var j = COL; j < NS; j++) {
        absorb(hi, lo, H_S, j);
    }
    // }LAYERED
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
    if (bond < SLOSH_BOND_MIN || max(abs(slosh_angle(s, ev.x.sl)), mode2_angle(s, ev.x.sl)) > SLOSH_ANGLE_MAX_RAD) {
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
/// running out (first time), and the tank running dry. Returns the share of the step at which it
/// ran dry, in [0, 1], or -1. `bad`: the end state's check_state; when it failed, `rate0` (the
/// liquid mass rate at the step's start), carried on, decides.
fn outcomes(r: ptr<function, GpuResult>, press0: f32, press1: f32, t0: f32, t1: f32, ev: Eval, bad: vec2<f32>, rate0: f32) -> f32 {
    if ((P.flags & FLAG_PRESSURIZATION) != 0u && (*r).exhausted == 0u) {
        let empty = P.press_bottle_kg * (1.0 - PRESSURANT_EMPTY_FRACTION);
        if (press1 >= empty) {
            (*r).exhausted = 1u;
            // Already empty at the step start (a 0 kg supply): exhausted there.
            let th = select(crossing(press0, press1, empty), 0.0, press0 >= empty);
            (*r).exhausted_time_s = t0 + th * (t1 - t0);
        }
    }
    let residual = (*r).m_liquid0_kg * DEPLETION_RESIDUAL_FRACTION;
    var m_l = ev.x.m_l;
    if (bad.x != 0.0) {
        m_l = (*r).m_liquid_kg + (t1 - t0) * rate0;
    }
    if (!(m_l <= residual)) {
        return -1.0;
    }
    let th = crossing((*r).m_liquid_kg, m_l, residual);
    (*r).depleted = 1u;
    (*r).depleted_time_s = t0 + th * (t1 - t0);
    return th;
}

/// An instance that ran dry at share `th` of the step from the state `hi_prev` + `lo_prev` to
/// `hi` + `lo` ends on the state interpolated there, observed like a step's end, or on the
/// step's start when the end state or the interpolated one left the model (LaneRun::outcomes).
/// Two halves around the interpolated state's evaluation, which each kernel makes at its own
/// one `evaluate` call site (NIR inlines every call): [`dry_state`], then [`dry_finish`].
///
/// The interpolated state as hi + lo words (Kahan, as a step's update; its lo word into `s_lo`).
fn dry_state(hi: ptr<function, St>, lo: ptr<function, St>, hi_prev: St, lo_prev: St, th: f32, s_lo: ptr<function, St>) -> St {
    var s_hi = hi_prev;
    *s_lo = lo_prev;
    for (var j = 0u; j < NS; j++) {
        let inc = th * (((*hi)[j] - hi_prev[j]) + ((*lo)[j] - lo_prev[j])) + (*s_lo)[j];
        let sum = (s_hi[j] + inc) * control.one;
        (*s_lo)[j] = inc - (sum - s_hi[j]);
        s_hi[j] = sum;
    }
    return s_hi;
}

/// The dry end once the interpolated state `s_hi` + `s_lo` ([`dry_state`]) has its evaluation
/// `ev` (drive `d`; share `th` of a step of `dt` seconds from mission time `t0`): the instance
/// ends there, or on the step's start (`hi_prev` + `lo_prev`, time `t0`) when that state left
/// the model. A kernel whose end state left the model ends on the step's start without this.
fn dry_finish(r: ptr<function, GpuResult>, hi: ptr<function, St>, lo: ptr<function, St>, hi_prev: St, lo_prev: St, s_hi: ptr<function, St>, s_lo: St, ev: Eval, d: Drive, t0: f32, th: f32, dt: f32) {
    if (check_state(s_hi, ev.x).x == 0.0) {
        let t = t0 + th * dt;
        observe(r, s_hi, t, ev, d);
        slosh_validity(r, s_hi, th * dt, ev, d);
        save_last(r, ev.x);
        (*r).final_time_s = t;
        *hi = *s_hi;
        *lo = s_lo;
        return;
    }
    *hi = hi_prev;
    *lo = lo_prev;
    (*r).final_time_s = t0;
}

fn save_last(r: ptr<function, GpuResult>, x: Derived) {
    (*r).m_vapor_kg = x.m_v;
    (*r).t_layer_k = x.t_s;
    (*r).t_bulk_k = x.t_b;
    (*r).p_ullage_pa = x.p_u;
    (*r).m_liquid_kg = x.m_l;
}

/// Load instance `i`'s parameters into the per-invocation globals (P, FL, HE, TANK).
fn load_instance(i: u32) {
    P = params[i];
    FL = fluid[0];
    HE = gas[0];
    TANK = P.tank;
}

/// The instance at t = 0 (both kernels): its initial state into `hi` + `lo`, evaluated with
/// step `dt` and observed once in its first phase record `base`. Returns that evaluation.
fn start_instance(r: ptr<function, GpuResult>, hi: ptr<function, St>, lo: ptr<function, St>, base: u32, dt: f32) -> Eval {
    for (var j = 0u; j < NS; j++) {
        (*hi)[j] = P.s0_hi[j];
        (*lo)[j] = P.s0_lo[j];
    }
    (*r).started = 1u;
    (*r).peak_pressure_pa = -3.4e38;
    (*r).min_pressure_pa = 3.4e38;
    // A TVS whose band the initial pressure already reaches runs from the start.
    // (One evaluation call site: NIR inlines every call.)
    TVS_ON = false;
    var d0: Drive;
    var ev0: Eval;
    var tries = 0u;
    for (; tries < 2u; tries++) {
        d0 = phase_drive(phases[base], 0.0, false);
        ev0 = evaluate(hi, d0, dt);
        if (tries == 1u || !switch_tvs(r, phases[base], ev0.x.p_u)) {
            break;
        }
    }
    // The right-hand-side evaluations the start cost: one, two when a TVS starts on.
    (*r).evaluations = tries + 1u;
    (*r).m_vapor0_kg = ev0.x.m_v;
    (*r).m_liquid0_kg = ev0.x.m_l;
    save_last(r, ev0.x);
    (*r).last_angle_rad = abs(slosh_angle(hi, ev0.x.sl));
    enter_phase(base, r, hi, lo);
    (*r).tvs_on = u32(TVS_ON);
    PHASE_SLOT = base;
    observe(r, hi, 0.0, ev0, d0);
    return ev0;
}
