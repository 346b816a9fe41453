//! States for the same-work peers of `benches/reference/` (issue 18): the lumped level's
//! right-hand side at states taken along real trajectories of a shipped campaign.
//!
//! ```text
//! cargo run --release --example rhs_states -- CAMPAIGN --out states.parquet [--rows 1000] [--set K=V]
//! cargo run --release --example rhs_states -- CAMPAIGN --time [--rows 1000] [--seconds 2]
//! cargo run --release --example rhs_states -- CAMPAIGN --initial --instances N --out start.parquet
//! ```
//!
//! `--initial` writes instead one row per instance, its state at t = 0, in instance order (where
//! `benches/reference/solution.py` starts its whole-mission runs).
//!
//! The instances are the campaign's own dispersion samples (`montecarlo::plan::Plan`, the
//! campaign's seed, `--instances` of them). Each is integrated by the engine's fixed-step path,
//! `model::rk4_step` at each phase's step with the relief valve updated and an empty bulk merged
//! between steps, and rows are picked at random (instance, step) pairs. Each row holds every
//! number the lumped right-hand side reads from `Params` (flattened, `p_*`), the drive (`d_*`),
//! the step `dt`, the state (`s_*`) and cryoslosh's rates (`r_*`, `Evaluation::rates`). The
//! constants the right-hand side reads (the propellant's fit coefficients, helium, the
//! vapour-energy offset, the slosh tables, model floors) go into the file's key-value metadata
//! `cryoslosh_constants` as JSON, so the Python ports read the engine's own numbers.
//!
//! `--time` evaluates the same rows as `Lanes` groups (`lanes::WIDTH` instances) on 1 and 2
//! rayon threads and prints right-hand-side evaluations per second.

use arrow_array::{ArrayRef, Float64Array, RecordBatch};
use arrow_schema::{DataType, Field, Schema};
use cryoslosh::campaign::Campaign;
use cryoslosh::fluids::{FluidProps, HELIUM, R_UNIVERSAL};
use cryoslosh::geometry::Shape;
use cryoslosh::lanes::{Lanes, Real, WIDTH};
use cryoslosh::model::derive::{Drive, Switches, MIN_WALL_SHARE};
use cryoslosh::model::params::{Fidelity, Params};
use cryoslosh::model::state::{vapor_energy_offset, State, M_B, NS};
use cryoslosh::model::{self, slosh, slosh_table, Group};
use cryoslosh::montecarlo::plan::Plan;
use parquet::arrow::ArrowWriter;
use parquet::file::metadata::KeyValue;
use parquet::file::properties::WriterProperties;
use rayon::prelude::*;
use std::sync::Arc;
use std::time::Instant;

/// One sampled right-hand-side input.
struct Row {
    params: Params,
    drive: Drive,
    dt: f64,
    state: State,
}

/// splitmix64: a reproducible stream without a new dependency.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

/// Steps of every phase of `c`, in order.
fn total_steps(c: &Campaign) -> u64 {
    c.phases.iter().map(|ph| ph.steps().0).sum()
}

/// Integrate instance `c` by fixed RK4 steps and return the states at the global step indices
/// `picks` (ascending), each with its drive and step.
fn trajectory_rows(c: &Campaign, picks: &[u64]) -> Vec<Row> {
    let p = &c.params;
    let g = Group::one(p);
    let mut s = cryoslosh::simulate::initial_state(c, p);
    let mut valve = false;
    let mut out = Vec::with_capacity(picks.len());
    let mut next = 0;
    let mut k = 0u64;
    for phase in &c.phases {
        let (n, dt) = phase.steps();
        for i in 0..n {
            let t = i as f64 * dt;
            while next < picks.len() && picks[next] == k {
                out.push(Row {
                    params: *p,
                    drive: Drive::of_phase(
                        phase,
                        t,
                        Switches {
                            relief: valve,
                            tvs: false,
                        },
                    ),
                    dt,
                    state: s,
                });
                next += 1;
            }
            if next == picks.len() {
                return out;
            }
            let m_b0 = s[M_B];
            model::rk4_step(
                g,
                |tt| {
                    Drive::of_phase(
                        phase,
                        tt,
                        Switches {
                            relief: valve,
                            tvs: false,
                        },
                    )
                },
                &mut s,
                t,
                dt,
                None,
            );
            let horizon = model::BULK_MERGE_DRAIN_S.max(2.0 * dt);
            model::merge_empty_bulk(p, &mut s, m_b0, (dt, horizon));
            let d = Drive::of_phase(
                phase,
                t + dt,
                Switches {
                    relief: valve,
                    tvs: false,
                },
            );
            let pressure = model::evaluate(g, &s, &d, dt).derived.p_ullage_pa;
            valve = model::update_valve(g, pressure, valve);
            k += 1;
        }
    }
    out
}

