//! The GPU backend from the command line (`devices`, `run --backend gpu`, the missing-adapter
//! error) and the Rust ↔ WGSL layout contract. Device tests skip without an adapter unless
//! `CRYOSLOSH_REQUIRE_GPU=1`.

mod common;
use common::campaign_path;
use cryoslosh::gpu::context;
use cryoslosh::gpu::params::{GpuControl, GpuParams, GpuPhase, GpuResult};
use cryoslosh::gpu::props::{GpuFluid, GpuGas, GpuTank};
use std::collections::HashMap;
use std::process::{Command, Output};

fn cryoslosh(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_cryoslosh"));
    c.args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("binary runs")
}

fn have_adapter() -> bool {
    if !context::adapters().is_empty() {
        return true;
    }
    assert!(
        std::env::var("CRYOSLOSH_REQUIRE_GPU").as_deref() != Ok("1"),
        "CRYOSLOSH_REQUIRE_GPU=1 but wgpu finds no adapter"
    );
    println!("skipped: no GPU adapter");
    false
}

/// Size in bytes WGSL gives a struct declaration (every member 4-byte aligned: no padding).
fn wgsl_size(decl: &str, known: &HashMap<String, usize>) -> usize {
    decl.lines()
        .filter_map(|l| l.trim().strip_suffix(','))
        .map(|field| {
            let ty = field.split_once(':').expect("name: type").1.trim();
            match ty {
                "f32" | "u32" => 4,
                _ if ty.starts_with("array<") => {
                    let n = ty.trim_end_matches('>').rsplit(',').next().unwrap().trim();
                    4 * n.parse::<usize>().expect("array length")
                }
                other => known[other],
            }
        })
        .sum()
}

#[test]
fn rust_and_wgsl_struct_layouts_agree() {
    let mut known = HashMap::new();
    for (name, decl, rust) in [
        ("GpuFluid", GpuFluid::wgsl(), size_of::<GpuFluid>()),
        ("GpuGas", GpuGas::wgsl(), size_of::<GpuGas>()),
        ("GpuTank", GpuTank::wgsl(), size_of::<GpuTank>()),
        ("GpuParams", GpuParams::wgsl(), size_of::<GpuParams>()),
        ("GpuPhase", GpuPhase::wgsl(), size_of::<GpuPhase>()),
        ("GpuResult", GpuResult::wgsl(), size_of::<GpuResult>()),
        ("GpuControl", GpuControl::wgsl(), size_of::<GpuControl>()),
    ] {
        assert!(decl.starts_with(&format!("struct {name} {{")), "{decl}");
        let w = wgsl_size(&decl, &known);
        assert_eq!(w, rust, "{name}: WGSL {w} bytes, Rust {rust} bytes");
        println!("{name}: {w} bytes");
        known.insert(name.to_string(), w);
    }
}

#[test]
fn devices_lists_adapters_with_limits() {
    if !have_adapter() {
        return;
    }
    let o = cryoslosh(&["devices"], &[]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.contains("Vulkan"), "{out}");
    assert!(out.contains("max storage binding"), "{out}");
    assert!(out.contains("max workgroups per dimension: "), "{out}");
}

#[test]
fn missing_adapter_with_backend_gpu_exits_2_and_writes_nothing() {
    let dir = std::env::temp_dir().join(format!("cryoslosh_noadapter_{}", std::process::id()));
    let path = campaign_path("lox_ascent");
    // An ICD list that names no driver: the Vulkan loader finds no adapter.
    let none = [
        ("VK_ICD_FILENAMES", "/nonexistent/icd.json"),
        ("VK_DRIVER_FILES", "/nonexistent/icd.json"),
    ];
    let args = [
        "run",
        path.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
        "--instances",
        "8",
        "--backend",
        "gpu",
    ];
    let o = cryoslosh(&args, &none);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("mesa-vulkan-drivers") && err.contains("--backend cpu"),
        "{err}"
    );
    assert!(!dir.exists(), "nothing may be written");
    // auto falls back to the CPU in the same situation.
    let auto = [&args[..6], &["--backend", "auto"]].concat();
    let o = cryoslosh(&auto, &none);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("run.json")).unwrap()).unwrap();
    assert_eq!(run["backend"], "cpu", "{run}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn run_with_backend_gpu_writes_the_campaign_outputs() {
    if !have_adapter() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("cryoslosh_gpu_run_{}", std::process::id()));
    let path = campaign_path("lox_ascent");
    let o = cryoslosh(
        &[
            "run",
            path.to_str().unwrap(),
            "--out",
            dir.to_str().unwrap(),
            "--instances",
            "64",
            "--backend",
            "gpu",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("run.json")).unwrap()).unwrap();
    assert_eq!(run["backend"], "gpu", "{run}");
    assert_eq!(run["instances"], 64, "{run}");
    assert!(dir.join("instances.parquet").exists());
    assert!(dir.join("statistics.parquet").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The GPU's Dormand–Prince runs in f32: tolerances tighter than the defaults are refused with
/// exit 2 naming the key (rtol 1e-12 used to run on without end), and events need the CPU.
#[test]
fn gpu_refuses_tolerances_below_f32_and_events() {
    if !have_adapter() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("cryoslosh_gpu_tol_{}", std::process::id()));
    let path = campaign_path("mhtb_selfpress");
    for extra in [
        &[
            "--set",
            "campaign.integrator=dopri5",
            "--set",
            "campaign.rtol=1e-8",
        ][..],
        &["--events"][..],
    ] {
        let mut args = vec![
            "run",
            path.to_str().unwrap(),
            "--out",
            dir.to_str().unwrap(),
            "--instances",
            "4",
            "--backend",
            "gpu",
        ];
        args.extend_from_slice(extra);
        let o = cryoslosh(&args, &[]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(
            err.contains("campaign.rtol") || err.contains("--events"),
            "{err}"
        );
        assert!(!dir.exists());
    }
}
