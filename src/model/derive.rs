//! Recover temperatures, volumes, pressures, level and slosh parameters from the conserved state.
//!
//! Shared by the right-hand side and by the time-history output, so that what is written is
//! exactly what the physics saw.

use super::flight::{self, PhaseKind};
use super::params::{Fidelity, Params};
use super::slosh::{self, MIN_AXIAL_ACCEL};
use super::state::*;
use super::Group;
use crate::fluids::HELIUM;
use crate::geometry::TankLanes;
use crate::lanes::{c, math, Mask, Real, WIDTH};

/// Smallest wetted or dry share of the wall mass: keeps both wall nodes finite at 0 % and 100 %.
pub const MIN_WALL_SHARE: f64 = 1.0e-3;

/// Wetted share of the wall area at level `z`, clamped to [MIN_WALL_SHARE, 1 − MIN_WALL_SHARE],
/// and its slope d(share)/dz, 1/m, zero where the clamp is active.
pub fn wetted_share<T: Real>(tank: &TankLanes<T>, z: T) -> (T, T) {
    let wall = tank.wall_area_m2();
    let raw = tank.wetted_area_m2(z) / wall;
    let clamped = raw.le(c(MIN_WALL_SHARE)) | raw.ge(c(1.0 - MIN_WALL_SHARE));
    let slope = tank.wetted_area_slope_m(z) / wall;
    (
        T::select(
            clamped,
            raw.clamp_c(MIN_WALL_SHARE, 1.0 - MIN_WALL_SHARE),
            raw,
        ),
        T::select(clamped, c(0.0), slope),
    )
}

/// What the trajectory imposes at one instant.
#[derive(Clone, Copy, Debug, Default)]
pub struct Drive<T: Real = f64> {
    /// Engine thrust, N (0 unless burning).
    pub thrust_n: T,
    /// Whether the engine draws propellant.
    pub burning: T::Mask,
    /// Whether the vehicle moves (false on a hold).
    pub flying: T::Mask,
    /// Flight-path angle, rad.
    pub gamma_rad: T,
    /// Phase gravity level / residual axial acceleration, m/s².
    pub gravity_m_s2: T,
    /// Lateral excitation, m/s².
    pub a_lat: T,
    /// Extra axial acceleration from a table excitation, m/s².
    pub a_ax_extra: T,
    /// Whether the pressurization system may flow.
    pub pressurize: T::Mask,
    /// Relief valve open (hysteresis state, updated between steps).
    pub valve_open: T::Mask,
    /// The insulation faces space (else the ground environment).
    pub space: T::Mask,
    /// The jet mixer runs (used only with `[mixer]`).
    pub mixing: T::Mask,
    /// The thermodynamic vent system runs (hysteresis state, updated between steps; used only
    /// with `[tvs]`).
    pub tvs_on: T::Mask,
    /// Nothing reads this evaluation's slosh modes ([`Derived::slosh`]) and the phase has no
    /// lateral excitation: an integrator's stage or step end with no history row. Where every
    /// lane says so and every lane's analog is at rest, [`motion`] leaves the modes out
    /// ([`SloshParams::at_rest`]); the rates are the same bits either way. False (the modes
    /// evaluated) in [`Drive::of_phase`] and by default.
    pub slosh_modes_unread: T::Mask,
}

/// The switched devices' states, held over a step and updated between steps: the relief valve
/// open, the thermodynamic vent system on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Switches {
    pub relief: bool,
    pub tvs: bool,
}

impl Drive {
    /// The drive of `phase` at phase time `t`.
    /// `sw` the switched devices' states (a TVS runs only where the phase lets it).
    pub fn of_phase(phase: &flight::Phase, t: f64, sw: Switches) -> Drive {
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
            valve_open: sw.relief,
            space: phase.environment == flight::Environment::Space,
            mixing: phase.mixer,
            tvs_on: sw.tvs && phase.tvs,
            slosh_modes_unread: false,
        }
    }
}