/// The first `instances` dispersed instances of `c` (the campaign's seed), as `run` samples them.
fn members(c: &Campaign, instances: u64) -> Vec<Campaign> {
    let plan = Plan {
        campaign: c,
        seed: c.seed,
        total: instances,
    };
    (0..instances)
        .map(|i| match plan.resolve(i).1 {
            Ok(Some(ci)) => ci,
            Ok(None) => c.clone(),
            Err(e) => panic!("instance {i} rejected: {e}"),
        })
        .collect()
}

/// `rows` states of `instances` dispersed instances of `c`.
fn sample_rows(c: &Campaign, instances: u64, rows: usize, seed: u64) -> Vec<Row> {
    let members = members(c, instances);
    let mut rng = Rng(seed);
    let mut picks: Vec<Vec<u64>> = vec![Vec::new(); members.len()];
    for _ in 0..rows {
        let i = rng.below(instances) as usize;
        picks[i].push(rng.below(total_steps(&members[i])));
    }
    for v in &mut picks {
        v.sort_unstable();
    }
    // Rows grouped by instance, each instance's in step order.
    members
        .par_iter()
        .zip(&picks)
        .flat_map_iter(|(ci, pk)| trajectory_rows(ci, pk))
        .collect()
}

/// The initial state of each of the first `instances` instances of `c`, in instance order (the
/// start of `benches/reference/solution.py`'s whole-mission runs).
fn initial_rows(c: &Campaign, instances: u64) -> Vec<Row> {
    members(c, instances)
        .iter()
        .flat_map(|ci| trajectory_rows(ci, &[0]))
        .collect()
}

/// The flattened numbers of `Params` that the lumped right-hand side reads. Options become a
/// 0/1 flag and NaN when absent.
fn param_columns(p: &Params) -> Vec<(&'static str, f64)> {
    let (shape, r, l, k) = Group::one(p).tank::<f64>().dimensions();
    let opt = |o: Option<f64>| o.unwrap_or(f64::NAN);
    let ht = &p.heat_transfer;
    let ps = p.pressurization;
    let rl = p.relief;
    vec![
        (
            "tank_shape",
            match shape {
                Shape::Cylinder => 0.0,
                Shape::Capsule => 1.0,
                Shape::Sphere => 2.0,
            },
        ),
        ("tank_radius_m", r),
        ("tank_length_m", l),
        ("tank_dome_ratio", k),
        ("heat_leak_w", p.heat_leak_w),
        ("wall_areal_mass_kg_per_m2", p.wall_areal_mass_kg_per_m2),
        ("wall_cp_j_per_kg_k", p.wall_cp_j_per_kg_k),
        (
            "evaporation_coefficient",
            opt(ht.evaporation_coefficient_kg_per_s_pa),
        ),
        ("accommodation", ht.accommodation),
        ("h_us", opt(ht.h_us_w_per_m2_k)),
        ("h_sb", opt(ht.h_sb_w_per_m2_k)),
        ("h_wall_ullage", opt(ht.h_wall_ullage_w_per_m2_k)),
        ("h_wall_liquid", opt(ht.h_wall_liquid_w_per_m2_k)),
        ("diffusivity_factor", p.stratification.diffusivity_factor),
        ("wall_heat_to_layer", p.stratification.wall_heat_to_layer),
        ("coupling_volume_m3", p.coupling.volume_m3),
        ("h_enhancement", p.coupling.h_enhancement_w_per_m2_k_s),
        ("mixing", p.coupling.mixing),
        ("baffle_count", f64::from(p.baffles.count)),
        ("baffle_width_m", p.baffles.width_m),
        ("baffle_spacing_m", p.baffles.spacing_m),
        ("baffle_top_height_m", p.baffles.top_height_m),
        ("baffle_wave_amplitude_m", p.baffles.wave_amplitude_m),
        ("extra_damping", p.extra_damping),
        ("has_pressurization", f64::from(u8::from(ps.is_some()))),
        ("pressurant_vapor_share", p.pressurant_vapor_share()),
        ("press_setpoint_pa", opt(ps.map(|q| q.setpoint_pa))),
        ("press_kp", opt(ps.map(|q| q.kp_kg_per_s_pa))),
        ("press_kd", opt(ps.map(|q| q.kd_kg_per_pa))),
        ("press_filter_s", opt(ps.map(|q| q.derivative_filter_s))),
        ("press_max_flow", opt(ps.map(|q| q.max_flow_kg_per_s))),
        (
            "press_gas_temperature_k",
            opt(ps.map(|q| q.gas_temperature_k)),
        ),
        ("press_bottle_kg", opt(ps.map(|q| q.bottle_mass_kg))),
        (
            "press_schedule_ref_m3",
            opt(ps.map(|q| q.gain_schedule.reference_or_zero_m3())),
        ),
        ("has_relief", f64::from(u8::from(rl.is_some()))),
        ("relief_flow_area_m2", opt(rl.map(|q| q.flow_area_m2))),
        (
            "has_insulation",
            f64::from(u8::from(p.insulation.is_some())),
        ),
        ("feed_isp_s", p.feed.isp_s),
        ("feed_propellant_fraction", p.feed.propellant_fraction),
        ("vehicle_dry_mass_kg", p.vehicle.dry_mass_kg),
        ("vehicle_drag_area_m2", p.vehicle.drag_area_m2),
    ]
}

