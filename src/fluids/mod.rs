//! Saturation-property fits for cryogenic propellants and helium pressurant.
//!
//! # Fluids and source data
//!
//! Propellants ([`Fluid`]): `LH2` (CoolProp `ParaHydrogen`: equilibrium para-hydrogen, what
//! flight and storage tanks hold after conversion), `nLH2` (CoolProp `Hydrogen`: *normal*
//! hydrogen, 75 % ortho, freshly liquefied), `LOX` (`Oxygen`), `LCH4` (`Methane`) and `LN2`
//! (`Nitrogen`); pressurant
//! [`HELIUM`] (`Helium`, treated as an ideal gas). All reference values come from
//! CoolProp 8.0.0 (the exact version and git revision are recorded in the header of
//! every fixture in `tests/fixtures/fluids/` and of [`table`]). The coefficients in
//! [`table`] are generated: run `python3 tools/coolprop_fixtures.py` (CoolProp →
//! fixture CSVs) and then `python3 tools/fit_fluids.py` (fixtures → `table.rs`).
//! All quantities are SI: K, Pa, kg/m³, J/kg, J/(kg K), W/(m K), Pa s.
//!
//! # Usable range and fit forms
//!
//! Each propellant is fitted along saturation from `t_min_k = T_triple + 1 K` to
//! `t_max_k = 0.93 T_crit` (so that LN2 at 2 MPa, T_sat = 0.916 T_crit, is inside). Every liquid-side property is a degree-7 polynomial with
//! exactly 8 monomial coefficients (constant term first, evaluated with Horner) in
//! the normalised variable `x = (T − T_mid) / T_half ∈ [−1, 1]`, with
//! `T_mid = (t_min_k + t_max_k) / 2` and `T_half = (t_max_k − t_min_k) / 2`:
//! `ln P_sat`, `ρ_l`, `c_p,l`, `h_fg`, `k_l`, `ln μ_l`, `ln ρ_v` (saturated vapour) and
//! `dh_l,sat/dT`. The layout is uniform so that a GPU backend can evaluate the same
//! [`FluidProps`] table in `f32`.
//!
//! * `h_l(T)` is the saturated-liquid enthalpy: the exact analytic integral of the
//!   `dh_l,sat/dT` polynomial, referenced to `h_l(t_min_k) = 0`, fitted to CoolProp's
//!   `H(Q=0)` rise itself (within 1e-5 of h_fg; the `c_p,l` integral used before missed it by
//!   up to 0.5 % of the rise because it drops `v (1 − βT) dP_sat/dT`). `c_p,l` stays for the
//!   heat-transfer correlations.
//! * `dρ_l/dT` and `dP_sat/dT` are the analytic derivatives of the fits.
//! * [`FluidProps::tsat_k`] inverts `ln P_sat` by safeguarded Newton iteration and
//!   [`FluidProps::t_from_h_l_k`] inverts `h_l`.
//!
//! Accuracy against the CoolProp fixtures (maximum relative error over the 121
//! saturated-liquid rows uniform in T, and for `k_v`, `μ_v` over the 61 gas rows
//! uniform in ln T; checked by `tests/fluids.rs` against the contract in brackets;
//! errors between the rows are the same to two digits). Evaluating the same
//! coefficients by `f32` Horner (at the same `x`) changes them by less than 1e-6.
//! The table is generated, so regenerate the numbers with `tools/fit_fluids.py`
//! if the fixtures change:
//!
//! | fluid | P_sat [0.5 %] | ρ_l [1 %] | c_p,l [2 %] | h_fg [1 %] | k_l [3 %] | μ_l [3 %] | k_v [15 %] | μ_v [15 %] |
//! |-------|---------|---------|---------|---------|---------|---------|--------|--------|
//! | LH2   | 8.9e-6  | 4.9e-5  | 3.1e-3  | 1.1e-4  | 2.8e-4  | 8.0e-5  | 1.57e-1¹ | 1.08e-1 |
//! | LOX   | 2.1e-4  | 9.3e-5  | 2.8e-3  | 1.7e-4  | 1.0e-4  | 2.6e-4  | 4.6e-2 | 4.1e-2 |
//! | LCH4  | 8.3e-6  | 3.9e-5  | 1.4e-3  | 7.9e-5  | 1.6e-5  | 7.1e-5  | 2.0e-2 | 4.0e-2 |
//! | LN2   | 3.8e-6  | 3.0e-5  | 1.2e-3  | 5.9e-5  | 1.0e-4  | 7.6e-5  | 4.1e-2 | 3.5e-2 |
//! | nLH2  | 8.4e-6  | 5.0e-5  | 3.2e-3  | 1.1e-4  | 4.1e-4  | 8.3e-5  | 4.2e-2 | 1.07e-1 |
//!
//! `h_l` is within 3.1e-5 of h_fg and `ρ_v,sat` within 1.3e-4 for every fluid.
//!
//! ¹ Para-hydrogen's rotational heat capacity peaks near 150 K and bends its gas conductivity away
//! from any single power law over 14–400 K; its contract is 17 %.
//!
//! Helium power laws: k 2.3e-2, μ 2.7e-2 (contract 15 %).
//!
//! # Outside the usable range
//!
//! Every function is total: no panics, no allocation, and no NaN for finite
//! inputs (a NaN input gives a NaN result). Results are finite for finite inputs,
//! except that the linear `h_l` continuation and its inverse overflow to ±∞ for
//! arguments beyond about 1e300.
//!
//! * `ρ_l`, `c_p,l`, `h_fg`, `k_l`, `μ_l`: `x` is clamped to `[−1, 1]`, i.e. the
//!   value at the nearest end of the range; `dρ_l/dT` is therefore 0 outside.
//! * `ln P_sat` is continued *linearly in x* (by value and slope at the nearest
//!   end), so `P_sat` is continuous, strictly increasing and positive everywhere;
//!   `ln P_sat` is finally limited to `[−700, 700]` so `P_sat` stays finite even for
//!   absurd temperatures (its derivative is 0 where that limit is active).
//! * `h_l` is continued linearly with the end-point `dh_l,sat/dT`, so its slope is that fit
//!   everywhere and `t_from_h_l_k` inverts it everywhere.
//! * `tsat_k` clamps: pressures at or below `P_sat(t_min_k)` (including zero and
//!   negative pressures) give `t_min_k`, pressures at or above `P_sat(t_max_k)` give
//!   `t_max_k`.
//!
//! # Vapour and helium
//!
//! The propellant vapour is a real gas ([`vapor`]): a virial residual part on an ideal-gas part
//! whose `c_v⁰(T)` follows CoolProp's `CP0MASS` from `t_min_k − 5 K` to 650 K (hydrogen's
//! rises from 1.5 R at 20 K to 3.5 R at 300 K, equilibrium para-hydrogen's through a
//! rotational bump of 3.9 R near 150 K; methane's from 3 R to 5.3 R at 600 K). Helium is an
//! ideal gas with constant `c_p`, `c_v` (`CP0MASS`; `c_v = c_p − R_u/M` with
//! [`R_UNIVERSAL`]). Gas thermal
//! conductivity and viscosity are power laws `y = y_ref (T / t_ref)^n` because the
//! ullage can be far warmer than saturation: the propellant laws are fitted over
//! `t_min_k .. 400 K` at `P_fit = 0.5 P_sat(t_min_k)` (single-phase gas over the
//! whole range; dilute-gas values), helium over 5 .. 400 K at 1 bar. They omit the
//! dense-gas excess: for 1–3 bar gas between `T_sat + 1 K` and 400 K they stay within
//! 8 % of CoolProp for LOX, LCH4 and LN2 (LH2: k −19 % / +4 %, μ ±12 %), but along the
//! saturated-vapour line they fall below CoolProp as the critical point nears
//! (at `0.9 T_crit`: k by 30–40 %, μ by 13–18 %). Power laws are evaluated with `T`
//! clamped to `[1, 10 000] K`.

