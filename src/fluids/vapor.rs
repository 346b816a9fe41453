//! Real-gas propellant vapour: a density-explicit virial form fitted to CoolProp.
//!
//! `Z = P / (ρ R T) = 1 + Σ_{k=1..4} r^k B_k(τ)`, `B_k(τ) = Σ_{j=0..5} c_kj (τ − 1)^j`, with
//! `r = ρ/ρ_c`, `τ = T_c/T` and `R = R_u/M`. It is the truncated density expansion of a residual
//! Helmholtz energy `α_r = Σ_k r^k B_k(τ) / k`, so pressure and energy come from one function
//! and are thermodynamically consistent: the residual internal energy is
//! `u_res / (R T) = τ ∂α_r/∂τ = Σ_k r^k τ B_k'(τ) / k` and the residual enthalpy
//! `h_res = u_res + (Z − 1) R T`. `tools/fit_fluids.py` fits the 24 `c_kj` per fluid by joint
//! least squares on Z and `u_res/(R T)` at the rows of `tests/fixtures/fluids/*_eos.csv`:
//! saturated vapour from `t_min_k` to `t_max_k` and superheated isobars from `P_sat(t_min_k)`
//! to `min(2 MPa, 0.9 P_crit)`, `1.001 T_sat .. max(3 T_sat, 400 K)`. Density at given (T, P)
//! within 4e-4 of CoolProp for every propellant over those rows (contract 1 % saturated, 2 %
//! superheated: `tests/fluids.rs`); between the rows, hydrogen within 5 K of saturation near
//! 0.9 P_c reaches 1.4e-3 (an independent check), `u_res/(R T)` within 2e-3 absolute. Outside those rows
//! (liquid-like densities, supercritical states) the form is an extrapolation: it is valid for
//! vapour at or below saturation density.
//!
//! The ideal-gas part is `u⁰(T) = R T Q(x)` with `Q` a degree-15 polynomial in
//! `x = 2 (√T − √T_lo)/(√T_hi − √T_lo) − 1` over `T_lo = t_min_k − 5 K .. T_hi = 650 K`, so that
//! `c_v⁰ = du⁰/dT = R (Q + Q'(x) √T/(√T_hi − √T_lo))` is its exact derivative (the ullage's Newton
//! solve for T from energy needs the pair consistent). `tools/fit_fluids.py` fits `Q` by joint
//! least squares on CoolProp's `CP0MASS − R` and ideal-gas energy (`*_ideal_gas.csv`): `c_v⁰`
//! within 3.8e-3 for equilibrium para-hydrogen (its ortho–para rotational bump near 150 K is what
//! needs the degree), 3.4e-4 for normal hydrogen, 1.2e-6 or better for O₂, N₂ and CH₄; `u⁰` within
//! 2.2e-5 of its span. Outside `[T_lo, T_hi]` `c_v⁰` is held at the end value (u⁰ continues
//! linearly), so energy stays invertible for any temperature.

use super::FluidProps;
use crate::lanes::Real;

/// Density powers of the virial form.
const K: usize = 4;
/// Temperature coefficients per density power.
const J: usize = 6;
/// Iteration cap of [`FluidProps::vapor_density_kg_per_m3`].
const MAX_ITER: usize = 60;

/// Coefficients of the ideal-gas polynomial `Q`.
const NIDEAL: usize = 16;

impl FluidProps {
    /// The vapour's ideal-gas internal energy `u⁰` (J/kg, on the fit's own reference: only
    /// differences matter, the model's energy offset fixes the rest) and isochoric heat
    /// capacity `c_v⁰ = du⁰/dT` (J/(kg K)) at `t_k` (K, any value; `c_v⁰` is held outside
    /// `ideal_t_lo_k .. ideal_t_hi_k`). `c_p⁰ = c_v⁰ + R`.
    #[inline]
    pub fn vapor_ideal<T: Real>(&self, t_k: T) -> (T, T) {
        let (s_lo, s_hi) = (self.ideal_t_lo_k.sqrt(), self.ideal_t_hi_k.sqrt());
        let inv_span = 1.0 / (s_hi - s_lo);
        let tc = t_k.clamp_c(self.ideal_t_lo_k, self.ideal_t_hi_k);
        let s = tc.sqrt();
        let x = (s - s_lo) * (2.0 * inv_span) - 1.0;
        let zero = T::splat(0.0);
        let (mut q, mut dq) = (zero, zero);
        for k in (0..NIDEAL).rev() {
            dq = dq.mul_add(x, q);
            q = q.mul_add_c(x, self.vapor_ideal[k]);
        }
        let cv = q + dq * s * inv_span;
        let rs = self.r_specific_j_per_kg_k();
        ((tc * q + cv * (t_k - tc)) * rs, cv * rs)
    }

