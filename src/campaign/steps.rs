//! The step plan of a campaign: per phase, the slosh and excitation periods a step must
//! resolve, and the refusal of a fixed RK4 step too coarse for them (issue 11).

use super::raw::RawCampaign;
use super::{Campaign, CampaignError, Integrator};
use crate::model::derive::{derive, Drive};
use crate::model::flight::Excitation;
use crate::model::params::Fidelity;
use crate::model::{state, Group};

/// Fewest fixed RK4 steps per slosh or excitation period a campaign may ask for without
/// `campaign.allow_coarse_step = true`. RK4's phase error per period is about (2π/n)⁵/120: at
/// 20 steps 2.5e-5 rad, at 10 steps 8e-4 rad, and its amplitude error grows like it.
pub const MIN_STEPS_PER_PERIOD: f64 = 20.0;

/// What one phase asks of the step.
#[derive(Clone, Debug, PartialEq)]
pub struct PhasePlan {
    /// First-mode slosh period at the phase start with the initial fill, s (the second mode of
    /// `two_mode` carries a few per cent of the first's mass, 3 % at h/R = 1, and is not counted)
    /// (None at the homogeneous level, which has no slosh analog, and while the liquid is at
    /// rest: no initial slosh angle and no excitation in this phase or an earlier one).
    pub slosh_period_s: Option<f64>,
    /// The excitation's shortest period, s (`Phase::excitation_period_s`).
    pub excitation_period_s: Option<f64>,
    /// The fixed RK4 step of the phase, s.
    pub fixed_dt_s: f64,
}

impl PhasePlan {
    /// Fixed RK4 steps per the shortest period the phase imposes (None: no period).
    pub fn fixed_steps_per_period(&self) -> Option<f64> {
        let period = match (self.slosh_period_s, self.excitation_period_s) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        period.map(|p| p / self.fixed_dt_s)
    }
}

/// The plan of every phase. The slosh period is estimated from the initial fill under each
/// phase's acceleration at its start: as a tank drains under thrust the frequency rises, so a
/// burn's later slosh is faster than this.
pub fn plan(c: &Campaign) -> Vec<PhasePlan> {
    let p = &c.params;
    let s0 = state::initial_state(p);
    let mut excited = c.initial_slosh_angle_rad != 0.0;
    c.phases
        .iter()
        .map(|ph| {
            excited |= ph.excitation != Excitation::None;
            let slosh_period_s = match p.fidelity {
                Fidelity::Homogeneous => None,
                _ if !excited => None,
                _ => {
                    let x = derive(
                        Group::one(p),
                        &s0,
                        &Drive::of_phase(ph, 0.0, Default::default()),
                    );
                    let omega = x.slosh.omega[0];
                    (omega > 0.0).then(|| std::f64::consts::TAU / omega)
                }
            };
            PhasePlan {
                slosh_period_s,
                excitation_period_s: ph.excitation_period_s(),
                fixed_dt_s: ph.steps().1,
            }
        })
        .collect()
}

/// Refuse a fixed RK4 step that resolves a slosh or excitation period with fewer than
/// [`MIN_STEPS_PER_PERIOD`] steps, naming the key that set it (`phases.N.dt_s`, or
/// `campaign.dt_s` when the phase takes the campaign's), unless the campaign allows it.
pub fn check_fixed_step(c: &Campaign, raw: &RawCampaign) -> Result<(), CampaignError> {
    if c.stepping.integrator != Integrator::Rk4 || c.stepping.allow_coarse_step {
        return Ok(());
    }
    for (i, (ph, pp)) in c.phases.iter().zip(plan(c)).enumerate() {
        let Some(n) = pp.fixed_steps_per_period() else {
            continue;
        };
        if n < MIN_STEPS_PER_PERIOD {
            let key = if raw.phases.get(i).is_some_and(|r| r.dt_s.is_some()) {
                format!("phases.{i}.dt_s")
            } else {
                "campaign.dt_s".to_string()
            };
            let what = match (pp.slosh_period_s, pp.excitation_period_s) {
                (Some(s), Some(e)) if e < s => format!("the excitation period {e:.4} s"),
                (Some(s), _) => format!("the slosh period {s:.4} s"),
                (None, Some(e)) => format!("the excitation period {e:.4} s"),
                (None, None) => unreachable!("a period exists"),
            };
            return Err(CampaignError::Invalid {
                file: c.path.clone(),
                key,
                value: format!("{}", ph.dt_s),
                allowed: format!(
                    "a step resolving {what} of phase {} with at least {MIN_STEPS_PER_PERIOD} steps (≤ {:.4} s here, {n:.2} steps now); or campaign.integrator = \"dopri5\", or campaign.allow_coarse_step = true",
                    ph.name,
                    pp.fixed_dt_s * n / MIN_STEPS_PER_PERIOD,
                ),
            });
        }
    }
    Ok(())
}
