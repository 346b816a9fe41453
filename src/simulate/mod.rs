//! One tank instance through its phase list: per-step quantities of interest (MODEL.md §11),
//! divergence detection and an optional sampled time history. The error-controlled integrator
//! lives in [`adaptive`]; fixed-step RK4 (`campaign.integrator = "rk4"`) in this file.

pub mod adaptive;
pub mod events;
pub mod plan;
pub mod qoi;

use events::{EventKind, EventLog};

use qoi::Tracker;
pub use qoi::{
    cumulative, describe_summary, finish_summary, PhaseSummary, Summary,
    DEPLETION_RESIDUAL_FRACTION, PRESSURANT_EMPTY_FRACTION, SLOSH_ANGLE_MAX_RAD, SLOSH_BOND_MIN,
};

use crate::campaign::{Campaign, Integrator};
use crate::lanes::{Lanes, Mask, Real, WIDTH};
use crate::model::derive::{mode2_angle, slosh_angle, Derived, Drive, Switches};
use crate::model::flight::{Excitation, Phase, G0};
use crate::model::params::{Fidelity, Params};
use crate::model::state::{self, *};
use crate::model::{self, Evaluation, Group};

/// The fraction of a step, from values `a` at its start and `b` at its end, where a linear
/// interpolation crosses `level` (the values are nearly linear over a step: a constant draw).
fn crossing(a: f64, b: f64, level: f64) -> f64 {
    if a == b {
        1.0
    } else {
        ((a - level) / (a - b)).clamp(0.0, 1.0)
    }
}

/// Names of the f64 time-history columns, in order (DESIGN.md "time history").
pub const HISTORY_COLUMNS: [&str; 35] = [
    "time_s",
    "pressure_pa",
    "vapor_pressure_pa",
    "helium_pressure_pa",
    "saturation_pressure_pa",
    "ullage_temp_k",
    "layer_temp_k",
    "bulk_temp_k",
    "wall_temp_k",
    "wall_dry_temp_k",
    "wall_wet_temp_k",
    "liquid_mass_kg",
    "layer_mass_kg",
    "vapor_mass_kg",
    "helium_mass_kg",
    "fill_fraction",
    "liquid_level_m",
    "slosh_angle_rad",
    "slosh_rate_rad_s",
    "slosh_mode2_m",
    "slosh_frequency_hz",
    "slosh_damping_ratio",
    "slosh_force_n",
    "slosh_moment_n_m",
    "cavitation_margin_m",
    "evaporation_kg_s",
    "vented_kg",
    "pressurant_used_kg",
    "propellant_drawn_kg",
    "velocity_m_s",
    "altitude_m",
    "axial_accel_m_s2",
    "lateral_accel_m_s2",
    "heat_leak_w",
    "tvs_vented_kg",
];

/// A sampled time history, column-major.
#[derive(Clone, Debug, Default)]
pub struct History {
    /// One vector per entry of [`HISTORY_COLUMNS`].
    pub columns: Vec<Vec<f64>>,
    /// Phase name per row.
    pub phase: Vec<String>,
    /// Relief valve open per row.
    pub valve_open: Vec<bool>,
}

impl History {
    fn push(&mut self, row: [f64; HISTORY_COLUMNS.len()], phase: &str, valve: bool) {
        if self.columns.is_empty() {
            self.columns = vec![Vec::new(); HISTORY_COLUMNS.len()];
        }
        for (c, v) in self.columns.iter_mut().zip(row) {
            c.push(v);
        }
        self.phase.push(phase.to_string());
        self.valve_open.push(valve);
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.phase.len()
    }

    /// Whether no row was recorded.
    pub fn is_empty(&self) -> bool {
        self.phase.is_empty()
    }

    /// The column called `name`.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        let i = HISTORY_COLUMNS.iter().position(|c| *c == name)?;
        self.columns.get(i).map(Vec::as_slice)
    }
}

/// Net positive suction head margin NPSH_a − NPSH_r, m, and the same in Pa (MODEL.md §9).
pub fn cavitation_margin(p: &Params, s: &State, x: &Derived) -> (f64, f64) {
    let f = p.fluid.props();
    let bulk_gone = s[M_B] <= model::BULK_MERGE_FRACTION * (s[M_B] + s[M_S]);
    let (rho, t_out) = if bulk_gone {
        (x.rho_layer, x.t_layer_k)
    } else {
        (x.rho_bulk, x.t_bulk_k)
    };
    let fd = &p.feed;
    let head_pa = x.p_ullage_pa + rho * x.a_ax * (x.level_m + fd.line_height_m)
        - fd.line_loss_pa
        - 0.5 * rho * fd.line_velocity_m_s * fd.line_velocity_m_s
        - f.psat_pa(t_out);
    let npsh_a = head_pa / (rho * G0);
    let margin_m = npsh_a - fd.npsh_required_m;
    (margin_m, margin_m * rho * G0)
}

