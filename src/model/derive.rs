//! Recover temperatures, volumes, pressures, level and slosh parameters from the conserved state.
//!
//! Shared by the right-hand side and by the time-history output, so that what is written is
//! exactly what the physics saw.

use super::flight::{self, PhaseKind};
use super::params::{Fidelity, Params};
use super::slosh::{self, MIN_AXIAL_ACCEL};
use super::state::*;
use crate::fluids::HELIUM;
use crate::geometry::Tank;

/// Smallest wetted or dry share of the wall mass: keeps both wall nodes finite at 0 % and 100 %.
pub const MIN_WALL_SHARE: f64 = 1.0e-3;

/// Wetted share of the wall area at level `z`, clamped to [MIN_WALL_SHARE, 1 − MIN_WALL_SHARE],
/// and its slope d(share)/dz, 1/m, zero where the clamp is active.
pub fn wetted_share(tank: &Tank, z: f64) -> (f64, f64) {
    let raw = tank.wetted_area_m2(z) / tank.wall_area_m2();
    if raw <= MIN_WALL_SHARE || raw >= 1.0 - MIN_WALL_SHARE {
        (raw.clamp(MIN_WALL_SHARE, 1.0 - MIN_WALL_SHARE), 0.0)
    } else {
        (raw, tank.wetted_area_slope_m(z) / tank.wall_area_m2())
    }
}

/// What the trajectory imposes at one instant.
#[derive(Clone, Copy, Debug, Default)]
pub struct Drive {
    /// Engine thrust, N (0 unless burning).
    pub thrust_n: f64,
    /// Whether the engine draws propellant.
    pub burning: bool,
    /// Whether the vehicle moves (false on a hold).
    pub flying: bool,
    /// Flight-path angle, rad.
    pub gamma_rad: f64,
    /// Phase gravity level / residual axial acceleration, m/s².
    pub gravity_m_s2: f64,
    /// Lateral excitation, m/s².
    pub a_lat: f64,
    /// Extra axial acceleration from a table excitation, m/s².
    pub a_ax_extra: f64,
    /// Whether the pressurization system may flow.
    pub pressurize: bool,
    /// Relief valve open (hysteresis state, updated between steps).
    pub valve_open: bool,
}

impl Drive {
    /// The drive of `phase` at phase time `t`.
    pub fn of_phase(phase: &flight::Phase, t: f64, valve_open: bool) -> Drive {
        let (a_lat, a_ax_extra) = phase.excitation.eval(t);
        let burning = phase.kind == PhaseKind::Burn;
        Drive {
            thrust_n: if burning { phase.thrust_n } else { 0.0 },
            burning,
            flying: phase.kind != PhaseKind::Hold,
            gamma_rad: phase.flight_path_angle_rad,
            gravity_m_s2: phase.gravity_m_s2,
            a_lat,
            a_ax_extra,
            pressurize: phase.pressurize,
            valve_open,
        }
    }
}

/// Slosh analog parameters at the current level and acceleration.
#[derive(Clone, Copy, Debug, Default)]
pub struct SloshParams {
    /// Modal masses m_1, m_2, kg.
    pub mass_kg: [f64; 2],
    /// Pendulum lengths L_1, L_2, m.
    pub length_m: [f64; 2],
    /// Natural angular frequencies ω_1, ω_2, rad/s.
    pub omega: [f64; 2],
    /// Damping ratios ζ_1, ζ_2.
    pub zeta: [f64; 2],
}

/// Everything derived from one state.
#[derive(Clone, Copy, Debug, Default)]
pub struct Derived {
    pub t_ullage_k: f64,
    pub t_layer_k: f64,
    pub t_bulk_k: f64,
    pub t_wall_dry_k: f64,
    pub t_wall_wet_k: f64,
    pub rho_layer: f64,
    pub rho_bulk: f64,
    pub v_layer_m3: f64,
    pub v_bulk_m3: f64,
    pub v_ullage_m3: f64,
    /// Liquid level above the tank bottom, m.
    pub level_m: f64,
    pub interface_area_m2: f64,
    pub wetted_share: f64,
    pub wetted_share_slope: f64,
    pub m_vapor_kg: f64,
    pub m_liquid_kg: f64,
    pub p_vapor_pa: f64,
    pub p_ullage_pa: f64,
    /// Effective axial acceleration seen by the liquid, m/s² (floored).
    pub a_ax: f64,
    /// Vehicle mass, kg.
    pub vehicle_mass_kg: f64,
    /// Drag, N.
    pub drag_n: f64,
    pub slosh: SloshParams,
}

/// Vehicle mass, drag and effective axial acceleration (MODEL.md §5, §8).
fn flight_state(p: &Params, s: &State, d: &Drive, m_tank: f64) -> (f64, f64, f64) {
    let frac = p.feed.propellant_fraction;
    let other_used = s[OUT] * (1.0 / frac - 1.0);
    let mass = (p.vehicle.dry_mass_kg + m_tank - other_used).max(1.0);
    let v = s[VEL];
    let drag = 0.5 * flight::air_density(s[ALT]) * v * v.abs() * p.vehicle.drag_area_m2;
    let a = if d.flying {
        (d.thrust_n - drag) / mass
    } else {
        0.0
    };
    (
        mass,
        drag,
        (a + d.gravity_m_s2 + d.a_ax_extra).max(MIN_AXIAL_ACCEL),
    )
}

