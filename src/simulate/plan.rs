//! The step plan `cryoslosh check` prints: per phase the periods a step must resolve and the
//! steps per period, then the cost of the nominal instance measured by integrating it.

use super::{adaptive::ADAPTIVE_STEPS_PER_PERIOD, simulate};
use crate::campaign::number;
use crate::campaign::steps::{plan, MIN_STEPS_PER_PERIOD};
use crate::campaign::{Campaign, Integrator};
use std::fmt::Write;

/// The step plan of campaign `c`, as text, and why its nominal instance diverged (`None` when
/// it did not).
pub fn describe_step_plan(c: &Campaign) -> (String, Option<String>) {
    let st = &c.stepping;
    let mut o = String::new();
    let _ = match st.integrator {
        Integrator::Rk4 => writeln!(
            o,
            "step plan: fixed-step RK4 (at least {MIN_STEPS_PER_PERIOD} steps per slosh or excitation period{})",
            if st.allow_coarse_step { ", coarser allowed by campaign.allow_coarse_step" } else { "" }
        ),
        Integrator::Dopri5 => writeln!(
            o,
            "step plan: Dormand–Prince 5(4), rtol {:e}, atol {:e} × slot scale, steps ≤ 1/{ADAPTIVE_STEPS_PER_PERIOD} of the slosh (while excited) and excitation periods{}",
            st.rtol,
            st.atol,
            if st.max_step_s.is_finite() { format!(", ≤ {} s", st.max_step_s) } else { String::new() }
        ),
    };
    let per = |period: Option<f64>, dt: f64| {
        period.map_or_else(
            || "-".to_string(),
            |p| format!("{} s ({:.1} steps)", number(p), p / dt),
        )
    };
    for (ph, pp) in c.phases.iter().zip(plan(c)) {
        let dt = match st.integrator {
            Integrator::Rk4 => pp.fixed_dt_s,
            Integrator::Dopri5 => {
                let mut h = ph.max_step_s;
                for period in [pp.slosh_period_s, pp.excitation_period_s]
                    .into_iter()
                    .flatten()
                {
                    h = h.min(period / ADAPTIVE_STEPS_PER_PERIOD);
                }
                h
            }
        };
        let step = if dt.is_finite() {
            format!("{} s", number(dt))
        } else {
            "unbounded".to_string()
        };
        let _ = writeln!(
            o,
            "  {}: {} step {step}; slosh period {}; excitation period {}",
            ph.name,
            if st.integrator == Integrator::Rk4 {
                "fixed"
            } else {
                "longest"
            },
            per(pp.slosh_period_s, dt),
            per(pp.excitation_period_s, dt),
        );
    }
    let q = simulate(c, &c.params, None);
    let _ = writeln!(
        o,
        "nominal instance: {} steps ({} rejected), {} right-hand-side evaluations{}",
        q.steps,
        q.rejected_steps,
        q.rhs_evaluations,
        if q.diverged { " — DIVERGED" } else { "" }
    );
    let why = q
        .diverged
        .then(|| q.diverged_reason.clone().unwrap_or_default());
    (o, why)
}
