//! The `[dispersions]` section: which campaign scalars vary, how, and under which design.
//!
//! Inputs name any numeric scalar of the campaign by its `--set` key path. Each instance's values
//! come from the seed, the instance index and, under Latin hypercube sampling (whose strata it
//! sets), the instance count: never from threads, chunks or shards.

use super::validate::Checker;
use super::CampaignError;
use crate::sampling::{Design, Distribution, MAX_SOBOL_DIMS};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawDispersions {
    pub design: Option<String>,
    pub confidence: Option<f64>,
    pub boiloff_budget_kg: Option<f64>,
    #[serde(default)]
    pub inputs: Vec<RawInput>,
    #[serde(default)]
    pub correlations: Vec<RawCorrelation>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawInput {
    pub key: String,
    pub distribution: String,
    pub mean: Option<f64>,
    pub std: Option<f64>,
    pub lo: Option<f64>,
    pub hi: Option<f64>,
    pub mode: Option<f64>,
    pub median: Option<f64>,
    pub sigma: Option<f64>,
    pub values: Option<Vec<f64>>,
    pub weights: Option<Vec<f64>>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawCorrelation {
    pub keys: Vec<String>,
    pub rho: f64,
}

/// One dispersed input.
#[derive(Clone, Debug, PartialEq)]
pub struct DispersedInput {
    /// Campaign key path, e.g. `tank.heat_leak_w`.
    pub key: String,
    /// Column name in instances.parquet: the key path with `.` → `_` (SQL-friendly).
    pub column: String,
    pub distribution: Distribution,
}

/// The validated dispersion plan of a campaign.
#[derive(Clone, Debug, PartialEq)]
pub struct Dispersions {
    pub design: Design,
    /// Confidence level of exceedance intervals (Clopper–Pearson), e.g. 0.95.
    pub confidence: f64,
    /// Boil-off budget for the exceedance probability, kg.
    pub boiloff_budget_kg: Option<f64>,
    pub inputs: Vec<DispersedInput>,
    /// Correlated pairs (index of the driving input, index of the driven input, ρ).
    pub correlations: Vec<(usize, usize, f64)>,
}

impl Dispersions {
    /// Instances per Saltelli group (A, AB₁…AB_k, B: k + 2); 1 for the other designs. Counts
    /// that must keep groups whole (a precision target's check points) are multiples of it.
    pub fn group_size(&self) -> u64 {
        match self.design {
            Design::Saltelli => self.inputs.len() as u64 + 2,
            _ => 1,
        }
    }
}

impl Default for Dispersions {
    fn default() -> Self {
        Dispersions {
            design: Design::MonteCarlo,
            confidence: 0.95,
            boiloff_budget_kg: None,
            inputs: Vec::new(),
            correlations: Vec::new(),
        }
    }
}

/// SQL-friendly column name of a key path.
pub fn column_name(key: &str) -> String {
    key.replace('.', "_")
}

/// The parameters each distribution takes (any other one set is an error, not ignored).
pub fn parameters(distribution: &str) -> &'static [&'static str] {
    match distribution {
        "normal" => &["mean", "std"],
        "truncated_normal" => &["mean", "std", "lo", "hi"],
        "uniform" => &["lo", "hi"],
        "lognormal" => &["median", "sigma"],
        "triangular" => &["lo", "mode", "hi"],
        "choice" => &["values", "weights"],
        _ => &[],
    }
}

fn distribution(c: &Checker, base: &str, r: &RawInput) -> Result<Distribution, CampaignError> {
    let set = [
        ("mean", r.mean.is_some()),
        ("std", r.std.is_some()),
        ("lo", r.lo.is_some()),
        ("hi", r.hi.is_some()),
        ("mode", r.mode.is_some()),
        ("median", r.median.is_some()),
        ("sigma", r.sigma.is_some()),
        ("values", r.values.is_some()),
        ("weights", r.weights.is_some()),
    ];
    let takes = parameters(&r.distribution);
    if !takes.is_empty() {
        if let Some((name, _)) = set.iter().find(|(n, on)| *on && !takes.contains(n)) {
            return Err(c.table_err(
                &format!("{base}.{name}"),
                "(set)",
                format!(
                    "no {name}: the {} distribution takes {} (a parameter it does not use \
                     would be silently ignored)",
                    r.distribution,
                    takes.join(", ")
                ),
            ));
        }
    }
    let need = |name: &str, v: Option<f64>| {
        v.ok_or_else(|| {
            c.table_err(
                &format!("{base}.{name}"),
                "(missing)",
                format!("a value: the {} distribution needs it", r.distribution),
            )
        })
    };
    Ok(match r.distribution.as_str() {
        "normal" => Distribution::Normal {
            mean: need("mean", r.mean)?,
            std: need("std", r.std)?,
        },
        "truncated_normal" => Distribution::TruncatedNormal {
            mean: need("mean", r.mean)?,
            std: need("std", r.std)?,
            lo: need("lo", r.lo)?,
            hi: need("hi", r.hi)?,
        },
        "uniform" => Distribution::Uniform {
            lo: need("lo", r.lo)?,
            hi: need("hi", r.hi)?,
        },
        "lognormal" => Distribution::LogNormal {
            median: need("median", r.median)?,
            sigma: need("sigma", r.sigma)?,
        },
        "triangular" => Distribution::Triangular {
            lo: need("lo", r.lo)?,
            mode: need("mode", r.mode)?,
            hi: need("hi", r.hi)?,
        },
        "choice" => Distribution::Choice {
            values: r.values.clone().ok_or_else(|| {
                c.table_err(
                    &format!("{base}.values"),
                    "(missing)",
                    "a non-empty list of values",
                )
            })?,
            weights: r.weights.clone().unwrap_or_default(),
        },
        other => {
            return Err(c.table_err(
                &format!("{base}.distribution"),
                other,
                "normal | truncated_normal | uniform | lognormal | triangular | choice",
            ))
        }
    })
}

/// The values a bounded distribution can reach at the edges of its support, with the parameter
/// that sets each: `lo` and `hi` (uniform, triangular, truncated normal) or every value of a
/// choice. Normal and log-normal are unbounded (above), so none: their far tails may leave a
/// field's range, and those samples are rejected at run time (`check`'s screen counts them).
fn support_edges(d: &Distribution) -> Vec<(String, f64)> {
    match d {
        Distribution::Uniform { lo, hi }
        | Distribution::Triangular { lo, hi, .. }
        | Distribution::TruncatedNormal { lo, hi, .. } => {
            vec![("lo".into(), *lo), ("hi".into(), *hi)]
        }
        Distribution::Choice { values, .. } => values
            .iter()
            .enumerate()
            .map(|(j, &v)| (format!("values.{j}"), v))
            .collect(),
        Distribution::Normal { .. } | Distribution::LogNormal { .. } => Vec::new(),
    }
}

/// A bounded support must lie wholly inside its field's allowed range: each edge (see
/// [`support_edges`]) is tried with the rest of the campaign as written (`allowed(key, v)`
/// validates it with `key` set to `v`). A support that leaves the range, wholly or in part, is
/// a user error (exit 2) naming the parameter, its value and the range, not a share of instances
/// rejected at run time (exit 3). `canonical` compares key spellings (a phase by name or index).
pub(super) fn check_supports(
    c: &Checker,
    d: &Dispersions,
    allowed: impl Fn(&str, f64) -> Result<(), CampaignError>,
    canonical: impl Fn(&str) -> String,
) -> Result<(), CampaignError> {
    for (i, input) in d.inputs.iter().enumerate() {
        for (parameter, v) in support_edges(&input.distribution) {
            let Err(e) = allowed(&input.key, v) else {
                continue;
            };
            let why = match &e {
                CampaignError::Invalid { key, allowed, .. }
                    if canonical(key) == canonical(&input.key) =>
                {
                    format!("{allowed}, the allowed range of {}", input.key)
                }
                CampaignError::Invalid {
                    key,
                    value,
                    allowed,
                    ..
                } => format!(
                    "a value the campaign allows for {} (there {key} = {value} is not \
                     allowed: expected {allowed})",
                    input.key
                ),
                other => format!("a value the campaign allows for {} ({other})", input.key),
            };
            let why = format!(
                "{why}; a {} support must lie inside it, or the samples beyond it are \
                 rejected at run time",
                input.distribution.name()
            );
            return Err(c.table_err(&format!("dispersions.inputs.{i}.{parameter}"), v, why));
        }
    }
    Ok(())
}

/// Validate the raw section. `known_scalar(key)` says whether a key path names a numeric scalar of
/// the campaign (checked by the caller against the parsed document).
pub(super) fn validate(
    c: &Checker,
    raw: &RawDispersions,
    known_scalar: impl Fn(&str) -> bool,
    canonical: impl Fn(&str) -> String,
) -> Result<Dispersions, CampaignError> {
    let design_name = raw.design.as_deref().unwrap_or("monte_carlo");
    let design = Design::from_name(design_name).ok_or_else(|| {
        c.table_err(
            "dispersions.design",
            design_name,
            "monte_carlo | latin_hypercube | sobol | saltelli",
        )
    })?;
    let confidence = raw.confidence.unwrap_or(0.95);
    if !(confidence > 0.5 && confidence < 1.0) {
        return Err(c.table_err("dispersions.confidence", confidence, "a number in (0.5, 1)"));
    }
    if let Some(b) = raw.boiloff_budget_kg {
        if !(b.is_finite() && b >= 0.0) {
            return Err(c.table_err("dispersions.boiloff_budget_kg", b, "a finite number ≥ 0"));
        }
    }
    let mut inputs: Vec<DispersedInput> = Vec::new();
    for (i, r) in raw.inputs.iter().enumerate() {
        let base = format!("dispersions.inputs.{i}");
        if !known_scalar(&r.key) {
            return Err(c.table_err(
                &format!("{base}.key"),
                &r.key,
                "the key path of a numeric scalar in this campaign",
            ));
        }
        if r.key.starts_with("dispersions.") || r.key.starts_with("campaign.") {
            return Err(c.table_err(
                &format!("{base}.key"),
                &r.key,
                "a physical input (not a campaign.* or dispersions.* setting)",
            ));
        }
        // One key, however spelled (a phase by index or by name), is dispersed once.
        if let Some(j) = inputs
            .iter()
            .position(|x| canonical(&x.key) == canonical(&r.key))
        {
            return Err(c.table_err(
                &format!("{base}.key"),
                &r.key,
                format!(
                    "each key dispersed once (dispersions.inputs.{j} disperses it as {})",
                    inputs[j].key
                ),
            ));
        }
        let dist = distribution(c, &base, r)?;
        dist.validate().map_err(|e| CampaignError::Distribution {
            file: c.file.to_path_buf(),
            key: base.clone(),
            distribution: r.distribution.clone(),
            input: r.key.clone(),
            message: e.to_string(),
        })?;
        inputs.push(DispersedInput {
            key: r.key.clone(),
            column: column_name(&r.key),
            distribution: dist,
        });
    }
    let mut correlations = Vec::new();
    for (i, r) in raw.correlations.iter().enumerate() {
        let base = format!("dispersions.correlations.{i}");
        if design == Design::Saltelli {
            return Err(c.table_err(
                &base,
                "a correlation",
                "independent inputs: Sobol indices assume them (use another design)",
            ));
        }
        let idx = |k: &String| inputs.iter().position(|x| &x.key == k);
        let (a, b) = match r.keys.as_slice() {
            [ka, kb] => match (idx(ka), idx(kb)) {
                (Some(a), Some(b)) if a != b => (a, b),
                _ => {
                    return Err(c.table_err(
                        &format!("{base}.keys"),
                        format!("{:?}", r.keys),
                        "two different keys listed in dispersions.inputs",
                    ))
                }
            },
            _ => {
                return Err(c.table_err(
                    &format!("{base}.keys"),
                    format!("{:?}", r.keys),
                    "exactly two keys",
                ))
            }
        };
        if !(r.rho.is_finite() && r.rho.abs() < 1.0) {
            return Err(c.table_err(&format!("{base}.rho"), r.rho, "a number in (−1, 1)"));
        }
        if correlations
            .iter()
            .any(|&(x, y, _)| [x, y].contains(&a) || [x, y].contains(&b))
        {
            return Err(c.table_err(
                &format!("{base}.keys"),
                format!("{:?}", r.keys),
                "each input in at most one correlated pair",
            ));
        }
        correlations.push((a, b, r.rho));
    }
    let dims = if design == Design::Saltelli {
        2 * inputs.len()
    } else {
        inputs.len()
    };
    if matches!(design, Design::Sobol | Design::Saltelli) && dims > MAX_SOBOL_DIMS {
        return Err(c.table_err(
            "dispersions.inputs",
            inputs.len(),
            format!("at most {MAX_SOBOL_DIMS} Sobol dimensions ({dims} needed)"),
        ));
    }
    Ok(Dispersions {
        design,
        confidence,
        boiloff_budget_kg: raw.boiloff_budget_kg,
        inputs,
        correlations,
    })
}
