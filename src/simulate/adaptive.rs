//! Error-controlled integration of a lane group (`campaign.integrator = "dopri5"`): every lane
//! keeps its own step length, the group stays in lockstep over right-hand-side evaluations.
//!
//! Per attempted step each lane's local error is measured against its tolerances; a lane whose
//! error is too large keeps its state and retries with a shorter step, the others move on.
//! Steps end exactly on phase ends and on the excitation's corners, and never exceed a
//! fraction of the slosh or excitation period. Relief-valve switching is located inside the
//! step on the pair's dense output (Illinois root finding on P_u − P_crack or P_reseat − P_u),
//! and the step is cut there; extremes between step ends are found by a probe at mid-step and
//! a parabolic refinement, so peaks do not depend on where the steps fall.

use super::events::EventKind;
use super::{row, History, LaneRun};
use crate::campaign::Campaign;
use crate::lanes::{Mask, Real};
use crate::model::derive::{self, Derived, Drive};
use crate::model::dopri::{self, Dense, Tolerance};
use crate::model::params::Params;
use crate::model::state::{self, *};
use crate::model::{self, Evaluation, Group};

/// Steps per slosh or excitation period that the adaptive step never falls below.
pub const ADAPTIVE_STEPS_PER_PERIOD: f64 = 16.0;

/// Shortest step before an instance is declared diverged, as a fraction of the phase time
/// scale (max(1 s, phase time)).
pub const MIN_STEP_FRACTION: f64 = 1.0e-12;

/// Reference scale of each state slot, in the slot's unit: the absolute tolerance of slot i is
/// `atol · scale_i`. Masses: the initial fluid mass; energies: the initial stored energy
/// ([`super::energy_scale`]); the pendulum angle 1 rad (rate 1 rad/s), two-mode displacements
/// the tank radius (rates radius/s); velocity 1 m/s, altitude 1 m; the pressure filter the
/// initial pressure.
pub fn reference_scales(p: &Params, s0: &State) -> State {
    let mass = (s0[M_V] + s0[M_G] + s0[M_S] + s0[M_B]).abs().max(1.0e-6);
    let energy = super::energy_scale(s0, s0).max(1.0);
    let slosh = if p.fidelity.two_mode_slosh() {
        p.tank.radius_m()
    } else {
        1.0
    };
    let mut r = [energy; NS];
    for i in [M_V, M_G, M_S, M_B, VENT_V, VENT_G, OUT, PRESS_IN, VENT_TVS] {
        r[i] = mass;
    }
    for i in [Q1, Q1D, Q2, Q2D] {
        r[i] = slosh;
    }
    r[VEL] = 1.0;
    r[ALT] = 1.0;
    r[P_FILT] = s0[P_FILT].abs().max(1.0e3);
    r
}

/// Which switched device cut a step.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Switched {
    Relief,
    Tvs,
}

/// Where a step was cut short.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Landing {
    /// The step ends where the proposal put it.
    Free,
    /// On an excitation corner at this phase time.
    Corner(f64),
    /// On the phase end.
    PhaseEnd,
}

