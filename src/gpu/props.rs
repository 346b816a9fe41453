//! Host side of the f32 property kernels in `shaders/fluids.wgsl` and `shaders/geometry.wgsl`:
//! one [`gpu_struct!`] per fluid, pressurant and tank, filled in f64 (end-point values,
//! derivative coefficients, hi/lo splits) so the shaders avoid f32 cancellation.

use crate::fluids::{
    poly, poly_deriv, FluidProps, GasProps, LN_P_LIMIT, POWER_LAW_T_MAX_K, POWER_LAW_T_MIN_K,
};
use crate::geometry::{Shape, Tank};
use crate::gpu_struct;
use crate::model::state::vapor_energy_offset_of;

/// `v` as an unevaluated f32 sum `hi + lo` (about 48 significant bits), for differences
/// like `T − t_min` that must stay accurate when the operand is close to `v`.
fn split(v: f64) -> (f32, f32) {
    let hi = v as f32;
    (hi, (v - f64::from(hi)) as f32)
}

/// Rounds eight f64 coefficients to f32.
fn coefs(c: &[f64; 8]) -> [f32; 8] {
    c.map(|a| a as f32)
}

/// Monomial coefficients of the derivative of `Σ c_i x^i` (last entry 0).
fn deriv_coefs(c: &[f64; 8]) -> [f32; 8] {
    let mut d = [0.0_f32; 8];
    for i in 1..8 {
        d[i - 1] = (i as f64 * c[i]) as f32;
    }
    d
}

/// Coefficients of `S(x) = (P(x) − P(−1)) / (x + 1)`, `P` the antiderivative of the
/// `dh_l,sat/dT` polynomial: its mean over `[−1, x]`, so that `h_l = (T − t_min) S(x)` has no
/// cancellation near `t_min`.
fn mean_coefs(c: &[f64; 8]) -> [f32; 8] {
    let mut e = [0.0_f32; 8];
    for (j, ej) in e.iter_mut().enumerate() {
        let sign = |i: usize| if (i - j).is_multiple_of(2) { 1.0 } else { -1.0 };
        *ej = (j..8).map(|i| sign(i) * c[i] / (i + 1) as f64).sum::<f64>() as f32;
    }
    e
}

/// Largest `|ln P|` whose `exp` is a normal, finite f32 (`LN_P_LIMIT` narrowed to f32).
fn ln_p_limit_f32() -> f32 {
    LN_P_LIMIT.min(-f64::from(f32::MIN_POSITIVE).ln()).floor() as f32
}