impl<T: Real> Drive<T> {
    /// The lanes' drives, lane `i` being `lane(i)`.
    pub fn gather(lane: impl Fn(usize) -> Drive) -> Drive<T> {
        let mut d = [Drive::default(); WIDTH];
        for (i, di) in d.iter_mut().enumerate().take(T::LANES) {
            *di = lane(i);
        }
        Drive {
            thrust_n: T::from_fn(|i| d[i].thrust_n),
            burning: T::Mask::from_fn(|i| d[i].burning),
            flying: T::Mask::from_fn(|i| d[i].flying),
            gamma_rad: T::from_fn(|i| d[i].gamma_rad),
            gravity_m_s2: T::from_fn(|i| d[i].gravity_m_s2),
            a_lat: T::from_fn(|i| d[i].a_lat),
            a_ax_extra: T::from_fn(|i| d[i].a_ax_extra),
            pressurize: T::Mask::from_fn(|i| d[i].pressurize),
            valve_open: T::Mask::from_fn(|i| d[i].valve_open),
            space: T::Mask::from_fn(|i| d[i].space),
            mixing: T::Mask::from_fn(|i| d[i].mixing),
            tvs_on: T::Mask::from_fn(|i| d[i].tvs_on),
            slosh_modes_unread: T::Mask::from_fn(|i| d[i].slosh_modes_unread),
        }
    }

    /// Lane `i`.
    pub fn lane(&self, i: usize) -> Drive {
        Drive {
            thrust_n: self.thrust_n.lane(i),
            burning: self.burning.lane(i),
            flying: self.flying.lane(i),
            gamma_rad: self.gamma_rad.lane(i),
            gravity_m_s2: self.gravity_m_s2.lane(i),
            a_lat: self.a_lat.lane(i),
            a_ax_extra: self.a_ax_extra.lane(i),
            pressurize: self.pressurize.lane(i),
            valve_open: self.valve_open.lane(i),
            space: self.space.lane(i),
            mixing: self.mixing.lane(i),
            tvs_on: self.tvs_on.lane(i),
            slosh_modes_unread: self.slosh_modes_unread.lane(i),
        }
    }
}

/// Slosh analog parameters at the current level and acceleration.
#[derive(Clone, Copy, Debug, Default)]
pub struct SloshParams<T = f64> {
    /// Modal masses m_1, m_2, kg.
    pub mass_kg: [T; 2],
    /// Pendulum lengths L_1, L_2, m.
    pub length_m: [T; 2],
    /// Natural angular frequencies ω_1, ω_2, rad/s.
    pub omega: [T; 2],
    /// Damping ratios ζ_1, ζ_2.
    pub zeta: [T; 2],
}

/// Everything derived from one state.
#[derive(Clone, Copy, Debug, Default)]
pub struct Derived<T = f64> {
    pub t_ullage_k: T,
    /// Temperature of the liquid at the interface, K: the warm layer (`lumped`, `two_mode`), the
    /// top layer (`layered`), the liquid (`homogeneous`).
    pub t_layer_k: T,
    /// Temperature of the liquid at the outlet, K: the bulk, the bottom layer (`layered`).
    pub t_bulk_k: T,
    /// Coldest and warmest liquid, K (every layer at `layered`): the validity check's range.
    pub t_liquid_min_k: T,
    pub t_liquid_max_k: T,
    pub t_wall_dry_k: T,
    pub t_wall_wet_k: T,
    pub rho_layer: T,
    pub rho_bulk: T,
    pub v_layer_m3: T,
    pub v_bulk_m3: T,
    pub v_ullage_m3: T,
    /// Liquid level above the tank bottom, m.
    pub level_m: T,
    pub interface_area_m2: T,
    pub wetted_share: T,
    pub wetted_share_slope: T,
    pub m_vapor_kg: T,
    pub m_liquid_kg: T,
    pub p_vapor_pa: T,
    pub p_ullage_pa: T,
    /// Effective axial acceleration seen by the liquid, m/s² (floored).
    pub a_ax: T,
    /// Vehicle mass, kg.
    pub vehicle_mass_kg: T,
    /// Drag, N.
    pub drag_n: T,
    pub slosh: SloshParams<T>,
    /// The real-gas vapour at the ullage's (T_u, ρ_v) and its ideal-gas energy u⁰ (J/kg) and
    /// c_v⁰ (J/(kg K)) there, from [`ullage_temperature`]: carried so that the right-hand side
    /// does not evaluate them again (lumped levels; zero at the homogeneous level).
    pub ullage_vapor: UllageVapor<T>,
}