fn drive_columns(d: &Drive, dt: f64) -> Vec<(&'static str, f64)> {
    let b = |m: bool| f64::from(u8::from(m));
    vec![
        ("d_thrust_n", d.thrust_n),
        ("d_burning", b(d.burning)),
        ("d_flying", b(d.flying)),
        ("d_gamma_rad", d.gamma_rad),
        ("d_gravity_m_s2", d.gravity_m_s2),
        ("d_a_lat", d.a_lat),
        ("d_a_ax_extra", d.a_ax_extra),
        ("d_pressurize", b(d.pressurize)),
        ("d_valve_open", b(d.valve_open)),
        ("d_space", b(d.space)),
        ("dt", dt),
    ]
}

fn props_json(f: &FluidProps) -> serde_json::Value {
    serde_json::json!({
        "molar_mass_kg_per_mol": f.molar_mass_kg_per_mol,
        "t_triple_k": f.t_triple_k,
        "t_crit_k": f.t_crit_k,
        "p_crit_pa": f.p_crit_pa,
        "t_min_k": f.t_min_k,
        "t_max_k": f.t_max_k,
        "ideal_t_lo_k": f.ideal_t_lo_k,
        "ideal_t_hi_k": f.ideal_t_hi_k,
        "k_vapor_ref_w_per_m_k": f.k_vapor_ref_w_per_m_k,
        "k_vapor_exp": f.k_vapor_exp,
        "mu_vapor_ref_pa_s": f.mu_vapor_ref_pa_s,
        "mu_vapor_exp": f.mu_vapor_exp,
        "vapor_t_ref_k": f.vapor_t_ref_k,
        "rho_crit_kg_per_m3": f.rho_crit_kg_per_m3,
        "ln_psat": f.ln_psat,
        "rho_l": f.rho_l,
        "cp_l": f.cp_l,
        "h_fg": f.h_fg,
        "k_l": f.k_l,
        "ln_mu_l": f.ln_mu_l,
        "ln_rho_v": f.ln_rho_v,
        "dh_l_sat": f.dh_l_sat,
        "vapor_virial": f.vapor_virial,
        "vapor_ideal": f.vapor_ideal,
    })
}

/// The constants the lumped right-hand side reads, from the engine itself.
fn constants(c: &Campaign) -> serde_json::Value {
    let p = &c.params;
    let h = &HELIUM;
    serde_json::json!({
        "campaign": c.name,
        "fluid": p.fluid.name(),
        "fidelity": p.fidelity.name(),
        "fluid_props": props_json(p.fluid.props()),
        "vapor_energy_offset_j_per_kg": vapor_energy_offset(p.fluid),
        "helium": {
            "molar_mass_kg_per_mol": h.molar_mass_kg_per_mol,
            "cp_j_per_kg_k": h.cp_j_per_kg_k,
            "cv_j_per_kg_k": h.cv_j_per_kg_k,
            "k_ref_w_per_m_k": h.k_ref_w_per_m_k,
            "k_exp": h.k_exp,
            "mu_ref_pa_s": h.mu_ref_pa_s,
            "mu_exp": h.mu_exp,
            "t_ref_k": h.t_ref_k,
        },
        "r_universal": R_UNIVERSAL,
        "min_wall_share": MIN_WALL_SHARE,
        "min_axial_accel": slosh::MIN_AXIAL_ACCEL,
        "min_depth_ratio": slosh::MIN_DEPTH_RATIO,
        "min_surface_radius_ratio": slosh::MIN_SURFACE_RADIUS_RATIO,
        "xi": slosh::XI,
        "bulk_merge_fraction": model::BULK_MERGE_FRACTION,
        "stiff_blend_order": model::thermal::STIFF_BLEND_ORDER,
        "g0": model::flight::G0,
        "p_sea_level_pa": model::flight::P_SEA_LEVEL_PA,
        "rho_sea_level": model::flight::RHO_SEA_LEVEL,
        "scale_height_m": model::flight::SCALE_HEIGHT_M,
        "earth_radius_m": model::flight::EARTH_RADIUS_M,
        "slosh_table": {
            "log2k_0": slosh_table::LOG2K_0,
            "log2k_step": slosh_table::LOG2K_STEP,
            "nk": slosh_table::NK,
            "n_sigma": slosh_table::N_SIGMA,
            "n_barrel": slosh_table::N_BARREL,
            "barrel_h_max": slosh_table::BARREL_H_MAX,
            "n_top": slosh_table::N_TOP,
            "top_u_max": slosh_table::TOP_U_MAX,
            "n_beta": slosh_table::N_BETA,
            "bottom": slosh_table::BOTTOM.to_vec(),
            "barrel": slosh_table::BARREL.to_vec(),
            "top": slosh_table::TOP.to_vec(),
        },
    })
}

