//! Tank shapes: volumes, liquid height ↔ volume, interface and wall areas.
//!
//! Every tank is axisymmetric about the vertical (thrust) axis. The height
//! coordinate `z` (metres) is measured upwards from the lowest point of the
//! tank, `0 ≤ z ≤ H`. The liquid is assumed settled with a flat free surface
//! perpendicular to the axis at height `z`, so all "liquid" quantities are
//! functions of `z` alone. All methods clamp `z` (or a volume) into its valid
//! range, never panic, never allocate, and return finite values for finite,
//! validated tank dimensions. A NaN argument is treated like `0` (empty).
//!
//! # Shapes
//!
//! * [`Shape::Cylinder`]: radius `R`, length `L`, flat end discs; `H = L`.
//! * [`Shape::Capsule`]: a cylinder of radius `R` and length `L ≥ 0` closed by
//!   two half-spheroid domes of height `a = k·R` (`k` = dome ratio);
//!   `H = L + 2a`. `k < 1` gives oblate (e.g. 2:1 elliptical, `k = 0.5`),
//!   `k = 1` hemispherical and `k > 1` prolate domes.
//! * [`Shape::Sphere`]: radius `R`, `H = 2R` (internally a capsule with
//!   `k = 1`, `L = 0`).
//!
//! # Numerical methods (all closed form, no quadrature)
//!
//! * Dome cap volume (depth `w` below/above a pole): `π w² (3a − w) / (3k²)`,
//!   the spheroid generalisation of the sphere cap `π w² (3R − w) / 3`.
//! * Dome zone (wall) area: the exact antiderivative of
//!   `2π r √(1 + r'²) = (2π/k²) √(c² + e s²)`, with `s` the distance from the
//!   equator, `c = k²R` and `e = 1 − k²`, which is an `asinh` form for oblate
//!   domes and an `asin` form for prolate ones. The *difference* of the
//!   antiderivative between two heights is rewritten with the addition
//!   theorems `asinh x − asinh y = asinh D` / `asin x − asin y = asin D` and
//!   `x² − y² = (x − y)(x + y)`, so that no cancellation occurs between the
//!   two ends of the zone (thin zones stay accurate); `asinh(D)/D` and `asin(D)/D` are evaluated by their
//!   Taylor series for small `D`, and for very prolate domes (`D → 1`, where
//!   `asin` is ill-conditioned) `asin D` is computed as `atan2(D, cos)` with
//!   the cosine of the angle difference formed from positive terms. Compared
//!   during development with 50-digit quadrature: a few ulps (≤ 1e-15 relative) for
//!   `1e-6 ≤ k ≤ 5`, including `k → 1` (the sphere limit `2π R w` is
//!   reproduced for `k = 1`) and thin zones at a pole. For strongly prolate
//!   domes the algebraic and `asin` parts partly cancel near the pole, so the
//!   error grows like `ε k²` (≈ 4e-14 at `k = 20`, 1e-12 at `k = 100`).
//!   The slope `2π r √(1 + r'²)` is evaluated from positive terms only and is
//!   accurate to a few ulps for every `k`; at a pole it is `2π R / k`.
//! * Height from volume: inside a dome the normalised cap equation
//!   `t² (3 − t) = q` (`t = w/a`, `q = 2 V_cap / V_dome`) is solved by Newton's
//!   method started from the trigonometric (Viète) root and safeguarded by
//!   bisection inside the bracket `√(q/3) ≤ t ≤ √(q/2)`; in the cylindrical
//!   part the inverse is linear. Round trips `z(V(z))` agree to ~1e-14
//!   relative. Very close to a domed top (within ~1e-6·H) the volume deficit
//!   `V_total − V` is itself only known to ~ε·V_total, which limits any
//!   inverse to `|Δz| ~ √(ε V_total / R)`; the backward error
//!   `V(z(V)) − V` stays at the rounding level there.
//!
//! The dome ratio is clamped internally to `[1e-6, 1e6]` so that extreme
//! values cannot underflow/overflow the intermediate quantities.

use crate::lanes::{Mask, Real};
use std::f64::consts::PI;

/// Smallest dome ratio used internally (larger inputs are unaffected).
const MIN_DOME_RATIO: f64 = 1e-6;
/// Largest dome ratio used internally (smaller inputs are unaffected).
const MAX_DOME_RATIO: f64 = 1e6;

