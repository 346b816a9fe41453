//! Heat leak through the tank's insulation (`[insulation]`, issue 17): spray-on foam (SOFI) on
//! the wall and multilayer insulation (MLI) over it, in series between the wall and the
//! surroundings of the phase (ground hold or space). Replaces the fixed `tank.heat_leak_w` when
//! the campaign has the section; docs/PHYSICS.md section 2.5 gives the equations and sources.
//!
//! The outer surface temperature follows from the steady energy balance of the insulation
//! (no heat stored in it): what the surroundings deliver to the outer surface is what the foam
//! and the blanket conduct to the wall. It is solved by a fixed number of safeguarded Newton
//! steps ([`OUTER_ITERATIONS`], [`INNER_ITERATIONS`]): the same count on the CPU (f64) and in
//! `shaders/insulation.wgsl` (f32), no loop whose length depends on the data.

use super::derive::{Derived, Drive};
use super::Group;
use crate::lanes::{c, Real};

/// Stefan–Boltzmann constant, W/(m²·K⁴) (CODATA 2018).
pub const STEFAN_BOLTZMANN: f64 = 5.670_374_419e-8;
/// Solid-conduction coefficient C_s of the modified Lockheed equation (Johnson 2010, below),
/// with the layer density in layers/cm; it multiplies the Dacron-netting factor
/// f(T_m) = 0.017 + 7e-6 (800 − T_m) + 0.0228 ln T_m.
pub const MLI_SOLID_COEFF: f64 = 2.4e-4;
/// Radiation coefficient C_r of the modified Lockheed equation, W/(m²·K^4.67).
pub const MLI_RADIATION_COEFF: f64 = 4.944e-10;
/// Residual-gas conduction coefficient C_g (nitrogen), W/(m²·torr·K^0.52) (Keller et al. 1974).
pub const MLI_GAS_COEFF: f64 = 1.46e4;
/// Exponent of the layer density in the solid-conduction term, –.
pub const MLI_DENSITY_EXPONENT: f64 = 2.63;
/// Temperature exponent of the radiation term, –.
pub const MLI_RADIATION_EXPONENT: f64 = 4.67;
/// Temperature exponent of the gas-conduction term, –.
pub const MLI_GAS_EXPONENT: f64 = 0.52;
/// Default effective emittance ε of the double-aluminized shields, – (Keller et al. 1974).
pub const MLI_DEFAULT_EMISSIVITY: f64 = 0.031;
/// Lowest temperature the correlations are evaluated at, K (a cold sink can pull a trial
/// interface temperature towards 0 K during the iteration).
pub const MIN_INSULATION_TEMPERATURE_K: f64 = 1.0;
/// Safeguarded Newton steps on the heat flux through the blanket. Ten reach the f64 round-off over layer counts 1–1000, densities 1–100 /cm,
/// foam 0.1 mm–0.3 m, convection 0–1000 W/(m²·K) and sinks 0–400 K (tests/insulation.rs).
pub const OUTER_ITERATIONS: u32 = 10;
/// Newton steps inverting the surroundings' flux for the outer temperature in each outer step
/// (from an upper bound of the root, where the concave flux makes them monotone).
pub const INNER_ITERATIONS: u32 = 12;
/// Safeguarded Newton steps on the outer temperature of bare foam (no blanket): polynomial
/// only, so more of them are cheap; 16 reach the round-off from the warm end on the same grid.
pub const FOAM_ITERATIONS: u32 = 20;

/// Spray-on foam bonded to the wall: 1-D conduction with a constant conductivity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Foam {
    /// Thickness L, m, in (0, 1].
    pub thickness_m: f64,
    /// Effective conductivity k over the foam's temperature span, W/(m·K), in [1e-4, 1].
    pub conductivity_w_per_m_k: f64,
}

impl Foam {
    /// Conduction resistance L/k, m²·K/W.
    pub fn resistance_m2_k_per_w(&self) -> f64 {
        self.thickness_m / self.conductivity_w_per_m_k
    }

