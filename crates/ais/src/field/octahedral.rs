//! The equal-area octahedral mapping (Clarberg 2008) between unit directions and a square
//! grid of texels: every texel covers the same solid angle, 4π / side², and there is no
//! pole, so no texel is a sliver.
//!
//! A direction's |x|, |y| split the azimuth within its quadrant and √(1 − |z|) gives the
//! distance from the centre of the unit diamond; the lower hemisphere folds over the diamond's
//! edges to fill the square [−1, 1]².

use crate::fast_trig;
use std::f32::consts::FRAC_2_PI;

/// Where a unit direction falls in [0, 1)², by the equal-area octahedral mapping.
#[inline]
pub fn square_of(direction: [f32; 3]) -> [f32; 2] {
    let [x, y, z] = direction;
    let (ax, ay, az) = (x.abs(), y.abs(), z.abs());
    let r = (1.0 - az.min(1.0)).max(0.0).sqrt();
    // The azimuth within the quadrant, as a fraction of a right angle.
    let phi = fast_trig::atan2(ay, ax) * FRAC_2_PI;
    let mut v = phi * r;
    let mut u = r - v;
    if z < 0.0 {
        (u, v) = (1.0 - v, 1.0 - u);
    }
    let u = if x < 0.0 { -u } else { u };
    let v = if y < 0.0 { -v } else { v };
    [
        (u * 0.5 + 0.5).clamp(0.0, ONE_BELOW),
        (v * 0.5 + 0.5).clamp(0.0, ONE_BELOW),
    ]
}

/// The unit direction at `p` ∈ [0, 1]² (the inverse of [`square_of`]).
pub fn direction_of(p: [f32; 2]) -> [f32; 3] {
    let (u, v) = (p[0] * 2.0 - 1.0, p[1] * 2.0 - 1.0);
    let (au, av) = (u.abs(), v.abs());
    let distance = 1.0 - (au + av);
    let r = 1.0 - distance.abs();
    let phi = if r > 0.0 { (av - au) / r + 1.0 } else { 1.0 } * std::f32::consts::FRAC_PI_4;
    let z = (1.0 - r * r).copysign(distance);
    let scale = r * (2.0 - r * r).max(0.0).sqrt();
    let x = (phi.cos() * scale).copysign(u);
    let y = (phi.sin() * scale).copysign(v);
    [x, y, z]
}

/// The texel of `direction` on a `side × side` grid, row-major.
#[inline]
pub fn texel_of(direction: [f32; 3], side: u32) -> usize {
    let [u, v] = square_of(direction);
    let column = ((u * side as f32) as u32).min(side - 1);
    let row = ((v * side as f32) as u32).min(side - 1);
    (row * side + column) as usize
}

/// The largest f32 below 1.
const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Pcg32;
    use crate::sampling::uniform_sphere;

    #[test]
    fn the_mapping_inverts() {
        let mut rng = Pcg32::new(5, 5);
        for _ in 0..10_000 {
            let d = uniform_sphere([rng.next_f32(), rng.next_f32()]);
            let back = direction_of(square_of(d.into()));
            let error = (d - glam::Vec3::from(back)).length();
            assert!(error < 1e-4, "{d:?} -> {back:?}");
        }
    }

    #[test]
    fn every_texel_covers_the_same_solid_angle() {
        // Uniform directions fill an equal-area grid evenly: a chi-square-style bound on
        // every texel of an 8 × 8 grid.
        let side = 8;
        let mut counts = vec![0u32; (side * side) as usize];
        let mut rng = Pcg32::new(9, 1);
        let n = 640_000;
        for _ in 0..n {
            let d = uniform_sphere([rng.next_f32(), rng.next_f32()]);
            counts[texel_of(d.into(), side)] += 1;
        }
        let expected = n as f64 / counts.len() as f64;
        for (texel, &count) in counts.iter().enumerate() {
            let z = (count as f64 - expected) / expected.sqrt();
            assert!(z.abs() < 5.0, "texel {texel}: {count} against {expected}");
        }
    }
}
