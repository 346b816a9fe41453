//! The first line of `run`'s summary (found by a new-user test of the CLI): it said "1 threads",
//! and after `--resume` its rate divided every instance-step, those loaded from the checkpoint
//! too, by the wall time of the resumed part alone; nothing said which CPU build ran, nor how
//! many right-hand sides a second it evaluated.

mod common;
use common::campaign_path;
use std::path::{Path, PathBuf};
use std::process::Output;

fn scratch(name: &str) -> PathBuf {
    common::scratch_in("summary", name)
}

/// `run` of a short MHTB campaign into `out` on the CPU with `extra` options.
fn run(out: &Path, extra: &[&str], failpoint: Option<&str>) -> Output {
    let mut args = vec!["--set", "phases.0.duration_s=600"];
    args.extend_from_slice(extra);
    run_campaign("mhtb_selfpress", out, &args, failpoint)
}

/// `run` of the shipped campaign `name` into `out` on the CPU with `extra` options.
fn run_campaign(name: &str, out: &Path, extra: &[&str], failpoint: Option<&str>) -> Output {
    let camp = campaign_path(name);
    let mut args = vec![
        "run",
        camp.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--backend",
        "cpu",
    ];
    args.extend_from_slice(extra);
    common::cryoslosh_at(&args, failpoint)
}

fn first_line(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .next()
        .unwrap_or_default()
        .to_string()
}

/// Regression: one worker thread was reported as "cpu: 1 threads" (summary and run.json).
#[test]
fn one_thread_is_singular() {
    let root = scratch("threads");
    for (threads, device) in [("1", "cpu: 1 thread"), ("2", "cpu: 2 threads")] {
        let out = root.join(threads);
        let o = run(&out, &["--instances", "4", "--threads", threads], None);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let line = first_line(&o);
        assert!(line.ends_with(&format!("on {device}")), "{line}");
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("run.json")).unwrap()).unwrap();
        assert_eq!(json["device"], device);
    }
    std::fs::remove_dir_all(root).ok();
}

/// Regression: a resumed run's rate counted the instance-steps loaded from the checkpoint as if
/// integrated in the resumed part's wall time (6.9e5 against 5.7e5 instance-steps/s).
#[test]
fn resumed_rate_counts_only_the_steps_integrated_now() {
    let root = scratch("resume");
    let out = root.join("r");
    let args = ["--instances", "16", "--chunk-size", "4", "--threads", "1"];
    // Killed after its second block: 8 instances committed, 8 left.
    let o = run(&out, &args, Some("after-part-1"));
    assert!(!o.status.success(), "the failpoint must stop the process");
    let o = run(&out, &[&args[..], &["--resume"]].concat(), None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("run.json")).unwrap()).unwrap();
    let total = json["instance_steps"].as_u64().unwrap();
    let resumed = json["resumed_instance_steps"].as_u64().unwrap();
    assert!(resumed > 0 && resumed < total, "{json}");
    let now = total - resumed;
    let wall = json["wall_s"].as_f64().unwrap();
    let rate = json["instance_steps_per_s"].as_f64().unwrap();
    assert!(
        (rate * wall - now as f64).abs() <= 1e-9 * now as f64,
        "the rate must be the {now} steps integrated now over {wall} s: {json}"
    );
    // So do the right-hand-side evaluations: half the instances came from the checkpoint.
    let evals = json["rhs_evaluations"].as_u64().unwrap();
    let resumed_evals = json["resumed_rhs_evaluations"].as_u64().unwrap();
    assert_eq!(2 * resumed_evals, evals, "{json}");
    let rhs_rate = json["rhs_evaluations_per_s"].as_f64().unwrap();
    let evals_now = (evals - resumed_evals) as f64;
    assert!(
        (rhs_rate * wall - evals_now).abs() <= 1e-9 * evals_now,
        "{json}"
    );
    let line = first_line(&o);
    assert!(
        line.contains(&format!(
            "{total} instance-steps ({resumed} from the checkpoint, {now} integrated now) in"
        )),
        "{line}"
    );
    // An uninterrupted run says nothing of a checkpoint, and its rate is all its steps.
    let whole = root.join("whole");
    let o = run(&whole, &args, None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(first_line(&o).contains(&format!("{total} instance-steps in")));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(whole.join("run.json")).unwrap()).unwrap();
    assert_eq!(json["resumed_instance_steps"], 0);
    std::fs::remove_dir_all(root).ok();
}

