//! Slosh mechanical-analog parameters and damping (MODEL.md §5, docs/PHYSICS.md "Slosh").
//!
//! Flat-bottom upright cylinders: the closed-form modal masses, lengths and frequencies of
//! Abramson, NASA SP-106, ch. 6 (Dodge, "The New Dynamic Behavior of Liquids in Moving
//! Containers", 2000), [`mode_shape`]. Spheres and capsules: tables of a converged linear
//! potential-flow solution of the real tank shape (`tools/slosh_fem.py`, generated into
//! [`super::slosh_table`] by `tools/slosh_tables.py`), interpolated by [`domed_modes`].
//! The damping correlations are cylinder correlations evaluated on [`equivalent_cylinder`].

use super::slosh_table as table;
use super::Group;
use crate::geometry::{Shape, TankLanes};
use crate::lanes::{c, Mask, Real, WIDTH};
use std::f64::consts::PI;

/// Roots of J1'(ξ) = 0 for the first two antisymmetric modes.
pub const XI: [f64; 2] = [1.841_18, 5.331_44];

/// Smallest axial acceleration the slosh model sees, m/s² (MODEL.md §5 floor). Below it the
/// restoring stiffness is this floor: frequencies go to ~0.3 mHz in a 1 m tank, never to NaN.
pub const MIN_AXIAL_ACCEL: f64 = 1.0e-6;

/// Shallowest equivalent depth ratio h/R, so that modal formulas stay finite near empty.
pub const MIN_DEPTH_RATIO: f64 = 0.02;

/// Smallest free-surface radius over the tank radius that the domed-tank tables are evaluated
/// with: a domed tank filled to its top pole keeps finite frequencies (ω² R/g ≲ 60).
pub const MIN_SURFACE_RADIUS_RATIO: f64 = 0.05;

/// Dimensionless properties of slosh mode `n` (0-based) at depth ratio h/R.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ModeShape<T = f64> {
    /// Modal mass over liquid mass, m_n / m_l.
    pub mass_ratio: T,
    /// Pendulum length over radius, L_n / R (= a_ax / (ω_n² R): the pendulum analog).
    pub length_ratio: T,
    /// ω_n² R / a_ax, R the tank radius (cylinder: the free-surface radius, the same).
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

/// Equivalent flat-bottom cylinder for any shape: the free-surface radius r (floored at
/// [`MIN_SURFACE_RADIUS_RATIO`] R) and the depth that holds the liquid volume under that
/// surface, h = V_l / (π r²). Returns (r, h), m. Exact for a cylinder. For spheres and capsules
/// it is used only for the damping correlations ([`wall_damping`], [`baffle_damping`]), which
/// are cylinder correlations; the modal properties come from [`domed_modes`] (the equivalent
/// cylinder was 6–12 % low in frequency there, see docs/PHYSICS.md).
pub fn equivalent_cylinder<T: Real>(
    surface_radius_m: T,
    liquid_volume_m3: T,
    tank_radius_m: T,
) -> (T, T) {
    let r = surface_radius_m.max(tank_radius_m * MIN_SURFACE_RADIUS_RATIO);
    let h = liquid_volume_m3 / (r * r * PI);
    (r, h)
}

/// The first two slosh modes of `tank` (every lane's own shape, radius, barrel length and dome
/// ratio) with the free surface at `level_m` (m above the bottom) over `liquid_volume_m3` (m³)
/// of liquid: cylinders by [`mode_shape`] at h = V_l / (π R²), spheres and capsules by
/// [`domed_modes`]. `length_ratio` and `omega2_ratio` are over the tank radius R.
pub fn tank_modes<T: Real>(
    tank: &TankLanes<T>,
    level_m: T,
    liquid_volume_m3: T,
) -> [ModeShape<T>; 2] {
    let (shape, radius, length, k) = tank.dimensions();
    if shape == Shape::Cylinder {
        let (r, h) = equivalent_cylinder(radius, liquid_volume_m3, radius);
        return [mode_shape(0, h / r), mode_shape(1, h / r)];
    }
    // The tank's table axes are worked out once for lanes of the same tank (all of them, unless
    // the dome ratio or barrel length is dispersed).
    let l_over_r = length / radius;
    let mut lane_axes = [DomeAxes::default(); WIDTH];
    for i in 0..T::LANES {
        let (k_i, l_i) = (k.lane(i), l_over_r.lane(i));
        lane_axes[i] = match i.checked_sub(1).map(|j| lane_axes[j]) {
            Some(a) if a.k.to_bits() == k_i.to_bits() && a.l.to_bits() == l_i.to_bits() => a,
            _ => DomeAxes::new(k_i, l_i),
        };
    }
    domed_modes_lanes(
        k,
        l_over_r,
        level_m / radius,
        liquid_volume_m3 / (radius * radius * radius),
        |i| lane_axes[i],
    )
}

