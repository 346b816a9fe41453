//! State vector layout and the initial state (MODEL.md §4).
//!
//! The state holds conserved quantities (masses and energies), never temperatures, so that the
//! Runge–Kutta step preserves total mass and energy to rounding: RK methods keep every linear
//! invariant exactly, and every flux here leaves one slot and enters another. Temperatures are
//! recovered from energies in [`super::derive`]. Accumulators of what crossed the tank boundary
//! (vented, drawn, pressurant, heat) live in the same vector for the same reason.

use super::params::{Fidelity, Params};
use crate::fluids::{Fluid, FluidProps, HELIUM};
use std::sync::OnceLock;

/// Vapour mass in the ullage, kg.
pub const M_V: usize = 0;
/// Helium mass in the ullage, kg.
pub const M_G: usize = 1;
/// Ullage internal energy, J (`lumped`/`two_mode`).
pub const U_U: usize = 2;
/// Stratified-layer mass, kg (0 at `layered`).
pub const M_S: usize = 3;
/// Stratified-layer enthalpy m_s h_l(T_s), J (0 at `layered`).
pub const H_S: usize = 4;
/// Bulk-liquid mass, kg (`homogeneous`: all propellant, liquid + vapour; `layered`: all liquid,
/// the column's layers holding fixed shares of it).
pub const M_B: usize = 5;
/// Bulk-liquid enthalpy, J (`homogeneous`: energy of all fluid incl. helium; 0 at `layered`,
/// whose enthalpies are the column's slots from [`COL`]).
pub const H_B: usize = 6;
/// Dry-wall energy m c_w T, J.
pub const E_WD: usize = 7;
/// Wetted-wall energy, J.
pub const E_WW: usize = 8;
/// Pendulum angle θ, rad (`lumped`) or mode-1 displacement x_1, m (`two_mode`).
pub const Q1: usize = 9;
/// Its rate.
pub const Q1D: usize = 10;
/// Mode-2 displacement x_2, m (`two_mode`).
pub const Q2: usize = 11;
/// Its rate.
pub const Q2D: usize = 12;
/// Vehicle velocity, m/s.
pub const VEL: usize = 13;
/// Altitude, m.
pub const ALT: usize = 14;
/// Low-pass filtered ullage pressure for the pressurization D-term, Pa.
pub const P_FILT: usize = 15;
/// Vented vapour, kg.
pub const VENT_V: usize = 16;
/// Vented helium, kg.
pub const VENT_G: usize = 17;
/// Propellant drawn by the engine, kg.
pub const OUT: usize = 18;
/// Helium admitted, kg.
pub const PRESS_IN: usize = 19;
/// ∫ Q_env dt, J.
pub const E_ENV: usize = 20;
/// ∫ ṁ_press h_He dt, J.
pub const E_PRESS: usize = 21;
/// Energy carried out by the vents, J: ∫ ṁ_vent h_u dt through the relief valve plus
/// ∫ ṁ_tvs h_out dt through the thermodynamic vent system (`model::tvs`).
pub const E_VENT: usize = 22;
/// ∫ ṁ_out h_l dt, J.
pub const E_OUT: usize = 23;
/// ∫ −P dΔV_slosh dt, J (work of the paper's coupling-I volume term; 0 when c_V = 0).
pub const E_WORK: usize = 24;
/// ∫ Q_pump dt, J: the pump heat of the jet mixer (`model::mixer`) and of the thermodynamic
/// vent system's recirculation pump (`model::tvs`) dissipated in the liquid.
pub const E_PUMP: usize = 25;
/// Propellant vented by the thermodynamic vent system, kg (`model::tvs`).
pub const VENT_TVS: usize = 26;
/// First of the `layered` column's enthalpy slots, J: slot `COL + k` holds m_k h_l(T_k) of layer
/// k, counted from the bottom (`model::column`); 0 at the other levels.
pub const COL: usize = 27;
/// Most layers a `layered` column may have (`layered.layers`): the state is one fixed-size array
/// for every level, and the GPU kernels carry it per invocation (docs/GPU.md).
pub const NL_MAX: usize = 40;
/// Number of state slots.
pub const NS: usize = COL + NL_MAX;