/// Regression (issue 18): nothing said which CPU build ran (lanes per group, AVX2 or AVX-512),
/// though the speed depends on it: `--version`, `run.json` and every Parquet file say it now.
#[test]
fn the_cpu_build_is_recorded_in_version_run_json_and_parquet() {
    let v = common::cryoslosh_at(&["--version"], None);
    assert!(v.status.success());
    let text = String::from_utf8_lossy(&v.stdout);
    let build = text
        .lines()
        .find_map(|l| l.strip_prefix("build: "))
        .unwrap_or_else(|| panic!("no build line in --version: {text}"))
        .to_string();
    let width = build
        .split(", ")
        .nth(1)
        .and_then(|w| w.strip_suffix(" f64 lanes"))
        .and_then(|w| w.parse::<usize>().ok())
        .unwrap_or_else(|| panic!("no lane width in {build}"));
    assert!(width == 16 || width == 32, "{build}");
    let root = scratch("build");
    let out = root.join("r");
    let o = run(&out, &["--instances", "4", "--threads", "1"], None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(json["build"], build.as_str());
    let file = std::fs::File::open(out.join("instances.parquet")).unwrap();
    let meta = parquet::file::reader::SerializedFileReader::new(file).unwrap();
    let kv = parquet::file::reader::FileReader::metadata(&meta)
        .file_metadata()
        .key_value_metadata()
        .cloned()
        .unwrap_or_default();
    let stored = kv.iter().find(|e| e.key == "cryoslosh.build");
    assert_eq!(
        stored.and_then(|e| e.value.as_deref()),
        Some(build.as_str())
    );
    std::fs::remove_dir_all(root).ok();
}

/// Issue 18 asks for right-hand-side evaluations per second of a `run`, a rate that does not
/// depend on the integrator; instance-steps/s alone hid it (an RK4 step is four evaluations, a
/// Dormand–Prince step seven). Each instance's count is checked against the methods' cost, the
/// run's total against the column, and the rate against total over wall time.
#[test]
fn rhs_evaluations_are_each_methods_cost_and_their_rate_is_reported() {
    let root = scratch("rhs");
    let read = |dir: &Path| -> (serde_json::Value, Vec<u64>, Vec<u64>) {
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join("run.json")).unwrap()).unwrap();
        let inst = dir.join("instances.parquet");
        let col = |n| cryoslosh::montecarlo::table::read_u64(&inst, n).unwrap();
        (json, col("steps"), col("rhs_evaluations"))
    };
    // RK4 on a locked-up tank (one phase, no valve): the initial state's evaluation, then five
    // on the first step (k1 is evaluated there) and four on each later one (k1 is the previous
    // step's end-of-step evaluation): 4 n + 2 for n steps.
    let out = root.join("rk4");
    let o = run(&out, &["--instances", "6", "--threads", "2"], None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (json, steps, evals) = read(&out);
    for (n, e) in steps.iter().zip(&evals) {
        assert_eq!(*n, 300, "600 s in 2 s steps");
        assert_eq!(*e, 4 * n + 2);
    }
    let total: u64 = evals.iter().sum();
    assert_eq!(json["rhs_evaluations"].as_u64(), Some(total), "{json}");
    assert_eq!(json["resumed_rhs_evaluations"].as_u64(), Some(0));
    let (rate, wall) = (
        json["rhs_evaluations_per_s"].as_f64().unwrap(),
        json["wall_s"].as_f64().unwrap(),
    );
    assert!(
        (rate * wall - total as f64).abs() <= 1e-9 * total as f64,
        "{json}"
    );
    assert!(
        first_line(&o).contains(" right-hand sides/s) on cpu"),
        "{}",
        first_line(&o)
    );
    // Dormand–Prince: six stages a try (the seventh is the next try's first), the mid-step probe
    // of an accepted step, so at least seven per accepted step.
    let out = root.join("dopri5");
    let o = run(
        &out,
        &["--instances", "6", "--set", "campaign.integrator=dopri5"],
        None,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (json, steps, evals) = read(&out);
    for (n, e) in steps.iter().zip(&evals) {
        assert!(
            *e > 7 * n && *e < 7 * n + 6 * n + 50,
            "{n} steps, {e} evaluations"
        );
    }
    assert_eq!(json["rhs_evaluations"].as_u64(), Some(evals.iter().sum()));
    std::fs::remove_dir_all(root).ok();
}

/// Regression (found by a new-user test of the cost outputs): a merge's `run.json` summed the
/// shards' wall times and threads and dropped each shard's own, though the README said it kept
/// them, so its rate read as the job's. Now it lists every shard's record (`shards`) and the
/// summary line says its time is the shards' summed and its rate per shard.
#[test]
fn a_merge_keeps_each_shards_own_cost() {
    let root = scratch("merge");
    let mut dirs = Vec::new();
    let mut shard_walls = Vec::new();
    for i in 0..2 {
        let out = root.join(format!("s{i}"));
        let shard = format!("{i}/2");
        let o = run(
            &out,
            &["--instances", "6", "--threads", "1", "--shard", &shard],
            None,
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("run.json")).unwrap()).unwrap();
        shard_walls.push(json["wall_s"].as_f64().unwrap());
        dirs.push(out);
    }
    let merged = root.join("merged");
    let o = common::cryoslosh_at(
        &[
            "merge",
            dirs[0].to_str().unwrap(),
            dirs[1].to_str().unwrap(),
            "--out",
            merged.to_str().unwrap(),
        ],
        None,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(merged.join("run.json")).unwrap()).unwrap();
    let shards = json["shards"].as_array().expect("a merge lists its shards");
    assert_eq!(shards.len(), 2, "{json}");
    for (i, (s, wall)) in shards.iter().zip(&shard_walls).enumerate() {
        assert_eq!(s["shard"], format!("{i}/2"));
        assert_eq!(s["threads"], 1);
        assert_eq!(s["device"], "cpu: 1 thread");
        assert_eq!(s["wall_s"].as_f64(), Some(*wall));
        assert!(s["rhs_evaluations_per_s"].as_f64().unwrap() > 0.0, "{s}");
    }
    let evals: u64 = shards
        .iter()
        .map(|s| s["rhs_evaluations"].as_u64().unwrap())
        .sum();
    assert_eq!(json["rhs_evaluations"].as_u64(), Some(evals));
    let summed: f64 = shard_walls.iter().sum();
    assert!((json["wall_s"].as_f64().unwrap() - summed).abs() <= 1e-12 * summed);
    let line = first_line(&o);
    assert!(
        line.contains("summed over 2 shards' wall times")
            && line.contains("instance-steps/s per shard"),
        "{line}"
    );
    std::fs::remove_dir_all(root).ok();
}