/// The ullage vapour's properties at the derived state (see [`Derived::ullage_vapor`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct UllageVapor<T = f64> {
    /// Residual state and its derivatives ([`crate::fluids::FluidProps::vapor_state`]).
    pub state: crate::fluids::vapor::VaporState<T>,
    /// Ideal-gas internal energy u⁰, J/kg ([`crate::fluids::FluidProps::vapor_ideal`]).
    pub u0_j_per_kg: T,
    /// Ideal-gas isochoric heat capacity c_v⁰, J/(kg K).
    pub cv0_j_per_kg_k: T,
}

impl<T: Real> UllageVapor<T> {
    /// Lane `i`.
    pub fn lane(&self, i: usize) -> UllageVapor {
        UllageVapor {
            state: self.state.lane(i),
            u0_j_per_kg: self.u0_j_per_kg.lane(i),
            cv0_j_per_kg_k: self.cv0_j_per_kg_k.lane(i),
        }
    }
}

impl<T: Real> SloshParams<T> {
    /// What [`motion`] gives in place of the modes where they are not read and the analog is at
    /// rest: no modal mass, unit lengths, no frequency or damping. Finite and positive where
    /// the rates divide, so that each slosh term is a zero of the same sign as with the modes
    /// (an angle, a rate and a force of 0 times a finite factor; `tests/slosh_at_rest.rs`).
    pub fn at_rest() -> SloshParams<T> {
        SloshParams {
            mass_kg: [c(0.0); 2],
            length_m: [c(1.0); 2],
            omega: [c(0.0); 2],
            zeta: [c(0.0); 2],
        }
    }

    /// Lane `i`.
    pub fn lane(&self, i: usize) -> SloshParams {
        let pair = |v: &[T; 2]| [v[0].lane(i), v[1].lane(i)];
        SloshParams {
            mass_kg: pair(&self.mass_kg),
            length_m: pair(&self.length_m),
            omega: pair(&self.omega),
            zeta: pair(&self.zeta),
        }
    }
}

impl<T: Real> Derived<T> {
    /// Lane `i`.
    pub fn lane(&self, i: usize) -> Derived {
        Derived {
            t_ullage_k: self.t_ullage_k.lane(i),
            t_layer_k: self.t_layer_k.lane(i),
            t_bulk_k: self.t_bulk_k.lane(i),
            t_liquid_min_k: self.t_liquid_min_k.lane(i),
            t_liquid_max_k: self.t_liquid_max_k.lane(i),
            t_wall_dry_k: self.t_wall_dry_k.lane(i),
            t_wall_wet_k: self.t_wall_wet_k.lane(i),
            rho_layer: self.rho_layer.lane(i),
            rho_bulk: self.rho_bulk.lane(i),
            v_layer_m3: self.v_layer_m3.lane(i),
            v_bulk_m3: self.v_bulk_m3.lane(i),
            v_ullage_m3: self.v_ullage_m3.lane(i),
            level_m: self.level_m.lane(i),
            interface_area_m2: self.interface_area_m2.lane(i),
            wetted_share: self.wetted_share.lane(i),
            wetted_share_slope: self.wetted_share_slope.lane(i),
            m_vapor_kg: self.m_vapor_kg.lane(i),
            m_liquid_kg: self.m_liquid_kg.lane(i),
            p_vapor_pa: self.p_vapor_pa.lane(i),
            p_ullage_pa: self.p_ullage_pa.lane(i),
            a_ax: self.a_ax.lane(i),
            vehicle_mass_kg: self.vehicle_mass_kg.lane(i),
            drag_n: self.drag_n.lane(i),
            slosh: self.slosh.lane(i),
            ullage_vapor: self.ullage_vapor.lane(i),
        }
    }
}