    /// Residual enthalpy `h − h⁰` (J/kg) of the vapour at `t_k` (K) and pressure `p_pa` (Pa):
    /// `u_res + (Z − 1) R T` at the density of two Newton steps on `P = ρ R T Z` from the ideal
    /// gas (within 1e-4 R T of the converged density's value from 1.5 T_sat to 600 K and 0.1 to
    /// 2 MPa: `tests/ideal_gas.rs`). For a pressurant inlet, where a converged solve per
    /// right-hand side would cost more than it buys.
    pub fn vapor_h_res_at_tp<T: Real>(&self, t_k: T, p_pa: T) -> T {
        let rt = t_k.max_c(1.0) * self.r_specific_j_per_kg_k();
        let mut rho = p_pa.max_c(0.0) / rt;
        for _ in 0..2 {
            let (z, _, dz) = self.virial(t_k, rho);
            let slope = (dz + 1.0).max_c(0.1);
            rho = (rho - (rho * z - p_pa / rt) / slope).max(rho * 0.5);
        }
        let (z, u) = self.vapor_z_u_res(t_k, rho);
        (u + z - 1.0) * rt
    }

    /// `(Z, u_res/(R T))` of the vapour at `t_k` (K, clamped to ≥ 1 K) and density `rho` (kg/m³).
    pub fn vapor_z_u_res<T: Real>(&self, t_k: T, rho_kg_per_m3: T) -> (T, T) {
        let (z, u, _) = self.virial(t_k, rho_kg_per_m3);
        (z, u)
    }

    /// `(Z − 1, u_res/(R T), Σ_k (k + 1) r^k B_k)`: the last is `d(ρ Z)/dρ − 1`, for Newton on P.
    fn virial<T: Real>(&self, t_k: T, rho: T) -> (T, T, T) {
        let tau = t_k.max_c(1.0).rdiv(self.t_crit_k);
        let y = tau - 1.0;
        // ρ/ρ_c as in `vapor_state`, so that the two give the same bits.
        let r = rho * (1.0 / self.rho_crit_kg_per_m3);
        let zero = T::splat(0.0);
        let (mut z, mut u, mut dz) = (zero, zero, zero);
        for k in (1..=K).rev() {
            let c = &self.vapor_virial[(k - 1) * J..k * J];
            let (mut b, mut db) = (zero, zero);
            for j in (0..J).rev() {
                b = b.mul_add_c(y, c[j]);
                if j > 0 {
                    db = db.mul_add_c(y, j as f64 * c[j]);
                }
            }
            z = (z + b) * r;
            u = (u + tau * db * (1.0 / k as f64)) * r;
            dz = (dz + b * (k + 1) as f64) * r;
        }
        (z + 1.0, u, dz)
    }

    /// The vapour's residual state and its partial derivatives at `t_k` (K, ≥ 1 K) and density
    /// `rho` (kg/m³): what an ullage node needs to recover T from its energy (Newton on
    /// [`VaporState::du_res_dt`]) and to carry dP/dt through the chain rule.
    // Inlined so that the ullage Newton loop, which reads two of its fields, computes only those.
    #[inline(always)]
    pub fn vapor_state<T: Real>(&self, t_k: T, rho_kg_per_m3: T) -> VaporState<T> {
        let t = t_k.max_c(1.0);
        let tau = t.rdiv(self.t_crit_k);
        // τ/T = τ²/T_c: a multiply where a divide was (as ρ/ρ_c below).
        let tau_over_t = tau * tau * (1.0 / self.t_crit_k);
        let y = tau - 1.0;
        let r = rho_kg_per_m3 * (1.0 / self.rho_crit_kg_per_m3);
        let zero = T::splat(0.0);
        // Σ r^k B_k, Σ k r^k B_k, Σ r^k B_k'/k, Σ r^(k−1) B_k', Σ r^k B_k''/k.
        let (mut z, mut kz, mut u, mut b1_sum, mut u2) = (zero, zero, zero, zero, zero);
        for k in (1..=K).rev() {
            let c = &self.vapor_virial[(k - 1) * J..k * J];
            let (mut b, mut b1, mut b2) = (zero, zero, zero);
            for j in (0..J).rev() {
                b = b.mul_add_c(y, c[j]);
                if j > 0 {
                    b1 = b1.mul_add_c(y, j as f64 * c[j]);
                }
                if j > 1 {
                    b2 = b2.mul_add_c(y, (j * (j - 1)) as f64 * c[j]);
                }
            }
            let kf = k as f64;
            z = (z + b) * r;
            kz = (kz + b * kf) * r;
            u = (u + b1 * (1.0 / kf)) * r;
            b1_sum = b1_sum.mul_add(r, b1);
            u2 = (u2 + b2 * (1.0 / kf)) * r;
        }
        let rs = self.r_specific_j_per_kg_k();
        let rt = t * rs;
        let z_full = z + 1.0;
        // u_res = R T_c Σ r^k B_k'(τ)/k; ∂/∂T = −(τ/T) R T_c Σ r^k B_k''/k; ∂/∂ρ = R T_c Σ r^k B_k' / ρ.
        let rtc = rs * self.t_crit_k;
        // ∂Z/∂T at constant ρ = −(τ/T) Σ r^k B_k'.
        // b1_sum is Σ r^(k−1) B_k' here (Horner without the last factor r).
        let dz_dt = -tau_over_t * b1_sum * r;
        VaporState {
            z: z_full,
            u_res_j_per_kg: u * rtc,
            du_res_dt: -tau_over_t * u2 * rtc,
            du_res_drho: b1_sum * (rtc / self.rho_crit_kg_per_m3),
            p_pa: rho_kg_per_m3 * rt * z_full,
            dp_dt: rho_kg_per_m3 * rs * (z_full + t * dz_dt),
            dp_drho: rt * (kz + z_full),
        }
    }

