//! The exponential in f32, within about one f32 ulp and without a call into libm, so that
//! a loop of them runs in vector lanes: what a film's Gaussian weights need for every
//! camera sample (Mitsuba's own filter takes its exponential from a polynomial too).
//!
//! exp(x) = 2ⁿ · exp(r), with n the integer nearest x / ln 2 and r = x − n ln 2 in
//! [−ln 2 / 2, ln 2 / 2] (ln 2 split in two parts, with fused multiply-adds); exp(r) is
//! 1 + r + r² · P(r), P of degree 5 (the classic Cephes coefficients), and 2ⁿ is written
//! into the exponent's bits. The unit test bounds the relative error against f64 libm by
//! 1.2e-7 over the whole range where exp(x) is a normal f32.

/// ln 2 in two parts: a value near it with few bits of mantissa (so that n times it is
/// exact for the n that occur, |n| ≤ 128), and what that leaves out.
const LN2_HIGH: f32 = 0.693_359_4;
const LN2_LOW: f32 = -2.121_944_4e-4;
/// Coefficients of P, highest degree first: exp(r) ≈ 1 + r + r² · P(r).
const COEFFICIENTS: [f32; 6] = [
    1.987_569_1e-4,
    1.398_199_9e-3,
    8.333_452e-3,
    4.166_579_6e-2,
    0.166_666_65,
    0.5,
];
/// 1.5 · 2²³: added to a float below 2²², it rounds it to an integer held in its low bits.
const ROUNDING: f32 = 12_582_912.0;
/// Below this exp(x) is not a normal f32; the lanes give 0 there.
const LOWEST: f32 = -87.336_54;
/// Above this exp(x) is within 1e-5 of f32's largest or overflows; the lanes give +∞
/// there.
const HIGHEST: f32 = 88.722_83;

/// exp(x), relative error below 1.2e-7 where the result is a normal f32; 0 below that, +∞
/// where it overflows, NaN for NaN.
#[inline]
pub fn exp(x: f32) -> f32 {
    exp_lanes(&[x])[0]
}

/// [`exp`] of each lane, in a form that the compiler runs in vector lanes (no branch).
#[inline(always)]
pub fn exp_lanes<const N: usize>(x: &[f32; N]) -> [f32; N] {
    std::array::from_fn(|k| {
        let x = x[k];
        let clamped = x.clamp(LOWEST, HIGHEST);
        // n = x / ln 2 rounded to the nearest integer (ties to even) by adding 1.5 · 2²³:
        // the sum's low bits hold n, read as an integer without a conversion.
        let shifted = clamped * std::f32::consts::LOG2_E + ROUNDING;
        let n = shifted - ROUNDING;
        let whole = (shifted.to_bits() as i32).wrapping_sub(ROUNDING.to_bits() as i32);
        let r = n.mul_add(-LN2_LOW, n.mul_add(-LN2_HIGH, clamped));
        let mut p = COEFFICIENTS[0];
        for &c in &COEFFICIENTS[1..] {
            p = p.mul_add(r, c);
        }
        let e = (r * r).mul_add(p, r) + 1.0;
        // 2ⁿ in the exponent's bits, in two factors (n in [−126, 128]: 2¹²⁸ is no f32).
        let half = whole >> 1;
        let power = |m: i32| f32::from_bits((m.wrapping_add(127) as u32) << 23);
        let value = e * power(half) * power(whole - half);
        // Two selects, not an `else if`, which the compiler made into branches. NaN stays
        // NaN through the clamp and the arithmetic.
        let value = if x < LOWEST { 0.0 } else { value };
        if x > HIGHEST {
            f32::INFINITY
        } else {
            value
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative error against f64 libm over every x where exp(x) is a normal f32, on a fine
    /// grid and at the ends; the ends and the special values exactly.
    #[test]
    fn exp_is_within_its_stated_bound() {
        let mut worst = 0.0f64;
        let steps = 2_000_000;
        for i in 0..=steps {
            let x = LOWEST + (HIGHEST - LOWEST) * i as f32 / steps as f32;
            let exact = (x as f64).exp();
            let error = ((exp(x) as f64 - exact) / exact).abs();
            worst = worst.max(error);
        }
        assert!(worst < 1.2e-7, "worst relative error {worst:e}");
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(-100.0), 0.0);
        assert_eq!(exp(100.0), f32::INFINITY);
        assert!(exp(f32::NAN).is_nan());
        let lanes = exp_lanes(&[-8.0, -2.0, 0.5, 10.0]);
        assert_eq!(lanes, [-8.0f32, -2.0, 0.5, 10.0].map(exp));
    }
}
