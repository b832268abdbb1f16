//! Inverse trigonometry in f32, accurate to a few f32 ulps and about three times cheaper
//! than libm: what a per-candidate lookup (an environment map's texel, a density) needs.
//!
//! atan on [0, 1] is an odd polynomial of degree 15, fitted here to near-minimax (absolute
//! error 1.6e-7 rad before rounding); atan2 reduces to it by octant, and acos(x) is
//! atan2(√((1 − x)(1 + x)), x), which stays accurate near ±1 where the classic
//! `√(1 − x) · P(x)` forms lose digits. The unit tests bound the error against f64 libm:
//! below 4e-7 rad for both.

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
    let (ax, ay) = (x.abs(), y.abs());
    let (low, high) = (ax.min(ay), ax.max(ay));
    if high == 0.0 {
        return 0.0;
    }
    let mut r = atan_unit(low / high);
    if ay > ax {
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
    atan2(((1.0 - x) * (1.0 + x)).sqrt(), x)
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
}
