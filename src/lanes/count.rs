//! An operation-counting [`Real`]: [`Counted`] wraps one `f64` and does exactly what `f64`
//! does, bit for bit, while a thread-local tally records every operation the model asks of it.
//! It measures the work of one right-hand side (`benches/roofline.rs`); the engine never uses
//! it, and the `f64` and [`super::Lanes`] paths do not go through it.
//!
//! Each trait method is counted as what it is: `+ -` (and [`Real::rsub`]) as adds, `*` as
//! multiplies, `/` (and [`Real::rdiv`]) as divides, `min`, `max`, `abs` and a clamp (two
//! operations) in one class, comparisons, selects, negations, and the transcendental kernels
//! ([`super::math`]) as calls, whose own operations are [`EXP_COST`], [`LN_COST`] and
//! [`POW_COST`]. `map`, `zip`, `test` and `is` run an arbitrary closure (libm `sin`, `cos`,
//! `atan`, `acos`, `atan2`, a table look-up, a NaN test): they are counted as opaque calls.

use super::{math, Mask, Real};
use std::cell::Cell;
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

/// Operations by class: a tally of [`Counted`] operations, or the cost of one kernel call.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Additions and subtractions.
    pub add: u64,
    pub mul: u64,
    pub div: u64,
    pub sqrt: u64,
    /// `min`, `max`, `abs`; a clamp counts two.
    pub minmax: u64,
    /// Comparisons giving a mask.
    pub cmp: u64,
    /// Per-lane selects.
    pub select: u64,
    /// Sign flips (not floating-point arithmetic: an XOR).
    pub neg: u64,
    /// Mask `&`, `|`, `!`.
    pub mask: u64,
    /// [`math::exp`], [`math::ln`], [`math::pow`] calls.
    pub exp: u64,
    pub ln: u64,
    pub pow: u64,
    /// `map`, `zip` and `test`/`is` calls with a closure the tally cannot see into.
    pub opaque_map: u64,
    pub opaque_zip: u64,
    pub opaque_test: u64,
}

impl Counts {
    /// Floating-point operations outside the kernels: adds, multiplies, divides, square roots
    /// and min/max/abs (what x86's FP arithmetic counters count, an FMA being two).
    pub fn flops(&self) -> u64 {
        self.add + self.mul + self.div + self.sqrt + self.minmax
    }

    /// Transcendental kernel calls.
    pub fn transcendentals(&self) -> u64 {
        self.exp + self.ln + self.pow
    }

    /// Opaque calls.
    pub fn opaque(&self) -> u64 {
        self.opaque_map + self.opaque_zip + self.opaque_test
    }

    /// These operations with every kernel call replaced by the operations inside it
    /// ([`EXP_COST`], [`LN_COST`], [`POW_COST`]); the kernel call counts become 0.
    pub fn with_transcendentals(&self) -> Counts {
        let mut out = Counts {
            exp: 0,
            ln: 0,
            pow: 0,
            ..*self
        };
        for (n, cost) in [
            (self.exp, EXP_COST),
            (self.ln, LN_COST),
            (self.pow, POW_COST),
        ] {
            out.add += n * cost.add;
            out.mul += n * cost.mul;
            out.div += n * cost.div;
            out.sqrt += n * cost.sqrt;
            out.minmax += n * cost.minmax;
            out.cmp += n * cost.cmp;
            out.select += n * cost.select;
            out.neg += n * cost.neg;
            out.mask += n * cost.mask;
        }
        out
    }
}

/// The operations of one [`math::exp`] call, counted on its source line by line:
/// the clamp (2 min/max); `xc·INV_LN2 + ROUNDER` (1 mul, 1 add); `shifted − ROUNDER` (1 add);
/// `hi = xc − kf·LN2_HI` (1 mul, 1 add); `lo = kf·LN2_LO` (1 mul); `r = hi − lo` (1 add);
/// `t = r²` (1 mul); the degree-5 polynomial in Horner form and `r − t·(…)` (5 mul, 5 add);
/// `y = 1 − ((lo − r·c/(2 − c)) − hi)` (1 mul, 4 add, 1 div); `y · 2^k1 · 2^(k−k1)` (2 mul);
/// the overflow and underflow tests (2 compares, 2 selects). 12 mul + 13 add + 1 div + 2 min/max
/// = 28 flops, besides 7 integer operations on the exponent bits.
pub const EXP_COST: Counts = Counts {
    add: 13,
    mul: 12,
    div: 1,
    sqrt: 0,
    minmax: 2,
    cmp: 2,
    select: 2,
    neg: 0,
    mask: 0,
    exp: 0,
    ln: 0,
    pow: 0,
    opaque_map: 0,
    opaque_zip: 0,
    opaque_test: 0,
};

