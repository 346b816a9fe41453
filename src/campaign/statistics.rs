//! The `[statistics]` section: which quantiles, tolerance bounds and threshold probabilities a
//! campaign reports, how many bootstrap resamples its intervals use, how many rejected or diverged
//! instances it tolerates, and the precision target of `run --until`.

use super::validate::Checker;
use super::CampaignError;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawStatistics {
    pub confidence: Option<f64>,
    pub quantiles: Option<Vec<f64>>,
    pub tolerance: Option<Vec<String>>,
    pub bootstrap: Option<u64>,
    pub max_rejected_fraction: Option<f64>,
    pub max_diverged_fraction: Option<f64>,
    #[serde(default)]
    pub thresholds: Vec<RawThreshold>,
    pub target: Option<RawTarget>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawThreshold {
    pub quantity: String,
    pub above: Option<f64>,
    pub below: Option<f64>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawTarget {
    pub quantity: String,
    pub above: Option<f64>,
    pub below: Option<f64>,
    pub quantile: Option<f64>,
    pub half_width: f64,
    pub max_instances: Option<u64>,
    pub check_every: Option<u64>,
}

/// Side of a threshold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    Above,
    Below,
}

impl Side {
    /// Campaign spelling.
    pub fn name(self) -> &'static str {
        match self {
            Side::Above => "above",
            Side::Below => "below",
        }
    }
}

/// A probability the campaign reports: P(quantity above/below value), with its Clopper–Pearson
/// interval.
#[derive(Clone, Debug, PartialEq)]
pub struct Threshold {
    /// Its key path in the campaign (`statistics.thresholds.0`), for messages.
    pub key: String,
    pub quantity: String,
    pub side: Side,
    pub value: f64,
}

/// The estimate whose confidence interval `run --until` narrows.
#[derive(Clone, Debug, PartialEq)]
pub enum TargetEstimate {
    /// P(quantity above/below value).
    Probability(Threshold),
    /// The p-quantile of a quantity (its order-statistic interval).
    Quantile { quantity: String, p: f64 },
}

/// `run --until`: integrate blocks of `check_every` instances until the estimate's interval
/// half-width is at most `half_width`, or `max_instances` are done.
#[derive(Clone, Debug, PartialEq)]
pub struct Target {
    pub estimate: TargetEstimate,
    /// Largest acceptable half-width of the interval (probability, or the QoI's unit).
    pub half_width: f64,
    /// Cap on the instances integrated (default: `campaign.instances`).
    pub max_instances: Option<u64>,
    /// Instances between checks (the stopping point depends only on instance order).
    pub check_every: u64,
}

/// The validated `[statistics]` section.
#[derive(Clone, Debug, PartialEq)]
pub struct StatisticsPlan {
    /// Confidence level of every two-sided interval (Clopper–Pearson, quantile order statistics,
    /// Spearman, Sobol bootstrap).
    pub confidence: f64,
    /// Quantile levels reported for every QoI, each with its distribution-free interval.
    pub quantiles: Vec<f64>,
    /// One-sided (Wilks) tolerance bounds as (coverage, confidence), e.g. (0.95, 0.95).
    pub tolerance: Vec<(f64, f64)>,
    /// Bootstrap resamples of the Sobol intervals.
    pub bootstrap: u64,
    /// Share of rejected instances above which `run` exits with code 3.
    pub max_rejected_fraction: f64,
    /// Share of diverged instances above which `run` exits with code 3.
    pub max_diverged_fraction: f64,
    /// User thresholds (the MEOP, boil-off budget and cavitation rows are always reported).
    pub thresholds: Vec<Threshold>,
    pub target: Option<Target>,
}

/// Quantile levels reported by default: the median and the 1/5/95/99 % tails.
pub const DEFAULT_QUANTILES: [f64; 5] = [0.01, 0.05, 0.5, 0.95, 0.99];
/// Tolerance bounds reported by default: 95/95 and 99/90 (coverage/confidence).
pub const DEFAULT_TOLERANCE: [(f64, f64); 2] = [(0.95, 0.95), (0.99, 0.90)];

