// Error-controlled integration on the device (`campaign.integrator = "dopri5"`): the WGSL mirror
// of src/model/dopri.rs (the Dormand–Prince 5(4) pair, its error norm and dense output) and of
// src/simulate/adaptive.rs (a step per invocation, bounded by the phase, its excitation and the
// slosh period, landing on phase ends and excitation corners; relief-valve and TVS switches
// located on the dense output and the step cut there; extremes between step ends from a probe
// and a parabola). The extremes, the switching functions, their root finder and the restart
// step are in `shaders/adaptive_events.wgsl`. Change one, change both; tests/gpu_parity.rs
// checks.
//
// Uses observe.wgsl's evaluate, observe, outcomes, check_state, merge_empty_bulk, enter_phase,
// slosh_validity, save_last, start_instance, dry_state and dry_finish. The state is carried in
// hi + lo words as under RK4: an accepted step's increment h Σ b_j k_j is added with Kahan
// compensation.

// Dormand & Prince (1980), as in Hairer, Nørsett & Wanner, Solving ODEs I (DOPRI5).
var<private> DP_C: array<f32, 7> = array<f32, 7>(0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0);
var<private> DP_A: array<array<f32, 6>, 6> = array<array<f32, 6>, 6>(
    array<f32, 6>(0.2, 0.0, 0.0, 0.0, 0.0, 0.0),
    array<f32, 6>(3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0),
    array<f32, 6>(44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0),
    array<f32, 6>(19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0, 0.0, 0.0),
    array<f32, 6>(9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0, 0.0),
    array<f32, 6>(35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0),
);
var<private> DP_E: array<f32, 7> = array<f32, 7>(
    71.0 / 57600.0, 0.0, -71.0 / 16695.0, 71.0 / 1920.0, -17253.0 / 339200.0, 22.0 / 525.0, -1.0 / 40.0,
);
var<private> DP_D: array<f32, 7> = array<f32, 7>(
    -12715105075.0 / 11282082432.0, 0.0, 87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0, 701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0, 69997945.0 / 29380423.0,
);

// Where an attempted step ends (adaptive::Landing).
const LAND_FREE: u32 = 0u;
const LAND_CORNER: u32 = 1u;
const LAND_PHASE_END: u32 = 2u;

// The stages of the attempt and the dense output of the accepted step (increments from the
// step's start: r1 = y1 − y0, r2 = h k1 − r1, r3 = r1 − h k7 − r2, r4 = h Σ d_j k_j).
var<private> K: array<St, 7>;
var<private> R1: St;
var<private> R2: St;
var<private> R3: St;
var<private> R4: St;

/// The step-length factor after error norm `err` (dopri::step_factor).
fn dp_factor(err: f32, rejected: bool) -> f32 {
    if (!(err < 3.4e38)) {
        return 0.2;
    }
    var f = 5.0;
    if (err > 0.0) {
        f = 0.9 * pow(err, -1.0 / DOPRI_ERROR_ORDER);
    }
    return clamp(f, 0.2, select(5.0, 1.0, rejected));
}

/// The longest step the instance may take now (LaneRun::max_step): the phase's bound, a
/// sixteenth of the excitation period (a gust's only while it blows) and of the slosh period
/// while the phase excites the liquid or the slosh state is not at rest.
fn dp_max_step(ph: GpuPhase, t_phase: f32, hi: ptr<function, St>, omega: f32) -> f32 {
    var h = ph.max_step_s;
    if (ph.exc_period_s > 0.0 && t_phase >= ph.period_from_s && t_phase < ph.period_to_s) {
        h = min(h, ph.exc_period_s / ADAPTIVE_STEPS_PER_PERIOD);
    }
    let moving = (*hi)[Q1] != 0.0 || (*hi)[Q1D] != 0.0 || (*hi)[Q2] != 0.0 || (*hi)[Q2D] != 0.0;
    if ((ph.excites != 0u || moving) && omega > 0.0) {
        h = min(h, 6.283185307 / omega / ADAPTIVE_STEPS_PER_PERIOD);
    }
    return h;
}

/// The highest modelled slosh frequency of a derived state, rad/s.
fn dp_omega(x: Derived) -> f32 {
    if (two_mode_slosh()) {
        return max(x.sl.omega.x, x.sl.omega.y);
    }
    return x.sl.omega.x;
}

