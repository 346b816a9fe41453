//! One instance of a dispersion campaign: its sampled inputs and its quantities of interest.
//! Instance i depends only on (campaign, seed, total instances, i).

use crate::campaign::dispersion::Dispersions;
use crate::campaign::{Campaign, CampaignError};
use crate::sampling::{correlate, unit_sample};
use crate::simulate::{simulate, simulate_lanes, Summary};

/// What every backend needs to integrate any instance of a campaign.
#[derive(Clone, Copy, Debug)]
pub struct Plan<'a> {
    pub campaign: &'a Campaign,
    pub seed: u64,
    /// Instances in the whole campaign (all shards): Latin hypercube strata depend on it.
    pub total: u64,
}

/// The result of one instance.
#[derive(Clone, Debug, PartialEq)]
pub struct InstanceRecord {
    pub instance: u64,
    /// Sampled values, in `dispersions.inputs` order.
    pub inputs: Vec<f64>,
    pub summary: Summary,
    /// The sample left a field's allowed range: not integrated, excluded from statistics.
    pub rejected: bool,
    /// The key path whose rule rejected the sample (rejected records only).
    pub rejected_by: Option<String>,
}

/// Sampled input values of instance `i` (inverse CDF of the design's unit samples, with the
/// Gaussian copula applied to correlated pairs).
pub fn sample_inputs(d: &Dispersions, seed: u64, total: u64, i: u64) -> Vec<f64> {
    let k = d.inputs.len();
    let mut u: Vec<f64> = (0..k)
        .map(|j| unit_sample(d.design, seed, total, i, j, k))
        .collect();
    for &(a, b, rho) in &d.correlations {
        u[b] = correlate(u[a], u[b], rho).1;
    }
    d.inputs
        .iter()
        .zip(&u)
        .map(|(input, &uj)| input.distribution.quantile(uj))
        .collect()
}

impl Plan<'_> {
    /// Instance `i`'s sampled inputs and the campaign they resolve to (`None`: nothing is
    /// dispersed, the nominal campaign itself); `Err` when a sample left a field's range.
    pub fn resolve(&self, i: u64) -> (Vec<f64>, Result<Option<Campaign>, CampaignError>) {
        let c = self.campaign;
        let inputs = sample_inputs(&c.dispersions, self.seed, self.total, i);
        let resolved = if inputs.is_empty() {
            Ok(None)
        } else {
            c.instance(&inputs).map(Some)
        };
        (inputs, resolved)
    }

    /// The record of instance `i`, integrated on the CPU from what [`Self::resolve`] gave.
    pub fn record(
        &self,
        i: u64,
        inputs: Vec<f64>,
        resolved: Result<Option<Campaign>, CampaignError>,
    ) -> InstanceRecord {
        match resolved {
            Ok(ci) => {
                let ci = ci.as_ref().unwrap_or(self.campaign);
                InstanceRecord {
                    instance: i,
                    inputs,
                    summary: simulate(ci, &ci.params, None),
                    rejected: false,
                    rejected_by: None,
                }
            }
            Err(e) => InstanceRecord {
                instance: i,
                inputs,
                rejected_by: Some(e.key().unwrap_or("(campaign)").to_string()),
                summary: Summary {
                    diverged_reason: Some(e.to_string()),
                    ..Summary::default()
                },
                rejected: true,
            },
        }
    }

    /// Sample, build and integrate instance `i`.
    pub fn run_instance(&self, i: u64) -> InstanceRecord {
        let (inputs, resolved) = self.resolve(i);
        self.record(i, inputs, resolved)
    }

    /// Sample, build and integrate the instances `range` in lane groups
    /// ([`simulate_lanes`]): the valid instances whose parameters are
    /// [`lane_compatible`](crate::model::params::Params::lane_compatible) with the first valid
    /// one together, any others one at a time. The records, in `range` order, equal
    /// [`Self::run_instance`]'s bit for bit.
    pub fn run_lanes(&self, range: std::ops::Range<u64>) -> Vec<InstanceRecord> {
        let resolved: Vec<_> = range.clone().map(|i| self.resolve(i)).collect();
        let nominal = self.campaign;
        let campaign = |r| resolved_campaign(r, nominal);
        let first = resolved.iter().find_map(|(_, r)| campaign(r));
        let in_lanes: Vec<bool> = resolved
            .iter()
            .map(|(_, r)| {
                campaign(r)
                    .is_some_and(|c| first.is_some_and(|f| f.params.lane_compatible(&c.params)))
            })
            .collect();
        let members: Vec<(&Campaign, &crate::model::params::Params)> = resolved
            .iter()
            .zip(&in_lanes)
            .filter(|(_, &lane)| lane)
            .filter_map(|((_, r), _)| campaign(r))
            .map(|c| (c, &c.params))
            .collect();
        // A single instance gains nothing from a lane group.
        let grouped = members.len() >= 2;
        let mut summaries = if grouped {
            simulate_lanes(&members)
        } else {
            Vec::new()
        }
        .into_iter();
        range
            .zip(resolved)
            .zip(in_lanes)
            .map(|((i, (inputs, r)), lane)| match r {
                Ok(_) if grouped && lane => InstanceRecord {
                    instance: i,
                    inputs,
                    summary: summaries.next().unwrap_or_default(),
                    rejected: false,
                    rejected_by: None,
                },
                _ => self.record(i, inputs, r),
            })
            .collect()
    }
}

/// The campaign a resolved instance runs (`None`: its sample was rejected).
fn resolved_campaign<'b>(
    r: &'b Result<Option<Campaign>, CampaignError>,
    nominal: &'b Campaign,
) -> Option<&'b Campaign> {
    r.as_ref().ok().map(|c| c.as_ref().unwrap_or(nominal))
}
