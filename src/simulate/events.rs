//! Discrete events of one instance, located in time (issue 11): relief-valve openings and
//! closings, thermodynamic-vent-system starts and stops, the pressurant bottle running out,
//! the bulk node merging into the layer, the tank
//! running dry, cavitation onset and end, phase ends. Recorded when the campaign asks
//! ([`crate::campaign::Campaign::record_events`], set by `run --events` and `simulate`), written
//! to `events.parquet` and printed by `simulate`.

/// What happened. The names are the `kind` column of `events.parquet`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EventKind {
    /// The relief valve cracked open (the ullage pressure reached the crack pressure).
    ReliefOpen,
    /// The relief valve reseated.
    ReliefClose,
    /// The thermodynamic vent system started (the pressure reached its band's upper end, or a
    /// phase that lets it run began above it).
    TvsOn,
    /// The thermodynamic vent system stopped (the band's lower end, or a phase that switches
    /// it off).
    TvsOff,
    /// The pressurant bottle reached its last `PRESSURANT_EMPTY_FRACTION`.
    PressurantExhausted,
    /// The bulk node emptied into the warm layer (`model::merge_empty_bulk`).
    BulkMerged,
    /// The tank ran dry (`DEPLETION_RESIDUAL_FRACTION` of the initial liquid left).
    Depleted,
    /// The cavitation margin NPSH_a − NPSH_r fell below zero while the engine drew.
    CavitationOnset,
    /// The cavitation margin rose back to zero while the engine drew.
    CavitationEnd,
    /// A phase ended (its last step, or the instance ending inside it).
    PhaseEnd,
    /// More than [`MAX_EVENTS`] events: the rest were not recorded.
    Truncated,
}

impl EventKind {
    /// The `kind` column's value.
    pub fn name(self) -> &'static str {
        match self {
            EventKind::ReliefOpen => "relief_open",
            EventKind::ReliefClose => "relief_close",
            EventKind::TvsOn => "tvs_on",
            EventKind::TvsOff => "tvs_off",
            EventKind::PressurantExhausted => "pressurant_exhausted",
            EventKind::BulkMerged => "bulk_merged",
            EventKind::Depleted => "depleted",
            EventKind::CavitationOnset => "cavitation_onset",
            EventKind::CavitationEnd => "cavitation_end",
            EventKind::PhaseEnd => "phase_end",
            EventKind::Truncated => "truncated",
        }
    }
}

/// One event: when, in which phase (index into the campaign's phases), what, the ullage pressure
/// then (Pa) and a kind-specific value ([`EventKind`]: the liquid mass left in kg for
/// `depleted` and `bulk_merged`, the pressurant used in kg for `pressurant_exhausted`, NaN
/// (null) otherwise).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Event {
    pub time_s: f64,
    pub phase: usize,
    pub kind: EventKind,
    pub pressure_pa: f64,
    pub value: f64,
}

/// Most events recorded per instance: a valve chattering every step of a long coast must not
/// fill memory. Past it one [`EventKind::Truncated`] event says so.
pub const MAX_EVENTS: usize = 10_000;

/// The events of one instance, in time order, bounded by [`MAX_EVENTS`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EventLog {
    pub events: Vec<Event>,
}

impl EventLog {
    /// Record `kind` at `time_s` in phase `phase` with ullage pressure `pressure_pa` and the
    /// kind's `value`.
    pub fn push(
        &mut self,
        time_s: f64,
        phase: usize,
        kind: EventKind,
        pressure_pa: f64,
        value: f64,
    ) {
        let n = self.events.len();
        if n > MAX_EVENTS {
            return;
        }
        let kind = if n == MAX_EVENTS {
            EventKind::Truncated
        } else {
            kind
        };
        self.events.push(Event {
            time_s,
            phase,
            kind,
            pressure_pa,
            value,
        });
    }
}

/// The events as `simulate` prints them, one per line with the phase names `phases`.
pub fn describe_events(events: &[Event], phases: &[String]) -> String {
    let mut o = String::new();
    for e in events {
        let phase = phases.get(e.phase).map_or("?", String::as_str);
        o += &format!(
            "\n  t = {:>12.3} s  {:<10} {:<20} p = {:.1} Pa",
            e.time_s,
            phase,
            e.kind.name(),
            e.pressure_pa
        );
        if e.value.is_finite() {
            o += &format!(", {:.4} kg", e.value);
        }
    }
    if o.is_empty() {
        o
    } else {
        format!("events:{o}")
    }
}