impl Default for StatisticsPlan {
    fn default() -> Self {
        StatisticsPlan {
            confidence: 0.95,
            quantiles: DEFAULT_QUANTILES.to_vec(),
            tolerance: DEFAULT_TOLERANCE.to_vec(),
            bootstrap: 1000,
            max_rejected_fraction: 0.01,
            max_diverged_fraction: 0.01,
            thresholds: Vec::new(),
            target: None,
        }
    }
}

/// Statistic name of the p-quantile: `p99`, `p05`, `p50`, `p99.9`, `p0.1`.
pub fn quantile_name(p: f64) -> String {
    let pct = p * 100.0;
    let rounded = pct.round();
    if (pct - rounded).abs() < 1e-9 {
        format!("p{:02}", rounded as u64)
    } else {
        let s = format!("{pct:.6}");
        format!("p{}", s.trim_end_matches('0'))
    }
}

/// Parse `"95/95"` (coverage/confidence in percent).
fn parse_tolerance(s: &str) -> Option<(f64, f64)> {
    let (a, b) = s.split_once('/')?;
    let (a, b): (f64, f64) = (a.trim().parse().ok()?, b.trim().parse().ok()?);
    // Percent, not fractions: "0.95/0.95" would mean 0.95 % coverage.
    let ok = |x: f64| (50.0..100.0).contains(&x);
    (ok(a) && ok(b)).then_some((a / 100.0, b / 100.0))
}

/// One side and value of a threshold entry.
fn side(
    c: &Checker,
    key: &str,
    above: Option<f64>,
    below: Option<f64>,
) -> Result<(Side, f64), CampaignError> {
    match (above, below) {
        (Some(v), None) if v.is_finite() => Ok((Side::Above, v)),
        (None, Some(v)) if v.is_finite() => Ok((Side::Below, v)),
        (Some(v), None) => Err(c.table_err(&format!("{key}.above"), v, "a finite number")),
        (None, Some(v)) => Err(c.table_err(&format!("{key}.below"), v, "a finite number")),
        (Some(_), Some(_)) => Err(c.table_err(
            key,
            "(both above and below)",
            "exactly one of above = X or below = X",
        )),
        (None, None) => Err(c.table_err(
            key,
            "(neither above nor below)",
            "exactly one of above = X or below = X",
        )),
    }
}