/// The state at fraction `theta` of the accepted step from `hi` (dense output, f32 hi word).
fn dp_dense(hi: ptr<function, St>, theta: f32) -> St {
    let u = 1.0 - theta;
    var y: St;
    for (var i = 0u; i < NS; i++) {
        y[i] = (*hi)[i] + theta * (R1[i] + u * (R2[i] + theta * (R3[i] + u * R4[i])));
    }
    return y;
}

/// Slot i of the dense output at theta (adaptive.rs: Dense::slot_at).
fn dp_dense_slot(hi: ptr<function, St>, i: u32, theta: f32) -> f32 {
    let u = 1.0 - theta;
    return (*hi)[i] + theta * (R1[i] + u * (R2[i] + theta * (R3[i] + u * R4[i])));
}

// One dispatch advances every unfinished instance by up to control.step_budget attempted steps.
@compute @workgroup_size(64)
fn main_dopri5(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= arrayLength(&results)) {
        return;
    }
    var r = results[i];
    if (r.done != 0u) {
        return;
    }
    load_instance(i);
    let base = i * P.n_phases;

    var hi: St;
    var lo: St;
    if (r.started == 0u) {
        let ph0 = phases[base];
        let ev0 = start_instance(&r, &hi, &lo, base, ph0.first_step_s);
        r.h_s = ph0.first_step_s;
        r.evap_last = ev0.evap;
        r.omega_last = dp_omega(ev0.x);
        r.q_last = dp_extremes(&hi, ev0);
        for (var j = 0u; j < NS; j++) {
            r.k1[j] = ev0.ds[j];
        }
        r.have_k1 = 1u;
    } else {
        for (var j = 0u; j < NS; j++) {
            hi[j] = r.s_hi[j];
            lo[j] = r.s_lo[j];
        }
    }
    for (var j = 0u; j < NS; j++) {
        K[0][j] = r.k1[j];
    }
    var valve = r.valve_open != 0u;
    TVS_ON = r.tvs_on != 0u;
    var have_k1 = r.have_k1 != 0u;
    var ip = r.phase;
    PHASE_SLOT = base + min(ip, P.n_phases - 1u);
    var budget = control.step_budget;
    loop {
        if (ip >= P.n_phases || r.diverged != 0u || r.depleted != 0u || budget == 0u) {
            break;
        }
        budget -= 1u;
        let ph = phases[base + ip];
        let t0 = r.t_phase_s;
        // The attempt: the proposal, bounded, cut at a corner or the phase end.
        var h = min(r.h_s, dp_max_step(ph, t0, &hi, r.omega_last));
        var landing = LAND_FREE;
        var corner = 0.0;
        for (var c = 0u; c < 2u; c++) {
            let bp = select(ph.corner0_s, ph.corner1_s, c == 1u);
            if (landing == LAND_FREE && bp > t0 && t0 + h >= bp - 1.0e-6 * h) {
                h = bp - t0;
                landing = LAND_CORNER;
                corner = bp;
            }
        }
        let remaining = ph.duration_s - t0;
        if (h >= remaining - 1.0e-6 * h) {
            h = remaining;
            landing = LAND_PHASE_END;
        }
        // Stages 1–7 (stage 1 only when k1 cannot be reused, evaluated at the proposal's step
        // as the CPU does; stage 7's state is the fifth-order end, its rates the next k1), the
        // error norm after stage 7, and for an accepted step the mid-step probe as an eighth
        // pass on the dense output: one `evaluate` call site, since NIR inlines every call and
        // the right-hand side is most of the kernel.
        var ev7: Eval;
        var y7: St;
        var ev_mid: Eval;
        var y_mid: St;
        var d_mid: Drive;
        var err = 0.0;
        for (var stage = select(0u, 1u, have_k1); stage < 8u; stage++) {
            var y = hi;
            var t_stage = t0;
            var h_eval = r.h_s;
            if (stage == 7u) {
                // Accepted: the dense output's coefficients, then the probe at mid-step.
                for (var j = 0u; j < NS; j++) {
                    var b = 0.0;
                    var d = 0.0;
                    for (var m = 0u; m < 7u; m++) {
                        if (m < 6u) {
                            b += DP_A[5][m] * K[m][j];
                        }
                        d += DP_D[m] * K[m][j];
                    }
                    R1[j] = h * b;
                    R2[j] = h * K[0][j] - R1[j];
                    R3[j] = R1[j] - h * K[6][j] - R2[j];
                    R4[j] = h * d;
                }
                y = dp_dense(&hi, 0.5);
                t_stage = t0 + 0.5 * h;
                h_eval = h;
            } else if (stage > 0u) {
                for (var j = 0u; j < NS; j++) {
                    var inc = 0.0;
                    for (var m = 0u; m < stage; m++) {
                        inc += DP_A[stage - 1u][m] * K[m][j];
                    }
                    y[j] = hi[j] + h * inc;
                }
                t_stage = t0 + DP_C[stage] * h;
                h_eval = h;
            }
            let d_stage = phase_drive(ph, t_stage, valve);
            let ev = evaluate(&y, d_stage, h_eval);
            if (stage == 7u) {
                ev_mid = ev;
                y_mid = y;
                d_mid = d_stage;
                r.evaluations += 1u;
                break;
            }
            K[stage] = ev.ds;
            if (stage == 0u) {
                r.evaluations += 1u;
                have_k1 = true;
                continue;
            }
            if (stage == 6u) {
                ev7 = ev;
                y7 = y;
                r.evaluations += 6u;
                // The error norm, with the stiff terms' lag held to the vapour-mass tolerance.
                for (var j = 0u; j < NS; j++) {
                    var e = 0.0;
                    for (var m = 0u; m < 7u; m++) {
                        e += DP_E[m] * K[m][j];
                    }
                    let scale = P.atol[j] + P.rtol * max(abs(hi[j] + lo[j]), abs(y7[j]));
                    let ratio = abs(e * h) / scale;
                    if (!(ratio <= err)) {
                        err = ratio;
                    }
                }
                let lag = abs(h * (ev7.evap - r.evap_last)) * 0.5
                    / (P.atol[M_V] + P.rtol * max(abs(hi[M_V] + lo[M_V]), abs(y7[M_V])));
                if (!(lag <= err)) {
                    err = lag;
                }
                if (!(err <= 1.0)) {
                    break;
                }
            }
        }
        if (!(err <= 1.0)) {
            r.rejected += 1u;
            r.h_s = h * dp_factor(err, true);
            let floor = MIN_STEP_FRACTION * max(t0, 1.0);
            if (!(r.h_s > floor)) {
                r.diverged = DIVERGED_STEP_SIZE;
                r.diverged_value = r.h_s;
                r.diverged_time_s = r.phase_start_s + t0;
                r.diverged_phase = ip;
                break;
            }
            continue;
        }

        // The relief valve's and then the TVS's switching function along the step (one
        // dp_locate call site): the earlier switch cuts the step (adaptive.rs). A root where
        // the pressure is not at the band's end is no switch (dp_locate): near an empty tank
        // the f32 equilibrium of the homogeneous level can make the switching function jump
        // without a crossing (a located "opening" at 242 kPa under a 340 kPa crack), and the
        // step goes on whole.
        var theta_end = 1.0;
        var cut = false;
        var cut_tvs = false;
        let open = valve;
        let tvs_was = TVS_ON;
        for (var kind = 0u; kind < 2u; kind++) {
            var band_pa = P.relief_crack_pa;
            var armed = (P.flags & FLAG_RELIEF) != 0u;
            if (kind == 1u) {
                band_pa = P.tvs_upper_pa;
                armed = (P.flags & FLAG_TVS) != 0u && ph.tvs != 0u;
            }
            if (!armed) {
                continue;
            }
            let g0 = any_switch(kind, r.p_ullage_pa, open);
            let gm = any_switch(kind, ev_mid.x.p_u, open);
            let g1 = any_switch(kind, ev7.x.p_u, open);
            var lo_b = vec2<f32>(0.5, gm);
            var hi_b = vec2<f32>(1.0, g1);
            if (gm >= 0.0) {
                lo_b = vec2<f32>(0.0, g0);
                hi_b = vec2<f32>(0.5, gm);
            } else if (!(g1 >= 0.0)) {
                continue;
            }
            let th = dp_locate(&hi, ph, t0, h, lo_b, hi_b, open, kind, select(2.0, theta_end, cut), band_pa, &r);
            if (th <= 1.0) {
                cut = true;
                cut_tvs = kind == 1u;
                theta_end = th;
            }
        }
        var hi_prev = hi;
        let lo_prev = lo;
        let u = 1.0 - theta_end;
        for (var j = 0u; j < NS; j++) {
            // Kahan: the value is hi + lo; lo keeps what the f32 hi word could not take.
            var step = R1[j];
            if (cut) {
                step = theta_end * (R1[j] + u * (R2[j] + theta_end * (R3[j] + u * R4[j])));
            }
            let inc = step + lo[j];
            let sum = (hi[j] + inc) * control.one;
            lo[j] = inc - (sum - hi[j]);
            hi[j] = sum;
        }
        var t_end = t0 + h;
        if (cut) {
            t_end = t0 + theta_end * h;
            if (cut_tvs) {
                TVS_ON = !tvs_was;
            } else {
                valve = !open;
            }
        } else if (landing == LAND_PHASE_END) {
            t_end = ph.duration_s;
        } else if (landing == LAND_CORNER) {
            t_end = corner;
        }
        var d_end = phase_drive(ph, t_end, valve);
        let merged = merge_empty_bulk(&hi, &lo, hi_prev[M_B] + lo_prev[M_B], t_end - t0, BULK_MERGE_DRAIN_S);
        let mission = r.phase_start_s + t_end;

        // The evaluations after the step, through one call site: visit 0 the end state (the
        // fifth-order end's evaluation unless the step was cut or the bulk merged; a cut step
        // whose bulk merged is evaluated once, merged), its outcomes; visit 1 the probe (at
        // mid-step, or inside a cut step), then the extremes' parabola vertices found from it,
        // one visit each; or, when the tank ran dry within the step, visit 1 the state there
        // and the instance's end (observe.wgsl: dry_state, this visit's evaluation, dry_finish).
        var ev_end = ev7;
        var dry = false;
        var th_dry = 0.0;
        var s_dry_lo: St;
        var q_end: array<f32, 5>;
        var stop = false;
        var vertices = array<f32, 6>(-1.0, -1.0, -1.0, -1.0, -1.0, -1.0);
        var vertex_of = array<u32, 6>(0u, 0u, 0u, 0u, 0u, 0u);
        var n_vertices = 0u;
        for (var visit = 0u; visit < 2u + n_vertices; visit++) {
            var th_p = 0.5;
            var need = true;
            if (visit == 0u) {
                th_p = theta_end;
                need = cut || merged;
            } else if (visit == 1u) {
                need = theta_end <= 0.5;
                if (need) {
                    th_p = 0.5 * theta_end;
                }
            } else {
                th_p = vertices[visit - 2u];
            }
            var s_p = y_mid;
            var d_p = d_mid;
            var ev_p = ev_mid;
            var dt_p = h;
            if (visit == 0u) {
                s_p = hi;
                d_p = d_end;
                ev_p = ev7;
            }
            if (dry) {
                th_p = th_dry;
                dt_p = t_end - t0;
                s_p = dry_state(&hi, &lo, hi_prev, lo_prev, th_p, &s_dry_lo);
                d_p = phase_drive(ph, t0 + th_p * dt_p, valve);
            } else if (need && visit > 0u) {
                s_p = dp_dense(&hi_prev, th_p);
                d_p = phase_drive(ph, t0 + th_p * h, open);
            }
            if (need || dry) {
                ev_p = evaluate(&s_p, d_p, dt_p);
                r.evaluations += 1u;
            }
            if (dry) {
                dry_finish(&r, &hi, &lo, hi_prev, lo_prev, &s_p, s_dry_lo, ev_p, d_p, r.phase_start_s + t0, th_p, dt_p);
                r.t_phase_s = t_end;
                stop = true;
                break;
            }
            if (visit == 0u) {
                ev_end = ev_p;
                r.steps += 1u;
                r.final_time_s = mission;
                let bad = check_state(&hi, ev_end.x);
                let press0 = hi_prev[PRESS_IN] + lo_prev[PRESS_IN];
                th_dry = outcomes(&r, press0, hi[PRESS_IN] + lo[PRESS_IN], r.phase_start_s + t0, mission, ev_end, bad, K[0][M_S] + K[0][M_B]);
                if (th_dry >= 0.0) {
                    if (bad.x == 0.0) {
                        dry = true;
                        continue;
                    }
                    // The end state left the model: the instance ends on the step's start.
                    hi = hi_prev;
                    lo = lo_prev;
                    r.final_time_s = r.phase_start_s + t0;
                    r.t_phase_s = t_end;
                    stop = true;
                    break;
                }
                if (cut && !cut_tvs && !open) {
                    r.relief_cycles += 1u;
                }
                if (cut_tvs && !tvs_was) {
                    r.tvs_cycles += 1u;
                }
                if (bad.x != 0.0) {
                    r.diverged = u32(bad.x);
                    r.diverged_value = bad.y;
                    r.diverged_time_s = mission;
                    r.diverged_phase = ip;
                    r.t_phase_s = t_end;
                    stop = true;
                    break;
                }
                q_end = dp_extremes(&hi, ev_end);
                continue;
            }
            observe(&r, &s_p, r.phase_start_s + t0 + th_p * h, ev_p, d_p);
            if (visit > 1u) {
                continue;
            }
            // Extremes between the step ends: the vertex of the parabola through start, probe
            // and end where the probe is extreme.
            let q_m = dp_drawing(dp_extremes(&s_p, ev_p), d_p.burning);
            let q_e = dp_drawing(q_end, d_p.burning);
            let q_0 = dp_drawing(r.q_last, d_p.burning);
            for (var j = 0u; j < 5u; j++) {
                if (q_m[j] > q_0[j] && q_m[j] > q_e[j]) {
                    let v = dp_vertex(vec2<f32>(0.0, q_0[j]), vec2<f32>(th_p, q_m[j]), vec2<f32>(theta_end, q_e[j]));
                    var distinct = v > 0.0 && v < theta_end;
                    for (var m = 0u; m < n_vertices; m++) {
                        distinct = distinct && abs(vertices[m] - v) > 1.0e-3 * theta_end;
                    }
                    if (distinct) {
                        vertices[n_vertices] = v;
                        vertex_of[n_vertices] = j;
                        n_vertices += 1u;
                    }
                }
            }
            // The slosh displacement's extreme on the dense output alone (adaptive.rs: eight
            // intervals, then the vertex through the largest interior sample).
            var best = 0u;
            var scan: array<f32, 9>;
            for (var i = 0u; i <= 8u; i++) {
                scan[i] = abs(dp_dense_slot(&hi_prev, Q1, theta_end * f32(i) / 8.0));
                if (scan[i] > scan[best]) {
                    best = i;
                }
            }
            if (best > 0u && best < 8u) {
                let step = theta_end / 8.0;
                let w = dp_vertex(
                    vec2<f32>(f32(best - 1u) * step, scan[best - 1u]),
                    vec2<f32>(f32(best) * step, scan[best]),
                    vec2<f32>(f32(best + 1u) * step, scan[best + 1u]),
                );
                var fresh = w > 0.0 && w < theta_end;
                for (var m = 0u; m < n_vertices; m++) {
                    fresh = fresh && (vertex_of[m] != 3u || abs(vertices[m] - w) > 1.0e-3 * theta_end);
                }
                if (fresh) {
                    vertices[n_vertices] = w;
                    vertex_of[n_vertices] = 5u;
                    n_vertices += 1u;
                }
            }
        }
        if (stop) {
            break;
        }
        observe(&r, &hi, mission, ev_end, d_end);
        slosh_validity(&r, &hi, t_end - t0, ev_end, d_end);

        // The next proposal.
        let grown = h * dp_factor(err, false);
        if (cut || landing != LAND_FREE) {
            r.h_s = max(r.h_s, grown);
        } else {
            r.h_s = grown;
        }
        if (cut) {
            r.h_s = min(r.h_s, dp_restart(ev_end));
        }
        r.t_phase_s = t_end;
        save_last(&r, ev_end.x);
        r.evap_last = ev_end.evap;
        r.omega_last = dp_omega(ev_end.x);
        r.q_last = q_end;
        K[0] = ev_end.ds;
        if (!cut && landing == LAND_PHASE_END) {
            ip += 1u;
            if (ip < P.n_phases) {
                PHASE_SLOT = base + ip;
                enter_phase(PHASE_SLOT, &r, &hi, &lo);
                r.phase_start_s = mission;
                r.t_phase_s = 0.0;
                r.h_s = min(phases[base + ip].first_step_s, dp_restart(ev_end));
                have_k1 = false;
            }
        }
    }
    r.phase = ip;
    r.valve_open = u32(valve);
    r.tvs_on = u32(TVS_ON);
    r.have_k1 = u32(have_k1);
    r.done = u32(ip >= P.n_phases || r.diverged != 0u || r.depleted != 0u);
    for (var j = 0u; j < NS; j++) {
        r.s_hi[j] = hi[j];
        r.s_lo[j] = lo[j];
        r.k1[j] = K[0][j];
    }
    results[i] = r;
}
