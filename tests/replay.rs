//! `simulate --instance 274` after `run --instances 300` integrated a different instance (it
//! sampled with the campaign file's instance count and seed); a replay from the run's metadata
//! must reproduce its row bit for bit, for every design and for a sharded run.

mod common;
use common::load;
use cryoslosh::campaign::Campaign;
use cryoslosh::engine::{Backend, CpuEngine};
use cryoslosh::montecarlo::{self, replay, RunOptions, Shard};
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cryoslosh-replay-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn run(c: &Campaign, dir: &Path, n: u64, shard: Shard) {
    let opts = RunOptions {
        out_dir: dir.to_path_buf(),
        instances: n,
        seed: 1234,
        shard,
        chunk_size: 8,
        progress: false,
        histories: Vec::new(),
        until: None,
        force: false,
        resume: false,
    };
    let backend = Backend::Cpu(CpuEngine::new(2).unwrap());
    montecarlo::run(c, &backend, &opts).unwrap();
}

/// Replay `instances` of the run in `dir` and assert each equals its row.
fn assert_replays(dir: &Path, instances: &[u64]) {
    for &i in instances {
        let (run, record) = replay::replay(dir, i, None).unwrap();
        let diffs = replay::compare_row(dir, &run.campaign, &record).unwrap();
        assert!(
            diffs.is_empty(),
            "{}: instance {i}: {diffs:?}",
            dir.display()
        );
    }
}

#[test]
fn replay_equals_the_row_for_every_design() {
    for (design, n) in [
        ("monte_carlo", 24),
        ("latin_hypercube", 24),
        ("sobol", 24),
        ("saltelli", 25),
    ] {
        // The campaign file says 100 instances and seed 3; the run uses 24 (25) and 1234.
        let c = load(
            "mhtb_selfpress",
            &[
                "phases.0.duration_s=1800",
                "campaign.output_interval_s=600",
                "campaign.instances=100",
                "campaign.seed=3",
                &format!("dispersions.design={design}"),
            ],
        );
        let dir = scratch(design);
        run(&c, &dir, n, Shard::ALL);
        assert_replays(&dir, &[0, 5, n - 1]);
        std::fs::remove_dir_all(dir).ok();
    }
}

#[test]
fn replay_equals_the_row_of_a_shard_and_of_adaptive_steps() {
    let c = load(
        "mhtb_selfpress",
        &[
            "phases.0.duration_s=1800",
            "campaign.output_interval_s=600",
            "campaign.integrator=dopri5",
        ],
    );
    let dir = scratch("shard");
    run(&c, &dir, 30, Shard { index: 1, count: 3 });
    assert_replays(&dir, &[10, 13, 19]);
    // Instance 0 lives in another shard: said, not silently compared.
    let (run, record) = replay::replay(&dir, 0, None).unwrap();
    let err = replay::compare_row(&dir, &run.campaign, &record).unwrap_err();
    assert!(err.to_string().contains("no row for instance 0"), "{err}");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn cli_replay_reports_bit_equality_and_refuses_an_instance_beyond_the_run() {
    let c = load(
        "lch4_coast",
        &["phases.0.duration_s=3600", "campaign.output_interval_s=600"],
    );
    let dir = scratch("cli");
    run(&c, &dir, 12, Shard::ALL);
    let hist = dir.with_extension("h.parquet"); // beside the results, never inside
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_cryoslosh"))
        .args([
            "simulate",
            "--run",
            dir.to_str().unwrap(),
            "--instance",
            "11",
        ])
        .args(["--out", hist.to_str().unwrap()])
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{out}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(out.contains("bit for bit"), "{out}");
    assert!(hist.exists());
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_cryoslosh"))
        .args([
            "simulate",
            "--run",
            dir.to_str().unwrap(),
            "--instance",
            "12",
        ])
        .args(["--out", hist.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "instance beyond the run");
    std::fs::remove_file(hist).ok();
    std::fs::remove_dir_all(dir).ok();
}

/// `run --histories worst:QOI:N,instance:I` writes one history per chosen instance, and each
/// history ends where its row of instances.parquet does.
#[test]
fn run_writes_the_histories_of_the_worst_and_named_instances() {
    use cryoslosh::montecarlo::histories;
    use cryoslosh::montecarlo::table::{read_f64, read_u64};
    let c = load(
        "lch4_coast",
        &["phases.0.duration_s=7200", "campaign.output_interval_s=600"],
    );
    let dir = scratch("histories");
    let opts = RunOptions {
        out_dir: dir.clone(),
        instances: 16,
        seed: 5,
        shard: Shard::ALL,
        chunk_size: 8,
        progress: false,
        histories: histories::parse("worst:peak_pressure_pa:3,instance:4").unwrap(),
        until: None,
        force: false,
        resume: false,
    };
    let backend = Backend::Cpu(CpuEngine::new(2).unwrap());
    montecarlo::run(&c, &backend, &opts).unwrap();
    let inst = dir.join("instances.parquet");
    let ids = read_u64(&inst, "instance").unwrap();
    let peak = read_f64(&inst, "peak_pressure_pa").unwrap();
    let mut order: Vec<usize> = (0..ids.len()).collect();
    order.sort_by(|&a, &b| peak[b].total_cmp(&peak[a]));
    let mut expected: Vec<u64> = order[..3].iter().map(|&r| ids[r]).chain([4]).collect();
    expected.sort_unstable();
    expected.dedup();
    let mut written: Vec<String> = std::fs::read_dir(dir.join("histories"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    written.sort();
    let want: Vec<String> = expected
        .iter()
        .map(|&i| format!("instance_{i:09}.parquet"))
        .collect();
    assert_eq!(written, want);
    let vented = read_f64(&inst, "vented_kg").unwrap();
    let final_t = read_f64(&inst, "final_time_s").unwrap();
    for &i in &expected {
        let h = histories::history_path(&dir, i);
        let t = read_f64(&h, "time_s").unwrap();
        let v = read_f64(&h, "vented_kg").unwrap();
        let row = ids.iter().position(|&x| x == i).unwrap();
        assert_eq!(*t.last().unwrap(), final_t[row], "instance {i}");
        assert_eq!(*v.last().unwrap(), vented[row], "instance {i}");
    }
    std::fs::remove_dir_all(dir).ok();
}