    /// Vapour pressure `ρ R T Z` at `t_k` (K) and density `rho` (kg/m³), Pa.
    pub fn vapor_pressure_pa<T: Real>(&self, t_k: T, rho_kg_per_m3: T) -> T {
        let (z, _) = self.vapor_z_u_res(t_k, rho_kg_per_m3);
        rho_kg_per_m3 * t_k * self.r_specific_j_per_kg_k() * z
    }

    /// Residual internal energy of the vapour, J/kg: `R T u_res/(R T)`.
    pub fn vapor_u_res_j_per_kg<T: Real>(&self, t_k: T, rho_kg_per_m3: T) -> T {
        self.vapor_z_u_res(t_k, rho_kg_per_m3).1 * t_k * self.r_specific_j_per_kg_k()
    }

    /// Vapour density at `t_k` (K) and pressure `p_pa` (Pa), kg/m³: Newton on
    /// `P = ρ R T Z(T, ρ)` from the ideal-gas density, converged to 1e-13 relative. Valid on
    /// the vapour side (at or below the saturated-vapour density); where the truncated form has
    /// no vapour root (far above saturation) the iteration stops at the density where
    /// `d(ρZ)/dρ` vanishes, the largest pressure the form represents. Non-positive or NaN
    /// pressure gives 0 or NaN.
    pub fn vapor_density_kg_per_m3(&self, t_k: f64, p_pa: f64) -> f64 {
        if p_pa.is_nan() || t_k.is_nan() {
            return f64::NAN;
        }
        if p_pa <= 0.0 {
            return 0.0;
        }
        let rt = self.r_specific_j_per_kg_k() * t_k.max(1.0);
        let mut rho = p_pa / rt;
        for _ in 0..MAX_ITER {
            let (z, _, dz) = self.virial(t_k, rho);
            let slope = rt * (1.0 + dz);
            if slope <= 0.0 {
                break;
            }
            let next = (rho - (rho * rt * z - p_pa) / slope).max(0.5 * rho);
            let done = (next - rho).abs() <= 1e-13 * rho;
            rho = next;
            if done {
                break;
            }
        }
        rho
    }
}

/// The real-gas vapour at one (T, ρ), from [`FluidProps::vapor_state`]. Internal energy is
/// `c_v T + offset + u_res`, enthalpy that plus `Z R T`.
#[derive(Clone, Copy, Debug, Default)]
pub struct VaporState<T> {
    /// Compressibility factor Z = P/(ρ R T).
    pub z: T,
    /// Residual internal energy, J/kg.
    pub u_res_j_per_kg: T,
    /// ∂u_res/∂T at constant ρ, J/(kg K).
    pub du_res_dt: T,
    /// ∂u_res/∂ρ at constant T, J m³/kg².
    pub du_res_drho: T,
    /// Pressure ρ R T Z, Pa.
    pub p_pa: T,
    /// ∂P/∂T at constant ρ, Pa/K.
    pub dp_dt: T,
    /// ∂P/∂ρ at constant T, Pa m³/kg.
    pub dp_drho: T,
}

impl<T: Real> VaporState<T> {
    /// Lane `i`.
    pub fn lane(&self, i: usize) -> VaporState<f64> {
        VaporState {
            z: self.z.lane(i),
            u_res_j_per_kg: self.u_res_j_per_kg.lane(i),
            du_res_dt: self.du_res_dt.lane(i),
            du_res_drho: self.du_res_drho.lane(i),
            p_pa: self.p_pa.lane(i),
            dp_dt: self.dp_dt.lane(i),
            dp_drho: self.dp_drho.lane(i),
        }
    }
}
