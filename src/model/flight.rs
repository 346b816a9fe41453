//! Trajectory phases, lateral excitation and the atmosphere (MODEL.md §8).
//!
//! A phase fixes thrust, gravity level, flight-path angle and a lateral excitation; within a
//! phase every instance advances with the same step, which keeps the GPU lockstep simple.

use crate::lanes::Real;

/// Standard gravity, m/s².
pub const G0: f64 = 9.806_65;
/// Sea-level pressure of the exponential atmosphere, Pa.
pub const P_SEA_LEVEL_PA: f64 = 101_325.0;
/// Sea-level density of the exponential atmosphere, kg/m³.
pub const RHO_SEA_LEVEL: f64 = 1.225;
/// Scale height of the exponential atmosphere, m (US 1976 fit over 0–80 km).
pub const SCALE_HEIGHT_M: f64 = 7_200.0;
/// Mean Earth radius for the inverse-square gravity of the trajectory, m.
pub const EARTH_RADIUS_M: f64 = 6_371_000.0;

/// What the vehicle is doing in a phase.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhaseKind {
    /// On the pad or a test stand: supported, at rest, a_ax = the phase's gravity level.
    Hold,
    /// Engine burning: outflow, NPSH evaluated, a_ax = (T − D)/M + gravity level.
    Burn,
    /// Engine off in flight: a_ax = the residual (settling) acceleration of the phase.
    Coast,
}

impl PhaseKind {
    /// Campaign spelling.
    pub fn name(self) -> &'static str {
        match self {
            PhaseKind::Hold => "hold",
            PhaseKind::Burn => "burn",
            PhaseKind::Coast => "coast",
        }
    }
}

/// The surroundings of the tank's insulation in a phase (`[insulation]`; docs/PHYSICS.md 2.5).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Environment {
    /// Air at the ambient temperature: convection and radiation to the outer surface.
    Ground,
    /// Radiation to a sink and an absorbed solar/planetary flux.
    Space,
}

impl Environment {
    /// Campaign spelling.
    pub fn name(self) -> &'static str {
        match self {
            Environment::Ground => "ground",
            Environment::Space => "space",
        }
    }

    /// The default of a phase kind: a hold is on the ground, a burn or coast in space.
    pub fn of_kind(kind: PhaseKind) -> Environment {
        match kind {
            PhaseKind::Hold => Environment::Ground,
            PhaseKind::Burn | PhaseKind::Coast => Environment::Space,
        }
    }
}

/// Lateral excitation a_lat(t), m/s², with t measured from the phase start.
#[derive(Clone, Debug, PartialEq)]
pub enum Excitation {
    None,
    /// a = amplitude for t ≥ start.
    Step {
        amplitude: f64,
        start_s: f64,
    },
    /// Linear rise from 0 at `start_s` to `amplitude` over `duration_s`, then held.
    Ramp {
        amplitude: f64,
        start_s: f64,
        duration_s: f64,
    },
    /// a = amplitude · sin(2π f t + phase).
    Sine {
        amplitude: f64,
        frequency_hz: f64,
        phase_rad: f64,
    },
    /// Linear sine sweep from `f_start_hz` to `f_end_hz` over `duration_s`.
    Sweep {
        amplitude: f64,
        f_start_hz: f64,
        f_end_hz: f64,
        duration_s: f64,
    },
    /// 1 − cos gust: a = amplitude/2 · (1 − cos(2π (t − start)/duration)) inside the gust.
    Gust {
        amplitude: f64,
        start_s: f64,
        duration_s: f64,
    },
    /// Tabulated (t, a_lat, a_ax extra), linearly interpolated, held beyond the ends.
    Table {
        time_s: Vec<f64>,
        a_lat: Vec<f64>,
        a_ax: Vec<f64>,
    },
}