gpu_struct! {
    /// One propellant's [`FluidProps`] in f32 for `shaders/fluids.wgsl` (`FL`), with the
    /// derived constants the shader would otherwise compute with cancellation.
    pub struct GpuFluid {
        /// `t_min_k` split as `hi + lo` (K).
        pub t_min_hi: f32,
        /// Low part of `t_min_k` (K).
        pub t_min_lo: f32,
        /// `t_max_k` (K).
        pub t_max: f32,
        /// Molar mass (kg/mol).
        pub molar_mass: f32,
        /// Critical pressure (Pa), for the divergence check.
        pub p_crit: f32,
        /// Real-gas vapour internal-energy offset (J/kg), `model::state::vapor_energy_offset`.
        pub vapor_offset: f32,
        /// Critical temperature (K), the virial form's `τ = T_c/T`.
        pub t_crit: f32,
        /// `1 / ρ_c` (m³/kg), the virial form's density scale.
        pub inv_rho_crit: f32,
        /// `T_mid = (t_min + t_max) / 2` split as `hi + lo` (K).
        pub t_mid_hi: f32,
        /// Low part of `T_mid` (K).
        pub t_mid_lo: f32,
        /// `T_half = (t_max − t_min) / 2` (K).
        pub t_half: f32,
        /// `1 / T_half` (1/K).
        pub inv_t_half: f32,
        /// `t_max − t_min` (K).
        pub t_span: f32,
        /// `ln P_sat` at `x = −1`.
        pub ln_psat_lo: f32,
        /// Slope of `ln P_sat` in `x` at `x = −1`.
        pub ln_psat_slope_lo: f32,
        /// `ln P_sat` at `x = 1`.
        pub ln_psat_hi: f32,
        /// Slope of `ln P_sat` in `x` at `x = 1`.
        pub ln_psat_slope_hi: f32,
        /// Limit on `|ln P_sat|` (the Rust limit, narrowed so `exp` stays a normal f32).
        pub ln_p_limit: f32,
        /// `dh_l,sat/dT` at `t_min` (J/(kg K)): slope of the `h_l` continuation below.
        pub dh_l_lo: f32,
        /// `dh_l,sat/dT` at `t_max` (J/(kg K)): slope of the `h_l` continuation above.
        pub dh_l_hi: f32,
        /// `h_l(t_max)` (J/kg).
        pub h_l_max: f32,
        /// Vapour specific gas constant `R_u / M` (J/(kg K)).
        pub r_specific: f32,
        /// Lower end of the vapour ideal-gas fit (K).
        pub ideal_t_lo: f32,
        /// Upper end of the vapour ideal-gas fit (K).
        pub ideal_t_hi: f32,
        /// `√T_lo` of the ideal-gas fit (√K).
        pub ideal_s_lo: f32,
        /// `1/(√T_hi − √T_lo)` of the ideal-gas fit (1/√K).
        pub ideal_inv_span: f32,
        /// Linearisation point of the ullage Newton start, the middle of the liquid range (K).
        pub ideal_t_ref: f32,
        /// `u⁰ + offset − c_v⁰ T` at `ideal_t_ref` (J/kg): the start's intercept.
        pub ideal_u_ref: f32,
        /// `c_v⁰` at `ideal_t_ref` (J/(kg K)): the start's slope.
        pub ideal_cv_ref: f32,
        /// Vapour conductivity at `vapor_t_ref` (W/(m K)).
        pub k_vapor_ref: f32,
        /// Vapour conductivity power-law exponent.
        pub k_vapor_exp: f32,
        /// Vapour viscosity at `vapor_t_ref` (Pa s).
        pub mu_vapor_ref: f32,
        /// Vapour viscosity power-law exponent.
        pub mu_vapor_exp: f32,
        /// Reference temperature of the vapour power laws (K).
        pub vapor_t_ref: f32,
        /// Lower temperature clamp of the power laws (K).
        pub power_t_min: f32,
        /// Upper temperature clamp of the power laws (K).
        pub power_t_max: f32,
        /// `ln P_sat` coefficients.
        pub ln_psat: [f32; 8],
        /// Derivative coefficients of `ln P_sat` in `x`.
        pub ln_psat_d: [f32; 8],
        /// `ρ_l` coefficients (kg/m³).
        pub rho_l: [f32; 8],
        /// Derivative coefficients of `ρ_l` in `x` (kg/m³).
        pub rho_l_d: [f32; 8],
        /// `c_p,l` coefficients (J/(kg K)).
        pub cp_l: [f32; 8],
        /// `dh_l,sat/dT` coefficients (J/(kg K)), the Newton slope of `h_l`'s inverse.
        pub dh_l_sat: [f32; 8],
        /// Mean-slope coefficients: `h_l = (T − t_min) Σ m_i x^i` inside the range (J/(kg K)).
        pub h_l_mean: [f32; 8],
        /// `h_fg` coefficients (J/kg).
        pub h_fg: [f32; 8],
        /// `k_l` coefficients (W/(m K)).
        pub k_l: [f32; 8],
        /// `ln μ_l` coefficients.
        pub ln_mu_l: [f32; 8],
        /// `ln ρ_v` (saturated vapour) coefficients.
        pub ln_rho_v: [f32; 8],
        /// Vapour virial coefficients `c_kj`, k-major (`FluidProps::vapor_virial`).
        pub virial: [f32; 24],
        /// Vapour ideal-gas polynomial `Q` (`FluidProps::vapor_ideal`).
        pub ideal: [f32; 16],
    }
}

