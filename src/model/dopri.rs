//! The Dormand–Prince 5(4) embedded Runge–Kutta pair (Dormand & Prince 1980; coefficients and
//! the continuous extension as in Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.5–6, DOPRI5),
//! written over [`Real`] so that a lane group advances in lockstep with a step length per lane.
//!
//! The fifth-order solution is propagated (local extrapolation), the difference to the embedded
//! fourth-order one estimates the local error, and the seven stages give a fourth-order dense
//! output used to locate events and extrema inside a step. Like RK4, every stage combination is
//! linear in the stages, so mass and energy invariants are kept to rounding, and so is the dense
//! output.

use super::derive::Drive;
use super::state::{State, M_V, NS};
use super::{Evaluation, Group};
use crate::lanes::Real;

/// Nodes c_i of the tableau.
pub const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];

/// Rows a_ij of the tableau (row 6 is the fifth-order weights b: first same as last).
const A: [[f64; 6]; 6] = [
    [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];

/// Error weights b_i − b*_i (fifth minus fourth order).
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Weights of the dense-output correction (Hairer's d_i).
const D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

/// Order of the embedded (error-estimating) solution plus one: the exponent of step control.
pub const ERROR_ORDER: f64 = 5.0;

/// One attempted step: the fifth-order end state, its evaluation (the next step's first stage
/// when the step is accepted), the stages and the scaled error norm per lane.
#[derive(Clone, Copy, Debug)]
pub struct Trial<T: Real> {
    pub end: State<T>,
    /// Evaluation at the end state (stage 7), with the step's drive at t + h.
    pub end_eval: Evaluation<T>,
    pub k: [State<T>; 7],
    /// max_i |local error_i| / (atol_i + rtol · max(|y0_i|, |y1_i|)) per lane; ≤ 1 accepts.
    pub error: T,
}

/// Absolute and relative tolerances per state slot, per lane.
#[derive(Clone, Copy, Debug)]
pub struct Tolerance<T: Real> {
    pub atol: State<T>,
    pub rtol: T,
}

/// Attempt one step of length `h` (per lane) from state `s` at phase time `t`; `k1` is the
/// derivative at (s, t) (first same as last), `evap0` the evaporation rate there. `drive(t)`
/// gives the trajectory at time t; the linearly implicit stiff terms of the right-hand side take
/// `h` as their step.
///
/// Written into `out`, in place (a [`Trial::default`] or an earlier attempt of the same group):
/// a caller that takes many steps keeps one, instead of zeroing and moving seven stage states
/// and two evaluations (75 kB for a lane group of 16) per attempt. The stages are built in
/// `out.end` and evaluated into `out.end_eval`, over the level's used slots; the last stage's
/// are the step's end.
pub fn trial<T: Real>(
    g: Group<'_>,
    drive: impl Fn(T) -> Drive<T>,
    s: &State<T>,
    k1: &State<T>,
    (evap0, t, h): (T, T, T),
    tol: &Tolerance<T>,
    out: &mut Trial<T>,
) {
    let n = super::used_slots(g);
    let Trial {
        end: y,
        end_eval,
        k,
        error,
    } = out;
    // The slots beyond the level's are 0 in every state and rate (k1 included: it is an
    // evaluation's rates, written over the used slots only); the stage carries `s`'s.
    debug_assert!(
        k1[n..]
            .iter()
            .all(|v| (0..T::LANES).all(|i| v.lane(i) == 0.0)),
        "k1 past the used slots"
    );
    y[n..].copy_from_slice(&s[n..]);
    k[0][..n].copy_from_slice(&k1[..n]);
    for stage in 1..7 {
        let row = &A[stage - 1];
        y[..n].copy_from_slice(&s[..n]);
        for (j, kj) in k.iter().enumerate().take(stage) {
            let a = row[j];
            if a != 0.0 {
                for (yi, &ki) in y[..n].iter_mut().zip(kj) {
                    *yi += h * a * ki;
                }
            }
        }
        super::evaluate_into(g, y, &drive(t + h * C[stage]), h, end_eval);
        k[stage][..n].copy_from_slice(&end_eval.rates[..n]);
    }
    let (end, end_eval) = (&*y, &*end_eval);
    *error = T::splat(0.0);
    for i in 0..n {
        let mut e = T::splat(0.0);
        for (j, kj) in k.iter().enumerate() {
            if E[j] != 0.0 {
                e += kj[i] * E[j];
            }
        }
        let scale = tol.atol[i] + tol.rtol * s[i].abs().max(end[i].abs());
        // A non-finite stage gives a NaN error, which must reject: NaN ≤ 1 is false.
        let ratio = (e * h).abs() / scale;
        *error = T::select(ratio.le(*error), *error, ratio);
    }
    // Where the step does not resolve the evaporation's relaxation, its rate takes implicit
    // Euler's limit (`thermal::stiff_blend`), which follows a change of the quasi-steady rate
    // within the step only through the stages' residual: the mass such a change moves over the
    // step, h·|Δṁ_evap|/2, is held to the vapour-mass tolerance (without it the QoIs of the
    // shipped campaigns move by up to 3.3e-4 between default and 100× tighter tolerances).
    let lag = (h * (end_eval.fluxes.evap_kg_s - evap0)).abs() * 0.5
        / (tol.atol[M_V] + tol.rtol * s[M_V].abs().max(end[M_V].abs()));
    *error = T::select(lag.le(*error), *error, lag);
}

/// All zeros: what [`trial`] writes over.
impl<T: Real> Default for Trial<T> {
    fn default() -> Self {
        Trial {
            end: [T::default(); NS],
            end_eval: Evaluation::default(),
            k: [[T::default(); NS]; 7],
            error: T::default(),
        }
    }
}

/// Coefficients of the dense output of one accepted step (scalar: one lane).
#[derive(Clone, Copy, Debug)]
pub struct Dense {
    r: [State; 5],
}

/// All zeros: what [`Dense::set_lane`] writes over.
impl Default for Dense {
    fn default() -> Self {
        Dense { r: [[0.0; NS]; 5] }
    }
}

impl Dense {
    /// The continuous extension of the step of length `h` from `y0` to `y1` with stages `k`.
    pub fn new(y0: &State, y1: &State, k: &[State; 7], h: f64) -> Dense {
        let mut d = Dense::default();
        d.set_lane((y0, y1, k), 0, h, NS);
        d
    }

    /// Overwrite with the continuous extension of lane `lane` of a lane group's step of length
    /// `h` from `y0` to `y1` with stages `k`, read in place (a lane group's stages are 60 kB
    /// for 16 lanes: not copied per lane). Only the first `n` slots move (a level's used slots:
    /// beyond them `y0` = `y1` and every stage is 0, and the extension is `y0` there, as
    /// computed over every slot). Same bits as [`Dense::new`] on the lane's own states.
    pub fn set_lane<T: Real>(
        &mut self,
        (y0, y1, k): (&State<T>, &State<T>, &[State<T>; 7]),
        lane: usize,
        h: f64,
        n: usize,
    ) {
        let r = &mut self.r;
        for i in n..NS {
            r[0][i] = y0[i].lane(lane);
            (r[1][i], r[2][i], r[3][i], r[4][i]) = (0.0, 0.0, 0.0, 0.0);
        }
        for i in 0..n {
            let (a, b) = (y0[i].lane(lane), y1[i].lane(lane));
            let diff = b - a;
            let bspl = h * k[0][i].lane(lane) - diff;
            let mut d = 0.0;
            for (j, kj) in k.iter().enumerate() {
                if D[j] != 0.0 {
                    d += D[j] * kj[i].lane(lane);
                }
            }
            r[0][i] = a;
            r[1][i] = diff;
            r[2][i] = bspl;
            r[3][i] = diff - h * k[6][i].lane(lane) - bspl;
            r[4][i] = h * d;
        }
    }

    /// Slot `i` of the state at fraction `theta` of the step, as [`Dense::at`].
    pub fn slot_at(&self, i: usize, theta: f64) -> f64 {
        let r = &self.r;
        let u = 1.0 - theta;
        r[0][i] + theta * (r[1][i] + u * (r[2][i] + theta * (r[3][i] + u * r[4][i])))
    }

    /// The state at fraction `theta` ∈ [0, 1] of the step (fourth-order accurate).
    pub fn at(&self, theta: f64) -> State {
        std::array::from_fn(|i| self.slot_at(i, theta))
    }
}

/// The step-length factor after a step with error norm `error`: the classical controller
/// 0.9 · error^(−1/5), kept within [0.2, 5] (no growth right after a rejection).
/// A non-finite error (a stage left the model's range) shrinks the step as much as allowed.
pub fn step_factor(error: f64, rejected: bool) -> f64 {
    if !error.is_finite() {
        return 0.2;
    }
    let f = if error > 0.0 {
        0.9 * error.powf(-1.0 / ERROR_ORDER)
    } else {
        5.0
    };
    f.clamp(0.2, if rejected { 1.0 } else { 5.0 })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tableau is consistent: each row sums to its node, the weights to one, the error
    /// weights to zero.
    #[test]
    fn tableau_is_consistent() {
        for (row, c) in A.iter().zip(&C[1..]) {
            assert!((row.iter().sum::<f64>() - c).abs() < 1e-14);
        }
        assert!(E.iter().sum::<f64>().abs() < 1e-15);
        let b: f64 = A[5].iter().sum();
        assert!((b - 1.0).abs() < 1e-15);
    }

    /// A NaN error norm once left the step unchanged (NaN > 0 is false, so the factor was the
    /// growth cap clamped to 1): the LOX ascent at two_mode retried the same step forever.
    #[test]
    fn non_finite_error_shrinks_the_step() {
        for e in [f64::NAN, f64::INFINITY] {
            assert_eq!(step_factor(e, true), 0.2);
            assert_eq!(step_factor(e, false), 0.2);
        }
        assert_eq!(step_factor(0.0, false), 5.0);
        assert_eq!(step_factor(0.0, true), 1.0);
    }

    /// On y' = y the dense output is fourth-order: halving h divides the midpoint error by ≈ 32.
    #[test]
    fn dense_output_is_fourth_order() {
        let err = |h: f64| {
            // Stages of the exact linear problem y' = y from y0 = 1 (slot 0 only).
            let mut k = [[0.0; NS]; 7];
            let mut ys = [[0.0; NS]; 7];
            ys[0][0] = 1.0;
            k[0][0] = 1.0;
            for stage in 1..7 {
                let mut y = 1.0;
                for j in 0..stage {
                    y += h * A[stage - 1][j] * k[j][0];
                }
                ys[stage][0] = y;
                k[stage][0] = y;
            }
            let y1 = ys[6];
            let d = Dense::new(&ys[0], &y1, &k, h);
            (d.at(0.5)[0] - (0.5 * h).exp()).abs()
        };
        let ratio = err(0.2) / err(0.1);
        assert!(ratio > 24.0 && ratio < 40.0, "ratio {ratio}");
        assert!(err(0.1) < 1e-8);
    }
}