mod inverse;
pub mod surface_tension;
pub mod table;
pub mod vapor;

use crate::lanes::{Mask, Real};

pub use table::HELIUM;

/// Universal gas constant R_u in J/(mol K) (CODATA 2018, exact).
pub const R_UNIVERSAL: f64 = 8.314_462_618;

/// Number of polynomial coefficients of every liquid-side fit (degree 7).
const NCOEF: usize = 8;
/// `ln P_sat` is limited to this magnitude so `P_sat` is finite for any input.
pub(crate) const LN_P_LIMIT: f64 = 700.0;
/// Relative convergence tolerance of [`FluidProps::tsat_k`] on T.
const TSAT_TOL: f64 = 1e-13;
/// Relative convergence tolerance of [`FluidProps::t_from_h_l_k`] on T.
const T_FROM_H_TOL: f64 = 1e-12;
/// Iteration cap of the safeguarded Newton solvers.
const MAX_ITER: usize = 40;
/// Temperature clamp (K) for the gas power laws.
pub(crate) const POWER_LAW_T_MIN_K: f64 = 1.0;
/// Temperature clamp (K) for the gas power laws.
pub(crate) const POWER_LAW_T_MAX_K: f64 = 10_000.0;

/// A cryogenic propellant with saturation-property fits (CoolProp 8.0.0 source data).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Fluid {
    /// Liquid hydrogen as flown and stored: equilibrium para-hydrogen (CoolProp
    /// `ParaHydrogen`); campaign name `"LH2"`. Its P_sat is 2.4–4.2 % above normal hydrogen's.
    Lh2,
    /// Liquid oxygen (CoolProp `Oxygen`); campaign name `"LOX"`.
    Lox,
    /// Liquid methane (CoolProp `Methane`); campaign name `"LCH4"`.
    Lch4,
    /// Liquid nitrogen (CoolProp `Nitrogen`); campaign name `"LN2"`.
    Ln2,
    /// Normal liquid hydrogen, 75 % ortho / 25 % para (CoolProp `Hydrogen`); campaign name
    /// `"nLH2"`. Freshly liquefied hydrogen before ortho–para conversion (the conversion heat
    /// itself is not modelled).
    NLh2,
}

