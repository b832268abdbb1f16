//! The lat-long mapping between unit directions and texels of a spherical map.
//!
//! A map of height `h` has `h` rows of polar angle θ ∈ [0, π] measured from +z and `2h`
//! columns of azimuth φ = atan2(y, x) ∈ [0, 2π). The talk uses this point-sampled lat-long
//! map. Directions are taken in whatever frame the host passes; world space lets maps be
//! shared between gather points with different normals.

use glam::Vec3;
use std::f32::consts::{PI, TAU};

/// Normalised spherical coordinates of a direction: `u` = φ / 2π and `v` = θ / π, both in [0, 1].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphericalCoordinates {
    /// Azimuth φ / 2π, in [0, 1).
    pub u: f32,
    /// Polar angle θ / π, in [0, 1].
    pub v: f32,
}

impl SphericalCoordinates {
    /// The coordinates of a unit direction (not checked; a zero vector maps to the +x equator).
    ///
    /// Uses polynomial approximations of acos and atan2 (errors below 3e-4 radians, far
    /// below a texel); the same function serves every lookup and update, so the mapping is
    /// consistent. Only directions within that error of a texel boundary may change texel.
    #[inline]
    pub fn of(direction: Vec3) -> Self {
        let v = fast_acos(direction.z) * (1.0 / PI);
        let mut phi = fast_atan2(direction.y, direction.x);
        if phi < 0.0 {
            phi += TAU;
        }
        let u = phi * (1.0 / TAU);
        SphericalCoordinates {
            u: if u >= 1.0 { 0.0 } else { u },
            v,
        }
    }

    /// The unit direction with these coordinates.
    pub fn direction(self) -> Vec3 {
        let (sin_theta, cos_theta) = (self.v * PI).sin_cos();
        let (sin_phi, cos_phi) = (self.u * TAU).sin_cos();
        Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)
    }
}

/// acos(x) for x in [-1, 1], absolute error below 7e-5 (Abramowitz and Stegun 4.4.45).
#[inline]
fn fast_acos(x: f32) -> f32 {
    let a = x.abs().min(1.0);
    let r =
        (1.0 - a).sqrt() * (1.570_728_8 + a * (-0.212_114_4 + a * (0.074_261 + a * -0.018_729_3)));
    if x >= 0.0 {
        r
    } else {
        PI - r
    }
}

/// atan2(y, x) in (−π, π], absolute error below 3e-4: an odd polynomial for atan on [0, 1]
/// after reduction by octant.
#[inline]
fn fast_atan2(y: f32, x: f32) -> f32 {
    let (ax, ay) = (x.abs(), y.abs());
    let (low, high) = (ax.min(ay), ax.max(ay));
    if high == 0.0 {
        return 0.0;
    }
    let a = low / high;
    let s = a * a;
    let mut r = (((-0.046_496_475 * s + 0.159_314_22) * s - 0.327_622_76) * s) * a + a;
    if ay > ax {
        r = std::f32::consts::FRAC_PI_2 - r;
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

/// A texel of a lat-long map: `row` indexes θ, `column` indexes φ.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Texel {
    /// Row, 0 at θ = 0 (+z).
    pub row: u32,
    /// Column, 0 at φ = 0 (+x).
    pub column: u32,
}

/// A lat-long map layout of a given height (its width is twice its height).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LatLong {
    height: u32,
}

impl LatLong {
    /// A layout with `height` rows and `2 * height` columns; `height` must be at least 1.
    pub fn new(height: u32) -> Self {
        assert!(height >= 1, "a lat-long map needs at least one row");
        LatLong { height }
    }

    /// Number of rows.
    #[inline]
    pub fn height(self) -> u32 {
        self.height
    }

    /// Number of columns (twice the height).
    #[inline]
    pub fn width(self) -> u32 {
        2 * self.height
    }

    /// Number of texels.
    #[inline]
    pub fn texel_count(self) -> usize {
        (self.width() * self.height) as usize
    }

    /// The texel containing the direction with coordinates `coordinates`.
    #[inline]
    pub fn texel_at(self, coordinates: SphericalCoordinates) -> Texel {
        let row = ((coordinates.v * self.height as f32) as u32).min(self.height - 1);
        let column = ((coordinates.u * self.width() as f32) as u32).min(self.width() - 1);
        Texel { row, column }
    }

    /// The texel containing a unit direction.
    #[inline]
    pub fn texel(self, direction: Vec3) -> Texel {
        self.texel_at(SphericalCoordinates::of(direction))
    }

    /// Row-major index of a texel in `0..texel_count()`.
    #[inline]
    pub fn index(self, texel: Texel) -> usize {
        (texel.row * self.width() + texel.column) as usize
    }

    /// The texel at a row-major index.
    #[inline]
    pub fn texel_of_index(self, index: usize) -> Texel {
        Texel {
            row: index as u32 / self.width(),
            column: index as u32 % self.width(),
        }
    }