/// Tank shape family. All shapes are axisymmetric about the thrust axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// Right circular cylinder with flat end discs.
    Cylinder,
    /// Cylinder closed by two half-spheroid (elliptical) domes.
    Capsule,
    /// Sphere.
    Sphere,
}

impl Shape {
    /// Canonical lower-case name (`"cylinder"`, `"capsule"`, `"sphere"`), used
    /// in configuration files and output metadata.
    pub fn name(self) -> &'static str {
        match self {
            Shape::Cylinder => "cylinder",
            Shape::Capsule => "capsule",
            Shape::Sphere => "sphere",
        }
    }

    /// Parses a shape name as produced by [`Shape::name`]. Surrounding
    /// whitespace and ASCII case are ignored; unknown names give `None`.
    pub fn from_name(s: &str) -> Option<Shape> {
        let s = s.trim();
        [Shape::Cylinder, Shape::Capsule, Shape::Sphere]
            .into_iter()
            .find(|shape| shape.name().eq_ignore_ascii_case(s))
    }
}

/// Tank geometry with precomputed totals.
///
/// Construct with [`Tank::new`]; all lengths are metres, areas m², volumes m³.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tank {
    /// Shape family.
    shape: Shape,
    /// Radius `R` of the cylindrical section / sphere (m).
    radius: f64,
    /// Length `L` of the cylindrical section (m); 0 for a sphere.
    length: f64,
    /// Dome ratio `k` (1 for a sphere, unused for a cylinder).
    k: f64,
    /// Dome height `a = k R` (m); 0 for a cylinder.
    a: f64,
    /// `e = 1 − k²` (oblate > 0, prolate < 0).
    e: f64,
    /// `c = k² R` (m): value of `√(c² + e s²)` at the equator.
    c: f64,
    /// Total height `H` (m).
    height: f64,
    /// Total internal volume (m³).
    volume: f64,
    /// Total internal wall area including ends (m²).
    wall_area: f64,
    /// Volume of one dome (m³); 0 for a cylinder.
    dome_volume: f64,
    /// Wall area of one dome (m²); for a cylinder the end-disc area `π R²`.
    dome_area: f64,
    /// Cylinder cross-section `π R²` (m²).
    disc_area: f64,
}

impl Tank {
    /// Builds a tank and precomputes its totals.
    ///
    /// `radius_m` is the radius `R` (m), `cylinder_length_m` the length `L`
    /// (m) of the straight cylindrical part and `dome_ratio` the dome height
    /// over radius `k` for a capsule.
    /// Inputs are assumed validated (positive finite radius, L ≥ 0,
    /// dome_ratio > 0); for Sphere and Cylinder dome_ratio is ignored, for
    /// Sphere L is ignored. A negative or NaN `L` is treated as 0 and the dome
    /// ratio is clamped to `[1e-6, 1e6]`.
    pub fn new(shape: Shape, radius_m: f64, cylinder_length_m: f64, dome_ratio: f64) -> Tank {
        let radius = radius_m;
        let length = match shape {
            Shape::Sphere => 0.0,
            _ => cylinder_length_m.max(0.0),
        };
        let k = match shape {
            Shape::Capsule => dome_ratio.clamp(MIN_DOME_RATIO, MAX_DOME_RATIO),
            _ => 1.0,
        };
        // NaN dome ratio: clamp propagates NaN; fall back to a hemisphere.
        let k = if k.is_nan() { 1.0 } else { k };
        let disc_area = PI * radius * radius;
        let mut tank = Tank {
            shape,
            radius,
            length,
            k,
            a: 0.0,
            e: (1.0 - k) * (1.0 + k),
            c: k * k * radius,
            height: length,
            volume: disc_area * length,
            wall_area: 0.0,
            dome_volume: 0.0,
            dome_area: disc_area,
            disc_area,
        };
        match shape {
            Shape::Cylinder => {
                tank.wall_area = 2.0 * disc_area + 2.0 * PI * radius * length;
            }
            Shape::Capsule | Shape::Sphere => {
                let a = k * radius;
                tank.a = a;
                tank.height = length + 2.0 * a;
                // Half spheroid with semi-axes (R, R, a): (2/3) π R² a.
                tank.dome_volume = 2.0 / 3.0 * PI * radius * radius * a;
                tank.volume = 2.0 * tank.dome_volume + disc_area * length;
                tank.dome_area = tank.lanes().zone_area(a);
                tank.wall_area = 2.0 * tank.dome_area + 2.0 * PI * radius * length;
            }
        }
        tank
    }

