//! The right-hand side leaves the slosh modes out where nothing reads them and the analog is at
//! rest (issue 18, `model::derive::motion`): that must not move a bit of the rates, the other
//! derived quantities or an instance's results, on every shipped campaign and level.

mod common;
use common::{each_campaign_level_integrator, load, CAMPAIGNS, LEVELS};
use cryoslosh::campaign::Campaign;
use cryoslosh::lanes::{Lanes, Real, WIDTH};
use cryoslosh::model::derive::{Drive, SloshParams};
use cryoslosh::model::params::Params;
use cryoslosh::model::state::{State, NS, Q1, Q1D, Q2, Q2D};
use cryoslosh::model::{self, evaluate, Evaluation, Group};
use cryoslosh::montecarlo::plan::Plan;
use cryoslosh::simulate::{self, simulate, History};

/// Each campaign's first `WIDTH` sampled instances (the nominal one where nothing is dispersed).
fn instances(c: &Campaign) -> Vec<Campaign> {
    let plan = Plan {
        campaign: c,
        seed: 11,
        total: WIDTH as u64,
    };
    (0..WIDTH as u64)
        .map(|i| plan.resolve(i).1.unwrap().unwrap_or_else(|| c.clone()))
        .collect()
}

/// Every number of `ev` but the slosh modes, as text: equal text is equal bits (Debug prints
/// the shortest exact decimal, signed zeros included).
fn without_modes(ev: &Evaluation<Lanes>) -> String {
    let mut ev = *ev;
    ev.derived.slosh = SloshParams::at_rest();
    format!("{ev:?}")
}

/// The rates' bits, slot by slot and lane by lane.
fn bits(s: &State<Lanes>) -> Vec<u64> {
    s.iter()
        .flat_map(|v| (0..WIDTH).map(move |i| v.lane(i).to_bits()))
        .collect()
}

/// Along 300 RK4 steps of the first phase with the lateral acceleration held at 0 and the analog
/// at rest, the group's right-hand side with the modes marked unread gives the same rates and
/// derived quantities as with them read; it does leave them out (so this test checks the
/// shortcut, not a path that never runs), and a lane whose analog swings makes the group
/// evaluate them again.
#[test]
fn resting_slosh_modes_left_out_change_no_bit_of_the_rates() {
    for name in CAMPAIGNS {
        for level in LEVELS {
            let c = load(name, &[&format!("campaign.fidelity={level}")]);
            let members = instances(&c);
            let params: Vec<Params> = members.iter().map(|m| m.params).collect();
            let g = Group::of(&params);
            let mut s: State<Lanes> = {
                let s0: Vec<State> = members
                    .iter()
                    .map(|m| simulate::initial_state(m, &m.params))
                    .collect();
                std::array::from_fn(|j| Lanes::from_fn(|i| s0[i][j]))
            };
            for q in [Q1, Q1D, Q2, Q2D] {
                s[q] = Lanes::splat(0.0);
            }
            let phase = &c.phases[0];
            let drive = |t: Lanes, unread: bool| {
                Drive::gather(|i| {
                    let mut d = Drive::of_phase(phase, t.lane(i), Default::default());
                    d.a_lat = 0.0;
                    d.slosh_modes_unread = unread;
                    d
                })
            };
            let dt = Lanes::splat(phase.dt_s);
            let what = format!("{name}/{level}");
            for k in 0..300 {
                let t = Lanes::splat(k as f64 * phase.dt_s);
                let read = evaluate(g, &s, &drive(t, false), dt);
                let unread = evaluate(g, &s, &drive(t, true), dt);
                assert_eq!(bits(&read.rates), bits(&unread.rates), "{what} step {k}");
                assert_eq!(
                    without_modes(&read),
                    without_modes(&unread),
                    "{what} step {k}"
                );
                let left_out = format!("{:?}", SloshParams::<Lanes>::at_rest());
                assert_eq!(format!("{:?}", unread.derived.slosh), left_out, "{what}");
                assert_ne!(format!("{:?}", read.derived.slosh), left_out, "{what}");
                model::rk4_step(g, |t| drive(t, true), &mut s, t, dt, None);
                assert!(
                    s[..NS].iter().all(|v| v.lane(0).is_finite()),
                    "{what} step {k}"
                );
            }
            if level != "homogeneous" {
                // One lane swinging: the modes are evaluated for the group.
                let mut swinging = s;
                swinging[Q1D] = Lanes::from_fn(|i| if i == 3 { 1e-3 } else { 0.0 });
                let t = Lanes::splat(0.0);
                let read = evaluate(g, &swinging, &drive(t, false), dt);
                let unread = evaluate(g, &swinging, &drive(t, true), dt);
                assert_eq!(format!("{read:?}"), format!("{unread:?}"), "{what}");
            }
        }
    }
}

/// End to end: an instance integrated with a history (whose rows report the modes, so they are
/// read at every evaluation) ends with the same results, bit for bit, as without one (the modes
/// left out wherever the analog rests), under either integrator.
#[test]
fn an_instance_ends_alike_with_the_slosh_modes_read_or_left_out() {
    each_campaign_level_integrator(&["phases.0.duration_s=120"], |what, c| {
        let mut h = History::default();
        let read = simulate(&c, &c.params, Some(&mut h));
        let unread = simulate(&c, &c.params, None);
        assert!(read.steps > 0);
        assert_eq!(format!("{read:?}"), format!("{unread:?}"), "{what}");
    });
}
