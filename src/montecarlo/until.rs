//! Precision-driven runs (`run --until`, `[statistics.target]`): integrate blocks of
//! `check_every` instances until a named estimate's confidence interval is narrower than asked,
//! or the cap is reached. The check points are fixed multiples of `check_every` and the estimate
//! sees the instances in index order, so the stopping point does not depend on threads, chunk
//! size or backend timing.

use super::plan::InstanceRecord;
use super::table::{row_values, RowShape};
use crate::campaign::statistics::{Side, Target, TargetEstimate};
use crate::stats::{exceedance, quantile_interval, Direction};

/// Where a precision-driven run stands at a check point.
#[derive(Clone, Debug, PartialEq)]
pub struct Progress {
    /// Instances integrated so far.
    pub instances: u64,
    /// Valid values the estimate used.
    pub n: u64,
    pub estimate: f64,
    pub ci_low: f64,
    pub ci_high: f64,
    /// Half the interval's width; infinite while a bound does not exist yet.
    pub half_width: f64,
    /// Whether the half-width reached the target.
    pub met: bool,
}

/// The stopping rule of one run.
#[derive(Clone, Debug)]
pub struct Stopper {
    pub target: Target,
    confidence: f64,
    /// The target quantity's column among the QoIs of `table::qoi_names`, its name and the
    /// campaign's row layout.
    column: usize,
    quantity: String,
    shape: RowShape,
    /// Its values in instance order (NaN: rejected, diverged or missing).
    values: Vec<f64>,
    /// Instances between checks (a multiple of the Saltelli group size when there is one).
    every: u64,
    /// The next check point (an instance index).
    next: u64,
    /// The last check's result.
    pub last: Option<Progress>,
}

impl Stopper {
    /// A stopper for a run starting at instance `start`; `group` is the Saltelli group size (1
    /// for other designs), to which the check interval is rounded up. `None` when the target
    /// names none of the QoI columns `qois` (of `table::qoi_names` for the phases of `shape`;
    /// the caller validated that already).
    pub fn new(
        target: Target,
        confidence: f64,
        (start, group): (u64, u64),
        qois: &[String],
        shape: RowShape,
    ) -> Option<Stopper> {
        let quantity = match &target.estimate {
            TargetEstimate::Probability(t) => t.quantity.clone(),
            TargetEstimate::Quantile { quantity, .. } => quantity.clone(),
        };
        let column = qois.iter().position(|n| *n == quantity)?;
        let group = group.max(1);
        let every = target.check_every.div_ceil(group) * group;
        Some(Stopper {
            target,
            confidence,
            column,
            quantity,
            shape,
            values: Vec::new(),
            every,
            next: start + every,
            last: None,
        })
    }

    /// The next check point: a block must not run past it.
    pub fn next_check(&self) -> u64 {
        self.next
    }

    /// The QoI column the target is about.
    pub fn quantity(&self) -> &str {
        &self.quantity
    }

    /// Record values of the target quantity as written in instances.parquet (nulls as NaN),
    /// in instance order (a resumed run replays its committed parts).
    pub fn observe_column(&mut self, values: &[f64]) {
        self.values.extend_from_slice(values);
    }

    /// Record a block of records (in instance order).
    pub fn observe(&mut self, block: &[InstanceRecord]) {
        for r in block {
            self.values.push(row_values(r, self.shape).0[self.column]);
        }
    }

    /// At a check point (`at` instances integrated from the start): evaluate and say whether to
    /// stop; otherwise move the check point on.
    pub fn check(&mut self, at: u64) -> bool {
        if at != self.next {
            return false;
        }
        let p = self.progress();
        let met = p.met;
        self.last = Some(p);
        if !met {
            self.next += self.every;
        }
        met
    }

    /// The estimate and its interval over the values seen so far.
    pub fn progress(&self) -> Progress {
        let (estimate, lo, hi, n) = match &self.target.estimate {
            TargetEstimate::Probability(t) => {
                let dir = match t.side {
                    Side::Above => Direction::Above,
                    Side::Below => Direction::Below,
                };
                let e = exceedance(&self.values, t.value, dir, self.confidence);
                (e.p, e.ci_low, e.ci_high, e.n)
            }
            TargetEstimate::Quantile { p, .. } => {
                let mut sorted: Vec<f64> = self
                    .values
                    .iter()
                    .copied()
                    .filter(|v| v.is_finite())
                    .collect();
                sorted.sort_by(f64::total_cmp);
                let (lo, hi) = quantile_interval(&sorted, *p, self.confidence);
                let est = crate::stats::percentile(&sorted, *p);
                (est, lo, hi, sorted.len() as u64)
            }
        };
        let half_width = if lo.is_finite() && hi.is_finite() {
            (hi - lo) / 2.0
        } else {
            f64::INFINITY
        };
        Progress {
            instances: self.values.len() as u64,
            n,
            estimate,
            ci_low: lo,
            ci_high: hi,
            half_width,
            met: half_width <= self.target.half_width,
        }
    }

    /// One line for the summary and run.json.
    pub fn describe(&self) -> String {
        let what = match &self.target.estimate {
            TargetEstimate::Probability(t) => {
                format!(
                    "P({} {} {})",
                    t.quantity,
                    if t.side == Side::Above { ">" } else { "<" },
                    t.value
                )
            }
            TargetEstimate::Quantile { quantity, p } => {
                format!(
                    "{} of {quantity}",
                    crate::campaign::statistics::quantile_name(*p)
                )
            }
        };
        let p = self.last.clone().unwrap_or_else(|| self.progress());
        if p.n == 0 {
            return format!(
                "{what}: no valid instance has a value of it in {} instances: the target cannot \
                 be reached (is the quantity ever defined in this mission?)",
                p.instances
            );
        }
        let verdict = if p.met {
            format!(
                "reached ±{} after {} instances",
                self.target.half_width, p.instances
            )
        } else {
            format!(
                "NOT reached (±{} asked) at the cap of {} instances",
                self.target.half_width, p.instances
            )
        };
        let bound = |v: f64| {
            if v.is_finite() {
                format!("{v:.6}")
            } else {
                "none yet".into()
            }
        };
        let half = if p.half_width.is_finite() {
            format!("±{:.3e}", p.half_width)
        } else {
            "a bound does not exist yet".into()
        };
        format!(
            "{what} = {:.6} [{}, {}] ({half}, n {}): precision {verdict}",
            p.estimate,
            bound(p.ci_low),
            bound(p.ci_high),
            p.n
        )
    }

    /// The outcome as `run.json` records it: the estimate, its interval, the half-width asked
    /// and reached, and the instances used (non-finite values are nulls).
    pub fn to_json(&self) -> serde_json::Value {
        let p = self.last.clone().unwrap_or_else(|| self.progress());
        let f = |v: f64| {
            if v.is_finite() {
                serde_json::json!(v)
            } else {
                serde_json::Value::Null
            }
        };
        serde_json::json!({
            "text": self.describe(),
            "estimate": f(p.estimate),
            "ci_low": f(p.ci_low),
            "ci_high": f(p.ci_high),
            "half_width": f(p.half_width),
            "target_half_width": self.target.half_width,
            "reached": p.met,
            "instances": p.instances,
            "n": p.n,
        })
    }
}