/// The operations of one [`math::ln`] call, counted on its source line by line: `special`
/// (`x ≤ 0`, NaN, `x = ∞`: 3 compares, 2 mask ors); `sub` (1 compare); the subnormal scaling
/// (1 mul, 1 select), the special argument replaced (1 select) and the bias (1 select); the
/// exponent as a double and `dk` (2 add); `f = m − 1` (1 add); `hfsq = 0.5·f·f` (2 mul);
/// `s = f/(2 + f)` (1 add, 1 div); `z = s²`, `w = z²` (2 mul); `t1` (3 mul, 2 add); `t2` (4 mul,
/// 3 add); `r = t2 + t1` (1 add); `y` (3 mul, 5 add); the edge value (2 compares, 2 selects) and
/// the final select. 15 mul + 15 add + 1 div = 31 flops, besides the integer operations on
/// the bits.
pub const LN_COST: Counts = Counts {
    add: 15,
    mul: 15,
    div: 1,
    sqrt: 0,
    minmax: 0,
    cmp: 6,
    select: 6,
    neg: 0,
    mask: 2,
    exp: 0,
    ln: 0,
    pow: 0,
    opaque_map: 0,
    opaque_zip: 0,
    opaque_test: 0,
};

/// One [`math::pow`] call: `exp(y · ln x)`, [`LN_COST`] + 1 mul + [`EXP_COST`] = 60 flops.
pub const POW_COST: Counts = Counts {
    add: EXP_COST.add + LN_COST.add,
    mul: EXP_COST.mul + LN_COST.mul + 1,
    div: EXP_COST.div + LN_COST.div,
    sqrt: 0,
    minmax: EXP_COST.minmax + LN_COST.minmax,
    cmp: EXP_COST.cmp + LN_COST.cmp,
    select: EXP_COST.select + LN_COST.select,
    neg: 0,
    mask: EXP_COST.mask + LN_COST.mask,
    exp: 0,
    ln: 0,
    pow: 0,
    opaque_map: 0,
    opaque_zip: 0,
    opaque_test: 0,
};

thread_local! {
    static TALLY: Cell<Counts> = const { Cell::new(Counts {
        add: 0, mul: 0, div: 0, sqrt: 0, minmax: 0, cmp: 0, select: 0, neg: 0, mask: 0,
        exp: 0, ln: 0, pow: 0, opaque_map: 0, opaque_zip: 0, opaque_test: 0,
    }) };
}

