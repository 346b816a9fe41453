//! Heat- and mass-transfer closures (MODEL.md §4): natural-convection correlations, Schrage
//! evaporation coefficient, orifice flow.
//!
//! Correlations are smooth in their arguments (no regime switches) so that the fixed-step
//! integrator and the f32 GPU mirror see the same continuous right-hand side.

use crate::lanes::{c, Real};
use std::f64::consts::PI;

/// Fluid properties a convection correlation needs, SI.
#[derive(Clone, Copy, Debug)]
pub struct ConvectionProps<T = f64> {
    /// Thermal conductivity, W/(m·K).
    pub k: T,
    /// Dynamic viscosity, Pa·s.
    pub mu: T,
    /// Density, kg/m³.
    pub rho: T,
    /// Specific heat at constant pressure, J/(kg·K).
    pub cp: T,
    /// Volumetric expansion coefficient, 1/K.
    pub beta: T,
}

/// Rayleigh number g β |ΔT| L³ / (ν α) and Prandtl number.
fn rayleigh<T: Real>(p: &ConvectionProps<T>, accel: T, dt_k: T, length_m: T) -> (T, T) {
    let nu = p.mu / p.rho;
    let alpha = p.k / (p.rho * p.cp);
    let l3 = length_m * length_m * length_m;
    let ra = accel.max_c(0.0) * p.beta.abs() * dt_k.abs() * l3 / (nu * alpha);
    (ra, nu / alpha)
}

/// Vertical-wall natural convection, Churchill & Chu (1975), valid for all Ra:
/// Nu = {0.825 + 0.387 Ra^(1/6) / [1 + (0.492/Pr)^(9/16)]^(8/27)}². Returns h, W/(m²·K).
pub fn h_vertical_wall<T: Real>(p: &ConvectionProps<T>, accel: T, dt_k: T, length_m: T) -> T {
    let length = length_m.max_c(1.0e-3);
    let (ra, pr) = rayleigh(p, accel, dt_k, length);
    let f = (pr.rdiv(0.492).powf(c(9.0 / 16.0)) + 1.0).powf(c(8.0 / 27.0));
    // Ra^(1/6) = exp(ln Ra / 6): both branch-free lane kernels (Ra = 0 gives 0).
    let nu = (ra.ln() * (1.0 / 6.0)).exp() * 0.387 / f + 0.825;
    nu * nu * p.k / length
}

/// Stably stratified horizontal interface (warm fluid above a cold surface): Nu = 0.27 Ra^(1/4)
/// (McAdams; Incropera & DeWitt eq. 9.32), plus the conduction floor Nu = 1. Length = A/P.
pub fn h_stable_interface<T: Real>(p: &ConvectionProps<T>, accel: T, dt_k: T, length_m: T) -> T {
    let length = length_m.max_c(1.0e-3);
    let (ra, _) = rayleigh(p, accel, dt_k, length);
    (ra.sqrt().sqrt() * 0.27 + 1.0) * p.k / length
}

/// Unstable horizontal interface (dense cold fluid above warm fluid): Nu = 0.15 Ra^(1/3)
/// (Lloyd & Moran 1974; Incropera & DeWitt eq. 9.31), 0 for a stable (ΔT ≤ 0) configuration.
/// `dt_unstable_k` is the temperature excess of the lower fluid. Length = A/P.
pub fn h_unstable_interface<T: Real>(
    p: &ConvectionProps<T>,
    accel: T,
    dt_unstable_k: T,
    length_m: T,
) -> T {
    let length = length_m.max_c(1.0e-3);
    let (ra, _) = rayleigh(p, accel, dt_unstable_k.max_c(0.0), length);
    (ra.ln() * (1.0 / 3.0)).exp() * 0.15 * p.k / length
}

/// Linearly implicit limiter for a stiff exchange between two heat capacities: the conductance
/// `ua` (W/K) becomes ua / (1 + dt·ua·(1/C_a + 1/C_b)), so the exchanged heat never overshoots
/// equilibrium within a step (a thin cryogenic wall relaxes in milliseconds). Exact as dt → 0.
pub fn limited_conductance<T: Real>(ua: T, dt: T, c_a: T, c_b: T) -> T {
    ua / (dt * ua * (c_a.rdiv(1.0) + c_b.rdiv(1.0)) + 1.0)
}

/// Heat from a wall node into a fluid node over a step of length `dt`, W: one implicit Euler
/// step of the temperature difference ΔT = T_wall − T_fluid, dΔT/dt = F − q (1/C_wall +
/// 1/C_fluid), with q = ua ΔT and F = `forcing_k_s` the rate at which the wall warms on its own
/// (heat leak / wall heat capacity). q = ua (ΔT + dt F) / (1 + dt ua (1/C_wall + 1/C_fluid)):
/// stable at any step, ua ΔT as dt → 0, and — F included — the physical quasi-steady ΔT at any
/// step, where without F the wall would hold dt·F too much (an error an embedded Runge–Kutta
/// estimate cannot see).
pub fn wall_exchange<T: Real>(
    ua: T,
    dt: T,
    c_wall: T,
    c_fluid: T,
    dtemp_k: T,
    forcing_k_s: T,
) -> T {
    limited_conductance(ua, dt, c_wall, c_fluid) * (dtemp_k + dt * forcing_k_s)
}

/// Schrage kinetic-theory interfacial coefficient K = A · 2σ/(2−σ) · sqrt(M / (2π R_u T)),
/// kg/(s·Pa) (Schrage 1953; MODEL.md §4).
pub fn schrage_coefficient<T: Real>(area_m2: T, accommodation: T, molar_mass: f64, t_k: T) -> T {
    let s = accommodation;
    area_m2 * 2.0 * s / s.rsub(2.0)
        * (t_k * (2.0 * PI * crate::fluids::R_UNIVERSAL))
            .rdiv(molar_mass)
            .sqrt()
}

/// Ideal-gas orifice mass flow from `p_up` to `p_down` through C_d·A = `area_m2`, choked or
/// subsonic (isentropic nozzle), kg/s. `r` specific gas constant, `gamma` cp/cv, `t_k` upstream.
pub fn orifice_flow<T: Real>(area_m2: T, p_up: T, p_down: T, t_k: T, r: T, gamma: T) -> T {
    let g = gamma;
    let pr_crit = (g + 1.0).rdiv(2.0).powf(g / (g - 1.0));
    let pr = (p_down / p_up).max(pr_crit);
    let flux = (g * 2.0 / ((g - 1.0) * r * t_k) * (pr.powf(g.rdiv(2.0)) - pr.powf((g + 1.0) / g)))
        .max_c(0.0)
        .sqrt();
    let closed = p_up.le(p_down) | p_up.le(c(0.0));
    T::select(closed, c(0.0), area_m2 * p_up * flux)
}