/// Validate the raw section; `fallback_confidence` is `dispersions.confidence`. Quantity names
/// are checked against the instances schema by `montecarlo::check_statistics` (the campaign
/// module does not know the QoI columns).
pub(super) fn validate(
    c: &Checker,
    raw: &RawStatistics,
    fallback_confidence: Option<f64>,
) -> Result<StatisticsPlan, CampaignError> {
    let d = StatisticsPlan::default();
    let confidence = raw
        .confidence
        .or(fallback_confidence)
        .unwrap_or(d.confidence);
    if !(confidence > 0.5 && confidence < 1.0) {
        return Err(c.table_err("statistics.confidence", confidence, "a number in (0.5, 1)"));
    }
    let quantiles = match &raw.quantiles {
        None => d.quantiles,
        Some(q) => {
            for (i, &p) in q.iter().enumerate() {
                if !(p > 0.0 && p < 1.0) {
                    return Err(c.table_err(
                        &format!("statistics.quantiles.{i}"),
                        p,
                        "a probability in (0, 1), e.g. 0.99",
                    ));
                }
            }
            let mut q = q.clone();
            q.sort_by(f64::total_cmp);
            q.dedup();
            q
        }
    };
    let tolerance = match &raw.tolerance {
        None => d.tolerance,
        Some(t) => t
            .iter()
            .enumerate()
            .map(|(i, s)| {
                parse_tolerance(s).ok_or_else(|| {
                    c.table_err(
                        &format!("statistics.tolerance.{i}"),
                        format!("{s:?}"),
                        "\"coverage/confidence\" in percent, each in [50, 100), e.g. \"95/95\" or \"99/90\"",
                    )
                })
            })
            .collect::<Result<_, _>>()?,
    };
    let bootstrap = raw.bootstrap.unwrap_or(d.bootstrap);
    if !(100..=100_000).contains(&bootstrap) {
        return Err(c.table_err(
            "statistics.bootstrap",
            bootstrap,
            "an integer in [100, 100000]",
        ));
    }
    let fraction = |key: &str, v: Option<f64>, default: f64| -> Result<f64, CampaignError> {
        let v = v.unwrap_or(default);
        if (0.0..=1.0).contains(&v) {
            Ok(v)
        } else {
            Err(c.table_err(key, v, "a fraction in [0, 1]"))
        }
    };
    let max_rejected_fraction = fraction(
        "statistics.max_rejected_fraction",
        raw.max_rejected_fraction,
        d.max_rejected_fraction,
    )?;
    let max_diverged_fraction = fraction(
        "statistics.max_diverged_fraction",
        raw.max_diverged_fraction,
        d.max_diverged_fraction,
    )?;
    let mut thresholds = Vec::new();
    for (i, t) in raw.thresholds.iter().enumerate() {
        let key = format!("statistics.thresholds.{i}");
        let (side, value) = side(c, &key, t.above, t.below)?;
        thresholds.push(Threshold {
            key,
            quantity: t.quantity.clone(),
            side,
            value,
        });
    }
    let target = match &raw.target {
        None => None,
        Some(t) => {
            let q = t.quantity.clone();
            let estimate = match (t.quantile, t.above, t.below) {
                (Some(p), None, None) if p > 0.0 && p < 1.0 => {
                    TargetEstimate::Quantile { quantity: q, p }
                }
                (Some(p), None, None) => {
                    return Err(c.table_err(
                        "statistics.target.quantile",
                        p,
                        "a probability in (0, 1)",
                    ))
                }
                (None, above, below) => {
                    let (side, value) = side(c, "statistics.target", above, below)?;
                    TargetEstimate::Probability(Threshold {
                        key: "statistics.target".into(),
                        quantity: q,
                        side,
                        value,
                    })
                }
                _ => {
                    return Err(c.table_err(
                        "statistics.target",
                        "(quantile with above/below)",
                        "either quantile = p or one of above = X / below = X",
                    ))
                }
            };
            if !(t.half_width.is_finite() && t.half_width > 0.0) {
                return Err(c.table_err(
                    "statistics.target.half_width",
                    t.half_width,
                    "a finite number > 0",
                ));
            }
            if t.max_instances == Some(0) {
                return Err(c.table_err("statistics.target.max_instances", 0, "at least 1"));
            }
            let check_every = t.check_every.unwrap_or(100);
            if check_every == 0 {
                return Err(c.table_err("statistics.target.check_every", 0, "at least 1"));
            }
            Some(Target {
                estimate,
                half_width: t.half_width,
                max_instances: t.max_instances,
                check_every,
            })
        }
    };
    Ok(StatisticsPlan {
        confidence,
        quantiles,
        tolerance,
        bootstrap,
        max_rejected_fraction,
        max_diverged_fraction,
        thresholds,
        target,
    })
}

/// The section as `check` prints it.
/// `group` is the Saltelli group size (1 for other designs): the run checks its target at whole
/// groups, so the interval shown is rounded up to one.
pub fn describe(p: &StatisticsPlan, group: u64) -> String {
    use super::number;
    let list = |v: &[f64]| {
        if v.is_empty() {
            "none".to_string()
        } else {
            v.iter().map(|x| number(*x)).collect::<Vec<_>>().join(", ")
        }
    };
    let tol: Vec<String> = p
        .tolerance
        .iter()
        .map(|(c, b)| format!("{}/{}", number(100.0 * c), number(100.0 * b)))
        .collect();
    let mut o = format!(
        "statistics: confidence {}, quantiles {}, tolerance {}, bootstrap {}, \
         max_rejected_fraction {}, max_diverged_fraction {}\n",
        number(p.confidence),
        list(&p.quantiles),
        if tol.is_empty() {
            "none".to_string()
        } else {
            tol.join(", ")
        },
        p.bootstrap,
        number(p.max_rejected_fraction),
        number(p.max_diverged_fraction)
    );
    for t in &p.thresholds {
        o += &format!(
            "  {}: P({} {} {})\n",
            t.key,
            t.quantity,
            if t.side == Side::Above { ">" } else { "<" },
            number(t.value)
        );
    }
    if let Some(t) = &p.target {
        let what = match &t.estimate {
            TargetEstimate::Probability(th) => format!(
                "P({} {} {})",
                th.quantity,
                if th.side == Side::Above { ">" } else { "<" },
                number(th.value)
            ),
            TargetEstimate::Quantile { quantity, p } => {
                format!("{} of {quantity}", quantile_name(*p))
            }
        };
        o += &format!(
            "  target: {what} to ±{}, checked every {} instances{}\n",
            number(t.half_width),
            t.check_every.div_ceil(group.max(1)) * group.max(1),
            t.max_instances
                .map_or_else(String::new, |m| format!(", at most {m}"))
        );
    }
    o
}

