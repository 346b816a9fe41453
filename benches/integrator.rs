//! Cost of error control (issue 11): on the MHTB, LCH4-coast and LH2 upper-stage campaigns
//! (lumped), right-hand-side evaluations and wall time per instance of `dopri5` at its default
//! tolerances against fixed-step RK4 at the step that reaches the same accuracy. Accuracy is
//! the largest relative error of peak pressure and boil-off against a `dopri5` run at
//! rtol 1e-8; the RK4 step is the coarsest of the shipped one times 2^k (k from 4 down to −7)
//! that is as accurate.
//! Prints the table, then criterion times both integrators.

use criterion::{criterion_group, criterion_main, Criterion};
use cryoslosh::campaign::Campaign;
use cryoslosh::simulate::{simulate, Summary};
use std::path::PathBuf;

const CAMPAIGNS: [&str; 3] = ["mhtb_selfpress", "lch4_coast", "lh2_upper_stage"];

fn load(name: &str, sets: &[String]) -> Campaign {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("campaigns")
        .join(format!("{name}.toml"));
    let mut all = vec!["campaign.fidelity=lumped".to_string()];
    all.extend_from_slice(sets);
    Campaign::load(&path, &all).expect("shipped campaign")
}

fn error(q: &Summary, r: &Summary) -> f64 {
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1e-12);
    rel(q.peak_pressure_pa, r.peak_pressure_pa).max(rel(q.boiloff_kg, r.boiloff_kg))
}

fn run(c: &Campaign) -> Summary {
    simulate(c, &c.params, None)
}

/// The RK4 campaign whose phase steps are the shipped ones divided by 2^k.
fn rk4(name: &str, k: i32) -> Campaign {
    let shipped = load(name, &[]);
    let mut sets = vec![
        "campaign.integrator=rk4".to_string(),
        "campaign.allow_coarse_step=true".to_string(),
    ];
    for (i, ph) in shipped.phases.iter().enumerate() {
        sets.push(format!("phases.{i}.dt_s={}", ph.dt_s / 2f64.powi(k)));
    }
    load(name, &sets)
}

fn integrators(c: &mut Criterion) {
    let adaptive_sets = ["campaign.integrator=dopri5".to_string()];
    println!("campaign | dopri5: evals, error | RK4 at equal accuracy: step, evals, error | evals RK4/dopri5");
    let mut pairs = Vec::new();
    for name in CAMPAIGNS {
        let reference = run(&load(
            name,
            &[
                "campaign.integrator=dopri5".into(),
                "campaign.rtol=1e-8".into(),
                "campaign.atol=1e-11".into(),
            ],
        ));
        let adaptive = load(name, &adaptive_sets);
        let qa = run(&adaptive);
        let ea = error(&qa, &reference);
        let (mut fixed, mut qf) = (rk4(name, 7), None);
        for k in -4..=7 {
            let c = rk4(name, k);
            let q = run(&c);
            if !q.diverged && error(&q, &reference) <= ea {
                (fixed, qf) = (c, Some(q));
                break;
            }
        }
        let qf = qf.unwrap_or_else(|| run(&fixed));
        println!(
            "{name} | {}, {ea:.2e} | {:.4} s, {}, {:.2e} | {:.2}",
            qa.rhs_evaluations,
            fixed.phases[0].steps().1,
            qf.rhs_evaluations,
            error(&qf, &reference),
            qf.rhs_evaluations as f64 / qa.rhs_evaluations as f64
        );
        pairs.push((name, adaptive, fixed));
    }
    let mut group = c.benchmark_group("integrator");
    group.sample_size(10);
    for (name, adaptive, fixed) in &pairs {
        group.bench_function(format!("{name}/dopri5"), |b| b.iter(|| run(adaptive)));
        group.bench_function(format!("{name}/rk4_equal_accuracy"), |b| {
            b.iter(|| run(fixed))
        });
    }
    group.finish();
}

criterion_group!(benches, integrators);
criterion_main!(benches);
