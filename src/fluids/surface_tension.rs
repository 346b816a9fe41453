//! Surface tension along saturation, σ = σ_0 (1 − T/T_c)^n (Guggenheim 1945), fitted to
//! CoolProp by `tools/surface_tension.py` (generated: do not edit). The fixtures
//! `tests/fixtures/fluids/*_sigma.csv` check it (`tests/fluids.rs`).

/// σ_0 (N/m), n and T_c (K) of one propellant; the largest relative fit error over
/// T_triple + 1 K .. 0.9 T_c in the comment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceTension {
    pub sigma0_n_per_m: f64,
    pub exponent: f64,
    pub t_crit_k: f64,
}

/// LH2: largest relative error 7.39e-06.
pub const LH2: SurfaceTension = SurfaceTension {
    sigma0_n_per_m: 0.005313941692436251,
    exponent: 1.059980215198373,
    t_crit_k: 32.93785506891549,
};
/// LOX: largest relative error 2.65e-04.
pub const LOX: SurfaceTension = SurfaceTension {
    sigma0_n_per_m: 0.03844041398171781,
    exponent: 1.2255727144075206,
    t_crit_k: 154.59938983528554,
};
/// LCH4: largest relative error 7.73e-03.
pub const LCH4: SurfaceTension = SurfaceTension {
    sigma0_n_per_m: 0.037600904608718545,
    exponent: 1.2114647349517564,
    t_crit_k: 190.56400265128698,
};
/// LN2: largest relative error 5.81e-12.
pub const LN2: SurfaceTension = SurfaceTension {
    sigma0_n_per_m: 0.028979999999672844,
    exponent: 1.245999999981627,
    t_crit_k: 126.19199999958556,
};
/// nLH2: largest relative error 2.92e-02.
pub const NLH2: SurfaceTension = SurfaceTension {
    sigma0_n_per_m: 0.005948596193729563,
    exponent: 1.194469473797576,
    t_crit_k: 33.1443326883113,
};