    /// Flux k (T_h − T_c)/L from the warm face at `t_hot_k` to the cold face at `t_cold_k`, W/m².
    pub fn flux_w_per_m2(&self, t_hot_k: f64, t_cold_k: f64) -> f64 {
        self.conductivity_w_per_m_k * (t_hot_k - t_cold_k) / self.thickness_m
    }
}

/// A multilayer blanket described by the modified Lockheed equation (layer-by-layer form).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mli {
    /// Number of reflective shields N_s, –, in [1, 1000] (real: dispersable).
    pub layers: f64,
    /// Layer density N̄, layers/cm, in [1, 100].
    pub layer_density_per_cm: f64,
    /// Interstitial (residual gas) pressure P, torr, in [0, 1e-3].
    pub interstitial_pressure_torr: f64,
    /// Effective shield emittance ε, –, in [0.005, 0.5].
    pub shield_emissivity: f64,
    /// Multiplier on the whole flux for seams, penetrations and compression, –, in [1, 100].
    pub degradation_factor: f64,
}

impl Mli {
    /// The flux coefficients of this blanket (degradation included).
    pub fn coefficients(&self) -> MliCoefficients {
        let d = self.degradation_factor;
        let n = self.layers;
        MliCoefficients {
            solid: d * MLI_SOLID_COEFF * self.layer_density_per_cm.powf(MLI_DENSITY_EXPONENT)
                / (n + 1.0),
            radiation: d * MLI_RADIATION_COEFF * self.shield_emissivity / n,
            gas: d * MLI_GAS_COEFF * self.interstitial_pressure_torr / n,
        }
    }

    /// Flux from the warm face at `t_hot_k` to the cold face at `t_cold_k`, W/m².
    pub fn flux_w_per_m2(&self, t_hot_k: f64, t_cold_k: f64) -> f64 {
        mli_flux(&self.coefficients(), t_hot_k, t_cold_k).0
    }
}

/// The modified Lockheed equation's three terms with the blanket's numbers folded in:
/// q = solid · f(T_m) (T_h − T_c) + radiation · (T_h^4.67 − T_c^4.67) + gas · (T_h^0.52 − T_c^0.52).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MliCoefficients<T = f64> {
    /// D C_s N̄^2.63 / (N_s + 1), W/(m²·K).
    pub solid: T,
    /// D C_r ε / N_s, W/(m²·K^4.67).
    pub radiation: T,
    /// D C_g P / N_s, W/(m²·K^0.52).
    pub gas: T,
}

/// MLI flux and its partial derivatives by the warm and the cold face temperature:
/// (q W/m², ∂q/∂T_h, ∂q/∂T_c in W/(m²·K)). Temperatures below
/// [`MIN_INSULATION_TEMPERATURE_K`] are evaluated there.
pub fn mli_flux<T: Real>(k: &MliCoefficients<T>, t_hot_k: T, t_cold_k: T) -> (T, T, T) {
    let th = t_hot_k.max_c(MIN_INSULATION_TEMPERATURE_K);
    let tc = t_cold_k.max_c(MIN_INSULATION_TEMPERATURE_K);
    let (ln_h, ln_c) = (th.ln(), tc.ln());
    let tm = (th + tc) * 0.5;
    // Dacron-netting conductivity factor and its slope in T_m.
    let f = (tm.rsub(800.0) * 7.0e-6) + tm.ln() * 0.0228 + 0.017;
    let df = tm.rdiv(0.0228) - 7.0e-6;
    let (rh, rc) = (
        (ln_h * MLI_RADIATION_EXPONENT).exp(),
        (ln_c * MLI_RADIATION_EXPONENT).exp(),
    );
    let (gh, gc) = (
        (ln_h * MLI_GAS_EXPONENT).exp(),
        (ln_c * MLI_GAS_EXPONENT).exp(),
    );
    let dt = th - tc;
    let q = k.solid * f * dt + k.radiation * (rh - rc) + k.gas * (gh - gc);
    let half_slope = df * dt * 0.5;
    let dq_dh = k.solid * (f + half_slope)
        + k.radiation * MLI_RADIATION_EXPONENT * rh / th
        + k.gas * MLI_GAS_EXPONENT * gh / th;
    let dq_dc = k.solid * (half_slope - f)
        - k.radiation * MLI_RADIATION_EXPONENT * rc / tc
        - k.gas * MLI_GAS_EXPONENT * gc / tc;
    // Where a face is held at the floor temperature the flux does not move with it.
    let floor = c(MIN_INSULATION_TEMPERATURE_K);
    (
        q,
        T::select(t_hot_k.lt(floor), c(0.0), dq_dh),
        T::select(t_cold_k.lt(floor), c(0.0), dq_dc),
    )
}

