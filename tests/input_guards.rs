//! Inputs that passed `check` and then hung, panicked, produced NaN or destroyed a file:
//! `phases.N.dt_s = 1e-300` (ran forever), `tank.radius_m = 1e-300` (a NaN wall), `--threads
//! 100000` (16000 threads), `--instances 2^64 − 1` (a lost row or a hang), `simulate --out` on the
//! campaign itself (replaced by Parquet), a CSV whose first data row had a typo (skipped as a
//! header) and a diverged history with nothing marking it.

mod common;
use common::campaign_path;
use std::path::PathBuf;
use std::process::{Command, Output};

fn cryoslosh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cryoslosh"))
        .args(args)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cryoslosh-guards-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn absurd_steps_radii_threads_and_instances_exit_2_naming_them() {
    let camp = campaign_path("mhtb_selfpress");
    let camp = camp.to_str().unwrap();
    for (set, key) in [
        ("phases.0.dt_s=1e-300", "phases.0.dt_s"),
        ("phases.0.dt_s=1e-5", "phases.0.dt_s"), // 14400 s / 1e-5 s = 1.44e9 steps
        ("tank.radius_m=1e-300", "tank.radius_m"),
    ] {
        let o = cryoslosh(&["check", camp, "--set", set]);
        assert_eq!(o.status.code(), Some(2), "{set}: {}", stderr(&o));
        assert!(stderr(&o).contains(key), "{set}: {}", stderr(&o));
    }
    let out = scratch("absurd");
    let o = cryoslosh(&[
        "run",
        camp,
        "--out",
        out.to_str().unwrap(),
        "--threads",
        "100000",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--threads"));
    let o = cryoslosh(&[
        "run",
        camp,
        "--out",
        out.join("r").to_str().unwrap(),
        "--instances",
        "18446744073709551615",
        "--backend",
        "cpu",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--instances"), "{}", stderr(&o));
    std::fs::remove_dir_all(out).ok();
}

#[test]
fn simulate_never_writes_over_its_inputs_or_a_special_file() {
    let dir = scratch("inputs");
    let campaign = dir.join("c.toml");
    let text = std::fs::read_to_string(campaign_path("aydelott_sphere")).unwrap();
    std::fs::write(&campaign, &text).unwrap();
    let c = campaign.to_str().unwrap();
    let o = cryoslosh(&["simulate", c, "--out", c]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(
        std::fs::read_to_string(&campaign).unwrap(),
        text,
        "the campaign survives"
    );
    // An excitation table the campaign reads.
    std::fs::write(dir.join("shake.csv"), "time_s,a_lat_m_s2\n0,0\n10,0.1\n").unwrap();
    std::fs::write(
        &campaign,
        text.clone() + "excitation = { kind = \"table\", file = \"shake.csv\" }\n",
    )
    .unwrap();
    let csv = dir.join("shake.csv");
    let o = cryoslosh(&["simulate", c, "--out", csv.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(std::fs::read_to_string(&csv).unwrap().starts_with("time_s"));
    // A directory at --out.
    let o = cryoslosh(&["simulate", c, "--out", dir.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn csv_header_only_by_name_bom_accepted_typos_named() {
    let dir = scratch("csv");
    let text = std::fs::read_to_string(campaign_path("aydelott_sphere")).unwrap()
        + "excitation = { kind = \"table\", file = \"shake.csv\" }\n";
    let campaign = dir.join("c.toml");
    std::fs::write(&campaign, text).unwrap();
    let check = |csv: &str| {
        std::fs::write(dir.join("shake.csv"), csv).unwrap();
        cryoslosh(&["check", campaign.to_str().unwrap()])
    };
    // A BOM and a header by name are fine.
    let o = check("\u{feff}time_s,a_lat_m_s2\n0,0\n10,1.9\n");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // A typo in the first data row is an error naming line and column, not a skipped header.
    let o = check("0,2.O\n10,1.9\n");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("shake.csv:1: column 2") && e.contains("2.O"),
        "{e}"
    );
    // So is a header with other names.
    let o = check("t,a\n0,0\n10,1.9\n");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn a_diverged_history_says_so_in_its_metadata() {
    use cryoslosh::montecarlo::table::read_metadata;
    let dir = scratch("diverged");
    let out = dir.join("h.parquet");
    // A fixed step far too coarse for the ascent's slosh (allowed on purpose) diverges.
    let o = cryoslosh(&[
        "simulate",
        campaign_path("lox_ascent").to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--set",
        "campaign.allow_coarse_step=true",
        "--set",
        "phases.ascent.dt_s=5",
        "--set",
        "phases.pad.duration_s=1",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let meta = read_metadata(&out).unwrap();
    let diverged = meta
        .iter()
        .find(|(k, _)| k == "cryoslosh.diverged")
        .map(|(_, v)| v.clone())
        .unwrap();
    assert!(
        diverged.starts_with("true: ") && diverged.contains("ascent"),
        "{diverged}"
    );
    // A healthy one says false.
    let o = cryoslosh(&[
        "simulate",
        campaign_path("aydelott_sphere").to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let meta = read_metadata(&out).unwrap();
    assert!(meta
        .iter()
        .any(|(k, v)| k == "cryoslosh.diverged" && v == "false"));
    std::fs::remove_dir_all(dir).ok();
}
