//! Human-readable resolved nominal of a campaign (`cryoslosh check`).
//!
//! Each section is one line of `key value unit` pairs under the campaign's own key names (so a
//! key can be copied into `--set section.key=…`), with every default shown as the value used;
//! derived quantities follow on indented lines. Numbers go through [`number`].

use super::Campaign;
use crate::geometry::Shape;
use crate::model::derive::{derive, Drive};
use crate::model::flight::Excitation;
use crate::model::params::{Fidelity, GainSchedule};
use crate::model::state::initial_state;
use crate::model::thermal::schrage_coefficient;
use std::fmt::Write;

/// A number as a person reads it: 6 significant digits with trailing zeros trimmed, integers
/// without a decimal point, exponent form below 1e-3 or from 1e7 up in magnitude (`2e-6`,
/// `1.5e8`), and `inf`, `-inf`, `nan` spelled so.
pub fn number(v: f64) -> String {
    if v.is_nan() {
        return "nan".into();
    }
    if v.is_infinite() {
        return if v > 0.0 { "inf" } else { "-inf" }.into();
    }
    if v == 0.0 {
        return "0".into();
    }
    // Round to 6 significant digits first, then let the shortest round-trip form drop the zeros.
    let rounded: f64 = format!("{v:.5e}").parse().unwrap_or(v);
    if (1.0e-3..1.0e7).contains(&rounded.abs()) {
        format!("{rounded}")
    } else {
        format!("{rounded:e}")
    }
}

/// `key value unit` (no unit for dimensionless keys).
fn kv(key: &str, v: f64, unit: &str) -> String {
    if unit.is_empty() {
        format!("{key} {}", number(v))
    } else {
        format!("{key} {} {unit}", number(v))
    }
}

/// `pressurization.gain_schedule` and, when the gains follow the ullage, the reference ullage
/// (saying when it is the default, the initial ullage).
fn gain_schedule(c: &Campaign, g: GainSchedule) -> String {
    match g {
        GainSchedule::Fixed => "fixed (k_p, k_d as written)".to_string(),
        GainSchedule::UllageVolume { reference_m3 } => {
            let reference = kv("schedule_reference_ullage_m3", reference_m3, "m³");
            let default = if is_set(c, "pressurization", "schedule_reference_ullage_m3") {
                ""
            } else {
                " (the initial ullage)"
            };
            format!("ullage_volume (k_p, k_d times V_u / {reference}{default})")
        }
    }
}

/// Whether the campaign document sets `section.key` (else the value shown is the default).
fn is_set(c: &Campaign, section: &str, key: &str) -> bool {
    c.document.get(section).and_then(|s| s.get(key)).is_some()
}

/// `key value unit` of a `[tank]` key, followed by `(default)` where the campaign leaves it out.
fn tank_kv(c: &Campaign, (key, value, unit): (&str, f64, &str), default: &str) -> String {
    if is_set(c, "tank", key) {
        kv(key, value, unit)
    } else {
        format!("{} ({default})", kv(key, value, unit))
    }
}

/// The excitation of phase `i`: its `Display` form, with a table's file name from the document.
fn excitation(c: &Campaign, i: usize, e: &Excitation) -> String {
    let text = e.to_string();
    match (e, text.strip_prefix("table(")) {
        (Excitation::Table { .. }, Some(rest)) => {
            let file = c
                .document
                .get("phases")
                .and_then(|p| p.get(i))
                .and_then(|p| p.get("excitation"))
                .and_then(|x| x.get("file"))
                .and_then(toml::Value::as_str)
                .unwrap_or("?");
            format!("table({file}: {rest}")
        }
        _ => text,
    }
}

