//! `cryoslosh report` of results combined from several runs: merged shards report like one run, and a run with `[[variants]]` gets each variant's report and a front page with the differences.

mod common;
use common::campaign_path;
use common::report::{check_plots, cryoslosh, ok, scratch};
use std::path::PathBuf;

#[test]
fn merged_shards_report_like_a_run() {
    let dir = scratch("merge");
    let path = campaign_path("mhtb_selfpress");
    let shards: Vec<PathBuf> = (0..2).map(|i| dir.join(format!("shard{i}"))).collect();
    for (i, shard) in shards.iter().enumerate() {
        ok(&cryoslosh(&[
            "run",
            path.to_str().unwrap(),
            "--out",
            shard.to_str().unwrap(),
            "--instances",
            "30",
            "--backend",
            "cpu",
            "--shard",
            &format!("{i}/2"),
        ]));
    }
    let merged = dir.join("merged");
    ok(&cryoslosh(&[
        "merge",
        shards[0].to_str().unwrap(),
        shards[1].to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]));
    ok(&cryoslosh(&["report", merged.to_str().unwrap()]));
    let report = merged.join("report");
    let svgs = check_plots(&report);
    assert!(
        svgs.iter().any(|s| s == "worst_peak_pressure_pa.svg"),
        "{svgs:?}"
    );
    let html = std::fs::read_to_string(report.join("index.html")).unwrap();
    assert!(
        html.contains("2 shards (merged)"),
        "the header does not say it is a merge"
    );
    // The merged directory's own manifest still verifies: the report is beside, not in it.
    let manifest = std::fs::read_to_string(merged.join("manifest.json")).unwrap();
    assert!(!manifest.contains("report/"));
}

/// Regression: `report DIR` of a run with `[[variants]]` failed ("no instances.parquet"); it now
/// writes each variant's report and a front page with the statistics and paired differences.
#[test]
fn report_of_a_variants_run_has_each_variant_and_the_differences() {
    let run = scratch("variants").join("run");
    let path = campaign_path("tank_design_trade");
    let (path, out) = (path.to_str().unwrap(), run.to_str().unwrap());
    let mut args = vec![
        "run",
        path,
        "--out",
        out,
        "--instances",
        "6",
        "--backend",
        "cpu",
    ];
    for set in [
        "phases.pad_hold.duration_s=30",
        "phases.burn1.duration_s=100",
        "phases.coast.duration_s=300",
    ] {
        args.extend(["--set", set]);
    }
    ok(&cryoslosh(&args));
    ok(&cryoslosh(&["report", out]));
    let report = run.join("report");
    let html = std::fs::read_to_string(report.join("index.html")).unwrap();
    for needle in [
        "Statistics per variant",
        "Paired differences against the baseline",
        "<code>thick_insulation</code> − <code>baseline</code>",
        "slosh.baffle_count=0, tank.heat_leak_w=90",
        "variants/baffles_insulation/index.html",
    ] {
        assert!(html.contains(needle), "index.html lacks {needle}");
    }
    let diffs = run.join("differences.parquet");
    let rows = cryoslosh::montecarlo::table::read_f64(&diffs, "value").unwrap();
    assert_eq!(html.matches("_diff</td>").count(), rows.len());
    // The run summary's table showed the share of instances outside the slosh range and the
    // front page did not (two copies of the table's rows): one list of rows now serves both.
    let share = |name: &str| {
        let path = run.join("variants").join(name).join("instances.parquet");
        let flags = cryoslosh::montecarlo::table::read_flag(&path, "slosh_out_of_range").unwrap();
        flags.iter().filter(|x| **x == Some(true)).count() as f64 / flags.len() as f64
    };
    let base = share("baseline");
    assert!(
        base > 0.0,
        "the short unbaffled baseline should leave the slosh range"
    );
    let row =
        "<code>slosh_out_of_range</code> (share of valid instances)</td><td>fraction</td><td>";
    let at = html
        .find(row)
        .unwrap_or_else(|| panic!("index.html lacks {row}"));
    let cell = &html[at + row.len()..];
    let shown: f64 = cell[..cell.find('<').unwrap()].parse().unwrap();
    assert!(
        (shown - base).abs() < 1e-3,
        "baseline share {shown} shown, {base} flagged"
    );
    for name in [
        "baseline",
        "baffles",
        "thick_insulation",
        "baffles_insulation",
    ] {
        let own = report.join("variants").join(name);
        let svgs = check_plots(&own);
        assert!(svgs.iter().any(|s| s == "worst_boiloff_kg.svg"), "{name}");
    }
    let hidden = std::fs::read_dir(report.join("variants")).unwrap();
    assert!(hidden
        .filter_map(Result::ok)
        .all(|e| !e.file_name().to_string_lossy().starts_with('.')));
}