impl Fluid {
    /// All propellants, in declaration order.
    pub const ALL: [Fluid; 5] = [Fluid::Lh2, Fluid::Lox, Fluid::Lch4, Fluid::Ln2, Fluid::NLh2];

    /// Campaign spelling: `"LH2"`, `"LOX"`, `"LCH4"`, `"LN2"`, `"nLH2"`.
    pub fn name(self) -> &'static str {
        match self {
            Fluid::Lh2 => "LH2",
            Fluid::Lox => "LOX",
            Fluid::Lch4 => "LCH4",
            Fluid::Ln2 => "LN2",
            Fluid::NLh2 => "nLH2",
        }
    }

    /// Parses the campaign spelling returned by [`Fluid::name`] (exact,
    /// case-sensitive); `None` for anything else.
    pub fn from_name(s: &str) -> Option<Fluid> {
        Fluid::ALL.into_iter().find(|f| f.name() == s)
    }

    /// [`FluidProps::t_from_h_l_k`] of this propellant (the same root to rounding), with the
    /// Newton iteration started from the propellant's inverse table: one step, two near t_min_k.
    pub fn t_from_h_l_k<T: Real>(self, h_j_per_kg: T) -> T {
        let table = inverse::hl_inverse(self);
        let (base, h_max) = table.limits();
        let start = table.guess(h_j_per_kg);
        self.props().invert_h_l(h_j_per_kg, base, h_max, start)
    }

    /// The constants and fit coefficients of this propellant (from [`table`]).
    pub fn props(self) -> &'static FluidProps {
        match self {
            Fluid::Lh2 => &table::LH2,
            Fluid::Lox => &table::LOX,
            Fluid::Lch4 => &table::LCH4,
            Fluid::Ln2 => &table::LN2,
            Fluid::NLh2 => &table::NLH2,
        }
    }

    /// Its surface tension fit ([`surface_tension`]).
    pub fn surface_tension(self) -> surface_tension::SurfaceTension {
        match self {
            Fluid::Lh2 => surface_tension::LH2,
            Fluid::Lox => surface_tension::LOX,
            Fluid::Lch4 => surface_tension::LCH4,
            Fluid::Ln2 => surface_tension::LN2,
            Fluid::NLh2 => surface_tension::NLH2,
        }
    }
}

impl surface_tension::SurfaceTension {
    /// Surface tension of the saturated liquid at `t_k`, N/m (0 at and above T_c). Within 3 %
    /// of CoolProp 8.0 for LH2, 0.8 % for LCH4, 0.03 % for LOX and LN2 over the fitted range.
    pub fn sigma_n_per_m(&self, t_k: f64) -> f64 {
        self.sigma0_n_per_m * (1.0 - t_k / self.t_crit_k).max(0.0).powf(self.exponent)
    }
}

