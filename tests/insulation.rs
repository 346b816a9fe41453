//! `[insulation]` (issue 17): the modified Lockheed MLI flux, foam conduction, the series
//! interface balance solved by a fixed number of Newton steps, and the heat leak of a shipped
//! campaign following the wall temperature and the phase's surroundings.

mod common;
use common::{campaign_path, load, LEVELS};
use cryoslosh::model::flight::Environment;
use cryoslosh::model::insulation::{
    leak, mli_flux, Foam, Mli, MliCoefficients, Stack, Surroundings, STEFAN_BOLTZMANN,
};
use cryoslosh::simulate::{simulate, History};
use std::process::Command;

/// The modified Lockheed equation written out independently of `model::insulation` (no shared
/// code or constants): Johnson, W. L., "Thermal Performance of Cryogenic Multilayer Insulation
/// at Various Layer Spacings", NASA/TM-2010-216956 (after Keller, Cunnington & Glassford 1974,
/// LMSC-D349866 / NASA CR-134477; the form used for the MHTB blanket, Hastings et al.):
///
/// ```text
/// q = C_s f(T_m) N̄^2.63 (T_h − T_c)/(N_s + 1) + C_r ε (T_h^4.67 − T_c^4.67)/N_s
///   + C_g P (T_h^0.52 − T_c^0.52)/N_s,
/// f(T_m) = 0.017 + 7e-6 (800 − T_m) + 0.0228 ln T_m, T_m = (T_h + T_c)/2,
/// C_s = 2.4e-4, C_r = 4.944e-10, C_g = 14 600, N̄ in layers/cm, P in torr, q in W/m².
/// ```
fn lockheed(th: f64, tc: f64, ns: f64, nbar: f64, p_torr: f64, eps: f64) -> f64 {
    let tm = (th + tc) / 2.0;
    let f = 0.017 + 7.0e-6 * (800.0 - tm) + 0.0228 * tm.ln();
    2.4e-4 * f * nbar.powf(2.63) * (th - tc) / (ns + 1.0)
        + 4.944e-10 * eps * (th.powf(4.67) - tc.powf(4.67)) / ns
        + 14_600.0 * p_torr * (th.powf(0.52) - tc.powf(0.52)) / ns
}

fn blanket(ns: f64, nbar: f64, p_torr: f64, eps: f64, degradation: f64) -> Mli {
    Mli {
        layers: ns,
        layer_density_per_cm: nbar,
        interstitial_pressure_torr: p_torr,
        shield_emissivity: eps,
        degradation_factor: degradation,
    }
}

/// No published worked number of this correlation could be retrieved and checked for this
/// test, so the MLI flux is held to the independent evaluation above (to 1e-12, far inside the
/// 1 % asked for) over the blanket's range, and the MHTB-like case (45 shields, 305 K / 20 K,
/// 1e-6 torr) to the ~0.2 W/m² order its reports give: with N̄ = 10 /cm the correlation gives
/// 0.228 W/m². The degradation factor multiplies the whole flux.
#[test]
fn mli_flux_is_the_modified_lockheed_equation() {
    for &(th, tc) in &[(305.0, 20.0), (293.0, 90.0), (150.0, 20.0), (400.0, 111.0)] {
        for &ns in &[1.0, 10.0, 45.0, 200.0] {
            for &nbar in &[2.0, 10.0, 25.0, 80.0] {
                for &p in &[0.0, 1.0e-6, 1.0e-4] {
                    for &eps in &[0.031, 0.05] {
                        let reference = lockheed(th, tc, ns, nbar, p, eps);
                        for d in [1.0, 2.5] {
                            let q = blanket(ns, nbar, p, eps, d).flux_w_per_m2(th, tc);
                            let e = (q - d * reference).abs() / (d * reference);
                            assert!(
                                e < 1e-12,
                                "{th}/{tc} K, N {ns}, N̄ {nbar}: {q} vs {reference}"
                            );
                        }
                    }
                }
            }
        }
    }
    let mhtb = blanket(45.0, 10.0, 1.0e-6, 0.031, 1.0).flux_w_per_m2(305.0, 20.0);
    assert!(
        (0.15..0.3).contains(&mhtb),
        "MHTB-like blanket: {mhtb} W/m²"
    );
    // The analytic partial derivatives that drive the Newton steps, against central differences.
    let k = blanket(30.0, 15.0, 1.0e-5, 0.031, 1.5).coefficients();
    for &(th, tc) in &[(293.0, 20.0), (200.0, 45.0), (60.0, 20.0)] {
        let (_, dh, dc) = mli_flux(&k, th, tc);
        let h = 1e-4;
        let fd_h = (mli_flux(&k, th + h, tc).0 - mli_flux(&k, th - h, tc).0) / (2.0 * h);
        let fd_c = (mli_flux(&k, th, tc + h).0 - mli_flux(&k, th, tc - h).0) / (2.0 * h);
        assert!(
            (dh - fd_h).abs() < 1e-6 * fd_h.abs(),
            "∂q/∂T_h {dh} vs {fd_h}"
        );
        assert!(
            (dc - fd_c).abs() < 1e-6 * fd_c.abs(),
            "∂q/∂T_c {dc} vs {fd_c}"
        );
    }
}

