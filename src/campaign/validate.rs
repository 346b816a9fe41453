//! Raw campaign → validated [`Campaign`]: ranges checked, defaults resolved, key paths kept for
//! error messages. Nothing downstream re-validates.

use super::raw::*;
use super::{Campaign, CampaignError, Integrator, Stepping, DEFAULT_ATOL, DEFAULT_RTOL};
use crate::fluids::Fluid;
use crate::geometry::{Shape, Tank};
use crate::model::params::*;
use std::path::Path;

mod composition;
mod insulation;
mod mixer;
mod phases;
mod systems;
mod tvs;

use phases::{phase, phase_names};

/// Smallest tank radius accepted, m: below it the wall area and the slosh parameters lose
/// their meaning (a 1e-300 m tank passed `check` with a NaN wall).
pub const MIN_RADIUS_M: f64 = 1.0e-3;
/// Smallest fixed step accepted, s.
pub const MIN_DT_S: f64 = 1.0e-6;
/// Most fixed steps one phase may ask for: a campaign that needs more says so at `check`
/// instead of running for days (`phases.N.dt_s = 1e-300` ran forever).
pub const MAX_STEPS_PER_PHASE: f64 = 1.0e8;

/// Checks values against allowed ranges, naming the file and key on failure.
pub(super) struct Checker<'a> {
    pub file: &'a Path,
}

impl Checker<'_> {
    fn err(&self, key: &str, value: impl ToString, allowed: impl ToString) -> CampaignError {
        CampaignError::Invalid {
            file: self.file.to_path_buf(),
            key: key.to_string(),
            value: value.to_string(),
            allowed: allowed.to_string(),
        }
    }

    /// A finite value in [lo, hi].
    fn range(&self, key: &str, v: f64, lo: f64, hi: f64) -> Result<f64, CampaignError> {
        if v.is_finite() && v >= lo && v <= hi {
            Ok(v)
        } else {
            Err(self.err(
                key,
                number(v),
                format!("a finite number in [{}, {}]", number(lo), number(hi)),
            ))
        }
    }

    /// A finite value in (lo, hi].
    fn positive(&self, key: &str, v: f64, hi: f64) -> Result<f64, CampaignError> {
        if v.is_finite() && v > 0.0 && v <= hi {
            Ok(v)
        } else {
            Err(self.err(
                key,
                number(v),
                format!("a finite number in (0, {}]", number(hi)),
            ))
        }
    }

    fn opt_range(
        &self,
        key: &str,
        v: Option<f64>,
        default: f64,
        lo: f64,
        hi: f64,
    ) -> Result<f64, CampaignError> {
        self.range(key, v.unwrap_or(default), lo, hi)
    }

    fn opt_positive(
        &self,
        key: &str,
        v: Option<f64>,
        hi: f64,
    ) -> Result<Option<f64>, CampaignError> {
        v.map(|x| self.positive(key, x, hi)).transpose()
    }

    fn required(&self, key: &str, v: Option<f64>) -> Result<f64, CampaignError> {
        v.ok_or_else(|| self.err(key, "(missing)", "a value: this excitation kind needs it"))
    }
}

/// A number as a person reads it: plain in [1e-4, 1e6), else in exponent form (1e300 would
/// otherwise print as 301 digits).
fn number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1.0e-4..1.0e6).contains(&v.abs()) {
        v.to_string()
    } else {
        format!("{v:e}")
    }
}

