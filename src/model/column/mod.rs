//! The `layered` level (docs/PHYSICS.md 2.8): the lumped levels' warm surface film over a
//! resolved column of N layers, each with its own temperature, under the same ullage, walls,
//! two-mode slosh analog and boundary flows.
//!
//! The film (slots `M_S`, `H_S`) is the lumped levels' stratified layer, with the same closures:
//! evaporation and the ullage's heat at its surface, growth by conduction penetration into the
//! liquid below (deepened by the slosh wave's eddy diffusivity, `wave_mixing`) and overturning when
//! it is colder than what is under it. It is the sub-grid model of the interface, whose
//! millimetre-thick conduction layer no affordable grid resolves. The column (slot `M_B` and the
//! enthalpies from `COL`) replaces the single bulk node: its layers hold fixed shares w_k of the
//! column's mass (finer towards the top by `layered.stretch`), so their masses need no slots and a
//! draining tank keeps its resolution. Mass leaves or enters where it physically does — the engine
//! and the thermodynamic vent draw from the bottom layer, the film entrains the top one, the wall
//! boundary layer takes liquid from the layers it passes and gives it to the layer where it stops
//! rising (the top one at the latest) — and the layer boundaries move with the liquid: the mass
//! that must cross boundary k for every layer to keep its share, F_k = Σ_{j≤k} (S_j − w_j ṁ_col),
//! carries the upwind layer's enthalpy (a conservative first-order remap). Energy moves between
//! neighbours by conduction (molecular, times `stratification.diffusivity_factor`), overturning
//! where the lower layer is warmer (Lloyd & Moran, as the lumped levels' unstable interface), and a
//! wave-induced eddy diffusivity that decays with depth as the slosh modes do. Every exchange is
//! written once and applied with opposite signs, so mass and energy close.

mod rhs;

pub use rhs::{neighbour_exchange, rhs, Exchange};

use super::derive::{self, Derived, Drive};
use super::params::{Layered, Params};
use super::state::*;
use super::Group;
use crate::lanes::{c, Real};

/// Default number of layers (`layered.layers`).
pub const DEFAULT_LAYERS: u32 = 20;

/// Default mass ratio of a layer to the one above it (`layered.stretch`): with 20 layers the top
/// layer holds 1.0 % of the column and the bottom one 14 %.
pub const DEFAULT_STRETCH: f64 = 1.15;

/// Smallest share of the column's mass the top (thinnest) layer may hold: `campaign::validate`
/// refuses a `layered.stretch` that makes it thinner. Thinner layers only refine what the film
/// already resolves, and the boundary layer's flow through them (explicit, upwind) outruns fixed
/// steps: the MHTB tank under 2 s RK4 steps diverged at top shares of 2.4e-5 and below (32
/// layers at stretch 1.35; 16 at 2), under 60 s steps at 1e-4; at 1e-3 it ran under 2, 60 and
/// 600 s steps, and every shipped campaign under its own.
pub const MIN_TOP_LAYER_SHARE: f64 = 1.0e-3;

