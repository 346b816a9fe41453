//! The machine's limit: the peak f64 throughput of one core (FMA in scalar, AVX2 and AVX-512;
//! vector divides; the engine's own `exp`, `ln`, `pow` over arrays; libm `sin`) against what one
//! right-hand side of the model costs (operations counted with `lanes::count::Counted`) and how
//! fast the lane engine evaluates it (`model::evaluate` over `Lanes`, 1 thread).
//!
//! `cargo bench --bench roofline` (no arguments). The flops of one right-hand side are those of
//! one instance (`Counted` is one lane): adds, multiplies, divides, square roots, min/max/abs,
//! with the transcendental kernels expanded to their own operations in the "+tr" columns.

use cryoslosh::campaign::Campaign;
use cryoslosh::lanes::count::{self, Counted, Counts, EXP_COST, LN_COST, POW_COST};
use cryoslosh::lanes::{math, Lanes, Real, WIDTH};
use cryoslosh::model::derive::Drive;
use cryoslosh::model::params::Params;
use cryoslosh::model::state::{self, State};
use cryoslosh::model::{evaluate, evaluate_into, rk4_step, Group};
use cryoslosh::montecarlo::plan::Plan;
use std::hint::black_box;
use std::path::PathBuf;
use std::time::Instant;

/// Independent accumulator chains of the peak loops: more than FMA latency × FMA ports (4 × 2),
/// so the loops are bound by throughput, not by the latency of one chain.
const CHAINS: usize = 12;

/// Best rate (operations per second) of `f` over a few runs; `f(n)` performs `n · ops_per_n`
/// operations. `n` grows until one run lasts at least 0.2 s. `n` passes through `black_box` so
/// that a pure `f` is not hoisted out of the timed region (the compiler did so with the AVX-512
/// loop, an out-of-line call with the same argument every run).
fn best_rate(ops_per_n: f64, mut f: impl FnMut(u64) -> f64) -> f64 {
    let mut n = 1_000u64;
    loop {
        let t = Instant::now();
        black_box(f(black_box(n)));
        if t.elapsed().as_secs_f64() > 0.05 {
            break;
        }
        n *= 2;
    }
    // Best of many short rounds: on a shared host a long window rarely runs undisturbed (five
    // rounds of 0.2 s gave the divide peak 1.04 and 2.93 G/s minutes apart).
    (0..20)
        .map(|_| {
            let t = Instant::now();
            black_box(f(black_box(n)));
            n as f64 * ops_per_n / t.elapsed().as_secs_f64()
        })
        .fold(0.0, f64::max)
}

#[cfg(target_arch = "x86_64")]
mod peak {
    use super::CHAINS;
    use std::arch::x86_64::*;

    /// `n` rounds of one scalar FMA (`vfmadd…sd`) on each chain.
    #[target_feature(enable = "avx2,fma")]
    pub fn fma_scalar(n: u64, a: f64, b: f64) -> f64 {
        let (va, vb) = (_mm_set_sd(a), _mm_set_sd(b));
        let mut acc = [_mm_set_sd(1.0); CHAINS];
        for _ in 0..n {
            for x in acc.iter_mut() {
                *x = _mm_fmadd_sd(*x, va, vb);
            }
        }
        acc.iter().map(|&x| _mm_cvtsd_f64(x)).sum()
    }

    /// `n` rounds of one 4-lane FMA (`vfmadd…pd ymm`) on each chain.
    #[target_feature(enable = "avx2,fma")]
    pub fn fma_avx2(n: u64, a: f64, b: f64) -> f64 {
        let (va, vb) = (_mm256_set1_pd(a), _mm256_set1_pd(b));
        let mut acc = [_mm256_set1_pd(1.0); CHAINS];
        for _ in 0..n {
            for x in acc.iter_mut() {
                *x = _mm256_fmadd_pd(*x, va, vb);
            }
        }
        let s = acc
            .iter()
            .fold(_mm256_setzero_pd(), |s, &x| _mm256_add_pd(s, x));
        _mm_cvtsd_f64(_mm256_castpd256_pd128(s))
    }

