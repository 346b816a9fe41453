//! The homogeneous level's closed-tank pressure-rise rate: against CoolProp's two-phase
//! equilibrium (issue 13: the ideal-gas vapour and c_p-integral liquid were off by up to 15 %),
//! and against the textbook closed form of its own property fits (MODEL.md §4): with specific
//! volume v = V/M fixed, the quality x = (v − v_l)/(v_v − v_l) and the specific energy
//! u = u_l + x (u_v − u_l) are functions of T alone, so M du/dT · dT/dt = Q and
//! dP/dt = P_sat'(T) dT/dt (`common::mixture_du_dt`, independent of the model's solver).

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
        ("nLH2", 111_500.0),
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

/// A closed homogeneous tank at fill `fill` and pressure `p_pa`, heated at `q_w`: its simulated
/// pressure-rise rate over the first 20 s, Pa/s, and its propellant mass, kg.
fn closed_tank_rate(fluid: &str, fill: f64, p_pa: f64, q_w: f64) -> (f64, f64) {
    let text = format!(
        "[campaign]\nfidelity = \"homogeneous\"\noutput_interval_s = 5.0\n[tank]\nshape = \"sphere\"\nradius_m = 0.8\nheat_leak_w = {q_w}\nwall_areal_mass_kg_per_m2 = 0.01\nmeop_pa = 1.0e7\n[propellant]\nfluid = \"{fluid}\"\nfill_fraction = {fill}\n[ullage]\npressure_pa = {p_pa}\n[[phases]]\nkind = \"hold\"\nduration_s = 30.0\ndt_s = 0.5\n"
    );
    let c = Campaign::from_text(Path::new("closed_tank.toml"), &text, &[])
        .unwrap_or_else(|e| panic!("{fluid} {fill} {p_pa}: {e}"));
    let mut h = History::default();
    let q = simulate(&c, &c.params, Some(&mut h));
    assert!(
        !q.diverged,
        "{fluid} {fill} {p_pa}: {:?}",
        q.diverged_reason
    );
    let (t, p) = (
        h.column("time_s").unwrap(),
        h.column("pressure_pa").unwrap(),
    );
    let mass = h.column("liquid_mass_kg").unwrap()[0] + h.column("vapor_mass_kg").unwrap()[0];
    // Rows at 5 s and 25 s: past the wall's start-up, before the state has moved.
    let (i, j) = (1, 5);
    ((p[j] - p[i]) / (t[j] - t[i]), mass)
}

/// Closed-tank rate within 1 % of CoolProp 8.0's two-phase equilibrium (fixture
/// `tests/fixtures/fluids/{fluid}_closed_tank.csv`: dP/du at constant mean density from its
/// (ρ, u) flash) at fills 10–90 % and 0.1, 0.6, 2 MPa below 0.9 P_c, for every propellant.
#[test]
fn closed_tank_pressure_rise_matches_coolprop_equilibrium() {
    let q_w = 100.0;
    let mut worst = 0.0_f64;
    for fluid in ["LH2", "LOX", "LCH4", "LN2", "nLH2"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures/fluids")
            .join(format!("{fluid}_closed_tank.csv"));
        let text = std::fs::read_to_string(&path).unwrap();
        let mut rows = 0;
        for line in text.lines().filter(|l| !l.starts_with('#')).skip(1) {
            let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
            let (p_pa, fill, dp_du) = (v[1], v[2], v[4]);
            let (rate, mass) = closed_tank_rate(fluid, fill, p_pa, q_w);
            // The wall (0.01 kg/m², ~30 J/K) takes a share of Q far below 1e-4: ignored.
            let reference = dp_du * q_w / mass;
            let e = rate / reference - 1.0;
            eprintln!(
                "{fluid} {:.1} MPa fill {fill}: model {rate:.5e} Pa/s, CoolProp {reference:.5e} ({e:+.2e})",
                p_pa / 1e6
            );
            assert!(e.abs() < 0.01, "{fluid} {p_pa} Pa fill {fill}: {e:+.3e}");
            worst = worst.max(e.abs());
            rows += 1;
        }
        assert!(rows >= 8, "{fluid}: {rows} rows");
    }
    eprintln!("largest deviation from CoolProp: {worst:.2e}");
}