/// One propellant's constants and fit coefficients (CoolProp 8.0.0 source data,
/// generated into [`table`] by `tools/fit_fluids.py`).
///
/// `#[repr(C)]` with only `f64` scalars and `[f64; 8]` arrays so the same table can
/// be uploaded to a GPU. The arrays are monomial coefficients (constant term first)
/// in `x = (T − T_mid) / T_half`; see the [module docs](self) for the evaluation
/// rules, range and accuracy.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct FluidProps {
    /// Molar mass M in kg/mol (CoolProp `molar_mass`).
    pub molar_mass_kg_per_mol: f64,
    /// Triple-point temperature in K (CoolProp `Ttriple`).
    pub t_triple_k: f64,
    /// Critical temperature in K (CoolProp `Tcrit`).
    pub t_crit_k: f64,
    /// Critical pressure in Pa (CoolProp `pcrit`).
    pub p_crit_pa: f64,
    /// Lower end of the fitted range in K: `t_triple_k + 1`.
    pub t_min_k: f64,
    /// Upper end of the fitted range in K: `0.93 t_crit_k`.
    pub t_max_k: f64,
    /// Lower end of the vapour ideal-gas fit in K (`t_min_k − 5`); below it `c_v⁰` is held.
    pub ideal_t_lo_k: f64,
    /// Upper end of the vapour ideal-gas fit in K (650); above it `c_v⁰` is held.
    pub ideal_t_hi_k: f64,
    /// Vapour thermal conductivity at `vapor_t_ref_k`, in W/(m K) (power-law fit).
    pub k_vapor_ref_w_per_m_k: f64,
    /// Exponent of the vapour thermal-conductivity power law (dimensionless).
    pub k_vapor_exp: f64,
    /// Vapour dynamic viscosity at `vapor_t_ref_k`, in Pa s (power-law fit).
    pub mu_vapor_ref_pa_s: f64,
    /// Exponent of the vapour viscosity power law (dimensionless).
    pub mu_vapor_exp: f64,
    /// Reference temperature of the vapour power laws in K.
    pub vapor_t_ref_k: f64,
    /// Critical density in kg/m³ (CoolProp `rhomass_critical`), the density scale of the
    /// vapour virial form.
    pub rho_crit_kg_per_m3: f64,
    /// `ln(P_sat / 1 Pa)` polynomial coefficients.
    pub ln_psat: [f64; 8],
    /// Saturated-liquid density polynomial coefficients, kg/m³.
    pub rho_l: [f64; 8],
    /// Saturated-liquid isobaric specific heat polynomial coefficients, J/(kg K).
    pub cp_l: [f64; 8],
    /// Latent heat `H(Q=1) − H(Q=0)` polynomial coefficients, J/kg.
    pub h_fg: [f64; 8],
    /// Saturated-liquid thermal conductivity polynomial coefficients, W/(m K).
    pub k_l: [f64; 8],
    /// `ln(μ_l / 1 Pa s)` polynomial coefficients (saturated-liquid viscosity).
    pub ln_mu_l: [f64; 8],
    /// `ln(ρ_v / 1 kg/m³)` polynomial coefficients (saturated-vapour density).
    pub ln_rho_v: [f64; 8],
    /// `dh_l,sat/dT` polynomial coefficients, J/(kg K): the slope of the saturated-liquid
    /// enthalpy along saturation (`c_p,l + v (1 − βT) dP_sat/dT`), whose integral is `h_l`.
    pub dh_l_sat: [f64; 8],
    /// Vapour virial coefficients `c_kj` (k = 1..4 outer, j = 0..5 inner) of
    /// `Z = 1 + Σ_k (ρ/ρ_c)^k Σ_j c_kj (τ − 1)^j`, `τ = T_c/T` (see [`vapor`]).
    pub vapor_virial: [f64; 24],
    /// Vapour ideal-gas coefficients: `u⁰/R = T Q(x)`, `Q = Σ_k q_k x^k` (k = 0..15),
    /// `x = 2 (√T − √T_lo)/(√T_hi − √T_lo) − 1` (see [`vapor`]; CoolProp `CP0MASS`).
    pub vapor_ideal: [f64; 16],
}

/// Horner evaluation of `Σ c_i x^i`.
#[inline]
pub(crate) fn poly<T: Real>(c: &[f64; NCOEF], x: T) -> T {
    c.iter()
        .rev()
        .fold(T::splat(0.0), |acc, &a| acc.mul_add_c(x, a))
}

/// Horner evaluation of the derivative `Σ i c_i x^(i−1)`.
#[inline]
pub(crate) fn poly_deriv<T: Real>(c: &[f64; NCOEF], x: T) -> T {
    // A counted loop: `enumerate().skip(1).rev()` was left as a call per evaluation (1.4 % of a
    // lumped run's instructions).
    let mut acc = T::splat(0.0);
    for i in (1..NCOEF).rev() {
        acc = acc.mul_add_c(x, i as f64 * c[i]);
    }
    acc
}

