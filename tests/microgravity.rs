//! Micro-g coast with the axial acceleration at its floor (MODEL.md §5): no NaN, no divergence,
//! slosh frequencies go smoothly to ~0 (ω² ∝ a_ax), convection falls to its conduction limit.

mod common;
use common::{load, LEVELS};
use cryoslosh::model::slosh::MIN_AXIAL_ACCEL;
use cryoslosh::simulate::{simulate, History};

#[test]
fn coast_at_the_acceleration_floor_stays_finite() {
    for level in LEVELS {
        let fid = format!("campaign.fidelity={level}");
        let c = load("lh2_upper_stage", &[&fid, "phases.2.gravity_m_s2=0"]);
        let mut h = History::default();
        let q = simulate(&c, &c.params, Some(&mut h));
        assert!(!q.diverged, "{level}: {:?}", q.diverged_reason);
        for (name, col) in [
            "time_s",
            "pressure_pa",
            "ullage_temp_k",
            "layer_temp_k",
            "slosh_angle_rad",
            "slosh_frequency_hz",
            "slosh_force_n",
        ]
        .iter()
        .map(|n| (n, h.column(n).unwrap()))
        {
            assert!(
                col.iter().all(|v| v.is_finite()),
                "{level}: {name} has a non-finite value"
            );
        }
        let (t, f1, a) = (
            h.column("time_s").unwrap(),
            h.column("slosh_frequency_hz").unwrap(),
            h.column("axial_accel_m_s2").unwrap(),
        );
        let coast_start = c.phases[0].duration_s + c.phases[1].duration_s;
        let coast: Vec<usize> = (0..t.len())
            .filter(|&i| {
                t[i] > coast_start + 1.0 && t[i] < coast_start + c.phases[2].duration_s - 1.0
            })
            .collect();
        assert!(!coast.is_empty());
        for &i in &coast {
            assert_eq!(
                a[i], MIN_AXIAL_ACCEL,
                "{level}: a_ax in the coast should sit at the floor"
            );
            assert!(
                f1[i] > 0.0 && f1[i] < 1.0e-3,
                "{level}: f_1 = {} Hz in micro-g",
                f1[i]
            );
        }
    }
}

/// A zero-g coast with a 0.01 m/s² lateral step on an LN2 cylinder (R = 1 m, h/R = 2): the
/// pendulum swings at √(|a| ξ/R tanh(ξ h/R)) of the total acceleration, which the analog now
/// reports (it reported 0.000216 Hz from the axial floor while moving at 0.0216 Hz), and the
/// swing beyond the linear range flags the instance.
#[test]
fn zero_g_lateral_push_reports_the_total_acceleration_frequency_and_flags() {
    let text = "[campaign]\nfidelity = \"lumped\"\ndt_s = 0.5\noutput_interval_s = 5.0\n[tank]\nshape = \"cylinder\"\nradius_m = 1.0\ncylinder_length_m = 3.0\nheat_leak_w = 10.0\nmeop_pa = 1.0e6\n[propellant]\nfluid = \"LN2\"\nfill_fraction = 0.6666666666666666\n[ullage]\npressure_pa = 101325.0\n[[phases]]\nkind = \"coast\"\nduration_s = 300.0\ngravity_m_s2 = 0.0\nexcitation = { kind = \"step\", amplitude_m_s2 = 0.01, start_s = 0.0 }\n";
    let c =
        cryoslosh::campaign::Campaign::from_text(std::path::Path::new("zero_g.toml"), text, &[])
            .unwrap();
    let mut h = History::default();
    let q = simulate(&c, &c.params, Some(&mut h));
    assert!(!q.diverged);
    let a = (1.0e-6f64.powi(2) + 0.01f64.powi(2)).sqrt();
    let xi = 1.8412;
    let expected = (a * xi * (xi * 2.0f64).tanh()).sqrt() / std::f64::consts::TAU;
    let f = h.column("slosh_frequency_hz").unwrap()[1];
    assert!((f / expected - 1.0).abs() < 1e-3, "{f} vs {expected}");
    assert!(q.slosh_out_of_range);
    // The pendulum swings through the small angles too: 74 % of the coast is beyond 0.5 rad.
    assert!(
        q.slosh_out_of_range_fraction > 0.5,
        "{}",
        q.slosh_out_of_range_fraction
    );
}

/// The LOX ascent (1 g and more, 0.37 rad of slosh at most) stays inside the analog's range;
/// the LCH4 coast at 1e-4 m/s² (Bond number about 6) is outside it for the whole coast.
#[test]
fn bond_number_and_angle_bound_the_analog() {
    let c = common::load("lox_ascent", &[]);
    let q = cryoslosh::simulate::simulate(&c, &c.params, None);
    assert!(!q.slosh_out_of_range, "{}", q.slosh_out_of_range_fraction);
    let c = common::load("lch4_coast", &[]);
    let q = cryoslosh::simulate::simulate(&c, &c.params, None);
    assert!(q.slosh_out_of_range);
    assert!(
        q.slosh_out_of_range_fraction > 0.999,
        "{}",
        q.slosh_out_of_range_fraction
    );
    let c = common::load("lch4_coast", &["campaign.fidelity=homogeneous"]);
    let q = cryoslosh::simulate::simulate(&c, &c.params, None);
    assert!(!q.slosh_out_of_range, "no analog at the homogeneous level");
}