impl Excitation {
    /// Lateral acceleration and an additional axial acceleration at phase time `t`, m/s².
    pub fn eval(&self, t: f64) -> (f64, f64) {
        use std::f64::consts::TAU;
        match self {
            Excitation::None => (0.0, 0.0),
            Excitation::Step { amplitude, start_s } => {
                (if t >= *start_s { *amplitude } else { 0.0 }, 0.0)
            }
            Excitation::Ramp {
                amplitude,
                start_s,
                duration_s,
            } => {
                let s = ((t - start_s) / duration_s).clamp(0.0, 1.0);
                (amplitude * s, 0.0)
            }
            Excitation::Sine {
                amplitude,
                frequency_hz,
                phase_rad,
            } => (amplitude * (TAU * frequency_hz * t + phase_rad).sin(), 0.0),
            Excitation::Sweep {
                amplitude,
                f_start_hz,
                f_end_hz,
                duration_s,
            } => {
                let tc = t.clamp(0.0, *duration_s);
                let rate = (f_end_hz - f_start_hz) / duration_s;
                // Phase of a linear chirp; beyond the sweep it continues at f_end.
                let phase =
                    TAU * (f_start_hz * tc + 0.5 * rate * tc * tc) + TAU * f_end_hz * (t - tc);
                (amplitude * phase.sin(), 0.0)
            }
            Excitation::Gust {
                amplitude,
                start_s,
                duration_s,
            } => {
                let tau = t - start_s;
                if tau >= 0.0 && tau <= *duration_s {
                    (
                        0.5 * amplitude * (1.0 - (TAU * tau / duration_s).cos()),
                        0.0,
                    )
                } else {
                    (0.0, 0.0)
                }
            }
            Excitation::Table {
                time_s,
                a_lat,
                a_ax,
            } => (interp(time_s, a_lat, t), interp(time_s, a_ax, t)),
        }
    }

    /// The instantaneous excitation frequency at phase time `t`, Hz (sweeps only).
    pub fn sweep_frequency_hz(&self, t: f64) -> Option<f64> {
        match self {
            Excitation::Sweep {
                f_start_hz,
                f_end_hz,
                duration_s,
                ..
            } => {
                let tc = t.clamp(0.0, *duration_s);
                Some(f_start_hz + (f_end_hz - f_start_hz) * tc / duration_s)
            }
            _ => None,
        }
    }
}

/// The campaign's spelling: the excitation `kind` with its keys, e.g.
/// `gust(amplitude_m_s2 0.3, start_s 60, duration_s 4)`; a table is summarised by its rows and
/// time span (`check` adds the file name).
impl std::fmt::Display for Excitation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use crate::campaign::number as n;
        match self {
            Excitation::None => write!(f, "none"),
            Excitation::Step { amplitude, start_s } => write!(
                f,
                "step(amplitude_m_s2 {}, start_s {})",
                n(*amplitude),
                n(*start_s)
            ),
            Excitation::Ramp {
                amplitude,
                start_s,
                duration_s,
            } => write!(
                f,
                "ramp(amplitude_m_s2 {}, start_s {}, duration_s {})",
                n(*amplitude),
                n(*start_s),
                n(*duration_s)
            ),
            Excitation::Sine {
                amplitude,
                frequency_hz,
                phase_rad,
            } => write!(
                f,
                "sine(amplitude_m_s2 {}, frequency_hz {}, phase_rad {})",
                n(*amplitude),
                n(*frequency_hz),
                n(*phase_rad)
            ),
            Excitation::Sweep {
                amplitude,
                f_start_hz,
                f_end_hz,
                duration_s,
            } => write!(
                f,
                "sweep(amplitude_m_s2 {}, f_start_hz {}, f_end_hz {}, duration_s {})",
                n(*amplitude),
                n(*f_start_hz),
                n(*f_end_hz),
                n(*duration_s)
            ),
            Excitation::Gust {
                amplitude,
                start_s,
                duration_s,
            } => write!(
                f,
                "gust(amplitude_m_s2 {}, start_s {}, duration_s {})",
                n(*amplitude),
                n(*start_s),
                n(*duration_s)
            ),
            Excitation::Table { time_s, .. } => write!(
                f,
                "table({} rows, {}–{} s)",
                time_s.len(),
                n(time_s.first().copied().unwrap_or(f64::NAN)),
                n(time_s.last().copied().unwrap_or(f64::NAN))
            ),
        }
    }
}

/// Piecewise-linear interpolation on ascending `xs`, constant beyond the ends.
fn interp(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let n = xs.len();
    if n == 0 {
        return 0.0;
    }
    if x <= xs[0] {
        return ys[0];
    }
    if x >= xs[n - 1] {
        return ys[n - 1];
    }
    let i = xs.partition_point(|&v| v <= x);
    let (x0, x1, y0, y1) = (xs[i - 1], xs[i], ys[i - 1], ys[i]);
    y0 + (y1 - y0) * (x - x0) / (x1 - x0)
}