thread_local! {
    /// Divides and square roots by `(file, line)` of the model code that made them.
    static DIVIDE_SITES: std::cell::RefCell<std::collections::HashMap<(&'static str, u32), u64>> =
        std::cell::RefCell::new(std::collections::HashMap::new());
}

/// Record one divide or square root at the caller's source line (its columns summed).
#[track_caller]
fn divide_site() {
    let at = std::panic::Location::caller();
    DIVIDE_SITES.with(|d| *d.borrow_mut().entry((at.file(), at.line())).or_insert(0) += 1);
}

/// This thread's divides and square roots by source line since the last call, which resets
/// them: `(file:line, count)`, most first.
pub fn take_divide_sites() -> Vec<(String, u64)> {
    let mut v: Vec<(String, u64)> = DIVIDE_SITES.with(|d| {
        d.borrow_mut()
            .drain()
            .map(|((file, line), n)| (format!("{file}:{line}"), n))
            .collect()
    });
    v.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    v
}

/// Add `n` to one class of this thread's tally.
#[inline]
fn tally(n: u64, f: impl FnOnce(&mut Counts) -> &mut u64) {
    TALLY.with(|t| {
        let mut c = t.get();
        *f(&mut c) += n;
        t.set(c);
    });
}

/// This thread's tally since the last [`take`], which resets it.
pub fn take() -> Counts {
    TALLY.with(|t| t.replace(Counts::default()))
}

/// One `f64` whose operations are tallied.
#[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd)]
pub struct Counted(pub f64);

/// One `bool` of a [`Counted`] comparison; `&`, `|`, `!` are tallied as mask operations.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CountedMask(pub bool);

impl BitAnd for CountedMask {
    type Output = CountedMask;
    fn bitand(self, o: CountedMask) -> CountedMask {
        tally(1, |c| &mut c.mask);
        CountedMask(self.0 & o.0)
    }
}

impl BitOr for CountedMask {
    type Output = CountedMask;
    fn bitor(self, o: CountedMask) -> CountedMask {
        tally(1, |c| &mut c.mask);
        CountedMask(self.0 | o.0)
    }
}

impl Not for CountedMask {
    type Output = CountedMask;
    fn not(self) -> CountedMask {
        tally(1, |c| &mut c.mask);
        CountedMask(!self.0)
    }
}

impl Mask for CountedMask {
    fn splat(b: bool) -> CountedMask {
        CountedMask(b)
    }
    fn from_fn(mut f: impl FnMut(usize) -> bool) -> CountedMask {
        CountedMask(f(0))
    }
    fn lane(&self, _: usize) -> bool {
        self.0
    }
    fn any(self) -> bool {
        self.0
    }
    fn all(self) -> bool {
        self.0
    }
}

/// A comparison, tallied.
fn compare(b: bool) -> CountedMask {
    tally(1, |c| &mut c.cmp);
    CountedMask(b)
}

impl Real for Counted {
    type Mask = CountedMask;
    const LANES: usize = 1;

    fn splat(v: f64) -> Counted {
        Counted(v)
    }
    fn from_fn(mut f: impl FnMut(usize) -> f64) -> Counted {
        Counted(f(0))
    }
    fn lane(&self, _: usize) -> f64 {
        self.0
    }
    fn map(self, f: impl Fn(f64) -> f64) -> Counted {
        tally(1, |c| &mut c.opaque_map);
        Counted(f(self.0))
    }
    fn zip(self, o: Counted, f: impl Fn(f64, f64) -> f64) -> Counted {
        tally(1, |c| &mut c.opaque_zip);
        Counted(f(self.0, o.0))
    }
    fn test(self, o: Counted, f: impl Fn(f64, f64) -> bool) -> CountedMask {
        tally(1, |c| &mut c.opaque_test);
        CountedMask(f(self.0, o.0))
    }
    fn mul_add(self, a: Counted, b: Counted) -> Counted {
        tally(1, |c| &mut c.mul);
        tally(1, |c| &mut c.add);
        Counted(self.0.mul_add(a.0, b.0))
    }
    fn select(m: CountedMask, a: Counted, b: Counted) -> Counted {
        tally(1, |c| &mut c.select);
        if m.0 {
            a
        } else {
            b
        }
    }
    fn lt(self, o: Counted) -> CountedMask {
        compare(self.0 < o.0)
    }
    fn le(self, o: Counted) -> CountedMask {
        compare(self.0 <= o.0)
    }
    fn gt(self, o: Counted) -> CountedMask {
        compare(self.0 > o.0)
    }
    fn ge(self, o: Counted) -> CountedMask {
        compare(self.0 >= o.0)
    }
    fn is(self, f: impl Fn(f64) -> bool) -> CountedMask {
        tally(1, |c| &mut c.opaque_test);
        CountedMask(f(self.0))
    }
    fn max(self, o: Counted) -> Counted {
        tally(1, |c| &mut c.minmax);
        Counted(self.0.max(o.0))
    }
    fn min(self, o: Counted) -> Counted {
        tally(1, |c| &mut c.minmax);
        Counted(self.0.min(o.0))
    }
    fn max_c(self, o: f64) -> Counted {
        tally(1, |c| &mut c.minmax);
        Counted(self.0.max(o))
    }
    fn min_c(self, o: f64) -> Counted {
        tally(1, |c| &mut c.minmax);
        Counted(self.0.min(o))
    }
    fn clamp_c(self, lo: f64, hi: f64) -> Counted {
        tally(2, |c| &mut c.minmax);
        Counted(self.0.clamp(lo, hi))
    }
    fn abs(self) -> Counted {
        tally(1, |c| &mut c.minmax);
        Counted(self.0.abs())
    }
    #[track_caller]
    fn sqrt(self) -> Counted {
        divide_site();
        tally(1, |c| &mut c.sqrt);
        Counted(self.0.sqrt())
    }
    fn exp(self) -> Counted {
        tally(1, |c| &mut c.exp);
        Counted(math::exp(self.0))
    }
    fn ln(self) -> Counted {
        tally(1, |c| &mut c.ln);
        Counted(math::ln(self.0))
    }
    fn powf(self, y: Counted) -> Counted {
        tally(1, |c| &mut c.pow);
        Counted(math::pow(self.0, y.0))
    }
    fn rsub(self, k: f64) -> Counted {
        tally(1, |c| &mut c.add);
        Counted(k - self.0)
    }
    #[track_caller]
    fn rdiv(self, k: f64) -> Counted {
        divide_site();
        tally(1, |c| &mut c.div);
        Counted(k / self.0)
    }
}

/// Binary operators with a `Counted` or an `f64` on the right, tallied in class `$class`.
macro_rules! counted_ops {
    ($($tr:ident $f:ident $op:tt $class:ident;)*) => {$(
        impl $tr for Counted {
            type Output = Counted;
            #[track_caller]
            fn $f(self, o: Counted) -> Counted {
                if stringify!($class) == "div" {
                    divide_site();
                }
                tally(1, |c| &mut c.$class);
                Counted(self.0 $op o.0)
            }
        }
        impl $tr<f64> for Counted {
            type Output = Counted;
            #[track_caller]
            fn $f(self, o: f64) -> Counted {
                if stringify!($class) == "div" {
                    divide_site();
                }
                tally(1, |c| &mut c.$class);
                Counted(self.0 $op o)
            }
        }
    )*};
}

counted_ops! {
    Add add + add;
    Sub sub - add;
    Mul mul * mul;
    Div div / div;
}

impl AddAssign for Counted {
    fn add_assign(&mut self, o: Counted) {
        *self = *self + o;
    }
}

impl SubAssign for Counted {
    fn sub_assign(&mut self, o: Counted) {
        *self = *self - o;
    }
}

impl MulAssign for Counted {
    fn mul_assign(&mut self, o: Counted) {
        *self = *self * o;
    }
}

impl Neg for Counted {
    type Output = Counted;
    fn neg(self) -> Counted {
        tally(1, |c| &mut c.neg);
        Counted(-self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_expression_is_counted_exactly() {
        let (a, b, k) = (Counted(1.5), Counted(2.0), Counted(-0.25));
        take();
        let r = a * b + k;
        assert_eq!(r.0, 2.75);
        assert_eq!(
            take(),
            Counts {
                add: 1,
                mul: 1,
                ..Counts::default()
            }
        );
        let m = a.lt(b) & !k.gt(Counted(0.0));
        let r = Counted::select(m, (a / b).sqrt(), (-k).exp().max(a.clamp_c(0.0, 1.0)));
        assert_eq!(r.0, (1.5f64 / 2.0).sqrt());
        let t = take();
        assert_eq!(
            t,
            Counts {
                div: 1,
                sqrt: 1,
                minmax: 3,
                cmp: 2,
                select: 1,
                neg: 1,
                mask: 2,
                exp: 1,
                ..Counts::default()
            }
        );
        assert_eq!(t.flops(), 5);
        assert_eq!(t.with_transcendentals().flops(), 5 + 28);
        a.map(f64::sin);
        a.zip(b, f64::atan2);
        a.is(f64::is_nan);
        assert_eq!(take().opaque(), 3);
    }

    /// The counted model is the f64 model: the same rates, bit for bit, on a campaign's
    /// initial state and a state a few RK4 steps in.
    #[test]
    fn counted_model_rates_equal_f64_rates() {
        use crate::campaign::Campaign;
        use crate::model::derive::Drive;
        use crate::model::state::{State, NS};
        use crate::model::{evaluate, rk4_step, Group};
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("campaigns");
        for name in ["mhtb_selfpress", "lh2_upper_stage"] {
            let c = Campaign::load(&dir.join(format!("{name}.toml")), &[]).expect("campaign");
            let p = &c.params;
            let g = Group::one(p);
            let phase = &c.phases[0];
            let dt = phase.dt_s;
            let mut s = crate::simulate::initial_state(&c, p);
            for k in 0..4 {
                let d = Drive::of_phase(phase, k as f64 * dt, Default::default());
                let sc: State<Counted> = s.map(Counted);
                let dc = Drive::<Counted>::gather(|_| d);
                take();
                let counted = evaluate(g, &sc, &dc, Counted(dt)).rates;
                assert!(take().flops() > 100, "{name}: the tally saw the model");
                let plain = evaluate(g, &s, &d, dt).rates;
                for j in 0..NS {
                    assert_eq!(
                        counted[j].0.to_bits(),
                        plain[j].to_bits(),
                        "{name} step {k} rate {j}"
                    );
                }
                rk4_step(
                    g,
                    |t| Drive::of_phase(phase, t, Default::default()),
                    &mut s,
                    k as f64 * dt,
                    dt,
                    None,
                );
            }
        }
    }
}