fn write(path: &str, c: &Campaign, rows: &[Row]) -> anyhow::Result<()> {
    let mut names: Vec<String> = Vec::new();
    let mut cols: Vec<Vec<f64>> = Vec::new();
    for (i, r) in rows.iter().enumerate() {
        let mut v: Vec<(String, f64)> = param_columns(&r.params)
            .into_iter()
            .map(|(n, x)| (format!("p_{n}"), x))
            .collect();
        v.extend(
            drive_columns(&r.drive, r.dt)
                .into_iter()
                .map(|(n, x)| (n.to_string(), x)),
        );
        let ev = model::evaluate(Group::one(&r.params), &r.state, &r.drive, r.dt);
        v.extend((0..NS).map(|k| (format!("s_{k}"), r.state[k])));
        v.extend((0..NS).map(|k| (format!("r_{k}"), ev.rates[k])));
        if i == 0 {
            names = v.iter().map(|(n, _)| n.clone()).collect();
            cols = vec![Vec::with_capacity(rows.len()); v.len()];
        }
        for (col, (_, x)) in cols.iter_mut().zip(v) {
            col.push(x);
        }
    }
    let schema = Arc::new(Schema::new(
        names
            .iter()
            .map(|n| Field::new(n, DataType::Float64, false))
            .collect::<Vec<_>>(),
    ));
    let arrays: Vec<ArrayRef> = cols
        .into_iter()
        .map(|c| Arc::new(Float64Array::from(c)) as ArrayRef)
        .collect();
    let batch = RecordBatch::try_new(Arc::clone(&schema), arrays)?;
    let props = WriterProperties::builder()
        .set_key_value_metadata(Some(vec![KeyValue::new(
            "cryoslosh_constants".to_string(),
            constants(c).to_string(),
        )]))
        .build();
    let mut w = ArrowWriter::try_new(std::fs::File::create(path)?, schema, Some(props))?;
    w.write(&batch)?;
    w.close()?;
    Ok(())
}

/// The rows as `WIDTH`-lane groups (the last one padded with its last row, whose copies are
/// evaluated but not counted).
struct LaneGroup {
    /// Rows of the file in this group (`WIDTH` but in the last group).
    rows: usize,
    params: Vec<Params>,
    state: State<Lanes>,
    drive: Drive<Lanes>,
    dt: Lanes,
}

fn lane_groups(rows: &[Row]) -> Vec<LaneGroup> {
    rows.chunks(WIDTH)
        .map(|ch| {
            let at = |i: usize| &ch[i.min(ch.len() - 1)];
            LaneGroup {
                rows: ch.len(),
                params: (0..WIDTH).map(|i| at(i).params).collect(),
                state: std::array::from_fn(|k| Lanes::from_fn(|i| at(i).state[k])),
                drive: Drive::gather(|i| at(i).drive),
                dt: Lanes::from_fn(|i| at(i).dt),
            }
        })
        .collect()
}

