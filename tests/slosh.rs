//! Slosh analog checks against analytic references (MODEL.md §5): SP-106 modal table, small-angle
//! pendulum period and damped decay, two-mode frequency, and sweep resonance at ω_1; and the
//! domed-tank tables against the potential-flow solver run at twice their resolution
//! (tests/fixtures/slosh/reference_2x.csv, written by tools/slosh_tables.py), McIver's
//! half-full sphere and the empty-sphere limit ω² R/g → 1.

mod common;
use cryoslosh::campaign::Campaign;
use cryoslosh::geometry::{Shape, Tank, TankLanes};
use cryoslosh::lanes::{Lanes, Real, WIDTH};
use cryoslosh::model::slosh::{mode_shape, tank_modes, wall_damping, ModeShape};
use cryoslosh::simulate::{simulate, History};
use std::f64::consts::TAU;
use std::path::Path;

#[test]
fn sp106_reference_values() {
    // (h/R, mode, m_n/m, L_n/R, ω² R/g) from MODEL.md §5 (Abramson SP-106, Dodge 2000).
    let table = [
        (1.0, 0, 0.432, 0.571, 1.751),
        (1.0, 1, 0.0137, 0.188, 5.331),
        (2.0, 0, 0.227, 0.544, 1.839),
    ];
    for (hr, n, m, l, w2) in table {
        let s = mode_shape(n, hr);
        for (what, got, want) in [
            ("m/m_l", s.mass_ratio, m),
            ("L/R", s.length_ratio, l),
            ("ω²R/g", s.omega2_ratio, w2),
        ] {
            assert!(
                (got - want).abs() < 1e-3,
                "h/R {hr} mode {}: {what} = {got}, reference {want}",
                n + 1
            );
        }
    }
}

/// A closed LN2 cylinder (R = 0.5 m, h/R = 1) with no heat, held at 1 g, released from `angle`.
fn free_decay(level: &str, extra_damping: f64, dt: f64, duration: f64) -> (Campaign, History) {
    let text = format!(
        r#"
[campaign]
fidelity = "{level}"
output_interval_s = {dt}
[tank]
shape = "cylinder"
radius_m = 0.5
cylinder_length_m = 2.0
heat_leak_w = 0.0
meop_pa = 1.0e6
[propellant]
fluid = "LN2"
fill_fraction = 0.25
[ullage]
pressure_pa = 101325.0
[slosh]
initial_angle_rad = 0.01
extra_damping_ratio = {extra_damping}
[[phases]]
kind = "hold"
duration_s = {duration}
dt_s = {dt}
"#
    );
    let c = Campaign::from_text(Path::new("free_decay.toml"), &text, &[]).expect("valid campaign");
    let mut h = History::default();
    let q = simulate(&c, &c.params, Some(&mut h));
    assert!(!q.diverged, "{:?}", q.diverged_reason);
    (c, h)
}

/// Peaks of a sampled signal, refined by a parabola through the three samples around each.
fn peaks(t: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for i in 1..y.len() - 1 {
        if y[i] > y[i - 1] && y[i] >= y[i + 1] && y[i] > 0.0 {
            let (a, b, c) = (y[i - 1], y[i], y[i + 1]);
            let d = 0.5 * (a - c) / (a - 2.0 * b + c);
            let h = t[i + 1] - t[i];
            out.push((t[i] + d * h, b - 0.25 * (a - c) * d));
        }
    }
    out
}

/// Independent reference: ω_1 and ζ of the test tank from the SP-106 closed forms.
#[expect(
    clippy::approx_constant,
    reason = "0.318 is the published empirical constant, not 1/π"
)]
fn reference(c: &Campaign, extra: f64) -> (f64, f64) {
    let p = &c.params;
    let f = p.fluid.props();
    let (r, hr, g) = (0.5, 1.0, 9.80665);
    let xi: f64 = 1.841_18;
    let omega = (g * xi * (xi * hr).tanh() / r).sqrt();
    let t = p.liquid_temperature_k;
    let nu = f.mu_l_pa_s(t) / f.rho_l_kg_per_m3(t);
    let x = 1.84 * hr;
    let shape = 1.0 + (0.318 / x.sinh()) * (1.0 + (1.0 - hr) / x.cosh());
    let zeta = (4.98 / TAU) * nu.sqrt() * r.powf(-0.75) * g.powf(-0.25) * shape + extra;
    assert!((zeta - extra - wall_damping(nu, r, g, hr)).abs() < 1e-15);
    (omega, zeta)
}

