//! Helpers of the `report` tests: run the binary, and check every plot of a report.

use super::campaign_path;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Run the `cryoslosh` binary with `args`.
pub fn cryoslosh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cryoslosh"))
        .args(args)
        .output()
        .expect("binary runs")
}

pub fn ok(o: &Output) {
    assert!(
        o.status.success(),
        "exit {:?}: {}",
        o.status.code(),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// A fresh empty directory under the target's temp dir.
pub fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("report-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Run `campaign` with `instances` and extra args into `dir/run`, then `report` it.
pub fn run_and_report(dir: &Path, campaign: &str, instances: &str, extra: &[&str]) -> PathBuf {
    let run = dir.join("run");
    let path = campaign_path(campaign);
    let mut args = vec![
        "run",
        path.to_str().unwrap(),
        "--out",
        run.to_str().unwrap(),
        "--instances",
        instances,
        "--backend",
        "cpu",
    ];
    args.extend_from_slice(extra);
    ok(&cryoslosh(&args));
    let o = cryoslosh(&["report", run.to_str().unwrap()]);
    ok(&o);
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("re-simulating worst case"),
        "no progress line for the re-simulations"
    );
    run.join("report")
}

/// The unit a column name's suffix spells (the names of these campaigns' columns).
fn unit(column: &str) -> &'static str {
    let base = column.split('.').next().unwrap();
    for (suffix, unit) in [
        ("_n_m", "N·m"),
        ("_pa", "Pa"),
        ("_kg", "kg"),
        ("_rad", "rad"),
        ("_k", "K"),
        ("_s", "s"),
        ("_n", "N"),
        ("_m", "m"),
        ("_w", "W"),
    ] {
        if base.ends_with(suffix) {
            return unit;
        }
    }
    "1"
}

/// The `src` of every `<img>` in index.html.
pub fn images(html: &str) -> Vec<String> {
    html.split("<img src=\"")
        .skip(1)
        .map(|s| s.split('"').next().unwrap().to_string())
        .collect()
}

/// Check every plot of a report: non-empty, referenced, labelled with its quantity and unit.
pub fn check_plots(report: &Path) -> Vec<String> {
    let html = std::fs::read_to_string(report.join("index.html")).unwrap();
    let referenced = images(&html);
    assert!(!referenced.is_empty(), "index.html shows no plot");
    for src in &referenced {
        assert!(
            !src.contains("://") && !src.starts_with('/'),
            "{src} is not a local file"
        );
        let len = std::fs::metadata(report.join(src))
            .map(|m| m.len())
            .unwrap_or(0);
        assert!(
            len > 0,
            "index.html references {src}, which is missing or empty"
        );
    }
    let mut svgs = Vec::new();
    for e in std::fs::read_dir(report).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        let Some(stem) = name.strip_suffix(".svg") else {
            continue;
        };
        assert!(
            referenced.contains(&name),
            "{name} is written but not shown"
        );
        let svg = std::fs::read_to_string(report.join(&name)).unwrap();
        assert!(
            svg.contains("<svg") && svg.contains("</svg>"),
            "{name} is not an SVG"
        );
        let (kind, column) = stem.split_once('_').unwrap();
        // File names spell a per-phase column's dot (`boiloff_kg.hold`) as a dash.
        let column = column.replace('-', ".");
        let column = column.as_str();
        // Every plot names its quantity with its unit on an axis or in its title.
        assert!(svg.contains(column), "{name} does not name {column}");
        let labelled = format!("{column} ({})", unit(column));
        match kind {
            "hist" | "exceed" | "scatter" => {
                assert!(svg.contains(&labelled), "{name} has no axis {labelled}")
            }
            "spearman" => assert!(svg.contains("Spearman ρ (1)"), "{name}: no ρ axis"),
            "sobol" => assert!(svg.contains("Sobol index (1)"), "{name}: no index axis"),
            "worst" | "worst2" | "worst3" => {
                for axis in [
                    "time_s (s)",
                    "pressure_pa (Pa)",
                    "temperature (K)",
                    "fill_fraction (1)",
                ] {
                    assert!(svg.contains(axis), "{name} has no axis {axis}");
                }
                let title = match kind {
                    "worst2" => format!("2nd worst {column}: instance"),
                    "worst3" => format!("3rd worst {column}: instance"),
                    _ => format!("worst {column}: instance"),
                };
                let suffix = format!(" {}", unit(column));
                assert!(
                    svg.lines()
                        .any(|l| l.contains(&title) && l.ends_with(&suffix)),
                    "{name}: no title naming {column} and its worst value in {}",
                    unit(column)
                );
            }
            other => panic!("unexpected plot kind {other} ({name})"),
        }
        svgs.push(name);
    }
    svgs
}