/// Allowed mismatch between two evaluations of a flux `q` (W/m²): 1e-9 relative (1e-3 W/m² at
/// least), plus what the round-off of a temperature near `t_k` moves it by through a
/// conductance `slope` (W/(m²·K)), 1e-13 relative: a flux recovered from a temperature
/// difference cannot be sharper than that.
fn tolerance(q: f64, slope: f64, t_k: f64) -> f64 {
    1e-9 * q.abs().max(1e-3) + slope.abs() * t_k * 1e-13
}

fn ground(t: f64, h: f64, eps: f64) -> Surroundings {
    Surroundings {
        h_w_per_m2_k: h,
        t_air_k: t,
        t_rad4_k4: t.powi(4),
        absorbed_w_per_m2: 0.0,
        eps_sigma: eps * STEFAN_BOLTZMANN,
    }
}

fn space(sink: f64, absorbed: f64, eps: f64) -> Surroundings {
    Surroundings {
        h_w_per_m2_k: 0.0,
        t_air_k: sink,
        t_rad4_k4: sink.powi(4),
        absorbed_w_per_m2: absorbed,
        eps_sigma: eps * STEFAN_BOLTZMANN,
    }
}

fn surroundings() -> Vec<Surroundings> {
    vec![
        ground(293.15, 5.0, 0.9),
        ground(400.0, 1000.0, 1.0),
        ground(250.0, 0.0, 0.05),
        space(2.725, 0.0, 0.9),
        space(2.725, 80.0, 0.9),
        space(4.0, 1000.0, 0.05),
        space(0.0, 0.0, 0.01),
    ]
}

/// Foam conduction is the closed form k ΔT / L exactly, and bare foam's outer temperature
/// balances the surroundings after the fixed number of steps.
#[test]
fn foam_is_closed_form_conduction() {
    let foam = Foam {
        thickness_m: 0.025,
        conductivity_w_per_m_k: 0.021,
    };
    for &(th, tc) in &[(293.15, 20.3), (120.0, 90.0), (20.0, 300.0)] {
        let closed = 0.021 * (th - tc) / 0.025;
        assert!((foam.flux_w_per_m2(th, tc) - closed).abs() <= 1e-12 * closed.abs());
    }
    for env in surroundings() {
        for &(l, k) in &[(0.025, 0.02), (1.0e-4, 10.0), (0.3, 0.01), (1.0, 1.0e-4)] {
            for t_wall in [20.0, 90.0, 300.0] {
                let f = Foam {
                    thickness_m: l,
                    conductivity_w_per_m_k: k,
                };
                let stack = Stack {
                    foam_resistance_m2_k_per_w: f.resistance_m2_k_per_w(),
                    mli: None,
                };
                let s = leak(&stack, &env, t_wall);
                let conducted = f.flux_w_per_m2(s.t_outer_k, t_wall);
                assert!(
                    (s.flux_w_per_m2 - conducted).abs() <= 1e-12 * conducted.abs().max(1e-300),
                    "{} vs {conducted}",
                    s.flux_w_per_m2
                );
                let (delivered, slope) = env.flux(s.t_outer_k);
                let t_max = s.t_outer_k.max(t_wall);
                assert!(
                    (delivered - conducted).abs()
                        <= tolerance(conducted, slope.abs() + k / l, t_max),
                    "L {l} k {k} wall {t_wall}: surroundings {delivered} vs foam {conducted}"
                );
            }
        }
    }
}

