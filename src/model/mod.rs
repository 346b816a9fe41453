//! The physics of one tank instance (MODEL.md): stateless math over a state vector and a
//! parameter record. No I/O, no threads, no allocation in the step.
//!
//! Written once over [`Real`]: `f64` integrates one instance, [`crate::lanes::Lanes`] a lane
//! group of instances in lockstep, each lane with its own [`Params`] (a [`Group`]).

pub mod boundary;
pub mod boundary_layer;
pub mod column;
pub mod derive;
pub mod dopri;
pub mod flight;
pub mod homogeneous;
pub mod insulation;
pub mod mixer;
pub mod nodes;
pub mod params;
pub mod slosh;
pub mod slosh_table;
pub mod state;
pub mod thermal;
pub mod tvs;
pub mod wave_mixing;

use crate::geometry::TankLanes;
use crate::lanes::{Mask, Real};
use derive::{Derived, Drive};
use nodes::Fluxes;
use params::{Fidelity, Params};
use state::{State, NS};

/// The parameters of the instances integrated together: one [`Params`] per lane, alike in
/// everything but numbers ([`Params::lane_compatible`]). Structure (level, propellant, shape,
/// which optional systems exist) is read from the first lane, every number from its own lane.
#[derive(Clone, Copy, Debug)]
pub struct Group<'a>(&'a [Params]);

impl<'a> Group<'a> {
    /// A group of one instance.
    pub fn one(p: &'a Params) -> Group<'a> {
        Group(std::slice::from_ref(p))
    }

    /// The group of `lanes`, which must be mutually [`Params::lane_compatible`].
    pub fn of(lanes: &'a [Params]) -> Group<'a> {
        debug_assert!(lanes.iter().all(|p| lanes[0].lane_compatible(p)));
        Group(lanes)
    }

    /// The structure every lane shares.
    pub fn shared(&self) -> &'a Params {
        &self.0[0]
    }

    /// Every lane's parameters.
    pub fn lanes(&self) -> &'a [Params] {
        self.0
    }

    /// Each lane's tank.
    pub fn tank<T: Real>(&self) -> TankLanes<T> {
        TankLanes::gather(|i| &self.0[i].tank)
    }

    /// A number of each lane's parameters.
    #[inline(always)]
    pub fn get<T: Real>(&self, f: impl Fn(&Params) -> f64) -> T {
        T::from_fn(|i| f(&self.0[i]))
    }
}

/// The derived quantities and fluxes at one instant, and the state derivative.
#[derive(Clone, Copy, Debug)]
pub struct Evaluation<T: Real = f64> {
    pub derived: Derived<T>,
    pub fluxes: Fluxes<T>,
    pub rates: State<T>,
}

/// All zeros: what [`evaluate_into`] writes over (a state array this long has no derived
/// `Default`).
impl<T: Real> Default for Evaluation<T> {
    fn default() -> Self {
        Evaluation {
            derived: Derived::default(),
            fluxes: Fluxes::default(),
            rates: [T::default(); NS],
        }
    }
}

impl<T: Real> Evaluation<T> {
    /// Lane `i`.
    pub fn lane(&self, i: usize) -> Evaluation {
        Evaluation {
            derived: self.derived.lane(i),
            fluxes: self.fluxes.lane(i),
            rates: state::lane(&self.rates, i),
        }
    }

    /// [`Self::lane`] into `out`, the rates over their first `n` slots ([`state::lane_into`]).
    pub fn lane_into(&self, i: usize, n: usize, out: &mut Evaluation) {
        out.derived = self.derived.lane(i);
        out.fluxes = self.fluxes.lane(i);
        state::lane_into(&self.rates, i, n, &mut out.rates);
    }
}

/// Evaluate the right-hand side at state `s` under drive `d`; `dt` is the integrator's step.
pub fn evaluate<T: Real>(g: Group<'_>, s: &State<T>, d: &Drive<T>, dt: T) -> Evaluation<T> {
    let mut ev = Evaluation::default();
    evaluate_into(g, s, d, dt, &mut ev);
    ev
}

/// [`evaluate`] into `ev`, in place: the same numbers without building and moving a new
/// evaluation through every caller (a lane group's is kilobytes). Slots of `ev.rates` past
/// [`used_slots`] are left as they are (zero in any evaluation made by [`evaluate`]).
pub fn evaluate_into<T: Real>(
    g: Group<'_>,
    s: &State<T>,
    d: &Drive<T>,
    dt: T,
    ev: &mut Evaluation<T>,
) {
    let Evaluation {
        derived,
        fluxes,
        rates,
    } = ev;
    rates_into(g, s, d, dt, derived, fluxes, rates);
}

