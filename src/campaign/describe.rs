//! Human-readable resolved nominal of a campaign (`cryoslosh check`).

use super::Campaign;
use crate::model::derive::{derive, Drive};
use crate::model::state::initial_state;
use std::fmt::Write;

/// The resolved nominal: every input with its default filled in, plus the derived initial state.
pub fn describe(c: &Campaign) -> String {
    let p = &c.params;
    let f = p.fluid.props();
    let mut o = String::new();
    let s0 = initial_state(p);
    let x = derive(
        crate::model::Group::one(p),
        &s0,
        &Drive::of_phase(&c.phases[0], 0.0, false),
    );
    let _ = writeln!(
        o,
        "campaign {} ({}), fidelity {}",
        c.name,
        c.path.display(),
        p.fidelity.name()
    );
    let _ = writeln!(
        o,
        "tank: {} R = {} m, height {:.4} m, volume {:.4} m³, wall {:.3} m² × {} kg/m², c_w {:.1} J/(kg·K)",
        p.tank.shape().name(),
        p.tank.radius_m(),
        p.tank.height_m(),
        p.tank.volume_m3(),
        p.tank.wall_area_m2(),
        p.wall_areal_mass_kg_per_m2,
        p.wall_cp_j_per_kg_k
    );
    let _ = writeln!(o, "heat leak {} W, MEOP {} Pa", p.heat_leak_w, p.meop_pa);
    let _ = writeln!(
        o,
        "propellant {}: fill {:.4}, T_l = {:.4} K (T_sat {:.4} K), liquid {:.3} kg, level {:.4} m, interface {:.4} m²",
        p.fluid.name(),
        p.fill_fraction,
        p.liquid_temperature_k,
        f.tsat_k(p.ullage_pressure_pa.min(f.psat_pa(f.t_max_k))),
        x.m_liquid_kg,
        x.level_m,
        x.interface_area_m2
    );
    let _ = writeln!(
        o,
        "ullage: P = {} Pa (vapour {:.1} Pa, helium {:.1} Pa), T_u = {:.4} K, V_u = {:.4} m³",
        p.ullage_pressure_pa,
        x.p_vapor_pa,
        x.p_ullage_pa - x.p_vapor_pa,
        p.ullage_temperature_k,
        x.v_ullage_m3
    );
    let _ = writeln!(
        o,
        "slosh at start: f_1 = {:.4} Hz, f_2 = {:.4} Hz, m_1 = {:.3} kg, L_1 = {:.4} m, ζ = {:.5}",
        x.slosh.omega[0] / std::f64::consts::TAU,
        x.slosh.omega[1] / std::f64::consts::TAU,
        x.slosh.mass_kg[0],
        x.slosh.length_m[0],
        x.slosh.zeta[0]
    );
    let _ = writeln!(o, "heat transfer: {:?}", p.heat_transfer);
    let _ = writeln!(o, "stratification: {:?}", p.stratification);
    let _ = writeln!(o, "coupling: {:?}", p.coupling);
    let _ = writeln!(
        o,
        "baffles: {:?}, extra damping {}",
        p.baffles, p.extra_damping
    );
    let _ = writeln!(o, "pressurization: {:?}", p.pressurization);
    let _ = writeln!(o, "relief: {:?}", p.relief);
    let _ = writeln!(o, "feed: {:?}", p.feed);
    let _ = writeln!(o, "vehicle: {:?}", p.vehicle);
    let _ = writeln!(o, "phases:");
    let mut t = 0.0;
    for (i, ph) in c.phases.iter().enumerate() {
        let (n, dt) = ph.steps();
        let steps = match c.stepping.integrator {
            super::Integrator::Rk4 => format!("{n} steps of {dt:.6} s"),
            super::Integrator::Dopri5 => format!("first step {} s", ph.dt_s),
        };
        let _ = writeln!(
            o,
            "  {i}: {} [{}] t = {t} → {} s, {steps}, thrust {} N, γ {:.2}°, g {} m/s², pressurize {}, excitation {:?}",
            ph.name,
            ph.kind.name(),
            t + ph.duration_s,
            ph.thrust_n,
            ph.flight_path_angle_rad.to_degrees(),
            ph.gravity_m_s2,
            ph.pressurize,
            ph.excitation
        );
        t += ph.duration_s;
    }
    let _ = writeln!(
        o,
        "output every {} s; run: {} instances, seed {}",
        c.output_interval_s, c.instances, c.seed
    );
    let d = &c.dispersions;
    if !d.inputs.is_empty() {
        let _ = writeln!(
            o,
            "dispersions: {} design, {} inputs, confidence {}, boil-off budget {:?} kg",
            d.design.name(),
            d.inputs.len(),
            d.confidence,
            d.boiloff_budget_kg
        );
        for i in &d.inputs {
            let (lo, hi) = i.distribution.support();
            let _ = writeln!(
                o,
                "  {} (column {}): {:?}, mean {:.6}, support [{lo}, {hi}]",
                i.key,
                i.column,
                i.distribution,
                i.distribution.mean()
            );
        }
        for &(a, b, rho) in &d.correlations {
            let _ = writeln!(
                o,
                "  correlated: {} ~ {} with ρ = {rho}",
                d.inputs[a].key, d.inputs[b].key
            );
        }
    }
    o
}
