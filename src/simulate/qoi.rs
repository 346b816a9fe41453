//! Quantities of interest of one instance (MODEL.md §11): the whole-mission [`Summary`], one
//! [`PhaseSummary`] per phase reached, the running [`Tracker`] that fills them after every step,
//! and the text `simulate` prints.

use super::{cavitation_margin, energy_scale};
use crate::model::derive::{slosh_angle, Derived, Drive};
use crate::model::params::Params;
use crate::model::state::*;
use crate::model::{Evaluation, Group};

/// Quantities of interest of one instance (MODEL.md §11).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Summary {
    pub peak_pressure_pa: f64,
    pub peak_pressure_time_s: f64,
    pub min_pressure_pa: f64,
    pub min_pressure_time_s: f64,
    /// Net mass evaporated at the interface, kg.
    pub boiloff_kg: f64,
    pub vented_kg: f64,
    pub vented_vapor_kg: f64,
    pub vented_helium_kg: f64,
    pub pressurant_used_kg: f64,
    pub propellant_drawn_kg: f64,
    /// Smallest cavitation margin NPSH_a − NPSH_r while the engine drew, m (None: never drew).
    pub min_cavitation_margin_m: Option<f64>,
    pub min_cavitation_margin_pa: Option<f64>,
    pub min_cavitation_margin_time_s: Option<f64>,
    pub cavitation: bool,
    pub overpressure: bool,
    pub max_slosh_angle_rad: f64,
    pub peak_slosh_force_n: f64,
    pub peak_slosh_moment_n_m: f64,
    /// T_s − T_b at the end, K.
    pub final_stratification_k: f64,
    pub final_pressure_pa: f64,
    pub diverged: bool,
    /// Relief-valve openings (closed → open switches).
    pub relief_cycles: u64,
    /// Propellant the thermodynamic vent system vented, kg (0 without `[tvs]`).
    pub tvs_vented_kg: f64,
    /// Thermodynamic-vent-system starts (off → on switches).
    pub tvs_cycles: u64,
    /// The pressurant bottle reached its last [`PRESSURANT_EMPTY_FRACTION`], and when, s.
    pub pressurant_exhausted: bool,
    pub pressurant_exhausted_time_s: Option<f64>,
    /// The tank ran dry, drawn by the engine or boiled off: the liquid fell to
    /// [`DEPLETION_RESIDUAL_FRACTION`] of its initial mass. An outcome, not a divergence: the
    /// instance ends there.
    pub depleted: bool,
    pub depleted_time_s: Option<f64>,
    /// The slosh analog left its range at some step end (Bond number below [`SLOSH_BOND_MIN`]
    /// or pendulum angle beyond [`SLOSH_ANGLE_MAX_RAD`]), and the share of the mission it spent
    /// there. Always false at the homogeneous level (no analog).
    pub slosh_out_of_range: bool,
    pub slosh_out_of_range_fraction: f64,
    /// What left which range, and when (None unless diverged).
    pub diverged_reason: Option<String>,
    pub final_time_s: f64,
    /// Accepted steps.
    pub steps: u64,
    /// Steps the error control rejected and retried shorter (0 under fixed-step RK4).
    pub rejected_steps: u64,
    /// Right-hand-side evaluations this instance cost (stages, probes, event location).
    pub rhs_evaluations: u64,
    /// |Δ mass invariant| / initial mass.
    pub mass_error_rel: f64,
    /// |Δ energy invariant| / energy scale (see [`super::energy_scale`]).
    pub energy_error_rel: f64,
    /// One entry per phase the instance entered, in phase order (shorter than the phase list
    /// when it ran dry or diverged early).
    pub phases: Vec<PhaseSummary>,
    /// The located events, in time order, when the campaign records them
    /// ([`crate::campaign::Campaign::record_events`]); empty otherwise.
    pub events: Vec<super::events::Event>,
}

/// Quantities of interest of one phase: extremes over the phase's step ends (and, under
/// `dopri5`, the extremes located between them), its start state included; the amounts are
/// differences of the cumulative ones between the phase's start and its end (or the instance's
/// end when it stopped inside the phase).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PhaseSummary {
    /// The phase's name (`phases.N.name`).
    pub name: String,
    /// Ullage pressure when the phase started, Pa.
    pub start_pressure_pa: f64,
    pub peak_pressure_pa: f64,
    pub min_pressure_pa: f64,
    /// Net mass evaporated during the phase (vapour gained plus vapour vented), kg.
    pub boiloff_kg: f64,
    /// Mass vented during the phase (vapour and helium), kg.
    pub vented_kg: f64,
    /// Bulk liquid the thermodynamic vent system vented during the phase, kg.
    pub tvs_vented_kg: f64,
    /// Smallest cavitation margin while the engine drew in this phase, m (None: no draw).
    pub min_cavitation_margin_m: Option<f64>,
    pub max_slosh_angle_rad: f64,
    /// The cumulative amounts at the phase start (the phase's amounts are differences).
    start_amounts: Amounts,
}

