//! `check`'s dispersion screen: before any integration, would the campaign's samples pass the
//! same validation as the nominal? Each input is tried at its far quantiles (others at their
//! medians), then the first instances of the design are resolved and their rejections counted
//! per key path, so a dispersion centred outside a field's range fails `check`, not `run`.

use super::plan::Plan;
use crate::campaign::{Campaign, CampaignError};
use std::collections::BTreeMap;
use std::fmt::Write;

/// Far quantiles tried per input: 0.1 % and 99.9 %.
pub const FAR_QUANTILES: [f64; 2] = [0.001, 0.999];
/// Instances resolved (not integrated) by the screen, at most.
pub const SCREEN_INSTANCES: u64 = 1000;

/// What the screen found.
#[derive(Clone, Debug, Default)]
pub struct Screen {
    /// Why the sample with every input at its median is rejected: the dispersion is centred
    /// outside a field's range (the key path and the reason).
    pub median_rejected: Option<(String, String)>,
    /// Per input and far quantile that was rejected: (input key, quantile, value, reason).
    pub far: Vec<(String, f64, f64, String)>,
    /// Instances resolved.
    pub screened: u64,
    /// Rejections among them per key path, most first.
    pub rejected_by: Vec<(String, u64)>,
}

impl Screen {
    /// Instances rejected among those screened.
    pub fn rejected(&self) -> u64 {
        self.rejected_by.iter().map(|(_, n)| n).sum()
    }
}

/// Screen campaign `c` run with `seed` and `total` instances.
pub fn screen(c: &Campaign, seed: u64, total: u64) -> Screen {
    let d = &c.dispersions;
    let mut out = Screen::default();
    if d.inputs.is_empty() {
        return out;
    }
    let medians: Vec<f64> = d
        .inputs
        .iter()
        .map(|i| i.distribution.quantile(0.5))
        .collect();
    if let Err(e) = c.instance(&medians) {
        out.median_rejected = Some((e.key().unwrap_or("(campaign)").to_string(), reason(&e)));
    }
    for (j, input) in d.inputs.iter().enumerate() {
        if out.median_rejected.is_some() {
            break;
        }
        for u in FAR_QUANTILES {
            let mut values = medians.clone();
            values[j] = input.distribution.quantile(u);
            if let Err(e) = c.instance(&values) {
                out.far.push((input.key.clone(), u, values[j], reason(&e)));
            }
        }
    }
    let plan = Plan {
        campaign: c,
        seed,
        total,
    };
    let mut counts = BTreeMap::<String, u64>::new();
    out.screened = total.min(SCREEN_INSTANCES);
    for i in 0..out.screened {
        if let (_, Err(e)) = plan.resolve(i) {
            *counts
                .entry(e.key().unwrap_or("(campaign)").to_string())
                .or_default() += 1;
        }
    }
    out.rejected_by = counts.into_iter().collect();
    out.rejected_by
        .sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    out
}

/// The error without its file prefix (the screen names the campaign once).
fn reason(e: &CampaignError) -> String {
    match e {
        CampaignError::Invalid {
            key,
            value,
            allowed,
            ..
        } => format!("{key} = {value} is not allowed: expected {allowed}"),
        other => other.to_string(),
    }
}

/// The screen as `check` prints it.
pub fn describe(s: &Screen, max_rejected_fraction: f64) -> String {
    let mut o = String::new();
    if s.screened == 0 {
        return o;
    }
    if let Some((_, why)) = &s.median_rejected {
        let _ = writeln!(o, "error: with every dispersed input at its median: {why}");
    }
    for (key, u, v, why) in &s.far {
        let _ = writeln!(
            o,
            "warning: {key} at its {} quantile ({}) is rejected: {why}",
            crate::campaign::statistics::quantile_name(*u),
            crate::campaign::number(*v)
        );
    }
    let rejected = s.rejected();
    let share = rejected as f64 / s.screened as f64;
    let _ = write!(
        o,
        "screen: the first {} instances resolve with {rejected} rejected ({:.1} %)",
        s.screened,
        100.0 * share
    );
    if rejected > 0 {
        let list: Vec<String> = s
            .rejected_by
            .iter()
            .map(|(k, n)| format!("{k} {n}"))
            .collect();
        let _ = write!(o, ": {}", list.join(", "));
    }
    o.push('\n');
    if share > max_rejected_fraction {
        let _ = writeln!(
            o,
            "warning: more than statistics.max_rejected_fraction = {} % would be rejected: `run` \
             would exit with code 3",
            100.0 * max_rejected_fraction
        );
    }
    o
}