impl LaneRun<'_> {
    /// The longest step the lane may take now, s: the phase's bound and a fraction of the
    /// excitation period; a fraction of the slosh period (from the last evaluation) too while
    /// the phase excites the liquid or the slosh state is not exactly at rest (a liquid at
    /// rest under no excitation stays at rest, and resolving its period would cost 16 steps
    /// per second on the ground for nothing).
    fn max_step(&self) -> f64 {
        let ph = self.phase();
        let mut h = ph.max_step_s;
        // A gust bounds the step only while it blows (steps land on its start and end).
        let blowing = match ph.excitation {
            crate::model::flight::Excitation::Gust {
                start_s,
                duration_s,
                ..
            } => self.t_phase >= start_s && self.t_phase < start_s + duration_s,
            _ => true,
        };
        if let Some(period) = ph.excitation_period_s().filter(|_| blowing) {
            h = h.min(period / ADAPTIVE_STEPS_PER_PERIOD);
        }
        let excited = ph.excitation != crate::model::flight::Excitation::None
            || [Q1, Q1D, Q2, Q2D]
                .iter()
                .any(|&i| self.last_state[i] != 0.0);
        let omega =
            self.last.derived.slosh.omega[0].max(if self.params.fidelity.two_mode_slosh() {
                self.last.derived.slosh.omega[1]
            } else {
                0.0
            });
        if excited && omega > 0.0 {
            h = h.min(std::f64::consts::TAU / omega / ADAPTIVE_STEPS_PER_PERIOD);
        }
        h
    }

    /// The step the lane attempts now: its proposal, bounded, cut at a corner or the phase end.
    fn attempt(&mut self) -> f64 {
        let ph = self.phase();
        let t = self.t_phase;
        let mut h = self.h.min(self.max_step());
        self.landing = Landing::Free;
        for bp in ph.breakpoints() {
            if bp > t && t + h >= bp - 1.0e-6 * h {
                h = bp - t;
                self.landing = Landing::Corner(bp);
                break;
            }
        }
        let remaining = ph.duration_s - t;
        if h >= remaining - 1.0e-6 * h {
            h = remaining;
            self.landing = Landing::PhaseEnd;
        }
        h
    }

    /// A rejected attempt of length `h` with error norm `error`: shorter next time; too short
    /// is a divergence.
    fn reject(&mut self, h: f64, error: f64) {
        self.rejected += 1;
        self.h = h * dopri::step_factor(error, true);
        let floor = MIN_STEP_FRACTION * self.t_phase.max(1.0);
        if self.h.is_nan() || self.h <= floor {
            let reason = format!("step size fell below {floor:.3e} s (error norm {error:.3e})");
            self.diverge(&reason, self.phase_start_s + self.t_phase, None);
        }
    }

    /// The evaluation of state `s` at phase time `t` (scalar, this lane), counted in
    /// `evaluations`: work the instance's integration does.
    fn eval_at(&mut self, s: &State, t: f64, h: f64) -> (Evaluation, Drive) {
        self.evaluations += 1;
        self.eval_uncounted(s, t, h)
    }

    /// [`Self::eval_at`] without the count: a time history's output sample, the history's cost
    /// rather than the instance's, so that a replay with a history counts what the run did.
    fn eval_uncounted(&self, s: &State, t: f64, h: f64) -> (Evaluation, Drive) {
        let d = self.drive(t);
        (model::evaluate(Group::one(self.params), s, &d, h), d)
    }

    /// An accepted step of length `h` from `y0` to `y1` with dense output `dense`, its end evaluation
    /// `ev1` and mid-step evaluation `mid`. Locates a valve switch inside the step and cuts
    /// the step there, checks outcomes and divergence, observes extremes, records history,
    /// moves to the next phase.
    #[expect(clippy::too_many_arguments, reason = "the step's facts, each named")]
    fn accept(
        &mut self,
        y0: &State,
        y1: &State,
        ev1: &Evaluation,
        dense: &Dense,
        h: f64,
        error: f64,
        mid: &Evaluation,
        mut history: Option<&mut History>,
    ) {
        let p = self.params;
        let t0 = self.t_phase;
        let ev0 = self.last;
        // Switches: the relief valve's and the TVS's switching functions, each located at the
        // first of mid-step and end where it is ≥ 0; the step is cut at the earlier one.
        let open = self.valve;
        let tvs_on = self.tvs;
        let relief_g = |x: &Derived| -> f64 {
            let r = p.relief.expect("a valve switch needs a relief valve");
            if open {
                r.reseat_pa - x.p_ullage_pa
            } else {
                x.p_ullage_pa - r.crack_pa
            }
        };
        let tvs_g = |x: &Derived| model::tvs::switching(p, tvs_on, x.p_ullage_pa);
        let mut cut: Option<(f64, Switched)> = None;
        if p.relief.is_some() {
            cut = self
                .find_switch(dense, (t0, h), [&ev0, mid, ev1], relief_g)
                .map(|th| (th, Switched::Relief));
        }
        if p.tvs.is_some() && self.phase().tvs {
            if let Some(th) = self.find_switch(dense, (t0, h), [&ev0, mid, ev1], tvs_g) {
                if cut.is_none_or(|(first, _)| th < first) {
                    cut = Some((th, Switched::Tvs));
                }
            }
        }
        let (theta_end, mut s_end, mut ev_end, d_end) = match cut {
            Some((theta, which)) => {
                match which {
                    Switched::Relief => self.valve = !open,
                    Switched::Tvs => self.tvs = !tvs_on,
                }
                let s = dense.at(theta);
                let (ev, d) = self.eval_at(&s, t0 + theta * h, h);
                (theta, s, ev, d)
            }
            None => (1.0, *y1, *ev1, self.drive(t0 + h)),
        };
        let t_end = if cut.is_none() {
            match self.landing {
                Landing::PhaseEnd => self.phase().duration_s,
                Landing::Corner(bp) => bp,
                Landing::Free => t0 + h,
            }
        } else {
            t0 + theta_end * h
        };
        let mission = self.phase_start_s + t_end;
        self.merge_bulk(&mut s_end, &mut ev_end, (&d_end, mission), h);
        self.steps += 1;
        self.t = mission;
        let bad = super::check_state(p, &s_end, &ev_end.derived);
        if self.outcomes(
            (self.phase_start_s + t0, mission),
            (&s_end, &ev_end),
            bad.is_none(),
            history.as_deref_mut(),
        ) {
            self.t_phase = t_end;
            return;
        }
        match cut {
            Some((_, Switched::Relief)) => {
                self.tracker.summary.relief_cycles += u64::from(!open);
                let kind = if open {
                    EventKind::ReliefClose
                } else {
                    EventKind::ReliefOpen
                };
                self.record(mission, kind, ev_end.derived.p_ullage_pa, f64::NAN);
            }
            Some((_, Switched::Tvs)) => {
                self.tracker.summary.tvs_cycles += u64::from(!tvs_on);
                let kind = if tvs_on {
                    EventKind::TvsOff
                } else {
                    EventKind::TvsOn
                };
                self.record(mission, kind, ev_end.derived.p_ullage_pa, f64::NAN);
            }
            None => {}
        }
        if let Some(reason) = bad {
            self.diverge(&reason, mission, Some(s_end));
            self.t_phase = t_end;
            return;
        }
        // Extremes between the step ends: a probe inside [0, theta_end], then a parabola.
        let probe = if theta_end > 0.5 {
            (0.5, *mid, self.drive(t0 + 0.5 * h))
        } else {
            let th = 0.5 * theta_end;
            let s = dense.at(th);
            let (ev, d) = self.eval_at(&s, t0 + th * h, h);
            (th, ev, d)
        };
        self.observe_probe(
            dense,
            y0,
            (t0, h),
            &ev0,
            probe,
            (theta_end, &s_end, &ev_end),
        );
        self.tracker.observe(p, mission, &s_end, &ev_end, &d_end);
        self.slosh_validity(t_end - t0, &s_end, &ev_end, &d_end);
        // Cavitation onset or end inside the step, located on the dense output.
        let margin = d_end
            .burning
            .then(|| super::cavitation_margin(p, &s_end, &ev_end.derived).0);
        let start = self.phase_start_s;
        let before = self.margin_prev;
        self.cavitation_events(
            (start + t0, mission),
            margin,
            ev_end.derived.p_ullage_pa,
            |lane, onset, _| {
                let sign = if onset { -1.0 } else { 1.0 };
                let g = |s: &State, x: &crate::model::derive::Derived| {
                    sign * super::cavitation_margin(p, s, x).0
                };
                let lo = (0.0, sign * before.unwrap_or(0.0));
                let hi = (theta_end, sign * margin.unwrap_or(0.0));
                start + t0 + lane.locate(dense, (t0, h), lo, hi, g) * h
            },
        );

        if let Some(hist) = history {
            let interval = self.campaign.output_interval_s;
            let start = self.phase_start_s;
            while self.next_sample < mission - 1.0e-9 * interval {
                let th = ((self.next_sample - start - t0) / h).clamp(0.0, theta_end);
                let s = dense.at(th);
                let (ev, d) = self.eval_uncounted(&s, t0 + th * h, h);
                hist.push(
                    row(p, start + t0 + th * h, &s, &ev, &d),
                    &self.phase().name,
                    open,
                );
                self.next_sample += interval;
            }
            let on_sample = (mission - self.next_sample).abs() <= 1.0e-9 * interval;
            if on_sample || cut.is_some() || self.landing == Landing::PhaseEnd {
                hist.push(
                    row(p, mission, &s_end, &ev_end, &d_end),
                    &self.phase().name,
                    self.valve,
                );
            }
            while self.next_sample <= mission + 1.0e-9 * interval {
                self.next_sample += interval;
            }
        }

        self.h = if cut.is_some() || self.landing != Landing::Free {
            // A cut step says little about the next one: keep the proposal if the error allows.
            self.h.max(h * dopri::step_factor(error, false))
        } else {
            h * dopri::step_factor(error, false)
        };
        if cut.is_some() {
            self.h = self.h.min(restart_step(&ev_end));
        }
        self.t_phase = t_end;
        self.last_state = s_end;
        self.last = ev_end;
        self.k1 = ev_end.rates;
        // The end evaluation used the closed-valve drive if the valve just switched: evaluated
        // again above with the new state; a phase change needs the next phase's drive.
        self.need_k1 = false;
        if cut.is_none() && self.landing == Landing::PhaseEnd {
            if self.phase + 1 == self.campaign.phases.len() {
                self.done = true;
            } else {
                self.next_phase();
                self.phase_start_s = mission;
                self.t_phase = 0.0;
                self.h = self.phase().dt_s.min(restart_step(&ev_end));
                self.need_k1 = true;
            }
        }
    }

    /// Observe the extremes between the step start (`ev0` at θ = 0), a probe and the end:
    /// where a quantity is more extreme at the probe than at both ends, the vertex of the
    /// parabola through the three samples is evaluated and observed too.
    fn observe_probe(
        &mut self,
        dense: &Dense,
        y0: &State,
        (t0, h): (f64, f64),
        ev0: &Evaluation,
        (th_m, ev_m, d_m): (f64, Evaluation, Drive),
        (th_e, s_e, ev_e): (f64, &State, &Evaluation),
    ) {
        let p = self.params;
        let s_m = dense.at(th_m);
        let mission = self.phase_start_s + t0;
        self.tracker
            .observe(p, mission + th_m * h, &s_m, &ev_m, &d_m);
        let burning = d_m.burning;
        let quantities = |s: &State, ev: &Evaluation| -> [f64; 5] {
            let x = &ev.derived;
            let margin = if burning {
                -super::cavitation_margin(p, s, x).0
            } else {
                0.0
            };
            [
                x.p_ullage_pa,
                -x.p_ullage_pa,
                margin,
                derive::slosh_angle(Group::one(p), s, &x.slosh).abs(),
                ev.fluxes.slosh_force_n.abs(),
            ]
        };
        let q0 = quantities(y0, ev0);
        let qm = quantities(&s_m, &ev_m);
        let qe = quantities(s_e, ev_e);
        let mut vertices: Vec<(f64, usize)> = Vec::new();
        for j in 0..5 {
            if qm[j] > q0[j] && qm[j] > qe[j] {
                let v = parabola_vertex((0.0, q0[j]), (th_m, qm[j]), (th_e, qe[j]));
                if v > 0.0 && v < th_e && vertices.iter().all(|u| (u.0 - v).abs() > 1.0e-3 * th_e) {
                    vertices.push((v, j));
                }
            }
        }
        for &(v, _) in &vertices {
            let s = dense.at(v);
            let (ev, d) = self.eval_at(&s, t0 + v * h, h);
            self.tracker.observe(p, mission + v * h, &s, &ev, &d);
        }
        // The slosh displacement is a state, so its extreme inside the step is found on the
        // dense output alone: eight intervals, then the vertex through the largest interior
        // sample. Start, probe and end alone missed a two_mode slosh peak by 1.3e-4 where the
        // peak fell between start and probe (methalox_autogenous at the default tolerances).
        let sample = |i: usize| {
            let th = th_e * i as f64 / SLOSH_SCAN as f64;
            (th, dense.slot_at(Q1, th).abs())
        };
        let samples: [(f64, f64); SLOSH_SCAN + 1] = std::array::from_fn(sample);
        let k = (0..=SLOSH_SCAN).fold(0, |k, i| if samples[i].1 > samples[k].1 { i } else { k });
        if k > 0 && k < SLOSH_SCAN {
            let w = parabola_vertex(samples[k - 1], samples[k], samples[k + 1]);
            let fresh = vertices
                .iter()
                .all(|u| u.1 != 3 || (u.0 - w).abs() > 1.0e-3 * th_e);
            if w > 0.0 && w < th_e && fresh {
                let s = dense.at(w);
                let (ev, d) = self.eval_at(&s, t0 + w * h, h);
                self.tracker.observe(p, mission + w * h, &s, &ev, &d);
            }
        }
    }

    /// Where switching function `g` of the step reaches 0: it is negative at the step start
    /// (`evs[0]`) and checked at mid-step (`evs[1]`) and the end (`evs[2]`); the first of those
    /// where it is ≥ 0 brackets the root, located on the dense output. None: no switch.
    fn find_switch(
        &mut self,
        dense: &Dense,
        (t0, h): (f64, f64),
        evs: [&Evaluation; 3],
        g: impl Fn(&Derived) -> f64,
    ) -> Option<f64> {
        let g0 = g(&evs[0].derived);
        let gm = g(&evs[1].derived);
        let (lo, hi) = if gm >= 0.0 {
            ((0.0, g0), (0.5, gm))
        } else {
            let g1 = g(&evs[2].derived);
            if g1 < 0.0 {
                return None;
            }
            ((0.5, gm), (1.0, g1))
        };
        Some(self.locate(dense, (t0, h), lo, hi, |_, x| g(x)))
    }

    /// The step fraction in [lo.0, hi.0] where `g` (of the derived state on the dense output)
    /// crosses zero, g(lo) < 0 ≤ g(hi): Illinois regula falsi to 1e-10 of the step. Returns
    /// the end of the last bracket where g ≥ 0, so the switch has happened there.
    fn locate(
        &mut self,
        dense: &Dense,
        (t0, h): (f64, f64),
        mut lo: (f64, f64),
        mut hi: (f64, f64),
        g: impl Fn(&State, &crate::model::derive::Derived) -> f64,
    ) -> f64 {
        let p = self.params;
        let mut side = 0i8;
        for _ in 0..60 {
            if hi.0 - lo.0 <= 1.0e-10 {
                break;
            }
            let (a, b) = (lo.1, hi.1);
            let mut th = (lo.0 * b - hi.0 * a) / (b - a);
            if !(th > lo.0 && th < hi.0) {
                th = 0.5 * (lo.0 + hi.0);
            }
            let s = dense.at(th);
            let d = self.drive(t0 + th * h);
            self.evaluations += 1;
            let v = g(&s, &derive::derive(Group::one(p), &s, &d));
            if v >= 0.0 {
                hi = (th, v);
                if side == 1 {
                    lo.1 *= 0.5;
                }
                side = 1;
            } else {
                lo = (th, v);
                if side == -1 {
                    hi.1 *= 0.5;
                }
                side = -1;
            }
        }
        hi.0
    }
}