/// Foam and blanket in series: the flux through the foam (wall → interface), through the
/// blanket (interface → outer surface) and from the surroundings are one, to 1e-9, after
/// `OUTER_ITERATIONS` Newton steps on the flux, over the keys' ranges.
#[test]
fn series_foam_and_blanket_balance_at_the_interface() {
    let blankets = [
        blanket(45.0, 10.0, 1.0e-6, 0.031, 1.0),
        blanket(5.0, 2.0, 1.0e-3, 0.05, 1.0),
        blanket(200.0, 50.0, 0.0, 0.031, 3.0),
        blanket(1.0, 1.0, 1.0e-5, 0.5, 1.0),
        blanket(1000.0, 100.0, 1.0e-3, 0.005, 100.0),
    ];
    let foams = [
        None,
        Some((0.025, 0.02)),
        Some((0.3, 0.01)),
        Some((1.0e-4, 1.0)),
    ];
    for env in surroundings() {
        for m in &blankets {
            for foam in foams {
                for t_wall in [15.0, 20.0, 90.0, 150.0, 300.0] {
                    let foam = foam.map(|(l, k)| Foam {
                        thickness_m: l,
                        conductivity_w_per_m_k: k,
                    });
                    let coefficients: MliCoefficients = m.coefficients();
                    let stack = Stack {
                        foam_resistance_m2_k_per_w: foam.map_or(0.0, |f| f.resistance_m2_k_per_w()),
                        mli: Some(coefficients),
                    };
                    let s = leak(&stack, &env, t_wall);
                    let q = s.flux_w_per_m2;
                    let through_foam = foam.map_or(q, |f| f.flux_w_per_m2(s.t_interface_k, t_wall));
                    let through_mli = m.flux_w_per_m2(s.t_outer_k, s.t_interface_k);
                    let (delivered, g_slope) = env.flux(s.t_outer_k);
                    let (_, dh, dc) = mli_flux(&coefficients, s.t_outer_k, s.t_interface_k);
                    let foam_conductance =
                        foam.map_or(0.0, |f| f.conductivity_w_per_m_k / f.thickness_m);
                    let t_max = s.t_outer_k.max(s.t_interface_k).max(t_wall);
                    let slope = g_slope.abs() + dh.abs() + dc.abs() + foam_conductance;
                    let tol = tolerance(q, slope, t_max);
                    let case = format!("{m:?} {foam:?} wall {t_wall} K {env:?}: {s:?}");
                    assert!(
                        (through_foam - q).abs() <= tol,
                        "foam {through_foam}; {case}"
                    );
                    assert!((through_mli - q).abs() <= tol, "MLI {through_mli}; {case}");
                    assert!((delivered - q).abs() <= tol, "outside {delivered}; {case}");
                }
            }
        }
    }
}