    /// Shape family of this tank.
    pub fn shape(&self) -> Shape {
        self.shape
    }

    /// Radius `R` of the cylindrical section or sphere (m).
    pub fn radius_m(&self) -> f64 {
        self.radius
    }

    /// Total internal height `H` (m) along the axis: `L` (cylinder),
    /// `L + 2kR` (capsule) or `2R` (sphere). Upper bound of `z`.
    pub fn height_m(&self) -> f64 {
        self.height
    }

    /// Total internal volume (m³); the capacity of the tank.
    pub fn volume_m3(&self) -> f64 {
        self.volume
    }

    /// Total internal wall area including ends/domes (m²), used for heat
    /// leak and wall thermal mass.
    pub fn wall_area_m2(&self) -> f64 {
        self.wall_area
    }

    /// Length `L` of the cylindrical section (m); 0 for a sphere.
    pub(crate) fn length_m(&self) -> f64 {
        self.length
    }

    /// Dome ratio `k` as used internally (clamped; 1 for a sphere or cylinder).
    pub(crate) fn dome_ratio(&self) -> f64 {
        self.k
    }

    /// Dome height `a = k R` (m); 0 for a cylinder.
    pub(crate) fn dome_height_m(&self) -> f64 {
        self.a
    }

    /// `e = 1 − k²` (oblate > 0, prolate < 0).
    pub(crate) fn dome_e(&self) -> f64 {
        self.e
    }

    /// `c = k² R` (m).
    pub(crate) fn dome_c_m(&self) -> f64 {
        self.c
    }

    /// Volume of one dome (m³); 0 for a cylinder.
    pub(crate) fn dome_volume_m3(&self) -> f64 {
        self.dome_volume
    }

    /// Wall area of one dome (m²); for a cylinder the end-disc area `π R²`.
    pub(crate) fn dome_area_m2(&self) -> f64 {
        self.dome_area
    }

    /// Cylinder cross-section `π R²` (m²).
    pub(crate) fn disc_area_m2(&self) -> f64 {
        self.disc_area
    }

    /// Liquid volume (m³) below the flat free surface at height `z_m` (m);
    /// `z_m` is clamped to `[0, H]`. Strictly increasing in `z`.
    pub fn liquid_volume_m3(&self, z_m: f64) -> f64 {
        let z = self.lanes().clamp_z(z_m);
        match self.shape {
            Shape::Cylinder => self.disc_area * z,
            Shape::Capsule | Shape::Sphere => {
                let z1 = self.a;
                let z2 = self.a + self.length;
                if z <= z1 {
                    self.cap_volume(z)
                } else if z < z2 {
                    self.dome_volume + self.disc_area * (z - z1)
                } else {
                    self.volume - self.cap_volume(self.height - z)
                }
            }
        }
    }

    /// Liquid height (m) whose [`liquid_volume_m3`](Tank::liquid_volume_m3)
    /// equals `volume_m3` (m³), the inverse used to place the free surface
    /// for a given liquid inventory. The volume is clamped to `[0, V]`.
    /// Inside a dome the cap cubic is solved by Newton's method safeguarded
    /// by bisection; round trips `z(V(z))` are accurate to ~1e-14 relative
    /// (see the module docs for the conditioning limit right at a domed top).
    pub fn liquid_height_m(&self, volume_m3: f64) -> f64 {
        self.lanes().liquid_height_m(volume_m3)
    }

    /// Radius (m) of the free surface (the tank's inner radius) at height
    /// `z_m` (m), clamped to `[0, H]`. Zero at the poles of domed shapes.
    pub fn surface_radius_m(&self, z_m: f64) -> f64 {
        self.lanes().surface_radius_m(z_m)
    }

    /// Area (m²) of the flat liquid–vapour interface `π r(z)²` at height
    /// `z_m` (m); drives interfacial heat and mass transfer.
    pub fn interface_area_m2(&self, z_m: f64) -> f64 {
        self.lanes().interface_area_m2(z_m)
    }

