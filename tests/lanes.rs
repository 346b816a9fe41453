//! Lockstep lanes (issue 4): a lane group integrates its instances exactly as one-at-a-time
//! integration does, bit for bit, on every shipped campaign and level — with lanes that differ
//! in phase durations, baffle counts and step lengths, and with lanes that diverge early.

mod common;
use common::{campaign_path, load, CAMPAIGNS, LEVELS};
use cryoslosh::campaign::Campaign;
use cryoslosh::lanes::WIDTH;
use cryoslosh::montecarlo::plan::{InstanceRecord, Plan};
use cryoslosh::simulate::simulate_lanes;

/// Every field of every record, as text (Debug prints the shortest exact decimal of a double, so
/// two records print alike only when they are equal bit for bit, NaN aside).
fn text(records: &[InstanceRecord]) -> Vec<String> {
    records.iter().map(|r| format!("{r:?}")).collect()
}

/// Lane groups of `plan` against one-at-a-time records, over instances 0..n.
fn assert_lanes_match(what: &str, plan: &Plan, n: u64) -> Vec<InstanceRecord> {
    let width = WIDTH as u64;
    let lanes: Vec<InstanceRecord> = (0..n.div_ceil(width))
        .flat_map(|k| plan.run_lanes(k * width..((k + 1) * width).min(n)))
        .collect();
    let single: Vec<InstanceRecord> = (0..n).map(|i| plan.run_instance(i)).collect();
    for (l, s) in text(&lanes).iter().zip(text(&single)) {
        assert_eq!(*l, s, "{what}: lane group and one-at-a-time records differ");
    }
    assert_eq!(lanes.len(), single.len());
    // The first group straight through `simulate_lanes` (run_lanes would fall back to one at a
    // time for unlike parameters, which these campaigns must not need).
    let resolved: Vec<Campaign> = (0..width)
        .map(|i| {
            plan.resolve(i)
                .1
                .unwrap()
                .unwrap_or_else(|| plan.campaign.clone())
        })
        .collect();
    assert!(resolved
        .iter()
        .all(|c| resolved[0].params.lane_compatible(&c.params)));
    let members: Vec<_> = resolved.iter().map(|c| (c, &c.params)).collect();
    let direct = simulate_lanes(&members);
    for (i, q) in direct.iter().enumerate() {
        assert_eq!(
            format!("{q:?}"),
            format!("{:?}", single[i].summary),
            "{what}: lane {i}"
        );
    }
    lanes
}

#[test]
fn lane_groups_equal_one_at_a_time_on_every_campaign_and_level() {
    for name in CAMPAIGNS {
        for level in LEVELS {
            // A short first phase keeps the test quick; later phases run in full.
            let c = load(
                name,
                &[
                    &format!("campaign.fidelity={level}"),
                    "phases.0.duration_s=120",
                ],
            );
            // One full group and one with an empty lane.
            let n = 2 * WIDTH as u64 - 1;
            let plan = Plan {
                campaign: &c,
                seed: 5,
                total: n,
            };
            let records = assert_lanes_match(&format!("{name}/{level}"), &plan, n);
            assert!(records.iter().all(|r| r.summary.steps > 0));
        }
    }
}

#[test]
fn lanes_with_different_phases_and_steps_stay_exact() {
    // The upper stage disperses the first burn's duration and the baffle count; the step length
    // is dispersed here too, so every lane has its own step count and phase boundaries.
    let text = std::fs::read_to_string(campaign_path("lh2_upper_stage")).unwrap()
        + "\n[[dispersions.inputs]]\nkey = \"phases.0.dt_s\"\ndistribution = \"uniform\"\nlo = 0.2\nhi = 1.0\n";
    let path = std::env::temp_dir().join(format!("cryoslosh-lanes-{}.toml", std::process::id()));
    std::fs::write(&path, text).unwrap();
    let c = Campaign::load(&path, &["phases.0.duration_s=60".to_string()]).unwrap();
    std::fs::remove_file(&path).ok();
    let plan = Plan {
        campaign: &c,
        seed: 11,
        total: WIDTH as u64,
    };
    let records = assert_lanes_match("lh2_upper_stage, dispersed dt", &plan, WIDTH as u64);
    let mut steps: Vec<u64> = records.iter().map(|r| r.summary.steps).collect();
    steps.dedup();
    assert!(
        steps.len() > 1,
        "lanes should differ in step count: {steps:?}"
    );
}

