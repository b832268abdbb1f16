//! Trigonometry in f32, accurate to a few f32 ulps and cheaper than libm: what a
//! per-candidate lookup (an environment map's texel, a density) and a per-candidate draw (a
//! direction from its angles) need.
//!
//! atan on [0, 1] is an odd polynomial of degree 15, fitted here to near-minimax (absolute
//! error 1.6e-7 rad before rounding); atan2 reduces to it by octant, and acos(x) is
//! atan2(√((1 − x)(1 + x)), x), which stays accurate near ±1 where the classic
//! `√(1 − x) · P(x)` forms lose digits. The unit tests bound the error against f64 libm:
//! below 4e-7 rad for both.
//!
//! sin and cos reduce the angle by multiples of π/2 (π/2 split in two parts, with fused
//! multiply-adds) to [−π/4, π/4], where each is a polynomial of degree 7 or 8 fitted here
//! to near-minimax (errors 4e-8 and 7e-8 in f32 arithmetic); the quadrant swaps and
//! negates them. No call into libm and no branch: written inline, the compiler can run it
//! over lanes. The unit test bounds the absolute error by 2e-7 for
//! angles up to 8π in size.

use std::f32::consts::{FRAC_PI_2, PI};

/// Coefficients of atan(a) ≈ a · P(a²) on [0, 1], lowest degree first.
const ATAN_COEFFICIENTS: [f32; 8] = [
    0.999_999_34,
    -0.333_298_6,
    0.199_465_66,
    -0.139_086_29,
    0.096_421_97,
    -0.055_912_316,
    0.021_862_945,
    -0.004_054_563,
];

/// atan(a) for a in [0, 1].
#[inline]
fn atan_unit(a: f32) -> f32 {
    let s = a * a;
    let mut p = ATAN_COEFFICIENTS[7];
    for &c in ATAN_COEFFICIENTS[..7].iter().rev() {
        p = p * s + c;
    }
    p * a
}

/// atan2(y, x) in [−π, π], absolute error below 4e-7 rad; (0, 0) gives 0.
#[inline]
pub fn atan2(y: f32, x: f32) -> f32 {
    let [low, high] = folded(y, x);
    if high == 0.0 {
        return 0.0;
    }
    unfolded(atan_unit(low / high), y, x)
}

/// [`atan2`] of each lane, the same numbers lane by lane, in a form that the compiler runs
/// in vector lanes: a select where [`atan2`] returns early (the polynomial gives 0 there,
/// which the signs leave at +0). One by one, the early return is the faster.
#[inline(always)]
pub fn atan2_lanes<const N: usize>(y: &[f32; N], x: &[f32; N]) -> [f32; N] {
    std::array::from_fn(|k| {
        let [low, high] = folded(y[k], x[k]);
        let ratio = if high == 0.0 { 0.0 } else { low / high };
        unfolded(atan_unit(ratio), y[k], x[k])
    })
}

/// The smaller and the larger of |x| and |y|: the arctangent of their ratio is the angle
/// of (x, y) folded into [0, π/4].
#[inline(always)]
fn folded(y: f32, x: f32) -> [f32; 2] {
    let (ax, ay) = (x.abs(), y.abs());
    [ax.min(ay), ax.max(ay)]
}

