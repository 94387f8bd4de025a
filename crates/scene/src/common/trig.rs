//! `sin` and `cos` of the expressions, written so that a loop over lanes vectorizes.
//!
//! # Method
//!
//! Argument reduction by Cody and Waite: with `n = round(2x/π)`,
//!
//! ```text
//!   x − n π/2 = ((x − n P₁) − n P₂) − n P₂ᵗ,    P₁ + P₂ + P₂ᵗ = π/2 to 119 bits,
//! ```
//!
//! where `P₁` and `P₂` have 33 significant bits, so `n P₁` and `n P₂` are exact for
//! `|n| < 2²⁰`; the reduced argument is kept as a head `y₀` and a tail `y₁`
//! (`|y₀| ≤ π/4`). Then `sin(y₀ + y₁)` and `cos(y₀ + y₁)` are the odd degree-13 and even
//! degree-14 minimax polynomials of fdlibm's `__kernel_sin` / `__kernel_cos` (Sun
//! Microsystems, 1993; error below 2⁻⁵⁸ on `[−π/4, π/4]`), with the first-order correction
//! for the tail, and the quadrant `n mod 4` swaps and negates them:
//!
//! ```text
//!   sin x = (sin y, cos y, −sin y, −cos y)[n mod 4],
//!   cos x = (cos y, −sin y, −cos y, sin y)[n mod 4].
//! ```
//!
//! `round` is the add-and-subtract of `1.5·2⁵²`, whose low mantissa bits are `n` in two's
//! complement, and the quadrant selection is done with bit masks, so the kernel has no
//! branch and no call: a loop over lanes compiles to vector instructions (two or four
//! values at once), about three times faster than a call to the C library's `sin_cos` per
//! value. The values stay within one unit in the last place of the correctly rounded
//! ones (checked against the C library's in the tests). Arguments outside `|x| < 2²⁰ π/2`
//! (and infinities and NaN) go to the standard library's `sin` / `cos`, in a second pass
//! over the lanes.
//!
//! The scalar functions compute exactly what the lane functions compute, bit for bit, so
//! an expression gives the same value evaluated alone or in a batch.

// The constants with the digits fdlibm publishes them with (each is the double nearest).
#![allow(clippy::excessive_precision)]

/// Lanes at or above this magnitude (and non-finite ones) use the standard library.
const REDUCIBLE: f64 = 1_647_099.0; // just below 2²⁰ π/2

/// Whether the kernel's reduction holds for `x` (false for NaN).
#[inline(always)]
fn reducible(x: f64) -> bool {
    x.abs() < REDUCIBLE
}

const INV_PIO2: f64 = std::f64::consts::FRAC_2_PI;
/// First 33 bits of π/2.
const PIO2_1: f64 = 1.570_796_326_734_125_614_17e0;
/// Next 33 bits of π/2.
const PIO2_2: f64 = 6.077_100_506_303_965_976_60e-11;
/// π/2 − P₁ − P₂.
const PIO2_2T: f64 = 2.022_266_248_795_950_631_54e-21;
/// `1.5·2⁵²`: adding and subtracting it rounds to the nearest integer.
const TO_INT: f64 = 6_755_399_441_055_744.0;

const S1: f64 = -1.666_666_666_666_663_243_48e-1;
const S2: f64 = 8.333_333_333_322_489_461_24e-3;
const S3: f64 = -1.984_126_982_985_794_931_34e-4;
const S4: f64 = 2.755_731_370_707_006_767_89e-6;
const S5: f64 = -2.505_076_025_340_686_341_95e-8;
const S6: f64 = 1.589_690_995_211_550_102_21e-10;

const C1: f64 = 4.166_666_666_666_660_190_37e-2;
const C2: f64 = -1.388_888_888_887_410_957_49e-3;
const C3: f64 = 2.480_158_728_947_672_941_78e-5;
const C4: f64 = -2.755_731_435_139_066_330_35e-7;
const C5: f64 = 2.087_572_321_298_174_827_90e-9;
const C6: f64 = -1.135_964_755_778_819_482_65e-11;

/// `a` where the mask `m` is all ones, `b` where it is zero.
#[inline(always)]
fn select(m: u64, a: f64, b: f64) -> f64 {
    f64::from_bits((a.to_bits() & m) | (b.to_bits() & !m))
}

/// `(sin x, cos x)` for `|x| < REDUCIBLE` (anything, without a branch, otherwise).
#[inline(always)]
fn kernel(x: f64) -> (f64, f64) {
    let k = x * INV_PIO2 + TO_INT;
    let n = k.to_bits();
    let f = k - TO_INT;
    // Two rounds of the reduction (good to about 118 bits before cancellation).
    let r1 = x - f * PIO2_1;
    let w1 = f * PIO2_2;
    let r = r1 - w1;
    let w = f * PIO2_2T - ((r1 - r) - w1);
    let y0 = r - w;
    let y1 = (r - y0) - w;
    let z = y0 * y0;
    let zz = z * z;
    let rs = S2 + z * (S3 + z * S4) + z * zz * (S5 + z * S6);
    let v = z * y0;
    let sin = y0 - ((z * (0.5 * y1 - v * rs) - y1) - v * S1);
    let rc = z * (C1 + z * (C2 + z * C3)) + zz * zz * (C4 + z * (C5 + z * C6));
    let hz = 0.5 * z;
    let wc = 1.0 - hz;
    let cos = wc + (((1.0 - wc) - hz) + (z * rc - y0 * y1));
    let swap = (n & 1).wrapping_neg();
    let s = select(swap, cos, sin);
    let c = select(swap, sin, cos);
    (
        f64::from_bits(s.to_bits() ^ ((n & 2) << 62)),
        f64::from_bits(c.to_bits() ^ ((n.wrapping_add(1) & 2) << 62)),
    )
}

