//! Campaign mistakes that used to pass silently: a `--set` on a dispersed key ignored by `run`, a
//! dispersion centred outside a field's range (every instance rejected, exit 0, NaN statistics),
//! a regulator set above the relief crack, a phase insert retargeting `phases.3.thrust_n`, a
//! results directory overwritten, a panic on a closed pipe. Each now exits 2 (or 3) naming the key.

mod common;
use common::campaign_path;
use std::path::PathBuf;
use std::process::{Command, Output, Stdio};

fn cryoslosh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cryoslosh"))
        .args(args)
        .output()
        .unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cryoslosh-checks-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A short LOX ascent (1 s pad, 5 s burn) so runs take milliseconds.
const SHORT: [&str; 4] = [
    "--set",
    "phases.pad.duration_s=1",
    "--set",
    "phases.ascent.duration_s=5",
];

#[test]
fn set_on_a_dispersed_key_is_refused_by_run_naming_the_entry() {
    let camp = campaign_path("lh2_upper_stage");
    let out = scratch("dispersed");
    let o = cryoslosh(&[
        "run",
        camp.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--set",
        "tank.heat_leak_w=500",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("tank.heat_leak_w") && e.contains("dispersions.inputs.0"),
        "{e}"
    );
    assert!(!out.exists());
    // The same key spelled by phase index or name is one key.
    let o = cryoslosh(&[
        "run",
        camp.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--set",
        "phases.1.thrust_n=1e5",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("dispersions.inputs.5"),
        "{}",
        stderr(&o)
    );
    // The nominal of `check` may use it.
    let o = cryoslosh(&[
        "check",
        camp.to_str().unwrap(),
        "--set",
        "tank.heat_leak_w=40",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn dispersion_centred_outside_a_range_fails_check_and_run_exits_3() {
    let camp = campaign_path("lox_ascent");
    let camp = camp.to_str().unwrap();
    let cold = [
        "--set",
        "dispersions.inputs.0.key=ullage.temperature_k",
        "--set",
        "dispersions.inputs.0.mean=30",
        "--set",
        "dispersions.inputs.0.std=3",
    ];
    let o = cryoslosh(&[&["check", camp][..], &cold, &SHORT].concat());
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("ullage.temperature_k"),
        "{}",
        stderr(&o)
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("1000 rejected"), "{stdout}");

    let out = scratch("cold");
    let o = cryoslosh(
        &[
            &[
                "run",
                camp,
                "--out",
                out.to_str().unwrap(),
                "--instances",
                "20",
            ][..],
            &["--backend", "cpu"],
            &cold,
            &SHORT,
        ]
        .concat(),
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(3), "{stdout}{}", stderr(&o));
    assert!(
        stdout.contains("rejected by        ullage.temperature_k 20"),
        "{stdout}"
    );
    assert!(
        stderr(&o).contains("20 of 20 instances rejected"),
        "{}",
        stderr(&o)
    );
    // The outputs are still written, and say it.
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(run["rejected_by"]["ullage.temperature_k"], 20, "{run}");
    assert!(run["untrusted"].is_string(), "{run}");
    std::fs::remove_dir_all(out).ok();
}

#[test]
fn cross_field_rules_name_their_keys() {
    let lh2 = campaign_path("lh2_upper_stage");
    let lh2 = lh2.to_str().unwrap();
    for (set, key) in [
        (
            "pressurization.setpoint_pa=310000",
            "pressurization.setpoint_pa",
        ),
        ("relief.crack_pa=360000", "relief.crack_pa"),
        ("relief.reseat_pa=310000", "relief.reseat_pa"),
    ] {
        let o = cryoslosh(&["check", lh2, "--set", set]);
        assert_eq!(o.status.code(), Some(2), "{set}: {}", stderr(&o));
        assert!(stderr(&o).contains(key), "{set}: {}", stderr(&o));
    }
    // A crack above MEOP is allowed when stated.
    let o = cryoslosh(&[
        "check",
        lh2,
        "--set",
        "relief.crack_pa=360000",
        "--set",
        "relief.reseat_pa=340000",
        "--set",
        "relief.crack_above_meop=true",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn phases_are_addressable_by_name() {
    let lh2 = campaign_path("lh2_upper_stage");
    let o = cryoslosh(&[
        "check",
        lh2.to_str().unwrap(),
        "--set",
        "phases.restart.duration_s=150",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    let line = out.lines().find(|l| l.contains("restart")).unwrap();
    assert!(
        line.contains("3370"),
        "restart must end at 3220 + 150 s: {line}"
    );
    // A phase inserted before it does not retarget the named key.
    let text = std::fs::read_to_string(&lh2).unwrap().replacen(
        "[[phases]]",
        "[[phases]]\nname = \"chill\"\nkind = \"hold\"\nduration_s = 10.0\n\n[[phases]]",
        1,
    );
    let dir = scratch("insert");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("c.toml");
    std::fs::write(&file, text).unwrap();
    let c = cryoslosh::campaign::Campaign::load(&file, &["phases.restart.duration_s=150".into()])
        .unwrap();
    let restart = c.phases.iter().find(|p| p.name == "restart").unwrap();
    assert_eq!(restart.duration_s, 150.0);
    assert_eq!(c.phases[4].name, "restart");
    // An unknown name lists the names.
    let o = cryoslosh(&[
        "check",
        lh2.to_str().unwrap(),
        "--set",
        "phases.restrat.duration_s=150",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("pad_hold, burn1, coast, restart"),
        "{}",
        stderr(&o)
    );
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn set_type_errors_name_the_key_and_file_errors_keep_their_line() {
    let mhtb = campaign_path("mhtb_selfpress");
    let o = cryoslosh(&[
        "check",
        mhtb.to_str().unwrap(),
        "--set",
        "campaign.allow_coarse_step=yes",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--set campaign.allow_coarse_step: invalid type"),
        "{}",
        stderr(&o)
    );
    let dir = scratch("badfile");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("c.toml");
    let text = std::fs::read_to_string(&mhtb).unwrap().replacen(
        "heat_leak_w = ",
        "heat_leak_w = \"a\" # ",
        1,
    );
    std::fs::write(&file, &text).unwrap();
    let line = text
        .lines()
        .position(|l| l.contains("heat_leak_w = \"a\""))
        .unwrap()
        + 1;
    let o = cryoslosh(&[
        "check",
        file.to_str().unwrap(),
        "--set",
        "tank.meop_pa=300000",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains(&format!("line {line}")),
        "{}",
        stderr(&o)
    );
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn threshold_on_an_unknown_quantity_is_refused() {
    let mhtb = campaign_path("mhtb_selfpress");
    let dir = scratch("threshold");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("c.toml");
    let text = std::fs::read_to_string(&mhtb).unwrap()
        + "\n[statistics]\n[[statistics.thresholds]]\nquantity = \"peak_presure_pa\"\nabove = 2e5\n";
    std::fs::write(&file, text).unwrap();
    let o = cryoslosh(&["check", file.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("statistics.thresholds.0.quantity"),
        "{}",
        stderr(&o)
    );
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn non_empty_out_needs_force_and_nothing_dispersed_is_said() {
    let camp = campaign_path("aydelott_sphere"); // no [dispersions]
    let camp = camp.to_str().unwrap();
    let out = scratch("force");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("notes.txt"), "keep").unwrap();
    let base = [
        &[
            "run",
            camp,
            "--out",
            out.to_str().unwrap(),
            "--instances",
            "3",
        ][..],
        &["--backend", "cpu", "--set", "phases.closed.duration_s=5"][..],
    ]
    .concat();
    let o = cryoslosh(&base);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("notes.txt") && stderr(&o).contains("--force"));
    // --force replaces only a previous result: a directory of other files is never deleted.
    let o = cryoslosh(&[&base[..], &["--force"]].concat());
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("not a cryoslosh results directory"),
        "{}",
        stderr(&o)
    );
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "keep"
    );
    std::fs::remove_dir_all(&out).unwrap();
    let o = cryoslosh(&base);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{stdout}{}", stderr(&o));
    assert!(stdout.contains("no [dispersions]"), "{stdout}");
    // A previous result: refused without --force, replaced with it.
    assert_eq!(cryoslosh(&base).status.code(), Some(2));
    let o = cryoslosh(&[&base[..], &["--force"]].concat());
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    std::fs::remove_dir_all(out).ok();
}

#[test]
fn a_closed_pipe_ends_quietly() {
    let camp = campaign_path("lh2_upper_stage");
    let mut child = Command::new(env!("CARGO_BIN_EXE_cryoslosh"))
        .args(["check", camp.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take()); // the reader goes away before anything is printed
    let o = child.wait_with_output().unwrap();
    let e = stderr(&o);
    assert!(!e.contains("panicked"), "{e}");
    assert_eq!(
        o.status.code(),
        Some(0),
        "a closed pipe is not an error: {e}"
    );
}

/// A reviewer's attack: one key dispersed under two spellings (one sample silently overwrote the
/// other), distribution and excitation parameters that do not apply (silently ignored, and the
/// refusal message recommended one), tolerance levels written as fractions, a threshold with
/// neither side, a valve reseating where it cracks. Each now exits 2 naming the key.
#[test]
fn spellings_unused_parameters_and_fraction_levels_are_refused() {
    let dir = scratch("spellings");
    std::fs::create_dir_all(&dir).unwrap();
    let lox = std::fs::read_to_string(campaign_path("lox_ascent")).unwrap();
    let cases: [(String, &str); 6] = [
        (
            lox.replacen(
                "key = \"feed.npsh_required_m\"",
                "key = \"phases.1.thrust_n\"",
                1,
            ),
            "dispersions.inputs.3.key",
        ),
        (
            lox.replacen("lo = 240000.0", "lo = 240000.0\nmean = 1.0", 1),
            "dispersions.inputs.2.mean",
        ),
        (
            lox.replacen(
                "duration_s = 120.0 }",
                "duration_s = 120.0, start_s = 3.0 }",
                1,
            ),
            "phases.1.excitation.start_s",
        ),
        (
            lox.clone() + "\n[statistics]\ntolerance = [\"0.95/0.95\"]\n",
            "statistics.tolerance.0",
        ),
        (
            lox.clone()
                + "\n[statistics]\n[[statistics.thresholds]]\nquantity = \"peak_pressure_pa\"\n",
            "statistics.thresholds.0",
        ),
        (
            lox.replacen("reseat_pa = 320000.0", "reseat_pa = 340000.0", 1),
            "relief.reseat_pa",
        ),
    ];
    for (i, (text, key)) in cases.iter().enumerate() {
        let file = dir.join(format!("c{i}.toml"));
        std::fs::write(&file, text).unwrap();
        let o = cryoslosh(&["check", file.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "{key}: {}", stderr(&o));
        assert!(stderr(&o).contains(key), "{key}: {}", stderr(&o));
    }
    // The refusal of a --set on a dispersed key recommends a parameter that distribution takes.
    let o = cryoslosh(&[
        "run",
        campaign_path("lox_ascent").to_str().unwrap(),
        "--out",
        dir.join("out").to_str().unwrap(),
        "--set",
        "pressurization.setpoint_pa=250000",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("dispersions.inputs.2.lo=…"),
        "{}",
        stderr(&o)
    );
    std::fs::remove_dir_all(dir).ok();
}

/// Under the saltelli design the AB rows are near-copies of their A row: the distribution
/// statistics use the A and B rows only (2 per group), the Sobol indices every row.
#[test]
fn saltelli_distribution_statistics_use_independent_rows() {
    use cryoslosh::engine::{Backend, CpuEngine};
    use cryoslosh::montecarlo::{self, statistics::find, RunOptions, Shard};
    let c = common::load(
        "mhtb_selfpress",
        &["phases.0.duration_s=600", "dispersions.design=saltelli"],
    );
    let out = scratch("saltelli-iid");
    let opts = RunOptions {
        out_dir: out.clone(),
        instances: 5 * 20,
        seed: 3,
        shard: Shard::ALL,
        chunk_size: 64,
        progress: false,
        histories: Vec::new(),
        until: None,
        force: false,
        resume: false,
    };
    let r = montecarlo::run(&c, &Backend::Cpu(CpuEngine::new(2).unwrap()), &opts).unwrap();
    assert_eq!(
        find(&r.statistics, "peak_pressure_pa", "p50").unwrap().n,
        40
    );
    let sobol = r
        .statistics
        .iter()
        .find(|x| x.stat.statistic == "sobol_first" && x.stat.quantity == "peak_pressure_pa")
        .unwrap();
    assert_eq!(sobol.stat.n, 20);
    std::fs::remove_dir_all(out).ok();
}

/// Regression: every command exited 101 "failed printing to stdout" on a full device; it now
/// exits 1 with a message and no panic.
#[test]
fn a_full_stdout_exits_1_without_a_panic() {
    let Ok(full) = std::fs::File::options().write(true).open("/dev/full") else {
        return; // no /dev/full on this system
    };
    let dir = scratch("full-stdout");
    std::fs::create_dir_all(&dir).unwrap();
    let history = dir.join("h.parquet");
    let aydelott = campaign_path("aydelott_sphere");
    let commands: [Vec<&str>; 2] = [
        vec!["check", aydelott.to_str().unwrap()],
        vec![
            "simulate",
            aydelott.to_str().unwrap(),
            "--out",
            history.to_str().unwrap(),
        ],
    ];
    for args in commands {
        let o = Command::new(env!("CARGO_BIN_EXE_cryoslosh"))
            .args(&args)
            .stdout(full.try_clone().unwrap())
            .output()
            .unwrap();
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {e}");
        assert!(
            e.contains("cannot write to standard output") && !e.contains("panicked"),
            "{args:?}: {e}"
        );
    }
    std::fs::remove_dir_all(dir).ok();
}

/// `--set pressurization.gas="helium"` (quoted, as in the file) kept its quotes and was refused
/// ("\"helium\"" is not helium | autogenous); TOML literals now parse as in the file.
#[test]
fn set_takes_toml_literals_as_written_in_the_file() {
    let path = campaign_path("methalox_autogenous");
    let path = path.to_str().unwrap();
    for value in ["\"helium\"", "'helium'", "helium"] {
        let set = format!("pressurization.gas={value}");
        let o = cryoslosh(&["check", path, "--set", &set]);
        assert!(o.status.success(), "{set}: {}", stderr(&o));
    }
    let o = cryoslosh(&["check", path, "--set", "pressurization.gas=\"neon\""]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("pressurization.gas"), "{}", stderr(&o));
}

/// An unknown excitation kind was refused for its amplitude ("a bogus excitation takes no
/// parameters") instead of for its kind, and a table excitation took 5000 m/s² that the other
/// kinds refuse: both now exit 2 naming the key, the value and the allowed range.
#[test]
fn an_unknown_excitation_kind_and_a_table_beyond_range_are_refused() {
    let dir = scratch("excitation");
    std::fs::create_dir_all(&dir).unwrap();
    let campaign = campaign_path("ln2_slosh_destratification");
    let o = cryoslosh(&[
        "check",
        campaign.to_str().unwrap(),
        "--set",
        "phases.shake.excitation.kind=bogus",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        // The key as the override spells it (a phase by name).
        e.contains("--set phases.shake.excitation.kind=")
            && e.contains("\"bogus\"")
            && e.contains("sine"),
        "{e}"
    );
    // Without its dispersions (which spread the sine's amplitude and frequency).
    let whole = std::fs::read_to_string(&campaign).unwrap();
    let text = whole.split("[dispersions]").next().unwrap().replacen(
        "excitation = { kind = \"sine\", amplitude_m_s2 = 0.0121995, frequency_hz = 1.757886 }",
        "excitation = { kind = \"table\", file = \"shake.csv\" }",
        1,
    );
    let file = dir.join("c.toml");
    std::fs::write(&file, text).unwrap();
    std::fs::write(dir.join("shake.csv"), "0,0\n10,5000\n").unwrap();
    let o = cryoslosh(&["check", file.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("phases.0.excitation.file")
            && e.contains("shake.csv:2")
            && e.contains("[-1000, 1000]"),
        "{e}"
    );
    std::fs::write(dir.join("shake.csv"), "0,0\n10,500\n").unwrap();
    let o = cryoslosh(&["check", file.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    std::fs::remove_dir_all(dir).ok();
}

/// A 400 K dry wall over LH2 kept the default c_w, aluminium's 9.8 J/(kg·K) at 20.6 K, held 1/70 of
/// its heat and fell to 36 K within 5 s: with the default c_w the dry wall may start only as warm
/// as that constant stores 2/3 of aluminium's heat (26.1 K over the LH2 stage), and the refusal
/// names the key that lifts the limit.
#[test]
fn a_warm_dry_wall_needs_a_wall_cp_for_it() {
    let stage = campaign_path("lh2_upper_stage");
    let stage = stage.to_str().unwrap();
    let o = cryoslosh(&["check", stage, "--set", "tank.dry_wall_temperature_k=400"]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("tank.dry_wall_temperature_k")
            && e.contains("26.1]")
            && e.contains("tank.wall_cp_j_per_kg_k"),
        "{e}"
    );
    let at_limit = cryoslosh(&["check", stage, "--set", "tank.dry_wall_temperature_k=26.1"]);
    assert_eq!(at_limit.status.code(), Some(0), "{}", stderr(&at_limit));
    // With c_w given, a 300 K wall is taken and its nominal runs. (At 400 K the nominal's film
    // boils past LH2's property range at 26 s: `check` exits 1 on that since it stopped passing
    // diverging nominals, so 300 K is the case that shows the key lifts the limit.)
    let with_cp = cryoslosh(&[
        "check",
        stage,
        "--set",
        "tank.dry_wall_temperature_k=300",
        "--set",
        "tank.wall_cp_j_per_kg_k=500",
    ]);
    assert_eq!(with_cp.status.code(), Some(0), "{}", stderr(&with_cp));
}

/// Regression: a bounded dispersion reaching beyond its field's allowed range (uniform fill
/// fraction up to 0.995 where 0.98 is the limit) passed `check` and made `run` reject its
/// samples one by one (exit 3); the support is now checked when the campaign is loaded (exit 2).
/// Unbounded distributions (normal, log-normal) are not: only their far tails leave the range.
#[test]
fn a_bounded_dispersion_beyond_its_field_range_is_refused_at_load() {
    let mhtb = campaign_path("mhtb_selfpress");
    let text = std::fs::read_to_string(&mhtb).unwrap();
    let dir = scratch("support");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("c.toml");
    // dispersions.inputs.1: propellant.fill_fraction, uniform on [0.89, 0.91].
    std::fs::write(&file, text.replacen("hi = 0.91", "hi = 0.995", 1)).unwrap();
    let out = dir.join("out");
    let short = ["--set", "phases.0.duration_s=600"];
    let expected = format!(
        "error: {}: dispersions.inputs.1.hi = 0.995 is not allowed: expected a finite number in \
         [0.02, 0.98], the allowed range of propellant.fill_fraction; a uniform support must \
         lie inside it, or the samples beyond it are rejected at run time",
        file.display()
    );
    for args in [
        vec!["check", file.to_str().unwrap()],
        vec![
            "run",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        vec![
            "simulate",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    ] {
        let o = cryoslosh(&[&args[..], &short].concat());
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert_eq!(stderr(&o).trim_end(), expected, "{args:?}");
        assert!(!out.exists(), "{args:?}: wrote {}", out.display());
    }
    // Wholly outside, from a --set, and a choice's value: the parameter is named.
    let camp = mhtb.to_str().unwrap();
    for (sets, blamed) in [
        (
            &[
                "dispersions.inputs.1.lo=0.99",
                "dispersions.inputs.1.hi=0.995",
            ][..],
            "dispersions.inputs.1.lo=0.99",
        ),
        (
            &["dispersions.inputs.2.lo=-6"][..],
            "dispersions.inputs.2.lo=-6",
        ),
    ] {
        let mut args = vec!["check", camp];
        for set in sets {
            args.extend(["--set", set]);
        }
        let o = cryoslosh(&args);
        assert_eq!(o.status.code(), Some(2), "{sets:?}: {}", stderr(&o));
        let head = format!("error: --set {blamed} is not allowed: expected ");
        assert!(stderr(&o).starts_with(&head), "{}", stderr(&o));
    }
    let choice = text.replacen(
        "distribution = \"uniform\"\nlo = 0.89\nhi = 0.91",
        "distribution = \"choice\"\nvalues = [0.9, 0.99]",
        1,
    );
    std::fs::write(&file, choice).unwrap();
    let o = cryoslosh(&["check", file.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("dispersions.inputs.1.values.1 = 0.99 is not allowed"),
        "{}",
        stderr(&o)
    );
    // A normal whose far tail crosses zero heat leak still loads: `check` warns, `run` counts.
    let o = cryoslosh(&["check", camp, "--set", "dispersions.inputs.0.std=30"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    std::fs::remove_dir_all(dir).ok();
}