    /// Wall area (m²) below height `z_m` (m), including the bottom, i.e. the
    /// wall in contact with liquid (heat leak into the liquid).
    ///
    /// For a cylinder the bottom disc `π R²` is always counted (also at
    /// `z = 0`), and the top disc only when the tank is full (`z ≥ H`), so the
    /// function has a step of `π R²` at `z = H`.
    pub fn wetted_area_m2(&self, z_m: f64) -> f64 {
        self.lanes().wetted_area_m2(z_m)
    }

    /// Wall area (m²) above height `z_m` (m), in contact with vapour:
    /// `wall_area − wetted_area`.
    pub fn dry_area_m2(&self, z_m: f64) -> f64 {
        (self.wall_area - self.wetted_area_m2(z_m)).max(0.0)
    }

    /// Derivative (m) of [`wetted_area_m2`](Tank::wetted_area_m2) with respect
    /// to `z`: `2π r(z) √(1 + r'(z)²)`, used to move wall heat-transfer
    /// regions with the free surface.
    ///
    /// Finite everywhere: at the poles of a dome the closed-form limit
    /// `2π R / k` is returned (`2π R` for a sphere). For a cylinder the side
    /// wall value `2π R` is returned for every `z`, including `z = 0` and
    /// `z = H`; the end discs are steps of the wetted area (Dirac terms of
    /// the derivative) and are not included.
    pub fn wetted_area_slope_m(&self, z_m: f64) -> f64 {
        self.lanes().wetted_area_slope_m(z_m)
    }

    /// Horizontal cross-section area (m²) of the tank at height `z_m` (m),
    /// equal to [`interface_area_m2`](Tank::interface_area_m2) and to
    /// `d(liquid_volume)/dz`.
    pub fn cross_section_area_m2(&self, z_m: f64) -> f64 {
        self.interface_area_m2(z_m)
    }

    /// Volume (m³) of a dome cap of depth `w` (m) measured from the pole:
    /// `π w² (3a − w) / (3k²) = V_dome · t² (3 − t) / 2` with `t = w / a`.
    fn cap_volume(&self, w: f64) -> f64 {
        let t = (w / self.a).clamp(0.0, 1.0);
        0.5 * self.dome_volume * t * t * (3.0 - t)
    }

    /// This tank as a one-lane [`TankLanes`]: the one implementation of the geometry.
    fn lanes(&self) -> TankLanes<f64> {
        TankLanes::gather(|_| self)
    }
}

/// The dimensions of one tank per lane (all lanes of the same shape), for the geometry that the
/// model evaluates in lockstep lanes. [`Tank`]'s methods are this with one lane. Zones become
/// selects: each lane takes the branch its own level is in.
#[derive(Clone, Copy, Debug)]
pub struct TankLanes<T> {
    shape: Shape,
    radius: T,
    length: T,
    k: T,
    a: T,
    e: T,
    c: T,
    height: T,
    volume: T,
    wall_area: T,
    dome_volume: T,
    dome_area: T,
    disc_area: T,
}