/// The first step after a discontinuity (valve switch, phase start), s: the interface's own
/// relaxation time 1/(K J). The linearly implicit evaporation follows a jump of its
/// quasi-steady rate about one step late, a lag the embedded error estimate cannot see (both
/// solutions share it); starting from the physical time scale keeps that lag physical, and the
/// controller grows the step fivefold per step once the jump has passed.
fn restart_step(ev: &Evaluation) -> f64 {
    let rate = ev.fluxes.evap_relaxation_per_s;
    if rate > 0.0 {
        1.0 / rate
    } else {
        f64::INFINITY
    }
}

/// Intervals of the dense-output scan for the slosh displacement's extreme in a step.
const SLOSH_SCAN: usize = 8;

/// Abscissa of the vertex of the parabola through three points with distinct abscissae.
fn parabola_vertex(a: (f64, f64), b: (f64, f64), c: (f64, f64)) -> f64 {
    let (p, q) = (b.0 - a.0, b.0 - c.0);
    let (fa, fc) = (b.1 - c.1, b.1 - a.1);
    let den = p * fa - q * fc;
    if den == 0.0 {
        return b.0;
    }
    b.0 - 0.5 * (p * p * fa - q * q * fc) / den
}

/// The error tolerances of `lanes` (each lane's own scales, `atol` and `rtol`).
fn tolerance<T: Real>(lanes: &[LaneRun<'_>]) -> Tolerance<T> {
    let scales: Vec<State> = lanes
        .iter()
        .map(|l| reference_scales(l.params, &l.s0))
        .collect();
    Tolerance {
        atol: std::array::from_fn(|j| {
            T::from_fn(|i| scales[i][j] * lanes[i].campaign.stepping.atol)
        }),
        rtol: T::from_fn(|i| lanes[i].campaign.stepping.rtol),
    }
}

/// Integrate `members` (any number, mutually [`Params::lane_compatible`]) with error control
/// in one lane group of `T::LANES` (see the module doc). Each lane runs one member; a lane
/// whose member has ended takes the next member not yet started, so that members with fewer
/// steps do not leave their lanes idle while the group's longest member runs on (a fixed
/// group of 16 `lch4_coast` instances kept 57 % of its lanes busy). A lane's numbers are its
/// own member's `f64` work whoever shares the group, so each member's run equals its
/// integration alone, bit for bit. Returns the members' runs in member order; history rows of
/// the first member go to `history`.
pub(super) fn integrate<'a, T: Real>(
    members: &[(&'a Campaign, &'a Params)],
    mut history: Option<&mut History>,
) -> Vec<LaneRun<'a>> {
    assert!(!members.is_empty(), "at least one member");
    let width = T::LANES;
    let start = |m: usize| LaneRun::start(members[m].0, members[m].1);
    // Lanes past the members (a group of fewer members than lanes) repeat the first member,
    // ended from the start: they step by 0 and their results are dropped.
    let mut member_of: Vec<Option<usize>> = (0..width)
        .map(|i| (i < members.len()).then_some(i))
        .collect();
    let mut lanes: Vec<LaneRun<'a>> = (0..width)
        .map(|i| {
            let mut l = start(if i < members.len() { i } else { 0 });
            l.done = i >= members.len();
            l
        })
        .collect();
    if let Some(h) = history.as_deref_mut() {
        lanes[0].history_start(h);
    }
    let mut next = width.min(members.len());
    let mut ended: Vec<Option<LaneRun<'a>>> = (0..members.len()).map(|_| None).collect();
    let mut params: Vec<Params> = lanes.iter().map(|l| *l.params).collect();
    let mut tol: Tolerance<T> = tolerance(&lanes);
    let mut s: State<T> = std::array::from_fn(|j| T::from_fn(|i| lanes[i].s0[j]));
    // The attempt's stages and end, and the mid-step probe, evaluated in place step after step.
    let mut trial = dopri::Trial::default();
    let mut mid = Evaluation::default();
    let mut dense = vec![Dense::default(); T::LANES];
    let n = model::used_slots(Group::of(&params));
    loop {
        // Lanes whose member ended take the next members, from their initial state.
        let mut refilled = false;
        for i in 0..width {
            if lanes[i].done && next < members.len() {
                let old = std::mem::replace(&mut lanes[i], start(next));
                if let Some(m) = member_of[i] {
                    ended[m] = Some(old);
                }
                member_of[i] = Some(next);
                params[i] = *members[next].1;
                next += 1;
                refilled = true;
            }
        }
        if refilled {
            tol = tolerance(&lanes);
            s = std::array::from_fn(|j| T::from_fn(|i| lanes[i].last_state[j]));
        }
        if lanes.iter().all(|l| l.done) {
            break;
        }
        let g = Group::of(&params);
        // A finished lane steps by 0: its stages stay on its last good state, so the group
        // never evaluates (and iterates) where that lane alone would not go.
        let h = T::from_fn(|i| {
            if lanes[i].done {
                0.0
            } else {
                lanes[i].attempt()
            }
        });
        let t = T::from_fn(|i| lanes[i].t_phase);
        if lanes.iter().any(|l| !l.done && l.need_k1) {
            let d = Drive::gather(|i| lanes[i].drive(t.lane(i)));
            let ev = model::evaluate(g, &s, &d, h);
            for (i, l) in lanes.iter_mut().enumerate() {
                if !l.done && l.need_k1 {
                    l.k1 = state::lane(&ev.rates, i);
                    l.evaluations += 1;
                }
            }
        }
        let k1: State<T> = std::array::from_fn(|j| T::from_fn(|i| lanes[i].k1[j]));
        let drive = |tt: T| Drive::gather(|i| lanes[i].drive(tt.lane(i)));
        let evap0 = T::from_fn(|i| lanes[i].last.fluxes.evap_kg_s);
        dopri::trial(g, drive, &s, &k1, (evap0, t, h), &tol, &mut trial);
        let accepted = T::Mask::from_fn(|i| !lanes[i].done && trial.error.lane(i) <= 1.0);
        // Each accepted lane's dense output (built once, for the probe and for `accept`), and
        // the mid-step probe of every accepted lane, evaluated together.
        for (i, di) in dense.iter_mut().enumerate() {
            if accepted.lane(i) {
                di.set_lane((&s, &trial.end, &trial.k), i, h.lane(i), n);
            }
        }
        if accepted.any() {
            let sm: State<T> = std::array::from_fn(|j| {
                T::from_fn(|i| {
                    if accepted.lane(i) {
                        dense[i].slot_at(j, 0.5)
                    } else {
                        s[j].lane(i)
                    }
                })
            });
            model::evaluate_into(g, &sm, &drive(t + h * 0.5), h, &mut mid);
        }
        for (i, l) in lanes.iter_mut().enumerate() {
            if l.done {
                continue;
            }
            l.evaluations += 6;
            let (hi, err) = (h.lane(i), trial.error.lane(i));
            if !accepted.lane(i) {
                l.reject(hi, err);
                continue;
            }
            l.evaluations += 1;
            let hist = if member_of[i] == Some(0) {
                history.as_deref_mut()
            } else {
                None
            };
            l.accept(
                &state::lane(&s, i),
                &state::lane(&trial.end, i),
                &trial.end_eval.lane(i),
                &dense[i],
                hi,
                err,
                &mid.lane(i),
                hist,
            );
        }
        // Each lane goes on from its last good state: the end of an accepted step, the start
        // of a rejected one; a diverged lane is frozen at its last good state.
        s = std::array::from_fn(|j| T::from_fn(|i| lanes[i].last_state[j]));
    }
    for (l, m) in lanes.into_iter().zip(member_of) {
        if let Some(m) = m {
            ended[m] = Some(l);
        }
    }
    ended
        .into_iter()
        .map(|l| l.expect("every member ran in a lane"))
        .collect()
}
