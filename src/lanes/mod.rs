//! Lane arithmetic: the model is written once over [`Real`], which is `f64` for one instance and
//! [`Lanes`] for [`WIDTH`] instances advanced in lockstep (structure of arrays).
//!
//! Every [`Lanes`] operation applies the `f64` operation of the same name to each lane, so lane
//! `i` of any computation is bit-identical to the same computation in `f64` on instance `i`:
//! `simulate --instance I` reproduces a row of a run exactly. The lane loops are fixed-length and
//! branch-free, which is what lets the compiler turn them into vector instructions. Branches of
//! the model become [`Real::select`] over a [`Mask`]; the transcendental functions the right-hand
//! side calls most often ([`math`]) are branch-free too, and `f64` uses the same code.

pub mod count;
pub mod isa;
pub mod math;

use std::fmt::Debug;
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

/// Instances per lane group of the CPU engine: four AVX2 vectors (the default x86-64-v3 build),
/// so that the right-hand side's serial chains (Newton iterations of dependent divides) have
/// independent work in flight (lumped MHTB right-hand side 496 → 412 ns per instance from 4 to 8
/// lanes, and 8 → 16 lanes another 10–12 % in right-hand sides per second); 32 lanes, four
/// AVX-512 vectors, in a build for AVX-512 (x86-64-v4 with 512-bit vectors: 16 → 32 lanes
/// 3.3 → 3.45 M right-hand sides/s, against 2.8 M for the AVX2 build; docs/ARCHITECTURE.md,
/// "Build target and width"). Results do not depend on it (lane i is instance i's `f64` work).
pub const WIDTH: usize = if cfg!(target_feature = "avx512f") {
    32
} else {
    16
};

/// A per-lane boolean: `bool` for one instance, [`LaneMask`] for a lane group.
pub trait Mask:
    Copy + Debug + Default + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self>
{
    /// The same value in every lane.
    fn splat(b: bool) -> Self;
    /// Lane `i` is `f(i)`.
    fn from_fn(f: impl FnMut(usize) -> bool) -> Self;
    /// Lane `i` (by reference, as [`Real::lane`]: a lane group's mask is read in place).
    fn lane(&self, i: usize) -> bool;
    /// Whether any lane is set.
    fn any(self) -> bool;
    /// Whether every lane is set.
    fn all(self) -> bool;
}