impl GpuFluid {
    /// The f32 table of `f`, derived constants computed in f64.
    pub fn new(f: &FluidProps) -> GpuFluid {
        let (t_min_hi, t_min_lo) = split(f.t_min_k);
        let t_mid = 0.5 * (f.t_min_k + f.t_max_k);
        let t_half = 0.5 * (f.t_max_k - f.t_min_k);
        let (t_mid_hi, t_mid_lo) = split(t_mid);
        let (u_ref, cv_ref) = f.vapor_ideal(t_mid);
        GpuFluid {
            t_min_hi,
            t_min_lo,
            t_max: f.t_max_k as f32,
            molar_mass: f.molar_mass_kg_per_mol as f32,
            p_crit: f.p_crit_pa as f32,
            vapor_offset: vapor_energy_offset_of(f) as f32,
            t_crit: f.t_crit_k as f32,
            inv_rho_crit: (1.0 / f.rho_crit_kg_per_m3) as f32,
            t_mid_hi,
            t_mid_lo,
            t_half: t_half as f32,
            inv_t_half: (1.0 / t_half) as f32,
            t_span: (f.t_max_k - f.t_min_k) as f32,
            ln_psat_lo: poly(&f.ln_psat, -1.0) as f32,
            ln_psat_slope_lo: poly_deriv(&f.ln_psat, -1.0) as f32,
            ln_psat_hi: poly(&f.ln_psat, 1.0) as f32,
            ln_psat_slope_hi: poly_deriv(&f.ln_psat, 1.0) as f32,
            ln_p_limit: ln_p_limit_f32(),
            dh_l_lo: poly(&f.dh_l_sat, -1.0) as f32,
            dh_l_hi: poly(&f.dh_l_sat, 1.0) as f32,
            h_l_max: f.h_l_j_per_kg(f.t_max_k) as f32,
            r_specific: f.r_specific_j_per_kg_k() as f32,
            ideal_t_lo: f.ideal_t_lo_k as f32,
            ideal_t_hi: f.ideal_t_hi_k as f32,
            ideal_s_lo: f.ideal_t_lo_k.sqrt() as f32,
            ideal_inv_span: (1.0 / (f.ideal_t_hi_k.sqrt() - f.ideal_t_lo_k.sqrt())) as f32,
            ideal_t_ref: t_mid as f32,
            ideal_u_ref: (u_ref + vapor_energy_offset_of(f) - cv_ref * t_mid) as f32,
            ideal_cv_ref: cv_ref as f32,
            k_vapor_ref: f.k_vapor_ref_w_per_m_k as f32,
            k_vapor_exp: f.k_vapor_exp as f32,
            mu_vapor_ref: f.mu_vapor_ref_pa_s as f32,
            mu_vapor_exp: f.mu_vapor_exp as f32,
            vapor_t_ref: f.vapor_t_ref_k as f32,
            power_t_min: POWER_LAW_T_MIN_K as f32,
            power_t_max: POWER_LAW_T_MAX_K as f32,
            ln_psat: coefs(&f.ln_psat),
            ln_psat_d: deriv_coefs(&f.ln_psat),
            rho_l: coefs(&f.rho_l),
            rho_l_d: deriv_coefs(&f.rho_l),
            cp_l: coefs(&f.cp_l),
            dh_l_sat: coefs(&f.dh_l_sat),
            h_l_mean: mean_coefs(&f.dh_l_sat),
            h_fg: coefs(&f.h_fg),
            k_l: coefs(&f.k_l),
            ln_mu_l: coefs(&f.ln_mu_l),
            ln_rho_v: coefs(&f.ln_rho_v),
            virial: f.vapor_virial.map(|c| c as f32),
            ideal: f.vapor_ideal.map(|c| c as f32),
        }
    }
}

gpu_struct! {
    /// The helium pressurant's [`GasProps`] in f32 for `shaders/fluids.wgsl` (`HE`).
    pub struct GpuGas {
        /// Specific gas constant `R_u / M` (J/(kg K)).
        pub r_specific: f32,
        /// Molar mass (kg/mol).
        pub molar_mass: f32,
        /// Ideal-gas `c_p` (J/(kg K)), for the kernels.
        pub cp: f32,
        /// Ideal-gas `c_v` (J/(kg K)), for the kernels.
        pub cv: f32,
        /// Conductivity at `t_ref` (W/(m K)).
        pub k_ref: f32,
        /// Conductivity power-law exponent.
        pub k_exp: f32,
        /// Viscosity at `t_ref` (Pa s).
        pub mu_ref: f32,
        /// Viscosity power-law exponent.
        pub mu_exp: f32,
        /// Reference temperature of the power laws (K).
        pub t_ref: f32,
        /// Lower temperature clamp of the power laws (K).
        pub power_t_min: f32,
        /// Upper temperature clamp of the power laws (K).
        pub power_t_max: f32,
    }
}

