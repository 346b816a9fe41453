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
    let camp = campaign_path("mhtb_selfpress");
    let mut args = vec![
        "run",
        camp.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--backend",
        "cpu",
        "--set",
        "phases.0.duration_s=600",
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