    /// `n` rounds of one 8-lane FMA (`vfmadd…pd zmm`) on each chain.
    #[target_feature(enable = "avx512f")]
    pub fn fma_avx512(n: u64, a: f64, b: f64) -> f64 {
        let (va, vb) = (_mm512_set1_pd(a), _mm512_set1_pd(b));
        let mut acc = [_mm512_set1_pd(1.0); CHAINS];
        for _ in 0..n {
            for x in acc.iter_mut() {
                *x = _mm512_fmadd_pd(*x, va, vb);
            }
        }
        let s = acc
            .iter()
            .fold(_mm512_setzero_pd(), |s, &x| _mm512_add_pd(s, x));
        _mm512_reduce_add_pd(s)
    }

    /// `n` rounds of one 4-lane divide (`vdivpd ymm`) on each chain.
    #[target_feature(enable = "avx2,fma")]
    pub fn div_avx2(n: u64, a: f64) -> f64 {
        let va = _mm256_set1_pd(a);
        let mut acc = [_mm256_set1_pd(1.0); CHAINS];
        for _ in 0..n {
            for x in acc.iter_mut() {
                *x = _mm256_div_pd(*x, va);
            }
        }
        let s = acc
            .iter()
            .fold(_mm256_setzero_pd(), |s, &x| _mm256_add_pd(s, x));
        _mm_cvtsd_f64(_mm256_castpd256_pd128(s))
    }
}

/// The engine's kernels over an array (the loop the compiler vectorises, as in `Lanes::exp`).
#[inline(never)]
fn exp_array(x: &[f64], out: &mut [f64]) {
    for (o, &v) in out.iter_mut().zip(x) {
        *o = math::exp(v);
    }
}

#[inline(never)]
fn ln_array(x: &[f64], out: &mut [f64]) {
    for (o, &v) in out.iter_mut().zip(x) {
        *o = math::ln(v);
    }
}

#[inline(never)]
fn pow_array(x: &[f64], out: &mut [f64]) {
    for (o, &v) in out.iter_mut().zip(x) {
        *o = math::pow(v, 0.5625);
    }
}

#[inline(never)]
fn sin_array(x: &[f64], out: &mut [f64]) {
    for (o, &v) in out.iter_mut().zip(x) {
        *o = v.sin();
    }
}

/// Peak rates of one core, per second.
struct Peaks {
    /// FMA flops (an FMA is 2).
    scalar: f64,
    avx2: f64,
    avx512: Option<f64>,
    /// Divides (lanes).
    div: f64,
    /// Kernel calls.
    exp: f64,
    ln: f64,
    pow: f64,
    sin: f64,
}

fn peaks() -> Peaks {
    let (a, b) = (black_box(0.999_999_9), black_box(1.0e-7));
    let fma = 2.0 * CHAINS as f64;
    #[cfg(target_arch = "x86_64")]
    // SAFETY: the build targets x86-64-v3 (AVX2 and FMA); AVX-512 runs only when detected.
    let (scalar, avx2, avx512, div) = unsafe {
        (
            best_rate(fma, |n| peak::fma_scalar(n, a, b)),
            best_rate(fma * 4.0, |n| peak::fma_avx2(n, a, b)),
            is_x86_feature_detected!("avx512f")
                .then(|| best_rate(fma * 8.0, |n| peak::fma_avx512(n, a, b))),
            best_rate(CHAINS as f64 * 4.0, |n| {
                peak::div_avx2(n, black_box(1.000_000_1))
            }),
        )
    };
    #[cfg(not(target_arch = "x86_64"))]
    let (scalar, avx2, avx512, div) = (f64::NAN, f64::NAN, None, f64::NAN);
    const N: usize = 4096;
    let x: Vec<f64> = (0..N).map(|i| -5.0 + 10.0 * i as f64 / N as f64).collect();
    let pos: Vec<f64> = (0..N)
        .map(|i| 1.0e-3 + 1.0e3 * i as f64 / N as f64)
        .collect();
    let mut out = vec![0.0; N];
    let mut kernel = |xs: &[f64], f: fn(&[f64], &mut [f64])| {
        best_rate(N as f64, |n| {
            for _ in 0..n {
                f(black_box(xs), &mut out);
            }
            out[N / 2]
        })
    };
    Peaks {
        scalar,
        avx2,
        avx512,
        div,
        exp: kernel(&x, exp_array),
        ln: kernel(&pos, ln_array),
        pow: kernel(&pos, pow_array),
        sin: kernel(&x, sin_array),
    }
}