/// A real number per lane: `f64` for one instance, [`Lanes`] for a lane group.
pub trait Real:
    Copy
    + Debug
    + Default
    + Send
    + Sync
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
{
    /// Its mask type.
    type Mask: Mask;
    /// Number of lanes.
    const LANES: usize;

    /// The same value in every lane.
    fn splat(v: f64) -> Self;
    /// Lane `i` is `f(i)`.
    fn from_fn(f: impl FnMut(usize) -> f64) -> Self;
    /// Lane `i` (by reference: a lane group's value is read in place, not copied out first).
    fn lane(&self, i: usize) -> f64;
    /// `f` applied to every lane.
    fn map(self, f: impl Fn(f64) -> f64) -> Self;
    /// `f` applied lane by lane to `self` and `o`.
    fn zip(self, o: Self, f: impl Fn(f64, f64) -> f64) -> Self;
    /// `f` applied lane by lane, giving a mask.
    fn test(self, o: Self, f: impl Fn(f64, f64) -> bool) -> Self::Mask;
    /// `a` where `m` is set, `b` elsewhere.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;

    /// `self < o`.
    #[inline(always)]
    fn lt(self, o: Self) -> Self::Mask {
        self.test(o, |a, b| a < b)
    }
    /// `self <= o`.
    #[inline(always)]
    fn le(self, o: Self) -> Self::Mask {
        self.test(o, |a, b| a <= b)
    }
    /// `self > o`.
    #[inline(always)]
    fn gt(self, o: Self) -> Self::Mask {
        self.test(o, |a, b| a > b)
    }
    /// `self >= o`.
    #[inline(always)]
    fn ge(self, o: Self) -> Self::Mask {
        self.test(o, |a, b| a >= b)
    }
    /// `f` applied to every lane, giving a mask.
    #[inline(always)]
    fn is(self, f: impl Fn(f64) -> bool) -> Self::Mask {
        self.test(self, |a, _| f(a))
    }
    /// Lanes equal to zero (+0 or −0; a NaN is not). Where a term is a product with such a
    /// factor in every lane, the model may leave out another factor that is finite there (0 · ∞
    /// and 0 · NaN are NaN), provided the zero keeps the sign the full product would have.
    #[inline(always)]
    fn is_zero(self) -> Self::Mask {
        self.is(|a| a == 0.0)
    }
    /// [`f64::max`].
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        self.zip(o, f64::max)
    }
    /// [`f64::min`].
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        self.zip(o, f64::min)
    }
    /// [`f64::max`] with a constant.
    #[inline(always)]
    fn max_c(self, o: f64) -> Self {
        self.map(|a| a.max(o))
    }
    /// [`f64::min`] with a constant.
    #[inline(always)]
    fn min_c(self, o: f64) -> Self {
        self.map(|a| a.min(o))
    }
    /// [`f64::clamp`] to constant bounds.
    #[inline(always)]
    fn clamp_c(self, lo: f64, hi: f64) -> Self {
        self.map(|a| a.clamp(lo, hi))
    }
    /// [`f64::abs`].
    #[inline(always)]
    fn abs(self) -> Self {
        self.map(f64::abs)
    }
    /// [`f64::sqrt`] (correctly rounded, a vector instruction).
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(f64::sqrt)
    }
    /// [`math::exp`].
    #[inline(always)]
    fn exp(self) -> Self {
        self.map(math::exp)
    }
    /// [`math::ln`].
    #[inline(always)]
    fn ln(self) -> Self {
        self.map(math::ln)
    }
    /// [`math::pow`]: `self` to the power `y` for a positive base.
    #[inline(always)]
    fn powf(self, y: Self) -> Self {
        self.zip(y, math::pow)
    }
    /// `self · a + b` rounded once (IEEE 754 fusedMultiplyAdd, [`f64::mul_add`]): one
    /// instruction where a multiply and an add were two, and the same bits on every target (a
    /// CPU without FMA gets the correctly rounded software `fma`; the default x86-64-v3 build and
    /// every AArch64 CPU have the instruction). Rust never fuses `a * b + c` on its own.
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// [`Real::mul_add`] with a constant addend.
    #[inline(always)]
    fn mul_add_c(self, a: Self, b: f64) -> Self {
        self.mul_add(a, Self::splat(b))
    }
    /// Constant `c` minus `self`.
    #[inline(always)]
    fn rsub(self, c: f64) -> Self {
        Self::splat(c) - self
    }
    /// Constant `c` divided by `self`.
    #[inline(always)]
    fn rdiv(self, c: f64) -> Self {
        Self::splat(c) / self
    }
}

impl Mask for bool {
    fn splat(b: bool) -> bool {
        b
    }
    fn from_fn(mut f: impl FnMut(usize) -> bool) -> bool {
        f(0)
    }
    fn lane(&self, _: usize) -> bool {
        *self
    }
    fn any(self) -> bool {
        self
    }
    fn all(self) -> bool {
        self
    }
}

impl Real for f64 {
    type Mask = bool;
    const LANES: usize = 1;

    #[inline(always)]
    fn splat(v: f64) -> f64 {
        v
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> f64) -> f64 {
        f(0)
    }
    #[inline(always)]
    fn lane(&self, _: usize) -> f64 {
        *self
    }
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> f64 {
        f(self)
    }
    #[inline(always)]
    fn zip(self, o: f64, f: impl Fn(f64, f64) -> f64) -> f64 {
        f(self, o)
    }
    #[inline(always)]
    fn test(self, o: f64, f: impl Fn(f64, f64) -> bool) -> bool {
        f(self, o)
    }
    #[inline(always)]
    fn mul_add(self, a: f64, b: f64) -> f64 {
        f64::mul_add(self, a, b)
    }
    #[inline(always)]
    fn select(m: bool, a: f64, b: f64) -> f64 {
        if m {
            a
        } else {
            b
        }
    }
}