/// Vehicle mass, drag and effective axial acceleration (MODEL.md §5, §8).
fn flight_state<T: Real>(g: Group<'_>, s: &State<T>, d: &Drive<T>, m_tank: T) -> (T, T, T) {
    let frac: T = g.get(|p| p.feed.propellant_fraction);
    let other_used = s[OUT] * (frac.rdiv(1.0) - 1.0);
    let dry: T = g.get(|p| p.vehicle.dry_mass_kg);
    let mass = (dry + m_tank - other_used).max_c(1.0);
    let v = s[VEL];
    let drag_area: T = g.get(|p| p.vehicle.drag_area_m2);
    // At rest in every lane (a hold, a ground test) v |v| = 0: the same signed zero as the
    // product with the air density, without its exponential.
    let drag = if v.is_zero().all() {
        v * v.abs() * drag_area
    } else {
        flight::air_density(s[ALT]) * 0.5 * v * v.abs() * drag_area
    };
    let a = T::select(d.flying, (d.thrust_n - drag) / mass, c(0.0));
    (
        mass,
        drag,
        (a + d.gravity_m_s2 + d.a_ax_extra).max_c(MIN_AXIAL_ACCEL),
    )
}

/// Slosh parameters at the current level (MODEL.md §5, docs/PHYSICS.md "Slosh"): the modal
/// masses, pendulum lengths and frequencies of the tank's own shape ([`slosh::tank_modes`]:
/// closed form for cylinders, potential-flow tables for spheres and capsules). The damping
/// correlations are for flat-bottom cylinders; they are evaluated on the equivalent cylinder,
/// free-surface radius r_s and depth V_l / (π r_s²) ([`slosh::equivalent_cylinder`]).
fn slosh_params<T: Real>(
    g: Group<'_>,
    tank: &TankLanes<T>,
    v_liquid: T,
    m_liquid: T,
    z: T,
    a_ax: T,
    nu: T,
) -> SloshParams<T> {
    let radius: T = g.get(|p| p.tank.radius_m());
    let (r, h) = slosh::equivalent_cylinder(tank.surface_radius_m(z), v_liquid, radius);
    let extra: T = g.get(|p| p.extra_damping);
    let zeta = slosh::wall_damping(nu, r, a_ax, h / r) + slosh::baffle_damping(g, r, z) + extra;
    let modes = slosh::tank_modes(tank, z, v_liquid);
    let mut out = SloshParams::default();
    for (n, shape) in modes.iter().enumerate() {
        out.mass_kg[n] = shape.mass_ratio * m_liquid;
        out.length_m[n] = shape.length_ratio * radius;
        out.omega[n] = (shape.omega2_ratio * a_ax / radius).sqrt();
        out.zeta[n] = zeta;
    }
    out
}

/// Derive temperatures, volumes and pressures from the state.
pub fn derive<T: Real>(g: Group<'_>, s: &State<T>, d: &Drive<T>) -> Derived<T> {
    let mut out = Derived::default();
    derive_into(g, s, d, &mut out);
    out
}

/// [`derive`] into `out`, in place (a lane group's derived state is kilobytes: the right-hand
/// side reuses one instead of moving a new one through every caller).
pub fn derive_into<T: Real>(g: Group<'_>, s: &State<T>, d: &Drive<T>, out: &mut Derived<T>) {
    match g.shared().fidelity {
        Fidelity::Homogeneous => {
            *out = super::homogeneous::derive(g, s, d);
            liquid_range(out);
        }
        Fidelity::Lumped | Fidelity::TwoMode => derive_nodes(g, &g.tank(), s, d, out),
        Fidelity::Layered => {
            let prof = super::column::profile(g, s);
            *out = super::column::derive_column(g, s, d, &prof);
        }
    }
}

