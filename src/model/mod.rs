//! The physics of one tank instance (MODEL.md): stateless math over a state vector and a
//! parameter record. No I/O, no threads, no allocation in the step.

pub mod boundary;
pub mod derive;
pub mod flight;
pub mod homogeneous;
pub mod nodes;
pub mod params;
pub mod slosh;
pub mod state;
pub mod thermal;

use derive::{Derived, Drive};
use flight::Phase;
use nodes::Fluxes;
use params::{Fidelity, Params};
use state::{State, NS};

/// The derived quantities and fluxes at one instant, and the state derivative.
#[derive(Clone, Copy, Debug)]
pub struct Evaluation {
    pub derived: Derived,
    pub fluxes: Fluxes,
    pub rates: State,
}

/// Evaluate the right-hand side at state `s` under drive `d`; `dt` is the integrator's step.
pub fn evaluate(p: &Params, s: &State, d: &Drive, dt: f64) -> Evaluation {
    let x = derive::derive(p, s, d);
    let mut ds = [0.0; NS];
    let fluxes = match p.fidelity {
        Fidelity::Homogeneous => {
            let b = homogeneous::rhs(p, s, d, &x, dt, &mut ds);
            Fluxes {
                boundary: b,
                ..Default::default()
            }
        }
        Fidelity::Lumped | Fidelity::TwoMode => nodes::rhs(p, s, d, &x, dt, &mut ds),
    };
    Evaluation {
        derived: x,
        fluxes,
        rates: ds,
    }
}

/// One classical fourth-order Runge–Kutta step of length `dt` from phase time `t` (the GPU
/// kernel mirrors this in lockstep). The relief-valve state is held over the step. `k1`, when
/// given, is the derivative already evaluated at (s, t, dt, valve_open) by the caller.
pub fn rk4_step(
    p: &Params,
    phase: &Phase,
    s: &mut State,
    t: f64,
    dt: f64,
    valve_open: bool,
    k1: Option<&State>,
) {
    let drive = |tt: f64| Drive::of_phase(phase, tt, valve_open);
    let k1 = match k1 {
        Some(k) => *k,
        None => evaluate(p, s, &drive(t), dt).rates,
    };
    let k2 = evaluate(p, &axpy(s, 0.5 * dt, &k1), &drive(t + 0.5 * dt), dt).rates;
    let k3 = evaluate(p, &axpy(s, 0.5 * dt, &k2), &drive(t + 0.5 * dt), dt).rates;
    let k4 = evaluate(p, &axpy(s, dt, &k3), &drive(t + dt), dt).rates;
    for i in 0..NS {
        s[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
}

/// s + a·k.
fn axpy(s: &State, a: f64, k: &State) -> State {
    let mut out = *s;
    for (o, ki) in out.iter_mut().zip(k) {
        *o += a * ki;
    }
    out
}

/// Relief-valve hysteresis: open at or above the crack pressure, closed at or below reseat.
pub fn update_valve(p: &Params, pressure_pa: f64, open: bool) -> bool {
    match p.relief {
        Some(r) if pressure_pa >= r.crack_pa => true,
        Some(r) if pressure_pa <= r.reseat_pa => false,
        Some(_) => open,
        None => false,
    }
}