#[test]
fn pendulum_period_and_decay_match_analytic() {
    let extra = 0.01;
    let (c, h) = free_decay("lumped", extra, 0.002, 60.0);
    let (omega, zeta) = reference(&c, extra);
    let pk = peaks(
        h.column("time_s").unwrap(),
        h.column("slosh_angle_rad").unwrap(),
    );
    let (first, last) = (pk[1], pk[pk.len() - 2]);
    let cycles = (pk.len() - 3) as f64;
    let period = (last.0 - first.0) / cycles;
    let want_period = TAU / (omega * (1.0 - zeta * zeta).sqrt());
    let decay = (first.1 / last.1).ln() / (last.0 - first.0);
    eprintln!(
        "period {period:.8} vs {want_period:.8}; decay {decay:.8} vs {:.8}",
        zeta * omega
    );
    assert!(
        (period / want_period - 1.0).abs() < 1e-4,
        "period {period} vs {want_period}"
    );
    assert!(
        (decay / (zeta * omega) - 1.0).abs() < 1e-4,
        "decay {decay} vs {}",
        zeta * omega
    );
}

#[test]
fn two_mode_first_mode_period_matches_analytic() {
    let (c, h) = free_decay("two_mode", 0.0, 0.002, 30.0);
    let (omega, zeta) = reference(&c, 0.0);
    let pk = peaks(
        h.column("time_s").unwrap(),
        h.column("slosh_angle_rad").unwrap(),
    );
    let period = (pk[pk.len() - 2].0 - pk[1].0) / (pk.len() - 3) as f64;
    let want = TAU / (omega * (1.0 - zeta * zeta).sqrt());
    assert!(
        (period / want - 1.0).abs() < 1e-4,
        "period {period} vs {want}"
    );
}

#[test]
fn sine_sweep_peaks_at_the_first_slosh_frequency() {
    // A slow sweep through f_1 at constant fill and 1 g: the largest angle comes at resonance.
    let (c0, _) = free_decay("lumped", 0.0, 0.01, 0.01);
    let (omega, _) = reference(&c0, 0.0);
    let f1 = omega / TAU;
    let sets = ["slosh.extra_damping_ratio=0.01".to_string()];
    let c = Campaign::from_text(
        Path::new("sweep.toml"),
        &format!(
            "[campaign]\noutput_interval_s = 0.01\n[tank]\nshape = \"cylinder\"\nradius_m = 0.5\ncylinder_length_m = 2.0\nheat_leak_w = 0.0\nmeop_pa = 1.0e6\n[propellant]\nfluid = \"LN2\"\nfill_fraction = 0.25\n[ullage]\npressure_pa = 101325.0\n[[phases]]\nkind = \"hold\"\nduration_s = 2000.0\ndt_s = 0.01\nexcitation = {{ kind = \"sweep\", amplitude_m_s2 = 0.001, f_start_hz = {}, f_end_hz = {}, duration_s = 2000.0 }}\n",
            0.5 * f1,
            1.5 * f1
        ),
        &sets,
    )
    .expect("valid");
    let mut h = History::default();
    simulate(&c, &c.params, Some(&mut h));
    let (t, a) = (
        h.column("time_s").unwrap(),
        h.column("slosh_angle_rad").unwrap(),
    );
    let i = (0..a.len())
        .max_by(|&i, &j| a[i].abs().total_cmp(&a[j].abs()))
        .unwrap();
    let f_at_peak = c.phases[0].excitation.sweep_frequency_hz(t[i]).unwrap();
    eprintln!(
        "peak at t = {:.1} s, sweep at {f_at_peak:.5} Hz, f_1 = {f1:.5} Hz",
        t[i]
    );
    assert!(
        (f_at_peak / f1 - 1.0).abs() < 0.02,
        "resonance at {f_at_peak} Hz, f_1 = {f1} Hz"
    );
}

