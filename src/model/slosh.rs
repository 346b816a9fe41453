//! Slosh mechanical-analog parameters and damping (MODEL.md §5).
//!
//! Modal masses, lengths and frequencies of a flat-bottom upright cylinder (Abramson, NASA SP-106,
//! ch. 6; Dodge, "The New Dynamic Behavior of Liquids in Moving Containers", 2000). Spheres and
//! domed tanks use the equivalent cylinder documented in [`equivalent_cylinder`].

use super::params::Baffles;
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
pub struct ModeShape {
    /// Modal mass over liquid mass, m_n / m_l.
    pub mass_ratio: f64,
    /// Pendulum length over radius, L_n / R.
    pub length_ratio: f64,
    /// ω_n² R / a_ax.
    pub omega2_ratio: f64,
}

/// SP-106 modal properties of a flat-bottom cylinder.
pub fn mode_shape(n: usize, h_over_r: f64) -> ModeShape {
    let xi = XI[n];
    let hr = h_over_r.max(MIN_DEPTH_RATIO);
    let th = (xi * hr).tanh();
    ModeShape {
        mass_ratio: 2.0 * th / (xi * (xi * xi - 1.0) * hr),
        length_ratio: 1.0 / (xi * th),
        omega2_ratio: xi * th,
    }
}

/// Equivalent flat-bottom cylinder for any shape: the free-surface radius r and the depth that
/// holds the liquid volume under that surface, h = V_l / (π r²). Exact for a cylinder; for a
/// half-full sphere it gives ω² R/g = 1.550 against 1.56 from McIver (1989). Returns (R, h).
pub fn equivalent_cylinder(
    surface_radius_m: f64,
    liquid_volume_m3: f64,
    tank_radius_m: f64,
) -> (f64, f64) {
    let r = surface_radius_m.max(0.05 * tank_radius_m);
    let h = liquid_volume_m3 / (PI * r * r);
    (r, h)
}

/// Smooth-wall viscous damping ratio (Mikishev & Dorozhkin, via SP-106 eq. 4.7).
#[expect(
    clippy::approx_constant,
    reason = "0.318 is the published empirical constant, not 1/π"
)]
/// `nu` kinematic viscosity m²/s, `r` radius m, `a_ax` axial acceleration m/s².
pub fn wall_damping(nu: f64, r: f64, a_ax: f64, h_over_r: f64) -> f64 {
    let hr = h_over_r.max(MIN_DEPTH_RATIO);
    let x = 1.84 * hr;
    let shape = 1.0 + (0.318 / x.sinh()) * (1.0 + (1.0 - hr) / x.cosh());
    // r^(-3/4) a^(-1/4) = (r³ a)^(-1/4), by two square roots.
    let a = a_ax.max(MIN_AXIAL_ACCEL);
    (4.98 / (2.0 * PI)) * nu.sqrt() * shape / (r * r * r * a).sqrt().sqrt()
}

/// Ring-baffle damping ratio (Miles 1958, SP-106 eq. 4.15): only rings below the surface count,
/// each weighted by exp(−4.6 d/R) with d its depth below the free surface `z_surface_m`.
pub fn baffle_damping(b: &Baffles, r: f64, z_surface_m: f64) -> f64 {
    if b.count == 0 || b.width_m <= 0.0 {
        return 0.0;
    }
    let w = (b.width_m / r).min(1.0);
    let alpha = w * (2.0 - w);
    let mut sum = 0.0;
    for k in 0..b.count {
        let z_ring = b.top_height_m - f64::from(k) * b.spacing_m;
        let depth = z_surface_m - z_ring;
        if depth >= 0.0 {
            sum += (-4.6 * depth / r).exp();
        }
    }
    2.83 * (b.wave_amplitude_m / r).sqrt() * sum * alpha * alpha.sqrt()
}
