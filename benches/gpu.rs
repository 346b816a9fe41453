//! GPU (WGSL through wgpu; lavapipe on a machine without a GPU) against the CPU engine, lumped
//! level, in instance-steps per second at N = 1e4, 1e5, 1e6 instances of a short MHTB
//! self-pressurisation (the ratios go in the notes). `CRYOSLOSH_BENCH_N=10000,100000` picks the
//! sizes; without an adapter only the CPU is measured.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use cryoslosh::campaign::Campaign;
use cryoslosh::engine::{CpuEngine, Engine};
use cryoslosh::gpu::context;
use cryoslosh::gpu::engine::GpuEngine;
use cryoslosh::montecarlo::plan::Plan;
use std::path::PathBuf;

fn sizes() -> Vec<u64> {
    std::env::var("CRYOSLOSH_BENCH_N")
        .ok()
        .map(|s| s.split(',').filter_map(|v| v.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![10_000, 100_000, 1_000_000])
}

fn gpu_vs_cpu(c: &mut Criterion) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("campaigns/mhtb_selfpress.toml");
    // 16 steps of 2 s per instance: the kernel, not the trajectory length, is what is measured.
    let sets = ["phases.0.duration_s=32".to_string()];
    let campaign = Campaign::load(&path, &sets).expect("shipped campaign");
    let cpu = CpuEngine::new(0).expect("thread pool");
    let gpu = context::open(false).and_then(GpuEngine::new).ok();
    if let Some(g) = &gpu {
        eprintln!("GPU adapter: {}", g.device());
    }
    let mut group = c.benchmark_group("gpu_vs_cpu_mhtb_lumped");
    group.sample_size(10);
    for n in sizes() {
        let plan = Plan {
            campaign: &campaign,
            seed: 1,
            total: n,
        };
        let steps: u64 = cpu
            .run_block(&plan, 0..n)
            .expect("cpu")
            .iter()
            .map(|r| r.summary.steps)
            .sum();
        group.throughput(Throughput::Elements(steps));
        group.bench_function(format!("cpu_n{n}"), |b| {
            b.iter(|| cpu.run_block(&plan, 0..n).expect("cpu"))
        });
        if let Some(g) = &gpu {
            group.bench_function(format!("gpu_n{n}"), |b| {
                b.iter(|| g.run_block(&plan, 0..n).expect("gpu"))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, gpu_vs_cpu);
criterion_main!(benches);