/// The liquid's temperature range of a level with at most two liquid nodes.
pub fn liquid_range<T: Real>(out: &mut Derived<T>) {
    out.t_liquid_min_k = out.t_layer_k.min(out.t_bulk_k);
    out.t_liquid_max_k = out.t_layer_k.max(out.t_bulk_k);
}

/// Wall temperatures from the wall energies and the wetted share.
pub fn wall_temperatures<T: Real>(g: Group<'_>, s: &State<T>, wet: T) -> (T, T) {
    let mc: T = g.get(Params::wall_heat_capacity_j_per_k);
    (s[E_WD] / (mc * wet.rsub(1.0)), s[E_WW] / (mc * wet))
}

/// Level-dependent quantities shared by both thermal formulations.
pub fn fill_level<T: Real>(g: Group<'_>, tank: &TankLanes<T>, out: &mut Derived<T>, v_liquid: T) {
    let z = tank.liquid_height_m(v_liquid);
    out.level_m = z;
    let floor: T = g.get(|p| 1.0e-6 * p.tank.radius_m().powi(2));
    out.interface_area_m2 = tank.interface_area_m2(z).max(floor);
    (out.wetted_share, out.wetted_share_slope) = wetted_share(tank, z);
}

/// Flight and slosh quantities shared by both thermal formulations. `nu_liquid` gives the
/// liquid's kinematic viscosity, m²/s, for the slosh damping: asked for only where the modes are
/// evaluated (not for an analog at rest, `slosh_at_rest`: a logarithm-fit `exp` and a divide
/// fewer).
pub fn motion<T: Real>(
    g: Group<'_>,
    tank: &TankLanes<T>,
    s: &State<T>,
    d: &Drive<T>,
    out: &mut Derived<T>,
    nu_liquid: impl FnOnce() -> T,
) {
    let m_tank = out.m_liquid_kg + s[M_V] + s[M_G];
    let (mass, drag, a_ax) = flight_state(g, s, d, m_tank);
    out.vehicle_mass_kg = mass;
    out.drag_n = drag;
    out.a_ax = a_ax;
    let v_l = out.v_layer_m3 + out.v_bulk_m3;
    // The analog's frequency and damping follow the acceleration the liquid actually sees, axial
    // and lateral: in a coast with a lateral push the pendulum swings at √(|a|/L), not at the
    // axial floor's frequency (issue 11: 0.000216 Hz reported, 0.0216 Hz seen).
    let a_total = (a_ax * a_ax + d.a_lat * d.a_lat).sqrt();
    out.slosh = if slosh_at_rest(g, s, d) {
        SloshParams::at_rest()
    } else {
        slosh_params(
            g,
            tank,
            v_l,
            out.m_liquid_kg,
            out.level_m,
            a_total,
            nu_liquid(),
        )
    };
}

/// Whether the slosh modes can be left out of this evaluation: in every lane nothing reads them
/// ([`Drive::slosh_modes_unread`]), there is no lateral acceleration and the analog's angles and
/// rates are zero (a NaN is not). Then every slosh term of the rates is a signed zero times a
/// finite factor, the same bits with the modes or with [`SloshParams::at_rest`], and the
/// modes' table reads, damping correlations and square roots (a fifth of a ground-test tank's
/// right-hand side, issue 18) are saved. An excited or swinging lane evaluates them for the group.
fn slosh_at_rest<T: Real>(g: Group<'_>, s: &State<T>, d: &Drive<T>) -> bool {
    let mut rest = d.slosh_modes_unread & d.a_lat.is_zero() & s[Q1].is_zero() & s[Q1D].is_zero();
    if g.shared().fidelity.two_mode_slosh() {
        rest = rest & s[Q2].is_zero() & s[Q2D].is_zero();
    }
    rest.all()
}