/// What the surroundings deliver to the outer surface at temperature T, W/m²:
/// g(T) = h (T_air − T) + ε σ (T_rad⁴ − T⁴) + q_abs — convection, grey radiation exchange with
/// a black enclosure at T_rad, and an absorbed flux.
#[derive(Clone, Copy, Debug)]
pub struct Surroundings<T = f64> {
    /// Convection coefficient, W/(m²·K).
    pub h_w_per_m2_k: T,
    /// Air temperature, K.
    pub t_air_k: T,
    /// Radiation sink temperature to the fourth, K⁴.
    pub t_rad4_k4: T,
    /// Absorbed flux, W/m².
    pub absorbed_w_per_m2: T,
    /// Outer emissivity times σ, W/(m²·K⁴).
    pub eps_sigma: T,
}

impl<T: Real> Surroundings<T> {
    /// g(T) and dg/dT (≤ 0).
    pub fn flux(&self, t_k: T) -> (T, T) {
        let t2 = t_k * t_k;
        let g = self.h_w_per_m2_k * (self.t_air_k - t_k)
            + self.eps_sigma * (self.t_rad4_k4 - t2 * t2)
            + self.absorbed_w_per_m2;
        let slope = -(self.h_w_per_m2_k + self.eps_sigma * t2 * t_k * 4.0);
        (g, slope)
    }

    /// Temperature at which the radiation and absorbed terms cancel, K.
    fn radiative_equilibrium_k(&self) -> T {
        (self.t_rad4_k4 + self.absorbed_w_per_m2 / self.eps_sigma)
            .sqrt()
            .sqrt()
    }
}

/// The insulation between wall and surroundings, per lane: foam resistance (0 without foam)
/// and the blanket's coefficients (`None`: no blanket).
#[derive(Clone, Copy, Debug)]
pub struct Stack<T = f64> {
    /// Foam L/k, m²·K/W.
    pub foam_resistance_m2_k_per_w: T,
    pub mli: Option<MliCoefficients<T>>,
}

/// The steady state of the insulation at one wall temperature.
#[derive(Clone, Copy, Debug)]
pub struct Leak<T = f64> {
    /// Heat flux into the wall, W/m² (negative: the wall loses heat).
    pub flux_w_per_m2: T,
    /// Outer surface temperature, K.
    pub t_outer_k: T,
    /// Foam–blanket interface temperature, K (the wall's, plus the foam's drop).
    pub t_interface_k: T,
}

/// The root `x` of a monotone residual with value `r` there: the Newton step `x − r/slope`
/// when it stays inside the bracket [lo, hi] that `r`'s sign has just narrowed, else its middle.
fn safeguarded<T: Real>(x: T, r: T, slope: T, increasing: bool, lo: &mut T, hi: &mut T) -> T {
    let above = if increasing {
        r.gt(c(0.0))
    } else {
        r.lt(c(0.0))
    };
    *hi = T::select(above, x, *hi);
    *lo = T::select(above, *lo, x);
    let next = x - r / slope;
    let inside = next.ge(*lo) & next.le(*hi);
    T::select(inside, next, (*lo + *hi) * 0.5)
}