/// `[insulation]`: the stack, the surroundings, and the steady leak at the initial wall
/// temperature `t_wall_k` in either environment.
fn insulation_lines(p: &crate::model::params::Params, t_wall_k: f64) -> String {
    use crate::model::flight::Environment;
    let Some(ins) = p.insulation else {
        return String::new();
    };
    let mut layers = Vec::new();
    if let Some(f) = ins.foam {
        layers.push(kv("foam_thickness_m", f.thickness_m, "m"));
        layers.push(kv(
            "foam_conductivity_w_per_m_k",
            f.conductivity_w_per_m_k,
            "W/(m·K)",
        ));
    }
    if let Some(m) = ins.mli {
        layers.push(kv("mli_layers", m.layers, ""));
        layers.push(kv(
            "mli_layer_density_per_cm",
            m.layer_density_per_cm,
            "/cm",
        ));
        layers.push(kv(
            "mli_interstitial_pressure_torr",
            m.interstitial_pressure_torr,
            "torr",
        ));
        layers.push(kv("mli_shield_emissivity", m.shield_emissivity, ""));
        layers.push(kv("mli_degradation_factor", m.degradation_factor, ""));
    }
    let mut o = format!(
        "insulation: {}, {}, {}, {}, {}, {}, {}\n",
        layers.join(", "),
        kv(
            "ground_ambient_temperature_k",
            ins.ground_ambient_temperature_k,
            "K"
        ),
        kv(
            "ground_convection_w_per_m2_k",
            ins.ground_convection_w_per_m2_k,
            "W/(m²·K)"
        ),
        kv(
            "space_sink_temperature_k",
            ins.space_sink_temperature_k,
            "K"
        ),
        kv(
            "space_incident_flux_w_per_m2",
            ins.space_incident_flux_w_per_m2,
            "W/m²"
        ),
        kv("outer_emissivity", ins.outer_emissivity, ""),
        kv("outer_absorptivity", ins.outer_absorptivity, ""),
    );
    let area = p.tank.wall_area_m2();
    for env in [Environment::Ground, Environment::Space] {
        let leak = ins.leak(env, t_wall_k);
        o += &format!(
            "  derived ({}, wall at {} K): outer surface {} K, heat leak {} W/m² = {} W\n",
            env.name(),
            n4(t_wall_k),
            n4(leak.t_outer_k),
            number(leak.flux_w_per_m2),
            number(leak.flux_w_per_m2 * area),
        );
    }
    o
}

/// A temperature to 4 significant digits.
fn n4(v: f64) -> String {
    number(format!("{v:.3e}").parse().unwrap_or(v))
}