/// Regression (same test): a run with `[[variants]]` reported no cost at its top level and no
/// rates on its summary lines; and a resumed run that found every instance committed stored a
/// rate of 0 (it integrated nothing, which is not a speed).
#[test]
fn variants_report_their_cost_and_a_run_with_nothing_left_has_no_rate() {
    let root = scratch("variants");
    let out = root.join("trade");
    let o = run_campaign(
        "tank_design_trade",
        &out,
        &[
            "--instances",
            "3",
            "--threads",
            "1",
            "--set",
            "phases.0.duration_s=60",
        ],
        None,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    let variant_lines: Vec<&str> = text.lines().filter(|l| l.starts_with("variant ")).collect();
    assert!(variant_lines.len() >= 2, "{text}");
    for l in &variant_lines {
        assert!(l.contains(" right-hand sides/s) on cpu"), "{l}");
    }
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("run.json")).unwrap()).unwrap();
    let variants = json["variants"].as_array().unwrap();
    let mut evals = 0;
    for v in variants {
        let dir = out.join(v["dir"].as_str().unwrap());
        let own: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join("run.json")).unwrap()).unwrap();
        for k in [
            "instance_steps",
            "rhs_evaluations",
            "wall_s",
            "rhs_evaluations_per_s",
        ] {
            assert_eq!(v[k], own[k], "{k}: {v} against {own}");
        }
        evals += v["rhs_evaluations"].as_u64().unwrap();
    }
    assert_eq!(json["rhs_evaluations"].as_u64(), Some(evals), "{json}");
    assert!(json["rhs_evaluations_per_s"].as_f64().unwrap() > 0.0);

    // Killed after its instances were committed, resumed: nothing is integrated again.
    let done = root.join("done");
    let args = ["--instances", "4", "--threads", "1"];
    let o = run(&done, &args, Some("after-instances"));
    assert!(!o.status.success(), "the failpoint must stop the process");
    let o = run(&done, &[&args[..], &["--resume"]].concat(), None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(done.join("run.json")).unwrap()).unwrap();
    assert_eq!(
        json["instance_steps"], json["resumed_instance_steps"],
        "{json}"
    );
    assert!(json["instance_steps_per_s"].is_null(), "{json}");
    assert!(json["rhs_evaluations_per_s"].is_null(), "{json}");
    assert!(
        first_line(&o).contains("(none integrated now)"),
        "{}",
        first_line(&o)
    );
    std::fs::remove_dir_all(root).ok();
}

/// Regression (same test): a thermodynamic vent system that starts on costs the start a second
/// evaluation (the state evaluated again with the TVS running), which the CPU did not count (the
/// GPU kernel evaluates the same two). Ten RK4 steps with the TVS on throughout: 4 n + 3.
#[test]
fn a_tvs_that_starts_on_counts_its_second_initial_evaluation() {
    let root = scratch("tvs_start");
    let out = root.join("r");
    let o = run_campaign(
        "lh2_tvs_coast",
        &out,
        &[
            "--instances",
            "4",
            "--threads",
            "1",
            "--set",
            "campaign.integrator=rk4",
            "--set",
            "ullage.pressure_pa=135000",
            "--set",
            "campaign.dt_s=20",
            "--set",
            "campaign.allow_coarse_step=true",
            "--set",
            "phases.0.duration_s=200",
        ],
        None,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let inst = out.join("instances.parquet");
    let col = |n| cryoslosh::montecarlo::table::read_u64(&inst, n).unwrap();
    let (steps, evals, tvs) = (col("steps"), col("rhs_evaluations"), col("tvs_cycles"));
    for ((n, e), t) in steps.iter().zip(&evals).zip(&tvs) {
        assert_eq!((*n, *t), (10, 1), "ten steps, the TVS on from the start");
        assert_eq!(*e, 4 * n + 3);
    }
    std::fs::remove_dir_all(root).ok();
}
