// Fixed-step RK4 on the device (`campaign.integrator = "rk4"`): the WGSL mirror of the step loop
// in src/simulate/mod.rs (integrate_fixed, LaneRun::after_step). Uses model.wgsl's physics and
// observation functions; tests/gpu_parity.rs checks.

// One dispatch advances every unfinished instance by up to control.step_budget steps and
// carries the rest in its result record: dispatches stay short on hardware with a watchdog,
// and llvmpipe's cap of 65,535 loop iterations per invocation is never reached.
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
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

    // Element-wise copies: naga types a struct member's array apart from the function-scope St.
    var hi: St;
    var lo: St;
    var k1: St;
    if (r.started == 0u) {
        start_instance(&r, &hi, &lo, base, phases[base].dt);
    } else {
        for (var j = 0u; j < NS; j++) {
            hi[j] = r.s_hi[j];
            lo[j] = r.s_lo[j];
            k1[j] = r.k1[j];
        }
    }
    var valve = r.valve_open != 0u;
    TVS_ON = r.tvs_on != 0u;
    var have_k1 = r.have_k1 != 0u;
    var ip = r.phase;
    var k = r.step_in_phase;
    PHASE_SLOT = base + min(ip, P.n_phases - 1u);
    var k2: St;
    var k3: St;
    var k4: St;
    var budget = control.step_budget;
    // Right-hand-side evaluations of this dispatch's steps (start_instance counts its own),
    // added to the record once at the end.
    var evals = 0u;
    loop {
        if (ip >= P.n_phases || r.diverged != 0u || r.depleted != 0u) {
            break;
        }
        let ph = phases[base + ip];
        if (k >= ph.n_steps) {
            ip += 1u;
            k = 0u;
            have_k1 = false;
            r.phase_start_s = r.final_time_s;
            if (ip < P.n_phases) {
                PHASE_SLOT = base + ip;
                enter_phase(PHASE_SLOT, &r, &hi, &lo);
            }
            continue;
        }
        if (budget == 0u) {
            break;
        }
        let dt = ph.dt;
        let tp = f32(k) * dt;
        let hi_prev = hi;
        let lo_prev = lo;
        // The four stages (k1 only when it cannot be reused), the evaluation at the step's end
        // and, for an instance that ran dry within the step, the state where it did (stage 5:
        // observe.wgsl's dry_state and dry_finish around it), through one call site: NIR
        // inlines every call, and the right-hand side is most of the kernel (eight call sites
        // made the `layered` kernel's cold compile take minutes).
        var merged = false;
        var tn = tp;
        var d: Drive;
        var ev: Eval;
        var t = 0.0;
        var bad = vec2<f32>(0.0, 0.0);
        var th = -1.0;
        var s_dry_lo: St;
        // The stages and the step's end read the slosh modes only through the rates (observe and
        // slosh_validity read angles and the force, zeros at rest): an unexcited phase may leave
        // them out. Cleared after the stages.
        SLOSH_UNREAD = ph.excites == 0u;
        for (var stage = select(0u, 1u, have_k1); stage < 6u; stage++) {
            var y = hi;
            var at = tp;
            var dt_eval = dt;
            if (stage == 5u) {
                // The step of phase times (tn − dt, tn), its length as the dry end always took it.
                dt_eval = tn - (tn - dt);
                y = dry_state(&hi, &lo, hi_prev, lo_prev, th, &s_dry_lo);
                at = (tn - dt) + th * dt_eval;
            } else if (stage == 4u) {
                for (var j = 0u; j < NS; j++) {
                    // Kahan: the value is hi + lo; lo keeps what the f32 hi word could not take.
                    let inc = dt / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]) + lo[j];
                    let sum = (hi[j] + inc) * control.one;
                    lo[j] = inc - (sum - hi[j]);
                    hi[j] = sum;
                }
                merged = merge_empty_bulk(&hi, &lo, hi_prev[M_B] + lo_prev[M_B], dt, max(BULK_MERGE_DRAIN_S, 2.0 * dt));
                r.steps += 1u;
                budget -= 1u;
                k += 1u;
                tn = f32(k) * dt;
                at = tn;
                y = hi;
            } else if (stage > 0u) {
                // k2, k3 at half a step along k1, k2; k4 at a whole step along k3.
                var kp = k3;
                if (stage == 1u) {
                    kp = k1;
                } else if (stage == 2u) {
                    kp = k2;
                }
                let a = select(0.5 * dt, dt, stage == 3u);
                at = tp + a;
                for (var j = 0u; j < NS; j++) {
                    y[j] = hi[j] + a * kp[j];
                }
            }
            d = phase_drive(ph, at, valve);
            ev = evaluate(&y, d, dt_eval);
            evals += 1u;
            if (stage == 5u) {
                dry_finish(&r, &hi, &lo, hi_prev, lo_prev, &y, s_dry_lo, ev, d, t - dt, th, dt_eval);
                break;
            }
            switch stage {
                case 0u: {
                    k1 = ev.ds;
                }
                case 1u: {
                    k2 = ev.ds;
                }
                case 2u: {
                    k3 = ev.ds;
                }
                case 3u: {
                    k4 = ev.ds;
                }
                default: {}
            }
            if (stage == 4u) {
                t = r.phase_start_s + tn;
                r.final_time_s = t;
                bad = check_state(&hi, ev.x);
                let press0 = hi_prev[PRESS_IN] + lo_prev[PRESS_IN];
                th = outcomes(&r, press0, hi[PRESS_IN] + lo[PRESS_IN], t - dt, t, ev, bad, k1[M_S] + k1[M_B]);
                if (!(th >= 0.0 && bad.x == 0.0)) {
                    break;
                }
            }
        }
        SLOSH_UNREAD = false;
        if (th >= 0.0) {
            // Ran dry: stage 5 ended the instance there, or, where the end state left the
            // model, it ends on the step's start.
            if (bad.x != 0.0) {
                hi = hi_prev;
                lo = lo_prev;
                r.final_time_s = t - dt;
            }
            break;
        }
        if (bad.x != 0.0) {
            r.diverged = u32(bad.x);
            r.diverged_value = bad.y;
            r.diverged_time_s = t;
            r.diverged_phase = ip;
            break;
        }
        observe(&r, &hi, t, ev, d);
        slosh_validity(&r, &hi, dt, ev, d);
        let before = valve;
        valve = update_valve(ev.x.p_u, valve);
        if (valve && !before) {
            r.relief_cycles += 1u;
        }
        let tvs_switched = switch_tvs(&r, ph, ev.x.p_u);
        have_k1 = valve == before && !tvs_switched && k != ph.n_steps && !merged;
        k1 = ev.ds;
        save_last(&r, ev.x);
    }
    r.phase = ip;
    r.step_in_phase = k;
    r.valve_open = u32(valve);
    r.tvs_on = u32(TVS_ON);
    r.have_k1 = u32(have_k1);
    r.evaluations += evals;
    r.done = u32(ip >= P.n_phases || r.diverged != 0u || r.depleted != 0u);
    for (var j = 0u; j < NS; j++) {
        r.s_hi[j] = hi[j];
        r.s_lo[j] = lo[j];
        r.k1[j] = k1[j];
    }
    results[i] = r;
}
