//! Branch-free `exp`, `ln` and `pow` for the model's hot loop.
//!
//! The platform libm branches and looks up tables, so a loop over lanes that calls it stays
//! scalar. These are the fdlibm/musl algorithms (Sun Microsystems 1993, public domain) with their
//! special cases turned into selects, so that lane loops vectorise. Both the `f64` path and the
//! lane path call them, which keeps the two bit-identical. Errors are checked against the
//! platform libm in the tests below: within 1 ulp for `exp` and `ln`; `pow` is
//! `exp(y ln x)` for a positive base, accurate to about `|y ln x| · 2⁻⁵²` relative.
#![allow(
    clippy::excessive_precision,
    reason = "fdlibm's published coefficients, kept digit for digit"
)]

const LN2_HI: f64 = 6.931_471_803_691_238_164_90e-1;
const LN2_LO: f64 = 1.908_214_929_270_587_700_02e-10;
const INV_LN2: f64 = std::f64::consts::LOG2_E;
/// 1.5 · 2⁵²: adding it rounds a double below 2⁵¹ to an integer held in the low mantissa bits.
const ROUNDER: f64 = 6_755_399_441_055_744.0;

/// Above this `exp` overflows to +∞.
const EXP_OVERFLOW: f64 = 709.782_712_893_384;
/// Below this `exp` underflows to 0.
const EXP_UNDERFLOW: f64 = -745.133_219_101_941_1;

/// 2^k for an integer k in [−1022, 1023], by building the exponent bits.
#[inline(always)]
fn pow2(k: i64) -> f64 {
    f64::from_bits(((k + 1023) as u64) << 52)
}

/// e^x (fdlibm `e_exp.c`): x = k ln 2 + r with |r| ≤ ln 2 / 2, a rational approximation on r,
/// and 2^k applied in two halves so that subnormal results come out right.
#[inline(always)]
pub fn exp(x: f64) -> f64 {
    let xc = x.clamp(EXP_UNDERFLOW, EXP_OVERFLOW);
    let shifted = xc * INV_LN2 + ROUNDER;
    let kf = shifted - ROUNDER;
    let k = (shifted.to_bits() as i64).wrapping_sub(ROUNDER.to_bits() as i64);
    let hi = xc - kf * LN2_HI;
    let lo = kf * LN2_LO;
    let r = hi - lo;
    let t = r * r;
    // Horner in fused multiply-adds (one rounding each, one instruction each).
    let q = t.mul_add(
        4.138_136_797_057_238_460_39e-8,
        -1.653_390_220_546_525_153_90e-6,
    );
    let q = t.mul_add(q, 6.613_756_321_437_934_361_17e-5);
    let q = t.mul_add(q, -2.777_777_777_701_559_338_42e-3);
    let q = t.mul_add(q, 1.666_666_666_666_660_190_37e-1);
    let c = (-t).mul_add(q, r);
    let y = 1.0 - ((lo - (r * c) / (2.0 - c)) - hi);
    let k1 = k >> 1;
    let scaled = y * pow2(k1) * pow2(k - k1);
    let scaled = if x > EXP_OVERFLOW {
        f64::INFINITY
    } else {
        scaled
    };
    if x < EXP_UNDERFLOW {
        0.0
    } else {
        scaled
    }
}