/// Instances sampled from a campaign (the engine's `Plan::resolve`), grouped `WIDTH` by `WIDTH`
/// as the engine groups them (two groups), with states `STEPS_IN` RK4 steps into the first phase.
const INSTANCES: u64 = 2 * WIDTH as u64;
const STEPS_IN: u32 = 20;

struct LaneGroup {
    params: Vec<Params>,
    s: State<Lanes>,
    d: Drive<Lanes>,
    dt: Lanes,
}

fn groups(c: &Campaign) -> Vec<LaneGroup> {
    let plan = Plan {
        campaign: c,
        seed: c.seed,
        total: INSTANCES,
    };
    let instances: Vec<Campaign> = (0..INSTANCES)
        .filter_map(|i| plan.resolve(i).1.ok())
        .map(|r| r.unwrap_or_else(|| c.clone()))
        .collect();
    instances
        .chunks_exact(WIDTH)
        .filter(|m| m.iter().all(|ci| m[0].params.lane_compatible(&ci.params)))
        .map(|m| {
            let params: Vec<Params> = m.iter().map(|ci| ci.params).collect();
            let g = Group::of(&params);
            let dt = Lanes::from_fn(|i| m[i].phases[0].steps().1);
            let drive = |t: Lanes| {
                Drive::gather(|i| Drive::of_phase(&m[i].phases[0], t.lane(i), Default::default()))
            };
            let s0: Vec<State> = m
                .iter()
                .map(|ci| cryoslosh::simulate::initial_state(ci, &ci.params))
                .collect();
            let mut s: State<Lanes> = std::array::from_fn(|j| Lanes::from_fn(|i| s0[i][j]));
            for k in 0..STEPS_IN {
                rk4_step(g, drive, &mut s, dt * k as f64, dt, None);
            }
            let d = drive(dt * STEPS_IN as f64);
            LaneGroup { params, s, d, dt }
        })
        .filter(|lg| lg.s.iter().all(|v| v.0.iter().all(|x| x.is_finite())))
        .collect()
}

/// Mean operations of one instance's right-hand side over the groups' lanes.
fn counts(gs: &[LaneGroup]) -> (Counts, f64) {
    let mut sum = Counts::default();
    let mut n = 0u64;
    for lg in gs {
        for (i, p) in lg.params.iter().enumerate() {
            let s: State<Counted> = state::lane(&lg.s, i).map(Counted);
            let d = lg.d.lane(i);
            let d = Drive::<Counted>::gather(|_| d);
            count::take();
            black_box(evaluate(Group::one(p), &s, &d, Counted(lg.dt.lane(i))));
            let c = count::take();
            for (a, b) in [
                (&mut sum.add, c.add),
                (&mut sum.mul, c.mul),
                (&mut sum.div, c.div),
                (&mut sum.sqrt, c.sqrt),
                (&mut sum.minmax, c.minmax),
                (&mut sum.cmp, c.cmp),
                (&mut sum.select, c.select),
                (&mut sum.neg, c.neg),
                (&mut sum.mask, c.mask),
                (&mut sum.exp, c.exp),
                (&mut sum.ln, c.ln),
                (&mut sum.pow, c.pow),
                (&mut sum.opaque_map, c.opaque_map),
                (&mut sum.opaque_zip, c.opaque_zip),
                (&mut sum.opaque_test, c.opaque_test),
            ] {
                *a += b;
            }
            n += 1;
        }
    }
    (sum, n as f64)
}