/// Energy scale for the closure check: the magnitudes of every stored and exchanged energy, J.
pub fn energy_scale(s0: &State, s: &State) -> f64 {
    [U_U, H_S, H_B, E_WD, E_WW]
        .iter()
        .chain(&std::array::from_fn::<usize, NL_MAX, _>(|k| COL + k))
        .map(|&i| s0[i].abs())
        .sum::<f64>()
        + [E_ENV, E_PRESS, E_VENT, E_OUT, E_WORK, E_PUMP]
            .iter()
            .map(|&i| s[i].abs())
            .sum::<f64>()
}

/// Why a state is unphysical, if it is.
fn check_state(p: &Params, s: &State, x: &Derived) -> Option<String> {
    if let Some(i) = s.iter().position(|v| !v.is_finite()) {
        return Some(format!("state slot {i} is not finite"));
    }
    let f = p.fluid.props();
    let checks = [
        ("ullage pressure", x.p_ullage_pa, 0.0, 10.0 * f.p_crit_pa),
        ("ullage volume", x.v_ullage_m3, 0.0, f64::INFINITY),
        ("ullage temperature", x.t_ullage_k, 1.0, 2000.0),
        (
            "layer temperature",
            x.t_layer_k,
            f.t_min_k - 2.0,
            f.t_max_k + 2.0,
        ),
        (
            "bulk temperature",
            x.t_bulk_k,
            f.t_min_k - 2.0,
            f.t_max_k + 2.0,
        ),
        ("dry wall temperature", x.t_wall_dry_k, 1.0, 2000.0),
        ("wetted wall temperature", x.t_wall_wet_k, 1.0, 2000.0),
        // Every layer of the `layered` column (the film and the bottom are checked above).
        (
            "coldest liquid temperature",
            x.t_liquid_min_k,
            f.t_min_k - 2.0,
            f.t_max_k + 2.0,
        ),
        (
            "warmest liquid temperature",
            x.t_liquid_max_k,
            f.t_min_k - 2.0,
            f.t_max_k + 2.0,
        ),
    ];
    for (what, v, lo, hi) in checks {
        if !(v > lo && v < hi) {
            return Some(format!("{what} {v:.6e} left ({lo}, {hi})"));
        }
    }
    let scale = 1.0e-9 * (s[M_B] + s[M_S]).abs().max(1.0);
    for (what, i) in [
        ("vapour mass", M_V),
        ("helium mass", M_G),
        ("layer mass", M_S),
        ("bulk mass", M_B),
    ] {
        if s[i] < -scale {
            return Some(format!("{what} {:.6e} kg is negative", s[i]));
        }
    }
    None
}

/// Vapour mass of the initial state (homogeneous keeps it implicit in the equilibrium).
pub fn initial_vapor_mass(p: &Params, s0: &State) -> f64 {
    match p.fidelity {
        Fidelity::Homogeneous => {
            model::derive::derive(Group::one(p), s0, &Drive::default()).m_vapor_kg
        }
        _ => s0[M_V],
    }
}

/// Initial state of a campaign, including the initial slosh displacement.
pub fn initial_state(c: &Campaign, p: &Params) -> State {
    let mut s = model::state::initial_state(p);
    let th = c.initial_slosh_angle_rad;
    match p.fidelity {
        Fidelity::Homogeneous => {}
        Fidelity::Lumped => s[Q1] = th,
        Fidelity::TwoMode | Fidelity::Layered => {
            let d = Drive::of_phase(&c.phases[0], 0.0, Default::default());
            let x = model::derive::derive(Group::one(p), &s, &d);
            s[Q1] = x.slosh.length_m[0] * th.tan();
        }
    }
    s
}

/// One history row.
fn row(p: &Params, t: f64, s: &State, ev: &Evaluation, d: &Drive) -> [f64; HISTORY_COLUMNS.len()] {
    let x = &ev.derived;
    let f = p.fluid.props();
    let wall_share = x.wetted_share;
    let (q1, q1d, q2) = if p.fidelity.two_mode_slosh() {
        (
            slosh_angle(Group::one(p), s, &x.slosh),
            s[Q1D] / x.slosh.length_m[0],
            s[Q2],
        )
    } else {
        (s[Q1], s[Q1D], 0.0)
    };
    let margin = if d.burning {
        cavitation_margin(p, s, x).0
    } else {
        f64::NAN
    };
    [
        t,
        x.p_ullage_pa,
        x.p_vapor_pa,
        x.p_ullage_pa - x.p_vapor_pa,
        f.psat_pa(x.t_layer_k),
        x.t_ullage_k,
        x.t_layer_k,
        x.t_bulk_k,
        wall_share * x.t_wall_wet_k + (1.0 - wall_share) * x.t_wall_dry_k,
        x.t_wall_dry_k,
        x.t_wall_wet_k,
        x.m_liquid_kg,
        s[M_S],
        x.m_vapor_kg,
        s[M_G],
        (x.v_layer_m3 + x.v_bulk_m3) / p.tank.volume_m3(),
        x.level_m,
        q1,
        q1d,
        q2,
        x.slosh.omega[0] / std::f64::consts::TAU,
        x.slosh.zeta[0],
        ev.fluxes.slosh_force_n,
        ev.fluxes.slosh_force_n * p.vehicle.slosh_lever_arm_m,
        margin,
        ev.fluxes.evap_kg_s,
        s[VENT_V] + s[VENT_G],
        s[PRESS_IN],
        s[OUT],
        s[VEL],
        s[ALT],
        x.a_ax,
        d.a_lat,
        crate::model::insulation::wall_heat(Group::one(p), d, x).total_w,
        s[VENT_TVS],
    ]
}

