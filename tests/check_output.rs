//! `cryoslosh check` prints values as a person reads them (no Rust `Debug`), `number` rounds as
//! documented, and `cryoslosh init` writes a template campaign that loads, checks and runs.

mod common;
use common::{campaign_path, CAMPAIGNS};
use cryoslosh::campaign::template::TEMPLATE;
use cryoslosh::campaign::{number, Campaign};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn cryoslosh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cryoslosh"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// A fresh, empty directory for one test.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cryoslosh-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Debug output of a struct, an Option or an enum variant with fields, as `check` once printed.
fn debug_leak(out: &str) -> Option<String> {
    let variants = [
        "Normal {",
        "TruncatedNormal {",
        "Uniform {",
        "LogNormal {",
        "Triangular {",
        "Choice {",
        "Gust {",
        "Sine {",
        "Sweep {",
        "Step {",
        "Ramp {",
        "Table {",
    ];
    for line in out.lines() {
        let leak = line.contains("Some(")
            || line.contains("None")
            || line.contains("{ ")
            || line.contains(" }")
            || variants.iter().any(|v| line.contains(v));
        if leak {
            return Some(line.to_string());
        }
    }
    None
}

fn check_is_readable(path: &Path) -> String {
    let o = cryoslosh(&["check", path.to_str().unwrap()]);
    let out = text(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "check {}: {}",
        path.display(),
        text(&o.stderr)
    );
    if let Some(line) = debug_leak(&out) {
        panic!("check {} prints Debug: {line}\n{out}", path.display());
    }
    out
}

/// (a) Every shipped campaign, the template included, checks cleanly and reads as values.
#[test]
fn check_prints_no_debug_on_shipped_campaigns() {
    for name in CAMPAIGNS.iter().copied().chain(["template"]) {
        let out = check_is_readable(&campaign_path(name));
        // Sections under the campaign's key names, values with units.
        for needle in [
            "tank: shape ",
            "heat_leak_w ",
            "heat_transfer:",
            "phases.0: name ",
        ] {
            assert!(out.contains(needle), "{name}: no {needle:?}\n{out}");
        }
    }
}

/// The guard in (a) catches the old Debug printout.
#[test]
fn debug_leak_detects_debug_output() {
    assert!(debug_leak("pressurization: Some(Pressurization { setpoint_pa: 1.0 })").is_some());
    assert!(debug_leak("heat transfer: HeatTransfer { h_us_w_per_m2_k: None }").is_some());
    assert!(debug_leak("  x: TruncatedNormal { mean: 150.0, std: 25.0 }").is_some());
    assert!(debug_leak("excitation Gust { amplitude: 0.3 }").is_some());
    assert!(debug_leak("relief: crack_pa 300000 Pa, reseat_pa 280000 Pa").is_none());
}

/// The LH2 campaign's sections, defaults and dispersions in their readable form.
#[test]
fn check_prints_keys_values_and_defaults() {
    let out = check_is_readable(&campaign_path("lh2_upper_stage"));
    for needle in [
        "relief: crack_pa 300000 Pa, reseat_pa 280000 Pa, flow_area_m2 1e-4 m²",
        "pressurization: setpoint_pa 220000 Pa, kp_kg_per_s_pa 2e-6 kg/(s·Pa)",
        "h_ullage_interface_w_per_m2_k: correlation (McAdams",
        "h_wall_liquid_w_per_m2_k: correlation (Churchill–Chu",
        "evaporation_coefficient_kg_per_s_pa: from Schrage kinetic theory with accommodation_coefficient, initial ≈ ",
        "excitation gust(amplitude_m_s2 0.3, start_s 60, duration_s 4)",
        "excitation sine(amplitude_m_s2 0.05, frequency_hz 0.4, phase_rad 0)",
        "excitation none",
        "boiloff_budget_kg 12 kg",
        "confidence 0.95",
        "truncated_normal(mean 150, std 25, lo 80, hi 250)",
        "lognormal(median 0.3, sigma 0.4)",
        "choice(2, 3, 4; weights 1, 2, 1)",
        "correlated: tank.heat_leak_w ~ ullage.temperature_k, rho 0.5",
    ] {
        assert!(out.contains(needle), "no {needle:?}\n{out}");
    }
    // Absent sections say so.
    let out = check_is_readable(&campaign_path("aydelott_sphere"));
    for needle in [
        "pressurization: none",
        "relief: none",
        "dispersions: none",
        "tank: shape sphere, radius_m 0.11505 m, heat_leak_w",
    ] {
        assert!(out.contains(needle), "no {needle:?}\n{out}");
    }
    let out = check_is_readable(&campaign_path("lch4_coast"));
    assert!(out.contains("boiloff_budget_kg 4 kg"), "{out}");
    let out = check_is_readable(&campaign_path("mhtb_selfpress"));
    assert!(out.contains("boiloff_budget_kg none"), "{out}");
}

