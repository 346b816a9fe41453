//! The homogeneous level reproduces the textbook closed-tank pressure-rise rate (MODEL.md §4):
//! with specific volume v = V/M fixed, the quality x = (v − v_l)/(v_v − v_l) and the specific
//! energy u = u_l + x (u_v − u_l) are functions of T alone, so M du/dT · dT/dt = Q and
//! dP/dt = P_sat'(T) dT/dt — written with analytic derivatives in `common::mixture_du_dt`,
//! independently of the model.

mod common;
use common::mixture_du_dt;
use cryoslosh::campaign::Campaign;
use cryoslosh::simulate::{simulate, History};
use std::path::Path;

#[test]
fn closed_tank_pressure_rise_matches_closed_form() {
    for (fluid, p0) in [
        ("LN2", 101_325.0),
        ("LH2", 111_500.0),
        ("LOX", 150_000.0),
        ("LCH4", 120_000.0),
    ] {
        let q_w = 200.0;
        let text = format!(
            "[campaign]\nfidelity = \"homogeneous\"\noutput_interval_s = 10.0\n[tank]\nshape = \"sphere\"\nradius_m = 0.8\nheat_leak_w = {q_w}\nwall_areal_mass_kg_per_m2 = 0.01\nmeop_pa = 1.0e7\n[propellant]\nfluid = \"{fluid}\"\nfill_fraction = 0.6\n[ullage]\npressure_pa = {p0}\n[[phases]]\nkind = \"hold\"\nduration_s = 3600.0\ndt_s = 1.0\n"
        );
        let c = Campaign::from_text(Path::new("homogeneous.toml"), &text, &[]).unwrap();
        let mut h = History::default();
        let q = simulate(&c, &c.params, Some(&mut h));
        assert!(!q.diverged);
        let f = c.params.fluid;
        let props = f.props();
        let (t, p, tb) = (
            h.column("time_s").unwrap(),
            h.column("pressure_pa").unwrap(),
            h.column("bulk_temp_k").unwrap(),
        );
        let total_mass =
            h.column("liquid_mass_kg").unwrap()[0] + h.column("vapor_mass_kg").unwrap()[0];
        let v = c.params.tank.volume_m3() / total_mass;
        let wall_heat_capacity = c.params.wall_areal_mass_kg_per_m2
            * c.params.tank.wall_area_m2()
            * c.params.wall_cp_j_per_kg_k;
        // Compare at mid-run, after the wall has settled into tracking the fluid.
        let i = t.len() / 2;
        let model_rate = (p[i + 1] - p[i - 1]) / (t[i + 1] - t[i - 1]);
        let temp = tb[i];
        let dtdt = q_w / (total_mass * mixture_du_dt(f, v, temp) + wall_heat_capacity);
        let closed_form = props.dpsat_dt_pa_per_k(temp) * dtdt;
        eprintln!("{fluid}: model {model_rate:.6} Pa/s, closed form {closed_form:.6} Pa/s");
        assert!(
            (model_rate / closed_form - 1.0).abs() < 1e-3,
            "{fluid}: {model_rate} vs {closed_form}"
        );
    }
}