/// Where one instance of a lane group is in its phase list, and what it has seen.
struct LaneRun<'a> {
    campaign: &'a Campaign,
    params: &'a Params,
    s0: State,
    /// Index of the current phase; the last phase once done.
    phase: usize,
    /// Steps taken in the current phase, its step count and step length.
    k: u64,
    n: u64,
    dt: f64,
    t: f64,
    steps: u64,
    valve: bool,
    /// The thermodynamic vent system runs (`model::tvs`).
    tvs: bool,
    /// The group's post-step derivative may serve as this lane's next k1 (switches unchanged,
    /// phase going on): RK4 would evaluate exactly the same one.
    reuse: bool,
    done: bool,
    tracker: Tracker,
    /// The last state that passed the checks and its evaluation.
    last_state: State,
    last: Evaluation,
    /// The state that failed the checks, if one did: the instance ends there.
    diverged_state: Option<State>,
    next_sample: f64,
    /// Adaptive stepping: mission time of the phase start, time within the phase, the next
    /// step's proposal, the derivative at the current state (valid unless `need_k1`) and where
    /// the step being attempted was cut.
    phase_start_s: f64,
    t_phase: f64,
    h: f64,
    k1: State,
    need_k1: bool,
    landing: adaptive::Landing,
    rejected: u64,
    evaluations: u64,
    /// Liquid mass at the start, kg (the depletion residual is a share of it).
    m_liquid0: f64,
    /// The last step merged an empty bulk node into the layer: the group's copy of this lane's
    /// state is stale.
    merged: bool,
    /// Time the slosh analog spent outside its range, s.
    slosh_out_s: f64,
    /// The events so far, when the campaign records them.
    events: Option<EventLog>,
    /// Cavitation margin at the last observation, m (None: the engine did not draw).
    margin_prev: Option<f64>,
    /// This lane's evaluations feed history rows, which report the slosh modes.
    records_history: bool,
}

