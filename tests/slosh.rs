//! Slosh analog checks against analytic references (MODEL.md §5): SP-106 modal table, small-angle
//! pendulum period and damped decay, two-mode frequency, and sweep resonance at ω_1.

mod common;
use cryoslosh::campaign::Campaign;
use cryoslosh::model::slosh::{mode_shape, wall_damping};
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
