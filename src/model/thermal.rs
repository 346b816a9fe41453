//! Heat- and mass-transfer closures (MODEL.md §4): natural-convection correlations, Schrage
//! evaporation coefficient, orifice flow.
//!
//! Correlations are smooth in their arguments (no regime switches) so that the fixed-step
//! integrator and the f32 GPU mirror see the same continuous right-hand side.

use std::f64::consts::PI;

/// Fluid properties a convection correlation needs, SI.
#[derive(Clone, Copy, Debug)]
pub struct ConvectionProps {
    /// Thermal conductivity, W/(m·K).
    pub k: f64,
    /// Dynamic viscosity, Pa·s.
    pub mu: f64,
    /// Density, kg/m³.
    pub rho: f64,
    /// Specific heat at constant pressure, J/(kg·K).
    pub cp: f64,
    /// Volumetric expansion coefficient, 1/K.
    pub beta: f64,
}

/// Rayleigh number g β |ΔT| L³ / (ν α) and Prandtl number.
fn rayleigh(p: &ConvectionProps, accel: f64, dt_k: f64, length_m: f64) -> (f64, f64) {
    let nu = p.mu / p.rho;
    let alpha = p.k / (p.rho * p.cp);
    let ra = accel.max(0.0) * p.beta.abs() * dt_k.abs() * length_m.powi(3) / (nu * alpha);
    (ra, nu / alpha)
}

/// Vertical-wall natural convection, Churchill & Chu (1975), valid for all Ra:
/// Nu = {0.825 + 0.387 Ra^(1/6) / [1 + (0.492/Pr)^(9/16)]^(8/27)}². Returns h, W/(m²·K).
pub fn h_vertical_wall(p: &ConvectionProps, accel: f64, dt_k: f64, length_m: f64) -> f64 {
    let length = length_m.max(1.0e-3);
    let (ra, pr) = rayleigh(p, accel, dt_k, length);
    let f = (1.0 + (0.492 / pr).powf(9.0 / 16.0)).powf(8.0 / 27.0);
    // Ra^(1/6) as cbrt(√Ra): two cheap roots instead of a general power.
    let nu = 0.825 + 0.387 * ra.sqrt().cbrt() / f;
    nu * nu * p.k / length
}

/// Stably stratified horizontal interface (warm fluid above a cold surface): Nu = 0.27 Ra^(1/4)
/// (McAdams; Incropera & DeWitt eq. 9.32), plus the conduction floor Nu = 1. Length = A/P.
pub fn h_stable_interface(p: &ConvectionProps, accel: f64, dt_k: f64, length_m: f64) -> f64 {
    let length = length_m.max(1.0e-3);
    let (ra, _) = rayleigh(p, accel, dt_k, length);
    (1.0 + 0.27 * ra.sqrt().sqrt()) * p.k / length
}

/// Unstable horizontal interface (dense cold fluid above warm fluid): Nu = 0.15 Ra^(1/3)
/// (Lloyd & Moran 1974; Incropera & DeWitt eq. 9.31), 0 for a stable (ΔT ≤ 0) configuration.
/// `dt_unstable_k` is the temperature excess of the lower fluid. Length = A/P.
pub fn h_unstable_interface(
    p: &ConvectionProps,
    accel: f64,
    dt_unstable_k: f64,
    length_m: f64,
) -> f64 {
    let length = length_m.max(1.0e-3);
    let (ra, _) = rayleigh(p, accel, dt_unstable_k.max(0.0), length);
    0.15 * ra.cbrt() * p.k / length
}

/// Linearly implicit limiter for a stiff exchange between two heat capacities: the conductance
/// `ua` (W/K) becomes ua / (1 + dt·ua·(1/C_a + 1/C_b)), so the exchanged heat never overshoots
/// equilibrium within a step (a thin cryogenic wall relaxes in milliseconds). Exact as dt → 0.
pub fn limited_conductance(ua: f64, dt: f64, c_a: f64, c_b: f64) -> f64 {
    ua / (1.0 + dt * ua * (1.0 / c_a + 1.0 / c_b))
}

/// Schrage kinetic-theory interfacial coefficient K = A · 2σ/(2−σ) · sqrt(M / (2π R_u T)),
/// kg/(s·Pa) (Schrage 1953; MODEL.md §4).
pub fn schrage_coefficient(area_m2: f64, accommodation: f64, molar_mass: f64, t_k: f64) -> f64 {
    let s = accommodation;
    area_m2 * 2.0 * s / (2.0 - s)
        * (molar_mass / (2.0 * PI * crate::fluids::R_UNIVERSAL * t_k)).sqrt()
}

/// Ideal-gas orifice mass flow from `p_up` to `p_down` through C_d·A = `area_m2`, choked or
/// subsonic (isentropic nozzle), kg/s. `r` specific gas constant, `gamma` cp/cv, `t_k` upstream.
pub fn orifice_flow(area_m2: f64, p_up: f64, p_down: f64, t_k: f64, r: f64, gamma: f64) -> f64 {
    if p_up <= p_down || p_up <= 0.0 {
        return 0.0;
    }
    let g = gamma;
    let pr_crit = (2.0 / (g + 1.0)).powf(g / (g - 1.0));
    let pr = (p_down / p_up).max(pr_crit);
    let flux = (2.0 * g / ((g - 1.0) * r * t_k) * (pr.powf(2.0 / g) - pr.powf((g + 1.0) / g)))
        .max(0.0)
        .sqrt();
    area_m2 * p_up * flux
}