#[test]
fn a_diverging_lane_leaves_the_others_exact() {
    // Ascent steps dispersed from 0.05 s to 4 s: the long ones (above about 1 s) blow up, the
    // short ones fly the whole ascent, side by side in the same groups.
    let text = std::fs::read_to_string(campaign_path("lox_ascent")).unwrap()
        + "\n[[dispersions.inputs]]\nkey = \"phases.1.dt_s\"\ndistribution = \"uniform\"\nlo = 0.05\nhi = 4.0\n";
    let path = std::env::temp_dir().join(format!("cryoslosh-diverge-{}.toml", std::process::id()));
    std::fs::write(&path, text).unwrap();
    let c = Campaign::load(&path, &["phases.0.duration_s=10".to_string()]).unwrap();
    std::fs::remove_file(&path).ok();
    let plan = Plan {
        campaign: &c,
        seed: 2,
        total: WIDTH as u64,
    };
    let records = assert_lanes_match("lox_ascent, dispersed dt", &plan, WIDTH as u64);
    let first = &records[..WIDTH];
    assert!(
        first.iter().any(|r| r.summary.diverged) && first.iter().any(|r| !r.summary.diverged),
        "the first group should mix diverged and healthy lanes: {:?}",
        first.iter().map(|r| r.summary.diverged).collect::<Vec<_>>()
    );
}

/// Under error control every lane keeps its own step length and rejects on its own; a lane
/// group still equals one-at-a-time integration bit for bit, valve events included (the LCH4
/// coast vents three times per instance).
#[test]
fn adaptive_lane_groups_equal_one_at_a_time() {
    for (name, level) in [
        ("lh2_upper_stage", "lumped"),
        ("lox_ascent", "two_mode"),
        ("lch4_coast", "lumped"),
        ("mhtb_selfpress", "homogeneous"),
    ] {
        let c = load(
            name,
            &[
                &format!("campaign.fidelity={level}"),
                "campaign.integrator=dopri5",
            ],
        );
        // A full group (the direct `simulate_lanes` check needs one) and a partial one.
        let n = WIDTH as u64 + 2;
        let plan = Plan {
            campaign: &c,
            seed: 3,
            total: n,
        };
        let records = assert_lanes_match(&format!("{name}/{level} dopri5"), &plan, n);
        let mut steps: Vec<u64> = records.iter().map(|r| r.summary.steps).collect();
        steps.dedup();
        assert!(
            steps.len() > 1,
            "{name}: lanes should differ in step count: {steps:?}"
        );
    }
}

/// Dormand–Prince lanes take the next instance of their chunk as theirs end
/// (`simulate::adaptive::integrate`): a chunk of more instances than lanes, whose members end
/// at different step counts, gives each instance's one-at-a-time record bit for bit, whatever
/// the chunk. The LCH4 coast's relief valve and the TVS coast's dispersed fill (each lane's own
/// tolerance scales) are both taken over mid-run.
#[test]
fn adaptive_lanes_refilled_from_a_chunk_equal_one_at_a_time() {
    for name in ["lch4_coast", "lh2_tvs_coast"] {
        let c = load(name, &["campaign.fidelity=lumped"]);
        let n = 2 * WIDTH as u64 + 5;
        let plan = Plan {
            campaign: &c,
            seed: 11,
            total: n,
        };
        let chunk = plan.run_lanes(0..n);
        let single: Vec<InstanceRecord> = (0..n).map(|i| plan.run_instance(i)).collect();
        assert_eq!(chunk.len(), single.len());
        for (i, (l, s)) in text(&chunk).iter().zip(text(&single)).enumerate() {
            assert_eq!(
                *l, s,
                "{name} instance {i}: refilled lanes and one at a time differ"
            );
        }
        // Other chunkings: a group at a time, and two uneven chunks.
        let width = WIDTH as u64;
        let groups: Vec<InstanceRecord> = (0..n.div_ceil(width))
            .flat_map(|k| plan.run_lanes(k * width..((k + 1) * width).min(n)))
            .collect();
        let uneven: Vec<InstanceRecord> = [0..7, 7..n]
            .into_iter()
            .flat_map(|r| plan.run_lanes(r))
            .collect();
        assert_eq!(text(&groups), text(&chunk), "{name}");
        assert_eq!(text(&uneven), text(&chunk), "{name}");
        // The lanes did end at different steps, so members were taken mid-run.
        let mut steps: Vec<u64> = single.iter().map(|r| r.summary.steps).collect();
        steps.sort_unstable();
        steps.dedup();
        assert!(steps.len() > WIDTH / 2, "{name}: step counts {steps:?}");
    }
}