/// Outer surface temperature at which the surroundings deliver `q` (W/m²), and dg/dT there:
/// Newton from an upper bound of the root (g is concave and decreasing, so the steps approach
/// it from above), kept in [t_lo, t_hi]. The bound is the smaller of max(A, T_rad) and
/// max(T_air, B), A the root of the convective and absorbed terms alone and B that of the
/// radiative and absorbed terms (exact without convection, as in space): at either both
/// parts of g − q are ≤ 0.
fn outer_temperature<T: Real>(env: &Surroundings<T>, q: T, t_lo: T, t_hi: T) -> (T, T) {
    let excess = env.absorbed_w_per_m2 - q;
    let a = env.t_air_k + excess / env.h_w_per_m2_k.max_c(1.0e-30);
    let b = (env.t_rad4_k4 + excess / env.eps_sigma)
        .max_c(0.0)
        .sqrt()
        .sqrt();
    let t_rad = env.t_rad4_k4.sqrt().sqrt();
    let mut t = a.max(t_rad).min(env.t_air_k.max(b)).max(t_lo).min(t_hi);
    for _ in 0..INNER_ITERATIONS {
        let (g, slope) = env.flux(t);
        t = (t - (g - q) / slope.min_c(-1.0e-12)).max(t_lo).min(t_hi);
    }
    let (_, slope) = env.flux(t);
    (t, slope)
}

/// Steady heat flux through `stack` into a wall at `t_wall_k` from `env`.
///
/// Bracket: the outer temperature lies between the wall's, the air's and the radiative
/// equilibrium temperature (where g = 0). Bare foam: Newton on T_o for
/// k/L (T_o − T_w) = g(T_o). With a blanket: Newton on the flux q, the outer temperature
/// from g(T_o) = q and the interface from T_i = T_w + q L/k, for
/// q_MLI(T_o, T_i) = q — decreasing in q, so bracketed between g at either end.
pub fn leak<T: Real>(stack: &Stack<T>, env: &Surroundings<T>, t_wall_k: T) -> Leak<T> {
    let t_eq = env.radiative_equilibrium_k();
    let t_lo = t_wall_k.min(env.t_air_k).min(t_eq);
    let t_hi = t_wall_k.max(env.t_air_k).max(t_eq);
    let r_foam = stack.foam_resistance_m2_k_per_w;
    let Some(mli) = stack.mli else {
        let conductance = r_foam.rdiv(1.0);
        let (mut lo, mut hi, mut t) = (t_lo, t_hi, t_hi);
        for _ in 0..FOAM_ITERATIONS {
            let (g, slope) = env.flux(t);
            let r = conductance * (t - t_wall_k) - g;
            t = safeguarded(t, r, conductance - slope, true, &mut lo, &mut hi);
        }
        return Leak {
            flux_w_per_m2: conductance * (t - t_wall_k),
            t_outer_k: t,
            t_interface_k: t,
        };
    };
    let (mut lo, mut hi) = (env.flux(t_hi).0, env.flux(t_lo).0);
    // Start from the bare blanket between the warm end and the wall, within the bracket and
    // below what the foam alone could pass.
    let bare = mli_flux(&mli, t_hi, t_wall_k).0;
    let foam_cap = (t_hi - t_wall_k) / r_foam.max_c(1.0e-300);
    let mut q = bare.min(foam_cap).max(lo).min(hi);
    for _ in 0..OUTER_ITERATIONS {
        let (t_o, slope) = outer_temperature(env, q, t_lo, t_hi);
        let (qm, dq_dh, dq_dc) = mli_flux(&mli, t_o, t_wall_k + r_foam * q);
        let dr = dq_dh / slope.min_c(-1.0e-12) + dq_dc * r_foam - 1.0;
        q = safeguarded(q, qm - q, dr, false, &mut lo, &mut hi);
    }
    Leak {
        flux_w_per_m2: q,
        t_outer_k: outer_temperature(env, q, t_lo, t_hi).0,
        t_interface_k: t_wall_k + r_foam * q,
    }
}