/// The derivative at `s` written into the first [`used_slots`] of `ds` (zeroed first, the
/// rest untouched), the derived quantities into `x` and the fluxes into `fl`.
fn rates_into<T: Real>(
    g: Group<'_>,
    s: &State<T>,
    d: &Drive<T>,
    dt: T,
    x: &mut Derived<T>,
    fl: &mut Fluxes<T>,
    ds: &mut State<T>,
) {
    ds[..used_slots(g)].fill(T::default());
    if g.shared().fidelity == Fidelity::Layered {
        let prof = column::profile(g, s);
        *x = column::derive_column(g, s, d, &prof);
        *fl = column::rhs(g, s, d, x, &prof, dt, ds);
        return;
    }
    match g.shared().fidelity {
        Fidelity::Homogeneous => {
            derive::derive_into(g, s, d, x);
            *fl = Fluxes {
                boundary: homogeneous::rhs(g, s, d, x, dt, ds),
                ..Default::default()
            }
        }
        Fidelity::Lumped | Fidelity::TwoMode => {
            // Each lane's tank, gathered once for the derivation and the rates.
            let tank = g.tank();
            derive::derive_nodes(g, &tank, s, d, x);
            nodes::rhs((g, &tank), s, d, x, dt, ds, fl);
        }
        Fidelity::Layered => unreachable!("evaluated above"),
    }
}

/// One classical fourth-order Runge–Kutta step of length `dt` from phase time `t` (the GPU
/// kernel mirrors this in lockstep); `drive(t)` is the trajectory at time t, with the
/// relief-valve state held over the step. `k1`, when given, is the derivative already evaluated
/// at (s, t, dt) by the caller. [`rk4_step_in`] with a workspace of its own.
pub fn rk4_step<T: Real>(
    g: Group<'_>,
    drive: impl Fn(T) -> Drive<T>,
    s: &mut State<T>,
    t: T,
    dt: T,
    k1: Option<&State<T>>,
) {
    rk4_step_in(g, drive, s, t, dt, k1, &mut Rk4Work::default());
}

/// The buffers of [`rk4_step_in`], kept by a caller that takes many steps: a lane group's state
/// is 67 slots × 16 lanes (8.6 kB; 32 lanes in an AVX-512 build), and zeroing four of them per step (the stage state, the
/// rates, their sum, the derived quantities) was 1–2 % of a lumped run.
#[derive(Clone, Debug)]
pub struct Rk4Work<T: Real> {
    stage: State<T>,
    rates: State<T>,
    sum: State<T>,
    derived: Derived<T>,
    fluxes: Fluxes<T>,
}

impl<T: Real> Default for Rk4Work<T> {
    fn default() -> Self {
        Rk4Work {
            stage: [T::default(); NS],
            rates: [T::default(); NS],
            sum: [T::default(); NS],
            derived: Derived::default(),
            fluxes: Fluxes::default(),
        }
    }
}

/// [`rk4_step`] in the buffers of `work` (what they held before does not matter).
///
/// The stages are evaluated into one stage state and one rate buffer, over the level's used
/// slots only, and k1 + 2 k2 + 2 k3 + k4 is summed as they come in the order the formula
/// reads (the same bits as summing the four at the end): no state is copied per stage.
pub fn rk4_step_in<T: Real>(
    g: Group<'_>,
    drive: impl Fn(T) -> Drive<T>,
    s: &mut State<T>,
    t: T,
    dt: T,
    k1: Option<&State<T>>,
    work: &mut Rk4Work<T>,
) {
    let n = used_slots(g);
    // What the stages derive on the way, not kept; `k` holds k1 when the caller has none, then
    // each later stage's rates.
    let Rk4Work {
        stage,
        rates: k,
        sum,
        derived: x,
        fluxes: fl,
    } = work;
    let k1 = match k1 {
        Some(k1) => k1,
        None => {
            rates_into(g, s, &drive(t), dt, x, fl, k);
            &*k
        }
    };
    sum[..n].copy_from_slice(&k1[..n]);
    let half = dt * 0.5;
    // The two midpoint stages share one drive (the trajectory at t + dt/2).
    let d_half = drive(t + half);
    // The slots beyond the level's are 0 in every state; the stage carries the caller's.
    stage[n..].copy_from_slice(&s[n..]);
    for i in 0..n {
        stage[i] = s[i] + half * k1[i];
    }
    rates_into(g, stage, &d_half, dt, x, fl, k);
    for i in 0..n {
        sum[i] += k[i] * 2.0;
        stage[i] = s[i] + half * k[i];
    }
    rates_into(g, stage, &d_half, dt, x, fl, k);
    for i in 0..n {
        sum[i] += k[i] * 2.0;
        stage[i] = s[i] + dt * k[i];
    }
    rates_into(g, stage, &drive(t + dt), dt, x, fl, k);
    let w = dt / 6.0;
    for i in 0..n {
        s[i] += w * (sum[i] + k[i]);
    }
}