#[test]
fn lox_ascent_sweep_resonates_near_the_instantaneous_first_mode() {
    // In the shipped flight campaign f_1 drifts as the vehicle accelerates and drains: the
    // largest slosh angle must still come where the sweep crosses the instantaneous f_1.
    let c = common::load("lox_ascent", &[]);
    let mut h = History::default();
    simulate(&c, &c.params, Some(&mut h));
    let a = h.column("slosh_angle_rad").unwrap();
    let i = (0..a.len())
        .max_by(|&i, &j| a[i].abs().total_cmp(&a[j].abs()))
        .unwrap();
    let t_phase = h.column("time_s").unwrap()[i] - c.phases[0].duration_s;
    let f_sweep = c.phases[1].excitation.sweep_frequency_hz(t_phase).unwrap();
    let f1 = h.column("slosh_frequency_hz").unwrap()[i];
    eprintln!("peak at phase time {t_phase:.1} s: sweep {f_sweep:.4} Hz, f_1 {f1:.4} Hz");
    assert!(
        (f_sweep / f1 - 1.0).abs() < 0.1,
        "sweep {f_sweep} Hz vs f_1 {f1} Hz"
    );
}

/// The two modes of `tank` at fill `fill` (liquid volume / tank volume), one lane.
fn modes_at_fill(tank: &Tank, fill: f64) -> [ModeShape; 2] {
    let v = fill * tank.volume_m3();
    let z = tank.liquid_height_m(v);
    tank_modes(&TankLanes::<f64>::gather(|_| tank), z, v)
}

#[test]
fn half_full_sphere_matches_mciver() {
    // McIver (1989): ω_1² R/g = 1.5602 for a half-full sphere.
    let tank = Tank::new(Shape::Sphere, 0.8, 0.0, 1.0);
    let w2 = modes_at_fill(&tank, 0.5)[0].omega2_ratio;
    eprintln!("half-full sphere ω² R/g = {w2:.5}");
    assert!((w2 / 1.5602 - 1.0).abs() < 2e-3, "{w2}");
}

#[test]
fn emptying_sphere_tends_to_the_pendulum_about_its_centre() {
    // Shallow liquid at the bottom of a sphere swings like a pendulum of length R: ω² R/g → 1
    // from above, decreasing as the sphere empties.
    let tank = Tank::new(Shape::Sphere, 1.0, 0.0, 1.0);
    let fills = [0.05, 0.02, 0.01, 0.005, 0.001, 1e-4, 1e-6, 0.0];
    let w2: Vec<f64> = fills
        .iter()
        .map(|&f| modes_at_fill(&tank, f)[0].omega2_ratio)
        .collect();
    eprintln!("fills {fills:?}: ω² R/g {w2:?}");
    // 1 % of the volume is 0.116 R deep: the solver gives 1.0412 there (the fixture's 1 % row),
    // 1.0067 at 1 % of the height (0.02 R deep).
    assert!((w2[2] / 1.0412 - 1.0).abs() < 2e-3, "1 % fill: {}", w2[2]);
    let z = 0.02 * tank.radius_m();
    let at_1pct_height = tank_modes(
        &TankLanes::<f64>::gather(|_| &tank),
        z,
        tank.liquid_volume_m3(z),
    )[0]
    .omega2_ratio;
    assert!(at_1pct_height < 1.01, "{at_1pct_height}");
    for pair in w2.windows(2) {
        assert!(pair[1] <= pair[0] && pair[1] >= 1.0, "{w2:?}");
    }
    assert!((w2[w2.len() - 1] - 1.0).abs() < 1e-3, "{w2:?}");
    let m: Vec<f64> = fills
        .iter()
        .map(|&f| modes_at_fill(&tank, f)[0].mass_ratio)
        .collect();
    assert!(m.iter().all(|&m| m > 0.9 && m <= 1.0 + 1e-9), "{m:?}");
}

