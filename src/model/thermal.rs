//! Heat- and mass-transfer closures (MODEL.md §4): natural-convection correlations, Schrage
//! evaporation coefficient, orifice flow.
//!
//! Correlations are smooth in their arguments (no regime switches) so that the fixed-step
//! integrator and the f32 GPU mirror see the same continuous right-hand side.

use crate::lanes::{c, Mask, Real};
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

/// Rayleigh number g β |ΔT| L³ / (ν α) and Prandtl number ν/α, with ν = μ/ρ and α = k/(ρ c_p)
/// substituted: Ra = g β |ΔT| L³ ρ² c_p / (μ k), Pr = μ c_p / k = μ² c_p / (μ k): one divide
/// for both, not four.
fn rayleigh<T: Real>(p: &ConvectionProps<T>, accel: T, dt_k: T, length_m: T) -> (T, T) {
    let l3 = length_m * length_m * length_m;
    let drive = accel.max_c(0.0) * p.beta.abs() * dt_k.abs() * l3;
    let inv_mu_k = (p.mu * p.k).rdiv(1.0);
    let ra = drive * (p.rho * p.rho * p.cp) * inv_mu_k;
    (ra, p.mu * p.mu * p.cp * inv_mu_k)
}

/// ln 0.492, the Prandtl-number constant of Churchill & Chu's correlation.
const LN_CHURCHILL_CHU_PR: f64 = -0.709_276_562_489_829;

/// Vertical-wall natural convection, Churchill & Chu (1975), valid for all Ra:
/// Nu = {0.825 + 0.387 Ra^(1/6) / [1 + (0.492/Pr)^(9/16)]^(8/27)}². Returns h, W/(m²·K).
///
/// The powers are taken in logarithms, 0.387 exp(ln Ra / 6 − (8/27) ln(1 + e^((9/16)(ln 0.492 −
/// ln Pr)))): three `ln` and two `exp`, where two `pow` (each an `ln` and an `exp`), an `exp`
/// and a `ln` were three of each, and two divides fewer (Ra = 0 gives ln Ra = −∞ and
/// Nu = 0.825², as before).
pub fn h_vertical_wall<T: Real>(p: &ConvectionProps<T>, accel: T, dt_k: T, length_m: T) -> T {
    let length = length_m.max_c(1.0e-3);
    let (ra, pr) = rayleigh(p, accel, dt_k, length);
    let pr_term = ((pr.ln().rsub(LN_CHURCHILL_CHU_PR)) * (9.0 / 16.0)).exp();
    let ln_core = (pr_term + 1.0)
        .ln()
        .mul_add(c(-8.0 / 27.0), ra.ln() * (1.0 / 6.0));
    let nu = ln_core.exp().mul_add_c(c(0.387), 0.825);
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
    // A stable pair has Ra = 0, and Ra^(1/3) = e^(ln 0 / 3) = e^(−∞) = +0 exactly
    // (`lanes::math`): where every lane has Ra = 0 the two kernels are left out, the same bits
    // (the usual case: a warm layer over the bulk, or a column stratified stably).
    let cube_root = if ra.is_zero().all() {
        c(0.0)
    } else {
        (ra.ln() * (1.0 / 3.0)).exp()
    };
    cube_root * 0.15 * p.k / length
}

/// Order of the stiff blend ([`stiff_blend`]): it changes the rate of a mode the step resolves by
/// O(z^6), a local error O(h^7), one order beyond the fifth-order solution Dormand–Prince
/// propagates, so that the pair's own error estimate, not the blend, sets the accuracy there.
pub const STIFF_BLEND_ORDER: u32 = 6;