/// Natural logarithm (fdlibm `e_log.c`): x = 2^k (1 + f) with √2/2 ≤ 1 + f < √2, and a
/// polynomial in s = f / (2 + f). 0 gives −∞, a negative argument NaN, +∞ gives +∞.
/// Vectorisable: only unsigned shifts and masks on the bits, k recovered as a double by the
/// 2⁵² trick (AVX2 has no 64-bit integer to double conversion), and the special arguments
/// replaced by 1 before the polynomial, so that the compiler does not branch around it.
#[inline(always)]
pub fn ln(x: f64) -> f64 {
    let special = x <= 0.0 || x.is_nan() || x == f64::INFINITY;
    // Subnormals are scaled into the normal range first.
    let sub = x < f64::MIN_POSITIVE;
    let xs = if sub { x * 18_014_398_509_481_984.0 } else { x };
    let xs = if special { 1.0 } else { xs };
    let bias = if sub { 1023.0 + 54.0 } else { 1023.0 };
    let bits = xs.to_bits();
    let hx = (bits >> 32) + (0x3ff0_0000 - 0x3fe6_a09e);
    // The biased exponent as an exact double: (2⁵² + e) − 2⁵².
    let biased = f64::from_bits(0x4330_0000_0000_0000 | (hx >> 20)) - 4_503_599_627_370_496.0;
    let dk = biased - bias;
    let hm = (hx & 0x000f_ffff) + 0x3fe6_a09e;
    let m = f64::from_bits((hm << 32) | (bits & 0xffff_ffff));
    let f = m - 1.0;
    let hfsq = 0.5 * f * f;
    let s = f / (2.0 + f);
    let z = s * s;
    let w = z * z;
    // Horner in fused multiply-adds.
    let p1 = w.mul_add(1.531_383_769_920_937_332e-1, 2.222_219_843_214_978_396e-1);
    let t1 = w * w.mul_add(p1, 3.999_999_999_940_941_908e-1);
    let p2 = w.mul_add(1.479_819_860_511_658_591e-1, 1.818_357_216_161_805_012e-1);
    let p2 = w.mul_add(p2, 2.857_142_874_366_239_149e-1);
    let t2 = z * w.mul_add(p2, 6.666_666_666_666_735_130e-1);
    let r = t2 + t1;
    let y = s * (hfsq + r) + dk * LN2_LO - hfsq + f + dk * LN2_HI;
    let edge = if x == 0.0 {
        f64::NEG_INFINITY
    } else if x == f64::INFINITY {
        x
    } else {
        f64::NAN
    };
    if special {
        edge
    } else {
        y
    }
}

/// x^y for x > 0 as exp(y ln x) (0 gives 0 for y > 0; a negative or NaN base gives NaN).
#[inline(always)]
pub fn pow(x: f64, y: f64) -> f64 {
    exp(y * ln(x))
}

/// Below this magnitude libm's `sin(x)` is `x` and `cos(x)` is 1 exactly (glibc returns them
/// without evaluating anything: `|x| < 2⁻²⁶` for sin, `|x| < 2⁻²⁷` for cos).
const TRIG_TINY: f64 = 7.450_580_596_923_828e-9; // 2⁻²⁷

/// `x.sin()` in every lane, skipping libm where every lane's |x| < 2⁻²⁷ (the result is `x`): a
/// pendulum at rest (the slosh angle of every hold and unexcited coast is 0) no longer pays
/// glibc's rounding-mode save and restore per lane and right-hand side. The same bits as libm.
/// The test is on the whole group: a per-lane branch around the call is flattened by the
/// compiler, which may call `sin` speculatively.
#[inline(always)]
pub fn sin<T: super::Real>(x: T) -> T {
    let tiny = x.abs().lt(T::splat(TRIG_TINY));
    if super::Mask::all(tiny) {
        x
    } else {
        T::select(tiny, x, x.map(f64::sin))
    }
}