/// Instance right-hand sides per second of `model::evaluate_into` over `Lanes` (in place, as
/// the engine's RK4 loop evaluates), 1 thread.
fn rhs_rate(gs: &[LaneGroup]) -> f64 {
    let first = &gs[0];
    let mut ev = evaluate(Group::of(&first.params), &first.s, &first.d, first.dt);
    best_rate((gs.len() * WIDTH) as f64, |n| {
        let mut acc = 0.0;
        for _ in 0..n {
            for lg in gs {
                evaluate_into(
                    Group::of(&lg.params),
                    black_box(&lg.s),
                    &lg.d,
                    lg.dt,
                    &mut ev,
                );
                acc += black_box(ev.rates[0]).0[0];
            }
        }
        acc
    })
}

fn main() {
    // A harness asking a bench binary for its tests (`--list`, as libtest's and nextest's
    // discovery do) gets none: this bench prints a report, it has no named cases to run apart.
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let p = peaks();
    let g = |x: f64| x / 1.0e9;
    println!("one core, f64:");
    println!("  FMA scalar   {:7.2} GFLOP/s", g(p.scalar));
    println!("  FMA AVX2     {:7.2} GFLOP/s (4 lanes)", g(p.avx2));
    match p.avx512 {
        Some(v) => println!("  FMA AVX-512  {:7.2} GFLOP/s (8 lanes)", g(v)),
        None => println!("  FMA AVX-512  (not on this CPU)"),
    }
    println!("  divide AVX2  {:7.2} G lane-divides/s", g(p.div));
    println!(
        "  math::exp {:.0} M/s ({:.2} GFLOP/s at {} flops), ln {:.0} M/s ({} flops), pow {:.0} M/s ({} flops); libm sin {:.0} M/s",
        p.exp / 1e6,
        g(p.exp * EXP_COST.flops() as f64),
        EXP_COST.flops(),
        p.ln / 1e6,
        LN_COST.flops(),
        p.pow / 1e6,
        POW_COST.flops(),
        p.sin / 1e6
    );
    println!();

    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("campaigns");
    let cases: [(&str, &[&str]); 7] = [
        ("mhtb_selfpress", &[]),
        ("mhtb_selfpress", &["campaign.fidelity=homogeneous"]),
        ("mhtb_selfpress", &["campaign.fidelity=two_mode"]),
        ("lh2_upper_stage", &[]),
        ("lch4_coast", &[]),
        ("aydelott_sphere", &[]),
        ("lh2_insulated", &[]),
    ];
    println!(
        "{:<16} {:<11} {:>6} {:>6} {:>11} {:>7} {:>7} {:>6} {:>9} {:>7} {:>6} {:>6} {:>6} {:>6}",
        "campaign",
        "level",
        "flops",
        "+tr",
        "exp/ln/pow",
        "div+tr",
        "cmp/sel",
        "opaq",
        "RHS/s",
        "ns/RHS",
        "GF/s",
        "GF+tr",
        "%AVX2",
        "%512"
    );
    let mut bounds = Vec::new();
    let show_divides = std::env::args().any(|a| a == "--divides");
    let mut divide_sites = Vec::new();
    // Per row: shares of the measured time of the flop, divide and kernel floors.
    let mut shares: Vec<[f64; 3]> = Vec::new();
    for (name, sets) in cases {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let c = Campaign::load(&dir.join(format!("{name}.toml")), &sets).expect("shipped campaign");
        let level = format!("{:?}", c.params.fidelity).to_lowercase();
        let gs = groups(&c);
        if gs.is_empty() {
            println!("{name:<16} {level:<11} no lane group of WIDTH compatible, finite instances");
            continue;
        }
        count::take_divide_sites();
        let (sum, n) = counts(&gs);
        let sites = count::take_divide_sites();
        let per = |v: u64| v as f64 / n;
        let tr = sum.with_transcendentals();
        let rate = rhs_rate(&gs);
        let flops = per(sum.flops());
        let flops_tr = per(tr.flops());
        let ns = 1.0e9 / rate;
        println!(
            "{:<16} {:<11} {:>6.0} {:>6.0} {:>11} {:>7.0} {:>7} {:>6.0} {:>8.2}M {:>7.0} {:>6.2} {:>6.2} {:>5.1}% {:>5.1}%",
            name,
            level,
            flops,
            flops_tr,
            format!("{:.0}/{:.0}/{:.0}", per(sum.exp), per(sum.ln), per(sum.pow)),
            per(tr.div + tr.sqrt),
            format!("{:.0}/{:.0}", per(sum.cmp), per(sum.select)),
            per(sum.opaque()),
            rate / 1.0e6,
            ns,
            g(flops * rate),
            g(flops_tr * rate),
            100.0 * flops_tr * rate / p.avx2,
            p.avx512.map_or(f64::NAN, |v| 100.0 * flops_tr * rate / v),
        );
        if show_divides {
            divide_sites.push(format!("{name} {level}: divides and square roots per right-hand side by source line (the kernels' own not included)"));
            let shown = sites.len().min(60);
            let listed: f64 = sites.iter().take(shown).map(|(_, k)| *k as f64 / n).sum();
            let all: f64 = sites.iter().map(|(_, k)| *k as f64 / n).sum();
            divide_sites.push(format!(
                "  (the {shown} busiest of {} source lines: {listed:.0} of {all:.0} per right-hand side)",
                sites.len()
            ));
            for (at, k) in sites.iter().take(shown) {
                divide_sites.push(format!("  {:>6.2}  {at}", *k as f64 / n));
            }
        }
        // Time floors of one instance's right-hand side, ns, if each resource alone bound it.
        let fma_floor = 1e9 * flops_tr / p.avx2;
        let div_floor = 1e9 * per(tr.div + tr.sqrt) / p.div;
        let tr_floor = 1e9 * (per(sum.exp) / p.exp + per(sum.ln) / p.ln + per(sum.pow) / p.pow);
        let opaque_floor = 1e9 * per(sum.opaque_map + sum.opaque_zip) / p.sin;
        shares.push([fma_floor / ns, div_floor / ns, tr_floor / ns]);
        bounds.push(format!(
            "{name} {level}: {ns:.0} ns; floors: all flops at AVX2 peak {fma_floor:.0} ns, divides+sqrt {div_floor:.0} ns, \
             kernels {tr_floor:.0} ns (flops plus the larger explain {:.0} %), {:.0} opaque map/zip at libm sin's \
             rate {opaque_floor:.0} ns ({:.0} opaque tests); divides per 100 flops {:.1}, selects+compares per flop {:.2}",
            100.0 * (fma_floor + div_floor.max(tr_floor)) / ns,
            per(sum.opaque_map + sum.opaque_zip),
            per(sum.opaque_test),
            100.0 * per(tr.div + tr.sqrt) / flops_tr,
            per(tr.select + tr.cmp) / flops_tr,
        ));
    }
    println!();
    for b in bounds {
        println!("{b}");
    }
    for l in divide_sites {
        println!("{l}");
    }
    let (lo, hi) = shares.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), s| {
        (lo.min(s[0] + s[1].max(s[2])), hi.max(s[0] + s[1].max(s[2])))
    });
    let div = shares.iter().map(|s| s[1]).fold(0.0f64, f64::max);
    let kernels = shares.iter().map(|s| s[2]).fold(0.0f64, f64::max);
    let fma = shares.iter().map(|s| s[0]).fold(0.0f64, f64::max);
    println!(
        "bound, across the rows above: not the FMA units (every flop at the AVX2 peak is at most {:.0} % of the measured time); \
         the divides (and square roots) alone at most {:.0} %, the kernels alone at most {:.0} %; flops at \
         peak plus the larger of the divide and kernel floors explain {:.0}-{:.0} %: the rest is \
         instruction issue and latency (the loads, stores and blends of the lane values beside the \
         arithmetic, serial Newton iterations, lane-by-lane libm calls behind the opaque maps)",
        100.0 * fma,
        100.0 * div,
        100.0 * kernels,
        100.0 * lo,
        100.0 * hi
    );
}