/// The slots the level `fidelity` with `layers` column layers uses: the leading slots of the
/// state; the integrators step only these.
pub fn slots_used(fidelity: Fidelity, layers: u32) -> usize {
    match fidelity {
        Fidelity::Layered => COL + layers as usize,
        _ => COL,
    }
}

/// A state vector (one per lane group: slot by slot, each slot a lane vector).
pub type State<T = f64> = [T; NS];

/// Lane `i` of a lane group's state.
pub fn lane<T: crate::lanes::Real>(s: &State<T>, i: usize) -> State {
    std::array::from_fn(|j| s[j].lane(i))
}

/// [`lane`] into `out` over the first `n` slots, for a caller whose `out` is 0 past them, as
/// are a state's slots past its level's ([`slots_used`]).
pub fn lane_into<T: crate::lanes::Real>(s: &State<T>, i: usize, n: usize, out: &mut State) {
    for (o, v) in out[..n].iter_mut().zip(&s[..n]) {
        *o = v.lane(i);
    }
    debug_assert!(out[n..].iter().zip(&s[n..]).all(|(o, v)| *o == v.lane(i)));
}

/// Internal-energy reference of the real-gas vapour (MODEL.md §4, consistent references):
/// u_v(T, ρ) = u⁰(T) + offset + u_res(T, ρ) (`fluids::vapor`), the offset chosen so that the
/// saturated vapour's enthalpy u_v + P_sat/ρ_v exceeds h_l by h_fg at the normal boiling point
/// (through the fits it then does so within 1e-3 of h_fg along the whole saturation line). Fixed
/// per fluid so that dispersed inputs never move a reference; computed once (it needs a T_sat
/// solve, which the right-hand side must not repeat).
pub fn vapor_energy_offset(fluid: Fluid) -> f64 {
    static OFFSETS: OnceLock<[f64; Fluid::ALL.len()]> = OnceLock::new();
    let table = OFFSETS.get_or_init(|| Fluid::ALL.map(|fl| vapor_energy_offset_of(fl.props())));
    let i = Fluid::ALL.iter().position(|&x| x == fluid).unwrap_or(0);
    table[i]
}

/// The offset of [`vapor_energy_offset`] computed for fit `f` (one T_sat solve).
pub fn vapor_energy_offset_of(f: &FluidProps) -> f64 {
    let t = f.tsat_k(101_325.0);
    let rho_v = f.rho_v_sat_kg_per_m3(t);
    let h_v = f.h_l_j_per_kg(t) + f.h_fg_j_per_kg(t);
    h_v - f.psat_pa(t) / rho_v - f.vapor_ideal(t).0 - f.vapor_u_res_j_per_kg(t, rho_v)
}

/// Initial wetted fraction of the wall and the liquid level for the initial fill.
fn initial_level(p: &Params) -> (f64, f64) {
    let v_l = p.fill_fraction * p.tank.volume_m3();
    let z = p.tank.liquid_height_m(v_l);
    (
        z,
        super::derive::wetted_share(&super::Group::one(p).tank(), z).0,
    )
}

/// Initial vapour partial pressure, Pa: the ullage pressure less the helium partial pressure.
pub fn initial_vapor_pressure_pa(p: &Params) -> f64 {
    vapor_partial_pressure_pa(
        p.fluid,
        p.ullage_pressure_pa,
        p.ullage_helium_partial_pressure_pa,
        p.liquid_temperature_k,
    )
}

/// Default helium partial pressure, Pa: the ullage pressure `p_ullage_pa` less the vapour
/// saturated at the liquid temperature `t_liquid_k` (at most the whole pressure), and exactly 0
/// where that difference is below [`SATURATED_RESIDUE`] of the pressure. A liquid saturated at
/// the ullage pressure (`propellant.temperature_k` omitted, T_l = T_sat(P_u)) gives
/// P_sat(T_l) = P_u to a few ulps, not exactly (MHTB at 111.5 kPa: 2.9e-11 Pa short), and that
/// residue would otherwise start the tank with about 1e-15 kg of helium it was never given.
pub fn default_helium_pressure_pa(fluid: Fluid, p_ullage_pa: f64, t_liquid_k: f64) -> f64 {
    let rest = p_ullage_pa - fluid.props().psat_pa(t_liquid_k).min(p_ullage_pa);
    if rest <= SATURATED_RESIDUE * p_ullage_pa {
        0.0
    } else {
        rest
    }
}