    /// The direction through the centre of a texel.
    pub fn center_direction(self, texel: Texel) -> Vec3 {
        SphericalCoordinates {
            u: (texel.column as f32 + 0.5) / self.width() as f32,
            v: (texel.row as f32 + 0.5) / self.height as f32,
        }
        .direction()
    }

    /// Solid angle of any texel in `row` (steradians).
    pub fn texel_solid_angle(self, row: u32) -> f32 {
        let theta0 = row as f32 * PI / self.height as f32;
        let theta1 = (row + 1) as f32 * PI / self.height as f32;
        (theta0.cos() - theta1.cos()) * TAU / self.width() as f32
    }

    /// Calls `visit` for the texel and its 1-texel border: columns wrap around in φ, rows are
    /// clipped at the poles. Each texel is visited once.
    pub fn for_each_in_neighbourhood(self, center: Texel, mut visit: impl FnMut(Texel)) {
        let width = self.width();
        let first_row = center.row.saturating_sub(1);
        let last_row = (center.row + 1).min(self.height - 1);
        for row in first_row..=last_row {
            if width < 3 {
                for column in 0..width {
                    visit(Texel { row, column });
                }
                continue;
            }
            for offset in [width - 1, 0, 1] {
                visit(Texel {
                    row,
                    column: (center.column + offset) % width,
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Pcg32;

    #[test]
    fn axes_land_in_the_expected_texels() {
        // The horizon is a texel boundary: tilt the horizontal axes just below it.
        let map = LatLong::new(4);
        let below = |v: Vec3| (v - 0.01 * Vec3::Z).normalize();
        assert_eq!(map.texel(Vec3::Z), Texel { row: 0, column: 0 });
        assert_eq!(map.texel(Vec3::NEG_Z), Texel { row: 3, column: 0 });
        assert_eq!(map.texel(below(Vec3::X)), Texel { row: 2, column: 0 });
        assert_eq!(map.texel(below(Vec3::Y)), Texel { row: 2, column: 2 });
        assert_eq!(map.texel(below(-Vec3::X)), Texel { row: 2, column: 4 });
        assert_eq!(map.texel(below(-Vec3::Y)), Texel { row: 2, column: 6 });
    }

    #[test]
    fn texel_centres_map_back_to_their_texel() {
        let map = LatLong::new(16);
        for index in 0..map.texel_count() {
            let texel = map.texel_of_index(index);
            assert_eq!(map.index(texel), index);
            assert_eq!(map.texel(map.center_direction(texel)), texel);
        }
    }

    #[test]
    fn coordinates_round_trip() {
        let mut rng = Pcg32::new(5, 5);
        for _ in 0..1000 {
            let c = SphericalCoordinates {
                u: rng.next_f32(),
                v: rng.next_f32(),
            };
            let back = SphericalCoordinates::of(c.direction());
            let du = (back.u - c.u).abs().min(1.0 - (back.u - c.u).abs());
            assert!(
                du < 1e-4 && (back.v - c.v).abs() < 1e-4,
                "{c:?} -> {back:?}"
            );
        }
    }

    #[test]
    fn fast_trigonometry_is_accurate() {
        let mut rng = Pcg32::new(9, 9);
        let mut worst: f32 = 0.0;
        for _ in 0..100_000 {
            let x = 2.0 * rng.next_f32() - 1.0;
            worst = worst.max((fast_acos(x) - x.acos()).abs());
            let (a, b) = (2.0 * rng.next_f32() - 1.0, 2.0 * rng.next_f32() - 1.0);
            let mut e = (fast_atan2(a, b) - a.atan2(b)).abs();
            e = e.min(TAU - e);
            worst = worst.max(e);
        }
        assert!(worst < 3e-4, "worst error {worst}");
        assert_eq!(fast_atan2(0.0, -1.0), PI);
        assert_eq!(fast_acos(1.0), 0.0);
    }

    #[test]
    fn texel_solid_angles_sum_to_the_sphere() {
        let map = LatLong::new(8);
        let total: f32 = (0..map.height())
            .map(|row| map.texel_solid_angle(row) * map.width() as f32)
            .sum();
        assert!((total - 4.0 * PI).abs() < 1e-4);
    }

    #[test]
    fn neighbourhood_wraps_in_phi_and_clips_at_poles() {
        let map = LatLong::new(4);
        let mut seen = Vec::new();
        map.for_each_in_neighbourhood(Texel { row: 0, column: 0 }, |t| seen.push(t));
        assert_eq!(seen.len(), 6);
        assert!(seen.contains(&Texel { row: 0, column: 7 }));
        assert!(seen.contains(&Texel { row: 1, column: 1 }));
        seen.clear();
        map.for_each_in_neighbourhood(Texel { row: 2, column: 3 }, |t| seen.push(t));
        assert_eq!(seen.len(), 9);
        let tiny = LatLong::new(1);
        seen.clear();
        tiny.for_each_in_neighbourhood(Texel { row: 0, column: 1 }, |t| seen.push(t));
        assert_eq!(seen.len(), 2);
    }
}