/// `1 / (i + 1)`: the antiderivative's divisors as factors (a multiply, not a divide, per term).
const RECIPROCALS: [f64; NCOEF] = [
    1.0,
    1.0 / 2.0,
    1.0 / 3.0,
    1.0 / 4.0,
    1.0 / 5.0,
    1.0 / 6.0,
    1.0 / 7.0,
    1.0 / 8.0,
];

/// Horner evaluation of the antiderivative `Σ c_i x^(i+1) / (i+1)` (zero at x = 0).
#[inline]
fn poly_integral<T: Real>(c: &[f64; NCOEF], x: T) -> T {
    (0..NCOEF).rev().fold(T::splat(0.0), |acc, i| {
        acc.mul_add_c(x, c[i] * RECIPROCALS[i])
    }) * x
}

/// `ln(T / t_ref)` with T clamped to the power-law range: one logarithm serves every law with
/// that reference temperature.
#[inline]
fn power_law_log<T: Real>(t_ref: f64, t_k: T) -> T {
    (t_k.clamp_c(POWER_LAW_T_MIN_K, POWER_LAW_T_MAX_K) / t_ref).ln()
}

/// `y_ref (T / t_ref)^n` from `ln(T / t_ref)` ([`power_law_log`]).
#[inline]
fn power_law<T: Real>(y_ref: f64, n: f64, log_ratio: T) -> T {
    (log_ratio * n).exp() * y_ref
}

impl FluidProps {
    /// Middle of the fitted range, K.
    #[inline]
    fn t_mid(&self) -> f64 {
        0.5 * (self.t_min_k + self.t_max_k)
    }

    /// Half width of the fitted range, K.
    #[inline]
    fn t_half(&self) -> f64 {
        0.5 * (self.t_max_k - self.t_min_k)
    }

    /// Reciprocal of the half width, 1/K: the slopes in T multiply by it where a divide would
    /// cost every lane a `vdivpd`.
    #[inline]
    fn inv_t_half(&self) -> f64 {
        1.0 / self.t_half()
    }

    /// Normalised temperature, unclamped. A divide, not a multiply by [`Self::inv_t_half`]: the
    /// range's ends must map to ±1 exactly (`tsat_k` clamps at `P_sat(t_min_k)` itself).
    #[inline]
    fn x_of<T: Real>(&self, t_k: T) -> T {
        (t_k - self.t_mid()) / self.t_half()
    }

    /// Normalised temperature clamped to `[−1, 1]`.
    #[inline]
    fn x_clamped<T: Real>(&self, t_k: T) -> T {
        self.x_of(t_k).clamp_c(-1.0, 1.0)
    }

    /// Temperature from a normalised temperature, K.
    #[inline]
    fn t_of<T: Real>(&self, x: T) -> T {
        x * self.t_half() + self.t_mid()
    }

    /// `(ln P_sat, d ln P_sat / dx)` with linear continuation outside `[−1, 1]`,
    /// before the `±LN_P_LIMIT` limit: the polynomial at the clamped x plus its slope times
    /// the distance beyond the end (zero inside).
    #[inline]
    fn ln_psat_and_slope<T: Real>(&self, t_k: T) -> (T, T) {
        let x = self.x_of(t_k);
        let xc = x.clamp_c(-1.0, 1.0);
        let s = poly_deriv(&self.ln_psat, xc);
        (poly(&self.ln_psat, xc) + s * (x - xc), s)
    }

    /// Specific gas constant `R_u / M` of the propellant vapour, J/(kg K).
    pub fn r_specific_j_per_kg_k(&self) -> f64 {
        R_UNIVERSAL / self.molar_mass_kg_per_mol
    }

    /// Saturation pressure at `t_k` (K), in Pa: `exp` of the `ln_psat` polynomial,
    /// continued linearly in `x` outside the range (strictly increasing, positive and
    /// finite for every finite input).
    pub fn psat_pa<T: Real>(&self, t_k: T) -> T {
        self.psat_and_slope(t_k).0
    }

    /// Analytic `dP_sat/dT` at `t_k` (K), in Pa/K; consistent with [`Self::psat_pa`]
    /// including the linear continuation outside the range.
    pub fn dpsat_dt_pa_per_k<T: Real>(&self, t_k: T) -> T {
        self.psat_and_slope(t_k).1
    }

    /// [`Self::psat_pa`] and [`Self::dpsat_dt_pa_per_k`] together, from one polynomial pair
    /// and one exponential; the slope is 0 where the `±LN_P_LIMIT` limit is active.
    pub fn psat_and_slope<T: Real>(&self, t_k: T) -> (T, T) {
        let (ln_p, slope) = self.ln_psat_and_slope(t_k);
        let p = ln_p.clamp_c(-LN_P_LIMIT, LN_P_LIMIT).exp();
        let limited = ln_p.abs().gt(T::splat(LN_P_LIMIT));
        (
            p,
            T::select(limited, T::splat(0.0), p * slope * self.inv_t_half()),
        )
    }

