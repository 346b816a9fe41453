//! `[[phases]]`: each phase's kind, duration, steps, environment and excitation, and the rules
//! on phase names (they label per-phase columns and address phases in key paths).

use super::{number, Checker, MAX_STEPS_PER_PHASE, MIN_DT_S};
use crate::campaign::raw::*;
use crate::campaign::CampaignError;
use crate::model::flight::{Environment, Excitation, Phase, PhaseKind, G0};
use std::path::Path;
/// Longest phase name: it becomes part of column names and of the report's file names.
pub const MAX_PHASE_NAME_LEN: usize = 64;

/// Phase names label the per-phase QoI columns (`peak_pressure_pa.burn`) and address phases in
/// key paths (`phases.burn.thrust_n`): each must be unique ignoring case (DuckDB's column names
/// and some file systems ignore it), made of at most [`MAX_PHASE_NAME_LEN`] letters, digits, `_`
/// and `-`, and not a number (a number is an index). An unnamed phase's default name (its kind
/// and index, `coast1`) counts too.
pub(super) fn phase_names(c: &Checker, phases: &[Phase]) -> Result<(), CampaignError> {
    for (i, ph) in phases.iter().enumerate() {
        let key = format!("phases.{i}.name");
        let name = &ph.name;
        let word = name
            .chars()
            .all(|ch| ch.is_ascii_alphanumeric() || ch == '_' || ch == '-');
        if name.is_empty()
            || name.len() > MAX_PHASE_NAME_LEN
            || !word
            || name.parse::<f64>().is_ok()
        {
            return Err(c.err(
                &key,
                format!("{name:?}"),
                format!(
                    "a name of 1 to {MAX_PHASE_NAME_LEN} ASCII letters, digits, '_' and '-' that is not a number"
                ),
            ));
        }
        if let Some(j) = phases[..i]
            .iter()
            .position(|o| o.name.eq_ignore_ascii_case(name))
        {
            return Err(c.err(
                &key,
                format!("{name:?}"),
                format!(
                    "a name no other phase has, ignoring case (phases.{j} is {:?}; an unnamed phase is called by its kind and index)",
                    phases[j].name
                ),
            ));
        }
    }
    Ok(())
}

pub(super) fn phase(
    c: &Checker,
    i: usize,
    ph: &RawPhase,
    dt_default: f64,
    max_step_default: f64,
    dir: &Path,
) -> Result<Phase, CampaignError> {
    let key = |k: &str| format!("phases.{i}.{k}");
    let kind = match ph.kind.as_str() {
        "hold" => PhaseKind::Hold,
        "burn" => PhaseKind::Burn,
        "coast" => PhaseKind::Coast,
        other => return Err(c.err(&key("kind"), other, "hold | burn | coast")),
    };
    let duration = c.positive(&key("duration_s"), ph.duration_s, 1.0e9)?;
    let dt = c.range(
        &key("dt_s"),
        ph.dt_s.unwrap_or(dt_default),
        MIN_DT_S,
        3600.0,
    )?;
    let steps = (duration / dt).ceil();
    if steps > MAX_STEPS_PER_PHASE {
        return Err(c.err(
            &key("dt_s"),
            number(dt),
            format!(
                "a step giving at most {} steps over the phase's {} s (this one gives {})",
                number(MAX_STEPS_PER_PHASE),
                number(duration),
                number(steps)
            ),
        ));
    }
    let thrust = match kind {
        PhaseKind::Burn => c.positive(&key("thrust_n"), ph.thrust_n.unwrap_or(f64::NAN), 1.0e9)?,
        _ => c.range(&key("thrust_n"), ph.thrust_n.unwrap_or(0.0), 0.0, 0.0)?,
    };
    let gravity_default = match kind {
        PhaseKind::Hold => G0,
        PhaseKind::Burn => 0.0,
        PhaseKind::Coast => 1.0e-4,
    };
    let gravity = c.opt_range(
        &key("gravity_m_s2"),
        ph.gravity_m_s2,
        gravity_default,
        0.0,
        1000.0,
    )?;
    let gamma = c.opt_range(
        &key("flight_path_angle_deg"),
        ph.flight_path_angle_deg,
        90.0,
        -90.0,
        90.0,
    )?;
    let environment = match ph.environment.as_deref() {
        None => Environment::of_kind(kind),
        Some("ground") => Environment::Ground,
        Some("space") => Environment::Space,
        Some(other) => return Err(c.err(&key("environment"), other, "ground | space")),
    };
    let excitation = match &ph.excitation {
        None => Excitation::None,
        Some(e) => excitation(c, &format!("phases.{i}.excitation"), e, dir)?,
    };
    Ok(Phase {
        name: ph
            .name
            .clone()
            .unwrap_or_else(|| format!("{}{}", kind.name(), i)),
        kind,
        duration_s: duration,
        dt_s: dt,
        max_step_s: ph
            .max_step_s
            .map(|v| c.range(&key("max_step_s"), v, 1.0e-5, 1.0e6))
            .transpose()?
            .unwrap_or(max_step_default),
        thrust_n: thrust,
        flight_path_angle_rad: gamma.to_radians(),
        gravity_m_s2: gravity,
        excitation,
        pressurize: ph.pressurize.unwrap_or(true),
        environment,
        mixer: ph.mixer.unwrap_or(true),
        tvs: ph.tvs.unwrap_or(true),
    })
}