/// One trajectory phase, validated.
#[derive(Clone, Debug, PartialEq)]
pub struct Phase {
    pub name: String,
    pub kind: PhaseKind,
    /// Duration, s.
    pub duration_s: f64,
    /// Integration step, s: fixed-step RK4 splits the phase into equal steps no longer than
    /// this; the adaptive integrator starts the phase with it.
    pub dt_s: f64,
    /// Longest step the adaptive integrator may take in this phase, s (`INFINITY`: bounded
    /// only by the slosh and excitation periods).
    pub max_step_s: f64,
    /// Engine thrust during a burn, N.
    pub thrust_n: f64,
    /// Flight-path angle γ, rad.
    pub flight_path_angle_rad: f64,
    /// Gravity level or residual acceleration along the tank axis, m/s² (hold: local g;
    /// coast: settling/micro-g level; burn: added to the thrust acceleration).
    pub gravity_m_s2: f64,
    pub excitation: Excitation,
    /// Whether the helium pressurization system may flow in this phase.
    pub pressurize: bool,
    /// The insulation's surroundings (used only with `[insulation]`).
    pub environment: Environment,
    /// Whether the jet mixer runs in this phase (used only with `[mixer]`; default on).
    pub mixer: bool,
    /// Whether the thermodynamic vent system may run in this phase (used only with `[tvs]`;
    /// default on).
    pub tvs: bool,
}

impl Phase {
    /// Number of equal steps and their length: ceil(duration/dt), ending exactly at the phase end.
    pub fn steps(&self) -> (u64, f64) {
        let n = (self.duration_s / self.dt_s).ceil().max(1.0);
        (n as u64, self.duration_s / n)
    }

    /// Phase times in (0, duration) where the excitation has a corner (step, ramp and gust
    /// ends), ascending, `INFINITY` where there is none: adaptive steps end on them exactly.
    pub fn breakpoints(&self) -> [f64; 2] {
        let (a, b) = match self.excitation {
            Excitation::Step { start_s, .. } => (start_s, f64::INFINITY),
            Excitation::Ramp {
                start_s,
                duration_s,
                ..
            }
            | Excitation::Gust {
                start_s,
                duration_s,
                ..
            } => (start_s, start_s + duration_s),
            _ => (f64::INFINITY, f64::INFINITY),
        };
        let inside = |t: f64| {
            if t > 0.0 && t < self.duration_s {
                t
            } else {
                f64::INFINITY
            }
        };
        [inside(a), inside(b)]
    }

    /// The shortest period the excitation imposes, s: a sine's period, a sweep's at its
    /// highest frequency, a gust's duration, a table's shortest interval (None: no period).
    pub fn excitation_period_s(&self) -> Option<f64> {
        match &self.excitation {
            Excitation::Sine { frequency_hz, .. } => Some(1.0 / frequency_hz),
            Excitation::Sweep {
                f_start_hz,
                f_end_hz,
                ..
            } => Some(1.0 / f_start_hz.max(*f_end_hz)),
            Excitation::Gust { duration_s, .. } => Some(*duration_s),
            Excitation::Table { time_s, .. } => time_s
                .windows(2)
                .map(|w| w[1] - w[0])
                .filter(|d| *d > 0.0)
                .reduce(f64::min),
            _ => None,
        }
    }
}

/// Atmospheric density at altitude `h`, kg/m³ (exponential model, 0 below sea level clamp).
pub fn air_density<T: Real>(h_m: T) -> T {
    (-h_m.max_c(0.0) / SCALE_HEIGHT_M).exp() * RHO_SEA_LEVEL
}

/// Ambient pressure at altitude `h`, Pa: the relief valve's back pressure.
pub fn ambient_pressure<T: Real>(h_m: T) -> T {
    (-h_m.max_c(0.0) / SCALE_HEIGHT_M).exp() * P_SEA_LEVEL_PA
}

/// Gravitational acceleration at altitude `h`, m/s² (inverse square).
pub fn gravity<T: Real>(h_m: T) -> T {
    let r = (h_m.max_c(0.0) + EARTH_RADIUS_M).rdiv(EARTH_RADIUS_M);
    r * r * G0
}
