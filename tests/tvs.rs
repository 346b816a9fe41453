//! Issue 17's thermodynamic vent system: it holds the pressure in its band over a 24 h LH2 coast, vents exactly its J-T flow while on, carries CoolProp's latent heat, conserves, and refuses bad input.

mod common;
use common::{campaign_path, load};
use cryoslosh::campaign::Campaign;
use cryoslosh::fluids::Fluid;
use cryoslosh::model::tvs;
use cryoslosh::simulate::events::EventKind;
use cryoslosh::simulate::{simulate, History, Summary};
use std::process::Command;

const CAMPAIGN: &str = "lh2_tvs_coast";

/// The shipped coast with overrides, its events recorded.
fn coast(sets: &[&str]) -> Campaign {
    let mut c = load(CAMPAIGN, sets);
    c.record_events = true;
    c
}

/// (start, stop) mission times of each period the TVS ran, from the located events; a period
/// still running at the end closes at `end_s`.
fn on_periods(q: &Summary, end_s: f64) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut start = None;
    for e in &q.events {
        match e.kind {
            EventKind::TvsOn => start = Some(e.time_s),
            EventKind::TvsOff => out.push((start.take().expect("an off without an on"), e.time_s)),
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push((s, end_s));
    }
    out
}

/// The acceptance case: the shipped 24 h coast (MHTB tank, half full, 50 W, band 124–131 kPa)
/// on the lumped and the homogeneous level. Every start is located at the band's upper end and
/// every stop at its lower end; from the second cycle on the pressure stays inside the band
/// (sampled every 60 s); the vented mass is the J-T flow times the time the TVS ran; mass and
/// energy close.
#[test]
fn tvs_holds_the_pressure_in_its_band_over_a_24_h_lh2_coast() {
    for level in ["lumped", "homogeneous"] {
        let fidelity = format!("campaign.fidelity={level}");
        let c = coast(&[&fidelity, "campaign.output_interval_s=60"]);
        let tvs = c.params.tvs.expect("the shipped coast has a [tvs]");
        let (upper, lower) = (tvs.band_upper_pa, tvs.band_lower_pa);
        let mut h = History::default();
        let q = simulate(&c, &c.params, Some(&mut h));
        assert!(!q.diverged, "{level}: {:?}", q.diverged_reason);
        assert_eq!(q.final_time_s, 86_400.0);
        let periods = on_periods(&q, q.final_time_s);
        println!(
            "{level}: {} starts, vented {:.3} kg, peak {:.1} Pa, final {:.1} Pa",
            q.tvs_cycles, q.tvs_vented_kg, q.peak_pressure_pa, q.final_pressure_pa
        );
        // The lumped tank cycles every few hours; the homogeneous one, whose whole liquid must
        // warm through the band, fewer times (once here).
        let least = if level == "homogeneous" { 1 } else { 3 };
        assert!(q.tvs_cycles >= least, "{level}: {} starts", q.tvs_cycles);
        assert!(
            q.events.iter().any(|e| e.kind == EventKind::TvsOff),
            "{level}: never stopped"
        );
        assert_eq!(q.tvs_cycles as usize, periods.len());
        for e in &q.events {
            let at = match e.kind {
                EventKind::TvsOn => upper,
                EventKind::TvsOff => lower,
                _ => continue,
            };
            assert!(
                (e.pressure_pa - at).abs() <= 1e-6 * at,
                "{level}: {:?} at {} Pa, the band's end is {at} Pa",
                e.kind,
                e.pressure_pa
            );
        }
        // Inside the band from the second start on (the homogeneous level: from the first).
        let from = if level == "homogeneous" { 0 } else { 1 };
        let since = periods[from].0;
        let (t, p) = (
            h.column("time_s").unwrap(),
            h.column("pressure_pa").unwrap(),
        );
        let late: Vec<f64> = t
            .iter()
            .zip(p)
            .filter(|(t, _)| **t >= since)
            .map(|(_, p)| *p)
            .collect();
        assert!(late.len() > 100, "{level}: {} samples", late.len());
        let (lo, hi) = late
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &p| (a.min(p), b.max(p)));
        println!(
            "{level}: from start {}, pressure in [{lo:.1}, {hi:.1}] Pa",
            from + 1
        );
        assert!(
            hi <= upper * (1.0 + 1e-6),
            "{level}: {hi} Pa above the band"
        );
        assert!(
            lo >= lower * (1.0 - 1e-6),
            "{level}: {lo} Pa below the band"
        );
        // The first start found the lock-up's warm layer: the lumped level's pressure runs on
        // while the spray mixes it down (the homogeneous level has no layer and turns at once).
        let overshoot = q.peak_pressure_pa - upper;
        println!(
            "{level}: first-cycle overshoot {overshoot:.1} Pa = {:.1} % of the band",
            100.0 * overshoot / (upper - lower)
        );
        let allowed = if level == "homogeneous" {
            1e-6 * upper
        } else {
            0.15 * (upper - lower)
        };
        assert!(overshoot <= allowed, "{level}: overshoot {overshoot} Pa");
        // The J-T flow is fixed while the TVS runs, and the switches are located: the vented
        // mass is the flow times the time on.
        let time_on: f64 = periods.iter().map(|(a, b)| b - a).sum();
        let expected = tvs.jt_flow_kg_s * time_on;
        let rel = (q.tvs_vented_kg - expected).abs() / expected;
        println!(
            "{level}: on {time_on:.1} s, vented {:.6} kg, flow × time {expected:.6} kg, rel {rel:.1e}",
            q.tvs_vented_kg
        );
        assert!(rel < 1e-9, "{level}: vented {} kg", q.tvs_vented_kg);
        assert!(
            q.mass_error_rel < 1e-12,
            "{level}: mass {}",
            q.mass_error_rel
        );
        assert!(
            q.energy_error_rel < 1e-12,
            "{level}: energy {}",
            q.energy_error_rel
        );
        assert_eq!(q.vented_kg, 0.0, "{level}: the relief valve opened");
    }
}

