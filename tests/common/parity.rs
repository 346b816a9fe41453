//! The GPU-against-CPU comparison of `tests/gpu_parity*.rs`: per instance, the 99th percentile
//! of each QoI's relative difference (against a floor at the QoI's physical resolution) within a
//! budget, flags agreeing, and the campaign statistics within the same budget.

use cryoslosh::gpu::context;
use cryoslosh::gpu::engine::GpuEngine;
use cryoslosh::montecarlo::plan::InstanceRecord;
use cryoslosh::montecarlo::table::PHASE_QOIS;
use cryoslosh::simulate::Summary;

/// Relative-difference budget of the headline QoIs (issue acceptance).
pub const TOL: f64 = 1.0e-3;

pub fn engine() -> Option<GpuEngine> {
    match context::open(false).and_then(GpuEngine::new) {
        Ok(e) => Some(e),
        Err(e) => {
            if std::env::var("CRYOSLOSH_REQUIRE_GPU").as_deref() == Ok("1") {
                panic!("CRYOSLOSH_REQUIRE_GPU=1 but no GPU engine: {e}");
            }
            println!("skipped: no GPU adapter ({e})");
            None
        }
    }
}

/// A headline QoI, the floor under its relative difference (the QoI's natural resolution, so
/// that a margin crossing zero is judged against metres, not against zero) and its value.
pub type Qoi = (&'static str, f64, fn(&Summary) -> Option<f64>);

pub const QOIS: [Qoi; 4] = [
    ("peak_pressure_pa", 1.0, |q| Some(q.peak_pressure_pa)),
    ("boiloff_kg", 1.0e-3, |q| Some(q.boiloff_kg)),
    ("min_cavitation_margin_m", 1.0e-2, |q| {
        q.min_cavitation_margin_m
    }),
    ("max_slosh_angle_rad", 1.0e-4, |q| {
        Some(q.max_slosh_angle_rad)
    }),
];

/// The p-quantile of `v` (nearest rank).
pub fn quantile(v: &mut [f64], p: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    let k = ((p * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1;
    v[k]
}

/// Every instance of a block compared at the default budget [`TOL`].
pub fn compare(name: &str, level: &str, cpu: &[InstanceRecord], gpu: &[InstanceRecord]) {
    compare_where(name, level, cpu, gpu, |_, _| true, |_| TOL);
}

/// Flags compared on every instance; values on the integrated instances whose summaries on
/// both backends pass `keep`, each QoI (headline `q`, per-phase `q.<phase>`) within `tol(q)`.
pub fn compare_where(
    name: &str,
    level: &str,
    cpu: &[InstanceRecord],
    gpu: &[InstanceRecord],
    keep: impl Fn(&Summary, &Summary) -> bool,
    tol: impl Fn(&str) -> f64,
) {
    let n = cpu.len();
    let mut flag_agree = 0usize;
    for (c, g) in cpu.iter().zip(gpu) {
        assert_eq!(c.instance, g.instance);
        assert_eq!(c.inputs, g.inputs, "{name}/{level}: inputs differ");
        assert_eq!(c.rejected, g.rejected, "{name}/{level}: rejection differs");
        if flags(&c.summary) == flags(&g.summary) {
            flag_agree += 1;
        }
    }
    let share = flag_agree as f64 / n as f64;
    assert!(
        share >= 0.999 || n - flag_agree == 0,
        "{name}/{level}: flags agree on {flag_agree} of {n}"
    );
    let values = qoi_values(cpu, gpu, keep);
    assert!(
        values.iter().any(|(_, v)| !v.is_empty()),
        "{name}/{level}: no instance was integrated"
    );
    for (qoi, v) in values {
        let t = tol(&qoi);
        compare_values(name, level, &qoi, v, t);
    }
}

/// The flags an instance's summary carries (compared exactly).
fn flags(q: &Summary) -> (bool, bool, bool, bool, bool, bool, u64) {
    (
        q.cavitation,
        q.overpressure,
        q.diverged,
        q.pressurant_exhausted,
        q.depleted,
        q.slosh_out_of_range,
        q.relief_cycles,
    )
}

/// One QoI's `(a, b, floor)` over paired instances of two runs.
pub type Paired = Vec<(f64, f64, f64)>;

/// For each headline QoI and each per-phase QoI (`<qoi>.<phase>`, over the instances that
/// entered the phase in both runs): `(a, b, floor)` over the paired instances of runs `a` and
/// `b` that are integrated (not rejected, not diverged) and whose summaries pass `keep`.
pub fn qoi_values(
    a: &[InstanceRecord],
    b: &[InstanceRecord],
    keep: impl Fn(&Summary, &Summary) -> bool,
) -> Vec<(String, Paired)> {
    let pairs: Vec<(&Summary, &Summary)> = a
        .iter()
        .zip(b)
        .filter(|(c, g)| !c.rejected && !c.summary.diverged && !g.summary.diverged)
        .map(|(c, g)| (&c.summary, &g.summary))
        .filter(|(c, g)| keep(c, g))
        .collect();
    let mut out = Vec::new();
    for (qoi, floor, get) in QOIS {
        let values = pairs
            .iter()
            .filter_map(|(c, g)| get(c).zip(get(g)))
            .map(|(x, y)| (x, y, floor))
            .collect();
        out.push((qoi.to_string(), values));
    }
    let n_phases = pairs.iter().map(|(c, _)| c.phases.len()).max().unwrap_or(0);
    for i in 0..n_phases {
        let phase = &pairs
            .iter()
            .find(|(c, _)| c.phases.len() > i)
            .unwrap()
            .0
            .phases[i]
            .name;
        for (qoi, get) in PHASE_QOIS {
            let values: Vec<(f64, f64, f64)> = pairs
                .iter()
                .filter_map(|(c, g)| {
                    let floor = phase_floor(qoi, c);
                    let (x, y) = c.phases.get(i).zip(g.phases.get(i))?;
                    Some((get(x), get(y), floor))
                })
                .filter(|(x, y, _)| !x.is_nan() && !y.is_nan())
                .collect();
            out.push((format!("{qoi}.{phase}"), values));
        }
    }
    out
}

/// The floor under a per-phase QoI's relative difference for an instance whose whole-mission
/// summary is `q` (as in [`QOIS`]). A phase's amounts and pressure rise are differences of two
/// cumulative values the f32 kernel carries to ~1e-6 of their size: the phase's boil-off and
/// vented mass are judged against the mission's, its pressure rise against its peak pressure. A
/// phase's slosh angle is judged against the mission's largest: a residual swing 1000× smaller
/// than the burn's (an LH2 coast: 2e-4 rad after 0.25 rad) carries the same absolute f32 error.
pub fn phase_floor(qoi: &str, q: &Summary) -> f64 {
    match qoi {
        "peak_pressure_pa" | "min_pressure_pa" => 1.0,
        "pressure_rise_pa" => q.peak_pressure_pa.abs(),
        "boiloff_kg" => q.boiloff_kg.abs().max(1.0e-3),
        "vented_kg" => q.vented_kg.abs().max(1.0e-3),
        "tvs_vented_kg" => q.tvs_vented_kg.abs().max(1.0e-3),
        "min_cavitation_margin_m" => 1.0e-2,
        "max_slosh_angle_rad" => q.max_slosh_angle_rad.max(1.0e-4),
        other => panic!("no floor for the per-phase QoI {other}"),
    }
}

/// The CPU and GPU values `(cpu, gpu, floor)` of one QoI over the instances of `name` at
/// `level`: the 99th percentile of the relative difference (against `floor` at least) below
/// `tol`, and the mean and quantiles within `tol` of the largest value or floor.
pub fn compare_values(name: &str, level: &str, qoi: &str, values: Vec<(f64, f64, f64)>, tol: f64) {
    let mut rel: Vec<f64> = values
        .iter()
        .map(|(a, b, floor)| (b - a).abs() / a.abs().max(*floor))
        .collect();
    if rel.is_empty() {
        return;
    }
    let floor = values.iter().fold(0.0f64, |m, v| m.max(v.2));
    let (mut cv, mut gv): (Vec<f64>, Vec<f64>) = values.iter().map(|v| (v.0, v.1)).unzip();
    let p99 = quantile(&mut rel, 0.99);
    let worst = quantile(&mut rel, 1.0);
    println!("{name:>16} {level:>11} {qoi:>24}: p99 rel {p99:.2e}, max {worst:.2e}");
    assert!(
        p99 < tol,
        "{name}/{level}: {qoi} p99 relative difference {p99:.3e}"
    );
    // Statistics: mean and the reported quantiles agree within the same budget.
    let scale = cv.iter().fold(floor, |m, v| m.max(v.abs()));
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let mut stats = vec![("mean", mean(&cv), mean(&gv))];
    for p in [0.01, 0.05, 0.5, 0.95, 0.99] {
        stats.push(("quantile", quantile(&mut cv, p), quantile(&mut gv, p)));
    }
    for (what, a, b) in stats {
        assert!(
            (a - b).abs() <= tol * scale,
            "{name}/{level}: {qoi} {what} {a} (cpu) vs {b} (gpu)"
        );
    }
}