/// Evaluations per second of the lane groups on `threads` threads over about `seconds`.
///
/// Each worker sweeps its own contiguous share of the groups again and again until the time is
/// up, evaluating into its own evaluation in place as the engine's RK4 loop does
/// (`model::evaluate_into`). No barrier per sweep: one sweep of 1000 rows lasts a fraction of a
/// millisecond, and building and returning a new evaluation per call (kilobytes for a lane
/// group) was 6 % of the time measured (`memmove` and `memset` in `perf`).
fn time(groups: &[LaneGroup], threads: usize, seconds: f64) -> f64 {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let shares: Vec<&[LaneGroup]> = (0..threads)
        .map(|t| &groups[t * groups.len() / threads..(t + 1) * groups.len() / threads])
        .filter(|share| !share.is_empty())
        .collect();
    let worker = |share: &[LaneGroup], deadline: Instant| -> (u64, f64) {
        let first = &share[0];
        let mut ev = model::evaluate(
            Group::of(&first.params),
            &first.state,
            &first.drive,
            first.dt,
        );
        let (mut evaluations, mut sink) = (0u64, 0.0);
        while Instant::now() < deadline {
            for gr in share {
                model::evaluate_into(Group::of(&gr.params), &gr.state, &gr.drive, gr.dt, &mut ev);
                sink += ev.rates[0].lane(0);
            }
            // The rows' evaluations: a padded group's copies of its last row are not work
            // any peer does (until 2026-12-06 they were counted, +0.8 % at 1000 rows).
            evaluations += share.iter().map(|g| g.rows as u64).sum::<u64>();
        }
        (evaluations, sink)
    };
    pool.install(|| {
        let run = |secs: f64| {
            let start = Instant::now();
            let deadline = start + std::time::Duration::from_secs_f64(secs);
            let (n, sink) = shares
                .par_iter()
                .map(|share| worker(share, deadline))
                .reduce(|| (0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
            std::hint::black_box(sink);
            n as f64 / start.elapsed().as_secs_f64()
        };
        run(0.1); // warm-up
        run(seconds)
    })
}

const USAGE: &str = "usage: rhs_states CAMPAIGN (--out FILE | --time) [--rows N] [--instances N] \
                     [--seed N] [--seconds S] [--initial] [--set KEY=VALUE]...";

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "--help" || a == "-h") {
        println!("{USAGE}");
        return Ok(());
    }
    // Every flag known and every value present: an unknown flag (a `--set` this example did not
    // take) used to be ignored and the file written for the campaign as it stands.
    let mut i = 1;
    let (mut values, mut sets) = (Vec::new(), Vec::new());
    while i < args.len() {
        match args[i].as_str() {
            "--time" | "--initial" => i += 1,
            "--out" | "--rows" | "--instances" | "--seed" | "--seconds" | "--set" => {
                let v = args
                    .get(i + 1)
                    .ok_or_else(|| anyhow::anyhow!("{} needs a value; {USAGE}", args[i]))?;
                if args[i] == "--set" {
                    sets.push(v.clone());
                } else {
                    values.push((args[i].clone(), v.clone()));
                }
                i += 2;
            }
            other => anyhow::bail!("unknown argument {other:?}; {USAGE}"),
        }
    }
    let flag = |name: &str| {
        values
            .iter()
            .rev()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.clone())
    };
    let number = |name: &str, default: f64, lo: f64| -> anyhow::Result<f64> {
        let v = flag(name).map_or(Ok(default), |v| {
            v.parse::<f64>()
                .map_err(|e| anyhow::anyhow!("{name} {v:?}: {e}"))
        })?;
        anyhow::ensure!(
            v.is_finite() && v >= lo,
            "{name} {v}: expected at least {lo}"
        );
        Ok(v)
    };
    let campaign = args
        .first()
        .filter(|a| !a.starts_with("--"))
        .ok_or_else(|| anyhow::anyhow!("{USAGE}"))?;
    anyhow::ensure!(
        flag("--out").is_some() || args.iter().any(|a| a == "--time"),
        "nothing to do; {USAGE}"
    );
    let rows = number("--rows", 1000.0, 1.0)? as usize;
    let instances = number("--instances", 32.0, 1.0)? as u64;
    let seed = number("--seed", 18.0, 0.0)? as u64;
    let seconds = number("--seconds", 2.0, 0.01)?;
    let c = Campaign::load(std::path::Path::new(campaign), &sets)?;
    anyhow::ensure!(
        c.params.fidelity == Fidelity::Lumped,
        "the peers port the lumped level; {} is {}",
        c.name,
        c.params.fidelity.name()
    );
    let sampled = if args.iter().any(|a| a == "--initial") {
        initial_rows(&c, instances)
    } else {
        sample_rows(&c, instances, rows, seed)
    };
    if let Some(out) = flag("--out") {
        write(&out, &c, &sampled)?;
        println!("{} rows of {} -> {out}", sampled.len(), c.name);
    }
    if args.iter().any(|a| a == "--time") {
        let groups = lane_groups(&sampled);
        for threads in [1, 2] {
            let rate = time(&groups, threads, seconds);
            println!("cryoslosh_lanes threads={threads} evals_per_s={rate:.1}");
        }
    }
    Ok(())
}