/// Each kilogram the TVS vents leaves as saturated vapour at the J-T outlet pressure, having
/// drawn its latent heat from the liquid: h_g(P_jt) − h_l(T_b) against CoolProp
/// (`ParaHydrogen`, `PropsSI('H','P',P,'Q',1) − PropsSI('H','T',T,'Q',0)`), within the fits'
/// 2e-3 (the energy ledger of that enthalpy: `tests/conservation.rs`).
#[test]
fn the_vent_carries_the_latent_heat_coolprop_gives() {
    // (J-T outlet Pa, liquid K, CoolProp J/kg)
    const COOLPROP: [(f64, f64, f64); 4] = [
        (20_000.0, 20.5, 412_122.64),
        (20_000.0, 21.0, 406_960.25),
        (50_000.0, 20.5, 429_968.01),
        (50_000.0, 21.0, 424_805.62),
    ];
    let f = Fluid::Lh2.props();
    for (p_jt, t_l, reference) in COOLPROP {
        let jt = format!("tvs.jt_outlet_pa={p_jt}");
        let c = load(CAMPAIGN, &[&jt]);
        let tvs = c.params.tvs.unwrap();
        let removed = tvs.vent_enthalpy_j_per_kg - f.h_l_j_per_kg(t_l);
        let rel = (removed - reference).abs() / reference;
        println!("P_jt {p_jt} Pa, T_l {t_l} K: {removed:.1} J/kg vs CoolProp {reference:.1} (rel {rel:.1e}), T_jt {:.3} K", tvs.jt_temperature_k);
        assert!(rel < 2e-3, "{removed} J/kg vs {reference}");
    }
}