impl<T: Real> TankLanes<T> {
    /// Lane `i` is `tank(i)`; every lane must have the shape of lane 0.
    pub fn gather<'a>(tank: impl Fn(usize) -> &'a Tank) -> TankLanes<T> {
        let f = |g: fn(&Tank) -> f64| T::from_fn(|i| g(tank(i)));
        TankLanes {
            shape: tank(0).shape,
            radius: f(|t| t.radius),
            length: f(|t| t.length),
            k: f(|t| t.k),
            a: f(|t| t.a),
            e: f(|t| t.e),
            c: f(|t| t.c),
            height: f(|t| t.height),
            volume: f(|t| t.volume),
            wall_area: f(|t| t.wall_area),
            dome_volume: f(|t| t.dome_volume),
            dome_area: f(|t| t.dome_area),
            disc_area: f(|t| t.disc_area),
        }
    }

    /// Shape, radius `R` (m), barrel length `L` (m) and dome ratio `k` per lane.
    pub fn dimensions(&self) -> (Shape, T, T, T) {
        (self.shape, self.radius, self.length, self.k)
    }

    /// Total internal wall area (m²).
    pub fn wall_area_m2(&self) -> T {
        self.wall_area
    }

    /// [`Tank::liquid_height_m`] per lane.
    pub fn liquid_height_m(&self, volume_m3: T) -> T {
        let zero = T::splat(0.0);
        let v = T::select(volume_m3.gt(zero), volume_m3.min(self.volume), zero);
        let full = v.ge(self.volume);
        match self.shape {
            Shape::Cylinder => T::select(full, self.height, (v / self.disc_area).min(self.height)),
            Shape::Capsule | Shape::Sphere => {
                // One cap solve per lane: the bottom dome's or the top dome's, whichever holds
                // the surface (the cylinder lanes ignore it).
                let bottom = v.le(self.dome_volume);
                let barrel = v.lt(self.volume - self.dome_volume);
                let cyl = (self.a + (v - self.dome_volume) / self.disc_area)
                    .max(self.a)
                    .min(self.a + self.length);
                // Skipped where every lane's surface is in the barrel (a capsule's usual level).
                if !(bottom | !barrel).any() {
                    return T::select(full, self.height, cyl);
                }
                let cap_v = T::select(bottom, v, self.volume - v);
                let w = self.a * cap_fraction(cap_v * 2.0 / self.dome_volume).0;
                let top = (self.height - w).max_c(0.0);
                let z = T::select(barrel, cyl, top);
                let z = T::select(bottom, w, z);
                T::select(full, self.height, z)
            }
        }
    }

    /// [`Tank::surface_radius_m`] per lane.
    pub fn surface_radius_m(&self, z_m: T) -> T {
        match self.shape {
            Shape::Cylinder => self.radius,
            Shape::Capsule | Shape::Sphere => {
                let w = self.dome_depth(self.clamp_z(z_m));
                let dome = (w * (self.a * 2.0 - w)).sqrt() / self.k;
                T::select(w.ge(self.a), self.radius, dome)
            }
        }
    }

    /// [`Tank::interface_area_m2`] per lane.
    pub fn interface_area_m2(&self, z_m: T) -> T {
        match self.shape {
            Shape::Cylinder => self.disc_area,
            Shape::Capsule | Shape::Sphere => {
                let w = self.dome_depth(self.clamp_z(z_m));
                let dome = w * PI * (self.a * 2.0 - w) / (self.k * self.k);
                T::select(w.ge(self.a), self.disc_area, dome)
            }
        }
    }

    /// [`Tank::wetted_area_m2`] per lane.
    pub fn wetted_area_m2(&self, z_m: T) -> T {
        let z = self.clamp_z(z_m);
        match self.shape {
            Shape::Cylinder => {
                let side = self.disc_area + self.radius * (2.0 * PI) * z;
                T::select(z.ge(self.height), self.wall_area, side)
            }
            Shape::Capsule | Shape::Sphere => {
                let z1 = self.a;
                let z2 = self.a + self.length;
                // One zone per lane: the bottom dome's below z1, the top dome's above z2.
                let bottom = z.le(z1);
                let barrel = z.lt(z2);
                let cyl = self.dome_area + self.radius * (2.0 * PI) * (z - z1);
                // Skipped where every lane's surface is in the barrel.
                if !(bottom | !barrel).any() {
                    return cyl;
                }
                let zone = self.zone_area(T::select(bottom, z, self.height - z));
                let top = (self.wall_area - zone).max_c(0.0);
                T::select(bottom, zone, T::select(barrel, cyl, top))
            }
        }
    }

    /// [`Tank::wetted_area_slope_m`] per lane.
    pub fn wetted_area_slope_m(&self, z_m: T) -> T {
        let side = self.radius * (2.0 * PI);
        match self.shape {
            Shape::Cylinder => side,
            Shape::Capsule | Shape::Sphere => {
                let w = self.dome_depth(self.clamp_z(z_m));
                let dome = self.zone_integrand(w) * (2.0 * PI) / (self.k * self.k);
                T::select(w.ge(self.a), side, dome)
            }
        }
    }

    /// Clamps a height into `[0, H]`; NaN maps to 0.
    fn clamp_z(&self, z: T) -> T {
        T::select(z.gt(T::splat(0.0)), z.min(self.height), T::splat(0.0))
    }

    /// Distance (m) from the nearest pole for a domed shape, capped at `a`
    /// (anything in the cylindrical part returns `a` or more).
    fn dome_depth(&self, z: T) -> T {
        let top = (self.height - z).max_c(0.0);
        let w = T::select(z.lt(self.a + self.length), self.a, top);
        T::select(z.le(self.a), z, w)
    }

    /// `√(c² + e s²)` (m) at depth `w` (m) below a pole, i.e. at distance
    /// `s = a − w` from the equator; the wall element is
    /// `dA = (2π / k²) √(c² + e s²) ds`. Evaluated as a sum of positive terms:
    /// directly for oblate domes and as `√(a² + |e| w (2a − w))` (using
    /// `c² + e a² = a²`) for prolate ones.
    fn zone_integrand(&self, w: T) -> T {
        let oblate_lanes = self.e.ge(T::splat(0.0));
        // Each form only where some lane's dome has it (a square root each).
        let oblate = if oblate_lanes.any() {
            let s = self.a - w;
            (self.c * self.c + self.e * s * s).sqrt()
        } else {
            T::splat(0.0)
        };
        if oblate_lanes.all() {
            return oblate;
        }
        let prolate = (self.a * self.a - self.e * w * (self.a * 2.0 - w)).sqrt();
        T::select(oblate_lanes, oblate, prolate)
    }

    /// Wall area (m²) of a dome zone of depth `w` (m) measured from the pole.
    ///
    /// `(2π/k²) ∫_{a−w}^{a} √(c² + e s²) ds`, evaluated with the
    /// cancellation-free difference form described in the module docs.
    fn zone_area(&self, w: T) -> T {
        let a = self.a;
        let w = w.max_c(0.0).min(a);
        let s1 = a - w;
        let s2 = a;
        let big1 = self.zone_integrand(w);
        // √(c² + e a²) = a exactly.
        let big2 = a;
        let c2 = self.c * self.c;
        // s2² − s1² without cancellation.
        let ds2 = w * (a * 2.0 - w);
        // ½ (s2 S2 − s1 S1) = ½ (s2² − s1²)(c² + e(s1² + s2²)) / (s2 S2 + s1 S1)
        let term1 = (c2 + self.e * (s1 * s1 + s2 * s2)) / (s2 * big2 + s1 * big1);
        // (c² / 2√|e|) [G(x2) − G(x1)] = ½ (s2² − s1²) c² g(D) / (s2 S1 + s1 S2)
        let cross = s2 * big1 + s1 * big2;
        let d = self.e.abs().sqrt() * ds2 / cross;
        let series = d.lt(T::splat(SERIES_LIMIT));
        let oblate = self.e.gt(T::splat(0.0));
        // asinh's logarithm and divides only where some lane's dome is oblate.
        let mut g = if oblate.any() {
            T::select(oblate, asinh_over_x(d), asin_over_x(d))
        } else {
            asin_over_x(d)
        };
        let steep = !oblate & !series;
        if steep.any() {
            // asin(D) is ill-conditioned as D → 1 (very prolate domes); use
            // atan2 with cos(asin x2 − asin x1) = (S1 S2 + |e| s1 s2) / c²,
            // a sum of positive terms.
            let cos_d = (big1 * big2 + self.e.abs() * s1 * s2) / c2;
            g = T::select(steep, d.zip(cos_d, f64::atan2) / d, g);
        }
        let term2 = c2 * g / cross;
        let integral = ds2 * 0.5 * (term1 + term2);
        let area = integral * (2.0 * PI) / (self.k * self.k);
        T::select(w.le(T::splat(0.0)), T::splat(0.0), area)
    }
}