/// Validate a parsed campaign read from `file` (its directory resolves excitation tables).
pub fn validate(raw: &RawCampaign, file: &Path, text: String) -> Result<Campaign, CampaignError> {
    let c = Checker { file };
    let run = &raw.campaign;
    let fidelity = match run.fidelity.as_deref().unwrap_or("lumped") {
        "homogeneous" => Fidelity::Homogeneous,
        "lumped" => Fidelity::Lumped,
        "two_mode" => Fidelity::TwoMode,
        "layered" => Fidelity::Layered,
        other => {
            return Err(c.err(
                "campaign.fidelity",
                other,
                "homogeneous | lumped | two_mode | layered",
            ))
        }
    };
    let layered = layered(&c, raw.layered.as_ref(), fidelity)?;
    let dt_default = c.opt_range("campaign.dt_s", run.dt_s, 0.1, 1.0e-5, 3600.0)?;
    let stepping = stepping(&c, run)?;
    let output_interval_s = c.opt_range(
        "campaign.output_interval_s",
        run.output_interval_s,
        1.0,
        1.0e-4,
        1.0e6,
    )?;

    // Tank.
    let t = &raw.tank;
    let shape = Shape::from_name(&t.shape)
        .ok_or_else(|| c.err("tank.shape", &t.shape, "cylinder | capsule | sphere"))?;
    let radius = c.range("tank.radius_m", t.radius_m, MIN_RADIUS_M, 50.0)?;
    let length = match shape {
        Shape::Cylinder => c.positive(
            "tank.cylinder_length_m",
            t.cylinder_length_m.unwrap_or(f64::NAN),
            500.0,
        )?,
        Shape::Capsule => c.opt_range(
            "tank.cylinder_length_m",
            t.cylinder_length_m,
            0.0,
            0.0,
            500.0,
        )?,
        Shape::Sphere => 0.0,
    };
    let dome = match shape {
        Shape::Capsule => {
            c.opt_range("tank.dome_ratio", t.dome_ratio, 1.0 / 2f64.sqrt(), 0.1, 3.0)?
        }
        _ => 1.0,
    };
    let tank = Tank::new(shape, radius, length, dome);
    let insulation = insulation::insulation(&c, raw.insulation.as_ref())?;
    // With [insulation] the stack computes the leak and a fixed one would be ignored without a
    // word (a variant adding the section drops the campaign's key, `Campaign::variant`);
    // without it the key is required.
    let heat_leak_w = match (t.heat_leak_w, &insulation) {
        (Some(q), Some(_)) => {
            return Err(c.err(
                "tank.heat_leak_w",
                number(q),
                "no fixed heat leak with an [insulation] section (the stack and each phase's \
                 environment compute it; remove the key)",
            ))
        }
        (Some(q), None) => c.range("tank.heat_leak_w", q, 0.0, 1.0e7)?,
        (None, Some(_)) => 0.0,
        (None, None) => {
            return Err(c.err(
                "tank.heat_leak_w",
                "(missing)",
                "a heat leak in [0, 1e7] W, or an [insulation] section",
            ))
        }
    };
    let wall_mass = c.opt_range(
        "tank.wall_areal_mass_kg_per_m2",
        t.wall_areal_mass_kg_per_m2,
        5.0,
        0.01,
        1000.0,
    )?;
    let meop_pa = c.positive("tank.meop_pa", t.meop_pa, 1.0e8)?;

    // Propellant and initial state.
    let pr = &raw.propellant;
    let fluid = Fluid::from_name(&pr.fluid).ok_or_else(|| {
        c.err(
            "propellant.fluid",
            &pr.fluid,
            "LH2 | nLH2 | LOX | LCH4 | LN2",
        )
    })?;
    let f = fluid.props();
    let fill = c.range("propellant.fill_fraction", pr.fill_fraction, 0.02, 0.98)?;
    let (p_lo, p_hi) = (f.psat_pa(f.t_min_k), f.psat_pa(f.t_max_k));
    let p0 = c.range(
        "ullage.pressure_pa",
        raw.ullage.pressure_pa,
        p_lo,
        0.95 * f.p_crit_pa,
    )?;
    let t_sat = f.tsat_k(p0.min(p_hi));
    let t_liquid = match (pr.temperature_k, pr.subcooling_k) {
        (Some(_), Some(_)) => {
            return Err(c.err(
                "propellant.subcooling_k",
                "set with temperature_k",
                "either temperature_k or subcooling_k, not both",
            ))
        }
        (Some(tk), None) => c.range("propellant.temperature_k", tk, f.t_min_k, t_sat)?,
        (None, Some(sc)) => {
            t_sat - c.range("propellant.subcooling_k", sc, 0.0, t_sat - f.t_min_k)?
        }
        (None, None) => {
            if p0 > p_hi {
                return Err(c.err("ullage.pressure_pa", p0, format!("at most {p_hi:.0} Pa for saturated {} (set propellant.temperature_k for a pressurized tank)", fluid.name())));
            }
            t_sat
        }
    };
    let t_ullage = c.opt_range(
        "ullage.temperature_k",
        raw.ullage.temperature_k,
        t_liquid,
        t_liquid,
        400.0,
    )?;
    let composition = composition::composition(
        &c,
        fluid,
        &raw.ullage,
        &raw.stratification,
        (p0, t_liquid, t_ullage),
    )?;
    let wall_cp = c.opt_range(
        "tank.wall_cp_j_per_kg_k",
        t.wall_cp_j_per_kg_k,
        aluminium_cp(t_liquid),
        0.1,
        5000.0,
    )?;
    // A pressurized tank's dry wall is warmer than its liquid; starting it at the liquid
    // temperature under warm vapour above T_sat(P_v) leaves the vapour supersaturated, since no
    // condensation on the dry wall is modelled (docs/PHYSICS.md 2.3). The wall's c_w is one
    // constant: with the default aluminium one (at the liquid temperature) the dry wall may start
    // only as warm as that constant still stores 2/3 of aluminium's heat (a 400 K dry wall over
    // LH2 held 1/70 of it and fell to 36 K within 5 s).
    let dry_wall_max_k = if t.wall_cp_j_per_kg_k.is_some() {
        400.0
    } else {
        warm_wall_limit_k(t_liquid)
    };
    let t_dry_wall = c
        .opt_range(
            "tank.dry_wall_temperature_k",
            t.dry_wall_temperature_k,
            t_liquid,
            t_liquid,
            dry_wall_max_k,
        )
        .map_err(|e| match e {
            CampaignError::Invalid {
                file,
                key,
                value,
                allowed,
            } if t.dry_wall_temperature_k.is_some_and(|v| v > dry_wall_max_k) => {
                CampaignError::Invalid {
                    file,
                    key,
                    value,
                    allowed: format!(
                        "{allowed}: the wall's c_w stays at aluminium's {} J/(kg·K) of the liquid \
                     temperature, which above {} K stores less than 2/3 of a warm wall's heat; \
                     give tank.wall_cp_j_per_kg_k for the warm wall to start it warmer",
                        (wall_cp * 10.0).round() / 10.0,
                        (dry_wall_max_k * 10.0).floor() / 10.0
                    ),
                }
            }
            e => e,
        })?;

    // Heat transfer, stratification, slosh.
    let h = &raw.heat_transfer;
    let heat_transfer = HeatTransfer {
        evaporation_coefficient_kg_per_s_pa: c.opt_positive(
            "heat_transfer.evaporation_coefficient_kg_per_s_pa",
            h.evaporation_coefficient_kg_per_s_pa,
            1.0e3,
        )?,
        accommodation: c.opt_range(
            "heat_transfer.accommodation_coefficient",
            h.accommodation_coefficient,
            0.1,
            1.0e-6,
            1.0,
        )?,
        h_us_w_per_m2_k: c.opt_positive(
            "heat_transfer.h_ullage_interface_w_per_m2_k",
            h.h_ullage_interface_w_per_m2_k,
            1.0e5,
        )?,
        h_sb_w_per_m2_k: h
            .h_layer_bulk_w_per_m2_k
            .map(|v| c.range("heat_transfer.h_layer_bulk_w_per_m2_k", v, 0.0, 1.0e5))
            .transpose()?,
        h_wall_ullage_w_per_m2_k: c.opt_positive(
            "heat_transfer.h_wall_ullage_w_per_m2_k",
            h.h_wall_ullage_w_per_m2_k,
            1.0e5,
        )?,
        h_wall_liquid_w_per_m2_k: c.opt_positive(
            "heat_transfer.h_wall_liquid_w_per_m2_k",
            h.h_wall_liquid_w_per_m2_k,
            1.0e5,
        )?,
    };
    let st = &raw.stratification;
    let stratification = Stratification {
        initial_thickness_m: c.opt_range(
            "stratification.initial_thickness_m",
            st.initial_thickness_m,
            DEFAULT_LAYER_M,
            1.0e-5,
            10.0,
        )?,
        diffusivity_factor: c.opt_range(
            "stratification.diffusivity_factor",
            st.diffusivity_factor,
            1.0,
            0.0,
            1.0e4,
        )?,
        wall_heat_to_layer: c.opt_range(
            "stratification.wall_heat_to_layer",
            st.wall_heat_to_layer,
            DEFAULT_WALL_HEAT_TO_LAYER,
            0.0,
            1.0,
        )?,
        initial_temperature_k: composition.layer_temperature_k,
    };
    let sl = &raw.slosh;
    let baffle_count = sl.baffle_count.unwrap_or(0);
    if baffle_count > 1000 {
        return Err(c.err(
            "slosh.baffle_count",
            baffle_count,
            "an integer in [0, 1000]",
        ));
    }
    let baffles = Baffles {
        count: baffle_count,
        width_m: c.opt_range("slosh.baffle_width_m", sl.baffle_width_m, 0.0, 0.0, radius)?,
        spacing_m: c.opt_range(
            "slosh.baffle_spacing_m",
            sl.baffle_spacing_m,
            0.0,
            0.0,
            tank.height_m(),
        )?,
        top_height_m: c.opt_range(
            "slosh.baffle_top_height_m",
            sl.baffle_top_height_m,
            0.0,
            0.0,
            tank.height_m(),
        )?,
        wave_amplitude_m: c.opt_range(
            "slosh.wave_amplitude_m",
            sl.wave_amplitude_m,
            0.1 * radius,
            0.0,
            radius,
        )?,
    };
    if baffle_count > 0 && baffles.width_m <= 0.0 {
        return Err(c.err(
            "slosh.baffle_width_m",
            baffles.width_m,
            format!("(0, {radius}] when slosh.baffle_count > 0"),
        ));
    }
    let coupling = Coupling {
        volume_m3: c.opt_range(
            "slosh.volume_coupling_m3",
            sl.volume_coupling_m3,
            0.0,
            0.0,
            0.5 * (1.0 - fill) * tank.volume_m3(),
        )?,
        h_enhancement_w_per_m2_k_s: c.opt_range(
            "slosh.heat_transfer_enhancement_w_per_m2_k_s",
            sl.heat_transfer_enhancement_w_per_m2_k_s,
            100.0,
            0.0,
            1.0e6,
        )?,
        mixing: c.opt_range(
            "slosh.mixing_coefficient",
            sl.mixing_coefficient,
            0.05,
            0.0,
            100.0,
        )?,
    };
    let extra_damping = c.opt_range(
        "slosh.extra_damping_ratio",
        sl.extra_damping_ratio,
        0.0,
        0.0,
        2.0,
    )?;
    let initial_angle_rad = c.opt_range(
        "slosh.initial_angle_rad",
        sl.initial_angle_rad,
        0.0,
        -1.5,
        1.5,
    )?;

    // Pressurization, relief, engine, feed, vehicle.
    let pressurization = systems::pressurization(&c, raw, fluid, tank.volume_m3(), fill)?;
    let relief = systems::relief(&c, raw, meop_pa)?;
    let mixer_runs = raw.phases.iter().any(|ph| ph.mixer.unwrap_or(true));
    let mixer = mixer::mixer(
        &c,
        raw.mixer.as_ref(),
        fluid,
        (t_liquid, tank.radius_m()),
        mixer_runs,
    )?;
    let tvs = tvs::tvs(&c, raw, fluid, (t_liquid, meop_pa), relief.as_ref())?;
    let feed = systems::feed(&c, raw)?;
    let vehicle = systems::vehicle(&c, raw)?;

    if raw.phases.is_empty() {
        return Err(c.err("phases", "[]", "at least one [[phases]] entry"));
    }
    let dir = file.parent().unwrap_or_else(|| Path::new("."));
    let phases = raw
        .phases
        .iter()
        .enumerate()
        .map(|(i, ph)| phase(&c, i, ph, dt_default, stepping.max_step_s, dir))
        .collect::<Result<Vec<_>, _>>()?;
    phase_names(&c, &phases)?;
    let m_liquid0_kg = fill * tank.volume_m3() * fluid.props().rho_l_kg_per_m3(t_liquid);
    systems::other_propellants(&c, (&feed, &vehicle), &phases, m_liquid0_kg)?;
    mixer::phases(
        &c,
        mixer.as_ref(),
        &raw.phases,
        &phases,
        stepping.integrator,
        fidelity,
        2.0 * tank.radius_m(),
    )?;
    tvs::phases(
        &c,
        (tvs.as_ref(), pressurization.as_ref()),
        &raw.phases,
        &phases,
        (stepping.integrator, fidelity),
        fill * tank.volume_m3(),
    )?;
    // A phase's environment selects the insulation's outer boundary; without a stack the fixed
    // tank.heat_leak_w applies in every phase, and the key would be ignored without a word.
    if insulation.is_none() {
        if let Some(i) = raw.phases.iter().position(|ph| ph.environment.is_some()) {
            return Err(c.err(
                &format!("phases.{i}.environment"),
                raw.phases[i].environment.as_deref().unwrap_or_default(),
                "no environment without an [insulation] section (the fixed tank.heat_leak_w \
                 applies in every phase)",
            ));
        }
    }

    let params = Params {
        fidelity,
        fluid,
        tank,
        heat_leak_w,
        insulation,
        wall_areal_mass_kg_per_m2: wall_mass,
        wall_cp_j_per_kg_k: wall_cp,
        dry_wall_temperature_k: t_dry_wall,
        meop_pa,
        fill_fraction: fill,
        liquid_temperature_k: t_liquid,
        ullage_pressure_pa: p0,
        ullage_helium_partial_pressure_pa: composition.helium_partial_pressure_pa,
        ullage_temperature_k: t_ullage,
        heat_transfer,
        stratification,
        coupling,
        layered,
        baffles,
        extra_damping,
        pressurization,
        relief,
        mixer,
        tvs,
        feed,
        vehicle,
    };
    Ok(Campaign {
        path: file.to_path_buf(),
        text,
        name: run.name.clone().unwrap_or_else(|| {
            file.file_stem()
                .map_or_else(|| "campaign".into(), |s| s.to_string_lossy().into_owned())
        }),
        params,
        phases,
        output_interval_s,
        stepping,
        instances: match run.instances.unwrap_or(1000) {
            n @ 1..=1_000_000_000_000 => n,
            n => return Err(c.err("campaign.instances", n, "an integer in [1, 1e12]")),
        },
        seed: run.seed.unwrap_or(0),
        initial_slosh_angle_rad: initial_angle_rad,
        dispersions: super::dispersion::Dispersions::default(),
        statistics: super::statistics::StatisticsPlan::default(),
        document: toml::Table::new(),
        record_events: false,
        variants: Vec::new(),
    })
}