/// The angle of (x, y) from its folded angle `r` ([`folded`]).
#[inline(always)]
fn unfolded(mut r: f32, y: f32, x: f32) -> f32 {
    if y.abs() > x.abs() {
        r = FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    if y < 0.0 {
        -r
    } else {
        r
    }
}

/// acos(x) in [0, π] for x in [−1, 1] (clamped), absolute error below 4e-7 rad.
#[inline]
pub fn acos(x: f32) -> f32 {
    let x = x.clamp(-1.0, 1.0);
    atan2(sine_of(x), x)
}

/// [`acos`] of each lane, the same numbers lane by lane, in vector lanes
/// ([`atan2_lanes`]).
#[inline(always)]
pub fn acos_lanes<const N: usize>(x: &[f32; N]) -> [f32; N] {
    let x = x.map(|x| x.clamp(-1.0, 1.0));
    atan2_lanes(&x.map(sine_of), &x)
}

/// √(1 − x²) for a cosine `x` in [−1, 1], as (1 − x)(1 + x) keeps it accurate near ±1.
#[inline(always)]
fn sine_of(x: f32) -> f32 {
    ((1.0 - x) * (1.0 + x)).sqrt()
}

/// Coefficients of sin(r) ≈ r + r³ · P(r²) on [−π/4, π/4], lowest degree first.
const SIN_COEFFICIENTS: [f32; 3] = [-0.166_666_51, 0.008_331_979, -0.000_194_956_36];
/// Coefficients of cos(r) ≈ 1 − r²/2 + r⁴ · Q(r²) on [−π/4, π/4], lowest degree first.
const COS_COEFFICIENTS: [f32; 3] = [0.041_666_646, -0.001_388_736_8, 0.000_024_438_45];
/// π/2 in two parts: the f32 nearest it, and what that leaves out.
const HALF_PI_HIGH: f32 = FRAC_PI_2;
const HALF_PI_LOW: f32 = -4.371_139e-8;

/// (sin x, cos x), absolute error below 2e-7 for |x| ≤ 8π (and slowly growing with |x|
/// beyond, as the reduction's rounding does).
#[inline]
pub fn sin_cos(x: f32) -> (f32, f32) {
    let quadrant = (x * (2.0 / PI)).round();
    let r = quadrant.mul_add(-HALF_PI_LOW, quadrant.mul_add(-HALF_PI_HIGH, x));
    let s = r * r;
    let [s0, s1, s2] = SIN_COEFFICIENTS;
    let [c0, c1, c2] = COS_COEFFICIENTS;
    let sin = (s * r).mul_add(s2.mul_add(s, s1).mul_add(s, s0), r);
    let cos = (s * s).mul_add(c2.mul_add(s, c1).mul_add(s, c0), s.mul_add(-0.5, 1.0));
    // The quadrant q swaps the two when odd and negates sin when q & 2, cos when (q + 1) & 2:
    // selects and sign flips, no branch, so that a loop of them runs in lanes.
    let q = quadrant as i32;
    let (sin, cos) = if q & 1 != 0 { (cos, sin) } else { (sin, cos) };
    let flip = |value: f32, bit: i32| f32::from_bits(value.to_bits() ^ (((bit & 2) as u32) << 30));
    (flip(sin, q), flip(cos, q.wrapping_add(1)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atan2_is_within_its_bound_everywhere() {
        let mut worst = 0.0f64;
        for k in 0..200_000 {
            let angle = (k as f64 / 200_000.0 - 0.5) * 2.0 * std::f64::consts::PI;
            for radius in [1e-3f64, 1.0, 7e5] {
                let (y, x) = ((radius * angle.sin()) as f32, (radius * angle.cos()) as f32);
                let exact = (y as f64).atan2(x as f64);
                let error = (atan2(y, x) as f64 - exact).abs();
                // Across the ±π cut both ends are the same angle.
                worst = worst.max(error.min((error - 2.0 * std::f64::consts::PI).abs()));
            }
        }
        assert!(worst < 4e-7, "worst error {worst}");
        assert_eq!(atan2(0.0, 0.0), 0.0);
        assert_eq!(atan2(0.0, -1.0), PI);
    }

    #[test]
    fn acos_is_within_its_bound_up_to_the_ends() {
        let mut worst = 0.0f64;
        for k in 0..=400_000 {
            let x = (k as f64 / 200_000.0 - 1.0) as f32;
            let error = (acos(x) as f64 - (x as f64).acos()).abs();
            worst = worst.max(error);
        }
        for x in [1.0f32, 1.0 - f32::EPSILON, -1.0, -1.0 + f32::EPSILON, 2.0] {
            let exact = (x.clamp(-1.0, 1.0) as f64).acos();
            worst = worst.max((acos(x) as f64 - exact).abs());
        }
        assert!(worst < 4e-7, "worst error {worst}");
    }

    #[test]
    fn the_lanes_give_the_numbers_of_one_at_a_time() {
        // Both signs, both zeros, the axes and the diagonals, tiny and huge values.
        let values = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            -0.5,
            1e-30,
            -1e-30,
            3e30,
            -3e30,
            0.999_999_9,
            std::f32::consts::FRAC_1_SQRT_2,
        ];
        let mut compared = 0;
        for chunk in values.chunks(4) {
            for &x in &values {
                let ys: [f32; 4] = std::array::from_fn(|k| chunk.get(k).copied().unwrap_or(0.0));
                let xs = [x; 4];
                let lanes = atan2_lanes(&ys, &xs);
                for k in 0..4 {
                    assert_eq!(
                        lanes[k].to_bits(),
                        atan2(ys[k], xs[k]).to_bits(),
                        "{ys:?} {x}"
                    );
                    compared += 1;
                }
            }
            let cosines: [f32; 4] = std::array::from_fn(|k| chunk.get(k).copied().unwrap_or(2.0));
            let lanes = acos_lanes(&cosines);
            for k in 0..4 {
                assert_eq!(
                    lanes[k].to_bits(),
                    acos(cosines[k]).to_bits(),
                    "{}",
                    cosines[k]
                );
            }
        }
        assert_eq!(compared, 144);
    }

    #[test]
    fn sin_cos_is_within_its_bound() {
        let mut worst = 0.0f64;
        let reach = 8.0 * std::f64::consts::PI;
        for k in 0..=2_000_000 {
            let x = ((k as f64 / 1_000_000.0 - 1.0) * reach) as f32;
            let (sin, cos) = sin_cos(x);
            let (exact_sin, exact_cos) = (x as f64).sin_cos();
            worst = worst
                .max((sin as f64 - exact_sin).abs())
                .max((cos as f64 - exact_cos).abs());
        }
        assert!(worst < 2e-7, "worst error {worst}");
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
    }
}