/// [`derive_into`] at the two-node levels (`lumped`, `two_mode`), with each lane's `tank`
/// gathered once by the caller (the right-hand side uses it again, `model::nodes::rhs`).
pub fn derive_nodes<T: Real>(
    g: Group<'_>,
    tank: &TankLanes<T>,
    s: &State<T>,
    d: &Drive<T>,
    out: &mut Derived<T>,
) {
    let fluid = g.shared().fluid;
    let f = fluid.props();
    // Every field of `out` is written below (and in `finish_nodes`, `liquid_range`): no zeroing
    // first (a lane group's `Derived` is 5 kB, zeroed per right-hand side until 2026-12-06).
    let m_s = s[M_S].max_c(1.0e-12);
    let m_b = s[M_B].max_c(1.0e-12);
    out.t_layer_k = fluid.t_from_h_l_k(s[H_S] / m_s);
    // A merged (empty) bulk takes the layer's temperature (`model::merge_empty_bulk`).
    let bulk_gone = s[M_B].le(c(0.0));
    let h_bulk = T::select(bulk_gone, s[H_S] / m_s, s[H_B] / m_b);
    out.t_bulk_k = T::select(bulk_gone, out.t_layer_k, fluid.t_from_h_l_k(h_bulk));
    out.rho_layer = f.rho_l_kg_per_m3(out.t_layer_k);
    out.rho_bulk = f.rho_l_kg_per_m3(out.t_bulk_k);
    out.v_layer_m3 = s[M_S] / out.rho_layer;
    out.v_bulk_m3 = s[M_B] / out.rho_bulk;
    out.m_liquid_kg = s[M_S] + s[M_B];
    let v_l = out.v_layer_m3 + out.v_bulk_m3;
    let (t_b, rho_b) = (out.t_bulk_k, out.rho_bulk);
    finish_nodes(g, tank, s, d, out, v_l, move || f.mu_l_pa_s(t_b) / rho_b);
    liquid_range(out);
}

/// What the node levels (`lumped`, `two_mode`, `layered`) derive alike once their liquid is
/// known (`out`'s liquid fields, the liquid volume `v_l` m³, its kinematic viscosity `nu` m²/s
/// at the outlet, evaluated only where the slosh modes are): level, flight and slosh, the
/// ullage's volume, temperature and pressures, and the walls' temperatures. `tank`: each lane's
/// tank ([`Group::tank`]).
pub fn finish_nodes<T: Real>(
    g: Group<'_>,
    tank: &TankLanes<T>,
    s: &State<T>,
    d: &Drive<T>,
    out: &mut Derived<T>,
    v_l: T,
    nu: impl FnOnce() -> T,
) {
    let fluid = g.shared().fluid;
    fill_level(g, tank, out, v_l);
    motion(g, tank, s, d, out, nu);
    let (v_tank, c_v): (T, T) = (
        g.get(|p| p.tank.volume_m3()),
        g.get(|p| p.coupling.volume_m3),
    );
    let angle = slosh_angle(g, s, &out.slosh);
    out.v_ullage_m3 = v_tank - v_l + c_v * math::sin(angle);
    let rho_v = s[M_V] / out.v_ullage_m3;
    let (t_u, vapor) = ullage_temperature(fluid, s[M_V], s[M_G], s[U_U], rho_v);
    out.t_ullage_k = t_u;
    out.ullage_vapor = vapor;
    out.m_vapor_kg = s[M_V];
    out.p_vapor_pa = vapor.state.p_pa;
    out.p_ullage_pa =
        out.p_vapor_pa + s[M_G] * HELIUM.r_specific_j_per_kg_k() * out.t_ullage_k / out.v_ullage_m3;
    let (twd, tww) = wall_temperatures(g, s, out.wetted_share);
    out.t_wall_dry_k = twd;
    out.t_wall_wet_k = tww;
}