impl<'a> LaneRun<'a> {
    /// The instance at t = 0, observed once.
    fn start(c: &'a Campaign, p: &'a Params) -> LaneRun<'a> {
        let s0 = initial_state(c, p);
        let mut d0 = Drive::of_phase(&c.phases[0], 0.0, Default::default());
        let mut ev0 = model::evaluate(Group::one(p), &s0, &d0, c.phases[0].dt_s);
        // A TVS whose band the initial pressure already reaches runs from the start (evaluated
        // again with it on, as `start_instance` in shaders/observe.wgsl does).
        let p0 = ev0.derived.p_ullage_pa;
        let tvs0 = model::tvs::update::<f64>(Group::one(p), p0, false, c.phases[0].tvs);
        if tvs0 {
            let on = Switches {
                relief: false,
                tvs: true,
            };
            d0 = Drive::of_phase(&c.phases[0], 0.0, on);
            ev0 = model::evaluate(Group::one(p), &s0, &d0, c.phases[0].dt_s);
        }
        let mut tracker = Tracker::new(initial_vapor_mass(p, &s0));
        tracker.enter_phase(&c.phases[0].name, p, &s0, &ev0);
        tracker.observe(p, 0.0, &s0, &ev0, &d0);
        let (n, dt) = c.phases[0].steps();
        tracker.summary.tvs_cycles = u64::from(tvs0);
        let mut events = c.record_events.then(EventLog::default);
        if let (true, Some(log)) = (tvs0, events.as_mut()) {
            log.push(0.0, 0, EventKind::TvsOn, p0, f64::NAN);
        }
        LaneRun {
            campaign: c,
            params: p,
            s0,
            phase: 0,
            k: 0,
            n,
            dt,
            t: 0.0,
            steps: 0,
            valve: false,
            tvs: tvs0,
            reuse: false,
            done: false,
            tracker,
            last_state: s0,
            last: ev0,
            diverged_state: None,
            next_sample: c.output_interval_s,
            phase_start_s: 0.0,
            t_phase: 0.0,
            h: c.phases[0].dt_s,
            k1: ev0.rates,
            need_k1: false,
            landing: adaptive::Landing::Free,
            rejected: 0,
            // The initial evaluation, and the second with the TVS on when it starts on.
            evaluations: 1 + u64::from(tvs0),
            m_liquid0: ev0.derived.m_liquid_kg,
            merged: false,
            slosh_out_s: 0.0,
            events,
            margin_prev: d0
                .burning
                .then(|| cavitation_margin(p, &s0, &ev0.derived).0),
            records_history: false,
        }
    }

    /// The history's first row: this lane at t = 0. From here on its evaluations carry the slosh
    /// modes, which the rows report ([`Drive::slosh_modes_unread`]).
    fn history_start(&mut self, h: &mut History) {
        self.records_history = true;
        h.push(
            row(self.params, 0.0, &self.s0, &self.last, &self.drive(0.0)),
            &self.phase().name,
            false,
        );
    }

    fn phase(&self) -> &'a Phase {
        &self.campaign.phases[self.phase]
    }

    /// The trajectory of this lane at time `t` of its current phase. The slosh modes are unread
    /// where the phase has no lateral excitation and no history row is recorded: the only other
    /// reader, the adaptive step's bound, reads them only in an excited phase or while the
    /// analog swings, and then the right-hand side evaluates them (`model::derive::motion`).
    fn drive(&self, t: f64) -> Drive {
        let phase = self.phase();
        let mut d = Drive::of_phase(phase, t, self.switches());
        d.slosh_modes_unread = !self.records_history && phase.excitation == Excitation::None;
        d
    }

    /// The switched devices' states now.
    fn switches(&self) -> Switches {
        Switches {
            relief: self.valve,
            tvs: self.tvs,
        }
    }

    /// Update the TVS's hysteresis at mission time `t` and ullage pressure `pressure_pa` under
    /// the current phase's switch, counting a start and recording the event.
    fn switch_tvs(&mut self, t: f64, pressure_pa: f64) {
        let p = self.params;
        if p.tvs.is_none() {
            return;
        }
        let before = self.tvs;
        self.tvs = model::tvs::update::<f64>(Group::one(p), pressure_pa, before, self.phase().tvs);
        if self.tvs != before {
            self.tracker.summary.tvs_cycles += u64::from(self.tvs);
            let kind = if self.tvs {
                EventKind::TvsOn
            } else {
                EventKind::TvsOff
            };
            self.record(t, kind, pressure_pa, f64::NAN);
        }
    }

    /// The instance diverged at mission time `t` for `reason`; `state` is the one that failed the
    /// checks (None: the step could not be taken at all).
    fn diverge(&mut self, reason: &str, t: f64, state: Option<State>) {
        let name = &self.phase().name;
        let q = &mut self.tracker.summary;
        q.diverged = true;
        q.diverged_reason = Some(format!("{reason} at t = {t:.3} s in phase {name}"));
        self.diverged_state = state;
        self.done = true;
    }

    /// Record event `kind` at mission time `t` with ullage pressure `pressure_pa` and the kind's
    /// `value` (see [`events::Event`]), when the campaign records events.
    fn record(&mut self, t: f64, kind: EventKind, pressure_pa: f64, value: f64) {
        if let Some(log) = &mut self.events {
            log.push(t, self.phase, kind, pressure_pa, value);
        }
    }

    /// Merge an empty bulk node of the step's end state `s` at mission time `t` into the layer
    /// ([`model::merge_empty_bulk`]) and evaluate the merged state again under drive `d` with
    /// step `h`. The step started from `self.last_state` at `self.t`. Returns whether it merged.
    fn merge_bulk(
        &mut self,
        s: &mut State,
        ev: &mut Evaluation,
        (d, t): (&Drive, f64),
        h: f64,
    ) -> bool {
        let step_s = t - self.t;
        let horizon_s = match self.campaign.stepping.integrator {
            Integrator::Rk4 => model::BULK_MERGE_DRAIN_S.max(2.0 * step_s),
            Integrator::Dopri5 => model::BULK_MERGE_DRAIN_S,
        };
        let m_b0 = self.last_state[M_B];
        let merged = model::merge_empty_bulk(self.params, s, m_b0, (step_s, horizon_s));
        if merged {
            self.evaluations += 1;
            *ev = model::evaluate(Group::one(self.params), s, d, h);
            // A merge into a state outside the model is the divergence `after_step` reports,
            // not an event (it recorded p = NaN and 6e290 kg).
            if check_state(self.params, s, &ev.derived).is_none() {
                self.record(t, EventKind::BulkMerged, ev.derived.p_ullage_pa, s[M_S]);
            }
        }
        merged
    }

    /// Cavitation onset or end between the last observation (mission time `t0`) and this one
    /// at `t1`, where the margin is `margin` (None: the engine does not draw) and the ullage
    /// pressure `pressure_pa`. `locate(onset, margin_before)` gives the time the margin crossed
    /// zero inside the step; the event's pressure is interpolated between the step's ends. A
    /// draw that starts cavitating (at a phase start) begins it at `t0`; the end of a draw while
    /// cavitating is [`Self::end_draw`]'s.
    fn cavitation_events(
        &mut self,
        (t0, t1): (f64, f64),
        margin: Option<f64>,
        pressure_pa: f64,
        locate: impl FnOnce(&mut Self, bool, f64) -> f64,
    ) {
        let before = self.margin_prev;
        self.margin_prev = margin;
        if self.events.is_none() {
            return;
        }
        let p0 = self.last.derived.p_ullage_pa;
        let at = |t: f64| {
            if t1 > t0 {
                p0 + (pressure_pa - p0) * ((t - t0) / (t1 - t0))
            } else {
                pressure_pa
            }
        };
        match (before, margin) {
            (Some(a), Some(b)) if a >= 0.0 && b < 0.0 => {
                let t = locate(self, true, a);
                self.record(t, EventKind::CavitationOnset, at(t), f64::NAN);
            }
            (Some(a), Some(b)) if a < 0.0 && b >= 0.0 => {
                let t = locate(self, false, a);
                self.record(t, EventKind::CavitationEnd, at(t), f64::NAN);
            }
            (None, Some(b)) if b < 0.0 => {
                // The draw began at the step's start (a phase start) already cavitating.
                self.record(t0, EventKind::CavitationOnset, p0, f64::NAN);
            }
            _ => {}
        }
    }

    /// The engine's draw ends now (a phase end, the tank dry, the mission's end): a cavitation
    /// going on ends with it, in the phase that drew, at the last good state's pressure.
    fn end_draw(&mut self) {
        if self.margin_prev.take().is_some_and(|m| m < 0.0) {
            let pressure = self.last.derived.p_ullage_pa;
            self.record(self.t, EventKind::CavitationEnd, pressure, f64::NAN);
        }
    }

    /// Whether the slosh analog is inside its range at the end of a step of `dt_s` seconds
    /// (state `s`, evaluation `ev`, drive `d`); the time outside is accumulated.
    fn slosh_validity(&mut self, dt_s: f64, s: &State, ev: &Evaluation, d: &Drive) {
        let p = self.params;
        if p.fidelity == Fidelity::Homogeneous {
            return;
        }
        let x = &ev.derived;
        let a = (x.a_ax * x.a_ax + d.a_lat * d.a_lat).sqrt();
        let surface = p.fluid.surface_tension();
        let r = p.tank.radius_m();
        let lift = x.rho_bulk * a * r * r;
        // σ(T) ≤ σ₀ for a liquid above 0 K (the check before this ensures one), so lift/σ₀ ≤ the
        // Bond number as computed: where it clears the bound, σ's libm `pow` is not needed.
        let clears = lift / surface.sigma0_n_per_m >= SLOSH_BOND_MIN;
        let low_bond = !clears && lift / surface.sigma_n_per_m(x.t_layer_k) < SLOSH_BOND_MIN;
        let angle = slosh_angle(Group::one(p), s, &x.slosh)
            .abs()
            .max(mode2_angle(Group::one(p), s, &x.slosh));
        if low_bond || angle > SLOSH_ANGLE_MAX_RAD {
            self.tracker.summary.slosh_out_of_range = true;
            self.slosh_out_s += dt_s;
        }
    }

    /// The end of a fixed step (or of the part of one before the tank ran dry) from mission time
    /// `t0` to `t`, at state `s` with evaluation `ev` under drive `d`: extremes, time outside
    /// the slosh analog's range, and cavitation onset or end located linearly in the step.
    fn observe_end(&mut self, (t0, t): (f64, f64), s: &State, ev: &Evaluation, d: &Drive) {
        let p = self.params;
        self.tracker.observe(p, t, s, ev, d);
        self.slosh_validity(t - t0, s, ev, d);
        let margin = d.burning.then(|| cavitation_margin(p, s, &ev.derived).0);
        self.cavitation_events((t0, t), margin, ev.derived.p_ullage_pa, |_, _, before| {
            t0 + crossing(before, margin.unwrap_or(0.0), 0.0) * (t - t0)
        });
    }

    /// Outcomes of the step from the last good state (mission time `t0`) to state `s` with
    /// evaluation `ev` at `t1`: the pressurant running out (first time) and the tank running dry
    /// (drawn by the engine or boiled off), which ends the instance at that time (its history row
    /// to `history`). Returns true when it ran dry. `valid`: [`check_state`] found nothing in the
    /// end state; when it did, the liquid mass rate at the step's start, carried on, decides.
    fn outcomes(
        &mut self,
        (t0, t1): (f64, f64),
        (s, ev): (&State, &Evaluation),
        valid: bool,
        history: Option<&mut History>,
    ) -> bool {
        let p = self.params;
        let q = &mut self.tracker.summary;
        if let Some(pr) = p.pressurization.filter(|_| !q.pressurant_exhausted) {
            let empty = pr.bottle_mass_kg * (1.0 - PRESSURANT_EMPTY_FRACTION);
            if s[PRESS_IN] >= empty {
                // Already empty at the step start (a 0 kg supply): exhausted there, not a
                // step later (it was reported at the first step's end, 0.5 s into a mission).
                let th = if self.last_state[PRESS_IN] >= empty {
                    0.0
                } else {
                    crossing(self.last_state[PRESS_IN], s[PRESS_IN], empty)
                };
                let t = t0 + th * (t1 - t0);
                q.pressurant_exhausted = true;
                q.pressurant_exhausted_time_s = Some(t);
                let pressure = ev.derived.p_ullage_pa;
                self.record(t, EventKind::PressurantExhausted, pressure, empty);
            }
        }
        let q = &mut self.tracker.summary;
        let residual = self.m_liquid0 * DEPLETION_RESIDUAL_FRACTION;
        let m_before = self.last.derived.m_liquid_kg;
        // A fixed step that overdrew the liquid can end outside the model (its stages saw a
        // negative layer): then the step start's liquid mass rate, carried on, decides whether
        // and when it ran dry. The LH2 stage at 2 % fill under 0.1 s RK4 steps diverged 0.16 kg
        // before running dry on an end state of 1.5e296 kg and a NaN ullage energy.
        let m_liquid = if valid {
            ev.derived.m_liquid_kg
        } else {
            m_before + (t1 - t0) * (self.last.rates[M_S] + self.last.rates[M_B])
        };
        if m_liquid.is_nan() || m_liquid > residual {
            return false;
        }
        let th = crossing(m_before, m_liquid, residual);
        let t = t0 + th * (t1 - t0);
        q.depleted = true;
        q.depleted_time_s = Some(t);
        // The instance ends where it ran dry, on the state interpolated linearly to that time
        // (so the liquid left is the residual and the amounts drawn do not depend on the step:
        // LOX at 20 % fill drew 38 540 to 38 584 kg over the steps when it ended on the step's
        // start), observed like any step's end. A step that left the model ends on its start.
        let dry = valid
            .then(|| {
                let mut s_dry = self.last_state;
                for (v, b) in s_dry.iter_mut().zip(s) {
                    *v += th * (b - *v);
                }
                let d = self.drive(t - self.phase_start_s);
                let ev = model::evaluate(Group::one(p), &s_dry, &d, t1 - t0);
                self.evaluations += 1;
                (s_dry, ev, d)
            })
            .filter(|(s_dry, ev, _)| check_state(p, s_dry, &ev.derived).is_none());
        match dry {
            Some((s_dry, ev, d)) => {
                self.observe_end((t0, t), &s_dry, &ev, &d);
                self.record(t, EventKind::Depleted, ev.derived.p_ullage_pa, residual);
                if let Some(h) = history {
                    h.push(row(p, t, &s_dry, &ev, &d), &self.phase().name, self.valve);
                }
                self.last_state = s_dry;
                self.last = ev;
                self.t = t;
            }
            None => {
                let pressure = self.last.derived.p_ullage_pa;
                self.record(t, EventKind::Depleted, pressure, residual);
                self.t = t0;
            }
        }
        self.done = true;
        true
    }

    /// Book-keeping after a step to state `merged_state` with evaluation `merged_ev` (a bulk about
    /// to empty merges into them) under drive `d`: divergence, extremes, valve, phase change,
    /// history. Returns false when the instance diverged.
    ///
    /// `merged_state` and `merged_ev` are the caller's buffers, filled in place from the lane
    /// group's (no state and evaluation built and moved by value per lane and step).
    fn after_step(
        &mut self,
        merged_state: &mut State,
        merged_ev: &mut Evaluation,
        d: &Drive,
        mut history: Option<&mut History>,
    ) -> bool {
        let p = self.params;
        // From the phase start, not summed step by step: a phase of n steps ends at its
        // duration exactly (3000 sums of 0.02 s give 60.00000000000031).
        let t = self.phase_start_s + (self.k + 1) as f64 * self.dt;
        self.merged = self.merge_bulk(merged_state, merged_ev, (d, t), self.dt);
        let (s, ev) = (&*merged_state, &*merged_ev);
        self.steps += 1;
        self.t = t;
        let bad = check_state(p, s, &ev.derived);
        if self.outcomes(
            (t - self.dt, t),
            (s, ev),
            bad.is_none(),
            history.as_deref_mut(),
        ) {
            return true;
        }
        if let Some(reason) = bad {
            self.diverge(&reason, t, Some(*s));
            return false;
        }
        self.observe_end((t - self.dt, t), s, ev, d);
        let pressure = ev.derived.p_ullage_pa;
        let before = self.valve;
        self.valve = model::update_valve(Group::one(p), pressure, self.valve);
        self.tracker.summary.relief_cycles += u64::from(self.valve && !before);
        if self.valve != before {
            let kind = if self.valve {
                EventKind::ReliefOpen
            } else {
                EventKind::ReliefClose
            };
            self.record(t, kind, pressure, f64::NAN);
        }
        let tvs_before = self.tvs;
        self.switch_tvs(t, pressure);
        let phase_end = self.k + 1 == self.n;
        self.reuse = self.valve == before && self.tvs == tvs_before && !phase_end && !self.merged;
        if let Some(h) = history {
            let interval = self.campaign.output_interval_s;
            if t >= self.next_sample - 1.0e-9 * interval || phase_end {
                h.push(row(p, t, s, ev, d), &self.phase().name, self.valve);
                while self.next_sample <= t + 1.0e-9 * interval {
                    self.next_sample += interval;
                }
            }
        }
        self.last_state = *s;
        self.last = *ev;
        self.k += 1;
        if phase_end {
            if self.phase + 1 == self.campaign.phases.len() {
                self.done = true;
            } else {
                self.next_phase();
                self.phase_start_s = t;
                (self.k, (self.n, self.dt)) = (0, self.phase().steps());
            }
        }
        true
    }

    /// Move to the next phase from the last good state: the phase that ends is closed there and
    /// the next one starts there.
    fn next_phase(&mut self) {
        self.end_draw();
        let pressure = self.last.derived.p_ullage_pa;
        self.record(self.t, EventKind::PhaseEnd, pressure, f64::NAN);
        let (s, x) = (&self.last_state, &self.last.derived);
        self.tracker.close_phase(self.params, s, x.m_vapor_kg);
        // An excited phase bounds its first adaptive step by the last evaluation's slosh
        // frequency (`adaptive`, `max_step`); that evaluation left the modes out if this phase
        // did and the analog rested, so they are evaluated now at the same state and drive.
        let next_excited = self.campaign.phases[self.phase + 1].excitation != Excitation::None;
        let mut d = self.drive(self.t - self.phase_start_s);
        if next_excited && d.slosh_modes_unread {
            d.slosh_modes_unread = false;
            let x = model::derive::derive(Group::one(self.params), &self.last_state, &d);
            self.last.derived.slosh = x.slosh;
        }
        self.phase += 1;
        let name = &self.campaign.phases[self.phase].name;
        self.tracker.enter_phase(name, self.params, s, &self.last);
        // The new phase may switch the TVS off, or let it start above its band.
        self.switch_tvs(self.t, pressure);
    }

    fn finish(mut self) -> Summary {
        let p = self.params;
        let m_vapor0 = initial_vapor_mass(p, &self.s0);
        let end = self.diverged_state.unwrap_or(self.last_state);
        self.tracker
            .close_phase(p, &end, self.last.derived.m_vapor_kg);
        self.end_draw();
        let pressure = self.last.derived.p_ullage_pa;
        self.record(self.t, EventKind::PhaseEnd, pressure, f64::NAN);
        let mut q = self.tracker.summary;
        q.events = self.events.map(|log| log.events).unwrap_or_default();
        q.rejected_steps = self.rejected;
        q.rhs_evaluations = self.evaluations;
        q.slosh_out_of_range_fraction = if self.t > 0.0 {
            self.slosh_out_s / self.t
        } else {
            0.0
        };
        finish_summary(
            q,
            p,
            &self.s0,
            m_vapor0,
            self.t,
            &end,
            &self.last.derived,
            self.steps,
        )
    }
}