    /// Saturation temperature at pressure `p_pa` (Pa), in K: inverse of
    /// [`Self::psat_pa`], converged to 1e-13 relative by Newton iteration on the
    /// `ln_psat` polynomial (bisection-safeguarded on `[t_min_k, t_max_k]`, started
    /// from `1/T` linear in `ln P` between the end points). Pressures outside
    /// `[P_sat(t_min_k), P_sat(t_max_k)]` are clamped: they give `t_min_k` (also for
    /// zero or negative pressure) or `t_max_k`.
    pub fn tsat_k(&self, p_pa: f64) -> f64 {
        if p_pa.is_nan() {
            return f64::NAN;
        }
        let c = &self.ln_psat;
        let l_lo = poly(c, -1.0);
        let l_hi = poly(c, 1.0);
        if p_pa <= 0.0 {
            return self.t_min_k;
        }
        let ln_p = p_pa.ln();
        if ln_p <= l_lo {
            return self.t_min_k;
        }
        if ln_p >= l_hi {
            return self.t_max_k;
        }
        // Clausius-Clapeyron guess: 1/T linear in ln P between the end points.
        let frac = (ln_p - l_lo) / (l_hi - l_lo);
        let inv_t = (1.0 - frac) / self.t_min_k + frac / self.t_max_k;
        let mut x = self.x_clamped(1.0 / inv_t);
        let (mut lo, mut hi) = (-1.0_f64, 1.0_f64);
        for _ in 0..MAX_ITER {
            let f = poly(c, x) - ln_p;
            if f == 0.0 {
                break;
            }
            if f > 0.0 {
                hi = x;
            } else {
                lo = x;
            }
            let x_newton = x - f / poly_deriv(c, x);
            if ((x_newton - x) * self.t_half()).abs() <= TSAT_TOL * self.t_of(x) {
                // Newton step below tolerance: accept it (quadratic convergence).
                x = x_newton.clamp(-1.0, 1.0);
                break;
            }
            x = if x_newton > lo && x_newton < hi {
                x_newton
            } else {
                0.5 * (lo + hi)
            };
            if (hi - lo) * self.t_half() <= TSAT_TOL * self.t_of(x) {
                break;
            }
        }
        self.t_of(x)
    }

    /// Saturated-liquid density at `t_k` (K), in kg/m³ (clamped outside the range).
    pub fn rho_l_kg_per_m3<T: Real>(&self, t_k: T) -> T {
        poly(&self.rho_l, self.x_clamped(t_k))
    }

    /// Analytic `dρ_l/dT` at `t_k` (K), in kg/(m³ K); 0 outside the range, where
    /// [`Self::rho_l_kg_per_m3`] is clamped.
    pub fn drho_l_dt<T: Real>(&self, t_k: T) -> T {
        let x = self.x_of(t_k);
        let outside = x.abs().gt(T::splat(1.0));
        let inside = poly_deriv(&self.rho_l, x.clamp_c(-1.0, 1.0)) * self.inv_t_half();
        T::select(outside, T::splat(0.0), inside)
    }

    /// Saturated-liquid isobaric specific heat at `t_k` (K), in J/(kg K) (clamped
    /// outside the range).
    pub fn cp_l_j_per_kg_k<T: Real>(&self, t_k: T) -> T {
        poly(&self.cp_l, self.x_clamped(t_k))
    }

    /// Saturated-liquid specific enthalpy at `t_k` (K), in J/kg, relative to 0 at `t_min_k`:
    /// the exact integral of the `dh_l_sat` fit of CoolProp's `H(Q=0)` rise (continued linearly
    /// with the end-point slope outside the range), so [`Self::dh_l_dt`] is its derivative
    /// everywhere. Within 3.1e-5 of h_fg of CoolProp over the range (`tests/fluids.rs`).
    pub fn h_l_j_per_kg<T: Real>(&self, t_k: T) -> T {
        let (base, h_max) = self.h_l_limits();
        let below = (t_k - self.t_min_k) * poly(&self.dh_l_sat, -1.0);
        let above = (t_k - self.t_max_k) * poly(&self.dh_l_sat, 1.0) + h_max;
        let inside = self.h_l_above(self.x_clamped(t_k), base);
        let h = T::select(t_k.ge(T::splat(self.t_max_k)), above, inside);
        T::select(t_k.le(T::splat(self.t_min_k)), below, h)
    }