/// `x.cos()` in every lane, skipping libm where every lane's |x| < 2⁻²⁷ (the result is 1; see
/// [`sin`]).
#[inline(always)]
pub fn cos<T: super::Real>(x: T) -> T {
    let tiny = x.abs().lt(T::splat(TRIG_TINY));
    if super::Mask::all(tiny) {
        T::splat(1.0)
    } else {
        T::select(tiny, T::splat(1.0), x.map(f64::cos))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance in units in the last place between two finite doubles of the same sign.
    fn ulps(a: f64, b: f64) -> u64 {
        if a == b {
            return 0;
        }
        (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs()
    }

    /// A deterministic spread of arguments: `n` points log-uniform in [lo, hi].
    fn spread(lo: f64, hi: f64, n: usize) -> impl Iterator<Item = f64> {
        let (a, b) = (lo.ln(), hi.ln());
        (0..n).map(move |i| (a + (b - a) * (i as f64 + 0.37) / n as f64).exp())
    }

    #[test]
    fn exp_within_one_ulp_of_libm() {
        let mut worst = 0;
        for x in spread(1.0e-12, 709.0, 200_000) {
            for v in [x, -x] {
                worst = worst.max(ulps(exp(v), v.exp()));
            }
        }
        assert!(worst <= 1, "exp worst {worst} ulp");
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(710.0), f64::INFINITY);
        assert_eq!(exp(f64::INFINITY), f64::INFINITY);
        assert_eq!(exp(-746.0), 0.0);
        // +0, not −0: a product with it keeps the other factors' sign (thermal's shortcuts).
        assert_eq!(exp(f64::NEG_INFINITY).to_bits(), 0);
        assert!(exp(f64::NAN).is_nan());
        // Subnormal results keep their leading bits.
        let sub = exp(-740.0);
        assert!((sub - (-740.0f64).exp()).abs() <= 2.0 * f64::from_bits(1));
    }

    #[test]
    fn ln_within_one_ulp_of_libm() {
        let mut worst = 0;
        for x in spread(1.0e-310, 1.0e308, 200_000) {
            worst = worst.max(ulps(ln(x), x.ln()));
        }
        for x in spread(0.5, 2.0, 100_000) {
            worst = worst.max(ulps(ln(x), x.ln()));
        }
        assert!(worst <= 1, "ln worst {worst} ulp");
        assert_eq!(ln(1.0), 0.0);
        assert_eq!(ln(0.0), f64::NEG_INFINITY);
        assert_eq!(ln(-0.0), f64::NEG_INFINITY);
        assert_eq!(ln(f64::INFINITY), f64::INFINITY);
        assert!(ln(-1.0).is_nan() && ln(f64::NAN).is_nan());
    }

    #[test]
    fn sin_and_cos_are_libm_s_bits() {
        use crate::lanes::Real;
        let tiny = [
            0.0,
            -0.0,
            1e-300,
            5e-324,
            1e-12,
            7.45e-9,
            TRIG_TINY,
            2.0 * TRIG_TINY,
        ];
        let wide = spread(1.0e-9, 10.0, 20_000);
        for x in tiny.into_iter().chain(wide) {
            for v in [x, -x] {
                assert_eq!(sin(v).to_bits(), v.sin().to_bits(), "sin({v:e})");
                assert_eq!(cos(v).to_bits(), v.cos().to_bits(), "cos({v:e})");
                // A lane group mixing tiny and ordinary arguments.
                let g = crate::lanes::Lanes::from_fn(|i| if i % 2 == 0 { v } else { 0.5 + v });
                let (s, c) = (sin(g), cos(g));
                for i in 0..crate::lanes::WIDTH {
                    assert_eq!(s.lane(i).to_bits(), g.lane(i).sin().to_bits());
                    assert_eq!(c.lane(i).to_bits(), g.lane(i).cos().to_bits());
                }
            }
        }
        assert!(sin(f64::NAN).is_nan() && cos(f64::INFINITY).is_nan());
        let zero = crate::lanes::Lanes::splat(0.0);
        assert_eq!(sin(zero), zero);
        assert_eq!(cos(zero), crate::lanes::Lanes::splat(1.0));
    }

    #[test]
    fn pow_matches_libm_for_the_model_s_arguments() {
        // Churchill–Chu Prandtl factor and the orifice pressure ratios.
        for x in spread(1.0e-3, 1.0e3, 50_000) {
            for y in [9.0 / 16.0, 8.0 / 27.0, 2.0 / 1.4, 2.4 / 1.4, 3.5] {
                let (got, want) = (pow(x, y), x.powf(y));
                assert!(
                    ((got - want) / want).abs() <= 1.0e-14,
                    "pow({x}, {y}) = {got}, libm {want}"
                );
            }
        }
        assert_eq!(pow(0.0, 0.5), 0.0);
        assert!(pow(-1.0, 0.5).is_nan());
    }
}