fn excitation(
    c: &Checker,
    base: &str,
    e: &RawExcitation,
    dir: &Path,
) -> Result<Excitation, CampaignError> {
    let key = |k: &str| format!("{base}.{k}");
    const KINDS: [&str; 7] = ["none", "step", "ramp", "sine", "sweep", "gust", "table"];
    if !KINDS.contains(&e.kind.as_str()) {
        return Err(c.err(&key("kind"), format!("{:?}", e.kind), KINDS.join(" | ")));
    }
    // A parameter the kind does not use is an error, not silently ignored (a gust's
    // frequency_hz, a table's amplitude).
    let takes: &[&str] = match e.kind.as_str() {
        "step" => &["amplitude_m_s2", "start_s"],
        "ramp" | "gust" => &["amplitude_m_s2", "start_s", "duration_s"],
        "sine" => &["amplitude_m_s2", "frequency_hz", "phase_rad"],
        "sweep" => &["amplitude_m_s2", "f_start_hz", "f_end_hz", "duration_s"],
        "table" => &["file"],
        _ => &[],
    };
    let set = [
        ("amplitude_m_s2", e.amplitude_m_s2.is_some()),
        ("frequency_hz", e.frequency_hz.is_some()),
        ("phase_rad", e.phase_rad.is_some()),
        ("start_s", e.start_s.is_some()),
        ("duration_s", e.duration_s.is_some()),
        ("f_start_hz", e.f_start_hz.is_some()),
        ("f_end_hz", e.f_end_hz.is_some()),
        ("file", e.file.is_some()),
    ];
    if let Some((name, _)) = set.iter().find(|(n, on)| *on && !takes.contains(n)) {
        let uses = if takes.is_empty() {
            "no parameters".to_string()
        } else {
            takes.join(", ")
        };
        return Err(c.err(
            &key(name),
            "(set)",
            format!("no {name}: a {} excitation takes {uses}", e.kind),
        ));
    }
    let amp = |c: &Checker| {
        c.range(
            &key("amplitude_m_s2"),
            c.required(&key("amplitude_m_s2"), e.amplitude_m_s2)?,
            -1000.0,
            1000.0,
        )
    };
    let start = c.opt_range(&key("start_s"), e.start_s, 0.0, 0.0, 1.0e9)?;
    Ok(match e.kind.as_str() {
        "none" => Excitation::None,
        "step" => Excitation::Step {
            amplitude: amp(c)?,
            start_s: start,
        },
        "ramp" => Excitation::Ramp {
            amplitude: amp(c)?,
            start_s: start,
            duration_s: c.positive(
                &key("duration_s"),
                c.required(&key("duration_s"), e.duration_s)?,
                1.0e9,
            )?,
        },
        "sine" => Excitation::Sine {
            amplitude: amp(c)?,
            frequency_hz: c.positive(
                &key("frequency_hz"),
                c.required(&key("frequency_hz"), e.frequency_hz)?,
                1.0e4,
            )?,
            phase_rad: c.opt_range(&key("phase_rad"), e.phase_rad, 0.0, -1.0e3, 1.0e3)?,
        },
        "sweep" => Excitation::Sweep {
            amplitude: amp(c)?,
            f_start_hz: c.positive(
                &key("f_start_hz"),
                c.required(&key("f_start_hz"), e.f_start_hz)?,
                1.0e4,
            )?,
            f_end_hz: c.positive(
                &key("f_end_hz"),
                c.required(&key("f_end_hz"), e.f_end_hz)?,
                1.0e4,
            )?,
            duration_s: c.positive(
                &key("duration_s"),
                c.required(&key("duration_s"), e.duration_s)?,
                1.0e9,
            )?,
        },
        "gust" => Excitation::Gust {
            amplitude: amp(c)?,
            start_s: start,
            duration_s: c.positive(
                &key("duration_s"),
                c.required(&key("duration_s"), e.duration_s)?,
                1.0e9,
            )?,
        },
        "table" => {
            let name = e.file.as_deref().ok_or_else(|| {
                c.err(
                    &key("file"),
                    "(missing)",
                    "a CSV path relative to the campaign file",
                )
            })?;
            crate::campaign::table::read_excitation_table(c, &key("file"), &dir.join(name))?
        }
        other => {
            return Err(c.err(
                &key("kind"),
                other,
                "none | step | ramp | sine | sweep | gust | table",
            ))
        }
    })
}