/// Parse `run --until`: `QOI>X:H` or `QOI<X:H` (the probability of being above/below X, to a
/// half-width H), or `QOI@pNN:H` (the NN % quantile to ±H in the QoI's unit); checked every 100
/// instances. Quantity names are checked by the run.
pub fn parse_until(spec: &str) -> Result<Target, String> {
    let bad = |why: &str| {
        format!(
            "--until {spec:?}: {why} (expected QOI>X:H, QOI<X:H or QOI@pNN:H, e.g. \
             peak_pressure_pa>350000:0.002 or peak_pressure_pa@p99:500)"
        )
    };
    let (what, half) = spec
        .rsplit_once(':')
        .ok_or_else(|| bad("no :H half-width"))?;
    let half_width: f64 = half.trim().parse().map_err(|_| bad("H is not a number"))?;
    if !(half_width.is_finite() && half_width > 0.0) {
        return Err(bad("H must be a finite number > 0"));
    }
    let number = |x: &str| -> Result<f64, String> {
        x.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| bad("the threshold is not a finite number"))
    };
    let estimate = if let Some((q, p)) = what.split_once('@') {
        let p = p.trim();
        let p: f64 = match p.strip_prefix('p') {
            Some(pct) => pct.parse::<f64>().map(|v| v / 100.0),
            None => p.parse::<f64>(),
        }
        .map_err(|_| bad("the quantile is not pNN or a probability"))?;
        if !(p > 0.0 && p < 1.0) {
            return Err(bad("the quantile must lie in (0, 1)"));
        }
        TargetEstimate::Quantile {
            quantity: q.trim().to_string(),
            p,
        }
    } else if let Some((q, x)) = what.split_once('>') {
        TargetEstimate::Probability(Threshold {
            key: "--until".into(),
            quantity: q.trim().to_string(),
            side: Side::Above,
            value: number(x)?,
        })
    } else if let Some((q, x)) = what.split_once('<') {
        TargetEstimate::Probability(Threshold {
            key: "--until".into(),
            quantity: q.trim().to_string(),
            side: Side::Below,
            value: number(x)?,
        })
    } else {
        return Err(bad("no >, < or @"));
    };
    Ok(Target {
        estimate,
        half_width,
        max_instances: None,
        check_every: 100,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantile_names() {
        assert_eq!(quantile_name(0.99), "p99");
        assert_eq!(quantile_name(0.05), "p05");
        assert_eq!(quantile_name(0.5), "p50");
        assert_eq!(quantile_name(0.999), "p99.9");
        assert_eq!(quantile_name(0.001), "p0.1");
    }

    #[test]
    fn until_spelling() {
        let t = parse_until("peak_pressure_pa>350000:0.002").unwrap();
        assert_eq!(t.half_width, 0.002);
        assert!(matches!(
            t.estimate,
            TargetEstimate::Probability(Threshold { side: Side::Above, value, .. }) if value == 350000.0
        ));
        let t = parse_until("min_cavitation_margin_m@p01:0.5").unwrap();
        assert!(matches!(t.estimate, TargetEstimate::Quantile { p, .. } if p == 0.01));
        assert!(parse_until("peak_pressure_pa>350000").is_err());
        assert!(parse_until("peak_pressure_pa=3:0.1").is_err());
        assert!(parse_until("peak_pressure_pa@p100:1").is_err());
        assert!(parse_until("peak_pressure_pa>1:-1").is_err());
    }

    #[test]
    fn tolerance_spelling() {
        assert_eq!(parse_tolerance("95/95"), Some((0.95, 0.95)));
        assert_eq!(parse_tolerance(" 99 / 90 "), Some((0.99, 0.9)));
        assert_eq!(parse_tolerance("95"), None);
        assert_eq!(parse_tolerance("100/95"), None);
        assert_eq!(parse_tolerance("0.95/0.95"), None);
    }
}