/// A tabulated excitation is summarised (file, rows, time span), not dumped.
#[test]
fn check_summarises_an_excitation_table() {
    let dir = temp_dir("check-table");
    let mut csv = String::from("time_s,a_lat_m_s2\n");
    for i in 0..121 {
        csv.push_str(&format!(
            "{},{}\n",
            2.5 * f64::from(i),
            0.01 * f64::from(i % 7)
        ));
    }
    std::fs::write(dir.join("shake.csv"), csv).unwrap();
    let campaign = std::fs::read_to_string(campaign_path("aydelott_sphere")).unwrap()
        + "excitation = { kind = \"table\", file = \"shake.csv\" }\n";
    let path = dir.join("table.toml");
    std::fs::write(&path, campaign).unwrap();
    let out = check_is_readable(&path);
    assert!(
        out.contains("excitation table(shake.csv: 121 rows, 0–300 s)"),
        "{out}"
    );
    assert!(!out.contains("0.01, 0.02"), "table values dumped: {out}");
    std::fs::remove_dir_all(&dir).ok();
}

/// (b) `number`: 6 significant digits, no trailing zeros, exponent form outside [1e-3, 1e7).
#[test]
fn number_rounds_as_documented() {
    let cases = [
        (0.0, "0"),
        (-0.0, "0"),
        (1.0, "1"),
        (150.0, "150"),
        (0.1538, "0.1538"),
        (1e-4, "1e-4"),
        (2e-6, "2e-6"),
        (6644.284, "6644.28"),
        (1.5e8, "1.5e8"),
        (-3.25, "-3.25"),
        (f64::INFINITY, "inf"),
        (f64::NEG_INFINITY, "-inf"),
        (f64::NAN, "nan"),
        (0.001, "0.001"),
        (9_999_999.0, "1e7"),
        (1234567.0, "1234570"),
        (0.30000000000000004, "0.3"),
        (1.234_567_89e-5, "1.23457e-5"),
        (-2.5e9, "-2.5e9"),
    ];
    for (v, want) in cases {
        assert_eq!(number(v), want, "number({v:e})");
    }
}

/// (c) `init` writes a template that loads; a second `init` refuses without `--force`.
#[test]
fn init_writes_a_template_and_refuses_to_overwrite() {
    let dir = temp_dir("init");
    let path = dir.join("campaign.toml");
    let p = path.to_str().unwrap();
    let o = cryoslosh(&["init", p]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    assert!(out.contains(p), "does not say where: {out}");
    assert!(
        out.contains(&format!("cryoslosh check {p}"))
            && out.contains(&format!("cryoslosh run {p}")),
        "no next commands: {out}"
    );
    assert_eq!(std::fs::read_to_string(&path).unwrap(), TEMPLATE);
    let c = Campaign::load(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(c.dispersions.inputs.len(), 3);
    assert!(c.params.pressurization.is_some() && c.params.relief.is_some());

    // An existing file is kept as it is.
    std::fs::write(&path, "# my edits\n").unwrap();
    let o = cryoslosh(&["init", p]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains(p), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("--force"), "{}", text(&o.stderr));
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "# my edits\n");

    let o = cryoslosh(&["init", p, "--force"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_eq!(std::fs::read_to_string(&path).unwrap(), TEMPLATE);

    // Without a path: campaign.toml in the current directory.
    let o = Command::new(env!("CARGO_BIN_EXE_cryoslosh"))
        .arg("init")
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    std::fs::remove_file(&path).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_cryoslosh"))
        .arg("init")
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_eq!(std::fs::read_to_string(&path).unwrap(), TEMPLATE);
    std::fs::remove_dir_all(&dir).ok();
}

/// The shipped template is the embedded one, and every key it sets carries a comment.
#[test]
fn template_is_the_shipped_file_and_commented() {
    let shipped = std::fs::read_to_string(campaign_path("template")).unwrap();
    assert_eq!(shipped, TEMPLATE);
    for line in TEMPLATE.lines() {
        let t = line.trim();
        let is_key = !t.starts_with('#') && !t.starts_with('[') && t.contains(" = ");
        // Dispersion entries are documented once, above them.
        let in_list = [
            "key",
            "distribution",
            "mean",
            "std",
            "lo",
            "hi",
            "median",
            "sigma",
        ]
        .iter()
        .any(|k| t.starts_with(&format!("{k} = ")));
        if is_key && !in_list && !t.starts_with("name = ") {
            assert!(t.contains('#'), "uncommented key: {line}");
        }
    }
}

/// (d) The template's dispersions resolve: a small run on the CPU succeeds.
#[test]
fn template_runs_a_small_campaign() {
    let dir = temp_dir("template-run");
    let out = dir.join("run");
    let o = cryoslosh(&[
        "run",
        campaign_path("template").to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--instances",
        "8",
        "--backend",
        "cpu",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let summary = text(&o.stdout);
    assert!(
        summary.contains("8 instances (0 diverged, 0 rejected)"),
        "{summary}"
    );
    assert!(out.join("instances.parquet").exists());
    std::fs::remove_dir_all(&dir).ok();
}