/// Heat into each wall node from outside, W, and the per-node forcing Q/C (K/s) of the stiff
/// wall exchange (`thermal::wall_exchange`).
#[derive(Clone, Copy, Debug)]
pub struct WallHeat<T = f64> {
    /// Into the dry (ullage) wall node, W.
    pub dry_w: T,
    /// Into the wetted wall node, W.
    pub wet_w: T,
    /// Total Q_env, W (the `E_ENV` ledger).
    pub total_w: T,
    /// dry_w over the dry node's heat capacity, K/s.
    pub warming_dry_k_s: T,
    /// wet_w over the wetted node's heat capacity, K/s.
    pub warming_wet_k_s: T,
}

/// Each lane's stack and the surroundings of its current phase (`d.space`).
fn lanes<T: Real>(g: Group<'_>, d: &Drive<T>) -> (Stack<T>, Surroundings<T>) {
    let ins = |f: fn(&super::params::Insulation) -> f64| {
        g.get::<T>(move |p| p.insulation.as_ref().map_or(0.0, f))
    };
    let shared = g.shared().insulation.as_ref();
    let stack = Stack {
        foam_resistance_m2_k_per_w: ins(|i| i.foam.map_or(0.0, |f| f.resistance_m2_k_per_w())),
        mli: shared.and_then(|i| i.mli).map(|_| MliCoefficients {
            solid: ins(|i| i.mli.map_or(0.0, |m| m.coefficients().solid)),
            radiation: ins(|i| i.mli.map_or(0.0, |m| m.coefficients().radiation)),
            gas: ins(|i| i.mli.map_or(0.0, |m| m.coefficients().gas)),
        }),
    };
    let t_amb = ins(|i| i.ground_ambient_temperature_k);
    let t_sink = ins(|i| i.space_sink_temperature_k);
    let t_rad = T::select(d.space, t_sink, t_amb);
    let t_rad2 = t_rad * t_rad;
    let env = Surroundings {
        h_w_per_m2_k: T::select(d.space, c(0.0), ins(|i| i.ground_convection_w_per_m2_k)),
        t_air_k: t_rad,
        t_rad4_k4: t_rad2 * t_rad2,
        absorbed_w_per_m2: T::select(
            d.space,
            ins(|i| i.outer_absorptivity * i.space_incident_flux_w_per_m2),
            c(0.0),
        ),
        eps_sigma: ins(|i| i.outer_emissivity * STEFAN_BOLTZMANN),
    };
    (stack, env)
}

/// The heat leak into the wall nodes: the fixed `tank.heat_leak_w` shared by area, or with
/// `[insulation]` the steady flux at each node's own temperature times its share of the wall
/// area (insulated area = the tank's inner wall area; the insulation's thickness is neglected
/// against the radius).
pub fn wall_heat<T: Real>(g: Group<'_>, d: &Drive<T>, x: &Derived<T>) -> WallHeat<T> {
    let c_wall: T = g.get(super::params::Params::wall_heat_capacity_j_per_k);
    let dry_share = x.wetted_share.rsub(1.0);
    if g.shared().insulation.is_none() {
        let q: T = g.get(|p| p.heat_leak_w);
        let warming = q / c_wall;
        return WallHeat {
            dry_w: q * dry_share,
            wet_w: q * x.wetted_share,
            total_w: q,
            warming_dry_k_s: warming,
            warming_wet_k_s: warming,
        };
    }
    let (stack, env) = lanes(g, d);
    let area = g.tank::<T>().wall_area_m2();
    let dry = leak(&stack, &env, x.t_wall_dry_k).flux_w_per_m2 * area;
    let wet = leak(&stack, &env, x.t_wall_wet_k).flux_w_per_m2 * area;
    WallHeat {
        dry_w: dry * dry_share,
        wet_w: wet * x.wetted_share,
        total_w: dry * dry_share + wet * x.wetted_share,
        warming_dry_k_s: dry / c_wall,
        warming_wet_k_s: wet / c_wall,
    }
}