/// Integrate the lane group `members` (one per lane of `T`, mutually
/// [`Params::lane_compatible`]) in lockstep over their phase lists with the campaign's
/// integrator; history rows of the first lane go to `history`. Lanes may differ in phase
/// durations and steps: each advances through its own phases, and a finished or diverged lane
/// is frozen until the last one ends.
fn integrate<T: Real>(
    members: &[(&Campaign, &Params)],
    mut history: Option<&mut History>,
) -> Vec<Summary> {
    let lanes = match members[0].0.stepping.integrator {
        Integrator::Dopri5 => adaptive::integrate::<T>(members, history),
        Integrator::Rk4 => {
            assert_eq!(members.len(), T::LANES, "one member per lane");
            let params: Vec<Params> = members.iter().map(|m| *m.1).collect();
            let mut lanes: Vec<LaneRun> =
                members.iter().map(|&(c, p)| LaneRun::start(c, p)).collect();
            if let Some(h) = history.as_deref_mut() {
                lanes[0].history_start(h);
            }
            integrate_fixed::<T>(Group::of(&params), lanes, history)
        }
    };
    lanes.into_iter().map(LaneRun::finish).collect()
}

/// Fixed-step RK4 over each lane's phase steps (`Phase::steps`).
fn integrate_fixed<'a, T: Real>(
    g: Group<'_>,
    mut lanes: Vec<LaneRun<'a>>,
    mut history: Option<&mut History>,
) -> Vec<LaneRun<'a>> {
    let mut s: State<T> = std::array::from_fn(|j| T::from_fn(|i| lanes[i].s0[j]));
    let n = model::used_slots(g);
    // The group's evaluation at the end of the last step, evaluated in place: the next step's
    // k1 where every lane may reuse it.
    let mut ev = Evaluation::<T>::default();
    let mut work = model::Rk4Work::default();
    // One lane's end state and evaluation, handed to `after_step`; their slots past `n` stay 0.
    let (mut lane_state, mut lane_ev): (State, Evaluation) = ([0.0; NS], Evaluation::default());
    let mut have_k1 = false;
    while lanes.iter().any(|l| !l.done) {
        let dt = T::from_fn(|i| lanes[i].dt);
        let tp = T::from_fn(|i| lanes[i].k as f64) * dt;
        // Without an excitation a lane's drive does not depend on time within its phase (the
        // switches are held over the step): gathered once for the step's stages and its end,
        // the same values as per stage (one gather of every lane's drive a step, not three, or
        // four where k1 is not reused; a group with an excited lane gathers per stage as before).
        let steady = lanes
            .iter()
            .all(|l| l.phase().excitation == Excitation::None);
        let held: Option<Drive<T>> = steady.then(|| Drive::gather(|i| lanes[i].drive(0.0)));
        let drive = |tt: T| held.unwrap_or_else(|| Drive::gather(|i| lanes[i].drive(tt.lane(i))));
        let reuse = lanes.iter().all(|l| l.done || l.reuse);
        let k1 = (have_k1 && reuse).then_some(&ev.rates);
        let active = T::Mask::from_fn(|i| !lanes[i].done);
        if active.all() {
            // The usual case: every lane steps, in place (no copy of the group's state).
            model::rk4_step_in(g, drive, &mut s, tp, dt, k1, &mut work);
        } else {
            let mut next = s;
            model::rk4_step_in(g, drive, &mut next, tp, dt, k1, &mut work);
            for (sj, nj) in s[..n].iter_mut().zip(&next[..n]) {
                *sj = T::select(active, *nj, *sj);
            }
        }
        let d: Drive<T> = held.unwrap_or_else(|| {
            Drive::gather(|i| lanes[i].drive((lanes[i].k + 1) as f64 * lanes[i].dt))
        });
        model::evaluate_into(g, &s, &d, dt, &mut ev);
        let mut diverged = T::Mask::splat(false);
        for (i, l) in lanes.iter_mut().enumerate() {
            if l.done {
                continue;
            }
            l.evaluations += if l.reuse { 4 } else { 5 };
            let h = if i == 0 { history.as_deref_mut() } else { None };
            state::lane_into(&s, i, n, &mut lane_state);
            ev.lane_into(i, n, &mut lane_ev);
            if !l.after_step(&mut lane_state, &mut lane_ev, &d.lane(i), h) {
                diverged = diverged | T::Mask::from_fn(|j| j == i);
            }
        }
        // A diverged lane goes on from its last good state, so that no NaN slows the others; a
        // lane whose bulk merged goes on from the merged state.
        let stale = diverged | T::Mask::from_fn(|i| lanes[i].merged);
        if stale.any() {
            let good: State<T> = std::array::from_fn(|j| T::from_fn(|i| lanes[i].last_state[j]));
            for (sj, gj) in s.iter_mut().zip(good) {
                *sj = T::select(stale, gj, *sj);
            }
        }
        have_k1 = true;
    }
    lanes
}