/// The fixed-step RK4 loop switches between steps: each start and stop lies past the band's
/// end by at most the largest pressure change of one step (from the history sampled every
/// step), and the vented mass is still the flow times the steps on.
#[test]
fn tvs_under_fixed_rk4_steps_switches_within_a_step() {
    let c = coast(&[
        "campaign.integrator=rk4",
        "phases.0.dt_s=20",
        "campaign.output_interval_s=20",
    ]);
    let tvs = c.params.tvs.unwrap();
    let mut h = History::default();
    let q = simulate(&c, &c.params, Some(&mut h));
    assert!(!q.diverged, "{:?}", q.diverged_reason);
    assert!(q.tvs_cycles >= 3);
    let p = h.column("pressure_pa").unwrap();
    let step = p
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    for e in &q.events {
        let (at, past) = match e.kind {
            EventKind::TvsOn => (tvs.band_upper_pa, e.pressure_pa - tvs.band_upper_pa),
            EventKind::TvsOff => (tvs.band_lower_pa, tvs.band_lower_pa - e.pressure_pa),
            _ => continue,
        };
        println!(
            "{:?} {past:.2} Pa past {at} Pa (one step moves up to {step:.2} Pa)",
            e.kind
        );
        assert!(
            (0.0..=step).contains(&past),
            "{:?} {past} Pa past {at}",
            e.kind
        );
    }
    let time_on: f64 = on_periods(&q, q.final_time_s)
        .iter()
        .map(|(a, b)| b - a)
        .sum();
    let rel = (q.tvs_vented_kg - tvs.jt_flow_kg_s * time_on).abs() / q.tvs_vented_kg;
    assert!(rel < 1e-9, "rel {rel}");
}

/// Without a spray the lumped TVS reaches only the bulk: it runs from its start to the end and
/// drives the bulk down to T_jt, where the exchanger's evaporated share falls to zero over its
/// pinch instead of jumping (the jump from h_g to h_l at T_jt made the bulk chatter on it: 11 719
/// steps here, 87 852 with the outlet near the liquid's P_sat, against 1 102 for the nominal
/// coast).
#[test]
fn tvs_cooling_the_bulk_to_the_jt_temperature_does_not_chatter() {
    let nominal = simulate(&coast(&[]), &coast(&[]).params, None);
    let c = coast(&["tvs.pump_flow_m3_s=0", "campaign.output_interval_s=600"]);
    let mut h = History::default();
    let q = simulate(&c, &c.params, Some(&mut h));
    assert!(!q.diverged, "{:?}", q.diverged_reason);
    let t_jt = c.params.tvs.unwrap().jt_temperature_k;
    let bulk = h.column("bulk_temp_k").unwrap();
    let coldest = bulk.iter().cloned().fold(f64::INFINITY, f64::min);
    println!(
        "no spray: {} steps (nominal {}), {} start(s), coldest bulk {coldest:.4} K, T_jt {t_jt:.4} K",
        q.steps, nominal.steps, q.tvs_cycles
    );
    assert_eq!(q.tvs_cycles, 1);
    assert!(coldest < t_jt + tvs::EXCHANGER_PINCH_K && coldest > t_jt - 1e-3);
    assert!(q.steps < 2 * nominal.steps, "{} steps", q.steps);
    assert!(q.energy_error_rel < 1e-12 && q.mass_error_rel < 1e-12);
}

/// A phase that switches the TVS off neither vents nor cools: the tank self-pressurizes past
/// the band as it would without one.
#[test]
fn tvs_switched_off_in_a_phase_does_nothing() {
    let c = coast(&["phases.0.tvs=false"]);
    let q = simulate(&c, &c.params, None);
    assert_eq!((q.tvs_cycles, q.tvs_vented_kg), (0, 0.0));
    assert!(q.peak_pressure_pa > c.params.tvs.unwrap().band_upper_pa + 5_000.0);
    assert!(q.energy_error_rel < 1e-12);
}

/// A lane group of TVS instances (different flows, fills and leaks; the last one's TVS off)
/// integrates each lane to the same bits as that instance alone.
#[test]
fn tvs_lane_group_equals_one_instance_at_a_time() {
    use cryoslosh::lanes::WIDTH;
    for integrator in ["dopri5", "rk4"] {
        let campaigns: Vec<Campaign> = (0..WIDTH)
            .map(|i| {
                let sets = [
                    format!("campaign.integrator={integrator}"),
                    "phases.0.dt_s=20".into(),
                    "phases.0.duration_s=30000".into(),
                    format!("tvs.jt_flow_kg_s={}", 8e-4 + 1e-4 * i as f64),
                    format!(
                        "propellant.fill_fraction={}",
                        0.3 + 0.56 * i as f64 / WIDTH as f64
                    ),
                    format!("tank.heat_leak_w={}", 40.0 + 3.0 * i as f64),
                    format!("phases.0.tvs={}", i + 1 < WIDTH),
                ];
                let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
                coast(&sets)
            })
            .collect();
        let lanes = common::lanes_equal_one_at_a_time(&campaigns, integrator);
        assert!(lanes[0].tvs_cycles > 0 && lanes[WIDTH - 1].tvs_cycles == 0);
    }
}

