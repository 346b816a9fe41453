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