/// Default initial layer thickness, m: a millimetre-scale surface film at lock-up.
pub const DEFAULT_LAYER_M: f64 = 1.0e-3;
/// Default share of the bulk's wall heat lifted into the surface layer: 0, the paper's
/// contact-area model (see `model::params::Stratification::wall_heat_to_layer`).
pub const DEFAULT_WALL_HEAT_TO_LAYER: f64 = 0.0;

/// Specific heat of aluminium alloy 6061 at temperature `t`, J/(kg·K): log-linear interpolation
/// of NIST cryogenic material data (rounded), the default wall material.
fn aluminium_cp(t: f64) -> f64 {
    const T: [f64; 7] = [10.0, 20.0, 40.0, 77.0, 100.0, 150.0, 300.0];
    const CP: [f64; 7] = [0.9, 8.9, 77.0, 336.0, 480.0, 683.0, 897.0];
    let t = t.clamp(T[0], T[6]);
    let i = T.partition_point(|&x| x <= t).clamp(1, 6);
    let w = (t.ln() - T[i - 1].ln()) / (T[i].ln() - T[i - 1].ln());
    (CP[i - 1].ln() * (1.0 - w) + CP[i].ln() * w).exp()
}

/// Highest initial dry-wall temperature, K (at most 400), at which the default wall c_w, aluminium
/// 6061's at the liquid temperature `t_liquid_k`, still stores at least 2/3 of the heat
/// ∫ c_al dT that aluminium holds between the two (trapezoids of 0.05 K over [`aluminium_cp`]).
/// Rounded down to 0.1 K: 26.1 K over LH2 at 20.6 K, 142.2 K over LN2 at 78 K, 240 K over LOX
/// at 96.8 K.
fn warm_wall_limit_k(t_liquid_k: f64) -> f64 {
    let c0 = aluminium_cp(t_liquid_k);
    let step = 0.05;
    let (mut t, mut heat) = (t_liquid_k, 0.0);
    while t < 400.0 {
        let next = (t + step).min(400.0);
        heat += 0.5 * (aluminium_cp(t) + aluminium_cp(next)) * (next - t);
        if c0 * (next - t_liquid_k) < heat * (2.0 / 3.0) {
            return ((t * 10.0).floor() / 10.0).max(t_liquid_k);
        }
        t = next;
    }
    400.0
}

