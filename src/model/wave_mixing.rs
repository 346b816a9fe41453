//! Slosh-driven mixing of the liquid (coupling III) on every level with slosh: a wave-induced eddy
//! diffusivity of the form of Qiao et al. (2004), amplitude times orbital velocity, decaying with
//! depth as the mode does (docs/PHYSICS.md 6.4). One closure for `lumped`, `two_mode` and
//! `layered`: D at the warm layer's (the film's) base adds to the diffusivity of its penetration
//! growth, so that the wave deepens the mixed layer by entraining the liquid under it, and the
//! `layered` column's layers exchange through D at their boundaries.

use super::derive::Derived;
use super::params::Fidelity;
use super::slosh::XI;
use super::state::*;
use super::Group;
use crate::lanes::{c, Mask, Real};

/// The waves that stir the liquid, per mode: (c_mix |x_n| |ẋ_n|, m²/s; ξ_n / R, 1/m; ξ_n the roots
/// of J₁′, [`XI`]: the mode's amplitude and velocity decay with depth d as e^(−ξ_n d / R),
/// Abramson, NASA SP-106, ch. 2), with x_n the mode's lateral displacement: the two pendulums' on
/// `two_mode` and `layered`, L θ (small angle) on `lumped`'s single pendulum of length L; none on
/// `homogeneous`. c_mix is `slosh.mixing_coefficient` (dimensionless, [0, 100]).
pub fn waves<T: Real>(g: Group<'_>, s: &State<T>, x: &Derived<T>) -> [(T, T); 2] {
    let mixing: T = g.get(|p| p.coupling.mixing);
    let radius: T = g.get(|p| p.tank.radius_m());
    let none = (c(0.0), c(0.0));
    match g.shared().fidelity {
        Fidelity::Homogeneous => [none, none],
        Fidelity::Lumped => {
            let l = x.slosh.length_m[0];
            let amplitude = mixing * (l * s[Q1]).abs() * (l * s[Q1D]).abs();
            [(amplitude, radius.rdiv(XI[0])), none]
        }
        Fidelity::TwoMode | Fidelity::Layered => [
            (mixing * s[Q1].abs() * s[Q1D].abs(), radius.rdiv(XI[0])),
            (mixing * s[Q2].abs() * s[Q2D].abs(), radius.rdiv(XI[1])),
        ],
    }
}

/// The eddy diffusivity D = Σ_n c_mix |x_n| |ẋ_n| e^(−2 ξ_n d / R) at `depth_m` (≥ 0) below the
/// surface, m²/s. A mode calm in every lane (amplitude 0: a tank that does not slosh) adds
/// nothing and its `exp` is not taken (the same bits: 0 times a factor in (0, 1] is 0).
pub fn eddy_diffusivity<T: Real>(waves: &[(T, T); 2], depth_m: T) -> T {
    let mut eddy = c::<T>(0.0);
    for &(amplitude, decay) in waves {
        if amplitude.is_zero().all() {
            continue;
        }
        eddy += amplitude * (depth_m * decay * -2.0).exp();
    }
    eddy
}