/// Weights (a, w) of a stiff scalar relaxation's rate over a step, r = K (a Δ + w h F), for
/// dΔ/dt = F − J r with z = h K J (dimensionless: the step over the relaxation time 1/(K J)):
///
/// a = S₅(z) / S₆(z),  w = z⁵ / S₆(z),  S_n(z) = 1 + z + … + zⁿ.
///
/// - **Resolved mode** (z ≪ 1): a = 1 − z⁶ + …, w = z⁵ + …: the explicit rate K Δ to O(z⁶), which
///   the Runge–Kutta pair integrates and its error estimate sees. Implicit Euler, a = w =
///   1/(1 + z), changes it by O(z): the rate K Δ(t + h), a first-order lead no embedded estimate
///   sees (it moved boil-off by 3.4e-4 on the LOX ascent, whose helium-limited evaporation relaxes
///   in minutes); so does the exact step average a = (1 − e^(−z))/z, w = (1 − a)/z, by O(z/2).
/// - **Stiff mode** (z ≫ 1): a, w → 1/z: implicit Euler's limit, r = F/J + (Δ − Δ*)/(h J) with
///   Δ* = F/(K J): a residual relaxes within the step.
/// - **At any step** dΔ/dt = a K J (Δ* − Δ), since 1 − a = z w: the quasi-steady rate is F/J
///   (minus the physical lag Δ*'/J), independent of h, as with implicit Euler; and the stages see
///   the mode at h λ_eff = z a(z) = 1 − 1/S₆(z) < 1, inside the stability interval of RK4 (2.78)
///   and of Dormand–Prince (3.3), at any z.
///
/// Construction: the rational blend between the explicit rate (a = 1) and implicit Euler's
/// (a = 1/(1 + z)) of these two limits, chosen here; the order argument for a resolved mode is the
/// modified-equation one (Hairer, Nørsett & Wanner I, §II.3), the stiff limit that of singular
/// perturbation (Hairer & Wanner II, §VI.3). Evaluated in 1/z beyond z = 1 (no overflow in f32):
/// a = u S₅(u)/S₆(u), w = u/S₆(u), u = 1/z.
pub fn stiff_blend<T: Real>(z: T) -> (T, T) {
    let big = z.gt(c(1.0));
    let v = T::select(big, z.rdiv(1.0), z);
    // S₅(v) by Horner, v⁵ alongside (p − 1 = 5 for the order p).
    let mut s_lo = c::<T>(1.0);
    let mut v_lo = c::<T>(1.0);
    for _ in 1..STIFF_BLEND_ORDER {
        s_lo = s_lo.mul_add_c(v, 1.0);
        v_lo *= v;
    }
    let s_hi = v_lo.mul_add(v, s_lo);
    // One divide for both weights (S₆ ≥ 1, so its reciprocal is as accurate as the quotients).
    let inv_s_hi = s_hi.rdiv(1.0);
    let a = s_lo * inv_s_hi * T::select(big, v, c(1.0));
    let w = T::select(big, v, v_lo) * inv_s_hi;
    (a, w)
}