/// The `[campaign]` integrator settings.
fn stepping(c: &Checker, run: &RawRun) -> Result<Stepping, CampaignError> {
    let integrator = match run.integrator.as_deref().unwrap_or("rk4") {
        "dopri5" => Integrator::Dopri5,
        "rk4" => Integrator::Rk4,
        other => return Err(c.err("campaign.integrator", other, "dopri5 | rk4")),
    };
    Ok(Stepping {
        integrator,
        rtol: c.opt_range("campaign.rtol", run.rtol, DEFAULT_RTOL, 1.0e-12, 1.0e-3)?,
        // atol is a fraction of each slot's scale (the whole fluid mass for the vapour slot):
        // above 1e-6 it lets the vapour mass go unchecked.
        atol: c.opt_range("campaign.atol", run.atol, DEFAULT_ATOL, 1.0e-15, 1.0e-6)?,
        max_step_s: run
            .max_step_s
            .map(|v| c.range("campaign.max_step_s", v, 1.0e-5, 1.0e6))
            .transpose()?
            .unwrap_or(f64::INFINITY),
        allow_coarse_step: run.allow_coarse_step.unwrap_or(false),
    })
}

impl Checker<'_> {
    /// Error for a table file (used by `table.rs`).
    pub(super) fn table_err(
        &self,
        key: &str,
        value: impl ToString,
        allowed: impl ToString,
    ) -> CampaignError {
        self.err(key, value, allowed)
    }
}