/// Slosh parameters from the equivalent cylinder at the current level (MODEL.md §5).
fn slosh_params(
    p: &Params,
    v_liquid: f64,
    m_liquid: f64,
    z: f64,
    a_ax: f64,
    nu: f64,
) -> SloshParams {
    let (r, h) =
        slosh::equivalent_cylinder(p.tank.surface_radius_m(z), v_liquid, p.tank.radius_m());
    let hr = h / r;
    let zeta = slosh::wall_damping(nu, r, a_ax, hr)
        + slosh::baffle_damping(&p.baffles, r, z)
        + p.extra_damping;
    let mut out = SloshParams::default();
    for n in 0..2 {
        let shape = slosh::mode_shape(n, hr);
        out.mass_kg[n] = shape.mass_ratio * m_liquid;
        out.length_m[n] = shape.length_ratio * r;
        out.omega[n] = (shape.omega2_ratio * a_ax / r).sqrt();
        out.zeta[n] = zeta;
    }
    out
}

/// Derive temperatures, volumes and pressures from the state.
pub fn derive(p: &Params, s: &State, d: &Drive) -> Derived {
    match p.fidelity {
        Fidelity::Homogeneous => super::homogeneous::derive(p, s, d),
        Fidelity::Lumped | Fidelity::TwoMode => derive_nodes(p, s, d),
    }
}

/// Wall temperatures from the wall energies and the wetted share.
pub fn wall_temperatures(p: &Params, s: &State, wet: f64) -> (f64, f64) {
    let mc = p.wall_areal_mass_kg_per_m2 * p.tank.wall_area_m2() * p.wall_cp_j_per_kg_k;
    (s[E_WD] / (mc * (1.0 - wet)), s[E_WW] / (mc * wet))
}

/// Level-dependent quantities shared by both thermal formulations.
pub fn fill_level(p: &Params, out: &mut Derived, v_liquid: f64) {
    let z = p.tank.liquid_height_m(v_liquid);
    out.level_m = z;
    out.interface_area_m2 = p
        .tank
        .interface_area_m2(z)
        .max(1.0e-6 * p.tank.radius_m().powi(2));
    (out.wetted_share, out.wetted_share_slope) = wetted_share(&p.tank, z);
}

/// Flight and slosh quantities shared by both thermal formulations.
pub fn motion(p: &Params, s: &State, d: &Drive, out: &mut Derived, nu_liquid: f64) {
    let m_tank = out.m_liquid_kg + s[M_V] + s[M_G];
    let (mass, drag, a_ax) = flight_state(p, s, d, m_tank);
    out.vehicle_mass_kg = mass;
    out.drag_n = drag;
    out.a_ax = a_ax;
    let v_l = out.v_layer_m3 + out.v_bulk_m3;
    out.slosh = slosh_params(p, v_l, out.m_liquid_kg, out.level_m, a_ax, nu_liquid);
}

fn derive_nodes(p: &Params, s: &State, d: &Drive) -> Derived {
    let f = p.fluid.props();
    let mut out = Derived::default();
    let m_s = s[M_S].max(1.0e-12);
    let m_b = s[M_B].max(1.0e-12);
    out.t_layer_k = p.fluid.t_from_h_l_k(s[H_S] / m_s);
    out.t_bulk_k = p.fluid.t_from_h_l_k(s[H_B] / m_b);
    out.rho_layer = f.rho_l_kg_per_m3(out.t_layer_k);
    out.rho_bulk = f.rho_l_kg_per_m3(out.t_bulk_k);
    out.v_layer_m3 = s[M_S] / out.rho_layer;
    out.v_bulk_m3 = s[M_B] / out.rho_bulk;
    out.m_liquid_kg = s[M_S] + s[M_B];
    let v_l = out.v_layer_m3 + out.v_bulk_m3;
    fill_level(p, &mut out, v_l);
    let nu = f.mu_l_pa_s(out.t_bulk_k) / out.rho_bulk;
    motion(p, s, d, &mut out, nu);
    out.v_ullage_m3 =
        p.tank.volume_m3() - v_l + p.coupling.volume_m3 * slosh_angle(p, s, &out.slosh).sin();
    let off = vapor_enthalpy_offset(p.fluid);
    let heat_cap = s[M_V] * f.cv_vapor_j_per_kg_k + s[M_G] * HELIUM.cv_j_per_kg_k;
    out.t_ullage_k = (s[U_U] - s[M_V] * off) / heat_cap;
    out.m_vapor_kg = s[M_V];
    out.p_vapor_pa = s[M_V] * f.r_specific_j_per_kg_k() * out.t_ullage_k / out.v_ullage_m3;
    out.p_ullage_pa =
        out.p_vapor_pa + s[M_G] * HELIUM.r_specific_j_per_kg_k() * out.t_ullage_k / out.v_ullage_m3;
    let (twd, tww) = wall_temperatures(p, s, out.wetted_share);
    out.t_wall_dry_k = twd;
    out.t_wall_wet_k = tww;
    out
}

/// Slosh angle, rad: the pendulum angle (`lumped`) or atan(x_1 / L_1) (`two_mode`).
pub fn slosh_angle(p: &Params, s: &State, sl: &SloshParams) -> f64 {
    match p.fidelity {
        Fidelity::TwoMode => (s[Q1] / sl.length_m[0]).atan(),
        _ => s[Q1],
    }
}