/// Heat from a wall node into a fluid node over a step of length `dt`, W: the temperature
/// difference ΔT = T_wall − T_fluid relaxes as dΔT/dt = F − q (1/C_wall + 1/C_fluid), q = ua ΔT,
/// F = `forcing_k_s` the rate at which the wall warms on its own (heat leak / wall heat
/// capacity, K/s); a thin cryogenic wall relaxes in milliseconds. q = ua (a ΔT + w dt F) with
/// ([`stiff_blend`]) z = dt ua (1/C_wall + 1/C_fluid): ua ΔT to O(z⁶) where the step resolves
/// the exchange, implicit Euler's ua (ΔT + dt F)/(1 + z) where it does not; with F included the
/// quasi-steady q is the physical one at any step.
pub fn wall_exchange<T: Real>(
    ua: T,
    dt: T,
    c_wall: T,
    c_fluid: T,
    dtemp_k: T,
    forcing_k_s: T,
) -> T {
    // 1/C_wall + 1/C_fluid as (C_wall + C_fluid)/(C_wall C_fluid): one divide, not two.
    let z = dt * ua * ((c_wall + c_fluid) / (c_wall * c_fluid));
    let (a, w) = stiff_blend(z);
    ua * (a * dtemp_k + w * dt * forcing_k_s)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The blend's properties (docs/INTEGRATION.md): 1 − a = z w at any z (the quasi-steady rate
    /// F/J whatever the step), the explicit rate to O(z⁶) for a resolved mode, implicit Euler's
    /// 1/z for a stiff one, h λ_eff = z a < 1 (stable explicit stages; ≤ 1 after rounding),
    /// continuous across the switch to the 1/z evaluation at z = 1, no overflow at z = 1e12.
    #[test]
    fn stiff_blend_limits() {
        for &z in &[
            0.0, 1e-3, 0.1, 0.5, 0.999_999, 1.0, 1.000_001, 2.0, 10.0, 1e3, 1e6, 1e12,
        ] {
            let (a, w) = stiff_blend(z);
            assert!(
                ((1.0 - a) - z * w).abs() <= 1e-15 * (1.0 + z * w),
                "z {z}: {a} {w}"
            );
            assert!(z * a <= 1.0 && a > 0.0 && w >= 0.0, "z {z}: {a} {w}");
        }
        let (a, w) = stiff_blend(1e-2);
        // z = 0.01: 1 − a = z⁶/S₆(z) and w = z⁵/S₆(z), S₆ = 1.0101….
        assert!(((1.0 - a) / 1e-12 * 1.0101 - 1.0).abs() < 1e-3, "{a}");
        assert!((w / 1e-10 * 1.0101 - 1.0).abs() < 1e-4, "{w}");
        let (a, w) = stiff_blend(1e4);
        assert!(
            (a * 1e4 - 1.0).abs() < 1e-12 && (w * 1e4 - 1.0).abs() < 2e-4,
            "{a} {w}"
        );
        let (lo, hi) = (stiff_blend(1.0 - 1e-12), stiff_blend(1.0 + 1e-12));
        assert!((lo.0 - hi.0).abs() < 1e-11 && (lo.1 - hi.1).abs() < 1e-11);
        assert_eq!(stiff_blend(1.0), (6.0 / 7.0, 1.0 / 7.0));
    }

    #[test]
    fn churchill_chu_constant_is_ln_0_492() {
        assert_eq!(LN_CHURCHILL_CHU_PR, 0.492_f64.ln());
    }

    /// The logarithmic form against the correlation as published, on f64 (Ra 1e3..1e15,
    /// Pr 0.5..10).
    #[test]
    fn churchill_chu_in_logarithms_is_the_published_form() {
        for &(ra, pr) in &[
            (1e3, 0.7),
            (1e9, 2.0),
            (3e12, 1.3),
            (1e15, 10.0),
            (5e6, 0.5),
        ] {
            // Properties giving that Ra and Pr at L = 1 m, a = 1 m/s², ΔT = 1 K.
            let (k, mu, cp) = (0.1, 1e-4, pr * 0.1 / 1e-4);
            let rho = (ra * mu * k / cp).sqrt();
            let p = ConvectionProps {
                k,
                mu,
                rho,
                cp,
                beta: 1.0,
            };
            let f = (1.0 + (0.492_f64 / pr).powf(9.0 / 16.0)).powf(8.0 / 27.0);
            let nu = 0.825 + 0.387 * ra.powf(1.0 / 6.0) / f;
            let h = h_vertical_wall(&p, 1.0, 1.0, 1.0);
            assert!(
                (h - nu * nu * k).abs() <= 1e-13 * h,
                "Ra {ra} Pr {pr}: {h} {}",
                nu * nu * k
            );
        }
    }

    /// The stable pair's shortcut in [`h_unstable_interface`] is the kernels' own value: where
    /// Ra = ±0 (ΔT ≤ 0; the model floors the acceleration at 1e-6 m/s², so a zero or negative
    /// one is a guard here), e^(ln Ra / 3) is +0, so leaving the two kernels out moves no bit;
    /// the shortcut is taken (no kernel call counted), a stable lane group gives +0 in every lane,
    /// and a group with one unstable lane evaluates them, each lane as alone.
    #[test]
    fn unstable_interface_shortcut_moves_no_bit() {
        use crate::lanes::{Lanes, Real, WIDTH};
        let p = ConvectionProps {
            k: 0.1,
            mu: 1.3e-5,
            rho: 70.0,
            cp: 9.7e3,
            beta: 0.016,
        };
        let formula = |accel: f64, dt: f64, length: f64| {
            let length = length.max(1.0e-3);
            let (ra, _) = rayleigh(&p, accel, dt.max(0.0), length);
            // The engine's kernels, not std's (an f64 method call would take the inherent one).
            crate::lanes::math::exp(crate::lanes::math::ln(ra) * (1.0 / 3.0)) * 0.15 * p.k / length
        };
        for &(accel, dt) in &[
            (9.81, -2.0),
            (9.81, 0.0),
            (9.81, -0.0),
            (0.0, 3.0),
            (-1e-3, 1.5),
        ] {
            let h = h_unstable_interface(&p, accel, dt, 0.8);
            assert_eq!(
                h.to_bits(),
                formula(accel, dt, 0.8).to_bits(),
                "{accel} {dt}"
            );
            assert_eq!(h.to_bits(), 0.0_f64.to_bits());
        }
        // One unstable lane among stable ones: the group takes the kernels, every lane as alone.
        let dt = Lanes::from_fn(|i| if i == 3 { 0.25 } else { -(i as f64) });
        let lanes = ConvectionProps {
            k: c::<Lanes>(p.k),
            mu: c(p.mu),
            rho: c(p.rho),
            cp: c(p.cp),
            beta: c(p.beta),
        };
        let h = h_unstable_interface(&lanes, c(9.81), dt, c(0.8));
        for i in 0..WIDTH {
            let alone = h_unstable_interface(&p, 9.81, dt.lane(i), 0.8);
            assert_eq!(h.lane(i).to_bits(), alone.to_bits(), "lane {i}");
        }
        assert!(h.lane(3) > 0.0);
        // An all-stable group takes the shortcut: +0 in every lane.
        let stable = h_unstable_interface(&lanes, c(9.81), Lanes::from_fn(|i| -(i as f64)), c(0.8));
        assert!((0..WIDTH).all(|i| stable.lane(i).to_bits() == 0));
        // Ra = −0 (a negative c_p at ΔT = 0): the kernels give +0 too.
        let negative = ConvectionProps { cp: -p.cp, ..p };
        let (ra, _) = rayleigh(&negative, 9.81, 0.0, 0.8);
        assert_eq!(ra.to_bits(), (-0.0_f64).to_bits());
        let h = h_unstable_interface(&negative, 9.81, 0.0, 0.8);
        let kernels =
            crate::lanes::math::exp(crate::lanes::math::ln(ra) * (1.0 / 3.0)) * 0.15 * p.k / 0.8;
        assert_eq!((h.to_bits(), kernels.to_bits()), (0, 0));
        // The shortcut is taken: no `ln` or `exp` is counted for a stable pair, one each for an
        // unstable one.
        use crate::lanes::count::{take, Counted};
        let counted = ConvectionProps {
            k: Counted(p.k),
            mu: Counted(p.mu),
            rho: Counted(p.rho),
            cp: Counted(p.cp),
            beta: Counted(p.beta),
        };
        for (dt, kernels) in [(-1.0, 0), (1.0, 1)] {
            take();
            let h = h_unstable_interface(&counted, Counted(9.81), Counted(dt), Counted(0.8));
            let n = take();
            assert_eq!((n.ln, n.exp), (kernels, kernels), "ΔT {dt}");
            assert_eq!(
                h.0.to_bits(),
                h_unstable_interface(&p, 9.81, dt, 0.8).to_bits()
            );
        }
    }
}