/// `[layered]`: the column's layer count and stretch (`model::column`); the section is refused at
/// the other levels, where it would be ignored without a word.
fn layered(
    c: &Checker<'_>,
    raw: Option<&super::raw::RawLayered>,
    fidelity: Fidelity,
) -> Result<Layered, CampaignError> {
    if raw.is_some() && fidelity != Fidelity::Layered {
        return Err(c.err(
            "layered",
            "a [layered] section",
            format!(
                "only with campaign.fidelity = \"layered\" (this campaign's is {})",
                fidelity.name()
            ),
        ));
    }
    let raw = raw.cloned().unwrap_or_default();
    let layers = raw.layers.unwrap_or(crate::model::column::DEFAULT_LAYERS);
    let most = crate::model::state::NL_MAX as u32;
    if !(1..=most).contains(&layers) {
        return Err(c.err(
            "layered.layers",
            layers,
            format!("an integer in [1, {most}]"),
        ));
    }
    let stretch = c.opt_range(
        "layered.stretch",
        raw.stretch,
        crate::model::column::DEFAULT_STRETCH,
        1.0,
        2.0,
    )?;
    let most_stretch = crate::model::column::max_stretch(layers, 2.0);
    if stretch > most_stretch {
        return Err(c.err(
            "layered.stretch",
            stretch,
            format!(
                "at most {:.4} with {layers} layers (the top layer's share of the column, \
                 (s − 1)/(s^n − 1), at least {:e}: thinner layers resolve nothing the film does \
                 not, and outrun fixed steps)",
                (most_stretch * 1.0e4).floor() / 1.0e4,
                crate::model::column::MIN_TOP_LAYER_SHARE
            ),
        ));
    }
    let detrain_width_k = c.opt_range(
        "layered.detrain_width_k",
        raw.detrain_width_k,
        crate::model::column::DETRAIN_WIDTH_K,
        1.0e-6,
        1.0,
    )?;
    Ok(Layered {
        layers,
        stretch,
        detrain_width_k,
    })
}