/// Below this argument `asinh(x)/x` and `asin(x)/x` use their Taylor series
/// (truncation error < 1e-17).
const SERIES_LIMIT: f64 = 1e-2;

/// `asinh(x) / x` for `x ≥ 0`, accurate to a few ulps (series near 0).
fn asinh_over_x<T: Real>(x: T) -> T {
    let x2 = x * x;
    let series = (x2 * (x2 * (x2 * (5.0 / 112.0)).rsub(3.0 / 40.0)).rsub(1.0 / 6.0)).rsub(1.0);
    // asinh x = ln(1 + x + x² / (1 + √(1 + x²))), accurate for all x ≥ 0, with
    // ln(1 + y) = ln u − ((u − 1) − y) / u, u = 1 + y (exact to a couple of ulps).
    let y = x + x2 / ((x2 + 1.0).sqrt() + 1.0);
    let u = y + 1.0;
    let log1p = u.ln() - ((u - 1.0) - y) / u;
    T::select(x.lt(T::splat(SERIES_LIMIT)), series, log1p / x)
}

/// `asin(x) / x` by its Taylor series, for `0 ≤ x < SERIES_LIMIT`.
fn asin_over_x<T: Real>(x: T) -> T {
    let x2 = x * x;
    x2 * (x2 * (x2 * (5.0 / 112.0) + 3.0 / 40.0) + 1.0 / 6.0) + 1.0
}