/// An array of `WIDTH` values, lane `i` being `f(i)`: a plain loop, which the compiler inlines
/// and vectorises (`std::array::from_fn` goes through a closure call per element here).
#[inline(always)]
fn lanes_from<V: Copy + Default>(mut f: impl FnMut(usize) -> V) -> [V; WIDTH] {
    let mut out = [V::default(); WIDTH];
    for (i, o) in out.iter_mut().enumerate() {
        *o = f(i);
    }
    out
}

/// One boolean per lane of a [`Lanes`], held as a 64-bit word per lane (all ones or zero): the
/// layout a vector compare produces and a blend consumes, so that a compare feeding a select
/// stays in vector registers (an array of `bool` was packed to bytes and widened again at every
/// select).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(align(64))]
pub struct LaneMask(pub [u64; WIDTH]);

/// The lane word of `b`: all ones for true.
#[inline(always)]
fn word(b: bool) -> u64 {
    (b as u64).wrapping_neg()
}

impl BitAnd for LaneMask {
    type Output = LaneMask;
    #[inline(always)]
    fn bitand(self, o: LaneMask) -> LaneMask {
        LaneMask(lanes_from(|i| self.0[i] & o.0[i]))
    }
}

impl BitOr for LaneMask {
    type Output = LaneMask;
    #[inline(always)]
    fn bitor(self, o: LaneMask) -> LaneMask {
        LaneMask(lanes_from(|i| self.0[i] | o.0[i]))
    }
}

impl Not for LaneMask {
    type Output = LaneMask;
    #[inline(always)]
    fn not(self) -> LaneMask {
        LaneMask(lanes_from(|i| !self.0[i]))
    }
}

impl Mask for LaneMask {
    #[inline(always)]
    fn splat(b: bool) -> LaneMask {
        LaneMask([word(b); WIDTH])
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> bool) -> LaneMask {
        LaneMask(lanes_from(|i| word(f(i))))
    }
    #[inline(always)]
    fn lane(&self, i: usize) -> bool {
        self.0[i] != 0
    }
    #[inline(always)]
    fn any(self) -> bool {
        self.0.iter().fold(0, |a, &w| a | w) != 0
    }
    #[inline(always)]
    fn all(self) -> bool {
        self.0.iter().fold(u64::MAX, |a, &w| a & w) != 0
    }
}

/// [`WIDTH`] `f64` lanes, one per instance of a lane group.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(align(64))]
pub struct Lanes(pub [f64; WIDTH]);

impl Real for Lanes {
    type Mask = LaneMask;
    const LANES: usize = WIDTH;