    /// `h_l` inside the range as a function of the normalised temperature `x`, given `base`,
    /// the `c_p,l` antiderivative at x = −1 (a constant that the inversion evaluates once, not
    /// per Newton step).
    #[inline]
    fn h_l_above<T: Real>(&self, x: T, base: f64) -> T {
        (poly_integral(&self.dh_l_sat, x) - base) * self.t_half()
    }

    /// Temperature (K) at which the liquid specific enthalpy is `h_j_per_kg` (J/kg):
    /// inverse of [`Self::h_l_j_per_kg`], including its linear continuation outside
    /// the range. Safeguarded Newton iteration converged to 1e-12 relative in T.
    pub fn t_from_h_l_k(&self, h_j_per_kg: f64) -> f64 {
        let (base, h_max) = self.h_l_limits();
        let start = (2.0 * h_j_per_kg / h_max - 1.0).clamp(-1.0, 1.0);
        self.invert_h_l(h_j_per_kg, base, h_max, start)
    }

    /// The antiderivative of the `dh_l_sat` fit at x = −1 and `h_l(t_max_k)`, J/kg.
    fn h_l_limits(&self) -> (f64, f64) {
        let base = poly_integral(&self.dh_l_sat, -1.0);
        (base, self.h_l_above(1.0, base))
    }

    /// [`Self::t_from_h_l_k`] given [`Self::h_l_limits`], with the Newton iteration started at
    /// `start`, a normalised temperature in [−1, 1] (used only for 0 < h < h_max). Each lane
    /// iterates until its own exit; lanes that are done no longer move.
    fn invert_h_l<T: Real>(&self, h_j_per_kg: T, base: f64, h_max: f64, start: T) -> T {
        let h = h_j_per_kg;
        let (cp_lo, cp_hi) = (poly(&self.dh_l_sat, -1.0), poly(&self.dh_l_sat, 1.0));
        let below = h * (1.0 / cp_lo) + self.t_min_k;
        let above = (h - h_max) * (1.0 / cp_hi) + self.t_max_k;
        let (le0, ge_max, nan) = (
            h.le(T::splat(0.0)),
            h.ge(T::splat(h_max)),
            h.is(f64::is_nan),
        );
        let mut x = start;
        let (mut lo, mut hi) = (T::splat(-1.0), T::splat(1.0));
        let mut done = le0 | ge_max | nan;
        for _ in 0..MAX_ITER {
            if done.all() {
                break;
            }
            let f = self.h_l_above(x, base) - h;
            let zero = f.is_zero();
            let moving = !done & !zero;
            hi = T::select(moving & f.gt(T::splat(0.0)), x, hi);
            lo = T::select(moving & f.lt(T::splat(0.0)), x, lo);
            let x_newton = x - f / (poly(&self.dh_l_sat, x) * self.t_half());
            // A Newton step below tolerance is accepted (quadratic convergence).
            let converged = ((x_newton - x) * self.t_half())
                .abs()
                .le(self.t_of(x) * T_FROM_H_TOL);
            let inside = x_newton.gt(lo) & x_newton.lt(hi);
            let next = T::select(inside, x_newton, (lo + hi) * 0.5);
            let bracketed = ((hi - lo) * self.t_half()).le(self.t_of(next) * T_FROM_H_TOL);
            let step = T::select(converged, x_newton.clamp_c(-1.0, 1.0), next);
            x = T::select(moving, step, x);
            done = done | zero | (moving & (converged | bracketed));
        }
        let t = T::select(ge_max, above, self.t_of(x));
        let t = T::select(le0, below, t);
        T::select(nan, h, t)
    }

    /// Slope of [`Self::h_l_j_per_kg`] along saturation, J/(kg K) (the end-point value outside
    /// the range). Differs from `c_p,l` by `v (1 − βT) dP_sat/dT`: below 1 % up to about
    /// 0.7 T_crit, more towards `t_max_k`.
    pub fn dh_l_dt<T: Real>(&self, t_k: T) -> T {
        poly(&self.dh_l_sat, self.x_clamped(t_k))
    }

    /// Saturated-vapour density at `t_k` (K), kg/m³ (clamped outside the range): the fit of
    /// CoolProp's `D(Q=1)`, within 1.3e-4 (`tests/fluids.rs`).
    pub fn rho_v_sat_kg_per_m3<T: Real>(&self, t_k: T) -> T {
        poly(&self.ln_rho_v, self.x_clamped(t_k)).exp()
    }