/// Where [`cap_fraction`]'s start changes from the low-fill to the high-fill form: the start's
/// error is largest there, 8e-4.
const CAP_START_SPLIT: f64 = 0.8;

/// Solves `t² (3 − t) = q` for `t ∈ [0, 1]` (`q ∈ [0, 2]`, clamped) in every
/// lane: the normalised depth of a dome cap holding the fraction `q / 2` of
/// the dome. Also returns the number of Newton/bisection rounds the slowest lane took.
///
/// Newton's method from a start within 8e-4 of the root, safeguarded by
/// bisection in the bracket `√(q/3) ≤ t ≤ √(q/2)` (valid because
/// `2t² ≤ t²(3 − t) ≤ 3t²` on `[0, 1]`). The polynomial is increasing and
/// convex on `(0, 1)`, so Newton converges quadratically; iterations are
/// bounded, so the function always terminates. A lane that has converged no longer moves.
///
/// The start: below q = 0.8, two rounds of the fixed point t = √(q / (3 − t)) from √(q/3);
/// above, y = 1 − t solves y³ − 3y + 2 − q = 0, and two rounds of y = (2 − q + y³)/3 from
/// (2 − q)/3. Arithmetic only, so it vectorises: the trigonometric (Viète) root it replaced was
/// exact but cost a libm `acos` and `cos` per lane, more than the two Newton rounds it saved.
fn cap_fraction<T: Real>(q: T) -> (T, usize) {
    let empty = q.is(|a| a.is_nan() || a <= 0.0);
    let full = q.ge(T::splat(2.0));
    let mut lo = (q / 3.0).sqrt();
    let mut hi = (q / 2.0).sqrt().min_c(1.0);
    // Each start only where some lane takes it (its divides and square roots are most of the
    // start's cost; a capsule's top dome is all high fill).
    let low = q.lt(T::splat(CAP_START_SPLIT));
    let mut low_start = lo;
    if low.any() {
        for _ in 0..2 {
            low_start = (q / low_start.rsub(3.0)).sqrt();
        }
    }
    let r = q.rsub(2.0);
    let mut y = r * (1.0 / 3.0);
    if !low.all() {
        for _ in 0..2 {
            y = (r + y * y * y) * (1.0 / 3.0);
        }
    }
    let guess = T::select(low, low_start, y.rsub(1.0));
    let mut t = T::select(guess.gt(lo) & guess.lt(hi), guess, (lo + hi) * 0.5);
    let mut done = empty | full;
    let mut rounds = 0;
    while rounds < 100 && !done.all() {
        rounds += 1;
        let f = t * t * t.rsub(3.0) - q;
        let moving = !done & !f.is_zero();
        hi = T::select(moving & f.gt(T::splat(0.0)), t, hi);
        lo = T::select(moving & f.lt(T::splat(0.0)), t, lo);
        let fp = t * 3.0 * t.rsub(2.0);
        let newton = t - f / fp;
        // A rounding-level Newton step is convergence, even where it lands on a bracket end
        // (the safeguard below would otherwise bisect away from an already exact root).
        let converged = (newton - t).abs().le(t * (2.0 * f64::EPSILON));
        let next = T::select(newton.gt(lo) & newton.lt(hi), newton, (lo + hi) * 0.5);
        let bracketed = (hi - lo).le(hi * f64::EPSILON);
        t = T::select(moving, T::select(converged, newton, next), t);
        done = done | !moving | converged | bracketed;
    }
    let t = T::select(full, T::splat(1.0), t);
    (T::select(empty, T::splat(0.0), t), rounds)
}