impl GpuGas {
    /// The f32 constants of `g`.
    pub fn new(g: &GasProps) -> GpuGas {
        GpuGas {
            r_specific: g.r_specific_j_per_kg_k() as f32,
            molar_mass: g.molar_mass_kg_per_mol as f32,
            cp: g.cp_j_per_kg_k as f32,
            cv: g.cv_j_per_kg_k as f32,
            k_ref: g.k_ref_w_per_m_k as f32,
            k_exp: g.k_exp as f32,
            mu_ref: g.mu_ref_pa_s as f32,
            mu_exp: g.mu_exp as f32,
            t_ref: g.t_ref_k as f32,
            power_t_min: POWER_LAW_T_MIN_K as f32,
            power_t_max: POWER_LAW_T_MAX_K as f32,
        }
    }
}

gpu_struct! {
    /// A [`Tank`] in f32 for `shaders/geometry.wgsl` (`TANK`): its dimensions and totals,
    /// with the top height and total volume split `hi + lo` for cancellation-free depths
    /// below the top.
    pub struct GpuTank {
        /// Shape code: 1 for a domed tank (capsule or sphere), 0 for a cylinder.
        pub domed: u32,
        /// Radius `R` (m).
        pub radius: f32,
        /// Cylinder length `L` (m).
        pub length: f32,
        /// Dome ratio `k`.
        pub k: f32,
        /// Dome height `a = k R` (m).
        pub a: f32,
        /// `e = 1 − k²`.
        pub e: f32,
        /// `√|e|`.
        pub sqrt_abs_e: f32,
        /// `c = k² R` (m).
        pub c: f32,
        /// `1 / k²`.
        pub inv_k2: f32,
        /// Height of the top of the cylindrical part, `a + L` (m).
        pub z_top_cyl: f32,
        /// Total height `H` split as `hi + lo` (m).
        pub height_hi: f32,
        /// Low part of `H` (m).
        pub height_lo: f32,
        /// Total volume split as `hi + lo` (m³).
        pub volume_hi: f32,
        /// Low part of the total volume (m³).
        pub volume_lo: f32,
        /// Total wall area (m²).
        pub wall_area: f32,
        /// Volume of one dome (m³).
        pub dome_volume: f32,
        /// Wall area of one dome, or the end disc of a cylinder (m²).
        pub dome_area: f32,
        /// Cross-section `π R²` (m²).
        pub disc_area: f32,
        /// `2π R` (m).
        pub two_pi_r: f32,
        /// `π / k²`.
        pub pi_over_k2: f32,
    }
}

impl GpuTank {
    /// The f32 description of `t`, derived constants computed in f64.
    pub fn new(t: &Tank) -> GpuTank {
        use std::f64::consts::PI;
        let k = t.dome_ratio();
        let (height_hi, height_lo) = split(t.height_m());
        let (volume_hi, volume_lo) = split(t.volume_m3());
        GpuTank {
            domed: u32::from(t.shape() != Shape::Cylinder),
            radius: t.radius_m() as f32,
            length: t.length_m() as f32,
            k: k as f32,
            a: t.dome_height_m() as f32,
            e: t.dome_e() as f32,
            sqrt_abs_e: t.dome_e().abs().sqrt() as f32,
            c: t.dome_c_m() as f32,
            inv_k2: (1.0 / (k * k)) as f32,
            z_top_cyl: (t.dome_height_m() + t.length_m()) as f32,
            height_hi,
            height_lo,
            volume_hi,
            volume_lo,
            wall_area: t.wall_area_m2() as f32,
            dome_volume: t.dome_volume_m3() as f32,
            dome_area: t.dome_area_m2() as f32,
            disc_area: t.disc_area_m2() as f32,
            two_pi_r: (2.0 * PI * t.radius_m()) as f32,
            pi_over_k2: (PI / (k * k)) as f32,
        }
    }
}