    #[inline(always)]
    fn splat(v: f64) -> Lanes {
        Lanes([v; WIDTH])
    }
    #[inline(always)]
    fn from_fn(f: impl FnMut(usize) -> f64) -> Lanes {
        Lanes(lanes_from(f))
    }
    #[inline(always)]
    fn lane(&self, i: usize) -> f64 {
        self.0[i]
    }
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> Lanes {
        Lanes(lanes_from(|i| f(self.0[i])))
    }
    #[inline(always)]
    fn zip(self, o: Lanes, f: impl Fn(f64, f64) -> f64) -> Lanes {
        Lanes(lanes_from(|i| f(self.0[i], o.0[i])))
    }
    #[inline(always)]
    fn test(self, o: Lanes, f: impl Fn(f64, f64) -> bool) -> LaneMask {
        LaneMask(lanes_from(|i| word(f(self.0[i], o.0[i]))))
    }
    // The transcendental kernels are called in plain loops (no closure in between) so that
    // their inlined bodies sit in the loop the compiler vectorises.
    #[inline(always)]
    fn exp(self) -> Lanes {
        let mut out = self.0;
        for o in &mut out {
            *o = math::exp(*o);
        }
        Lanes(out)
    }
    #[inline(always)]
    fn ln(self) -> Lanes {
        let mut out = self.0;
        for o in &mut out {
            *o = math::ln(*o);
        }
        Lanes(out)
    }
    #[inline(always)]
    fn powf(self, y: Lanes) -> Lanes {
        let mut out = self.0;
        for (o, &e) in out.iter_mut().zip(&y.0) {
            *o = math::pow(*o, e);
        }
        Lanes(out)
    }
    #[inline(always)]
    fn mul_add(self, a: Lanes, b: Lanes) -> Lanes {
        Lanes(lanes_from(|i| self.0[i].mul_add(a.0[i], b.0[i])))
    }
    #[inline(always)]
    fn select(m: LaneMask, a: Lanes, b: Lanes) -> Lanes {
        Lanes(lanes_from(|i| if m.0[i] != 0 { a.0[i] } else { b.0[i] }))
    }
}

/// Lane-by-lane binary operators, with a `Lanes` or an `f64` on the right.
macro_rules! lane_ops {
    ($($tr:ident $f:ident $tra:ident $fa:ident $op:tt;)*) => {$(
        impl $tr for Lanes {
            type Output = Lanes;
            #[inline(always)]
            fn $f(self, o: Lanes) -> Lanes {
                Lanes(lanes_from(|i| self.0[i] $op o.0[i]))
            }
        }
        impl $tr<f64> for Lanes {
            type Output = Lanes;
            #[inline(always)]
            fn $f(self, o: f64) -> Lanes {
                Lanes(lanes_from(|i| self.0[i] $op o))
            }
        }
        impl $tra for Lanes {
            #[inline(always)]
            fn $fa(&mut self, o: Lanes) {
                *self = *self $op o;
            }
        }
    )*};
}

lane_ops! {
    Add add AddAssign add_assign +;
    Sub sub SubAssign sub_assign -;
    Mul mul MulAssign mul_assign *;
}

impl Div for Lanes {
    type Output = Lanes;
    #[inline(always)]
    fn div(self, o: Lanes) -> Lanes {
        Lanes(lanes_from(|i| self.0[i] / o.0[i]))
    }
}

impl Div<f64> for Lanes {
    type Output = Lanes;
    #[inline(always)]
    fn div(self, o: f64) -> Lanes {
        Lanes(lanes_from(|i| self.0[i] / o))
    }
}

impl Neg for Lanes {
    type Output = Lanes;
    #[inline(always)]
    fn neg(self) -> Lanes {
        Lanes(lanes_from(|i| -self.0[i]))
    }
}

/// `c` in every lane (shorthand for [`Real::splat`] in the model's formulas).
#[inline(always)]
pub fn c<T: Real>(v: f64) -> T {
    T::splat(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lane i of a lane computation equals the same computation in f64, bit for bit.
    #[test]
    fn lanes_match_scalar_bit_for_bit() {
        let xs = Lanes::from_fn(|i| [0.3, -2.5, 1.0e-300, 7.0e5][i % 4] * (1.0 + i as f64));
        let f = |x: f64| math::exp((x * 3.0 - 1.0) / (x.abs() + 2.0)) + math::ln(x.abs());
        let g = |x: Lanes| ((x * 3.0 - 1.0) / (x.abs() + 2.0)).exp() + x.abs().ln();
        let lanes = g(xs);
        for i in 0..WIDTH {
            assert_eq!(lanes.lane(i).to_bits(), f(xs.lane(i)).to_bits());
        }
        let m = xs.gt(Lanes::splat(0.0));
        let s = Lanes::select(m, xs, -xs);
        assert_eq!(s, xs.abs());
        assert!(m.any() && !m.all());
    }
}