/// The largest `layered.stretch` whose top layer keeps [`MIN_TOP_LAYER_SHARE`] with `layers`
/// layers (bisection on the share, which falls as the stretch grows), at most `most`.
pub fn max_stretch(layers: u32, most: f64) -> f64 {
    let top = |stretch: f64| {
        let n = (layers as usize).clamp(1, NL_MAX);
        fractions(&Layered {
            layers,
            stretch,
            detrain_width_k: DETRAIN_WIDTH_K,
        })[n - 1]
    };
    if top(most) >= MIN_TOP_LAYER_SHARE {
        return most;
    }
    let (mut lo, mut hi) = (1.0, most);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if top(mid) >= MIN_TOP_LAYER_SHARE {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Default width, K, over which the boundary layer's detrainment into a layer goes from none
/// (its mean temperature half of it above the layer over it) to all (half below):
/// `layered.detrain_width_k`, a numerical smoothing of the neutral-buoyancy switch so that the
/// right-hand side stays continuous, small against any stratification that matters.
pub const DETRAIN_WIDTH_K: f64 = 2.0e-3;

/// The layers' mass fractions w_k, bottom (k = 0) to top, for `l`: geometric, each layer
/// `l.stretch` times the mass of the one above it, summing to 1. Entries from `l.layers` on are 0.
pub fn fractions(l: &Layered) -> [f64; NL_MAX] {
    let n = (l.layers as usize).clamp(1, NL_MAX);
    let mut w = [0.0; NL_MAX];
    let mut weight = 1.0;
    for k in (0..n).rev() {
        w[k] = weight;
        weight *= l.stretch;
    }
    let total: f64 = w.iter().sum();
    for x in &mut w {
        *x /= total;
    }
    w
}

/// The column at one instant: per layer, bottom (k = 0) to top (`n − 1`).
#[derive(Clone, Copy, Debug)]
pub struct Profile<T> {
    /// Number of layers.
    pub n: usize,
    /// Mass fractions w_k.
    pub w: [f64; NL_MAX],
    /// Masses w_k m_col, kg.
    pub m: [T; NL_MAX],
    /// Specific enthalpies, J/kg.
    pub h: [T; NL_MAX],
    /// Temperatures T(h_k), K.
    pub t: [T; NL_MAX],
    /// Densities, kg/m³.
    pub rho: [T; NL_MAX],
    /// Volumes, m³.
    pub v: [T; NL_MAX],
}

/// The column of state `s`: every layer's mass, enthalpy, temperature, density and volume. A
/// column merged into the film (`model::merge_empty_bulk`: `M_B` = 0) has the film's enthalpy in
/// every (massless) layer.
pub fn profile<T: Real>(g: Group<'_>, s: &State<T>) -> Profile<T> {
    let p0 = g.shared();
    let fluid = p0.fluid;
    let f = fluid.props();
    let n = (p0.layered.layers as usize).clamp(1, NL_MAX);
    let zero = [T::default(); NL_MAX];
    let mut out = Profile {
        n,
        w: fractions(&p0.layered),
        m: zero,
        h: zero,
        t: zero,
        rho: zero,
        v: zero,
    };
    let gone = s[M_B].le(c(0.0));
    let h_film = s[H_S] / s[M_S].max_c(1.0e-12);
    let m_col = s[M_B].max_c(1.0e-12);
    for k in 0..n {
        let m = m_col * out.w[k];
        let h = T::select(gone, h_film, s[COL + k] / m);
        let t = fluid.t_from_h_l_k(h);
        let rho = f.rho_l_kg_per_m3(t);
        out.m[k] = m;
        out.h[k] = h;
        out.t[k] = t;
        out.rho[k] = rho;
        out.v[k] = T::select(gone, c(0.0), m / rho);
    }
    out
}

/// The derived quantities of the `layered` level: the film is the warm layer (interface
/// temperature, evaporation), the column's bottom layer the bulk (the outlet: NPSH, and the
/// stratification film − bottom); once the column has merged into the film, the film is both.
pub fn derive_column<T: Real>(
    g: Group<'_>,
    s: &State<T>,
    d: &Drive<T>,
    prof: &Profile<T>,
) -> Derived<T> {
    let fluid = g.shared().fluid;
    let f = fluid.props();
    let t_film = fluid.t_from_h_l_k(s[H_S] / s[M_S].max_c(1.0e-12));
    let rho_film = f.rho_l_kg_per_m3(t_film);
    let gone = s[M_B].le(c(0.0));
    let mut out = Derived {
        t_layer_k: t_film,
        t_bulk_k: T::select(gone, t_film, prof.t[0]),
        rho_layer: rho_film,
        rho_bulk: T::select(gone, rho_film, prof.rho[0]),
        v_layer_m3: s[M_S] / rho_film,
        m_liquid_kg: s[M_S] + s[M_B],
        ..Default::default()
    };
    let (mut v_col, mut lo, mut hi) = (c::<T>(0.0), t_film, t_film);
    for k in 0..prof.n {
        v_col += prof.v[k];
        lo = lo.min(prof.t[k]);
        hi = hi.max(prof.t[k]);
    }
    out.v_bulk_m3 = v_col;
    out.t_liquid_min_k = lo;
    out.t_liquid_max_k = hi;
    let (t_b, rho_b) = (out.t_bulk_k, out.rho_bulk);
    let nu = move || f.mu_l_pa_s(t_b) / rho_b;
    let v_l = out.v_layer_m3 + v_col;
    derive::finish_nodes(g, &g.tank(), s, d, &mut out, v_l, nu);
    out
}

/// The initial state of the film and the column: the film as the lumped levels' initial layer
/// (`stratification.initial_thickness_m` at `stratification.initial_temperature_k`, by volume at
/// most half the liquid), the column at the liquid temperature filling the rest of the stated
/// liquid volume.
pub fn initial_column(p: &Params, s: &mut State) {
    let f = p.fluid.props();
    let n = (p.layered.layers as usize).clamp(1, NL_MAX);
    let w = fractions(&p.layered);
    let (t_l, t_s) = (
        p.liquid_temperature_k,
        p.stratification.initial_temperature_k,
    );
    let v_l = p.fill_fraction * p.tank.volume_m3();
    let z = p.tank.liquid_height_m(v_l);
    let area = p.tank.interface_area_m2(z).max(1.0e-6);
    let v_s = (area * p.stratification.initial_thickness_m).min(0.5 * v_l);
    let m_s = f.rho_l_kg_per_m3(t_s) * v_s;
    let m_b = f.rho_l_kg_per_m3(t_l) * (v_l - v_s);
    let h_l = f.h_l_j_per_kg(t_l);
    s[M_S] = m_s;
    s[H_S] = m_s * f.h_l_j_per_kg(t_s);
    s[M_B] = m_b;
    s[H_B] = 0.0;
    for k in 0..n {
        s[COL + k] = w[k] * m_b * h_l;
    }
}
