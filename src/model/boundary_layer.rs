//! The natural-convection boundary layer on the wetted wall of the `layered` level: how much
//! liquid a heated vertical wall carries upward (docs/PHYSICS.md 2.8).
//!
//! A wall warmer than the liquid drives a thin buoyant layer up along it; the liquid it entrains
//! on the way and the wall heat it carries reach the layer where it stops being lighter than its
//! surroundings (`model::column`). Its mass flow per unit perimeter at height x above the layer's
//! start is the integral of the velocity profile across its thickness, from the classic
//! integral solutions for an isothermal vertical plate:
//!
//! - **laminar** (Squire 1938; Eckert & Drake, *Analysis of Heat and Mass Transfer*, §10-4;
//!   Holman, *Heat Transfer*, §7-2): δ/x = 3.93 Pr^(−1/2) (0.952 + Pr)^(1/4) Gr_x^(−1/4),
//!   u₁ = 5.17 (ν/x) (0.952 + Pr)^(−1/2) Gr_x^(1/2), u = u₁ η (1 − η)², η = y/δ, so
//!   ṁ' = ρ u₁ δ / 12 = 1.6932 ρ ν Pr^(−1/2) (0.952 + Pr)^(−1/4) Gr_x^(1/4);
//! - **turbulent** (Eckert & Jackson 1951, NACA Report 1015): δ/x = 0.565 Gr_x^(−1/10) Pr^(−8/15)
//!   (1 + 0.494 Pr^(2/3))^(1/10), u₁ = 1.185 (ν/x) Gr_x^(1/2) (1 + 0.494 Pr^(2/3))^(−1/2),
//!   u = u₁ η^(1/7) (1 − η)⁴, ∫₀¹ η^(1/7)(1 − η)⁴ dη = B(8/7, 5) = 0.146351, so
//!   ṁ' = 0.097986 ρ ν Gr_x^(2/5) Pr^(−8/15) (1 + 0.494 Pr^(2/3))^(−2/5);
//!
//! with Gr_x = a β ΔT x³ / ν². The larger of the two is taken: they cross at Gr_x ≈ 1.7e8 for
//! Pr = 1 (the usual transition is Gr Pr ≈ 1e9), and the flow stays continuous in every input.

use super::thermal::ConvectionProps;
use crate::lanes::{c, Real};

/// Laminar coefficient 3.93 · 5.17 / 12 of ṁ' / (ρ ν) (Squire's profile integral).
pub const LAMINAR_COEFFICIENT: f64 = 3.93 * 5.17 / 12.0;

/// Turbulent coefficient 0.565 · 1.185 · B(8/7, 5) of ṁ' / (ρ ν) (Eckert & Jackson), with
/// B(8/7, 5) = Γ(8/7) Γ(5) / Γ(47/7) = 0.146 351 445 489 (scipy.special.beta).
pub const TURBULENT_COEFFICIENT: f64 = 0.565 * 1.185 * 0.146_351_445_489_376_65;

/// Mass flow per unit perimeter of the wall boundary layer, kg/(m·s), at `x_m` (m) above its
/// start, for a wall `dt_k` (K) warmer than the liquid of properties `p` under the acceleration
/// `accel` (m/s²); 0 where the wall is not warmer (no upward layer) or x ≤ 0.
pub fn mass_flow_per_perimeter<T: Real>(p: &ConvectionProps<T>, accel: T, dt_k: T, x_m: T) -> T {
    let nu = p.mu / p.rho;
    let pr = nu * p.rho * p.cp / p.k;
    let x = x_m.max_c(0.0);
    let gr = accel.max_c(0.0) * p.beta.abs() * dt_k.max_c(0.0) * (x * x * x) / (nu * nu);
    let ln_gr = gr.ln();
    let laminar =
        (ln_gr * 0.25).exp() * LAMINAR_COEFFICIENT / (pr.sqrt() * (pr + 0.952).sqrt().sqrt());
    let damp = pr.powf(c(2.0 / 3.0)) * 0.494 + 1.0;
    let turbulent =
        (ln_gr * 0.4 - pr.ln() * (8.0 / 15.0) - damp.ln() * 0.4).exp() * TURBULENT_COEFFICIENT;
    p.rho * nu * laminar.max(turbulent)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn water_like() -> ConvectionProps {
        // Pr = 1 exactly: μ c_p = k.
        ConvectionProps {
            k: 0.1,
            mu: 1.0e-5,
            rho: 70.0,
            cp: 1.0e4,
            beta: 0.016,
        }
    }

    /// The two regimes against their closed forms at Pr = 1, where
    /// Gr_x = a β ΔT x³ / ν² is set by x alone.
    #[test]
    fn regimes_match_the_integral_solutions() {
        let p = water_like();
        let nu = p.mu / p.rho;
        for (x, turbulent) in [(0.01, false), (0.05, false), (1.0, true), (3.0, true)] {
            let gr = 9.81 * 0.016 * 0.1 * x * x * x / (nu * nu);
            let lam = p.rho * nu * LAMINAR_COEFFICIENT * gr.powf(0.25) / 1.952f64.powf(0.25);
            let tur = p.rho * nu * TURBULENT_COEFFICIENT * gr.powf(0.4) / 1.494f64.powf(0.4);
            let got = mass_flow_per_perimeter(&p, 9.81, 0.1, x);
            let want = if turbulent { tur } else { lam };
            assert!(
                (got / want - 1.0).abs() < 1e-12,
                "x {x}: Gr {gr:e}: {got} vs {want}"
            );
            assert_eq!(tur > lam, turbulent, "x {x}: Gr {gr:e}");
        }
        assert_eq!(mass_flow_per_perimeter(&p, 9.81, -0.1, 1.0), 0.0);
        assert_eq!(mass_flow_per_perimeter(&p, 9.81, 0.1, 0.0), 0.0);
    }

    /// B(8/7, 5) by the trapezoid rule on η = s⁷ (the integrand η^(1/7) (1 − η)⁴ dη becomes
    /// 7 s⁷ (1 − s⁷)⁴ ds, smooth): the constant in the turbulent coefficient.
    #[test]
    fn turbulent_profile_integral() {
        let n = 200_000;
        let f = |s: f64| 7.0 * s.powi(7) * (1.0 - s.powi(7)).powi(4);
        let h = 1.0 / n as f64;
        let sum: f64 = (1..n).map(|i| f(i as f64 * h)).sum::<f64>() + 0.5 * (f(0.0) + f(1.0));
        assert!((sum * h / 0.146_351_445_489_376_65 - 1.0).abs() < 1e-9);
    }
}
