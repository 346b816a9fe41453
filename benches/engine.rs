//! CPU engine throughput in instance-steps per second, lumped level: a one-instance-at-a-time
//! loop over the same model, and the engine on 1 and 2 threads (the ratios go in the notes).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use cryoslosh::campaign::Campaign;
use cryoslosh::engine::{CpuEngine, Engine};
use cryoslosh::montecarlo::plan::Plan;
use std::path::PathBuf;

const INSTANCES: u64 = 64;

fn engine(c: &mut Criterion) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("campaigns/mhtb_selfpress.toml");
    let sets = ["phases.0.duration_s=1800".to_string()];
    let campaign = Campaign::load(&path, &sets).expect("shipped campaign");
    let plan = Plan {
        campaign: &campaign,
        seed: 1,
        total: INSTANCES,
    };
    let steps: u64 = (0..INSTANCES)
        .map(|i| plan.run_instance(i).summary.steps)
        .sum();
    let mut group = c.benchmark_group("engine_mhtb_lumped");
    group.sample_size(10);
    group.throughput(Throughput::Elements(steps));
    group.bench_function("one_at_a_time", |b| {
        b.iter(|| {
            (0..INSTANCES)
                .map(|i| plan.run_instance(i).summary.steps)
                .sum::<u64>()
        })
    });
    for threads in [1, 2] {
        let e = CpuEngine::new(threads).expect("thread pool");
        group.bench_function(format!("cpu_{threads}_threads"), |b| {
            b.iter(|| e.run_block(&plan, 0..INSTANCES).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, engine);
criterion_main!(benches);