/// The state slots the group's level uses ([`state::slots_used`]); the rest stay 0.
pub fn used_slots(g: Group<'_>) -> usize {
    let p = g.shared();
    state::slots_used(p.fidelity, p.layered.layers)
}

/// Share of the initial liquid mass left when the tank counts as dry: the engine stops drawing
/// (the unusable residual, of the order of a sump's and the lines' trapped propellant). Below it
/// the lumped nodes' vanishing masses take the wetted wall's heat and the outlet temperature
/// spikes: with 0.1 % the minimum cavitation margin of a tank drained dry was set there and
/// depended on the integrator (LH2 stage at 2–2.5 % fill, 50 instances: 1 cavitating under RK4,
/// 15 under DOPRI5, median margins 10.3 m and 1.8 m); at 1 % both give 0 (39.8 m and 40.6 m).
pub const DEPLETION_RESIDUAL_FRACTION: f64 = 1.0e-2;

/// Share of the liquid below which the bulk node is merged into the warm layer.
pub const BULK_MERGE_FRACTION: f64 = 1.0e-4;

/// Drain time, s, below which the bulk node is merged into the warm layer: a bulk that the
/// last step's draw would empty within this time joins the layer.
pub const BULK_MERGE_DRAIN_S: f64 = 1.0;

/// Merge a nearly empty bulk node into the layer, conserving mass and enthalpy exactly: when
/// the layer has entrained the bulk (a long coast at low fill), T_b = T(H_b/m_b) of a vanishing
/// node is ill-conditioned and the instance used to diverge. A step that drew the bulk below zero
/// (an engine draining more than the bulk's fade share in one step: 3 kg per 0.05 s step of the
/// methalox stage at 2 % fill) merges too, the layer giving up the overdrawn mass at the bulk's
/// enthalpy, instead of diverging on a negative bulk mass.
///
/// A draining bulk merges when the step just taken (length `step_s`, from a bulk of
/// `m_bulk_before_kg`) drew it at a rate that empties it within `horizon_s`: [`BULK_MERGE_DRAIN_S`]
/// under an error-controlled step, at least two steps under a fixed one (which cannot follow a
/// faster drain). Its last kilograms take the wall's heat through a vanishing mass, so T_b
/// spikes as 1/m_b: the minimum cavitation margin of the LH2 stage at 2 % fill then depended on
/// where the last step landed (−80 m under DOPRI5, +26 m under 0.1 s RK4, −12 m under 0.01 s
/// RK4), and a 0.1 s RK4 step that left 6 g ended at T_b = −206 K and diverged. The outflow's
/// last second mixes the two nodes instead, at any step.
///
/// Afterwards the bulk stays empty (nothing flows into it) and takes the layer's temperature.
/// Returns whether it merged.
pub fn merge_empty_bulk(
    p: &Params,
    s: &mut State,
    m_bulk_before_kg: f64,
    (step_s, horizon_s): (f64, f64),
) -> bool {
    let m_b = s[state::M_B];
    let taken = m_bulk_before_kg - m_b;
    if p.fidelity == Fidelity::Homogeneous
        || m_b == 0.0
        || !m_b.is_finite()
        || (m_b > BULK_MERGE_FRACTION * (m_b + s[state::M_S])
            && (step_s <= 0.0 || m_b * step_s >= horizon_s * taken))
    {
        return false;
    }
    s[state::M_S] += m_b;
    s[state::H_S] += s[state::H_B];
    s[state::M_B] = 0.0;
    s[state::H_B] = 0.0;
    // The `layered` column's enthalpy goes with its mass (`model::column`).
    for k in state::COL..state::NS {
        s[state::H_S] += s[k];
        s[k] = 0.0;
    }
    true
}

/// Relief-valve hysteresis: open at or above the crack pressure, closed at or below reseat.
pub fn update_valve<T: Real>(g: Group<'_>, pressure_pa: T, open: T::Mask) -> T::Mask {
    if g.shared().relief.is_none() {
        return T::Mask::splat(false);
    }
    let crack: T = g.get(|p| p.relief.map_or(0.0, |r| r.crack_pa));
    let reseat: T = g.get(|p| p.relief.map_or(0.0, |r| r.reseat_pa));
    pressure_pa.ge(crack) | (!pressure_pa.le(reseat) & open)
}
