//! Single-instance integration speed per physics level: steps per second of `simulate` on the
//! shipped LH2 upper-stage campaign (criterion reports elements/s = steps/s).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use cryoslosh::campaign::Campaign;
use cryoslosh::simulate::simulate;
use std::path::PathBuf;

fn levels(c: &mut Criterion) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("campaigns/lh2_upper_stage.toml");
    let mut group = c.benchmark_group("simulate_lh2_upper_stage");
    group.sample_size(10);
    for level in ["homogeneous", "lumped", "two_mode"] {
        let campaign = Campaign::load(&path, &[format!("campaign.fidelity={level}")])
            .expect("shipped campaign");
        let steps: u64 = campaign.phases.iter().map(|p| p.steps().0).sum();
        group.throughput(Throughput::Elements(steps));
        group.bench_function(level, |b| {
            b.iter(|| simulate(&campaign, &campaign.params, None))
        });
    }
    group.finish();
}

criterion_group!(benches, levels);
criterion_main!(benches);
