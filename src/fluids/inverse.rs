//! Starting points for inverting the liquid enthalpy h_l(T) of a propellant: a cubic Hermite
//! table of x(h) built once from the fits. From it the safeguarded Newton iteration of
//! [`FluidProps::t_from_h_l_k`] starts within about 1e-12 of the root and stops after one step
//! (two near t_min_k) instead of four or five: the state holds enthalpies, so every right-hand
//! side inverts two of them. 513 nodes, 8 KiB per propellant.

use super::{Fluid, FluidProps};
use crate::lanes::{Real, WIDTH};
use std::sync::OnceLock;

/// Intervals of the table, uniform in h over [0, h_l(t_max_k)].
const INTERVALS: usize = 512;

/// x(h) and dx/dh (times the interval width) at the table nodes.
#[derive(Clone, Debug)]
pub(crate) struct HlInverse {
    /// [`FluidProps::h_l_limits`] of the fit.
    limits: (f64, f64),
    width: f64,
    x: [f64; INTERVALS + 1],
    slope: [f64; INTERVALS + 1],
}

impl HlInverse {
    /// The table of fit `f`, each node solved by the unguided Newton iteration.
    fn build(f: &FluidProps) -> HlInverse {
        let limits = f.h_l_limits();
        let h_max = limits.1;
        let width = h_max / INTERVALS as f64;
        let mut x = [0.0; INTERVALS + 1];
        let mut slope = [0.0; INTERVALS + 1];
        for i in 0..=INTERVALS {
            let h = width * i as f64;
            let xi = f.x_of(f.t_from_h_l_k(h)).clamp(-1.0, 1.0);
            x[i] = xi;
            // dx/dh = 1 / (T_half dh_l/dT(x)).
            slope[i] = width / (f.t_half() * super::poly(&f.dh_l_sat, xi));
        }
        HlInverse {
            limits,
            width,
            x,
            slope,
        }
    }

    /// [`FluidProps::h_l_limits`] of the fit.
    pub(crate) fn limits(&self) -> (f64, f64) {
        self.limits
    }

    /// Normalised temperature x whose enthalpy is close to `h`, clamped to [−1, 1], per lane:
    /// the interval and position in lanes, the four node values gathered per lane, the Hermite
    /// cubic in lanes (the `f64` operations of one lane in the same order, so the same bits
    /// whatever the width). Only lanes with 0 < h < h_max use it; a NaN lane reads interval 0.
    pub(crate) fn guess<T: Real>(&self, h: T) -> T {
        let u = (h * (1.0 / self.width)).clamp_c(0.0, INTERVALS as f64);
        // u ≥ 0, so truncation is the floor.
        let mut cell = [0usize; WIDTH];
        for (l, c) in cell.iter_mut().enumerate().take(T::LANES) {
            *c = (u.lane(l) as usize).min(INTERVALS - 1);
        }
        let t = u - T::from_fn(|l| cell[l] as f64);
        let (t2, t3) = (t * t, t * t * t);
        let node = |v: &[f64; INTERVALS + 1], next: usize| T::from_fn(|l| v[cell[l] + next]);
        let x = (t3 * 2.0 - t2 * 3.0 + 1.0) * node(&self.x, 0)
            + (t3 - t2 * 2.0 + t) * node(&self.slope, 0)
            + (t2 * 3.0 - t3 * 2.0) * node(&self.x, 1)
            + (t3 - t2) * node(&self.slope, 1);
        x.clamp_c(-1.0, 1.0)
    }
}

/// The table of propellant `fluid`, built on first use.
pub(crate) fn hl_inverse(fluid: Fluid) -> &'static HlInverse {
    static TABLES: OnceLock<[HlInverse; Fluid::ALL.len()]> = OnceLock::new();
    let tables = TABLES.get_or_init(|| Fluid::ALL.map(|fl| HlInverse::build(fl.props())));
    &tables[fluid as usize]
}