/// The resolved nominal: every input with its default filled in, plus the derived initial state.
pub fn describe(c: &Campaign) -> String {
    let p = &c.params;
    let f = p.fluid.props();
    let mut o = String::new();
    let s0 = initial_state(p);
    let x = derive(
        crate::model::Group::one(p),
        &s0,
        &Drive::of_phase(&c.phases[0], 0.0, Default::default()),
    );
    let n = number;
    let st = &c.stepping;
    let _ = writeln!(
        o,
        "campaign {} ({}), fidelity {}",
        c.name,
        c.path.display(),
        p.fidelity.name()
    );
    if p.fidelity == Fidelity::Layered {
        let l = &p.layered;
        let w = crate::model::column::fractions(l);
        let _ = writeln!(
            o,
            "  column: {} layers under the film, stretch {} (top layer {} %, bottom {} % of the \
             column's mass), detrainment width {} K",
            l.layers,
            n(l.stretch),
            n(100.0 * w[l.layers as usize - 1]),
            n(100.0 * w[0]),
            n(l.detrain_width_k)
        );
    }
    let mut run = vec![format!("integrator {}", st.integrator.name())];
    if st.integrator == super::Integrator::Dopri5 {
        run.push(kv("rtol", st.rtol, ""));
        run.push(kv("atol", st.atol, "× slot scale"));
        run.push(if st.max_step_s.is_finite() {
            kv("max_step_s", st.max_step_s, "s")
        } else {
            "max_step_s none".into()
        });
    }
    run.push(format!("allow_coarse_step {}", st.allow_coarse_step));
    run.push(kv("output_interval_s", c.output_interval_s, "s"));
    run.push(format!("instances {}", c.instances));
    run.push(format!("seed {}", c.seed));
    let _ = writeln!(o, "campaign: {}", run.join(", "));

    // [tank]
    let tank = &p.tank;
    let wall_cp = tank_kv(
        c,
        ("wall_cp_j_per_kg_k", p.wall_cp_j_per_kg_k, "J/(kg·K)"),
        "aluminium 6061 at the liquid temperature",
    );
    // Only the shape's own keys: a sphere has no cylinder, a cylinder no domes.
    let mut size = vec![kv("radius_m", tank.radius_m(), "m")];
    if tank.shape() != Shape::Sphere {
        size.push(kv("cylinder_length_m", tank.length_m(), "m"));
    }
    if tank.shape() == Shape::Capsule {
        size.push(kv("dome_ratio", tank.dome_ratio(), ""));
    }
    let leak = match p.insulation {
        Some(_) => "heat_leak_w from [insulation]".to_string(),
        None => kv("heat_leak_w", p.heat_leak_w, "W"),
    };
    let dry_wall = tank_kv(
        c,
        ("dry_wall_temperature_k", p.dry_wall_temperature_k, "K"),
        "the liquid temperature",
    );
    let _ = writeln!(
        o,
        "tank: shape {}, {}, {}, {}, {wall_cp}, {dry_wall}, {}",
        tank.shape().name(),
        size.join(", "),
        leak,
        kv(
            "wall_areal_mass_kg_per_m2",
            p.wall_areal_mass_kg_per_m2,
            "kg/m²"
        ),
        kv("meop_pa", p.meop_pa, "Pa"),
    );
    if p.insulation.is_none() {
        let _ = writeln!(
            o,
            "  derived: height {} m, volume {} m³, wall {} m² ({} kg, {} J/K); heat leak {} W = {} W/m² of wall",
            n(tank.height_m()),
            n(tank.volume_m3()),
            n(tank.wall_area_m2()),
            n(p.wall_mass_kg()),
            n(p.wall_heat_capacity_j_per_k()),
            n(p.heat_leak_w),
            n(p.heat_leak_w / tank.wall_area_m2()),
        );
    } else {
        let _ = writeln!(
            o,
            "  derived: height {} m, volume {} m³, wall {} m² ({} kg, {} J/K)",
            n(tank.height_m()),
            n(tank.volume_m3()),
            n(tank.wall_area_m2()),
            n(p.wall_mass_kg()),
            n(p.wall_heat_capacity_j_per_k()),
        );
        o += &insulation_lines(p, x.t_wall_wet_k);
    }

    // [propellant], [ullage]
    let t_sat = f.tsat_k(p.ullage_pressure_pa.min(f.psat_pa(f.t_max_k)));
    let _ = writeln!(
        o,
        "propellant: fluid {}, {}, {}, {}",
        p.fluid.name(),
        kv("fill_fraction", p.fill_fraction, ""),
        kv("temperature_k", p.liquid_temperature_k, "K"),
        kv("subcooling_k", t_sat - p.liquid_temperature_k, "K"),
    );
    let _ = writeln!(
        o,
        "  derived: T_sat {} K at the ullage pressure, liquid {} kg, level {} m, interface {} m²",
        n(t_sat),
        n(x.m_liquid_kg),
        n(x.level_m),
        n(x.interface_area_m2),
    );
    let _ = writeln!(
        o,
        "ullage: {}, {}, {}",
        kv("pressure_pa", p.ullage_pressure_pa, "Pa"),
        kv("temperature_k", p.ullage_temperature_k, "K"),
        kv(
            "helium_partial_pressure_pa",
            p.ullage_helium_partial_pressure_pa,
            "Pa"
        ),
    );
    // P_u − P_v, shown as 0 where it is rounding noise of the pressure (an ullage without helium
    // reads 0 exactly; the filter keeps any state whose sum rounds off a few ulps from showing it).
    let helium_pa = x.p_ullage_pa - x.p_vapor_pa;
    let helium_pa = if helium_pa.abs() < 1.0e-9 * x.p_ullage_pa {
        0.0
    } else {
        helium_pa
    };
    let _ = writeln!(
        o,
        "  derived: vapour {} Pa, helium {} Pa, volume {} m³",
        n(x.p_vapor_pa),
        n(helium_pa),
        n(x.v_ullage_m3),
    );

    // [heat_transfer]: constants, or the correlation that computes them as the state evolves.
    let ht = &p.heat_transfer;
    let interface_unused = p.fidelity == Fidelity::Homogeneous;
    let closure = |key: &str, unit: &str, v: Option<f64>, correlation: String| match v {
        Some(v) => kv(key, v, unit),
        None => format!("{key}: {correlation}"),
    };
    let mut lines = Vec::new();
    let evaporation = closure(
        "evaporation_coefficient_kg_per_s_pa",
        "kg/(s·Pa)",
        ht.evaporation_coefficient_kg_per_s_pa,
        format!(
            "from Schrage kinetic theory with accommodation_coefficient, initial ≈ {} kg/(s·Pa)",
            n(schrage_coefficient(
                x.interface_area_m2,
                ht.accommodation,
                f.molar_mass_kg_per_mol,
                x.t_layer_k
            ))
        ),
    );
    lines.push(format!(
        "{evaporation}; in series with gas-side diffusion through the helium"
    ));
    lines.push(kv("accommodation_coefficient", ht.accommodation, ""));
    lines.push(format!(
        "{} + slosh enhancement",
        closure(
            "h_ullage_interface_w_per_m2_k",
            "W/(m²·K)",
            ht.h_us_w_per_m2_k,
            "correlation (McAdams stable horizontal interface, Nu = 0.27 Ra^1/4 + 1)".into(),
        )
    ));
    lines.push(format!(
        "{} + Lloyd & Moran unstable-interface correlation while the layer is colder than the bulk + slosh enhancement",
        kv(
            "h_layer_bulk_w_per_m2_k",
            ht.h_sb_w_per_m2_k.unwrap_or(0.0),
            "W/(m²·K)"
        )
    ));
    if interface_unused {
        for l in &mut lines {
            l.push_str(" — unused at the homogeneous level");
        }
    }
    lines.push(closure(
        "h_wall_ullage_w_per_m2_k",
        "W/(m²·K)",
        ht.h_wall_ullage_w_per_m2_k,
        "correlation (Churchill–Chu vertical wall over the dry height)".into(),
    ));
    lines.push(closure(
        "h_wall_liquid_w_per_m2_k",
        "W/(m²·K)",
        ht.h_wall_liquid_w_per_m2_k,
        "correlation (Churchill–Chu vertical wall over the wetted height)".into(),
    ));
    let _ = writeln!(o, "heat_transfer:");
    for l in lines {
        let _ = writeln!(o, "  {l}");
    }

    // [stratification], [slosh]
    let s = &p.stratification;
    let _ = writeln!(
        o,
        "stratification: {}, {}, {}, {}",
        kv("initial_thickness_m", s.initial_thickness_m, "m"),
        kv("initial_temperature_k", s.initial_temperature_k, "K"),
        kv("diffusivity_factor", s.diffusivity_factor, ""),
        kv("wall_heat_to_layer", s.wall_heat_to_layer, ""),
    );
    let (b, cp) = (&p.baffles, &p.coupling);
    let _ = writeln!(
        o,
        "slosh: baffle_count {}, {}, {}, {}, {}, {}, {}, {}, {}, {}",
        b.count,
        kv("baffle_width_m", b.width_m, "m"),
        kv("baffle_spacing_m", b.spacing_m, "m"),
        kv("baffle_top_height_m", b.top_height_m, "m"),
        kv("wave_amplitude_m", b.wave_amplitude_m, "m"),
        kv("extra_damping_ratio", p.extra_damping, ""),
        kv("volume_coupling_m3", cp.volume_m3, "m³"),
        kv(
            "heat_transfer_enhancement_w_per_m2_k_s",
            cp.h_enhancement_w_per_m2_k_s,
            "W/(m²·K) per rad/s"
        ),
        kv("mixing_coefficient", cp.mixing, ""),
        kv("initial_angle_rad", c.initial_slosh_angle_rad, "rad"),
    );
    let _ = writeln!(
        o,
        "  at start: f_1 {} Hz, f_2 {} Hz, m_1 {} kg, L_1 {} m, ζ {}",
        n(x.slosh.omega[0] / std::f64::consts::TAU),
        n(x.slosh.omega[1] / std::f64::consts::TAU),
        n(x.slosh.mass_kg[0]),
        n(x.slosh.length_m[0]),
        n(x.slosh.zeta[0]),
    );

    // [pressurization], [relief], [engine], [feed], [vehicle]
    let _ = match &p.pressurization {
        None => writeln!(o, "pressurization: none (no pressurant)"),
        Some(ps) => writeln!(
            o,
            "pressurization: {}, {}, {}, {}, {}, {}, {}, gas {}, gain_schedule {}",
            kv("setpoint_pa", ps.setpoint_pa, "Pa"),
            kv("kp_kg_per_s_pa", ps.kp_kg_per_s_pa, "kg/(s·Pa)"),
            kv("kd_kg_per_pa", ps.kd_kg_per_pa, "kg/Pa"),
            kv("derivative_filter_s", ps.derivative_filter_s, "s"),
            kv("max_flow_kg_per_s", ps.max_flow_kg_per_s, "kg/s"),
            kv("gas_temperature_k", ps.gas_temperature_k, "K"),
            kv("bottle_mass_kg", ps.bottle_mass_kg, "kg"),
            ps.gas.name(),
            gain_schedule(c, ps.gain_schedule),
        ),
    };
    let _ = match &p.relief {
        None => writeln!(o, "relief: none (closed tank: nothing vents)"),
        Some(r) => writeln!(
            o,
            "relief: {}, {}, {}",
            kv("crack_pa", r.crack_pa, "Pa"),
            kv("reseat_pa", r.reseat_pa, "Pa"),
            kv("flow_area_m2", r.flow_area_m2, "m²"),
        ),
    };
    if let Some(m) = &p.mixer {
        let d = 2.0 * p.tank.radius_m();
        let f = p.fluid.props();
        let t = p.liquid_temperature_k;
        let _ = writeln!(
            o,
            "mixer: {}, {}, {}; jet {} m/s, Re_j {}, Fossett–Prosser t_mix {} s (τ = t_mix/ln 20)",
            kv("pump_flow_m3_s", m.pump_flow_m3_s, "m³/s"),
            kv("nozzle_diameter_m", m.nozzle_diameter_m, "m"),
            kv("pump_heat_w", m.pump_heat_w, "W"),
            number(m.jet_velocity_m_s()),
            number(m.jet_reynolds(f.rho_l_kg_per_m3(t), f.mu_l_pa_s(t))),
            number(m.mixing_time_s(d)),
        );
    }
    if let Some(t) = &p.tvs {
        let _ = writeln!(
            o,
            "tvs: band {} to {} Pa, {}, {} (T_sat {} K), {}, {}",
            number(t.band_lower_pa),
            number(t.band_upper_pa),
            kv("jt_flow_kg_s", t.jt_flow_kg_s, "kg/s"),
            kv("jt_outlet_pa", t.jt_outlet_pa, "Pa"),
            number((t.jt_temperature_k * 1000.0).round() / 1000.0),
            kv("pump_flow_m3_s", t.pump_flow_m3_s, "m³/s"),
            kv("pump_heat_w", t.pump_heat_w, "W"),
        );
        // Per kilogram vented the liquid loses h_g(T_jt) − h_l(T_l) of heat (docs/PHYSICS.md
        // 2.7): at full duty the TVS removes that times its flow. Below the heat coming in it
        // runs without stopping and the pressure climbs past the band anyway.
        let h_g = f.h_l_j_per_kg(t.jt_temperature_k) + f.h_fg_j_per_kg(t.jt_temperature_k);
        let cooling_w = t.jt_flow_kg_s * (h_g - f.h_l_j_per_kg(p.liquid_temperature_k));
        // A TVS that may run in no phase holds nothing and is not warned about.
        let runs = c.phases.iter().any(|ph| ph.tvs);
        match p.insulation {
            Some(_) => {
                let short = if runs && cooling_w < t.pump_heat_w {
                    "; warning: less than the pump heat alone: the TVS cannot hold its band"
                } else {
                    ""
                };
                let _ = writeln!(
                    o,
                    "  derived: cooling at full duty {} W (compare with the [insulation] heat leak \
                     above and the {} W pump heat){short}",
                    n(cooling_w),
                    n(t.pump_heat_w)
                );
            }
            None => {
                let heat_in_w = p.heat_leak_w + t.pump_heat_w;
                let short = if runs && cooling_w < heat_in_w {
                    "; warning: less than the heat coming in: the TVS cannot hold its band"
                } else {
                    ""
                };
                let _ = writeln!(
                    o,
                    "  derived: cooling at full duty {} W against {} W in (heat leak + pump heat){short}",
                    n(cooling_w),
                    n(heat_in_w)
                );
            }
        }
    }
    let fd = &p.feed;
    let _ = writeln!(
        o,
        "engine: {}, {}",
        kv("isp_s", fd.isp_s, "s"),
        kv("propellant_fraction", fd.propellant_fraction, ""),
    );
    let _ = writeln!(
        o,
        "feed: {}, {}, {}, {}",
        kv("line_height_m", fd.line_height_m, "m"),
        kv("line_loss_pa", fd.line_loss_pa, "Pa"),
        kv("line_velocity_m_s", fd.line_velocity_m_s, "m/s"),
        kv("npsh_required_m", fd.npsh_required_m, "m"),
    );
    let v = &p.vehicle;
    let _ = writeln!(
        o,
        "vehicle: {}, {}, {}, {}, {}",
        kv("dry_mass_kg", v.dry_mass_kg, "kg"),
        kv("drag_area_m2", v.drag_area_m2, "m²"),
        kv("initial_velocity_m_s", v.initial_velocity_m_s, "m/s"),
        kv("initial_altitude_m", v.initial_altitude_m, "m"),
        kv("slosh_lever_arm_m", v.slosh_lever_arm_m, "m"),
    );

    // [[phases]]
    let _ = writeln!(o, "phases:");
    let mut t = 0.0;
    for (i, ph) in c.phases.iter().enumerate() {
        let (steps, dt) = ph.steps();
        let stepping = match st.integrator {
            super::Integrator::Rk4 => format!(
                "{} ({steps} steps of {} s)",
                kv("dt_s", ph.dt_s, "s"),
                n(dt)
            ),
            super::Integrator::Dopri5 => format!(
                "{} (first step), {}",
                kv("dt_s", ph.dt_s, "s"),
                if ph.max_step_s.is_finite() {
                    kv("max_step_s", ph.max_step_s, "s")
                } else {
                    "max_step_s none".into()
                }
            ),
        };
        let _ = writeln!(
            o,
            "  phases.{i}: name {}, kind {}, t {} → {} s, {}, {stepping}, {}, flight_path_angle_deg {}°, {}, pressurize {}, excitation {}",
            ph.name,
            ph.kind.name(),
            n(t),
            n(t + ph.duration_s),
            kv("duration_s", ph.duration_s, "s"),
            kv("thrust_n", ph.thrust_n, "N"),
            n(ph.flight_path_angle_rad.to_degrees()),
            kv("gravity_m_s2", ph.gravity_m_s2, "m/s²"),
            ph.pressurize,
            excitation(c, i, &ph.excitation),
        );
        if p.mixer.is_some() {
            let _ = writeln!(o, "    mixer {}", if ph.mixer { "on" } else { "off" });
        }
        if p.tvs.is_some() {
            let _ = writeln!(o, "    tvs {}", if ph.tvs { "may run" } else { "off" });
        }
        if p.insulation.is_some() {
            let _ = writeln!(o, "    environment {}", ph.environment.name());
        }
        t += ph.duration_s;
    }

    // [dispersions]
    let d = &c.dispersions;
    if d.inputs.is_empty() {
        let _ = writeln!(o, "dispersions: none (every instance is the nominal)");
    } else {
        let _ = writeln!(
            o,
            "dispersions: design {}, {} inputs, {}, boiloff_budget_kg {}",
            d.design.name(),
            d.inputs.len(),
            kv("confidence", d.confidence, ""),
            d.boiloff_budget_kg
                .map_or_else(|| "none".to_string(), |b| format!("{} kg", n(b))),
        );
        for i in &d.inputs {
            let (lo, hi) = i.distribution.support();
            let _ = writeln!(
                o,
                "  {} (column {}): {}; mean {}, support [{}, {}]",
                i.key,
                i.column,
                i.distribution,
                n(i.distribution.mean()),
                n(lo),
                n(hi),
            );
        }
        for &(a, b, rho) in &d.correlations {
            let _ = writeln!(
                o,
                "  correlated: {} ~ {}, rho {}",
                d.inputs[a].key,
                d.inputs[b].key,
                n(rho)
            );
        }
    }
    o
}