fn check(sets: &[&str]) -> std::process::Output {
    common::check_shipped(CAMPAIGN, sets)
}

#[test]
fn bad_tvs_input_exits_2_naming_the_key_and_range() {
    let ok = check(&[]);
    assert_eq!(
        ok.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    for (bad, key, says) in [
        (
            "tvs.band_lower_pa=140000",
            "tvs.band_lower_pa",
            "below tvs.band_upper_pa",
        ),
        // Narrower than a transducer resolves: the TVS would cycle without bound.
        (
            "tvs.band_lower_pa=130990",
            "tvs.band_lower_pa",
            "0.1 % below",
        ),
        (
            "tvs.band_upper_pa=400000",
            "tvs.band_upper_pa",
            "tank.meop_pa",
        ),
        (
            "tvs.band_upper_pa=250000",
            "tvs.band_upper_pa",
            "below relief.crack_pa",
        ),
        (
            "tvs.jt_outlet_pa=124000",
            "tvs.jt_outlet_pa",
            "below tvs.band_lower_pa",
        ),
        // Boiling warmer than the liquid (P_sat 117 kPa) it is to cool.
        (
            "tvs.jt_outlet_pa=120000",
            "tvs.jt_outlet_pa",
            "of the initial liquid",
        ),
        (
            "tvs.jt_outlet_pa=100",
            "tvs.jt_outlet_pa",
            "a finite number in [",
        ),
        ("tvs.jt_flow_kg_s=0", "tvs.jt_flow_kg_s", "(0, 10]"),
        ("tvs.jt_flow_kg_s=nan", "tvs.jt_flow_kg_s", "(0, 10]"),
        ("tvs.pump_flow_m3_s=-1", "tvs.pump_flow_m3_s", "[0, 10]"),
        ("tvs.pump_heat_w=1e6", "tvs.pump_heat_w", "[0, 100000]"),
        ("phases.0.mixer=true", "phases.0.mixer", "without a [mixer]"),
    ] {
        let out = check(&[bad]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{bad}: {err}");
        assert!(err.contains(key) && err.contains(says), "{bad}: {err}");
        assert!(err.contains("lh2_tvs_coast.toml"), "{bad}: {err}");
    }
    // A per-phase switch without the section, and a regulator set inside the band where both
    // run.
    let c = Campaign::load(
        &campaign_path("mhtb_selfpress"),
        &["phases.0.tvs=true".to_string()],
    );
    let e = c.unwrap_err().to_string();
    assert!(
        e.contains("phases.0.tvs") && e.contains("without a [tvs]"),
        "{e}"
    );
    let sets: Vec<String> = [
        "pressurization.setpoint_pa=126000",
        "pressurization.kp_kg_per_s_pa=1e-6",
        "pressurization.max_flow_kg_per_s=0.01",
        "pressurization.gas_temperature_k=100",
        "pressurization.bottle_mass_kg=10",
    ]
    .map(String::from)
    .to_vec();
    let e = Campaign::load(&campaign_path(CAMPAIGN), &sets)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("pressurization.setpoint_pa") && e.contains("tvs.band_lower_pa"),
        "{e}"
    );
    let mut off = sets.clone();
    off.push("phases.0.pressurize=false".into());
    Campaign::load(&campaign_path(CAMPAIGN), &off).unwrap();
}

/// `run` reports the vented mass and the starts per instance.
#[test]
fn run_reports_the_tvs_vented_mass_and_cycles() {
    let out = common::scratch_in("tvs", "run");
    let st = Command::new(env!("CARGO_BIN_EXE_cryoslosh"))
        .args(["run", campaign_path(CAMPAIGN).to_str().unwrap()])
        .args(["--instances", "8", "--threads", "2", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let t = cryoslosh::montecarlo::table::read_f64(&out.join("instances.parquet"), "tvs_vented_kg")
        .unwrap();
    let n = cryoslosh::montecarlo::table::read_u64(&out.join("instances.parquet"), "tvs_cycles")
        .unwrap();
    assert_eq!(t.len(), 8);
    assert!(t.iter().all(|v| *v > 0.0), "{t:?}");
    assert!(n.iter().all(|v| *v > 0), "{n:?}");
    std::fs::remove_dir_all(&out).ok();
}

/// The per-phase `tvs_vented_kg.<phase>` columns: in the trade's `pressure_control` variant the
/// TVS may run only in the coast, so the coast's amount is the mission's and the other phases'
/// are zero (the GPU's phase records carried no TVS slot before, so there were no such columns).
#[test]
fn tvs_vented_mass_per_phase_adds_up_to_the_mission() {
    let trade = load("tank_design_trade", &[]);
    let variants = trade.variant_campaigns().unwrap();
    let k = trade
        .variants
        .iter()
        .position(|v| v.name == "pressure_control")
        .expect("the trade has a pressure_control variant");
    let c = &variants[k];
    let q = simulate(c, &c.params, None);
    assert!(!q.diverged, "{:?}", q.diverged_reason);
    assert!(q.tvs_vented_kg > 0.1, "vented {}", q.tvs_vented_kg);
    let sum: f64 = q.phases.iter().map(|p| p.tvs_vented_kg).sum();
    assert!((sum - q.tvs_vented_kg).abs() <= 1e-12 * q.tvs_vented_kg);
    for p in &q.phases {
        let expect = if p.name == "coast" {
            q.tvs_vented_kg
        } else {
            0.0
        };
        assert!(
            (p.tvs_vented_kg - expect).abs() <= 1e-12 * q.tvs_vented_kg,
            "{}: {} kg (mission {} kg)",
            p.name,
            p.tvs_vented_kg,
            q.tvs_vented_kg
        );
    }
}

/// An undersized TVS ran without a word: `check` now prints its cooling at full duty,
/// ṁ_jt (h_g(T_jt) − h_l(T_l)), against the heat coming in and warns below it; with a tenth of
/// the shipped J-T flow (41 W against 65 W) the pressure indeed climbs past the band.
#[test]
fn check_warns_of_a_tvs_that_cannot_hold_its_band() {
    let text = |o: &std::process::Output| String::from_utf8_lossy(&o.stdout).into_owned();
    let shipped = check(&[]);
    assert!(text(&shipped).contains("cooling at full duty"));
    assert!(!text(&shipped).contains("cannot hold its band"));
    let small = check(&["tvs.jt_flow_kg_s=0.0001"]);
    assert_eq!(small.status.code(), Some(0));
    assert!(
        text(&small).contains("cannot hold its band"),
        "{}",
        text(&small)
    );
    // A TVS that may run in no phase is not warned about.
    let off = check(&["tvs.jt_flow_kg_s=0.0001", "phases.0.tvs=false"]);
    assert!(
        !text(&off).contains("cannot hold its band"),
        "{}",
        text(&off)
    );
    // Written here from the fits: 1e-4 kg/s × (h_g(T_jt) − h_l(T_l)) against 50 W + 15 W.
    let c = coast(&["tvs.jt_flow_kg_s=0.0001"]);
    let f = Fluid::Lh2.props();
    let t = c.params.tvs.unwrap();
    let h_g = f.h_l_j_per_kg(t.jt_temperature_k) + f.h_fg_j_per_kg(t.jt_temperature_k);
    let cooling = 1e-4 * (h_g - f.h_l_j_per_kg(c.params.liquid_temperature_k));
    assert!(cooling < c.params.heat_leak_w + t.pump_heat_w);
    let q = simulate(&c, &c.params, None);
    assert!(
        q.peak_pressure_pa > t.band_upper_pa + 5_000.0,
        "peak {} Pa",
        q.peak_pressure_pa
    );
}