/// One row of tests/fixtures/slosh/reference_2x.csv.
struct Reference {
    shape: Shape,
    dome_ratio: f64,
    length_over_r: f64,
    fill: f64,
    level_over_r: f64,
    mode: usize,
    omega2: f64,
    mass_ratio: f64,
}

fn reference_rows() -> Vec<Reference> {
    let text = include_str!("fixtures/slosh/reference_2x.csv");
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("shape"))
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let num = |i: usize| f[i].parse::<f64>().expect("number");
            Reference {
                shape: Shape::from_name(f[0]).expect("shape"),
                dome_ratio: num(1),
                length_over_r: num(2),
                fill: num(3),
                level_over_r: num(4),
                mode: f[5].parse::<usize>().expect("mode") - 1,
                omega2: num(6),
                mass_ratio: num(7),
            }
        })
        .collect()
}

#[test]
fn domed_tables_match_the_solver_at_twice_their_resolution() {
    // Every fixture row with 5 % ≤ fill ≤ 95 %, evaluated WIDTH rows at a time through the lane
    // API (different dome ratios and barrel lengths side by side): ω_n² R/g and m_n/m_l of both
    // modes within 1 % of the solver.
    let radius = 1.7;
    let rows: Vec<Reference> = reference_rows()
        .into_iter()
        .filter(|r| (0.05 - 1e-9..=0.95 + 1e-9).contains(&r.fill))
        .collect();
    assert!(rows.len() >= 4 * 19 * 2, "{} rows", rows.len());
    let mut worst = [(0.0_f64, String::new()), (0.0_f64, String::new())];
    for shape in [Shape::Sphere, Shape::Capsule] {
        let of_shape: Vec<&Reference> = rows.iter().filter(|r| r.shape == shape).collect();
        for chunk in of_shape.chunks(WIDTH) {
            let tanks: Vec<Tank> = chunk
                .iter()
                .map(|r| Tank::new(shape, radius, r.length_over_r * radius, r.dome_ratio))
                .collect();
            let lanes = TankLanes::<Lanes>::gather(|i| &tanks[i.min(tanks.len() - 1)]);
            let at = |i: usize| chunk[i.min(chunk.len() - 1)];
            let z = Lanes::from_fn(|i| at(i).level_over_r * radius);
            let v = Lanes::from_fn(|i| tanks[i.min(tanks.len() - 1)].liquid_volume_m3(z.lane(i)));
            let modes = tank_modes(&lanes, z, v);
            for (i, r) in chunk.iter().enumerate() {
                let m = &modes[r.mode];
                let fill = v.lane(i) / tanks[i].volume_m3();
                assert!((fill - r.fill).abs() < 1e-6, "fill {fill} vs {}", r.fill);
                for (q, got, want) in [
                    (0, m.omega2_ratio.lane(i), r.omega2),
                    (1, m.mass_ratio.lane(i), r.mass_ratio),
                ] {
                    let err = (got / want - 1.0).abs();
                    let what = format!(
                        "{} k {} L/R {} fill {} mode {}: {got:.6} vs {want:.6}",
                        shape.name(),
                        r.dome_ratio,
                        r.length_over_r,
                        r.fill,
                        r.mode + 1
                    );
                    if err > worst[q].0 {
                        worst[q] = (err, what.clone());
                    }
                    assert!(err < 0.01, "{}: {what}", ["ω²R/g", "m/m_l"][q]);
                }
            }
        }
    }
    eprintln!("worst ω² R/g {:.2e} at {}", worst[0].0, worst[0].1);
    eprintln!("worst m_n/m_l {:.2e} at {}", worst[1].0, worst[1].1);
}