/// The shipped insulated campaign's steady leak falls as the wall warms and is lower in space
/// (2.7 K sink, 80 W/m² absorbed) than on the pad (293 K air).
#[test]
fn leak_follows_the_wall_temperature_and_the_surroundings() {
    let c = load("lh2_insulated", &[]);
    let ins = c.params.insulation.expect("the campaign has [insulation]");
    for env in [Environment::Ground, Environment::Space] {
        let cold = ins.leak(env, 20.0).flux_w_per_m2;
        let warm = ins.leak(env, 60.0).flux_w_per_m2;
        assert!(warm < cold, "{env:?}: {warm} at 60 K vs {cold} at 20 K");
    }
    let pad = ins.leak(Environment::Ground, 20.6).flux_w_per_m2;
    let orbit = ins.leak(Environment::Space, 20.6).flux_w_per_m2;
    assert!(orbit < 0.7 * pad, "space {orbit} W/m² vs ground {pad} W/m²");
}

fn column(h: &History, name: &str) -> Vec<f64> {
    h.column(name)
        .unwrap_or_else(|| panic!("no history column {name}"))
        .to_vec()
}

/// Mean recorded heat leak per phase, W.
fn phase_leak(h: &History, phase: &str) -> f64 {
    let q = column(h, "heat_leak_w");
    let rows: Vec<f64> = q
        .iter()
        .zip(&h.phase)
        .filter(|(_, p)| p.as_str() == phase)
        .map(|(v, _)| *v)
        .collect();
    rows.iter().sum::<f64>() / rows.len() as f64
}