/// Share of the ullage pressure below which [`default_helium_pressure_pa`]'s difference
/// P_u − P_sat(T_l) is the property fits' round trip P_sat(T_sat(P)), not helium: that round
/// trip is good to a few ulps (2.6e-16 relative at MHTB's 111.5 kPa), and a helium partial
/// pressure of 1e-13 P_u changes nothing physical. Below the 1e-12 by which the composition
/// check lets vapour exceed P_sat(T_u), so that the vapour at P_u it leaves always passes.
pub const SATURATED_RESIDUE: f64 = 1.0e-13;

/// Vapour partial pressure P_u − P_He, Pa, for ullage pressure `p_ullage_pa` and helium partial
/// pressure `p_helium_pa`. For a default helium above the round-trip residue it is
/// min(P_sat(T_l), P_u) itself, not P_u − (P_u − P_sat) rounded; a saturated liquid's ullage
/// (no helium) is vapour at P_u.
pub fn vapor_partial_pressure_pa(
    fluid: Fluid,
    p_ullage_pa: f64,
    p_helium_pa: f64,
    t_liquid_k: f64,
) -> f64 {
    let saturated = fluid.props().psat_pa(t_liquid_k).min(p_ullage_pa);
    if p_helium_pa == p_ullage_pa - saturated {
        saturated
    } else {
        (p_ullage_pa - p_helium_pa).max(0.0)
    }
}

/// Default initial layer temperature, K: saturation at the initial vapour partial pressure
/// `p_vapor_pa`, clamped to the fluid's range. Exactly the liquid temperature `t_liquid_k` when
/// the vapour is saturated at it (the default composition over a subcooled liquid). A liquid
/// saturated at the ullage pressure has no default helium ([`SATURATED_RESIDUE`]) and vapour at
/// P_u: its layer is T_sat(P_u), the liquid temperature itself where that was defaulted (the
/// campaign's T_l is the same `tsat_k` call).
pub fn default_layer_temperature_k(fluid: Fluid, t_liquid_k: f64, p_vapor_pa: f64) -> f64 {
    let f = fluid.props();
    if p_vapor_pa == f.psat_pa(t_liquid_k) {
        t_liquid_k
    } else {
        f.tsat_k(p_vapor_pa.clamp(f.psat_pa(f.t_min_k), f.psat_pa(f.t_max_k)))
    }
}

