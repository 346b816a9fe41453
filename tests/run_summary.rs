//! The first line of `run`'s summary (found by a new-user test of the CLI): it said "1 threads".

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
