//! The command line: `check` and `simulate` on shipped campaigns, and one test per class of bad
//! input — exit code 2 and a message that names the key (DESIGN.md interface contract).

mod common;
use common::{campaign_path, load};
use std::process::{Command, Output};

fn cryoslosh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cryoslosh"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs `check` on the LH2 campaign with one override and expects exit 2 naming `needle`.
fn rejects(set: &str, needle: &str) {
    let path = campaign_path("lh2_upper_stage");
    let o = cryoslosh(&["check", path.to_str().unwrap(), "--set", set]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "--set {set}: {err}");
    assert!(
        err.contains(needle),
        "--set {set}: message does not name {needle}: {err}"
    );
    assert!(
        err.contains("lh2_upper_stage.toml"),
        "message does not name the file: {err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn out_of_range_values_name_key_and_range() {
    rejects("tank.radius_m=-1", "tank.radius_m");
    rejects("propellant.fill_fraction=1.5", "propellant.fill_fraction");
    rejects("phases.1.duration_s=0", "phases.1.duration_s");
    rejects("relief.reseat_pa=400000", "relief.reseat_pa");
    let o = cryoslosh(&[
        "check",
        campaign_path("mhtb_selfpress").to_str().unwrap(),
        "--set",
        "propellant.fill_fraction=0.999",
    ]);
    assert!(
        stderr(&o).contains("expected a finite number in [0.02, 0.98]"),
        "{}",
        stderr(&o)
    );
}

/// A fixed RK4 step that resolves the excitation or slosh period with fewer than 20 steps is
/// refused naming the key that set it (issue 11: LOX `dt_s = 0.4` ran and halved the boil-off).
#[test]
fn coarse_fixed_step_is_refused_naming_the_key() {
    let lox = campaign_path("lox_ascent");
    let o = cryoslosh(&["check", lox.to_str().unwrap(), "--set", "campaign.dt_s=0.4"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("campaign.dt_s") && err.contains("excitation period"),
        "{err}"
    );
    rejects("phases.1.dt_s=0.3", "phases.1.dt_s");
    rejects("campaign.integrator=euler", "campaign.integrator");
    rejects("campaign.rtol=0", "campaign.rtol");
    // The campaign may say it knows, or integrate adaptively instead.
    for set in [
        "campaign.allow_coarse_step=true",
        "campaign.integrator=dopri5",
    ] {
        let o = cryoslosh(&[
            "check",
            lox.to_str().unwrap(),
            "--set",
            "campaign.dt_s=0.4",
            "--set",
            set,
        ]);
        assert_eq!(o.status.code(), Some(0), "{set}: {}", stderr(&o));
    }
}

/// `check` on a campaign whose nominal instance leaves the model (a 1 MW heat leak boils the
/// MHTB tank's liquid past its property range in 20 s) prints the plan, then fails with the
/// reason and `simulate`'s exit code 1: it exited 0 after printing "DIVERGED" (found by a
/// new-user attack), so a script gating on `check` passed a campaign that cannot run.
#[test]
fn check_fails_when_the_nominal_instance_diverges() {
    let mhtb = campaign_path("mhtb_selfpress");
    let o = cryoslosh(&[
        "check",
        mhtb.to_str().unwrap(),
        "--set",
        "tank.heat_leak_w=1e6",
    ]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(out.contains("DIVERGED"), "{out}");
    assert!(
        stderr(&o).contains("the nominal instance diverged: layer temperature"),
        "{}",
        stderr(&o)
    );
}

/// `check` prints the step plan: steps per period and the nominal's measured cost.
#[test]
fn check_prints_the_step_plan() {
    let lox = campaign_path("lox_ascent");
    for integrator in ["rk4", "dopri5"] {
        let o = cryoslosh(&[
            "check",
            lox.to_str().unwrap(),
            "--set",
            &format!("campaign.integrator={integrator}"),
        ]);
        let out = String::from_utf8_lossy(&o.stdout);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        assert!(out.contains("step plan:"), "{out}");
        assert!(out.contains("excitation period 0.833333 s"), "{out}");
        assert!(out.contains("right-hand-side evaluations"), "{out}");
    }
}

/// Regression: `--set tank.heat_leak_w=1_000` was refused as the string "1_000" although TOML
/// reads `1_000` as an integer (and `1_000.5`, `1e3` as floats): `--set` takes TOML scalars.
#[test]
fn set_accepts_toml_number_literals() {
    let same = |written: &str, plain: &str| {
        let a = load("mhtb_selfpress", &[written]);
        let b = load("mhtb_selfpress", &[plain]);
        assert_eq!(a.text, b.text, "--set {written} is not --set {plain}");
    };
    same("tank.heat_leak_w=1_000", "tank.heat_leak_w=1000");
    same("tank.heat_leak_w=1_000.5", "tank.heat_leak_w=1000.5");
    same("tank.heat_leak_w=1e3", "tank.heat_leak_w=1000.0");
    same("tank.heat_leak_w=+1_0.2_5", "tank.heat_leak_w=10.25");
    same("campaign.instances=0x40", "campaign.instances=64");
    // A count written as a float (instances.parquet stores `slosh.baffle_count` as 3.0) is
    // taken: it was refused as "invalid type: floating point `3.0`, expected u32".
    same("campaign.instances=64.0", "campaign.instances=64");
    same("campaign.instances=6.4e1", "campaign.instances=64");
    same("tank.heat_leak_w=1_000.0", "tank.heat_leak_w=1000");
    assert_eq!(
        load("mhtb_selfpress", &["campaign.instances=2_000"]).instances,
        2000
    );
    // Through the command line too, and what TOML refuses is still refused, naming the key.
    let path = campaign_path("mhtb_selfpress");
    let o = cryoslosh(&[
        "check",
        path.to_str().unwrap(),
        "--set",
        "tank.heat_leak_w=1_000",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for bad in [
        "tank.heat_leak_w=1__000",
        "tank.heat_leak_w=_1000",
        "tank.heat_leak_w=1_000_",
    ] {
        let o = cryoslosh(&["check", path.to_str().unwrap(), "--set", bad]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "--set {bad}: {err}");
        assert!(err.contains("tank.heat_leak_w"), "{err}");
    }
}

/// Regression: a `--set` whose value is out of range was reported as an error in the campaign
/// file (`FILE: KEY = VALUE is not allowed`), which holds a valid value.
#[test]
fn invalid_set_value_is_attributed_to_the_override() {
    let path = campaign_path("lh2_upper_stage");
    let file = path.to_str().unwrap();
    let out = std::env::temp_dir().join(format!("cryoslosh-cli-{}-set", std::process::id()));
    for (set, allowed) in [
        ("tank.heat_leak_w=-5", "a finite number in [0, 1e7]"),
        // A phase by its name keeps the spelling of the override.
        ("phases.burn1.duration_s=0", "a finite number in (0, 1e9]"),
    ] {
        for cmd in ["check", "run"] {
            let mut args = vec![cmd, file, "--set", set];
            if cmd == "run" {
                args.extend(["--out", out.to_str().unwrap(), "--instances", "2"]);
            }
            let o = cryoslosh(&args);
            let err = stderr(&o);
            assert_eq!(o.status.code(), Some(2), "{cmd} --set {set}: {err}");
            assert_eq!(
                err.trim_end(),
                format!(
                    "error: --set {set} is not allowed: expected {allowed} (overriding {file})"
                ),
                "{cmd}"
            );
            assert!(!out.exists());
        }
    }
    // The file's own bad value is still the file's.
    let text = std::fs::read_to_string(&path).unwrap();
    let bad = out.with_extension("toml");
    std::fs::write(
        &bad,
        text.replacen("heat_leak_w = 150.0", "heat_leak_w = -5.0", 1),
    )
    .unwrap();
    let o = cryoslosh(&["check", bad.to_str().unwrap()]);
    assert_eq!(
        stderr(&o).trim_end(),
        format!(
            "error: {}: tank.heat_leak_w = -5 is not allowed: expected a finite number in [0, 1e7]",
            bad.display()
        )
    );
    std::fs::remove_file(&bad).ok();
}

/// Regression: a value of the wrong type in the file was reported without its key path, with
/// TOML's source snippet and caret squashed onto the message's line.
#[test]
fn toml_type_errors_name_the_key_path_value_and_expectation() {
    let text = std::fs::read_to_string(campaign_path("lh2_upper_stage")).unwrap();
    let file = std::env::temp_dir().join(format!("cryoslosh-cli-{}-type.toml", std::process::id()));
    let line_of =
        |t: &str, needle: &str| t.lines().position(|l| l.starts_with(needle)).unwrap() + 1;
    for (from, to, key, value, expected) in [
        (
            "heat_leak_w = 150.0",
            "heat_leak_w = \"forty\"",
            "tank.heat_leak_w",
            "\"forty\"",
            "a number",
        ),
        (
            "instances = 10000",
            "instances = -3",
            "campaign.instances",
            "-3",
            "a whole number ≥ 0",
        ),
        // The second [[phases]] entry, by index.
        (
            "duration_s = 400.0",
            "duration_s = true",
            "phases.1.duration_s",
            "true",
            "a number",
        ),
    ] {
        let bad = text.replacen(from, to, 1);
        std::fs::write(&file, &bad).unwrap();
        let o = cryoslosh(&["check", file.to_str().unwrap()]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{err}");
        let line = line_of(&bad, to);
        let column = to.find(value).unwrap() + 1;
        assert_eq!(
            err.trim_end(),
            format!(
                "error: {}: {key} = {value} is not allowed: expected {expected} (line {line}, \
                 column {column})",
                file.display()
            )
        );
    }
    // Any other schema error names its key path too.
    let bad = text.replacen("heat_leak_w = 150.0", "heat_leek_w = 150.0", 1);
    std::fs::write(&file, &bad).unwrap();
    let err = stderr(&cryoslosh(&["check", file.to_str().unwrap()]));
    assert!(
        err.starts_with(&format!(
            "error: {}: tank.heat_leek_w: unknown field",
            file.display()
        )),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    std::fs::remove_file(&file).ok();
}

#[test]
fn nan_and_infinity_are_rejected() {
    rejects("tank.heat_leak_w=nan", "tank.heat_leak_w");
    rejects("tank.heat_leak_w=inf", "tank.heat_leak_w");
    rejects("ullage.pressure_pa=-inf", "ullage.pressure_pa");
}

#[test]
fn unknown_keys_are_rejected() {
    rejects("tank.heat_leek_w=40", "heat_leek_w");
    rejects("phases.9.duration_s=1", "phases.9.duration_s");
    rejects("campaign.seed=abc", "seed");
}

#[test]
fn unknown_enumerations_are_rejected() {
    rejects("propellant.fluid=LF2", "propellant.fluid");
    rejects("tank.shape=torus", "tank.shape");
    rejects("campaign.fidelity=cfd", "campaign.fidelity");
    rejects("phases.0.kind=hover", "phases.0.kind");
}

#[test]
fn broken_toml_and_missing_file_exit_2() {
    let dir = std::env::temp_dir().join(format!("cryoslosh-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let broken = dir.join("broken.toml");
    std::fs::write(&broken, "[tank\nradius_m = 1\n").unwrap();
    let o = cryoslosh(&["check", broken.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("broken.toml") && stderr(&o).contains("invalid TOML"),
        "{}",
        stderr(&o)
    );
    let o = cryoslosh(&[
        "simulate",
        dir.join("nope.toml").to_str().unwrap(),
        "--out",
        dir.join("x.parquet").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("nope.toml"), "{}", stderr(&o));
    assert!(
        !dir.join("x.parquet").exists(),
        "nothing is written on bad input"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Regression: a missing campaign file printed the OS error twice ("cannot read campaign
/// nope.toml: No such file or directory (os error 2): No such file or directory (os error 2)").
#[test]
fn missing_campaign_file_names_the_os_error_once() {
    let missing =
        std::env::temp_dir().join(format!("cryoslosh-cli-{}-nope.toml", std::process::id()));
    let o = cryoslosh(&["check", missing.to_str().unwrap()]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    let head = format!("error: cannot read campaign {}: ", missing.display());
    assert!(err.starts_with(&head), "{err}");
    assert_eq!(err.matches("(os error 2)").count(), 1, "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
}

/// Regression: an output file that cannot be created printed its path and OS error twice
/// ("error: writing X: cannot write X: No such file or directory (os error 2): No such file or
/// directory (os error 2)").
#[test]
fn an_unwritable_output_names_its_path_and_os_error_once() {
    let out = std::env::temp_dir()
        .join(format!("cryoslosh-cli-{}-no-dir", std::process::id()))
        .join("h.parquet");
    let o = cryoslosh(&[
        "simulate",
        campaign_path("mhtb_selfpress").to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_eq!(err.matches(out.to_str().unwrap()).count(), 1, "{err}");
    assert_eq!(err.matches("(os error 2)").count(), 1, "{err}");
}

/// Regression: with standard error a pipe nobody reads (`cryoslosh … 2>&1 | head` after `head`
/// exited), printing the error panicked (exit 101) instead of exiting with the command's code.
#[test]
fn a_closed_stderr_keeps_the_exit_code() {
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    let missing =
        std::env::temp_dir().join(format!("cryoslosh-cli-{}-gone.toml", std::process::id()));
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_cryoslosh"))
        .args(["check", missing.to_str().unwrap()])
        .stdout(std::process::Stdio::null())
        .stderr(writer)
        .status()
        .expect("cryoslosh runs");
    assert_eq!(status.code(), Some(2), "{status}");
}

#[test]
fn check_prints_the_resolved_nominal() {
    let o = cryoslosh(&[
        "check",
        campaign_path("lh2_upper_stage").to_str().unwrap(),
        "--set",
        "tank.heat_leak_w=40",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("heat leak 40 W"), "{out}");
    assert!(
        out.contains("fidelity lumped") && out.contains("restart"),
        "{out}"
    );
}

#[test]
fn simulate_writes_the_documented_history_columns() {
    use parquet::file::reader::{FileReader, SerializedFileReader};
    let dir = std::env::temp_dir().join(format!("cryoslosh-sim-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("h.parquet");
    let o = cryoslosh(&[
        "simulate",
        campaign_path("lh2_upper_stage").to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--set",
        "campaign.output_interval_s=60",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let summary = String::from_utf8_lossy(&o.stdout);
    for needle in [
        "peak pressure",
        "boil-off",
        "min cavitation margin",
        "max slosh angle",
    ] {
        assert!(
            summary.contains(needle),
            "summary lacks {needle}: {summary}"
        );
    }
    let reader = SerializedFileReader::new(std::fs::File::open(&out).unwrap()).unwrap();
    let meta = reader.metadata().file_metadata();
    let names: Vec<String> = meta
        .schema_descr()
        .columns()
        .iter()
        .map(|c| c.name().to_string())
        .collect();
    for col in [
        "time_s",
        "pressure_pa",
        "vapor_pressure_pa",
        "ullage_temp_k",
        "layer_temp_k",
        "bulk_temp_k",
        "wall_temp_k",
        "liquid_mass_kg",
        "fill_fraction",
        "slosh_angle_rad",
        "slosh_force_n",
        "cavitation_margin_m",
        "vented_kg",
        "pressurant_used_kg",
        "velocity_m_s",
        "altitude_m",
        "phase",
    ] {
        assert!(
            names.iter().any(|n| n == col),
            "missing column {col}: {names:?}"
        );
    }
    let kv = meta.key_value_metadata().expect("file-level metadata");
    let keys: Vec<&str> = kv.iter().map(|e| e.key.as_str()).collect();
    for k in [
        "cryoslosh.campaign",
        "cryoslosh.seed",
        "cryoslosh.shard",
        "cryoslosh.backend",
        "cryoslosh.version",
    ] {
        assert!(keys.contains(&k), "missing metadata {k}: {keys:?}");
    }
    // Total duration 3420 s sampled every 60 s plus phase ends.
    assert!(meta.num_rows() >= 58, "{} rows", meta.num_rows());
    std::fs::remove_dir_all(&dir).ok();
}