/// Cumulative amounts of a state since the mission's start, kg ([`cumulative`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Amounts {
    /// Net mass evaporated (vapour gained plus vapour vented, pressurant vapour excluded).
    pub boiloff_kg: f64,
    /// Vapour and helium through the relief valve.
    pub vented_kg: f64,
    /// Bulk liquid through the thermodynamic vent system.
    pub tvs_vented_kg: f64,
}

impl PhaseSummary {
    /// Phase `name` starting at ullage pressure `pressure_pa` with the cumulative amounts
    /// `start` of [`cumulative`] at its start.
    pub fn start(name: &str, pressure_pa: f64, start: Amounts) -> Self {
        PhaseSummary {
            name: name.to_string(),
            start_pressure_pa: pressure_pa,
            peak_pressure_pa: pressure_pa,
            min_pressure_pa: pressure_pa,
            start_amounts: start,
            ..Default::default()
        }
    }

    /// Close the phase at the cumulative amounts `end` of its end (or of the instance's end
    /// inside it).
    pub fn close(&mut self, end: Amounts) {
        let s = self.start_amounts;
        self.boiloff_kg = end.boiloff_kg - s.boiloff_kg;
        self.vented_kg = end.vented_kg - s.vented_kg;
        self.tvs_vented_kg = end.tvs_vented_kg - s.tvs_vented_kg;
    }

    /// Highest pressure in the phase above its start pressure, Pa (0 when it only fell).
    pub fn pressure_rise_pa(&self) -> f64 {
        self.peak_pressure_pa - self.start_pressure_pa
    }
}

/// Cumulative boil-off, relief-vented mass (vapour and helium) and TVS-vented mass of state `s`
/// with vapour mass `m_vapor_kg`, counted from the initial vapour mass `m_vapor0`, kg: the
/// definitions of [`finish_summary`], so that the phases' amounts add up to the mission's.
/// Boil-off is the vapour the liquid made: autogenous pressurant vapour (`p`'s) is not counted.
pub fn cumulative(p: &Params, s: &State, m_vapor_kg: f64, m_vapor0: f64) -> Amounts {
    Amounts {
        boiloff_kg: m_vapor_kg - m_vapor0 + s[VENT_V] - vapor_pressurant_kg(p, s),
        vented_kg: s[VENT_V] + s[VENT_G],
        tvs_vented_kg: s[VENT_TVS],
    }
}

impl Summary {
    /// The summary with its rejected steps and right-hand-side evaluations set (a backend that
    /// counts them itself).
    pub fn with_costs(self, rejected_steps: u64, rhs_evaluations: u64) -> Summary {
        Summary {
            rejected_steps,
            rhs_evaluations,
            ..self
        }
    }

    /// Why the instance diverged, or `None` when it did not (the `cryoslosh.diverged` of its
    /// history).
    pub fn divergence(&self) -> Option<&str> {
        self.diverged
            .then(|| self.diverged_reason.as_deref().unwrap_or(""))
    }
}

/// Bond number ρ_l |a| R² / σ below which surface tension, not the body force, shapes the free
/// surface and the SP-106 analog no longer holds (low-gravity regime, Abramson NASA SP-106
/// ch. 11 and Dodge 2000: capillary effects dominate as Bo falls towards 1–10).
pub const SLOSH_BOND_MIN: f64 = 10.0;
/// Pendulum angle beyond which the linear SP-106 parameters no longer describe the motion (the
/// analog's masses and lengths come from linear potential flow), rad.
pub const SLOSH_ANGLE_MAX_RAD: f64 = 0.5;

/// Relative difference below which two pressure peaks are the same peak (CPU, f64).
const PEAK_TIE_REL: f64 = 1.0e-9;

/// Share of the initial liquid left when the tank counts as dry (defined beside the model,
/// whose campaign checks use it too).
pub use crate::model::DEPLETION_RESIDUAL_FRACTION;
/// Share of the bottle left when the pressurant counts as exhausted: the flow fades to zero over
/// it (`model::boundary::boundary_flows`).
pub const PRESSURANT_EMPTY_FRACTION: f64 = 1.0e-3;

/// Running extremes of one instance (MODEL.md §11), updated after every step.
pub(super) struct Tracker {
    pub(super) summary: Summary,
    /// Vapour mass of the initial state, kg (boil-off is counted from it).
    m_vapor0: f64,
}

impl Tracker {
    /// A tracker for an instance whose initial vapour mass is `m_vapor0`, kg.
    pub(super) fn new(m_vapor0: f64) -> Tracker {
        Tracker {
            summary: Summary {
                peak_pressure_pa: f64::NEG_INFINITY,
                min_pressure_pa: f64::INFINITY,
                ..Default::default()
            },
            m_vapor0,
        }
    }

