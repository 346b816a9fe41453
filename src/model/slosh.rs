//! Slosh mechanical-analog parameters and damping (MODEL.md §5).
//!
//! Modal masses, lengths and frequencies of a flat-bottom upright cylinder (Abramson, NASA SP-106,
//! ch. 6; Dodge, "The New Dynamic Behavior of Liquids in Moving Containers", 2000). Spheres and
//! domed tanks use the equivalent cylinder documented in [`equivalent_cylinder`].

use super::Group;
use crate::lanes::{c, Mask, Real};
use std::f64::consts::PI;

/// Roots of J1'(ξ) = 0 for the first two antisymmetric modes.
pub const XI: [f64; 2] = [1.841_18, 5.331_44];

/// Smallest axial acceleration the slosh model sees, m/s² (MODEL.md §5 floor). Below it the
/// restoring stiffness is this floor: frequencies go to ~0.3 mHz in a 1 m tank, never to NaN.
pub const MIN_AXIAL_ACCEL: f64 = 1.0e-6;

/// Shallowest equivalent depth ratio h/R, so that modal formulas stay finite near empty.
pub const MIN_DEPTH_RATIO: f64 = 0.02;

/// Dimensionless properties of slosh mode `n` (0-based) at depth ratio h/R.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeShape<T = f64> {
    /// Modal mass over liquid mass, m_n / m_l.
    pub mass_ratio: T,
    /// Pendulum length over radius, L_n / R.
    pub length_ratio: T,
    /// ω_n² R / a_ax.
    pub omega2_ratio: T,
}

/// SP-106 modal properties of a flat-bottom cylinder.
pub fn mode_shape<T: Real>(n: usize, h_over_r: T) -> ModeShape<T> {
    let xi = XI[n];
    let hr = h_over_r.max_c(MIN_DEPTH_RATIO);
    // tanh a = 1 − 2 / (e^(2a) + 1), a ≥ 0.037 here: within 1e-14 of libm, one exp.
    let th = ((hr * (2.0 * xi)).exp() + 1.0).rdiv(2.0).rsub(1.0);
    ModeShape {
        mass_ratio: th * 2.0 / (hr * (xi * (xi * xi - 1.0))),
        length_ratio: (th * xi).rdiv(1.0),
        omega2_ratio: th * xi,
    }
}

/// Equivalent flat-bottom cylinder for any shape: the free-surface radius r and the depth that
/// holds the liquid volume under that surface, h = V_l / (π r²). Exact for a cylinder; for a
/// half-full sphere it gives ω² R/g = 1.550 against 1.56 from McIver (1989). Returns (R, h).
pub fn equivalent_cylinder<T: Real>(
    surface_radius_m: T,
    liquid_volume_m3: T,
    tank_radius_m: T,
) -> (T, T) {
    let r = surface_radius_m.max(tank_radius_m * 0.05);
    let h = liquid_volume_m3 / (r * r * PI);
    (r, h)
}

/// Smooth-wall viscous damping ratio (Mikishev & Dorozhkin, via SP-106 eq. 4.7).
#[expect(
    clippy::approx_constant,
    reason = "0.318 is the published empirical constant, not 1/π"
)]
/// `nu` kinematic viscosity m²/s, `r` radius m, `a_ax` axial acceleration m/s².
pub fn wall_damping<T: Real>(nu: T, r: T, a_ax: T, h_over_r: T) -> T {
    let hr = h_over_r.max_c(MIN_DEPTH_RATIO);
    let x = hr * 1.84;
    // sinh and cosh from one exp (x ≥ 0.037: within 1e-14 of libm).
    let (e, inv) = (x.exp(), x.exp().rdiv(1.0));
    let (sinh, cosh) = ((e - inv) * 0.5, (e + inv) * 0.5);
    let shape = sinh.rdiv(0.318) * ((hr.rsub(1.0) / cosh) + 1.0) + 1.0;
    // r^(-3/4) a^(-1/4) = (r³ a)^(-1/4), by two square roots.
    let a = a_ax.max_c(MIN_AXIAL_ACCEL);
    nu.sqrt() * (4.98 / (2.0 * PI)) * shape / (r * r * r * a).sqrt().sqrt()
}

/// Ring-baffle damping ratio (Miles 1958, SP-106 eq. 4.15): only rings below the surface count,
/// each weighted by exp(−4.6 d/R) with d its depth below the free surface `z_surface_m`. The
/// ring count may differ between lanes: rings beyond a lane's count add nothing to it.
pub fn baffle_damping<T: Real>(g: Group<'_>, r: T, z_surface_m: T) -> T {
    let rings = g.lanes().iter().map(|p| p.baffles.count).max().unwrap_or(0);
    if rings == 0 {
        return c(0.0);
    }
    let width: T = g.get(|p| p.baffles.width_m);
    let (top, spacing): (T, T) = (
        g.get(|p| p.baffles.top_height_m),
        g.get(|p| p.baffles.spacing_m),
    );
    let w = (width / r).min_c(1.0);
    let alpha = w * w.rsub(2.0);
    let mut sum: T = c(0.0);
    for k in 0..rings {
        let z_ring = top - spacing * f64::from(k);
        let depth = z_surface_m - z_ring;
        let counts = T::Mask::from_fn(|i| k < g.lanes()[i].baffles.count);
        let under = depth.ge(c(0.0)) & counts;
        sum += T::select(under, (depth * -4.6 / r).exp(), c(0.0));
    }
    let amplitude: T = g.get(|p| p.baffles.wave_amplitude_m);
    let zeta = (amplitude / r).sqrt() * 2.83 * sum * alpha * alpha.sqrt();
    let none = T::Mask::from_fn(|i| g.lanes()[i].baffles.count == 0) | width.le(c(0.0));
    T::select(none, c(0.0), zeta)
}