/// Catmull-Rom nodes and weights at grid coordinate `x` (clamped to [0, n − 1]) on `n` nodes; the
/// end intervals use a ghost node extended linearly from the last two.
fn catmull_rom(n: usize, x: f64) -> ([usize; 4], [f64; 4]) {
    let (i, t) = cell(n, x);
    let (t2, t3) = (t * t, t * t * t);
    let mut w = [
        0.5 * (-t3 + 2.0 * t2 - t),
        0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t),
        0.5 * (t3 - t2),
    ];
    let mut idx = [i.saturating_sub(1), i, i + 1, (i + 2).min(n - 1)];
    if i == 0 {
        (w[1], w[2], w[0]) = (w[1] + 2.0 * w[0], w[2] - w[0], 0.0);
        idx[0] = 0;
    }
    if i + 2 > n - 1 {
        (w[2], w[1], w[3]) = (w[2] + 2.0 * w[3], w[1] - w[3], 0.0);
    }
    (idx, w)
}

/// Linear-interpolation nodes and weights at grid coordinate `x` (clamped) on `n` nodes.
fn linear(n: usize, x: f64) -> ([usize; 2], [f64; 2]) {
    let (i, t) = cell(n, x);
    ([i, i + 1], [1.0 - t, t])
}

/// Interval `i` of grid coordinate `x` on `n` nodes and the position `t` ∈ [0, 1] in it; `x` is
/// clamped to [0, n − 1], NaN to 0.
fn cell(n: usize, x: f64) -> (usize, f64) {
    let x = if x.is_nan() {
        0.0
    } else {
        x.clamp(0.0, (n - 1) as f64)
    };
    let i = (x.floor() as usize).min(n - 2);
    (i, x - i as f64)
}

/// One table column (nodes of 4 values from `base`) at the Catmull-Rom nodes and weights
/// `(idx, w)` of [`catmull_rom`] (computed once per surface position, shared by the k nodes).
fn column(data: &[f64], base: usize, (idx, w): &([usize; 4], [f64; 4])) -> [f64; 4] {
    let mut out = [0.0; 4];
    for (&j, &wj) in idx.iter().zip(w) {
        let node: &[f64; 4] = data[base + 4 * j..base + 4 * j + 4]
            .try_into()
            .expect("a table node holds 4 values");
        for (o, d) in out.iter_mut().zip(node) {
            *o += wj * d;
        }
    }
    out
}

/// The first two slosh modes of a capsule of dome ratio `k` and barrel length `l_over_r` L/R
/// (the sphere: k = 1, L = 0) with the free surface at `z_over_r` z/R above the bottom pole and
/// `v_over_r3` V_l/R³ of liquid, from the generated [`super::slosh_table`] (linear potential
/// flow, `tools/slosh_fem.py`): `omega2_ratio` = ω² R/a, `mass_ratio` = m_n/m_l,
/// `length_ratio` = a/(ω² R).
///
/// Interpolation: linear in log₂ k between the nodes k = 2^(j/4) (0.088 … 3.36), Catmull-Rom
/// along the fill coordinate of the region holding the surface (bottom dome √(z/kR), barrel
/// √(h/3R) with h the depth above the bottom dome, top-dome height u), linear in
/// β = exp(−2 ξ_1 L/R) in the top dome.
/// Interpolation error against the solver (docs/PHYSICS.md): for 0.25 ≤ k ≤ 2 ω_n² ≤ 0.12 %,
/// m_1 ≤ 0.11 %, m_2 ≤ 0.63 %; down to k = 0.1 and up to k = 3 (the input range) ω_1² ≤ 1 %,
/// m_2 ≤ 3.2 %. Outside the ranges: k beyond the end nodes takes the end node's table at the
/// tank's own normalised fill; a barrel surface more than 3 R above the bottom dome takes the deep values
/// (ω² and m_n then change by < 1e-4); a top-dome surface above u = 0.96 keeps its ω² r_s/g and
/// m_n/(ρ r_s³), with r_s floored at [`MIN_SURFACE_RADIUS_RATIO`] R.
pub fn domed_modes(k: f64, l_over_r: f64, z_over_r: f64, v_over_r3: f64) -> [ModeShape; 2] {
    let axes = DomeAxes::new(k, l_over_r);
    domed_modes_lanes(k, l_over_r, z_over_r, v_over_r3, |_| axes)
}

/// Region of the tank holding the free surface, which picks the table.
#[derive(Clone, Copy)]
enum Region {
    Bottom,
    Barrel,
    Top,
}