/// The domed-tank slosh tables of [`crate::model::slosh_table`] in f32 as the GPU reads them:
/// bottom dome, barrel, top dome, zero-padded to whole excitation rows of three floats. They
/// are the first floats of the kernel's `tables` storage buffer ([`super::params::Tables`]
/// puts them there; `shaders/slosh_modes.wgsl` reads them). A buffer rather than a WGSL
/// `const` array: every storage binding is taken, and a runtime-indexed 6,604-element constant
/// array is lowered by llvmpipe into compare-and-select chains (a test kernel took over 14
/// minutes to compile).
pub fn slosh_table_f32() -> Vec<f32> {
    use crate::model::slosh_table as t;
    let mut v: Vec<f32> = [&t::BOTTOM[..], &t::BARREL[..], &t::TOP[..]]
        .concat()
        .iter()
        .map(|&x| x as f32)
        .collect();
    v.resize(v.len().div_ceil(3) * 3, 0.0);
    v
}

/// WGSL constants of the domed-tank slosh tables, generated from [`crate::model::slosh_table`]
/// (layouts and constants generated, not copied): the grid sizes and steps as `SLOSH_*`
/// constants, and `SLOSH_BARREL_AT` and `SLOSH_TOP_AT` the offsets of the barrel and top-dome
/// tables in [`slosh_table_f32`] (the bottom dome's is 0). `shaders/slosh_modes.wgsl`
/// interpolates them as `model::slosh::domed_modes` does.
pub fn slosh_table_wgsl() -> String {
    use crate::model::slosh::{MIN_DEPTH_RATIO, MIN_SURFACE_RADIUS_RATIO, XI};
    use crate::model::slosh_table as t;
    let mut s = String::new();
    for (name, v) in [
        ("SLOSH_NK", t::NK),
        ("SLOSH_N_SIGMA", t::N_SIGMA),
        ("SLOSH_N_BARREL", t::N_BARREL),
        ("SLOSH_N_TOP", t::N_TOP),
        ("SLOSH_N_BETA", t::N_BETA),
        ("SLOSH_BARREL_AT", t::BOTTOM.len()),
        ("SLOSH_TOP_AT", t::BOTTOM.len() + t::BARREL.len()),
    ] {
        s += &format!("const {name}: u32 = {v}u;\n");
    }
    for (name, v) in [
        ("SLOSH_LOG2K_0", t::LOG2K_0),
        ("SLOSH_LOG2K_STEP", t::LOG2K_STEP),
        ("SLOSH_BARREL_H_MAX", t::BARREL_H_MAX),
        ("SLOSH_TOP_U_MAX", t::TOP_U_MAX),
        ("SLOSH_BETA_RATE", 2.0 * XI[0]),
        ("SLOSH_RS_MIN", MIN_SURFACE_RADIUS_RATIO),
        ("SLOSH_XI_0", XI[0]),
        ("SLOSH_XI_1", XI[1]),
        ("SLOSH_MIN_DEPTH_RATIO", MIN_DEPTH_RATIO),
    ] {
        s += &format!("const {name}: f32 = {v:e};\n");
    }
    s
}

/// WGSL source of the property library: the `GpuFluid`, `GpuGas` and `GpuTank` declarations,
/// the slosh table constants ([`slosh_table_wgsl`]), then `shaders/fluids.wgsl`,
/// `shaders/geometry.wgsl` and `shaders/slosh_modes.wgsl`. Kernels append their entry points,
/// assign `FL`, `HE` and `TANK` once per invocation, and declare
/// `var<storage, read> tables: array<f32>` starting with [`slosh_table_f32`].
pub fn props_wgsl() -> String {
    let mut s = GpuFluid::wgsl();
    s += &GpuGas::wgsl();
    s += &GpuTank::wgsl();
    s += &slosh_table_wgsl();
    s += include_str!("../../shaders/fluids.wgsl");
    s += include_str!("../../shaders/geometry.wgsl");
    s += include_str!("../../shaders/slosh_modes.wgsl");
    s
}