/// The initial state: liquid at `liquid_temperature_k` with its surface layer at
/// `stratification.initial_temperature_k`; ullage at `ullage_temperature_k` holding helium at
/// `ullage_helium_partial_pressure_pa` and real-gas vapour (CoolProp's density at T_u and its
/// partial pressure, `fluids::vapor`) at the rest of `ullage_pressure_pa`; wetted wall at the
/// liquid temperature, dry wall at `dry_wall_temperature_k`; vehicle at its initial flight state.
///
/// The `homogeneous` level is an equilibrium: it keeps the stated propellant (liquid + vapour)
/// and helium masses, but its vapour is saturated at the liquid temperature whatever partial
/// pressure the campaign states, and all of it starts at the liquid temperature.
pub fn initial_state(p: &Params) -> State {
    let f = p.fluid.props();
    let mut s = [0.0; NS];
    let t_l = p.liquid_temperature_k;
    let rho = f.rho_l_kg_per_m3(t_l);
    let v_tank = p.tank.volume_m3();
    let v_l = p.fill_fraction * v_tank;
    let v_u = v_tank - v_l;
    let t_u = p.ullage_temperature_k;
    let p_g = p.ullage_helium_partial_pressure_pa;
    let p_v = initial_vapor_pressure_pa(p);
    let m_v = f.vapor_density_kg_per_m3(t_u, p_v) * v_u;
    let m_g = p_g * v_u / (HELIUM.r_specific_j_per_kg_k() * t_u);
    let m_l = rho * v_l;
    s[M_V] = m_v;
    s[M_G] = m_g;
    match p.fidelity {
        Fidelity::Homogeneous => {
            // One equilibrium node: liquid, vapour and helium at the liquid temperature. The
            // stated propellant inventory is kept; the equilibrium splits it into liquid and
            // vapour saturated at T_l.
            s[M_B] = m_l + m_v;
            s[H_B] = super::homogeneous::fluid_energy(super::Group::one(p), m_l + m_v, m_g, t_l);
            s[M_V] = 0.0;
        }
        Fidelity::Lumped | Fidelity::TwoMode => {
            let (z, _) = initial_level(p);
            let area = p.tank.interface_area_m2(z).max(1.0e-6);
            let t_s = p.stratification.initial_temperature_k;
            let thickness = p.stratification.initial_thickness_m;
            // The layer fills its thickness at its own density, the bulk the rest of the liquid
            // volume (so that the ullage volume, hence the pressure, is the stated one).
            let (m_s, m_b) = if t_s == t_l {
                let m_s = (rho * area * thickness).min(0.5 * m_l);
                (m_s, m_l - m_s)
            } else {
                let rho_s = f.rho_l_kg_per_m3(t_s);
                let v_s = (area * thickness).min(0.5 * v_l);
                (rho_s * v_s, rho * (v_l - v_s))
            };
            let u_v = f.vapor_ideal(t_u).0
                + vapor_energy_offset(p.fluid)
                + f.vapor_u_res_j_per_kg(t_u, m_v / v_u);
            s[U_U] = m_v * u_v + m_g * HELIUM.cv_j_per_kg_k * t_u;
            s[M_S] = m_s;
            s[H_S] = m_s * f.h_l_j_per_kg(t_s);
            s[M_B] = m_b;
            s[H_B] = m_b * f.h_l_j_per_kg(t_l);
        }
        Fidelity::Layered => {
            let u_v = f.vapor_ideal(t_u).0
                + vapor_energy_offset(p.fluid)
                + f.vapor_u_res_j_per_kg(t_u, m_v / v_u);
            s[U_U] = m_v * u_v + m_g * HELIUM.cv_j_per_kg_k * t_u;
            super::column::initial_column(p, &mut s);
        }
    }
    let (_, wet) = initial_level(p);
    let m_wall = p.wall_mass_kg();
    s[E_WD] = m_wall * (1.0 - wet) * p.wall_cp_j_per_kg_k * p.dry_wall_temperature_k;
    s[E_WW] = m_wall * wet * p.wall_cp_j_per_kg_k * t_l;
    s[VEL] = p.vehicle.initial_velocity_m_s;
    s[ALT] = p.vehicle.initial_altitude_m;
    s[P_FILT] = p.ullage_pressure_pa;
    s
}

/// Propellant vapour admitted as autogenous pressurant so far, kg (0 for helium): boil-off counts
/// the vapour the liquid made, not the vapour the pressurization brought.
pub fn vapor_pressurant_kg(p: &Params, s: &State) -> f64 {
    p.pressurant_vapor_share() * s[PRESS_IN]
}

/// Total propellant + helium mass in the tank plus everything that left or entered, kg:
/// constant to rounding (MODEL.md §10).
pub fn mass_invariant(s: &State) -> f64 {
    s[M_V] + s[M_G] + s[M_S] + s[M_B] + s[VENT_V] + s[VENT_G] + s[OUT] + s[VENT_TVS] - s[PRESS_IN]
}

/// Internal energy of fluid and wall minus the net energy brought in across the boundary, J:
/// constant to rounding (MODEL.md §10).
pub fn energy_invariant(s: &State) -> f64 {
    let inside = s[U_U] + s[H_S] + s[H_B] + s[E_WD] + s[E_WW] + s[COL..].iter().sum::<f64>();
    inside - (s[E_ENV] + s[E_PRESS] - s[E_VENT] - s[E_OUT] + s[E_WORK] + s[E_PUMP])
}