/// [`domed_modes`] per lane, with lane i's table axes `axes(i)`. The arithmetic on the tank and
/// the fill (the region, the grid coordinate, the scale factors: divides and square roots) runs
/// in lanes; only the table lookup is per lane. Lane i does the `f64` operations of
/// [`domed_modes`] in the same order, so the same bits.
fn domed_modes_lanes<T: Real>(
    k: T,
    l_over_r: T,
    z_over_r: T,
    v_over_r3: T,
    axes: impl Fn(usize) -> DomeAxes,
) -> [ModeShape<T>; 2] {
    let (l, z, v) = (
        l_over_r.max_c(0.0),
        z_over_r.max_c(0.0),
        v_over_r3.max_c(1e-300),
    );
    let bottom = z.le(k);
    let barrel = !bottom & z.lt(k + l);
    let x_bottom = (z / k).sqrt() * (table::N_SIGMA - 1) as f64;
    let x_barrel = ((z - k) / table::BARREL_H_MAX).sqrt() * (table::N_BARREL - 1) as f64;
    let u = ((z - k - l) / k).min_c(1.0);
    let rs = (u * u)
        .rsub(1.0)
        .max_c(0.0)
        .sqrt()
        .max_c(MIN_SURFACE_RADIUS_RATIO);
    let x_top = u / table::TOP_U_MAX * (table::N_TOP - 1) as f64;
    let x = T::select(bottom, x_bottom, T::select(barrel, x_barrel, x_top));
    // Per-node values (a_1, b_1, a_2, b_2), from each lane's table.
    let mut q = [[0.0; 4]; WIDTH];
    for (i, qi) in q.iter_mut().enumerate().take(T::LANES) {
        let region = if bottom.lane(i) {
            Region::Bottom
        } else if barrel.lane(i) {
            Region::Barrel
        } else {
            Region::Top
        };
        *qi = table_values(&axes(i), region, x.lane(i));
    }
    let node = |j: usize| T::from_fn(|i| q[i][j]);
    // How the node values become (ω² R/a, m_n/m_l): ×1 in the bottom dome; the barrel's masses
    // over V/R³; the top dome's ω² over r_s/R and masses times (r_s/R)³/(V/R³).
    let one = T::splat(1.0);
    let omega_scale = T::select(bottom | barrel, one, rs.rdiv(1.0));
    let mass_scale = T::select(
        bottom,
        one,
        T::select(barrel, v.rdiv(1.0), rs * rs * rs / v),
    );
    [0, 1].map(|n| {
        let omega2 = node(2 * n) * omega_scale;
        ModeShape {
            mass_ratio: node(2 * n + 1) * mass_scale,
            length_ratio: omega2.rdiv(1.0),
            omega2_ratio: omega2,
        }
    })
}

/// The table's node values (a_1, b_1, a_2, b_2) of `region` at grid coordinate `x`, linear in
/// the dome-ratio axis (and in β in the top dome) of `axes`, Catmull-Rom along `x`.
fn table_values(axes: &DomeAxes, region: Region, x: f64) -> [f64; 4] {
    let (kn, kw) = (axes.kn, axes.kw);
    let mut q = [0.0; 4];
    match region {
        Region::Bottom | Region::Barrel => {
            let (data, n): (&[f64], usize) = match region {
                Region::Bottom => (&table::BOTTOM, table::N_SIGMA),
                _ => (&table::BARREL, table::N_BARREL),
            };
            let cr = catmull_rom(n, x);
            for (&i, w) in kn.iter().zip(kw) {
                let c = column(data, 4 * i * n, &cr);
                q.iter_mut().zip(c).for_each(|(a, b)| *a += w * b);
            }
        }
        Region::Top => {
            let (bn, bw) = (axes.bn, axes.bw);
            let cr = catmull_rom(table::N_TOP, x);
            for (&i, w) in kn.iter().zip(kw) {
                for (&b, wb) in bn.iter().zip(bw) {
                    let base = 4 * table::N_TOP * (b + table::N_BETA * i);
                    let c = column(&table::TOP, base, &cr);
                    q.iter_mut().zip(c).for_each(|(a, b)| *a += w * wb * b);
                }
            }
        }
    }
    q
}

/// What [`domed_modes`] reads of the tank alone: its dome ratio `k` and barrel length `l` L/R
/// as given, their table nodes and weights (log₂ k, and β = exp(−2 ξ_1 L/R) for the top dome).
#[derive(Clone, Copy, Debug, Default)]
struct DomeAxes {
    k: f64,
    l: f64,
    kn: [usize; 2],
    kw: [f64; 2],
    bn: [usize; 2],
    bw: [f64; 2],
}

impl DomeAxes {
    fn new(k: f64, l_over_r: f64) -> DomeAxes {
        let (kn, kw) = linear(table::NK, (k.log2() - table::LOG2K_0) / table::LOG2K_STEP);
        let beta = (-2.0 * XI[0] * l_over_r.max(0.0)).exp() * (table::N_BETA - 1) as f64;
        let (bn, bw) = linear(table::N_BETA, beta);
        DomeAxes {
            k,
            l: l_over_r,
            kn,
            kw,
            bn,
            bw,
        }
    }
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
    let e = x.exp();
    let inv = e.rdiv(1.0);
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
