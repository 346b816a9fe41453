//! `run --until`: the run stops at the first check point where the estimate's interval is narrow
//! enough, at the same instance for any thread count and chunk size, and its files hold exactly
//! the instances up to there (a replay of the stopped run reproduces its rows).

mod common;
use common::load;
use cryoslosh::campaign::statistics::parse_until;
use cryoslosh::engine::{Backend, CpuEngine};
use cryoslosh::montecarlo::table::read_f64;
use cryoslosh::montecarlo::{self, replay, RunOptions, RunReport, Shard};
use cryoslosh::stats::quantile_interval;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cryoslosh-until-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn run(dir: &Path, threads: usize, chunk: u64, spec: &str) -> RunReport {
    let c = load(
        "mhtb_selfpress",
        &[
            "phases.0.duration_s=1800",
            "campaign.output_interval_s=600",
            "dispersions.design=monte_carlo",
        ],
    );
    let opts = RunOptions {
        out_dir: dir.to_path_buf(),
        instances: 300,
        seed: 11,
        shard: Shard::ALL,
        chunk_size: chunk,
        progress: false,
        histories: Vec::new(),
        until: Some(parse_until(spec).unwrap()),
        force: false,
        resume: false,
    };
    montecarlo::run(&c, &Backend::Cpu(CpuEngine::new(threads).unwrap()), &opts).unwrap()
}

#[test]
fn until_stops_at_the_same_instance_for_any_threads_and_chunks() {
    // The median's 95 % half-width is 2.25e-4 kg after 100 instances and 2.04e-4 after 200
    // (0.00025 until the liquid's flow work moved with it, 2026-12-02): the run stops at 200.
    let spec = "boiloff_kg@p50:0.000215";
    let (a, b) = (scratch("t1"), scratch("t2"));
    let ra = run(&a, 1, 37, spec);
    let rb = run(&b, 2, 64, spec);
    assert_eq!(ra.instances, rb.instances);
    let stop = ra.instances;
    assert!(stop < 300 && stop.is_multiple_of(100), "stopped at {stop}");
    let (_, json) = ra.until.clone().unwrap();
    assert_eq!(json["reached"], true, "{json}");
    assert_eq!(json["instances"], stop, "{json}");
    assert!(json["half_width"].as_f64().unwrap() <= 0.000215, "{json}");
    for f in ["instances.parquet", "statistics.parquet"] {
        assert!(
            std::fs::read(a.join(f)).unwrap() == std::fs::read(b.join(f)).unwrap(),
            "{f} differs between 1 and 2 threads"
        );
    }
    // Independently: the order-statistic interval of the median is narrow enough at the stop
    // and was not at the check point before it.
    let boiloff = read_f64(&a.join("instances.parquet"), "boiloff_kg").unwrap();
    assert_eq!(boiloff.len() as u64, stop);
    let half = |n: usize| {
        let mut s: Vec<f64> = boiloff[..n].to_vec();
        s.sort_by(f64::total_cmp);
        let (lo, hi) = quantile_interval(&s, 0.5, 0.95);
        (hi - lo) / 2.0
    };
    assert!(half(stop as usize) <= 0.000215);
    assert!(half(stop as usize - 100) > 0.000215);
    // The stopped run replays: its metadata holds the count it stopped at.
    let (_, record) = replay::replay(&a, stop - 1, None).unwrap();
    let c = replay::run_campaign(&a).unwrap();
    assert_eq!(c.total, stop);
    assert!(replay::compare_row(&a, &c.campaign, &record)
        .unwrap()
        .is_empty());
    for d in [a, b] {
        std::fs::remove_dir_all(d).ok();
    }
}

#[test]
fn until_that_cannot_be_met_runs_to_the_cap_and_says_so() {
    let dir = scratch("cap");
    let r = run(&dir, 2, 128, "peak_pressure_pa>115000:0.00001");
    assert_eq!(r.instances, 300);
    let (text, json) = r.until.clone().unwrap();
    assert!(text.contains("NOT reached"), "{text}");
    assert_eq!(json["reached"], false, "{json}");
    // A quantity without values: said, not NaN.
    let dir2 = scratch("novalue");
    let r = run(&dir2, 2, 128, "min_cavitation_margin_m<0:0.1");
    let (text, json) = r.until.clone().unwrap();
    assert!(text.contains("no valid instance has a value"), "{text}");
    assert!(!text.contains("NaN"), "{text}");
    assert!(json["estimate"].is_null(), "{json}");
    std::fs::remove_dir_all(dir2).ok();
    std::fs::remove_dir_all(dir).ok();
}