/// Iteration cap of [`ullage_temperature`]'s Newton solve (it needs 3–5).
const ULLAGE_NEWTON_MAX: usize = 16;
/// A lane stops after a Newton step below this share of T: Newton's error after a step s is
/// (T f''/2f') (s/T)² relative, under 1e-13 for |s| ≤ 1e-7 T since T f''/f' (the relative
/// change of the heat capacity m_v (c_v⁰ + ∂u_res/∂T) + m_g c_v,He over T) stays below 10 on
/// the fits' range (`tests/real_gas_ullage.rs` checks the result against a bisected root).
pub const ULLAGE_NEWTON_STEP_TOL: f64 = 1e-7;

/// Ullage temperature from its energy `u_j` (J) with `m_v` kg of real-gas vapour at density
/// `rho_v` (kg/m³) and `m_g` kg of ideal helium: the root of
/// m_v (u⁰(T) + e_0 + u_res(T, ρ_v)) + m_g c_v,He T = U (u⁰: the vapour's ideal-gas energy,
/// [`crate::fluids::FluidProps::vapor_ideal`]; e_0: [`vapor_energy_offset`]), by Newton from the
/// root of the ideal gas linearised at the middle of the liquid range, until a step below
/// 1e-7 T has been taken (then within 1e-13 T of the root, [`ULLAGE_NEWTON_STEP_TOL`]; each lane
/// stops moving on its own; three steps at MHTB conditions, five near saturation at 2 MPa,
/// where the start is 20 K low). Also returns the vapour's state and ideal-gas energy there.
pub fn ullage_temperature<T: Real>(
    fluid: crate::fluids::Fluid,
    m_v: T,
    m_g: T,
    u_j: T,
    rho_v: T,
) -> (T, UllageVapor<T>) {
    let f = fluid.props();
    let off = vapor_energy_offset(fluid);
    let t_r = 0.5 * (f.t_min_k + f.t_max_k);
    let (u_r, cv_r) = f.vapor_ideal(t_r);
    let cv_g = m_g * HELIUM.cv_j_per_kg_k;
    let mut t = (u_j - m_v * (off + u_r - cv_r * t_r)) / (m_v * cv_r + cv_g);
    let mut done = T::Mask::splat(false);
    for _ in 0..ULLAGE_NEWTON_MAX {
        let v = f.vapor_state(t, rho_v);
        let (u0, cv0) = f.vapor_ideal(t);
        let r = m_v * (u0 + off + v.u_res_j_per_kg) + cv_g * t - u_j;
        let step = r / (m_v * (cv0 + v.du_res_dt) + cv_g);
        t = T::select(done, t, t - step);
        done = done | step.abs().le(t.abs() * ULLAGE_NEWTON_STEP_TOL) | step.is(f64::is_nan);
        if done.all() {
            break;
        }
    }
    let (u0, cv0) = f.vapor_ideal(t);
    let vapor = UllageVapor {
        state: f.vapor_state(t, rho_v),
        u0_j_per_kg: u0,
        cv0_j_per_kg_k: cv0,
    };
    (t, vapor)
}

/// Slosh angle, rad: the pendulum angle (`lumped`) or atan(x_1 / L_1) (`two_mode`).
pub fn slosh_angle<T: Real>(g: Group<'_>, s: &State<T>, sl: &SloshParams<T>) -> T {
    if g.shared().fidelity.two_mode_slosh() {
        (s[Q1] / sl.length_m[0]).map(f64::atan)
    } else {
        s[Q1]
    }
}

/// The second mode's equivalent angle atan(|x_2| / L_2), rad (`two_mode`; 0 otherwise): the
/// wave slope that the validity check holds to the same range as the first mode's. A 0.1 mm
/// shake at f2 of the 43 L LN2 tank swung x_2 to 0.036 m (~0.9 rad) unflagged while θ_1 stayed
/// at 0.005 rad.
pub fn mode2_angle<T: Real>(g: Group<'_>, s: &State<T>, sl: &SloshParams<T>) -> T {
    if g.shared().fidelity.two_mode_slosh() {
        (s[Q2].abs() / sl.length_m[1]).map(f64::atan)
    } else {
        c(0.0)
    }
}