#[cfg(test)]
mod tests {
    use super::{cap_fraction, Shape, Tank, TankLanes};
    use crate::lanes::{Lanes, Real, WIDTH};

    /// The skipped branches (the cap solve's unused start, the dome form no lane has, asinh for
    /// prolate and spherical domes) move no bit: lane groups mixing fills on either side of the
    /// start's split, and oblate, spherical and prolate domes, give every lane what the tank gives
    /// alone, and so do groups all of one kind (spheres and k = 1 capsules, e = 0, included),
    /// empty and full lanes among them.
    #[test]
    fn lanes_skip_only_what_no_lane_takes() {
        let ratios = [0.3, 0.5, 0.75, 1.0, 1.4, 2.5];
        let mut tanks: Vec<Tank> = (0..WIDTH)
            .map(|i| {
                Tank::new(
                    Shape::Capsule,
                    1.0 + 0.1 * i as f64,
                    1.3,
                    ratios[i % ratios.len()],
                )
            })
            .collect();
        tanks.push(Tank::new(Shape::Sphere, 0.8, 0.0, 1.0));
        tanks.push(Tank::new(Shape::Sphere, 1.7, 0.0, 1.0));
        // Which tank each lane takes: every shape mixed, oblate domes only, prolate only,
        // spheres and hemispherical capsules only (e = 0).
        type Pick = fn(usize) -> usize;
        let picks: [(&str, Pick); 4] = [
            ("mixed", |i| i),
            ("oblate", |i| i % 2),
            ("prolate", |i| 4 + i % 2),
            ("spherical", |i| [3, WIDTH, WIDTH + 1][i % 3]),
        ];
        for (name, pick) in picks {
            let tank = |i: usize| &tanks[pick(i)];
            let group = TankLanes::<Lanes>::gather(tank);
            for fill in [0.0, 0.02, 0.1, 0.3, 0.5, 0.7, 0.9, 0.97, 1.0] {
                // Lane i at fill ± a spread that puts lanes on both sides of the cap start split
                // (clamped: the first and last fills hold empty and full lanes).
                let share = |i: usize| (fill + 0.004 * (i as f64 - 8.0)).clamp(0.0, 1.0);
                let v = Lanes::from_fn(|i| share(i) * tank(i).volume_m3());
                let z = group.liquid_height_m(v);
                let wet = group.wetted_area_m2(z);
                let slope = group.wetted_area_slope_m(z);
                for i in 0..WIDTH {
                    let alone = tank(i);
                    let z_i = alone.liquid_height_m(v.lane(i));
                    assert_eq!(z.lane(i).to_bits(), z_i.to_bits(), "{name} {fill} lane {i}");
                    let w = alone.wetted_area_m2(z_i);
                    assert_eq!(wet.lane(i).to_bits(), w.to_bits(), "{name} {fill} lane {i}");
                    let sl = alone.wetted_area_slope_m(z_i);
                    assert_eq!(
                        slope.lane(i).to_bits(),
                        sl.to_bits(),
                        "{name} {fill} lane {i}"
                    );
                }
            }
        }
        // The cap solve on a group on either side of the split and across it.
        for qs in [[0.3, 0.79], [0.81, 1.9], [0.1, 1.99]] {
            let q = Lanes::from_fn(|i| qs[0] + (qs[1] - qs[0]) * i as f64 / (WIDTH - 1) as f64);
            let (t, _) = cap_fraction(q);
            for i in 0..WIDTH {
                assert_eq!(t.lane(i).to_bits(), cap_fraction(q.lane(i)).0.to_bits());
            }
        }
    }

    /// The start is within 8e-4 of the root, so Newton converges in at most four steps for every
    /// fill, the last confirming (a bisection fallback once took up to 48).
    #[test]
    fn cap_fraction_converges_in_few_steps() {
        let n = 200_000;
        let mut worst = 0;
        for i in 1..n {
            let q = 2.0 * i as f64 / n as f64;
            let (t, steps) = cap_fraction(q);
            let residual = (t * t * (3.0 - t) - q).abs();
            assert!(
                residual <= 8.0 * f64::EPSILON * q.max(1.0),
                "q = {q}: residual {residual:e}"
            );
            worst = worst.max(steps);
        }
        assert!(worst <= 4, "worst case {worst} steps");
    }
}