    /// Phase `name` starts at state `s` with evaluation `ev`: its start values are recorded,
    /// and the start state is its first observation (pressure and slosh angle).
    pub(super) fn enter_phase(&mut self, name: &str, p: &Params, s: &State, ev: &Evaluation) {
        let x = &ev.derived;
        let mut phase = PhaseSummary::start(
            name,
            x.p_ullage_pa,
            cumulative(p, s, x.m_vapor_kg, self.m_vapor0),
        );
        phase.max_slosh_angle_rad = slosh_angle(Group::one(p), s, &x.slosh).abs();
        self.summary.phases.push(phase);
    }

    /// Close the current phase at state `s` with vapour mass `m_vapor_kg` (its end, or the
    /// instance's end inside it).
    pub(super) fn close_phase(&mut self, p: &Params, s: &State, m_vapor_kg: f64) {
        let end = cumulative(p, s, m_vapor_kg, self.m_vapor0);
        if let Some(ph) = self.summary.phases.last_mut() {
            ph.close(end);
        }
    }

    pub(super) fn observe(&mut self, p: &Params, t: f64, s: &State, ev: &Evaluation, d: &Drive) {
        let x = &ev.derived;
        let q = &mut self.summary;
        let pu = x.p_ullage_pa;
        if pu > q.peak_pressure_pa {
            // A relief valve caps the pressure at its crack every cycle: a later peak within
            // rounding of the first is the same peak, and its time is when it was first reached.
            if pu > q.peak_pressure_pa + PEAK_TIE_REL * q.peak_pressure_pa.abs() {
                q.peak_pressure_time_s = t;
            }
            q.peak_pressure_pa = pu;
        }
        if pu < q.min_pressure_pa {
            q.min_pressure_pa = pu;
            q.min_pressure_time_s = t;
        }
        let margin = d.burning.then(|| cavitation_margin(p, s, x));
        if let Some((m, m_pa)) = margin {
            if q.min_cavitation_margin_m.is_none_or(|old| m < old) {
                q.min_cavitation_margin_m = Some(m);
                q.min_cavitation_margin_pa = Some(m_pa);
                q.min_cavitation_margin_time_s = Some(t);
            }
        }
        let angle = slosh_angle(Group::one(p), s, &x.slosh).abs();
        q.max_slosh_angle_rad = q.max_slosh_angle_rad.max(angle);
        if let Some(ph) = q.phases.last_mut() {
            ph.peak_pressure_pa = ph.peak_pressure_pa.max(pu);
            ph.min_pressure_pa = ph.min_pressure_pa.min(pu);
            ph.max_slosh_angle_rad = ph.max_slosh_angle_rad.max(angle);
            if let Some((m, _)) = margin {
                ph.min_cavitation_margin_m =
                    Some(ph.min_cavitation_margin_m.map_or(m, |o| o.min(m)));
            }
        }
        let force = ev.fluxes.slosh_force_n.abs();
        q.peak_slosh_force_n = q.peak_slosh_force_n.max(force);
        q.peak_slosh_moment_n_m = q
            .peak_slosh_moment_n_m
            .max(force * p.vehicle.slosh_lever_arm_m.abs());
    }
}

/// Complete the running extremes in `q` with the end-of-run quantities: final state `s` at time
/// `t` after `steps` steps from `s0` (initial vapour mass `m_vapor0`), its derived quantities `x`
/// (temperatures, vapour mass, pressure). Shared by every backend so that flags and closures are
/// computed one way.
#[expect(
    clippy::too_many_arguments,
    reason = "the end-of-run facts, each named"
)]
pub fn finish_summary(
    mut q: Summary,
    p: &Params,
    s0: &State,
    m_vapor0: f64,
    t: f64,
    s: &State,
    x: &Derived,
    steps: u64,
) -> Summary {
    q.final_time_s = t;
    q.steps = steps;
    q.vented_vapor_kg = s[VENT_V];
    q.tvs_vented_kg = s[VENT_TVS];
    q.vented_helium_kg = s[VENT_G];
    q.vented_kg = s[VENT_V] + s[VENT_G];
    q.pressurant_used_kg = s[PRESS_IN];
    q.propellant_drawn_kg = s[OUT];
    q.boiloff_kg = cumulative(p, s, x.m_vapor_kg, m_vapor0).boiloff_kg;
    q.final_stratification_k = x.t_layer_k - x.t_bulk_k;
    q.final_pressure_pa = x.p_ullage_pa;
    q.cavitation = q.min_cavitation_margin_m.is_some_and(|m| m < 0.0);
    q.overpressure = q.peak_pressure_pa > p.meop_pa;
    let m0 = mass_invariant(s0);
    q.mass_error_rel = (mass_invariant(s) - m0).abs() / m0.abs();
    q.energy_error_rel = (energy_invariant(s) - energy_invariant(s0)).abs() / energy_scale(s0, s);
    q
}