/// `cryoslosh simulate` runs the shipped insulated campaign; its history's heat leak is the
/// insulation's at the wall temperature (not a constant), lower in the coast (space) than on the
/// pad (ground); `phases.coast.environment = "ground"` puts the coast back near the pad's.
#[test]
fn insulated_campaign_runs_and_its_leak_follows_the_phase() {
    let dir = std::env::temp_dir().join(format!("cryoslosh-insul-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("h.parquet");
    let o = Command::new(env!("CARGO_BIN_EXE_cryoslosh"))
        .args(["simulate", campaign_path("lh2_insulated").to_str().unwrap()])
        .args(["--out", out.to_str().unwrap()])
        .output()
        .expect("binary runs");
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(out.exists());

    let c = load("lh2_insulated", &["campaign.output_interval_s=20"]);
    let mut h = History::default();
    let q = simulate(&c, &c.params, Some(&mut h));
    assert!(!q.diverged, "{:?}", q.diverged_reason);
    let (pad, coast) = (phase_leak(&h, "pad_hold"), phase_leak(&h, "coast"));
    eprintln!("heat leak: pad {pad:.2} W, coast {coast:.2} W");
    assert!(coast < 0.7 * pad, "coast {coast} W vs pad {pad} W");
    let leak = column(&h, "heat_leak_w");
    let (lo, hi) = leak
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    assert!(hi > 1.5 * lo, "the leak did not change: {lo} … {hi} W");

    let c = load(
        "lh2_insulated",
        &[
            "campaign.output_interval_s=20",
            "phases.coast.environment=ground",
        ],
    );
    let mut g = History::default();
    simulate(&c, &c.params, Some(&mut g));
    let coast_ground = phase_leak(&g, "coast");
    assert!(
        (coast_ground - pad).abs() < 0.1 * pad,
        "coast on the ground {coast_ground} W vs pad {pad} W"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// MODEL.md §10 with the insulation: mass and energy close on every level (the `E_ENV` ledger
/// carries the leak the wall nodes received).
#[test]
fn insulated_campaign_conserves_mass_and_energy() {
    for level in LEVELS {
        let c = load("lh2_insulated", &[&format!("campaign.fidelity={level}")]);
        let q = simulate(&c, &c.params, None);
        assert!(!q.diverged, "{level}: {:?}", q.diverged_reason);
        eprintln!(
            "{level:12} mass {:.2e} energy {:.2e}",
            q.mass_error_rel, q.energy_error_rel
        );
        assert!(q.mass_error_rel < 1e-9, "{level}: {}", q.mass_error_rel);
        assert!(q.energy_error_rel < 1e-6, "{level}: {}", q.energy_error_rel);
    }
}

/// Bad insulation input exits 2 naming the file, the key path, the value and the range.
#[test]
fn bad_insulation_input_names_key_and_range() {
    let path = campaign_path("lh2_insulated");
    let check = |sets: &[&str]| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_cryoslosh"));
        cmd.args(["check", path.to_str().unwrap()]);
        for s in sets {
            cmd.args(["--set", s]);
        }
        let o = cmd.output().expect("binary runs");
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    for (set, needles) in [
        (
            "insulation.mli_layers=0",
            &["insulation.mli_layers", "0", "[1, 1000]"][..],
        ),
        (
            "insulation.foam_thickness_m=-0.01",
            &["insulation.foam_thickness_m", "-0.01", "(0, 1]"][..],
        ),
        (
            "insulation.mli_degradation_factor=0.5",
            &["insulation.mli_degradation_factor", "0.5", "[1, 100]"][..],
        ),
        (
            "insulation.outer_emissivity=nan",
            &["insulation.outer_emissivity", "NaN"][..],
        ),
        (
            "phases.coast.environment=orbit",
            // The key as the override spells it (a phase by name).
            &["--set phases.coast.environment=", "orbit", "ground | space"][..],
        ),
    ] {
        let (code, err) = check(&[set]);
        assert_eq!(code, Some(2), "--set {set}: {err}");
        for n in needles {
            assert!(err.contains(n), "--set {set}: no {n:?} in {err}");
        }
        assert!(err.contains("lh2_insulated.toml"), "{err}");
    }
    // A campaign without a heat leak and without [insulation] is refused naming the key.
    let (code, err) = check(&[]);
    assert_eq!(code, Some(0), "{err}");
    let text = "[campaign]\n[tank]\nshape = \"sphere\"\nradius_m = 1.0\nmeop_pa = 1.0e6\n[propellant]\nfluid = \"LN2\"\nfill_fraction = 0.5\n[ullage]\npressure_pa = 101325.0\n[[phases]]\nkind = \"hold\"\nduration_s = 10.0\n";
    let dir = std::env::temp_dir().join(format!("cryoslosh-noleak-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("no_leak.toml");
    std::fs::write(&file, text).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_cryoslosh"))
        .args(["check", file.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("tank.heat_leak_w") && err.contains("[insulation]"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Keys an `[insulation]` section makes meaningless were accepted and ignored: a variant of
/// the insulated stage setting `tank.heat_leak_w` gave a zero difference, a `--set`, a
/// dispersion or the file's own line of it changed nothing, a phase `environment` without
/// insulation did nothing, and a blanket without its layer density read "= NaN". Each is now
/// refused naming the key.
#[test]
fn keys_the_insulation_makes_unused_are_refused() {
    use cryoslosh::campaign::{Campaign, CampaignError};
    let path = campaign_path("lh2_insulated");
    let text = std::fs::read_to_string(&path).unwrap();
    let refused = |text: &str, sets: &[&str]| -> (String, String) {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        match Campaign::from_text(&path, text, &sets) {
            Ok(_) => panic!("accepted: {sets:?}"),
            Err(e) => (e.key().unwrap_or_default().to_string(), e.to_string()),
        }
    };
    let (key, msg) = refused(&text, &["tank.heat_leak_w=5"]);
    assert_eq!(key, "tank.heat_leak_w", "{msg}");
    assert!(msg.contains("[insulation]"), "{msg}");

    let dispersed = format!(
        "{text}\n[[dispersions.inputs]]\nkey = \"tank.heat_leak_w\"\ndistribution = \"uniform\"\nlo = 1.0\nhi = 2.0\n"
    );
    let last = text.matches("[[dispersions.inputs]]").count();
    let (key, msg) = refused(&dispersed, &[]);
    assert_eq!(key, format!("dispersions.inputs.{last}.key"), "{msg}");
    assert!(msg.contains("tank.heat_leak_w"), "{msg}");

    let variants = format!(
        "{text}\n[[variants]]\nname = \"as_written\"\n\n[[variants]]\nname = \"leakier\"\n\"tank.heat_leak_w\" = 90.0\n"
    );
    let (key, msg) = refused(&variants, &[]);
    assert_eq!(key, "variants.leakier.tank.heat_leak_w", "{msg}");

    let no_density: String = text
        .lines()
        .filter(|l| !l.starts_with("mli_layer_density_per_cm"))
        .collect::<Vec<_>>()
        .join("\n");
    let (key, msg) = refused(&no_density, &[]);
    assert_eq!(key, "insulation.mli_layer_density_per_cm", "{msg}");
    assert!(msg.contains("(missing)") && !msg.contains("NaN"), "{msg}");

    // Written in the file beside the stack, the fixed leak was ignored without a word.
    let stale = text.replacen("[tank]\n", "[tank]\nheat_leak_w = 5000.0\n", 1);
    let (key, msg) = refused(&stale, &[]);
    assert_eq!(key, "tank.heat_leak_w", "{msg}");
    // A variant that adds [insulation] to a campaign with a fixed leak replaces it.
    let trade = campaign_path("tank_design_trade");
    let with_mli = std::fs::read_to_string(&trade).unwrap()
        + "\n[[variants]]\nname = \"mli\"\n\"insulation.mli_layers\" = 30\n\"insulation.mli_layer_density_per_cm\" = 15\n";
    let c = Campaign::from_text(&trade, &with_mli, &[]).unwrap();
    let mli = c.variant(c.variants.len() - 1).unwrap();
    assert!(mli.params.insulation.is_some());
    // One that adds it to a campaign dispersing the fixed leak is refused naming the
    // campaign's dispersion, a path a variant cannot hold (it read
    // `variants.b.dispersions.inputs.0.key`).
    let stage = campaign_path("lh2_upper_stage");
    let text = std::fs::read_to_string(&stage).unwrap();
    let dispersed = text
        .split("[[dispersions.inputs]]")
        .position(|block| block.contains("key = \"tank.heat_leak_w\""))
        .expect("lh2_upper_stage disperses tank.heat_leak_w")
        - 1;
    let with_mli = text
        + "\n[[variants]]\nname = \"a\"\n\n[[variants]]\nname = \"b\"\n\"insulation.mli_layers\" = 30\n\"insulation.mli_layer_density_per_cm\" = 15\n";
    let e = Campaign::from_text(&stage, &with_mli, &[]).unwrap_err();
    assert_eq!(
        e.key(),
        Some(format!("dispersions.inputs.{dispersed}.key").as_str()),
        "{e}"
    );
    assert!(e.to_string().contains("under variant b"), "{e}");

    let bare = campaign_path("lh2_upper_stage");
    let e = Campaign::load(&bare, &["phases.0.environment=space".to_string()]).unwrap_err();
    assert!(matches!(e, CampaignError::InvalidOverride { .. }), "{e}");
    assert_eq!(e.key(), Some("phases.0.environment"), "{e}");
    assert!(e.to_string().contains("[insulation]"), "{e}");
}

/// The insulation solve in lockstep lanes (`Lanes`, the CPU engine) is the `f64` solve lane by
/// lane: a group of dispersed instances (different degradation, foam conductivity and absorbed
/// flux per lane) gives the one-at-a-time records bit for bit on every level.
#[test]
fn insulated_lane_groups_equal_one_at_a_time() {
    use cryoslosh::lanes::WIDTH;
    use cryoslosh::montecarlo::plan::Plan;
    for level in LEVELS {
        let c = load(
            "lh2_insulated",
            &[
                &format!("campaign.fidelity={level}"),
                "phases.coast.duration_s=600",
            ],
        );
        let plan = Plan {
            campaign: &c,
            seed: 11,
            total: WIDTH as u64,
        };
        let lanes = plan.run_lanes(0..WIDTH as u64);
        for (i, l) in lanes.iter().enumerate() {
            let single = plan.run_instance(i as u64);
            assert_eq!(format!("{l:?}"), format!("{single:?}"), "{level}: lane {i}");
        }
    }
}