/// `sin x`.
pub fn sin(x: f64) -> f64 {
    if reducible(x) { kernel(x).0 } else { x.sin() }
}

/// `cos x`.
pub fn cos(x: f64) -> f64 {
    if reducible(x) { kernel(x).1 } else { x.cos() }
}

/// `(sin x, cos x)`, the values of [`sin`] and [`cos`].
pub fn sin_cos(x: f64) -> (f64, f64) {
    if reducible(x) { kernel(x) } else { x.sin_cos() }
}

/// [`sin`] of every lane.
pub fn sin_lanes<const L: usize>(a: &[f64; L]) -> [f64; L] {
    let mut s: [f64; L] = std::array::from_fn(|l| kernel(a[l]).0);
    for (s, &x) in s.iter_mut().zip(a) {
        if !reducible(x) {
            *s = x.sin();
        }
    }
    s
}

/// [`cos`] of every lane.
pub fn cos_lanes<const L: usize>(a: &[f64; L]) -> [f64; L] {
    let mut c: [f64; L] = std::array::from_fn(|l| kernel(a[l]).1);
    for (c, &x) in c.iter_mut().zip(a) {
        if !reducible(x) {
            *c = x.cos();
        }
    }
    c
}

/// [`sin_cos`] of every lane: the sines and the cosines.
pub fn sin_cos_lanes<const L: usize>(a: &[f64; L]) -> ([f64; L], [f64; L]) {
    let (mut s, mut c) = ([0.0; L], [0.0; L]);
    for l in 0..L {
        (s[l], c[l]) = kernel(a[l]);
    }
    for ((s, c), &x) in s.iter_mut().zip(c.iter_mut()).zip(a) {
        if !reducible(x) {
            (*s, *c) = x.sin_cos();
        }
    }
    (s, c)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance in units in the last place (same sign assumed; a sign change of a value
    /// next to zero counts as far apart).
    fn ulps(a: f64, b: f64) -> u64 {
        (a.to_bits() as i64).abs_diff(b.to_bits() as i64)
    }

    /// Against the C library (whose `sin` and `cos` are correctly rounded but for rare
    /// cases): at most one unit in the last place, over random arguments of magnitudes
    /// 1e-9 to 1e7 (both sides of the reduction's range), next to multiples of π/2 (the
    /// reduction's cancellation) and at the special values.
    #[test]
    fn within_one_ulp_of_the_c_library() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut unit = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut xs = Vec::new();
        for i in 0..400_000 {
            let scale = [1e-9, 0.5, 1.0, 4.0, 10.0, 100.0, 1e4, 1e6, 1.6e6, 1e7][i % 10];
            xs.push((2.0 * unit() - 1.0) * scale);
        }
        for k in 1..20_000i64 {
            let x = k as f64 * std::f64::consts::FRAC_PI_2;
            for d in -2i64..=2 {
                xs.push(f64::from_bits((x.to_bits() as i64 + d) as u64));
            }
        }
        let (mut worst, mut differ) = (0, 0usize);
        for &x in &xs {
            let (s, c) = sin_cos(x);
            assert_eq!(s.to_bits(), sin(x).to_bits());
            assert_eq!(c.to_bits(), cos(x).to_bits());
            let (es, ec) = x.sin_cos();
            let u = ulps(s, es).max(ulps(c, ec));
            worst = worst.max(u);
            differ += usize::from(u > 0);
        }
        assert!(worst <= 1, "{worst} ulps");
        // Most values are the correctly rounded ones.
        assert!(differ * 10 < xs.len(), "{differ} of {} differ", xs.len());
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        assert_eq!(sin(-0.0).to_bits(), (-0.0f64).to_bits());
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert!(sin(x).is_nan() && cos(x).is_nan());
        }
    }

    /// The lane functions give the scalar values bit for bit, inside and outside the
    /// reduction's range.
    #[test]
    fn lanes_give_the_scalar_values() {
        let a: [f64; 8] = [0.3, -2.0e6, 1.0e3, f64::NAN, -0.0, 7.5, 1.6e6, 1.7e6];
        let (s, c) = sin_cos_lanes(&a);
        let (s1, c1) = (sin_lanes(&a), cos_lanes(&a));
        for l in 0..8 {
            for (v, w) in [
                (s[l], sin(a[l])),
                (s1[l], sin(a[l])),
                (c[l], cos(a[l])),
                (c1[l], cos(a[l])),
            ] {
                assert_eq!(v.to_bits(), w.to_bits(), "lane {l}: {}", a[l]);
            }
        }
    }
}