/// A short summary a designer reads at a glance.
pub fn describe_summary(q: &Summary) -> String {
    let margin = q.min_cavitation_margin_m.map_or_else(
        || "n/a (engine never drew)".to_string(),
        |m| {
            format!(
                "{m:.3} m at t = {:.1} s",
                q.min_cavitation_margin_time_s.unwrap_or(0.0)
            )
        },
    );
    format!(
        "peak pressure {:.1} Pa at t = {:.1} s (min {:.1} Pa){}\nboil-off {:.4} kg, vented {:.4} kg, pressurant used {:.4} kg, drawn {:.2} kg\nmin cavitation margin {}{}\nmax slosh angle {:.4} rad, peak slosh force {:.2} N\nfinal stratification {:.4} K, final pressure {:.1} Pa\nclosure: mass {:.2e}, energy {:.2e}{}",
        q.peak_pressure_pa,
        q.peak_pressure_time_s,
        q.min_pressure_pa,
        if q.overpressure { " — OVERPRESSURE (above MEOP)" } else { "" },
        q.boiloff_kg,
        q.vented_kg,
        q.pressurant_used_kg,
        q.propellant_drawn_kg,
        margin,
        if q.cavitation { " — CAVITATION" } else { "" },
        q.max_slosh_angle_rad,
        q.peak_slosh_force_n,
        q.final_stratification_k,
        q.final_pressure_pa,
        q.mass_error_rel,
        q.energy_error_rel,
        if q.diverged { " — DIVERGED" } else { "" },
    ) + &outcomes_text(q)
        + &phases_text(q)
        + &events_text(q)
}

/// The located events, one per line, when the instance recorded them.
fn events_text(q: &Summary) -> String {
    let names: Vec<String> = q.phases.iter().map(|ph| ph.name.clone()).collect();
    let text = super::events::describe_events(&q.events, &names);
    if text.is_empty() {
        text
    } else {
        format!("\n{text}")
    }
}

/// One line per phase entered: its extremes and amounts (the `<qoi>.<phase>` columns); a TVS
/// column when the thermodynamic vent system vented.
fn phases_text(q: &Summary) -> String {
    if q.phases.len() < 2 {
        return String::new();
    }
    let width = q.phases.iter().map(|ph| ph.name.len()).max().unwrap_or(0);
    let tvs = q.tvs_vented_kg != 0.0;
    let mut o = format!(
        "\nper phase: {:width$}  {:>12} {:>12} {:>11} {:>11} {:>11} {:>9}",
        "", "peak Pa", "rise Pa", "boil-off kg", "vented kg", "min NPSH m", "slosh rad"
    );
    if tvs {
        o += &format!(" {:>11}", "TVS kg");
    }
    for ph in &q.phases {
        let margin = ph
            .min_cavitation_margin_m
            .map_or_else(|| "-".to_string(), |m| format!("{m:.3}"));
        o += &format!(
            "\n           {:width$}  {:>12.1} {:>12.1} {:>11.4} {:>11.4} {:>11} {:>9.4}",
            ph.name,
            ph.peak_pressure_pa,
            ph.pressure_rise_pa(),
            ph.boiloff_kg,
            ph.vented_kg,
            margin,
            ph.max_slosh_angle_rad
        );
        if tvs {
            o += &format!(" {:>11.4}", ph.tvs_vented_kg);
        }
    }
    o
}

/// The outcome lines of a summary: relief cycles, pressurant exhaustion, depletion.
fn outcomes_text(q: &Summary) -> String {
    let mut o = String::new();
    if q.relief_cycles > 0 {
        o += &format!("\nrelief valve opened {} times", q.relief_cycles);
    }
    if q.tvs_cycles > 0 || q.tvs_vented_kg > 0.0 {
        o += &format!(
            "\nthermodynamic vent system started {} times, vented {:.4} kg",
            q.tvs_cycles, q.tvs_vented_kg
        );
    }
    if q.slosh_out_of_range {
        o += &format!(
            "\nslosh analog out of range for {:.1} % of the mission (Bond number below {SLOSH_BOND_MIN} or angle beyond {SLOSH_ANGLE_MAX_RAD} rad)",
            100.0 * q.slosh_out_of_range_fraction
        );
    }
    if let Some(t) = q.pressurant_exhausted_time_s {
        o += &format!("\npressurant exhausted at t = {t:.1} s");
    }
    if let Some(t) = q.depleted_time_s {
        o += &format!("\nDEPLETED: the tank ran dry at t = {t:.3} s (the instance ends there)");
    }
    o
}