/// Integrate one instance with parameters `p` over the campaign's phases. With `history`,
/// rows are recorded every `output_interval_s` and at every phase end.
pub fn simulate(c: &Campaign, p: &Params, history: Option<&mut History>) -> Summary {
    integrate::<f64>(&[(c, p)], history).remove(0)
}

/// Integrate `members` (any number, mutually [`Params::lane_compatible`]) in lockstep
/// [`Lanes`]: the summaries, in member order, equal those of [`simulate`] on each instance, bit
/// for bit. Fixed-step RK4 integrates them in groups of [`crate::lanes::WIDTH`] (the last one
/// padded with the first member, whose copies are dropped); Dormand–Prince in one group whose
/// lanes take the next member as theirs end ([`adaptive::integrate`]).
pub fn simulate_lanes(members: &[(&Campaign, &Params)]) -> Vec<Summary> {
    match members.first().map(|m| m.0.stepping.integrator) {
        None => Vec::new(),
        Some(Integrator::Dopri5) => integrate::<Lanes>(members, None),
        Some(Integrator::Rk4) => members
            .chunks(WIDTH)
            .flat_map(|chunk| {
                let padded: Vec<_> = (0..WIDTH)
                    .map(|k| *chunk.get(k).unwrap_or(&chunk[0]))
                    .collect();
                let mut summaries = integrate::<Lanes>(&padded, None);
                summaries.truncate(chunk.len());
                summaries
            })
            .collect(),
    }
}