    /// Latent heat of vaporisation at `t_k` (K), in J/kg (clamped outside the range).
    pub fn h_fg_j_per_kg<T: Real>(&self, t_k: T) -> T {
        poly(&self.h_fg, self.x_clamped(t_k))
    }

    /// Saturated-liquid thermal conductivity at `t_k` (K), in W/(m K) (clamped
    /// outside the range).
    pub fn k_l_w_per_m_k<T: Real>(&self, t_k: T) -> T {
        poly(&self.k_l, self.x_clamped(t_k))
    }

    /// Saturated-liquid dynamic viscosity at `t_k` (K), in Pa s (clamped outside the
    /// range).
    pub fn mu_l_pa_s<T: Real>(&self, t_k: T) -> T {
        poly(&self.ln_mu_l, self.x_clamped(t_k)).exp()
    }

    /// Vapour (dilute-gas) thermal conductivity at `t_k` (K), in W/(m K): power law
    /// fitted over `t_min_k .. 400 K` (T clamped to `[1, 10 000] K`).
    pub fn k_v_w_per_m_k(&self, t_k: f64) -> f64 {
        self.vapor_transport(t_k).0
    }

    /// Vapour (dilute-gas) dynamic viscosity at `t_k` (K), in Pa s: power law fitted
    /// over `t_min_k .. 400 K` (T clamped to `[1, 10 000] K`).
    pub fn mu_v_pa_s(&self, t_k: f64) -> f64 {
        self.vapor_transport(t_k).1
    }

    /// ([`Self::k_v_w_per_m_k`], [`Self::mu_v_pa_s`]) at `t_k` from one logarithm.
    pub fn vapor_transport<T: Real>(&self, t_k: T) -> (T, T) {
        let l = power_law_log(self.vapor_t_ref_k, t_k);
        (
            power_law(self.k_vapor_ref_w_per_m_k, self.k_vapor_exp, l),
            power_law(self.mu_vapor_ref_pa_s, self.mu_vapor_exp, l),
        )
    }
}

/// Helium pressurant, ideal gas (CoolProp 8.0.0 `Helium` source data, generated into
/// [`table`] by `tools/fit_fluids.py`); `#[repr(C)]`, only `f64` fields.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct GasProps {
    /// Molar mass in kg/mol (CoolProp `molar_mass`).
    pub molar_mass_kg_per_mol: f64,
    /// Ideal-gas isobaric specific heat in J/(kg K) (CoolProp `CP0MASS`).
    pub cp_j_per_kg_k: f64,
    /// Ideal-gas isochoric specific heat in J/(kg K): `cp − R_u/M`.
    pub cv_j_per_kg_k: f64,
    /// Thermal conductivity at `t_ref_k`, in W/(m K) (power law fitted at 1 bar over
    /// 5 .. 400 K).
    pub k_ref_w_per_m_k: f64,
    /// Exponent of the thermal-conductivity power law (dimensionless).
    pub k_exp: f64,
    /// Dynamic viscosity at `t_ref_k`, in Pa s (power law fitted at 1 bar over
    /// 5 .. 400 K).
    pub mu_ref_pa_s: f64,
    /// Exponent of the viscosity power law (dimensionless).
    pub mu_exp: f64,
    /// Reference temperature of the power laws in K.
    pub t_ref_k: f64,
}

impl GasProps {
    /// Specific gas constant `R_u / M`, J/(kg K).
    pub fn r_specific_j_per_kg_k(&self) -> f64 {
        R_UNIVERSAL / self.molar_mass_kg_per_mol
    }

    /// Thermal conductivity at `t_k` (K), in W/(m K): `k_ref (T/t_ref)^k_exp`, with T
    /// clamped to `[1, 10 000] K`.
    pub fn k_w_per_m_k(&self, t_k: f64) -> f64 {
        self.transport(t_k).0
    }

    /// Dynamic viscosity at `t_k` (K), in Pa s: `mu_ref (T/t_ref)^mu_exp`, with T
    /// clamped to `[1, 10 000] K`.
    pub fn mu_pa_s(&self, t_k: f64) -> f64 {
        self.transport(t_k).1
    }

    /// ([`Self::k_w_per_m_k`], [`Self::mu_pa_s`]) at `t_k` from one logarithm.
    pub fn transport<T: Real>(&self, t_k: T) -> (T, T) {
        let l = power_law_log(self.t_ref_k, t_k);
        (
            power_law(self.k_ref_w_per_m_k, self.k_exp, l),
            power_law(self.mu_ref_pa_s, self.mu_exp, l),
        )
    }
}
